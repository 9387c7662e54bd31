// Tests of the distance recomputed in double-double near the contact band
// (src/query/extended_distance.h, issue 25 §4): adversarial near-contact
// families far from the origin, where a distance computed in double is off
// by a few u R, a sizeable share of the band 64 u R, against the exact
// oracle (the given doubles' hulls, in rationals): the status follows the
// exact distance against the band, and the distance is within a relative
// 1e-12 of the exact one, without the standard's absolute term.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

#include "proxima/query/distance.h"
#include "support/exact_oracle.h"
#include "support/generators.h"

namespace proxima::test {
namespace {

// The relative accuracy asked of an answer near the band: the standard's
// relative term alone (its absolute term 64 u R is the band itself).
constexpr double kRelative = 1e-12;

// Distances as multiples of the band: on both sides of its edge and a few
// bands above, where the status and the distance were rounding's.
constexpr std::array<double, 8> kBands = {0.3, 0.7, 0.95, 1.05, 1.4, 2.0, 5.0, 12.0};

double largest_coordinate(const Points& a, const Points& b) {
  double r = 0.0;
  for (const Vec3& x : a) r = std::max(r, x.cwiseAbs().maxCoeff());
  for (const Vec3& y : b) r = std::max(r, y.cwiseAbs().maxCoeff());
  return r;
}

std::string g(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

struct Tally {
  int cases = 0;
  int touching = 0;
  int separated = 0;
};

// Checks every algorithm on the pair (world coordinates, identity poses:
// the oracle sees the same doubles), both orders.
void check_pair(const Points& a, const Points& b, ExactOracle& oracle, Tally& tally,
                const std::string& what) {
  const std::optional<ExactDistance> exact = oracle.distance(a, b);
  ASSERT_TRUE(exact) << oracle.last_error();
  const double band = kContactBandUlps * kUnitRoundoff * largest_coordinate(a, b);
  const bool touching = sqrt_at_most(exact->distance_squared, band);
  ++tally.cases;
  (touching ? tally.touching : tally.separated) += 1;
  const ConvexPolytope pa(a), pb(b);
  for (const Algorithm alg : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool swapped : {false, true}) {
      const DistanceResult r = swapped ? distance(pb, Pose::identity(), pa, Pose::identity(), options)
                                       : distance(pa, Pose::identity(), pb, Pose::identity(), options);
      const std::string where = what + ", " + to_string(alg) + (swapped ? ", swapped" : "") +
                                ", exact " + g(exact->distance()) + ", band " + g(band) +
                                ", answer " + g(r.distance);
      EXPECT_EQ(r.status, touching ? Status::touching : Status::separated) << where;
      EXPECT_TRUE(within_bound(r.distance, exact->distance_squared, kRelative, 0.0)) << where;
      EXPECT_LE(r.lower_bound, exact->distance() * (1 + kRelative)) << where;
      EXPECT_LE(r.lower_bound, r.distance) << where;
    }
  }
}

// A box of size 1 to 10, turned at random, 1e3 to 1e6 of its size from the
// origin; a tetrahedron's vertex above the middle of one of its faces at
// kBands bands, its other vertices further out.
TEST(ExtendedDistance, VertexAboveAFaceNearTheBand) {
  Rng rng(25004);
  ExactOracle oracle;
  Tally tally;
  for (int trial = 0; trial < 6; ++trial) {
    const double size = uniform(rng, 1.0, 10.0);
    const Vec3 centre = log_uniform(rng, 1e3, 1e6) * size * random_unit_vector(rng);
    const Mat3 turn = random_rotation(rng);
    const Points a = transformed(box(Vec3(size, 0.7 * size, 0.4 * size)), turn, centre);
    const Vec3 n = turn.col(0);  // the face x = size, outward
    const Vec3 across = turn.col(1);
    const double band = kContactBandUlps * kUnitRoundoff * (centre.cwiseAbs().maxCoeff() + 2 * size);
    for (const double k : kBands) {
      const Vec3 apex = centre + (size + k * band) * n + 0.1 * size * across;
      const Points b = {apex, apex + size * (n + 0.3 * across), apex + size * (n - 0.3 * across),
                        apex + size * (n + 0.3 * turn.col(2))};
      check_pair(a, b, oracle, tally, "trial " + std::to_string(trial) + ", " + std::to_string(k) + " bands");
    }
  }
  // The family reaches both sides of the band's edge.
  EXPECT_GE(tally.touching, 10);
  EXPECT_GE(tally.separated, 20);
}

// Two crossing edges (a box's edge and a tetrahedron's) at kBands bands,
// far from the origin: the edge-edge pair, whose normal is their cross
// product.
TEST(ExtendedDistance, CrossingEdgesNearTheBand) {
  Rng rng(25005);
  ExactOracle oracle;
  Tally tally;
  for (int trial = 0; trial < 6; ++trial) {
    const double size = uniform(rng, 1.0, 10.0);
    const Vec3 centre = log_uniform(rng, 1e3, 1e6) * size * random_unit_vector(rng);
    const Mat3 turn = random_rotation(rng);
    const Points a = transformed(box(Vec3(size, size, size)), turn, centre);
    // The edge x = y = size of the box (along z); the direction out of it
    // halves the two faces' normals.
    const Vec3 out = (turn.col(0) + turn.col(1)).normalized();
    const Vec3 edge_middle = centre + size * (turn.col(0) + turn.col(1));
    const Vec3 along = (turn.col(0) - turn.col(1)).normalized();  // across the box's edge
    const double band = kContactBandUlps * kUnitRoundoff * (centre.cwiseAbs().maxCoeff() + 3 * size);
    for (const double k : kBands) {
      const Vec3 m = edge_middle + k * band * out;
      const Points b = {m - 0.5 * size * along, m + 0.5 * size * along, m + size * (out + 0.2 * turn.col(2)),
                        m + size * (out - 0.2 * turn.col(2))};
      check_pair(a, b, oracle, tally, "trial " + std::to_string(trial) + ", " + std::to_string(k) + " bands");
    }
  }
  EXPECT_GE(tally.touching, 10);
  EXPECT_GE(tally.separated, 20);
}

}  // namespace
}  // namespace proxima::test
