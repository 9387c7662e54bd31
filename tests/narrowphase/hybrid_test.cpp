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

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "proxima/geometry/closest_point.h"
#include "proxima/query/distance.h"

namespace proxima {
namespace {

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
    Vec3 p(g(rng), g(rng), g(rng));
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
  const Quat q(g(rng), g(rng), g(rng), g(rng));
  return Pose(q, Vec3(spread * g(rng), spread * g(rng), spread * g(rng)));
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
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Pose pose(Quat(g(rng), g(rng), g(rng), g(rng)).normalized(), Vec3(3.0 * dir));
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
