// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 5: the GJK baselines, behind the same call as the hybrid.
//   gjk_distance:          classic GJK, brute-force support, cold start.
//   enhanced_gjk_distance: Cameron's Enhanced GJK, hill-climbing support from
//                          the cached hints and the last simplex as a warm
//                          start.
// Both work in A's frame like hybrid_distance.
#pragma once

#include "proxima/polytope.h"
#include "proxima/types.h"

namespace proxima {

DistanceResult gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance);

DistanceResult enhanced_gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                     const Pose& b_in_a, const DistanceOptions& options,
                                     double contact_tolerance, DistanceCache& cache);

}  // namespace proxima
