// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Batch queries: validate everything in the calling thread (so that bad input
// is reported with its index, deterministically, before anything is written),
// then hand index ranges to TBB. Each index belongs to exactly one range, so
// each cache and result is touched by one thread; the polytopes are only
// read. No state is shared between queries, which is why a batch answer is
// bit for bit the sequential one.
#include "proxima/query/batch.h"

#include <cstddef>
#include <new>
#include <string>
#include <type_traits>

#include "core/accuracy.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "query/parallel_ranges.h"

namespace proxima {
namespace {

// Smallest index range a task runs. A tracked query costs tens of
// nanoseconds and a TBB task about a microsecond to schedule and steal, so a
// task must hold some tens of queries for the scheduling to stay a few per
// cent; TBB's auto partitioner still splits larger ranges for balance. Below
// two grains the batch runs in the calling thread. batch_bench measures it.
constexpr std::size_t kGrainSize = 32;

std::string at(std::size_t k) { return std::to_string(k); }

void check_size(const char* who, std::size_t size, std::size_t expected, const char* name) {
  if (size != expected) {
    throw InvalidInput(std::string(who) + ": " + name + " has " + at(size) +
                       " elements, expected " + at(expected) + " (one per pair)");
  }
}

// Every pose under the contract, before any query runs: both poses of pair
// k in one paired test (detail::are_rigid, as distance() itself does), the
// full check, which names the pose, only for a pair that fails it. True
// when every pose passed the paired test: the queries may then take them
// as they are, without checking them again (a pose accepted but within
// kRotationTolerance only is re-orthonormalized by the query that checks
// it, so a batch holding one asks the checking queries).
bool check_poses(const char* who, std::span<const Pose> poses_a, std::span<const Pose> poses_b) {
  bool rigid = true;
  for (std::size_t k = 0; k < poses_a.size(); ++k) {
    if (detail::are_rigid(poses_a[k], poses_b[k])) [[likely]]
      continue;
    check_pose(poses_a[k], [&] { return std::string(who) + ": poses_a[" + at(k) + "]"; });
    check_pose(poses_b[k], [&] { return std::string(who) + ": poses_b[" + at(k) + "]"; });
    rigid = false;
  }
  return rigid;
}

// The shared part of every overload. `pair(k)` returns the pair of index k
// (a span lookup or the one fixed pair): a BatchPair or a BodyPair;
// `query(pair, pose_a, pose_b, cache, rigid)` answers it into Result with a
// Cache (null: cold); `rigid`: the poses passed check_poses' paired test, so
// the query need not check them again. `who` names the batch in every
// message.
template <class PairOf, class Query, class Result, class Cache>
void run_batch(const char* who, std::size_t n, PairOf pair, Query query,
               std::span<const Pose> poses_a, std::span<const Pose> poses_b,
               std::span<Result> results, std::span<Cache> caches, int threads) {
  check_size(who, poses_a.size(), n, "poses_a");
  check_size(who, poses_b.size(), n, "poses_b");
  check_size(who, results.size(), n, "results");
  if (!caches.empty()) check_size(who, caches.size(), n, "caches (when not empty)");
  detail::check_at_least(threads, 0, who, "threads", "0: all cores");
  for (std::size_t k = 0; k < n; ++k) {
    const auto p = pair(k);
    if (p.a == nullptr || p.b == nullptr) {
      throw InvalidInput(std::string(who) + ": pairs[" + at(k) + "]." +
                         (p.a == nullptr ? "a" : "b") + " is null");
    }
  }
  const bool rigid = check_poses(who, poses_a, poses_b);

  // Runs the queries of [begin, end). An InvalidInput from a query (the
  // options are checked by distance() itself) is re-thrown with its index;
  // TBB carries the exception object to the calling thread as is, so the
  // message arrives whole.
  const auto run_range = [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto p = pair(k);
      try {
        // The answer made in its row (C++17's guaranteed elision through
        // the query's returned object) instead of made aside and copied
        // over a hundred bytes per row: the old answer needs no destructor.
        static_assert(std::is_trivially_destructible_v<Result>);
        ::new (static_cast<void*>(&results[k]))
            Result(query(p, poses_a[k], poses_b[k], caches.empty() ? nullptr : &caches[k], rigid));
      } catch (const InvalidInput& e) {
        throw InvalidInput(std::string(who) + ": pair " + at(k) + ": " + e.what());
      }
    }
  };

  if (threads == 1 || n < 2 * kGrainSize) {
    run_range(0, n);
    return;
  }
  detail::parallel_ranges(n, kGrainSize, threads, run_range);
}

// The distance query of one pair, for run_batch: poses that passed
// check_poses' test go to the query that does not check them again (the
// same answer, bit for bit).
auto distance_with(const DistanceOptions& options) {
  return [&options](const auto& p, const Pose& pose_a, const Pose& pose_b, auto* cache,
                    bool rigid) {
    if (rigid) [[likely]]
      return detail::distance_of_rigid_poses(*p.a, pose_a, *p.b, pose_b, options, cache);
    return distance(*p.a, pose_a, *p.b, pose_b, options, cache);
  };
}

// The margin query of one pair, for run_batch; the margin and the options
// are checked once, in the calling thread, before anything is written.
auto within_margin_with(double margin, const DistanceOptions& options, const char* who) {
  detail::check_finite_non_negative(margin, who, "margin");
  detail::check_distance_options(options, who);
  return [margin, &options](const auto& p, const Pose& pose_a, const Pose& pose_b, auto* cache,
                            bool rigid) {
    // A convex pair or a Body row with a cache, in a batch whose poses all
    // passed check_poses' paired test: the query that does not check the
    // poses (nor the margin and options, checked above) again.
    if constexpr (std::is_same_v<std::remove_pointer_t<decltype(cache)>, DistanceCache> ||
                  std::is_same_v<std::remove_cvref_t<decltype(p)>, BodyPair>) {
      if (rigid && cache != nullptr) [[likely]]
        return detail::within_margin_of_rigid_poses(*p.a, pose_a, *p.b, pose_b, margin, options,
                                                    *cache);
    }
    return within_margin(*p.a, pose_a, *p.b, pose_b, margin, options, cache);
  };
}

constexpr const char* kDistance = "distance_batch";
constexpr const char* kWithin = "within_margin_batch";
constexpr const char* kIntersects = "intersects_batch";

}  // namespace

void distance_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options, int threads) {
  run_batch(
      kDistance, pairs.size(), [pairs](std::size_t k) { return pairs[k]; },
      distance_with(options), poses_a, poses_b, results, caches, threads);
}

void distance_batch(const ConvexPolytope& a, std::span<const Pose> poses_a, const ConvexPolytope& b,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options, int threads) {
  const BatchPair fixed{&a, &b};
  run_batch(
      kDistance, poses_a.size(), [fixed](std::size_t) { return fixed; }, distance_with(options),
      poses_a, poses_b, results, caches, threads);
}

void distance_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<BodyResult> results,
                    std::span<BodyCache> caches, const DistanceOptions& options, int threads) {
  run_batch(
      kDistance, pairs.size(), [pairs](std::size_t k) { return pairs[k]; },
      distance_with(options), poses_a, poses_b, results, caches, threads);
}

namespace {

// Every margin batch: `who` names it (within_margin_batch, or
// intersects_batch with the margin 0).
template <class PairOf, class Cache>
void margin_batch(const char* who, std::size_t n, PairOf pair, std::span<const Pose> poses_a,
                  std::span<const Pose> poses_b, double margin, std::span<MarginResult> results,
                  std::span<Cache> caches, const DistanceOptions& options, int threads) {
  run_batch(who, n, pair, within_margin_with(margin, options, who), poses_a, poses_b, results,
            caches, threads);
}

}  // namespace

void within_margin_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                         std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<DistanceCache> caches,
                         const DistanceOptions& options, int threads) {
  margin_batch(
      kWithin, pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b,
      margin, results, caches, options, threads);
}

void within_margin_batch(const ConvexPolytope& a, std::span<const Pose> poses_a,
                         const ConvexPolytope& b, std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<DistanceCache> caches,
                         const DistanceOptions& options, int threads) {
  const BatchPair fixed{&a, &b};
  margin_batch(
      kWithin, poses_a.size(), [fixed](std::size_t) { return fixed; }, poses_a, poses_b, margin,
      results, caches, options, threads);
}

void within_margin_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                         std::span<const Pose> poses_b, double margin,
                         std::span<MarginResult> results, std::span<BodyCache> caches,
                         const DistanceOptions& options, int threads) {
  margin_batch(
      kWithin, pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b,
      margin, results, caches, options, threads);
}

void intersects_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                      std::span<const Pose> poses_b, std::span<MarginResult> results,
                      std::span<DistanceCache> caches, const DistanceOptions& options,
                      int threads) {
  margin_batch(
      kIntersects, pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b,
      0.0, results, caches, options, threads);
}

void intersects_batch(const ConvexPolytope& a, std::span<const Pose> poses_a,
                      const ConvexPolytope& b, std::span<const Pose> poses_b,
                      std::span<MarginResult> results, std::span<DistanceCache> caches,
                      const DistanceOptions& options, int threads) {
  const BatchPair fixed{&a, &b};
  margin_batch(
      kIntersects, poses_a.size(), [fixed](std::size_t) { return fixed; }, poses_a, poses_b, 0.0,
      results, caches, options, threads);
}

void intersects_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                      std::span<const Pose> poses_b, std::span<MarginResult> results,
                      std::span<BodyCache> caches, const DistanceOptions& options, int threads) {
  margin_batch(
      kIntersects, pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b,
      0.0, results, caches, options, threads);
}

}  // namespace proxima
