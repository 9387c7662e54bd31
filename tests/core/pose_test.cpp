// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The rigid-pose contract (proxima/core/pose.h): one definition, the same
// acceptance and the same refusal in every C++ entry point (the CLI's and
// Python's are tested in cli_query_test and python/tests).
#include "proxima/core/pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "proxima/query/batch.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/distance.h"
#include "proxima/scene/scene.h"
#include "proxima/shape/primitives.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::drawn;
using test::drawn_quaternion;

double skew(const Mat3& r) { return (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff(); }

std::vector<Vec3> cube_points() {
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  return cube;
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(no InvalidInput thrown)";
}

// Regression (issue 9): q and s q are the same rotation for any s > 0, yet
// Eigen's normalized() squares the components: 1e200 (1, 0, 0, 1) overflowed
// to an infinite norm and 3e-162 (1, 0, 0, 1) to a subnormal squared norm
// that had lost its digits (a matrix with det 0.84, not a rotation).
TEST(Pose, QuaternionsAreNormalizedAtAnyMagnitude) {
  const Mat3 quarter_turn_x = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  for (const double s : {1e-300, 3e-162, 1e-160, 1e-20, 1.0, 1e20, 1e200, 1e300}) {
    SCOPED_TRACE(s);
    const Pose pose(Quat(s, s, 0, 0), Vec3::Zero());
    EXPECT_LE(skew(pose.rotation), 8 * kUnitRoundoff);
    EXPECT_NEAR(pose.rotation.determinant(), 1.0, 8 * kUnitRoundoff);
    EXPECT_LE((pose.rotation - quarter_turn_x).cwiseAbs().maxCoeff(), 8 * kUnitRoundoff);
  }
  // The smallest subnormal is as good a direction as any.
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_LE(
      (Pose(Quat(tiny, tiny, 0, 0), Vec3::Zero()).rotation - quarter_turn_x).cwiseAbs().maxCoeff(),
      8 * kUnitRoundoff);
}

// Regression (issue 9): a zero quaternion must be refused, never taken as
// the identity (Eigen leaves it unnormalized: a zero "rotation").
TEST(Pose, ZeroOrNonFiniteQuaternionsAreRefused) {
  EXPECT_NE(
      message_of([] { Pose(Quat(0, 0, 0, 0), Vec3::Zero()); }).find("Pose: the quaternion is zero"),
      std::string::npos);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(
      message_of([&] { Pose(Quat(1, nan, 0, 0), Vec3::Zero()); }).find("quaternion is not finite"),
      std::string::npos);
  EXPECT_NE(
      message_of([&] { Pose(Quat(inf, 0, 0, 0), Vec3::Zero()); }).find("quaternion is not finite"),
      std::string::npos);
  EXPECT_NE(message_of([] {
              unit_quaternion(Quat(0, 0, 0, 0), "a.rotation");
            }).find("a.rotation: the quaternion is zero: it is not a rotation"),
            std::string::npos);
}

TEST(Pose, OrthonormalRotationsPassUnchanged) {
  const Pose pose(Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())), Vec3(1, -2, 3));
  const Pose checked = checked_pose(pose, "p");
  EXPECT_EQ(checked.rotation, pose.rotation);
  EXPECT_EQ(checked.translation, pose.translation);
}

// A rotation that went through float32 is accepted and replaced by a
// rotation orthonormal to machine precision, within the contract's
// tolerance of the given one.
TEST(Pose, Float32RotationsAreReorthonormalized) {
  const Mat3 exact = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mat3 rounded = exact.cast<float>().cast<double>();
  ASSERT_GT(skew(rounded),
            kOrthonormalUlps * kUnitRoundoff);  // premise: float32 rounding is visible
  const Pose checked = checked_pose(Pose(rounded, Vec3(4, 5, 6)), "p");
  EXPECT_LE(skew(checked.rotation), 8 * kUnitRoundoff);
  EXPECT_GT(checked.rotation.determinant(), 0.0);
  EXPECT_LE((checked.rotation - rounded).cwiseAbs().maxCoeff(), kRotationTolerance);
  EXPECT_EQ(checked.translation, Vec3(4, 5, 6));
}

TEST(Pose, NonRigidPosesAreRefusedByName) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Pose nan_pose;
  nan_pose.rotation(2, 2) = nan;
  EXPECT_EQ(message_of([&] { check_pose(nan_pose, "pose_a"); }),
            "pose_a is not finite (NaN or infinite rotation or translation)");
  const Pose scaled(Mat3(Mat3::Identity() * (1 + 1e-5)), Vec3::Zero());
  EXPECT_NE(
      message_of([&] {
        check_pose(scaled, "pose_a");
      }).find("pose_a: rotation is not orthonormal (max |R^T R - I| = 2e-05, tolerance 1e-6)"),
      std::string::npos);
  const Pose mirror(Mat3(Vec3(1, 1, -1).asDiagonal()), Vec3::Zero());
  EXPECT_NE(
      message_of([&] { check_pose(mirror, "pose_a"); }).find("pose_a: rotation is a reflection"),
      std::string::npos);
  const Pose zero(Mat3::Zero(), Vec3::Zero());
  EXPECT_NE(message_of([&] { check_pose(zero, "pose_a"); }).find("not a rotation"),
            std::string::npos);
}

// Every entry point refuses the same poses with the same words, naming
// where; and a re-orthonormalized pose gives the same answer everywhere.
TEST(Pose, EveryEntryPointUsesTheContract) {
  const auto cube = std::make_shared<const ConvexPolytope>(cube_points());
  const Pose skewed(Mat3(Mat3::Identity() * 1.001), Vec3(3, 0, 0));
  const std::string words = "rotation is not orthonormal";

  EXPECT_NE(message_of([&] {
              distance(*cube, Pose{}, *cube, skewed);
            }).find("distance: pose_b: " + words),
            std::string::npos);
  const CompoundBody compound({{cube, Pose{}}});
  EXPECT_NE(message_of([&] {
              distance(compound, skewed, compound, Pose{});
            }).find("distance: pose_a: " + words),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              CompoundBody({{cube, Pose{}}, {cube, skewed}});
            }).find("CompoundBody: piece 1: pose: " + words),
            std::string::npos);
  Scene scene;
  const BodyId id = scene.add(cube, Pose{});
  EXPECT_NE(message_of([&] {
              scene.add(cube, skewed);
            }).find("Scene::add: pose of the new convex body: " + words),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              scene.set_pose(id, skewed);
            }).find("Scene::set_pose: pose of body 0: " + words),
            std::string::npos);
  std::vector<Pose> poses_a(3), poses_b(3, Pose::from_translation(Vec3(3, 0, 0)));
  poses_b[2] = skewed;
  std::vector<DistanceResult> results(3);
  EXPECT_NE(message_of([&] {
              distance_batch(*cube, poses_a, *cube, poses_b, results, {});
            }).find("distance_batch: poses_b[2]: " + words),
            std::string::npos);

  // A float32 pose: the query answers for the re-orthonormalized pose.
  const Mat3 exact = Eigen::AngleAxisd(0.3, Vec3(0, 1, 1).normalized()).toRotationMatrix();
  const Pose float_pose(Mat3(exact.cast<float>().cast<double>()), Vec3(2.5, 0.3, 0.1));
  const Pose snapped = checked_pose(float_pose, "p");
  const DistanceResult given = distance(*cube, Pose{}, *cube, float_pose);
  const DistanceResult as_snapped = distance(*cube, Pose{}, *cube, snapped);
  EXPECT_EQ(given.distance, as_snapped.distance);
  EXPECT_EQ(given.point_b, as_snapped.point_b);
}

// A pose checked once (RigidPose, issue 28): refused with the contract's
// words naming where, re-orthonormalized like any query does it, and a
// query given two of them answers as the Pose overload does, bit for bit,
// along a tracked walk (the same cache evolution) and cold.
TEST(Pose, RigidPosesAreCheckedOnceAndAnswerAsPlainPoses) {
  const Pose skewed(Mat3(Mat3::Identity() * 1.001), Vec3(3, 0, 0));
  EXPECT_NE(message_of([&] { RigidPose(skewed, "planner: configuration 7"); })
                .find("planner: configuration 7: rotation is not orthonormal"),
            std::string::npos);
  Pose nan_pose;
  nan_pose.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message_of([&] { RigidPose{nan_pose}; }),
            "RigidPose is not finite (NaN or infinite rotation or translation)");
  EXPECT_EQ(RigidPose().pose().rotation, Mat3::Identity());

  const ConvexPolytope a(cube_points());
  std::mt19937 rng(28);
  std::vector<Vec3> points;
  std::normal_distribution<double> g;
  for (int i = 0; i < 40; ++i) points.push_back(drawn([&] { return g(rng); }));
  const ConvexPolytope b(points);
  // Float32 rotations (re-orthonormalized by both) and exact ones, B
  // circling A and spinning: the walk crosses feature changes.
  DistanceCache plain_cache;
  DistanceCache rigid_cache;
  const RigidPose rigid_a(Pose::from_translation(Vec3(0.1, -0.2, 0.3)));
  for (int i = 0; i < 400; ++i) {
    const double t = 0.05 * i;
    const Mat3 turn = Eigen::AngleAxisd(0.07 * i, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Mat3 r = i % 3 == 0 ? Mat3(turn.cast<float>().cast<double>()) : turn;
    const Pose pose_b(r, Vec3(4 * std::cos(t), 4 * std::sin(t), std::sin(3 * t)));
    const RigidPose rigid_b(pose_b);
    for (DistanceCache* cache : {&plain_cache, static_cast<DistanceCache*>(nullptr)}) {
      DistanceCache* other = cache == nullptr ? nullptr : &rigid_cache;
      const DistanceResult p = distance(a, rigid_a.pose(), b, pose_b, {}, cache);
      const DistanceResult q = distance(a, rigid_a, b, rigid_b, {}, other);
      ASSERT_EQ(p.status, q.status) << "step " << i;
      ASSERT_EQ(p.distance, q.distance) << "step " << i;
      ASSERT_EQ(p.lower_bound, q.lower_bound) << "step " << i;
      ASSERT_EQ(p.point_a, q.point_a) << "step " << i;
      ASSERT_EQ(p.point_b, q.point_b) << "step " << i;
      ASSERT_EQ(p.normal, q.normal) << "step " << i;
      ASSERT_EQ(p.feature_a.vertices, q.feature_a.vertices) << "step " << i;
      ASSERT_EQ(p.feature_b.vertices, q.feature_b.vertices) << "step " << i;
      ASSERT_EQ(p.iterations, q.iterations) << "step " << i;
    }
    ASSERT_EQ(plain_cache.vertices_a, rigid_cache.vertices_a) << "step " << i;
    ASSERT_EQ(plain_cache.vertices_b, rigid_cache.vertices_b) << "step " << i;
  }
}


// Bodies take RigidPoses too (issue 28: a robot's placed geometries are
// checked once per configuration, not once per pair): the overload answers
// as the Pose overload, bit for bit, along a tracked walk with float32
// rotations (re-orthonormalized by both) on rounded, compound and convex
// bodies; the Pose overload still refuses a bad pose with its words, after
// its paired fast test.
TEST(Pose, RigidPosesOfBodiesAnswerAsPlainPoses) {
  const Pose skewed(Mat3(Mat3::Identity() * 1.001), Vec3(3, 0, 0));
  const Body sphere = make_sphere(0.5);
  EXPECT_NE(message_of([&] { (void)distance(sphere, skewed, sphere, Pose{}); })
                .find("distance: pose_a: rotation is not orthonormal"),
            std::string::npos);
  EXPECT_NE(message_of([&] { (void)distance(sphere, Pose{}, sphere, skewed); })
                .find("distance: pose_b: rotation is not orthonormal"),
            std::string::npos);

  std::mt19937 rng(2828);
  std::normal_distribution<double> g;
  std::vector<Vec3> points;
  for (int i = 0; i < 30; ++i) points.push_back(drawn([&] { return g(rng); }));
  std::vector<CompoundPiece> pieces;
  pieces.push_back({std::make_shared<const ConvexPolytope>(cube_points()), Pose{}});
  pieces.push_back({std::make_shared<const ConvexPolytope>(points),
                    Pose::from_translation(Vec3(2.5, 0, 0))});
  const std::vector<Body> bodies = {Body(ConvexPolytope(points), 0.1), make_box(Vec3(1, 0.5, 0.3)),
                                    Body(CompoundBody(std::move(pieces)))};
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    for (std::size_t j = 0; j < bodies.size(); ++j) {
      BodyCache plain_cache;
      BodyCache rigid_cache;
      const RigidPose rigid_a(Pose::from_translation(Vec3(0.1, -0.2, 0.3)));
      for (int k = 0; k < 120; ++k) {
        const double t = 0.05 * k;
        const Mat3 turn =
            Eigen::AngleAxisd(0.07 * k, Vec3(1, 2, 3).normalized()).toRotationMatrix();
        const Mat3 r = k % 3 == 0 ? Mat3(turn.cast<float>().cast<double>()) : turn;
        // From apart (radius 5) to overlapping (radius 1).
        const double radius = 5.0 - 4.0 * k / 120.0;
        const Pose pose_b(r, Vec3(radius * std::cos(t), radius * std::sin(t), std::sin(3 * t)));
        const BodyResult p = distance(bodies[i], rigid_a.pose(), bodies[j], pose_b, {},
                                      &plain_cache);
        const BodyResult q =
            distance(bodies[i], rigid_a, bodies[j], RigidPose(pose_b), {}, &rigid_cache);
        const std::string where = "bodies " + std::to_string(i) + ", " + std::to_string(j) +
                                  ", step " + std::to_string(k);
        ASSERT_EQ(p.status, q.status) << where;
        ASSERT_EQ(p.distance, q.distance) << where;
        ASSERT_EQ(p.depth, q.depth) << where;
        ASSERT_EQ(p.lower_bound, q.lower_bound) << where;
        ASSERT_EQ(p.point_a, q.point_a) << where;
        ASSERT_EQ(p.point_b, q.point_b) << where;
        ASSERT_EQ(p.normal, q.normal) << where;
        ASSERT_EQ(p.piece_a, q.piece_a) << where;
        ASSERT_EQ(p.piece_b, q.piece_b) << where;
        ASSERT_EQ(p.iterations, q.iterations) << where;
      }
    }
  }
}

}  // namespace
}  // namespace proxima

namespace proxima {
namespace {

using test::drawn;
using test::drawn_quaternion;

// The fast path of the check refuses a rotation entry of 2 or more on the
// bits (before any arithmetic, so that no trap fires on an infinite entry);
// the full test would refuse it too (a column's squared norm >= 4). Each is
// refused with the contract's words, whatever its sign, under the test
// main's traps.
TEST(Pose, RotationEntriesOfTwoOrMoreAreRefusedAsNotOrthonormal) {
  const auto cube = std::make_shared<const ConvexPolytope>(cube_points());
  for (const double x : {2.0, -2.0, 3.99, 4.0, 1e300, -1e300}) {
    for (int k = 0; k < 9; ++k) {
      Pose pose;
      pose.rotation.data()[k] = x;
      EXPECT_FALSE(detail::is_rigid(pose)) << x << " at " << k;
      EXPECT_FALSE(detail::are_rigid(pose, Pose()));
      EXPECT_FALSE(detail::are_rigid(Pose(), pose));
      EXPECT_NE(message_of([&] {
                  (void)distance(*cube, Pose(), *cube, pose);
                }).find("distance: pose_b: rotation is not orthonormal"),
                std::string::npos)
          << x << " at " << k;
    }
  }
  // Just below 2 passes the bounds and is decided by the arithmetic.
  Pose almost;
  almost.rotation(1, 1) = std::nextafter(2.0, 0.0);
  EXPECT_FALSE(detail::is_rigid(almost));
  EXPECT_NE(message_of([&] {
              (void)distance(*cube, almost, *cube, Pose());
            }).find("distance: pose_a: rotation is not orthonormal"),
            std::string::npos);
}

// distance() tests its options on the bits first (sign clear and exponent
// below all ones in both tolerances) and runs the exact test only when that
// fails: -0.0 is still accepted (it is >= 0), the largest finite tolerance
// and a subnormal one too, and every non-finite or negative one is refused
// with the same words. Regression: a NaN tolerance was compared as a
// double (comisd raises FE_INVALID on any NaN), so under the traps of the
// test main (a caller's traps) distance() died of SIGFPE instead of
// refusing it.
TEST(Pose, DistanceOptionsAreCheckedExactly) {
  const auto cube = std::make_shared<const ConvexPolytope>(cube_points());
  const Pose far = Pose::from_translation(Vec3(3, 0, 0));
  const DistanceResult plain = distance(*cube, Pose(), *cube, far);
  const double largest = std::numeric_limits<double>::max();
  for (const double x : {-0.0, 0.0, 4.9e-324, 1e-3, largest}) {
    DistanceOptions relative;
    relative.relative_tolerance = x;
    EXPECT_EQ(distance(*cube, Pose(), *cube, far, relative).status, plain.status) << x;
    DistanceOptions absolute;
    absolute.absolute_tolerance = x;
    if (x < 1.0) {
      EXPECT_EQ(distance(*cube, Pose(), *cube, far, absolute).distance, plain.distance);
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double x : {nan, -nan, inf, -inf, -1e-300, -4.9e-324, -1.0}) {
    for (const bool relative : {true, false}) {
      DistanceOptions options;
      (relative ? options.relative_tolerance : options.absolute_tolerance) = x;
      const std::string field = relative ? "relative_tolerance" : "absolute_tolerance";
      EXPECT_EQ(message_of([&] { (void)distance(*cube, Pose(), *cube, far, options); })
                    .rfind("distance: options." + field + " must be finite and >= 0, got ", 0),
                0u)
          << x;
    }
  }
  DistanceOptions none;
  none.max_iterations = 0;
  EXPECT_EQ(message_of([&] { (void)distance(*cube, Pose(), *cube, far, none); }),
            "distance: options.max_iterations must be at least 1, got 0");
}

// are_rigid (both poses in the two SIMD lanes, the check every query pays)
// decides exactly as is_rigid on each pose: rotations from quaternions and
// products of them, ones perturbed around the 32 u threshold, float32
// rotations, reflections, scaled and huge entries, NaN and infinity in any
// entry of either pose.
TEST(Pose, PairedCheckDecidesAsTheSingleCheck) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> entry(0, 11);
  std::uniform_int_distribution<int> kind(0, 7);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto random_pose = [&] {
    // The translation first, the order gcc gives the call (see drawn()).
    const Vec3 at = drawn([&] { return g(rng); }) * 10.0;
    Pose p(drawn_quaternion([&] { return g(rng); }), at);
    const int k = kind(rng);
    const int e = entry(rng);
    double& x = e < 9 ? p.rotation.data()[e] : p.translation[e - 9];
    switch (k) {
      case 0:  // around the threshold: a few tens of u on one entry
        x += std::ldexp(static_cast<double>(entry(rng) - 6) * 8.0, -53);
        break;
      case 1:
        p.rotation = p.rotation.cast<float>().cast<double>();
        break;
      case 2:
        p.rotation.col(0) *= -1.0;  // a reflection
        break;
      case 3:
        x = (entry(rng) % 2 == 0) ? nan : -inf;
        break;
      case 4:
        x *= 1e300;
        break;
      case 5:
        p.rotation = p.rotation * Mat3(drawn_quaternion([&] { return g(rng); }).normalized());
        break;
      default:
        break;  // as built
    }
    return p;
  };
  int rigid = 0;
  int refused = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose a = random_pose();
    const Pose b = random_pose();
    const bool single = detail::is_rigid(a) && detail::is_rigid(b);
    ASSERT_EQ(detail::are_rigid(a, b), single) << trial;
    ASSERT_EQ(detail::are_rigid(b, a), single) << trial;
    ASSERT_EQ(detail::are_rigid(a, a), detail::is_rigid(a)) << trial;
    (single ? rigid : refused) += 1;
  }
  EXPECT_GT(rigid, 2000);  // premise: both decisions are well represented
  EXPECT_GT(refused, 2000);
}

}  // namespace
}  // namespace proxima
