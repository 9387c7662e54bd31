// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the GJK baselines, behind the same call as the hybrid.
//   gjk_distance:          classic GJK, brute-force support, cold start.
//   enhanced_gjk_distance: Cameron's Enhanced GJK, hill-climbing support from
//                          the cached hints and the last simplex as a warm
//                          start.
// Both work in A's frame like hybrid_distance.
#pragma once

#include <array>
#include <cstdint>

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima {

DistanceResult gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance);

DistanceResult enhanced_gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                     const Pose& b_in_a, const DistanceOptions& options,
                                     double contact_tolerance, DistanceCache& cache);

// Whether the Minkowski-difference points a_k - b_k, k = 0..3 (hull vertex
// ids; a tetrahedron cached by a contact classification) hold the origin
// deeper than contact_tolerance: then the hulls intersect, certified (the
// same certificate as Enhanced GJK's contact search). False for ids out of
// range and for a flat or shallow tetrahedron. O(1).
bool encloses_origin_deeply(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            double contact_tolerance, const std::array<std::int32_t, 4>& ids_a,
                            const std::array<std::int32_t, 4>& ids_b);

}  // namespace proxima
