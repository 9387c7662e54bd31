// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The distance between two compound bodies (proxima/shape/compound.h): the
// minimum of the convex query over piece pairs, by branch and bound over the
// pieces' hierarchies, with the caller-owned cache that tracks it.
#pragma once

#include <cstdint>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/shape/compound.h"

namespace proxima {

// Coherence between compound queries of one pair, owned by the caller.
// Default-constructed means cold. It keeps the best piece pair of the last
// answer (tried first: its distance is the first upper bound of the branch and
// bound) and the feature cache of each near piece pair, so that a tracked
// query of a compound costs about one tracked convex query per near pair. A
// cache from another pair of bodies is range-checked: at worst slower, never
// wrong.
struct CompoundCache {
  struct Entry {
    std::int32_t piece_a = -1;
    std::int32_t piece_b = -1;
    DistanceCache cache;
  };
  std::int32_t piece_a = -1;  // best pair of the last answer
  std::int32_t piece_b = -1;
  std::vector<Entry> near;  // sorted by (piece_a, piece_b); bounded in size
  bool is_cold() const { return piece_a < 0 && near.empty(); }
  void reset() { *this = CompoundCache{}; }
};

// The convex result of the closest piece pair (points and normal in world
// frame, features in the pieces' hull ids), plus which pieces and how much
// work the branch and bound did.
struct CompoundResult : DistanceResult {
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
  int pairs_tested = 0;  // convex queries run
};

// Minimum distance between two compound bodies. Status is the convex
// status of the reported pair. The distance is the twin's within the
// accuracy standard, R being the largest coordinate of both bodies' placed
// vertices; which pair is reported may differ from the twin's when two
// pairs are that close. Throws InvalidInput for non-finite poses or bad
// options.
//
// Signed distance: the minimum over piece pairs of the convex signed
// distance (the piecewise definition FCL and Coal use for unions). When
// pieces overlap it is minus the depth of the deepest overlapping piece
// pair, reported with that pair's deepest points, normal and features. The
// certificate is the whole search's: the lower bounds are the least over
// the tested pairs' (a pruned pair's sphere bound lies above them), the
// signed upper bound the least of the tested pairs' signed upper bounds;
// the twin's is the same over every pair. It is NOT the
// penetration depth of the two unions: moving B by that pair's depth along
// its normal separates that pair but may leave other pieces overlapping
// (the union's depth is at least every pair's depth). With the depth
// (DistanceOptions::penetration, the default) the search goes on after the
// first overlapping pair, pruning node pairs whose sphere bound (a lower
// bound on the signed distance as well) cannot beat the deepest pair found;
// without it, it stops at the first overlapping pair as a status query
// should.
CompoundResult distance(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                        const Pose& pose_b, const DistanceOptions& options = {},
                        CompoundCache* cache = nullptr);

// The slow, obvious twin: the convex query on every piece pair, cold, and the
// minimum of the signed distance (ties broken by an intersecting pair first,
// then by the smaller (piece_a, piece_b)). For tests and benchmarks.
CompoundResult distance_all_pairs(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                                  const Pose& pose_b, const DistanceOptions& options = {});

}  // namespace proxima
