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
#include <string>

#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
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

void check_size(std::size_t size, std::size_t expected, const char* name) {
  if (size != expected) {
    throw InvalidInput("distance_batch: " + std::string(name) + " has " + at(size) +
                       " elements, expected " + at(expected) + " (one per pair)");
  }
}

// Every pose under the contract, before any query runs: both poses of pair
// k in one paired test (detail::are_rigid, as distance() itself does), the
// full check, which names the pose, only for a pair that fails it.
void check_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) {
  for (std::size_t k = 0; k < poses_a.size(); ++k) {
    if (detail::are_rigid(poses_a[k], poses_b[k])) [[likely]]
      continue;
    check_pose(poses_a[k], [&] { return "distance_batch: poses_a[" + at(k) + "]"; });
    check_pose(poses_b[k], [&] { return "distance_batch: poses_b[" + at(k) + "]"; });
  }
}

// The shared part of every overload. `pair(k)` returns the pair of index k
// (a span lookup or the one fixed pair): a BatchPair or a BodyPair, whose
// distance() overload answers into Result with a Cache.
template <class PairOf, class Result, class Cache>
void run_batch(std::size_t n, PairOf pair, std::span<const Pose> poses_a,
               std::span<const Pose> poses_b, std::span<Result> results, std::span<Cache> caches,
               const DistanceOptions& options, int threads) {
  check_size(poses_a.size(), n, "poses_a");
  check_size(poses_b.size(), n, "poses_b");
  check_size(results.size(), n, "results");
  if (!caches.empty()) check_size(caches.size(), n, "caches (when not empty)");
  if (threads < 0) {
    throw InvalidInput("distance_batch: threads must be >= 0 (0: all cores), got " +
                       std::to_string(threads));
  }
  for (std::size_t k = 0; k < n; ++k) {
    const auto p = pair(k);
    if (p.a == nullptr || p.b == nullptr) {
      throw InvalidInput("distance_batch: pairs[" + at(k) + "]." + (p.a == nullptr ? "a" : "b") +
                         " is null");
    }
  }
  check_poses(poses_a, poses_b);

  // Runs the queries of [begin, end). An InvalidInput from a query (the
  // options are checked by distance() itself) is re-thrown with its index;
  // TBB carries the exception object to the calling thread as is, so the
  // message arrives whole.
  const auto run_range = [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto p = pair(k);
      try {
        results[k] = distance(*p.a, poses_a[k], *p.b, poses_b[k], options,
                              caches.empty() ? nullptr : &caches[k]);
      } catch (const InvalidInput& e) {
        throw InvalidInput("distance_batch: pair " + at(k) + ": " + e.what());
      }
    }
  };

  if (threads == 1 || n < 2 * kGrainSize) {
    run_range(0, n);
    return;
  }
  detail::parallel_ranges(n, kGrainSize, threads, run_range);
}

}  // namespace

void distance_batch(std::span<const BatchPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options, int threads) {
  run_batch(
      pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b, results, caches,
      options, threads);
}

void distance_batch(const ConvexPolytope& a, std::span<const Pose> poses_a, const ConvexPolytope& b,
                    std::span<const Pose> poses_b, std::span<DistanceResult> results,
                    std::span<DistanceCache> caches, const DistanceOptions& options, int threads) {
  const BatchPair fixed{&a, &b};
  run_batch(
      poses_a.size(), [fixed](std::size_t) { return fixed; }, poses_a, poses_b, results, caches,
      options, threads);
}

void distance_batch(std::span<const BodyPair> pairs, std::span<const Pose> poses_a,
                    std::span<const Pose> poses_b, std::span<BodyResult> results,
                    std::span<BodyCache> caches, const DistanceOptions& options, int threads) {
  run_batch(
      pairs.size(), [pairs](std::size_t k) { return pairs[k]; }, poses_a, poses_b, results, caches,
      options, threads);
}

}  // namespace proxima
