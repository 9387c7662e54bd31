// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between a point and a segment.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"

namespace proxima {

// a = point p, b = segment [s0, s1]. Derivation: the segment is s0 + t M,
// t in [0, 1], M = s1 - s0; Q(t) = |s0 + t M - p|^2 = a t^2 + 2 d t + f with
// a = M.M, d = M.(s0 - p). Q'(t) = 0 at t = -d / a; Q is convex, so the
// constrained minimum is that t clamped to [0, 1], decided by comparing -d
// with 0 and a before the only division (detail::edge_foot). A segment with
// a <= tol.min_length_squared is its first vertex.
template <class S>
ClosestPoints<S> closest_point_segment(const Vec3T<S>& p, const Vec3T<S>& s0, const Vec3T<S>& s1,
                                       const KernelTolerance<S>& tol = {}) {
  ClosestPoints<S> r;
  r.point_a = p;
  r.coef_a[0] = S(1);
  const detail::EdgeFoot<S> e = detail::edge_foot(p, s0, s1, tol.min_length_squared);
  r.point_b = e.point;
  detail::put_edge(r.coef_b, 0, 1, e.lambda);
  return detail::finish(r);
}

}  // namespace proxima
