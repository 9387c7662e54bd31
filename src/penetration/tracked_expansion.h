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
// triangle's key at the pose where it was last evaluated in full (the
// anchor G). At a new pose of B the vertices are the same points of the new
// M, each moved from its place at G by at most
//   moved = |R - R_G|_F max_j |b_j| + |t - t_G|
// (plus their placement's rounding): (R - R_G) b_j + (t - t_G).
//
// Winding. Move every vertex along the segment from its place at G to its
// place now: each point of a triangle (the same barycentric combination)
// moves along a segment of length at most `moved`, so it stays at distance
// at least key_G - moved > 0 from the origin when the least key at G
// exceeds `moved`. The origin never meets the moving surface, and its
// winding number, an integer that changes only there, is still at least 1.
//
// The ball. Every point of a triangle is now within `moved` of a point of
// the same triangle at G, so its distance from the origin is at least
// key_G - moved; or, evaluated at this pose, at least its plane's offset
// less rounding (its key now). Every point of the ball whose radius is the
// least of these bounds has winding number at least 1 too (the ball does
// not meet P), so it lies in conv(P), inside M: that radius is a certified
// lower bound on the depth, as the cold one.
//
// Laziness. The triangles are sorted by key at G, so the least bound is
// found by evaluating only the triangles whose key_G - moved is below the
// least key evaluated so far: those near the answer's facet, a handful when
// B turned a little. The least triangle's normal n then gives the upper
// bound h_M(n) from the supports (hill climbing from the triangle's own
// vertex ids); when n.s is on the triangle's plane (the expansion's
// convergence test) the answer is certified as a cold expansion's is
// (penetration.cpp, solve_expanding). Otherwise, and when `moved` reached
// the least key at G, the expansion goes on from P placed at this pose
// (every key evaluated again: a new anchor), and falls back to the cold
// query only when that does not certify.
#pragma once

#include "penetration/expanding_polytope.h"

namespace proxima::detail {

// B's pose in A's frame (A's units), the query's unit (a power of two: m's
// inverse is its reciprocal), R (the standard's magnitude, A's units), and
// the largest distance of a vertex of B from B's origin (A's units) or a
// bound above it.
struct TrackedPose {
  const Pose& b_in_a;
  double unit;
  double magnitude;
  double b_reach;
};

// The expanding polytope's result at this pose, from the kept surface when
// there is one (from the octahedron when not), keeping P in `surface` for
// the next query (cleared when the expansion did not certify, or when P
// grew past kMaxSurfaceTriangles). `warm` tells whether the kept surface
// answered without an expansion (the lazy path).
ExpansionResult track_expansion(const MinkowskiSupport& m, const TrackedPose& pose,
                                ExpansionSurface& surface, int max_iterations, bool& warm);

}  // namespace proxima::detail
