// Tests of Scene with any Body (issues 11 and 12): rounded and padded
// convex and compound bodies and triangle meshes, added by
// Scene::add(Body, pose, padding).
//   1. A random scene of every kind, moving: step() against the all-pairs
//      twin (the same pairs; bit for bit on the first, cold step, where the
//      same calls are made), every general pair bit for bit against the
//      direct distance(Body, Body) of the padded bodies, and 1 and 2
//      threads, both broad phases, bit-identical.
//   2. A padding changes which pairs are reported exactly as the radius
//      would (the same bits as the bodies with the radius), set_padding too.
//   3. A closed room mesh with bodies inside: every (room, body) pair is
//      intersecting; a body outside far from it is not reported; sweep()
//      refuses a scene with a mesh, naming it.
//   4. The filters drop pairs before the narrow phase, general pairs too.
//   5. sweep() on padded bodies: the padding acts as a radius in the time of
//      impact and in the swept boxes.
//   6. nearest_pair and pairs_within on general bodies, bad padding refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/primitives.h"
#include "proxima/scene/scene.h"
#include "proxima/motion/time_of_impact.h"
#include "support/generators.h"
#include "support/same_bits.h"
#include "support/scene_bodies.h"

namespace proxima {
namespace {

using test::Rng;
using test::same_bits;
using test::same_feature;
using Tri = TriangleMesh::Triangle;
using Entry = test::SceneEntry;
using test::box_mesh;
using test::lockstep_scenes;

// An open soup of n triangles within `extent` of the origin.
TriangleMesh random_soup(Rng& rng, int n, double extent, double size) {
  std::vector<Vec3> v;
  std::vector<Tri> t;
  for (int i = 0; i < n; ++i) {
    const Vec3 c = test::uniform(rng, 0, extent) * test::random_unit_vector(rng);
    for (int k = 0; k < 3; ++k) v.push_back(c + size * test::random_unit_vector(rng));
    const auto b = static_cast<std::uint32_t>(3 * i);
    t.push_back({b, b + 1, b + 2});
  }
  return TriangleMesh(v, t);
}

std::shared_ptr<const ConvexPolytope> random_convex(Rng& rng) {
  return std::make_shared<const ConvexPolytope>(test::scaled(
      test::points_in_cube(rng, test::uniform_int(rng, 12, 60), 0.6), test::uniform(rng, 0.5, 1)));
}

std::shared_ptr<const CompoundBody> random_compound(Rng& rng) {
  std::vector<std::vector<Vec3>> sets;
  const int pieces = test::uniform_int(rng, 2, 3);
  for (int i = 0; i < pieces; ++i) {
    const Vec3 offset = test::uniform(rng, 0.2, 0.6) * test::random_unit_vector(rng);
    sets.push_back(test::translated(
        test::scaled(test::points_on_sphere(rng, test::uniform_int(rng, 12, 30)), 0.4), offset));
  }
  return std::make_shared<const CompoundBody>(CompoundBody::from_point_sets(sets));
}


// Every kind, rounded or not, padded or not, in a cube of side `side`.
std::vector<Entry> random_entries(Rng& rng, int n, double side) {
  std::vector<Entry> out;
  for (int i = 0; i < n; ++i) {
    const Pose pose{test::random_quaternion(rng),
                    test::drawn([&] { return test::uniform(rng, 0, side); })};
    const double pad = test::uniform(rng, 0.0, 0.25);
    switch (i % 9) {
      case 0:
      case 1:
        out.push_back({Body(random_convex(rng)), 0.0, pose});  // plain: the fast path
        break;
      case 2:
        out.push_back({Body(random_convex(rng), test::uniform(rng, 0.05, 0.3)), 0.0, pose});
        break;
      case 3:
        out.push_back({Body(random_convex(rng)), pad, pose});
        break;
      case 4:
        out.push_back({Body(random_compound(rng)), i % 2 == 0 ? pad : 0.0, pose});
        break;
      case 5:
        out.push_back({make_sphere(test::uniform(rng, 0.2, 0.6)), pad, pose});
        break;
      case 6:
        out.push_back({make_capsule(test::uniform(rng, 0.2, 0.6), 0.2), 0.0, pose});
        break;
      case 7:
        out.push_back({Body(box_mesh(Vec3(-0.5, -0.3, -0.4), Vec3(0.5, 0.3, 0.4))), pad, pose});
        break;
      default:
        out.push_back({Body(random_soup(rng, 10, 0.5, 0.3)), 0.0, pose});
        break;
    }
  }
  return out;
}

bool same_answer(const ClosePair& x, const ClosePair& y) {
  return x.a == y.a && x.b == y.b && x.result.status == y.result.status &&
         same_bits(x.result.distance, y.result.distance) &&
         same_bits(x.result.lower_bound, y.result.lower_bound) &&
         same_bits(x.result.signed_distance(), y.result.signed_distance()) &&
         same_bits(x.result.signed_lower_bound(), y.result.signed_lower_bound()) &&
         same_bits(x.result.point_a, y.result.point_a) &&
         same_bits(x.result.point_b, y.result.point_b) &&
         same_bits(x.result.normal, y.result.normal) &&
         same_feature(x.result.feature_a, y.result.feature_a) &&
         same_feature(x.result.feature_b, y.result.feature_b) &&
         x.result.iterations == y.result.iterations && x.result.piece_a == y.result.piece_a &&
         x.result.piece_b == y.result.piece_b && x.result.pairs_tested == y.result.pairs_tested &&
         x.triangle_a == y.triangle_a && x.triangle_b == y.triangle_b;
}

// Pair (a, b) as the scene should answer it from distance(Body, Body) of
// the padded bodies, cold.
ClosePair direct(const std::vector<Entry>& e, BodyId a, BodyId b, const DistanceOptions& options) {
  const Entry& ea = e[static_cast<std::size_t>(a)];
  const Entry& eb = e[static_cast<std::size_t>(b)];
  const BodyResult d = distance(ea.padded(), ea.pose, eb.padded(), eb.pose, options);
  ClosePair p{a, b, {}, d.triangle_a, d.triangle_b};
  static_cast<DistanceResult&>(p.result) = d;
  p.result.piece_a = ea.body.kind() == Body::Kind::convex ? 0 : d.piece_a;
  p.result.piece_b = eb.body.kind() == Body::Kind::convex ? 0 : d.piece_b;
  p.result.pairs_tested = 1;
  return p;
}

std::vector<ClosePair> steps(Scene& scene) {
  const std::span<const ClosePair> pairs = scene.step();
  return {pairs.begin(), pairs.end()};
}

bool general(const Entry& e) {
  return e.body.kind() == Body::Kind::mesh || e.body.radius() + e.padding > 0.0;
}

TEST(SceneBodies, EveryKindMatchesTheTwinAndDistanceOfBodiesOnAnyThreadsAndBroadPhase) {
  Rng rng(4242);
  constexpr int kBodies = 72;
  // A cube of side 6 for 72 bodies of size ~1: well over 64 candidate
  // pairs, so that 2 threads really split the narrow phase.
  std::vector<Entry> entries = random_entries(rng, kBodies, 6.0);
  std::vector<Scene> scenes = lockstep_scenes(0.1);
  for (Scene& s : scenes) {
    for (std::size_t i = 0; i < entries.size(); ++i) {
      ASSERT_EQ(s.add(entries[i].body, entries[i].pose, entries[i].padding),
                static_cast<BodyId>(i));
    }
  }
  const DistanceOptions options = scenes[0].options().distance;
  int general_pairs = 0;
  int mesh_pairs = 0;
  int plain_pairs = 0;
  int intersecting = 0;
  int separated = 0;
  for (int step = 0; step < 4; ++step) {
    const std::string where = "step " + std::to_string(step);
    const std::span<const ClosePair> first = scenes[0].step();
    const std::vector<ClosePair> out(first.begin(), first.end());
    const SceneStats stats = scenes[0].stats();
    if (step == 0) {
      EXPECT_GE(stats.candidate_pairs, 64) << "too few pairs to split between threads";
    }
    EXPECT_EQ(stats.warm_pairs > 0, step > 0) << where;
    for (std::size_t k = 1; k < scenes.size(); ++k) {
      const std::span<const ClosePair> other = scenes[k].step();
      EXPECT_EQ(scenes[k].stats().candidate_pairs, stats.candidate_pairs) << where << " " << k;
      EXPECT_EQ(scenes[k].stats().convex_queries, stats.convex_queries) << where << " " << k;
      ASSERT_EQ(other.size(), out.size()) << where << ", scene " << k;
      for (std::size_t i = 0; i < out.size(); ++i) {
        EXPECT_TRUE(same_answer(out[i], other[i]))
            << where << ", scene " << k << ": pair (" << out[i].a << ", " << out[i].b << ")";
      }
    }

    // The twin: the same pairs; on the first step (cold caches: the same
    // calls) the same bits, later within the accuracy standard.
    const std::vector<ClosePair> twin = scenes[0].close_pairs_all_pairs();
    ASSERT_EQ(twin.size(), out.size()) << where;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const ClosePair& x = out[i];
      const ClosePair& y = twin[i];
      ASSERT_TRUE(x.a == y.a && x.b == y.b) << where << ": pair " << i;
      if (step == 0) {
        EXPECT_TRUE(same_answer(x, y)) << where << ": pair (" << x.a << ", " << x.b << ")";
      } else {
        const double tol = 1e-12 * y.result.distance + 1e-12;  // R is about 10 here
        EXPECT_NEAR(x.result.distance, y.result.distance, tol)
            << where << ": pair (" << x.a << ", " << x.b << ")";
        EXPECT_EQ(x.result.status, y.result.status)
            << where << ": pair (" << x.a << ", " << x.b << ")";
      }
      const Entry& ea = entries[static_cast<std::size_t>(x.a)];
      const Entry& eb = entries[static_cast<std::size_t>(x.b)];
      if (general(ea) || general(eb)) {
        ++general_pairs;
        if (ea.body.kind() == Body::Kind::mesh || eb.body.kind() == Body::Kind::mesh) {
          ++mesh_pairs;
          EXPECT_TRUE(x.triangle_a >= 0 || x.triangle_b >= 0) << where;
        }
        if (step == 0) {
          EXPECT_TRUE(same_answer(x, direct(entries, x.a, x.b, options)))
              << where << ": pair (" << x.a << ", " << x.b << ") against distance(Body, Body)";
        }
      } else {
        ++plain_pairs;
        EXPECT_EQ(x.triangle_a, -1);
        EXPECT_EQ(x.triangle_b, -1);
      }
      intersecting += x.result.status == Status::intersecting ? 1 : 0;
      separated += x.result.status == Status::separated ? 1 : 0;
    }
    // No pair within the margin is missed by the broad phase: every pair
    // of the twin is a candidate, so the two lists above are equal.
    for (std::size_t i = 0; i < entries.size(); ++i) {
      entries[i].pose = {Mat3(test::random_small_rotation(rng, 0.05) * entries[i].pose.rotation),
                         Vec3(entries[i].pose.translation +
                              test::uniform(rng, 0, 0.08) * test::random_unit_vector(rng))};
      for (Scene& s : scenes) s.set_pose(static_cast<BodyId>(i), entries[i].pose);
    }
  }
  // The random set really holds each case.
  EXPECT_GE(general_pairs, 40);
  EXPECT_GE(mesh_pairs, 8);
  EXPECT_GE(plain_pairs, 4);
  EXPECT_GE(intersecting, 20);
  EXPECT_GE(separated, 4);
}

TEST(SceneBodies, PaddingChangesThePairsExactlyAsTheRadiusWould) {
  Rng rng(77);
  std::vector<Entry> entries = random_entries(rng, 45, 6.0);
  for (Entry& e : entries) e.padding = test::uniform(rng, 0.05, 0.3);
  SceneOptions o;
  o.margin = 0.05;
  Scene padded(o);        // bodies with their padding
  Scene rounded(o);       // the same bodies with radius + padding, no padding
  Scene bare(o);          // no padding: fewer pairs
  Scene padded_later(o);  // no padding until set_padding
  for (const Entry& e : entries) {
    const BodyId id = padded.add(e.body, e.pose, e.padding);
    EXPECT_EQ(rounded.add(e.padded(), e.pose), id);
    EXPECT_EQ(bare.add(e.body, e.pose), id);
    EXPECT_EQ(padded_later.add(e.body, e.pose), id);
    EXPECT_EQ(padded.padding(id), e.padding);
    EXPECT_EQ(padded.body(id).radius(), e.body.radius());
  }
  const std::vector<ClosePair> p(steps(padded));
  const std::vector<ClosePair> r(steps(rounded));
  const std::vector<ClosePair> b(steps(bare));
  ASSERT_EQ(p.size(), r.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_TRUE(same_answer(p[i], r[i])) << "pair (" << p[i].a << ", " << p[i].b << ")";
  }
  EXPECT_GT(p.size(), b.size() + 5) << "the padding must bring pairs in";

  // A step without padding made caches; set_padding on every body makes
  // every pair a Body pair. A pair of two bodies that were plain has a cold
  // Body cache: the padded scene's first step, bit for bit. The others
  // start from their Body cache of the smaller radii (tracking: the same
  // answer within the accuracy standard).
  padded_later.step();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    padded_later.set_padding(static_cast<BodyId>(i), entries[i].padding);
  }
  const std::span<const ClosePair> later = padded_later.step();
  ASSERT_EQ(later.size(), p.size());
  const auto was_plain = [&](BodyId id) {
    const Body& body = entries[static_cast<std::size_t>(id)].body;
    return body.kind() != Body::Kind::mesh && body.radius() == 0.0;
  };
  int bit_for_bit = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (was_plain(p[i].a) && was_plain(p[i].b)) {
      EXPECT_TRUE(same_answer(later[i], p[i])) << "pair (" << p[i].a << ", " << p[i].b << ")";
      ++bit_for_bit;
    } else {
      EXPECT_EQ(later[i].a, p[i].a);
      EXPECT_EQ(later[i].b, p[i].b);
      EXPECT_NEAR(later[i].result.distance, p[i].result.distance, 1e-12);
      EXPECT_EQ(later[i].result.status, p[i].result.status);
    }
  }
  EXPECT_GE(bit_for_bit, 5);
  // And back: padding 0 makes the plain bodies plain again (the bare twin).
  for (std::size_t i = 0; i < entries.size(); ++i) {
    padded_later.set_padding(static_cast<BodyId>(i), 0.0);
  }
  const std::vector<ClosePair> back(steps(padded_later));
  const std::vector<ClosePair> bare_twin = bare.close_pairs_all_pairs();
  ASSERT_EQ(back.size(), bare_twin.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].a, bare_twin[i].a);
    EXPECT_EQ(back[i].b, bare_twin[i].b);
  }
}

TEST(SceneBodies, BodiesInsideAClosedRoomMeshIntersectIt) {
  SceneOptions o;
  o.margin = 0.0;
  Scene scene(o);
  // A room 20 x 20 x 10 (a closed, outward-oriented box surface), three
  // bodies inside, far from the walls and from each other, one outside.
  const BodyId room =
      scene.add(Body(box_mesh(Vec3(-10, -10, 0), Vec3(10, 10, 10))), Pose::identity());
  const BodyId ball = scene.add(make_sphere(0.5), Pose{Mat3::Identity(), Vec3(0, 0, 5)});
  const BodyId box =
      scene.add(make_box(Vec3(0.5, 0.5, 0.5)), Pose{Mat3::Identity(), Vec3(5, 5, 5)}, 0.1);
  const BodyId crate = scene.add(Body(box_mesh(Vec3(-1, -1, -1), Vec3(1, 1, 1))),
                                 Pose{Mat3::Identity(), Vec3(-5, 4, 3)});
  const BodyId outside = scene.add(make_sphere(0.5), Pose{Mat3::Identity(), Vec3(30, 0, 5)});
  const std::span<const ClosePair> pairs = scene.step();
  ASSERT_EQ(pairs.size(), 3u);
  for (const ClosePair& p : pairs) {
    EXPECT_EQ(p.a, room);
    EXPECT_EQ(p.result.status, Status::intersecting) << "body " << p.b << " inside the room";
    EXPECT_NE(p.b, outside);
  }
  EXPECT_EQ(pairs[0].b, ball);
  EXPECT_EQ(pairs[1].b, box);
  EXPECT_EQ(pairs[2].b, crate);
  // The all-pairs twin agrees, and nearest_pair puts an intersecting pair
  // first.
  EXPECT_EQ(scene.close_pairs_all_pairs().size(), 3u);
  const std::optional<ClosePair> nearest = scene.nearest_pair();
  ASSERT_TRUE(nearest.has_value());
  EXPECT_EQ(nearest->result.status, Status::intersecting);
  EXPECT_EQ(nearest->a, room);
  // Outside, 19.5 from the wall x = 10 and 0.5 of radius: within 20 only.
  EXPECT_TRUE(scene.pairs_within(outside, 19.4).empty());
  const std::vector<ClosePair> near_outside = scene.pairs_within(outside, 19.6);
  ASSERT_EQ(near_outside.size(), 1u);
  EXPECT_EQ(near_outside[0].a, room);
  EXPECT_NEAR(near_outside[0].result.distance, 19.5, 1e-12);
  EXPECT_GE(near_outside[0].triangle_a, 0);

  // Meshes sweep too (time_of_impact takes them): the bodies inside the
  // closed room overlap it at t = 0; the outside ball flying to x = 8 turns
  // while it goes, crosses the wall at x = 10 and meets the crate mesh
  // nowhere. The sweep equals its all-pairs twin.
  scene.set_end_pose(outside, Pose{Mat3(Eigen::AngleAxisd(2.0, Vec3(0, 0, 1))), Vec3(8, 0, 5)});
  scene.set_end_pose(crate, Pose{Mat3(Eigen::AngleAxisd(1.0, Vec3(1, 0, 0))), Vec3(-5, 4, 3.5)});
  const std::span<const ImpactPair> hits = scene.sweep();
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  ASSERT_EQ(hits.size(), twin.size());
  ASSERT_EQ(hits.size(), 4u);  // the three inside at t = 0, the outside ball at the wall
  for (std::size_t i = 0; i < hits.size(); ++i) {
    EXPECT_EQ(hits[i].a, twin[i].a);
    EXPECT_EQ(hits[i].b, twin[i].b);
    EXPECT_EQ(hits[i].result.status, twin[i].result.status);
    EXPECT_NEAR(hits[i].result.t, twin[i].result.t, 1e-6);
  }
  const ImpactPair& wall = hits.back();
  EXPECT_EQ(wall.b, outside);
  EXPECT_EQ(wall.result.status, ImpactStatus::contact);
  // The ball's surface reaches x = 10 when its center is at 10.5: t = 19.5 / 22.
  EXPECT_LE(wall.result.t, 19.5 / 22.0);
  EXPECT_NEAR(wall.result.t, 19.5 / 22.0, 1e-5);
}

TEST(SceneBodies, FiltersDropGeneralPairsBeforeTheNarrowPhase) {
  Rng rng(9);
  const std::vector<Entry> entries = random_entries(rng, 40, 4.0);
  Scene all;
  Scene filtered;
  for (const Entry& e : entries) {
    all.add(e.body, e.pose, e.padding);
    filtered.add(e.body, e.pose, e.padding);
  }
  // Even ids in group 2 tested only against group 2; a few pairs excluded.
  for (std::size_t i = 0; i < entries.size(); i += 2) {
    filtered.set_filter(static_cast<BodyId>(i), CollisionFilter{2, 2});
  }
  const std::vector<ClosePair> unfiltered(steps(all));
  ASSERT_GE(unfiltered.size(), 20u);
  std::set<std::pair<BodyId, BodyId>> excluded;
  for (std::size_t i = 1; i < unfiltered.size(); i += 3) {
    filtered.exclude_pair(unfiltered[i].a, unfiltered[i].b);
    excluded.insert({unfiltered[i].a, unfiltered[i].b});
  }
  const std::vector<ClosePair> kept(steps(filtered));
  std::vector<ClosePair> expected;
  for (const ClosePair& p : unfiltered) {
    if (filtered.tests_pair(p.a, p.b)) expected.push_back(p);
  }
  ASSERT_EQ(kept.size(), expected.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_TRUE(same_answer(kept[i], expected[i]));
    EXPECT_EQ(excluded.count({kept[i].a, kept[i].b}), 0u);
  }
  // Dropped before any query: one query per general pair, and the dropped
  // pairs are counted.
  EXPECT_EQ(filtered.stats().candidate_pairs + filtered.stats().filtered_pairs,
            all.stats().candidate_pairs);
  EXPECT_GT(filtered.stats().filtered_pairs, 0);
  EXPECT_LT(filtered.stats().convex_queries, all.stats().convex_queries);
}

TEST(SceneBodies, SweepTakesThePaddingAsARadius) {
  // Two points (spheres of radius 0 padded by p) 3 apart along x, each
  // moving 4 along y: parallel, they never get nearer than 3. With p = 1.6
  // they overlap all the way (at t = 0), with p = 1.4 they never meet.
  const auto point = std::make_shared<const ConvexPolytope>(std::vector<Vec3>{Vec3::Zero()});
  for (const double p : {1.4, 1.6}) {
    Scene scene;
    const BodyId a = scene.add(Body(point), Pose{Mat3::Identity(), Vec3(0, 0, 0)}, p);
    const BodyId b = scene.add(Body(point), Pose{Mat3::Identity(), Vec3(3, 0, 0)}, p);
    scene.set_end_pose(a, Pose{Mat3::Identity(), Vec3(0, 4, 0)});
    scene.set_end_pose(b, Pose{Mat3::Identity(), Vec3(3, 4, 0)});
    const std::span<const ImpactPair> hits = scene.sweep();
    EXPECT_EQ(hits.size(), p > 1.5 ? 1u : 0u) << "padding " << p;
    EXPECT_EQ(scene.sweep_stats().candidate_pairs, p > 1.5 ? 1 : 0) << "padding " << p;
    if (!hits.empty()) {
      EXPECT_EQ(hits[0].result.status, ImpactStatus::intersecting);
    }
  }
  // Moving towards each other: the padded contact time, bit for bit the
  // time_of_impact of the rounded bodies, and the all-pairs twin agrees.
  Scene scene;
  const double pad = 0.5;
  const Body ball = make_sphere(0.25);
  const BodyId a = scene.add(ball, Pose{Mat3::Identity(), Vec3(0, 0, 0)}, pad);
  const BodyId b = scene.add(Body(point), Pose{Mat3::Identity(), Vec3(5, 0, 0)}, pad);
  const Pose end_a{Mat3::Identity(), Vec3(2, 0, 0)};
  const Pose end_b{Mat3::Identity(), Vec3(3, 0, 0)};
  scene.set_end_pose(a, end_a);
  scene.set_end_pose(b, end_b);
  const std::vector<ImpactPair> hits = [&] {
    const std::span<const ImpactPair> h = scene.sweep();
    return std::vector<ImpactPair>(h.begin(), h.end());
  }();
  ASSERT_EQ(hits.size(), 1u);
  ImpactOptions options;
  options.distance = scene.options().distance;
  const ImpactResult direct_hit =
      time_of_impact(ball.with_radius(0.25 + pad), Motion{scene.pose(a), end_a},
                     Body(point).with_radius(pad), Motion{scene.pose(b), end_b}, options);
  EXPECT_EQ(hits[0].result.status, ImpactStatus::contact);
  EXPECT_TRUE(same_bits(hits[0].result.t, direct_hit.t));
  // Gap 5 - 1.25 = 3.75 closed at speed 4: t = 0.9375 (from below).
  EXPECT_NEAR(hits[0].result.t, 0.9375, 1e-5);
  EXPECT_LE(hits[0].result.t, 0.9375);
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  ASSERT_EQ(twin.size(), 1u);
  EXPECT_TRUE(same_bits(twin[0].result.t, direct_hit.t));
}

TEST(SceneBodies, NearestPairAndPairsWithinOnGeneralBodies) {
  Rng rng(31);
  const std::vector<Entry> entries = random_entries(rng, 27, 12.0);
  Scene scene;
  for (const Entry& e : entries) scene.add(e.body, e.pose, e.padding);
  // Brute force: distance(Body, Body) on every pair of padded bodies.
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    for (std::size_t j = i + 1; j < entries.size(); ++j) {
      best = std::min(best, distance(entries[i].padded(), entries[i].pose, entries[j].padded(),
                                     entries[j].pose, scene.options().distance)
                                .distance);
    }
  }
  const std::optional<ClosePair> nearest = scene.nearest_pair();
  ASSERT_TRUE(nearest.has_value());
  EXPECT_NEAR(nearest->result.distance, best, 1e-12 * (1 + best));
  // pairs_within of each body at margin 1: exactly the brute force's pairs.
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto id = static_cast<BodyId>(i);
    std::vector<BodyId> expected;
    for (std::size_t j = 0; j < entries.size(); ++j) {
      if (j == i) continue;
      const ClosePair p = direct(entries, static_cast<BodyId>(std::min(i, j)),
                                 static_cast<BodyId>(std::max(i, j)), scene.options().distance);
      if (p.result.status != Status::separated || p.result.distance <= 1.0)
        expected.push_back(static_cast<BodyId>(j));
    }
    std::vector<BodyId> got;
    for (const ClosePair& p : scene.pairs_within(id, 1.0)) got.push_back(p.a == id ? p.b : p.a);
    EXPECT_EQ(got, expected) << "body " << i;
  }
}

TEST(SceneBodies, BadPaddingIsRefusedByName) {
  Scene scene;
  const Body ball = make_sphere(1.0);
  for (const double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    try {
      scene.add(ball, Pose::identity(), bad);
      ADD_FAILURE() << "padding " << bad << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("padding"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(scene.body_count(), 0);
  const BodyId id = scene.add(ball, Pose::identity(), 0.5);
  try {
    scene.set_padding(id, -0.1);
    ADD_FAILURE() << "negative padding accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("body 0"), std::string::npos) << e.what();
  }
  EXPECT_EQ(scene.padding(id), 0.5);
  EXPECT_THROW(scene.set_padding(7, 0.1), InvalidInput);
  EXPECT_THROW(scene.padding(7), InvalidInput);
  EXPECT_THROW(scene.body(7), InvalidInput);
}

// body(id) is the Body as given, even for a plain one (radius and padding
// 0), which takes the convex fast path: a cylinder keeps its approximation
// error.
TEST(SceneBodies, BodyIsTheBodyAsGiven) {
  Scene scene;
  const Body cylinder = make_cylinder(0.5, 1.0, 1e-3);
  ASSERT_GT(cylinder.approximation_error(), 0.0);
  const BodyId plain = scene.add(cylinder, Pose::identity());
  const BodyId padded = scene.add(cylinder, Pose{Mat3::Identity(), Vec3(5, 0, 0)}, 0.25);
  for (const BodyId id : {plain, padded}) {
    EXPECT_EQ(scene.body(id).approximation_error(), cylinder.approximation_error());
    EXPECT_EQ(scene.body(id).radius(), 0.0);
    EXPECT_EQ(scene.body(id).convex(), cylinder.convex());
  }
  EXPECT_EQ(scene.padding(padded), 0.25);
}

}  // namespace
}  // namespace proxima
