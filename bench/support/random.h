// proxima benchmarks: seeded, portable random draws for the benchmarks' inputs
// (the paper's experiments, the scene scenario, the micro-benchmarks).
// SPDX-License-Identifier: BSD-3-Clause
//
// Only integer draws and the basic IEEE operations feed the values
// (std::uniform_real_distribution and std::normal_distribution are
// implementation-defined), so a seed gives the same bodies and poses on
// every machine, and the figures in bench/results can be reproduced.
// tests/support/generators.h draws the tests' inputs the same way; the
// benchmarks keep their own copy so that bench/ does not depend on tests/.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "proxima/core/types.h"

namespace proxima::bench {

using Rng = std::mt19937_64;

// Uniform in [0, 1): the top 53 bits of the generator as a fraction.
inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }
inline double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }
// Integer in [lo, hi]; the modulo bias of a 64-bit draw over such small
// ranges is ~1e-17.
inline int uniform_int(Rng& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
}
// Log-uniform in [lo, hi] (both > 0): every decade equally likely.
inline double log_uniform(Rng& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

// Uniform on the unit sphere: rejection in the cube keeps the distribution
// uniform without a normal deviate.
inline Vec3 random_unit_vector(Rng& rng) {
  for (;;) {
    const Vec3 p(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    const double n2 = p.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) return p / std::sqrt(n2);
  }
}

// Uniform rotation: a uniform unit quaternion, by rejection in the 4-cube.
inline Quat random_quaternion(Rng& rng) {
  for (;;) {
    const Eigen::Vector4d q(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1),
                            uniform(rng, -1, 1));
    const double n2 = q.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) {
      const Eigen::Vector4d u = q / std::sqrt(n2);
      return Quat(u[0], u[1], u[2], u[3]);
    }
  }
}
inline Mat3 random_rotation(Rng& rng) { return random_quaternion(rng).toRotationMatrix(); }

// n points on the sphere of the given radius about the origin: round hulls
// with many small faces.
inline std::vector<Vec3> points_on_sphere(Rng& rng, int n, double radius = 1.0) {
  std::vector<Vec3> points;
  points.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) points.push_back(radius * random_unit_vector(rng));
  return points;
}

}  // namespace proxima::bench
