// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Time of impact (proxima/motion/time_of_impact.h) against closed forms
// (translating boxes) and against a dense sampling of the distance along
// the motion: the reported t is never after the first sampled contact, no
// sample before t is in contact, and at t the distance is within the
// tolerance of the target.
#include "proxima/motion/time_of_impact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/primitives.h"
#include "motion/sweep.h"
#include "motion/time_of_impact.h"
#include "support/penetration_oracle.h"
#include "support/sanitizers.h"

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

std::vector<Vec3> sphere_points(int n, std::uint32_t seed, double radius) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(radius * drawn([&] { return g(rng); }).normalized());
  return pts;
}

double distance_at(const ConvexPolytope& a, const Motion& ma, const ConvexPolytope& b,
                   const Motion& mb, double t) {
  return distance(a, ma.at(t), b, mb.at(t)).distance;
}

// A distance answer at the reported time of contact (a fresh query's, or
// the result's own) within the target separation and its tolerance, up to
// 1e-9 of rounding.
template <class Answer>
void expect_within_target(const Answer& at, const ImpactOptions& options) {
  EXPECT_GE(at.signed_distance(), options.target_separation - 1e-9);
  EXPECT_LE(at.signed_distance(), options.target_separation + options.tolerance + 1e-9);
}

// The guarantee of time_of_impact checked against `samples` evenly spaced
// times: no sample before the reported t within the target (minus a
// rounding margin), the reported t not after the first sample within it,
// and for contact the distance at t within the tolerance.
void check_against_sampling(const ConvexPolytope& a, const Motion& ma, const ConvexPolytope& b,
                            const Motion& mb, const ImpactOptions& options, const ImpactResult& r,
                            int samples) {
  const double margin = 1e-9;
  double first_contact = 2.0;
  for (int i = 0; i <= samples; ++i) {
    const double s = static_cast<double>(i) / samples;
    const double d = distance_at(a, ma, b, mb, s);
    if (d <= options.target_separation && first_contact > 1.0) first_contact = s;
    if (s < r.t) {
      EXPECT_GT(d, options.target_separation - margin) << "contact missed at t = " << s;
    }
  }
  EXPECT_LE(r.t, first_contact + 1e-15);
  if (r.status == ImpactStatus::contact) {
    EXPECT_LE(r.at_t.distance, options.target_separation + options.tolerance + margin);
    EXPECT_GE(r.at_t.distance, options.target_separation - margin);
  }
  if (r.status == ImpactStatus::separated) {
    EXPECT_GT(first_contact, 1.0);
  }
}

TEST(TimeOfImpact, TranslatingBoxesMeetAtTheClosedFormTime) {
  // B, a cube of half side 1, from x = 5 to x = -5 through A (the same cube
  // at the origin): the faces meet when B's centre is at x = 2, t* = 0.3.
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Motion ma = Motion::fixed(Pose::identity());
  const Motion mb{Pose::from_translation(Vec3(5, 0.3, -0.2)),
                  Pose::from_translation(Vec3(-5, 0.3, -0.2))};
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult r = time_of_impact(cube, ma, cube, mb, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  EXPECT_LE(r.t, 0.3);
  EXPECT_GE(r.t, 0.3 - 1e-9 / 10 - 1e-14);
  EXPECT_LE(r.at_t.distance, 1e-9);
  EXPECT_NEAR(r.at_t.normal.x(), 1.0, 1e-12);  // from A towards B
  EXPECT_LE(r.iterations, 3);                  // along the normal, one step lands there

  // With a contact offset of 0.5: t* = (3 - 2.5) / 10 = 0.25.
  options.target_separation = 0.5;
  const ImpactResult o = time_of_impact(cube, ma, cube, mb, options);
  ASSERT_EQ(o.status, ImpactStatus::contact);
  EXPECT_LE(o.t, 0.25);
  EXPECT_GE(o.t, 0.25 - 1e-10 - 1e-14);
  EXPECT_NEAR(o.at_t.distance, 0.5, 1e-9);
}

// Tunnelling: a plate 1e-3 thick and a small cube that crosses it in one
// step (from 10 on one side to 10 on the other); sampling the two ends only
// (what a discrete step does) sees no contact.
TEST(TimeOfImpact, AFastBodyDoesNotTunnelThroughAThinPlate) {
  const ConvexPolytope plate(box(Vec3(5e-4, 3, 3)));
  const ConvexPolytope bullet(box(Vec3(0.01, 0.01, 0.01)));
  const Motion ma = Motion::fixed(Pose::identity());
  const Motion mb{Pose::from_translation(Vec3(-10, 0.5, 0.5)),
                  Pose::from_translation(Vec3(10, 0.5, 0.5))};
  EXPECT_GT(distance_at(plate, ma, bullet, mb, 0.0), 9.0);
  EXPECT_GT(distance_at(plate, ma, bullet, mb, 1.0), 9.0);
  ImpactOptions options;
  options.tolerance = 1e-10;
  const ImpactResult r = time_of_impact(plate, ma, bullet, mb, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  const double t_star = (10.0 - 5e-4 - 0.01) / 20.0;
  EXPECT_LE(r.t, t_star);
  EXPECT_GE(r.t, t_star - 1e-11 - 1e-14);
}

TEST(TimeOfImpact, BodiesMovingApartAreSeparatedThroughout) {
  const ConvexPolytope a(sphere_points(30, 1, 1.0));
  const ConvexPolytope b(sphere_points(30, 2, 1.0));
  const Motion ma = Motion::fixed(Pose::identity());
  const Motion mb{Pose::from_translation(Vec3(3, 0, 0)), Pose::from_translation(Vec3(8, 1, 0))};
  const ImpactResult r = time_of_impact(a, ma, b, mb);
  EXPECT_EQ(r.status, ImpactStatus::separated);
  EXPECT_EQ(r.t, 1.0);
  EXPECT_LE(r.iterations, 2);
  EXPECT_GT(r.at_t.distance, 5.0);
}

TEST(TimeOfImpact, OverlappingAtTheStartSaysSo) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Motion ma = Motion::fixed(Pose::identity());
  const Motion mb{Pose::from_translation(Vec3(1.5, 0, 0)), Pose::from_translation(Vec3(9, 0, 0))};
  const ImpactResult r = time_of_impact(cube, ma, cube, mb);
  EXPECT_EQ(r.status, ImpactStatus::intersecting);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.at_t.status, Status::intersecting);
}

// A bar spinning a quarter turn about its centre sweeps into a cube beside
// it: the distance is not monotone in t, the sampling referees.
TEST(TimeOfImpact, ASpinningBarIsCaughtWhereItFirstReachesTheCube) {
  const ConvexPolytope bar(box(Vec3(2, 0.05, 0.05)));
  const ConvexPolytope cube(box(Vec3(0.5, 0.5, 0.5)));
  const Motion mb = Motion::from_velocity(Pose::identity(), Vec3::Zero(), Vec3(0, 0, M_PI / 2));
  const Motion mcube = Motion::fixed(Pose::from_translation(Vec3(1.2, 1.5, 0)));
  ImpactOptions options;
  options.tolerance = 1e-8;
  const ImpactResult r = time_of_impact(cube, mcube, bar, mb, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  check_against_sampling(cube, mcube, bar, mb, options, r, 4000);
}

// Seeded random pairs and motions (translation up to 8, rotation up to a
// half turn each, contact offsets 0 .. 0.2): the guarantee against 1,000
// samples of each motion.
TEST(TimeOfImpact, RandomMotionsNeverReportContactLate) {
  std::mt19937 rng(2026);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const ConvexPolytope a(sphere_points(12 + trial % 20, 100 + trial, 0.5 + u(rng)));
    const ConvexPolytope b(sphere_points(6 + trial % 30, 200 + trial, 0.2 + u(rng)));
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const auto random_pose = [&](double spread) {
      const Vec3 at = drawn([&] { return spread * g(rng); });
      return Pose(drawn_quaternion([&] { return g(rng); }).normalized(), at);
    };
    const Pose a0 = random_pose(1.0);
    const Vec3 a_axis = drawn([&] { return g(rng); }).normalized();
    const Motion ma = Motion::from_velocity(a0, drawn([&] { return g(rng); }), M_PI / 2 * a_axis);
    const Pose b0 = random_pose(4.0);
    const Vec3 b_shift = drawn([&] { return g(rng); });
    const Motion mb{b0, Pose(b0.rotation * Eigen::AngleAxisd(3.0 * u(rng), Vec3::UnitX()),
                             Vec3(-b0.translation + 0.5 * b_shift))};
    ImpactOptions options;
    options.target_separation = trial % 3 == 0 ? 0.2 * u(rng) : 0.0;
    options.tolerance = 1e-7;
    const ImpactResult r = time_of_impact(a, ma, b, mb, options);
    if (r.status == ImpactStatus::intersecting) continue;
    ASSERT_NE(r.status, ImpactStatus::iteration_cap) << "trial " << trial;
    contacts += r.status == ImpactStatus::contact ? 1 : 0;
    SCOPED_TRACE("trial " + std::to_string(trial));
    check_against_sampling(a, ma, b, mb, options, r, 1000);
  }
  EXPECT_GT(contacts, 20);  // the motions cross: most trials meet
}

// An octahedron 10 above its reference point swings down about it (a
// quarter turn about z) onto a slab: its lowest vertex starts moving
// sideways, with no speed along the normal at all, and comes down only by
// its centripetal acceleration, 9.5 cos(theta): it meets the slab's top
// (0.5) at theta = acos(8.5 / 9.5), t* = theta / (pi / 2) = 0.2952. A bound
// on that vertex's plane without the acceleration term would step over the
// contact in one go (the vertex stays lowest until the turn reaches its
// normal cone's wall, past t*).
TEST(TimeOfImpact, AVertexSwingingDownAboutAFarPivotIsCaughtAtSecondOrder) {
  const ConvexPolytope slab(box(Vec3(5, 0.5, 5)));
  const ConvexPolytope octahedron({Vec3(0, 9.5, 0), Vec3(0, 10.5, 0), Vec3(0.5, 10, 0),
                                   Vec3(-0.5, 10, 0), Vec3(0, 10, 0.5), Vec3(0, 10, -0.5)});
  const Motion still = Motion::fixed(Pose::identity());
  const Motion swing = Motion::from_velocity(Pose::from_translation(Vec3(0, -8, 0)), Vec3::Zero(),
                                             Vec3(0, 0, M_PI / 2));
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult r = time_of_impact(slab, still, octahedron, swing, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  const double t_star = std::acos(8.5 / 9.5) / (M_PI / 2);
  EXPECT_LE(r.t, t_star + 1e-12);
  EXPECT_GE(r.t, t_star - 1e-6);
  EXPECT_GE(distance(slab, r.pose_a, octahedron, r.pose_b).signed_distance(), -1e-12);
  check_against_sampling(slab, still, octahedron, swing, options, r, 2000);
}

// Fast turns, slow approach, hulls of few vertices (wide normal cones: the
// witness feature's own plane bounds long steps, src/motion/time_of_impact.cpp
// feature_plane), some off their reference point: a step that overshot
// would leave the bodies overlapping at the reported t (the signed
// distance below the target) or skip a sampled contact.
TEST(TimeOfImpact, FastTurnsOfFewVertexHullsNeverOvershoot) {
  std::mt19937 rng(1313);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0, capped = 0;
  long steps = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const auto hull = [&](int n, double radius, double off) {
      std::vector<Vec3> pts;
      const Vec3 shift = off * drawn([&] { return g(rng); }).normalized();
      for (int i = 0; i < n; ++i) {
        pts.push_back(radius * drawn([&] { return g(rng); }).normalized() + shift);
      }
      return ConvexPolytope(pts);
    };
    const ConvexPolytope a = hull(4 + trial % 7, 0.5 + u(rng), trial % 3 == 0 ? u(rng) : 0.0);
    const ConvexPolytope b = hull(4 + trial % 5, 0.3 + u(rng), trial % 4 == 0 ? u(rng) : 0.0);
    const Vec3 dir = drawn([&] { return g(rng); }).normalized();
    const Pose a0(drawn_quaternion([&] { return g(rng); }).normalized(), Vec3::Zero());
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const double b_distance = 2.5 + u(rng);
    const Pose b0(drawn_quaternion([&] { return g(rng); }).normalized(), b_distance * dir);
    const Vec3 a_axis = drawn([&] { return g(rng); }).normalized();
    const double a_turn = M_PI * u(rng);
    const Motion ma =
        Motion::from_velocity(a0, 0.3 * drawn([&] { return g(rng); }), a_turn * a_axis);
    const Vec3 b_axis = drawn([&] { return g(rng); }).normalized();
    const double b_turn = M_PI * u(rng);
    const Motion mb = Motion::from_velocity(b0, -(1.0 + 2.0 * u(rng)) * dir, b_turn * b_axis);
    ImpactOptions options;
    options.target_separation = trial % 5 == 0 ? 0.1 * u(rng) : 0.0;
    options.tolerance = 1e-9;
    const ImpactResult r = time_of_impact(a, ma, b, mb, options);
    SCOPED_TRACE("trial " + std::to_string(trial));
    if (r.status == ImpactStatus::intersecting) continue;
    // A near miss while turning fast can stall the advancement (steps
    // shrink with the gap, which stays): the cap, with t still safe.
    capped += r.status == ImpactStatus::iteration_cap ? 1 : 0;
    if (r.status == ImpactStatus::contact) {
      ++contacts;
      steps += r.iterations;
      const DistanceResult at = distance(a, r.pose_a, b, r.pose_b);
      expect_within_target(at, options);
    }
    check_against_sampling(a, ma, b, mb, options, r, 2000);
  }
  EXPECT_GT(contacts, 60);
  EXPECT_LE(capped, 2);
  std::printf("%d contacts, %.2f steps each, %d capped\n", contacts,
              static_cast<double>(steps) / contacts, capped);
}

// A vertex running into the face of a turning slab. Planes along a fixed
// normal charge the face's fastest corner, so each step closed about
// nine tenths of the gap (linear convergence); the slab's face plane
// turning with it is approached at the vertex's true rate in the slab's
// frame, and the gap closes at second order (src/motion/time_of_impact.cpp
// fixed_plane_step): 7 steps where the fixed planes alone took 34, and
// still never late.
TEST(TimeOfImpact, AVertexRunningIntoATurningFaceConvergesInFewSteps) {
  const ConvexPolytope slab(box(Vec3(0.5, 3, 3)));
  const ConvexPolytope spike(
      {Vec3(0, 0, 0), Vec3(1, 0.3, 0), Vec3(1, -0.3, 0.2), Vec3(1, -0.1, -0.3), Vec3(1.2, 0, 0)});
  const Motion turning = Motion::from_velocity(Pose::identity(), Vec3::Zero(), Vec3(0, 0.3, 1.2));
  const Motion in{Pose::from_translation(Vec3(4, 0.4, -0.3)),
                  Pose::from_translation(Vec3(-2, 0.2, 0.1))};
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult r = time_of_impact(slab, turning, spike, in, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  EXPECT_EQ(r.at_t.feature_a.type, FeatureType::face);
  EXPECT_EQ(r.at_t.feature_b.type, FeatureType::vertex);
  // 7 to 10: the count moves with the last bits of the motion (the same
  // turn with its end rotation from Eigen's angle-axis or from the sweep's
  // Rodrigues formula, 2.2e-16 apart, takes 7 or 10 steps); the fixed
  // planes alone took 34.
  EXPECT_LE(r.iterations, 10);
  check_against_sampling(slab, turning, spike, in, options, r, 4000);
}

// Long thin bars and many-sided prisms crossing each other while both turn
// fast: contacts between two edges. The planes along a fixed normal charge
// each edge's fastest end, so each step closed about nine tenths of the
// gap (31.5 steps per edge-edge contact here); the plane through both
// edges (src/motion/time_of_impact.cpp edge_pair_step) approaches at the true
// rate and closes at second order (13.8), and with its acceleration bound
// taken over the step rather than the rest of the interval
// (widest_closing) in 12.1. Against dense sampling and the
// signed distance at t: without the bound's acceleration, or without its
// span (a prism turning about its axis hands the support from edge to
// edge), contacts are reported late here.
TEST(TimeOfImpact, TurningBarsCrossingEdgeOnNeverOvershoot) {
  std::mt19937 rng(2718);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0, edge_pairs = 0;
  long steps = 0, edge_steps = 0;
  const int trials = test::sanitized_count(120, 4);
  for (int trial = 0; trial < trials; ++trial) {
    const double length = 1.0 + 2.0 * u(rng);
    const ConvexPolytope a(box(drawn([&] { return length; }, [&] { return 0.05 + 0.1 * u(rng); },
                                     [&] { return 0.05 + 0.1 * u(rng); })));
    // B: a thin box, or every other time a prism of many sides (its long
    // edges between nearly coplanar faces: turning about its axis hands
    // the support from edge to edge quickly, where the bound's span ends).
    const double half = 1.0 + 2.0 * u(rng);
    std::vector<Vec3> prism;
    const int sides = 12 + trial % 13;
    const double radius = 0.1 + 0.2 * u(rng);
    for (int k = 0; k < sides; ++k) {
      const double angle = 2.0 * M_PI * k / sides;
      for (const double y : {-half, half})
        prism.emplace_back(radius * std::cos(angle), y, radius * std::sin(angle));
    }
    const ConvexPolytope b(
        trial % 2 == 0 ? box(drawn([&] { return 0.05 + 0.1 * u(rng); }, [&] { return half; },
                                   [&] { return 0.05 + 0.1 * u(rng); }))
                       : prism);
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const auto small = [&] { return 0.2 * g(rng); };
    const auto offset = [&] { return 0.3 * g(rng); };
    const Vec3 a_at = drawn(offset, offset, [] { return 0.0; });
    const Pose a0(drawn_quaternion([] { return 1.0; }, small, small, small).normalized(), a_at);
    const Vec3 b_at = drawn(offset, offset, [&] { return 2.0 + u(rng); });
    const Pose b0(drawn_quaternion([] { return 1.0; }, small, small, small).normalized(), b_at);
    const Vec3 a_axis = drawn([&] { return g(rng); }).normalized();
    const double a_turn = 2.0 * u(rng);
    const Motion ma =
        Motion::from_velocity(a0, 0.3 * drawn([&] { return g(rng); }), a_turn * a_axis);
    const Vec3 b_axis = drawn([&] { return g(rng); }).normalized();
    const double b_turn = 3.0 * u(rng);
    const auto lateral = [&] { return 0.5 * g(rng); };
    const Motion mb = Motion::from_velocity(
        b0, drawn(lateral, lateral, [&] { return -(2.5 + 2.0 * u(rng)); }), b_turn * b_axis);
    ImpactOptions options;
    options.target_separation = trial % 4 == 0 ? 0.05 * u(rng) : 0.0;
    options.tolerance = 1e-9;
    const ImpactResult r = time_of_impact(a, ma, b, mb, options);
    SCOPED_TRACE("trial " + std::to_string(trial));
    if (r.status == ImpactStatus::intersecting) continue;
    EXPECT_NE(r.status, ImpactStatus::iteration_cap);
    if (r.status == ImpactStatus::contact) {
      ++contacts;
      steps += r.iterations;
      if (r.at_t.feature_a.type == FeatureType::edge &&
          r.at_t.feature_b.type == FeatureType::edge) {
        ++edge_pairs;
        edge_steps += r.iterations;
      }
      const DistanceResult at = distance(a, r.pose_a, b, r.pose_b);
      expect_within_target(at, options);
    }
    check_against_sampling(a, ma, b, mb, options, r, 4000);
  }
  EXPECT_GT(contacts, trials / 2);
  EXPECT_GT(edge_pairs, trials / 4);
  EXPECT_LT(static_cast<double>(edge_steps) / edge_pairs, 13.0);
  std::printf("%d contacts, %.2f steps each; %d between two edges, %.2f steps each\n", contacts,
              static_cast<double>(steps) / contacts, edge_pairs,
              static_cast<double>(edge_steps) / edge_pairs);
}

// One bar swinging across another, edge on: without the plane through both
// edges this took 17 steps, with it 8 (each closing about nine tenths of the gap).
TEST(TimeOfImpact, AnEdgeSwingingOntoAnEdgeConvergesInFewSteps) {
  const ConvexPolytope bar_a(box(Vec3(2, 0.1, 0.1)));
  const ConvexPolytope bar_b(box(Vec3(0.1, 2, 0.1)));
  const Motion turning = Motion::from_velocity(Pose::identity(), Vec3::Zero(), Vec3(0.4, 0.2, 1.5));
  const Motion falling = Motion::from_velocity(Pose::from_translation(Vec3(0.2, -0.3, 2.0)),
                                               Vec3(0, 0, -4), Vec3(-0.3, 0.5, -1.0));
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult r = time_of_impact(bar_a, turning, bar_b, falling, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  EXPECT_EQ(r.at_t.feature_a.type, FeatureType::edge);
  EXPECT_EQ(r.at_t.feature_b.type, FeatureType::edge);
  EXPECT_LE(r.iterations, 10);
  check_against_sampling(bar_a, turning, bar_b, falling, options, r, 4000);
}

TEST(TimeOfImpact, TheCacheTracksAlongTheSteps) {
  const ConvexPolytope a(sphere_points(200, 3, 1.0));
  const ConvexPolytope b(sphere_points(200, 4, 1.0));
  const Motion ma = Motion::fixed(Pose::identity());
  const Motion mb = Motion::from_velocity(Pose::from_translation(Vec3(6, 0.4, 0)), Vec3(-8, 0, 0),
                                          Vec3(0, 0.5, 2.0));
  DistanceCache cache;
  const ImpactResult tracked = time_of_impact(a, ma, b, mb, {}, &cache);
  const ImpactResult cold = time_of_impact(a, ma, b, mb);
  EXPECT_EQ(tracked.status, ImpactStatus::contact);
  EXPECT_EQ(tracked.iterations, cold.iterations);
  EXPECT_NEAR(tracked.t, cold.t, 1e-12);
  EXPECT_FALSE(cache.is_cold());
}

TEST(TimeOfImpact, MotionFromVelocityMatchesItsEndPoses) {
  const Pose p(Quat(0.3, 0.1, -0.5, 0.8).normalized(), Vec3(1, 2, 3));
  const Motion m = Motion::from_velocity(p, Vec3(2, 0, -1), Vec3(0, 0, 1.0), 0.5);
  EXPECT_TRUE(m.end.translation.isApprox(Vec3(2, 2, 2.5), 1e-15));
  EXPECT_NEAR(m.angular_velocity().z(), 0.5, 1e-12);
  const Pose half = m.at(0.5);
  EXPECT_TRUE(half.translation.isApprox(Vec3(1.5, 2, 2.75), 1e-15));
  const Mat3 expected = Eigen::AngleAxisd(0.25, Vec3::UnitZ()).toRotationMatrix() * p.rotation;
  EXPECT_TRUE(half.rotation.isApprox(expected, 1e-14));
  EXPECT_TRUE(m.at(0.0).rotation == p.rotation);
}

// Motion::at turns by Rodrigues' formula from products made once
// (src/motion/time_of_impact.cpp Sweep): the same rotation as an angle-axis turn
// of t times the angle, and rigid to machine precision (within the pose
// contract's kOrthonormalUlps, so that no step's query re-orthonormalizes
// it), for turns from 1e-9 rad to a half turn.
TEST(TimeOfImpact, MotionAtIsTheAngleAxisTurnAndStaysRigid) {
  std::mt19937 rng(77);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const Vec3 start = drawn([&] { return g(rng); });
    const Pose p(drawn_quaternion([&] { return g(rng); }).normalized(), start);
    const Vec3 axis = drawn([&] { return g(rng); }).normalized();
    const double angle = trial % 4 == 0 ? 1e-9 * u(rng) : M_PI * u(rng);
    const Motion m = Motion::from_velocity(p, drawn([&] { return g(rng); }), angle * axis);
    for (int i = 1; i < 16; ++i) {
      const double t = i / 16.0;
      const Pose at = m.at(t);
      EXPECT_TRUE(detail::is_rigid(at)) << "trial " << trial << ", t = " << t;
      const Mat3 expected = Eigen::AngleAxisd(t * angle, axis).toRotationMatrix() * p.rotation;
      EXPECT_LE((at.rotation - expected).cwiseAbs().maxCoeff(), 1e-14)
          << "trial " << trial << ", t = " << t;
    }
  }
}

// Pure translation against the exact oracle: 80 seeded pairs, B moving
// towards A (most hit, some miss by a margin, some graze). Every contact
// found is never after t* and within the tolerance of it; every t* in
// [0, 1] is found (no miss). Then the same motions at 2^-996 and 2^996
// (near 1e-300 and 1e300): the same times.
TEST(TimeOfImpact, PureTranslationAgreesWithTheExactRayAgainstTheMinkowskiHull) {
  std::mt19937 rng(13);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 80; ++trial) {
    std::vector<Vec3> pa = sphere_points(8 + trial % 40, 300 + trial, 0.5 + u01(rng));
    std::vector<Vec3> pb = sphere_points(5 + trial % 25, 400 + trial, 0.3 + u01(rng));
    const Vec3 dir = drawn([&] { return g(rng); }).normalized();
    for (Vec3& y : pb) y += (3.0 + u01(rng)) * dir;  // B starts about 3 to 4 away
    const Vec3 aim = 0.6 * drawn([&] { return g(rng); });
    const Vec3 move = (aim - (pb[0] - 0.0 * dir)).normalized() * (4.0 + 4.0 * u01(rng));
    const std::optional<double> t_star = test::exact_translation_toi(pa, pb, move);
    for (const int e : {0, -996, 996}) {
      SCOPED_TRACE("trial " + std::to_string(trial) + ", scale 2^" + std::to_string(e));
      const double s = std::ldexp(1.0, e);
      std::vector<Vec3> sa = pa, sb = pb;
      for (Vec3& x : sa) x *= s;
      for (Vec3& y : sb) y *= s;
      const ConvexPolytope a(sa), b(sb);
      const Motion ma = Motion::fixed(Pose::identity());
      const Motion mb{Pose::identity(), Pose::from_translation(s * move)};
      ImpactOptions options;
      options.tolerance = 1e-10 * s;
      const ImpactResult r = time_of_impact(a, ma, b, mb, options);
      ASSERT_NE(r.status, ImpactStatus::iteration_cap);
      ASSERT_NE(r.status, ImpactStatus::intersecting);
      if (t_star) {
        ASSERT_EQ(r.status, ImpactStatus::contact) << "missed the contact at t* = " << *t_star;
        EXPECT_LE(r.t, *t_star * (1 + 1e-12));
        EXPECT_GE(r.t, *t_star - 1e-10 / move.norm() - 1e-12);
        hits += e == 0 ? 1 : 0;
      } else if (r.status == ImpactStatus::contact) {
        // Contact without t*: only a graze within the tolerance.
        EXPECT_LE(r.at_t.distance, options.tolerance);
      }
    }
  }
  EXPECT_GT(hits, 30);
}

// Grazing and near misses: B slides past a cube's face at a clearance c.
// Tolerance below c: separated; c within the tolerance: contact, at a time
// where the distance is within it. Contact at t = 1 (B ends touching) and
// at t = 0 (B starts touching), and no motion at all.
TEST(TimeOfImpact, GrazesNearMissesAndContactsAtTheEnds) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Motion still = Motion::fixed(Pose::identity());
  for (const double c : {1e-3, 1e-9}) {
    const Motion pass{Pose::from_translation(Vec3(-6, 2 + c, 0)),
                      Pose::from_translation(Vec3(6, 2 + c, 0))};
    ImpactOptions tight;
    tight.tolerance = c / 4;
    const ImpactResult miss = time_of_impact(cube, still, cube, pass, tight);
    EXPECT_EQ(miss.status, ImpactStatus::separated) << c;
    EXPECT_EQ(miss.t, 1.0);
    ImpactOptions loose;
    loose.tolerance = 4 * c;
    const ImpactResult graze = time_of_impact(cube, still, cube, pass, loose);
    EXPECT_EQ(graze.status, ImpactStatus::contact) << c;
    EXPECT_LE(graze.at_t.distance, 4 * c + 1e-15);
  }
  // Ends touching at t = 1: B's face arrives at A's.
  const Motion arrive{Pose::from_translation(Vec3(5, 0, 0)), Pose::from_translation(Vec3(2, 0, 0))};
  const ImpactResult end = time_of_impact(cube, still, cube, arrive);
  EXPECT_EQ(end.status, ImpactStatus::contact);
  EXPECT_GT(end.t, 1.0 - 1e-6);
  // Starts touching, moving away: contact at t = 0.
  const Motion leave{Pose::from_translation(Vec3(2, 0.5, 0)),
                     Pose::from_translation(Vec3(5, 0, 0))};
  const ImpactResult start = time_of_impact(cube, still, cube, leave);
  EXPECT_EQ(start.status, ImpactStatus::contact);
  EXPECT_EQ(start.t, 0.0);
  // No motion: one query (and the end's) decide.
  const ImpactResult idle =
      time_of_impact(cube, still, cube, Motion::fixed(Pose::from_translation(Vec3(3, 0, 0))));
  EXPECT_EQ(idle.status, ImpactStatus::separated);
  EXPECT_LE(idle.iterations, 2);
}

// Bodies: two spheres head-on (closed form: the centres 0.75 apart), a
// capsule swinging into a box, and a compound (two cubes) against a moving
// cube, refereed by sampling the Bodies' signed distance.
TEST(TimeOfImpact, RoundedAndCompoundBodies) {
  const Body s1 = make_sphere(0.5);
  const Body s2 = make_sphere(0.25);
  const Motion still = Motion::fixed(Pose::identity());
  const Motion head_on{Pose::from_translation(Vec3(4, 0, 0)),
                       Pose::from_translation(Vec3(-4, 0, 0))};
  ImpactOptions options;
  options.tolerance = 1e-10;
  const ImpactResult spheres = time_of_impact(s1, still, s2, head_on, options);
  ASSERT_EQ(spheres.status, ImpactStatus::contact);
  const double t_star = (4.0 - 0.75) / 8.0;
  EXPECT_LE(spheres.t, t_star);
  EXPECT_GE(spheres.t, t_star - 1e-10 / 8 - 1e-14);
  EXPECT_NEAR(spheres.at_t.point_a.x(), 0.5, 1e-9);  // on the rounded surface

  const auto sampled = [&](const Body& a, const Motion& ma, const Body& b, const Motion& mb,
                           const ImpactResult& r) {
    double first = 2.0;
    for (int i = 0; i <= 2000; ++i) {
      const double s = i / 2000.0;
      const double d = distance(a, ma.at(s), b, mb.at(s)).signed_distance();
      if (d <= 0.0 && first > 1.0) first = s;
      if (s < r.t) {
        EXPECT_GT(d, -1e-9) << "contact missed at " << s;
      }
    }
    EXPECT_LE(r.t, first + 1e-15);
    if (r.status == ImpactStatus::contact) {
      EXPECT_LE(r.at_t.distance, 1e-6);
    }
  };
  const Body capsule = make_capsule(1.0, 0.2);
  const Body block = make_box(Vec3(0.5, 0.5, 0.5), 0.05);
  const Motion swing = Motion::from_velocity(Pose::identity(), Vec3(0.5, 0, 0), Vec3(0, 2.5, 0));
  const Motion block_still = Motion::fixed(Pose::from_translation(Vec3(1.2, 0, 0.9)));
  const ImpactResult cap = time_of_impact(block, block_still, capsule, swing, options);
  EXPECT_EQ(cap.status, ImpactStatus::contact);
  sampled(block, block_still, capsule, swing, cap);

  std::vector<std::vector<Vec3>> sets = {box(Vec3(0.5, 0.5, 0.5)), box(Vec3(0.5, 0.5, 0.5))};
  for (Vec3& p : sets[1]) p += Vec3(0, 2.0, 0);
  const Body pair(CompoundBody::from_point_sets(sets), 0.1);
  const Body cube(ConvexPolytope(box(Vec3(0.3, 0.3, 0.3))));
  const Motion through{
      Pose::from_translation(Vec3(5, 2.2, 0.1)),
      Pose(Quat(Eigen::AngleAxisd(2.0, Vec3(1, 1, 0).normalized())), Vec3(-5, 1.9, 0))};
  BodyCache cache;
  const ImpactResult comp = time_of_impact(pair, still, cube, through, options, &cache);
  EXPECT_EQ(comp.status, ImpactStatus::contact);
  sampled(pair, still, cube, through, comp);
  const ImpactResult flipped = time_of_impact(cube, through, pair, still, options);
  EXPECT_NEAR(flipped.t, comp.t, 1e-6);
}

// The slow, obvious twin of a compound's time of impact: every piece pair
// on its own, each piece re-hulled in its body's frame (so that it moves
// with the body's Motion as a convex body), the convex Body time of impact
// of each pair, and the earliest (an overlapping pair, then a contact,
// first at equal times). No pruning, no hierarchy.
std::vector<Body> pieces_in_body_frame(const Body& body) {
  std::vector<Body> out;
  const CompoundBody& c = *body.compound();
  for (const CompoundPiece& piece : c.pieces()) {
    std::vector<Vec3> placed;
    for (const Vec3& v : piece.polytope->vertices()) placed.push_back(piece.pose.apply(v));
    out.emplace_back(ConvexPolytope(placed), body.radius());
  }
  return out;
}

ImpactResult every_pair_time_of_impact(const Body& a, const Motion& ma, const Body& b,
                                       const Motion& mb, const ImpactOptions& options) {
  const std::vector<Body> pa = pieces_in_body_frame(a), pb = pieces_in_body_frame(b);
  ImpactResult best;
  for (const Body& x : pa) {
    for (const Body& y : pb) {
      const ImpactResult r = time_of_impact(x, ma, y, mb, options);
      if (r.status == ImpactStatus::separated) continue;
      const bool first = best.status == ImpactStatus::separated || r.t < best.t ||
                         (r.t == best.t && r.status == ImpactStatus::intersecting);
      if (first) best = r;
    }
  }
  if (best.status == ImpactStatus::separated) best.t = 1.0;
  return best;
}

// A compound of `count` random hulls scattered in a box of half side
// `spread`, some placed by a turned piece pose.
CompoundBody random_compound(std::mt19937& rng, int count, double spread, double size) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<CompoundPiece> pieces;
  for (int i = 0; i < count; ++i) {
    auto hull = std::make_shared<const ConvexPolytope>(
        sphere_points(5 + i % 6, 900 + static_cast<std::uint32_t>(rng() % 1000), size));
    const Vec3 at = drawn([&] { return spread * u(rng); });
    const Pose pose = i % 2 == 0 ? Pose::from_translation(at)
                                 : Pose(drawn_quaternion([&] { return g(rng); }).normalized(), at);
    pieces.push_back({hull, pose});
  }
  return CompoundBody(std::move(pieces));
}

// Compounds (2 to 12 pieces, some turned in their body, some rounded)
// against convex bodies and against compounds, moving and turning through
// each other: the hierarchy's pruned answer is the earliest of every piece
// pair's own (the twin above) within the tolerance's time, with the same
// status, and it stops where the Bodies are within the tolerance of the
// target.
TEST(TimeOfImpact, CompoundsPrunedAnswerIsTheEarliestOfEveryPiecePair) {
  std::mt19937 rng(4242);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0, pruned = 0;
  for (int trial = 0; trial < 40; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const double radius_a = trial % 3 == 0 ? 0.05 : 0.0;
    const Body a(random_compound(rng, 2 + trial % 11, 1.5, 0.4), radius_a);
    const Body b = trial % 2 == 0 ? Body(ConvexPolytope(sphere_points(12, 50 + trial, 0.5)), 0.0)
                                  : Body(random_compound(rng, 2 + trial % 5, 0.8, 0.3), 0.02);
    const Vec3 dir = drawn([&] { return g(rng); }).normalized();
    // Drawn last argument (and right operand) first, the order gcc gives a
    // call (see drawn()).
    const Vec3 a_axis = drawn([&] { return g(rng); }).normalized();
    const double a_turn = M_PI * u(rng);
    const Vec3 a_velocity = 0.3 * drawn([&] { return g(rng); });
    const Motion ma = Motion::from_velocity(
        Pose(drawn_quaternion([&] { return g(rng); }).normalized(), Vec3::Zero()), a_velocity,
        a_turn * a_axis);
    const double b_distance = 4.0 + u(rng);
    const Pose b0(drawn_quaternion([&] { return g(rng); }).normalized(), b_distance * dir);
    const Vec3 b_axis = drawn([&] { return g(rng); }).normalized();
    const double b_turn = 2.0 * M_PI * u(rng);
    const Vec3 b_wobble = 0.5 * drawn([&] { return g(rng); });
    const Motion mb =
        Motion::from_velocity(b0, -(8.0 + 2.0 * u(rng)) * dir + b_wobble, b_turn * b_axis);
    ImpactOptions options;
    options.tolerance = 1e-9;
    options.target_separation = trial % 4 == 1 ? 0.05 : 0.0;
    const ImpactResult got = time_of_impact(a, ma, b, mb, options);
    const ImpactResult want = every_pair_time_of_impact(a, ma, b, mb, options);
    ASSERT_EQ(got.status, want.status);
    if (got.status == ImpactStatus::separated) continue;
    EXPECT_NEAR(got.t, want.t, 1e-6);
    const BodyResult at = distance(a, got.pose_a, b, got.pose_b);
    expect_within_target(at, options);
    EXPECT_EQ(got.piece_a, at.piece_a);
    EXPECT_EQ(got.piece_b, at.piece_b);
    contacts += got.status == ImpactStatus::contact ? 1 : 0;
    const int all = a.compound()->piece_count() * b.compound()->piece_count();
    pruned += got.pairs_advanced < all ? 1 : 0;
  }
  EXPECT_GT(contacts, 20);
  EXPECT_GT(pruned, 10);  // the hierarchy did prune
}

// A wall of 8 x 8 small cubes and a ball thrown at one corner of it: only
// the pieces near where it lands are advanced (the others' balls cannot
// be reached before that contact), and the answer is the twin's.
TEST(TimeOfImpact, ACompoundPrunesPiecePairsThatCannotMeetFirst) {
  std::vector<std::vector<Vec3>> cubes;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      std::vector<Vec3> c = box(Vec3(0.2, 0.2, 0.2));
      for (Vec3& p : c) p += Vec3(0.5 * i, 0.5 * j, 0.0);
      cubes.push_back(c);
    }
  }
  const Body wall(CompoundBody::from_point_sets(cubes));
  const Body ball = make_sphere(0.1);
  const Motion still = Motion::fixed(Pose::identity());
  const Motion thrown{Pose::from_translation(Vec3(0.1, 0.05, 5)),
                      Pose::from_translation(Vec3(0.0, 0.0, -5))};
  ImpactOptions options;
  options.tolerance = 1e-10;
  const ImpactResult r = time_of_impact(wall, still, ball, thrown, options);
  ASSERT_EQ(r.status, ImpactStatus::contact);
  // The ball's lowest point reaches the first cube's top (z = 0.2) when
  // its centre is at 0.3: t* = (5 - 0.3) / 10 (its x, y stay over the cube).
  const double t_star = 4.7 / 10.0;
  EXPECT_LE(r.t, t_star);
  EXPECT_GE(r.t, t_star - 1e-9);
  EXPECT_EQ(r.piece_a, 0);
  EXPECT_LE(r.pairs_advanced, 4);  // of 64
  const ImpactResult twin = every_pair_time_of_impact(wall, still, ball, thrown, options);
  EXPECT_NEAR(r.t, twin.t, 1e-9);
}

// The ends of the interval with a compound: a ball starting in one cube
// and touching another (overlapping at t = 0), one
// arriving exactly on a cube's top at t = 1 (contact at 1: its balls reach
// the wall only at the end, the Bodies' query at 1 decides), and bodies
// that do not move (no ball can close: nothing advanced).
TEST(TimeOfImpact, CompoundContactsAtTheEndsAndNoMotion) {
  std::vector<std::vector<Vec3>> cubes;
  for (int i = 0; i < 4; ++i) {
    std::vector<Vec3> c = box(Vec3(0.2, 0.2, 0.2));
    for (Vec3& p : c) p += Vec3(0.5 * i, 0.0, 0.0);
    cubes.push_back(c);
  }
  const Body wall(CompoundBody::from_point_sets(cubes));
  const Body ball = make_sphere(0.1);
  const Motion still = Motion::fixed(Pose::identity());
  // A ball of radius 0.25 at x = 0.5 touching one cube (its face x = 0.25,
  // exactly) and reaching into another (x >= 0.5) at the start:
  // overlapping, whichever pair is advanced first (a contact at 0 does not
  // end the search), in both orders of the pieces.
  const Motion up{Pose::from_translation(Vec3(0.5, 0.0, 0.0)),
                  Pose::from_translation(Vec3(0.5, 0.0, 3.0))};
  for (const double first : {0.0, 1.0}) {
    std::vector<std::vector<Vec3>> two = {box(Vec3(0.25, 0.25, 0.25)), box(Vec3(0.25, 0.25, 0.25))};
    for (Vec3& p : two[0]) p.x() += 0.75 * first;
    for (Vec3& p : two[1]) p.x() += 0.75 * (1.0 - first);
    const ImpactResult start =
        time_of_impact(Body(CompoundBody::from_point_sets(two)), still, make_sphere(0.25), up);
    EXPECT_EQ(start.status, ImpactStatus::intersecting) << first;
    EXPECT_EQ(start.t, 0.0);
    EXPECT_EQ(start.piece_a, first == 0.0 ? 1 : 0);
  }
  // Arriving on cube 3's top (z = 0.2) at t = 1.
  const Motion arrive{Pose::from_translation(Vec3(1.5, 0.0, 3.0)),
                      Pose::from_translation(Vec3(1.5, 0.0, 0.3))};
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult end = time_of_impact(wall, still, ball, arrive, options);
  EXPECT_EQ(end.status, ImpactStatus::contact);
  EXPECT_GT(end.t, 1.0 - 1e-9);
  EXPECT_EQ(end.piece_a, 3);
  // No motion at all, 1 apart: separated, no pair advanced.
  const ImpactResult idle = time_of_impact(
      wall, still, ball, Motion::fixed(Pose::from_translation(Vec3(0.0, 0.0, 1.3))), options);
  EXPECT_EQ(idle.status, ImpactStatus::separated);
  EXPECT_EQ(idle.t, 1.0);
  EXPECT_EQ(idle.pairs_advanced, 0);
  EXPECT_NEAR(idle.at_t.distance, 1.0, 1e-12);
}

// Issue 13 with issue 12's meshes: a triangle mesh moving into a box and a
// closed mesh sweeping over a ball. Before mesh bodies were handled here a
// mesh Body was read as a compound (a null one): a crash.
TEST(TimeOfImpact, MeshBodies) {
  // The cube [-0.5, 0.5]^3 as 12 triangles (closed), and the same cube as a
  // polytope: the two must hit at the same time.
  const std::vector<Vec3> corners = box(Vec3(0.5, 0.5, 0.5));
  std::vector<TriangleMesh::Triangle> faces;
  const ConvexPolytope hull(corners);
  for (int f = 0; f < hull.face_count(); ++f) {
    const auto face = hull.face(f);
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      const auto v = [&](std::size_t i) {
        return static_cast<std::uint32_t>(hull.input_index()[static_cast<std::size_t>(face[i])]);
      };
      faces.push_back({v(0), v(k), v(k + 1)});
    }
  }
  const Body mesh(std::make_shared<const TriangleMesh>(corners, faces));
  ASSERT_TRUE(mesh.mesh()->is_closed());
  const Body convex(hull);
  const Body ball = make_sphere(0.2);
  const Motion still = Motion::fixed(Pose::identity());
  const Motion spin_in{Pose::from_translation(Vec3(4, 0.1, 0)),
                       Pose(Quat(Eigen::AngleAxisd(1.0, Vec3(0, 0, 1))), Vec3(-2, 0.1, 0))};
  ImpactOptions options;
  options.tolerance = 1e-9;
  const ImpactResult want = time_of_impact(convex, spin_in, ball, still, options);
  const ImpactResult got = time_of_impact(mesh, spin_in, ball, still, options);
  ASSERT_EQ(want.status, ImpactStatus::contact);
  ASSERT_EQ(got.status, ImpactStatus::contact);
  // Both never pass the true time, and both stop within the tolerance of
  // contact: they agree to the distance covered at the fastest speed.
  EXPECT_NEAR(got.t, want.t, 1e-6);
  EXPECT_LE(got.at_t.distance, 1e-8);
  // Mesh against mesh, and a mesh that starts around the ball (inside a
  // closed mesh: overlapping at t = 0).
  const ImpactResult both = time_of_impact(mesh, spin_in, mesh, still, options);
  EXPECT_EQ(both.status, ImpactStatus::contact);
  const ImpactResult around = time_of_impact(mesh, still, ball, still, options);
  EXPECT_EQ(around.status, ImpactStatus::intersecting);
}

TEST(TimeOfImpact, BadInputIsRefusedByName) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Motion still = Motion::fixed(Pose::from_translation(Vec3(5, 0, 0)));
  const Motion origin = Motion::fixed(Pose::identity());
  const auto message = [&](const ImpactOptions& o, const Motion& mb) {
    try {
      time_of_impact(cube, origin, cube, mb, o);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ImpactOptions o;
  o.target_separation = -1.0;
  EXPECT_NE(message(o, still).find("target_separation"), std::string::npos);
  o = {};
  o.tolerance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(o, still).find("tolerance"), std::string::npos);
  o = {};
  o.max_iterations = 0;
  EXPECT_NE(message(o, still).find("max_iterations"), std::string::npos);
  Motion bad = still;
  bad.end.translation.x() = std::numeric_limits<double>::infinity();
  EXPECT_NE(message({}, bad).find("motion_b.end"), std::string::npos);
  EXPECT_THROW(Motion::from_velocity(Pose::identity(), Vec3::Zero(), Vec3::Zero(), 0.0),
               InvalidInput);
}

// Issue 25 (toi_spin_wrap.sh): a motion given by velocities was kept as
// its two end poses and replayed the shorter way, so a bar spinning at
// w = 2 pi (one whole turn: the end pose is the start) or 1000 rad per
// unit t was reported separated, though it sweeps through the cube (first
// contact at t = 0.506 and 0.0032), and at w = 3.2 or 4 it turned the
// wrong way. The oracle: dense sampling of the true motion, written here
// without the library's motion (the bar's rotation at s is the angle s w
// about z), then bisection of the first sampled contact.
TEST(TimeOfImpact, AVelocityMotionTurnsAtItsRateThroughAnyAngle) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const ConvexPolytope bar(std::vector<Vec3>{{0, 0, 0}, {100, 0, 0}, {0, 0.01, 0}});
  const Pose pivot = Pose::from_translation(Vec3(0, 1.05, 0));
  const Motion still = Motion::fixed(Pose::identity());
  ImpactOptions options;
  options.tolerance = 1e-9;
  // At the default cap (256 steps): the bar is a sliver (0.01 by 100)
  // whose two long edges are 1e-4 rad apart, and the edge pair's plane
  // held each step to a turn of 1e-4 rad (the bar edge's cone margin over
  // the relative turn |w|), so every contact case ended iteration_cap
  // about 0.001 of distance short of the cube. The turn is about the cube
  // edge's own line, along which the plane's normal stands still in the
  // bar (edge_pair_step's finer arc bound): a few tens of steps now.
  ASSERT_EQ(options.max_iterations, 256);
  // {w, the end of the sampled span (past the true contact, or 1)}.
  const std::pair<double, double> cases[] = {
      {3.0, 1.0}, {3.2, 1.0}, {4.0, 1.0}, {2 * M_PI, 1.0}, {1000.0, 0.01}};
  for (const auto& [rate, span] : cases) {
    // A named copy: lambdas may not capture a structured binding before
    // C++20's P1091, which clang 14 (the sanitizer build) lacks.
    const double w = rate;
    SCOPED_TRACE("w = " + std::to_string(w));
    const Motion spin = Motion::from_velocity(pivot, Vec3::Zero(), Vec3(0, 0, w));
    ASSERT_TRUE(spin.angular.has_value());
    const auto true_pose = [&](double s) {
      return Pose(Mat3(Eigen::AngleAxisd(s * w, Vec3::UnitZ())), pivot.translation);
    };
    const auto within = [&](double s) {
      return distance(cube, Pose::identity(), bar, true_pose(s)).distance <=
             options.target_separation;
    };
    // 20,000 samples over the span: a turn of at most 5e-4 rad between
    // them, far below the angle (about 0.05 rad) over which the bar's
    // passage through the cube's top lasts.
    const int samples = 20000;
    double first = 2.0;
    for (int i = 0; i <= samples; ++i) {
      const double s = span * i / samples;
      if (!within(s)) continue;
      double lo = span * (i - 1) / samples, hi = s;
      for (int k = 0; k < 60; ++k) (within(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
      first = hi;
      break;
    }
    const ImpactResult r = time_of_impact(cube, still, bar, spin, options);
    // The reproducer's query: every option at its default.
    const ImpactResult plain = time_of_impact(cube, still, bar, spin);
    if (first > 1.0) {
      EXPECT_EQ(r.status, ImpactStatus::separated);
      EXPECT_EQ(plain.status, ImpactStatus::separated);
      continue;
    }
    EXPECT_EQ(plain.status, ImpactStatus::contact);
    EXPECT_LE(plain.t, first);
    EXPECT_LE(plain.at_t.distance,
              detail::kDefaultImpactTolerance * (cube.bounding_radius() + bar.bounding_radius()));
    ASSERT_EQ(r.status, ImpactStatus::contact);
    EXPECT_LE(r.t, first);
    // Within the tolerance of the distance at t: the tip of the contact,
    // about 1 from the pivot, closes at about w per unit t, so 1e-9 of
    // distance is within about 1e-9 / w of time (a grazing approach,
    // slower, is allowed 100 times that).
    EXPECT_GE(r.t, first - 1e-7 / w);
    EXPECT_LE(r.at_t.distance, options.tolerance + 1e-12);
    // The reported poses are the true motion's at t.
    EXPECT_TRUE(r.pose_b.rotation.isApprox(true_pose(r.t).rotation, 1e-12));
  }
  // The reproducer's first contacts (dense sampling there).
  const auto t_of = [&](double w) {
    return time_of_impact(cube, still, bar,
                          Motion::from_velocity(pivot, Vec3::Zero(), Vec3(0, 0, w)), options)
        .t;
  };
  EXPECT_NEAR(t_of(3.2), 0.994, 1e-3);
  EXPECT_NEAR(t_of(4.0), 0.795, 1e-3);
  EXPECT_NEAR(t_of(2 * M_PI), 0.506, 1e-3);
  EXPECT_NEAR(t_of(1000.0), 0.0032, 1e-4);
}

// The same end pose given without the angular velocity keeps its
// documented meaning, the turn the shorter way: at w = 4 (a turn of 4 rad,
// past a half turn) the end poses alone turn by 2 pi - 4 the other way.
TEST(TimeOfImpact, AMotionByEndPosesTurnsTheShorterWay) {
  const Pose start = Pose::from_translation(Vec3(0, 1.05, 0));
  const Motion spin = Motion::from_velocity(start, Vec3::Zero(), Vec3(0, 0, 4.0));
  const Motion ends{spin.start, spin.end};
  EXPECT_FALSE(ends.angular.has_value());
  EXPECT_NEAR(spin.angular_velocity().z(), 4.0, 1e-15);
  EXPECT_NEAR(ends.angular_velocity().z(), 4.0 - 2 * M_PI, 1e-12);
  const Mat3 half_spin = Eigen::AngleAxisd(2.0, Vec3::UnitZ()).toRotationMatrix();
  const Mat3 half_ends = Eigen::AngleAxisd(2.0 - M_PI, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(spin.at(0.5).rotation.isApprox(half_spin, 1e-14));
  EXPECT_TRUE(ends.at(0.5).rotation.isApprox(half_ends, 1e-12));
  // Several whole turns: the end is the start, the motion is not still.
  const Motion turns = Motion::from_velocity(start, Vec3::Zero(), Vec3(0, 0, 6 * M_PI));
  EXPECT_TRUE(turns.end.rotation.isApprox(start.rotation, 1e-14));
  EXPECT_TRUE(turns.at(0.25).rotation.isApprox(
      Eigen::AngleAxisd(1.5 * M_PI, Vec3::UnitZ()).toRotationMatrix(), 1e-14));
}

// Issue 25 (toi_tiny_tolerance.sh): a tolerance below the contact band
// (1e-14, 1e-300 on cubes of size 1 at 5) ended at iteration_cap after 3
// of 256 steps with the distance (2.6e-14) already within the band: no
// step could be taken there. The tolerance is now raised to
// kMinToleranceBands contact bands: contact, before the true time.
TEST(TimeOfImpact, AToleranceBelowTheContactBandIsRaisedToIt) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Motion still = Motion::fixed(Pose::identity());
  const Motion through{Pose::from_translation(Vec3(5, 0, 0)),
                       Pose::from_translation(Vec3(-5, 0, 0))};
  for (const double tolerance : {1e-13, 1e-14, 1e-300}) {
    SCOPED_TRACE(tolerance);
    ImpactOptions options;
    options.tolerance = tolerance;
    const ImpactResult r = time_of_impact(cube, still, cube, through, options);
    ASSERT_EQ(r.status, ImpactStatus::contact);
    EXPECT_LE(r.t, 0.3);
    // Four bands at the poses of t (R <= 3 + sqrt(3)).
    const double bands = 4.0 * contact_band(3.0 + std::sqrt(3.0));
    EXPECT_LE(r.at_t.distance, std::max(tolerance, bands));
    EXPECT_GE(r.t, 0.3 - bands / 10);
  }
}

// Issue 25 (toi_huge_velocity.sh): velocities near the largest double.
// Both bodies at 1e308 towards each other: their relative velocity
// overflowed, and the answer was iteration_cap at t = 0; a body moving
// away at 1e308 failed in the query at t = 1; an angular velocity of
// 1e300 (every input finite) was refused as a non-finite end pose (its
// norm squared overflowed). Now: a motion whose end lies beyond the
// coordinates the distance queries accept (2^1018) is refused by name, a
// turn too fast for doubles to know its angle is refused by name, and so
// is a closing speed bound that overflows.
TEST(TimeOfImpact, VelocitiesNearTheLargestDoubleAreAnsweredOrRefusedByName) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  const Pose at5 = Pose::from_translation(Vec3(5, 0, 0));
  const Motion origin = Motion::fixed(Pose::identity());
  const auto message = [&](const Motion& ma, const Motion& mb) {
    try {
      time_of_impact(cube, ma, cube, mb);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const Motion toward = Motion::from_velocity(at5, Vec3(-1e308, 0, 0), Vec3::Zero());
  const Motion away = Motion::from_velocity(at5, Vec3(1e308, 0, 0), Vec3::Zero());
  const Motion fast_a = Motion::from_velocity(Pose::identity(), Vec3(1e308, 0, 0), Vec3::Zero());
  for (const std::string& m :
       {message(fast_a, toward), message(origin, toward), message(origin, away)}) {
    EXPECT_NE(m.find(".end reaches coordinates of magnitude 1e+308"), std::string::npos) << m;
    EXPECT_NE(m.find("beyond the supported 2.81e+306"), std::string::npos) << m;
  }
  EXPECT_NE(message(fast_a, toward).find("motion_a.end"), std::string::npos);
  EXPECT_NE(message(origin, away).find("motion_b.end"), std::string::npos);

  // Within the supported coordinates, both moving: the contact at the
  // closed-form time 3 / 2e306.
  const Motion a_in = Motion::from_velocity(Pose::identity(), Vec3(1e306, 0, 0), Vec3::Zero());
  const Motion b_in = Motion::from_velocity(at5, Vec3(-1e306, 0, 0), Vec3::Zero());
  const ImpactResult both = time_of_impact(cube, a_in, cube, b_in);
  ASSERT_EQ(both.status, ImpactStatus::contact);
  EXPECT_LE(both.t, 1.5e-306);
  EXPECT_GE(both.t, 1.5e-306 * (1 - 1e-6));

  // A turn of 1e300 rad per unit t: its angle at t is not known to a
  // radian (consecutive doubles near it are 1e284 apart), refused by name;
  // at 2^52 rad per unit t it still turns (a cube spinning about its
  // center beside another is separated).
  const Motion spin = Motion::from_velocity(at5, Vec3::Zero(), Vec3(0, 0, 1e300));
  ASSERT_TRUE(spin.angular.has_value());
  EXPECT_NE(message(origin, spin).find("motion_b.angular turns at 1e+300 rad per unit t, beyond "
                                       "the supported 4.5e+15"),
            std::string::npos)
      << message(origin, spin);
  const Motion fastest = Motion::from_velocity(at5, Vec3::Zero(), Vec3(0, 0, 0x1p52));
  const ImpactResult r = time_of_impact(cube, origin, cube, fastest);
  EXPECT_EQ(r.status, ImpactStatus::separated);
  EXPECT_TRUE(r.at_t.distance >= 4.0 - std::sqrt(2.0) && r.at_t.distance <= 3.0 + 1e-12);

  // A body of size 1e300 turning at 1e10: its points' speed overflows.
  const ConvexPolytope huge(box(Vec3(1e300, 1e300, 1e300)));
  const Motion turning = Motion::from_velocity(Pose::identity(), Vec3::Zero(), Vec3(0, 0, 1e10));
  try {
    time_of_impact(huge, turning, cube, Motion::fixed(Pose::from_translation(Vec3(3e300, 0, 0))));
    ADD_FAILURE() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("closing speed bound"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Motion::from_velocity(at5, Vec3(1e308, 0, 0), Vec3::Zero(), 10.0), InvalidInput);
  EXPECT_THROW(Motion::from_velocity(at5, Vec3::Zero(), Vec3(1e308, 1e308, 1e308)),
               InvalidInput);
}

// A Motion whose angular velocity does not end at its end pose (built by
// hand) is refused by name rather than followed to one end or the other.
TEST(TimeOfImpact, AnAngularVelocityThatDoesNotEndAtTheEndPoseIsRefused) {
  const ConvexPolytope cube(box(Vec3(1, 1, 1)));
  Motion m = Motion::from_velocity(Pose::from_translation(Vec3(5, 0, 0)), Vec3::Zero(),
                                   Vec3(0, 0, 1.0));
  m.angular = Vec3(0, 0, 1.5);
  try {
    time_of_impact(cube, Motion::fixed(Pose::identity()), cube, m);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("motion_b.end.rotation is not where .angular turns"),
              std::string::npos)
        << e.what();
  }
  m.angular = Vec3(0, std::numeric_limits<double>::quiet_NaN(), 1.0);
  EXPECT_THROW(time_of_impact(cube, Motion::fixed(Pose::identity()), cube, m), InvalidInput);
}

// A rolling terrain: an n x n grid of cells over [-size / 2, size / 2]^2,
// two triangles per cell, heights of a few bumps (open, non-convex).
TriangleMesh terrain(int n, double size) {
  std::vector<Vec3> vertices;
  std::vector<TriangleMesh::Triangle> triangles;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = size * (static_cast<double>(i) / n - 0.5);
      const double y = size * (static_cast<double>(j) / n - 0.5);
      vertices.emplace_back(x, y,
                            0.3 * std::sin(1.3 * x) * std::cos(0.9 * y) + 0.1 * std::sin(5 * y));
    }
  }
  const auto id = [n](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return TriangleMesh(vertices, triangles);
}

// The flat hull of triangle i of `mesh` (its corners in the mesh's frame).
ConvexPolytope triangle_hull(const TriangleMesh& mesh, int i) {
  const TriangleMesh::Triangle& t = mesh.triangle(i);
  return ConvexPolytope(std::vector<Vec3>{mesh.vertex(static_cast<int>(t[0])),
                                          mesh.vertex(static_cast<int>(t[1])),
                                          mesh.vertex(static_cast<int>(t[2]))});
}

// The first time the Bodies' signed distance comes within `target`: dense
// sampling, then bisection with the exact distance (2 if never).
double first_contact_of_bodies(const Body& a, const Motion& ma, const Body& b, const Motion& mb,
                               double target, int samples) {
  const auto within = [&](double s) {
    return distance(a, ma.at(s), b, mb.at(s)).signed_distance() <= target;
  };
  for (int i = 0; i <= samples; ++i) {
    const double s = static_cast<double>(i) / samples;
    if (!within(s)) continue;
    if (i == 0) return 0.0;
    double lo = static_cast<double>(i - 1) / samples, hi = s;
    for (int k = 0; k < 60; ++k) (within(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    return hi;
  }
  return 2.0;
}

// Issue 13 for meshes: the branch and bound over the mesh's triangles (each
// a flat convex piece, src/motion/time_of_impact.cpp MeshTree) against its slow
// twin, every triangle advanced on its own against the convex body (the
// convex call per triangle, the earliest kept), and against the oracle
// (dense sampling and bisection of the Bodies' exact distance): never
// after t*, within the tolerance of the target at t, the same time as every
// triangle's earliest, and its triangle (piece_a) one that is there.
TEST(TimeOfImpact, MeshPrunedAnswerIsTheEarliestOfEveryTriangle) {
  const auto mesh = std::make_shared<const TriangleMesh>(terrain(14, 6.0));
  const Body ground(mesh);
  std::mt19937 rng(1717);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const ConvexPolytope rock(sphere_points(10, 50 + trial, 0.2 + 0.3 * u(rng)));
    const Body body(rock);
    // The ground turning a little about a tilted axis; the rock thrown
    // across it, spinning.
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const auto normal = [&] { return g(rng); };
    const Vec3 a_spin = 0.3 * drawn(normal);
    const Vec3 a_velocity = 0.2 * drawn(normal, normal, [] { return 0.0; });
    const auto tenth = [&] { return 0.1 * g(rng); };
    const Motion ma = Motion::from_velocity(
        Pose::from_translation(drawn(tenth, tenth, [] { return 0.0; })), a_velocity, a_spin);
    const auto twice = [&] { return 2.0 * g(rng); };
    const Vec3 b_at = drawn(twice, twice, [&] { return 1.5 + u(rng); });
    const Pose b0(drawn_quaternion(normal).normalized(), b_at);
    const Vec3 b_spin = 4.0 * drawn(normal);
    const auto lateral = [&] { return 1.5 * g(rng); };
    const Motion mb = Motion::from_velocity(
        b0, drawn(lateral, lateral, [&] { return -(2.0 + 2.0 * u(rng)); }), b_spin);
    ImpactOptions options;
    options.tolerance = 1e-9;
    options.target_separation = trial % 3 == 0 ? 0.05 : 0.0;
    const ImpactResult r = time_of_impact(ground, ma, body, mb, options);
    SCOPED_TRACE("trial " + std::to_string(trial));
    ASSERT_NE(r.status, ImpactStatus::iteration_cap);
    ASSERT_NE(r.status, ImpactStatus::intersecting);

    double every = 2.0;
    for (int i = 0; i < mesh->triangle_count(); ++i) {
      const ImpactResult p = time_of_impact(triangle_hull(*mesh, i), ma, rock, mb, options);
      if (p.status != ImpactStatus::separated) every = std::min(every, p.t);
    }
    const double t_star =
        first_contact_of_bodies(ground, ma, body, mb, options.target_separation, 2000);
    EXPECT_LE(r.t, t_star + 1e-12);
    if (t_star > 1.0) {
      EXPECT_EQ(r.status, ImpactStatus::separated);
      EXPECT_GT(every, 1.0);
      continue;
    }
    ASSERT_EQ(r.status, ImpactStatus::contact);
    ++contacts;
    EXPECT_NEAR(r.t, every, 1e-6);
    expect_within_target(r.at_t, options);
    // piece_a: the closest triangle at t, as far from the rock as the mesh.
    ASSERT_GE(r.piece_a, 0);
    ASSERT_LT(r.piece_a, mesh->triangle_count());
    EXPECT_EQ(r.piece_b, -1);
    EXPECT_NEAR(distance(triangle_hull(*mesh, r.piece_a), r.pose_a, rock, r.pose_b).distance,
                r.at_t.distance, 1e-9);
  }
  EXPECT_GE(contacts, 6);
}

// Mesh against mesh: every triangle pair is the slow twin.
TEST(TimeOfImpact, MeshAgainstMeshIsTheEarliestOfEveryTrianglePair) {
  const auto ground = std::make_shared<const TriangleMesh>(terrain(6, 4.0));
  // A closed mesh: the hull of 12 points, fanned into triangles.
  const ConvexPolytope hull(sphere_points(12, 77, 0.4));
  std::vector<TriangleMesh::Triangle> faces;
  for (int f = 0; f < hull.face_count(); ++f) {
    const auto face = hull.face(f);
    for (std::size_t k = 1; k + 1 < face.size(); ++k)
      faces.push_back({static_cast<std::uint32_t>(face[0]), static_cast<std::uint32_t>(face[k]),
                       static_cast<std::uint32_t>(face[k + 1])});
  }
  const std::vector<Vec3> hull_vertices(hull.vertices().begin(), hull.vertices().end());
  const auto stone = std::make_shared<const TriangleMesh>(hull_vertices, faces);
  ASSERT_TRUE(stone->is_closed());
  std::mt19937 rng(99);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int contacts = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const Motion ma =
        Motion::from_velocity(Pose::identity(), Vec3::Zero(), 0.3 * drawn([&] { return g(rng); }));
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const auto normal = [&] { return g(rng); };
    const Vec3 b_at = drawn(normal, normal, [&] { return 1.5 + u(rng); });
    const Pose b0(drawn_quaternion(normal).normalized(), b_at);
    const Vec3 b_spin = 3.0 * drawn(normal);
    const Motion mb = Motion::from_velocity(
        b0, drawn(normal, normal, [&] { return -(2.0 + 2.0 * u(rng)); }), b_spin);
    ImpactOptions options;
    options.tolerance = 1e-9;
    const ImpactResult r = time_of_impact(Body(ground), ma, Body(stone), mb, options);
    SCOPED_TRACE("trial " + std::to_string(trial));
    double every = 2.0;
    for (int i = 0; i < ground->triangle_count(); ++i) {
      const ConvexPolytope ti = triangle_hull(*ground, i);
      for (int j = 0; j < stone->triangle_count(); ++j) {
        const ImpactResult p = time_of_impact(ti, ma, triangle_hull(*stone, j), mb, options);
        if (p.status != ImpactStatus::separated) every = std::min(every, p.t);
      }
    }
    const double t_star = first_contact_of_bodies(Body(ground), ma, Body(stone), mb, 0.0, 2000);
    EXPECT_LE(r.t, t_star + 1e-12);
    if (t_star > 1.0) continue;
    ASSERT_EQ(r.status, ImpactStatus::contact);
    ++contacts;
    EXPECT_NEAR(r.t, every, 1e-6);
    EXPECT_LE(r.at_t.distance, options.tolerance + 1e-9);
    EXPECT_GE(r.piece_a, 0);
    EXPECT_GE(r.piece_b, 0);
  }
  EXPECT_GE(contacts, 3);
}

// The point of the branch and bound: a small body landing on a large
// terrain advances against the few triangles near where it lands (the
// whole-mesh advancement it replaces stepped by the mesh distance's lower
// bound over the fastest point speed: more steps, each a mesh query, and
// no triangle: piece_a was -1).
TEST(TimeOfImpact, AMeshPrunesTrianglesThatCannotBeHitFirst) {
  const auto mesh = std::make_shared<const TriangleMesh>(terrain(60, 30.0));
  const Body ground(mesh);
  const Body pebble(ConvexPolytope(sphere_points(12, 5, 0.25)));
  const Motion still = Motion::fixed(Pose::identity());
  std::mt19937 rng(4);
  std::normal_distribution<double> g;
  int most = 0;
  for (int trial = 0; trial < 8; ++trial) {
    // Drawn last argument first, the order gcc gives a call (see drawn()).
    const auto normal = [&] { return g(rng); };
    const auto wide = [&] { return 5.0 * g(rng); };
    const Vec3 b_at = drawn(wide, wide, [] { return 2.0; });
    const Pose b0(drawn_quaternion(normal).normalized(), b_at);
    const Vec3 b_spin = 5.0 * drawn(normal);
    const Motion fall =
        Motion::from_velocity(b0, drawn(normal, normal, [] { return -4.0; }), b_spin);
    const ImpactResult r = time_of_impact(ground, still, pebble, fall);
    ASSERT_EQ(r.status, ImpactStatus::contact);
    EXPECT_GE(r.pairs_advanced, 1);
    EXPECT_GE(r.piece_a, 0);
    most = std::max(most, r.pairs_advanced);
  }
  // 7200 triangles; a handful advanced: 18 at most with balls alone around
  // the nodes and triangles, 10 with the boxes and the triangles
  // themselves (earliest_contact), 3 with the triangles' planes first
  // (triangle_plane_advance).
  EXPECT_LE(most, 6);
  std::printf("most triangles advanced: %d of %d\n", most, mesh->triangle_count());
}

}  // namespace
}  // namespace proxima

// The sweep's poses take sin and cos of their half angle from
// detail::sin_cos_quadrant (Taylor polynomials, not libm): its twin is
// std::sin and std::cos, over the half angles a sweep takes, [0, pi/2],
// and a little outside (where it falls back to them).
TEST(TimeOfImpact, SweepSineAndCosineAreLibmsWithinAFewUlps) {
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> angle(0.0, 1.5707963267948966);
  std::vector<double> xs = {0.0,
                            1e-300,
                            1e-20,
                            1e-8,
                            1e-3,
                            0.5,
                            0.7853981633974483,
                            0.7853981633974484,
                            1.0,
                            1.5707963267948966,
                            std::nextafter(1.5707963267948966, 0.0),
                            -1e-3,
                            1.6,
                            3.0};
  for (int i = 0; i < 200000; ++i) xs.push_back(angle(rng));
  const double u = std::numeric_limits<double>::epsilon() / 2;
  for (const double x : xs) {
    double s = 0.0, c = 0.0;
    proxima::detail::sin_cos_quadrant(x, s, c);
    const double s_ref = std::sin(x), c_ref = std::cos(x);
    // A few ulps of the value, or of 1 near cos's zero at pi/2 (where the
    // tail of pi/2 sets the last bits).
    ASSERT_LE(std::abs(s - s_ref), 4 * u * std::abs(s_ref)) << x;
    ASSERT_LE(std::abs(c - c_ref), 4 * u * std::abs(c_ref) + 2 * u * u) << x;
    ASSERT_LE(std::abs(s * s + c * c - 1.0), 8 * u) << x;
  }
}
