// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): the exact convex hull of a solid's points.
#pragma once

#include <span>

#include "hull/affine_frame.h"
#include "hull/half_edges.h"
#include "proxima/core/types.h"

namespace proxima::detail {

// The exact convex hull of `pts` (distinct points, `frame` of dimension 3;
// `scaled` the same points times a power of two), as outward triangles over
// point ids (coplanar neighbours not merged: see face_cleaning.h). Every
// decision is an exact predicate, so every point is inside or on the result
// and every triangle's vertices are input points (see incremental_hull.cpp).
// False only if the points are coplanar.
bool exact_incremental_hull(std::span<const Vec3> pts, std::span<const Vec3> scaled,
                            const Frame& frame, Cycles& out);

}  // namespace proxima::detail
