// Tests of the scene's pair finders (src/scene/broad_phase.h, private to the
// library): sweep and prune and the dynamic AABB tree against the obvious
// twin, the closed-box test on every pair, over seeded random box sets that
// move, grow, lose and gain members between calls. Coordinates are
// multiples of 1/8, so that boxes whose faces exactly touch (the closed-box
// case that contact at margin 0 depends on) and boxes of zero extent are
// common; the tests check that they really occur.
#include "scene/broad_phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "proxima/shape/support.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::drawn;

using detail::Aabb;
using test::Rng;

std::vector<std::uint64_t> all_pairs(const std::vector<Aabb>& boxes,
                                     const std::vector<std::uint8_t>& member) {
  std::vector<std::uint64_t> pairs;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      if (member[i] != 0 && member[j] != 0 && detail::overlaps(boxes[i], boxes[j])) {
        pairs.push_back(
            detail::pair_key(static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)));
      }
    }
  }
  return pairs;
}

double grid(Rng& rng, int lo, int hi) { return test::uniform_int(rng, 8 * lo, 8 * hi) / 8.0; }

// A box on the 1/8 grid: half-extents 0 to 1 on each axis, so some boxes
// are flat or points.
Aabb random_box(Rng& rng, const Vec3& extent) {
  const Vec3 c = drawn([&] { return grid(rng, 0, static_cast<int>(extent.x())); },
                       [&] { return grid(rng, 0, static_cast<int>(extent.y())); },
                       [&] { return grid(rng, 0, static_cast<int>(extent.z())); });
  const Vec3 h = drawn([&] { return grid(rng, 0, 1); });
  return {c - h, c + h};
}

// Pairs of the set that overlap only on a face, edge or corner: some
// coordinate of one box equals the opposite one of the other.
int touching_only(const std::vector<Aabb>& boxes, const std::vector<std::uint64_t>& pairs) {
  int n = 0;
  for (const std::uint64_t key : pairs) {
    const Aabb& a = boxes[static_cast<std::size_t>(detail::pair_first(key))];
    const Aabb& b = boxes[static_cast<std::size_t>(detail::pair_second(key))];
    bool touch = false;
    for (int k = 0; k < 3; ++k) touch = touch || a.hi[k] == b.lo[k] || b.hi[k] == a.lo[k];
    n += touch ? 1 : 0;
  }
  return n;
}

class PairFinderTest : public testing::TestWithParam<BroadPhase> {};

TEST_P(PairFinderTest, MatchesAllPairsWhileBoxesMoveAndMembersChange) {
  Rng rng(20261122);
  constexpr int kIds = 300;
  const Vec3 extent(12, 12, 12);
  auto finder = detail::make_pair_finder(GetParam());
  std::vector<Aabb> boxes(kIds);
  std::vector<std::uint8_t> member(kIds, 0);
  for (int i = 0; i < kIds; ++i) {
    boxes[static_cast<std::size_t>(i)] = random_box(rng, extent);
    if (i % 5 != 0) {  // a fifth start outside the set
      finder->add(i);
      member[static_cast<std::size_t>(i)] = 1;
    }
  }
  std::vector<std::uint64_t> pairs;
  int touching = 0;
  int flat = 0;
  for (int step = 0; step < 40; ++step) {
    finder->find_pairs(boxes, pairs);
    const std::vector<std::uint64_t> expected = all_pairs(boxes, member);
    ASSERT_EQ(pairs, expected) << "step " << step;
    touching += touching_only(boxes, pairs);
    for (const Aabb& b : boxes) flat += (b.hi - b.lo).minCoeff() == 0.0 ? 1 : 0;
    // Small moves of every box (an eighth, often zero: boxes stay in their
    // fat boxes or leave them), a few big jumps, and members leaving,
    // joining, or leaving and joining again before the next call.
    for (int i = 0; i < kIds; ++i) {
      Aabb& b = boxes[static_cast<std::size_t>(i)];
      const Vec3 d = drawn([&] { return grid(rng, -1, 1) / 8; });
      b.lo += d;
      b.hi += d;
      if (test::uniform_int(rng, 0, 99) == 0) b = random_box(rng, extent);
    }
    for (int k = 0; k < 6; ++k) {
      const int i = test::uniform_int(rng, 0, kIds - 1);
      auto& m = member[static_cast<std::size_t>(i)];
      if (m != 0) {
        finder->remove(i);
        if (k % 3 == 0) {
          finder->add(i);  // the id reused at once, by a body somewhere else
          boxes[static_cast<std::size_t>(i)] = random_box(rng, extent);
        } else {
          m = 0;
        }
      } else {
        finder->add(i);
        m = 1;
      }
    }
  }
  // The random set must really hold the closed-box cases.
  EXPECT_GT(touching, 40);
  EXPECT_GT(flat, 100);
}

TEST_P(PairFinderTest, FollowsTheSceneWhenItsLongAxisTurns) {
  // Boxes spread along x, then along z: sweep and prune changes its axis
  // (and fully re-sorts); the tree re-inserts every leaf.
  Rng rng(7);
  constexpr int kIds = 200;
  auto finder = detail::make_pair_finder(GetParam());
  std::vector<Aabb> boxes(kIds);
  const std::vector<std::uint8_t> member(kIds, 1);
  for (int i = 0; i < kIds; ++i) {
    boxes[static_cast<std::size_t>(i)] = random_box(rng, Vec3(40, 4, 4));
    finder->add(i);
  }
  std::vector<std::uint64_t> pairs;
  finder->find_pairs(boxes, pairs);
  EXPECT_EQ(pairs, all_pairs(boxes, member));
  for (Aabb& b : boxes) {
    std::swap(b.lo.x(), b.lo.z());
    std::swap(b.hi.x(), b.hi.z());
  }
  finder->find_pairs(boxes, pairs);
  EXPECT_EQ(pairs, all_pairs(boxes, member));
  EXPECT_FALSE(pairs.empty());
}

// The tree's loops run in fixed chunks on 2 threads (1,024 ids, 32 moved
// leaves, 4,096 fat pairs a chunk): a set large enough for many chunks of
// each, with members leaving and joining, must give the 1-thread finder's
// pairs, which are the all-pairs loop's.
TEST_P(PairFinderTest, TwoThreadsGiveTheSamePairsOnALargeSet) {
  Rng rng(20261125);
  constexpr int kIds = 5000;
  const Vec3 extent(16, 16, 16);
  auto one = detail::make_pair_finder(GetParam());
  auto two = detail::make_pair_finder(GetParam());
  std::vector<Aabb> boxes(kIds);
  std::vector<std::uint8_t> member(kIds, 1);
  for (int i = 0; i < kIds; ++i) {
    boxes[static_cast<std::size_t>(i)] = random_box(rng, extent);
    one->add(i);
    two->add(i);
  }
  std::vector<std::uint64_t> pairs_one;
  std::vector<std::uint64_t> pairs_two;
  for (int step = 0; step < 4; ++step) {
    one->find_pairs(boxes, pairs_one, 1);
    two->find_pairs(boxes, pairs_two, 2);
    ASSERT_EQ(pairs_two, pairs_one) << "step " << step;
    ASSERT_EQ(pairs_one, all_pairs(boxes, member)) << "step " << step;
    EXPECT_GT(pairs_one.size(), 3u * 4096u) << "too few pairs for several chunks";
    // Every box moves by up to a quarter (many leave their fat boxes), some
    // ids leave and come back.
    for (int i = 0; i < kIds; ++i) {
      Aabb& b = boxes[static_cast<std::size_t>(i)];
      const Vec3 d = drawn([&] { return grid(rng, -1, 1) / 4; });
      b.lo += d;
      b.hi += d;
    }
    for (int k = 0; k < 50; ++k) {
      const int i = test::uniform_int(rng, 0, kIds - 1);
      auto& m = member[static_cast<std::size_t>(i)];
      for (auto* f : {one.get(), two.get()}) m != 0 ? f->remove(i) : f->add(i);
      m = m != 0 ? 0 : 1;
    }
  }
}

TEST_P(PairFinderTest, EmptyAndSingleSets) {
  auto finder = detail::make_pair_finder(GetParam());
  std::vector<std::uint64_t> pairs{42};
  const std::vector<Aabb> boxes(3);
  finder->find_pairs(boxes, pairs);
  EXPECT_TRUE(pairs.empty());
  finder->add(2);
  finder->find_pairs(boxes, pairs);
  EXPECT_TRUE(pairs.empty());
  finder->add(0);  // identical point boxes at the origin: they touch
  finder->find_pairs(boxes, pairs);
  EXPECT_EQ(pairs, std::vector<std::uint64_t>{detail::pair_key(0, 2)});
  finder->remove(2);
  finder->remove(0);
  finder->find_pairs(boxes, pairs);
  EXPECT_TRUE(pairs.empty());
}

// Subnormal centers: the sweep's axis choice scales the centers by 1 /
// their largest magnitude, which overflows to infinity below about 5.6e-309
// (and infinity times a zero coordinate is NaN, trapped by the test main).
// kMinSpreadScale in broad_phase.cpp keeps the current axis there; the pairs
// must be the closed-box test's all the same.
TEST_P(PairFinderTest, TinyCentersKeepTheirAxis) {
  const double tiny = 0x1p-1070;  // subnormal
  std::vector<Aabb> boxes;
  for (int k = 0; k < 6; ++k) {
    const Vec3 c(k * tiny, 0.0, (k % 2) * tiny);
    boxes.push_back({c - Vec3::Constant(tiny), c + Vec3::Constant(tiny)});
  }
  const std::vector<std::uint8_t> member(boxes.size(), 1);
  auto finder = detail::make_pair_finder(GetParam());
  for (std::int32_t id = 0; id < static_cast<std::int32_t>(boxes.size()); ++id) finder->add(id);
  std::vector<std::uint64_t> pairs;
  finder->find_pairs(boxes, pairs);
  std::sort(pairs.begin(), pairs.end());
  EXPECT_EQ(pairs, all_pairs(boxes, member));
  EXPECT_FALSE(pairs.empty());
}

INSTANTIATE_TEST_SUITE_P(BothFinders, PairFinderTest,
                         testing::Values(BroadPhase::sweep_and_prune,
                                         BroadPhase::dynamic_aabb_tree),
                         [](const testing::TestParamInfo<BroadPhase>& p) {
                           return to_string(p.param);
                         });

TEST(WorldBox, SupportBoxIsTheBoxOfThePlacedVerticesAndInsideTheSphereBox) {
  Rng rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const test::Points pts = trial % 2 == 0
                                 ? test::points_in_cube(rng, test::uniform_int(rng, 20, 200))
                                 : test::points_on_sphere(rng, test::uniform_int(rng, 20, 200));
    const ConvexPolytope body(pts);
    detail::BoxHints hints;
    Pose pose(test::random_quaternion(rng), Vec3(test::uniform(rng, -50, 50), 3.0, -7.0));
    for (int step = 0; step < 3; ++step) {
      const Aabb box = detail::support_box(body, pose, hints);
      Aabb exact{Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY)};
      for (const Vec3& v : body.vertices()) {
        exact.lo = exact.lo.cwiseMin(pose.apply(v));
        exact.hi = exact.hi.cwiseMax(pose.apply(v));
      }
      const double tol = 64 * kUnitRoundoff * 60;
      EXPECT_LE((box.lo - exact.lo).cwiseAbs().maxCoeff(), tol);
      EXPECT_LE((box.hi - exact.hi).cwiseAbs().maxCoeff(), tol);
      const Aabb sphere = detail::sphere_box(body, pose);
      EXPECT_TRUE((sphere.lo.array() <= box.lo.array() + tol).all());
      EXPECT_TRUE((box.hi.array() <= sphere.hi.array() + tol).all());
      // Next step: a small motion, from the hints just left.
      pose = Pose(Mat3(test::random_small_rotation(rng, 0.05) * pose.rotation), pose.translation);
    }
  }
}

// support_box skips a direction's hill climb while the direction stays
// within its certificate's allowance (broad_phase.h). Its slow, obvious
// twin: the six plain climbs (support_hill_climb) from the same hints. Along
// slow turns (most directions skip) and fast ones (most climb), on hulls of
// points on a sphere and in a cube, boxes (plateaus: coplanar neighbours
// tie, no certificate), flat polygons and scales 1e-90 to 1e90 (under the
// test main's floating-point traps), the vertices and the box are the
// twin's, bit for bit, step after step.
TEST(WorldBox, SupportBoxSkipsOnlyClimbsThatWouldStay) {
  Rng rng(17);
  long skipped = 0;
  long directions = 0;
  for (int trial = 0; trial < 60; ++trial) {
    test::Points pts;
    switch (trial % 4) {
      case 0:
        pts = test::points_on_sphere(rng, test::uniform_int(rng, 20, 200));
        break;
      case 1:
        pts = test::points_in_cube(rng, test::uniform_int(rng, 20, 200));
        break;
      case 2:
        for (int i = 0; i < 8; ++i)
          pts.emplace_back(i & 1 ? 1.0 : -1.0, i & 2 ? 0.5 : -0.5, i & 4 ? 2.0 : -2.0);
        break;
      default:
        pts = test::points_on_sphere(rng, test::uniform_int(rng, 8, 40));
        for (Vec3& p : pts) p.z() = 0.0;  // a polygon
    }
    const double scale = trial % 5 == 4 ? (trial % 10 == 4 ? 1e-90 : 1e90) : 1.0;
    const ConvexPolytope body(test::scaled(pts, scale));
    const double turn = trial % 3 == 0 ? 0.3 : 0.005;
    detail::BoxHints hints;
    std::array<std::int32_t, 6> twin = {-1, -1, -1, -1, -1, -1};
    Pose pose(test::random_quaternion(rng), scale * Vec3(test::uniform(rng, -50, 50), 3.0, -7.0));
    // An axis-aligned start for the boxes: their faces' neighbours tie.
    if (trial % 4 == 2) pose = Pose::from_translation(pose.translation);
    for (int step = 0; step < 40; ++step) {
      const detail::BoxHints before = hints;
      const Aabb box = detail::support_box(body, pose, hints);
      Aabb expected;
      for (int k = 0; k < 3; ++k) {
        const Vec3 dir = pose.rotation.row(k).transpose();
        const auto hi = static_cast<std::size_t>(2 * k);
        twin[hi] = support_hill_climb(body, dir, twin[hi]);
        twin[hi + 1] = support_hill_climb(body, -dir, twin[hi + 1]);
        expected.hi[k] = pose.translation[k] + dir.dot(body.vertex(twin[hi]));
        expected.lo[k] = pose.translation[k] + dir.dot(body.vertex(twin[hi + 1]));
      }
      SCOPED_TRACE(testing::Message() << "trial " << trial << ", step " << step);
      EXPECT_EQ(hints.vertex, twin);
      EXPECT_EQ(box.lo, expected.lo);
      EXPECT_EQ(box.hi, expected.hi);
      for (std::size_t i = 0; i < 6; ++i) {
        skipped += step > 0 && hints.direction[i] == before.direction[i] ? 1 : 0;
        directions += step > 0 ? 1 : 0;
      }
      pose = Pose(Mat3(test::random_small_rotation(rng, turn) * pose.rotation),
                  pose.translation + scale * Vec3(0.01, 0.0, 0.0));
    }
  }
  // Both paths ran often.
  EXPECT_GT(skipped, directions / 4);
  EXPECT_LT(skipped, directions * 3 / 4);
}

}  // namespace
}  // namespace proxima
