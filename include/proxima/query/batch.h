// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: batch queries. Many independent distance() (or
// within_margin(), intersects(): below) calls at once, spread
// over a TBB thread pool. Result k is exactly (bit for bit) what
//   distance(*pairs[k].a, poses_a[k], *pairs[k].b, poses_b[k], options, &caches[k])
// returns: the batch only decides which thread computes it.
//
//   std::vector<proxima::BatchPair> pairs = ...;        // polytopes shared freely
//   std::vector<proxima::DistanceCache> caches(pairs.size());  // cold; keep them
//   std::vector<proxima::DistanceResult> results(pairs.size());
//   for each step:
//     proxima::distance_batch(pairs, poses_a, poses_b, results, caches);  // tracking
//
// Thread safety:
// - A ConvexPolytope is immutable after construction: the same polytope may
//   appear in any number of pairs and be used by other threads at the same
//   time, without locks.
// - caches[k] and results[k] belong to pair k. distance_batch hands each
//   index k to exactly one task, so within one call every cache is used by
//   one thread at a time and nothing is shared that is written. Across calls
//   the caller keeps the caches (tracking); the caller must not touch the
//   spans' elements from another thread while a call runs, nor run two calls
//   at once that share a cache or a result element.
// - Distinct calls with distinct caches and results may run concurrently.
//
// Threads: `threads == 0` runs in the caller's current TBB arena (by default
// TBB's global one, all cores; a caller inside its own tbb::task_arena keeps
// its limit). `threads == 1` runs every query in the calling thread.
// `threads > 1` runs in a dedicated arena of that many threads (the calling
// thread among them), created by a calling thread's first such call and
// kept for its next ones; each loop runs under the caller's floating-point
// settings of that moment.
#pragma once

#include <span>

#include "proxima/core/types.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/margin.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// One pair of a batch. Both pointers must be non-null and outlive the call.
struct BatchPair {
  const ConvexPolytope* a = nullptr;
  const ConvexPolytope* b = nullptr;
};

// results[k] = distance(*pairs[k].a, poses_a[k], *pairs[k].b, poses_b[k],
// options, caches.empty() ? nullptr : &caches[k]) for every k.
//
// `caches` is either empty (every query cold, nothing kept) or one cache per
// pair, read and updated in place. poses_a, poses_b and results must have
// pairs.size() elements.
//
// Throws InvalidInput, before any result or cache is written, for a size
// mismatch, a null polytope at index k, a non-finite pose at index k or a
// negative thread count; each message names the index. An InvalidInput
// thrown by a query inside a worker (bad options) reaches the caller with
// "distance_batch: pair k: " before the query's own message; results and
// caches of other pairs may then have been written.
void distance_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options = {},
                    int threads = 0);

// One pair of polytopes at K pose pairs: results[k] = distance(a, poses_a[k],
// b, poses_b[k], options, &caches[k]). Each k is its own scene with its own
// cache (K bodies pairs in lockstep, or K candidate placements), so that the
// queries are independent. Same sizes, errors and threads as above.
void distance_batch(const ConvexPolytope& a, std::span<const Pose> poses_a, const ConvexPolytope& b,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options = {},
                    int threads = 0);

// One pair of Bodies of any kinds (convex, rounded, compound). Both
// pointers must be non-null and outlive the call; a Body may appear in any
// number of pairs.
struct BodyPair {
  const Body* a = nullptr;
  const Body* b = nullptr;
};

// results[k] = distance(*pairs[k].a, poses_a[k], *pairs[k].b, poses_b[k],
// options, caches.empty() ? nullptr : &caches[k]) for every k (proxima/query/body_distance.h),
// bit for bit. Same sizes, errors and threads as the polytope batch above; a
// Body's lazily built one-piece compound (Body::compound()) is thread-safe.
void distance_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<BodyResult> results,
                    std::span<BodyCache> caches, const DistanceOptions& options = {},
                    int threads = 0);

// The boolean and margin queries (proxima/query/margin.h) in batches: results[k] is
// exactly (bit for bit) within_margin(*pairs[k].a, poses_a[k], *pairs[k].b,
// poses_b[k], margin, options, caches.empty() ? nullptr : &caches[k]), each
// stopped at its first proof and certified as the single query is (within:
// a witness pair at most margin + band apart; beyond: a lower bound above
// the margin). The caches are the distance batch's: a row's cache kept
// from a distance_batch serves its margin query and the other way round.
// Same sizes, threads and errors as distance_batch (messages begin with
// the function's name); a bad margin is refused before anything is
// written. intersects_batch is the margin 0.
//
//   std::vector<proxima::MarginResult> hits(pairs.size());
//   proxima::within_margin_batch(pairs, poses_a, poses_b, 0.05, hits, caches);
//   for (const auto& h : hits) if (h.is_within()) ...  // h.point_a, h.point_b: the witness
void within_margin_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                         std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<DistanceCache> caches,
                         const DistanceOptions& options = {}, int threads = 0);
void within_margin_batch(const ConvexPolytope& a, std::span<const Pose> poses_a,
                         const ConvexPolytope& b, std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<DistanceCache> caches,
                         const DistanceOptions& options = {}, int threads = 0);
void within_margin_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                         std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<BodyCache> caches,
                         const DistanceOptions& options = {}, int threads = 0);
void intersects_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                      std::span<const Pose> poses_b, std::span<MarginResult> results,
                      std::span<DistanceCache> caches, const DistanceOptions& options = {},
                      int threads = 0);
void intersects_batch(const ConvexPolytope& a, std::span<const Pose> poses_a,
                      const ConvexPolytope& b, std::span<const Pose> poses_b,
                      std::span<MarginResult> results, std::span<DistanceCache> caches,
                      const DistanceOptions& options = {}, int threads = 0);
void intersects_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                      std::span<const Pose> poses_b, std::span<MarginResult> results,
                      std::span<BodyCache> caches, const DistanceOptions& options = {},
                      int threads = 0);

}  // namespace proxima
