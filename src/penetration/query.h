// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the query in scaled units (Query), the tolerances every part shares, and the query's scratch memory.
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <memory_resource>
#include <vector>
#include "core/power_of_two.h"
#include "proxima/detail/penetration/penetration.h"

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

// The fast face normals (HullNormals, fast_normals): a fan triangle's edges
// p, q of at least 2^-450 (their squares 2^-900 and above: no subnormal
// rounding in p2 or q2), and |p x q| >= 2^-10 |p||q| (a sine above 2^-10,
// compared as squares: no square root), since the normal's error bound
// grows as |p||q| / |p x q|; other faces take face_plane's exact normal.
constexpr double kMinFastEdgeSquared = 0x1p-900;
constexpr double kMinFastSineSquared = 0x1p-20;

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
        if (std::min(p2, q2) > kMinFastEdgeSquared && c2 >= kMinFastSineSquared * (p2 * q2)) {
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

}  // namespace
}  // namespace proxima
