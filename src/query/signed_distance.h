// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal: the signed distance of an answer the algorithm did not finish
// (intersecting: the penetration depth; iteration cap: its bounds), called
// by distance() after its algorithm answered.
#pragma once

#include "core/accuracy.h"
#include "proxima/core/types.h"
#include "proxima/detail/penetration/penetration.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// Fills the signed distance of `result` (A's frame; distance() maps it to
// the world afterwards) when result.status is not separated. Intersecting:
// with options.penetration, the penetration depth of a and b (b_in_a,
// rigid) replaces the answer's points, normal and features, tracked in
// cache.penetration (allocated here on the first overlap). Touching: with
// options.penetration, the depth too, and a depth beyond the contact band
// turns the answer into intersecting (the contact classification can call
// an overlap of coplanar faces touching). Iteration cap: the bounds.
// A touching answer turns intersecting exactly when the depth exceeds
// the band of the exact R_w (the world poses pose_a, pose_b give it): its
// O(1) certificate (an overlap of the supports within the band) is
// checked against a lower bound on that band first, the band itself
// computed (O(N)) only when that does not decide.
void finish_signed_distance(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                            const Pose& pose_b, const Pose& b_in_a, const DistanceOptions& options,
                            DistanceCache& cache, DistanceResult& result);

// Whether tracked_overlap may answer for the pair: its last depth was
// penetrating, with options.penetration and the hybrid, without
// extended_precision (whose depth finish_signed_distance recomputes).
// Inline: distance() asks it of every query, and a pair that overlapped
// once and separated since pays only this test (not a call that fails).
inline bool overlap_trackable(const DistanceOptions& options, const DistanceCache& cache) {
  const PenetrationCache* depth_cache = cache.penetration.get();
  return depth_cache != nullptr && depth_cache->last_status == PenetrationStatus::intersecting &&
         options.penetration && options.algorithm == Algorithm::hybrid &&
         !options.extended_precision;
}

// Before distance()'s algorithm runs, for a pair that distance() found
// overlap_trackable (a precondition, not tested again), the tracked depth alone
// (penetration_depth_tracked). When it certifies an overlap deeper than
// `band` (distance()'s contact band, at least the exact one), `result` is
// the intersecting answer the algorithm and finish_signed_distance would
// give (A's frame; no iterations) and the function returns true; else
// false, and the pair is not tried again until its depth is penetrating.
bool tracked_overlap(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                     double band, DistanceCache& cache, DistanceResult& result);

}  // namespace proxima::detail
