// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer (internal): the distance of an answer's witness feature pair
// recomputed in double-double arithmetic (issue 25 §4), for answers near
// the contact band, where a distance computed in double is off by a few
// u R, as much as the band itself, and the status would follow rounding.
#pragma once

#include <cstdint>

#include "core/accuracy.h"
#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// The answers within detail::kExtendedBands contact bands of zero
// (core/accuracy.h) are recomputed: distance() calls
// refine_distance_extended for them.

// What refine_distance_extended changed.
enum class ExtendedOutcome : std::uint8_t {
  unchanged,         // nothing (but a lower bound lowered to the certified gap, see below)
  refined,           // distance, lower bound and `normal`
  lower_bound_only,  // a contact's lower bound 0 raised to the certified gap along `normal`
};

// Recomputes the distance between `result`'s witness features (hull ids
// of a and of b) placed at the world poses, in double-double: the placed
// coordinates R y + t to 2^-104 of their magnitude, the feature pair's
// distance in closed form (vertex, edge and face: the distance of their
// affine hulls, which is the features' own when the pair realizes the
// answer), and a certified lower bound, the support gap along the pair's
// normal computed in double-double over the vertices whose support value
// in double ties with the best. When the two agree (the feature pair is
// right), `result.distance` and `result.lower_bound` take them, rounded,
// `normal` the pair's unit normal (world frame, from A towards B): refined.
// Otherwise the gap, less its rounding bound, is still a lower bound
// whatever the pair: with `certify_lower_bound`
// (DistanceOptions::extended_precision) it replaces the lower bound in
// double (up to rounding) when lower (unchanged); without, it replaces a
// lower bound of 0 when positive (lower_bound_only: a contact answer whose
// algorithm stopped at the band without a support gap), `normal` the
// direction it is certified along. The caller decides the status from a
// refined distance. For a separated or touching `result` with witness
// features.
ExtendedOutcome refine_distance_extended(const ConvexPolytope& a, const Pose& pose_a,
                                         const ConvexPolytope& b, const Pose& pose_b,
                                         DistanceResult& result, Vec3& normal,
                                         bool certify_lower_bound = false);

// The penetration depth of an intersecting `result` (A's frame, as
// finish_signed_distance holds it; `pose_a`, `pose_b` the world poses)
// with DistanceOptions::extended_precision: its Minkowski face, the
// witness features (a face of one body and a vertex of the other, or two
// edges), placed in the world in double-double, gives the face's normal N
// and its offset, the distance of the features' affine hulls; the
// overlap of the supports along N, h_A(N) + h_B(-N) over the vertices tied
// with the double supports (the exact maximizers are among them, as for
// the distance), is an upper bound on the exact depth whatever the face,
// computed to a few 2^-104 of the coordinates. When the two agree (the
// features are the supports along N: a face of A - B), the face's offset
// is its exact value within that error, and when it is within the double
// answer's own tolerance (below) of the double depth, it replaces it:
// `result.depth` the offset rounded, `depth_upper_bound` the overlap plus
// its rounding bound, `normal` (A's frame) N. Otherwise only a tighter
// upper bound along N is kept. The lower bound is the algorithm's: it is
// certified over every face of A - B, which a recomputation of one face
// cannot be. Returns whether the depth was replaced. The tolerance is the
// band of the poses' magnitude bound (wider than the exact one: it only
// widens the window) and the larger of the standard's relative term and
// options.relative_tolerance.
bool refine_depth_extended(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                           const Pose& pose_b, const DistanceOptions& options,
                           DistanceResult& result);

}  // namespace proxima::detail
