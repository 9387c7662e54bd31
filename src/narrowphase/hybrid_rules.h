// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the rules the hybrid's loop
// (hybrid.cpp) and its certified tracked pair (certified_pair.cpp) share,
// one definition each, so that where both answer they answer alike: the
// range of magnitudes run unscaled, the search direction of a feature pair,
// B's support direction in B's frame, the witness rule's far-edge test,
// and the staleness test of a cached pair.
#pragma once

#include <cmath>

#include "narrowphase/witness_features.h"
#include "proxima/core/types.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// Range of R (the largest coordinate magnitude in A's frame) in which the
// algorithm runs on the given coordinates. Squared lengths overflow from
// R ~ 1e154 on (inf - inf: NaN) and underflow to subnormals or 0 from
// R ~ 1e-154 down (answers off by 1e-5, then distances of 0); the kernels'
// length^4 and length^6 terms are only valid for extents within 1e-75 ..
// 1e75 (closest_point.h). Outside this range every coordinate is
// multiplied by the power of two that brings R into [1/2, 1): exact, so the
// answer is the same one the unscaled algorithm would give in exact range.
// 2^+-64 leaves a wide margin both ways and sends the paper's stress cases
// (cubes at 1e39, tetrahedra of 1e-23) and the accuracy suite's 1e-20 ..
// 1e20 scales through the scaled path too, where the tests compare them
// with the oracle. DistanceRegression.ScalesFrom1eMinus300To1e300 pins it.
inline constexpr double kMinUnscaled = 0x1p-64;
inline constexpr double kMaxUnscaled = 0x1p64;

// -(R^T w): the direction of B's support search in B's frame. Entry j is
// column j of R (contiguous) dotted with w, rounded as Eigen rounds
// -(R^T w), (c0 w0 + c1 w1) + c2 w2, then negated (exact): the same bits
// (2e6 random rotations and directions compared). Written out because
// Eigen's transposed product takes more instructions for the same bits, on
// every tracked query (bench/tracked_instructions under callgrind).
[[gnu::always_inline]] inline Vec3 minus_transpose_times(const Mat3& r, const Vec3& w) {
  const double* c = r.data();  // column-major: column j at c + 3 j
  const auto dot = [&](const double* col) {
    return -((col[0] * w[0] + col[1] * w[1]) + col[2] * w[2]);
  };
  return Vec3(dot(c), dot(c + 3), dot(c + 6));
}

// Unit direction from A towards B, as accurate as the features allow. The
// difference XB - XA of two computed points carries an absolute error of a
// few u R, so for nearly touching bodies (d << R) its direction is off by
// u R / d: enough to pick wrong support points on a needle or a sliver. A
// face normal or the cross product of two edges is accurate to a few u
// whatever d is, so those are used where the pair is vertex-face or
// edge-edge; XB - XA where it is exact (vertex-vertex).
//
// What matters for the support search is the error of the direction along
// the bodies' long dimensions: tilted by e, a direction moves the support
// value of a vertex a length L away by e L, and on a needle of thickness h
// the wrong end of the needle wins once e L > h. Two such errors are removed
// by projection, which is exact in theory (the true direction is orthogonal
// to the edge or to the face's edges):
//  * vertex-edge: XB - XA is orthogonal to the edge; its rounding is not.
//    Removing its component along the edge leaves an error across the edge
//    only, which a support value sees times the body's thickness.
//  * vertex-face: the cross product of a sliver's edges is off by u / sin
//    (sin: the face's smallest angle) in a direction that tilts it along the
//    face; its component along the longest edge is removed, as in
//    crossing_candidate (closest_point.h).
// (DistanceRegression.PointOnTheSurfaceOfANeedle: a point on an edge of a
// needle 1.6 long and 1e-9 thick stopped on the needle's inner diagonal at
// 1.7e-9 with lower bound 0, the direction's 3e-7 tilt along the axis
// making the diagonal's own ends the support points.)
inline Vec3 across(const Vec3& x, const Vec3& edge) {
  const double ee = edge.squaredNorm();
  return ee > 0.0 ? Vec3(x - (x.dot(edge) / ee) * edge) : x;
}

// The normal of triangle t (unnormalized, either orientation), without its
// rounding component along the longest edge (see search_direction).
inline Vec3 face_direction(const Vec3* t) {
  const Vec3 e0 = t[1] - t[0];
  const Vec3 e1 = t[2] - t[0];
  const Vec3 e2 = t[2] - t[1];
  const double l0 = e0.squaredNorm();
  const double l1 = e1.squaredNorm();
  const double l2 = e2.squaredNorm();
  const Vec3& longest = l0 >= l1 ? (l0 >= l2 ? e0 : e2) : (l1 >= l2 ? e1 : e2);
  return across(e0.cross(e1), longest);
}

// The direction for a pair of features given by their points in A's frame
// (`pa`: na of them, `pb`: nb), w = XB - XA and d = |w| > 0.
[[gnu::always_inline]] inline Vec3 search_direction(const Vec3* pa, int na, const Vec3* pb, int nb,
                                                    const Vec3& w, double d) {
  Vec3 n;
  if (na == 1 && nb == 3) {
    n = face_direction(pb);
  } else if (na == 3 && nb == 1) {
    n = face_direction(pa);
  } else if (na == 2 && nb == 2) {
    n = (pa[1] - pa[0]).cross(pb[1] - pb[0]);
  } else if (na + nb == 3) {
    // Vertex-edge: the edge has length above the kernel's tolerance.
    n = across(w, na == 2 ? Vec3(pa[1] - pa[0]) : Vec3(pb[1] - pb[0]));
  } else {
    return w / d;
  }
  const double along = n.dot(w);
  const double length = n.norm();
  // Parallel edges (or a face seen edge-on): no better direction than w.
  if (!(length > 0.0) || along == 0.0) return w / d;
  return (along > 0.0 ? 1.0 : -1.0) / length * n;
}

// How far, in witness bands, the closest point x on a two-vertex feature
// must be from both of its vertices in A's frame for rule 1 of the witness
// rule (witness_features.h) to keep both in the hull's own frame too. There
// the point is R^T (x - t) and the vertices y exact, while here they are
// R y + t: the two distances differ by the rounding of both maps (about
// 10 u R each) and by R's departure from orthonormality, |(I - R^T R) y|:
// R = R_a^T R_b, two rotations within kOrthonormalUlps u of orthonormal
// (pose.h) and a rounded product, so R^T R - I has entries below about
// 70 u and that term stays below about 210 u R (R >= |y|, the algorithm's
// bound). Against a band of 16 u R (witness_band), 64 bands (1024 u R)
// leave all of it far behind, so the decision is the one the hull's frame
// would make; nearer points take the general path, which makes it there.
inline constexpr double kWitnessFarBands = 64.0;

// Whether x is farther than `far` from both vertices p0 and p1 of an edge,
// at magnitudes where squaring does not underflow or overflow (the range in
// which witness_feature's edge case runs).
inline bool far_from_both_ends(const ConvexPolytope& poly, const Vec3& p0, const Vec3& p1,
                               const Vec3& x, double far) {
  const double far2 = far * far;
  return detail::squares_are_safe(poly.scale()) && (p0 - x).squaredNorm() > far2 &&
         (p1 - x).squaredNorm() > far2;
}

// A cache whose pose is further than this share of the bodies' size from
// the query's is taken for stale (see moved_far).
inline constexpr double kStaleMotion = 0.5;

// Whether B moved so far relative to A since the cache's query that its
// feature pair says nothing any more (a planner sampling unrelated
// configurations with one cache per pair): a bound on how far any point of
// B moved, |t - t'| + ||R - R'||_F max|y|, beyond a share of the bodies'
// size. Such a warm start costs more iterations than a cold one
// (bench/distance_bench WarmRandom), so the cold start is taken.
// A cache without a pose (rotation zero: cold, or filled by GJK) moved
// far. The test is paid by every query, so it is kept to a norm and a
// Frobenius distance; a heuristic for speed only: any start ends in the
// same certified answer.
[[gnu::always_inline]] inline bool moved_far(const ConvexPolytope& a, const ConvexPolytope& b,
                                             const Pose& b_in_a, const DistanceCache& cache) {
  const double turn2 = (b_in_a.rotation - cache.rotation).squaredNorm();
  const double shift = (b_in_a.translation - cache.translation).norm();
  const double size = a.bounding_radius() + b.bounding_radius();
  const double reach = std::sqrt(3.0) * b.scale();  // >= max |y| over B
  // A quiet comparison: a garbage cache may hold NaN (moved far, then).
  return !std::islessequal(shift + std::sqrt(turn2) * reach, kStaleMotion * size);
}

// The witness features of the answer (witness_features.h) from the final
// pair (fa, fb) and its closest points `loc` (local units; `unit` maps them
// back), and the faces the cache keeps for the next query. One rule for the
// hybrid's loop and the certified tracked pair (certified_pair.cpp, unscaled,
// unit 1): Features is either's feature set (ids, points in A's frame, n).
template <bool kScaled, class Features>
[[gnu::always_inline]] inline void witness_pair(const ConvexPolytope& a, const ConvexPolytope& b,
                                                const Pose& b_in_a, const Features& fa,
                                                const Features& fb,
                                                const ClosestPoints<double>& loc,
                                                double r_local, double unit, bool locate,
                                                DistanceCache& cache, DistanceResult& result) {
  const Mat3& rot = b_in_a.rotation;
  const Vec3& tr = b_in_a.translation;
  const double witness_band = detail::witness_band(r_local * unit);
  // The tracked edge: rule 1 keeps both vertices when the closest point is
  // farther than the band from each of them, and rule 2 needs their ids
  // only. A's frame is A's own (unscaled: the same arithmetic as
  // witness_feature's); B's point is tested in A's frame, with the margin
  // of kWitnessFarBands. Otherwise the point is mapped into its hull's frame
  // and the whole rule applied there.
  const auto edge_far_from_ends = [&](const ConvexPolytope& poly, const Features& f,
                                      const Vec3& x, double bands, Feature& out) {
    if constexpr (kScaled) {
      return false;
    } else {
      return f.n == 2 &&
             detail::far_from_both_ends(poly, f.p[0], f.p[1], x, bands * witness_band) &&
             detail::hull_edge(poly, f.id[0], f.id[1], out);
    }
  };
  if (!edge_far_from_ends(a, fa, loc.point_a, 1.0, result.feature_a)) {
    result.feature_a = detail::witness_feature(
        a, std::span(fa.id.data(), static_cast<std::size_t>(fa.n)), witness_band, cache.face_a,
        [&] {
          return detail::WitnessPoint{Vec3(loc.point_a * unit), result.normal};
        },
        locate);
  }
  if (!edge_far_from_ends(b, fb, loc.point_b, kWitnessFarBands, result.feature_b)) {
    result.feature_b = detail::witness_feature(
        b, std::span(fb.id.data(), static_cast<std::size_t>(fb.n)), witness_band, cache.face_b,
        [&] {
          // The outward side only matters on a polygon.
          return detail::WitnessPoint{
              Vec3(rot.transpose() * (loc.point_b * unit - tr)),
              b.dimension() == 2 ? Vec3(-(rot.transpose() * result.normal)) : Vec3::UnitX()};
        },
        locate);
  }
  cache.face_a = result.feature_a.face;
  cache.face_b = result.feature_b.face;
}

}  // namespace proxima::detail
