// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the distance between two triangle meshes (mesh.h). A branch
// and bound over pairs of hierarchy nodes with a running upper bound (the
// best triangle pair so far), the triangle-triangle kernel at the leaves,
// the status from exact predicates, and tracking through MeshCache.
//
// Everything runs in A's frame on copies scaled by 2^-e, e the exponent of
// the query's magnitude R: a squared distance of meshes at 1e300 (or 1e-300)
// neither overflows nor underflows, and the scaling is exact.
#include "proxima/query/mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/accuracy.h"
#include "core/power_of_two.h"
#include "geometry/triangle_distance.h"
#include "proxima/detail/geometry/exact_predicates.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"

namespace proxima {
namespace {

using detail::magnitude_exponent;
using detail::times_pow2;

// The slack of a node pair's lower bound is detail::prune_slack of the
// query's magnitude, in the scaled frame (core/accuracy.h): the box corners
// are a float decoded by a power of two (exact) and a rotation plus
// translation away (a few u each), the gaps a few sums and one square root.

// The kernel's own error (rounded points of rounded transformed vertices):
// a few u R. The reported lower bound is the distance minus this.
constexpr double kLowerBoundUlps = 32.0;

// Tracking: the candidate list is collected with a margin of this many
// times the last step's motion, so that it serves about as many more steps
// of the same speed before the next collection.
constexpr double kMarginSteps = 8.0;
// No list when that margin exceeds this fraction of B's bounding radius: the
// poses are then unrelated, and a wide margin would only slow the search.
constexpr double kMarginRadiusFraction = 0.25;
// The most candidate pairs a cache keeps; beyond, no list (a cold search
// with the last pair as upper bound). Bounds the cache's size and the
// tracked query's cost.
constexpr std::size_t kNearCapacity = 256;

struct Query {
  const TriangleMesh& a;
  const TriangleMesh& b;
  Mat3 rotation;       // B's pose in A's frame
  Vec3 translation;    // unscaled
  Vec3 translation_s;  // scaled
  double factor = 1;   // 2^-e
  int exponent = 0;
  double magnitude = 0;                   // R (unscaled)
  double band_s = 0;                      // the contact band, scaled
  double box_unit_a = 1, box_unit_b = 1;  // box floats -> scaled units
  Mat3 abs_rotation;
  KernelTolerance<double> tol;
  Pose pose_a, pose_b;  // the world poses, checked
  // A unit direction n from A towards B (the hulls' normal) that bounds
  // every node pair by the gap of their projections on n (slab_gap), when
  // `slab`: n in A's frame and in B's, and n . translation_s.
  bool slab = false;
  Vec3 n_a = Vec3::Zero(), abs_n_a = Vec3::Zero();
  Vec3 n_b = Vec3::Zero(), abs_n_b = Vec3::Zero();
  double n_offset = 0.0;

  // Aim the slab bound along `direction` (A's frame, any length > 0).
  void set_slab(const Vec3& direction) {
    const double length = direction.norm();
    if (!(length > 0.0) || !std::isfinite(length)) return;
    n_a = direction / length;
    abs_n_a = n_a.cwiseAbs();
    n_b = rotation.transpose() * n_a;
    abs_n_b = n_b.cwiseAbs();
    n_offset = n_a.dot(translation_s);
    slab = true;
  }

  Vec3 a_vertex(std::uint32_t v) const { return a.vertex(static_cast<int>(v)) * factor; }
  Vec3 b_vertex(std::uint32_t v) const {
    return rotation * (b.vertex(static_cast<int>(v)) * factor) + translation_s;
  }
};

Query make_query(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                 const Pose& pose_b, const DistanceOptions& options) {
  const Pose pa = checked_pose(pose_a, "mesh distance: pose_a");
  const Pose pb = checked_pose(pose_b, "mesh distance: pose_b");
  detail::check_distance_options(options, "mesh distance: options");
  const Pose rel = pa.inverse() * pb;
  Query q{a, b, rel.rotation, rel.translation, {}, 1.0, 0, 0.0, 0.0, 1.0, 1.0, {}, {}, {}, {}};
  q.magnitude = std::max({magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale()), a.scale(),
                          magnitude_bound(rel, b.scale())});
  q.exponent = detail::clamped_magnitude_exponent(q.magnitude);
  q.factor = std::ldexp(1.0, -q.exponent);
  q.translation_s = times_pow2(rel.translation, -q.exponent);
  q.band_s = contact_band(std::ldexp(q.magnitude, -q.exponent),
                          std::ldexp(options.absolute_tolerance, -q.exponent));
  q.box_unit_a = std::ldexp(1.0, magnitude_exponent(a.unit()) - 1 - q.exponent);
  q.box_unit_b = std::ldexp(1.0, magnitude_exponent(b.unit()) - 1 - q.exponent);
  q.abs_rotation = rel.rotation.cwiseAbs();
  q.tol = kernel_tolerance(std::ldexp(q.magnitude, -q.exponent));
  q.pose_a = pa;
  q.pose_b = pb;
  return q;
}

// A node's box as center and half extents, scaled units of the query.
struct Box {
  Vec3 center;
  Vec3 half;
};
Box node_box(const TriangleMesh::Node& n, double unit) {
  const Vec3 lo(n.lo[0], n.lo[1], n.lo[2]);
  const Vec3 hi(n.hi[0], n.hi[1], n.hi[2]);
  return {0.5 * (lo + hi) * unit, 0.5 * (hi - lo) * unit};
}

// Squared lower bound on the distance between box a (A's frame) and box b
// (B's frame, placed by the query's rotation and translation). Each
// coordinate of x - y along an orthonormal basis is at least the gap of the
// two boxes' projections on that axis, so |x - y|^2 >= the sum of the
// squared gaps along A's three axes, and likewise along B's: the larger of
// the two sums. Exact for aligned boxes (R = I), never above the true
// distance.
//
// Both orders below compute the same two sums; each starts with the axes
// whose other box is already placed (shared by the two children of a split)
// and stops when that sum alone prunes.
double sum_of_squared_gaps(const Vec3& d, const Vec3& half, const Vec3& extent) {
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double g = std::abs(d[i]) - half[i] - extent[i];
    if (g > 0.0) sum += g * g;
  }
  return sum;
}

// The squared gap of box a's and box b's projections on the query's slab
// direction n (0 without one): |x - y| >= n . (y - x) >= min over b of
// n . y - max over a of n . x for any unit n, and a box's extreme
// projection is its center's plus or minus its half extents against |n|.
// Along the hulls' normal it prunes every node farther than the best
// pair's excess over the hulls' distance from the hulls' supporting
// planes: the search keeps to the thin slabs where the closest pair can
// be. Its rounding (a few u of the scaled magnitudes, n unit within a few
// u) is far below the prune slack.
double squared_slab_gap(const Query& q, const Box& a, const Box& b) {
  if (!q.slab) return 0.0;
  const double a_max = a.center.dot(q.n_a) + a.half.dot(q.abs_n_a);
  const double b_min = b.center.dot(q.n_b) + q.n_offset - b.half.dot(q.abs_n_b);
  const double gap = b_min - a_max;
  return gap > 0.0 ? gap * gap : 0.0;
}

// a: A's child box; b: B's box, whose center and extents in A's frame are
// cb and extent_b.
double lower_bound_on_a_axes(const Query& q, const Box& a, const Box& b, const Vec3& cb,
                             const Vec3& extent_b, double prune2) {
  const double slab = squared_slab_gap(q, a, b);
  if (slab > prune2) return slab;
  const Vec3 d = a.center - cb;
  const double sa = std::max(slab, sum_of_squared_gaps(d, a.half, extent_b));
  if (sa > prune2) return sa;
  const Vec3 db = q.rotation.transpose() * d;
  return std::max(sa, sum_of_squared_gaps(db, b.half, q.abs_rotation.transpose() * a.half));
}

// b: B's child box; a: A's box, whose center and extents in B's frame are
// ca and extent_a.
double lower_bound_on_b_axes(const Query& q, const Box& a, const Box& b, const Vec3& ca,
                             const Vec3& extent_a, double prune2) {
  const double slab = squared_slab_gap(q, a, b);
  if (slab > prune2) return slab;
  const double sb = std::max(slab, sum_of_squared_gaps(b.center - ca, b.half, extent_a));
  if (sb > prune2) return sb;
  const Vec3 d = a.center - (q.rotation * b.center + q.translation_s);
  return std::max(sb, sum_of_squared_gaps(d, a.half, q.abs_rotation * b.half));
}

// Whether an edge of one triangle passes through the interior of the other
// with both ends farther than `band` from its plane (exact signs; the
// distances to the plane in doubles).
bool edge_crosses(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b, const Vec3& c,
                  double band) {
  const int s0 = detail::side3d(a, b, c, p0);
  const int s1 = detail::side3d(a, b, c, p1);
  if (s0 == 0 || s1 == 0 || s0 == s1) return false;
  const int o0 = detail::side3d(p0, p1, a, b);
  const int o1 = detail::side3d(p0, p1, b, c);
  const int o2 = detail::side3d(p0, p1, c, a);
  if (!((o0 > 0 && o1 > 0 && o2 > 0) || (o0 < 0 && o1 < 0 && o2 < 0))) return false;
  const Vec3 n = (b - a).cross(c - a);
  const double length = n.norm();
  if (!(length > 0.0)) return false;
  return std::abs(n.dot(p0 - a)) > band * length && std::abs(n.dot(p1 - a)) > band * length;
}

bool triangles_cross(const std::array<Vec3, 3>& ta, const std::array<Vec3, 3>& tb, double band) {
  for (int k = 0; k < 3; ++k) {
    const int l = (k + 1) % 3;
    if (edge_crosses(ta[k], ta[l], tb[0], tb[1], tb[2], band)) return true;
    if (edge_crosses(tb[k], tb[l], ta[0], ta[1], ta[2], band)) return true;
  }
  return false;
}

struct Best {
  double d2 = std::numeric_limits<double>::infinity();
  std::int32_t ta = -1, tb = -1;
  bool crossing = false;
};

// A triangle placed in the query's scaled frame, prepared for the fast
// kernel, with its box and plane.
struct Triangles {
  std::array<Vec3, 3> v;
  detail::FastTriangle fast;
  // The triangle's box in the query frame (A's, scaled): two triangles are
  // at least as far apart as their boxes.
  Vec3 lo, hi;
  // Unit normal and offset of the plane (zero normal for a degenerate
  // triangle): every point x has |unit_normal . x - offset| within rounding
  // of its distance to the plane.
  Vec3 unit_normal = Vec3::Zero();
  double offset = 0.0;
  std::int32_t id = -1;
};

// Whether the plane of t has all three vertices of `other` on one side,
// farther than `limit` (a lower bound on the pair's distance: the plane
// separates the triangles by at least the nearest of those vertices).
bool plane_separates(const Triangles& t, const Triangles& other, double limit) {
  const double s0 = t.unit_normal.dot(other.v[0]) - t.offset;
  const double s1 = t.unit_normal.dot(other.v[1]) - t.offset;
  const double s2 = t.unit_normal.dot(other.v[2]) - t.offset;
  return (s0 > limit && s1 > limit && s2 > limit) || (s0 < -limit && s1 < -limit && s2 < -limit);
}

Triangles prepared(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::int32_t id,
                   const KernelTolerance<double>& tol) {
  Triangles t;
  t.v = {p0, p1, p2};
  t.fast = detail::FastTriangle(p0, p1, p2, tol.min_sin_squared);
  t.lo = p0.cwiseMin(p1).cwiseMin(p2);
  t.hi = p0.cwiseMax(p1).cwiseMax(p2);
  if (t.fast.planar) {
    const Vec3 n(t.fast.n.x, t.fast.n.y, t.fast.n.z);
    t.unit_normal = n / n.norm();
    t.offset = t.unit_normal.dot(p0);
  }
  t.id = id;
  return t;
}

// Slack of a box gap against a limit (scaled units, magnitudes about 1):
// each coordinate difference rounds once, the squares and sum a few times.
constexpr double kBoxSlackUlps = 16.0;

// Slack of the planes' bound against a limit (scaled units, magnitudes about
// 1): a triangle's plane and the other's vertices' offsets from it are a
// few products and sums, a few u each. Pinned with kBoxSlackUlps by
// MeshDistanceTraversal.MatchesBruteForceAtAnyScale.
constexpr double kPlaneSlackUlps = 16.0;

// Relative slack of motion_bound: the norms, the product and the sums round
// by a few u each, and the bound must stay an upper bound on the motion (a
// tracked answer is kept only when it held; MeshDistanceTraversal.
// TrackingGivesTheColdAnswer).
constexpr double kMotionBoundUlps = 64.0;

// Squared gap between two axis-aligned boxes of the query frame.
double box_gap_squared(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
  double gap2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max(alo[k] - bhi[k], blo[k] - ahi[k]);
    if (g > 0.0) gap2 += g * g;
  }
  return gap2;
}

// One triangle pair: skipped when its spheres are farther apart than
// `limit` (scaled; the caller needs only pairs within it), else the fast
// kernel, and the crossing test when in the band. Returns the pair's squared
// distance (infinity when skipped).
double test_pair(const Query& q, const Triangles& a, const Triangles& b, Best& best, int& tested,
                 double limit = std::numeric_limits<double>::infinity()) {
  // The boxes' gap (exact differences of stored coordinates, rounded once
  // each; the slack below covers them).
  const double gap2 = box_gap_squared(a.lo, a.hi, b.lo, b.hi);
  const double box_limit = limit + kBoxSlackUlps * kUnitRoundoff;
  if (gap2 > box_limit * box_limit) return std::numeric_limits<double>::infinity();
  // The planes' bound, with the slack of its rounding (a few u of the
  // scaled magnitudes, about 1).
  const double plane_limit = limit + kPlaneSlackUlps * kUnitRoundoff;
  if (plane_separates(a, b, plane_limit) || plane_separates(b, a, plane_limit))
    return std::numeric_limits<double>::infinity();
  // A separating axis through the boxes' centers: along any direction w, the
  // gap between the triangles' projections over |w| is a lower bound on
  // their distance. Catches the pairs of large slanted triangles whose
  // boxes overlap and whose planes cut each other, a large share of the
  // kernel calls on the slowest poses (env/rob in bench/mesh_bench).
  // Rounding: scaled coordinates are at most 1 (so is |w| / 4), each
  // projection is within 3u|w| and the gap within 6u|w|; the slack covers
  // that and the squares.
  {
    const Vec3 w = (b.lo + b.hi) - (a.lo + a.hi);  // twice the boxes' center difference
    const double a_max = std::max({w.dot(a.v[0]), w.dot(a.v[1]), w.dot(a.v[2])});
    const double b_min = std::min({w.dot(b.v[0]), w.dot(b.v[1]), w.dot(b.v[2])});
    const double gap = b_min - a_max;
    const double reach = limit + kBoxSlackUlps * 2.0 * kUnitRoundoff;
    if (gap > 0.0 && gap * gap > w.squaredNorm() * reach * reach)
      return std::numeric_limits<double>::infinity();
  }
  ++tested;
  // The kernel needs no answer beyond the limit (plus its slack): a result
  // at or above that bound is a pair farther than the limit.
  const double bound = plane_limit * plane_limit;
  const double d2 = detail::triangle_distance_squared(a.fast, b.fast, q.tol, bound);
  if (d2 >= bound) return std::numeric_limits<double>::infinity();
  if (d2 <= q.band_s * q.band_s && !best.crossing && triangles_cross(a.v, b.v, q.band_s)) {
    best.d2 = d2;
    best.ta = a.id;
    best.tb = b.id;
    best.crossing = true;
    return d2;
  }
  if (!best.crossing &&
      (d2 < best.d2 ||
       (d2 == best.d2 && (a.id < best.ta || (a.id == best.ta && b.id < best.tb))))) {
    best.d2 = d2;
    best.ta = a.id;
    best.tb = b.id;
  }
  return d2;
}

Triangles a_triangle(const Query& q, std::int32_t t) {
  const auto& tri = q.a.triangle(t);
  return prepared(q.a_vertex(tri[0]), q.a_vertex(tri[1]), q.a_vertex(tri[2]), t, q.tol);
}
Triangles b_triangle(const Query& q, std::int32_t t) {
  const auto& tri = q.b.triangle(t);
  return prepared(q.b_vertex(tri[0]), q.b_vertex(tri[1]), q.b_vertex(tri[2]), t, q.tol);
}

Feature feature_of(const TriangleMesh& mesh, std::int32_t t, std::uint8_t active) {
  Feature f;
  const auto& tri = mesh.triangle(t);
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    if ((active >> k & 1u) != 0)
      f.vertices[static_cast<std::size_t>(n++)] =
          static_cast<std::int32_t>(tri[static_cast<std::size_t>(k)]);
  }
  f.type = n >= 3 ? FeatureType::face : n == 2 ? FeatureType::edge : FeatureType::vertex;
  if (f.type == FeatureType::face) f.face = t;
  return f;
}

// A surface component of one mesh inside the other, closed mesh: which
// side holds it and one of its vertices, a point of both bodies (on the one
// surface, inside the other's solid).
struct Containment {
  std::int8_t side = 0;  // 0: none; 1: a vertex of B inside A; 2: a vertex of A inside B
  std::int32_t vertex = -1;
};

// Whether a surface component of one mesh lies inside the other, closed
// mesh. Component vertices are placed in the other mesh's frame.
Containment contained(const Query& q) {
  if (q.a.is_closed()) {
    for (const std::int32_t v : q.b.component_vertices())
      if (q.a.contains(q.rotation * q.b.vertex(v) + q.translation)) return {1, v};
  }
  if (q.b.is_closed()) {
    const Mat3 rt = q.rotation.transpose();
    for (const std::int32_t v : q.a.component_vertices())
      if (q.b.contains(rt * (q.a.vertex(v) - q.translation))) return {2, v};
  }
  return {};
}

// The contained vertex in A's frame (unscaled).
Vec3 containment_point(const Query& q, const Containment& c) {
  return c.side == 1 ? Vec3(q.rotation * q.b.vertex(c.vertex) + q.translation)
                     : q.a.vertex(c.vertex);
}

MeshResult finish(const Query& q, const Pose& pose_a, const Best& best, const Containment& inside) {
  const Pose pa = checked_pose(pose_a, "mesh distance: pose_a");
  MeshResult r;
  r.triangle_a = best.ta;
  r.triangle_b = best.tb;
  // The winner's points and features from the slow twin (the traversal
  // ranked pairs by the fast kernel).
  const Triangles ta = a_triangle(q, best.ta);
  const Triangles tb = b_triangle(q, best.tb);
  const ClosestPoints<double> points =
      closest_triangle_triangle(ta.v[0], ta.v[1], ta.v[2], tb.v[0], tb.v[1], tb.v[2], q.tol);
  r.feature_a = feature_of(q.a, best.ta, points.active_a);
  r.feature_b = feature_of(q.b, best.tb, points.active_b);
  const double d_s = std::sqrt(points.distance_squared);
  const Vec3 pa_local = times_pow2(points.point_a, q.exponent);
  const Vec3 pb_local = times_pow2(points.point_b, q.exponent);
  r.point_a = pa.apply(pa_local);
  r.point_b = pa.apply(pb_local);
  const Vec3 diff = points.point_b - points.point_a;
  if (d_s > 0.0) {
    r.normal = pa.rotation * (diff / d_s);
  } else {
    const auto& tri = q.a.triangle(best.ta);
    const Vec3 n = detail::exact_triangle_normal(q.a.vertex(static_cast<int>(tri[0])),
                                                 q.a.vertex(static_cast<int>(tri[1])),
                                                 q.a.vertex(static_cast<int>(tri[2])));
    r.normal =
        n.squaredNorm() > 0.0 ? Vec3(pa.rotation * n.normalized()) : Vec3(pa.rotation.col(0));
  }
  if (!best.crossing && inside.side != 0) {
    // No surfaces cross: the closest points above are those of the two
    // surfaces, apart by up to the inner body's size, and realize no
    // answer of distance 0. The contained vertex lies on both bodies.
    r.point_a = pa.apply(containment_point(q, inside));
    r.point_b = r.point_a;
  }
  if (best.crossing || inside.side != 0) {
    r.status = Status::intersecting;
    r.distance = 0.0;
    r.lower_bound = 0.0;
    r.depth_upper_bound = std::numeric_limits<double>::infinity();
    return r;
  }
  r.distance = std::ldexp(d_s, q.exponent);
  r.lower_bound = std::max(0.0, std::ldexp(d_s - kLowerBoundUlps * kUnitRoundoff, q.exponent));
  r.status = d_s <= q.band_s ? Status::touching : Status::separated;
  return r;
}

// Upper bound on how far any point of B moved, in A's frame, between the
// relative poses (r0, t0) and (r1, t1): |(R1 - R0)(y - c)| + |(R1 - R0) c +
// t1 - t0| over B's root box (center c, half-diagonal h), with the
// Frobenius norm bounding the spectral one.
double motion_bound(const TriangleMesh& b, const Mat3& r0, const Vec3& t0, const Mat3& r1,
                    const Vec3& t1) {
  Vec3 lo, hi;
  b.box(0, lo, hi);
  const Vec3 c = 0.5 * (lo + hi);
  const double h = (0.5 * (hi - lo)).stableNorm();
  const Mat3 dr = r1 - r0;
  const double m = dr.norm() * h + (dr * c + (t1 - t0)).stableNorm();
  return m * (1.0 + kMotionBoundUlps * kUnitRoundoff);
}

double b_radius(const TriangleMesh& b) {
  Vec3 lo, hi;
  b.box(0, lo, hi);
  return (0.5 * (hi - lo)).stableNorm();
}

// A point of one surface inside the other, closed mesh (contained()'s
// test), in A's frame unscaled; false when there is none.
bool contained_point(const Query& q, Vec3& point) {
  if (q.a.is_closed()) {
    for (const std::int32_t v : q.b.component_vertices()) {
      const Vec3 p = q.rotation * q.b.vertex(v) + q.translation;
      if (q.a.contains(p)) {
        point = p;
        return true;
      }
    }
  }
  if (q.b.is_closed()) {
    const Mat3 rt = q.rotation.transpose();
    for (const std::int32_t v : q.a.component_vertices()) {
      if (q.b.contains(rt * (q.a.vertex(v) - q.translation))) {
        point = q.a.vertex(v);
        return true;
      }
    }
  }
  return false;
}

// The stop rule of a search against the hulls' lower bound L: a triangle
// pair whose kernel distance d is at most L (1 + kHullStopRelative) +
// kHullStopUlps u R is the answer, since no pair is closer than L. Its
// exact distance is then within the accuracy standard of the meshes'
// (DESIGN.md: 1e-12 relative plus 64 u R, of which the kernel's error
// kLowerBoundUlps takes half).
constexpr double kHullStopRelative = 1e-12;
constexpr double kHullStopUlps = 32.0;

// What the meshes' hulls (TriangleMesh::hull()) tell a query.
struct HullBound {
  bool apart = false;   // the hulls are separated: no surface crosses or holds the other
  double lower = 0.0;   // certified lower bound on the meshes' distance (unscaled)
  double stop2 = -1.0;  // squared scaled distance that ends a search (-1: none)
};

HullBound hull_bound(Query& q, const DistanceOptions& options, DistanceCache* cache) {
  // Meshes are accepted up to coordinates of kMaxMagnitude, the convex
  // query up to placed magnitudes (|t| + sqrt(3) scale) of it: beyond, no
  // hull bound (the search alone answers).
  if (!(q.magnitude <= kMaxMagnitude)) return {};
  DistanceOptions hull_options;
  hull_options.absolute_tolerance = options.absolute_tolerance;
  hull_options.penetration = false;
  DistanceCache local;
  const DistanceResult r = detail::distance_of_rigid_poses(
      q.a.hull(), q.pose_a, q.b.hull(), q.pose_b, hull_options, cache != nullptr ? cache : &local);
  HullBound h;
  if (r.status != Status::separated || !(r.lower_bound > 0.0)) return h;
  h.apart = true;
  q.set_slab(q.pose_a.rotation.transpose() * r.normal);
  h.lower = r.lower_bound;
  const double stop = std::ldexp(r.lower_bound, -q.exponent) * (1.0 + kHullStopRelative) +
                      kHullStopUlps * kUnitRoundoff * std::ldexp(q.magnitude, -q.exponent);
  h.stop2 = stop * stop;
  return h;
}

// The margin query between two meshes (proxima/query/margin.h), in the scaled
// frame of the distance query: depth first over node pairs, the nearer
// child on top, a node pair pruned when its box bound exceeds the margin by
// the bound's rounding slack, and the first triangle pair within margin +
// band (test_pair's filters and kernel, limited there) ends the search.
class MarginSearch {
 public:
  MarginSearch(const Query& q, double margin) : q_(q), margin_(margin) {
    margin_s_ = std::ldexp(margin, -q.exponent);
    yes_s_ = margin_s_ + q.band_s;
    slack_s_ = detail::prune_slack(std::ldexp(q.magnitude, -q.exponent));
    prune_s_ = margin_s_ + slack_s_;
    lower_s_ = std::numeric_limits<double>::infinity();
  }

  // Whether triangle pair (ta, tb) is within; tested pairs lower the bound.
  bool test(const Triangles& ta, const Triangles& tb) {
    Best unused;
    const double d2 = test_pair(q_, ta, tb, unused, tested_, yes_s_);
    if (d2 <= yes_s_ * yes_s_) {
      witness_a_ = ta.id;
      witness_b_ = tb.id;
      return true;
    }
    // Skipped by the filters or the kernel's limit: farther than yes_s_ up
    // to their rounding (a few u, below half the band); tested: the
    // kernel's distance less its error.
    lower_s_ = std::min(lower_s_, std::isfinite(d2) ? std::sqrt(d2) - kLowerBoundUlps * kUnitRoundoff
                                                    : yes_s_ - 0.5 * q_.band_s);
    return false;
  }

  bool traverse() {
    const auto nodes_a = q_.a.nodes();
    const auto nodes_b = q_.b.nodes();
    const auto order_a = q_.a.triangle_order();
    const auto order_b = q_.b.triangle_order();
    const double prune2 = prune_s_ * prune_s_;
    std::array<Triangles, TriangleMesh::kLeafSize> leaf_a, leaf_b;
    stack_.clear();
    stack_.push_back({0, 0});
    while (!stack_.empty()) {
      const auto [ia, ib] = stack_.back();
      stack_.pop_back();
      const TriangleMesh::Node& na = nodes_a[static_cast<std::size_t>(ia)];
      const TriangleMesh::Node& nb = nodes_b[static_cast<std::size_t>(ib)];
      if (na.is_leaf() && nb.is_leaf()) {
        for (std::int32_t i = 0; i < na.count; ++i)
          leaf_a[static_cast<std::size_t>(i)] =
              a_triangle(q_, order_a[static_cast<std::size_t>(na.first_or_right + i)]);
        for (std::int32_t j = 0; j < nb.count; ++j)
          leaf_b[static_cast<std::size_t>(j)] =
              b_triangle(q_, order_b[static_cast<std::size_t>(nb.first_or_right + j)]);
        for (std::int32_t i = 0; i < na.count; ++i)
          for (std::int32_t j = 0; j < nb.count; ++j)
            if (test(leaf_a[static_cast<std::size_t>(i)], leaf_b[static_cast<std::size_t>(j)]))
              return true;
        continue;
      }
      const Box ba = node_box(na, q_.box_unit_a);
      const Box bb = node_box(nb, q_.box_unit_b);
      const bool split_a = !na.is_leaf() && (nb.is_leaf() || ba.half.sum() >= bb.half.sum());
      std::array<std::int32_t, 2> child_a = {ia, ia};
      std::array<std::int32_t, 2> child_b = {ib, ib};
      std::array<double, 2> lb2;
      if (split_a) {
        const Vec3 cb = q_.rotation * bb.center + q_.translation_s;
        const Vec3 extent_b = q_.abs_rotation * bb.half;
        child_a = {ia + 1, na.first_or_right};
        for (int c = 0; c < 2; ++c) {
          const Box box = node_box(nodes_a[static_cast<std::size_t>(child_a[c])], q_.box_unit_a);
          lb2[c] = lower_bound_on_a_axes(q_, box, bb, cb, extent_b, prune2);
        }
      } else {
        const Vec3 ca = q_.rotation.transpose() * (ba.center - q_.translation_s);
        const Vec3 extent_a = q_.abs_rotation.transpose() * ba.half;
        child_b = {ib + 1, nb.first_or_right};
        for (int c = 0; c < 2; ++c) {
          const Box box = node_box(nodes_b[static_cast<std::size_t>(child_b[c])], q_.box_unit_b);
          lb2[c] = lower_bound_on_b_axes(q_, ba, box, ca, extent_a, prune2);
        }
      }
      nodes_tested_ += 2;
      // The nearer child on top (pushed last).
      const int near = lb2[0] <= lb2[1] ? 0 : 1;
      for (const int c : {1 - near, near}) {
        if (lb2[c] > prune2) {
          lower_s_ = std::min(lower_s_, std::sqrt(lb2[c]) - slack_s_);
        } else {
          stack_.push_back({child_a[c], child_b[c]});
        }
      }
    }
    return false;
  }

  double margin() const { return margin_; }
  double lower_scaled() const { return lower_s_; }
  int tested() const { return tested_; }
  int nodes_tested() const { return nodes_tested_; }
  std::int32_t witness_a() const { return witness_a_; }
  std::int32_t witness_b() const { return witness_b_; }

 private:
  const Query& q_;
  double margin_;
  double margin_s_ = 0.0, yes_s_ = 0.0, prune_s_ = 0.0, lower_s_ = 0.0, slack_s_ = 0.0;
  int tested_ = 0;
  int nodes_tested_ = 0;
  std::int32_t witness_a_ = -1, witness_b_ = -1;
  std::vector<std::array<std::int32_t, 2>> stack_;
};

}  // namespace

MarginResult within_margin(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options,
                           MeshCache* cache) {
  detail::check_margin(margin, "within_margin");
  const Pose pa = checked_pose(pose_a, "within_margin: pose_a");
  const Pose pb = checked_pose(pose_b, "within_margin: pose_b");
  MarginResult r;
  r.margin = margin;
  // Far apart: the root boxes' balls prove it without the hierarchies (the
  // options are checked first, as every query checks them).
  if (!is_finite_bits(options.absolute_tolerance) || !(options.absolute_tolerance >= 0.0))
    throw InvalidInput("within_margin: absolute_tolerance must be finite and >= 0");
  const double gap = detail::sphere_gap_lower_bound(pa.apply(a.center()), a.bounding_radius(),
                                                    pb.apply(b.center()), b.bounding_radius());
  if (gap > margin) {
    r.lower_bound = gap;
    return r;
  }
  Query q = make_query(a, pa, b, pb, options);
  if (cache != nullptr && (cache->mesh_a != a.id() || cache->mesh_b != b.id())) {
    cache->reset();
    cache->mesh_a = a.id();
    cache->mesh_b = b.id();
  }
  // The hulls hold the surfaces: hulls beyond the margin prove the meshes
  // beyond it, and otherwise the hulls' closest points aim the slab bound
  // of the traversal.
  double hull_lower = 0.0;
  if (q.magnitude <= kMaxMagnitude) {  // the convex query's range (hull_bound)
    DistanceCache local;
    const MarginResult hull = detail::within_margin_of_rigid_poses(
        a.hull(), q.pose_a, b.hull(), q.pose_b, margin, options,
        cache != nullptr ? cache->hull : local);
    if (hull.status == MarginStatus::beyond) {
      r.lower_bound = hull.lower_bound;
      r.upper_bound = std::numeric_limits<double>::infinity();
      return r;
    }
    hull_lower = hull.lower_bound;
    if (hull.upper_bound > 0.0) q.set_slab(q.pose_a.rotation.transpose() * (hull.point_b - hull.point_a));
  }
  MarginSearch search(q, margin);
  const bool same_pair = cache != nullptr;
  // The last witness (or closest) pair first: a colliding pair often still
  // collides there.
  bool found = same_pair && cache->triangle_a >= 0 && cache->triangle_a < a.triangle_count() &&
               cache->triangle_b >= 0 && cache->triangle_b < b.triangle_count() &&
               search.test(a_triangle(q, cache->triangle_a), b_triangle(q, cache->triangle_b));
  if (!found) found = search.traverse();
  r.pairs_tested = search.tested();
  if (found) {
    const Triangles ta = a_triangle(q, search.witness_a());
    const Triangles tb = b_triangle(q, search.witness_b());
    const ClosestPoints<double> points =
        closest_triangle_triangle(ta.v[0], ta.v[1], ta.v[2], tb.v[0], tb.v[1], tb.v[2], q.tol);
    r.status = MarginStatus::within;
    r.point_a = pa.apply(times_pow2(points.point_a, q.exponent));
    r.point_b = pa.apply(times_pow2(points.point_b, q.exponent));
    r.upper_bound = (r.point_b - r.point_a).norm();
    r.triangle_a = search.witness_a();
    r.triangle_b = search.witness_b();
    r.lower_bound = 0.0;
    if (cache != nullptr) {
      cache->triangle_a = r.triangle_a;
      cache->triangle_b = r.triangle_b;
    }
    return r;
  }
  // No pair within: within any margin still when a surface lies inside the
  // other, closed mesh (a point of both).
  Vec3 inside;
  if (contained_point(q, inside)) {
    r.status = MarginStatus::within;
    r.point_a = pa.apply(inside);
    r.point_b = r.point_a;
    r.upper_bound = 0.0;
    r.lower_bound = 0.0;
    return r;
  }
  r.lower_bound = std::max({0.0, std::ldexp(search.lower_scaled(), q.exponent), hull_lower});
  r.status = r.lower_bound > margin ? MarginStatus::beyond : MarginStatus::undecided;
  return r;
}

MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                              const Pose& pose_b, const DistanceOptions& options) {
  const Query q = make_query(a, pose_a, b, pose_b, options);
  std::vector<Triangles> tb(static_cast<std::size_t>(b.triangle_count()));
  for (std::int32_t j = 0; j < b.triangle_count(); ++j)
    tb[static_cast<std::size_t>(j)] = b_triangle(q, j);
  Best best;
  int tested = 0;
  for (std::int32_t i = 0; i < a.triangle_count() && !best.crossing; ++i) {
    const Triangles ta = a_triangle(q, i);
    for (const Triangles& t : tb) {
      test_pair(q, ta, t, best, tested);
      if (best.crossing) break;
    }
  }
  const Containment inside = best.crossing ? Containment{} : contained(q);
  MeshResult r = finish(q, pose_a, best, inside);
  r.pairs_tested = tested;
  return r;
}

MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                    const Pose& pose_b, const DistanceOptions& options, MeshCache* cache) {
  Query q = make_query(a, pose_a, b, pose_b, options);
  const double slack_s = detail::prune_slack(std::ldexp(q.magnitude, -q.exponent));
  const double unscaled_slack = std::ldexp(slack_s, q.exponent);
  Best best;
  int tested = 0;
  int nodes_tested = 0;

  // A cache of another pair starts over (its hull state and triangles
  // belong to other meshes).
  if (cache != nullptr && (cache->mesh_a != a.id() || cache->mesh_b != b.id())) {
    cache->reset();
    cache->mesh_a = a.id();
    cache->mesh_b = b.id();
  }
  const bool same_pair = cache != nullptr;
  HullBound hull;
  if (cache != nullptr && cache->hull_wait > 0) {
    --cache->hull_wait;
  } else {
    hull = hull_bound(q, options, cache != nullptr ? &cache->hull : nullptr);
    if (cache != nullptr && hull.apart) {
      cache->hull_backoff = 0;
    } else if (cache != nullptr) {
      cache->hull_backoff = static_cast<std::uint8_t>(std::min(2 * cache->hull_backoff + 1, 32));
      cache->hull_wait = cache->hull_backoff;
    }
  }
  const auto remember = [&] {
    cache->triangle_a = best.ta;
    cache->triangle_b = best.tb;
    cache->last_rotation = q.rotation;
    cache->last_translation = q.translation;
  };

  // The last closest pair: an upper bound before any search, and the
  // answer when it reaches the hulls' lower bound.
  if (same_pair && cache->triangle_a >= 0 && cache->triangle_a < a.triangle_count() &&
      cache->triangle_b >= 0 && cache->triangle_b < b.triangle_count()) {
    test_pair(q, a_triangle(q, cache->triangle_a), b_triangle(q, cache->triangle_b), best, tested);
    if (best.d2 <= hull.stop2) {
      MeshResult r = finish(q, pose_a, best, Containment{});
      r.lower_bound = std::min(r.lower_bound, hull.lower);
      r.pairs_tested = tested;
      r.tracked = true;
      remember();
      return r;
    }
  }

  double last_step = std::numeric_limits<double>::infinity();
  if (same_pair && cache->triangle_a >= 0) {
    last_step =
        motion_bound(b, cache->last_rotation, cache->last_translation, q.rotation, q.translation);
  }

  // Tracked: the candidate pairs are enough while B moved less than the
  // margin since they were collected (see MeshCache).
  // A list that did not pay delays the next collections (MeshCache).
  const auto list_failed = [&] {
    cache->list_backoff = static_cast<std::uint8_t>(std::min(2 * cache->list_backoff + 1, 32));
    cache->list_wait = cache->list_backoff;
  };
  if (same_pair && !cache->near.empty()) {
    const double moved =
        motion_bound(b, cache->rotation, cache->translation, q.rotation, q.translation);
    if (!(moved + unscaled_slack <= cache->margin) && cache->list_uses == 0) list_failed();
    if (moved + unscaled_slack <= cache->margin) {
      cache->list_uses = static_cast<std::uint16_t>(std::min(cache->list_uses + 1, 0xffff));
      cache->list_backoff = 0;
      for (const auto& pair : cache->near) {
        test_pair(q, a_triangle(q, pair[0]), b_triangle(q, pair[1]), best, tested,
                  std::sqrt(best.d2) + slack_s);
        if (best.crossing) break;
      }
      // The containment found at the list's collection still holds while
      // B moved less than the surfaces' distance then: the contained vertex
      // cannot have crossed the other surface.
      Containment inside;
      if (!best.crossing && !hull.apart) {
        inside = moved + unscaled_slack < cache->base_distance && cache->inside >= 0
                     ? Containment{cache->inside, cache->inside_vertex}
                     : contained(q);
      }
      MeshResult r = finish(q, pose_a, best, inside);
      r.pairs_tested = tested;
      r.tracked = true;
      remember();
      return r;
    }
  }

  // The margin of a new candidate list (scaled), 0 for none.
  // Hulls apart: no list. The hulls' bound and the last pair already make
  // the tracked search the cold one with a tight first upper bound, and a
  // list's wider search costs more than it saves there (on a planner's
  // steps the closest pair wanders over near-parallel faces, whose pairs
  // within the margin overflow the list). Lists serve the pairs whose
  // hulls overlap (a body moving inside or around another).
  double margin = 0.0;
  if (hull.apart) {
    // no list
  } else if (cache != nullptr && same_pair && cache->list_wait > 0) {
    --cache->list_wait;
  } else if (cache != nullptr && same_pair && std::isfinite(last_step) &&
             kMarginSteps * last_step <= kMarginRadiusFraction * b_radius(b)) {
    margin = std::max(kMarginSteps * last_step, 4.0 * unscaled_slack) * q.factor;
  }
  struct Candidate {
    std::int32_t ta, tb;
    double d2;
  };
  std::vector<Candidate> candidates;
  bool overflow = false;

  struct Entry {
    std::int32_t na, nb;
    double lb2;
    double center2;  // squared distance of the boxes' centers: ties of lb2
  };
  // Best first (a binary heap of node pairs, the smallest lower bound on
  // top, ties to the nearer centers), each pop followed by a dive to a leaf
  // pair along the nearer child: the first leaves reached are near the
  // closest pair, so the upper bound is tight early and prunes most of the
  // rest: far fewer triangle pairs than a depth-first stack, cold and along
  // a motion (bench/mesh_bench, env/rob). A plain heap without the dive
  // tests about as few pairs but pays heap work for every node pair (slower
  // when the meshes are apart); a depth-first stack with the same tie rule
  // stays slower than this.
  const auto later = [](const Entry& x, const Entry& y) {
    return x.lb2 > y.lb2 || (x.lb2 == y.lb2 && x.center2 > y.center2);
  };
  std::vector<Entry> heap;
  heap.reserve(256);
  const auto nodes_a = a.nodes();
  const auto nodes_b = b.nodes();
  const auto order_a = a.triangle_order();
  const auto order_b = b.triangle_order();
  const auto threshold2 = [&]() {
    const double t = std::sqrt(best.d2) + 2.0 * margin + slack_s;
    return t * t;
  };
  double prune2 = threshold2();
  heap.push_back({0, 0, 0.0, 0.0});
  // Prepared leaves, direct-mapped by node id: a dive meets the same leaf
  // against several leaves of the other mesh in a row.
  // Per thread (the query is reentrant), stamped with this query so that no
  // leaf placed at another query's pose is used. 128 slots a side (a few
  // hundred KB per thread); with the best-first traversal fewer or more
  // slots measure the same (bench/mesh_bench, env/rob): the size is not
  // critical.
  struct LeafSlot {
    std::uint64_t stamp = 0;
    std::int32_t node = -1;
    std::array<Triangles, TriangleMesh::kLeafSize> t;
    Vec3 lo, hi;  // the union of the triangles' boxes (query frame)
  };
  constexpr std::size_t kSlots = 128;
  thread_local std::array<LeafSlot, kSlots> slots_a, slots_b;
  thread_local std::uint64_t query_stamp = 0;
  const std::uint64_t stamp = ++query_stamp;
  const auto leaf = [&](std::array<LeafSlot, kSlots> & slots, std::int32_t node,
                        const TriangleMesh::Node& n, bool side_a) -> const auto& {
    LeafSlot& slot = slots[static_cast<std::size_t>(node) % kSlots];
    if (slot.stamp != stamp || slot.node != node) {
      slot.stamp = stamp;
      slot.node = node;
      slot.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      slot.hi = -slot.lo;
      for (std::int32_t i = 0; i < n.count; ++i) {
        const auto k = static_cast<std::size_t>(n.first_or_right + i);
        Triangles& t = slot.t[static_cast<std::size_t>(i)];
        t = side_a ? a_triangle(q, order_a[k]) : b_triangle(q, order_b[k]);
        slot.lo = slot.lo.cwiseMin(t.lo);
        slot.hi = slot.hi.cwiseMax(t.hi);
      }
    }
    return slot;
  };
  // Stopped when the best pair reaches the hulls' lower bound: every pair
  // left is at least as far as that bound.
  bool reached_hull = best.d2 <= hull.stop2;
  while (!heap.empty() && !best.crossing && !reached_hull) {
    std::pop_heap(heap.begin(), heap.end(), later);
    Entry e = heap.back();
    heap.pop_back();
    if (e.lb2 > prune2) break;  // every other pair's bound is as large
    // Dive: follow the nearer child down to a leaf pair, the other child
    // waits in the heap.
    while (true) {
      const TriangleMesh::Node& na = nodes_a[static_cast<std::size_t>(e.na)];
      const TriangleMesh::Node& nb = nodes_b[static_cast<std::size_t>(e.nb)];
      if (na.is_leaf() && nb.is_leaf()) {
        const LeafSlot& leaf_a = leaf(slots_a, e.na, na, true);
        const LeafSlot& leaf_b = leaf(slots_b, e.nb, nb, false);
        // Each triangle against the other leaf's box first (both in the
        // query frame): a triangle farther than the limit from every
        // triangle of the other leaf skips its row or column of pairs.
        const double box_limit = std::sqrt(prune2) + kBoxSlackUlps * kUnitRoundoff;
        unsigned columns = 0;
        for (std::int32_t j = 0; j < nb.count; ++j) {
          const Triangles& tj = leaf_b.t[static_cast<std::size_t>(j)];
          if (box_gap_squared(tj.lo, tj.hi, leaf_a.lo, leaf_a.hi) <= box_limit * box_limit)
            columns |= 1u << j;
        }
        for (std::int32_t i = 0; i < na.count && columns != 0 && !best.crossing; ++i) {
          const Triangles& ti = leaf_a.t[static_cast<std::size_t>(i)];
          if (box_gap_squared(ti.lo, ti.hi, leaf_b.lo, leaf_b.hi) > box_limit * box_limit) continue;
          for (std::int32_t j = 0; j < nb.count; ++j) {
            if ((columns >> j & 1u) == 0) continue;
            const Triangles& tj = leaf_b.t[static_cast<std::size_t>(j)];
            const double before = best.d2;
            const double d2 = test_pair(q, ti, tj, best, tested, std::sqrt(prune2));
            if (best.d2 < before) prune2 = threshold2();
            if (best.crossing) break;
            if (margin > 0.0 && !overflow && d2 <= prune2) {
              // Every tested pair that may end within the margin; filtered
              // against the final best at the end.
              candidates.push_back({ti.id, tj.id, d2});
              overflow = candidates.size() > 4 * kNearCapacity;
            }
          }
        }
        prune2 = threshold2();
        reached_hull = best.d2 <= hull.stop2;
        break;
      }
      // Split the larger node (an inner node against a leaf: the inner one).
      const Box ba = node_box(na, q.box_unit_a);
      const Box bb = node_box(nb, q.box_unit_b);
      const bool split_a = !na.is_leaf() && (nb.is_leaf() || ba.half.sum() >= bb.half.sum());
      Entry c0, c1;
      if (split_a) {
        // B's box in A's frame, shared by both children.
        const Vec3 cb = q.rotation * bb.center + q.translation_s;
        const Vec3 extent_b = q.abs_rotation * bb.half;
        const std::int32_t l = e.na + 1, r = na.first_or_right;
        const Box b0 = node_box(nodes_a[static_cast<std::size_t>(l)], q.box_unit_a);
        const Box b1 = node_box(nodes_a[static_cast<std::size_t>(r)], q.box_unit_a);
        c0 = {l, e.nb, lower_bound_on_a_axes(q, b0, bb, cb, extent_b, prune2),
              (b0.center - cb).squaredNorm()};
        c1 = {r, e.nb, lower_bound_on_a_axes(q, b1, bb, cb, extent_b, prune2),
              (b1.center - cb).squaredNorm()};
      } else {
        // A's box in B's frame, shared by both children.
        const Vec3 ca = q.rotation.transpose() * (ba.center - q.translation_s);
        const Vec3 extent_a = q.abs_rotation.transpose() * ba.half;
        const std::int32_t l = e.nb + 1, r = nb.first_or_right;
        const Box b0 = node_box(nodes_b[static_cast<std::size_t>(l)], q.box_unit_b);
        const Box b1 = node_box(nodes_b[static_cast<std::size_t>(r)], q.box_unit_b);
        c0 = {e.na, l, lower_bound_on_b_axes(q, ba, b0, ca, extent_a, prune2),
              (b0.center - ca).squaredNorm()};
        c1 = {e.na, r, lower_bound_on_b_axes(q, ba, b1, ca, extent_a, prune2),
              (b1.center - ca).squaredNorm()};
      }
      nodes_tested += 2;
      if (later(c0, c1)) std::swap(c0, c1);
      if (c1.lb2 <= prune2) {
        heap.push_back(c1);
        std::push_heap(heap.begin(), heap.end(), later);
      }
      if (c0.lb2 > prune2) break;
      e = c0;
    }
  }

  // Hulls apart: no surface crosses or holds the other.
  const Containment inside = best.crossing || hull.apart ? Containment{} : contained(q);
  MeshResult r = finish(q, pose_a, best, inside);
  if (reached_hull) r.lower_bound = std::min(r.lower_bound, hull.lower);
  r.pairs_tested = tested;
  r.nodes_tested = nodes_tested;
  if (cache != nullptr) {
    remember();
    cache->near.clear();
    // A search stopped at the hulls' bound did not meet every pair within
    // the margin: no list from it.
    if (margin > 0.0 && !overflow && !best.crossing && !reached_hull) {
      // Keep the tested pairs within the margin of the final best: every
      // pair left out is farther than best + 2 margin (pruned by its
      // node pair's bound, or by its own distance here).
      const double keep = std::sqrt(best.d2) + 2.0 * margin + slack_s;
      // Closest first: a tracked query then finds its best early and skips
      // the rest by their boxes.
      std::sort(candidates.begin(), candidates.end(),
                [](const Candidate& x, const Candidate& y) { return x.d2 < y.d2; });
      for (const Candidate& c : candidates)
        if (c.d2 <= keep * keep) cache->near.push_back({c.ta, c.tb});
      if (cache->near.size() <= kNearCapacity) {
        cache->list_uses = 0;
        cache->base_distance = std::ldexp(std::sqrt(best.d2), q.exponent);
        cache->margin = std::ldexp(margin, q.exponent);
        cache->rotation = q.rotation;
        cache->translation = q.translation;
        cache->inside = inside.side;
        cache->inside_vertex = inside.vertex;
      } else {
        cache->near.clear();
        list_failed();
      }
    } else if (margin > 0.0 && overflow) {
      list_failed();
    }
  }
  return r;
}

}  // namespace proxima
