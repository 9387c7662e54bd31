// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between two points.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"

namespace proxima {

// Derivation: |p - q|^2, both vertices active.
template <class S>
ClosestPoints<S> closest_point_point(const Vec3T<S>& p, const Vec3T<S>& q) {
  ClosestPoints<S> r;
  r.point_a = p;
  r.point_b = q;
  r.coef_a[0] = S(1);
  r.coef_b[0] = S(1);
  return detail::finish(r);
}

}  // namespace proxima
