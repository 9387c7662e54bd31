// Tests of Scene: step() (broad phase, then tracked queries with the caches
// kept between steps) against its slow twin close_pairs_all_pairs() (the
// cold query on every pair), over seeded random scenes that move and change
// between steps; the same answer, bit for bit, from both broad phases and
// from 1 and 2 threads; hand-computed contact cases; bad input named by id;
// and proof that the caches carry over (the tracked run does less work).
#include "proxima/scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "support/generators.h"
#include "support/same_bits.h"
#include "support/scene_bodies.h"

namespace proxima {
namespace {

using test::Rng;
using test::same_bits;
using test::same_feature;

// A random body for a scene: mostly round or boxy clouds of 20 to 200
// points, sometimes a degenerate shape (needle, polygon, segment, point,
// grid with coplanar faces), scaled to a radius of about 0.5 to 1.2.
std::shared_ptr<const ConvexPolytope> random_convex(Rng& rng) {
  const int n = test::uniform_int(rng, 20, 200);
  test::Points pts;
  switch (test::uniform_int(rng, 0, 9)) {
    case 0:
      pts = test::random_shape(rng, test::ShapeKind::needle, n);
      break;
    case 1:
      pts = test::random_shape(rng, test::ShapeKind::flat_polygon, n);
      break;
    case 2:
      pts = test::random_shape(rng, test::ShapeKind::segment, n);
      break;
    case 3:
      pts = test::random_shape(rng, test::ShapeKind::point, n);
      break;
    case 4:
      pts = test::random_shape(rng, test::ShapeKind::grid, n);
      break;
    case 5:
      pts = test::random_shape(rng, test::ShapeKind::box, n);
      break;
    case 6:
    case 7:
      pts = test::points_in_cube(rng, n, 0.6);
      break;
    default:
      pts = test::points_on_sphere(rng, n);
      break;
  }
  return std::make_shared<const ConvexPolytope>(test::scaled(pts, test::uniform(rng, 0.5, 1.2)));
}

// Two to four small clouds around offsets within the body: a non-convex
// body (an L, a dumbbell, a cluster).
std::shared_ptr<const CompoundBody> random_compound(Rng& rng) {
  std::vector<std::vector<Vec3>> sets;
  const int pieces = test::uniform_int(rng, 2, 4);
  for (int i = 0; i < pieces; ++i) {
    const Vec3 offset = test::uniform(rng, 0.2, 0.8) * test::random_unit_vector(rng);
    sets.push_back(test::translated(
        test::scaled(test::points_on_sphere(rng, test::uniform_int(rng, 12, 40)), 0.45), offset));
  }
  return std::make_shared<const CompoundBody>(CompoundBody::from_point_sets(sets));
}

Pose random_pose(Rng& rng, double side, const Vec3& offset) {
  return {test::random_quaternion(rng),
          Vec3(offset + test::drawn([&] { return test::uniform(rng, 0, side); }))};
}

// The next frame of a slow simulation.
Pose moved(Rng& rng, const Pose& p) {
  return {Mat3(test::random_small_rotation(rng, 0.03) * p.rotation),
          Vec3(p.translation + test::uniform(rng, 0, 0.04) * test::random_unit_vector(rng))};
}

// Scenes fed the same calls: both broad phases, 1 and 2 threads. They must
// give the same ids and, step by step, the same answers bit for bit.
struct Lockstep {
  std::vector<Scene> scenes;
  // Magnitude bound |t|_inf + sqrt(3) scale of each body, by id: the R of
  // the accuracy standard.
  std::vector<double> magnitude;
  std::vector<double> scale;

  explicit Lockstep(double margin) : scenes(test::lockstep_scenes(margin)) {}

  template <class Body>
  BodyId add(const Body& body, const Pose& pose, double body_scale) {
    const BodyId id = scenes[0].add(body, pose);
    for (std::size_t k = 1; k < scenes.size(); ++k) EXPECT_EQ(scenes[k].add(body, pose), id);
    if (static_cast<std::size_t>(id) >= scale.size()) {
      scale.resize(static_cast<std::size_t>(id) + 1);
      magnitude.resize(static_cast<std::size_t>(id) + 1);
    }
    scale[static_cast<std::size_t>(id)] = body_scale;
    note_pose(id, pose);
    return id;
  }
  void set_pose(BodyId id, const Pose& pose) {
    for (Scene& s : scenes) s.set_pose(id, pose);
    note_pose(id, pose);
  }
  void remove(BodyId id) {
    for (Scene& s : scenes) s.remove(id);
  }
  void note_pose(BodyId id, const Pose& pose) {
    magnitude[static_cast<std::size_t>(id)] = pose.translation.cwiseAbs().maxCoeff() +
                                              std::sqrt(3.0) * scale[static_cast<std::size_t>(id)];
  }

  // Steps every scene; checks them against each other and the first one
  // against the all-pairs twin. Returns the first scene's pairs.
  std::vector<ClosePair> step_and_check(const std::string& where) {
    const std::span<const ClosePair> first = scenes[0].step();
    std::vector<ClosePair> out(first.begin(), first.end());
    const SceneStats stats = scenes[0].stats();
    for (std::size_t k = 1; k < scenes.size(); ++k) {
      const std::span<const ClosePair> other = scenes[k].step();
      const std::string which = where + ", scene " + std::to_string(k) + " (" +
                                to_string(scenes[k].options().broad_phase) + ", " +
                                std::to_string(scenes[k].options().threads) + " threads)";
      EXPECT_EQ(scenes[k].stats().candidate_pairs, stats.candidate_pairs) << which;
      EXPECT_EQ(scenes[k].stats().warm_pairs, stats.warm_pairs) << which;
      EXPECT_EQ(scenes[k].stats().convex_queries, stats.convex_queries) << which;
      EXPECT_EQ(scenes[k].stats().bodies, stats.bodies) << which;
      EXPECT_EQ(scenes[k].stats().close_pairs, stats.close_pairs) << which;
      EXPECT_EQ(other.size(), out.size()) << which;
      if (other.size() != out.size()) continue;
      for (std::size_t i = 0; i < out.size(); ++i) {
        const ClosePair& x = out[i];
        const ClosePair& y = other[i];
        EXPECT_TRUE(x.a == y.a && x.b == y.b && x.result.status == y.result.status &&
                    same_bits(x.result.distance, y.result.distance) &&
                    same_bits(x.result.lower_bound, y.result.lower_bound) &&
                    same_bits(x.result.point_a, y.result.point_a) &&
                    same_bits(x.result.point_b, y.result.point_b) &&
                    same_bits(x.result.normal, y.result.normal) &&
                    same_feature(x.result.feature_a, y.result.feature_a) &&
                    same_feature(x.result.feature_b, y.result.feature_b) &&
                    x.result.iterations == y.result.iterations &&
                    x.result.piece_a == y.result.piece_a && x.result.piece_b == y.result.piece_b &&
                    x.result.pairs_tested == y.result.pairs_tested)
            << which << ": pair " << i << " (" << x.a << ", " << x.b << ") differs";
      }
    }
    EXPECT_EQ(stats.close_pairs, static_cast<int>(out.size()));
    EXPECT_LE(stats.close_pairs, stats.candidate_pairs);
    EXPECT_LE(stats.warm_pairs, stats.candidate_pairs);
    EXPECT_GE(stats.convex_queries, stats.candidate_pairs);
    EXPECT_GE(stats.candidate_pairs, 64) << where << ": too few pairs to split between threads";

    const std::vector<ClosePair> twin = scenes[0].close_pairs_all_pairs();
    EXPECT_EQ(twin.size(), out.size()) << where;
    for (std::size_t i = 0, j = 0; i < out.size() || j < twin.size();) {
      // Walk both sorted lists so that a missing pair is named.
      const bool take_out =
          j == twin.size() || (i < out.size() && (out[i].a < twin[j].a ||
                                                  (out[i].a == twin[j].a && out[i].b < twin[j].b)));
      const bool take_twin =
          i == out.size() || (j < twin.size() && (twin[j].a < out[i].a ||
                                                  (twin[j].a == out[i].a && twin[j].b < out[i].b)));
      if (take_out) {
        ADD_FAILURE() << where << ": step() reports (" << out[i].a << ", " << out[i].b
                      << ") at distance " << out[i].result.distance << ", the twin does not";
        ++i;
        continue;
      }
      if (take_twin) {
        ADD_FAILURE() << where << ": the twin reports (" << twin[j].a << ", " << twin[j].b
                      << ") at distance " << twin[j].result.distance << " ("
                      << to_string(twin[j].result.status) << "), step() does not";
        ++j;
        continue;
      }
      const ClosePair& x = out[i++];
      const ClosePair& y = twin[j++];
      const double r = std::max(magnitude[static_cast<std::size_t>(x.a)],
                                magnitude[static_cast<std::size_t>(x.b)]);
      // Both answers are within the standard's bound of the exact distance.
      const double tol = 2 * (1e-12 * y.result.distance + 64 * kUnitRoundoff * r);
      EXPECT_NEAR(x.result.distance, y.result.distance, tol)
          << where << ": pair (" << x.a << ", " << x.b << ")";
      EXPECT_EQ(x.result.status, y.result.status)
          << where << ": pair (" << x.a << ", " << x.b << ")";
      EXPECT_LE(x.result.distance, scenes[0].options().margin + tol);
    }
    return out;
  }
};

struct RandomSceneCase {
  double margin;
  double offset;         // every body this far from the origin (each axis)
  int compound_percent;  // share of compound bodies
};

class RandomScene : public testing::TestWithParam<RandomSceneCase> {};

TEST_P(RandomScene, StepEqualsTheAllPairsTwinWhileBodiesMoveJoinAndLeave) {
  const RandomSceneCase c = GetParam();
  Rng rng(1000 + static_cast<std::uint64_t>(c.margin * 1000) +
          static_cast<std::uint64_t>(c.compound_percent));
  constexpr int kBodies = 60;
  // A cube of side 7 holding 60 bodies of radius ~1: a few neighbours each,
  // and over 64 candidate pairs (two grains: the narrow phase is really
  // split between 2 threads; below that it runs in the caller's thread).
  constexpr double kSide = 7.0;
  const Vec3 offset = Vec3::Constant(c.offset);
  Lockstep scene(c.margin);
  std::vector<BodyId> ids;
  std::vector<Pose> poses;
  const auto add_one = [&] {
    const Pose p = random_pose(rng, kSide, offset);
    BodyId id = -1;
    if (test::uniform_int(rng, 0, 99) < c.compound_percent) {
      const auto body = random_compound(rng);
      id = scene.add(body, p, body->scale());
    } else {
      const auto body = random_convex(rng);
      id = scene.add(body, p, body->scale());
    }
    if (static_cast<std::size_t>(id) >= poses.size())
      poses.resize(static_cast<std::size_t>(id) + 1);
    poses[static_cast<std::size_t>(id)] = p;
    ids.push_back(id);
  };
  for (int i = 0; i < kBodies; ++i) add_one();

  int contacts = 0;
  int separated = 0;
  for (int step = 0; step < 5; ++step) {
    const std::vector<ClosePair> pairs = scene.step_and_check("step " + std::to_string(step));
    for (const ClosePair& p : pairs) {
      const bool contact =
          p.result.status == Status::intersecting || p.result.status == Status::touching;
      contacts += contact ? 1 : 0;
      separated += contact ? 0 : 1;
    }
    // Everybody moves a little; two leave, two join (taking the freed ids
    // first), one jumps across the scene.
    for (const BodyId id : ids) {
      poses[static_cast<std::size_t>(id)] = moved(rng, poses[static_cast<std::size_t>(id)]);
      scene.set_pose(id, poses[static_cast<std::size_t>(id)]);
    }
    for (int k = 0; k < 2; ++k) {
      const auto at =
          static_cast<std::size_t>(test::uniform_int(rng, 0, static_cast<int>(ids.size()) - 1));
      scene.remove(ids[at]);
      ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(at));
    }
    for (int k = 0; k < 2; ++k) add_one();
    const BodyId jumper =
        ids[static_cast<std::size_t>(test::uniform_int(rng, 0, static_cast<int>(ids.size()) - 1))];
    poses[static_cast<std::size_t>(jumper)] = random_pose(rng, kSide, offset);
    scene.set_pose(jumper, poses[static_cast<std::size_t>(jumper)]);
  }
  // The scene must really hold overlapping bodies, and (above margin 0)
  // separated close pairs too.
  EXPECT_GT(contacts, 20);
  if (c.margin > 0) {
    EXPECT_GT(separated, 10);
  }
}

// The step's other parallel loops run in fixed chunks (512 world boxes,
// 1,024 pairs gathered, and the tree's own, broad_phase.cpp): a scene of
// 2,000 bodies spans several chunks of each, and its 2-thread steps must
// equal the 1-thread ones bit for bit (the small scenes above fit in one
// chunk, where the loops run in the calling thread).
TEST(SceneThreads, TwoThreadsEqualOneOnAScenePastTheChunkSizes) {
  Rng rng(20261125);
  constexpr int kBodies = 2000;
  constexpr double kSide = 24.0;  // about 5 candidates per body
  std::vector<std::shared_ptr<const ConvexPolytope>> pool;
  for (int i = 0; i < 20; ++i) {
    pool.push_back(std::make_shared<const ConvexPolytope>(
        test::points_on_sphere(rng, test::uniform_int(rng, 12, 40))));
  }
  SceneOptions o;
  o.margin = 0.05;
  o.threads = 1;
  Scene one(o);
  o.threads = 2;
  Scene two(o);
  std::vector<Pose> poses;
  for (int i = 0; i < kBodies; ++i) {
    poses.push_back(random_pose(rng, kSide, Vec3::Zero()));
    const auto& body = pool[static_cast<std::size_t>(i) % pool.size()];
    ASSERT_EQ(one.add(body, poses.back()), two.add(body, poses.back()));
  }
  for (int step = 0; step < 3; ++step) {
    const std::span<const ClosePair> a = one.step();
    const std::span<const ClosePair> b = two.step();
    EXPECT_GT(one.stats().candidate_pairs, 2 * 1024) << "too few pairs for several chunks";
    EXPECT_EQ(two.stats().candidate_pairs, one.stats().candidate_pairs);
    EXPECT_EQ(two.stats().convex_queries, one.stats().convex_queries);
    EXPECT_EQ(two.stats().warm_pairs, one.stats().warm_pairs);
    ASSERT_EQ(a.size(), b.size()) << "step " << step;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_TRUE(a[i].a == b[i].a && a[i].b == b[i].b &&
                  a[i].result.status == b[i].result.status &&
                  same_bits(a[i].result.distance, b[i].result.distance) &&
                  same_bits(a[i].result.point_a, b[i].result.point_a) &&
                  same_bits(a[i].result.point_b, b[i].result.point_b) &&
                  same_feature(a[i].result.feature_a, b[i].result.feature_a) &&
                  same_feature(a[i].result.feature_b, b[i].result.feature_b))
          << "step " << step << ", close pair " << i;
    }
    for (int i = 0; i < kBodies; ++i) {
      Pose& p = poses[static_cast<std::size_t>(i)];
      p = moved(rng, p);
      one.set_pose(i, p);
      two.set_pose(i, p);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RandomScene,
    testing::Values(RandomSceneCase{0.0, 0.0, 0}, RandomSceneCase{0.05, 0.0, 0},
                    RandomSceneCase{0.5, 0.0, 0}, RandomSceneCase{0.05, 1e5, 0},
                    RandomSceneCase{0.1, 0.0, 20}, RandomSceneCase{0.0, -3e4, 20}),
    [](const testing::TestParamInfo<RandomSceneCase>& p) {
      return "margin" + std::to_string(static_cast<int>(p.param.margin * 100)) + "cm_offset" +
             (p.param.offset < 0 ? "minus" : "") +
             std::to_string(static_cast<long long>(std::abs(p.param.offset))) + "_compounds" +
             std::to_string(p.param.compound_percent);
    });

std::shared_ptr<const ConvexPolytope> unit_cube() {
  return std::make_shared<const ConvexPolytope>(test::cube(1.0));
}

TEST(Scene, TouchingIntersectingAndMarginPairsByHand) {
  for (const double far : {0.0, 1e6}) {
    // Unit cubes centred at x = 0, 1 (faces touching), 1.5 (overlapping the
    // second) and 2.625 (0.125 from the third).
    const Vec3 o(far, -far, far);
    for (const BroadPhase bp : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
      for (const double margin : {0.0, 0.12, 0.125}) {
        SceneOptions options;
        options.margin = margin;
        options.broad_phase = bp;
        Scene scene(options);
        for (const double x : {0.0, 1.0, 1.5, 2.625}) {
          scene.add(unit_cube(), Pose::from_translation(o + Vec3(x, 0, 0)));
        }
        const std::span<const ClosePair> pairs = scene.step();
        const std::string where = "far " + std::to_string(far) + ", margin " +
                                  std::to_string(margin) + ", " + to_string(bp);
        // Spans [-0.5, 0.5], [0.5, 1.5], [1, 2], [2.125, 3.125]: (0, 1)
        // touch, (1, 2) overlap, (2, 3) are 0.125 apart, the others 0.5 or more.
        const std::size_t expected = margin >= 0.125 ? 3 : 2;
        ASSERT_EQ(pairs.size(), expected) << where;
        EXPECT_EQ(pairs[0].a, 0);
        EXPECT_EQ(pairs[0].b, 1);
        EXPECT_EQ(pairs[0].result.status, Status::touching) << where;
        EXPECT_LE(pairs[0].result.distance, 64 * kUnitRoundoff * (far + 4)) << where;
        EXPECT_EQ(pairs[1].a, 1);
        EXPECT_EQ(pairs[1].b, 2);
        EXPECT_EQ(pairs[1].result.status, Status::intersecting) << where;
        EXPECT_EQ(pairs[1].result.distance, 0.0);
        if (expected == 3) {
          EXPECT_EQ(pairs[2].a, 2);
          EXPECT_EQ(pairs[2].b, 3);
          EXPECT_EQ(pairs[2].result.status, Status::separated);
          EXPECT_NEAR(pairs[2].result.distance, 0.125, 64 * kUnitRoundoff * (far + 4));
        }
        // The 0.125 gap is outside a 0.12 margin for the boxes as well.
        EXPECT_EQ(scene.stats().candidate_pairs, static_cast<int>(expected)) << where;
        EXPECT_EQ(scene.stats().close_pairs, static_cast<int>(expected)) << where;
      }
    }
  }
}

TEST(Scene, ScenesSpanningMoreThanTheSquareRootOfTheDoubleRange) {
  // Regression: the tree's insertion cost was a box area; for bodies at
  // -1e160 and +1e160 the areas of the merged boxes overflowed to inf, and
  // inf - inf made NaN (a crash under the traps). Far out, the contact band
  // 64 u R is wide: cubes 4 apart at 1e160 are touching, and step() must say
  // what the twin says.
  const auto cube = std::make_shared<const ConvexPolytope>(test::cube(2.0));
  for (const double far : {1e100, 1e160, 1e200, 1e300}) {
    for (const BroadPhase bp : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
      SceneOptions options;
      options.broad_phase = bp;
      Scene scene(options);
      for (int i = 0; i < 6; ++i) {
        scene.add(cube, Pose::from_translation(Vec3(i % 2 == 0 ? -far : far, far, 3.0 * i)));
      }
      const std::span<const ClosePair> pairs = scene.step();
      const std::vector<ClosePair> twin = scene.close_pairs_all_pairs();
      ASSERT_EQ(pairs.size(), twin.size()) << far << " " << to_string(bp);
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        EXPECT_EQ(pairs[k].a, twin[k].a);
        EXPECT_EQ(pairs[k].b, twin[k].b);
        EXPECT_EQ(pairs[k].result.status, twin[k].result.status);
      }
      // Each side's three cubes touch each other at that magnitude.
      EXPECT_EQ(pairs.size(), 6u) << far << " " << to_string(bp);
    }
  }
}

TEST(Scene, RemovedIdsAreReusedWithFreshCaches) {
  Rng rng(5);
  SceneOptions options;
  options.margin = 0.6;
  Scene scene(options);
  std::vector<std::shared_ptr<const ConvexPolytope>> bodies;
  for (int i = 0; i < 4; ++i)
    bodies.push_back(std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 40)));
  // A row of unit spheres (40 points on them) 2.2 apart: neighbours are 0.2
  // to 0.5 apart (close pairs), the next ones over 2.4.
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(
        scene.add(bodies[static_cast<std::size_t>(i)], Pose::from_translation(Vec3(2.2 * i, 0, 0))),
        i);
  ASSERT_EQ(scene.step().size(), 3u);
  ASSERT_EQ(scene.step().size(), 3u);
  EXPECT_EQ(scene.stats().warm_pairs, 3);
  scene.remove(1);
  EXPECT_FALSE(scene.contains(1));
  EXPECT_EQ(scene.body_count(), 3);
  EXPECT_EQ(scene.body_ids(), (std::vector<BodyId>{0, 2, 3}));
  // Id 1 comes back as another body in the same place: its pairs are new.
  const auto cube = std::make_shared<const ConvexPolytope>(test::cube(1.6));
  EXPECT_EQ(scene.add(cube, Pose::from_translation(Vec3(2.2, 0, 0))), 1);
  EXPECT_TRUE(scene.contains(1));
  EXPECT_EQ(scene.pose(1).translation, Vec3(2.2, 0, 0));
  const std::span<const ClosePair> pairs = scene.step();
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(scene.stats().warm_pairs, 1);  // only (2, 3) kept its cache
  const std::vector<ClosePair> twin = scene.close_pairs_all_pairs();
  ASSERT_EQ(twin.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(pairs[k].a, twin[k].a);
    EXPECT_EQ(pairs[k].b, twin[k].b);
    EXPECT_NEAR(pairs[k].result.distance, twin[k].result.distance, 1e-12);
  }
  // A fresh id after the free list is used up.
  EXPECT_EQ(scene.add(cube, Pose::from_translation(Vec3(50, 0, 0))), 4);
}

TEST(Scene, CachesCarryOverBetweenSteps) {
  // A slow scene with a wide margin: most candidate pairs are close pairs,
  // and each keeps its cache from step to step. The tracked queries must
  // then do clearly less work than cold queries of the same pairs: this
  // fails if the caches are dropped or reset each step.
  Rng rng(77);
  SceneOptions options;
  options.margin = 0.5;
  Scene scene(options);
  std::vector<Pose> poses;
  std::vector<std::shared_ptr<const ConvexPolytope>> bodies;
  for (int i = 0; i < 60; ++i) {
    poses.push_back(random_pose(rng, 7.0, Vec3::Zero()));
    bodies.push_back(std::make_shared<const ConvexPolytope>(
        test::points_on_sphere(rng, test::uniform_int(rng, 60, 200))));
    scene.add(bodies.back(), poses.back());
  }
  scene.step();
  long long tracked = 0;
  long long cold = 0;
  int warm = 0;
  int candidates = 0;
  for (int step = 0; step < 6; ++step) {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      poses[i] = Pose(Mat3(test::random_small_rotation(rng, 0.005) * poses[i].rotation),
                      Vec3(poses[i].translation + 0.005 * test::random_unit_vector(rng)));
      scene.set_pose(static_cast<BodyId>(i), poses[i]);
    }
    for (const ClosePair& p : scene.step()) {
      const auto a = static_cast<std::size_t>(p.a);
      const auto b = static_cast<std::size_t>(p.b);
      const DistanceResult r = distance(*bodies[a], poses[a], *bodies[b], poses[b]);
      EXPECT_NEAR(p.result.distance, r.distance, 1e-12);
      tracked += p.result.iterations;
      cold += r.iterations;
    }
    warm += scene.stats().warm_pairs;
    candidates += scene.stats().candidate_pairs;
  }
  ASSERT_GT(cold, 500);
  EXPECT_LT(tracked, cold / 2) << "tracked iterations " << tracked << ", cold " << cold;
  EXPECT_GT(warm, candidates * 9 / 10);
}

TEST(Scene, BadInputIsRefusedAndNamesTheBody) {
  const auto expect_error = [](const auto& f, const std::string& needle) {
    try {
      f();
      ADD_FAILURE() << "no InvalidInput, expected one mentioning '" << needle << "'";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  SceneOptions bad;
  bad.margin = -0.1;
  expect_error([&] { Scene s(bad); }, "margin");
  bad.margin = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { Scene s(bad); }, "margin");
  bad.margin = std::numeric_limits<double>::infinity();
  expect_error([&] { Scene s(bad); }, "margin");
  bad.margin = 0.0;
  bad.threads = -1;
  expect_error([&] { Scene s(bad); }, "threads");
  bad.threads = 1;
  bad.distance.max_iterations = 0;
  expect_error([&] { Scene s(bad); }, "max_iterations");

  Scene scene;
  const Pose nan_pose =
      Pose::from_translation(Vec3(0, std::numeric_limits<double>::quiet_NaN(), 0));
  expect_error([&] { scene.add(std::shared_ptr<const ConvexPolytope>(), Pose{}); }, "null");
  expect_error([&] { scene.add(std::shared_ptr<const CompoundBody>(), Pose{}); }, "null");
  expect_error([&] { scene.add(unit_cube(), nan_pose); }, "not finite");
  EXPECT_EQ(scene.body_count(), 0);
  const BodyId a = scene.add(unit_cube(), Pose{});
  const BodyId b = scene.add(unit_cube(), Pose::from_translation(Vec3(3, 0, 0)));
  expect_error([&] { scene.set_pose(b, nan_pose); }, "body " + std::to_string(b));
  Pose inf_rotation;
  inf_rotation.rotation(1, 2) = std::numeric_limits<double>::infinity();
  expect_error([&] { scene.set_pose(a, inf_rotation); }, "body " + std::to_string(a));
  expect_error([&] { scene.set_pose(7, Pose{}); }, "body 7");
  expect_error([&] { scene.set_pose(-1, Pose{}); }, "body -1");
  expect_error([&] { scene.remove(9); }, "body 9");
  expect_error([&] { (void)scene.pose(9); }, "body 9");
  scene.remove(a);
  expect_error([&] { scene.set_pose(a, Pose{}); }, "body " + std::to_string(a));
  expect_error([&] { scene.remove(a); }, "body " + std::to_string(a));
  EXPECT_FALSE(scene.contains(a));
  EXPECT_FALSE(scene.contains(-3));
  // Nothing was changed by the refused calls.
  EXPECT_EQ(scene.body_count(), 1);
  EXPECT_EQ(scene.pose(b).translation, Vec3(3, 0, 0));
  EXPECT_TRUE(scene.step().empty());
}

TEST(Scene, EmptyAndMovedScenes) {
  Scene empty;
  EXPECT_TRUE(empty.step().empty());
  EXPECT_EQ(empty.stats().bodies, 0);
  EXPECT_TRUE(empty.close_pairs_all_pairs().empty());
  // A scene moved into another variable keeps its bodies.
  Scene scene;
  scene.add(unit_cube(), Pose{});
  scene.add(unit_cube(), Pose::from_translation(Vec3(0.5, 0, 0)));
  Scene other = std::move(scene);
  EXPECT_EQ(other.body_count(), 2);
  ASSERT_EQ(other.step().size(), 1u);
  EXPECT_EQ(other.step()[0].result.status, Status::intersecting);
}

}  // namespace
}  // namespace proxima

namespace proxima {
namespace {

// Issue 11, pair filters: groups and masks (Box2D's category and mask bits)
// and excluded pairs are applied in the broad phase. step() must report
// exactly the unfiltered twin's close pairs that the filters let through,
// run no distance query on a dropped pair, and forget a removed body's
// exclusions (its id is reused by a new body).
TEST(SceneFilters, StepIsTheUnfilteredTwinMinusTheFilteredPairs) {
  Rng rng(4242);
  for (const BroadPhase bp : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
    SceneOptions o;
    o.margin = 0.3;
    o.broad_phase = bp;
    Scene filtered(o);
    Scene plain(o);
    std::vector<BodyId> ids;
    for (int i = 0; i < 50; ++i) {
      const auto body = random_convex(rng);
      const Pose p = random_pose(rng, 6.0, Vec3::Zero());
      ids.push_back(filtered.add(body, p));
      EXPECT_EQ(plain.add(body, p), ids.back());
    }
    // Three groups: robot links (bit 1) skip each other, the world (bit 2)
    // meets everything, and a ghost (bit 3) meets nothing.
    for (const BodyId id : ids) {
      const int kind = id % 5;
      if (kind < 2) filtered.set_filter(id, {0b010, 0b100});  // robot: meets the world only
      if (kind == 4) filtered.set_filter(id, {0b1000, 0});    // ghost
    }
    std::set<std::pair<BodyId, BodyId>> excluded;
    for (int k = 0; k < 40; ++k) {
      const BodyId a = ids[static_cast<std::size_t>(test::uniform_int(rng, 0, 49))];
      const BodyId b = ids[static_cast<std::size_t>(test::uniform_int(rng, 0, 49))];
      if (a == b) continue;
      filtered.exclude_pair(a, b);
      excluded.insert({std::min(a, b), std::max(a, b)});
    }
    int dropped_close = 0;
    for (int step = 0; step < 3; ++step) {
      const std::vector<ClosePair> out(filtered.step().begin(), filtered.step().end());
      const SceneStats stats = filtered.stats();
      const std::vector<ClosePair> all(plain.step().begin(), plain.step().end());
      std::vector<ClosePair> expected;
      for (const ClosePair& p : all) {
        const bool groups = (filtered.filter(p.a).group & filtered.filter(p.b).mask) != 0 &&
                            (filtered.filter(p.b).group & filtered.filter(p.a).mask) != 0;
        const bool kept = groups && excluded.count({p.a, p.b}) == 0;
        EXPECT_EQ(filtered.tests_pair(p.a, p.b), kept);
        if (kept) {
          expected.push_back(p);
        } else {
          ++dropped_close;
        }
      }
      ASSERT_EQ(out.size(), expected.size()) << to_string(bp) << " step " << step;
      for (std::size_t k = 0; k < out.size(); ++k) {
        EXPECT_EQ(out[k].a, expected[k].a);
        EXPECT_EQ(out[k].b, expected[k].b);
        EXPECT_TRUE(same_bits(out[k].result.distance, expected[k].result.distance));
      }
      // The twin of step() applies the same filters.
      const std::vector<ClosePair> twin = filtered.close_pairs_all_pairs();
      ASSERT_EQ(twin.size(), out.size());
      for (std::size_t k = 0; k < out.size(); ++k) {
        EXPECT_EQ(twin[k].a, out[k].a);
        EXPECT_EQ(twin[k].b, out[k].b);
      }
      // Dropped pairs never reached the narrow phase.
      EXPECT_GT(stats.filtered_pairs, 0);
      EXPECT_EQ(stats.candidate_pairs + stats.filtered_pairs, plain.stats().candidate_pairs);
      EXPECT_EQ(stats.convex_queries, stats.candidate_pairs);
      for (const BodyId id : ids) {
        const Pose next = moved(rng, filtered.pose(id));
        filtered.set_pose(id, next);
        plain.set_pose(id, next);
      }
    }
    EXPECT_GT(dropped_close, 10);  // premise: the filters dropped close pairs

    // A removed body's exclusions go with it: the new body on its id is
    // tested against everyone.
    const auto [a, b] = *excluded.begin();
    filtered.remove(b);
    const BodyId reused = filtered.add(random_convex(rng), filtered.pose(a));
    ASSERT_EQ(reused, b);
    EXPECT_FALSE(filtered.is_excluded(a, reused));
    filtered.include_pair(a, a == ids[0] ? ids[1] : ids[0]);  // not excluded: no effect
  }
}

TEST(SceneFilters, BadPairsAreRefusedByName) {
  Scene scene;
  const BodyId a = scene.add(unit_cube(), Pose{});
  EXPECT_THROW(scene.exclude_pair(a, a), InvalidInput);
  try {
    scene.exclude_pair(a, 7);
    ADD_FAILURE() << "no throw";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("Scene::exclude_pair: body 7 is not in the scene"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(scene.set_filter(3, {}), InvalidInput);
  EXPECT_EQ(scene.filter(a).group, 1u);
  EXPECT_EQ(scene.filter(a).mask, 0xffffffffu);
}

}  // namespace
}  // namespace proxima

namespace proxima {
namespace {

// The brute-force distance of bodies a and b of `scene` (cold, the query
// the scene's twin uses).
CompoundResult brute(const Scene& scene, BodyId a, BodyId b,
                     const std::vector<std::shared_ptr<const ConvexPolytope>>& convex) {
  CompoundResult r;
  static_cast<DistanceResult&>(r) = distance(*convex[static_cast<std::size_t>(a)], scene.pose(a),
                                             *convex[static_cast<std::size_t>(b)], scene.pose(b));
  return r;
}

// Issue 11, the queries a planner asks of a scene: the nearest pair however
// far apart, and one body's pairs within a margin, against brute force over
// every pair the filters let through, on sparse scenes (the nearest pair far
// beyond the margin) and dense ones, with tracking (the scene's caches) in
// between.
TEST(SceneQueries, NearestPairAndPairsWithinMatchBruteForce) {
  Rng rng(777);
  for (const double side : {4.0, 12.0, 60.0}) {
    SceneOptions o;
    o.margin = 0.05;
    Scene scene(o);
    std::vector<std::shared_ptr<const ConvexPolytope>> convex;
    for (int i = 0; i < 25; ++i) {
      convex.push_back(random_convex(rng));
      EXPECT_EQ(scene.add(convex.back(), random_pose(rng, side, Vec3::Zero())), i);
    }
    scene.exclude_pair(0, 1);
    scene.set_filter(2, {0b10, 0b10});  // meets only its own group: nobody else
    for (int step = 0; step < 3; ++step) {
      scene.step();
      double best = std::numeric_limits<double>::infinity();
      for (BodyId a = 0; a < 25; ++a) {
        for (BodyId b = a + 1; b < 25; ++b) {
          if (scene.tests_pair(a, b)) best = std::min(best, brute(scene, a, b, convex).distance);
        }
      }
      const std::optional<ClosePair> nearest = scene.nearest_pair();
      ASSERT_TRUE(nearest.has_value());
      EXPECT_TRUE(scene.tests_pair(nearest->a, nearest->b));
      const double r = 2 * side;
      EXPECT_NEAR(nearest->result.distance, best, 2 * (1e-12 * best + 64 * kUnitRoundoff * r))
          << "side " << side << " step " << step;

      const BodyId id = static_cast<BodyId>(step * 7 % 25);
      const double margin = side / 4;
      const std::vector<ClosePair> within = scene.pairs_within(id, margin);
      std::vector<BodyId> expected;
      for (BodyId other = 0; other < 25; ++other) {
        if (other == id || !scene.tests_pair(id, other)) continue;
        if (brute(scene, std::min(id, other), std::max(id, other), convex).distance <= margin)
          expected.push_back(other);
      }
      std::vector<BodyId> got;
      for (const ClosePair& p : within) got.push_back(p.a == id ? p.b : p.a);
      EXPECT_EQ(got, expected) << "side " << side << " body " << id;

      for (BodyId k = 0; k < 25; ++k) scene.set_pose(k, moved(rng, scene.pose(k)));
    }
  }
  Scene lonely;
  EXPECT_FALSE(lonely.nearest_pair().has_value());
  const BodyId a = lonely.add(unit_cube(), Pose{});
  const BodyId b = lonely.add(unit_cube(), Pose::from_translation(Vec3(5, 0, 0)));
  EXPECT_NEAR(lonely.nearest_pair()->result.distance, 4.0, 1e-14);
  lonely.exclude_pair(a, b);
  EXPECT_FALSE(lonely.nearest_pair().has_value());  // no tested pair
  EXPECT_THROW(lonely.pairs_within(a, -1.0), InvalidInput);
  EXPECT_THROW(lonely.pairs_within(9, 1.0), InvalidInput);
}

}  // namespace
}  // namespace proxima
