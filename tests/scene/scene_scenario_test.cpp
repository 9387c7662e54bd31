// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Tests of the scene benchmark's two building blocks (bench/paper and
// bench/peers, issue 6): the seeded scenario of moving bodies (deterministic,
// inside its cube, at the density asked for, at the speeds asked for) and
// FCL's broad-phase scene (its close pairs equal those of its own all-pairs
// twin and those of proxima's distance query run on every pair).
#include "paper/scene_scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "peers/fcl_scene.h"
#include "proxima/query/distance.h"

namespace {

using proxima::InvalidInput;
using proxima::Pose;
using proxima::Vec3;
using proxima::bench::FclClosePair;
using proxima::bench::FclScene;
using proxima::bench::kBodyRadius;
using proxima::bench::ReferencePair;
using proxima::bench::SceneScenario;
using proxima::bench::SceneScenarioOptions;

bool same_pose(const Pose& x, const Pose& y) {
  return x.rotation == y.rotation && x.translation == y.translation;
}

TEST(SceneScenario, SameSeedSamePosesOtherSeedOtherPoses) {
  SceneScenarioOptions o;
  o.bodies = 200;
  o.shape_pool = 10;
  o.seed = 11;
  const SceneScenario s1(o);
  const SceneScenario s2(o);
  o.seed = 12;
  const SceneScenario s3(o);
  for (const int k : {0, 17, 999}) {
    const auto p1 = s1.step(k);
    const auto p2 = s2.step(k);
    const auto p3 = s3.step(k);
    ASSERT_EQ(p1.size(), 200u);
    int differ = 0;
    for (std::size_t i = 0; i < p1.size(); ++i) {
      EXPECT_TRUE(same_pose(p1[i], p2[i])) << "body " << i << " step " << k;
      differ += same_pose(p1[i], p3[i]) ? 0 : 1;
      EXPECT_TRUE(same_pose(p1[i], s1.pose(static_cast<int>(i), k)));
    }
    EXPECT_EQ(differ, 200);
  }
  for (std::size_t k = 0; k < s1.shapes().size(); ++k) {
    EXPECT_EQ(s1.shapes()[k]->vertex_count(), s2.shapes()[k]->vertex_count());
  }
  EXPECT_EQ(std::vector<int>(s1.shape_of().begin(), s1.shape_of().end()),
            std::vector<int>(s2.shape_of().begin(), s2.shape_of().end()));
}

TEST(SceneScenario, ShapesAreSolidWithinTheBodyRadiusAndUseThePool) {
  SceneScenarioOptions o;
  o.bodies = 500;
  o.shape_pool = 30;
  o.min_points = 20;
  o.max_points = 200;
  const SceneScenario s(o);
  ASSERT_EQ(s.shapes().size(), 30u);
  int smallest = std::numeric_limits<int>::max();
  int largest = 0;
  for (const auto& shape : s.shapes()) {
    EXPECT_EQ(shape->dimension(), 3);
    EXPECT_LE(shape->vertex_count(), 200);
    smallest = std::min(smallest, shape->vertex_count());
    largest = std::max(largest, shape->vertex_count());
    for (const Vec3& v : shape->vertices()) EXPECT_LE(v.norm(), kBodyRadius * (1 + 1e-12));
  }
  // The pool really spans small and large hulls (round shapes keep all
  // their points, boxy ones far fewer).
  EXPECT_LT(smallest, 40);
  EXPECT_GT(largest, 120);
  std::vector<int> uses(30, 0);
  for (const int k : s.shape_of()) {
    ASSERT_GE(k, 0);
    ASSERT_LT(k, 30);
    ++uses[static_cast<std::size_t>(k)];
  }
  EXPECT_EQ(std::count(uses.begin(), uses.end(), 0), 0);
}

TEST(SceneScenario, BodiesStayInTheCubeAtTheirSpeeds) {
  SceneScenarioOptions o;
  o.bodies = 100;
  o.shape_pool = 5;
  o.neighbours = 20.0;  // a small cube, so that bodies hit the walls often
  o.max_speed = 0.05;
  o.max_angular_speed = 0.02;
  const SceneScenario s(o);
  const double size = s.cube_size();
  std::vector<Pose> previous = s.step(0);
  std::vector<Pose> current;
  double fastest = 0.0;
  for (int k = 1; k <= 300; ++k) {
    s.step(k, current);
    for (std::size_t i = 0; i < current.size(); ++i) {
      const Vec3& t = current[i].translation;
      ASSERT_GE(t.minCoeff(), 0.0) << "body " << i << " step " << k;
      ASSERT_LE(t.maxCoeff(), size) << "body " << i << " step " << k;
      // A bounce folds the path but does not lengthen it.
      const double moved = (t - previous[i].translation).norm();
      ASSERT_LE(moved, o.max_speed * (1 + 1e-9));
      fastest = std::max(fastest, moved);
      const double turned =
          Eigen::AngleAxisd(current[i].rotation * previous[i].rotation.transpose()).angle();
      ASSERT_LE(turned, o.max_angular_speed * (1 + 1e-6) + 1e-12);
      ASSERT_NEAR(
          (current[i].rotation.transpose() * current[i].rotation - proxima::Mat3::Identity())
              .norm(),
          0.0, 1e-12);
    }
    std::swap(previous, current);
  }
  EXPECT_GT(fastest, 0.5 * o.max_speed);
}

// The cube is sized so that each body has `neighbours` others with centres
// within 2 + margin on average; bodies near the walls have fewer, so the
// count is a little under it.
TEST(SceneScenario, DensityGivesTheNeighboursAskedFor) {
  SceneScenarioOptions o;
  o.bodies = 1500;
  o.shape_pool = 3;
  o.neighbours = 4.0;
  o.margin = 0.1;
  const SceneScenario s(o);
  const auto poses = s.step(0);
  const double reach = 2 * kBodyRadius + o.margin;
  long pairs = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      if ((poses[i].translation - poses[j].translation).norm() <= reach) ++pairs;
    }
  }
  const double per_body = 2.0 * static_cast<double>(pairs) / static_cast<double>(o.bodies);
  EXPECT_GT(per_body, 0.75 * o.neighbours);
  EXPECT_LT(per_body, 1.05 * o.neighbours);
}

TEST(SceneScenario, BadOptionsThrowNamingTheOption) {
  auto message = [](const SceneScenarioOptions& o) -> std::string {
    try {
      const SceneScenario s(o);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "";
  };
  SceneScenarioOptions o;
  o.bodies = 0;
  EXPECT_NE(message(o).find("bodies"), std::string::npos);
  o = {};
  o.shape_pool = 0;
  EXPECT_NE(message(o).find("shape_pool"), std::string::npos);
  o = {};
  o.min_points = 3;
  EXPECT_NE(message(o).find("min_points"), std::string::npos);
  o = {};
  o.min_points = 50;
  o.max_points = 40;
  EXPECT_NE(message(o).find("max_points"), std::string::npos);
  o = {};
  o.margin = -1;
  EXPECT_NE(message(o).find("margin"), std::string::npos);
  o = {};
  o.neighbours = 0;
  EXPECT_NE(message(o).find("neighbours"), std::string::npos);
  o = {};
  o.max_speed = std::numeric_limits<double>::infinity();
  EXPECT_NE(message(o).find("max_speed"), std::string::npos);
  o = {};
  o.bodies = 3;
  o.shape_pool = 1;
  const SceneScenario s(o);
  EXPECT_THROW(s.step(-1), InvalidInput);
}

// The reference: proxima's cold distance query on every pair of bodies.
std::vector<ReferencePair> proxima_all_pairs(const SceneScenario& s, const std::vector<Pose>& poses,
                                             double margin) {
  std::vector<ReferencePair> out;
  for (int i = 0; i < s.body_count(); ++i) {
    for (int j = i + 1; j < s.body_count(); ++j) {
      const auto r = proxima::distance(*s.body_shape(i), poses[static_cast<std::size_t>(i)],
                                       *s.body_shape(j), poses[static_cast<std::size_t>(j)]);
      if (r.distance <= margin) out.push_back({i, j, r.distance});
    }
  }
  return out;
}

// FCL's broad phase finds every pair within the margin (the callback's bound
// keeps its traversal from stopping at the nearest pair), and FCL's
// distances agree with proxima's. A dense scene, so that there are many
// close and many intersecting pairs.
TEST(FclScene, ClosePairsEqualAllPairsTwinAndProximaDistance) {
  SceneScenarioOptions o;
  o.bodies = 90;
  o.shape_pool = 12;
  o.neighbours = 6.0;
  o.margin = 0.1;
  o.max_speed = 0.05;
  o.max_angular_speed = 0.05;
  o.seed = 5;
  const SceneScenario s(o);
  std::vector<Pose> poses = s.step(0);
  FclScene fcl(s.shapes(), s.shape_of(), poses, o.margin);
  EXPECT_EQ(fcl.body_count(), o.bodies);
  int close_seen = 0;
  int intersecting_seen = 0;
  const std::vector<int> steps = {0, 1, 30, 200};
  for (const int k : steps) {
    s.step(k, poses);
    fcl.set_poses(poses);
    const auto found = fcl.step();
    std::vector<FclClosePair> pairs(found.begin(), found.end());
    proxima::bench::sort_by_bodies(pairs);
    const auto& stats = fcl.stats();
    EXPECT_EQ(stats.close_pairs, static_cast<int>(pairs.size()));
    EXPECT_GE(stats.candidate_pairs, stats.close_pairs);
    EXPECT_LT(stats.candidate_pairs, o.bodies * (o.bodies - 1) / 2);
    close_seen += stats.close_pairs;
    intersecting_seen += stats.intersecting_pairs;

    // Same pairs and distances as FCL on every pair. The traversal may hand
    // a pair over as (b, a), and FCL's GJK is not symmetric: the two answers
    // agree to FCL's tolerance (1e-6 absolute), not bit for bit.
    const auto twin = fcl.close_pairs_all_pairs();
    ASSERT_EQ(pairs.size(), twin.size()) << "step " << k;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      EXPECT_EQ(pairs[p].a, twin[p].a);
      EXPECT_EQ(pairs[p].b, twin[p].b);
      EXPECT_LT(pairs[p].a, pairs[p].b);
      EXPECT_NEAR(pairs[p].distance, twin[p].distance, 2e-6);
      if (pairs[p].distance > 0) {
        EXPECT_NEAR((pairs[p].point_a - pairs[p].point_b).norm(), pairs[p].distance, 1e-9);
      }
    }

    // Against proxima: FCL stops at its absolute distance_tolerance 1e-6.
    const auto reference = proxima_all_pairs(s, poses, o.margin);
    const auto diff = proxima::bench::compare_close_pairs(pairs, reference, o.margin, 1e-6, 1e-6);
    EXPECT_EQ(diff.mismatches(), 0) << "step " << k << ": only FCL " << diff.only_fcl
                                    << ", only proxima " << diff.only_reference << ", boundary "
                                    << diff.boundary << ", distances " << diff.distance_mismatches;
    EXPECT_GE(diff.common, static_cast<int>(reference.size()) - diff.boundary);
  }
  // The scene really has close and intersecting pairs to find.
  const int n_steps = static_cast<int>(steps.size());
  EXPECT_GT(close_seen, n_steps * 20);
  EXPECT_GT(intersecting_seen, n_steps * 5);
}

// Tight boxes (the transformed hull vertices) find the same pairs as FCL's
// own loose ones, from far fewer candidates.
TEST(FclScene, TightBoxesSamePairsFewerCandidates) {
  SceneScenarioOptions o;
  o.bodies = 150;
  o.shape_pool = 10;
  o.neighbours = 4.0;
  o.seed = 8;
  const SceneScenario s(o);
  std::vector<Pose> poses = s.step(0);
  FclScene loose(s.shapes(), s.shape_of(), poses, o.margin);
  FclScene tight(s.shapes(), s.shape_of(), poses, o.margin, proxima::bench::FclSolver::libccd,
                 proxima::bench::FclBoxes::tight);
  long loose_candidates = 0;
  long tight_candidates = 0;
  int close = 0;
  for (int k = 0; k < 40; k += 3) {
    s.step(k, poses);
    loose.set_poses(poses);
    tight.set_poses(poses);
    const auto a = loose.step();
    const auto b = tight.step();
    std::vector<FclClosePair> pa(a.begin(), a.end());
    std::vector<FclClosePair> pb(b.begin(), b.end());
    proxima::bench::sort_by_bodies(pa);
    proxima::bench::sort_by_bodies(pb);
    ASSERT_EQ(pa.size(), pb.size()) << "step " << k;
    for (std::size_t p = 0; p < pa.size(); ++p) {
      EXPECT_EQ(pa[p].a, pb[p].a);
      EXPECT_EQ(pa[p].b, pb[p].b);
    }
    loose_candidates += loose.stats().candidate_pairs;
    tight_candidates += tight.stats().candidate_pairs;
    close += static_cast<int>(pa.size());
  }
  EXPECT_GT(close, 0);
  EXPECT_LT(2 * tight_candidates, loose_candidates);
}

TEST(FclScene, BadInputThrows) {
  SceneScenarioOptions o;
  o.bodies = 4;
  o.shape_pool = 2;
  const SceneScenario s(o);
  const auto poses = s.step(0);
  EXPECT_THROW(FclScene(s.shapes(), s.shape_of(), poses, -0.1), InvalidInput);
  EXPECT_THROW(FclScene(s.shapes(), s.shape_of(), std::span(poses).first(3), 0.1), InvalidInput);
  const std::vector<int> bad_shape = {0, 1, 2, 0};
  EXPECT_THROW(FclScene(s.shapes(), bad_shape, poses, 0.1), InvalidInput);
  FclScene fcl(s.shapes(), s.shape_of(), poses, 0.1);
  EXPECT_THROW(fcl.set_poses(std::span(poses).first(2)), InvalidInput);
  auto nan_poses = poses;
  nan_poses[2].translation.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(fcl.set_poses(nan_poses), InvalidInput);
}

}  // namespace
