// Body queries (body.h): what a radius and the one call for any two bodies
// cost over the plain convex query, tracked along the same sequence.
//
//   ./build/release/bench/body_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
//
// Rows, each tracked (one cache across the sequence), time per query:
//   Convex/N         distance(ConvexPolytope, ..., DistanceCache*): the baseline
//   BodyConvex/N     the same hulls as Bodies with radius 0.1 (separated)
//   BodyOverlap/N    radius 0.8: the rounded bodies overlap, the cores do not
//   BodyCoreOverlap/N  B 0.6 from A's center: the cores overlap (penetration
//                    depth, tracked through BodyCache::penetration)
//   BodyMixed/N      a convex Body against a one-piece compound Body
//   Capsules         two capsules (segment cores)
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/shape/primitives.h"

namespace proxima {
namespace {

std::vector<Vec3> sphere_points(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(g(rng), g(rng), g(rng));
    if (p.norm() > 1e-3) pts.push_back(p.normalized());
  }
  return pts;
}

constexpr int kSteps = 4096;

// B drifts around A at `distance` between centers, turning slowly.
std::vector<Pose> sequence(double distance) {
  std::vector<Pose> poses;
  for (int i = 0; i < kSteps; ++i) {
    const double t = 2.0 * M_PI * i / kSteps;
    poses.emplace_back(Quat(Eigen::AngleAxisd(t, Vec3(1, 2, 3).normalized())),
                       Vec3(distance * std::cos(t), distance * std::sin(t), 0.1 * std::sin(3 * t)));
  }
  return poses;
}

void BM_Convex(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ConvexPolytope a(sphere_points(n, 1)), b(sphere_points(n, 2));
  const std::vector<Pose> poses = sequence(2.5);
  DistanceCache cache;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(distance(a, Pose::identity(), b, poses[i], {}, &cache));
    i = (i + 1) % poses.size();
  }
}

void run_body(benchmark::State& state, double radius, double center_distance, bool mixed,
              bool depth = true) {
  const int n = static_cast<int>(state.range(0));
  const Body a(std::make_shared<const ConvexPolytope>(sphere_points(n, 1)), radius);
  const Body convex_b(std::make_shared<const ConvexPolytope>(sphere_points(n, 2)), radius);
  const Body b = mixed ? Body(convex_b.compound(), radius) : convex_b;
  const std::vector<Pose> poses = sequence(center_distance);
  DistanceOptions options;
  options.penetration = depth;
  BodyCache cache;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(distance(a, Pose::identity(), b, poses[i], options, &cache));
    i = (i + 1) % poses.size();
  }
}

void BM_BodyConvex(benchmark::State& state) { run_body(state, 0.1, 2.5, false); }
void BM_BodyOverlap(benchmark::State& state) { run_body(state, 0.8, 2.5, false); }
void BM_BodyCoreOverlap(benchmark::State& state) { run_body(state, 0.1, 0.6, false); }
// The cores overlap and the caller skips the depth (a Scene's default).
void BM_BodyCoreOverlapStatusOnly(benchmark::State& state) {
  run_body(state, 0.1, 0.6, false, false);
}
void BM_BodyMixed(benchmark::State& state) { run_body(state, 0.1, 2.5, true); }

void BM_Capsules(benchmark::State& state) {
  const Body a = make_capsule(1.0, 0.2), b = make_capsule(0.5, 0.3);
  const std::vector<Pose> poses = sequence(2.0);
  BodyCache cache;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(distance(a, Pose::identity(), b, poses[i], {}, &cache));
    i = (i + 1) % poses.size();
  }
}

BENCHMARK(BM_Convex)->Arg(16)->Arg(256);
BENCHMARK(BM_BodyConvex)->Arg(16)->Arg(256);
BENCHMARK(BM_BodyOverlap)->Arg(16)->Arg(256);
BENCHMARK(BM_BodyCoreOverlap)->Arg(16)->Arg(256);
BENCHMARK(BM_BodyCoreOverlapStatusOnly)->Arg(16)->Arg(256);
BENCHMARK(BM_BodyMixed)->Arg(16)->Arg(256);
BENCHMARK(BM_Capsules);

}  // namespace
}  // namespace proxima

BENCHMARK_MAIN();
