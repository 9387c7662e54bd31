// Tests of the support functions (layer 4): the twins must agree.
//
// support_hill_climb walks the hull's true edges from a hint; on a convex
// polytope a vertex without a strictly better neighbour is a global maximum,
// so its value must equal the brute-force scan's. Compared: the support value
// dir.dot(vertex) of both answers, computed by the test with one expression.
//
// Exactly equal, always, when the value has a clear winner or when every
// dot product is exact (integer data and directions, axis directions on
// dyadic boxes: the plateaus of coplanar faces). The one justified slack:
// directions along a face's unit normal, which is rounded (d = n / |n| for
// an exact integer normal n: each component within 3 u of n's direction).
// On the face, exact values d.x then differ by at most
// |d - n/|n|| |x - y| <= 3 u * 2 sqrt(3) R < 10.4 u R, and each rounded dot
// product is off by at most gamma_3 sum |d_i||v_i| <= 3.0001 u |d|_1 R; hill
// climbing may stop at a vertex that is a local maximum of the rounded values
// only (vertices off the face are far below: integer data). So the values
// differ by at most (10.4 + 2 * 3.0001) u |d|_1 R (|d|_1 >= |d|_2 = 1), and
// kPlateauSlack = 32 leaves a margin of two. The test records how often the
// slack was needed (most plateau queries: rounding noise makes many local
// maxima).
#include "proxima/shape/support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "proxima/shape/polytope.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::drawn;

using Rng = std::mt19937_64;
using Points = std::vector<Vec3>;

// Slack, in units of u |d|_1 R, for directions along rounded unit face
// normals (derivation above; pinned by TiltedPlateausAlongRoundedNormals).
constexpr double kPlateauSlack = 32.0;

double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }
double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }
int uniform_int(Rng& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
}

Vec3 random_direction(Rng& rng) {
  for (;;) {
    const Vec3 d = drawn([&] { return uniform(rng, -1, 1); });
    if (d.squaredNorm() > 1e-4 && d.squaredNorm() <= 1.0) return d;
  }
}

Points sphere_points(Rng& rng, int n) {
  Points pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p = random_direction(rng);
    pts.push_back(p / p.norm());
  }
  return pts;
}

// A box with a g x g grid of points on each face (the faces' interior points
// are not vertices: the plateaus are the corners of each face).
Points box_with_face_grids(const Vec3& half, int g) {
  Points pts;
  for (int a = 0; a <= g; ++a) {
    for (int b = 0; b <= g; ++b) {
      const double s = -1.0 + 2.0 * a / g, t = -1.0 + 2.0 * b / g;
      for (const double side : {-1.0, 1.0}) {
        pts.emplace_back(side * half.x(), s * half.y(), t * half.z());
        pts.emplace_back(s * half.x(), side * half.y(), t * half.z());
        pts.emplace_back(s * half.x(), t * half.y(), side * half.z());
      }
    }
  }
  return pts;
}

// A prism over the integer points of a thin annulus: two faces with many
// vertices each (large plateaus for +-z), exact integer coordinates.
Points annulus_prism(int radius, double height) {
  Points pts;
  for (int x = -radius; x <= radius; ++x) {
    for (int y = -radius; y <= radius; ++y) {
      const int r2 = x * x + y * y;
      if (r2 <= radius * radius && r2 > (radius - 2) * (radius - 2)) {
        pts.emplace_back(x, y, 0.0);
        pts.emplace_back(x, y, height);
      }
    }
  }
  return pts;
}

struct Tally {
  long queries = 0;
  long exact = 0;
  long within_slack = 0;
};

// Compares the twins for one direction and one hint.
void compare(const ConvexPolytope& p, const Vec3& dir, int hint, bool must_be_exact, Tally& tally) {
  const int brute = support_brute_force(p.vertices(), dir);
  const int hill = support_hill_climb(p, dir, hint);
  ASSERT_GE(hill, 0);
  ASSERT_LT(hill, p.vertex_count());
  const double best = dir.dot(p.vertex(brute));
  const double got = dir.dot(p.vertex(hill));
  ++tally.queries;
  if (got == best) {
    ++tally.exact;
    return;
  }
  ASSERT_FALSE(must_be_exact) << "hill climbing value " << got << " != brute force " << best
                              << " (dir " << dir.transpose() << ", hint " << hint << ")";
  const double slack = kPlateauSlack * kUnitRoundoff * dir.lpNorm<1>() * p.scale();
  ASSERT_LE(best - got, slack) << "dir " << dir.transpose() << ", hint " << hint;
  ++tally.within_slack;
}

// Random directions, every hint (small polytopes) or sampled hints plus the
// warm hint (the previous answer) for large ones.
void compare_random_directions(const ConvexPolytope& p, Rng& rng, int directions, Tally& tally) {
  int warm = 0;
  for (int i = 0; i < directions; ++i) {
    const Vec3 dir = random_direction(rng);
    if (p.vertex_count() <= 64) {
      for (int hint = 0; hint < p.vertex_count(); ++hint) compare(p, dir, hint, true, tally);
    } else {
      compare(p, dir, uniform_int(rng, 0, p.vertex_count() - 1), true, tally);
      compare(p, dir, warm, true, tally);
    }
    warm = support_hill_climb(p, dir, warm);
  }
}

// Directions along face normals: plateaus. For integer data the exact
// (unnormalized, integer) normal, so every dot product is exact; otherwise
// face_plane's unit normal, on random clouds whose faces are triangles: its
// three vertices are mutual neighbours and every other vertex is far below,
// so the walk ends at the best of the three and the twins agree exactly.
// Large polytopes: about 200 faces and 20 hints each, spread evenly.
void compare_face_normals(const ConvexPolytope& p, bool integer_data, Tally& tally) {
  const int face_step = std::max(1, p.face_count() / 200);
  for (int f = 0; f < p.face_count(); f += face_step) {
    Vec3 dir = p.face_plane(f).normal;
    if (integer_data) {
      const auto c = p.face(f);
      dir = (p.vertex(c[1]) - p.vertex(c[0])).cross(p.vertex(c[2]) - p.vertex(c[0]));
    }
    const bool all_hints = p.vertex_count() <= 200;
    for (int h = 0; h < (all_hints ? p.vertex_count() : 20); ++h) {
      const int hint =
          all_hints ? h : static_cast<int>((static_cast<long>(h) * 7919) % p.vertex_count());
      compare(p, dir, hint, true, tally);
    }
  }
}

TEST(Support, BruteForceTakesTheFirstOnTies) {
  const Points pts = {{0, 0, 0}, {1, 0, 5}, {1, 0, -5}, {1, 2, 0}, {1, 0, 5}};
  EXPECT_EQ(support_brute_force(pts, Vec3(1, 0, 0)), 1);
  EXPECT_EQ(support_brute_force(pts, Vec3(0, 0, 1)), 1);
  EXPECT_EQ(support_brute_force(pts, Vec3(0, 0, -1)), 2);
  EXPECT_EQ(support_brute_force(pts, Vec3(-1, 0, 0)), 0);
  EXPECT_EQ(support_brute_force(pts, Vec3(0, 0, 0)), 0);
  EXPECT_EQ(support_brute_force(std::vector<Vec3>{{3, 3, 3}}, Vec3(1, 1, 1)), 0);
}

// A unit cube: the corner in direction (1, 1, 1) is found from every hint;
// in direction +z the whole top face is a plateau and every hint on it is
// already an answer (the walk does not move on equal values).
TEST(Support, CubeHandCases) {
  const ConvexPolytope cube(box_with_face_grids(Vec3(1, 1, 1), 1));
  ASSERT_EQ(cube.vertex_count(), 8);
  int top = -1;
  for (int v = 0; v < 8; ++v) {
    if (cube.vertex(v) == Vec3(1, 1, 1)) top = v;
  }
  ASSERT_GE(top, 0);
  for (int hint = 0; hint < 8; ++hint) {
    EXPECT_EQ(support_hill_climb(cube, Vec3(1, 1, 1), hint), top);
    const int on_top = support_hill_climb(cube, Vec3(0, 0, 1), hint);
    EXPECT_EQ(cube.vertex(on_top).z(), 1.0);
    if (cube.vertex(hint).z() == 1.0) {
      EXPECT_EQ(on_top, hint);
    }
  }
}

TEST(Support, OutOfRangeHintIsVertexZero) {
  Rng rng(3);
  const ConvexPolytope p(sphere_points(rng, 100));
  const Vec3 dir(0.3, -0.2, 0.9);
  const int expected = support_hill_climb(p, dir, 0);
  for (const int hint : {-1, -100, 100, 101, INT_MAX, INT_MIN})
    EXPECT_EQ(support_hill_climb(p, dir, hint), expected);
  EXPECT_EQ(dir.dot(p.vertex(expected)), dir.dot(p.vertex(support_brute_force(p.vertices(), dir))));
}

// support_without_hint (a cold start's search): the brute-force scan itself
// up to kScanVertices vertices, the same index; beyond, a climb from the
// best of evenly spaced seeds, a maximizer like the scan's. Sizes around
// the scan limit and around multiples of the seed count (the stride
// n / kSupportSeeds, the last seed next to the end), plateaus of boxes with
// face grids (integer coordinates: exact dot products), polygons, a
// segment and a point.
TEST(Support, WithoutHintIsTheScanOnSmallBodiesAndAMaximizerOnLarge) {
  Rng rng(107);
  std::vector<ConvexPolytope> bodies;
  for (const int n : {4, 5, 8, kScanVertices - 1, kScanVertices, kScanVertices + 1, 31, 32, 33,
                      2 * kSupportSeeds - 1, 100, 1000, 4097}) {
    bodies.emplace_back(sphere_points(rng, n));
  }
  bodies.emplace_back(box_with_face_grids(Vec3(2, 1, 3), 4));
  bodies.emplace_back(annulus_prism(6, 1.0));
  Points hexagon;
  for (int k = 0; k < 6; ++k)
    hexagon.emplace_back(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3), 0.5);
  bodies.emplace_back(hexagon);
  bodies.emplace_back(Points{{0, 0, 0}, {1, 2, 3}});
  bodies.emplace_back(Points{{1, 2, 3}});
  long scanned = 0;
  long climbed = 0;
  for (const ConvexPolytope& p : bodies) {
    SCOPED_TRACE("vertices " + std::to_string(p.vertex_count()));
    std::vector<Vec3> dirs;
    for (int i = 0; i < 300; ++i) dirs.push_back(random_direction(rng));
    for (int f = 0; f < p.face_count(); ++f) dirs.push_back(p.face_plane(f).normal);
    for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}) {
      dirs.push_back(axis);
      dirs.push_back(-axis);
    }
    for (const Vec3& dir : dirs) {
      const int brute = support_brute_force(p.vertices(), dir);
      const int got = support_without_hint(p, dir);
      ASSERT_GE(got, 0);
      ASSERT_LT(got, p.vertex_count());
      if (p.vertex_count() <= kScanVertices) {
        ASSERT_EQ(got, brute) << dir.transpose();
        ++scanned;
      } else {
        ASSERT_EQ(dir.dot(p.vertex(got)), dir.dot(p.vertex(brute))) << dir.transpose();
        ++climbed;
      }
    }
  }
  EXPECT_GT(scanned, 1000);  // premise: both regimes ran
  EXPECT_GT(climbed, 1000);
}

// ConvexPolytope::support_start's table: at the centre of every cell the
// start is the support itself (the table holds the cell centre's support),
// so a wrong cell index, a face or axis mixed up, or a table lost or
// misplaced by a copy or a move gives a start below the maximum there; on
// random directions the start is a vertex id in range and the climb from
// it a maximizer. Small hulls (scanned) and refused directions (zero, NaN,
// infinite) have no start.
TEST(Support, TableStartIsTheSupportAtCellCentres) {
  Rng rng(211);
  std::vector<ConvexPolytope> bodies;
  for (const int n : {ConvexPolytope::kTableMinVertices + 1, 100, 2000})
    bodies.emplace_back(sphere_points(rng, n));
  Points thin = sphere_points(rng, 300);  // a flat ellipsoid: far from round
  for (Vec3& x : thin) x = x.cwiseProduct(Vec3(3.0, 1.0, 1e-3));
  bodies.emplace_back(thin);
  long centres = 0;
  for (const ConvexPolytope& built : bodies) {
    const ConvexPolytope copy(built);
    ConvexPolytope moved_from(built);
    const ConvexPolytope moved(std::move(moved_from));
    for (const ConvexPolytope* p : {&built, &copy, &moved}) {
      SCOPED_TRACE("vertices " + std::to_string(p->vertex_count()));
      const int cells = std::max(1, p->vertex_count() / ConvexPolytope::kTableVerticesPerCell);
      const int side = static_cast<int>(std::ceil(std::sqrt(cells / 6.0)));
      for (int axis = 0; axis < 3; ++axis)
        for (const double sign : {1.0, -1.0})
          for (int row = 0; row < side; ++row)
            for (int column = 0; column < side; ++column) {
              Vec3 d;
              d[axis] = sign;
              d[(axis + 1) % 3] = -1.0 + (2.0 * row + 1.0) / side;
              d[(axis + 2) % 3] = -1.0 + (2.0 * column + 1.0) / side;
              const int start = p->support_start(d);
              ASSERT_GE(start, 0);
              ASSERT_EQ(d.dot(p->vertex(start)),
                        d.dot(p->vertex(support_brute_force(p->vertices(), d))))
                  << d.transpose();
              ++centres;
            }
      for (int i = 0; i < 200; ++i) {
        const Vec3 d = random_direction(rng) * std::pow(10.0, uniform(rng, -300, 300));
        const int start = p->support_start(d);
        ASSERT_GE(start, 0);
        ASSERT_LT(start, p->vertex_count());
        const int got = support_hill_climb(*p, d, start);
        ASSERT_EQ(d.dot(p->vertex(got)), d.dot(p->vertex(support_brute_force(p->vertices(), d))));
      }
      const double inf = std::numeric_limits<double>::infinity();
      for (const Vec3& refused : {Vec3(0, 0, 0), Vec3(std::nan(""), 1, 0), Vec3(inf, 0, 0)})
        EXPECT_EQ(p->support_start(refused), -1);
    }
  }
  EXPECT_GT(centres, 2000);  // premise: the tables were walked
  const ConvexPolytope small(sphere_points(rng, ConvexPolytope::kTableMinVertices));
  EXPECT_EQ(small.support_start(Vec3(1, 0, 0)), -1);
}

TEST(Support, RandomSpherePolytopes) {
  Rng rng(101);
  Tally tally;
  for (const int n : {4, 5, 8, 16, 64, 256, 1000, 10000}) {
    SCOPED_TRACE("sphere n=" + std::to_string(n));
    const ConvexPolytope p(sphere_points(rng, n));
    ASSERT_EQ(p.vertex_count(), n);
    compare_random_directions(p, rng, n <= 64 ? 300 : 2000, tally);
    compare_face_normals(p, false, tally);
  }
  EXPECT_GT(tally.queries, 50000);
  EXPECT_EQ(tally.exact, tally.queries);
}

TEST(Support, RandomCubeClouds) {
  Rng rng(102);
  Tally tally;
  for (const int n : {10, 100, 1000, 10000}) {
    SCOPED_TRACE("cube cloud n=" + std::to_string(n));
    Points pts;
    for (int i = 0; i < n; ++i) pts.push_back(drawn([&] { return uniform(rng, -1, 1); }));
    const ConvexPolytope p(pts);
    compare_random_directions(p, rng, 2000, tally);
    compare_face_normals(p, false, tally);
  }
  EXPECT_EQ(tally.exact, tally.queries);
}

// Integer data: every dot product with an integer direction is exact, so
// plateaus are exact ties and the twins must agree exactly.
TEST(Support, IntegerGridPolytopesExactPlateaus) {
  Rng rng(103);
  Tally tally;
  for (const int g : {1, 2, 4, 10}) {
    for (int rep = 0; rep < 3; ++rep) {
      Points pts;
      for (int i = 0; i < 300; ++i) pts.push_back(drawn([&] { return uniform_int(rng, -g, g); }));
      const ConvexPolytope p(pts);
      ASSERT_EQ(p.dimension(), 3);
      compare_face_normals(p, true, tally);
      for (int i = 0; i < 200; ++i) {
        const Vec3 dir = drawn([&] { return uniform_int(rng, -2, 2); });
        for (int hint = 0; hint < p.vertex_count(); ++hint) compare(p, dir, hint, true, tally);
      }
      compare_random_directions(p, rng, 200, tally);
    }
  }
  EXPECT_EQ(tally.exact, tally.queries);
}

// Boxes with grids on their faces, at several scales and aspect ratios:
// axis directions hit the face plateaus exactly.
TEST(Support, BoxesWithFaceGrids) {
  Rng rng(104);
  Tally tally;
  for (const Vec3& half : {Vec3(1, 1, 1), Vec3(4, 0.5, 0.125), Vec3(0x1p-40, 0x1p-38, 0x1p-41),
                           Vec3(0x1p60, 1, 0x1p30)}) {
    const ConvexPolytope p(box_with_face_grids(half, 6));
    ASSERT_EQ(p.vertex_count(), 8);
    for (int axis = 0; axis < 3; ++axis) {
      for (const double sign : {-1.0, 1.0}) {
        const Vec3 dir = sign * Vec3::Unit(axis);
        for (int hint = 0; hint < 8; ++hint) compare(p, dir, hint, true, tally);
      }
    }
    compare_face_normals(p, true, tally);
    compare_random_directions(p, rng, 500, tally);
  }
  EXPECT_EQ(tally.exact, tally.queries);
}

// A prism over an integer annulus: faces with many vertices. Directions
// +-z are plateaus of ~100 vertices; directions close to z make the walk run
// along the polygon's boundary.
TEST(Support, PrismWithLargePlateaus) {
  Rng rng(105);
  Tally tally;
  const ConvexPolytope p(annulus_prism(40, 3.0));
  ASSERT_EQ(p.dimension(), 3);
  std::size_t largest = 0;
  for (int f = 0; f < p.face_count(); ++f) largest = std::max(largest, p.face(f).size());
  EXPECT_GE(largest, 40u);  // the hard case is really there
  for (int hint = 0; hint < p.vertex_count(); ++hint) {
    compare(p, Vec3(0, 0, 1), hint, true, tally);
    compare(p, Vec3(0, 0, -1), hint, true, tally);
  }
  for (int i = 0; i < 300; ++i) {
    const Vec3 dir = drawn([&] { return uniform(rng, -1e-3, 1e-3); },
                           [&] { return uniform(rng, -1e-3, 1e-3); }, [&] { return 1.0; });
    compare(p, dir, uniform_int(rng, 0, p.vertex_count() - 1), true, tally);
  }
  compare_face_normals(p, true, tally);
  compare_random_directions(p, rng, 1000, tally);
  EXPECT_EQ(tally.exact, tally.queries);
}

// Tilted faces with many exactly coplanar vertices, probed along their
// rounded unit normals: the one case that needs the slack. A
// prism over an exactly tilted disc (integer combinations of integer
// vectors), and the disc itself.
TEST(Support, TiltedPlateausAlongRoundedNormals) {
  Rng rng(108);
  Points disc;
  for (int i = 0; i < 3000; ++i) {
    const double a = uniform_int(rng, -300, 300), b = uniform_int(rng, -300, 300);
    if (a * a + b * b <= 90000) disc.push_back(a * Vec3(2, 3, 6) + b * Vec3(3, -6, 2));
  }
  Points prism = disc;
  for (const Vec3& q : disc) prism.push_back(q + Vec3(6, 2, -3) * 40.0);
  Tally tally;
  for (const Points* pts : {&disc, &prism}) {
    const ConvexPolytope p(*pts);
    std::size_t largest = 0;
    for (int f = 0; f < p.face_count(); ++f) largest = std::max(largest, p.face(f).size());
    EXPECT_GE(largest, 40u);
    for (int f = 0; f < p.face_count(); ++f) {
      if (p.face(f).size() < 40) continue;
      const auto c = p.face(f);
      const Vec3 n = (p.vertex(c[1]) - p.vertex(c[0]))
                         .cross(p.vertex(c[2]) - p.vertex(c[0]));  // exact: integers
      const Vec3 dir = n / n.norm();
      for (int hint = 0; hint < p.vertex_count(); ++hint) compare(p, dir, hint, false, tally);
    }
  }
  EXPECT_GT(tally.queries, 200);
  // Report how often the rounded plateau needed the slack.
  RecordProperty("queries", std::to_string(tally.queries));
  RecordProperty("within_slack", std::to_string(tally.within_slack));
}

// Lower-dimensional polytopes: polygons (the whole polygon is a plateau for
// its normal), segments (a plateau for any orthogonal direction) and points.
TEST(Support, PolygonsSegmentsAndPoints) {
  Rng rng(106);
  Tally tally;
  {
    Points disc;
    for (int x = -30; x <= 30; ++x) {
      for (int y = -30; y <= 30; ++y) {
        if (x * x + y * y <= 900) disc.emplace_back(0.5 * x, 0.25 * y, 0.1);
      }
    }
    const ConvexPolytope p(disc);
    ASSERT_EQ(p.dimension(), 2);
    EXPECT_GT(p.vertex_count(), 20);
    for (int hint = 0; hint < p.vertex_count(); ++hint) {
      compare(p, Vec3(0, 0, 1), hint, true, tally);
      EXPECT_EQ(support_hill_climb(p, Vec3(0, 0, -1), hint), hint);  // all tie: stay
    }
    compare_random_directions(p, rng, 500, tally);
    for (int i = 0; i < 200; ++i)
      compare(p,
              drawn([&] { return uniform_int(rng, -3, 3); },
                    [&] { return uniform_int(rng, -3, 3); }, [&] { return 1; }),
              i % p.vertex_count(), true, tally);
  }
  {
    // An exactly tilted polygon: integer combinations of integer vectors.
    Points tilted;
    for (int i = 0; i < 2000; ++i) {
      const double a = uniform_int(rng, -500, 500), b = uniform_int(rng, -500, 500);
      if (a * a + b * b <= 250000) tilted.push_back(a * Vec3(1, 2, 2) + b * Vec3(2, -2, 1));
    }
    const ConvexPolytope p(tilted);
    ASSERT_EQ(p.dimension(), 2);
    compare_random_directions(p, rng, 500, tally);
    compare_face_normals(p, true, tally);
  }
  {
    Points seg;
    for (int i = 0; i < 50; ++i) {
      const double t = uniform_int(rng, -1000, 1000);
      seg.emplace_back(t, -2 * t, 0.5 * t);
    }
    const ConvexPolytope p(seg);
    ASSERT_EQ(p.dimension(), 1);
    compare_random_directions(p, rng, 500, tally);
    compare(p, Vec3(2, 1, 0), 0, true, tally);  // orthogonal: a plateau
    compare(p, Vec3(2, 1, 0), 1, true, tally);
  }
  {
    const ConvexPolytope p(Points(10, Vec3(1, 2, 3)));
    ASSERT_EQ(p.dimension(), 0);
    EXPECT_EQ(support_hill_climb(p, Vec3(1, 0, 0), 0), 0);
    compare_random_directions(p, rng, 100, tally);
  }
  EXPECT_EQ(tally.exact, tally.queries);
}

// Tracking: a slowly rotating direction with the previous answer as hint
// stays exact along the way.
TEST(Support, WarmHintAlongRotatingDirection) {
  Rng rng(107);
  const ConvexPolytope p(sphere_points(rng, 4096));
  Tally tally;
  int hint = 0;
  for (int i = 0; i < 5000; ++i) {
    const double angle = 1e-3 * i;
    const Vec3 dir(std::cos(angle), std::sin(angle) * std::cos(0.3 * angle),
                   std::sin(angle) * std::sin(0.3 * angle));
    compare(p, dir, hint, true, tally);
    hint = support_hill_climb(p, dir, hint);
  }
  EXPECT_EQ(tally.exact, tally.queries);
}

// support_hill_climb_through_plateaus against the brute-force scan on
// rounded prisms (issue 25: PenetrationRegression.PrismsWithCoplanarFacetsAtSmallScale),
// whose caps rounding splits into nearly coplanar faces with nearly flat
// vertices: climbed from every vertex along each cap's normal (the plain
// climb's trap: from the far cap, every edge at a nearly flat vertex rises
// by less than the rounding) and along directions a few u off it. The
// value must be within its proven bound, 2 gamma_3 |d|_1 scale() of the
// maximum (support.h), at scales 1e-6 to 1e6. The set holds the trap: the
// plain climb stops far below the maximum on some of them (counted).
TEST(Support, ThroughPlateausOfRoundedPrismCaps) {
  Rng rng(20261129);
  int trapped = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 w = test::random_unit_vector(rng);
    const double s = test::log_uniform(rng, 1e-6, 1e6);
    const ConvexPolytope p(test::rounded_prism(rng, w, s, s * uniform(rng, 0.1, 1.0),
                                               uniform_int(rng, 6, 16), Vec3::Zero()));
    bool plain_trapped = false;
    for (const double sign : {1.0, -1.0}) {
      for (int k = 0; k < 3; ++k) {
        const Vec3 d = (sign * w + (k == 0 ? 0.0 : 4 * kUnitRoundoff) * test::random_unit_vector(rng))
                           .normalized();
        const double best = d.dot(p.vertex(support_brute_force(p.vertices(), d)));
        const double bound = 2 * 3.01 * kUnitRoundoff * d.lpNorm<1>() * p.scale();
        for (int hint = 0; hint < p.vertex_count(); ++hint) {
          const int v = support_hill_climb_through_plateaus(p, d, hint);
          ASSERT_GE(d.dot(p.vertex(v)), best - bound)
              << "trial " << trial << ", hint " << hint << ", direction " << d.transpose();
          plain_trapped =
              plain_trapped || d.dot(p.vertex(support_hill_climb(p, d, hint))) < best - 0.01 * s;
        }
      }
    }
    trapped += plain_trapped;
  }
  EXPECT_GE(trapped, 5);
}

}  // namespace
}  // namespace proxima
