// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): hulls of lower dimension, exact: the ends of collinear
// points, the strict convex polygon of coplanar points.
#pragma once

#include <span>
#include <vector>

#include "hull/affine_frame.h"
#include "hull/half_edges.h"
#include "proxima/core/types.h"

namespace proxima::detail {

// The extreme points of exactly collinear, distinct points.
std::vector<Index> segment_ends(std::span<const Vec3> pts, const Frame& frame);
// Which coordinate to drop when projecting the plane of the frame's base
// (see polygon_hull.cpp).
int projection_axis(std::span<const Vec3> pts, std::span<const Vec3> scaled, const Frame& frame);
// Strict convex hull (extreme points only) of coplanar points,
// counter-clockwise in the projection that drops `axis`.
std::vector<Index> polygon_hull(std::span<const Vec3> pts, int axis);

}  // namespace proxima::detail
