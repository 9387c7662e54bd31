// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): see affine_frame.h.
#include "hull/affine_frame.h"

#include "core/power_of_two.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima::detail {

// Exact affine dimension of `pts` (distinct points). p1 is the point farthest
// from p0 and p2 the point farthest from the line p0 p1 (both measured in
// double, only to keep the later projections well conditioned); the decisions
// "collinear" and "coplanar" are exact.
Frame find_frame(std::span<const Vec3> pts, std::span<const Vec3> scaled) {
  Frame frame;
  const auto n = static_cast<Index>(pts.size());
  if (n == 1) return frame;
  const Vec3& s0 = scaled[0];
  Index i1 = 1;
  double best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const double d = (scaled[static_cast<std::size_t>(i)] - s0).squaredNorm();
    if (d > best) best = d, i1 = i;
  }
  frame.dimension = 1;
  frame.base[1] = i1;
  const Vec3& p0 = pts[0];
  const Vec3& p1 = pts[static_cast<std::size_t>(i1)];
  const Vec3 line = scaled[static_cast<std::size_t>(i1)] - s0;
  Index i2 = -1;
  best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (collinear3d(p0, p1, pts[k])) continue;
    const double d = line.cross(scaled[k] - s0).squaredNorm();
    if (d > best) best = d, i2 = i;
  }
  if (i2 < 0) return frame;
  frame.dimension = 2;
  frame.base[2] = i2;
  const Vec3& p2 = pts[static_cast<std::size_t>(i2)];
  for (Index i = 1; i < n; ++i) {
    if (side3d(p0, p1, p2, pts[static_cast<std::size_t>(i)]) != 0) {
      frame.dimension = 3;
      break;
    }
  }
  return frame;
}

}  // namespace proxima::detail
