// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the tracked query's certified pair, the
// hybrid's fast path. When the bodies moved a little, the closest features
// of the last answer (the cache's pair) are most often still the closest:
// their closed-form distance is the answer, and one support check per body
// proves it. Its slow twin is the full hybrid (hybrid.h) from the same
// cache; tests/narrowphase/hybrid_test.cpp compares them.
#pragma once

#include <array>
#include <cstdint>

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// Rounding slack of the certified pair's lower bound, in units of u R (R:
// the largest coordinate magnitude in A's frame, |p|_2 <= sqrt(3) R for
// every vertex p there). The exact bound is (w.b* - w.a*) / |w| for the
// computed direction w; what is computed is fl(fl(w.b*) - fl(w.a*)):
//   each support value, a dot product of three terms: gamma_3 |w|_2 |p|_2
//     <= 3.01 u (1 + 4 u) sqrt(3) R < 5.3 u R, twice: 10.6 u R;
//   the subtraction: u times the gap, at most the distance of two points of
//     coordinates within R, 2 sqrt(3) R: 3.5 u R;
//   |w| = 1 within 4 u (a normalized vector): dividing by it moves the gap
//     by 4 u times the gap, at most 14 u R.
// Together below 28.1 u R; 32 leaves room. It covers the rounding of the
// support values only: that a* and b* are the supports is the hill climb's
// (a vertex no neighbour of which is computed higher), exact but for ties
// within the rounding of w.x, as in the hybrid's own termination test
// (docs/accuracy.md). Pinned by CertifiedPair.* (the exact oracle on the
// lower bound).
inline constexpr double kCertifiedGapUlps = 32.0;

// What a declined certificate already computed, for the hybrid's loop to
// go on from (hybrid_distance_from_pair, hybrid.h) instead of computing it
// again: the cached pair reduced to its active vertices (ids and points in
// A's frame), its closed-form answer, and the pair's search direction with
// both supports along it, the loop's first pass. Filled only when the pair was
// evaluated and B did not move far since the cache's pose (else the loop's
// cold start is the better one).
//
// Its fields but `valid` are left uninitialized (written together when the
// pair is declined): every tracked query builds one.
struct TrackedPairStart {
  std::array<std::int32_t, 3> id_a;
  std::array<std::int32_t, 3> id_b;
  std::array<Vec3, 3> p_a;
  std::array<Vec3, 3> p_b;
  int n_a;
  int n_b;
  // The pair's closed-form answer: the closest points and their squared
  // distance (the pair is already reduced to its active vertices).
  double distance_squared;
  Vec3 point_a;
  Vec3 point_b;
  // With has_direction, the pair's search direction and the supports
  // along it; else the cache's hints.
  Vec3 direction;
  std::int32_t support_a;
  std::int32_t support_b;
  bool has_direction;
  bool valid = false;
};

// The answer of hybrid_distance from the cache's feature pair alone, when
// that pair certifies it; false otherwise, and then `cache` is unchanged,
// `result` holds nothing of use, and `start` what the loop can go on from
// when `start.valid` (the caller runs hybrid_distance_from_pair with it, or
// hybrid_distance from the same cache).
//
// Certified means, in A's frame with B placed by `b_in_a`: the cached
// features (as the hybrid stores them) give the closest points XA, XB in
// closed form (d = |XB - XA|); along the hybrid's search direction w of
// that pair, A's support a* and B's b* (hill climbs from the cached hints,
// each a vertex none of whose neighbours is higher) bound the distance from
// below by w.b* - w.a*, and the hybrid's termination test holds:
// d - (w.b* - w.a*) <= relative_tolerance d + kTerminationGapUlps u R. The
// hybrid's loop would stop there too, at its first pass, with the same pair.
// Declined: a cache without a complete pair, R outside the hybrid's unscaled
// range, distances within kExtendedBands contact bands of touching (the
// query's exact-band and extended refinements decide those), and the
// options the query refines otherwise (another algorithm,
// extended_precision).
//
// On success `result` (default-constructed by the caller) holds a separated
// answer in A's frame: distance d, lower_bound the support gap less its
// rounding slack (kCertifiedGapUlps u R), the closest
// points, normal (XB - XA) / d, the witness features by the rule all
// algorithms share (witness_features.h), no iterations; the cache holds the
// pair (reduced to its active vertices), the supports as hints, the faces
// and B's pose, as the hybrid leaves them.
bool certified_tracked_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                const Pose& b_in_a, const DistanceOptions& options,
                                double contact_tolerance, DistanceCache& cache,
                                DistanceResult& result, TrackedPairStart& start);

}  // namespace proxima::detail
