// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer: penetration depth (see proxima/detail/penetration/penetration.h for the
// definitions).
//
// Derivation. For M = A - B containing the origin, depth = min over the
// facets of M of h_M(n) (n the facet's outward unit normal), and
// h_M(n) >= depth for every unit n (the support function of a convex set
// containing a ball of radius depth about the origin is at least depth).
// The facets of M are the crossings of the Gauss maps of A and of -B: a
// vertex of A's Gauss map (a face of A, normal n) lying in a cell of -B's
// (a vertex of B), the reverse, or an arc of A (an edge, between the normals
// of its two faces) crossing an arc of -B. So
//   1. candidates: all faces of A, all faces of B, and the edge pairs whose
//      arcs cross (tested with a tolerance that errs towards inclusion);
//   2. every candidate's value is h_A(n) + h_B(-n) evaluated with
//      hill-climbing supports started at the candidate's own vertices (one
//      look at their neighbours when the candidate is a true facet; the
//      climb goes on across ties, so that rounding on nearly flat vertices
//      cannot stop it below the support), so a wrong inclusion only adds
//      an upper bound;
//   3. depth = the smallest value; its normal, supports and the Minkowski
//      face are the answer.
// The slow twin tests every pair of edges; the fast cold query walks the
// overlay: for each arc of A, the cells of -B (vertices of B) that it passes
// through form a chain linked by the B edges whose arcs it crosses, found
// from the support at the arc's start by stepping across crossing edges.
// It also prunes (pruned_by): faces whose lower bound exceeds the best value
// so far are not evaluated, which leaves the faces near the answer.
// Tracking (penetration_depth): under a translation of B the faces of M
// only translate, so the cache keeps them with their offsets and a query
// searches them by branch and bound on a tree over their normals
// (search_tree); see PenetrationCache.
//
// Arcs. For a directed edge v -> w of a solid with the face L on its left
// and R on its right (outward normals nL, nR), nL x nR points along +(w - v)
// (a cube's top edge checks it); the arc runs from nL to nR around the axis
// k = w - v. A polygon's edge has the two sides as faces (nR = -nL): its arc
// is the half circle through the outward in-plane normal o = (w - v) x nL,
// cut into the quarter arcs nL -> o -> -nL (still around k = w - v). A
// segment's arc is the whole circle orthogonal to it: four quarter arcs.
// For -B the endpoints are negated and the axis is unchanged
// ((-nL) x (-nR) = nL x nR).
//
// Crossing of two arcs X = (p1, q1, k1) and Y = (p2, q2, k2) (after
// Gregorius, "The Separating Axis Test between convex polyhedra", GDC 2013):
// with s1 = p1.k2, t1 = q1.k2, s2 = p2.k1, t2 = q2.k1, they cross when
// s1 t1 < 0 (X's ends on both sides of Y's plane), s2 t2 < 0, and
// s2 t1 > 0 (the crossing is the one on the arcs, not its antipode).
#include "proxima/detail/penetration/penetration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <memory_resource>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "core/power_of_two.h"
#include "proxima/detail/geometry/exact_predicates.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/shape/support.h"

namespace proxima {
namespace {

// A sign value s = p.k (p unit) with |s| <= kArcTolerance |k| counts as
// zero, and zeros never reject a pair. The arcs' endpoints are face
// normals within kArcNormalError of the exact ones (face_plane's, about
// 16 u per face vertex: polytope.cpp, kSliverRatio; or fast ones) and the
// scaled edge vectors within a few u: a true crossing whose signs are
// decided wrongly by rounding is always kept. Pairs kept by it that do
// not cross cost one evaluation each and cannot lower the minimum (step 2
// above). Pinned by PenetrationDegenerate.* (parallel and coplanar edges).
constexpr double kArcTolerance = 1e-12;

// The largest error bound of a fast face normal (Query::fast_normals) that
// an arc's endpoint takes instead of face_plane's: 512 u, about 1/17 of
// kArcTolerance and face_plane's own bound for a face of 32 vertices (16 u
// per vertex). A well-shaped triangle's bound is about 45 u (equilateral);
// slivers pay for face_plane. Saves face_plane on every face whose arcs
// the walk reads but that it never evaluates (most of them: the walk
// evaluates few of the faces it passes); 512 u rather than 128 u lets
// more faces keep the fast normal (bench/penetration_bench's Cold).
constexpr double kArcNormalError = 512.0 * kUnitRoundoff;

// Slack on a value computed in double, in units of u times the scaled
// magnitude (about 1 after scaling): the dot product of a unit normal with
// a difference of two rounded points. Used for the lower bound and the
// tracked certificate (the contact band of types.h, 64 u R).
constexpr double kValueSlackUlps = kContactBandUlps;

// A vertex belongs to the supporting feature of a direction when its value
// is within this many u (scaled units) of the support value: ties of a
// coplanar face-face contact or a parallel edge, seen through rounding.
constexpr double kTieUlps = 64.0;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Arc {
  Vec3 p, q;         // unit endpoints
  Vec3 k;            // axis: p x q along +k
  double tolerance;  // kArcTolerance |k| (no initializer: see add_edge_candidates_walk)
};

bool arcs_may_cross(const Arc& x, const Arc& y) {
  const double s1 = x.p.dot(y.k), t1 = x.q.dot(y.k);
  const double s2 = y.p.dot(x.k), t2 = y.q.dot(x.k);
  const double ty = y.tolerance, tx = x.tolerance;
  if ((s1 > ty && t1 > ty) || (s1 < -ty && t1 < -ty)) return false;
  if ((s2 > tx && t2 > tx) || (s2 < -tx && t2 < -tx)) return false;
  if ((s2 > tx && t1 < -ty) || (s2 < -tx && t1 > ty)) return false;
  return true;
}

// The elements an expansion of pruned groups enumerates again
// (Query::only, PenetrationCache::Bound): faces of A, faces of B, and
// edges of A as (v, w), w = -1 for all the edges (v, w) at v with v < w.
struct Subset {
  std::vector<int> faces_a, faces_b;
  std::vector<std::array<int, 2>> edges_a;
};

// The query in scaled units: A's vertices times s, B's mapped by b_in_a and
// times s (s a power of two near 1 / R, exact), normals unchanged.
struct Query {
  const ConvexPolytope& a;
  const ConvexPolytope& b;
  Mat3 rotation;
  Mat3 rotation_t;
  Vec3 translation;  // scaled
  double inverse = 1.0;
  double unit = 1.0;
  double magnitude = 0.0;  // R, unscaled
  // Face normals of each hull in its own frame (fast or exact: see
  // PenetrationCache::HullNormals); the shapes outlive the query.
  PenetrationCache::HullNormals* shapes_a = nullptr;
  PenetrationCache::HullNormals* shapes_b = nullptr;
  // Pruning (cold fast path only): the centroids (scaled, A's frame) and
  // the radii of balls about them inside the hulls (0 for flat hulls), so
  // that h_X(n) >= n.centroid_X + inradius_X for every unit n.
  Vec3 centroid_a = Vec3::Zero();
  Vec3 centroid_b = Vec3::Zero();
  double inradius_a = 0.0;
  double inradius_b = 0.0;
  bool prune = false;
  double bound = std::numeric_limits<double>::infinity();   // upper bound on the depth (scaled)
  double pruned = std::numeric_limits<double>::infinity();  // least lower bound of a pruned face
  // Where pruned groups are recorded (PenetrationCache::bounds), or null.
  std::vector<PenetrationCache::Bound>* bounds_out = nullptr;
  // The candidate loops visit only these elements (an expansion), or all.
  const Subset* only = nullptr;
  double prune_margin = 0.0;  // faces within this of the bound are kept (scaled)
  // Points of A and of B (scaled, A's frame): the supports of the best
  // candidate so far (see pruned_by).
  Vec3 reference_a = Vec3::Zero();
  Vec3 reference_b = Vec3::Zero();
  // The enumeration's scratch lists (candidates, hints, the walk's marks
  // and B's arcs): a ScratchScope's buffer while one is open, else null
  // (add_face_candidates and add_edge_candidates_walk need one).
  std::pmr::memory_resource* memory = nullptr;
  // Per vertex v of A (null until a face of A is evaluated): B's support
  // found for the last face through v evaluated, or -1 (a hint).
  std::int32_t* near_b = nullptr;
  // centroid_a and reference_a in B's frame (scaled): R^T (x - t).
  Vec3 centroid_a_in_b = Vec3::Zero();
  Vec3 reference_a_in_b = Vec3::Zero();
  void set_references(int support_a, int support_b) {
    reference_a = point_a(support_a);
    reference_b = point_b(support_b);
    reference_a_in_b = rotation_t * (reference_a - translation);
  }
  // A bound on |x - y| for x in A and y in B (scaled): twice the sum of
  // the bounding radii and the centroids' distance.
  double reach = 0.0;

  Query(const ConvexPolytope& pa, const ConvexPolytope& pb, const Pose& b_in_a)
      : a(pa), b(pb), rotation(b_in_a.rotation), rotation_t(b_in_a.rotation.transpose()) {
    magnitude = std::max(a.scale(), magnitude_bound(b_in_a, b.scale()));
    const detail::PowerOfTwoUnit u = detail::power_of_two_unit(magnitude);
    unit = u.unit;
    inverse = u.inverse;
    translation = b_in_a.translation * inverse;
  }

  Vec3 point_a(int i) const { return a.vertex(i) * inverse; }
  Vec3 point_b(int j) const { return rotation * (b.vertex(j) * inverse) + translation; }

  // Points the query at the hulls' normals and inradii in `shapes`,
  // computed first when they are not (or not for these hulls): fast ones
  // unless `fast` is false (the slow twin: face_plane's only).
  void use_shapes(PenetrationCache::Shapes& shapes, bool fast) {
    if (shapes.a.normals.size() != static_cast<std::size_t>(a.face_count()) ||
        shapes.b.normals.size() != static_cast<std::size_t>(b.face_count())) {
      fast_normals(a, shapes.a, fast);
      fast_normals(b, shapes.b, fast);
    }
    shapes_a = &shapes.a;
    shapes_b = &shapes.b;
    centroid_a = a.centroid() * inverse;
    centroid_b = rotation * (b.centroid() * inverse) + translation;
    centroid_a_in_b = rotation_t * (centroid_a - translation);
    inradius_a = shapes.a.inradius * inverse;
    inradius_b = shapes.b.inradius * inverse;
    reach = 2.0 * ((a.bounding_radius() + b.bounding_radius()) * inverse +
                   (centroid_a - centroid_b).norm());
  }

  // Fills `out` with fast face normals of the hull (its own frame) and the
  // radius of a ball about its centroid inside it. A triangle's normal is
  // its rounded cross product c = p x q (p, q its edges from its first
  // vertex, in units of a power of two near the hull's scale), normalized:
  // |c - c*| <= 8 u |p||q| (the roundings of p, q and of the products), so
  // the unit normal is within 16 u |p||q| / |c| of the exact one, plus the
  // normalization's rounding; kept with twice that bound (|p||q| read as
  // (|p|^2 + |q|^2) / 2, no square root) when |c| >= 2^-10 |p||q| (an
  // angle above 0.06 degree), else, for faces of more vertices and when
  // `fast` is false, face_plane's (error 0). Small hulls too: a cold query
  // evaluates few of their faces (4 of 24 at N = 8 in
  // bench/penetration_bench's Cold), and one face_plane costs several fast
  // normals. The inradius:
  // the least over the faces of n.(v - centroid) less the normal's error
  // and the rounding times twice the bounding radius (>= |v - centroid|),
  // then less 64 u R; 0 for a flat hull (its two faces' planes hold the
  // centroid).
  static void fast_normals(const ConvexPolytope& poly, PenetrationCache::HullNormals& out,
                           bool fast) {
    const auto count = static_cast<std::size_t>(poly.face_count());
    out.normals.resize(count);
    out.error.resize(count);
    out.exact.assign(count, 0);
    const detail::PowerOfTwoUnit s = detail::power_of_two_unit(poly.scale());
    const Vec3 centroid = poly.centroid() * s.inverse;
    const double u = kUnitRoundoff;
    // |v - centroid| <= reach for every vertex v (no square root).
    const double reach = 2.0 * poly.bounding_radius() * s.inverse;
    double r = std::numeric_limits<double>::infinity();
    for (std::size_t f = 0; f < count; ++f) {
      const auto cycle = poly.face(static_cast<int>(f));
      if (fast && cycle.size() == 3) {
        const Vec3 v0 = poly.vertex(cycle[0]) * s.inverse;
        const Vec3 p = poly.vertex(cycle[1]) * s.inverse - v0;
        const Vec3 q = poly.vertex(cycle[2]) * s.inverse - v0;
        const Vec3 c = p.cross(q);
        const double p2 = p.squaredNorm(), q2 = q.squaredNorm();
        const double c2 = c.squaredNorm();
        // Edges of at least 2^-450 (no subnormal roundings in p2 q2); |c|
        // >= 2^-10 |p||q| as squares (no square root); |p||q| <= (p2 +
        // q2) / 2 in the error bound; one rounding more from multiplying
        // by 1 / |c| (within the 8 u).
        if (std::min(p2, q2) > 0x1p-900 && c2 >= 0x1p-20 * (p2 * q2)) {
          const double inverse_length = 1.0 / std::sqrt(c2);
          const Vec3 n = c * inverse_length;
          const double e = (16.0 * (p2 + q2) * inverse_length + 8.0) * u;
          out.normals[f] = n;
          out.error[f] = e;
          r = std::min(r, n.dot(v0 - centroid) - (e + 8.0 * u) * reach);
          continue;
        }
      }
      const Plane plane = poly.face_plane(static_cast<int>(f));
      out.normals[f] = plane.normal;
      out.error[f] = 0.0;
      out.exact[f] = 1;
      r = std::min(r, (plane.offset - plane.normal.dot(poly.centroid())) * s.inverse);
    }
    out.inradius = poly.dimension() < 3 || !(r > 0.0)
                       ? 0.0
                       : std::max(0.0, r * s.unit - kValueSlackUlps * u * poly.scale());
  }

  // face_plane's normal of face f of the hull, computed once.
  static const Vec3& exact_normal(const ConvexPolytope& poly, PenetrationCache::HullNormals& h,
                                  int f) {
    const auto i = static_cast<std::size_t>(f);
    if (!h.exact[i]) {
      h.normals[i] = poly.face_plane(f).normal;
      h.error[i] = 0.0;
      h.exact[i] = 1;
    }
    return h.normals[i];
  }
  Vec3 normal_a(int f) const { return exact_normal(a, *shapes_a, f); }
  // Of -B, in A's frame.
  Vec3 normal_b(int g) const { return -(rotation * exact_normal(b, *shapes_b, g)); }

  // A face's normal for its edges' Gauss-map arcs: the stored one when
  // within kArcNormalError of the exact one (face_plane's has error 0),
  // else face_plane's.
  static const Vec3& arc_normal(const ConvexPolytope& poly, PenetrationCache::HullNormals& h,
                                int f) {
    const auto i = static_cast<std::size_t>(f);
    return h.error[i] <= kArcNormalError ? h.normals[i] : exact_normal(poly, h, f);
  }
  Vec3 arc_normal_a(int f) const { return arc_normal(a, *shapes_a, f); }
  Vec3 arc_normal_b(int g) const { return -(rotation * arc_normal(b, *shapes_b, g)); }
};

// The face to the left of the directed edge v -> w, or -1.
int left_face(const ConvexPolytope& poly, int v, int w) {
  const auto offsets = poly.adjacency_offsets();
  const auto adjacency = poly.adjacency();
  const auto faces = poly.adjacency_faces();
  for (std::int32_t k = offsets[static_cast<std::size_t>(v)];
       k < offsets[static_cast<std::size_t>(v) + 1]; ++k)
    if (adjacency[static_cast<std::size_t>(k)] == w) return faces[static_cast<std::size_t>(k)];
  return -1;
}

// The Gauss-map arcs of edge v -> w (1 for a solid, 2 for a polygon, 4 for
// a segment), axis `k` (the edge vector in A's frame), endpoints from the
// face normals `nl`, `nr` (in A's frame; already negated for -B, in which
// case `negate` flips the in-plane normals the same way). Returns the count.
int edge_arcs(int dimension, const Vec3& k, const Vec3& nl, const Vec3& nr, bool negate,
              std::array<Arc, 4>& out) {
  const double tolerance = kArcTolerance * k.norm();
  const double sign = negate ? -1.0 : 1.0;
  if (dimension == 3) {
    out[0] = {nl, nr, k, tolerance};
    return 1;
  }
  const Vec3 axis = detail::exponent_free(k).normalized();
  if (dimension == 2) {
    // nl is the left side's normal (for -B: minus it); o the outward normal.
    const Vec3 left = sign * nl;  // the un-negated left normal
    const Vec3 o = axis.cross(left).normalized();
    out[0] = {sign * left, sign * o, k, tolerance};
    out[1] = {sign * o, -sign * left, k, tolerance};
    return 2;
  }
  // Segment: u, v orthonormal with u x v = axis.
  const Vec3 helper = std::abs(axis.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = axis.cross(helper).normalized();
  const Vec3 v = axis.cross(u);
  out[0] = {u, v, k, tolerance};
  out[1] = {v, -u, k, tolerance};
  out[2] = {-u, -v, k, tolerance};
  out[3] = {-v, u, k, tolerance};
  return 4;
}

// The arcs of A's edge v -> w, whose left and right faces are l and r
// (left_face's; read only for dimensions 2 and 3).
int arcs_of_a(const Query& q, int v, int w, int l, int r, std::array<Arc, 4>& out) {
  const int dim = q.a.dimension();
  const Vec3 k = q.point_a(w) - q.point_a(v);
  if (dim == 3 || dim == 2) {
    if (l < 0 || r < 0) return 0;
    return edge_arcs(dim, k, q.arc_normal_a(l), q.arc_normal_a(r), false, out);
  }
  return edge_arcs(1, k, Vec3::Zero(), Vec3::Zero(), false, out);
}

int arcs_of_a(const Query& q, int v, int w, std::array<Arc, 4>& out) {
  return arcs_of_a(q, v, w, left_face(q.a, v, w), left_face(q.a, w, v), out);
}

// The arcs of -B's edge v -> w, whose left and right faces are l and r
// (left_face's; read only for dimensions 2 and 3).
int arcs_of_b(const Query& q, int v, int w, int l, int r, std::array<Arc, 4>& out) {
  const int dim = q.b.dimension();
  const Vec3 k = q.point_b(w) - q.point_b(v);
  if (dim == 3 || dim == 2) {
    if (l < 0 || r < 0) return 0;
    return edge_arcs(dim, k, q.arc_normal_b(l), q.arc_normal_b(r), true, out);
  }
  return edge_arcs(1, k, Vec3::Zero(), Vec3::Zero(), true, out);
}

int arcs_of_b(const Query& q, int v, int w, std::array<Arc, 4>& out) {
  return arcs_of_b(q, v, w, left_face(q.b, v, w), left_face(q.b, w, v), out);
}

bool edges_may_cross(const std::array<Arc, 4>& xs, int nx, const std::array<Arc, 4>& ys, int ny) {
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      if (arcs_may_cross(xs[static_cast<std::size_t>(i)], ys[static_cast<std::size_t>(j)]))
        return true;
  return false;
}

// The side of an arc that a normal n lies on is read from the arc's middle
// only when the arc is clearly shorter than a half circle: |p + q| >= this
// (an arc of at most about 150 degrees; |p + q| = 2 cos(angle / 2)).
// Longer arcs (a plate's rim, whose two faces are nearly opposite; a
// needle's edges) have a middle made of rounding; then the other body's
// arc decides, and when both are long both n and -n are evaluated (each an
// upper bound). Pinned by PenetrationOracle.RandomOverlapsFromGrazingToContainment
// (a needle of width 1e-17 on a plate) and PenetrationDegenerate.PolygonCuttingThroughSolid.
constexpr double kClearMiddle = 0.5;

// The middle of an edge's Gauss-map arcs (from arcs_of_a / arcs_of_b), as
// a direction whose side tells which of n, -n lies on them: for a solid
// p + q, for a polygon the outward in-plane normal (both negated for -B,
// as the arcs are); zero when unclear (see kClearMiddle) or for a segment
// (its arcs make a whole circle).
Vec3 arc_middle(const std::array<Arc, 4>& arcs, int count) {
  if (count == 1) {
    const Vec3 middle = arcs[0].p + arcs[0].q;
    return middle.norm() >= kClearMiddle ? middle : Vec3::Zero();
  }
  if (count == 2) return arcs[0].q;  // o (for -B: -o)
  return Vec3::Zero();
}

// An evaluated candidate: its value h_A(n) + h_B(-n) (scaled units), the
// normal and the supports found.
struct Candidate {
  MinkowskiFaceId id;
  Vec3 normal = Vec3::UnitX();
  double value = std::numeric_limits<double>::infinity();
  int support_a = 0;
  int support_b = 0;
};

Candidate evaluate(const Query& q, const MinkowskiFaceId& id, const Vec3& n, int hint_a,
                   int hint_b) {
  Candidate c;
  c.id = id;
  c.normal = n;
  // Through plateaus: a candidate's hints are its own vertices, which for
  // a pair the arc test kept without a crossing can sit on the far side of
  // a hull, on a facet split by rounding into nearly coplanar faces, where
  // the plain climb stops far below the support and the value is no upper
  // bound (support_hill_climb_through_plateaus). Not from a face along its
  // own normal: its vertices are supports already (up to the normal's
  // rounding), and a climb from a support only rises.
  const bool own_face_a = id.kind == MinkowskiFace::face_vertex && id.a0 >= 0;
  const bool own_face_b = id.kind == MinkowskiFace::vertex_face && id.b0 >= 0;
  const Vec3 n_b = q.rotation_t * (-n);
  c.support_a = own_face_a ? support_hill_climb(q.a, n, hint_a)
                           : support_hill_climb_through_plateaus(q.a, n, hint_a);
  c.support_b = own_face_b ? support_hill_climb(q.b, n_b, hint_b)
                           : support_hill_climb_through_plateaus(q.b, n_b, hint_b);
  c.value = n.dot(q.point_a(c.support_a) - q.point_b(c.support_b));
  return c;
}

// The candidate of a face of A (face_vertex) or of B (vertex_face), hints
// from the id.
Candidate evaluate_face(const Query& q, const MinkowskiFaceId& id) {
  if (id.kind == MinkowskiFace::face_vertex)
    return evaluate(q, id, q.normal_a(id.a0), q.a.face(id.a0)[0], id.b0);
  return evaluate(q, id, q.normal_b(id.b0), id.a0, q.b.face(id.b0)[0]);
}

// Pruning (fast cold query): a face of A - B whose lower bound exceeds the
// best value found so far (an upper bound on the depth, q.bound) by more
// than rounding cannot realize the depth and is not evaluated; q.pruned
// keeps the least such lower bound, and q.bounds_out (when set) the group
// with the ball around its normals that `cone` gives (the tracking cache
// needs them: PenetrationCache::Bound). Lower bounds from the balls inside
// the hulls (Query::inradius):
//   face f of A, normal n:   n.a_f + h_B(-n) >= n.(a_f - c_B) + r_B,
//   face g of B, normal n:   h_A(n) - n.b_g >= n.(c_A - b_g) + r_A,
//   edge e of A, n on its arc: n.a_e + h_B(-n) >= min over the arc of
//                            n.(a_e - c_B), plus r_B (arc_minimum);
// and from points a' of A and b' of B (h_A(n) >= n.a', h_B(-n) >= -n.b'):
//   face f of A:  >= n.(a_f - b'),   face g of B:  >= n.(a' - b_g),
//   edge e of A:  >= min over the arc of n.(a_e - b').
// The points are the supports of the best candidate so far (reference_a,
// reference_b): for the faces whose normals are near its direction, the
// ones that can realize the depth, they bound h_A and h_B to second order
// in the angle, where the balls leave the gap between the hulls'
// circumradius and inradius. The face that realizes the depth has a lower
// bound at most the depth, so it is never pruned.
// `kind`, `i`, `j`: the group's element (PenetrationCache::Bound).
template <class Cone>
bool pruned_by(Query& q, double lower, PenetrationCache::Group kind, int i, int j, Cone&& cone) {
  if (!q.prune || !(lower > q.bound + q.prune_margin + kValueSlackUlps * kUnitRoundoff))
    return false;
  q.pruned = std::min(q.pruned, lower);
  if (q.bounds_out != nullptr) {
    PenetrationCache::Bound b = cone();
    b.lower = lower * q.unit;
    b.anchor = q.translation * q.unit;
    b.kind = kind;
    b.i = i;
    b.j = j;
    q.bounds_out->push_back(b);
  }
  return true;
}

// Whether pruned_by would prune a group of lower bound `lower` (a cheaper
// bound first, a dearer one only when that does not prune).
bool above_bound(const Query& q, double lower) {
  return q.prune && lower > q.bound + q.prune_margin + kValueSlackUlps * kUnitRoundoff;
}

// Balls around a pruned group's normals (PenetrationCache::Bound). Slack
// on a ball's radius for the roundings of its centre and of the distances
// to it (a few u each).
constexpr double kConeSlack = 0x1p-40;
// A cap of the unit sphere about a unit centre c is geodesically convex
// when its angular radius is below 90 degrees, i.e. its chord radius below
// sqrt(2): then it holds the arcs between any of its points. Balls wider
// than this are replaced by the whole sphere.
constexpr double kMaxConeChord = 1.4;

PenetrationCache::Bound whole_sphere() { return {Vec3::Zero(), 2.0, 0.0}; }

// The ball around the normals on the arc between the unit normals p and q
// (a face's normals within ep and eq of them): the cap about the
// normalized p + q through both ends.
PenetrationCache::Bound cone_of_arc(const Vec3& p, double ep, const Vec3& q, double eq) {
  const Vec3 sum = p + q;
  const double length = sum.norm();
  if (!(length > 0.25)) return whole_sphere();
  const Vec3 c = sum / length;
  const double spread = std::max((p - c).norm(), (q - c).norm()) + std::max(ep, eq) + kConeSlack;
  if (!(spread < kMaxConeChord)) return whole_sphere();
  return {c, spread, 0.0};
}

using Candidates = std::pmr::vector<Candidate>;

void keep(Query& q, const Candidate& c, Candidates& out) {
  out.push_back(c);
  if (c.value < q.bound) {
    q.bound = c.value;
    q.set_references(c.support_a, c.support_b);
  }
}

// The candidates of an edge pair whose arcs may cross (xa: A's arcs, yb:
// -B's), appended to out: none for parallel edges (they span no face of
// A - B; their faces' candidates cover it). The face's normal is on A's
// arc (outward at A's edge) and on -B's. An arc shorter than a half circle
// holds n or -n, the one on the side of its middle; a segment's arcs make
// a whole circle, then -B's arc decides; for two segments (or arcs so near
// a half circle that the side is unclear, kClearMiddle) both n and -n are
// added (each an upper bound). Pruning: a0 is in A and b0 in B, so the
// value h_A(n) + h_B(-n) is at least n.(a0 - b0), the value itself when
// the pair is a face of A - B (its supports are the edges' points); most
// edge pairs the walk evaluates have a value above the bound, and each
// evaluation costs two hill climbs. Not when the pruned groups are recorded
// (an enumeration after a translation, PenetrationCache::bounds): the
// tracked queries that follow would search one more group per pair
// (bench/penetration_bench's TrackedSweep).
void add_edge_candidate(Query& q, int a0, int a1, const std::array<Arc, 4>& xa, int na, int b0,
                        int b1, const std::array<Arc, 4>& yb, int nb, Candidates& out) {
  const MinkowskiFaceId id{MinkowskiFace::edge_edge, a0, a1, b0, b1};
  // Scaled, a small body's edges can be 2^-500 long beside the other's
  // (PenetrationRegression.TinyBodyInHugeOneHasUnitNormal): exponent_free.
  const Vec3 ea = detail::exponent_free(xa[0].k);
  const Vec3 eb = detail::exponent_free(yb[0].k);
  Vec3 n = ea.cross(eb);
  const double length = n.norm();
  if (!(length > 0x1p-200 * ea.norm() * eb.norm()) || !(length > 0.0)) return;
  n /= length;
  Vec3 middle = arc_middle(xa, na);
  if (middle.squaredNorm() == 0) middle = arc_middle(yb, nb);
  const auto add = [&](const Vec3& normal) {
    if (q.bounds_out == nullptr) {
      // Pruned as pruned_by does when it records no group.
      const double lower = normal.dot(q.point_a(a0) - q.point_b(b0));
      if (above_bound(q, lower)) {
        q.pruned = std::min(q.pruned, lower);
        return;
      }
    }
    keep(q, evaluate(q, id, normal, a0, b0), out);
  };
  if (middle.squaredNorm() == 0) {
    add(n);
    add(-n);
    return;
  }
  add(n.dot(middle) < 0 ? Vec3(-n) : n);
}

// A lower bound on n.w for the exact unit normal n of a face, from its
// stored normal `m` (within `error` of n; a few u more for B's, turned by
// the rotation), |w| <= reach (Query::reach: no square root).
double face_lower(const Vec3& m, double error, const Vec3& w, double reach) {
  return m.dot(w) - error * reach;
}

// Appends every face candidate (faces of A, faces of B), the ones that
// pruned_by leaves. The pruning test reads the fast normals; a face kept
// is evaluated along its exact one.
// A list of n hints in q.memory, all -1.
std::int32_t* new_hints(const Query& q, int n) {
  std::int32_t* hints =
      std::pmr::polymorphic_allocator<std::int32_t>(q.memory).allocate(static_cast<std::size_t>(n));
  std::fill_n(hints, n, -1);
  return hints;
}

void add_face_candidates(Query& q, Candidates& out) {
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const PenetrationCache::HullNormals& sb = *q.shapes_b;
  // Hints for the other hull's support: the last one found for a face
  // through each vertex (neighbouring faces have near normals, so the
  // climb from it is short; the previous face's, in index order, can be
  // anywhere: at N = 4096 an enumeration that keeps many faces spent most
  // of its time climbing). Allocated with the first face evaluated.
  // A face that the two lower bounds of pruned_by's comment leave gets a
  // third, the same with the hint's point of the other hull (a point of
  // it, and near its support along the face's normal, so that the bound
  // is near the face's value): most faces evaluated have a value above the
  // bound, so the test saves most candidates of a cold query
  // (bench/penetration_bench's Cold, with the edge pairs' test).
  std::int32_t*& near_b = q.near_b;
  std::int32_t* near_a = nullptr;
  int hint_b = 0;
  const int count_a =
      q.only != nullptr ? static_cast<int>(q.only->faces_a.size()) : q.a.face_count();
  for (int k = 0; k < count_a; ++k) {
    const int f = q.only != nullptr ? q.only->faces_a[static_cast<std::size_t>(k)] : k;
    const auto i = static_cast<std::size_t>(f);
    if (q.prune) {
      const auto cycle = q.a.face(f);
      const Vec3 af = q.point_a(cycle[0]);
      const Vec3& n = sa.normals[i];
      const double error = sa.error[i];
      double lower = std::max(face_lower(n, error, af - q.centroid_b, q.reach) + q.inradius_b,
                              face_lower(n, error, af - q.reference_b, q.reach));
      if (!above_bound(q, lower)) {
        const std::int32_t near = near_b == nullptr ? -1 : near_b[cycle[0]];
        lower = std::max(lower,
                         face_lower(n, error, af - q.point_b(near >= 0 ? near : hint_b), q.reach));
      }
      if (pruned_by(q, lower, PenetrationCache::Group::face_a, f, -1, [&] {
            return PenetrationCache::Bound{n, error + kConeSlack, 0.0};
          }))
        continue;
    }
    const auto cycle = q.a.face(f);
    if (near_b == nullptr) near_b = new_hints(q, q.a.vertex_count());
    const std::int32_t near = near_b[static_cast<std::size_t>(cycle[0])];
    MinkowskiFaceId id{MinkowskiFace::face_vertex, f, -1, near >= 0 ? near : hint_b, -1};
    Candidate c = evaluate_face(q, id);
    c.id.b0 = c.support_b;
    hint_b = c.support_b;
    for (const std::int32_t v : cycle) near_b[static_cast<std::size_t>(v)] = c.support_b;
    keep(q, c, out);
  }
  int hint_a = 0;
  const int count_b =
      q.only != nullptr ? static_cast<int>(q.only->faces_b.size()) : q.b.face_count();
  for (int k = 0; k < count_b; ++k) {
    const int g = q.only != nullptr ? q.only->faces_b[static_cast<std::size_t>(k)] : k;
    const auto i = static_cast<std::size_t>(g);
    if (q.prune) {
      // In B's frame (scaled): with n = -(R m), b_g = R b'_g + t and x' =
      // R^T (x - t), n.(x - b_g) = m.(b'_g - x'); 8 u more of error for
      // the rotations' roundings.
      const Vec3& m = sb.normals[i];
      const double error = sb.error[i] + 8.0 * kUnitRoundoff;
      const auto cycle = q.b.face(g);
      const Vec3 bg = q.b.vertex(cycle[0]) * q.inverse;
      double lower = std::max(face_lower(m, error, bg - q.centroid_a_in_b, q.reach) + q.inradius_a,
                              face_lower(m, error, bg - q.reference_a_in_b, q.reach));
      if (!above_bound(q, lower)) {
        const std::int32_t near = near_a == nullptr ? -1 : near_a[cycle[0]];
        const Vec3 hint_in_b =
            q.rotation_t * (q.point_a(near >= 0 ? near : hint_a) - q.translation);
        lower = std::max(lower, face_lower(m, error, bg - hint_in_b, q.reach));
      }
      // The face's normal of A - B is -(R m), within error of it (8 u
      // for the rotation's rounding included).
      if (pruned_by(q, lower, PenetrationCache::Group::face_b, g, -1, [&] {
            return PenetrationCache::Bound{-(q.rotation * m), error + kConeSlack, 0.0};
          }))
        continue;
    }
    const auto cycle = q.b.face(g);
    if (near_a == nullptr) near_a = new_hints(q, q.b.vertex_count());
    const std::int32_t near = near_a[static_cast<std::size_t>(cycle[0])];
    MinkowskiFaceId id{MinkowskiFace::vertex_face, near >= 0 ? near : hint_a, -1, g, -1};
    Candidate c = evaluate_face(q, id);
    c.id.a0 = c.support_a;
    hint_a = c.support_a;
    for (const std::int32_t v : cycle) near_a[static_cast<std::size_t>(v)] = c.support_a;
    keep(q, c, out);
  }
}

// The least n.w over the arc from p to q (unit, angle alpha < pi), or a
// lower bound on it: with n = c1 p + c2 q, c1, c2 >= 0 and
// 1 <= c1 + c2 <= 1 / cos(alpha / 2), n.w >= m = min(p.w, q.w) when
// m >= 0 and n.w >= m / cos(alpha / 2) otherwise (cos(alpha / 2) =
// |p + q| / 2). -infinity for an arc too near a half circle. The arc's
// ends within `error` of the exact arc's (fast face normals,
// kArcNormalError), |w| <= reach: each end's value within error * reach,
// and the exact cos(alpha / 2) at least |p + q| / 2 - error.
//
// kMinArcHalfCos: below it the arc is taken as a half circle. Soundness
// needs only a positive threshold (the lower bound on cos(alpha / 2) must
// be positive for the division to keep the sign); at 1e-3 the bound m /
// half_cos is already a thousand times m, too loose to prune a group, so a
// smaller threshold would buy nothing and risk dividing by rounding noise.
// The fast-against-brute-force twins (PenetrationTwins.WalkMatchesBruteForce,
// ...SmallHullsWithFastArcNormalsMatchBruteForce) catch an unsound prune.
constexpr double kMinArcHalfCos = 1e-3;
double arc_minimum(const Arc& arc, const Vec3& w, double error, double reach) {
  const double m = std::min(arc.p.dot(w), arc.q.dot(w)) - error * reach;
  if (m >= 0.0) return m;
  const double half_cos = 0.5 * (arc.p + arc.q).norm() - error;
  return half_cos > kMinArcHalfCos ? m / half_cos : -std::numeric_limits<double>::infinity();
}

// Brute force over all edge pairs.
void add_edge_candidates_brute_force(Query& q, Candidates& out) {
  struct EdgeArcs {
    int v, w, count;
    std::array<Arc, 4> arcs;
  };
  auto all = [](const ConvexPolytope& poly, auto&& arcs_of) {
    std::vector<EdgeArcs> edges;
    for (const auto& e : poly.edges()) {
      EdgeArcs x{e[0], e[1], 0, {}};
      x.count = arcs_of(e[0], e[1], x.arcs);
      if (x.count > 0) edges.push_back(x);
    }
    return edges;
  };
  const std::vector<EdgeArcs> ea =
      all(q.a, [&](int v, int w, std::array<Arc, 4>& o) { return arcs_of_a(q, v, w, o); });
  const std::vector<EdgeArcs> eb =
      all(q.b, [&](int v, int w, std::array<Arc, 4>& o) { return arcs_of_b(q, v, w, o); });
  for (const EdgeArcs& x : ea)
    for (const EdgeArcs& y : eb)
      if (edges_may_cross(x.arcs, x.count, y.arcs, y.count))
        add_edge_candidate(q, x.v, x.w, x.arcs, x.count, y.v, y.w, y.arcs, y.count, out);
}

// B's arcs by adjacency slot (add_edge_candidates_walk) up to this size
// come from the query's scratch buffer (solve_cold).
constexpr std::size_t kScratchArcBytes = 4096;

// The overlay walk: for each arc of A, the chain of B cells it crosses.
void add_edge_candidates_walk(Query& q, Candidates& out) {
  // Visited B vertices of the current arc (the queue too).
  std::pmr::vector<std::int32_t> chain(q.memory);
  std::pmr::vector<char> visited(static_cast<std::size_t>(q.b.vertex_count()), 0, q.memory);
  int hint = 0;
  // A vertex of B near B's support along -n for the normals n near v's
  // cell of A's Gauss map: the support found for a face through v, else
  // the last arc's start. The lower bounds read it as a point of B when
  // the centroid's and the reference's do not prune (a third bound, as
  // for the faces in add_face_candidates).
  const auto near_hint = [&](int v) {
    const std::int32_t near = q.near_b == nullptr ? -1 : q.near_b[v];
    return near >= 0 ? static_cast<int>(near) : hint;
  };
  std::array<Arc, 4> xs, ys;
  // A solid B's arcs, one per edge, computed once on first use (each is
  // met from several arcs of A), by adjacency slot of either direction
  // (an arc read backwards is the same arc for the crossing test).
  const bool memo = q.b.dimension() == 3;
  const auto offsets = q.b.adjacency_offsets();
  const auto adjacency_b = q.b.adjacency();
  const auto faces_b = q.b.adjacency_faces();
  // Storage only (not value-initialized): with pruning a query reads a
  // few of B's slots, and writing all of them (80 bytes each) would make a
  // large cold query pay the page faults of the fresh allocation.
  // From the scratch buffer when small; else from the heap (the buffer's
  // next blocks double in size: a large body's arcs would take a fresh
  // block, and its page faults, every query).
  const std::size_t slots = memo ? q.b.adjacency().size() : 0;
  std::unique_ptr<Arc[]> heap_arcs;
  Arc* slot_arc = nullptr;
  if (slots * sizeof(Arc) <= kScratchArcBytes) {
    slot_arc = std::pmr::polymorphic_allocator<Arc>(q.memory).allocate(slots);
    std::uninitialized_default_construct_n(slot_arc, slots);
  } else {
    heap_arcs = std::make_unique_for_overwrite<Arc[]>(slots);
    slot_arc = heap_arcs.get();
  }
  std::pmr::vector<char> slot_ready(slots, 0, q.memory);
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const bool solid_a = q.a.dimension() == 3;
  const auto offsets_a = q.a.adjacency_offsets();
  const auto adjacency_a = q.a.adjacency();
  const auto faces_a = q.a.adjacency_faces();
  // Every edge of A once, as ConvexPolytope::edges() lists them (v < w, in
  // adjacency order), with the face to its left from the slot.
  // In an expansion (Query::only) an item is all the edges at a vertex
  // (only_w = -1) or one edge.
  const int items =
      q.only != nullptr ? static_cast<int>(q.only->edges_a.size()) : q.a.vertex_count();
  for (int item = 0; item < items; ++item) {
    const int v = q.only != nullptr ? q.only->edges_a[static_cast<std::size_t>(item)][0] : item;
    const int only_w = q.only != nullptr ? q.only->edges_a[static_cast<std::size_t>(item)][1] : -1;
    const auto slot_begin = static_cast<std::size_t>(offsets_a[static_cast<std::size_t>(v)]);
    const auto slot_end = static_cast<std::size_t>(offsets_a[static_cast<std::size_t>(v) + 1]);
    if (q.prune && solid_a && only_w < 0) {
      // All edges at v at once: the faces to the left of v -> w over its
      // neighbours w are all the faces around v, so both faces of every
      // edge at v; the bound below (the per-edge one, with the least over
      // all of them) is at most each edge's. Saves finding each edge's
      // right face (a scan of its other end's neighbours) away from the
      // answer.
      const Vec3 av = q.point_a(v);
      const Vec3 wc = av - q.centroid_b, wr = av - q.reference_b;
      double mc = kInfinity, mr = kInfinity;
      bool all = true;
      for (std::size_t at = slot_begin; at < slot_end && all; ++at) {
        const int f = faces_a[at];
        all = f >= 0;
        if (!all) break;
        const auto i = static_cast<std::size_t>(f);
        mc = std::min(mc, face_lower(sa.normals[i], sa.error[i], wc, q.reach));
        mr = std::min(mr, face_lower(sa.normals[i], sa.error[i], wr, q.reach));
      }
      // The faces of A - B of the edges at v have their normals in v's
      // cell of A's Gauss map, the spherical polygon of the normals of the
      // faces around v: inside the cap about their normalized sum that
      // holds them all.
      const auto cone = [&] {
        Vec3 sum = Vec3::Zero();
        double error = 0.0;
        for (std::size_t at = slot_begin; at < slot_end; ++at) {
          const auto i = static_cast<std::size_t>(faces_a[at]);
          sum += sa.normals[i];
          error = std::max(error, sa.error[i]);
        }
        const double length = sum.norm();
        if (!(length > 0.25)) return whole_sphere();
        const Vec3 c = sum / length;
        double spread = 0.0;
        for (std::size_t at = slot_begin; at < slot_end; ++at)
          spread = std::max(spread, (sa.normals[static_cast<std::size_t>(faces_a[at])] - c).norm());
        spread += error + kConeSlack;
        if (!(spread < kMaxConeChord)) return whole_sphere();
        return PenetrationCache::Bound{c, spread, 0.0};
      };
      double lower =
          std::max(mc >= 0.0 ? mc + q.inradius_b : -kInfinity, mr >= 0.0 ? mr : -kInfinity);
      if (all && slot_begin < slot_end && !above_bound(q, lower)) {
        // The same with B's point at the hint (near_hint).
        const Vec3 wh = av - q.point_b(near_hint(v));
        double mh = kInfinity;
        for (std::size_t at = slot_begin; at < slot_end; ++at) {
          const auto i = static_cast<std::size_t>(faces_a[at]);
          mh = std::min(mh, face_lower(sa.normals[i], sa.error[i], wh, q.reach));
        }
        if (mh >= 0.0) lower = std::max(lower, mh);
      }
      if (all && slot_begin < slot_end &&
          pruned_by(q, lower, PenetrationCache::Group::vertex_a, v, -1, cone))
        continue;
    }
    for (std::size_t at = slot_begin; at < slot_end; ++at) {
      const int w_end = adjacency_a[at];
      if (!(v < w_end) || (only_w >= 0 && w_end != only_w)) continue;
      const std::array<int, 2> e = {v, w_end};
      const int l = q.a.dimension() >= 2 ? faces_a[at] : -1;
      const int r = q.a.dimension() >= 2 ? left_face(q.a, w_end, v) : -1;
      if (q.prune && solid_a && l >= 0 && r >= 0) {
        // First from the faces' stored normals, without the arc: every n
        // on the arc from nL to nR is c1 nL + c2 nR with c1, c2 >= 0 and
        // c1 + c2 >= 1, so n.w >= min(nL.w, nR.w) when that is >= 0
        // (arc_minimum).
        const auto il = static_cast<std::size_t>(l), ir = static_cast<std::size_t>(r);
        const auto least = [&](const Vec3& w) {
          return std::min(face_lower(sa.normals[il], sa.error[il], w, q.reach),
                          face_lower(sa.normals[ir], sa.error[ir], w, q.reach));
        };
        const Vec3 av = q.point_a(v);
        const double m = least(av - q.centroid_b), m2 = least(av - q.reference_b);
        const double lower =
            std::max(m >= 0.0 ? m + q.inradius_b : -kInfinity, m2 >= 0.0 ? m2 : -kInfinity);
        if (pruned_by(q, lower, PenetrationCache::Group::edge_a, v, w_end, [&] {
              return cone_of_arc(sa.normals[il], sa.error[il], sa.normals[ir], sa.error[ir]);
            }))
          continue;
      }
      const int nx = arcs_of_a(q, v, w_end, l, r, xs);
      if (q.prune && nx > 0) {
        const Vec3 w = q.point_a(e[0]) - q.centroid_b;
        const Vec3 w2 = q.point_a(e[0]) - q.reference_b;
        // The arcs' ends: the faces' normals as arcs_of_a read them (error
        // 0 once face_plane's), and for a polygon the in-plane normal from
        // them, normalized (twice the error at most).
        const double error = l >= 0 && r >= 0
                                 ? 2.0 * std::max(sa.error[static_cast<std::size_t>(l)],
                                                  sa.error[static_cast<std::size_t>(r)])
                                 : 0.0;
        double lower = kInfinity, lower2 = kInfinity;
        for (int i = 0; i < nx; ++i) {
          const Arc& x = xs[static_cast<std::size_t>(i)];
          lower = std::min(lower, arc_minimum(x, w, error, q.reach));
          lower2 = std::min(lower2, arc_minimum(x, w2, error, q.reach));
        }
        double arc_lower = std::max(lower + q.inradius_b, lower2);
        if (!above_bound(q, arc_lower)) {
          const Vec3 wh = q.point_a(e[0]) - q.point_b(near_hint(v));
          double lower3 = kInfinity;
          for (int i = 0; i < nx; ++i)
            lower3 =
                std::min(lower3, arc_minimum(xs[static_cast<std::size_t>(i)], wh, error, q.reach));
          arc_lower = std::max(arc_lower, lower3);
        }
        if (pruned_by(q, arc_lower, PenetrationCache::Group::edge_a, v, w_end, [&] {
              // A solid's one arc; a polygon's or a segment's half or
              // whole circle: anywhere.
              return nx == 1 ? cone_of_arc(xs[0].p, 0.0, xs[0].q, 0.0) : whole_sphere();
            }))
          continue;
      }
      for (int i = 0; i < nx; ++i) {
        const Arc& x = xs[static_cast<std::size_t>(i)];
        // The B cell of direction p: B's support along -p.
        // From the support found for a face through v, when one was
        // evaluated (for a solid A, p is the normal of such a face).
        const std::int32_t near = q.near_b == nullptr ? -1 : q.near_b[v];
        const int start = support_hill_climb_through_plateaus(q.b, q.rotation_t * (-x.p),
                                                              near >= 0 ? near : hint);
        hint = start;
        chain.clear();
        chain.push_back(start);
        visited[static_cast<std::size_t>(start)] = 1;
        for (std::size_t head = 0; head < chain.size(); ++head) {
          const int j = chain[head];
          const auto slot0 = static_cast<std::size_t>(offsets[static_cast<std::size_t>(j)]);
          const auto nbrs = q.b.neighbors(j);
          for (std::size_t slot = slot0; slot < slot0 + nbrs.size(); ++slot) {
            const std::int32_t k = nbrs[slot - slot0];
            int ny = 0;
            if (memo) {
              if (!slot_ready[slot]) {
                // Both directions of the edge at once: k -> j's slot (its
                // left face is j -> k's right one) gets the same arc read
                // backwards, (q, p, -k), what arcs_of_b gives for it.
                const auto back = static_cast<std::size_t>(
                    std::find(adjacency_b.begin() + offsets[static_cast<std::size_t>(k)],
                              adjacency_b.begin() + offsets[static_cast<std::size_t>(k) + 1], j) -
                    adjacency_b.begin());
                const int count = arcs_of_b(q, j, k, faces_b[slot], faces_b[back], ys);
                slot_ready[slot] = slot_ready[back] = count == 1 ? 1 : 2;
                slot_arc[slot] = ys[0];
                slot_arc[back] = {ys[0].q, ys[0].p, -ys[0].k, ys[0].tolerance};
              }
              ny = slot_ready[slot] == 1 ? 1 : 0;
              ys[0] = slot_arc[slot];
            } else {
              ny = arcs_of_b(q, j, k, ys);
            }
            bool crosses = false;
            for (int m = 0; m < ny && !crosses; ++m)
              crosses = arcs_may_cross(x, ys[static_cast<std::size_t>(m)]);
            if (!crosses) continue;
            // Each crossing edge once: from its first-visited end.
            if (!visited[static_cast<std::size_t>(k)]) {
              visited[static_cast<std::size_t>(k)] = 1;
              chain.push_back(k);
              add_edge_candidate(q, e[0], e[1], xs, nx, std::min(j, static_cast<int>(k)),
                                 std::max(j, static_cast<int>(k)), ys, ny, out);
            } else if (std::find(chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(head),
                                 k) == chain.begin() + static_cast<std::ptrdiff_t>(head)) {
              // k was reached from another cell of this chain, not expanded
              // yet: the edge j-k is another crossing of the arc.
              add_edge_candidate(q, e[0], e[1], xs, nx, std::min(j, static_cast<int>(k)),
                                 std::max(j, static_cast<int>(k)), ys, ny, out);
            }
          }
        }
        for (const std::int32_t j : chain) visited[static_cast<std::size_t>(j)] = 0;
      }
    }
  }
}

// The supporting region of `poly` (mapped by `point`) in direction d, from
// its support vertex v: the vertices whose value is within `tie` of v's,
// found by a walk over the adjacency (the region is connected: it is a face
// of the hull thickened by rounding), as simplices to search for witness
// points, appended to `out`: every face all of whose vertices are in the
// region (fan triangles), else every edge in it, else v. Nearly coplanar
// faces (a polygon whose doubles are not exactly planar, a coplanar
// face-face contact) are all in, so the witness is found wherever it is.
// The walk's lists live in `memory` (a buffer on the stack: six heap
// allocations were a tenth of a tracked query at N = 8).
template <class PointOf, class Out>
void support_region(const ConvexPolytope& poly, PointOf&& point, const Vec3& d, int v, double tie,
                    std::pmr::memory_resource* memory, Out& out) {
  const auto simplex = [](FeatureType type, int v0, int v1, int v2, int face) {
    Feature f;
    f.type = type;
    f.vertices = {v0, v1, v2};
    f.face = face;
    return f;
  };
  const double top = d.dot(point(v));
  const auto in = [&](int w) { return d.dot(point(w)) >= top - tie; };
  std::pmr::vector<int> region({v}, memory);
  // Bounded by the vertex count: each vertex enters once.
  for (std::size_t head = 0; head < region.size(); ++head)
    for (const std::int32_t w : poly.neighbors(region[head]))
      if (std::find(region.begin(), region.end(), w) == region.end() && in(w)) region.push_back(w);
  // A vertex, or an edge (the BFS joined its two ends along it): no face
  // has all its vertices in (what the general case below finds, without
  // evaluating the faces around it).
  if (region.size() == 1) {
    out.push_back(simplex(FeatureType::vertex, v, -1, -1, -1));
    return;
  }
  if (region.size() == 2) {
    out.push_back(simplex(FeatureType::edge, std::min(region[0], region[1]),
                          std::max(region[0], region[1]), -1, -1));
    return;
  }
  // A face's vertices are all within the tie exactly when they are all in
  // the region: its boundary runs along hull edges, so they are connected
  // to the region's vertex it was found from.
  const auto in_region = [&](int w) {
    return std::find(region.begin(), region.end(), w) != region.end();
  };
  const std::size_t first = out.size();
  std::pmr::vector<int> faces_seen(memory);
  const auto faces = poly.adjacency_faces();
  for (const int x : region) {
    const auto offset =
        static_cast<std::size_t>(poly.adjacency_offsets()[static_cast<std::size_t>(x)]);
    const auto nbrs = poly.neighbors(x);
    for (std::size_t k = 0; k < nbrs.size(); ++k) {
      const int f = faces[offset + k];
      if (f < 0 || std::find(faces_seen.begin(), faces_seen.end(), f) != faces_seen.end()) continue;
      faces_seen.push_back(f);
      const auto cycle = poly.face(f);
      bool all = true;
      for (const std::int32_t w : cycle) all = all && in_region(w);
      if (!all) continue;
      for (std::size_t i = 1; i + 1 < cycle.size(); ++i)
        out.push_back(simplex(FeatureType::face, cycle[0], cycle[i], cycle[i + 1], f));
    }
  }
  if (out.size() > first) return;
  for (const int x : region)
    for (const std::int32_t w : poly.neighbors(x))
      if (x < w && in_region(w)) out.push_back(simplex(FeatureType::edge, x, w, -1, -1));
  if (out.size() > first) return;
  out.push_back(simplex(FeatureType::vertex, v, -1, -1, -1));
}

// The supporting regions of the winning candidate: A's along its normal n,
// B's along -n, appended to `ta` and `tb`.
template <class Out>
void support_regions(const Query& q, const Candidate& best, std::pmr::memory_resource* memory,
                     Out& ta, Out& tb) {
  const double tie = kTieUlps * kUnitRoundoff;
  support_region(
      q.a, [&](int i) { return q.point_a(i); }, best.normal, best.support_a, tie, memory, ta);
  support_region(
      q.b, [&](int j) { return q.point_b(j); }, Vec3(-best.normal), best.support_b, tie, memory,
      tb);
}

// A tracking cache's regions for the winning candidate, walked again
// (out of line: its buffer is not paid for by the queries that read them).
[[gnu::noinline]] void remember_regions(const Query& q, const Candidate& best,
                                        PenetrationCache::Witnesses& memo) {
  std::array<std::byte, 1024> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  memo.id = best.id;
  memo.normal = best.normal;
  memo.a.clear();
  memo.b.clear();
  support_regions(q, best, &memory, memo.a, memo.b);
}

bool same_face(const MinkowskiFaceId& x, const MinkowskiFaceId& y) {
  return x.kind == y.kind && x.a0 == y.a0 && x.a1 == y.a1 && x.b0 == y.b0 && x.b1 == y.b1;
}

// Builds the result from the winning candidate and the supporting regions
// along its normal n: A's simplices `ta`, B's `tb`.
[[gnu::always_inline]] inline PenetrationResult finish_with_regions(
    const Query& q, const Candidate& best, double lower_scaled, int candidates, bool tracked,
    std::span<const Feature> ta, std::span<const Feature> tb) {
  PenetrationResult r;
  r.candidates = candidates;
  r.tracked = tracked;
  r.face = best.id;
  const double band = contact_band(q.magnitude);
  const Vec3& n = best.normal;
  const double value = best.value;  // scaled
  r.normal = n;
  // Witnesses: a pair of points of the supporting features that differ by
  // value * n: the closest points of feature A and feature B moved by
  // value * n (the first least pair of simplices).
  const Vec3 shift = std::max(value, 0.0) * n;
  ClosestPoints<double> closest;
  closest.point_a = closest.point_b = Vec3::Zero();
  closest.distance_squared = std::numeric_limits<double>::infinity();
  const Feature* best_ta = nullptr;
  const Feature* best_tb = nullptr;
  for (const Feature& s : ta) {
    Vec3 pa[3];
    const int na = s.vertex_count();
    for (int i = 0; i < na; ++i) pa[i] = q.point_a(s.vertices[static_cast<std::size_t>(i)]);
    for (const Feature& t : tb) {
      Vec3 pb[3];
      const int nb = t.vertex_count();
      for (int j = 0; j < nb; ++j)
        pb[j] = q.point_b(t.vertices[static_cast<std::size_t>(j)]) + shift;
      const ClosestPoints<double> c = closest_points<double>(pa, na, pb, nb);
      if (c.distance_squared < closest.distance_squared) {
        closest = c;
        best_ta = &s;
        best_tb = &t;
      }
    }
  }
  const double residual = std::sqrt(closest.distance_squared) * q.unit;
  r.point_a = closest.point_a * q.unit;
  r.point_b = (closest.point_b - shift) * q.unit;
  if (best_ta != nullptr) {
    r.feature_a = *best_ta;
    r.feature_b = *best_tb;
  }
  const double depth = value * q.unit;
  if (depth < -band || (residual > band && depth <= band)) {
    // Separated: a plane separates them (depth < 0), or the supporting
    // features along the nearest plane do not meet (a flat M whose plane
    // holds the origin outside M; solve_cold first tries the faces tied
    // with it). Not for a value above the band: then the origin is inside
    // a solid M deeper than the band (every face's value is above it),
    // and features that do not meet only mean that a face tied with this
    // one within rounding holds the witness (a sliver's nearly coplanar
    // faces: the origin's foot on this face's plane lies outside it), not
    // that the hulls are apart (PenetrationRegression.SliverWithNearlyCoplanarFaces).
    r.status = PenetrationStatus::separated;
    r.depth = r.lower_bound = r.upper_bound = 0.0;
    return r;
  }
  r.status = depth > band ? PenetrationStatus::intersecting : PenetrationStatus::touching;
  r.depth = std::max(depth, 0.0);
  r.upper_bound = r.depth;
  r.lower_bound = std::max(0.0, std::min(lower_scaled, value) * q.unit - contact_band(q.magnitude));
  return r;
}

// Builds the result from the winning candidate. `memo` (a tracking cache's,
// or null) keeps the supporting regions of the answer's direction: a
// tracked answer along the same face of A - B (same id, same normal: B
// only translated) reads them instead of walking the hulls again.
// Without a cache (cold queries): the regions on the stack, out of line so
// that the tracked path's frame does not hold their buffer.
[[gnu::noinline]] PenetrationResult finish_untracked(const Query& q, const Candidate& best,
                                                     double lower_scaled, int candidates,
                                                     bool tracked) {
  std::array<std::byte, 2048> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  std::pmr::vector<Feature> ta(&memory), tb(&memory);
  support_regions(q, best, &memory, ta, tb);
  return finish_with_regions(q, best, lower_scaled, candidates, tracked, ta, tb);
}

PenetrationResult finish(const Query& q, const Candidate& best, double lower_scaled, int candidates,
                         bool tracked, PenetrationCache::Witnesses* memo = nullptr) {
  if (memo == nullptr) return finish_untracked(q, best, lower_scaled, candidates, tracked);
  if (memo->a.empty() || !same_face(memo->id, best.id) || memo->normal != best.normal)
    remember_regions(q, best, *memo);
  return finish_with_regions(q, best, lower_scaled, candidates, tracked, memo->a, memo->b);
}

// Both hulls of dimension <= 1 with no crossing edges (points, parallel or
// collinear segments): M is a point or a segment, flat, depth 0. Touching
// when it holds the origin (the two hulls meet), else separated.
PenetrationResult finish_without_candidates(const Query& q) {
  Vec3 pa[2], pb[2];
  const int na = std::min(q.a.vertex_count(), 2), nb = std::min(q.b.vertex_count(), 2);
  for (int i = 0; i < na; ++i) pa[i] = q.point_a(i);
  for (int j = 0; j < nb; ++j) pb[j] = q.point_b(j);
  const ClosestPoints<double> c = closest_points<double>(pa, na, pb, nb);
  PenetrationResult r;
  r.point_a = c.point_a * q.unit;
  r.point_b = c.point_b * q.unit;
  r.feature_a.vertices = {0, na > 1 ? 1 : -1, -1};
  r.feature_a.type = na > 1 ? FeatureType::edge : FeatureType::vertex;
  r.feature_b.vertices = {0, nb > 1 ? 1 : -1, -1};
  r.feature_b.type = nb > 1 ? FeatureType::edge : FeatureType::vertex;
  // A normal orthogonal to M's direction (any, if M is a point).
  Vec3 along = na > 1 ? Vec3(pa[1] - pa[0]) : nb > 1 ? Vec3(pb[1] - pb[0]) : Vec3::UnitZ();
  along.normalize();
  r.normal = along.cross(std::abs(along.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY()).normalized();
  const double distance = std::sqrt(c.distance_squared) * q.unit;
  r.status = distance > contact_band(q.magnitude) ? PenetrationStatus::separated
                                                  : PenetrationStatus::touching;
  return r;
}

// The fingerprint of a pair: sizes and a few coordinates, so that a cache
// of another pair of polytopes built at the same addresses is not trusted.
std::array<double, 4> fingerprint(const ConvexPolytope& a, const ConvexPolytope& b) {
  const auto sum = [](const ConvexPolytope& p) {
    const Vec3& first = p.vertex(0);
    const Vec3& last = p.vertex(p.vertex_count() - 1);
    return first.x() + 2 * first.y() + 3 * first.z() + 5 * last.x() + 7 * last.y() + 11 * last.z();
  };
  return {static_cast<double>(a.vertex_count()) + 1e6 * a.face_count(),
          static_cast<double>(b.vertex_count()) + 1e6 * b.face_count(), sum(a), sum(b)};
}

// B's translation since the enumeration: delta = t - t_enumeration and its
// length (computed in the query's unit: no overflow, no underflow); t and
// the unit for the groups, each anchored at its own translation.
struct Moved {
  Vec3 delta;
  double length;
  Vec3 t = Vec3::Zero();
  double inverse = 1.0, unit = 1.0;
};

// The value at B's translation t of a cached face: its offset at the
// enumeration moved by -n.(t - t_enumeration), one rounding whatever the
// path.
double entry_value(const PenetrationCache::Facet& f, const Moved& m) {
  return f.enumerated_offset - f.normal.dot(m.delta);
}
// A lower bound at t on the values of a pruned group's faces: with delta
// = t - its anchor (correctly rounded: within u |delta|), each normal n has
// n.delta <= c.delta + spread |delta| (|n - c| <= spread) and <= |delta|
// (unit), plus the rounding of c.delta (|c| <= 1) and of the sums, a few
// u of |delta|.
double entry_value(const PenetrationCache::Bound& b, const Moved& m) {
  const Vec3 delta = m.t - b.anchor;
  const double length = (delta * m.inverse).norm() * m.unit;
  return b.lower - std::min(length, b.center.dot(delta) + b.spread * length) - 0x1p-44 * length;
}
const Vec3& entry_normal(const PenetrationCache::Facet& f) { return f.normal; }
const Vec3& entry_normal(const PenetrationCache::Bound& b) { return b.center; }
double entry_spread(const PenetrationCache::Bound& b) { return b.spread; }

// Fills node `at` (already allocated) over entries[begin, end) (the cached
// faces or the pruned groups): the ball around their normals (and their
// balls) and their least value at B's translation t (its anchor; `moved`
// from the enumeration to t); not split.
template <class Entry>
void make_node(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
               int at, int begin, int end, const Vec3& t, const Moved& moved) {
  const auto first = entries.begin() + begin;
  const auto last = entries.begin() + end;
  Vec3 lo = entry_normal(*first), hi = entry_normal(*first);
  double least = std::numeric_limits<double>::infinity();
  for (auto f = first; f != last; ++f) {
    lo = lo.cwiseMin(entry_normal(*f));
    hi = hi.cwiseMax(entry_normal(*f));
    least = std::min(least, entry_value(*f, moved));
  }
  const Vec3 center = 0.5 * (lo + hi);
  double radius = 0.0;
  if constexpr (std::is_same_v<Entry, PenetrationCache::Facet>) {
    double radius2 = 0.0;
    for (auto f = first; f != last; ++f)
      radius2 = std::max(radius2, (f->normal - center).squaredNorm());
    radius = std::sqrt(radius2);
  } else {
    for (auto f = first; f != last; ++f)
      radius = std::max(radius, (entry_normal(*f) - center).norm() + entry_spread(*f));
  }
  // Rounded up: the norm is within a few u of the exact one (normals are
  // unit, so |n - c| <= 2), and the query adds its own slack.
  radius = radius * (1.0 + 0x1p-48) + 0x1p-48;
  PenetrationCache::Node& node = nodes[static_cast<std::size_t>(at)];
  node.center = center;
  node.radius = radius;
  node.least_offset = least;
  node.anchor = t;
  node.begin = begin;
  node.end = end;
  node.left = -1;
}

// Splits node `at` (more than kLeaf entries, no children yet) at the
// median of its normals' coordinate of largest spread: O(its entries).
// Children come after their parent in nodes.
template <class Entry>
void split_node(std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes, int at,
                const Vec3& t, const Moved& moved) {
  const PenetrationCache::Node node = nodes[static_cast<std::size_t>(at)];
  const auto first = entries.begin() + node.begin;
  const auto last = entries.begin() + node.end;
  Vec3 lo = entry_normal(*first), hi = entry_normal(*first);
  for (auto f = first; f != last; ++f) {
    lo = lo.cwiseMin(entry_normal(*f));
    hi = hi.cwiseMax(entry_normal(*f));
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const int middle = node.begin + (node.end - node.begin) / 2;
  std::nth_element(first, entries.begin() + middle, last, [axis](const Entry& x, const Entry& y) {
    return entry_normal(x)[axis] < entry_normal(y)[axis];
  });
  const int left = static_cast<int>(nodes.size());
  nodes.resize(nodes.size() + 2);
  nodes[static_cast<std::size_t>(at)].left = left;
  make_node(entries, nodes, left, node.begin, middle, t, moved);
  make_node(entries, nodes, left + 1, middle, node.end, t, moved);
}

// The tree's root over all entries (the searches split it), anchored at
// B's translation t; their count.
template <class Entry>
std::int32_t build_tree(const std::vector<Entry>& entries,
                        std::vector<PenetrationCache::Node>& nodes, const Vec3& t,
                        const Moved& moved) {
  nodes.clear();
  if (entries.empty()) return 0;
  nodes.reserve(4 * entries.size() / PenetrationCache::kLeaf + 2);
  nodes.resize(1);
  make_node(entries, nodes, 0, 0, static_cast<int>(entries.size()), t, moved);
  return static_cast<std::int32_t>(entries.size());
}

// The forest over entries (PenetrationCache::roots): one tree over all
// when there is none (or when the nodes left behind by merges outnumber
// the live ones: a tree split to its leaves has about 2 n / kLeaf nodes).
template <class Entry>
void ensure_forest(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
                   std::vector<std::int32_t>& roots, const Vec3& t, const Moved& moved) {
  if (!roots.empty() && nodes.size() <= 8 * entries.size() / PenetrationCache::kLeaf + 256) return;
  roots.clear();
  if (build_tree(entries, nodes, t, moved) > 0) roots.push_back(0);
}

// A tree over entries[begin, end) (appended by an expansion) added to the
// forest, then merged with the tree before it (one new root over both
// runs, contiguous) while that one is at most twice as large.
template <class Entry>
void add_tree(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
              std::vector<std::int32_t>& roots, int begin, const Vec3& t, const Moved& moved) {
  const int end = static_cast<int>(entries.size());
  if (roots.empty() || begin >= end) return;  // the next search builds the whole forest
  const auto size = [&](std::int32_t r) {
    const PenetrationCache::Node& n = nodes[static_cast<std::size_t>(r)];
    return n.end - n.begin;
  };
  int first = begin;
  while (!roots.empty() && size(roots.back()) <= 2 * (end - first)) {
    first = nodes[static_cast<std::size_t>(roots.back())].begin;
    roots.pop_back();
  }
  const auto at = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  make_node(entries, nodes, at, first, end, t, moved);
  roots.push_back(at);
}

// The query's scratch memory (Query::memory) while it lives: a buffer on
// the stack, which holds an enumeration's lists up to about N = 10 (sphere
// hulls of N vertices; larger ones continue on the heap, and release it
// at the end): eight heap allocations were a tenth of a cold query at
// N = 8. On leaving, the query's pointers into it are cleared.
class ScratchScope {
 public:
  explicit ScratchScope(Query& q) : q_(q), memory_(buffer_.data(), buffer_.size()) {
    q.memory = &memory_;
  }
  ~ScratchScope() {
    q_.memory = nullptr;
    q_.near_b = nullptr;
  }
  ScratchScope(const ScratchScope&) = delete;
  ScratchScope& operator=(const ScratchScope&) = delete;

 private:
  Query& q_;
  std::array<std::byte, 8192> buffer_;
  std::pmr::monotonic_buffer_resource memory_;
};

// Refinement at the contact band. In double, a value's error is a few u
// R (the normal's rounding times the support points' magnitude), so a
// depth within a few bands of the band cannot be told above or below it:
// the status there would follow rounding (a depth 1.09 bands deep was
// called touching, PenetrationRegression.DepthJustAboveTheBandIsPenetrating).
// Answers whose least value is within kRefineBands bands of zero are
// refined: each face of A - B that can realize the depth (value within
// kRefineWindow of the least, plus its own normal's error times the
// points' magnitude for an edge pair, whose normal is ill-conditioned when
// the edges are nearly parallel) gets its value exactly (exact_offset: the
// face's normal N from its edge vectors in integers, the supports along N
// the exact best of the tie region along the rounded normal, which holds an
// exact maximizer by support_hill_climb_through_plateaus' argument), and
// the depth is the least exact value, rounded, its status decided exactly
// against 64 u R (R the largest coordinate of A's vertices and B's placed
// ones). Off the tracked path: a tracked answer there enumerates again.
constexpr double kRefineBands = 4.0;
// Twice a value's slack: the face that realizes the depth, whose exact
// value is the least, has a rounded value within it of the least rounded.
constexpr double kRefineWindow = 2.0 * kValueSlackUlps;

// Whether a value (scaled units) is within kRefineBands bands of zero.
bool near_band(const Query& q, double value) {
  return std::abs(value) <= kRefineBands * kValueSlackUlps * kUnitRoundoff * q.magnitude * q.inverse;
}

// Whether an answer is one to refine: an overlap (a separated answer's
// value is below minus the band) within kRefineBands bands of zero.
bool needs_refinement(const Query& q, const PenetrationResult& r) {
  return r.status != PenetrationStatus::separated && near_band(q, r.depth * q.inverse);
}

// The vertices of `poly` (mapped by `point`) connected to v through
// vertices whose value along d is within `tie` of v's, appended to `out`.
template <class PointOf>
void tie_region(const ConvexPolytope& poly, PointOf&& point, const Vec3& d, int v, double tie,
                std::vector<int>& ids, std::vector<Vec3>& out) {
  const double top = d.dot(point(v));
  ids.assign(1, v);
  for (std::size_t head = 0; head < ids.size(); ++head)
    for (const std::int32_t w : poly.neighbors(ids[head]))
      if (std::find(ids.begin(), ids.end(), w) == ids.end() && d.dot(point(w)) >= top - tie)
        ids.push_back(w);
  out.clear();
  for (const int i : ids) out.push_back(point(i));
}

// The exact value of candidate c (scaled units) against c_band, or
// nothing for a candidate that is not a named face of A - B.
std::optional<detail::ExactOffset> exact_value(const Query& q, const Candidate& c, double c_band) {
  const MinkowskiFaceId& id = c.id;
  Vec3 u0, u1, w0, w1;
  // The normal's angle error (of the rounded normal from the exact one).
  double angle = 0.0;
  if (id.kind == MinkowskiFace::face_vertex && id.a0 >= 0) {
    const auto cycle = q.a.face(id.a0);
    u0 = w0 = q.point_a(cycle[0]);
    u1 = q.point_a(cycle[1]);
    w1 = q.point_a(cycle[2]);
    angle = 16.0 * (static_cast<double>(cycle.size()) + 1.0) * kUnitRoundoff;
  } else if (id.kind == MinkowskiFace::vertex_face && id.b0 >= 0) {
    const auto cycle = q.b.face(id.b0);
    u0 = w0 = q.point_b(cycle[0]);
    u1 = q.point_b(cycle[1]);
    w1 = q.point_b(cycle[2]);
    angle = (16.0 * (static_cast<double>(cycle.size()) + 1.0) + 8.0) * kUnitRoundoff;
  } else if (id.kind == MinkowskiFace::edge_edge && id.a0 >= 0 && id.b0 >= 0) {
    u0 = q.point_a(id.a0);
    u1 = q.point_a(id.a1);
    w0 = q.point_b(id.b0);
    w1 = q.point_b(id.b1);
    const Vec3 ea = detail::exponent_free(u1 - u0), eb = detail::exponent_free(w1 - w0);
    const double cross = ea.cross(eb).norm();
    if (!(cross > 0.0)) return std::nullopt;
    angle = (8.0 * ea.norm() * eb.norm() / cross + 4.0) * kUnitRoundoff;
  } else {
    return std::nullopt;
  }
  // N along the rounded normal: (u1 - u0) x (w1 - w0), or with the edges
  // swapped its negative.
  if ((u1 - u0).cross(w1 - w0).dot(c.normal) < 0.0) {
    std::swap(u0, w0);
    std::swap(u1, w1);
  }
  // Rounded values along c.normal are within (angle + 4 u) |x| of the
  // exact ones along N / |N| (|x| <= 2 in scaled units): twice that is the
  // tie that keeps an exact maximizer in the region.
  const double tie = 2.0 * (angle + 4.0 * kUnitRoundoff) * 2.0;
  std::vector<int> ids;
  std::vector<Vec3> xs, ys;
  tie_region(
      q.a, [&](int i) { return q.point_a(i); }, c.normal, c.support_a, tie, ids, xs);
  tie_region(
      q.b, [&](int j) { return q.point_b(j); }, Vec3(-c.normal), c.support_b, tie, ids, ys);
  const detail::ExactOffset e = detail::exact_offset(u0, u1, w0, w1, xs, ys, c_band);
  if (e.degenerate) return std::nullopt;
  return e;
}

// The largest coordinate of A's vertices and B's placed ones (scaled):
// the R of the standard in A's frame.
double frame_magnitude(const Query& q) {
  double r = 0.0;
  for (int i = 0; i < q.a.vertex_count(); ++i) r = std::max(r, q.point_a(i).cwiseAbs().maxCoeff());
  for (int j = 0; j < q.b.vertex_count(); ++j) r = std::max(r, q.point_b(j).cwiseAbs().maxCoeff());
  return r;
}

// Refines an answer near the band (see kRefineBands): `r` from `best`
// among `candidates`. The least exact value's candidate gives the answer,
// its status exact against the band of the frame's R.
PenetrationResult refine(const Query& q, std::span<const Candidate> candidates,
                         const Candidate& best, const PenetrationResult& r, int count) {
  const double band_scaled = contact_band(frame_magnitude(q));
  const double reach = 2.0;
  const Candidate* winner = nullptr;
  double least = kInfinity;
  bool touching = false;
  for (const Candidate& c : candidates) {
    // The window, widened by an edge pair's normal error times the points'
    // magnitude (exact_value's angle, recomputed cheaply here).
    double widen = 0.0;
    if (c.id.kind == MinkowskiFace::edge_edge && c.id.a0 >= 0 && c.id.b0 >= 0) {
      const Vec3 ea = detail::exponent_free(q.point_a(c.id.a1) - q.point_a(c.id.a0));
      const Vec3 eb = detail::exponent_free(q.point_b(c.id.b1) - q.point_b(c.id.b0));
      const double cross = ea.cross(eb).norm();
      widen = cross > 0.0 ? 8.0 * ea.norm() * eb.norm() / cross * kUnitRoundoff * reach : kInfinity;
    }
    if (!(c.value <= best.value + kRefineWindow * kUnitRoundoff + widen)) continue;
    const std::optional<detail::ExactOffset> e = exact_value(q, c, band_scaled);
    if (!e) continue;
    touching = touching || e->versus <= 0;
    if (e->offset < least) {
      least = e->offset;
      winner = &c;
    }
  }
  if (winner == nullptr) return r;
  Candidate refined = *winner;
  refined.value = least;
  PenetrationResult out = finish(q, refined, least, count, false);
  if (out.status == PenetrationStatus::separated) return out;
  // The exact value is within 4 u of `least`; the bounds say so.
  const double depth = std::max(least, 0.0) * q.unit;
  out.status = touching ? PenetrationStatus::touching : PenetrationStatus::intersecting;
  out.depth = depth;
  out.upper_bound = depth * (1.0 + 8.0 * kUnitRoundoff);
  out.lower_bound = depth * (1.0 - 8.0 * kUnitRoundoff);
  return out;
}

// The faces of A - B whose values are within this many u (scaled units)
// of the least are tried for witnesses that meet when the least one's do
// not (solve_cold): twice the slack of a value (kValueSlackUlps), so that
// the face that holds the origin's foot, whose exact value is the least,
// is among them. Pinned by PenetrationRegression.SliverWithNearlyCoplanarFaces.
constexpr double kWitnessWindow = 2.0 * kValueSlackUlps;

// Whether an answer's witnesses realize its depth: point_b + depth * normal
// within the contact band of point_a (a separated answer's do not).
bool witnesses_meet(const Query& q, const PenetrationResult& r) {
  if (r.status == PenetrationStatus::separated) return false;
  return (r.point_b + r.depth * r.normal - r.point_a).norm() <= contact_band(q.magnitude);
}

// `record`: keep the pruned groups in cache->bounds (PenetrationCache).
PenetrationResult solve_cold(Query& q, bool walk, PenetrationCache* cache, const Pose& b_in_a,
                             const PenetrationCache::Facet* start, bool record) {
  ScratchScope scratch(q);
  PenetrationCache::Shapes local;
  q.use_shapes(cache != nullptr ? cache->shapes : local, walk);
  if (cache != nullptr) {
    // Filled by this enumeration; until the cache is written below, the
    // last one's faces are certified by the scalar `pruned` alone.
    cache->bounds.clear();
    cache->bound_nodes.clear();
    cache->bound_roots.clear();
    cache->expanded = 0;
    cache->bounded = false;
    if (record) q.bounds_out = &cache->bounds;
  }
  Candidate first;
  if (walk) {
    // The first upper bound: the last answer's direction (a rotated B), or
    // the direction from A's centroid to B's.
    q.prune = true;
    if (cache != nullptr) q.prune_margin = cache->prune_margin * q.inverse;
    Vec3 d = start != nullptr ? start->normal : Vec3(q.centroid_b - q.centroid_a);
    if (!(d.squaredNorm() > 0x1p-400)) d = Vec3::UnitZ();
    d.normalize();
    first = evaluate(q, {}, d, start != nullptr ? start->support_a : -1,
                     start != nullptr ? start->support_b : -1);
    q.bound = first.value;
    q.set_references(first.support_a, first.support_b);
  }
  Candidates candidates(q.memory);
  // Every face and crossing for the slow twin; a pruned walk keeps a few
  // hundred at most on the benchmarks' spheres (reserving for all of them,
  // megabytes at N = 4096, would cost an mmap and its page faults per cold
  // query).
  const auto all = static_cast<std::size_t>(q.a.face_count() + q.b.face_count() +
                                            2 * (q.a.vertex_count() + q.b.vertex_count()));
  candidates.reserve(walk ? std::min<std::size_t>(all, 512) : all);
  add_face_candidates(q, candidates);
  if (walk)
    add_edge_candidates_walk(q, candidates);
  else
    add_edge_candidates_brute_force(q, candidates);
  // The first direction is an upper bound too (and, when every face was
  // pruned below it, a separating direction: the bodies are apart). Last,
  // so that a face of A - B wins a tie. Its id has no hull ids (-1).
  if (candidates.empty()) {
    // No face of A - B: flat (points, segments), or all pruned below a
    // separating first direction.
    if (walk && first.value < 0.0) return finish(q, first, first.value, 0, false);
    return finish_without_candidates(q);
  }
  if (walk) candidates.push_back(first);
  const int count = static_cast<int>(candidates.size());
  const auto best =
      std::min_element(candidates.begin(), candidates.end(),
                       [](const Candidate& x, const Candidate& y) { return x.value < y.value; });
  PenetrationResult r = finish(q, *best, best->value, count, false);
  if (!witnesses_meet(q, r) && !(best->value < -kValueSlackUlps * kUnitRoundoff)) {
    // The least value's features do not meet: a flat M whose plane holds
    // the origin outside M, or a face tied with the least within rounding
    // (nearly coplanar faces of A - B) holds the origin's foot. The faces
    // within kWitnessWindow of the least are tried, least first; the first
    // whose features meet gives the answer (its value is the depth within
    // the window).
    const double window = best->value + kWitnessWindow * kUnitRoundoff;
    const Candidate* tried = &*best;
    for (;;) {
      const Candidate* next = nullptr;
      for (const Candidate& c : candidates)
        if (c.value <= window && c.value >= tried->value && &c != tried &&
            (c.value > tried->value || &c > tried) &&
            (next == nullptr || c.value < next->value ||
             (c.value == next->value && &c < next)))
          next = &c;
      if (next == nullptr) break;
      const PenetrationResult alt = finish(q, *next, best->value, count, false);
      tried = next;
      if (witnesses_meet(q, alt)) {
        r = alt;
        break;
      }
    }
  }
  if (needs_refinement(q, r))
    r = refine(q, std::span<const Candidate>(candidates.data(), candidates.size()), *best, r, count);
  if (cache != nullptr) {
    cache->a = &q.a;
    cache->b = &q.b;
    cache->fingerprint = fingerprint(q.a, q.b);
    cache->rotation = b_in_a.rotation;
    cache->facets.resize(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
      cache->facets[i] = {candidates[i].id, candidates[i].normal, candidates[i].value * q.unit,
                          candidates[i].support_a, candidates[i].support_b};
    cache->enumerated_translation = b_in_a.translation;
    cache->pruned = q.pruned * q.unit;
    cache->bounded = record;
    cache->expanded = 0;
    ++cache->enumerations;
    // B's rotation may have changed: its supporting features with it.
    cache->witnesses.a.clear();
    cache->witnesses.b.clear();
    // The trees are built by the first tracked query (a rotating B, which
    // enumerates every query, never pays for it); until then `last` is the
    // answer's face.
    cache->nodes.clear();
    cache->roots.clear();
    cache->last = cache->facets[static_cast<std::size_t>(best - candidates.begin())];
  }
  return r;
}

// A translation-only tracked query: the least of the cached faces' values
// at B's translation t (facet_value), by branch and bound on the tree
// (PenetrationCache::Node), starting from the last answer's face. A node's
// bound at t: its least value at its anchor less the most any of its
// normals can gain, c.delta + rho |delta| and at most |delta| (delta = t -
// anchor), rounded up; it is skipped when that is at least the best value
// found: every face skipped has a value at least the best (up to the
// rounding of the values themselves, which the certificate's slack
// covers). A node the search enters is re-anchored at t: a leaf with the
// least of its faces' values, an inner node with the lesser of its
// children's bounds at t (each a lower bound there), so the nodes near the
// answer stay tight however far B goes, and the ones far from it, never
// entered, keep their anchors (their bounds loosen by at most the distance
// moved, and only one node's gain per level of the tree is ever chained).
// A node not split yet is split when the search enters it.
// The same search over the pruned groups (PenetrationCache::Bound), from
// the faces' best value, finds whether any group's bound is below it; with
// `found` set, it collects every entry below `best` instead (best fixed).
template <class Entry>
struct TreeSearch {
  std::vector<Entry>& entries;
  std::vector<PenetrationCache::Node>& nodes;
  Vec3 t;                            // B's translation
  Moved moved;                       // from the enumeration to t
  double inverse = 1.0, unit = 1.0;  // the query's power-of-two unit
  double best = 0.0;
  Entry winner;
  int work = 0;
  std::vector<int>* found = nullptr;

  // A lower bound at t on the values of the faces under node `at` (its
  // bound, or after entering it the least found).
  double bound(const PenetrationCache::Node& node) const {
    const Vec3 delta = t - node.anchor;
    const double length = (delta * inverse).norm() * unit;
    // Rounding of c.delta (|c| <= 1) and of the sum: a few u of |delta|.
    const double gain = std::min(length, node.center.dot(delta) + node.radius * length);
    return node.least_offset - gain - 0x1p-44 * length;
  }

  double visit(int at, double node_bound) {
    ++work;
    if (!(node_bound < best)) return node_bound;
    {
      const PenetrationCache::Node& node = nodes[static_cast<std::size_t>(at)];
      if (node.left < 0 && node.end - node.begin > PenetrationCache::kLeaf)
        split_node(entries, nodes, at, t, moved);
    }
    // A copy: splitting below appends to nodes.
    const PenetrationCache::Node node = nodes[static_cast<std::size_t>(at)];
    double least = std::numeric_limits<double>::infinity();
    if (node.left < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const Entry& f = entries[static_cast<std::size_t>(i)];
        const double value = entry_value(f, moved);
        ++work;
        least = std::min(least, value);
        if (value < best) {
          if (found != nullptr) {
            found->push_back(i);
          } else {
            best = value;
            winner = f;
          }
        }
      }
    } else {
      const int l = node.left;
      const double bl = bound(nodes[static_cast<std::size_t>(l)]);
      const double br = bound(nodes[static_cast<std::size_t>(l) + 1]);
      // The nearer child first.
      if (bl <= br) {
        least = visit(l, bl);
        least = std::min(least, visit(l + 1, br));
      } else {
        least = visit(l + 1, br);
        least = std::min(least, visit(l, bl));
      }
    }
    PenetrationCache::Node& stored = nodes[static_cast<std::size_t>(at)];
    stored.least_offset = least;
    stored.anchor = t;
    return least;
  }
};

// At most this many cached faces are searched one by one, without their
// tree: a few dozen faces are scanned faster than the tree is walked, a
// few hundred are not (bench/penetration_peers' sweep with a warm cache).
constexpr std::size_t kScanFacets = 64;

// B's translation since the enumeration, for the cached faces and groups.
Moved moved_since(const Query& q, const PenetrationCache& cache, const Pose& b_in_a) {
  const Vec3 delta = b_in_a.translation - cache.enumerated_translation;
  return {delta, (delta * q.inverse).norm() * q.unit, b_in_a.translation, q.inverse, q.unit};
}

// The tracked query (a cache of this pair at B's rotation): the least of
// the cached faces' values, certified against the pruned ones. True with
// the answer in `out`; false when a pruned group may be nearer now (then
// `best` is the least cached value, `cache.last` its face). `extra`: work
// of an expansion before it, counted in the answer's candidates.
bool track(Query& q, PenetrationCache& cache, const Pose& b_in_a, PenetrationResult& out,
           double& best_out, int extra = 0) {
  // M is the reference's M translated by -(t - t_ref): the cached facets
  // are all of its facets but the pruned ones, each offset moved by
  // -n.(t - t_ref).
  const double slack = kValueSlackUlps * kUnitRoundoff * q.magnitude;
  const Moved moved = moved_since(q, cache, b_in_a);
  const bool scan = cache.facets.size() <= kScanFacets;
  if (!scan) ensure_forest(cache.facets, cache.nodes, cache.roots, b_in_a.translation, moved);
  TreeSearch<PenetrationCache::Facet> search{cache.facets,
                                             cache.nodes,
                                             b_in_a.translation,
                                             moved,
                                             q.inverse,
                                             q.unit,
                                             entry_value(cache.last, moved),
                                             cache.last,
                                             1};
  if (scan) {
    for (const PenetrationCache::Facet& g : cache.facets) {
      const double value = entry_value(g, moved);
      if (value < search.best) {
        search.best = value;
        search.winner = g;
      }
    }
    search.work += static_cast<int>(cache.facets.size());
  } else {
    for (const std::int32_t r : cache.roots)
      search.visit(r, search.bound(cache.nodes[static_cast<std::size_t>(r)]));
  }
  const double best = search.best;
  const PenetrationCache::Facet& f = search.winner;
  int work = search.work + extra;
  cache.last = f;
  best_out = best;
  // The pruned faces: no group's bound below the best (searched on their
  // forest), or when they were not recorded, their least bound at the
  // enumeration less the distance moved since.
  bool certified = false;
  if (!cache.bounded) {
    certified = best <= cache.pruned - moved.length;
  } else {
    ensure_forest(cache.bounds, cache.bound_nodes, cache.bound_roots, b_in_a.translation, moved);
    TreeSearch<PenetrationCache::Bound> check{
        cache.bounds, cache.bound_nodes, b_in_a.translation, moved, q.inverse, q.unit, best, {}, 0};
    for (std::size_t k = 0; k < cache.bound_roots.size() && !(check.best < best); ++k) {
      const std::int32_t r = cache.bound_roots[k];
      check.visit(r, check.bound(cache.bound_nodes[static_cast<std::size_t>(r)]));
    }
    certified = !(check.best < best);
    work += check.work;
  }
  if (!certified) return false;
  // The winner's value with its true supports: the cached ones, which a
  // translation does not move (hill climbing along the same normal, with
  // B's rotation the same bits, from them stays at them: they were found by
  // it, and it moves only to a strictly larger value).
  Candidate c;
  c.id = f.id;
  c.normal = f.normal;
  c.support_a = f.support_a;
  c.support_b = f.support_b;
  c.value = f.normal.dot(q.point_a(f.support_a) - q.point_b(f.support_b));
  out = finish(q, c, (best - slack) * q.inverse, work, true, &cache.witnesses);
  return true;
}

// The margin of an expansion or of an enumeration after a translation
// outgrew the cache (PenetrationCache::prune_margin): twice the last one,
// at least this many of B's last steps and a small fraction of the bodies'
// radii, at most half of them (a B that jumps keeps pruning). A margin of
// a few steps that does not grow is outgrown again and again when B nears
// A's centre, where all the faces of A - B are near the best value: each
// expansion then reopens hundreds to thousands of groups whose bounds had
// just passed it. Doubling, from 32 steps, keeps those expansions rare
// (bench/penetration_peers' sweep, B through A and back).
constexpr double kMarginSteps = 32.0;

double translation_margin(const ConvexPolytope& a, const ConvexPolytope& b,
                          const PenetrationCache& cache, const Pose& b_in_a) {
  const double radii = a.bounding_radius() + b.bounding_radius();
  const double step = (b_in_a.translation - cache.previous_translation).norm();
  return std::min(std::max({2.0 * cache.prune_margin, kMarginSteps * step, 0x1p-10 * radii}),
                  0.5 * radii);
}

// Expands the pruned groups whose bound at B's translation is below `best`
// (the least cached value) plus `margin`: each is enumerated alone at this
// pose, by the enumeration's own loops (Query::only), pruned against the
// best value with the margin, its faces added to the cache (their offsets
// moved back to the enumeration's translation: value + n.(t -
// t_enumeration), as a cached face's) and its own pruned groups recorded,
// anchored here; the group itself is dropped (lower +infinity). Then every
// group's bound is at least the best value again, up to the faces found.
// An expansion costs at most what an enumeration would (it tests the
// groups it expands, the enumeration all of them, and evaluates no face
// twice), so it is never refused; the false return (nothing changed) is
// for no group below the threshold. The work (faces evaluated) in
// `work`.
bool expand(Query& q, PenetrationCache& cache, const Pose& b_in_a, double best, double margin,
            int& work) {
  const Moved moved = moved_since(q, cache, b_in_a);
  const double threshold = best + margin;
  std::vector<int> failing;
  ensure_forest(cache.bounds, cache.bound_nodes, cache.bound_roots, b_in_a.translation, moved);
  TreeSearch<PenetrationCache::Bound> collect{cache.bounds,
                                              cache.bound_nodes,
                                              b_in_a.translation,
                                              moved,
                                              q.inverse,
                                              q.unit,
                                              threshold,
                                              {},
                                              0,
                                              &failing};
  for (const std::int32_t r : cache.bound_roots)
    collect.visit(r, collect.bound(cache.bound_nodes[static_cast<std::size_t>(r)]));
  if (failing.empty()) return false;
  Subset subset;
  for (const int i : failing) {
    PenetrationCache::Bound& g = cache.bounds[static_cast<std::size_t>(i)];
    switch (g.kind) {
      case PenetrationCache::Group::face_a:
        subset.faces_a.push_back(g.i);
        break;
      case PenetrationCache::Group::face_b:
        subset.faces_b.push_back(g.i);
        break;
      case PenetrationCache::Group::vertex_a:
        subset.edges_a.push_back({g.i, -1});
        break;
      case PenetrationCache::Group::edge_a:
        subset.edges_a.push_back({g.i, g.j});
        break;
    }
    g.lower = kInfinity;
  }
  // In the enumeration's order (its hints for the other hull's supports
  // follow neighbouring faces).
  std::sort(subset.faces_a.begin(), subset.faces_a.end());
  std::sort(subset.faces_b.begin(), subset.faces_b.end());
  std::sort(subset.edges_a.begin(), subset.edges_a.end());
  cache.expanded += static_cast<std::int32_t>(failing.size());
  std::vector<PenetrationCache::Bound> fresh;
  // The enumeration's loops keep their lists in the query's scratch memory.
  ScratchScope scratch(q);
  q.use_shapes(cache.shapes, true);
  q.prune = true;
  q.bound = best * q.inverse;
  q.set_references(cache.last.support_a, cache.last.support_b);
  q.prune_margin = margin * q.inverse;
  q.bounds_out = &fresh;
  q.only = &subset;
  Candidates found(q.memory);
  add_face_candidates(q, found);
  if (!subset.edges_a.empty()) add_edge_candidates_walk(q, found);
  q.only = nullptr;
  q.bounds_out = nullptr;
  const Vec3 since = b_in_a.translation - cache.enumerated_translation;
  const int old_facets = static_cast<int>(cache.facets.size());
  const int old_bounds = static_cast<int>(cache.bounds.size());
  for (const Candidate& c : found)
    cache.facets.push_back(
        {c.id, c.normal, c.value * q.unit + c.normal.dot(since), c.support_a, c.support_b});
  cache.bounds.insert(cache.bounds.end(), fresh.begin(), fresh.end());
  work = static_cast<int>(found.size());
  ++cache.expansions;
  // The new entries get trees of their own in the forests; the groups are
  // compacted (and their forest built again by the next search) when the
  // expanded ones are half of them.
  add_tree(cache.facets, cache.nodes, cache.roots, old_facets, b_in_a.translation, moved);
  if (2 * static_cast<std::size_t>(cache.expanded) > cache.bounds.size()) {
    std::erase_if(cache.bounds,
                  [](const PenetrationCache::Bound& g) { return g.lower == kInfinity; });
    cache.expanded = 0;
    cache.bound_nodes.clear();
    cache.bound_roots.clear();
  } else {
    add_tree(cache.bounds, cache.bound_nodes, cache.bound_roots, old_bounds, b_in_a.translation,
             moved);
  }
  return true;
}

// The tracked query, expanding the pruned groups a translation reached
// (at most twice: the second search certifies unless rounding decided a
// group at the threshold). False when the cache needs an enumeration: the
// groups were not recorded (or two expansions did not certify); then
// `margin` is the one to enumerate with.
bool track_or_expand(Query& q, PenetrationCache& cache, const Pose& b_in_a, PenetrationResult& out,
                     double& margin) {
  double best = 0.0;
  if (track(q, cache, b_in_a, out, best)) return true;
  margin = translation_margin(q.a, q.b, cache, b_in_a);
  cache.prune_margin = margin;
  if (!cache.bounded) return false;
  int work = 0;
  for (int round = 0; round < 2; ++round) {
    int more = 0;
    if (!expand(q, cache, b_in_a, best, margin, more)) return false;
    work += more;
    if (track(q, cache, b_in_a, out, best, work)) return true;
  }
  return false;
}

bool same_pair(const PenetrationCache& cache, const ConvexPolytope& a, const ConvexPolytope& b) {
  return cache.a == &a && cache.b == &b && cache.fingerprint == fingerprint(a, b);
}

PenetrationResult depth(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                        PenetrationCache& cache) {
  Query q(a, b, b_in_a);
  const bool same_polytopes = same_pair(cache, a, b);
  if (!same_polytopes) {
    cache.reset();
  } else if (!cache.facets.empty() && cache.rotation == b_in_a.rotation) {
    PenetrationResult r;
    double margin = 0.0;
    // Else the pruned faces were not recorded, or too many are nearer now:
    // enumerate again, keeping the faces within the margin (track_or_expand
    // set cache.prune_margin to it).
    // An answer near the band is refined by an enumeration (kRefineBands).
    if (track_or_expand(q, cache, b_in_a, r, margin) && !needs_refinement(q, r)) return r;
  }
  // Enumerate, pruned by the last answer's direction when there is one. A
  // rotated B halves the margin (rotating bodies enumerate every query:
  // the fewer faces kept, the faster). The pruned groups are recorded only
  // when the cache's own faces were outgrown by a translation (the next
  // query is likely a translation again): not for a rotated B (likely
  // rotated again) nor for a cold cache (a caller that queries cold every
  // time would pay for tens of thousands of groups at N = 4096 and never
  // use them, bench/penetration_bench's Cold), whose first tracked
  // query certifies with their least bound, as an unrecorded cache does.
  const bool has_start = same_polytopes && !cache.facets.empty();
  const bool turned = has_start && cache.rotation != b_in_a.rotation;
  if (turned) cache.prune_margin *= 0.5;
  const PenetrationCache::Facet start = has_start ? cache.last : PenetrationCache::Facet{};
  return solve_cold(q, true, &cache, b_in_a, has_start ? &start : nullptr, has_start && !turned);
}

}  // namespace

PenetrationResult penetration_depth_brute_force(const ConvexPolytope& a, const ConvexPolytope& b,
                                                const Pose& b_in_a) {
  Query q(a, b, b_in_a);
  return solve_cold(q, false, nullptr, b_in_a, nullptr, false);
}

PenetrationResult penetration_depth(const ConvexPolytope& a, const ConvexPolytope& b,
                                    const Pose& b_in_a, PenetrationCache& cache) {
  PenetrationResult r = depth(a, b, b_in_a, cache);
  cache.last_status = r.status;
  cache.previous_translation = b_in_a.translation;
  return r;
}

bool penetration_depth_tracked(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                               PenetrationCache& cache, PenetrationResult& out) {
  if (cache.facets.empty() || !same_pair(cache, a, b) || cache.rotation != b_in_a.rotation)
    return false;
  Query q(a, b, b_in_a);
  double margin = 0.0;
  // Near the band the answer needs an enumeration (kRefineBands): not
  // certified here.
  const bool certified =
      track_or_expand(q, cache, b_in_a, out, margin) && !needs_refinement(q, out);
  cache.previous_translation = b_in_a.translation;
  if (!certified) return false;
  cache.last_status = out.status;
  return true;
}

}  // namespace proxima
