// Tests of the test oracles themselves (tests/support/exact_oracle.h) and of
// the generators (tests/support/generators.h): hand-computed exact answers,
// certificates that must reject wrong candidates, the two candidate sources
// (CGAL, brute force over the exact kernels) against each other on seeded
// random inputs, and the paper's extreme scales.
#include "support/exact_oracle.h"
#include "support/generators.h"
#include "support/sanitizers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

namespace proxima::test {
namespace {

// Exact arithmetic runs about 5x slower under ASan and UBSan.
constexpr int kRandomPairs = kUnderSanitizers ? 40 : 300;
constexpr int kPaperRepeats = kUnderSanitizers ? 3 : 10;

// Runs one candidate source directly (not through the fallback chain).
std::optional<ExactDistance> via_cgal(const Points& a, const Points& b, std::string* why = nullptr) {
  return cgal_distance(a, b, to_rational(a), to_rational(b), why);
}
std::optional<ExactDistance> via_brute_force(const Points& a, const Points& b, std::string* why = nullptr) {
  return brute_force_distance(a, b, to_rational(a), to_rational(b), why);
}

// Both sources must certify the hand case and agree with its exact answer.
void expect_exact(const Points& a, const Points& b, const mpq_class& expected_sq) {
  std::string why;
  const auto c = via_cgal(a, b, &why);
  ASSERT_TRUE(c) << why;
  EXPECT_EQ(c->distance_squared, expected_sq) << "cgal " << c->distance_squared.get_str();
  const auto f = via_brute_force(a, b, &why);
  ASSERT_TRUE(f) << why;
  EXPECT_EQ(f->distance_squared, expected_sq) << "brute force " << f->distance_squared.get_str();
  const auto c_swapped = via_cgal(b, a, &why);
  ASSERT_TRUE(c_swapped) << why;
  EXPECT_EQ(c_swapped->distance_squared, expected_sq);
}

Points unit_cube_at(const Vec3& corner, double edge = 1.0) {
  return translated(scaled(cube(1.0), edge), corner + Vec3::Constant(edge / 2));
}

TEST(ExactOracleHandCases, FaceFaceCubes) {
  expect_exact(unit_cube_at(Vec3(0, 0, 0)), unit_cube_at(Vec3(2, 0.25, -0.5)), mpq_class(1));
}

TEST(ExactOracleHandCases, PointAboveTriangleInterior) {
  // (0.25, 0.25, 2) projects inside the triangle: d = 2.
  expect_exact({Vec3(0.25, 0.25, 2)}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, mpq_class(4));
}

TEST(ExactOracleHandCases, PointNearTriangleEdge) {
  // (1, 1, 1) projects to (0.5, 0.5, 0) on the hypotenuse: d^2 = 0.25 + 0.25 + 1.
  expect_exact({Vec3(1, 1, 1)}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, mpq_class(3, 2));
}

TEST(ExactOracleHandCases, SkewEdges) {
  expect_exact({Vec3(-1, 0, 0), Vec3(1, 0, 0)}, {Vec3(0, -1, 1), Vec3(0, 1, 1)}, mpq_class(1));
}

TEST(ExactOracleHandCases, ParallelOverlappingSegments) {
  expect_exact({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, 1, 0), Vec3(2, 1, 0)}, mpq_class(1));
}

TEST(ExactOracleHandCases, DistanceNotRepresentableInDouble) {
  // The origin and the plane x + y + z = 1: d^2 = 1/3 exactly, at (1/3, 1/3, 1/3).
  const Points tri{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  expect_exact({Vec3(0, 0, 0)}, tri, mpq_class(1, 3));
  const auto r = via_cgal({Vec3(0, 0, 0)}, tri);
  ASSERT_TRUE(r);
  for (const mpq_class& x : r->point_b) EXPECT_EQ(x, mpq_class(1, 3));
}

TEST(ExactOracleHandCases, OverlappingCubes) {
  expect_exact(unit_cube_at(Vec3(0, 0, 0)), unit_cube_at(Vec3(0.5, 0.5, 0.5)), mpq_class(0));
}

TEST(ExactOracleHandCases, CubeInsideCubeNeedsContainment) {
  // No boundary contact at all: brute force over boundary pairs finds a
  // positive minimum and must fall back to the containment certificate.
  const Points big = unit_cube_at(Vec3(0, 0, 0), 4.0);
  const Points small = unit_cube_at(Vec3(1, 1, 1), 0.5);
  expect_exact(big, small, mpq_class(0));
  expect_exact(small, big, mpq_class(0));
}

TEST(ExactOracleHandCases, SharedVertexAndSharedFace) {
  const Points a = unit_cube_at(Vec3(0, 0, 0));
  expect_exact(a, unit_cube_at(Vec3(1, 1, 1)), mpq_class(0));  // one shared corner
  expect_exact(a, unit_cube_at(Vec3(0, 0, 1)), mpq_class(0));  // stacked: shared face
}

TEST(ExactOracleHandCases, ExtremeScalesAreExact) {
  // Powers of two keep every coordinate exact: gap 2^-80 and 2^100.
  for (const double s : {0x1p-80, 0x1p100}) {
    const Points a = unit_cube_at(Vec3(0, 0, 0), s);
    const Points b = unit_cube_at(Vec3(2 * s, 0, 0), s);
    expect_exact(a, b, mpq_class(s) * mpq_class(s));
  }
}

TEST(ExactOracleHandCases, DegenerateInputs) {
  Rng rng(7);
  const Points tri{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};
  // Duplicates and interior points change nothing.
  expect_exact(with_duplicates(rng, {Vec3(0.5, 0.5, 3)}, 3), with_duplicates(rng, tri, 4), mpq_class(9));
  // Collinear points: only the extreme ones matter.
  expect_exact({Vec3(-1, 0, 1), Vec3(0, 0, 1), Vec3(3, 0, 1), Vec3(1, 0, 1)}, tri, mpq_class(1));
  // Point against point.
  expect_exact({Vec3(1, 2, 3)}, {Vec3(1, 2, 5)}, mpq_class(4));
}

// ---------------------------------------------------------------------------
// The certificate must reject what is not a closest pair.

TEST(ExactOracleCertificate, RejectsWrongCandidates) {
  const Points a = unit_cube_at(Vec3(0, 0, 0));
  const Points b = unit_cube_at(Vec3(2, 0, 0));
  const auto qa = to_rational(a), qb = to_rational(b);
  // The cube's corner i has x = 1 when bit 0 of i is set (see box()).
  const ConvexCombination near_a{{1, mpq_class(1)}}, far_a{{0, mpq_class(1)}}, near_b{{0, mpq_class(1)}};
  std::string why;
  const auto good = certify(qa, qb, near_a, near_b, OracleMethod::cgal, &why);
  ASSERT_TRUE(good) << why;
  EXPECT_EQ(good->distance_squared, mpq_class(1));
  EXPECT_FALSE(certify(qa, qb, far_a, near_b, OracleMethod::cgal, &why)) << "farther pair accepted";
  EXPECT_FALSE(certify(qa, qb, {{1, mpq_class(1, 2)}}, near_b, OracleMethod::cgal, &why)) << "sum 1/2";
  EXPECT_FALSE(certify(qa, qb, {{1, mpq_class(3, 2)}, {0, mpq_class(-1, 2)}}, near_b, OracleMethod::cgal, &why))
      << "negative coefficient (a point outside A)";
  EXPECT_FALSE(certify(qa, qb, {{9, mpq_class(1)}}, near_b, OracleMethod::cgal, &why)) << "bad index";
  // A pair that is closest but off by one ulp in a coordinate of B: the
  // plane through it no longer separates exactly.
  Points b_moved = b;
  b_moved[2].x() = std::nextafter(2.0, 1.0);  // corner 2 sticks out towards A
  EXPECT_FALSE(certify(qa, to_rational(b_moved), near_a, near_b, OracleMethod::cgal, &why));
}

TEST(ExactOracleCertificate, ConvexCoefficientsFindsAffinelyIndependentSubset) {
  // The centroid of a tetrahedron given with a duplicate and a point on an
  // edge among the ids: Gaussian elimination on all five would be singular.
  const std::vector<QPoint> pts = to_rational(
      Points{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0), Vec3(0, 0, 4), Vec3(4, 0, 0), Vec3(2, 0, 0)});
  const QPoint centroid{mpq_class(1), mpq_class(1), mpq_class(1)};
  const auto c = convex_coefficients(pts, {0, 1, 2, 3, 4, 5}, centroid);
  ASSERT_TRUE(c);
  QPoint p{0, 0, 0};
  mpq_class sum = 0;
  for (const auto& [i, l] : *c) {
    EXPECT_GE(sgn(l), 0);
    sum += l;
    for (std::size_t k = 0; k < 3; ++k) p[k] += l * pts[static_cast<std::size_t>(i)][k];
  }
  EXPECT_EQ(sum, 1);
  EXPECT_EQ(p, centroid);
  // A point outside the hull has no convex coefficients.
  EXPECT_FALSE(convex_coefficients(pts, {0, 1, 2, 3}, QPoint{mpq_class(3), mpq_class(3), mpq_class(0)}));
}

TEST(ExactOracleCertificate, WithinBoundIsExact) {
  const double one_up = std::nextafter(1.0, 2.0);  // 1 + 2^-52
  EXPECT_TRUE(within_bound(1.0, mpq_class(1), 0.0, 0.0));
  EXPECT_FALSE(within_bound(one_up, mpq_class(1), 0.0, 0.0));
  EXPECT_TRUE(within_bound(one_up, mpq_class(1), 0.0, 0x1p-52));
  EXPECT_FALSE(within_bound(one_up, mpq_class(1), 0.0, 0x1p-53));
  EXPECT_TRUE(within_bound(one_up, mpq_class(1), 0x1p-52, 0.0));
  // sqrt(2) is irrational: its double neighbours are within one ulp, and
  // both roundings are not within a quarter ulp.
  const double s = std::sqrt(2.0);
  EXPECT_TRUE(within_bound(s, mpq_class(2), 0.0, 0x1p-52));
  const bool below = within_bound(s, mpq_class(2), 0.0, 0x1p-55);
  const bool above = within_bound(std::nextafter(s, 2.0), mpq_class(2), 0.0, 0x1p-55);
  EXPECT_FALSE(below && above);
  // Relative part: 1000 vs 1001 within 1e-3 relative plus nothing.
  EXPECT_TRUE(within_bound(1001.0, mpq_class(1000) * 1000, 1e-3, 0.0));
  EXPECT_FALSE(within_bound(1001.0, mpq_class(1000) * 1000, 0.999e-3, 0.0));
  EXPECT_TRUE(within_bound(0.0, mpq_class(0), 0.0, 0.0));
  EXPECT_TRUE(sqrt_at_most(mpq_class(4), 2.0));
  EXPECT_FALSE(sqrt_at_most(mpq_class(4), std::nextafter(2.0, 0.0)));
}

// ---------------------------------------------------------------------------
// CGAL and brute force against each other on seeded random inputs. Both
// answers are certified, so they must agree exactly; a disagreement means a
// hole in the certificate itself.

TEST(ExactOracleCrossCheck, CgalAgreesWithBruteForce) {
  Rng rng(20240611);
  ExactOracle placer;  // only to tighten gaps; the cross-check runs both sources directly
  std::map<std::string, int> counts;
  int cgal_rejected = 0;
  for (int i = 0; i < kRandomPairs; ++i) {
    const ShapeKind ka = random_shape_kind(rng), kb = random_shape_kind(rng);
    const Points a0 = transformed(random_shape(rng, ka, uniform_int(rng, 4, 10)), random_rotation(rng), Vec3::Zero());
    const Points b0 = transformed(random_shape(rng, kb, uniform_int(rng, 4, 10)), random_rotation(rng), Vec3::Zero());
    // Gaps from deep overlap through slab contact and near-touching (d*
    // itself set with tighten_to_gap) to far apart.
    const int mode = uniform_int(rng, 0, 3);
    const double gap = mode == 0 ? -uniform(rng, 0.0, 0.5) : mode == 1 ? 0.0 : log_uniform(rng, 1e-14, 1e3);
    Points b = place_along(a0, b0, random_unit_vector(rng), gap);
    if (mode == 2) {
      const std::optional<Points> t = tighten_to_gap(placer, a0, b, log_uniform(rng, 1e-14, 1e-9));
      if (t) b = *t;
    }
    std::string why_c, why_f;
    const auto c = via_cgal(a0, b, &why_c);
    const auto f = via_brute_force(a0, b, &why_f);
    ASSERT_TRUE(f) << "brute force failed: " << why_f << "\nA = " << format_points(a0) << "\nB = " << format_points(b);
    if (!c) {
      ++cgal_rejected;
      std::printf("CGAL not certified (%s)\n", why_c.c_str());
      continue;
    }
    ASSERT_EQ(c->distance_squared, f->distance_squared)
        << "A = " << format_points(a0) << "\nB = " << format_points(b);
    counts[f->is_zero() ? "zero" : (f->distance() < 1e-9 ? "near_touching" : "separated")]++;
    counts[std::string("shape_") + to_string(ka)]++;
  }
  std::printf("cross-check: %d pairs, CGAL not certified on %d\n", kRandomPairs, cgal_rejected);
  for (const auto& [k, n] : counts) std::printf("  %-22s %d\n", k.c_str(), n);
  EXPECT_GT(counts["zero"], 0);
  EXPECT_GT(counts["near_touching"], 0);
  EXPECT_GT(counts["separated"], 0);
  // CGAL with exact pricing is expected to be right; a few rejections are
  // tolerated (the fallback covers them) but must stay rare.
  EXPECT_LE(cgal_rejected, kRandomPairs / 50);
}

TEST(ExactOracleCrossCheck, FallbackChainCountsMethods) {
  // The oracle answers through CGAL when it certifies; its statistics say so.
  ExactOracle oracle;
  const auto r = oracle.distance(unit_cube_at(Vec3(0, 0, 0)), unit_cube_at(Vec3(3, 0, 0)));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->distance_squared, mpq_class(4));
  EXPECT_EQ(oracle.stats().queries, 1);
  EXPECT_EQ(oracle.stats().cgal_certified + oracle.stats().brute_force_certified, 1);
  const auto p = oracle.point_distance_squared(Vec3(0.5, 0.5, 3), unit_cube_at(Vec3(0, 0, 0)));
  ASSERT_TRUE(p);
  EXPECT_EQ(*p, mpq_class(4));
}

// ---------------------------------------------------------------------------
// Generators.

TEST(Generators, SameSeedSameDoubles) {
  for (int k = 0; k < kShapeKindCount; ++k) {
    Rng r1(99), r2(99);
    const auto kind = static_cast<ShapeKind>(k);
    EXPECT_EQ(random_shape(r1, kind, 20), random_shape(r2, kind, 20)) << to_string(kind);
  }
  Rng r1(5), r2(5);
  EXPECT_TRUE(random_rotation(r1).isApprox(random_rotation(r2), 0.0));
}

TEST(Generators, RotationsAreOrthonormal) {
  Rng rng(11);
  for (int i = 0; i < 100; ++i) {
    const Mat3 r = random_rotation(rng);
    // Orthonormal to a few roundings of the quaternion-to-matrix formula.
    EXPECT_LT((r * r.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff(), 16 * kUnitRoundoff);
    EXPECT_NEAR(r.determinant(), 1.0, 16 * kUnitRoundoff);
  }
}

TEST(Generators, PlaceAlongGivesAtLeastTheGap) {
  // d* >= gap up to the rounding of the translation (a few u R).
  Rng rng(3);
  ExactOracle oracle;
  for (int i = 0; i < 40; ++i) {
    const Points a = points_on_sphere(rng, 10);
    const Points b0 = points_in_cube(rng, 10, 0.5);
    const double gap = log_uniform(rng, 1e-9, 10.0);
    const Points b = place_along(a, b0, random_unit_vector(rng), gap);
    const auto r = oracle.distance(a, b);
    ASSERT_TRUE(r) << oracle.last_error();
    const double slack = 16 * kUnitRoundoff * std::max(max_abs_coordinate(a), max_abs_coordinate(b));
    EXPECT_FALSE(sqrt_at_most(r->distance_squared, gap - slack)) << "gap " << gap << " d* " << r->distance();
  }
}

TEST(Generators, PaperStressExperimentsHaveTheirScale) {
  // Experiment 1: tetrahedra of edge 1e-23 placed 2e-22 apart; experiment
  // 2: cubes of edge 2e42 and 1e24, 1e29 apart. place_along gives d* at
  // least the gap; tighten_to_gap makes it the gap up to the rounding of
  // the translation (a few u R).
  Rng rng(1998);
  ExactOracle oracle;
  for (int i = 0; i < kPaperRepeats; ++i) {
    for (const bool tetrahedra : {true, false}) {
      const BodyPair p = tetrahedra ? paper_tetrahedra(rng) : paper_cubes(rng);
      const double gap = tetrahedra ? kPaperTetrahedronGap : kPaperCubeGap;
      const double slack = 16 * kUnitRoundoff * std::max(max_abs_coordinate(p.a), max_abs_coordinate(p.b));
      const auto placed = oracle.distance(p.a, p.b);
      ASSERT_TRUE(placed) << oracle.last_error();
      EXPECT_FALSE(sqrt_at_most(placed->distance_squared, gap - slack));
      const auto b = tighten_to_gap(oracle, p.a, p.b, gap);
      ASSERT_TRUE(b);
      const auto r = oracle.distance(p.a, *b);
      ASSERT_TRUE(r) << oracle.last_error();
      EXPECT_TRUE(within_bound(gap, r->distance_squared, 0.0, slack)) << "d* " << r->distance() << " gap " << gap;
      // Brute force agrees at these scales too.
      std::string why;
      const auto f = via_brute_force(p.a, *b, &why);
      ASSERT_TRUE(f) << why << "\nA = " << format_points(p.a) << "\nB = " << format_points(*b);
      EXPECT_EQ(f->distance_squared, r->distance_squared);
    }
  }
}

}  // namespace
}  // namespace proxima::test
