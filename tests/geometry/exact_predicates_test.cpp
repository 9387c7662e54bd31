// Tests of the exact orientation predicates (layer 2,
// proxima/detail/geometry/exact_predicates.h) against GMP rationals: every finite
// double is a dyadic rational, so mpq_class(double) is exact and the signs
// computed here are the true ones.
//
// Adversarial inputs, seeded, thousands per family: nearly coplanar points
// (a rounded point of the plane nudged by 0 to 3 ulps), coordinates with
// exponents mixed from 1e-300 to 1e300, subnormals, points that differ in the
// last bit, and exactly coplanar or collinear points whose coordinates are
// hostile to rounding (0.1-like decimals, huge and tiny dyadics whose sums
// are exact). Plus hand cases at the ends of the double range.
#include "proxima/detail/geometry/exact_predicates.h"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "support/generators.h"

namespace proxima {
namespace {

using detail::collinear3d;
using detail::exact_triangle_normal;
using detail::orient2d;
using detail::side3d;
using test::drawn;

using Rng = std::mt19937_64;
double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }
double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }
int uniform_int(Rng& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
}

// ---------------------------------------------------------------------------
// The oracle
// ---------------------------------------------------------------------------

using Q3 = std::array<mpq_class, 3>;
Q3 rational(const Vec3& p) { return {mpq_class(p.x()), mpq_class(p.y()), mpq_class(p.z())}; }
Q3 minus(const Q3& a, const Q3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Q3 cross(const Q3& a, const Q3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
mpq_class dot(const Q3& a, const Q3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

int exact_orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const mpq_class acx = mpq_class(ax) - mpq_class(cx), acy = mpq_class(ay) - mpq_class(cy);
  const mpq_class bcx = mpq_class(bx) - mpq_class(cx), bcy = mpq_class(by) - mpq_class(cy);
  return sgn(mpq_class(acx * bcy - acy * bcx));
}
int exact_side3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Q3 qa = rational(a);
  return sgn(dot(cross(minus(rational(b), qa), minus(rational(c), qa)), minus(rational(d), qa)));
}
bool exact_collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Q3 qa = rational(a);
  const Q3 n = cross(minus(rational(b), qa), minus(rational(c), qa));
  return sgn(n[0]) == 0 && sgn(n[1]) == 0 && sgn(n[2]) == 0;
}

std::string show(const Vec3& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%a, %a, %a)", p.x(), p.y(), p.z());
  return buf;
}

// Checks all predicates on one quadruple against the oracle, and side3d
// under the permutations that must flip or keep its sign.
void check(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const std::string& what) {
  SCOPED_TRACE(what + ": a=" + show(a) + " b=" + show(b) + " c=" + show(c) + " d=" + show(d));
  const int s = exact_side3d(a, b, c, d);
  ASSERT_EQ(side3d(a, b, c, d), s);
  ASSERT_EQ(side3d(b, c, a, d), s);
  ASSERT_EQ(side3d(b, a, c, d), -s);
  ASSERT_EQ(side3d(d, b, c, a), exact_side3d(d, b, c, a));
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    ASSERT_EQ(orient2d(a[i], a[j], b[i], b[j], d[i], d[j]),
              exact_orient2d(a[i], a[j], b[i], b[j], d[i], d[j]));
  }
  const bool collinear = exact_collinear(a, b, d);
  ASSERT_EQ(collinear3d(a, b, d), collinear);
  // exact_triangle_normal: zero exactly when collinear, else the exact
  // normal's direction within a few u.
  const Vec3 n = exact_triangle_normal(a, b, d);
  if (collinear) {
    ASSERT_EQ(n, Vec3::Zero());
  } else {
    const Q3 qa = rational(a);
    const Q3 e = cross(minus(rational(b), qa), minus(rational(d), qa));
    ASSERT_TRUE(n.allFinite());
    // Same direction within 8 u, in exact arithmetic (no overflow whatever
    // the magnitudes): n . e > 0 and |n x e|^2 <= (8 u)^2 |n|^2 |e|^2.
    const Q3 qn = rational(n);
    ASSERT_GT(sgn(dot(qn, e)), 0) << "normal reversed";
    const Q3 nxe = cross(qn, e);
    const mpq_class tolerance = mpq_class(8 * 0x1p-53) * mpq_class(8 * 0x1p-53);
    EXPECT_LE(dot(nxe, nxe), tolerance * dot(qn, qn) * dot(e, e)) << "normal direction off";
  }
}

// ---------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------

Vec3 random_point(Rng& rng, double r) {
  return {uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r)};
}

// A double nudged by k ulps (k may be negative).
double nudge(double x, int k) {
  for (; k > 0; --k) x = std::nextafter(x, INFINITY);
  for (; k < 0; ++k) x = std::nextafter(x, -INFINITY);
  return x;
}
Vec3 nudge(Rng& rng, const Vec3& p, int ulps) {
  return {nudge(p.x(), uniform_int(rng, -ulps, ulps)), nudge(p.y(), uniform_int(rng, -ulps, ulps)),
          nudge(p.z(), uniform_int(rng, -ulps, ulps))};
}

// m * 2^e with a random 53-bit m and sign, e in [lo, hi]: magnitudes spread
// over many decades (subnormal when e is low enough).
double spread_double(Rng& rng, int lo, int hi) {
  const double m = uniform(rng, 0.5, 1.0) * (rng() & 1 ? 1.0 : -1.0);
  return std::ldexp(m, uniform_int(rng, lo, hi));
}

TEST(ExactPredicates, NearlyCoplanarPoints) {
  Rng rng(1);
  for (int rep = 0; rep < 4000; ++rep) {
    const double r = std::ldexp(1.0, uniform_int(rng, -60, 60));
    const Vec3 a = random_point(rng, r), b = random_point(rng, r), c = random_point(rng, r);
    const double s = uniform01(rng), t = uniform01(rng);
    const Vec3 on_plane = a + s * (b - a) + t * (c - a);  // rounded: near the plane
    check(a, b, c, nudge(rng, on_plane, rep % 4), "nearly coplanar");
    // Far from the origin: a small triangle at a large offset.
    const Vec3 offset = random_point(rng, r * 1e12);
    check(a + offset, b + offset, c + offset, nudge(rng, on_plane + offset, rep % 4),
          "nearly coplanar far away");
  }
}

TEST(ExactPredicates, NearlyCollinearPoints) {
  Rng rng(2);
  for (int rep = 0; rep < 3000; ++rep) {
    const double r = std::ldexp(1.0, uniform_int(rng, -40, 40));
    const Vec3 a = random_point(rng, r), b = random_point(rng, r);
    const Vec3 on_line = a + uniform(rng, -2, 2) * (b - a);
    const Vec3 d = nudge(rng, on_line, rep % 3);
    check(a, b, random_point(rng, r), d, "nearly collinear");
  }
}

TEST(ExactPredicates, ExponentsMixedFrom1eMinus300To1e300) {
  Rng rng(3);
  for (int rep = 0; rep < 4000; ++rep) {
    std::array<Vec3, 4> p;
    for (Vec3& q : p)
      q = {spread_double(rng, -996, 996), spread_double(rng, -996, 996),
           spread_double(rng, -996, 996)};
    check(p[0], p[1], p[2], p[3], "mixed exponents");
    // The same with a huge common part: differences cancel.
    const Vec3 big = drawn([&] { return spread_double(rng, 900, 1000); });
    check(big + p[0] * 0x1p-900, big, big + p[2] * 0x1p-900, big + p[3] * 0x1p-900,
          "huge base, spread offsets");
  }
}

TEST(ExactPredicates, SubnormalAndTinyCoordinates) {
  Rng rng(4);
  for (int rep = 0; rep < 3000; ++rep) {
    std::array<Vec3, 4> p;
    for (Vec3& q : p) {
      for (int k = 0; k < 3; ++k) {
        const int kind = uniform_int(rng, 0, 3);
        q[k] = kind == 0   ? spread_double(rng, -1074, -1023)  // subnormal
               : kind == 1 ? spread_double(rng, -1022, -900)   // tiny normal
               : kind == 2 ? 0.0
                           : spread_double(rng, -10, 10);
      }
    }
    check(p[0], p[1], p[2], p[3], "subnormal and tiny");
    // Exactly the smallest steps: subnormal integer multiples.
    const auto tiny = [&] { return drawn([&] { return uniform_int(rng, -3, 3) * DBL_TRUE_MIN; }); };
    check(tiny(), tiny(), tiny(), tiny(), "multiples of the smallest subnormal");
  }
}

TEST(ExactPredicates, PointsThatDifferInTheLastBit) {
  Rng rng(5);
  for (int rep = 0; rep < 3000; ++rep) {
    const double r = std::ldexp(1.0, uniform_int(rng, -1000, 1000));
    const Vec3 a = random_point(rng, r);
    check(a, nudge(rng, a, 1), nudge(rng, a, 1), nudge(rng, a, 2), "last-bit cluster");
    const Vec3 b = random_point(rng, r);
    check(a, b, nudge(rng, a, 1), nudge(rng, b, 1), "two last-bit pairs");
  }
}

TEST(ExactPredicates, ExactlyCoplanarWithRoundingHostileCoordinates) {
  Rng rng(6);
  const double decimals[] = {0.1, 0.2,   0.3,  1.0 / 3.0,         2.0 / 3.0,
                             0.7, 1e-17, 1e17, 3.3333333333333335};
  const auto decimal = [&] { return decimals[uniform_int(rng, 0, 8)] * (rng() & 1 ? 1.0 : -1.0); };
  for (int rep = 0; rep < 3000; ++rep) {
    // All four on an axis plane (one coordinate shared): exactly coplanar,
    // the other coordinates arbitrary decimals.
    const int axis = rep % 3;
    const double level = decimal() * std::ldexp(1.0, uniform_int(rng, -500, 500));
    std::array<Vec3, 4> p;
    for (Vec3& q : p) {
      const double s = std::ldexp(1.0, uniform_int(rng, -3, 3));
      const double x = decimal() * s, y = decimal() * s, z = decimal() * s;
      q = Vec3(axis == 0 ? level : x, axis == 1 ? level : y, axis == 2 ? level : z);
    }
    ASSERT_EQ(exact_side3d(p[0], p[1], p[2], p[3]), 0);
    check(p[0], p[1], p[2], p[3], "axis plane");
    // On the plane x = y (a diagonal plane).
    std::array<Vec3, 4> diagonal;
    for (std::size_t k = 0; k < 4; ++k) diagonal[k] = Vec3(p[k].y(), p[k].y(), p[k].z());
    check(diagonal[0], diagonal[1], diagonal[2], diagonal[3], "diagonal plane");
    // A parallelogram a, b, c, b + c - a with short dyadic coordinates at a
    // huge or tiny scale: the sum is exact, so the four are coplanar.
    const int e = uniform_int(rng, -1000, 950);
    const auto dyadic = [&] {
      const double s = std::ldexp(1.0, e);
      const double x = uniform_int(rng, -1 << 20, 1 << 20) * s;
      const double y = uniform_int(rng, -1 << 20, 1 << 20) * s;
      const double z = uniform_int(rng, -1 << 20, 1 << 20) * s;
      return Vec3(x, y, z);
    };
    const Vec3 a = dyadic(), b = dyadic(), c = dyadic();
    const Vec3 d = b + c - a;
    ASSERT_EQ(exact_side3d(a, b, c, d), 0);
    check(a, b, c, d, "dyadic parallelogram");
    // Collinear: a, the midpoint, b (exact for short dyadics).
    check(a, b, c, 0.5 * (a + b), "dyadic midpoint");
  }
}

TEST(ExactPredicates, HandCases) {
  const double M = DBL_MAX, m = DBL_TRUE_MIN, n = DBL_MIN;
  const Vec3 o = Vec3::Zero();
  // Degenerate: equal points, all zero.
  check(o, o, o, o, "all zero");
  check(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(7, 8, 9), "repeated point");
  // Unit tetrahedron and its mirror.
  check(o, Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), "unit tetrahedron");
  check(o, Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), "mirrored");
  // The ends of the double range: differences overflow in double.
  check(Vec3(M, -M, M), Vec3(-M, M, M), Vec3(M, M, -M), Vec3(-M, -M, -M), "largest doubles");
  check(Vec3(M, M, M), Vec3(-M, -M, -M), Vec3(M, -M, 0), Vec3(0, 0, 0), "largest doubles, origin");
  check(Vec3(m, 0, 0), Vec3(0, m, 0), Vec3(0, 0, m), Vec3(m, m, m), "smallest subnormals");
  check(Vec3(n, 0, 0), Vec3(0, n, 0), Vec3(0, 0, n), Vec3(-m, -m, -m),
        "smallest normal and subnormal");
  check(Vec3(M, 0, 0), Vec3(0, m, 0), Vec3(0, 0, 1), Vec3(m, m, m), "largest with smallest");
  // Shewchuk's classic: points near the line y = x, 0.5 + k ulp.
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      const double x = nudge(0.5, i), y = nudge(0.5, j);
      check(Vec3(x, y, 0), Vec3(12, 12, 0), Vec3(24, 24, 0), Vec3(x, y, 1),
            "Shewchuk's near-collinear grid");
    }
  }
}

}  // namespace
}  // namespace proxima
