// Penetration depth benchmarks (include/proxima/detail/penetration/penetration.h): cold and
// tracked queries, the fast algorithm (Gauss-map overlay walk, cached
// margin) against its slow twin (every edge pair), N = 8 ... 4096 points on
// a sphere (seeded). B, a sphere of radius 0.8, sweeps through A (radius 1)
// along a line and back: from 1.5 on one side to 1.5 on the other, so the
// two overlap all along the sweep (penetrating; depth up to 1.8). Time per
// query is the benchmark's time per iteration.
//
//   ./build/release/bench/penetration_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
//
// Sweep: translation only, B's rotation fixed (the tracked path's case).
// Spin: the same sweep with B turning 0.001 radian per step: every tracked
// query re-enumerates (the cache certifies translations only), so it
// measures the cost of that fallback.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "proxima/detail/penetration/penetration.h"
#include "support/random.h"

namespace proxima {
namespace {

constexpr int kSteps = 2000;

std::vector<Pose> sweep(double spin) {
  std::vector<Pose> poses;
  poses.reserve(kSteps);
  const Vec3 dir = Vec3(1.0, 0.3, -0.2).normalized();
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  const Mat3 base =
      Quat(Eigen::AngleAxisd(0.7, Vec3(0.2, -1.0, 0.4).normalized())).toRotationMatrix();
  for (int i = 0; i < kSteps; ++i) {
    // Triangle wave in [-1.5, 1.5]: through A and back.
    const double phase = static_cast<double>(i) / kSteps;
    const double s = phase < 0.5 ? -1.5 + 6.0 * phase : 4.5 - 6.0 * phase;
    const Mat3 r = spin == 0.0
                       ? base
                       : Mat3(Quat(Eigen::AngleAxisd(spin * i, axis)).toRotationMatrix() * base);
    poses.emplace_back(r, s * dir + Vec3(0.01, 0.02, -0.03));
  }
  return poses;
}

struct Bodies {
  ConvexPolytope a, b;
};

Bodies bodies(int n) {
  bench::Rng rng(static_cast<std::uint64_t>(n) * 7919 + 1);
  std::vector<Vec3> pa = bench::points_on_sphere(rng, n, 1.0);
  std::vector<Vec3> pb = bench::points_on_sphere(rng, n, 0.8);
  return {ConvexPolytope(pa), ConvexPolytope(pb)};
}

void report(benchmark::State& state, long candidates, long tracked) {
  state.counters["candidates/query"] =
      benchmark::Counter(static_cast<double>(candidates), benchmark::Counter::kAvgIterations);
  state.counters["tracked"] =
      benchmark::Counter(static_cast<double>(tracked), benchmark::Counter::kAvgIterations);
}

// Fast algorithm; `tracking` keeps the cache between queries.
void fast(benchmark::State& state, bool tracking, double spin) {
  const Bodies x = bodies(static_cast<int>(state.range(0)));
  const std::vector<Pose> poses = sweep(spin);
  PenetrationCache cache;
  std::size_t i = 0;
  long candidates = 0, tracked = 0;
  for (auto _ : state) {
    if (!tracking) cache.reset();
    const PenetrationResult r = penetration_depth(x.a, x.b, poses[i], cache);
    benchmark::DoNotOptimize(r.depth);
    candidates += r.candidates;
    tracked += r.tracked;
    if (++i == poses.size()) i = 0;
  }
  report(state, candidates, tracked);
}

// The slow twin: no cache, so its cold and tracked costs are the same.
void slow(benchmark::State& state) {
  const Bodies x = bodies(static_cast<int>(state.range(0)));
  const std::vector<Pose> poses = sweep(0.0);
  std::size_t i = 0;
  long candidates = 0;
  for (auto _ : state) {
    const PenetrationResult r = penetration_depth_brute_force(x.a, x.b, poses[i]);
    benchmark::DoNotOptimize(r.depth);
    candidates += r.candidates;
    // Stride through the sweep so that a few iterations still see varied poses.
    i = (i + 97) % poses.size();
  }
  report(state, candidates, 0);
}

void Cold(benchmark::State& state) { fast(state, false, 0.0); }
void TrackedSweep(benchmark::State& state) { fast(state, true, 0.0); }
void TrackedSpin(benchmark::State& state) { fast(state, true, 0.001); }
void SlowTwin(benchmark::State& state) { slow(state); }

BENCHMARK(Cold)->RangeMultiplier(8)->Range(8, 4096);
BENCHMARK(TrackedSweep)->RangeMultiplier(8)->Range(8, 4096);
BENCHMARK(TrackedSpin)->RangeMultiplier(8)->Range(8, 4096);
BENCHMARK(SlowTwin)->RangeMultiplier(8)->Range(8, 4096);

}  // namespace
}  // namespace proxima

BENCHMARK_MAIN();
