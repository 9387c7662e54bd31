// Tests of compound bodies (compound.h): the branch-and-bound distance
// against its slow twin distance_all_pairs on seeded random compounds (1 to
// 200 pieces of the generators' shapes, overlapping pieces, near-touching
// and intersecting placements, far from the origin, tiny and huge scales),
// under the accuracy standard of DESIGN.md with R the largest coordinate of
// the placed vertices of both bodies. The reported points are checked to lie
// on the reported pieces by independent convex queries; tracking with one
// CompoundCache must agree with cold queries and test fewer pairs; foreign
// and garbage caches must never change an answer; pruning must prune; the
// hierarchy must hold every vertex of every piece in each ancestor's sphere.
#include "proxima/query/compound_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "support/generators.h"
#include "support/sanitizers.h"

namespace proxima {
namespace {

using test::Points;
using test::Rng;

constexpr int count(int n) { return test::sanitized_count(n, 6); }

constexpr double kBandUlps = 64.0;
constexpr double kRelativeTolerance = 1e-12;

// A random convex piece of unit-ish size: mostly point clouds on a sphere or
// in a cube, sometimes one of the generators' degenerate shapes (needles,
// slivers, polygons, segments, single points).
Points random_piece_points(Rng& rng) {
  const int n = test::uniform_int(rng, 4, 24);
  switch (test::uniform_int(rng, 0, 5)) {
    case 0:
      return test::points_in_cube(rng, n);
    case 1:
      return test::random_shape(rng, test::random_shape_kind(rng), n);
    default:
      return test::points_on_sphere(rng, n);
  }
}

Pose random_pose(Rng& rng, double spread) {
  return {test::random_quaternion(rng),
          test::drawn([&] { return test::uniform(rng, -spread, spread); })};
}

// `n` pieces of size `size` spread over a cube of half-width `spread` (small
// spreads make pieces overlap within the body). Half of the pieces are placed
// by a piece pose, half by moving their points (identity pose).
CompoundBody random_compound(Rng& rng, int n, double spread, double size = 1.0) {
  std::vector<CompoundPiece> pieces;
  for (int i = 0; i < n; ++i) {
    const Points local =
        test::scaled(random_piece_points(rng), size * test::uniform(rng, 0.3, 1.0));
    const Pose place = random_pose(rng, spread);
    if (rng() & 1) {
      pieces.push_back({std::make_shared<const ConvexPolytope>(local), place});
    } else {
      pieces.push_back({std::make_shared<const ConvexPolytope>(test::transformed(local, place)),
                        Pose::identity()});
    }
  }
  return CompoundBody(std::move(pieces));
}

// R of the standard: the largest world coordinate of a placed vertex.
double world_magnitude(const CompoundBody& body, const Pose& pose) {
  double r = 0.0;
  for (const CompoundPiece& p : body.pieces()) {
    const Pose placed = pose * p.pose;
    for (const Vec3& v : p.polytope->vertices())
      r = std::max(r, placed.apply(v).cwiseAbs().maxCoeff());
  }
  return r;
}

double tolerance(const CompoundBody& a, const Pose& pa, const CompoundBody& b, const Pose& pb,
                 double d) {
  return kRelativeTolerance * d +
         kBandUlps * kUnitRoundoff * std::max(world_magnitude(a, pa), world_magnitude(b, pb));
}

// The checks every answer must pass against its twin: same distance within
// the standard, both intersecting or neither (when the distance is clearly
// outside the contact band), and the reported points on the reported pieces:
// the cold convex query of those two pieces agrees with the distance, and
// each point is within the band of its piece: a convex query from a
// one-point polytope must not certify (by its lower bound) a larger gap.
// The lower bound, not the distance, because that query is not always
// certified itself: a point on an edge of a needle piece came back at
// 1.7e-9 with lower bound 0 from all three algorithms (a convex-layer gap,
// reported; the point was the pair query's own witness, an edge point).
void check_against_twin(const CompoundBody& a, const Pose& pa, const CompoundBody& b,
                        const Pose& pb, const CompoundResult& r, const CompoundResult& twin) {
  const double tol = tolerance(a, pa, b, pb, twin.distance);
  ASSERT_TRUE(std::isfinite(r.distance));
  EXPECT_NEAR(r.distance, twin.distance, tol) << "pieces " << r.piece_a << "," << r.piece_b
                                              << " vs twin " << twin.piece_a << "," << twin.piece_b;
  if (twin.distance > 2 * tol) {
    EXPECT_EQ(r.status == Status::intersecting, twin.status == Status::intersecting);
  }
  if (twin.status == Status::intersecting) {
    EXPECT_EQ(r.distance, 0.0);
  }
  ASSERT_GE(r.piece_a, 0);
  ASSERT_LT(r.piece_a, a.piece_count());
  ASSERT_GE(r.piece_b, 0);
  ASSERT_LT(r.piece_b, b.piece_count());
  const CompoundPiece& piece_a = a.piece(r.piece_a);
  const CompoundPiece& piece_b = b.piece(r.piece_b);
  const DistanceResult pair =
      distance(*piece_a.polytope, pa * piece_a.pose, *piece_b.polytope, pb * piece_b.pose);
  EXPECT_NEAR(pair.distance, r.distance, tol);
  // Apart: the closest points; intersecting: the deepest points of the
  // pair, |point_a - point_b| the depth (the signed distance's negative).
  EXPECT_NEAR((r.point_a - r.point_b).norm(), std::abs(r.signed_distance()),
              tol + 1e-12 * std::abs(r.signed_distance()));
  EXPECT_NEAR(r.signed_distance(), twin.signed_distance(),
              tol + 1e-12 * std::abs(twin.signed_distance()));
  const ConvexPolytope at_a(Points{r.point_a});
  const ConvexPolytope at_b(Points{r.point_b});
  EXPECT_LE(distance(at_a, Pose::identity(), *piece_a.polytope, pa * piece_a.pose).lower_bound,
            tol);
  EXPECT_LE(distance(at_b, Pose::identity(), *piece_b.polytope, pb * piece_b.pose).lower_bound,
            tol);
  EXPECT_LE(r.lower_bound, r.distance);
  EXPECT_GE(r.pairs_tested, 1);
  EXPECT_LE(r.pairs_tested, a.piece_count() * b.piece_count());
}

// Moves pose_b along the twin's normal so that the closest pair's distance
// becomes `gap` (the slab argument: translating B by -(d - gap) n shrinks
// that pair's separating slab to `gap`); other pairs may come closer.
Pose closer_to(const CompoundResult& twin, const Pose& pose_b, double gap) {
  Pose moved = pose_b;
  moved.translation -= (twin.distance - gap) * twin.normal;
  return moved;
}

TEST(Compound, SinglePieceIsTheConvexQueryBitForBit) {
  Rng rng(101);
  for (int k = 0; k < count(60); ++k) {
    const auto pa = std::make_shared<const ConvexPolytope>(random_piece_points(rng));
    const auto pb = std::make_shared<const ConvexPolytope>(random_piece_points(rng));
    const Pose local_a = random_pose(rng, 1.0);
    const Pose local_b = random_pose(rng, 1.0);
    const CompoundBody a({{pa, local_a}});
    const CompoundBody b({{pb, local_b}});
    Pose pose_a = random_pose(rng, 2.0);
    Pose pose_b = random_pose(rng, 2.0);
    CompoundCache compound_cache;
    DistanceCache convex_cache;
    for (int step = 0; step < 5; ++step) {
      const CompoundResult r = distance(a, pose_a, b, pose_b, {}, &compound_cache);
      const DistanceResult c =
          distance(*pa, pose_a * local_a, *pb, pose_b * local_b, {}, &convex_cache);
      EXPECT_EQ(r.distance, c.distance);
      EXPECT_EQ(r.lower_bound, c.lower_bound);
      EXPECT_EQ(r.status, c.status);
      EXPECT_EQ(r.point_a, c.point_a);
      EXPECT_EQ(r.point_b, c.point_b);
      EXPECT_EQ(r.normal, c.normal);
      EXPECT_EQ(r.feature_a.vertices, c.feature_a.vertices);
      EXPECT_EQ(r.feature_b.vertices, c.feature_b.vertices);
      EXPECT_EQ(r.feature_a.face, c.feature_a.face);
      EXPECT_EQ(r.feature_b.face, c.feature_b.face);
      EXPECT_EQ(r.iterations, c.iterations);
      EXPECT_EQ(r.piece_a, 0);
      EXPECT_EQ(r.piece_b, 0);
      EXPECT_EQ(r.pairs_tested, 1);
      ASSERT_EQ(compound_cache.near.size(), 1u);
      EXPECT_EQ(compound_cache.near[0].cache.vertices_a, convex_cache.vertices_a);
      pose_b.translation += 0.01 * test::random_unit_vector(rng);
      pose_a.rotation = test::random_small_rotation(rng, 0.01) * pose_a.rotation;
    }
  }
}

// The main twin comparison: random compounds of 1 to 200 pieces on both
// sides, random poses, cold queries. Tallies say the hard cases are there.
TEST(Compound, RandomCompoundsAgreeWithTheTwin) {
  Rng rng(202);
  int intersecting = 0;
  int near_touching = 0;
  int separated = 0;
  int many_pieces = 0;
  for (int k = 0; k < count(120); ++k) {
    // Piece counts log-uniform in [1, 200]; the product kept moderate so the
    // twin stays fast.
    const int na = static_cast<int>(test::log_uniform(rng, 1.0, 200.5));
    const int nb =
        std::max(1, std::min(static_cast<int>(test::log_uniform(rng, 1.0, 200.5)), 4000 / na));
    many_pieces += std::max(na, nb) >= 100;
    const double spread_a = test::log_uniform(rng, 0.2, 3.0 * std::cbrt(na));
    const double spread_b = test::log_uniform(rng, 0.2, 3.0 * std::cbrt(nb));
    const CompoundBody a = random_compound(rng, na, spread_a);
    const CompoundBody b = random_compound(rng, nb, spread_b);
    const Pose pose_a = random_pose(rng, 1.0);
    Pose pose_b = random_pose(rng, 1.0);
    pose_b.translation += test::uniform(rng, 0.0, 2.0) *
                          (a.bounding_radius() + b.bounding_radius()) *
                          test::random_unit_vector(rng);
    CompoundResult twin = distance_all_pairs(a, pose_a, b, pose_b);
    // One case in three moved to near touching: the closest pair at a
    // relative gap 1e-9 .. 1e-3.
    if (k % 3 == 0 && twin.status == Status::separated) {
      pose_b = closer_to(twin, pose_b, test::log_uniform(rng, 1e-9, 1e-3));
      twin = distance_all_pairs(a, pose_a, b, pose_b);
    }
    SCOPED_TRACE("case " + std::to_string(k) + ": " + std::to_string(na) + " x " +
                 std::to_string(nb) + " pieces");
    const CompoundResult r = distance(a, pose_a, b, pose_b);
    check_against_twin(a, pose_a, b, pose_b, r, twin);
    if (twin.status == Status::intersecting) {
      ++intersecting;
    } else if (twin.distance <= 1e-3) {
      ++near_touching;
    } else {
      ++separated;
    }
  }
  std::printf("[ compound ] intersecting %d, near touching %d, separated %d, >= 100 pieces %d\n",
              intersecting, near_touching, separated, many_pieces);
  EXPECT_GE(intersecting, count(120) / 10);
  EXPECT_GE(near_touching, count(120) / 10);
  EXPECT_GE(separated, count(120) / 10);
  EXPECT_GE(many_pieces, count(120) / 20);
}

// Pieces that overlap each other inside each body, bodies interpenetrating
// or just apart: many pairs at nearly the same distance, and many
// intersecting pairs.
TEST(Compound, OverlappingPiecesWithinOneBody) {
  Rng rng(303);
  for (int k = 0; k < count(40); ++k) {
    const CompoundBody a = random_compound(rng, test::uniform_int(rng, 2, 30), 0.3);
    const CompoundBody b = random_compound(rng, test::uniform_int(rng, 2, 30), 0.3);
    const Pose pose_a = random_pose(rng, 0.5);
    const Pose pose_b = random_pose(rng, test::uniform(rng, 0.5, 4.0));
    SCOPED_TRACE("case " + std::to_string(k));
    check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b),
                       distance_all_pairs(a, pose_a, b, pose_b));
  }
}

// The options reach every convex query: each algorithm's compound answer
// agrees with the twin run with the same options, tracked or cold.
TEST(Compound, EveryAlgorithmAgreesWithItsTwin) {
  Rng rng(350);
  for (const Algorithm algorithm : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    SCOPED_TRACE(to_string(algorithm));
    DistanceOptions options;
    options.algorithm = algorithm;
    for (int k = 0; k < count(10); ++k) {
      const CompoundBody a = random_compound(rng, test::uniform_int(rng, 1, 30), 2.0);
      const CompoundBody b = random_compound(rng, test::uniform_int(rng, 1, 30), 2.0);
      const Pose pose_a = random_pose(rng, 1.0);
      Pose pose_b = random_pose(rng, 1.0);
      pose_b.translation +=
          (a.bounding_radius() + b.bounding_radius()) * 0.8 * test::random_unit_vector(rng);
      CompoundCache cache;
      for (int step = 0; step < 3; ++step) {
        pose_b.translation += 0.05 * test::random_unit_vector(rng);
        const CompoundResult twin = distance_all_pairs(a, pose_a, b, pose_b, options);
        SCOPED_TRACE("case " + std::to_string(k) + " step " + std::to_string(step));
        check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b, options, &cache),
                           twin);
        check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b, options), twin);
      }
    }
  }
}

// Far from the origin, tiny and huge: the standard scales with R, and the
// pruning's slack must scale with it too (a pruned pair must never hide a
// closer one by more than 64 u R). Scales stop at 1e150 and 1e-150: beyond
// them the convex query itself fails (measured: FE_INVALID from about 1e155
// on, its squares overflowing, and "touching at 0" for bodies a unit of
// their size apart from about 1e-200 down, its squares underflowing).
TEST(Compound, ScalesAndFarFromTheOrigin) {
  Rng rng(test::test_seed(404));
  struct Setting {
    double size;
    double offset;
  };
  for (const Setting s :
       {Setting{1.0, 1e6}, Setting{1e-20, 0.0}, Setting{1e20, 0.0}, Setting{1e-3, 1e6},
        Setting{1e-30, 1e-25}, Setting{1e30, 1e35}, Setting{1e150, 0.0}, Setting{1e-150, 0.0}}) {
    SCOPED_TRACE("size " + std::to_string(s.size) + " offset " + std::to_string(s.offset));
    int near = 0;
    for (int k = 0; k < count(16); ++k) {
      const int na = test::uniform_int(rng, 1, 40);
      const int nb = test::uniform_int(rng, 1, 40);
      const CompoundBody a = random_compound(rng, na, 2.0 * s.size, s.size);
      const CompoundBody b = random_compound(rng, nb, 2.0 * s.size, s.size);
      const Vec3 far = s.offset * test::random_unit_vector(rng);
      Pose pose_a = random_pose(rng, s.size);
      pose_a.translation += far;
      Pose pose_b = random_pose(rng, s.size);
      // The direction first, then the factor: the order gcc evaluated the
      // expression these draws replace in, on which the seed's cases were
      // chosen.
      const Vec3 direction = test::random_unit_vector(rng);
      const double factor = test::uniform(rng, 0.5, 1.2);
      const double reach = a.bounding_radius() + b.bounding_radius();
      if (k % 2 == 1) {
        // Apart by about the bounding spheres: mostly separated, some
        // intersecting.
        pose_b.translation += far + factor * reach * direction;
      } else {
        // To be moved to near touching: separated, the bounding spheres
        // apart by 2% to 16% of the sum of their radii along `direction`
        // (when their origins were placed at random instead, the first
        // case of a setting, the only even one under the sanitizers'
        // count, often overlapped and no case of the setting came near).
        pose_b.translation = pose_a.apply(a.center()) - pose_b.rotation * b.center() +
                             (1.0 + 0.2 * (factor - 0.4)) * reach * direction;
      }
      CompoundResult twin = distance_all_pairs(a, pose_a, b, pose_b);
      if (k % 2 == 0) {
        ASSERT_EQ(twin.status, Status::separated);
        pose_b = closer_to(twin, pose_b, s.size * test::log_uniform(rng, 1e-9, 1e-3));
        twin = distance_all_pairs(a, pose_a, b, pose_b);
        near += twin.distance <= 1e-3 * s.size;
      }
      SCOPED_TRACE("case " + std::to_string(k));
      check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b), twin);
    }
    EXPECT_GE(near, 1);
  }
}

// Tracking: a sequence of small motions with one cache answers as the cold
// queries do and tests fewer piece pairs on average: the cached best pair
// gives a tight upper bound before the traversal starts.
TEST(Compound, TrackingAgreesWithColdAndTestsFewerPairs) {
  Rng rng(505);
  long long warm_pairs = 0;
  long long cold_pairs = 0;
  for (int k = 0; k < count(12); ++k) {
    const CompoundBody a = random_compound(rng, test::uniform_int(rng, 20, 120), 6.0);
    const CompoundBody b = random_compound(rng, test::uniform_int(rng, 20, 120), 6.0);
    Pose pose_a = random_pose(rng, 1.0);
    Pose pose_b = random_pose(rng, 1.0);
    pose_b.translation +=
        (a.bounding_radius() + b.bounding_radius()) * 0.9 * test::random_unit_vector(rng);
    CompoundCache cache;
    const Vec3 drift = 0.02 * test::random_unit_vector(rng);
    for (int step = 0; step < 30; ++step) {
      pose_b.translation += drift + 0.005 * test::random_unit_vector(rng);
      pose_b.rotation = test::random_small_rotation(rng, 0.01) * pose_b.rotation;
      pose_a.rotation = test::random_small_rotation(rng, 0.005) * pose_a.rotation;
      const CompoundResult warm = distance(a, pose_a, b, pose_b, {}, &cache);
      const CompoundResult cold = distance(a, pose_a, b, pose_b);
      SCOPED_TRACE("case " + std::to_string(k) + " step " + std::to_string(step));
      EXPECT_NEAR(warm.distance, cold.distance, tolerance(a, pose_a, b, pose_b, cold.distance));
      EXPECT_EQ(warm.status == Status::intersecting, cold.status == Status::intersecting);
      EXPECT_LE(cache.near.size(), 64u);
      EXPECT_TRUE(
          std::is_sorted(cache.near.begin(), cache.near.end(), [](const auto& x, const auto& y) {
            return std::pair(x.piece_a, x.piece_b) < std::pair(y.piece_a, y.piece_b);
          }));
      if (step > 0) {
        warm_pairs += warm.pairs_tested;
        cold_pairs += cold.pairs_tested;
      }
      if (step % 10 == 0)
        check_against_twin(a, pose_a, b, pose_b, warm, distance_all_pairs(a, pose_a, b, pose_b));
    }
  }
  std::printf("[ compound ] tracked pairs tested %lld, cold %lld\n", warm_pairs, cold_pairs);
  EXPECT_LT(warm_pairs, cold_pairs);
}

// A cache from another pair of bodies (piece indices out of range, or in
// range but meaning other pieces) and outright garbage never change an
// answer beyond the standard.
TEST(Compound, ForeignAndGarbageCachesAreHarmless) {
  Rng rng(606);
  for (int k = 0; k < count(30); ++k) {
    const CompoundBody a = random_compound(rng, test::uniform_int(rng, 1, 40), 3.0);
    const CompoundBody b = random_compound(rng, test::uniform_int(rng, 1, 40), 3.0);
    const CompoundBody big_a = random_compound(rng, 80, 8.0);
    const CompoundBody big_b = random_compound(rng, 80, 8.0);
    const Pose pose_a = random_pose(rng, 1.0);
    const Pose pose_b = random_pose(rng, 6.0);
    // A cache earned on two other, larger bodies.
    CompoundCache foreign;
    distance(big_a, random_pose(rng, 1.0), big_b, random_pose(rng, 10.0), {}, &foreign);
    distance(big_a, random_pose(rng, 1.0), big_b, random_pose(rng, 10.0), {}, &foreign);
    // And garbage: indices out of range both ways, an unsorted near list,
    // feature caches with ids past the hulls' ends.
    CompoundCache garbage;
    garbage.piece_a = test::uniform_int(rng, -5, 200);
    garbage.piece_b = test::uniform_int(rng, -5, 200);
    for (int e = 0; e < 20; ++e) {
      CompoundCache::Entry entry;
      entry.piece_a = test::uniform_int(rng, -3, 50);
      entry.piece_b = test::uniform_int(rng, -3, 50);
      for (int v = 0; v < 4; ++v) {
        entry.cache.vertices_a[static_cast<std::size_t>(v)] = test::uniform_int(rng, -2, 1000);
        entry.cache.vertices_b[static_cast<std::size_t>(v)] = test::uniform_int(rng, -2, 1000);
      }
      entry.cache.hint_a = test::uniform_int(rng, -2, 1000);
      entry.cache.hint_b = test::uniform_int(rng, -2, 1000);
      entry.cache.face_a = test::uniform_int(rng, -2, 1000);
      entry.cache.face_b = test::uniform_int(rng, -2, 1000);
      garbage.near.push_back(entry);
    }
    if (k % 2 == 0) {
      std::sort(garbage.near.begin(), garbage.near.end(), [](const auto& x, const auto& y) {
        return std::pair(x.piece_a, x.piece_b) < std::pair(y.piece_a, y.piece_b);
      });
    }
    const CompoundResult twin = distance_all_pairs(a, pose_a, b, pose_b);
    SCOPED_TRACE("case " + std::to_string(k));
    check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b, {}, &foreign), twin);
    check_against_twin(a, pose_a, b, pose_b, distance(a, pose_a, b, pose_b, {}, &garbage), twin);
    // After one query the caches hold only valid pairs of these bodies.
    for (const CompoundCache* c : {&foreign, &garbage}) {
      EXPECT_GE(c->piece_a, 0);
      EXPECT_LT(c->piece_a, a.piece_count());
      for (const auto& e : c->near) {
        EXPECT_LT(e.piece_a, a.piece_count());
        EXPECT_LT(e.piece_b, b.piece_count());
      }
    }
  }
}

TEST(Compound, IntersectingBodiesStopEarly) {
  Rng rng(707);
  for (int k = 0; k < count(20); ++k) {
    const CompoundBody a = random_compound(rng, test::uniform_int(rng, 5, 60), 3.0);
    const CompoundBody b = random_compound(rng, test::uniform_int(rng, 5, 60), 3.0);
    const Pose pose_a = random_pose(rng, 0.1);
    const Pose pose_b = random_pose(rng, 0.1);
    const CompoundResult twin = distance_all_pairs(a, pose_a, b, pose_b);
    const CompoundResult r = distance(a, pose_a, b, pose_b);
    SCOPED_TRACE("case " + std::to_string(k));
    if (twin.status != Status::intersecting) continue;
    EXPECT_EQ(r.status, Status::intersecting);
    EXPECT_EQ(r.distance, 0.0);
    // The reported pair itself intersects.
    const CompoundPiece& pa = a.piece(r.piece_a);
    const CompoundPiece& pb = b.piece(r.piece_b);
    EXPECT_EQ(distance(*pa.polytope, pose_a * pa.pose, *pb.polytope, pose_b * pb.pose).status,
              Status::intersecting);
    EXPECT_LT(r.pairs_tested, a.piece_count() * b.piece_count());
  }
}

// Spread-out compounds (pieces along a 10 x 10 grid, bodies side by side):
// the branch and bound tests a small fraction of the pairs. Measured:
// a few dozen of 10000 (see the printed figure); the bound has ample margin.
TEST(Compound, PruningPrunes) {
  Rng rng(808);
  const auto grid_body = [&](double spacing) {
    std::vector<CompoundPiece> pieces;
    for (int i = 0; i < 10; ++i) {
      for (int j = 0; j < 10; ++j) {
        pieces.push_back(
            {std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 12, 0.4)),
             Pose::from_translation(Vec3(spacing * i, spacing * j, 0.0))});
      }
    }
    return CompoundBody(std::move(pieces));
  };
  const CompoundBody a = grid_body(1.0);
  const CompoundBody b = grid_body(1.0);
  int worst = 0;
  long long total = 0;
  for (int k = 0; k < count(20); ++k) {
    Pose pose_b = random_pose(rng, 2.0);
    pose_b.translation += Vec3(4.5, 4.5, test::uniform(rng, 8.0, 12.0));
    const CompoundResult r = distance(a, Pose::identity(), b, pose_b);
    worst = std::max(worst, r.pairs_tested);
    total += r.pairs_tested;
    if (k < count(3))
      check_against_twin(a, Pose::identity(), b, pose_b, r,
                         distance_all_pairs(a, Pose::identity(), b, pose_b));
  }
  std::printf("[ compound ] pruning: pairs tested worst %d, mean %.1f of 10000\n", worst,
              static_cast<double>(total) / count(20));
  EXPECT_LE(worst, 500);
}

// Every vertex of every piece lies in its piece sphere and in the sphere of
// each ancestor; leaves partition the pieces; piece_order is a permutation;
// a binary tree over n single-piece leaves has 2n - 1 nodes. Also at the
// ends of the double range (the build scales its norms; the test divides by
// the power-of-two scale, exactly, before squaring).
TEST(Compound, HierarchyInvariants) {
  Rng rng(909);
  for (const double scale : {1.0, 0x1p-1000, 0x1p1000}) {
    for (const int n : {1, 2, 3, 7, 64, count(200)}) {
      SCOPED_TRACE("pieces " + std::to_string(n) + " scale 2^" + std::to_string(std::log2(scale)));
      const CompoundBody body = random_compound(rng, n, 5.0 * scale, scale);
      const auto dist = [scale](const Vec3& p, const Vec3& q) {
        return (p / scale - q / scale).norm() * scale;
      };
      std::vector<int> seen(static_cast<std::size_t>(n), 0);
      const auto order = body.piece_order();
      ASSERT_EQ(order.size(), static_cast<std::size_t>(n));
      for (const std::int32_t p : order) {
        ASSERT_GE(p, 0);
        ASSERT_LT(p, n);
        ++seen[static_cast<std::size_t>(p)];
      }
      EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
      EXPECT_EQ(body.nodes().size(), static_cast<std::size_t>(2 * n - 1));
      std::vector<int> in_leaf(static_cast<std::size_t>(n), 0);
      std::vector<std::int32_t> ancestors;
      const auto visit = [&](auto&& self, std::int32_t id) -> void {
        const CompoundBody::Node& node = body.nodes()[static_cast<std::size_t>(id)];
        ancestors.push_back(id);
        if (node.left < 0) {
          EXPECT_GE(node.count, 1);
          for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
            const std::int32_t p = order[static_cast<std::size_t>(i)];
            ++in_leaf[static_cast<std::size_t>(p)];
            const CompoundPiece& piece = body.piece(p);
            const auto& sphere = body.piece_sphere(p);
            for (const Vec3& v : piece.polytope->vertices()) {
              const Vec3 placed = piece.pose.apply(v);
              EXPECT_LE(dist(placed, sphere.center), sphere.radius);
              for (const std::int32_t anc : ancestors) {
                const CompoundBody::Node& up = body.nodes()[static_cast<std::size_t>(anc)];
                EXPECT_LE(dist(placed, up.center), up.radius) << "node " << anc << " piece " << p;
              }
            }
            // The piece sphere itself inside each ancestor (what the pruning uses).
            for (const std::int32_t anc : ancestors) {
              const CompoundBody::Node& up = body.nodes()[static_cast<std::size_t>(anc)];
              EXPECT_LE(dist(sphere.center, up.center) + sphere.radius, up.radius * (1 + 1e-15));
            }
          }
        } else {
          EXPECT_EQ(node.count, 0);
          self(self, node.left);
          self(self, node.right);
        }
        ancestors.pop_back();
      };
      visit(visit, 0);
      EXPECT_TRUE(std::all_of(in_leaf.begin(), in_leaf.end(), [](int c) { return c == 1; }));
      EXPECT_EQ(body.center(), body.nodes()[0].center);
      // scale() is the largest coordinate of a placed vertex.
      EXPECT_EQ(body.scale(), world_magnitude(body, Pose::identity()));
    }
  }
}

TEST(Compound, MemoryCountsSharedPolytopesOnce) {
  Rng rng(1010);
  const auto shared = std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 50));
  const auto other = std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 50));
  const CompoundBody one({{shared, Pose::identity()}});
  const CompoundBody three({{shared, Pose::identity()},
                            {shared, Pose::from_translation(Vec3(3, 0, 0))},
                            {other, Pose::from_translation(Vec3(6, 0, 0))}});
  EXPECT_GT(one.memory_bytes(), shared->memory_bytes());
  EXPECT_LT(three.memory_bytes(),
            one.memory_bytes() + shared->memory_bytes() + other->memory_bytes() + 4096);
  EXPECT_GE(three.memory_bytes(), shared->memory_bytes() + other->memory_bytes());
}

std::string message_of(const auto& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(Compound, BadInputNamesThePiece) {
  Rng rng(1111);
  const auto poly = std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 10));
  const auto body_with = [&](int bad, const CompoundPiece& piece) {
    std::vector<CompoundPiece> pieces(5, CompoundPiece{poly, Pose::identity()});
    pieces[static_cast<std::size_t>(bad)] = piece;
    return [pieces] { CompoundBody body(pieces); };
  };
  EXPECT_NE(message_of([] { CompoundBody body(std::vector<CompoundPiece>{}); }).find("no pieces"),
            std::string::npos);
  EXPECT_NE(message_of(body_with(2, {nullptr, Pose::identity()})).find("piece 2: null polytope"),
            std::string::npos);
  Pose nan_pose;
  nan_pose.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message_of(body_with(3, {poly, nan_pose})).find("piece 3: pose is not finite"),
            std::string::npos);
  Pose inf_pose;
  inf_pose.rotation(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_NE(message_of(body_with(0, {poly, inf_pose})).find("piece 0: pose is not finite"),
            std::string::npos);
  const Pose scaled_pose(Mat3(Mat3::Identity() * 1.001), Vec3::Zero());
  EXPECT_NE(message_of(body_with(1, {poly, scaled_pose}))
                .find("piece 1: pose: rotation is not orthonormal"),
            std::string::npos);
  const Pose mirror(Mat3(Eigen::Vector3d(1, 1, -1).asDiagonal()), Vec3::Zero());
  EXPECT_NE(message_of(body_with(4, {poly, mirror})).find("piece 4: pose: rotation is a reflection"),
            std::string::npos);
  const Pose overflow = Pose::from_translation(Vec3(1.7e308, 0, 0));
  const auto huge =
      std::make_shared<const ConvexPolytope>(test::scaled(test::points_on_sphere(rng, 10), 1e308));
  EXPECT_NE(message_of(body_with(1, {huge, overflow})).find("piece 1: placed vertex overflows"),
            std::string::npos);

  std::vector<Points> sets = {test::cube(1.0), test::cube(2.0), Points{}, test::cube(3.0)};
  EXPECT_NE(message_of([&] { CompoundBody::from_point_sets(sets); }).find("piece 2: "),
            std::string::npos);
  sets[2] = {Vec3(0, 0, 0), Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)};
  EXPECT_NE(message_of([&] { CompoundBody::from_point_sets(sets); }).find("piece 2: "),
            std::string::npos);

  const CompoundBody good =
      CompoundBody::from_point_sets(std::vector<Points>{test::cube(1.0), test::cube(2.0)});
  EXPECT_EQ(good.piece_count(), 2);
  EXPECT_NE(message_of([&] { distance(good, nan_pose, good, Pose::identity()); }).find("pose_a"),
            std::string::npos);
  EXPECT_NE(message_of([&] { distance(good, Pose::identity(), good, inf_pose); }).find("pose_b"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              distance_all_pairs(good, nan_pose, good, Pose::identity());
            }).find("pose_a"),
            std::string::npos);
  DistanceOptions bad_options;
  bad_options.max_iterations = 0;
  EXPECT_NE(message_of([&] {
              distance(good, Pose::identity(), good, Pose::identity(), bad_options);
            }).find("max_iterations"),
            std::string::npos);
}

// Regression (issue 24): the compound's lower bound was the best pair's own
// certificate, not one over the whole search. Capped at one iteration, the
// pair of piece 0 stopped with a loose answer (an upper bound above the
// point piece's distance) and a lower bound below it; the point piece's pair
// won with its exact distance 3.8715 as the lower bound, above the true
// distance 3.7076 of piece 0. The certificate must cover every tested pair:
// the least of their lower bounds. Found by a seeded search against
// distance_all_pairs at the default options.
TEST(CompoundRegression, LowerBoundCoversALooselyCertifiedPair) {
  const CompoundBody a = CompoundBody::from_point_sets(std::vector<Points>{
      {Vec3(-6.08, -6.6, -0.07), Vec3(-1.26, 1.25, -0.5), Vec3(-1.85, -2.13, -0.56),
       Vec3(-1.83, 1.06, -0.24)},
      {Vec3(-4.19, -3.59, 0.7)}});
  const CompoundBody b = CompoundBody::from_point_sets(std::vector<Points>{{Vec3(-0.16, -0.66, 0.84)}});
  const Pose pose_b = Pose::from_translation(Vec3(-0.77, -4.54, 1.19));
  const CompoundResult exact = distance_all_pairs(a, Pose::identity(), b, pose_b);
  ASSERT_EQ(exact.status, Status::separated);
  const double band = kBandUlps * kUnitRoundoff * 8.0;
  DistanceOptions capped;
  capped.max_iterations = 1;
  for (const bool twin : {false, true}) {
    SCOPED_TRACE(twin ? "distance_all_pairs" : "distance");
    const CompoundResult r = twin ? distance_all_pairs(a, Pose::identity(), b, pose_b, capped)
                                  : distance(a, Pose::identity(), b, pose_b, capped);
    EXPECT_LE(r.lower_bound, exact.distance + band);
    EXPECT_LE(r.signed_lower_bound(), exact.signed_distance() + band);
    EXPECT_GE(r.distance, exact.distance - band);  // an upper bound all the same
  }
}

}  // namespace
}  // namespace proxima
