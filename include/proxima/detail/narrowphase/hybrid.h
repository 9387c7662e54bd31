// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the paper's hybrid algorithm (sections 4-5, as DESIGN.md reads
// it). Works in A's frame: B's vertices are mapped by `b_in_a` on demand and
// support directions are rotated into B's frame, never the vertex arrays.
#pragma once

#include "proxima/core/types.h"
#include "proxima/detail/narrowphase/certified_pair.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// Result points, normal and features are in A's frame. The status is decided
// by the caller's contact band `contact_tolerance` (64 u R plus Ae): the
// hybrid's own answer, cross-checked by Enhanced GJK where it could not
// certify it, and classified as touching or intersecting within the band
// (proxima/detail/narrowphase/contact.h; DistanceResult::second_algorithm says when either
// ran). The same answer as distance(..., Algorithm::hybrid) given the band.
DistanceResult hybrid_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                               const DistanceOptions& options, double contact_tolerance,
                               DistanceCache& cache);

// hybrid_distance from a pair the certified tracked pair evaluated and
// could not certify (`start.valid`; proxima/detail/narrowphase/certified_pair.h): the loop goes on
// from that pair, its closed-form answer and its supports as hints, with
// the answer hybrid_distance gives from the same cache when B did not move
// far. Coordinates in the unscaled range only (where the pair is
// evaluated).
DistanceResult hybrid_distance_from_pair(const ConvexPolytope& a, const ConvexPolytope& b,
                                         const Pose& b_in_a, const DistanceOptions& options,
                                         double contact_tolerance, DistanceCache& cache,
                                         const detail::TrackedPairStart& start);

// The margin query's loop (proxima/query/margin.h): the same iterations, stopped
// at the first proof about `margin` (>= 0): a feature pair whose closest
// points are at most margin + contact_tolerance apart (distance, point_a,
// point_b), or a support gap that certifies lower_bound > margin (the gap
// minus its rounding slack). Otherwise the loop ran to machine precision or
// to the iteration cap (status iteration_cap), and neither may hold. The
// cache is tracked as by hybrid_distance; no features, no contact
// classification, status separated unless capped.
DistanceResult hybrid_within(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                             const DistanceOptions& options, double contact_tolerance,
                             double margin, DistanceCache& cache);

}  // namespace proxima
