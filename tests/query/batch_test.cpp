// Tests of distance_batch: the batch is the sequential loop, bit for bit
// (results and caches), at 1 and 2 threads and in the caller's arena, for
// every algorithm; caches carry tracking across calls; bad input is refused
// with its index before anything is written; an exception thrown inside a
// worker reaches the caller as InvalidInput with its message.
//
// The reference is distance() itself, called in a plain loop: the batch
// promises nothing more than running that loop on several threads. Accuracy
// of the answers is the business of distance_accuracy_test.cpp.
#include "proxima/query/batch.h"

#include <gtest/gtest.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "query/parallel_ranges.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "proxima/shape/primitives.h"
#include "support/generators.h"
#include "support/same_bits.h"

namespace proxima {
namespace {

using test::Rng;
using test::same_bits;
using test::same_feature;

// A scene of `n` pairs drawn from a pool of shared polytopes (20 to 100
// random points each, on a sphere or in a cube), with random poses spread so
// that a fair share of the pairs overlap and the rest are separated.
struct Scene {
  std::vector<std::unique_ptr<ConvexPolytope>> pool;
  std::vector<BatchPair> pairs;
  std::vector<Pose> poses_a;
  std::vector<Pose> poses_b;
};

Pose random_pose(Rng& rng, double spread) {
  return {test::random_quaternion(rng),
          test::drawn([&] { return test::uniform(rng, -spread, spread); })};
}

Scene make_scene(Rng& rng, int n, int pool_size = 12) {
  Scene s;
  for (int i = 0; i < pool_size; ++i) {
    const int count = test::uniform_int(rng, 20, 100);
    s.pool.push_back(std::make_unique<ConvexPolytope>(
        i % 2 == 0 ? test::points_on_sphere(rng, count) : test::points_in_cube(rng, count)));
  }
  for (int k = 0; k < n; ++k) {
    const auto pick = [&] {
      return s.pool[static_cast<std::size_t>(test::uniform_int(rng, 0, pool_size - 1))].get();
    };
    s.pairs.push_back({pick(), pick()});
    s.poses_a.push_back(random_pose(rng, 2.0));
    s.poses_b.push_back(random_pose(rng, 2.0));
  }
  return s;
}

// Every pose moved by a small rotation and translation: the next frame of a
// simulation, whose closest features mostly stay the same.
void step(Rng& rng, std::vector<Pose>& poses) {
  for (Pose& p : poses) {
    p = Pose(Mat3(test::random_small_rotation(rng, 0.01) * p.rotation),
             Vec3(p.translation + 0.01 * test::random_unit_vector(rng)));
  }
}

void expect_same_result(const DistanceResult& x, const DistanceResult& y, std::size_t k) {
  EXPECT_EQ(x.status, y.status) << "pair " << k;
  EXPECT_TRUE(same_bits(x.distance, y.distance))
      << "pair " << k << ": " << x.distance << " vs " << y.distance;
  EXPECT_TRUE(same_bits(x.lower_bound, y.lower_bound)) << "pair " << k;
  EXPECT_TRUE(same_bits(x.point_a, y.point_a)) << "pair " << k;
  EXPECT_TRUE(same_bits(x.point_b, y.point_b)) << "pair " << k;
  EXPECT_TRUE(same_bits(x.normal, y.normal)) << "pair " << k;
  EXPECT_TRUE(same_feature(x.feature_a, y.feature_a)) << "pair " << k;
  EXPECT_TRUE(same_feature(x.feature_b, y.feature_b)) << "pair " << k;
  EXPECT_EQ(x.iterations, y.iterations) << "pair " << k;
}

void expect_same_cache(const DistanceCache& x, const DistanceCache& y, std::size_t k) {
  EXPECT_EQ(x.vertices_a, y.vertices_a) << "pair " << k;
  EXPECT_EQ(x.vertices_b, y.vertices_b) << "pair " << k;
  EXPECT_EQ(x.hint_a, y.hint_a) << "pair " << k;
  EXPECT_EQ(x.hint_b, y.hint_b) << "pair " << k;
}

// The sequential reference: distance() in a loop, updating `caches` (empty:
// cold queries).
std::vector<DistanceResult> sequential(const Scene& s, std::vector<DistanceCache>& caches,
                                       const DistanceOptions& options) {
  std::vector<DistanceResult> out;
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    out.push_back(distance(*s.pairs[k].a, s.poses_a[k], *s.pairs[k].b, s.poses_b[k], options,
                           caches.empty() ? nullptr : &caches[k]));
  }
  return out;
}

// Large enough for many TBB tasks (the batch runs anything under two grains,
// 64 pairs, in the calling thread), small enough for the tsan preset.
constexpr int kPairs = 800;

// The runs compared with the sequential loop: one thread, two threads in a
// dedicated arena, and the caller's arena (threads = 0).
constexpr int kThreadCounts[] = {1, 2, 0};

TEST(Batch, EqualsSequentialBitForBitColdAndTracking) {
  for (Algorithm algorithm : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    for (int threads : kThreadCounts) {
      SCOPED_TRACE(std::string(to_string(algorithm)) + ", threads " + std::to_string(threads));
      Rng rng(20240501);
      Scene s = make_scene(rng, kPairs);
      DistanceOptions options;
      options.algorithm = algorithm;

      // Cold, no caches.
      std::vector<DistanceCache> none;
      std::vector<DistanceResult> batch(s.pairs.size());
      distance_batch(s.pairs, s.poses_a, s.poses_b, batch, {}, options, threads);
      const std::vector<DistanceResult> cold = sequential(s, none, options);
      for (std::size_t k = 0; k < batch.size(); ++k) expect_same_result(batch[k], cold[k], k);

      // With caches, three frames of motion: each call starts from the
      // caches the previous one left (tracking), in the batch as in the loop.
      std::vector<DistanceCache> batch_caches(s.pairs.size());
      std::vector<DistanceCache> loop_caches(s.pairs.size());
      for (int frame = 0; frame < 3; ++frame) {
        distance_batch(s.pairs, s.poses_a, s.poses_b, batch, batch_caches, options, threads);
        const std::vector<DistanceResult> loop = sequential(s, loop_caches, options);
        for (std::size_t k = 0; k < batch.size(); ++k) {
          expect_same_result(batch[k], loop[k], k);
          expect_same_cache(batch_caches[k], loop_caches[k], k);
        }
        step(rng, s.poses_a);
        step(rng, s.poses_b);
      }
      if (HasFailure()) return;  // one algorithm's failures are enough to read
    }
  }
}

TEST(Batch, CachesAreUpdatedAndTrackingSavesIterations) {
  Rng rng(7);
  Scene s = make_scene(rng, kPairs);
  // Separate every pair (B well away from A along x) so that every query has
  // closest features to track; overlapping pairs stop at the first
  // intersection test and say little about tracking.
  // Unit-size bodies (radius at most sqrt(3)) 5 apart stay apart through a
  // step of 0.01.
  for (std::size_t k = 0; k < s.pairs.size(); ++k)
    s.poses_b[k].translation = s.poses_a[k].translation + Vec3(5, 0, 0);
  std::vector<DistanceResult> first(s.pairs.size());
  std::vector<DistanceCache> caches(s.pairs.size());
  for (const DistanceCache& c : caches) ASSERT_TRUE(c.is_cold());
  distance_batch(s.pairs, s.poses_a, s.poses_b, first, caches, {}, 2);
  for (std::size_t k = 0; k < caches.size(); ++k) {
    EXPECT_FALSE(caches[k].is_cold()) << "pair " << k << ": the batch did not write its cache";
  }

  // The next frame, tracked and cold: the same answers (the accuracy
  // standard's "same with a warm cache"), and far fewer iterations tracked.
  step(rng, s.poses_a);
  step(rng, s.poses_b);
  std::vector<DistanceResult> tracked(s.pairs.size());
  std::vector<DistanceResult> cold(s.pairs.size());
  distance_batch(s.pairs, s.poses_a, s.poses_b, tracked, caches, {}, 2);
  distance_batch(s.pairs, s.poses_a, s.poses_b, cold, {}, {}, 2);
  long tracked_iterations = 0;
  long cold_iterations = 0;
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    ASSERT_EQ(tracked[k].status, Status::separated) << "pair " << k;
    ASSERT_EQ(cold[k].status, Status::separated) << "pair " << k;
    // Both answers are within 1e-12 relative of d* (the standard's bound at
    // these unit-size, well-separated bodies), hence within 2.5e-12 of each
    // other.
    EXPECT_NEAR(tracked[k].distance, cold[k].distance, 2.5e-12 * cold[k].distance) << "pair " << k;
    tracked_iterations += tracked[k].iterations;
    cold_iterations += cold[k].iterations;
  }
  EXPECT_LT(2 * tracked_iterations, cold_iterations)
      << "tracking through the batch should at least halve the iterations after a small motion";
}

TEST(Batch, OnePairManyPosesEqualsPairsOverload) {
  Rng rng(11);
  const ConvexPolytope a(test::points_on_sphere(rng, 60));
  const ConvexPolytope b(test::points_in_cube(rng, 40));
  std::vector<Pose> poses_a;
  std::vector<Pose> poses_b;
  for (int k = 0; k < 500; ++k) {
    poses_a.push_back(random_pose(rng, 2.0));
    poses_b.push_back(random_pose(rng, 2.0));
  }
  const std::vector<BatchPair> pairs(poses_a.size(), BatchPair{&a, &b});
  std::vector<DistanceResult> one(poses_a.size());
  std::vector<DistanceResult> many(poses_a.size());
  std::vector<DistanceCache> caches_one(poses_a.size());
  std::vector<DistanceCache> caches_many(poses_a.size());
  distance_batch(a, poses_a, b, poses_b, one, caches_one, {}, 2);
  distance_batch(pairs, poses_a, poses_b, many, caches_many, {}, 2);
  for (std::size_t k = 0; k < one.size(); ++k) {
    expect_same_result(one[k], many[k], k);
    expect_same_cache(caches_one[k], caches_many[k], k);
  }
}

TEST(Batch, EmptyBatchIsANoOp) {
  EXPECT_NO_THROW(distance_batch(std::span<const BatchPair>{}, {}, {}, {}, {}, {}, 2));
}

// The message of the InvalidInput that `run` throws; fails if it throws
// nothing or something else.
template <class Run>
std::string invalid_input_message(Run run) {
  try {
    run();
  } catch (const InvalidInput& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InvalidInput, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InvalidInput, nothing was thrown";
  return {};
}

TEST(Batch, BadInputIsRefusedWithItsIndexBeforeAnythingIsWritten) {
  Rng rng(3);
  Scene s = make_scene(rng, 300);
  const std::size_t n = s.pairs.size();
  std::vector<DistanceResult> results(n);
  std::vector<DistanceCache> caches(n);
  // Sentinels: a refused call must leave them as they are.
  for (DistanceResult& r : results) r.iterations = -7;
  const auto untouched = [&] {
    for (std::size_t k = 0; k < n; ++k) {
      if (results[k].iterations != -7 || !caches[k].is_cold()) return false;
    }
    return true;
  };
  const auto run = [&](std::span<const BatchPair> pairs, std::span<const Pose> pa,
                       std::span<const Pose> pb, std::span<DistanceResult> res,
                       std::span<DistanceCache> cs, int threads = 2) {
    return invalid_input_message([&] { distance_batch(pairs, pa, pb, res, cs, {}, threads); });
  };
  const std::span<DistanceResult> all_results(results);
  const std::span<DistanceCache> all_caches(caches);
  const std::span<const Pose> poses_a(s.poses_a);
  const std::span<const Pose> poses_b(s.poses_b);

  EXPECT_NE(run(s.pairs, poses_a.first(n - 1), poses_b, all_results, all_caches)
                .find("poses_a has 299 elements"),
            std::string::npos);
  EXPECT_NE(run(s.pairs, poses_a, poses_b.first(n - 2), all_results, all_caches)
                .find("poses_b has 298 elements"),
            std::string::npos);
  EXPECT_NE(run(s.pairs, poses_a, poses_b, all_results.first(10), all_caches)
                .find("results has 10 elements"),
            std::string::npos);
  EXPECT_NE(run(s.pairs, poses_a, poses_b, all_results, all_caches.first(5)).find("caches"),
            std::string::npos);
  EXPECT_NE(run(s.pairs, poses_a, poses_b, all_results, all_caches, -1).find("threads"),
            std::string::npos);

  std::vector<BatchPair> with_null = s.pairs;
  with_null[217].b = nullptr;
  EXPECT_NE(run(with_null, poses_a, poses_b, all_results, all_caches).find("pairs[217].b is null"),
            std::string::npos);
  with_null[41].a = nullptr;  // the first bad index is the one named
  EXPECT_NE(run(with_null, poses_a, poses_b, all_results, all_caches).find("pairs[41].a is null"),
            std::string::npos);

  std::vector<Pose> bad_b = s.poses_b;
  bad_b[123].translation.y() = std::numeric_limits<double>::infinity();
  bad_b[250].rotation(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(
      run(s.pairs, poses_a, bad_b, all_results, all_caches).find("poses_b[123] is not finite"),
      std::string::npos);
  EXPECT_NE(
      run(s.pairs, poses_a, bad_b, all_results, all_caches, 1).find("poses_b[123] is not finite"),
      std::string::npos);

  const ConvexPolytope& a = *s.pool[0];
  EXPECT_NE(invalid_input_message([&] {
              distance_batch(a, poses_a, a, bad_b, all_results, all_caches, {}, 2);
            }).find("poses_b[123] is not finite"),
            std::string::npos);
  EXPECT_NE(invalid_input_message([&] {
              distance_batch(a, poses_a, a, poses_b.first(7), all_results, all_caches, {}, 2);
            }).find("poses_b has 7 elements, expected 300"),
            std::string::npos);
  EXPECT_TRUE(untouched()) << "a refused batch wrote results or caches";
}

// Bodies of every kind (convex, rounded, compound, primitives) mixed in one
// batch: the batch is the loop of distance(Body, ...) bit for bit, cold and
// tracking, with pairs that overlap (signed distance, depth) and pairs apart.
TEST(Batch, BodyPairsEqualSequentialBitForBit) {
  Rng rng(20261125);
  std::vector<Body> pool;
  for (int i = 0; i < 4; ++i) {
    pool.emplace_back(ConvexPolytope(test::points_on_sphere(rng, 30 + 10 * i)), 0.1 * i);
  }
  std::vector<CompoundPiece> pieces;
  for (int i = 0; i < 3; ++i) {
    pieces.push_back({std::make_shared<const ConvexPolytope>(test::points_in_cube(rng, 20)),
                      Pose(Mat3::Identity(), Vec3(1.5 * i, 0, 0))});
  }
  pool.emplace_back(CompoundBody(std::move(pieces)), 0.05);
  pool.push_back(make_box(Vec3(0.5, 0.3, 0.2), 0.02));
  pool.push_back(make_sphere(0.4));
  pool.push_back(make_capsule(0.6, 0.2));
  std::vector<BodyPair> pairs;
  std::vector<Pose> poses_a;
  std::vector<Pose> poses_b;
  for (int k = 0; k < 300; ++k) {
    const auto pick = [&] {
      return &pool[static_cast<std::size_t>(test::uniform_int(rng, 0, int(pool.size()) - 1))];
    };
    pairs.push_back({pick(), pick()});
    poses_a.push_back(random_pose(rng, 2.0));
    poses_b.push_back(random_pose(rng, 2.0));
  }
  const std::size_t n = pairs.size();
  for (int threads : kThreadCounts) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    std::vector<BodyCache> loop_caches(n);
    std::vector<BodyCache> batch_caches(n);
    std::vector<Pose> pa = poses_a;
    std::vector<Pose> pb = poses_b;
    Rng motion(5);
    bool overlaps = false;
    bool apart = false;
    for (int frame = 0; frame < 3; ++frame) {
      std::vector<BodyResult> batch(n);
      distance_batch(pairs, pa, pb, batch, batch_caches, {}, threads);
      std::vector<BodyResult> cold(n);
      distance_batch(pairs, pa, pb, cold, {}, {}, threads);
      for (std::size_t k = 0; k < n; ++k) {
        const BodyResult loop =
            distance(*pairs[k].a, pa[k], *pairs[k].b, pb[k], {}, &loop_caches[k]);
        expect_same_result(batch[k], loop, k);
        EXPECT_TRUE(same_bits(batch[k].depth, loop.depth)) << "pair " << k;
        EXPECT_EQ(batch[k].piece_a, loop.piece_a) << "pair " << k;
        EXPECT_EQ(batch[k].piece_b, loop.piece_b) << "pair " << k;
        const BodyResult once = distance(*pairs[k].a, pa[k], *pairs[k].b, pb[k]);
        expect_same_result(cold[k], once, k);
        overlaps = overlaps || loop.signed_distance() < 0;
        apart = apart || loop.signed_distance() > 0;
      }
      step(motion, pa);
      step(motion, pb);
    }
    EXPECT_TRUE(overlaps && apart) << "the scene should mix overlapping and separated pairs";
  }
  // A null body is refused with its index, before anything is written.
  std::vector<BodyPair> bad = pairs;
  bad[7].b = nullptr;
  std::vector<BodyResult> results(n);
  EXPECT_EQ(
      invalid_input_message([&] { distance_batch(bad, poses_a, poses_b, results, {}, {}, 2); }),
      "distance_batch: pairs[7].b is null");
}

// The batch checks its poses once, before the queries, and hands them to
// the queries that do not check them again (issue 28) only when every pose
// passed the paired test as it is. A pose accepted only after
// re-orthonormalization (a rotation through float32, within 1e-6 of
// orthonormal) must still be re-orthonormalized: the batch then answers as
// distance() and within_margin() do for the same poses, bit for bit. It
// fails when such a batch gives the unchecked queries the raw rotation.
TEST(Batch, PosesReOrthonormalizedByTheQueryAnswerAsTheSingleQueries) {
  Rng rng(2811);
  Scene s = make_scene(rng, 40);
  // Every fifth pose of B through float32: within the contract's 1e-6, not
  // orthonormal to 32 u, so the single query re-orthonormalizes it.
  for (std::size_t k = 0; k < s.poses_b.size(); k += 5) {
    s.poses_b[k].rotation = s.poses_b[k].rotation.cast<float>().cast<double>();
    ASSERT_FALSE(detail::is_rigid(s.poses_b[k])) << "pair " << k;
  }
  for (int frame = 0; frame < 2; ++frame) {
    std::vector<DistanceCache> batch_caches(s.pairs.size());
    std::vector<DistanceCache> loop_caches(s.pairs.size());
    std::vector<DistanceResult> batch(s.pairs.size());
    distance_batch(s.pairs, s.poses_a, s.poses_b, batch, batch_caches, {}, 1);
    const std::vector<DistanceResult> loop = sequential(s, loop_caches, {});
    for (std::size_t k = 0; k < batch.size(); ++k) expect_same_result(batch[k], loop[k], k);
    std::vector<MarginResult> within(s.pairs.size());
    std::vector<DistanceCache> margin_caches(s.pairs.size());
    within_margin_batch(s.pairs, s.poses_a, s.poses_b, 0.3, within, margin_caches, {}, 1);
    for (std::size_t k = 0; k < s.pairs.size(); ++k) {
      DistanceCache cache;
      const MarginResult one = within_margin(*s.pairs[k].a, s.poses_a[k], *s.pairs[k].b,
                                             s.poses_b[k], 0.3, {}, &cache);
      EXPECT_EQ(within[k].status, one.status) << "pair " << k;
      EXPECT_TRUE(same_bits(within[k].lower_bound, one.lower_bound)) << "pair " << k;
      EXPECT_TRUE(same_bits(within[k].point_a, one.point_a)) << "pair " << k;
      EXPECT_TRUE(same_bits(within[k].point_b, one.point_b)) << "pair " << k;
    }
    step(rng, s.poses_a);  // a second frame: A moved, the caches tracked
  }
}

TEST(Batch, ExceptionInsideAWorkerReachesTheCallerWithItsMessage) {
  // Bad options are checked by distance() itself, so with more than two
  // grains of pairs the first throw happens on a TBB task (on a worker
  // thread or the caller's), and TBB carries it to the caller.
  Rng rng(5);
  Scene s = make_scene(rng, kPairs);
  std::vector<DistanceResult> results(s.pairs.size());
  DistanceOptions bad;
  bad.max_iterations = 0;
  for (int threads : kThreadCounts) {
    const std::string message = invalid_input_message(
        [&] { distance_batch(s.pairs, s.poses_a, s.poses_b, results, {}, bad, threads); });
    EXPECT_EQ(message.rfind("distance_batch: pair ", 0), 0u) << message;
    EXPECT_NE(message.find("max_iterations must be at least 1"), std::string::npos) << message;
  }
}

// Waits, inside a parallel loop's tasks, until a second thread has been
// seen running one of them: each task registers its thread, and the tasks
// that run before another thread has registered block until one does. A
// task that blocks keeps its thread busy, so the loop's remaining ranges can
// only be run by another thread of the arena; if none ever joins (the loop
// ran on one thread), the wait gives up after kSecondThreadTimeout and the
// test sees one thread. Replaces a 1 ms sleep per task, which let a loop run
// entirely on the calling thread and the test still pass.
class SecondThreadRendezvous {
 public:
  // Generous: a worker that wakes late on a loaded machine (the suite runs
  // on 2 shared cores, under the sanitizers too) must not fail the test; a
  // loop that never gets a second thread costs this once, then every later
  // task goes through without waiting.
  static constexpr std::chrono::seconds kSecondThreadTimeout{30};

  // Called by every task; returns once two threads have been seen or the
  // wait has timed out once.
  void arrive() {
    std::unique_lock<std::mutex> lock(mutex_);
    threads_.insert(std::this_thread::get_id());
    if (threads_.size() >= 2) {
      joined_.notify_all();
      return;
    }
    if (timed_out_) return;
    if (!joined_.wait_for(lock, kSecondThreadTimeout, [&] { return threads_.size() >= 2; })) {
      timed_out_ = true;
    }
  }
  std::size_t threads_seen() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return threads_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable joined_;
  std::set<std::thread::id> threads_;
  bool timed_out_ = false;
};

// The floating-point traps of the test main cover the main thread only (the
// FP environment is per thread). TBB hands the FP control settings of the
// thread that initializes an arena to every task the arena runs (the
// arena's default context captures them), so an arena initialized here
// runs its workers with the traps on too. That premise is checked first,
// on every thread that runs a task, before the batch relies on it.
//
// An earlier version turned the traps on with a task_scheduler_observer;
// oneTBB 2021.8 leaks the observer's registration (40 bytes, seen by
// LeakSanitizer in CI), so the test no longer uses one.
TEST(Batch, CallerArenaWithFloatingPointTrapsOnEveryThread) {
  // threads = 0 runs in the caller's arena: here a two-thread arena whose
  // threads all trap on invalid operations and divisions by zero, over
  // overlapping and separated pairs.
  tbb::task_arena arena(2);
  arena.initialize();
  std::mutex mutex;
  SecondThreadRendezvous rendezvous;
  int tasks_without_traps = 0;
  // Through proxima's own pool (parallel_ranges, the code distance_batch
  // runs on), not a tbb::parallel_for instantiated here: under
  // ThreadSanitizer this file is instrumented and TBB's templates would be
  // too, which reports TBB's own synchronization as races.
  arena.execute([&] {
    detail::parallel_ranges(64, 1, 0, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        rendezvous.arrive();
        const bool traps =
            (fegetexcept() & (FE_INVALID | FE_DIVBYZERO)) == (FE_INVALID | FE_DIVBYZERO);
        const std::lock_guard<std::mutex> lock(mutex);
        tasks_without_traps += traps ? 0 : 1;
      }
    });
  });
  // The premise is about the worker: without it, the loop proved nothing.
  ASSERT_GE(rendezvous.threads_seen(), 2u) << "the arena's second thread never ran a task";
  EXPECT_EQ(tasks_without_traps, 0) << "over " << rendezvous.threads_seen() << " threads";
  Rng rng(13);
  Scene s = make_scene(rng, kPairs);
  std::vector<DistanceCache> caches(s.pairs.size());
  std::vector<DistanceResult> results(s.pairs.size());
  arena.execute([&] { distance_batch(s.pairs, s.poses_a, s.poses_b, results, caches, {}, 0); });
  std::vector<DistanceCache> loop_caches(s.pairs.size());
  const std::vector<DistanceResult> loop = sequential(s, loop_caches, {});
  int overlapping = 0;
  for (std::size_t k = 0; k < results.size(); ++k) {
    expect_same_result(results[k], loop[k], k);
    overlapping += results[k].status == Status::intersecting ? 1 : 0;
  }
  // The scene must really mix overlapping and separated pairs.
  EXPECT_GT(overlapping, kPairs / 10);
  EXPECT_LT(overlapping, kPairs * 9 / 10);
}

// parallel_ranges keeps one arena per calling thread and thread count
// between loops (parallel_ranges.cpp: a new one per loop cost 100 to 300 us).
// TBB gives an arena's tasks the floating-point settings of the thread that
// made it, so each loop captures the caller's settings again: turned off
// after the kept arena was made with the test main's traps on, and on
// again, every task sees the settings of its own call, on every thread that
// runs one. Also: loops nested in a loop with another thread count, and a
// loop that throws, leave the kept arena usable.
TEST(ParallelRanges, EachLoopRunsUnderTheCallersFloatingPointSettings) {
  const int traps = FE_INVALID | FE_DIVBYZERO;
  ASSERT_EQ(fegetexcept() & traps, traps);  // the test main's
  std::mutex mutex;
  // Each loop must be seen running on two threads: the settings are the
  // caller's on the caller's thread anyway, so a loop the worker never
  // joined would check nothing.
  const auto tasks_with_traps = [&](int threads, int& tasks) {
    int trapping = 0;
    tasks = 0;
    SecondThreadRendezvous rendezvous;
    detail::parallel_ranges(32, 1, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        rendezvous.arrive();
        const bool on = (fegetexcept() & traps) == traps;
        const std::lock_guard<std::mutex> lock(mutex);
        ++tasks;
        trapping += on ? 1 : 0;
      }
    });
    EXPECT_GE(rendezvous.threads_seen(), 2u)
        << "the loop's second thread never ran a task (" << threads << " threads asked)";
    return trapping;
  };
  int tasks = 0;
  EXPECT_EQ(tasks_with_traps(2, tasks), 32);  // makes (or reuses) the kept arena
  fedisableexcept(traps);
  const int off = tasks_with_traps(2, tasks);
  feenableexcept(traps);
  EXPECT_EQ(off, 0) << "tasks that trapped with the caller's traps off";
  EXPECT_EQ(tasks, 32);
  EXPECT_EQ(tasks_with_traps(2, tasks), 32);

  std::atomic<int> inner{0};
  detail::parallel_ranges(8, 1, 2, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      detail::parallel_ranges(
          16, 1, 3, [&](std::size_t b, std::size_t e) { inner += static_cast<int>(e - b); });
    }
  });
  EXPECT_EQ(inner.load(), 8 * 16);
  EXPECT_THROW(detail::parallel_ranges(
                   64, 1, 2, [](std::size_t, std::size_t) { throw InvalidInput("a task threw"); }),
               InvalidInput);
  for (const int threads : {2, 3, 1, 2}) {
    std::atomic<int> covered{0};
    detail::parallel_ranges(
        100, 7, threads, [&](std::size_t b, std::size_t e) { covered += static_cast<int>(e - b); });
    EXPECT_EQ(covered.load(), 100) << threads << " threads";
  }
}


// ---------------------------------------------------------------------------
// The margin batches (issue 26): within_margin_batch and intersects_batch.

bool same_margin(const MarginResult& x, const MarginResult& y) {
  return x.status == y.status && same_bits(x.lower_bound, y.lower_bound) &&
         same_bits(x.upper_bound, y.upper_bound) && same_bits(x.point_a, y.point_a) &&
         same_bits(x.point_b, y.point_b) && x.piece_a == y.piece_a && x.piece_b == y.piece_b &&
         x.triangle_a == y.triangle_a && x.triangle_b == y.triangle_b &&
         x.pairs_tested == y.pairs_tested && x.iterations == y.iterations;
}

// A closed box mesh of half extents h.
TriangleMesh box_triangles(const Vec3& h) {
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k)
    v.emplace_back((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
  const std::vector<TriangleMesh::Triangle> t = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                                 {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                                 {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return TriangleMesh(v, t);
}

TEST(MarginBatch, EqualsTheSingleQueriesBitForBitTrackedOnEveryKindAndThreads) {
  Rng rng(2603);
  const Scene s = make_scene(rng, 200);
  std::vector<Body> pool;
  pool.emplace_back(ConvexPolytope(test::points_on_sphere(rng, 40)), 0.1);
  pool.emplace_back(ConvexPolytope(test::points_in_cube(rng, 30)));
  const std::vector<std::vector<Vec3>> piece_points = {
      test::points_on_sphere(rng, 20),
      test::translated(test::points_in_cube(rng, 20), Vec3(1.5, 0, 0))};
  pool.emplace_back(CompoundBody::from_point_sets(piece_points));
  pool.emplace_back(box_triangles(Vec3(0.6, 0.4, 0.3)));
  pool.push_back(make_capsule(0.6, 0.2));
  std::vector<BodyPair> body_pairs;
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    const auto pick = [&] {
      return &pool[static_cast<std::size_t>(test::uniform_int(rng, 0, int(pool.size()) - 1))];
    };
    body_pairs.push_back({pick(), pick()});
  }
  const std::size_t n = s.pairs.size();
  constexpr double kMarginOfTest = 0.3;
  for (int threads : kThreadCounts) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    std::vector<DistanceCache> loop_caches(n), batch_caches(n), fixed_loop(n), fixed_batch(n);
    std::vector<BodyCache> body_loop(n), body_batch(n);
    std::vector<Pose> pa = s.poses_a;
    std::vector<Pose> pb = s.poses_b;
    Rng motion(11);
    int within = 0;
    int beyond = 0;
    for (int frame = 0; frame < 3; ++frame) {
      // Frame 1 asks intersects; the others the margin; frame 2 follows a
      // distance batch on the same caches (they serve both queries).
      const double margin = frame == 1 ? 0.0 : kMarginOfTest;
      if (frame == 2) {
        std::vector<DistanceResult> d(n);
        distance_batch(s.pairs, pa, pb, d, batch_caches, {}, threads);
        for (std::size_t k = 0; k < n; ++k)
          distance(*s.pairs[k].a, pa[k], *s.pairs[k].b, pb[k], {}, &loop_caches[k]);
        std::vector<BodyResult> bd(n);
        distance_batch(body_pairs, pa, pb, bd, body_batch, {}, threads);
        for (std::size_t k = 0; k < n; ++k)
          distance(*body_pairs[k].a, pa[k], *body_pairs[k].b, pb[k], {}, &body_loop[k]);
      }
      std::vector<MarginResult> batch(n), fixed(n), bodies(n), cold(n);
      if (margin == 0.0) {
        intersects_batch(s.pairs, pa, pb, batch, batch_caches, {}, threads);
        intersects_batch(*s.pairs[0].a, pa, *s.pairs[0].b, pb, fixed, fixed_batch, {}, threads);
        intersects_batch(body_pairs, pa, pb, bodies, body_batch, {}, threads);
      } else {
        within_margin_batch(s.pairs, pa, pb, margin, batch, batch_caches, {}, threads);
        within_margin_batch(*s.pairs[0].a, pa, *s.pairs[0].b, pb, margin, fixed, fixed_batch, {},
                            threads);
        within_margin_batch(body_pairs, pa, pb, margin, bodies, body_batch, {}, threads);
      }
      within_margin_batch(s.pairs, pa, pb, margin, cold, {}, {}, threads);
      for (std::size_t k = 0; k < n; ++k) {
        const MarginResult loop = within_margin(*s.pairs[k].a, pa[k], *s.pairs[k].b, pb[k],
                                                margin, {}, &loop_caches[k]);
        EXPECT_TRUE(same_margin(batch[k], loop)) << "pair " << k << ", frame " << frame;
        expect_same_cache(batch_caches[k], loop_caches[k], k);
        const MarginResult one = within_margin(*s.pairs[0].a, pa[k], *s.pairs[0].b, pb[k], margin,
                                               {}, &fixed_loop[k]);
        EXPECT_TRUE(same_margin(fixed[k], one)) << "fixed pair, row " << k;
        const MarginResult body = within_margin(*body_pairs[k].a, pa[k], *body_pairs[k].b, pb[k],
                                                margin, {}, &body_loop[k]);
        EXPECT_TRUE(same_margin(bodies[k], body)) << "body pair " << k << ", frame " << frame;
        const MarginResult once =
            within_margin(*s.pairs[k].a, pa[k], *s.pairs[k].b, pb[k], margin);
        EXPECT_TRUE(same_margin(cold[k], once)) << "cold pair " << k;
        within += loop.is_within() ? 1 : 0;
        beyond += loop.status == MarginStatus::beyond ? 1 : 0;
      }
      step(motion, pa);
      step(motion, pb);
    }
    EXPECT_GE(within, 50) << "the batch should mix verdicts";
    EXPECT_GE(beyond, 50) << "the batch should mix verdicts";
  }
}

// The slow twin: the full distance query compared with the margin gives
// the same verdicts, up to the contact band.
TEST(MarginBatch, VerdictsAreTheFullDistanceComparedWithTheMargin) {
  Rng rng(2604);
  const Scene s = make_scene(rng, 400);
  const std::size_t n = s.pairs.size();
  // R is about 4 here: the band 64 u R is about 6e-14; a thousand times it.
  constexpr double kBand = 1e-10;
  int within = 0;
  for (const double margin : {0.0, 0.05, 0.5}) {
    std::vector<MarginResult> hits(n);
    std::vector<DistanceCache> caches(n);
    within_margin_batch(s.pairs, s.poses_a, s.poses_b, margin, hits, caches, {}, 2);
    for (std::size_t k = 0; k < n; ++k) {
      const DistanceResult d = distance(*s.pairs[k].a, s.poses_a[k], *s.pairs[k].b, s.poses_b[k]);
      const bool contact = d.status == Status::touching || d.status == Status::intersecting;
      if (contact || d.distance < margin - kBand) {
        EXPECT_TRUE(hits[k].is_within()) << "pair " << k << " at " << d.distance;
        EXPECT_LE(hits[k].upper_bound, margin + kBand) << "pair " << k;
        if (!contact) {
          EXPECT_GE(hits[k].upper_bound, d.distance - kBand) << "pair " << k;
        }
        ++within;
      } else if (d.distance > margin + kBand) {
        EXPECT_EQ(hits[k].status, MarginStatus::beyond) << "pair " << k << " at " << d.distance;
        EXPECT_GT(hits[k].lower_bound, margin) << "pair " << k;
        EXPECT_LE(hits[k].lower_bound, d.distance + kBand) << "pair " << k;
      }
    }
  }
  EXPECT_GE(within, 100);
}

TEST(MarginBatch, BadInputIsRefusedByNameBeforeAnythingIsWritten) {
  Rng rng(2605);
  const Scene s = make_scene(rng, 80);
  const std::size_t n = s.pairs.size();
  std::vector<MarginResult> results(n);
  for (MarginResult& r : results) r.margin = -7.0;  // a mark: untouched
  std::vector<DistanceCache> caches(n);
  const auto untouched = [&] {
    return std::all_of(results.begin(), results.end(), [](const MarginResult& r) {
      return r.margin == -7.0;
    }) && std::all_of(caches.begin(), caches.end(), [](const DistanceCache& c) {
      return c.is_cold();
    });
  };
  EXPECT_EQ(invalid_input_message([&] {
              within_margin_batch(s.pairs, s.poses_a, s.poses_b, -0.1, results, caches, {}, 2);
            }),
            "within_margin_batch: margin must be finite and >= 0, got -0.1");
  EXPECT_EQ(invalid_input_message([&] {
              within_margin_batch(s.pairs, s.poses_a, s.poses_b,
                                  std::numeric_limits<double>::quiet_NaN(), results, caches, {}, 2);
            }),
            "within_margin_batch: margin must be finite and >= 0, got nan");
  std::vector<Pose> bad = s.poses_b;
  bad[41].translation.y() = std::numeric_limits<double>::infinity();
  const std::string pose_message = invalid_input_message(
      [&] { intersects_batch(s.pairs, s.poses_a, bad, results, caches, {}, 2); });
  EXPECT_TRUE(pose_message.starts_with("intersects_batch: poses_b[41]")) << pose_message;
  EXPECT_EQ(invalid_input_message([&] {
              within_margin_batch(s.pairs, s.poses_a, s.poses_b, 0.1,
                                  std::span<MarginResult>(results).first(n - 1), caches, {}, 2);
            }),
            "within_margin_batch: results has 79 elements, expected 80 (one per pair)");
  DistanceOptions options;
  options.max_iterations = 0;
  const std::string options_message = invalid_input_message(
      [&] { within_margin_batch(s.pairs, s.poses_a, s.poses_b, 0.1, results, caches, options, 2); });
  EXPECT_TRUE(options_message.starts_with("within_margin_batch: options")) << options_message;
  EXPECT_TRUE(untouched());
}

}  // namespace
}  // namespace proxima
