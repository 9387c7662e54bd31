// Micro-benchmarks of the closed-form closest-point kernels (layer 2), S =
// double. Each benchmark cycles through a precomputed array of seeded random
// inputs, so that branch prediction sees the real mix of regions and the
// cost of a call is measured, not the cost of one input.
//
//   closest_point_bench --benchmark_min_time=0.2
//
// "mixed": features in the unit cube, the second shifted by up to 2 units
// (every region type occurs). "face" / "interior": the main path only (a
// point above a triangle's interior; segments whose closest points are both
// interior), which is what a tracked query repeats. "thin": slivers and
// nearly parallel segments, the degenerate paths.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "proxima/geometry/closest_point.h"

namespace {

using proxima::ClosestPoints;
using proxima::KernelTolerance;
using proxima::Vec3;

constexpr std::size_t kInputs = 1024;  // a power of two: the index wraps with a mask

struct Input {
  std::array<Vec3, 3> a, b;
};

class Gen {
 public:
  explicit Gen(std::uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  Vec3 cube(double h = 1) { return {uniform(-h, h), uniform(-h, h), uniform(-h, h)}; }
  Vec3 unit() {
    for (;;) {
      const Vec3 v = cube();
      if (v.norm() > 0.1) return v.normalized();
    }
  }

 private:
  std::mt19937_64 rng_;
};

std::vector<Input> mixed(std::uint64_t seed) {
  Gen g(seed);
  std::vector<Input> in(kInputs);
  for (Input& x : in) {
    const Vec3 shift = g.cube(2);
    for (auto& v : x.a) v = g.cube();
    for (auto& v : x.b) v = g.cube() + shift;
  }
  return in;
}

// A triangle in the unit cube and a point above its interior.
std::vector<Input> face(std::uint64_t seed) {
  Gen g(seed);
  std::vector<Input> in(kInputs);
  for (Input& x : in) {
    for (auto& v : x.b) v = g.cube();
    const double s = g.uniform(0.05, 0.9), t = g.uniform(0.05, 0.95 - s);
    const Vec3 n = (x.b[1] - x.b[0]).cross(x.b[2] - x.b[0]).normalized();
    x.a[0] = x.b[0] + s * (x.b[1] - x.b[0]) + t * (x.b[2] - x.b[0]) + g.uniform(0.1, 1) * n;
  }
  return in;
}

// Two skew segments whose closest points are inside both.
std::vector<Input> interior(std::uint64_t seed) {
  Gen g(seed);
  std::vector<Input> in(kInputs);
  for (Input& x : in) {
    const Vec3 c = g.cube(), d0 = g.unit(), d1 = g.unit();
    const Vec3 gap = d0.cross(d1).normalized() * g.uniform(0.1, 1);
    const double s = g.uniform(0.2, 0.8), t = g.uniform(0.2, 0.8);
    x.a[0] = c - s * d0;
    x.a[1] = c + (1 - s) * d0;
    x.b[0] = c + gap - t * d1;
    x.b[1] = c + gap + (1 - t) * d1;
  }
  return in;
}

// Slivers (relative thickness 1e-9) and nearly parallel segments (1e-9 rad).
std::vector<Input> thin(std::uint64_t seed) {
  Gen g(seed);
  std::vector<Input> in(kInputs);
  for (Input& x : in) {
    const Vec3 t0 = g.cube(), dir = g.unit() * g.uniform(0.5, 2);
    Vec3 across = g.unit().cross(dir).normalized();
    x.b = {t0, t0 + dir, t0 + g.uniform(0.1, 0.9) * dir + 1e-9 * across};
    x.a[0] = g.cube(2);
    x.a[1] = x.a[0] + dir + 1e-9 * g.unit();
    x.a[2] = x.a[0] + g.cube();
  }
  return in;
}

template <class Kernel>
void run(benchmark::State& state, const std::vector<Input>& in, Kernel kernel) {
  const KernelTolerance<double> tol = proxima::kernel_tolerance(4.0);
  std::size_t i = 0;
  for (auto _ : state) {
    const Input& x = in[i++ & (kInputs - 1)];
    const ClosestPoints<double> r = kernel(x, tol);
    benchmark::DoNotOptimize(r.distance_squared);
    benchmark::DoNotOptimize(r.active_a);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

const auto point_point = [](const Input& x, const KernelTolerance<double>&) {
  return proxima::closest_point_point(x.a[0], x.b[0]);
};
const auto point_segment = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_point_segment(x.a[0], x.b[0], x.b[1], tol);
};
const auto point_triangle = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_point_triangle(x.a[0], x.b[0], x.b[1], x.b[2], tol);
};
const auto segment_segment = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_segment_segment(x.a[0], x.a[1], x.b[0], x.b[1], tol);
};
const auto segment_triangle = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_segment_triangle(x.a[0], x.a[1], x.b[0], x.b[1], x.b[2], tol);
};
const auto triangle_triangle = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_triangle_triangle(x.a[0], x.a[1], x.a[2], x.b[0], x.b[1], x.b[2], tol);
};
const auto dispatch_point_triangle = [](const Input& x, const KernelTolerance<double>& tol) {
  return proxima::closest_points<double>(x.a.data(), 1, x.b.data(), 3, tol);
};

void BM_PointPoint(benchmark::State& s) { run(s, mixed(1), point_point); }
void BM_PointSegment_Mixed(benchmark::State& s) { run(s, mixed(2), point_segment); }
void BM_PointTriangle_Mixed(benchmark::State& s) { run(s, mixed(3), point_triangle); }
void BM_PointTriangle_Face(benchmark::State& s) { run(s, face(4), point_triangle); }
void BM_PointTriangle_Thin(benchmark::State& s) { run(s, thin(5), point_triangle); }
void BM_ClosestPoints_PointTriangle_Mixed(benchmark::State& s) {
  run(s, mixed(3), dispatch_point_triangle);
}
void BM_SegmentSegment_Mixed(benchmark::State& s) { run(s, mixed(6), segment_segment); }
void BM_SegmentSegment_Interior(benchmark::State& s) { run(s, interior(7), segment_segment); }
void BM_SegmentSegment_NearlyParallel(benchmark::State& s) { run(s, thin(8), segment_segment); }
void BM_SegmentTriangle_Mixed(benchmark::State& s) { run(s, mixed(9), segment_triangle); }
void BM_TriangleTriangle_Mixed(benchmark::State& s) { run(s, mixed(10), triangle_triangle); }

BENCHMARK(BM_PointPoint);
BENCHMARK(BM_PointSegment_Mixed);
BENCHMARK(BM_PointTriangle_Mixed);
BENCHMARK(BM_PointTriangle_Face);
BENCHMARK(BM_PointTriangle_Thin);
BENCHMARK(BM_ClosestPoints_PointTriangle_Mixed);
BENCHMARK(BM_SegmentSegment_Mixed);
BENCHMARK(BM_SegmentSegment_Interior);
BENCHMARK(BM_SegmentSegment_NearlyParallel);
BENCHMARK(BM_SegmentTriangle_Mixed);
BENCHMARK(BM_TriangleTriangle_Mixed);

}  // namespace

BENCHMARK_MAIN();
