// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between a point and a triangle.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"
#include "proxima/detail/geometry/triangle_foot.h"

namespace proxima {

// a = point p, b = triangle (t0, t1, t2). Derivation: see detail::triangle_foot
// (Eberly's seven regions with triple-product numerators, one division). A
// triangle with det = a c - b^2 <= tol.min_sin_squared * a c is its longest
// edge (a point if that edge is shorter than the length tolerance).
template <class S>
ClosestPoints<S> closest_point_triangle(const Vec3T<S>& p, const Vec3T<S>& t0, const Vec3T<S>& t1,
                                        const Vec3T<S>& t2, const KernelTolerance<S>& tol = {}) {
  const detail::TriangleFrame<S> f(t0, t1, t2, tol);
  const detail::TriangleFoot<S> foot = detail::triangle_foot(f, p, tol.min_length_squared);
  ClosestPoints<S> r;
  r.point_a = p;
  r.coef_a[0] = S(1);
  r.point_b = foot.point;
  r.coef_b = foot.w;
  return detail::finish(r);
}

}  // namespace proxima
