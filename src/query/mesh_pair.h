// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer (internal): a pair of triangle meshes in the frame of one
// query, what the mesh distance (mesh_distance.cpp) and the mesh margin
// query (mesh_margin.cpp) share: the scaled frame, node-pair bounds,
// prepared triangles and the triangle-pair test, the status and its
// answer, the inside test and the hulls' bound. Inline: the traversals'
// inner loops call them.
//
// Everything runs in A's frame on copies scaled by 2^-e, e the exponent of
// the query's magnitude R: a squared distance of meshes at 1e300 (or 1e-300)
// neither overflows nor underflows, and the scaling is exact.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/accuracy.h"
#include "core/power_of_two.h"
#include "geometry/triangle_distance.h"
#include "proxima/detail/geometry/exact_predicates.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"

namespace proxima::detail::mesh_pair {

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

// The query of poses already under the contract (checked_pose) and options
// already checked. Every scaling is a product with a power of two between
// 2^-1000 and 2^1000 (a normal double: the exponent is clamped), so each
// is the correctly rounded value, the same bits as ldexp's, at a
// multiplication's cost instead of a libm call.
inline Query make_query_of_rigid_poses(const TriangleMesh& a, const Pose& pa, const TriangleMesh& b,
                                       const Pose& pb, const DistanceOptions& options) {
  const Pose rel = pa.inverse() * pb;
  Query q{a, b, rel.rotation, rel.translation, {}, 1.0, 0, 0.0, 0.0, 1.0, 1.0, {}, {}, {}, {}};
  q.magnitude = std::max({magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale()), a.scale(),
                          magnitude_bound(rel, b.scale())});
  q.exponent = detail::clamped_magnitude_exponent(q.magnitude);
  q.factor = detail::pow2(-q.exponent);
  q.translation_s = rel.translation * q.factor;
  q.band_s = contact_band(q.magnitude * q.factor, options.absolute_tolerance * q.factor);
  q.box_unit_a = detail::pow2(magnitude_exponent(a.unit()) - 1 - q.exponent);
  q.box_unit_b = detail::pow2(magnitude_exponent(b.unit()) - 1 - q.exponent);
  q.abs_rotation = rel.rotation.cwiseAbs();
  q.tol = kernel_tolerance(q.magnitude * q.factor);
  q.pose_a = pa;
  q.pose_b = pb;
  return q;
}

inline Query make_query(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                 const Pose& pose_b, const DistanceOptions& options) {
  const Pose pa = checked_pose(pose_a, "mesh distance: pose_a");
  const Pose pb = checked_pose(pose_b, "mesh distance: pose_b");
  detail::check_mesh_options(options, "mesh distance", detail::MeshOptionUse::triangle_pairs);
  return make_query_of_rigid_poses(a, pa, b, pb, options);
}

// A node's box as center and half extents, scaled units of the query.
struct Box {
  Vec3 center;
  Vec3 half;
};
inline Box node_box(const TriangleMesh::Node& n, double unit) {
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
inline double sum_of_squared_gaps(const Vec3& d, const Vec3& half, const Vec3& extent) {
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
inline double squared_slab_gap(const Query& q, const Box& a, const Box& b) {
  if (!q.slab) return 0.0;
  const double a_max = a.center.dot(q.n_a) + a.half.dot(q.abs_n_a);
  const double b_min = b.center.dot(q.n_b) + q.n_offset - b.half.dot(q.abs_n_b);
  const double gap = b_min - a_max;
  return gap > 0.0 ? gap * gap : 0.0;
}

// a: A's child box; b: B's box, whose center and extents in A's frame are
// cb and extent_b.
inline double lower_bound_on_a_axes(const Query& q, const Box& a, const Box& b, const Vec3& cb,
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
inline double lower_bound_on_b_axes(const Query& q, const Box& a, const Box& b, const Vec3& ca,
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
inline bool edge_crosses(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b, const Vec3& c,
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

inline bool triangles_cross(const std::array<Vec3, 3>& ta, const std::array<Vec3, 3>& tb, double band) {
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
inline bool plane_separates(const Triangles& t, const Triangles& other, double limit) {
  const double s0 = t.unit_normal.dot(other.v[0]) - t.offset;
  const double s1 = t.unit_normal.dot(other.v[1]) - t.offset;
  const double s2 = t.unit_normal.dot(other.v[2]) - t.offset;
  return (s0 > limit && s1 > limit && s2 > limit) || (s0 < -limit && s1 < -limit && s2 < -limit);
}

inline Triangles prepared(const Vec3& p0, const Vec3& p1, const Vec3& p2, std::int32_t id,
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
inline double box_gap_squared(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
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
inline double test_pair(const Query& q, const Triangles& a, const Triangles& b, Best& best, int& tested,
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

inline Triangles a_triangle(const Query& q, std::int32_t t) {
  const auto& tri = q.a.triangle(t);
  return prepared(q.a_vertex(tri[0]), q.a_vertex(tri[1]), q.a_vertex(tri[2]), t, q.tol);
}
inline Triangles b_triangle(const Query& q, std::int32_t t) {
  const auto& tri = q.b.triangle(t);
  return prepared(q.b_vertex(tri[0]), q.b_vertex(tri[1]), q.b_vertex(tri[2]), t, q.tol);
}

inline Feature feature_of(const TriangleMesh& mesh, std::int32_t t, std::uint8_t active) {
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
inline Containment contained(const Query& q) {
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
inline Vec3 containment_point(const Query& q, const Containment& c) {
  return c.side == 1 ? Vec3(q.rotation * q.b.vertex(c.vertex) + q.translation)
                     : q.a.vertex(c.vertex);
}

inline MeshResult finish(const Query& q, const Pose& pose_a, const Best& best, const Containment& inside) {
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
inline double motion_bound(const TriangleMesh& b, const Mat3& r0, const Vec3& t0, const Mat3& r1,
                    const Vec3& t1) {
  Vec3 lo, hi;
  b.box(0, lo, hi);
  const Vec3 c = 0.5 * (lo + hi);
  const double h = (0.5 * (hi - lo)).stableNorm();
  const Mat3 dr = r1 - r0;
  const double m = dr.norm() * h + (dr * c + (t1 - t0)).stableNorm();
  return m * (1.0 + kMotionBoundUlps * kUnitRoundoff);
}

inline double b_radius(const TriangleMesh& b) {
  Vec3 lo, hi;
  b.box(0, lo, hi);
  return (0.5 * (hi - lo)).stableNorm();
}

// A point of one surface inside the other, closed mesh (contained()'s
// test), in A's frame unscaled; false when there is none.
inline bool contained_point(const Query& q, Vec3& point) {
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
// The mesh queries refuse any other relative_tolerance (core/accuracy.h,
// check_mesh_options), whose message names this one.
static_assert(kHullStopRelative == DistanceOptions{}.relative_tolerance);

// What the meshes' hulls (TriangleMesh::hull()) tell a query.
struct HullBound {
  bool apart = false;   // the hulls are separated: no surface crosses or holds the other
  double lower = 0.0;   // certified lower bound on the meshes' distance (unscaled)
  double stop2 = -1.0;  // squared scaled distance that ends a search (-1: none)
};

inline HullBound hull_bound(Query& q, const DistanceOptions& options, DistanceCache* cache) {
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

}  // namespace proxima::detail::mesh_pair
