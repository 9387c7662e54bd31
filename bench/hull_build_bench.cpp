// Hull build driver: time and memory of one ConvexPolytope build, one input
// per process so that the peak resident set (/usr/bin/time -v) belongs to
// that input alone.
//
//   hull_build_bench <shape> <n> [repeats]
//
// Shapes (seeded, portable draws):
//   ball      n points uniform in the unit ball (mostly interior)
//   sphere    n points on the unit sphere, rounded (all extreme)
//   cylinder  a rounded, nearly flat case: 2 x n/2 points on the two rim
//             circles of a thin cylinder (radius 1, height 0.01), rotated
//             and moved to distance 500
// Prints one line: shape, n, vertices, faces, best build time in seconds
// over the repeats, and the polytope's memory_bytes().
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "proxima/shape/polytope.h"
#include "support/random.h"

namespace {

using namespace proxima;

std::vector<Vec3> make_points(const std::string& shape, int n) {
  bench::Rng rng(20261125);
  std::vector<Vec3> pts;
  pts.reserve(static_cast<std::size_t>(n));
  if (shape == "ball") {
    while (static_cast<int>(pts.size()) < n) {
      const Vec3 p(bench::uniform(rng, -1, 1), bench::uniform(rng, -1, 1),
                   bench::uniform(rng, -1, 1));
      if (p.squaredNorm() <= 1.0) pts.push_back(p);
    }
  } else if (shape == "sphere") {
    pts = bench::points_on_sphere(rng, n);
  } else if (shape == "cylinder") {
    const Mat3 rotation = bench::random_rotation(rng);
    const Vec3 offset = 500.0 * bench::random_unit_vector(rng);
    const int half = n / 2;
    for (int cap = 0; cap < 2; ++cap) {
      for (int i = 0; i < half; ++i) {
        const double angle = 2.0 * M_PI * bench::uniform01(rng);
        const Vec3 local(std::cos(angle), std::sin(angle), cap == 0 ? 0.0 : 0.01);
        pts.push_back(Vec3(rotation * local) + offset);
      }
    }
  } else {
    std::fprintf(stderr, "hull_build_bench: unknown shape '%s' (ball, sphere, cylinder)\n",
                 shape.c_str());
    std::exit(2);
  }
  return pts;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: hull_build_bench <ball|sphere|cylinder> <n> [repeats]\n");
    return 2;
  }
  const std::string shape = argv[1];
  const int n = std::atoi(argv[2]);
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 1;
  if (n < 4) {
    std::fprintf(stderr, "hull_build_bench: n must be at least 4\n");
    return 2;
  }
  const std::vector<Vec3> pts = make_points(shape, n);
  double best = 1e300;
  int vertices = 0, faces = 0;
  std::size_t bytes = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const ConvexPolytope p(pts);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double>(t1 - t0).count());
    vertices = p.vertex_count();
    faces = p.face_count();
    bytes = p.memory_bytes();
  }
  std::printf("%s n=%d vertices=%d faces=%d build_s=%.4f bytes=%zu\n", shape.c_str(), n, vertices,
              faces, best, bytes);
  return 0;
}
