// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the contact unit the algorithms share. What an algorithm's first
// answer may still need before it is the query's answer, in A's frame like
// the algorithms themselves:
//   - a separated answer whose certificate (distance - lower_bound) is wider
//     than the rounding of its own arithmetic is cross-checked by Enhanced
//     GJK from a cold start (cross_check_separation);
//   - an answer within the contact band is classified: touching, or
//     intersecting when a tetrahedron of Minkowski-difference points holds
//     the origin deeper than the band (classify_contact).
// hybrid_distance calls both, so it keeps the contract of
// distance(..., Algorithm::hybrid); the query layer (distance.h) only adds
// the pose contract, the band of the accuracy standard and the world frame.
#pragma once

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// Slack of a certificate (distance - lower_bound) in units of u R, R the
// magnitude of the coordinates the algorithm computed with: the lower
// bound's own rounding is a few u R, so a wider gap means the answer was
// not certified at machine precision.
inline constexpr double kCertificateUlps = 32.0;

// Whether `result` (separated) needs the cross-check: its certificate is
// wider than relative_tolerance * distance + kCertificateUlps u magnitude.
inline bool needs_cross_check(const DistanceResult& result, const DistanceOptions& options,
                              double magnitude) {
  return result.status == Status::separated &&
         result.distance - result.lower_bound > options.relative_tolerance * result.distance +
                                                    kCertificateUlps * kUnitRoundoff * magnitude;
}

// Cross-checks a separated `result` that needs it: Enhanced GJK runs from
// its own cold start with the same band; the closer of the two pairs of
// points (both lie in the hulls) is kept, with the larger of the two lower
// bounds (capped by the distance kept). Sets result.second_algorithm.
void cross_check_separation(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance,
                            DistanceResult& result);

// Classifies a `result` whose status is touching (distance within the band
// `contact_tolerance`): Enhanced GJK's contact search decides (a direction
// whose support gap is within the band: touching; a polytope inside A - B
// holding a ball of the band's radius around the origin: intersecting;
// undecided within the iteration cap: touching, the distance being in the
// band anyway). An intersecting result gets distance 0 and both points at
// the midpoint of the touching pair.
//
// Tracking: the search's last tetrahedron around the origin is kept in
// cache.contact_a/contact_b; while it still holds the origin deeper than the
// band, intersection is certified in O(1) without a search (the certificate
// the search ends with, encloses_origin_deeply in gjk.h). Otherwise the
// search starts from its last simplex and the support hints of `cache`.
void classify_contact(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                      const DistanceOptions& options, double contact_tolerance,
                      DistanceCache& cache, DistanceResult& result);

}  // namespace proxima
