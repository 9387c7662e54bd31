// Micro-benchmarks of the GJK baselines, nanoseconds per query:
//   gjk_cold / enhanced_gjk_cold:  independent random poses (Enhanced GJK
//       with a cold cache every query: hill climbing from vertex 0);
//   gjk_tracking / enhanced_gjk_tracking:  B circles A in small steps (about
//       1% of the body radius and 0.2 degrees per step), Enhanced GJK with the
//       pair's cache kept between queries (classic GJK has no state: the
//       same motion measured for comparison).
// Bodies: N points on the unit sphere (all hull vertices), N = 8 .. 4096,
// separated by about one body size. The counter `iterations` is the mean
// number of support evaluations per query.
//
//   build/<dir>/bench/gjk_bench --benchmark_min_time=0.2
#include "proxima/detail/narrowphase/gjk.h"
#include "support/random.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <vector>

namespace {

using proxima::ConvexPolytope;
using proxima::DistanceCache;
using proxima::DistanceOptions;
using proxima::DistanceResult;
using proxima::Mat3;
using proxima::Pose;
using proxima::Vec3;

using proxima::bench::points_on_sphere;
using proxima::bench::random_rotation;
using proxima::bench::random_unit_vector;
using proxima::bench::Rng;

struct Pair {
  std::unique_ptr<ConvexPolytope> a;
  std::unique_ptr<ConvexPolytope> b;
};

// Bodies are built once per N (the hull of 4096 points is not what is timed).
const Pair& bodies(int n) {
  static std::map<int, Pair> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    Rng rng(0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(n));
    const std::vector<Vec3> pa = points_on_sphere(rng, n);
    const std::vector<Vec3> pb = points_on_sphere(rng, n);
    Pair p{std::make_unique<ConvexPolytope>(pa), std::make_unique<ConvexPolytope>(pb)};
    it = cache.emplace(n, std::move(p)).first;
  }
  return it->second;
}

// The contact band as distance() chooses it: 64 u R, R bounded from the
// pose without mapping vertices.
double contact_tolerance(const Pair& p, const Pose& b_in_a) {
  const double r = std::max(p.a->scale(), b_in_a.translation.cwiseAbs().maxCoeff() + std::sqrt(3.0) * p.b->scale());
  return 64.0 * proxima::kUnitRoundoff * r;
}

struct Query {
  Pose b_in_a;
  double tolerance;
};

std::vector<Query> random_poses(const Pair& p, int count) {
  Rng rng(12345);
  std::vector<Query> out;
  for (int i = 0; i < count; ++i) {
    const Pose pose(random_rotation(rng), Vec3(3.0 * random_unit_vector(rng)));
    out.push_back({pose, contact_tolerance(p, pose)});
  }
  return out;
}

// A closed loop: B at distance 3 circling A (with a vertical wobble) and
// spinning slowly about a fixed axis.
std::vector<Query> tracking_poses(const Pair& p, int count) {
  std::vector<Query> out;
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  for (int i = 0; i < count; ++i) {
    const double s = 2.0 * M_PI * i / count;
    const Pose pose(Mat3(Eigen::AngleAxisd(s, axis)), Vec3(3.0 * std::cos(s), 3.0 * std::sin(s), 0.5 * std::sin(3.0 * s)));
    out.push_back({pose, contact_tolerance(p, pose)});
  }
  return out;
}

DistanceOptions options(proxima::Algorithm algorithm) {
  DistanceOptions o;
  o.algorithm = algorithm;
  return o;
}

void report(benchmark::State& state, std::int64_t iterations) {
  state.SetItemsProcessed(state.iterations());
  state.counters["iterations"] =
      benchmark::Counter(static_cast<double>(iterations) / static_cast<double>(std::max<std::int64_t>(state.iterations(), 1)));
}

constexpr int kRandomPoses = 256;
// One loop of radius 3 in 2000 steps: 0.0094 (about 1% of a body radius) and
// 0.18 degrees per step.
constexpr int kTrackingSteps = 2000;

void BM_gjk_cold(benchmark::State& state) {
  const Pair& p = bodies(static_cast<int>(state.range(0)));
  const std::vector<Query> poses = random_poses(p, kRandomPoses);
  const DistanceOptions o = options(proxima::Algorithm::gjk);
  std::size_t k = 0;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    const Query& q = poses[k++ % poses.size()];
    const DistanceResult r = proxima::gjk_distance(*p.a, *p.b, q.b_in_a, o, q.tolerance);
    benchmark::DoNotOptimize(r.distance);
    iterations += r.iterations;
  }
  report(state, iterations);
}

void BM_enhanced_gjk_cold(benchmark::State& state) {
  const Pair& p = bodies(static_cast<int>(state.range(0)));
  const std::vector<Query> poses = random_poses(p, kRandomPoses);
  const DistanceOptions o = options(proxima::Algorithm::enhanced_gjk);
  std::size_t k = 0;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    const Query& q = poses[k++ % poses.size()];
    DistanceCache cache;
    const DistanceResult r = proxima::enhanced_gjk_distance(*p.a, *p.b, q.b_in_a, o, q.tolerance, cache);
    benchmark::DoNotOptimize(r.distance);
    iterations += r.iterations;
  }
  report(state, iterations);
}

void BM_gjk_tracking(benchmark::State& state) {
  const Pair& p = bodies(static_cast<int>(state.range(0)));
  const std::vector<Query> poses = tracking_poses(p, kTrackingSteps);
  const DistanceOptions o = options(proxima::Algorithm::gjk);
  std::size_t k = 0;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    const Query& q = poses[k++ % poses.size()];
    const DistanceResult r = proxima::gjk_distance(*p.a, *p.b, q.b_in_a, o, q.tolerance);
    benchmark::DoNotOptimize(r.distance);
    iterations += r.iterations;
  }
  report(state, iterations);
}

void BM_enhanced_gjk_tracking(benchmark::State& state) {
  const Pair& p = bodies(static_cast<int>(state.range(0)));
  const std::vector<Query> poses = tracking_poses(p, kTrackingSteps);
  const DistanceOptions o = options(proxima::Algorithm::enhanced_gjk);
  DistanceCache cache;
  std::size_t k = 0;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    const Query& q = poses[k++ % poses.size()];
    const DistanceResult r = proxima::enhanced_gjk_distance(*p.a, *p.b, q.b_in_a, o, q.tolerance, cache);
    benchmark::DoNotOptimize(r.distance);
    iterations += r.iterations;
  }
  report(state, iterations);
}

}  // namespace

BENCHMARK(BM_gjk_cold)->Arg(8)->Arg(64)->Arg(512)->Arg(4096)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_enhanced_gjk_cold)->Arg(8)->Arg(64)->Arg(512)->Arg(4096)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_gjk_tracking)->Arg(8)->Arg(64)->Arg(512)->Arg(4096)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_enhanced_gjk_tracking)->Arg(8)->Arg(64)->Arg(512)->Arg(4096)->Unit(benchmark::kNanosecond);

BENCHMARK_MAIN();
