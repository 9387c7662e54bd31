// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between two segments.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"

namespace proxima {

// a = segment [a0, a1], b = segment [b0, b1]. Derivation (Eberly's "Distance
// Between Two Line Segments in 3D", in our names, the paper's eqs. 16-18).
// A(s) = a0 + s M0, B(t) = b0 + t M1, s, t in [0, 1], D = a0 - b0,
//   Q(s, t) = |A(s) - B(t)|^2 = a s^2 + 2 b s t + c t^2 + 2 d s + 2 e t + f,
//   a = M0.M0, b = -M0.M1, c = M1.M1, d = M0.D, e = -M1.D, f = D.D.
// det = a c - b^2 = |M0 x M1|^2 (Lagrange) is zero iff the segments are
// parallel. Otherwise Q is strictly convex with minimum (sn, tn) / det,
// sn = b e - c d, tn = b d - a e, which Lagrange's identity turns into
// triple products with n = M0 x M1 and m = n x D:
//   sn = -M1.m,   tn = -M0.m,
// accurate to u |D| |n| |M| where b e - c d loses a further factor 1 / sin.
// The signs of sn, tn and of det - sn, det - tn give nine regions of the
// (s, t) plane around the unit square:
//
//     t
//     ^   4  |   3   |  2
//   1 +------+-------+
//         5  |   0   |  1
//   0 +------+-------+
//         6  |   7   |  8
//            0       1  --> s
//
//  0: the unconstrained minimum is inside; it is the answer.
//  1, 3, 5, 7: the minimum over the square is on the edge facing the region
//     (from any other point of the square, the direction towards the
//     unconstrained minimum stays inside the square and decreases Q). That
//     edge is a point-segment problem, e.g. s = 1: the foot of a1 on B.
//  2, 4, 6, 8: the minimum is on one of the two edges through the corner.
//     With the corner's gradient g = H (corner - minimum), the two inward
//     directional derivatives cannot both be negative (H positive definite),
//     so: if Q decreases entering along the t-edge, take that edge, else the
//     s-edge. The derivative along s is M0.(A(s) - B(t)) at the corner.
// Region 0 divides once, by a*det (detail::substitute): t = tn / det, and s
// from the first normal equation a s - (M0.M1) t = -M0.D, i.e. A(s) is the
// exact foot of B(t) on line A. In exact arithmetic this is sn / det; in floating point, for nearly
// parallel segments, it keeps the error of t along the valley of Q, where
// the distance is flat, instead of pulling the two points apart. If rounding
// puts s outside [0, 1] (never in exact arithmetic) the facing edge is taken.
// Parallel segments (det <= tol.min_sin_squared * a c): Q is constant along
// the common direction, so a minimum lies on the boundary of the square, i.e.
// at an end of one segment: the best of the four end-to-segment feet, ties
// going to the smaller feature pair. A segment with |M|^2 <=
// tol.min_length_squared is its first vertex.
template <class S>
ClosestPoints<S> closest_segment_segment(const Vec3T<S>& a0, const Vec3T<S>& a1, const Vec3T<S>& b0,
                                         const Vec3T<S>& b1, const KernelTolerance<S>& tol = {}) {
  const Vec3T<S> m0 = a1 - a0;
  const Vec3T<S> m1 = b1 - b0;
  const S a = detail::norm2(m0);
  const S c = detail::norm2(m1);
  if (a <= tol.min_length_squared) return closest_point_segment(a0, b0, b1, tol);
  if (c <= tol.min_length_squared) return detail::swapped(closest_point_segment(b0, a0, a1, tol));

  // The foot of one end of A on B (edge s = 0 or 1), or of one end of B on A.
  const auto end_of_a = [&](bool at_a1) {
    ClosestPoints<S> r = closest_point_segment(at_a1 ? a1 : a0, b0, b1, tol);
    if (at_a1) std::swap(r.coef_a[0], r.coef_a[1]);
    return detail::finish(r);
  };
  const auto end_of_b = [&](bool at_b1) {
    ClosestPoints<S> r = detail::swapped(closest_point_segment(at_b1 ? b1 : b0, a0, a1, tol));
    if (at_b1) std::swap(r.coef_b[0], r.coef_b[1]);
    return detail::finish(r);
  };

  // A foot clamped to an end of the other segment sits at a corner of the
  // square; the minimum may then lie on the other edge through that corner.
  // In exact arithmetic the region analysis picked the right edge and Q is
  // strictly convex, so the second foot returns the same corner and nothing
  // changes. In floating point, for nearly parallel segments whose (sn, tn)
  // are mostly rounding, the picked edge can miss the valley of Q by a whole
  // segment length (ClosestPointExact.NearlyParallelSegments found one at
  // sine 9u: antiparallel segments overlapping at their ends, off by 2.6% of
  // their length); the corner's other edge then holds the answer. A clamped
  // foot does not divide, so an answer still costs at most one division.
  const auto corner_safe = [&](ClosestPoints<S> r, bool from_a) {
    const std::uint8_t other_side = from_a ? r.active_b : r.active_a;
    if (other_side == 3) return r;  // the foot is inside the other segment
    ClosestPoints<S> other = from_a ? end_of_b(other_side == 2) : end_of_a(other_side == 2);
    return detail::improves(other, r) ? other : r;
  };
  const auto from_end_of_a = [&](bool at_a1) { return corner_safe(end_of_a(at_a1), true); };
  const auto from_end_of_b = [&](bool at_b1) { return corner_safe(end_of_b(at_b1), false); };

  const Vec3T<S> n = detail::cross(m0, m1);
  const S det = detail::norm2(n);
  if (det <= tol.min_sin_squared * a * c) {
    ClosestPoints<S> best = end_of_a(false);
    for (int k = 1; k < 4; ++k) {
      ClosestPoints<S> cand = k == 1 ? end_of_a(true) : end_of_b(k == 3);
      if (detail::improves(cand, best)) best = std::move(cand);
    }
    return best;
  }

  const Vec3T<S> dd = a0 - b0;
  const Vec3T<S> m = detail::cross(n, dd);
  const S sn = -detail::dot(m1, m);
  const S tn = -detail::dot(m0, m);
  const int s_side = sn < S(0) ? 0 : (sn > det ? 2 : 1);  // 0: s < 0, 1: inside, 2: s > 1
  const int t_side = tn < S(0) ? 0 : (tn > det ? 2 : 1);
  if (s_side == 1 && t_side == 1) {  // region 0
    S s, t;
    if (detail::substitute(a, det, tn, S(-detail::dot(m0, dd)), S(-detail::dot(m0, m1)), s, t)) {
      if (t > S(1)) t = S(1);  // tn <= det: an excess is rounding
      if (s < S(0)) return from_end_of_a(false);
      if (s > S(1)) return from_end_of_a(true);
      ClosestPoints<S> r;
      r.point_a = a0 + s * m0;
      r.point_b = b0 + t * m1;
      r.coef_a = {S(1) - s, s, S(0)};
      r.coef_b = {S(1) - t, t, S(0)};
      return detail::finish(r);
    }
  }
  // Regions 5 (s = 0) and 1 (s = 1); region 0 only if |M0|^2 underflowed.
  if (t_side == 1) return from_end_of_a(s_side == 2);
  if (s_side == 1) return from_end_of_b(t_side == 2);  // regions 7 (t = 0) and 3 (t = 1)
  // Corner regions 2, 4, 6, 8: corner (s, t) = (s_side / 2, t_side / 2).
  const Vec3T<S>& corner_a = s_side == 2 ? a1 : a0;
  const Vec3T<S>& corner_b = t_side == 2 ? b1 : b0;
  const S slope_s = detail::dot(m0, corner_a - corner_b);  // dQ/ds / 2 at the corner
  // Entering the square along the t-edge means decreasing s at s = 1 and
  // increasing it at s = 0.
  const bool along_t_edge = s_side == 2 ? slope_s > S(0) : slope_s < S(0);
  return along_t_edge ? from_end_of_b(t_side == 2) : from_end_of_a(s_side == 2);
}

}  // namespace proxima
