// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between a segment and a triangle.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"
#include "proxima/detail/geometry/triangle_foot.h"
#include "proxima/geometry/closest_segment_segment.h"

namespace proxima {

namespace detail {

// A segment crossing a triangle's plane strictly (its ends on opposite sides)
// meets the plane at X = a0 + lambda (a1 - a0), lambda = sa / (sa - sb) with
// sa, sb the ends' signed distances times |n|; lambda is in (0, 1) and the
// difference has no cancellation. The candidate pairs X with the triangle's
// closest point to X: zero distance iff X is in the triangle. In floating
// point X is off the plane by rounding only, and the pair stays a valid
// (point on A, point on B) candidate whatever the rounding. Returns false
// when the ends do not straddle the plane or the triangle is degenerate
// (a segment crossing a degenerate triangle crosses one of its edges).
//
// The heights use n made orthogonal to the triangle's longest edge L,
// n - (n.L / L.L) L, which is n itself in exact arithmetic. In floating point
// the rounding of E0 x E1 has a component along L of relative size u / sin
// (sin: the triangle's smallest angle); it tilts the plane about an axis
// across L and puts the heights of points far along L (a segment running
// along a sliver) off by more than the heights themselves. Removing it
// leaves the tilt about L, which only scales with the distance from L.
// (ClosestPointRegression.SegmentAlongASliverPiercesIt: a sliver of sines
// 1e-8 to 4e-8 pierced by a segment along it at 1.7e-8 radians to its plane,
// whose crossing came out 6.6 units away along the segment.)
template <class S>
bool crossing_candidate(const Vec3T<S>& a0, const Vec3T<S>& a1, const TriangleFrame<S>& f,
                        const KernelTolerance<S>& tol, ClosestPoints<S>& out) {
  if (f.degenerate) return false;
  const Vec3T<S> e2 = f.t2 - f.t1;
  const S l12 = detail::norm2(e2);
  const Vec3T<S>& longest = f.a >= f.c ? (f.a >= l12 ? f.e0 : e2) : (f.c >= l12 ? f.e1 : e2);
  const Vec3T<S> n = f.n - (detail::dot(f.n, longest) / detail::norm2(longest)) * longest;
  const S sa = detail::dot(n, a0 - f.t0);
  const S sb = detail::dot(n, a1 - f.t0);
  if (!((sa < S(0) && sb > S(0)) || (sa > S(0) && sb < S(0)))) return false;
  const S lambda = sa / (sa - sb);
  out.point_a = a0 + lambda * (a1 - a0);
  out.coef_a = {S(1) - lambda, lambda, S(0)};
  const TriangleFoot<S> foot = triangle_foot(f, out.point_a, tol.min_length_squared);
  out.point_b = foot.point;
  out.coef_b = foot.w;
  finish(out);
  return true;
}

template <class S>
ClosestPoints<S> segment_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1, const TriangleFrame<S>& f,
                                  const KernelTolerance<S>& tol) {
  // A piercing at exactly zero distance cannot be improved on, and its pair
  // is minimal: the segment's ends are strictly off the plane, and the
  // triangle side is point_triangle's minimal set. Otherwise the piercing is
  // one candidate among the others: in floating point a sliver's normal is
  // mostly rounding, and its "piercing" may be far from the answer.
  ClosestPoints<S> crossing;
  const bool crosses = crossing_candidate(a0, a1, f, tol, crossing);
  if (crosses && crossing.distance_squared == S(0)) return crossing;

  const Vec3T<S>* v[3] = {&f.t0, &f.t1, &f.t2};
  ClosestPoints<S> best;
  bool have = false;
  const auto consider = [&](ClosestPoints<S>&& cand) {
    if (!have || improves(cand, best)) {
      best = std::move(cand);
      have = true;
    }
  };
  if (crosses) consider(std::move(crossing));
  for (int k = 0; k < 2; ++k) {  // segment ends against the triangle
    const Vec3T<S>& p = k == 0 ? a0 : a1;
    const TriangleFoot<S> foot = triangle_foot(f, p, tol.min_length_squared);
    ClosestPoints<S> cand;
    cand.point_a = p;
    cand.coef_a[static_cast<std::size_t>(k)] = S(1);
    cand.point_b = foot.point;
    cand.coef_b = foot.w;
    consider(std::move(finish(cand)));
  }
  constexpr int kEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (const auto& edge : kEdges) {  // segment against the triangle's edges
    ClosestPoints<S> cand = closest_segment_segment(a0, a1, *v[edge[0]], *v[edge[1]], tol);
    const S w0 = cand.coef_b[0], w1 = cand.coef_b[1];
    cand.coef_b = {S(0), S(0), S(0)};
    cand.coef_b[static_cast<std::size_t>(edge[0])] = w0;
    cand.coef_b[static_cast<std::size_t>(edge[1])] = w1;
    cand.active_b = nonzero_bits(cand.coef_b);
    consider(std::move(cand));
  }
  return best;
}

}  // namespace detail

// a = segment [a0, a1], b = triangle (t0, t1, t2). Derivation by reduction:
// minimize |A(u) - T(s, t)|^2 over the segment's u and the triangle's (s, t).
// At a minimizer with u inside (0, 1) and (s, t) inside the triangle, the
// gradient vanishes: the difference v is orthogonal to the segment and to the
// plane. If v != 0 the segment is parallel to the plane and sliding along it
// keeps the distance until u or (s, t) reaches a boundary, so a minimizer
// exists on the boundary: a segment end against the triangle (two
// point-triangle problems) or the segment against an edge (three
// segment-segment problems). If v = 0 the segment pierces the triangle:
// detected by crossing_candidate, distance 0. The best candidate wins, ties
// going to the smaller feature pair.
template <class S>
ClosestPoints<S> closest_segment_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1,
                                          const Vec3T<S>& t0, const Vec3T<S>& t1,
                                          const Vec3T<S>& t2, const KernelTolerance<S>& tol = {}) {
  return detail::segment_triangle(a0, a1, detail::TriangleFrame<S>(t0, t1, t2, tol), tol);
}

}  // namespace proxima
