// Tests of Scene::sweep (continuous collision in a scene, issue 13) against
// its slow twin impact_pairs_all_pairs() (the cold time_of_impact on every
// pair the filters let through, no broad phase): hand-made motions that
// tunnel between two steps (a thin plate and a fast cube, a bar turning in
// place past a block), the filters, and seeded random scenes of convex and
// compound bodies moving, turning, added and removed between sweeps, where
// no pair the twin reports may be missing, and both broad phases and 1 and
// 2 threads give the same answers bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "proxima/scene/scene.h"
#include "proxima/motion/time_of_impact.h"
#include "support/generators.h"
#include "support/same_bits.h"

namespace proxima {
namespace {

using test::Rng;
using test::same_bits;

std::shared_ptr<const ConvexPolytope> box(const Vec3& half) {
  return std::make_shared<const ConvexPolytope>(test::box(half));
}

Pose at(const Vec3& t, const Mat3& r = Mat3::Identity()) { return {r, t}; }

Mat3 turn_z(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(); }

// The box of a convex body's vertices at `pose`, from the vertices.
struct Box {
  Vec3 lo, hi;
};
Box box_at(const ConvexPolytope& body, const Pose& pose) {
  Box b{Vec3::Constant(1e300), Vec3::Constant(-1e300)};
  for (const Vec3& v : body.vertices()) {
    const Vec3 p = pose.apply(v);
    b.lo = b.lo.cwiseMin(p);
    b.hi = b.hi.cwiseMax(p);
  }
  return b;
}
Box merged(const Box& a, const Box& b) { return {a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; }
Box shifted(const Box& a, const Vec3& v) { return {a.lo + v, a.hi + v}; }
bool overlaps(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// The box of the body at both ends of its motion and at each end shifted by
// the other's translation: what a swept box is without the turn's sag.
Box chord_box(const ConvexPolytope& body, const Pose& start, const Pose& end) {
  const Vec3 v = end.translation - start.translation;
  const Box b0 = box_at(body, start);
  const Box b1 = box_at(body, end);
  return merged(merged(b0, b1), merged(shifted(b0, v), shifted(b1, -v)));
}

bool same_impact(const ImpactPair& x, const ImpactPair& y) {
  return x.a == y.a && x.b == y.b && x.result.status == y.result.status &&
         same_bits(x.result.t, y.result.t) && x.result.iterations == y.result.iterations &&
         same_bits(x.result.at_t.distance, y.result.at_t.distance) &&
         same_bits(x.result.at_t.point_a, y.result.at_t.point_a) &&
         same_bits(x.result.at_t.point_b, y.result.at_t.point_b) &&
         same_bits(x.result.at_t.normal, y.result.at_t.normal);
}

TEST(SceneSweep, ThinPlateAndFastCubeTunnelBetweenStepsButNotThroughTheSweep) {
  // A plate 0.02 thick and a cube of edge 0.1 that goes from 1 above it to
  // 1 below in one step: apart at both poses, so step() sees nothing.
  Scene scene;
  const BodyId plate = scene.add(box(Vec3(2, 2, 0.01)), at(Vec3::Zero()));
  const BodyId cube = scene.add(box(Vec3::Constant(0.05)), at(Vec3(0.3, -0.2, 1.0)));
  EXPECT_TRUE(scene.step().empty());
  scene.set_end_pose(cube, at(Vec3(0.3, -0.2, -1.0)));
  EXPECT_TRUE(same_bits(scene.end_pose(cube).translation, Vec3(0.3, -0.2, -1.0)));
  EXPECT_TRUE(same_bits(scene.pose(cube).translation, Vec3(0.3, -0.2, 1.0)));

  const std::span<const ImpactPair> hits = scene.sweep();
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].a, plate);
  EXPECT_EQ(hits[0].b, cube);
  EXPECT_EQ(hits[0].result.status, ImpactStatus::contact);
  // The cube's bottom (0.95) meets the plate's top (0.01) after 0.94 of a
  // fall of 2: t* = 0.47. t <= t*, and the gap at t is within the default
  // tolerance (1e-6 of the sizes) of 0.
  const double t_star = 0.47;
  EXPECT_LE(hits[0].result.t, t_star + 1e-15);
  EXPECT_GE(hits[0].result.t, t_star - 1e-5);
  EXPECT_EQ(scene.sweep_stats().candidate_pairs, 1);
  EXPECT_EQ(scene.sweep_stats().impact_pairs, 1);
  EXPECT_EQ(scene.sweep_stats().moving_bodies, 1);
  EXPECT_EQ(scene.sweep_stats().distance_queries, hits[0].result.iterations);
  // The sweep leaves poses alone.
  EXPECT_TRUE(same_bits(scene.pose(cube).translation, Vec3(0.3, -0.2, 1.0)));

  // Cold and without another step, the sweep is the twin, bit for bit.
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  ASSERT_EQ(twin.size(), 1u);
  EXPECT_TRUE(same_impact(hits[0], twin[0]));

  // Moving the cube to its end pose ends its motion: the next sweep is
  // empty, and step() sees the two apart.
  scene.set_pose(cube, scene.end_pose(cube));
  EXPECT_TRUE(same_bits(scene.end_pose(cube).translation, scene.pose(cube).translation));
  EXPECT_TRUE(scene.sweep().empty());
  EXPECT_EQ(scene.sweep_stats().moving_bodies, 0);
  EXPECT_TRUE(scene.step().empty());
}

TEST(SceneSweep, TurnInPlaceIsCaughtWhereTheBoxesAtBothEndsMissIt) {
  // A bar of length 2 turns 0.9 of a half turn about its middle (no
  // translation). A block beside it at y = 0.7 is in the disc the bar sweeps
  // (the bar points along y at a quarter turn) but outside the boxes of the
  // bar at both ends (it reaches y = sin(0.9 pi) + 0.02 = 0.33 there).
  Scene scene;
  const auto bar_shape = box(Vec3(1.0, 0.02, 0.02));
  const auto block_shape = box(Vec3::Constant(0.05));
  const BodyId bar = scene.add(bar_shape, at(Vec3::Zero()));
  const BodyId block = scene.add(block_shape, at(Vec3(0.0, 0.7, 0.0)));
  const Pose bar_end = at(Vec3::Zero(), turn_z(0.9 * M_PI));
  scene.set_end_pose(bar, bar_end);
  ASSERT_FALSE(overlaps(chord_box(*bar_shape, scene.pose(bar), bar_end),
                        box_at(*block_shape, scene.pose(block))));

  const std::span<const ImpactPair> hits = scene.sweep();
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].a, bar);
  EXPECT_EQ(hits[0].b, block);
  EXPECT_EQ(hits[0].result.status, ImpactStatus::contact);
  // Against dense sampling: no sampled time before t is in contact, and the
  // bodies touch at t.
  const Motion motion{scene.pose(bar), bar_end};
  for (int i = 0; i <= 2000; ++i) {
    const double s = hits[0].result.t * i / 2000.0;
    EXPECT_GT(distance(*bar_shape, motion.at(s), *block_shape, scene.pose(block)).distance, 0.0)
        << "in contact at " << s << " before the reported t " << hits[0].result.t;
  }
  EXPECT_LT(
      distance(*bar_shape, hits[0].result.pose_a, *block_shape, hits[0].result.pose_b).distance,
      1e-5);
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  ASSERT_EQ(twin.size(), 1u);
  EXPECT_TRUE(same_impact(hits[0], twin[0]));
}

// Issue 25: a body given velocities turns at their rate through any angle
// in a sweep. A bar spinning one whole turn in place (set_velocity, w =
// 2 pi) sweeps through a block beside it, though its end pose is its start
// pose: set_end_pose to that same end pose (no turn, the shorter way) and
// the sweep before the fix (which kept end poses only) found nothing. The
// swept box grows by the whole circle the bar's points run round (a box of
// the two ends would miss the block, above the bar's line).
TEST(SceneSweep, AWholeTurnByVelocityIsSweptThroughAndAnEndPoseIsNot) {
  Scene scene;
  const auto bar_shape = box(Vec3(1.0, 0.02, 0.02));
  const auto block_shape = box(Vec3::Constant(0.05));
  const BodyId bar = scene.add(bar_shape, at(Vec3::Zero()));
  const BodyId block = scene.add(block_shape, at(Vec3(0.0, 0.7, 0.0)));
  const double w = 2 * M_PI;
  scene.set_velocity(bar, Vec3::Zero(), Vec3(0, 0, w));
  ASSERT_TRUE(scene.angular_velocity(bar).has_value());
  EXPECT_TRUE(scene.end_pose(bar).rotation.isApprox(Mat3::Identity(), 1e-14));

  const std::span<const ImpactPair> hits = scene.sweep();
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].result.status, ImpactStatus::contact);
  // The first contact of the true motion (angle s w), by dense sampling.
  const auto true_pose = [&](double s) { return at(Vec3::Zero(), turn_z(s * w)); };
  double first = 2.0;
  for (int i = 0; i <= 4000 && first > 1.0; ++i) {
    const double s = i / 4000.0;
    if (distance(*bar_shape, true_pose(s), *block_shape, scene.pose(block)).distance <= 0.0)
      first = s;
  }
  ASSERT_LE(first, 1.0);
  EXPECT_LE(hits[0].result.t, first);
  EXPECT_GE(hits[0].result.t, first - 1.0 / 4000);
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  ASSERT_EQ(twin.size(), 1u);
  EXPECT_TRUE(same_impact(hits[0], twin[0]));

  // The same end pose as an end pose: no turn at all.
  scene.set_end_pose(bar, scene.end_pose(bar));
  EXPECT_FALSE(scene.angular_velocity(bar).has_value());
  EXPECT_TRUE(scene.sweep().empty());
  // set_pose forgets the velocities too.
  scene.set_velocity(bar, Vec3::Zero(), Vec3(0, 0, w));
  scene.set_pose(bar, at(Vec3::Zero()));
  EXPECT_FALSE(scene.angular_velocity(bar).has_value());
  EXPECT_THROW(scene.set_velocity(bar, Vec3::Zero(), Vec3(0, 0, NAN)), InvalidInput);
}

TEST(SceneSweep, FiltersAndExclusionsDropPairsBeforeAnyQuery) {
  // Two cubes fall through one plate at different places; they never meet.
  Scene scene;
  const BodyId plate = scene.add(box(Vec3(3, 3, 0.01)), at(Vec3::Zero()));
  const BodyId c1 = scene.add(box(Vec3::Constant(0.05)), at(Vec3(-1, 0, 1)));
  const BodyId c2 = scene.add(box(Vec3::Constant(0.05)), at(Vec3(1, 0, 1)));
  scene.set_end_pose(c1, at(Vec3(-1, 0, -1)));
  scene.set_end_pose(c2, at(Vec3(1, 0, -1)));
  const auto pairs_of = [](std::span<const ImpactPair> hits) {
    std::vector<std::pair<BodyId, BodyId>> out;
    for (const ImpactPair& p : hits) out.emplace_back(p.a, p.b);
    return out;
  };
  using Pairs = std::vector<std::pair<BodyId, BodyId>>;
  EXPECT_EQ(pairs_of(scene.sweep()), (Pairs{{plate, c1}, {plate, c2}}));

  scene.exclude_pair(c1, plate);
  EXPECT_EQ(pairs_of(scene.sweep()), (Pairs{{plate, c2}}));
  EXPECT_EQ(scene.sweep_stats().filtered_pairs, 1);
  EXPECT_EQ(scene.sweep_stats().candidate_pairs, 1);
  EXPECT_EQ(pairs_of(scene.impact_pairs_all_pairs()), (Pairs{{plate, c2}}));

  // Groups: c2 in group 2 only, the plate tests group 1 only.
  scene.include_pair(plate, c1);
  scene.set_filter(c2, CollisionFilter{2u, 0xffffffffu});
  scene.set_filter(plate, CollisionFilter{1u, 1u});
  EXPECT_EQ(pairs_of(scene.sweep()), (Pairs{{plate, c1}}));
  EXPECT_EQ(scene.sweep_stats().filtered_pairs, 1);
  EXPECT_EQ(pairs_of(scene.impact_pairs_all_pairs()), (Pairs{{plate, c1}}));
}

TEST(SceneSweep, TargetSeparationReachesPairsThatNeverTouch) {
  // A cube passes 0.3 beside a post: no contact at target 0, a contact
  // at target 0.5 (the offset a simulator keeps), found by the broad phase
  // even though the bodies' own swept volumes never overlap.
  Scene scene;
  const BodyId post = scene.add(box(Vec3(0.1, 0.1, 2)), at(Vec3::Zero()));
  const BodyId cube = scene.add(box(Vec3::Constant(0.1)), at(Vec3(-3, 0.5, 0)));
  scene.set_end_pose(cube, at(Vec3(3, 0.5, 0)));
  EXPECT_TRUE(scene.sweep().empty());
  ImpactOptions options;
  options.target_separation = 0.5;
  const std::span<const ImpactPair> hits = scene.sweep(options);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].a, post);
  EXPECT_EQ(hits[0].result.status, ImpactStatus::contact);
  // The faces are 0.3 apart across (y); the edges come within
  // sqrt(dx^2 + 0.3^2) = 0.5 at an x gap dx = 0.4, the cube's center at
  // x = -0.6: t* = (3 - 0.6) / 6 = 0.4.
  EXPECT_LE(hits[0].result.t, 0.4 + 1e-15);
  EXPECT_GE(hits[0].result.t, 0.4 - 1e-5);
}

TEST(SceneSweep, BadInputIsNamed) {
  Scene empty;
  EXPECT_TRUE(empty.sweep().empty());
  EXPECT_EQ(empty.sweep_stats().candidate_pairs, 0);
  Scene scene;
  const BodyId a = scene.add(box(Vec3::Constant(0.5)), at(Vec3::Zero()));
  const auto message = [](auto&& call) {
    try {
      call();
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([&] { scene.set_end_pose(7, at(Vec3::Zero())); }).find("body 7"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)scene.end_pose(-1); }).find("body -1"), std::string::npos);
  const double nan = std::nan("");
  EXPECT_NE(message([&] { scene.set_end_pose(a, at(Vec3(nan, 0, 0))); }).find("end pose of body 0"),
            std::string::npos);
  ImpactOptions bad;
  bad.target_separation = -1.0;
  EXPECT_NE(message([&] { scene.sweep(bad); }).find("Scene::sweep: options.target_separation"),
            std::string::npos);
  bad = ImpactOptions{};
  bad.max_iterations = 0;
  EXPECT_NE(message([&] { scene.sweep(bad); }).find("max_iterations"), std::string::npos);
  // A removed body's end pose goes with it.
  scene.remove(a);
  EXPECT_NE(message([&] { (void)scene.end_pose(a); }).find("not in the scene"), std::string::npos);
}

// Compares a sweep's pairs with the twin's: the same pairs, the same
// statuses, times within `t_tolerance`. Returns how many agree.
int expect_twin(const std::vector<ImpactPair>& hits, const std::vector<ImpactPair>& twin,
                double t_tolerance, const std::string& where) {
  int agreed = 0;
  std::size_t i = 0;
  for (const ImpactPair& p : twin) {
    while (i < hits.size() && (hits[i].a < p.a || (hits[i].a == p.a && hits[i].b < p.b))) {
      ADD_FAILURE() << where << ": sweep reports (" << hits[i].a << ", " << hits[i].b
                    << "), the twin does not";
      ++i;
    }
    if (i == hits.size() || hits[i].a != p.a || hits[i].b != p.b) {
      ADD_FAILURE() << where << ": the twin reports (" << p.a << ", " << p.b << ") at t "
                    << p.result.t << " (" << to_string(p.result.status) << "), sweep misses it";
      continue;
    }
    const ImpactPair& h = hits[i++];
    EXPECT_EQ(h.result.status, p.result.status) << where << " (" << p.a << ", " << p.b << ")";
    EXPECT_NEAR(h.result.t, p.result.t, t_tolerance) << where << " (" << p.a << ", " << p.b << ")";
    ++agreed;
  }
  for (; i < hits.size(); ++i) {
    ADD_FAILURE() << where << ": sweep reports (" << hits[i].a << ", " << hits[i].b
                  << "), the twin does not";
  }
  return agreed;
}

TEST(SceneSweep, RandomTurnstilesAreCaughtWhereTheBoxesAtBothEndsMissThem) {
  // Sixty turnstiles apart from each other: a bar (random length and
  // thickness, its reference point up to a fifth of its length off its
  // middle) turns in place by 0.5 to 0.98 of a half turn about a random
  // axis across it, and a small random body waits near a point the bar
  // passes mid-turn. Many of them meet where neither end's box reaches.
  Rng rng(13);
  Scene scene;
  struct Turnstile {
    std::shared_ptr<const ConvexPolytope> bar, block;
    BodyId bar_id, block_id;
  };
  std::vector<Turnstile> all;
  for (int k = 0; k < 60; ++k) {
    const Vec3 site(10.0 * (k % 8), 10.0 * ((k / 8) % 8), 0.0);
    const double length = test::uniform(rng, 1.0, 3.0);
    const double offset = test::uniform(rng, -0.2, 0.2) * length;
    auto bar = std::make_shared<const ConvexPolytope>(test::translated(
        test::needle(rng, length, test::uniform(rng, 0.005, 0.05)), Vec3(offset, 0, 0)));
    auto block = std::make_shared<const ConvexPolytope>(
        test::points_in_cube(rng, 12, test::uniform(rng, 0.02, 0.1)));
    const Mat3 r0 = test::random_rotation(rng);
    // An axis across the bar (its x axis in its own frame).
    const Vec3 across = r0 * test::drawn([&] { return 0; },
                                         [&] { return std::cos(test::uniform(rng, 0, 2 * M_PI)); },
                                         [&] { return std::sin(test::uniform(rng, 0, 2 * M_PI)); })
                                 .normalized();
    const double angle = test::uniform(rng, 0.5, 0.98) * M_PI;
    const Pose start{r0, site};
    const Pose end{Mat3(Eigen::AngleAxisd(angle, across).toRotationMatrix() * r0), site};
    // The point of the bar at fraction f of its length, half way through
    // the turn, and the block a little off it.
    const double f = test::uniform(rng, -0.5, 0.5) * length + offset;
    const Motion motion{start, end};
    const Vec3 passed = motion.at(0.5).apply(Vec3(f, 0, 0));
    const Vec3 block_at = passed + test::uniform(rng, 0.0, 0.1) * test::random_unit_vector(rng);
    const BodyId bar_id = scene.add(bar, start);
    const BodyId block_id = scene.add(block, Pose{test::random_rotation(rng), block_at});
    scene.set_end_pose(bar_id, end);
    all.push_back({bar, block, bar_id, block_id});
  }
  const std::span<const ImpactPair> got = scene.sweep();
  const std::vector<ImpactPair> hits(got.begin(), got.end());
  const std::vector<ImpactPair> twin = scene.impact_pairs_all_pairs();
  EXPECT_GE(expect_twin(hits, twin, 1e-3, "turnstiles"), 30);
  // Cold (a first sweep): the same answers as the twin, bit for bit.
  ASSERT_EQ(hits.size(), twin.size());
  for (std::size_t i = 0; i < hits.size(); ++i) EXPECT_TRUE(same_impact(hits[i], twin[i]));
  int beyond_end_boxes = 0;
  for (const ImpactPair& p : twin) {
    for (const Turnstile& ts : all) {
      if (p.a != ts.bar_id || p.b != ts.block_id) continue;
      const Box block_box = box_at(*ts.block, scene.pose(ts.block_id));
      if (!overlaps(chord_box(*ts.bar, scene.pose(ts.bar_id), scene.end_pose(ts.bar_id)),
                    block_box)) {
        ++beyond_end_boxes;
      }
    }
  }
  EXPECT_GE(beyond_end_boxes, 10);
}

// A random scene body: a convex cloud (sometimes a needle or a flat plate,
// the shapes that tunnel) or a compound of two or three clouds.
struct Shape {
  std::shared_ptr<const ConvexPolytope> convex;
  std::shared_ptr<const CompoundBody> compound;
};

Shape random_shape(Rng& rng) {
  const int kind = test::uniform_int(rng, 0, 9);
  if (kind == 9) {
    std::vector<std::vector<Vec3>> sets;
    const int pieces = test::uniform_int(rng, 2, 3);
    for (int i = 0; i < pieces; ++i) {
      sets.push_back(
          test::translated(test::points_on_sphere(rng, 16, 0.3),
                           test::uniform(rng, 0.2, 0.6) * test::random_unit_vector(rng)));
    }
    return {nullptr, std::make_shared<const CompoundBody>(CompoundBody::from_point_sets(sets))};
  }
  test::Points pts;
  if (kind <= 1) {
    pts = test::needle(rng, 2.0, 0.02);
  } else if (kind == 2) {
    pts = test::box(Vec3(0.8, 0.8, 0.01));
  } else if (kind <= 5) {
    pts = test::points_in_cube(rng, test::uniform_int(rng, 8, 40), 0.4);
  } else {
    pts = test::points_on_sphere(rng, test::uniform_int(rng, 8, 40), 0.4);
  }
  // Off-center sometimes: the reference point is not the middle, so a turn
  // also swings the body around.
  if (test::uniform_int(rng, 0, 3) == 0)
    pts = test::translated(pts, 0.5 * test::random_unit_vector(rng));
  return {std::make_shared<const ConvexPolytope>(pts), nullptr};
}

// A motion: mostly a few sizes of travel and up to a half turn, sometimes
// none, sometimes only a wide turn (the motion whose swept volume leaves the
// boxes at both ends).
Pose random_end(Rng& rng, const Pose& start) {
  const int kind = test::uniform_int(rng, 0, 5);
  if (kind == 0) return start;
  const bool turn_only = kind <= 2;
  const Vec3 travel = turn_only
                          ? Vec3(Vec3::Zero())
                          : Vec3(test::uniform(rng, 0.0, 3.0) * test::random_unit_vector(rng));
  const double angle = test::uniform(rng, turn_only ? 0.5 * M_PI : 0.0, 0.98 * M_PI);
  const Mat3 turn = Eigen::AngleAxisd(angle, test::random_unit_vector(rng)).toRotationMatrix();
  return {Mat3(turn * start.rotation), Vec3(start.translation + travel)};
}

struct Lockstep {
  std::vector<Scene> scenes;
  Lockstep() {
    for (const BroadPhase bp : {BroadPhase::dynamic_aabb_tree, BroadPhase::sweep_and_prune}) {
      for (const int threads : {1, 2}) {
        SceneOptions o;
        o.broad_phase = bp;
        o.threads = threads;
        scenes.emplace_back(o);
      }
    }
  }
  BodyId add(const Shape& shape, const Pose& pose) {
    BodyId id = -1;
    for (Scene& s : scenes) {
      const BodyId got = shape.convex ? s.add(shape.convex, pose) : s.add(shape.compound, pose);
      if (id >= 0) {
        EXPECT_EQ(got, id);
      }
      id = got;
    }
    return id;
  }
};

TEST(SceneSweep, RandomScenesMissNoPairOfTheTwinAndAgreeBitForBitAcrossThreadsAndBroadPhases) {
  Rng rng(20261125);
  Lockstep lock;
  std::vector<Shape> shapes;  // by id
  const double side = 7.0;
  const auto place = [&](Rng& r) {
    return Pose{test::random_rotation(r), Vec3(test::uniform(r, 0, side), test::uniform(r, 0, side),
                                               test::uniform(r, 0, side))};
  };
  for (int i = 0; i < 70; ++i) {
    const Shape s = random_shape(rng);
    const BodyId id = lock.add(s, place(rng));
    shapes.resize(std::max(shapes.size(), static_cast<std::size_t>(id) + 1));
    shapes[static_cast<std::size_t>(id)] = s;
  }
  Scene& first = lock.scenes[0];
  int reported = 0, tunnelled = 0, warm = 0, compound_pairs = 0;
  for (int round = 0; round < 8; ++round) {
    const std::string where = "round " + std::to_string(round);
    for (const BodyId id : first.body_ids()) {
      const Pose end = random_end(rng, first.pose(id));
      for (Scene& s : lock.scenes) s.set_end_pose(id, end);
    }
    ImpactOptions options;
    options.target_separation = round % 3 == 2 ? 0.05 : 0.0;
    options.distance.penetration = round % 2 == 0;  // the depth of pairs overlapping at t = 0
    const std::span<const ImpactPair> got = first.sweep(options);
    const std::vector<ImpactPair> hits(got.begin(), got.end());
    for (std::size_t k = 1; k < lock.scenes.size(); ++k) {
      const std::span<const ImpactPair> other = lock.scenes[k].sweep(options);
      ASSERT_EQ(other.size(), hits.size()) << where << ", scene " << k;
      for (std::size_t i = 0; i < hits.size(); ++i) {
        EXPECT_TRUE(same_impact(hits[i], other[i]))
            << where << ", scene " << k << ": pair (" << hits[i].a << ", " << hits[i].b
            << ") differs";
      }
      EXPECT_EQ(lock.scenes[k].sweep_stats().candidate_pairs, first.sweep_stats().candidate_pairs);
      EXPECT_EQ(lock.scenes[k].sweep_stats().distance_queries,
                first.sweep_stats().distance_queries);
    }
    EXPECT_GE(first.sweep_stats().candidate_pairs, 64) << where << ": too few for two threads";
    warm += first.sweep_stats().warm_pairs;

    // The twin: every pair it reports is reported, with the same status;
    // both times are safe (not after t*), so they differ only by how close
    // to the contact each one's last step landed (within the tolerance in
    // distance, 1e-6 of the sizes: far less than 1e-3 in time at these
    // speeds).
    const std::vector<ImpactPair> twin = first.impact_pairs_all_pairs(options);
    reported += expect_twin(hits, twin, 1e-3, where);
    for (const ImpactPair& p : twin) {
      const Shape& sa = shapes[static_cast<std::size_t>(p.a)];
      const Shape& sb = shapes[static_cast<std::size_t>(p.b)];
      if (!sa.convex || !sb.convex) {
        ++compound_pairs;
        continue;
      }
      // The hard case: apart at both ends (tunnelling between steps).
      if (p.result.status == ImpactStatus::contact &&
          distance(*sa.convex, first.pose(p.a), *sb.convex, first.pose(p.b)).distance >
              options.target_separation &&
          distance(*sa.convex, first.end_pose(p.a), *sb.convex, first.end_pose(p.b)).distance >
              options.target_separation) {
        ++tunnelled;
      }
    }

    // The simulator's step: each body goes to its end pose (or, for a few,
    // where its first contact let it go); some bodies leave, new ones come
    // (ids reused), and a step() now and then (its caches seed the sweep's).
    for (const BodyId id : first.body_ids()) {
      Pose next = first.end_pose(id);
      for (const ImpactPair& h : hits) {
        if (h.a == id && test::uniform_int(rng, 0, 1) == 0) next = h.result.pose_a;
      }
      for (Scene& s : lock.scenes) s.set_pose(id, next);
    }
    for (int k = 0; k < 3; ++k) {
      const std::vector<BodyId> ids = first.body_ids();
      const BodyId gone = ids[static_cast<std::size_t>(
          test::uniform_int(rng, 0, static_cast<int>(ids.size()) - 1))];
      for (Scene& s : lock.scenes) s.remove(gone);
      const Shape s = random_shape(rng);
      const BodyId id = lock.add(s, place(rng));
      shapes.resize(std::max(shapes.size(), static_cast<std::size_t>(id) + 1));
      shapes[static_cast<std::size_t>(id)] = s;
    }
    if (round % 2 == 1) {
      for (Scene& s : lock.scenes) s.step();
    }
    // Bodies that stray far from the box come back.
    for (const BodyId id : first.body_ids()) {
      const Pose p = first.pose(id);
      if ((p.translation.array() < -2.0).any() || (p.translation.array() > side + 2.0).any()) {
        const Pose back = place(rng);
        for (Scene& s : lock.scenes) s.set_pose(id, back);
      }
    }
  }
  // The random set holds the hard cases.
  EXPECT_GE(reported, 100);
  EXPECT_GE(tunnelled, 10);
  EXPECT_GE(compound_pairs, 5);
  EXPECT_GT(warm, 0);
  std::printf("reported %d, tunnelled %d, compound pairs %d, warm %d\n", reported, tunnelled,
              compound_pairs, warm);
}

}  // namespace
}  // namespace proxima
