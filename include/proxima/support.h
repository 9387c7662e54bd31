// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 4: support functions. The support point of a set in direction d is
// argmax over its vertices of d.x. Two twins: a brute-force scan (the obvious
// one, O(N)) and hill climbing over the vertex adjacency from a hint vertex
// (near O(1) when the hint is the previous answer). Tests compare them.
#pragma once

#include "proxima/polytope.h"

#include <span>

namespace proxima {

// Index of a vertex maximizing dir.dot(vertex); the first one on ties.
// `vertices` must not be empty.
int support_brute_force(std::span<const Vec3> vertices, const Vec3& dir);

// Index of a vertex maximizing dir.dot(vertex), found by walking from `hint`
// to a neighbour with a strictly larger dot product until none is larger. On
// a convex polytope with its true edges, a vertex with no improving edge is a
// global maximum (the tangent cone at a vertex is spanned by its edges), so
// the walk is exact, plateaus of coplanar faces included. `hint` out of range
// is treated as vertex 0.
int support_hill_climb(const ConvexPolytope& polytope, const Vec3& dir, int hint);

}  // namespace proxima
