// proxima benchmarks: the signed-distance sweep of bench/penetration_peers
// (B, a hull of N points on the sphere of radius 0.8, turned once, sweeping
// through A, a hull of N points on the unit sphere, and back), shared with
// bench/cold_instructions so that their figures are of the same poses.
// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"
#include "random.h"

namespace proxima::bench {

// The sweep's step (the paper's translation experiment, bench/paper) and
// the half length of B's centre's triangle wave.
constexpr double kSweepStep = 1.6e-3;
constexpr double kSweepHalfLength = 2.4;

// B's pose in A's frame (A at the identity), 6,000 poses.
inline std::vector<Pose> penetration_sweep() {
  const int steps = static_cast<int>(std::lround(4 * kSweepHalfLength / kSweepStep));
  std::vector<Pose> poses;
  poses.reserve(static_cast<std::size_t>(steps));
  const Vec3 dir = Vec3(1.0, 0.3, -0.2).normalized();
  const Mat3 rotation =
      Quat(Eigen::AngleAxisd(0.7, Vec3(0.2, -1.0, 0.4).normalized())).toRotationMatrix();
  for (int i = 0; i < steps; ++i) {
    const double phase = static_cast<double>(i) / steps;
    const double h = kSweepHalfLength;
    const double s = phase < 0.5 ? -h + 4 * h * phase : 3 * h - 4 * h * phase;
    poses.emplace_back(rotation, s * dir + Vec3(0.01, 0.02, -0.03));
  }
  return poses;
}

// The sweep's two hulls for N (seeded by N).
struct SweepBodies {
  ConvexPolytope a, b;
};
inline SweepBodies penetration_sweep_bodies(int n) {
  Rng rng(static_cast<std::uint64_t>(n) * 7919 + 1);
  const std::vector<Vec3> va = points_on_sphere(rng, n, 1.0);
  const std::vector<Vec3> vb = points_on_sphere(rng, n, 0.8);
  return {ConvexPolytope(va), ConvexPolytope(vb)};
}

}  // namespace proxima::bench
