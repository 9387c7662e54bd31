// Micro-benchmarks of layers 3 and 4: support functions, hull build, memory.
//
//   support_brute_force         O(N) scan, random directions
//   support_hill_climb cold     hint = 0, random directions
//   support_hill_climb warm     hint = previous answer, a slowly rotating
//                               direction (the tracking case)
//   build                       ConvexPolytope from N points on a sphere
//                               (all extreme) and N points in a cube (mostly
//                               interior), with memory counters
//
// Polytopes: N = 8, 64, 512, 4096, 10000 points on the unit sphere, seeded.
#include "proxima/shape/polytope.h"
#include "proxima/shape/support.h"
#include "support/random.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <vector>

namespace proxima {
namespace {

using bench::random_unit_vector;
using bench::Rng;
using bench::uniform;

std::vector<Vec3> sphere_points(int n, std::uint64_t seed) {
  Rng rng(seed);
  return bench::points_on_sphere(rng, n);
}

std::vector<Vec3> cube_points(int n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
  return pts;
}

const ConvexPolytope& sphere_polytope(int n) {
  static std::map<int, std::unique_ptr<ConvexPolytope>> cache;
  auto& slot = cache[n];
  if (!slot) slot = std::make_unique<ConvexPolytope>(sphere_points(n, 2024));
  return *slot;
}

// Random unit directions, cycled through (a power of two: cheap wrap).
constexpr std::size_t kDirections = 4096;
const std::vector<Vec3>& random_directions() {
  static const std::vector<Vec3> dirs = [] {
    Rng rng(7);
    std::vector<Vec3> d;
    for (std::size_t i = 0; i < kDirections; ++i) d.push_back(random_unit_vector(rng));
    return d;
  }();
  return dirs;
}

// A slowly rotating direction: 1e-3 rad per query about a tilted axis, so
// the support vertex changes every few queries on the larger polytopes.
const std::vector<Vec3>& rotating_directions() {
  static const std::vector<Vec3> dirs = [] {
    std::vector<Vec3> d;
    const Eigen::AngleAxisd step(1e-3, Vec3(0.3, 0.4, 1.0).normalized());
    Vec3 dir = Vec3(1, 0.2, -0.1).normalized();
    for (std::size_t i = 0; i < kDirections; ++i) {
      d.push_back(dir);
      dir = step * dir;
    }
    return d;
  }();
  return dirs;
}

void BM_SupportBruteForce(benchmark::State& state) {
  const ConvexPolytope& p = sphere_polytope(static_cast<int>(state.range(0)));
  const auto& dirs = random_directions();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(support_brute_force(p.vertices(), dirs[i++ % kDirections]));
  }
  state.counters["vertices"] = p.vertex_count();
}

void BM_SupportHillClimbCold(benchmark::State& state) {
  const ConvexPolytope& p = sphere_polytope(static_cast<int>(state.range(0)));
  const auto& dirs = random_directions();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(support_hill_climb(p, dirs[i++ % kDirections], 0));
  }
}

void BM_SupportHillClimbWarm(benchmark::State& state) {
  const ConvexPolytope& p = sphere_polytope(static_cast<int>(state.range(0)));
  const auto& dirs = rotating_directions();
  std::size_t i = 0;
  int hint = 0;
  for (auto _ : state) {
    hint = support_hill_climb(p, dirs[i++ % kDirections], hint);
    benchmark::DoNotOptimize(hint);
  }
}

// Memory of one polytope against the raw vertex array (24 bytes a vertex)
// and the vertex adjacency (CSR offsets and neighbour ids, 4 bytes each).
void memory_counters(benchmark::State& state, const ConvexPolytope& p) {
  const double raw = static_cast<double>(p.vertices().size_bytes());
  const double adjacency = static_cast<double>(p.adjacency_offsets().size_bytes() + p.adjacency().size_bytes());
  const double bytes = static_cast<double>(p.memory_bytes());
  state.counters["vertices"] = p.vertex_count();
  state.counters["faces"] = p.face_count();
  state.counters["bytes"] = bytes;
  state.counters["raw_vertex_bytes"] = raw;
  state.counters["adjacency_bytes"] = adjacency;
  state.counters["bytes_per_vertex"] = bytes / p.vertex_count();
  state.counters["ratio_to_raw_plus_adjacency"] = bytes / (raw + adjacency);
}

void BM_BuildSphere(benchmark::State& state) {
  const auto pts = sphere_points(static_cast<int>(state.range(0)), 2024);
  for (auto _ : state) {
    const ConvexPolytope p(pts);
    benchmark::DoNotOptimize(p.vertex_count());
  }
  memory_counters(state, ConvexPolytope(pts));
}

void BM_BuildCube(benchmark::State& state) {
  const auto pts = cube_points(static_cast<int>(state.range(0)), 2025);
  for (auto _ : state) {
    const ConvexPolytope p(pts);
    benchmark::DoNotOptimize(p.vertex_count());
  }
  memory_counters(state, ConvexPolytope(pts));
}

void sizes(benchmark::internal::Benchmark* b) {
  for (const int n : {8, 64, 512, 4096, 10000}) b->Arg(n);
}
BENCHMARK(BM_SupportBruteForce)->Apply(sizes);
BENCHMARK(BM_SupportHillClimbCold)->Apply(sizes);
BENCHMARK(BM_SupportHillClimbWarm)->Apply(sizes);
BENCHMARK(BM_BuildSphere)->Apply(sizes)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BuildCube)->Apply(sizes)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace proxima

BENCHMARK_MAIN();
