// Tests of the hybrid algorithm through distance(): hand-computed cases with
// their witness features, the contact classification, tracking behaviour
// (a tracked query with unchanged closest features does no iteration), and
// caches that are stale or belong to another pair.
//
// The exact-oracle accuracy suite for all three algorithms is
// distance_accuracy_test.cpp; here the reference is a brute force in double
// over all feature pairs, enough for well-conditioned random cases.
#include "proxima/detail/narrowphase/hybrid.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/accuracy.h"
#include "proxima/detail/geometry/tetrahedron_coordinates.h"
#include "proxima/detail/narrowphase/certified_pair.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/query/distance.h"
#include "support/exact_oracle.h"
#include "support/generators.h"
#include "support/same_bits.h"

namespace proxima {
namespace {

using test::drawn;
using test::drawn_quaternion;

std::vector<Vec3> box(const Vec3& half) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i) {
    pts.emplace_back((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(),
                     (i & 4 ? 1 : -1) * half.z());
  }
  return pts;
}

std::vector<Vec3> sphere_points(int n, std::uint32_t seed, double radius = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) {
    Vec3 p = drawn([&] { return g(rng); });
    pts.push_back(radius * p.normalized());
  }
  return pts;
}

// Brute force over all vertex/edge/triangle pairs of the two hulls, in
// double: the slow obvious twin for well-conditioned cases.
double brute_force_distance(const ConvexPolytope& a, const Pose& pa, const ConvexPolytope& b,
                            const Pose& pb) {
  std::vector<std::vector<Vec3>> fa;
  std::vector<std::vector<Vec3>> fb;
  const auto collect = [](const ConvexPolytope& p, const Pose& pose,
                          std::vector<std::vector<Vec3>>& out) {
    for (int v = 0; v < p.vertex_count(); ++v) out.push_back({pose.apply(p.vertex(v))});
    for (const auto& e : p.edges())
      out.push_back({pose.apply(p.vertex(e[0])), pose.apply(p.vertex(e[1]))});
    for (const auto& t : p.triangles()) {
      out.push_back(
          {pose.apply(p.vertex(t[0])), pose.apply(p.vertex(t[1])), pose.apply(p.vertex(t[2]))});
    }
  };
  collect(a, pa, fa);
  collect(b, pb, fb);
  double best = INFINITY;
  for (const auto& x : fa) {
    for (const auto& y : fb) {
      const auto c = closest_points<double>(x.data(), static_cast<int>(x.size()), y.data(),
                                            static_cast<int>(y.size()));
      best = std::min(best, c.distance_squared);
    }
  }
  return std::sqrt(best);
}

Pose random_pose(std::mt19937& rng, double spread) {
  std::normal_distribution<double> g;
  const Quat q = drawn_quaternion([&] { return g(rng); });
  return Pose(q, drawn([&] { return spread * g(rng); }));
}

// Regression (issue 24): the hybrid's inside test of a four-vertex feature
// compared the signs of the sub-volumes with the whole's through their
// product. The hybrid runs unscaled for R in 2^-64 .. 2^64, and a feature
// of a small body beside a large one (kernel tolerances keep features down
// to 4 u R long) has a volume of 1e-210 while a far point's sub-volumes are
// about 1e-140: the products underflowed to 0, passed as "same sign", and a
// point far outside was reported inside (distance 0).
TEST(TetrahedronCoordinates, UnderflowingVolumesKeepTheirSigns) {
  const double s = 1e-70;
  const std::array<Vec3, 4> t = {Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0, s, 0), Vec3(0, 0, s)};
  // Points on the axes: every difference with a vertex is exact, so the
  // sub-volumes are exact too (about -1e-140 for the far side).
  EXPECT_FALSE(detail::tetrahedron_coordinates(t, Vec3(-1.0, 0.0, 0.0)));
  EXPECT_FALSE(detail::tetrahedron_coordinates(t, Vec3(0.0, -1.0, 0.0)));
  EXPECT_FALSE(detail::tetrahedron_coordinates(t, Vec3(0.0, 0.0, -1.0)));
  // Inside, at the same scale: coordinates that sum to one.
  const auto inside = detail::tetrahedron_coordinates(t, Vec3(0.25 * s, 0.25 * s, 0.25 * s));
  ASSERT_TRUE(inside);
  EXPECT_NEAR((*inside)[0] + (*inside)[1] + (*inside)[2] + (*inside)[3], 1.0, 1e-15);
  for (const double c : *inside) EXPECT_GE(c, 0.0);
  // The same at 1e70, where the products overflow instead (their signs held).
  const double big = 1e70;
  const std::array<Vec3, 4> t_big = {Vec3(0, 0, 0), Vec3(big, 0, 0), Vec3(0, big, 0),
                                     Vec3(0, 0, big)};
  EXPECT_FALSE(detail::tetrahedron_coordinates(t_big, Vec3(big, big, big)));
  EXPECT_TRUE(detail::tetrahedron_coordinates(t_big, Vec3(0.25 * big, 0.25 * big, 0.25 * big)));
}

TEST(Hybrid, UnitCubesFaceToFace) {
  const ConvexPolytope cube(box(Vec3(0.5, 0.5, 0.5)));
  const auto r = distance(cube, Pose::identity(), cube, Pose::from_translation(Vec3(3, 0, 0)));
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, 2.0, 1e-15);
  EXPECT_NEAR(r.lower_bound, 2.0, 1e-12);
  EXPECT_NEAR(r.point_a.x(), 0.5, 1e-15);
  EXPECT_NEAR(r.point_b.x(), 2.5, 1e-15);
  EXPECT_NEAR(r.normal.x(), 1.0, 1e-15);
  // Parallel faces: whichever vertex/face pair realizes it, the witnesses
  // are on the facing sides.
  for (int i = 0; i < r.feature_a.vertex_count(); ++i) {
    EXPECT_EQ(cube.vertex(r.feature_a.vertices[static_cast<std::size_t>(i)]).x(), 0.5);
  }
  for (int i = 0; i < r.feature_b.vertex_count(); ++i) {
    EXPECT_EQ(cube.vertex(r.feature_b.vertices[static_cast<std::size_t>(i)]).x(), -0.5);
  }
}

TEST(Hybrid, VertexToFaceWitnesses) {
  // A tetrahedron pointing down at the cube's top face.
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const ConvexPolytope tet(std::vector<Vec3>{{0.1, 0.2, 0}, {1, 0, 1}, {-1, 1, 1}, {-1, -1, 1}});
  const auto r = distance(cube, Pose::identity(), tet, Pose::from_translation(Vec3(0, 0, 1.5)));
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  EXPECT_NEAR(r.point_a.x(), 0.1, 1e-15);
  EXPECT_NEAR(r.point_a.y(), 0.2, 1e-15);
  EXPECT_EQ(r.feature_a.type, FeatureType::face);
  ASSERT_GE(r.feature_a.face, 0);
  EXPECT_NEAR(cube.face_plane(r.feature_a.face).normal.z(), 1.0, 1e-15);
  EXPECT_EQ(r.feature_b.type, FeatureType::vertex);
  EXPECT_EQ(tet.vertex(r.feature_b.vertices[0]), Vec3(0.1, 0.2, 0));
}

TEST(Hybrid, EdgeToEdgeWitnesses) {
  // Two boxes whose closest features are crossing edges.
  const ConvexPolytope a(box(Vec3(1, 1, 1)));
  const ConvexPolytope b(box(Vec3(1, 1, 1)));
  const Pose pb(Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())),
                Vec3(0, 0, 2 * std::sqrt(2.0) + 0.25));
  const Pose pa(Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX())), Vec3::Zero());
  const auto r = distance(a, pa, b, pb);
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, 0.25, 1e-14);
  EXPECT_EQ(r.feature_a.type, FeatureType::edge);
  EXPECT_EQ(r.feature_b.type, FeatureType::edge);
  EXPECT_NEAR(r.distance, brute_force_distance(a, pa, b, pb), 1e-14);
}

TEST(Hybrid, TrackedEdgeWitnessNearAVertexFollowsTheBand) {
  // A tracked edge's witness is decided from the loop's own points in A's
  // frame when the closest point is far from both ends (src/narrowphase/hybrid.cpp,
  // kWitnessFarBands), in B's frame otherwise. Either way the rule is
  // witness_features.h's: a closest point on B's edge within the band of a
  // vertex is that vertex, beyond it the edge. A's apex moves along B's top
  // edge, B rotated, from its middle (the cache then holds the edge) to 0.1,
  // 8 and 1000 bands from its end y0 (a cold query would stop at y0 itself:
  // the distance to y0 is larger by a second-order amount only).
  const std::vector<Vec3> tb = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, -1), Vec3(0.5, -1, -1)};
  const ConvexPolytope b(tb);
  int id0 = -1, id1 = -1;
  for (int i = 0; i < b.vertex_count(); ++i) {
    if (b.vertex(i) == tb[0]) id0 = i;
    if (b.vertex(i) == tb[1]) id1 = i;
  }
  ASSERT_GE(id0, 0);
  ASSERT_GE(id1, 0);
  const Pose pb(Quat(Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized())), Vec3(0.3, -0.2, 0.9));
  // A: an apex at its origin, its base above it along B's z axis.
  std::vector<Vec3> ta = {Vec3::Zero()};
  for (const Vec3& d : {Vec3(-0.3, -0.3, 1), Vec3(0.6, 0, 1), Vec3(-0.3, 0.3, 1)})
    ta.push_back(pb.rotation * d);
  const ConvexPolytope a(ta);
  const auto apex_at = [&](double s) { return Pose::from_translation(pb.apply(Vec3(s, 0, 0.5))); };
  for (const double bands : {0.1, 8.0, 1000.0}) {
    DistanceCache cache;
    const auto middle = distance(a, apex_at(0.5), b, pb, {}, &cache);
    ASSERT_EQ(middle.feature_b.type, FeatureType::edge);
    // The witness band for coordinates bounded by r (witness_features.h): a
    // quarter of the contact band; r >= the algorithm's bound in A's frame.
    const double r = std::max(a.scale(), magnitude_bound(pb, b.scale())) + 2.0;
    const double s = bands * 0.25 * contact_band(r);
    const auto res = distance(a, apex_at(s), b, pb, {}, &cache);
    ASSERT_EQ(res.status, Status::separated) << bands;
    EXPECT_NEAR(res.distance, 0.5, 1e-12) << bands;
    EXPECT_EQ(res.feature_a.type, FeatureType::vertex) << bands;
    if (bands < 1.0) {
      EXPECT_EQ(res.feature_b.type, FeatureType::vertex) << bands;
      EXPECT_EQ(res.feature_b.vertices[0], id0) << bands;
    } else {
      EXPECT_EQ(res.feature_b.type, FeatureType::edge) << bands;
      EXPECT_EQ(res.feature_b.vertices[0], std::min(id0, id1)) << bands;
      EXPECT_EQ(res.feature_b.vertices[1], std::max(id0, id1)) << bands;
    }
  }
}

TEST(Hybrid, TouchingAndIntersecting) {
  const ConvexPolytope cube(box(Vec3(0.5, 0.5, 0.5)));
  // Stacked cubes sharing a face exactly: touching.
  const auto stacked =
      distance(cube, Pose::identity(), cube, Pose::from_translation(Vec3(0.3, -0.2, 1.0)));
  EXPECT_EQ(stacked.status, Status::touching);
  EXPECT_LE(stacked.distance, 64 * kUnitRoundoff * 2);
  // Edge on edge, crossing at right angles: touching.
  const Pose ridge_a(Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX())), Vec3::Zero());
  const Pose ridge_b(Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())),
                     Vec3(0, 0, 2 * std::sqrt(0.5)));
  const auto edge_edge = distance(cube, ridge_a, cube, ridge_b);
  EXPECT_EQ(edge_edge.status, Status::touching);
  EXPECT_EQ(edge_edge.feature_a.type, FeatureType::edge);
  EXPECT_EQ(edge_edge.feature_b.type, FeatureType::edge);
  // Deep overlap: intersecting, distance 0.
  const auto deep =
      distance(cube, Pose::identity(), cube, Pose::from_translation(Vec3(0.2, 0.1, 0.3)));
  EXPECT_EQ(deep.status, Status::intersecting);
  EXPECT_EQ(deep.distance, 0.0);
  EXPECT_EQ(deep.lower_bound, 0.0);
  // Concentric: intersecting.
  const auto same = distance(cube, Pose::identity(), cube, Pose::identity());
  EXPECT_EQ(same.status, Status::intersecting);
}

// Regression (issue 9): the contact classification and the cross-check of
// uncertified answers lived in the query layer (distance.cpp), so
// hybrid_distance answered an overlapping pair `touching` with no second
// algorithm while distance(..., hybrid) answered `intersecting`: figures
// labelled "hybrid" did not measure what ran. Now hybrid_distance is the
// whole algorithm: given the same band, the same answer in A's frame.
TEST(Hybrid, HybridDistanceIsTheWholeAlgorithm) {
  const ConvexPolytope cube(box(Vec3(0.5, 0.5, 0.5)));
  const ConvexPolytope ball(sphere_points(40, 3, 0.6));
  std::mt19937 rng(11);
  int overlapping = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Pose pa = random_pose(rng, 0.4);
    Pose pb = random_pose(rng, 0.4);
    pb.translation *= 2.5;
    // Without the penetration depth, which distance() adds after the
    // algorithm (an intersecting answer's points become the deepest ones).
    DistanceOptions status_only;
    status_only.penetration = false;
    const DistanceResult whole = distance(cube, pa, ball, pb, status_only);
    const Pose b_in_a = pa.inverse() * pb;
    const double band = contact_band(
        std::max(magnitude_bound(pa, cube.scale()), magnitude_bound(pb, ball.scale())));
    DistanceCache cache;
    const DistanceResult algorithm = hybrid_distance(cube, ball, b_in_a, {}, band, cache);
    ASSERT_EQ(algorithm.status, whole.status) << trial;
    EXPECT_EQ(algorithm.second_algorithm, whole.second_algorithm) << trial;
    EXPECT_NEAR(algorithm.distance, whole.distance, 1e-14) << trial;
    EXPECT_LE((pa.apply(algorithm.point_a) - whole.point_a).norm(), 1e-13) << trial;
    overlapping += whole.status == Status::intersecting;
  }
  EXPECT_GE(overlapping, 5);   // premise: the set holds overlapping pairs
  EXPECT_LE(overlapping, 35);  // and separated ones
}

TEST(Hybrid, RandomPairsMatchBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const ConvexPolytope a(sphere_points(4 + trial % 40, 100 + static_cast<std::uint32_t>(trial)));
    const ConvexPolytope b(
        sphere_points(4 + (trial * 7) % 50, 900 + static_cast<std::uint32_t>(trial), 0.7));
    // Bounding spheres of radius 1 and 0.7 whose centres are at least
    // 2.55 - 2 * 0.1 * sqrt(3) * 3 apart in the worst 3-sigma case: separated.
    const Pose pa = random_pose(rng, 0.1);
    Pose pb = random_pose(rng, 0.1);
    pb.translation += Vec3(2.5, 0.5, -0.2);
    const auto r = distance(a, pa, b, pb);
    const double expected = brute_force_distance(a, pa, b, pb);
    ASSERT_EQ(r.status, Status::separated) << trial << " brute force " << expected;
    EXPECT_NEAR(r.distance, expected, 1e-12 * expected + 1e-14) << trial;
    EXPECT_LE(r.lower_bound, r.distance);
    EXPECT_NEAR((r.point_b - r.point_a).norm(), r.distance, 1e-14) << trial;
  }
}

TEST(Hybrid, TrackingUnchangedFeaturesCostsNoIteration) {
  const ConvexPolytope a(sphere_points(2000, 1));
  const ConvexPolytope b(sphere_points(2000, 2));
  DistanceCache cache;
  Pose pb = Pose::from_translation(Vec3(3, 0, 0));
  const auto first = distance(a, Pose::identity(), b, pb, {}, &cache);
  EXPECT_FALSE(cache.is_cold());
  EXPECT_GT(first.iterations, 0);
  // A motion too small to change the closest features.
  pb.translation += Vec3(1e-9, 0, 0);
  const auto second = distance(a, Pose::identity(), b, pb, {}, &cache);
  EXPECT_EQ(second.iterations, 0);
  const auto cold = distance(a, Pose::identity(), b, pb);
  EXPECT_NEAR(second.distance, cold.distance, 1e-15);
  EXPECT_NEAR(second.distance, first.distance, 1.1e-9);
}

TEST(Hybrid, TrackingAlongMotionEqualsCold) {
  const ConvexPolytope a(sphere_points(500, 3));
  const ConvexPolytope b(sphere_points(300, 4, 0.5));
  DistanceCache cache;
  int total_warm_iterations = 0;
  int total_cold_iterations = 0;
  for (int step = 0; step < 400; ++step) {
    const double t = 0.01 * step;
    const Pose pb(Quat(Eigen::AngleAxisd(t, Vec3(1, 2, 3).normalized())),
                  Vec3(2.0 + 0.3 * std::sin(t), 0.8 * std::cos(0.7 * t), 0.4 * std::sin(1.3 * t)));
    const auto warm = distance(a, Pose::identity(), b, pb, {}, &cache);
    const auto cold = distance(a, Pose::identity(), b, pb);
    ASSERT_NEAR(warm.distance, cold.distance, 1e-12 * cold.distance + 64 * kUnitRoundoff * 3)
        << step;
    total_warm_iterations += warm.iterations;
    total_cold_iterations += cold.iterations;
  }
  // Tracking must be doing the work it is for.
  EXPECT_LT(total_warm_iterations * 3, total_cold_iterations);
}

TEST(Hybrid, ForeignAndGarbageCachesAreHarmless) {
  const ConvexPolytope big(sphere_points(400, 5));
  const ConvexPolytope small(sphere_points(6, 6));
  const Pose pb = Pose::from_translation(Vec3(0.3, 2.4, 0.1));
  const double expected = distance(big, Pose::identity(), small, pb).distance;

  DistanceCache foreign;
  distance(small, Pose::identity(), big, Pose::from_translation(Vec3(-3, 0, 0)), {}, &foreign);
  EXPECT_NEAR(distance(big, Pose::identity(), small, pb, {}, &foreign).distance, expected, 1e-13);

  DistanceCache garbage;
  garbage.vertices_a = {399, 399, -7, 123456};
  garbage.vertices_b = {5, 1000, 2, 3};
  garbage.hint_a = 99999;
  garbage.hint_b = -42;
  // The cache's pose is the query's, so that the garbage ids are loaded
  // (a cache whose pose is far from the query's starts cold).
  garbage.rotation = pb.rotation;
  garbage.translation = pb.translation;
  const DistanceCache garbage_at_pose = garbage;
  EXPECT_NEAR(distance(big, Pose::identity(), small, pb, {}, &garbage).distance, expected, 1e-13);
  // And a garbage pose in the cache: NaN, infinite, huge.
  for (const double junk : {std::nan(""), std::numeric_limits<double>::infinity(), -1e300}) {
    DistanceCache c = garbage_at_pose;
    c.rotation(1, 2) = junk;
    c.translation.y() = junk;
    EXPECT_NEAR(distance(big, Pose::identity(), small, pb, {}, &c).distance, expected, 1e-13);
  }
}

// A cache carried to an unrelated pose (a planner sampling configurations
// with one cache per pair) must not cost more than no cache (issue 14). The
// stale pair used to be the start: 7.7 iterations per query against the
// cold start's 1.2 at N = 64 (bench/distance_bench WarmRandom), 2.7 times
// the cold query's instructions at N = 4096. A cache whose pose is far from
// the query's is now dropped for the cold start.
TEST(Hybrid, AWarmCacheOnUnrelatedPosesCostsNoMoreThanCold) {
  const ConvexPolytope a(sphere_points(64, 1));
  const ConvexPolytope b(sphere_points(64, 2));
  std::mt19937 rng(99);
  std::normal_distribution<double> g;
  DistanceCache warm;
  long warm_iterations = 0;
  long cold_iterations = 0;
  for (int i = 0; i < 500; ++i) {
    const Vec3 dir = drawn([&] { return g(rng); }).normalized();
    const Pose pose(drawn_quaternion([&] { return g(rng); }).normalized(), Vec3(3.0 * dir));
    const DistanceResult w = distance(a, Pose::identity(), b, pose, {}, &warm);
    const DistanceResult c = distance(a, Pose::identity(), b, pose);
    EXPECT_NEAR(w.distance, c.distance, 1e-12);
    warm_iterations += w.iterations;
    cold_iterations += c.iterations;
  }
  EXPECT_LE(warm_iterations, cold_iterations);
}

TEST(Hybrid, IterationCapIsReportedNotHidden) {
  const ConvexPolytope a(sphere_points(4000, 8));
  const ConvexPolytope b(sphere_points(4000, 9));
  DistanceOptions options;
  options.max_iterations = 1;
  const auto r =
      distance(a, Pose::identity(), b, Pose::from_translation(Vec3(2.5, 0.1, 0)), options);
  EXPECT_LE(r.iterations, 1);
  if (r.status == Status::iteration_cap) {
    EXPECT_LE(r.lower_bound, r.distance);
  } else {
    EXPECT_EQ(r.status, Status::separated);
  }
}

// The certified tracked pair (certified_pair.h) against its slow twin, the
// full hybrid from a copy of the same cache, on random walks of B in A's
// frame. Where the pair certifies, the hybrid must stop at its first pass
// with the same pair, so every field agrees bit for bit (the same kernel,
// direction and supports) but the lower bound, the fast one being the gap
// less its rounding slack: at most the hybrid's, and at most the exact
// distance (every `kOracleEvery`-th step, exact oracle). Where it declines,
// the cache is untouched. Counts the certified steps and the steps whose
// cached pair changed (certified or not: the walk must cross many).
struct TwinWalk {
  int certified = 0;
  int pair_changes = 0;
  int oracle_checks = 0;
  int cold_restarts = 0;
  int handed_on = 0;
};

// One step of a twin walk at B's pose `pose` in A's frame (see above).
void twin_step(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose, bool use_oracle,
               test::ExactOracle& oracle, DistanceCache& cache, TwinWalk& out) {
  using test::same_bits;
  const DistanceOptions options;
  const double r_local = std::max(a.scale(), magnitude_bound(pose, b.scale()));
  const double band = contact_band(r_local);
  const DistanceCache before = cache;
  DistanceCache slow_cache = cache;
  DistanceResult fast;
  detail::TrackedPairStart start;
  const bool hit =
      detail::certified_tracked_distance(a, b, pose, options, band, cache, fast, start);
  const DistanceResult slow = hybrid_distance(a, b, pose, options, band, slow_cache);
  const bool pair_changed =
      before.vertices_a != slow_cache.vertices_a || before.vertices_b != slow_cache.vertices_b;
  out.pair_changes += pair_changed ? 1 : 0;
  if (!hit) {
    EXPECT_TRUE(cache.vertices_a == before.vertices_a && cache.vertices_b == before.vertices_b &&
                cache.hint_a == before.hint_a && cache.hint_b == before.hint_b)
        << "declined but wrote the cache";
    if (start.valid) {
      // The loop going on from the declined pair's evaluation gives the
      // answer of the loop from the cache, bit for bit.
      ++out.handed_on;
      DistanceCache from_pair_cache = cache;
      const DistanceResult from_pair =
          hybrid_distance_from_pair(a, b, pose, options, band, from_pair_cache, start);
      EXPECT_EQ(from_pair.status, slow.status);
      EXPECT_EQ(from_pair.iterations, slow.iterations);
      EXPECT_TRUE(same_bits(from_pair.distance, slow.distance));
      EXPECT_TRUE(same_bits(from_pair.lower_bound, slow.lower_bound));
      EXPECT_TRUE(same_bits(from_pair.point_a, slow.point_a));
      EXPECT_TRUE(same_bits(from_pair.point_b, slow.point_b));
      EXPECT_TRUE(test::same_feature(from_pair.feature_a, slow.feature_a));
      EXPECT_TRUE(test::same_feature(from_pair.feature_b, slow.feature_b));
    }
    cache = slow_cache;
    return;
  }
  ++out.certified;
  EXPECT_EQ(slow.status, Status::separated);
  EXPECT_EQ(fast.status, Status::separated);
  if (slow.iterations > 0) {
    // The hybrid took B for moved far since the cache's pose and started
    // cold (hybrid.cpp, moved_far), where the pair, certified whatever the
    // motion, does not look: the same distance within the standard, from
    // other closest points where they are not unique (faces face to face).
    ++out.cold_restarts;
    EXPECT_NEAR(fast.distance, slow.distance, 1e-12 * slow.distance + 64 * kUnitRoundoff * r_local);
    return;
  }
  EXPECT_TRUE(same_bits(fast.distance, slow.distance));
  EXPECT_TRUE(same_bits(fast.point_a, slow.point_a));
  EXPECT_TRUE(same_bits(fast.point_b, slow.point_b));
  EXPECT_TRUE(same_bits(fast.normal, slow.normal));
  EXPECT_TRUE(test::same_feature(fast.feature_a, slow.feature_a));
  EXPECT_TRUE(test::same_feature(fast.feature_b, slow.feature_b));
  EXPECT_LE(fast.lower_bound, slow.lower_bound);
  EXPECT_GE(fast.lower_bound,
            slow.lower_bound - detail::kCertifiedGapUlps * kUnitRoundoff * r_local * (1 + 1e-15));
  EXPECT_TRUE(cache.vertices_a == slow_cache.vertices_a &&
              cache.vertices_b == slow_cache.vertices_b && cache.hint_a == slow_cache.hint_a &&
              cache.hint_b == slow_cache.hint_b && cache.face_a == slow_cache.face_a &&
              cache.face_b == slow_cache.face_b)
      << "the caches differ";
  if (!use_oracle) return;
  // B's vertices placed as both algorithms place them, R y + t.
  test::Points placed;
  for (const Vec3& y : b.vertices()) placed.push_back(pose.rotation * y + pose.translation);
  const std::optional<test::ExactDistance> exact =
      oracle.distance(test::Points(a.vertices().begin(), a.vertices().end()), placed);
  if (!exact) {
    ADD_FAILURE() << oracle.last_error();
    return;
  }
  ++out.oracle_checks;
  const mpq_class lower(fast.lower_bound);
  EXPECT_LE(lower * lower, exact->distance_squared) << "lower bound above the exact distance";
  EXPECT_TRUE(test::within_bound(fast.distance, exact->distance_squared, 1e-12,
                                 64 * kUnitRoundoff * r_local));
}

// A random walk of B around A (both of radius 1 before `scale`): steps of
// `step_length`, turns of `turn` radians about random axes, the centre kept
// between 0.9 and 1.6 `reach` from A's.
TwinWalk twin_walk(const test::Points& pa, const test::Points& pb, double scale, double reach,
                   double step_length, double turn, int steps, std::uint64_t seed) {
  test::Points sa = pa;
  test::Points sb = pb;
  for (Vec3& p : sa) p *= scale;
  for (Vec3& p : sb) p *= scale;
  const ConvexPolytope a(sa);
  const ConvexPolytope b(sb);
  test::Rng rng(seed);
  test::ExactOracle oracle;
  constexpr int kOracleEvery = 40;
  DistanceCache cache;
  Vec3 position = reach * scale * test::random_unit_vector(rng);
  Quat turn_so_far = test::random_quaternion(rng);
  TwinWalk out;
  for (int step = 0; step < steps; ++step) {
    SCOPED_TRACE(step);
    const Vec3 next = position + step_length * scale * test::random_unit_vector(rng);
    const double r = next.norm() / scale;
    if (r > 0.9 * reach && r < 1.6 * reach) position = next;
    turn_so_far =
        (turn_so_far * Quat(Eigen::AngleAxisd(turn, test::random_unit_vector(rng)))).normalized();
    twin_step(a, b, Pose(turn_so_far, position), step % kOracleEvery == 0, oracle, cache, out);
  }
  return out;
}

std::vector<Vec3> random_hull_points(int n, std::uint64_t seed) {
  test::Rng rng(seed);
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(test::random_unit_vector(rng));
  return pts;
}

TEST(CertifiedPair, AgreesWithTheFullHybridOnRandomWalks) {
  // Round bodies: the closest features change every few steps.
  const TwinWalk round = twin_walk(random_hull_points(14, 1), random_hull_points(11, 2), 1.0, 2.6,
                                   0.02, 0.03, 1500, 7);
  EXPECT_GT(round.certified, 900);
  EXPECT_GT(round.pair_changes, 50);
  EXPECT_GT(round.handed_on, 20);
  EXPECT_GE(round.oracle_checks, 20);
  // Near touching: reach 2.02 on unit spheres leaves gaps down to ~1e-3,
  // and large turns change the pair at most steps.
  const TwinWalk close = twin_walk(random_hull_points(20, 3), random_hull_points(20, 4), 1.0, 2.02,
                                   0.003, 0.1, 800, 8);
  EXPECT_GT(close.certified, 100);
  EXPECT_GT(close.pair_changes, 30);
}

TEST(CertifiedPair, AgreesWithTheFullHybridOnBoxes) {
  // Boxes without turns: coplanar faces face to face and parallel edges,
  // the certificate's ties (vertices of one face level along its normal).
  const std::vector<Vec3> unit = box(Vec3(1, 1, 1));
  const TwinWalk parallel = twin_walk(unit, box(Vec3(0.5, 0.7, 0.3)), 1.0, 2.4, 0.02, 0.0, 600, 9);
  EXPECT_GT(parallel.certified, 300);
  const TwinWalk turning = twin_walk(unit, unit, 1.0, 3.0, 0.02, 0.05, 600, 10);
  EXPECT_GT(turning.certified, 300);
  EXPECT_GT(turning.pair_changes, 20);
}

TEST(CertifiedPair, AgreesWithTheFullHybridNearTouching) {
  // Boxes face to face at gaps from 1e-12 to 1e-2 of their size, sliding
  // along the face, level (ties along the face normal on both sides, edges
  // parallel) and then tilted by up to 6e-7 rad.
  const ConvexPolytope a(box(Vec3(1, 1, 1)));
  const ConvexPolytope b(box(Vec3(0.4, 0.6, 0.5)));
  test::Rng rng(14);
  test::ExactOracle oracle;
  DistanceCache cache;
  TwinWalk out;
  Vec3 slide = Vec3::Zero();
  for (int step = 0; step < 400; ++step) {
    SCOPED_TRACE(step);
    const double gap = test::log_uniform(rng, 1e-12, 1e-2);
    // The tilt's axis turns slowly, so that B's lowest vertex changes now
    // and then, not at every step.
    const double tilt = step < 100 ? 0.0 : 1e-7 * (step % 7);
    const Quat q(Eigen::AngleAxisd(tilt, Vec3(std::cos(0.01 * step), std::sin(0.01 * step), 0)));
    slide += test::drawn([&] { return test::uniform(rng, -0.05, 0.05); },
                         [&] { return test::uniform(rng, -0.05, 0.05); }, [&] { return 0.0; });
    slide = slide.cwiseMax(Vec3(-1.2, -1.2, 0)).cwiseMin(Vec3(1.2, 1.2, 0));
    // B's lowest point along z is 0.5 below its centre (less for a tilt).
    const Pose pose(q, slide + Vec3(0, 0, 1.5 + gap));
    twin_step(a, b, pose, step % 20 == 0, oracle, cache, out);
  }
  EXPECT_GT(out.certified, 200);
  EXPECT_GE(out.oracle_checks, 10);
}

TEST(CertifiedPair, ScalesFrom1eMinus300To1e300) {
  // The unscaled range of the hybrid (2^-64 .. 2^64) is certified by the
  // pair; beyond it the pair declines and the hybrid's scaled run answers.
  for (const double scale : {1e-300, 1e-150, 1e-18, 1e-6, 1.0, 1e6, 1e18, 1e150, 1e300}) {
    const bool unscaled = scale > 0x1p-64 && scale < 0x1p63;
    const TwinWalk walk = twin_walk(random_hull_points(10, 11), random_hull_points(9, 12), scale,
                                    2.5, 0.02, 0.03, 200, 13);
    if (unscaled) {
      EXPECT_GT(walk.certified, 100) << scale;
    } else {
      EXPECT_EQ(walk.certified, 0) << scale;
    }
  }
}

TEST(Hybrid, NonFinitePoseIsAClearError) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  Pose bad = Pose::from_translation(Vec3(NAN, 0, 0));
  try {
    distance(cube, Pose::identity(), cube, bad);
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("pose_b"), std::string::npos);
  }
}

}  // namespace
}  // namespace proxima
