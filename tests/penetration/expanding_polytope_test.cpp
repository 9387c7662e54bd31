// proxima tests: the cold depth's expanding polytope (src/penetration/expanding_polytope.h,
// issue 29): its certified lower bound at every iteration cap, and the cold
// fast path it drives against the slow twin on round, thin, flat, scaled
// and offset pairs.
// SPDX-License-Identifier: BSD-3-Clause
#include "penetration/expanding_polytope.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/power_of_two.h"
#include "proxima/detail/penetration/penetration.h"
#include "proxima/query/distance.h"
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
Scaled expand(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose, int cap,
              const DepthSeed& seed = {}) {
  const detail::PowerOfTwoUnit u =
      detail::power_of_two_unit(std::max(a.scale(), magnitude_bound(pose, b.scale())));
  const detail::MinkowskiSupport m{a, b, pose.rotation, pose.rotation.transpose(),
                                   pose.translation * u.inverse, u.inverse};
  return {detail::expand_polytope(m, cap, seed), u.unit};
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

TEST(ExpandingPolytope, SeededFromTheContactTetrahedronCertifiesTheSameDepth) {
  // The distance query's contact tetrahedron (DistanceCache::contact_a,
  // contact_b) as the start: at every cap the bound is certified as from
  // the octahedron, and converged it is the depth. Seeds that cannot start
  // a certified surface (ids out of range, a repeated point, a tetrahedron
  // beside the origin: its vertices shifted to one side) fall back to the
  // octahedron and give the same converged depth.
  Rng rng(2905);
  int seeded = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = uniform_int(rng, 8, 120);
    const ConvexPolytope a(trial % 3 == 0 ? points_in_cube(rng, n) : points_on_sphere(rng, n));
    const ConvexPolytope b(points_on_sphere(rng, n, uniform(rng, 0.2, 0.9)));
    const Pose pose(random_quaternion(rng), uniform(rng, 0.0, 1.0) * random_unit_vector(rng));
    DistanceCache cache;
    if (distance(a, Pose::identity(), b, pose, {}, &cache).status != Status::intersecting) continue;
    const DepthSeed seed{cache.contact_a, cache.contact_b};
    if (seed.a[3] < 0) continue;
    ++seeded;
    const PenetrationResult slow = penetration_depth_brute_force(a, b, pose);
    const double band = band_of(a, b, pose);
    for (const int cap : {1, 2, 4, 16, 4096}) {
      const Scaled s = expand(a, b, pose, cap, seed);
      if (!s.e.certified) continue;
      EXPECT_LE(s.e.lower * s.unit, slow.depth + band) << trial << " cap " << cap;
      if (s.e.converged) {
        EXPECT_NEAR(s.e.lower * s.unit, slow.depth, kRel * slow.depth + 2 * band) << trial;
      }
    }
    const Scaled from_octahedron = expand(a, b, pose, 4096);
    ASSERT_TRUE(from_octahedron.e.converged) << trial;
    DepthSeed out_of_range = seed, repeated = seed;
    out_of_range.b[2] = b.vertex_count();
    repeated.a[1] = repeated.a[0];
    repeated.b[1] = repeated.b[0];
    for (const DepthSeed& bad : {out_of_range, repeated}) {
      const Scaled s = expand(a, b, pose, 4096, bad);
      EXPECT_TRUE(s.e.converged) << trial;
      EXPECT_EQ(s.e.lower, from_octahedron.e.lower) << trial;
    }
  }
  EXPECT_GE(seeded, 20);
}

TEST(ExpandingPolytope, SeedBesideTheOriginIsNotUsed) {
  // A tetrahedron of points of A - B all on one side of the origin (A's
  // four vertices furthest along +x less B's four furthest along -x, as
  // placed): its keys are not all positive, and the expansion must start
  // from the octahedron instead, the same answer to the last bit.
  Rng rng(2906);
  const ConvexPolytope a(points_on_sphere(rng, 60));
  const ConvexPolytope b(points_on_sphere(rng, 60, 0.7));
  const Pose pose(random_quaternion(rng), Vec3(0.1, -0.05, 0.02));
  const auto furthest = [](const ConvexPolytope& p, const Pose& place, double sign) {
    std::vector<int> ids(static_cast<std::size_t>(p.vertex_count()));
    for (int i = 0; i < p.vertex_count(); ++i) ids[static_cast<std::size_t>(i)] = i;
    std::sort(ids.begin(), ids.end(), [&](int i, int j) {
      return sign * place.apply(p.vertex(i)).x() > sign * place.apply(p.vertex(j)).x();
    });
    return std::array<std::int32_t, 4>{ids[0], ids[1], ids[2], ids[3]};
  };
  const DepthSeed beside{furthest(a, Pose::identity(), 1.0), furthest(b, pose, -1.0)};
  for (std::size_t k = 0; k < 4; ++k)
    ASSERT_GT((a.vertex(beside.a[k]) - pose.apply(b.vertex(beside.b[k]))).x(), 0.5);
  const Scaled seeded = expand(a, b, pose, 4096, beside);
  const Scaled plain = expand(a, b, pose, 4096);
  ASSERT_TRUE(plain.e.certified && plain.e.converged);
  EXPECT_EQ(seeded.e.lower, plain.e.lower);
  EXPECT_EQ(seeded.e.iterations, plain.e.iterations);
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
