// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the expanding polytope's lower bound kept
// across queries of a B that turns (issue 28): the tracked depth under
// rotation.
//
// The cold expansion (expanding_polytope.h) ends with a closed surface P
// whose vertices are points a_i - b_j of M = A - B named by their ids, and
// whose triangles all have positive keys (plane offset less its rounding
// bound): the origin has winding number at least 1 about P, and the ball of
// radius min key is in M. The cache keeps P (ExpansionSurface) with each
// triangle's key and rounded unit normal n at the pose where they were
// last evaluated (the anchor G). At a new pose of B its vertices are the
// same points of the new M, each moved by
//   -((R - R_G) b_j + (t - t_G)) = -((R - R_G) (b_j - c) + shift),
// c B's centroid, shift = (R - R_G) c + (t - t_G) the same for all, so
// along a triangle's exact unit normal n* (within e of n) every point X of
// it has now
//   n*.X >= key - turn - n.shift - e |shift|_1 =: bound,
// turn = |R - R_G|_F max_j |b_j - c| (plus the placements' rounding): the
// plane offset at G (at least key) less how far the point can have moved
// towards the origin along n*. A turn about B's centroid costs only B's
// radius about it, wherever B's frame is.
//
// Winding. Move every vertex along the segment from its place at G to its
// place now: each point of a triangle (the same barycentric combination)
// moves along a segment, and n*.X along it stays at least min(key, bound)
// (linear in the segment's parameter). When every triangle's bound is
// positive, the origin never meets the moving surface, and its winding
// number about it, an integer that changes only there, is still at least 1.
//
// The ball. A triangle's distance from the origin is at least its bound
// (|X| >= n*.X), or, evaluated at this pose, its key now. Every point of
// the ball whose radius is the least of these has winding number at least
// 1 too (the ball does not meet P), so it lies in conv(P), inside M: that
// radius is a certified lower bound on the depth, as the cold one.
//
// Laziness. A pass over the triangles computes their bounds (a dot
// product each); only the triangle of least bound, and then those whose
// bound is below the least key evaluated, are evaluated: those near the
// answer's facet, a handful when B moved a little. The least triangle's
// normal n then gives the upper bound h_M(n) from the supports (hill
// climbing from the triangle's own vertex ids); when n.s is on the
// triangle's plane (the expansion's convergence test) the answer is
// certified as a cold expansion's is (penetration.cpp, solve_expanding).
// Otherwise, and when a bound is not positive, a fresh expansion from the
// octahedron answers and its P is kept (a new anchor); the enumeration
// answers only when that does not certify.
#pragma once

#include "penetration/expanding_polytope.h"

namespace proxima::detail {

// B's pose in A's frame (A's units), the query's unit (a power of two: m's
// inverse is its reciprocal), R (the standard's magnitude, A's units), and
// B's centroid (B's frame) and the largest distance of a vertex of B from
// it.
struct TrackedPose {
  const Pose& b_in_a;
  double unit;
  double magnitude;
  Vec3 b_centroid;
  double b_radius;
};

// The expanding polytope's result at this pose: from the kept surface when
// it answers (`warm`), else from a fresh expansion, whose P is kept in
// `surface` for the next query (cleared when it did not certify); `seed`
// as expand_polytope's.
ExpansionResult track_expansion(const MinkowskiSupport& m, const TrackedPose& pose,
                                ExpansionSurface& surface, int max_iterations,
                                const DepthSeed& seed, bool& warm);

}  // namespace proxima::detail
