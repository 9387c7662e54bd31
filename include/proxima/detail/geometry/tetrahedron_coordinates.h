// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Barycentric coordinates of a point in a tetrahedron, the hybrid's test of
// whether the other feature lies inside a four-vertex feature (src/narrowphase/hybrid.cpp).
// In detail/: an internal kernel, here so that the tests can reach it.
#pragma once

#include <array>
#include <optional>

#include "proxima/core/types.h"

namespace proxima::detail {

// Barycentric coordinates of x in the tetrahedron t when x lies inside it
// (signed volumes of the sub-tetrahedra over the whole), nothing otherwise or
// when the tetrahedron is flat.
//
// The signs are compared, not the product ci * whole: volumes are cubes of
// lengths, and at the extents the hybrid runs unscaled (coordinates of
// 2^-64 .. 2^64, with features down to 4 u R long) a small tetrahedron's
// volume times a far point's sub-volume underflows to 0, which passed every
// sign test and put a point far outside the tetrahedron inside it
// (TetrahedronCoordinates.UnderflowingVolumesKeepTheirSigns).
inline std::optional<std::array<double, 4>> tetrahedron_coordinates(const std::array<Vec3, 4>& t,
                                                                    const Vec3& x) {
  const auto volume = [](const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3) {
    return (p1 - p0).cross(p2 - p0).dot(p3 - p0);
  };
  const double whole = volume(t[0], t[1], t[2], t[3]);
  if (whole == 0.0) return std::nullopt;
  std::array<double, 4> c = {volume(x, t[1], t[2], t[3]), volume(t[0], x, t[2], t[3]),
                             volume(t[0], t[1], x, t[3]), volume(t[0], t[1], t[2], x)};
  const bool whole_negative = whole < 0.0;
  for (double& ci : c) {
    if (ci != 0.0 && (ci < 0.0) != whole_negative) return std::nullopt;
    ci /= whole;
  }
  return c;
}

}  // namespace proxima::detail
