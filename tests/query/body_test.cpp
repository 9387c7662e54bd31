// Tests of bodies with a radius and of the primitives (body.h,
// primitives.h): closed forms (sphere-sphere, capsule-capsule as segments
// minus radii, axis-aligned boxes), seeded random rounded hulls against the
// exact convex oracle offset by the radii, overlapping rounded bodies
// (cores apart: signed = d - ra - rb; cores overlapping: minus the exact
// penetration depth minus the radii), compounds and mixed kinds against
// their convex pieces, tracking against cold, the cylinder's and cone's
// stated deviation against samples of the true surfaces, and the refusals
// of bad radii and tolerances.
#include "proxima/query/body_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "proxima/shape/primitives.h"
#include "support/exact_oracle.h"
#include "support/generators.h"
#include "support/penetration_oracle.h"
#include "support/sanitizers.h"

namespace proxima {
namespace {

using test::Points;
using test::Rng;

constexpr int count(int n) { return test::sanitized_count(n, 4); }

constexpr double kBand = 64.0 * kUnitRoundoff;

std::shared_ptr<const ConvexPolytope> hull(const Points& points) {
  return std::make_shared<const ConvexPolytope>(points);
}

// The accuracy standard's bound for a value of size d among coordinates of
// magnitude R.
double bound(double d, double magnitude) { return 1e-12 * std::abs(d) + kBand * magnitude; }

// Checks what every answer must hold: |point_a - point_b| = |signed|,
// point_b - point_a along the normal with the sign of signed, distance and
// lower bound from the signed values, the bounds around the value.
void expect_consistent(const BodyResult& r, double magnitude) {
  const double tol = bound(r.signed_distance(), magnitude);
  EXPECT_NEAR((r.point_b - r.point_a).norm(), std::abs(r.signed_distance()), tol);
  EXPECT_NEAR((r.point_b - r.point_a - r.signed_distance() * r.normal).norm(), 0.0, tol);
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
  EXPECT_EQ(r.distance, std::max(r.signed_distance(), 0.0));
  EXPECT_LE(r.signed_lower_bound(), r.signed_distance() + tol);
  EXPECT_GE(r.signed_upper_bound(), r.signed_distance() - tol);
  EXPECT_LE(r.lower_bound, r.distance + tol);
}

// --- Closed forms -------------------------------------------------------------

TEST(BodyClosedForm, SphereSphere) {
  Rng rng(11);
  for (int i = 0; i < count(200); ++i) {
    const double ra = test::log_uniform(rng, 1e-3, 10.0);
    const double rb = test::log_uniform(rng, 1e-3, 10.0);
    const Vec3 ca = test::drawn([&] { return test::uniform(rng, -5, 5); });
    const Vec3 cb = test::drawn([&] { return test::uniform(rng, -5, 5); });
    const Body a = make_sphere(ra);
    const Body b = make_sphere(rb);
    // A rotation of a sphere changes nothing.
    const Pose pa(test::random_quaternion(rng), ca);
    const Pose pb(test::random_quaternion(rng), cb);
    const BodyResult r = distance(a, pa, b, pb);
    const double exact = (cb - ca).norm() - ra - rb;
    const double magnitude = std::max(ca.cwiseAbs().maxCoeff() + ra, cb.cwiseAbs().maxCoeff() + rb);
    EXPECT_NEAR(r.signed_distance(), exact, bound(exact, magnitude)) << i;
    EXPECT_EQ(r.status, exact > 0 ? Status::separated : Status::intersecting) << i;
    EXPECT_FALSE(r.intersecting);
    const Vec3 n = (cb - ca).normalized();
    EXPECT_NEAR((r.normal - n).norm(), 0.0, 1e-12);
    EXPECT_NEAR((r.point_a - (ca + ra * n)).norm(), 0.0, bound(0, magnitude));
    EXPECT_NEAR((r.point_b - (cb - rb * n)).norm(), 0.0, bound(0, magnitude));
    expect_consistent(r, magnitude);
  }
}

TEST(BodyClosedForm, ConcentricSpheresOverlapByTheirRadii) {
  // The cores are one point: touching at distance 0, no direction from the
  // closest points; the penetration query supplies a normal.
  const BodyResult r = distance(make_sphere(1.0), Pose::identity(), make_sphere(0.5),
                                  Pose::from_translation(Vec3::Zero()));
  EXPECT_EQ(r.status, Status::intersecting);
  EXPECT_DOUBLE_EQ(r.signed_distance(), -1.5);
  EXPECT_EQ(r.distance, 0.0);
  expect_consistent(r, 1.0);
}

// Closed form of the distance between segments p0 + s u and q0 + t v
// (s, t in [0, 1]): the stationary point of |P(s) - Q(t)|^2 when it lies
// inside the square, else the least of the four endpoint-to-segment
// distances (the minimum of a convex function over the square is on its
// boundary when the stationary point is outside).
double point_segment(const Vec3& x, const Vec3& p0, const Vec3& u) {
  const double t = std::clamp((x - p0).dot(u) / u.squaredNorm(), 0.0, 1.0);
  return (p0 + t * u - x).norm();
}
double segment_segment(const Vec3& p0, const Vec3& u, const Vec3& q0, const Vec3& v) {
  const Vec3 w = p0 - q0;
  const double a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  const double det = a * c - b * b;
  if (det > 1e-9 * a * c) {
    const double s = (b * e - c * d) / det;
    const double t = (a * e - b * d) / det;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) return (w + s * u - t * v).norm();
  }
  return std::min({point_segment(p0, q0, v), point_segment(p0 + u, q0, v), point_segment(q0, p0, u),
                   point_segment(q0 + v, p0, u)});
}

TEST(BodyClosedForm, CapsuleCapsuleIsSegmentsMinusRadii) {
  Rng rng(12);
  int overlapping = 0, separated = 0;
  for (int i = 0; i < count(300); ++i) {
    const double ha = test::uniform(rng, 0.1, 2.0), hb = test::uniform(rng, 0.1, 2.0);
    const double ra = test::uniform(rng, 0.01, 0.8), rb = test::uniform(rng, 0.01, 0.8);
    // Each translation first, the order gcc gives the call (see drawn()).
    const auto spread = [&] { return test::uniform(rng, -2, 2); };
    const Vec3 at_a = test::drawn(spread, spread, [] { return 0.0; });
    const Pose pa(test::random_quaternion(rng), at_a);
    const Vec3 at_b = test::drawn(spread, spread, [] { return 1.0; });
    const Pose pb(test::random_quaternion(rng), at_b);
    const Vec3 a0 = pa.apply(Vec3(0, 0, -ha)), a1 = pa.apply(Vec3(0, 0, ha));
    const Vec3 b0 = pb.apply(Vec3(0, 0, -hb)), b1 = pb.apply(Vec3(0, 0, hb));
    const double core = segment_segment(a0, a1 - a0, b0, b1 - b0);
    const BodyResult r = distance(make_capsule(ha, ra), pa, make_capsule(hb, rb), pb);
    if (core <= 1e-9) continue;  // crossing cores: the depth cases below
    const double exact = core - ra - rb;
    EXPECT_NEAR(r.signed_distance(), exact, 1e-9) << i;
    EXPECT_EQ(r.status, exact > 0 ? Status::separated : Status::intersecting) << i;
    (exact > 0 ? separated : overlapping)++;
    expect_consistent(r, 6.0);
  }
  // The set holds both kinds.
  EXPECT_GT(overlapping, count(300) / 10);
  EXPECT_GT(separated, count(300) / 10);
}

TEST(BodyClosedForm, AxisAlignedBoxes) {
  Rng rng(13);
  for (int i = 0; i < count(300); ++i) {
    const Vec3 ha = test::drawn([&] { return test::uniform(rng, 0, 2); });
    const Vec3 hb = test::drawn([&] { return test::uniform(rng, 0, 2); });
    const double ra = i % 2 ? test::uniform(rng, 0, 0.5) : 0.0;
    const double rb = i % 3 ? test::uniform(rng, 0, 0.5) : 0.0;
    const Vec3 c = test::drawn([&] { return test::uniform(rng, -6, 6); });
    // Per axis the gap between the intervals [-ha, ha] and c + [-hb, hb].
    Vec3 gap;
    for (int k = 0; k < 3; ++k) gap[k] = std::max(0.0, std::abs(c[k]) - ha[k] - hb[k]);
    if (gap.norm() == 0.0) continue;  // overlapping cores: the depth cases below
    const double exact = gap.norm() - ra - rb;
    const BodyResult r =
        distance(make_box(ha, ra), Pose::identity(), make_box(hb, rb), Pose::from_translation(c));
    EXPECT_NEAR(r.signed_distance(), exact, bound(exact, 9.0)) << i;
    expect_consistent(r, 9.0);
  }
}

// --- Random rounded hulls against the exact oracle --------------------------

TEST(BodyOracle, RoundedHullsAreTheConvexOracleOffsetByTheRadii) {
  Rng rng(14);
  test::ExactOracle oracle;
  int overlapping = 0, separated = 0, checked = 0;
  for (int i = 0; i < count(120); ++i) {
    const Points a = test::points_on_sphere(rng, test::uniform_int(rng, 4, 30));
    Points b = test::points_in_cube(rng, test::uniform_int(rng, 4, 30));
    b = test::translated(b, 2.5 * test::random_unit_vector(rng));
    const double ra = i % 4 == 0 ? 0.0 : test::uniform(rng, 0.0, 0.6);
    const double rb = i % 5 == 0 ? 0.0 : test::uniform(rng, 0.0, 0.6);
    const auto exact = oracle.distance(a, b);
    ASSERT_TRUE(exact) << oracle.last_error();
    if (exact->is_zero()) continue;
    ++checked;
    const double d = exact->distance();
    const BodyResult r =
        distance(Body(hull(a), ra), Pose::identity(), Body(hull(b), rb), Pose::identity());
    const double magnitude =
        std::max(test::max_abs_coordinate(a) + ra, test::max_abs_coordinate(b) + rb);
    EXPECT_NEAR(r.signed_distance(), d - ra - rb, bound(d, magnitude)) << i;
    EXPECT_FALSE(r.intersecting);
    expect_consistent(r, magnitude);
    // The points lie on the rounded bodies: within the radius of the core.
    const auto da = oracle.point_distance_squared(r.point_a, a);
    const auto db = oracle.point_distance_squared(r.point_b, b);
    ASSERT_TRUE(da && db);
    EXPECT_LE(test::sqrt_to_double(*da), ra + bound(ra, magnitude)) << i;
    EXPECT_LE(test::sqrt_to_double(*db), rb + bound(rb, magnitude)) << i;
    (d - ra - rb > 0 ? separated : overlapping)++;
  }
  EXPECT_GT(overlapping, checked / 10);
  EXPECT_GT(separated, checked / 10);
}

TEST(BodyOracle, PosesMoveTheRoundedBodiesAsTheirCores) {
  Rng rng(15);
  for (int i = 0; i < count(100); ++i) {
    const Points a = test::points_on_sphere(rng, 20);
    const Points b = test::points_in_cube(rng, 20);
    const Pose pa(test::random_quaternion(rng), 3.0 * test::random_unit_vector(rng));
    const Pose pb(test::random_quaternion(rng), 3.0 * test::random_unit_vector(rng));
    const double ra = test::uniform(rng, 0, 1), rb = test::uniform(rng, 0, 1);
    const BodyResult r = distance(Body(hull(a), ra), pa, Body(hull(b), rb), pb);
    const DistanceResult core = distance(*hull(a), pa, *hull(b), pb);
    if (core.status != Status::separated) continue;
    EXPECT_NEAR(r.signed_distance(), core.distance - ra - rb, 1e-13) << i;
    EXPECT_NEAR(r.signed_lower_bound(), core.lower_bound - ra - rb, 1e-13) << i;
    EXPECT_NEAR((r.point_a - (core.point_a + ra * core.normal)).norm(), 0.0, 1e-13);
    EXPECT_NEAR((r.point_b - (core.point_b - rb * core.normal)).norm(), 0.0, 1e-13);
    EXPECT_EQ(r.feature_a.vertices, core.feature_a.vertices);
    EXPECT_EQ(r.feature_b.vertices, core.feature_b.vertices);
  }
}

TEST(BodyOracle, OverlappingCoresGiveMinusTheExactDepthMinusTheRadii) {
  Rng rng(16);
  int deep = 0;
  for (int i = 0; i < count(60); ++i) {
    const Points a = test::points_on_sphere(rng, test::uniform_int(rng, 4, 16));
    const Points b = test::translated(test::points_in_cube(rng, test::uniform_int(rng, 4, 16)),
                                      test::uniform(rng, 0.0, 1.5) * test::random_unit_vector(rng));
    const test::ExactDepth exact = test::exact_depth(a, b);
    if (exact.origin != test::OriginInM::inside || exact.flat) continue;
    const double ra = i % 3 == 0 ? 0.0 : test::uniform(rng, 0.0, 0.4);
    const double rb = test::uniform(rng, 0.0, 0.4);
    BodyCache cache;
    const BodyResult r = distance(Body(hull(a), ra), Pose::identity(), Body(hull(b), rb),
                                    Pose::identity(), {}, &cache);
    const double depth = exact.depth();
    EXPECT_EQ(r.status, Status::intersecting) << i;
    EXPECT_TRUE(r.intersecting) << i;
    EXPECT_NEAR(r.signed_distance(), -depth - ra - rb, bound(depth, 2.5)) << i;
    EXPECT_LE(r.signed_lower_bound(), -depth - ra - rb + bound(depth, 2.5)) << i;
    EXPECT_GE(r.signed_upper_bound(), -depth - ra - rb - bound(depth, 2.5)) << i;
    expect_consistent(r, 2.5);
    // Translating B by -signed along the normal makes the rounded bodies
    // touch: the cores are then ra + rb apart.
    const Points moved = test::translated(b, -r.signed_distance() * r.normal);
    const DistanceResult after =
        distance(*hull(a), Pose::identity(), *hull(moved), Pose::identity());
    EXPECT_NEAR(after.distance, ra + rb, 1e-9) << i;
    ++deep;
  }
  EXPECT_GT(deep, count(60) / 4);
}

TEST(BodyOracle, TouchingCoresTakeTheNormalOfTheirContact) {
  // Cores in exact contact (distance 0, no gap to certify a direction):
  // the distance query's normal is whatever direction it last held, and
  // the rounded bodies' overlap must come from the contact's own normal.
  // Translating B by -signed * normal must make the rounded bodies touch.
  Rng rng(21);
  int cases = 0;
  for (int i = 0; i < count(40); ++i) {
    const Vec3 ha = test::drawn([&] { return test::uniform(rng, 0.5, 1.5); });
    const Vec3 hb = test::drawn([&] { return test::uniform(rng, 0.5, 1.5); });
    const int axis = i % 3;
    // Face to face along `axis`, offset sideways by a quarter: the contact
    // is a rectangle.
    Vec3 c = Vec3::Zero();
    c[axis] = ha[axis] + hb[axis];
    c[(axis + 1) % 3] = 0.25;
    const double ra = 0.1, rb = 0.2;
    const BodyResult r =
        distance(make_box(ha, ra), Pose::identity(), make_box(hb, rb), Pose::from_translation(c));
    EXPECT_EQ(r.status, Status::intersecting) << i;
    EXPECT_NEAR(r.signed_distance(), -ra - rb, 1e-14) << i;
    EXPECT_NEAR(std::abs(r.normal[axis]), 1.0, 1e-14) << i;
    const DistanceResult after =
        distance(*make_box(ha).convex(), Pose::identity(), *make_box(hb).convex(),
                 Pose::from_translation(c - r.signed_distance() * r.normal));
    EXPECT_NEAR(after.distance, ra + rb, 1e-14) << i;
    ++cases;
  }
  EXPECT_GT(cases, 0);
}

// --- Compounds and mixed kinds ------------------------------------------------

std::shared_ptr<const CompoundBody> two_boxes() {
  std::vector<CompoundPiece> pieces;
  pieces.push_back({make_box(Vec3(1, 1, 1)).convex(), Pose::from_translation(Vec3(-2, 0, 0))});
  pieces.push_back({make_box(Vec3(0.5, 0.5, 0.5)).convex(), Pose::from_translation(Vec3(2, 0, 0))});
  return std::make_shared<const CompoundBody>(std::move(pieces));
}

TEST(BodyCompound, RoundedCompoundIsItsClosestRoundedPiece) {
  Rng rng(17);
  const auto compound = two_boxes();
  for (int i = 0; i < count(100); ++i) {
    const double rc = test::uniform(rng, 0, 0.5), rs = test::uniform(rng, 0, 0.5);
    const Body a(compound, rc);
    const Body b = make_capsule(0.3, rs);
    const Pose pa(test::random_quaternion(rng), Vec3::Zero());
    const Pose pb(test::random_quaternion(rng), 4.0 * test::random_unit_vector(rng));
    const BodyResult r = distance(a, pa, b, pb);
    double best = std::numeric_limits<double>::infinity();
    for (int p = 0; p < compound->piece_count(); ++p) {
      const BodyResult piece =
          distance(Body(compound->piece(p).polytope, rc), pa * compound->piece(p).pose, b, pb);
      best = std::min(best, piece.signed_distance());
    }
    EXPECT_NEAR(r.signed_distance(), best, 1e-12) << i;
    EXPECT_GE(r.piece_a, 0);
    EXPECT_EQ(r.piece_b, -1);  // a convex body has no pieces
    expect_consistent(r, 8.0);
  }
}

TEST(BodyCompound, OverlappingCompoundReportsItsDeepestPiecePair) {
  // A ball whose core point (the origin) lies inside both pieces of a
  // rounded compound at different depths: the answer is the deeper pair's,
  // not the first overlapping pair the compound query stops at.
  std::vector<CompoundPiece> pieces;
  pieces.push_back({make_box(Vec3(1, 1, 1)).convex(), Pose::from_translation(Vec3(0.8, 0, 0))});
  pieces.push_back({make_box(Vec3(1, 1, 1)).convex(), Pose::from_translation(Vec3(-0.6, 0, 0))});
  const Body compound(std::make_shared<const CompoundBody>(std::move(pieces)), 0.1);
  const Body ball = make_sphere(0.5);
  // The core point (origin) is 0.2 inside piece 0 (face at x = -0.2) and
  // 0.4 inside piece 1 (face at x = 0.4): the deeper pair is piece 1.
  const BodyResult r = distance(compound, Pose::identity(), ball, Pose::identity());
  EXPECT_EQ(r.status, Status::intersecting);
  EXPECT_TRUE(r.intersecting);
  EXPECT_EQ(r.piece_a, 1);
  EXPECT_NEAR(r.signed_distance(), -0.4 - 0.1 - 0.5, 1e-14);
  expect_consistent(r, 2.0);
}

TEST(BodyDepth, PenetrationOffSkipsTheDepthOfOverlappingCores) {
  // DistanceOptions::penetration false is a caller's "status only": before,
  // a Body pair computed the cores' depth whatever it said, so a Scene of
  // padded bodies (penetration off by default) paid 5 to 60 us per
  // overlapping pair and step for a depth it then reported. Now the cores'
  // signed value is 0 with bounds [-inf, 0], as for a mesh overlap, and the
  // penetration cache stays cold.
  DistanceOptions status_only;
  status_only.penetration = false;
  const Body box = make_box(Vec3(1, 1, 1), 0.25);
  const Body ball = make_sphere(0.5);
  const Pose inside = Pose::from_translation(Vec3(0.7, 0.1, 0));
  BodyCache cache;
  const BodyResult r = distance(box, Pose::identity(), ball, inside, status_only, &cache);
  EXPECT_EQ(r.status, Status::intersecting);
  EXPECT_TRUE(r.intersecting);
  EXPECT_TRUE(cache.penetration.is_cold());
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_DOUBLE_EQ(r.signed_upper_bound(), -0.75);
  EXPECT_EQ(r.signed_lower_bound(), -std::numeric_limits<double>::infinity());
  // The default takes the depth: the core point is 0.3 inside the box.
  const BodyResult deep = distance(box, Pose::identity(), ball, inside);
  EXPECT_NEAR(deep.signed_distance(), -0.3 - 0.75, 1e-14);
  EXPECT_GE(r.signed_upper_bound(), deep.signed_distance());

  // A compound whose pieces overlap the ball's core: no deepest-pair search.
  std::vector<CompoundPiece> pieces;
  pieces.push_back({make_box(Vec3(1, 1, 1)).convex(), Pose::from_translation(Vec3(0.8, 0, 0))});
  pieces.push_back({make_box(Vec3(1, 1, 1)).convex(), Pose::from_translation(Vec3(-0.6, 0, 0))});
  const Body compound(std::make_shared<const CompoundBody>(std::move(pieces)), 0.1);
  const BodyResult c = distance(compound, Pose::identity(), ball, Pose::identity(), status_only);
  EXPECT_EQ(c.status, Status::intersecting);
  EXPECT_TRUE(c.intersecting);
  EXPECT_DOUBLE_EQ(c.signed_upper_bound(), -0.6);
  EXPECT_EQ(c.signed_lower_bound(), -std::numeric_limits<double>::infinity());

  // Cores apart: the option changes nothing.
  const Pose apart = Pose::from_translation(Vec3(2.0, 0, 0));
  const BodyResult far = distance(box, Pose::identity(), ball, apart, status_only);
  EXPECT_EQ(far.status, Status::separated);  // cores 1 apart, radii 0.75
  EXPECT_FALSE(far.intersecting);
  EXPECT_NEAR(far.signed_distance(), 1.0 - 0.75, 1e-14);
}

TEST(BodyCompound, DeepestPairIsTheAllPairsTwins) {
  // Overlapping compounds of a few random pieces: the signed distance is the
  // smallest over every piece pair of the pair's own (minus its brute-force
  // penetration depth where the pieces overlap, else its distance), minus
  // the radii. Checks that the hierarchy walk misses no overlapping pair.
  Rng rng(22);
  int overlapping = 0;
  for (int i = 0; i < count(60); ++i) {
    const auto random_compound = [&](int pieces) {
      std::vector<CompoundPiece> list;
      for (int p = 0; p < pieces; ++p) {
        // The braces are evaluated in order; in the calls, the last
        // argument first (gcc's order, see drawn()).
        const double radius = test::uniform(rng, 0.3, 1.0);
        const auto piece = hull(test::points_on_sphere(rng, test::uniform_int(rng, 4, 12), radius));
        const Vec3 at = 2.0 * test::drawn([&] { return test::uniform(rng, -1, 1); });
        list.push_back({piece, Pose(test::random_quaternion(rng), at)});
      }
      return std::make_shared<const CompoundBody>(std::move(list));
    };
    const auto ca = random_compound(test::uniform_int(rng, 1, 8));
    const auto cb = random_compound(test::uniform_int(rng, 1, 8));
    const double ra = test::uniform(rng, 0, 0.2), rb = test::uniform(rng, 0, 0.2);
    const Pose pa(test::random_quaternion(rng), Vec3::Zero());
    const Pose pb(test::random_quaternion(rng),
                  test::uniform(rng, 0, 2) * test::random_unit_vector(rng));
    const BodyResult r = distance(Body(ca, ra), pa, Body(cb, rb), pb);
    double twin = std::numeric_limits<double>::infinity();
    for (int x = 0; x < ca->piece_count(); ++x) {
      for (int y = 0; y < cb->piece_count(); ++y) {
        const Pose place_a = pa * ca->piece(x).pose;
        const Pose place_b = pb * cb->piece(y).pose;
        const DistanceResult d =
            distance(*ca->piece(x).polytope, place_a, *cb->piece(y).polytope, place_b);
        double value = d.distance;
        if (d.status == Status::intersecting) {
          value = -penetration_depth_brute_force(*ca->piece(x).polytope, *cb->piece(y).polytope,
                                                 place_a.inverse() * place_b)
                       .depth;
        }
        twin = std::min(twin, value);
      }
    }
    EXPECT_NEAR(r.signed_distance(), twin - ra - rb, 1e-12) << i;
    expect_consistent(r, 6.0);
    if (r.intersecting) ++overlapping;
  }
  EXPECT_GT(overlapping, count(60) / 4);
}

TEST(BodyCompound, MixedKindsAgreeWithTheirOnePieceCompounds) {
  Rng rng(18);
  for (int i = 0; i < count(100); ++i) {
    const auto pa_points = test::points_on_sphere(rng, 12);
    const auto pb_points = test::points_in_cube(rng, 12);
    const double ra = test::uniform(rng, 0, 0.3), rb = test::uniform(rng, 0, 0.3);
    const Body convex_a(hull(pa_points), ra);
    const Body convex_b(hull(pb_points), rb);
    const Body compound_b(convex_b.compound(), rb);
    const Pose pa(test::random_quaternion(rng), Vec3::Zero());
    const Pose pb(test::random_quaternion(rng),
                  test::uniform(rng, 0.5, 3.0) * test::random_unit_vector(rng));
    const BodyResult convex = distance(convex_a, pa, convex_b, pb);
    const BodyResult mixed = distance(convex_a, pa, compound_b, pb);
    EXPECT_EQ(convex.status, mixed.status) << i;
    EXPECT_NEAR(convex.signed_distance(), mixed.signed_distance(),
                bound(convex.signed_distance(), 4.0))
        << i;
    EXPECT_EQ(mixed.piece_b, 0);
    EXPECT_EQ(mixed.piece_a, -1);
  }
}

// Bitwise equality of two answers' signed distance, certificate, points,
// normal and features.
void expect_same_bits(const DistanceResult& body, double radii, const DistanceResult& core,
                      int i) {
  EXPECT_EQ(body.status, core.status) << i;
  EXPECT_EQ(body.signed_distance(), core.signed_distance() - radii) << i;
  EXPECT_EQ(body.signed_lower_bound(), core.signed_lower_bound() - radii) << i;
  EXPECT_EQ(body.signed_upper_bound(), core.signed_upper_bound() - radii) << i;
  EXPECT_EQ(body.normal, core.normal) << i;
  EXPECT_EQ(body.feature_a.vertices, core.feature_a.vertices) << i;
  EXPECT_EQ(body.feature_b.vertices, core.feature_b.vertices) << i;
}

TEST(BodyDepth, OverlappingCoresAreTheirQuerysOwnAnswerBitForBit) {
  // Story: a Body pair took the depth of overlapping cores through a
  // pipeline of its own (the cores' query without the depth, then a
  // penetration query per pair; for compounds a second, cold traversal of
  // both hierarchies after the compound search stopped at its first
  // overlapping pair), which answered a few ulps away from the convex and
  // compound queries on the same cores (another relative pose, another
  // seed). Now the cores' own query takes the depth: overlapping cores
  // give its answer offset by the radii, bit for bit, cold and tracked.
  Rng rng(23);
  const auto random_compound = [&](int pieces) {
    std::vector<CompoundPiece> list;
    for (int p = 0; p < pieces; ++p) {
      // The braces are evaluated in order; in the calls, the last
      // argument first (gcc's order, see drawn()).
      const double radius = test::uniform(rng, 0.3, 1.0);
      const auto piece = hull(test::points_on_sphere(rng, test::uniform_int(rng, 4, 12), radius));
      const Vec3 at = 1.5 * test::drawn([&] { return test::uniform(rng, -1, 1); });
      list.push_back({piece, Pose(test::random_quaternion(rng), at)});
    }
    return std::make_shared<const CompoundBody>(std::move(list));
  };
  const auto ca = random_compound(6);
  const auto cb = random_compound(5);
  const auto hull_a = ca->piece(0).polytope;
  const auto hull_b = cb->piece(0).polytope;
  BodyCache tracked_bodies, tracked_hulls;
  CompoundCache tracked_compounds;
  DistanceCache tracked_convex;
  int overlapping = 0;
  for (int i = 0; i < count(40); ++i) {
    const double ra = i % 3 == 0 ? 0.0 : 0.1, rb = i % 2 == 0 ? 0.0 : 0.2;
    // B passes through A, turning.
    const Pose pa = Pose::identity();
    const Pose pb(Quat(Eigen::AngleAxisd(0.05 * i, Vec3(1, 2, 3).normalized())),
                  Vec3(-2.0 + 4.0 * i / count(40), 0.3, 0.1));
    const CompoundResult compound = distance(*ca, pa, *cb, pb);
    const CompoundResult compound_tracked = distance(*ca, pa, *cb, pb, {}, &tracked_compounds);
    const DistanceResult convex = distance(*hull_a, pa, *hull_b, pb);
    const DistanceResult convex_tracked = distance(*hull_a, pa, *hull_b, pb, {}, &tracked_convex);
    if (compound.status == Status::intersecting) {
      ++overlapping;
      const BodyResult r = distance(Body(ca, ra), pa, Body(cb, rb), pb);
      expect_same_bits(r, ra + rb, compound, i);
      EXPECT_EQ(r.piece_a, compound.piece_a) << i;
      EXPECT_EQ(r.piece_b, compound.piece_b) << i;
    }
    if (compound_tracked.status == Status::intersecting) {
      const BodyResult r = distance(Body(ca, ra), pa, Body(cb, rb), pb, {}, &tracked_bodies);
      expect_same_bits(r, ra + rb, compound_tracked, i);
    } else {
      distance(Body(ca, ra), pa, Body(cb, rb), pb, {}, &tracked_bodies);
    }
    if (convex.status == Status::intersecting) {
      expect_same_bits(distance(Body(hull_a, ra), pa, Body(hull_b, rb), pb), ra + rb, convex, i);
    }
    const BodyResult r = distance(Body(hull_a, ra), pa, Body(hull_b, rb), pb, {}, &tracked_hulls);
    if (convex_tracked.status == Status::intersecting)
      expect_same_bits(r, ra + rb, convex_tracked, i);
  }
  EXPECT_GT(overlapping, count(40) / 4);
}

TEST(BodyRegression, CoplanarOverlapOfBoxesIsIntersecting) {
  // Story: unit cubes with B at (0.8, 0, 0) overlap by 0.2, but the
  // contact classification answers touching (the origin on planes of A -
  // B's vertex differences; SignedDistanceHand.CoplanarOverlapCalledTouching
  // GetsItsDepth). The convex query checks a touching answer's depth; a
  // Body pair asked its cores' query without the depth and took one only
  // for an intersecting answer or a rounded touching one, so unrounded
  // boxes came out touching with signed distance 0, and rounded ones
  // overlapping by the right amount but with intersecting false.
  for (const double r : {0.0, 0.1}) {
    const Body box = make_box(Vec3(0.5, 0.5, 0.5), r);
    const Body compound(box.compound(), r);
    for (const Algorithm algorithm : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
      DistanceOptions options;
      options.algorithm = algorithm;
      for (int step = 0; step < 3; ++step) {
        const Pose pb = Pose::from_translation(Vec3(0.8 - 0.1 * step, 0, 0));
        for (const BodyResult& a : {distance(box, Pose::identity(), box, pb, options),
                                    distance(compound, Pose::identity(), box, pb, options)}) {
          EXPECT_EQ(a.status, Status::intersecting) << r << " " << step;
          EXPECT_TRUE(a.intersecting) << r << " " << step;
          EXPECT_NEAR(a.signed_distance(), -0.2 - 0.1 * step - 2 * r, 1e-15) << r << " " << step;
          expect_consistent(a, 2.0);
        }
      }
    }
  }
}

TEST(BodyRegression, IterationCapLeavesRoomForTheOverlap) {
  // Story: the cores' query stopped at DistanceOptions::max_iterations
  // with a lower bound <= 0 does not certify separation: the convex query
  // bounds the possible depth by the bounding balls' (its
  // depth_upper_bound), but a Body pair read only its lower bound, so two
  // rounded balls of 64 points overlapping by 1.76 reported a signed lower
  // bound of -0.2 (minus the radii), above the signed distance.
  Rng rng(24);
  const auto ball = hull(test::points_on_sphere(rng, 64));
  const Pose pb(Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())), Vec3(0.3, 0.2, 0.1));
  const double depth = penetration_depth_brute_force(*ball, *ball, pb).depth;
  for (const Algorithm algorithm : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    DistanceOptions capped;
    capped.algorithm = algorithm;
    capped.max_iterations = 1;
    const Body a(ball, 0.1);
    const Body compound(a.compound(), 0.1);
    for (const BodyResult& r : {distance(a, Pose::identity(), a, pb, capped),
                                distance(compound, Pose::identity(), a, pb, capped)}) {
      ASSERT_EQ(r.status, Status::iteration_cap) << to_string(algorithm);
      EXPECT_LE(r.signed_lower_bound(), -depth - 0.2) << to_string(algorithm);
      EXPECT_GE(r.signed_upper_bound(), -depth - 0.2) << to_string(algorithm);
    }
  }
}

// --- Tracking -----------------------------------------------------------------

TEST(BodyTracking, TrackedAnswersAreTheColdAnswers) {
  Rng rng(19);
  const Body a(hull(test::points_on_sphere(rng, 40)), 0.2);
  const Body b = make_cylinder(0.5, 1.0, 1e-3);
  const Body c(two_boxes(), 0.05);
  BodyCache ab, ac;
  for (int step = 0; step < count(200); ++step) {
    // B and C pass through A and out again.
    const double t = -3.0 + 6.0 * step / count(200);
    const Pose pa = Pose::identity();
    const Pose pb(Quat(Eigen::AngleAxisd(0.01 * step, Vec3::UnitY())), Vec3(t, 0.3, 0));
    const Pose pc(Quat(Eigen::AngleAxisd(0.02 * step, Vec3::UnitZ())), Vec3(0, t, 0.1));
    const BodyResult tracked_b = distance(a, pa, b, pb, {}, &ab);
    const BodyResult cold_b = distance(a, pa, b, pb);
    EXPECT_EQ(tracked_b.status, cold_b.status) << step;
    EXPECT_NEAR(tracked_b.signed_distance(), cold_b.signed_distance(),
                bound(cold_b.signed_distance(), 4.0))
        << step;
    const BodyResult tracked_c = distance(a, pa, c, pc, {}, &ac);
    const BodyResult cold_c = distance(a, pa, c, pc);
    EXPECT_EQ(tracked_c.status, cold_c.status) << step;
    EXPECT_NEAR(tracked_c.signed_distance(), cold_c.signed_distance(),
                bound(cold_c.signed_distance(), 6.0))
        << step;
  }
}

// --- Cylinder and cone: the stated deviation ------------------------------------

// Largest violation of the polytope's face planes by x (<= 0 inside).
double outside(const ConvexPolytope& p, const Vec3& x) {
  double worst = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < p.face_count(); ++f) {
    const Plane plane = p.face_plane(f);
    worst = std::max(worst, plane.normal.dot(x) - plane.offset);
  }
  return worst;
}

// Distance from x to the solid cylinder (radius r, |z| <= h) and cone.
double to_cylinder(const Vec3& x, double r, double h) {
  const double radial = std::max(0.0, std::hypot(x.x(), x.y()) - r);
  const double axial = std::max(0.0, std::abs(x.z()) - h);
  return std::hypot(radial, axial);
}
double to_cone(const Vec3& x, double r, double h) {
  // In the half plane (rho, z): the triangle (0, -h), (r, -h), (0, h).
  const double rho = std::hypot(x.x(), x.y());
  const Vec3 p(rho, x.z(), 0);
  const Vec3 base0(0, -h, 0), corner(r, -h, 0), apex(0, h, 0);
  const auto segment = [&](const Vec3& s0, const Vec3& s1) {
    const double t = std::clamp((p - s0).dot(s1 - s0) / (s1 - s0).squaredNorm(), 0.0, 1.0);
    return (s0 + t * (s1 - s0) - p).norm();
  };
  const bool inside = x.z() >= -h && rho <= r * (h - x.z()) / (2 * h);
  if (inside) return 0.0;
  return std::min({segment(base0, corner), segment(corner, apex), segment(apex, base0)});
}

TEST(Primitives, CylinderAndConeStayWithinTheirStatedDeviation) {
  Rng rng(20);
  for (const double tolerance : {0.5, 1e-1, 1e-2, 1e-3, 1e-5}) {
    const double r = 0.7, h = 1.3;
    const PolygonApproximation poly = polygon_sides(r, tolerance);
    EXPECT_LE(poly.deviation, tolerance);
    // The fewest sides: one fewer would not meet the tolerance.
    if (poly.sides > 3) {
      EXPECT_GT(r / std::cos(std::numbers::pi / (poly.sides - 1)) - r, tolerance);
    }
    for (const bool cone : {false, true}) {
      const Body body = cone ? make_cone(r, h, tolerance) : make_cylinder(r, h, tolerance);
      EXPECT_EQ(body.approximation_error(), poly.deviation);
      const ConvexPolytope& p = *body.convex();
      EXPECT_EQ(p.vertex_count(), cone ? poly.sides + 1 : 2 * poly.sides);
      // Every vertex within the deviation of the true solid, and the true
      // deviation not far below the stated one.
      double farthest = 0.0;
      for (const Vec3& v : p.vertices())
        farthest = std::max(farthest, cone ? to_cone(v, r, h) : to_cylinder(v, r, h));
      EXPECT_LE(farthest, poly.deviation);
      EXPECT_GE(farthest, 0.99 * poly.deviation);
      // Samples of the true surface (rim circles, side, cap, apex) inside
      // the polytope.
      for (int k = 0; k < 500; ++k) {
        const double t = test::uniform(rng, 0, 2 * std::numbers::pi);
        const double z = test::uniform(rng, -h, h);
        const double rho = cone ? r * (h - z) / (2 * h) : r;
        const Vec3 side(rho * std::cos(t), rho * std::sin(t), z);
        const Vec3 rim(r * std::cos(t), r * std::sin(t), -h);
        EXPECT_LE(outside(p, side), 1e-15) << tolerance << " " << cone;
        EXPECT_LE(outside(p, rim), 1e-15) << tolerance << " " << cone;
      }
    }
  }
}

TEST(Primitives, ShapesAreTheirDefinitions) {
  EXPECT_EQ(make_sphere(2.0).convex()->dimension(), 0);
  EXPECT_EQ(make_sphere(2.0).radius(), 2.0);
  EXPECT_EQ(make_capsule(1.0, 0.5).convex()->dimension(), 1);
  EXPECT_EQ(make_box(Vec3(1, 2, 3)).convex()->vertex_count(), 8);
  EXPECT_EQ(make_box(Vec3(1, 2, 0)).convex()->dimension(), 2);
  EXPECT_EQ(make_box(Vec3(1, 2, 3), 0.5).scale(), 3.5);
  EXPECT_EQ(make_box(Vec3(1, 2, 3)).approximation_error(), 0.0);
  // Rounded boxes face to face, centers 7 apart: minus 2 (half extents) and
  // 2 (radii).
  const BodyResult r =
      distance(make_box(Vec3(1, 1, 1), 1.0), Pose::identity(), make_box(Vec3(1, 1, 1), 1.0),
               Pose::from_translation(Vec3(7, 0, 0)));
  EXPECT_DOUBLE_EQ(r.signed_distance(), 3.0);
  EXPECT_DOUBLE_EQ(r.point_a.x(), 2.0);
  EXPECT_DOUBLE_EQ(r.point_b.x(), 5.0);
  // The answer carries the approximation error of both bodies.
  const Body cyl = make_cylinder(1.0, 1.0, 1e-3);
  EXPECT_EQ(distance(cyl, Pose::identity(), cyl, Pose::from_translation(Vec3(5, 0, 0)))
                .approximation_error,
            2 * cyl.approximation_error());
}

// --- Refusals -------------------------------------------------------------------

void expect_refusal(const auto& make, const std::string& words) {
  try {
    make();
    ADD_FAILURE() << "no InvalidInput; expected: " << words;
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(BodyRefusals, BadRadiiAndTolerancesAreNamed) {
  const auto core = make_box(Vec3(1, 1, 1)).convex();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expect_refusal([&] { return Body(core, -0.5); }, "radius must be finite and >= 0, got -0.5");
  expect_refusal([&] { return Body(core, nan); }, "radius must be finite and >= 0, got nan");
  expect_refusal([&] { return Body(core, inf); }, "radius must be finite and >= 0, got inf");
  expect_refusal([&] { return Body(core).with_radius(-1.0); }, "radius must be finite");
  expect_refusal([&] { return Body(core, 0.0, -1.0); }, "approximation_error must be finite");
  expect_refusal([&] { return Body(std::shared_ptr<const ConvexPolytope>()); }, "null convex core");
  expect_refusal([&] { return make_sphere(-1.0); }, "make_sphere: radius must be finite and >= 0");
  expect_refusal([&] { return make_box(Vec3(1, nan, 1)); }, "make_box: half_extents.y must be");
  expect_refusal([&] { return make_capsule(-1.0, 1.0); }, "make_capsule: half_length must be");
  expect_refusal([&] { return make_cylinder(1.0, 1.0, 0.0); },
                 "make_cylinder: tolerance must be finite and > 0, got 0");
  expect_refusal([&] { return make_cone(1.0, 1.0, 1e-12); }, "make_cone: tolerance 1e-12");
  expect_refusal([&] { return make_cone(1.0, inf, 1e-3); }, "make_cone: half_length must be");
  // A tolerance below the radius's last digit (r + tol == r, so acos(1) = 0
  // sides' angle) divided by zero, and a radius near the largest double
  // overflowed the corners to infinity and then to NaN (inf * sin(0)): both
  // trapped (SIGFPE) in the test main instead of being refused.
  expect_refusal([&] { return make_cylinder(1.0, 1.0, 1e-17); }, "make_cylinder: tolerance 1e-17");
  expect_refusal([&] { return make_cylinder(1e308, 1.0, 1e307); },
                 "make_cylinder: radius 1e+308 is too large");
}

TEST(BodyRefusals, BadPosesAreNamed) {
  const Body s = make_sphere(1.0);
  Pose bad;
  bad.translation.x() = std::numeric_limits<double>::quiet_NaN();
  expect_refusal([&] { return distance(s, bad, s, Pose::identity()); }, "distance: pose_a");
  expect_refusal([&] { return distance(s, Pose::identity(), s, bad); }, "distance: pose_b");
  // Radii near the largest double: their sum was infinite, and so was the
  // signed distance (-inf), not refused.
  const Body huge = make_sphere(1e308);
  expect_refusal([&] { return distance(huge, Pose::identity(), huge, Pose::identity()); },
                 "(with its radius 1e+308), beyond the supported 2.81e+306 where differences");
}

}  // namespace
}  // namespace proxima
