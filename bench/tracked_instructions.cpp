// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A fixed amount of tracked-query work for instruction counts, which are
// repeatable where timings on a shared machine are not:
//
//   valgrind --tool=callgrind --toggle-collect='proxima::distance(*'
//     build/release/bench/tracked_instructions translation 64
// (one command line)
//
// then instructions per query = the collected total / the printed queries.
// Modes: translation (B circles A, distance about 1), rotation (B spins at
// 0.01 rad per step), fast_rotation (0.1 rad per step), random (unrelated
// poses, warm cache), cold_random (the same poses, cold every query: the
// figure a warm cache must not exceed by more than 10%, issue 14), cold
// (the same poses without a cache, as the paper's cold experiment calls
// distance()). The poses are those of bench/distance_bench.cpp. A third
// argument `rigid` gives the queries poses checked once (RigidPose), so that
// the rigid-pose check of every query is not counted; `extended` asks every
// query for DistanceOptions::extended_precision (its cost against the same
// mode without it).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "proxima/query/distance.h"

namespace {

using proxima::Pose;
using proxima::Quat;
using proxima::Vec3;

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

constexpr int kSteps = 10000;

}  // namespace

int main(int argc, char** argv) {
  const bool rigid_poses = argc == 4 && std::strcmp(argv[3], "rigid") == 0;
  const bool extended = argc == 4 && std::strcmp(argv[3], "extended") == 0;
  if (argc != 3 && !rigid_poses && !extended) {
    std::fprintf(
        stderr,
        "usage: tracked_instructions translation|rotation|fast_rotation|random|cold_random|cold "
        "N [rigid|extended]\n");
    return 2;
  }
  const char* mode = argv[1];
  const int n = std::atoi(argv[2]);
  std::vector<Pose> poses;
  std::mt19937 rng(99);
  std::normal_distribution<double> g;
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  for (int i = 0; i < kSteps; ++i) {
    const double t = 2.0 * M_PI * i / kSteps;
    if (std::strcmp(mode, "translation") == 0) {
      poses.push_back(Pose::from_translation(
          Vec3(3.0 * std::cos(t), 3.0 * std::sin(t), 0.5 * std::sin(3 * t))));
    } else if (std::strcmp(mode, "rotation") == 0 || std::strcmp(mode, "fast_rotation") == 0) {
      const double speed = mode[0] == 'r' ? 0.01 : 0.1;
      poses.emplace_back(Quat(Eigen::AngleAxisd(speed * i, axis)), Vec3(3.0, 0.2, -0.1));
    } else if (std::strcmp(mode, "random") == 0 || std::strcmp(mode, "cold_random") == 0 ||
               std::strcmp(mode, "cold") == 0) {
      const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
      poses.emplace_back(Quat(g(rng), g(rng), g(rng), g(rng)), Vec3(3.0 * dir));
    } else {
      std::fprintf(stderr, "tracked_instructions: unknown mode '%s'\n", mode);
      return 2;
    }
  }
  const proxima::ConvexPolytope a(sphere_points(n, 1));
  const proxima::ConvexPolytope b(sphere_points(n, 2));
  proxima::DistanceCache cache;
  double sum = 0.0;
  const bool cold = std::strcmp(mode, "cold_random") == 0;
  const bool no_cache = std::strcmp(mode, "cold") == 0;
  proxima::DistanceOptions options;
  options.extended_precision = extended;
  if (rigid_poses) {
    std::vector<proxima::RigidPose> rigid(poses.begin(), poses.end());
    const proxima::RigidPose identity;
    for (const proxima::RigidPose& pose : rigid) {
      if (cold) cache.reset();
      sum += proxima::distance(a, identity, b, pose, {}, no_cache ? nullptr : &cache).distance;
    }
  } else {
    for (const Pose& pose : poses) {
      if (cold) cache.reset();
      sum += proxima::distance(a, Pose::identity(), b, pose, options, no_cache ? nullptr : &cache)
                 .distance;
    }
  }
  std::printf("queries %d, mode %s, N %d, mean distance %.6f\n", kSteps, mode, n, sum / kSteps);
  return 0;
}
