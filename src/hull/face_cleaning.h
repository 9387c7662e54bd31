// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): exact cleaning of a hull's triangles into its faces.
#pragma once

#include <span>

#include "hull/half_edges.h"
#include "proxima/core/types.h"

namespace proxima::detail {

// Exact cleaning of a closed triangulated (or polygonal) surface, in the
// coordinates of the given doubles:
//  - neighbouring facets that are exactly coplanar (and lie on either side of
//    their common edge, not folded) become one face: the triangles of a
//    square;
//  - a vertex on exactly two faces and exactly collinear with its two
//    neighbours along them lies inside an edge: it is not an extreme point and
//    is dropped from both cycles (a cube's edge midpoints).
// A vertex strictly inside a face disappears with the merge, because it is on
// no boundary cycle any more.
//
// `proven_convex` tells whether the result is exactly a convex polytope's
// boundary: a closed, consistently oriented surface whose faces are planar
// and whose every edge is exactly convex (x strictly below the plane of the
// face across the edge). A closed surface that is locally convex at every
// edge bounds a convex body, so no global test is needed.
Cycles clean_faces(const Cycles& raw, Index point_count, std::span<const Vec3> pts,
                   std::span<const Vec3> scaled, bool& proven_convex);

}  // namespace proxima::detail
