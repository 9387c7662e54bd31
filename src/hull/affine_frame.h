// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): the exact affine dimension of a point set and a
// well-spread base of it.
#pragma once

#include <array>
#include <span>

#include "hull/half_edges.h"
#include "proxima/core/types.h"

namespace proxima::detail {

struct Frame {
  int dimension = 0;
  // Indices into the unique point list: p0, p1 (dimension >= 1), p2 (>= 2).
  std::array<Index, 3> base = {0, 0, 0};
};

// Exact affine dimension of `pts` (distinct points). p1 is the point farthest
// from p0 and p2 the point farthest from the line p0 p1 (both measured in
// double, only to keep the later projections well conditioned); the decisions
// "collinear" and "coplanar" are exact.
Frame find_frame(std::span<const Vec3> pts, std::span<const Vec3> scaled);

}  // namespace proxima::detail
