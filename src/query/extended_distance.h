// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer (internal): the distance of an answer's witness feature pair
// recomputed in double-double arithmetic (issue 25 §4), for answers near
// the contact band, where a distance computed in double is off by a few
// u R, as much as the band itself, and the status would follow rounding.
#pragma once

#include "core/accuracy.h"
#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// The answers within detail::kExtendedBands contact bands of zero
// (core/accuracy.h) are recomputed: distance() calls
// refine_distance_extended for them.

// Recomputes the distance between `result`'s witness features (hull ids
// of a and of b) placed at the world poses, in double-double: the placed
// coordinates R y + t to 2^-104 of their magnitude, the feature pair's
// distance in closed form (vertex, edge and face: the distance of their
// affine hulls, which is the features' own when the pair realizes the
// answer), and a certified lower bound, the support gap along the pair's
// normal computed in double-double over the vertices whose support value
// in double ties with the best. When the two agree (the feature pair is
// right), `result.distance` and `result.lower_bound` take them, rounded,
// `normal` the pair's unit normal (world frame, from A towards B), and it
// returns true; otherwise `result` is unchanged, but for its lower bound
// when `certify_lower_bound` (DistanceOptions::extended_precision): the
// gap is a lower bound whatever the pair, and then replaces the one in
// double (up to rounding) when it is lower. The caller decides the status
// from the new distance. For a separated or touching `result` with
// witness features.
bool refine_distance_extended(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                              const Pose& pose_b, DistanceResult& result, Vec3& normal,
                              bool certify_lower_bound = false);

}  // namespace proxima::detail
