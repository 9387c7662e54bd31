// Tests of a scene's collision checks (issue 26): Scene::step_within (every
// pair within the margin, by the margin query) and Scene::first_within
// (stop at the first such pair).
//   1. Random moving scenes of every kind (convex, rounded, padded,
//      compound, mesh): step_within against the slow twin, the cold full
//      distance query on every pair (close_pairs_all_pairs): the same pairs
//      except within the contact band of the margin, each witness no closer
//      than the exact distance and no farther apart than the margin; 1 and
//      2 threads and both broad phases bit-identical; first_within finds a
//      pair exactly when the twin has one; step() on the caches that
//      step_within left is still the twin's.
//   2. first_within by hand: it stops at the first pair, asks the last
//      call's pair first, and proves "no pair" on a scene apart.
//   3. Touching and margin pairs by hand, step_within against step().
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/scene/scene.h"
#include "proxima/shape/primitives.h"
#include "support/generators.h"
#include "support/same_bits.h"
#include "support/scene_bodies.h"

namespace proxima {
namespace {

using test::Rng;
using test::same_bits;
using Entry = test::SceneEntry;
using test::box_mesh;
using test::lockstep_scenes;

// Verdicts of pairs closer to the margin than this may differ between the
// margin query and the twin: the contact band 64 u R of the accuracy
// standard is about 1.4e-13 for these scenes (R about 10); the test allows
// a thousand times that, far below any other distance in the scenes.
constexpr double kBandSlack = 1e-10;

std::shared_ptr<const ConvexPolytope> random_convex(Rng& rng) {
  return std::make_shared<const ConvexPolytope>(test::scaled(
      test::points_in_cube(rng, test::uniform_int(rng, 12, 40), 0.6), test::uniform(rng, 0.5, 1)));
}

std::shared_ptr<const CompoundBody> random_compound(Rng& rng) {
  std::vector<std::vector<Vec3>> sets;
  for (int i = 0; i < 2; ++i) {
    const Vec3 offset = test::uniform(rng, 0.2, 0.6) * test::random_unit_vector(rng);
    sets.push_back(test::translated(
        test::scaled(test::points_on_sphere(rng, test::uniform_int(rng, 12, 24)), 0.4), offset));
  }
  return std::make_shared<const CompoundBody>(CompoundBody::from_point_sets(sets));
}


// Every kind in a cube of side `side`; `plain_only` keeps to plain convex
// and compound bodies (the scene's fast paths).
std::vector<Entry> random_entries(Rng& rng, int n, double side, bool plain_only) {
  std::vector<Entry> out;
  for (int i = 0; i < n; ++i) {
    const Pose pose{test::random_quaternion(rng),
                    test::drawn([&] { return test::uniform(rng, 0, side); })};
    const int kind = plain_only ? i % 3 : i % 7;
    switch (kind) {
      case 0:
      case 1:
        out.push_back({Body(random_convex(rng)), 0.0, pose});
        break;
      case 2:
        out.push_back({Body(random_compound(rng)), 0.0, pose});
        break;
      case 3:
        out.push_back({Body(random_convex(rng), test::uniform(rng, 0.05, 0.3)), 0.0, pose});
        break;
      case 4:
        out.push_back({make_capsule(test::uniform(rng, 0.2, 0.6), 0.2),
                       test::uniform(rng, 0.0, 0.2), pose});
        break;
      case 5:
        out.push_back({Body(random_compound(rng)), test::uniform(rng, 0.0, 0.2), pose});
        break;
      default:
        out.push_back({Body(box_mesh(Vec3(-0.5, -0.3, -0.4), Vec3(0.5, 0.3, 0.4))), 0.0, pose});
        break;
    }
  }
  return out;
}

bool same_margin_answer(const MarginPair& x, const MarginPair& y) {
  return x.a == y.a && x.b == y.b && x.result.status == y.result.status &&
         same_bits(x.result.lower_bound, y.result.lower_bound) &&
         same_bits(x.result.upper_bound, y.result.upper_bound) &&
         same_bits(x.result.point_a, y.result.point_a) &&
         same_bits(x.result.point_b, y.result.point_b) && x.result.piece_a == y.result.piece_a &&
         x.result.piece_b == y.result.piece_b && x.result.triangle_a == y.result.triangle_a &&
         x.result.triangle_b == y.result.triangle_b &&
         x.result.pairs_tested == y.result.pairs_tested;
}

std::uint64_t key(BodyId a, BodyId b) {
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

bool in_contact(const ClosePair& p) {
  return p.result.status == Status::touching || p.result.status == Status::intersecting;
}

// step_within's pairs against the twin's full answers: every twin pair
// clearly within the margin is reported, every reported pair is within
// the margin up to the band, and its witness is an honest pair of points
// (no closer than the distance, no farther apart than the margin).
// Returns the number of reported pairs.
int expect_twin_pairs(std::span<const MarginPair> within, const std::vector<ClosePair>& twin,
                      double margin, const std::string& where) {
  std::set<std::uint64_t> reported;
  for (const MarginPair& p : within) {
    EXPECT_LT(p.a, p.b) << where;
    EXPECT_EQ(p.result.status, MarginStatus::within) << where;
    EXPECT_LE(p.result.upper_bound, margin + kBandSlack) << where;
    EXPECT_NEAR((p.result.point_b - p.result.point_a).norm(), p.result.upper_bound, kBandSlack)
        << where;
    reported.insert(key(p.a, p.b));
  }
  std::set<std::uint64_t> twin_keys;
  for (const ClosePair& t : twin) {
    twin_keys.insert(key(t.a, t.b));
    const bool clearly = in_contact(t) || t.result.distance < margin - kBandSlack;
    if (clearly) {
      EXPECT_TRUE(reported.contains(key(t.a, t.b)))
          << where << ": pair (" << t.a << ", " << t.b << ") at " << t.result.distance
          << " not reported";
    }
  }
  for (const MarginPair& p : within) {
    const auto at = std::find_if(twin.begin(), twin.end(),
                                 [&](const ClosePair& t) { return t.a == p.a && t.b == p.b; });
    if (at == twin.end()) {
      ADD_FAILURE() << where << ": pair (" << p.a << ", " << p.b
                    << ") reported within but the twin has it beyond the margin";
      continue;
    }
    // A witness pair is never closer than the bodies' distance.
    if (!in_contact(*at)) {
      EXPECT_GE(p.result.upper_bound, at->result.distance - kBandSlack) << where;
    }
  }
  return static_cast<int>(within.size());
}

void move(Rng& rng, std::vector<Entry>& entries, std::vector<Scene>& scenes) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    entries[i].pose = {Mat3(test::random_small_rotation(rng, 0.05) * entries[i].pose.rotation),
                       Vec3(entries[i].pose.translation +
                            test::uniform(rng, 0, 0.08) * test::random_unit_vector(rng))};
    for (Scene& s : scenes) s.set_pose(static_cast<BodyId>(i), entries[i].pose);
  }
}

void run_random_scene(std::uint64_t seed, bool plain_only, int* reported_total,
                      int* mesh_pairs_total) {
  Rng rng(seed);
  constexpr int kBodies = 70;
  constexpr double kMargin = 0.1;
  std::vector<Entry> entries = random_entries(rng, kBodies, 6.0, plain_only);
  std::vector<Scene> scenes = lockstep_scenes(kMargin);
  Scene checker(scenes[0].options());  // first_within and step() on shared caches
  for (Scene* s : {&scenes[0], &scenes[1], &scenes[2], &scenes[3], &checker}) {
    for (const Entry& e : entries) s->add(e.body, e.pose, e.padding);
  }
  for (int step = 0; step < 5; ++step) {
    const std::string where =
        "seed " + std::to_string(seed) + ", step " + std::to_string(step);
    const std::span<const MarginPair> first = scenes[0].step_within();
    const std::vector<MarginPair> out(first.begin(), first.end());
    const SceneStats stats = scenes[0].stats();
    EXPECT_EQ(stats.close_pairs, static_cast<int>(out.size())) << where;
    if (step == 0) {
      EXPECT_GE(stats.candidate_pairs, 64) << "too few pairs for two threads";
    }
    for (std::size_t k = 1; k < scenes.size(); ++k) {
      const std::span<const MarginPair> other = scenes[k].step_within();
      EXPECT_EQ(scenes[k].stats().convex_queries, stats.convex_queries) << where << " " << k;
      ASSERT_EQ(other.size(), out.size()) << where << ", scene " << k;
      for (std::size_t i = 0; i < out.size(); ++i) {
        EXPECT_TRUE(same_margin_answer(out[i], other[i]))
            << where << ", scene " << k << ": pair (" << out[i].a << ", " << out[i].b << ")";
      }
    }
    const std::vector<ClosePair> twin = scenes[0].close_pairs_all_pairs();
    *reported_total += expect_twin_pairs(out, twin, kMargin, where);
    for (const MarginPair& p : out) {
      const Body::Kind ka = entries[static_cast<std::size_t>(p.a)].body.kind();
      const Body::Kind kb = entries[static_cast<std::size_t>(p.b)].body.kind();
      if (ka == Body::Kind::mesh || kb == Body::Kind::mesh) {
        ++*mesh_pairs_total;
        EXPECT_TRUE(p.result.triangle_a >= 0 || p.result.triangle_b >= 0) << where;
      }
      if (ka != Body::Kind::compound) {
        EXPECT_EQ(p.result.piece_a, -1) << where;
      }
      if (kb != Body::Kind::compound) {
        EXPECT_EQ(p.result.piece_b, -1) << where;
      }
    }

    // first_within and step() alternate on one scene, sharing its caches.
    const std::optional<MarginPair> hit = checker.first_within();
    EXPECT_EQ(hit.has_value(), !twin.empty()) << where;
    if (hit) {
      EXPECT_TRUE(std::any_of(twin.begin(), twin.end(), [&](const ClosePair& t) {
        return t.a == hit->a && t.b == hit->b;
      })) << where;
      EXPECT_EQ(checker.stats().close_pairs, 1) << where;
    }
    const std::span<const ClosePair> full = checker.step();
    ASSERT_EQ(full.size(), twin.size()) << where;
    for (std::size_t i = 0; i < twin.size(); ++i) {
      EXPECT_TRUE(full[i].a == twin[i].a && full[i].b == twin[i].b) << where;
      EXPECT_NEAR(full[i].result.distance, twin[i].result.distance,
                  1e-12 * twin[i].result.distance + 1e-12)
          << where;
    }
    move(rng, entries, scenes);
    for (std::size_t i = 0; i < entries.size(); ++i)
      checker.set_pose(static_cast<BodyId>(i), entries[i].pose);
  }
}

TEST(SceneMargin, StepWithinIsTheTwinsPairsOnEveryKindAnyThreadsAndBroadPhase) {
  int reported = 0;
  int mesh_pairs = 0;
  run_random_scene(2601, false, &reported, &mesh_pairs);
  // The random set really holds what the test is about.
  EXPECT_GE(reported, 40);
  EXPECT_GE(mesh_pairs, 8);
}

TEST(SceneMargin, StepWithinIsTheTwinsPairsOnPlainConvexAndCompoundBodies) {
  int reported = 0;
  int mesh_pairs = 0;
  run_random_scene(2602, true, &reported, &mesh_pairs);
  EXPECT_GE(reported, 40);
  EXPECT_EQ(mesh_pairs, 0);
}

std::shared_ptr<const ConvexPolytope> unit_cube() {
  return std::make_shared<const ConvexPolytope>(test::cube(1.0));
}

Pose at(double x, double y = 0.0) { return Pose{Quat::Identity(), Vec3(x, y, 0.0)}; }

// A unit cube beside one at (0, y, 0), off by 0.008 along each axis: their
// boxes grown by half the margin 0.01 overlap (a candidate pair), their
// distance 0.008 sqrt 3 is beyond the margin.
Pose diagonally_apart(double y) { return Pose{Quat::Identity(), Vec3(1.008, y + 1.008, 1.008)}; }

TEST(SceneMargin, FirstWithinStopsAtTheFirstPairAndAsksTheLastOneFirst) {
  SceneOptions o;
  o.margin = 0.01;
  Scene scene(o);
  const auto cube = unit_cube();
  // Three pairs along y, 10 apart: (0, 1) beyond the margin, (2, 3) and
  // (4, 5) overlapping.
  scene.add(cube, at(0.0, 0.0));
  scene.add(cube, diagonally_apart(0.0));
  scene.add(cube, at(0.0, 10.0));
  scene.add(cube, at(0.5, 10.0));
  scene.add(cube, at(0.0, 20.0));
  scene.add(cube, at(0.5, 20.0));
  std::optional<MarginPair> hit = scene.first_within();
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->a, 2);
  EXPECT_EQ(hit->b, 3);
  EXPECT_EQ(hit->result.status, MarginStatus::within);
  EXPECT_EQ(scene.stats().candidate_pairs, 3);
  EXPECT_EQ(scene.stats().close_pairs, 1);
  // It stopped there: (4, 5) was not asked (its query would count one).
  EXPECT_LE(scene.stats().convex_queries, 2);

  // (0, 1) now overlaps too; the last call's pair (2, 3) is asked first
  // and ends the search in one query.
  scene.set_pose(1, at(0.5, 0.0));
  hit = scene.first_within();
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->a, 2);
  EXPECT_EQ(scene.stats().convex_queries, 1);

  // (2, 3) apart: the ordered pass finds (0, 1).
  scene.set_pose(3, diagonally_apart(10.0));
  hit = scene.first_within();
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->a, 0);
  EXPECT_EQ(hit->b, 1);

  // Everything apart: no pair, every candidate proved beyond.
  scene.set_pose(1, diagonally_apart(0.0));
  scene.set_pose(5, diagonally_apart(20.0));
  EXPECT_FALSE(scene.first_within().has_value());
  EXPECT_EQ(scene.stats().candidate_pairs, 3);
  EXPECT_EQ(scene.stats().close_pairs, 0);
  EXPECT_TRUE(scene.step_within().empty());
  EXPECT_TRUE(scene.step().empty());
}

TEST(SceneMargin, TouchingAndMarginPairsByHand) {
  SceneOptions o;
  o.margin = 0.25;
  Scene scene(o);
  const auto cube = unit_cube();
  scene.add(cube, at(0.0));        // 0
  scene.add(cube, at(1.0));        // 1: touches 0 face to face
  scene.add(cube, at(2.2));        // 2: 0.2 from 1, within the margin
  scene.add(cube, at(3.5));        // 3: 0.3 from 2, beyond it
  scene.add(Body(cube, 0.05), at(4.75), 0.0);  // 4: rounded, 0.2 from 3 (0.25 - radius)
  const std::span<const MarginPair> within = scene.step_within();
  std::vector<std::pair<BodyId, BodyId>> got;
  for (const MarginPair& p : within) got.emplace_back(p.a, p.b);
  const std::vector<std::pair<BodyId, BodyId>> expected = {{0, 1}, {1, 2}, {3, 4}};
  EXPECT_EQ(got, expected);
  for (const MarginPair& p : within) {
    EXPECT_LE((p.result.point_b - p.result.point_a).norm(), 0.25 + kBandSlack);
  }
  // The rounded pair's witness lies on the rounded surface: 0.2 apart.
  EXPECT_NEAR(within[2].result.upper_bound, 0.2, 1e-12);
  std::vector<std::pair<BodyId, BodyId>> full;
  for (const ClosePair& p : scene.step()) full.emplace_back(p.a, p.b);
  EXPECT_EQ(full, expected);
}

}  // namespace
}  // namespace proxima
