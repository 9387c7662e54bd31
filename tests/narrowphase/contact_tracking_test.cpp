// Tracked queries of pairs in contact: the contact classification (touching
// or intersecting) keeps a tetrahedron of the Minkowski difference around
// the origin in the DistanceCache and re-certifies it in O(1) while the
// bodies overlap (contact.cpp, gjk.cpp's encloses_origin_deeply).
//
// What must hold: a tracked query says what a cold one says, status for
// status, with distances within the accuracy standard, along sequences that
// go from separated to touching to intersecting and back; a cache from
// another pair or from another pose never turns a touching or separated pair
// into an intersecting one; the certificate itself is checked on a
// hand-computed tetrahedron.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "proxima/detail/narrowphase/gjk.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::Points;
using test::Rng;

constexpr std::array kAlgorithms = {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk};

// The contact band of the accuracy standard for bodies placed at these
// poses: 64 u R with R the largest placed coordinate.
double band(const Points& a, const Pose& pose_a, const Points& b, const Pose& pose_b) {
  const double r = std::max(test::max_abs_coordinate(test::transformed(a, pose_a)),
                            test::max_abs_coordinate(test::transformed(b, pose_b)));
  return 64.0 * kUnitRoundoff * r;
}

std::string where(Algorithm alg, int step) {
  return std::string(to_string(alg)) + " step " + std::to_string(step);
}

// Runs the poses of B in order with one cache per algorithm and checks each
// tracked answer against a cold query of the same pose. Returns how many
// steps ended in each status (cold answers, all algorithms).
std::array<int, 4> check_sequence(const Points& pa, const Points& pb,
                                  const std::vector<Pose>& poses_b) {
  const ConvexPolytope a(pa);
  const ConvexPolytope b(pb);
  std::array<int, 4> seen{};
  for (const Algorithm alg : kAlgorithms) {
    DistanceOptions options;
    options.algorithm = alg;
    DistanceCache cache;
    for (std::size_t i = 0; i < poses_b.size(); ++i) {
      const Pose& pose_b = poses_b[i];
      const DistanceResult cold = distance(a, Pose::identity(), b, pose_b, options);
      const DistanceResult warm = distance(a, Pose::identity(), b, pose_b, options, &cache);
      const std::string at = where(alg, static_cast<int>(i));
      ++seen[static_cast<std::size_t>(cold.status)];
      EXPECT_EQ(warm.status, cold.status)
          << at << " cold " << cold.distance << " warm " << warm.distance;
      const double tol = 1e-12 * cold.distance + band(pa, Pose::identity(), pb, pose_b);
      EXPECT_NEAR(warm.distance, cold.distance, tol) << at;
      if (warm.status == Status::intersecting) {
        // The deepest points (the penetration depth, types.h): B moved by
        // depth * normal carries point_b onto point_a.
        EXPECT_EQ(warm.distance, 0.0) << at;
        EXPECT_NEAR((warm.point_b + warm.depth * warm.normal - warm.point_a).norm(), 0.0, 1e-12)
            << at;
        EXPECT_NEAR(warm.depth, cold.depth, 1e-12 * cold.depth + 1e-13) << at;
      }
    }
  }
  return seen;
}

// Unit cubes; B slides along x from 1.5 (gap 0.5) to 0.5 (depth 0.5) and
// back in steps of 1/64, spinning about the x axis and drifting in y and z.
// The steps and a rotation about x keep B's x faces exact, so the gap x - 1
// is exact: separated above 0, touching at 0 (face on face), intersecting
// below, deeper than the band.
TEST(ContactTracking, CubesSlideThroughContactAndBack) {
  const Points cube = test::cube(1.0);
  std::vector<Pose> poses;
  std::vector<Status> expected;
  const auto add = [&](int k) {
    const double x = 0.5 + k / 64.0;
    const double angle = 0.01 * static_cast<double>(poses.size());
    poses.emplace_back(Quat(Eigen::AngleAxisd(angle, Vec3::UnitX())),
                       Vec3(x, 0.1 * std::sin(angle), 0.1 * std::cos(3 * angle)));
    expected.push_back(x > 1.0    ? Status::separated
                       : x == 1.0 ? Status::touching
                                  : Status::intersecting);
  };
  for (int k = 64; k >= 0; --k) add(k);
  for (int k = 1; k <= 64; ++k) add(k);

  const ConvexPolytope a(cube);
  for (const Algorithm alg : kAlgorithms) {
    DistanceOptions options;
    options.algorithm = alg;
    DistanceCache cache;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const DistanceResult r = distance(a, Pose::identity(), a, poses[i], options, &cache);
      EXPECT_EQ(r.status, expected[i])
          << where(alg, static_cast<int>(i)) << " distance " << r.distance;
    }
  }
  const std::array<int, 4> seen = check_sequence(cube, cube, poses);
  EXPECT_GT(seen[static_cast<std::size_t>(Status::separated)], 0);
  EXPECT_EQ(seen[static_cast<std::size_t>(Status::touching)],
            2 * static_cast<int>(kAlgorithms.size()));
  EXPECT_GT(seen[static_cast<std::size_t>(Status::intersecting)], 0);
  EXPECT_EQ(seen[static_cast<std::size_t>(Status::iteration_cap)], 0);
}

// Round bodies of 20 to 200 vertices: B's centre moves along a random line
// through A's, from 2.5 apart to 1 apart (overlapping by half their size)
// and back, while B spins a little each step.
TEST(ContactTracking, RoundBodiesApproachOverlapAndSeparate) {
  Rng rng(20261122);
  for (int trial = 0; trial < 6; ++trial) {
    const int na = test::uniform_int(rng, 20, 200);
    const int nb = test::uniform_int(rng, 20, 200);
    const Points pa = test::points_on_sphere(rng, na);
    const Points pb = test::points_on_sphere(rng, nb);
    const Vec3 dir = test::random_unit_vector(rng);
    const Vec3 axis = test::random_unit_vector(rng);
    const Vec3 side = dir.cross(axis);
    std::vector<Pose> poses;
    constexpr int kSteps = 60;
    for (int i = 0; i <= 2 * kSteps; ++i) {
      const double s = std::abs(static_cast<double>(i - kSteps)) / kSteps;  // 1 -> 0 -> 1
      const double angle = 0.02 * i;
      poses.emplace_back(Quat(Eigen::AngleAxisd(angle, axis)),
                         Vec3((1.0 + 1.5 * s) * dir + 0.05 * std::sin(angle) * side));
    }
    const std::array<int, 4> seen = check_sequence(pa, pb, poses);
    EXPECT_GT(seen[static_cast<std::size_t>(Status::separated)], 0) << "trial " << trial;
    EXPECT_GT(seen[static_cast<std::size_t>(Status::intersecting)], 0) << "trial " << trial;
    EXPECT_EQ(seen[static_cast<std::size_t>(Status::iteration_cap)], 0) << "trial " << trial;
  }
}

// A cache filled by a deep overlap, then used on the same bodies placed
// touching and apart, and on other bodies (ids partly out of range, partly
// naming other vertices): every answer equals the cold one.
TEST(ContactTracking, ForeignCacheOnOverlappingAndTouchingPairs) {
  Rng rng(7);
  const Points cube = test::cube(1.0);
  const ConvexPolytope c(cube);
  const ConvexPolytope round_a(test::points_on_sphere(rng, 150));
  const ConvexPolytope round_b(test::points_on_sphere(rng, 40));
  const Pose deep = Pose::from_translation(Vec3(0.25, 0.0, 0.0));
  const Pose touching = Pose::from_translation(Vec3(1.0, 0.25, -0.125));
  const Pose apart = Pose::from_translation(Vec3(1.0 + 1e-9, 0.0, 0.0));
  const Pose overlap_round = Pose::from_translation(Vec3(1.2, 0.3, 0.0));

  struct Query {
    const ConvexPolytope* a;
    const ConvexPolytope* b;
    Pose pose_b;
  };
  const std::vector<Query> queries = {
      {&c, &c, touching},   {&c, &c, apart},          {&round_a, &round_b, overlap_round},
      {&c, &round_b, deep}, {&round_b, &c, touching}, {&round_b, &round_a, overlap_round}};
  for (const Algorithm alg : kAlgorithms) {
    DistanceOptions options;
    options.algorithm = alg;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      for (const auto& [fill_a, fill_b] : {std::pair{&c, &c}, std::pair{&round_a, &round_b}}) {
        DistanceCache cache;
        const Pose fill_pose = fill_a == &c ? deep : overlap_round;
        ASSERT_EQ(distance(*fill_a, Pose::identity(), *fill_b, fill_pose, options, &cache).status,
                  Status::intersecting);
        const Query& query = queries[q];
        const DistanceResult cold =
            distance(*query.a, Pose::identity(), *query.b, query.pose_b, options);
        const DistanceResult warm =
            distance(*query.a, Pose::identity(), *query.b, query.pose_b, options, &cache);
        const std::string at = std::string(to_string(alg)) + " query " + std::to_string(q);
        EXPECT_EQ(warm.status, cold.status) << at;
        EXPECT_NEAR(warm.distance, cold.distance,
                    1e-12 * cold.distance + 64.0 * kUnitRoundoff * 4.0)
            << at;
      }
    }
  }
  // Both cube queries have a known status.
  EXPECT_EQ(distance(c, Pose::identity(), c, touching).status, Status::touching);
  EXPECT_EQ(distance(c, Pose::identity(), c, apart).status, Status::separated);

  // Garbage in the contact fields: out of range, negative, repeated.
  for (const auto& ids :
       {std::array<std::int32_t, 4>{1000000, 0, 1, 2}, std::array<std::int32_t, 4>{-5, 3, 2, 1},
        std::array<std::int32_t, 4>{0, 0, 0, 0}}) {
    DistanceCache cache;
    cache.contact_a = ids;
    cache.contact_b = ids;
    EXPECT_EQ(cache.is_cold(), ids[0] < 0);  // is_cold() reads the first slot of each field
    EXPECT_EQ(distance(c, Pose::identity(), c, touching, {}, &cache).status, Status::touching);
    EXPECT_EQ(distance(c, Pose::identity(), c, deep, {}, &cache).status, Status::intersecting);
    cache.reset();
    EXPECT_TRUE(cache.is_cold());
  }
}

// The certificate by hand: a cube of edge 2 around the origin minus a point
// at the origin is the cube itself; its alternate corners span a regular
// tetrahedron whose faces are 1/sqrt(3) from the centre. Deeper than a band
// of 0.57, not deeper than 0.58; a flat or out-of-range set certifies
// nothing.
TEST(ContactTracking, CertificateOnAHandComputedTetrahedron) {
  const ConvexPolytope a(test::cube(2.0));
  const ConvexPolytope b(test::single_point());
  const auto id_of = [&](const Vec3& p) {
    for (int i = 0; i < a.vertex_count(); ++i) {
      if (a.vertex(i) == p) return static_cast<std::int32_t>(i);
    }
    return std::int32_t{-1};
  };
  const std::array<std::int32_t, 4> tet = {id_of(Vec3(1, 1, 1)), id_of(Vec3(1, -1, -1)),
                                           id_of(Vec3(-1, 1, -1)), id_of(Vec3(-1, -1, 1))};
  for (const std::int32_t id : tet) ASSERT_GE(id, 0);
  const std::array<std::int32_t, 4> zero = {0, 0, 0, 0};
  const Pose same = Pose::identity();
  EXPECT_TRUE(encloses_origin_deeply(a, b, same, 0.57, tet, zero));
  EXPECT_FALSE(encloses_origin_deeply(a, b, same, 0.58, tet, zero));
  // B moved by 0.5 towards the face x + y - z = 1 (opposite (-1, -1, 1)):
  // the origin of A - B is 1/sqrt(3) - 0.5 = 0.077 below that face and
  // 1/sqrt(3) + 1/6 below the three others.
  const Pose shifted = Pose::from_translation(Vec3(1, 1, -1) * (0.5 / std::sqrt(3.0)));
  EXPECT_TRUE(encloses_origin_deeply(a, b, shifted, 0.07, tet, zero));
  EXPECT_FALSE(encloses_origin_deeply(a, b, shifted, 0.08, tet, zero));
  // Repeated vertex pairs: flat.
  EXPECT_FALSE(encloses_origin_deeply(a, b, same, 0.0, {tet[0], tet[1], tet[2], tet[2]}, zero));
  // Out of range on either side.
  EXPECT_FALSE(encloses_origin_deeply(a, b, same, 0.0, {tet[0], tet[1], tet[2], 8}, zero));
  EXPECT_FALSE(encloses_origin_deeply(a, b, same, 0.0, tet, {0, 0, 1, 0}));
  EXPECT_FALSE(encloses_origin_deeply(a, b, same, 0.0, tet, {0, -1, 0, 0}));
}

}  // namespace
}  // namespace proxima
