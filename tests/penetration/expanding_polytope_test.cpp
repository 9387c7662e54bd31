// proxima tests: the cold depth's expanding polytope (src/penetration/expanding_polytope.h,
// issue 29): its certified lower bound at every iteration cap, and the cold
// fast path it drives against the slow twin on round, thin, flat, scaled
// and offset pairs.
// SPDX-License-Identifier: BSD-3-Clause
#include "penetration/expanding_polytope.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "core/power_of_two.h"
#include "proxima/detail/penetration/penetration.h"
#include "support/generators.h"

namespace proxima::test {
namespace {

constexpr double kRel = 1e-12;

double band_of(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose) {
  return contact_band(std::max(a.scale(), magnitude_bound(pose, b.scale())));
}

// The expansion in the query's scaled units, as penetration_depth runs it.
struct Scaled {
  detail::ExpansionResult e;
  double unit = 1.0;
};
Scaled expand(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose, int cap) {
  const detail::PowerOfTwoUnit u =
      detail::power_of_two_unit(std::max(a.scale(), magnitude_bound(pose, b.scale())));
  const detail::MinkowskiSupport m{a, b, pose.rotation, pose.rotation.transpose(),
                                   pose.translation * u.inverse, u.inverse};
  return {detail::expand_polytope(m, cap), u.unit};
}

TEST(ExpandingPolytope, CertifiedLowerBoundHoldsAtEveryIterationCap) {
  // The certificate (closed surface, positive keys) must hold whether or
  // not the expansion converged: a cap of 1, 2, 4, ... stops it midway,
  // where its surface is coarse and its least key far below the depth.
  Rng rng(2901);
  int certified = 0, converged = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int n = uniform_int(rng, 8, 200);
    const ConvexPolytope a(trial % 3 == 0 ? points_in_cube(rng, n) : points_on_sphere(rng, n));
    const ConvexPolytope b(points_on_sphere(rng, n, uniform(rng, 0.2, 0.9)));
    const Pose pose(random_quaternion(rng), uniform(rng, 0.0, 1.2) * random_unit_vector(rng));
    const PenetrationResult slow = penetration_depth_brute_force(a, b, pose);
    const double band = band_of(a, b, pose);
    for (const int cap : {1, 2, 4, 8, 16, 64, 1024}) {
      const Scaled s = expand(a, b, pose, cap);
      if (!s.e.certified) continue;
      ++certified;
      converged += s.e.converged;
      ASSERT_NE(slow.status, PenetrationStatus::separated) << trial << " cap " << cap;
      EXPECT_LE(s.e.lower * s.unit, slow.depth + band) << trial << " cap " << cap;
      EXPECT_GE(s.e.upper * s.unit, slow.depth - band) << trial << " cap " << cap;
      if (s.e.converged) {
        EXPECT_NEAR(s.e.lower * s.unit, slow.depth, kRel * slow.depth + 2 * band) << trial;
      }
    }
  }
  // The set holds certified stops both midway and converged.
  EXPECT_GT(certified, converged);
  EXPECT_GT(converged, 30);
}

TEST(ExpandingPolytope, SeparatedAndFlatPairsAreNeverCertified) {
  // The origin outside M (apart) or M without interior (coplanar squares):
  // no closed surface of M's points can hold a ball about the origin.
  Rng rng(2902);
  const ConvexPolytope cube(box(Vec3(0.5, 0.5, 0.5)));
  for (int trial = 0; trial < 20; ++trial) {
    const Pose apart(random_quaternion(rng), uniform(rng, 1.8, 3.0) * random_unit_vector(rng));
    EXPECT_FALSE(expand(cube, cube, apart, 1024).e.certified) << trial;
  }
  const ConvexPolytope square(
      {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)});
  EXPECT_FALSE(
      expand(square, square, Pose::from_translation(Vec3(0.3, 0.2, 0.0)), 1024).e.certified);
}

// Cold penetration_depth against the slow twin; true when the expansion
// answered (the cache counts no enumeration).
bool cold_matches_slow(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose,
                       int trial) {
  PenetrationCache cache;
  const PenetrationResult fast = penetration_depth(a, b, pose, cache);
  const PenetrationResult slow = penetration_depth_brute_force(a, b, pose);
  const double band = band_of(a, b, pose);
  EXPECT_EQ(fast.status, slow.status) << trial;
  EXPECT_NEAR(fast.depth, slow.depth, kRel * slow.depth + band) << trial;
  EXPECT_LE(fast.lower_bound, slow.depth + band) << trial;
  EXPECT_GE(fast.upper_bound, slow.depth - band) << trial;
  if (fast.status != PenetrationStatus::separated) {
    // The largest coordinate (a norm would overflow near 1e300).
    EXPECT_LE((fast.point_b + fast.depth * fast.normal - fast.point_a).lpNorm<Eigen::Infinity>(),
              band)
        << trial;
  }
  return cache.enumerations == 0;
}

TEST(ExpandingPolytope, ColdFastPathMatchesTheSlowTwinOnRoundHulls) {
  Rng rng(2903);
  int expanded = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int n = std::array<int, 4>{8, 32, 128, 400}[static_cast<std::size_t>(trial % 4)];
    const ConvexPolytope a(points_on_sphere(rng, n));
    const ConvexPolytope b(points_on_sphere(rng, n, 0.8));
    const Pose pose(random_quaternion(rng), uniform(rng, 0.05, 1.6) * random_unit_vector(rng));
    expanded += cold_matches_slow(a, b, pose, trial);
  }
  // The fast path answers nearly all of them (not only the fallback).
  EXPECT_GE(expanded, 50);
}

TEST(ExpandingPolytope, ColdFastPathOnThinScaledAndOffsetPairs) {
  // Plates and needles (thin M, slivers in the expansion), scales from
  // 1e-300 to 1e300, bodies far from the origin relative to their size:
  // the answer is the slow twin's whichever path gives it.
  Rng rng(2904);
  int expanded = 0, total = 0;
  for (const double scale : {1e-300, 1e-20, 1.0, 1e20, 1e300}) {
    for (int trial = 0; trial < 8; ++trial) {
      const Vec3 offset = trial % 2 == 0 ? Vec3::Zero() : Vec3(1e3, -2e3, 5e2);
      Points pa = trial % 4 < 2 ? box(Vec3(1.0, 1.0, 1e-6)) : points_on_sphere(rng, 60);
      Points pb = trial % 4 == 1 ? needle(rng, 2.0, 1e-7) : points_on_sphere(rng, 60, 0.7);
      const ConvexPolytope a(scaled(translated(pa, offset), scale));
      const ConvexPolytope b(scaled(pb, scale));
      const Pose pose(random_quaternion(rng),
                      scale * (offset + uniform(rng, 0.0, 0.5) * random_unit_vector(rng)));
      expanded += cold_matches_slow(a, b, pose, trial);
      ++total;
    }
  }
  EXPECT_GT(expanded, 0);
  EXPECT_LT(expanded, total);  // the thin ones fall back
}

}  // namespace
}  // namespace proxima::test
