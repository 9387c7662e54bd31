// The scene's broad phase, per step: sweep and prune against the dynamic
// AABB tree, and the two ways of boxing a convex body (bounding sphere or
// support points), at 1,000 and 10,000 bodies; then the whole Scene::step
// (boxes, broad phase, tracked narrow phase) with each broad phase.
//
// The scenario: bodies drawn from 64 random polytopes of 20 to 200 vertices
// (points on a sphere or in a cube, radius about 0.5 to 1.2), placed in a
// cube sized so that each has a few neighbours within the margin (0.1), each
// moving with its own small constant velocity (up to 0.02 per step, about 2%
// of a body) and spin (up to 0.02 rad per step), bouncing off the walls.
// Every benchmark iteration is one step of that motion, so the broad phases
// see the coherence they are built for.
//
//   ./build/release/bench/broad_phase_bench --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
//
// Counters: pairs = candidate pairs per step; for Scene::step also close
// pairs, warm pairs (candidates that kept their cache) and contacts (close
// pairs touching or intersecting: the bodies pass through each other).
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "scene/broad_phase.h"
#include "proxima/scene/scene.h"
#include "support/random.h"

namespace proxima {
namespace {

constexpr int kPoolSize = 64;
constexpr double kMargin = 0.1;
// Side of the cube holding 120 bodies with a few neighbours each (the
// density of tests/scene/scene_test.cpp); grown with the cube root of the count.
constexpr double kSideAt120 = 10.0;

using bench::random_quaternion;
using bench::random_unit_vector;
using bench::uniform;

const std::vector<std::shared_ptr<const ConvexPolytope>>& pool() {
  static const auto bodies = [] {
    std::vector<std::shared_ptr<const ConvexPolytope>> out;
    std::mt19937_64 rng(20261122);
    for (int i = 0; i < kPoolSize; ++i) {
      const int n = 20 + static_cast<int>(rng() % 181);
      const double radius = uniform(rng, 0.5, 1.2);
      std::vector<Vec3> pts;
      for (int j = 0; j < n; ++j) {
        pts.push_back(
            i % 2 == 0 ? Vec3(radius * random_unit_vector(rng))
                       : Vec3(radius * 0.6 *
                              Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1))));
      }
      out.push_back(std::make_shared<const ConvexPolytope>(pts));
    }
    return out;
  }();
  return bodies;
}

// Bodies moving with constant velocities in a box, bouncing off its walls.
struct Motion {
  std::vector<std::shared_ptr<const ConvexPolytope>> bodies;
  std::vector<Pose> poses;
  std::vector<Vec3> velocity;
  std::vector<Mat3> spin;
  double side = 0.0;

  explicit Motion(int n) : side(kSideAt120 * std::cbrt(n / 120.0)) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(n));
    for (int i = 0; i < n; ++i) {
      bodies.push_back(pool()[rng() % kPoolSize]);
      poses.emplace_back(random_quaternion(rng),
                         Vec3(uniform(rng, 0, side), uniform(rng, 0, side), uniform(rng, 0, side)));
      velocity.push_back(uniform(rng, 0, 0.02) * random_unit_vector(rng));
      spin.push_back(
          Eigen::AngleAxisd(uniform(rng, 0, 0.02), random_unit_vector(rng)).toRotationMatrix());
    }
  }

  void advance() {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      Pose& p = poses[i];
      p.rotation = spin[i] * p.rotation;
      p.translation += velocity[i];
      for (int k = 0; k < 3; ++k) {
        if (p.translation[k] < 0 || p.translation[k] > side) velocity[i][k] = -velocity[i][k];
      }
    }
  }
};

enum class BoxKind { sphere, support };

// Boxes and pair finding only: what the choice of broad phase and of box
// changes, without the narrow phase.
void broad_phase(benchmark::State& state, BroadPhase kind, BoxKind box_kind) {
  const int n = static_cast<int>(state.range(0));
  Motion motion(n);
  auto finder = detail::make_pair_finder(kind);
  for (int i = 0; i < n; ++i) finder->add(i);
  std::vector<detail::Aabb> boxes(static_cast<std::size_t>(n));
  std::vector<detail::BoxHints> hints(static_cast<std::size_t>(n));
  std::vector<std::uint64_t> pairs;
  const auto compute_boxes = [&] {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const ConvexPolytope& body = *motion.bodies[i];
      detail::Aabb b = box_kind == BoxKind::sphere
                           ? detail::sphere_box(body, motion.poses[i])
                           : detail::support_box(body, motion.poses[i], hints[i]);
      b.lo.array() -= 0.5 * kMargin;
      b.hi.array() += 0.5 * kMargin;
      boxes[i] = b;
    }
  };
  compute_boxes();
  finder->find_pairs(boxes, pairs);  // the first, unsorted call is not timed
  double total_pairs = 0;
  for (auto _ : state) {
    state.PauseTiming();
    motion.advance();
    state.ResumeTiming();
    compute_boxes();
    finder->find_pairs(boxes, pairs);
    benchmark::DoNotOptimize(pairs.data());
    total_pairs += static_cast<double>(pairs.size());
  }
  state.counters["pairs"] = total_pairs / static_cast<double>(state.iterations());
}

void scene_step(benchmark::State& state, BroadPhase kind) {
  const int n = static_cast<int>(state.range(0));
  Motion motion(n);
  SceneOptions options;
  options.margin = kMargin;
  options.broad_phase = kind;
  Scene scene(options);
  for (int i = 0; i < n; ++i)
    scene.add(motion.bodies[static_cast<std::size_t>(i)],
              motion.poses[static_cast<std::size_t>(i)]);
  scene.step();
  double candidates = 0, close = 0, warm = 0, contacts = 0;
  for (auto _ : state) {
    state.PauseTiming();
    motion.advance();
    state.ResumeTiming();
    for (int i = 0; i < n; ++i) scene.set_pose(i, motion.poses[static_cast<std::size_t>(i)]);
    for (const ClosePair& p : scene.step()) {
      contacts += p.result.status == Status::intersecting || p.result.status == Status::touching;
    }
    candidates += scene.stats().candidate_pairs;
    close += scene.stats().close_pairs;
    warm += scene.stats().warm_pairs;
  }
  const auto it = static_cast<double>(state.iterations());
  state.counters["pairs"] = candidates / it;
  state.counters["close"] = close / it;
  state.counters["warm"] = warm / it;
  state.counters["contacts"] = contacts / it;
}

void register_all() {
  for (const BroadPhase kind : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
    for (const BoxKind box : {BoxKind::sphere, BoxKind::support}) {
      const std::string name = std::string("broad_phase/") + to_string(kind) + "/" +
                               (box == BoxKind::sphere ? "sphere_box" : "support_box");
      benchmark::RegisterBenchmark(name.c_str(), broad_phase, kind, box)
          ->Arg(1000)
          ->Arg(10000)
          ->Unit(benchmark::kMicrosecond);
    }
  }
  for (const BroadPhase kind : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
    const std::string name = std::string("scene_step/") + to_string(kind);
    benchmark::RegisterBenchmark(name.c_str(), scene_step, kind)
        ->Arg(1000)
        ->Arg(10000)
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace
}  // namespace proxima

int main(int argc, char** argv) {
  proxima::register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
