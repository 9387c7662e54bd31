// Tests of the GJK baselines (gjk.h), called directly in A's frame:
//   - hand-computed cases with their witness features (cubes apart along an
//     axis and a diagonal, a point against each region of a tetrahedron,
//     parallel faces, crossing edges), touching and intersecting contacts;
//   - seeded random polytopes (points on spheres, 4..500 vertices, and a few
//     polygons, segments and points) against a brute force over all
//     vertex/edge/triangle pairs written here, with a check that the random
//     set really contains vertex-face and edge-edge answers;
//   - optimality certificates: the closest points' difference is a
//     separating direction, and lower_bound <= distance;
//   - Enhanced GJK equal to classic GJK along a motion with a tracking cache,
//     and with caches from another pair or full of garbage ids;
//   - the iteration cap, and scale (1e-23 .. 1e120) without NaN or inf;
//   - regressions (thin simplices) against the exact oracle.
#include "proxima/detail/narrowphase/gjk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/accuracy.h"
#include "narrowphase/gjk_contact.h"
#include "proxima/query/distance.h"
#include "support/exact_oracle.h"
#include "support/generators.h"
#include "support/sanitizers.h"

namespace proxima {
namespace {

using test::drawn;
using test::drawn_quaternion;

using Rng = std::mt19937_64;

// Portable draws (std::*_distribution algorithms are implementation-defined):
// a uniform double from 53 random bits.
double uniform(Rng& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1p-53);
}
int uniform_int(Rng& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
}
Vec3 random_unit(Rng& rng) {
  for (;;) {
    const Vec3 p = drawn([&] { return uniform(rng, -1, 1); });
    const double n2 = p.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) return p / std::sqrt(n2);
  }
}
Mat3 random_rotation(Rng& rng) {
  for (;;) {
    const Quat q = drawn_quaternion([&] { return uniform(rng, -1, 1); });
    if (q.squaredNorm() > 1e-4 && q.squaredNorm() <= 1.0) return q.normalized().toRotationMatrix();
  }
}

std::vector<Vec3> box(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i) {
    pts.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  }
  return pts;
}
std::vector<Vec3> unit_cube() { return box(Vec3::Zero(), Vec3::Ones()); }

std::vector<Vec3> sphere_points(Rng& rng, int n, double radius) {
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(radius * random_unit(rng));
  return pts;
}

// A random body: mostly points on a sphere (4..500 of them, small counts
// more often), sometimes a polygon (points on a circle), a segment or a
// point, so that lower-dimensional hulls are exercised too.
std::vector<Vec3> random_body(Rng& rng, int max_vertices) {
  const int kind = uniform_int(rng, 0, 19);
  if (kind == 0) return {random_unit(rng)};
  if (kind == 1) return {random_unit(rng), random_unit(rng)};
  const int n = std::min(max_vertices, kind < 12 ? uniform_int(rng, 4, 16) : uniform_int(rng, 4, max_vertices));
  std::vector<Vec3> pts = sphere_points(rng, n, uniform(rng, 0.3, 1.5));
  if (kind == 2 || kind == 3) {
    for (Vec3& p : pts) p.z() = 0.0;  // a polygon
  }
  return pts;
}

// The contact band of the accuracy standard, with R taken exactly (B's
// vertices mapped into A's frame, here in the test only).
double largest_coordinate(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a) {
  double r = 0.0;
  for (const Vec3& x : a.vertices()) r = std::max(r, x.cwiseAbs().maxCoeff());
  for (const Vec3& y : b.vertices()) r = std::max(r, b_in_a.apply(y).cwiseAbs().maxCoeff());
  return r;
}
double contact_band(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a) {
  return 64.0 * kUnitRoundoff * largest_coordinate(a, b, b_in_a);
}

// ---------------------------------------------------------------------------
// The slow, obvious twin: the minimum over all vertex/edge/triangle pairs of
// both hulls. Disjoint convex hulls are closest at a vertex-face or edge-edge
// pair (lower ones included); a polygon is its fan triangles, a segment its
// edge. Each primitive distance is the minimum over the closed pieces, which
// keeps every case explicit.
// ---------------------------------------------------------------------------
double point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 e = b - a;
  const double ee = e.squaredNorm();
  const double t = ee > 0.0 ? std::clamp((p - a).dot(e) / ee, 0.0, 1.0) : 0.0;
  return (a + t * e - p).norm();
}

double point_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  double best = std::min({point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a)});
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn > 0.0) {
    const Vec3 q = p - n * (n.dot(p - a) / nn);  // projection onto the plane
    const bool inside = n.dot((b - a).cross(q - a)) >= 0.0 && n.dot((c - b).cross(q - b)) >= 0.0 &&
                        n.dot((a - c).cross(q - c)) >= 0.0;
    if (inside) best = std::min(best, (p - q).norm());
  }
  return best;
}

// The minimum over the unit square of |p + s d1 - q - t d2| is at the
// interior critical point (when it exists and is inside) or on the square's
// boundary, i.e. an endpoint against the other segment.
double segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  double best = std::min({point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1),
                          point_segment(q1, p0, p1)});
  const Vec3 d1 = p1 - p0;
  const Vec3 d2 = q1 - q0;
  const Vec3 r = p0 - q0;
  const double a = d1.dot(d1);
  const double b = d1.dot(d2);
  const double c = d2.dot(d2);
  const double d = d1.dot(r);
  const double e = d2.dot(r);
  const double den = a * c - b * b;
  if (den > 1e-14 * a * c) {
    const double s = (b * e - c * d) / den;
    const double t = (a * e - b * d) / den;
    if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) best = std::min(best, (r + s * d1 - t * d2).norm());
  }
  return best;
}

struct Pieces {
  std::vector<Vec3> vertices;
  std::vector<std::array<Vec3, 2>> edges;
  std::vector<std::array<Vec3, 3>> triangles;
};

Pieces pieces(const ConvexPolytope& p, const Pose& pose) {
  Pieces out;
  for (const Vec3& v : p.vertices()) out.vertices.push_back(pose.apply(v));
  for (const auto& e : p.edges()) out.edges.push_back({pose.apply(p.vertex(e[0])), pose.apply(p.vertex(e[1]))});
  for (const auto& t : p.triangles()) {
    out.triangles.push_back({pose.apply(p.vertex(t[0])), pose.apply(p.vertex(t[1])), pose.apply(p.vertex(t[2]))});
  }
  return out;
}

double brute_force_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a) {
  const Pieces pa = pieces(a, Pose::identity());
  const Pieces pb = pieces(b, b_in_a);
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& x : pa.vertices) {
    for (const Vec3& y : pb.vertices) best = std::min(best, (x - y).norm());
    for (const auto& e : pb.edges) best = std::min(best, point_segment(x, e[0], e[1]));
    for (const auto& t : pb.triangles) best = std::min(best, point_triangle(x, t[0], t[1], t[2]));
  }
  for (const Vec3& y : pb.vertices) {
    for (const auto& e : pa.edges) best = std::min(best, point_segment(y, e[0], e[1]));
    for (const auto& t : pa.triangles) best = std::min(best, point_triangle(y, t[0], t[1], t[2]));
  }
  for (const auto& e : pa.edges) {
    for (const auto& f : pb.edges) best = std::min(best, segment_segment(e[0], e[1], f[0], f[1]));
  }
  return best;
}

// How far x is outside the hull (0 inside): the largest face-plane
// violation of a solid; for lower-dimensional hulls the distance to the
// pieces (the polygon's fan triangles, the segment, the point).
double outside_by(const ConvexPolytope& p, const Pose& pose, const Vec3& x) {
  if (p.dimension() == 3) {
    double worst = 0.0;
    for (int f = 0; f < p.face_count(); ++f) {
      const Plane pl = p.face_plane(f);
      const Vec3 n = pose.rotation * pl.normal;
      worst = std::max(worst, n.dot(x) - (pl.offset + n.dot(pose.translation)));
    }
    return worst;
  }
  const Pieces pc = pieces(p, pose);
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& v : pc.vertices) best = std::min(best, (x - v).norm());
  for (const auto& e : pc.edges) best = std::min(best, point_segment(x, e[0], e[1]));
  for (const auto& t : pc.triangles) best = std::min(best, point_triangle(x, t[0], t[1], t[2]));
  return best;
}

// How deep x is inside a solid hull (negative outside).
double depth(const ConvexPolytope& p, const Pose& pose, const Vec3& x) {
  double d = std::numeric_limits<double>::infinity();
  for (int f = 0; f < p.face_count(); ++f) {
    const Plane pl = p.face_plane(f);
    const Vec3 n = pose.rotation * pl.normal;
    d = std::min(d, pl.offset + n.dot(pose.translation) - n.dot(x));
  }
  return d;
}

int vertex_at(const ConvexPolytope& p, const Vec3& x) {
  for (int i = 0; i < p.vertex_count(); ++i) {
    if (p.vertex(i) == x) return i;
  }
  return -1;
}

void expect_finite(const DistanceResult& r) {
  EXPECT_TRUE(std::isfinite(r.distance));
  EXPECT_TRUE(std::isfinite(r.lower_bound));
  EXPECT_TRUE(r.point_a.allFinite());
  EXPECT_TRUE(r.point_b.allFinite());
  EXPECT_TRUE(r.normal.allFinite());
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
  EXPECT_GE(r.lower_bound, 0.0);
  EXPECT_LE(r.lower_bound, r.distance);
}

// Every vertex id of the feature is valid, and the feature is well formed:
// a vertex has one id, an edge two adjacent ids, a face the hull face id
// whose polygon holds its ids.
void expect_well_formed(const ConvexPolytope& p, const Feature& f) {
  const int n = f.vertex_count();
  ASSERT_GE(n, 1);
  for (int i = 0; i < n; ++i) {
    EXPECT_GE(f.vertices[static_cast<std::size_t>(i)], 0);
    EXPECT_LT(f.vertices[static_cast<std::size_t>(i)], p.vertex_count());
  }
  switch (f.type) {
    case FeatureType::vertex: EXPECT_EQ(n, 1); break;
    case FeatureType::edge: {
      ASSERT_EQ(n, 2);
      const auto nb = p.neighbors(f.vertices[0]);
      EXPECT_NE(std::find(nb.begin(), nb.end(), f.vertices[1]), nb.end());
      break;
    }
    case FeatureType::face: {
      ASSERT_GE(f.face, 0);
      ASSERT_LT(f.face, p.face_count());
      const auto poly = p.face(f.face);
      for (int i = 0; i < n; ++i) {
        EXPECT_NE(std::find(poly.begin(), poly.end(), f.vertices[static_cast<std::size_t>(i)]), poly.end());
      }
      break;
    }
  }
}

DistanceOptions gjk_options() {
  DistanceOptions o;
  o.algorithm = Algorithm::gjk;
  return o;
}

// ---------------------------------------------------------------------------
// Hand cases.
// ---------------------------------------------------------------------------

TEST(Gjk, UnitCubesApartAlongX) {
  const ConvexPolytope cube(unit_cube());
  const Pose b_in_a = Pose::from_translation(Vec3(3, 0, 0));
  for (const bool enhanced : {false, true}) {
    DistanceCache cache;
    const DistanceResult r = enhanced ? enhanced_gjk_distance(cube, cube, b_in_a, gjk_options(), 1e-14, cache)
                                      : gjk_distance(cube, cube, b_in_a, gjk_options(), 1e-14);
    expect_finite(r);
    EXPECT_EQ(r.status, Status::separated);
    EXPECT_NEAR(r.distance, 2.0, 1e-15);
    EXPECT_NEAR(r.lower_bound, 2.0, 1e-12);
    EXPECT_NEAR(r.point_a.x(), 1.0, 1e-15);
    EXPECT_NEAR(r.point_b.x(), 3.0, 1e-15);
    EXPECT_NEAR(r.point_a.y(), r.point_b.y(), 1e-15);
    EXPECT_NEAR(r.point_a.z(), r.point_b.z(), 1e-15);
    EXPECT_NEAR(r.normal.x(), 1.0, 1e-15);
    // Parallel faces: any witness within the facing faces is right.
    expect_well_formed(cube, r.feature_a);
    expect_well_formed(cube, r.feature_b);
    for (int i = 0; i < r.feature_a.vertex_count(); ++i) EXPECT_EQ(cube.vertex(r.feature_a.vertices[static_cast<std::size_t>(i)]).x(), 1.0);
    for (int i = 0; i < r.feature_b.vertex_count(); ++i) EXPECT_EQ(cube.vertex(r.feature_b.vertices[static_cast<std::size_t>(i)]).x(), 0.0);
    if (r.feature_a.type == FeatureType::face) {
      EXPECT_NEAR(cube.face_plane(r.feature_a.face).normal.x(), 1.0, 1e-15);
    }
    if (r.feature_b.type == FeatureType::face) {
      EXPECT_NEAR(cube.face_plane(r.feature_b.face).normal.x(), -1.0, 1e-15);
    }
  }
}

TEST(Gjk, UnitCubesApartAlongDiagonal) {
  const ConvexPolytope cube(unit_cube());
  const Pose b_in_a = Pose::from_translation(Vec3(2, 2, 2));
  const DistanceResult r = gjk_distance(cube, cube, b_in_a, gjk_options(), 1e-14);
  expect_finite(r);
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(r.lower_bound, std::sqrt(3.0), 1e-12);
  EXPECT_TRUE(r.point_a.isApprox(Vec3(1, 1, 1), 1e-15));
  EXPECT_TRUE(r.point_b.isApprox(Vec3(2, 2, 2), 1e-15));
  EXPECT_TRUE(r.normal.isApprox(Vec3(1, 1, 1).normalized(), 1e-15));
  EXPECT_EQ(r.feature_a.type, FeatureType::vertex);
  EXPECT_EQ(r.feature_a.vertices[0], vertex_at(cube, Vec3(1, 1, 1)));
  EXPECT_EQ(r.feature_b.type, FeatureType::vertex);
  EXPECT_EQ(r.feature_b.vertices[0], vertex_at(cube, Vec3(0, 0, 0)));
}

TEST(Gjk, PointAgainstEachRegionOfATetrahedron) {
  const ConvexPolytope tet(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)});
  const int o = vertex_at(tet, Vec3(0, 0, 0));
  const int x = vertex_at(tet, Vec3(1, 0, 0));
  const int y = vertex_at(tet, Vec3(0, 1, 0));
  const int z = vertex_at(tet, Vec3(0, 0, 1));
  struct Case {
    Vec3 point;
    double distance;
    Vec3 closest;
    FeatureType type;
    std::array<int, 3> ids;  // sorted, -1 unused
  };
  const auto sorted = [](std::array<int, 3> v) {
    std::sort(v.begin(), v.begin() + (v[2] >= 0 ? 3 : v[1] >= 0 ? 2 : 1));
    return v;
  };
  const Case cases[] = {
      {Vec3(1, 1, 1), 2.0 / std::sqrt(3.0), Vec3::Constant(1.0 / 3.0), FeatureType::face, sorted({x, y, z})},
      {Vec3(-1, -1, -1), std::sqrt(3.0), Vec3::Zero(), FeatureType::vertex, {o, -1, -1}},
      {Vec3(0.5, -1, -1), std::sqrt(2.0), Vec3(0.5, 0, 0), FeatureType::edge, sorted({o, x, -1})},
      {Vec3(0.25, 0.25, -2), 2.0, Vec3(0.25, 0.25, 0), FeatureType::face, sorted({o, x, y})},
      {Vec3(3, 0, 0), 2.0, Vec3(1, 0, 0), FeatureType::vertex, {x, -1, -1}},
  };
  for (const Case& c : cases) {
    const ConvexPolytope point(std::vector<Vec3>{Vec3::Zero()});
    // The point is body A at the origin; the tetrahedron is B, placed so
    // that in A's frame it sits at its given coordinates.
    const Pose b_in_a = Pose::from_translation(-c.point);
    for (const bool enhanced : {false, true}) {
      DistanceCache cache;
      const DistanceResult r = enhanced ? enhanced_gjk_distance(point, tet, b_in_a, gjk_options(), 1e-14, cache)
                                        : gjk_distance(point, tet, b_in_a, gjk_options(), 1e-14);
      expect_finite(r);
      EXPECT_EQ(r.status, Status::separated);
      EXPECT_NEAR(r.distance, c.distance, 1e-15);
      EXPECT_TRUE(r.point_b.isApprox(c.closest - c.point, 1e-15)) << r.point_b.transpose();
      EXPECT_EQ(r.feature_a.type, FeatureType::vertex);
      EXPECT_EQ(r.feature_a.vertices[0], 0);
      EXPECT_EQ(r.feature_b.type, c.type) << to_string(r.feature_b.type);
      std::array<int, 3> got = {r.feature_b.vertices[0], r.feature_b.vertices[1], r.feature_b.vertices[2]};
      EXPECT_EQ(got, c.ids);
      expect_well_formed(tet, r.feature_b);
    }
  }
}

TEST(Gjk, ParallelFacesOverlappingInProjection) {
  const ConvexPolytope a(unit_cube());
  const ConvexPolytope b(box(Vec3(0, 0, 0), Vec3(2, 0.5, 1)));
  const Pose b_in_a = Pose::from_translation(Vec3(0.5, 0.3, 1.5));
  const DistanceResult r = gjk_distance(a, b, b_in_a, gjk_options(), 1e-14);
  expect_finite(r);
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  EXPECT_NEAR(r.point_a.z(), 1.0, 1e-15);
  EXPECT_NEAR(r.point_b.z(), 1.5, 1e-15);
  // The witnesses lie where the facing faces overlap: x in [0.5, 1], y in [0.3, 0.8].
  EXPECT_GE(r.point_a.x(), 0.5 - 1e-15);
  EXPECT_LE(r.point_a.x(), 1.0 + 1e-15);
  EXPECT_GE(r.point_a.y(), 0.3 - 1e-15);
  EXPECT_LE(r.point_a.y(), 0.8 + 1e-15);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ(), 1e-15));
  for (int i = 0; i < r.feature_a.vertex_count(); ++i) EXPECT_EQ(a.vertex(r.feature_a.vertices[static_cast<std::size_t>(i)]).z(), 1.0);
  for (int i = 0; i < r.feature_b.vertex_count(); ++i) EXPECT_EQ(b.vertex(r.feature_b.vertices[static_cast<std::size_t>(i)]).z(), 0.0);
  expect_well_formed(a, r.feature_a);
  expect_well_formed(b, r.feature_b);
}

// Two prisms whose ridges cross at right angles, 0.5 apart: edge-edge.
TEST(Gjk, CrossingEdges) {
  const ConvexPolytope a(std::vector<Vec3>{Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(-1, 1, 0), Vec3(1, 1, 0),
                                           Vec3(-1, 0, 1), Vec3(1, 0, 1)});
  const ConvexPolytope b(std::vector<Vec3>{Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(-1, -1, 1), Vec3(1, -1, 1),
                                           Vec3(-1, 1, 1), Vec3(1, 1, 1)});
  const Pose b_in_a = Pose::from_translation(Vec3(0.1, 0.2, 1.5));
  for (const bool enhanced : {false, true}) {
    DistanceCache cache;
    const DistanceResult r = enhanced ? enhanced_gjk_distance(a, b, b_in_a, gjk_options(), 1e-14, cache)
                                      : gjk_distance(a, b, b_in_a, gjk_options(), 1e-14);
    expect_finite(r);
    EXPECT_EQ(r.status, Status::separated);
    EXPECT_NEAR(r.distance, 0.5, 1e-15);
    EXPECT_TRUE(r.point_a.isApprox(Vec3(0.1, 0, 1), 1e-15)) << r.point_a.transpose();
    EXPECT_TRUE(r.point_b.isApprox(Vec3(0.1, 0, 1.5), 1e-15)) << r.point_b.transpose();
    EXPECT_EQ(r.feature_a.type, FeatureType::edge);
    EXPECT_EQ(r.feature_b.type, FeatureType::edge);
    const auto edge = [](int u, int v) { return std::array<int, 3>{std::min(u, v), std::max(u, v), -1}; };
    const std::array<int, 3> ridge_a = edge(vertex_at(a, Vec3(-1, 0, 1)), vertex_at(a, Vec3(1, 0, 1)));
    const std::array<int, 3> ridge_b = edge(vertex_at(b, Vec3(0, -1, 0)), vertex_at(b, Vec3(0, 1, 0)));
    EXPECT_EQ(r.feature_a.vertices, ridge_a);
    EXPECT_EQ(r.feature_b.vertices, ridge_b);
  }
}

// Contacts at machine precision: face on face, edge on edge, vertex on
// vertex, a rotated cube resting on an edge. Touching, never separated or
// intersecting, and the points coincide within the band.
TEST(Gjk, TouchingContacts) {
  const ConvexPolytope cube(unit_cube());
  const Pose poses[] = {
      Pose::from_translation(Vec3(1, 0, 0)),    Pose::from_translation(Vec3(1, 0.3, -0.2)),
      Pose::from_translation(Vec3(1, 1, 0)),    Pose::from_translation(Vec3(1, 1, 1)),
      Pose::from_translation(Vec3(0, 0, -1)),   Pose::from_translation(Vec3(-1, -1, 0.5)),
      Pose(Mat3(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())), Vec3(1 + std::sqrt(0.5), 0.5 - std::sqrt(0.5), 0.25)),
  };
  for (const Pose& b_in_a : poses) {
    const double tol = contact_band(cube, cube, b_in_a);
    for (const bool enhanced : {false, true}) {
      DistanceCache cache;
      const DistanceResult r = enhanced ? enhanced_gjk_distance(cube, cube, b_in_a, gjk_options(), tol, cache)
                                        : gjk_distance(cube, cube, b_in_a, gjk_options(), tol);
      expect_finite(r);
      EXPECT_EQ(r.status, Status::touching) << b_in_a.translation.transpose() << " " << to_string(r.status);
      EXPECT_LE(r.distance, tol);
      EXPECT_LE((r.point_a - r.point_b).norm(), tol);
      EXPECT_LE(outside_by(cube, Pose::identity(), r.point_a), tol);
      EXPECT_LE(outside_by(cube, b_in_a, r.point_b), tol);
    }
  }
}

// Overlaps, the symmetric ones included (identical cubes put the origin on
// segments and triangles of the Minkowski difference, not inside a
// tetrahedron): intersecting, distance 0, one contact point in both hulls.
TEST(Gjk, IntersectingContacts) {
  const ConvexPolytope cube(unit_cube());
  const ConvexPolytope small(box(Vec3(0.25, 0.25, 0.25), Vec3(0.75, 0.75, 0.75)));
  struct Case {
    const ConvexPolytope* b;
    Pose pose;
  };
  const Case cases[] = {
      {&cube, Pose::identity()},
      {&cube, Pose::from_translation(Vec3(0.5, 0, 0))},
      {&cube, Pose::from_translation(Vec3(0.5, 0.5, 0.5))},
      {&cube, Pose(Mat3(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())), Vec3(0.5, 0.5, 0.5))},
      {&small, Pose::identity()},  // B inside A
      {&cube, Pose::from_translation(Vec3(0.999, 0.999, 0.999))},
  };
  for (const Case& c : cases) {
    const double tol = contact_band(cube, *c.b, c.pose);
    for (const bool enhanced : {false, true}) {
      DistanceCache cache;
      const DistanceResult r = enhanced ? enhanced_gjk_distance(cube, *c.b, c.pose, gjk_options(), tol, cache)
                                        : gjk_distance(cube, *c.b, c.pose, gjk_options(), tol);
      expect_finite(r);
      EXPECT_EQ(r.status, Status::intersecting) << c.pose.translation.transpose();
      EXPECT_EQ(r.distance, 0.0);
      EXPECT_EQ(r.lower_bound, 0.0);
      EXPECT_EQ(r.point_a, r.point_b);
      EXPECT_LE(outside_by(cube, Pose::identity(), r.point_a), tol);
      EXPECT_LE(outside_by(*c.b, c.pose, r.point_b), tol);
    }
  }
}

// ---------------------------------------------------------------------------
// Random polytopes against the brute force.
// ---------------------------------------------------------------------------

struct Tally {
  int vertex_face = 0;
  int edge_edge = 0;
  int other = 0;
};

// Checks one separated answer against the reference distance and the
// optimality certificate, and tallies its feature pair.
void check_separated(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a, const DistanceResult& r,
                     double reference, Tally& tally) {
  const double big_r = largest_coordinate(a, b, b_in_a);
  const double band = 64.0 * kUnitRoundoff * big_r;
  // Accuracy standard, plus the reference's own rounding (a few u R).
  const double slack = 1e-12 * reference + band + 16.0 * kUnitRoundoff * big_r;
  expect_finite(r);
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_NEAR(r.distance, reference, slack);
  EXPECT_LE(r.lower_bound, reference + slack);
  EXPECT_NEAR((r.point_b - r.point_a).norm(), r.distance, band);
  EXPECT_LE(outside_by(a, Pose::identity(), r.point_a), band);
  EXPECT_LE(outside_by(b, b_in_a, r.point_b), band);
  // Certificate: the normal separates, with A's support plane through
  // point_a and B's through point_b.
  double max_a = -std::numeric_limits<double>::infinity();
  double min_b = std::numeric_limits<double>::infinity();
  for (const Vec3& x : a.vertices()) max_a = std::max(max_a, r.normal.dot(x));
  for (const Vec3& y : b.vertices()) min_b = std::min(min_b, r.normal.dot(b_in_a.apply(y)));
  EXPECT_LE(max_a, r.normal.dot(r.point_a) + slack);
  EXPECT_GE(min_b, r.normal.dot(r.point_b) - slack);
  // The witness features hold the closest points, on the support planes.
  expect_well_formed(a, r.feature_a);
  expect_well_formed(b, r.feature_b);
  for (int i = 0; i < r.feature_a.vertex_count(); ++i) {
    EXPECT_NEAR(r.normal.dot(a.vertex(r.feature_a.vertices[static_cast<std::size_t>(i)])), max_a, slack + 1e-9 * big_r);
  }
  for (int i = 0; i < r.feature_b.vertex_count(); ++i) {
    EXPECT_NEAR(r.normal.dot(b_in_a.apply(b.vertex(r.feature_b.vertices[static_cast<std::size_t>(i)]))), min_b,
                slack + 1e-9 * big_r);
  }
  const FeatureType ta = r.feature_a.type;
  const FeatureType tb = r.feature_b.type;
  if ((ta == FeatureType::vertex && tb == FeatureType::face) || (ta == FeatureType::face && tb == FeatureType::vertex)) {
    ++tally.vertex_face;
  } else if (ta == FeatureType::edge && tb == FeatureType::edge) {
    ++tally.edge_edge;
  } else {
    ++tally.other;
  }
}

TEST(Gjk, RandomSeparatedPairsMatchBruteForce) {
  Rng rng(20240611);
  Tally tally;
  int large = 0;
  for (int trial = 0; trial < 300; ++trial) {
    // A few large bodies (the brute force is quadratic in edges), many small.
    const bool big = trial % 30 == 0;
    const ConvexPolytope a(big ? sphere_points(rng, uniform_int(rng, 100, 500), 1.0) : random_body(rng, 40));
    const ConvexPolytope b(big ? sphere_points(rng, uniform_int(rng, 100, 500), 0.7) : random_body(rng, 40));
    large += std::min(a.vertex_count(), b.vertex_count()) >= 100;
    // Apart by 0.001 .. 10 beyond the bounding spheres.
    const double gap = std::exp(uniform(rng, std::log(1e-3), std::log(10.0)));
    const Vec3 dir = random_unit(rng);
    const Vec3 t = a.centroid() + dir * (a.bounding_radius() + b.bounding_radius() + gap);
    const Mat3 rot = random_rotation(rng);
    const Pose b_in_a(rot, Vec3(t - rot * b.centroid()));
    const double reference = brute_force_distance(a, b, b_in_a);
    SCOPED_TRACE(testing::Message() << "trial " << trial << " na " << a.vertex_count() << " nb " << b.vertex_count());
    const DistanceResult classic = gjk_distance(a, b, b_in_a, gjk_options(), contact_band(a, b, b_in_a));
    check_separated(a, b, b_in_a, classic, reference, tally);
    DistanceCache cache;
    const DistanceResult enhanced =
        enhanced_gjk_distance(a, b, b_in_a, gjk_options(), contact_band(a, b, b_in_a), cache);
    Tally ignored;
    check_separated(a, b, b_in_a, enhanced, reference, ignored);
  }
  // The random set must contain the hard cases, not only vertex-vertex.
  EXPECT_GE(tally.vertex_face, 30);
  EXPECT_GE(tally.edge_edge, 30);
  EXPECT_GE(large, 5);
}

// Near contact the separation is a few ulps to a few thousand ulps of R:
// the status flips from touching to separated at the band, and the distance
// is still right to the band. (Regression, trial 65: a touching contact whose
// last simplex was a sliver tetrahedron "enclosing" the origin reported the
// sliver's barycentric rounding, 2e-14 = 1.6 bands, as its distance; it now
// reports the nearest face's witnesses.)
TEST(Gjk, RandomNearContact) {
  Rng rng(77);
  int touching = 0;
  int separated = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const ConvexPolytope a(sphere_points(rng, uniform_int(rng, 4, 60), 1.0));
    const ConvexPolytope b(sphere_points(rng, uniform_int(rng, 4, 60), 1.0));
    const Mat3 rot = random_rotation(rng);
    const Vec3 dir = random_unit(rng);
    Pose b_in_a(rot, Vec3(dir * 3.0));
    // Slide B along -normal by the distance found, less a few ulps: a
    // contact within or just beyond the band.
    const DistanceResult first = gjk_distance(a, b, b_in_a, gjk_options(), contact_band(a, b, b_in_a));
    ASSERT_EQ(first.status, Status::separated);
    const double extra = std::ldexp(uniform(rng, 0.0, 1.0), uniform_int(rng, -60, -40));
    b_in_a.translation -= first.normal * (first.distance - extra);
    const double tol = contact_band(a, b, b_in_a);
    const double reference = brute_force_distance(a, b, b_in_a);
    for (const bool enhanced : {false, true}) {
      DistanceCache cache;
      const DistanceResult r = enhanced ? enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache)
                                        : gjk_distance(a, b, b_in_a, gjk_options(), tol);
      expect_finite(r);
      // The brute force itself rounds at a few u R, so only clear cases
      // are held to a status.
      if (reference > 2.0 * tol) {
        EXPECT_EQ(r.status, Status::separated);
      }
      if (reference < 0.5 * tol) {
        EXPECT_EQ(r.status, Status::touching) << reference / tol;
      }
      EXPECT_NE(r.status, Status::intersecting);
      EXPECT_NEAR(r.distance, reference, tol);
      touching += r.status == Status::touching;
      separated += r.status == Status::separated;
    }
  }
  EXPECT_GE(touching, 20);
  EXPECT_GE(separated, 20);
}

// Bodies that share a ball around a common point: intersecting, with a
// contact point in both hulls.
TEST(Gjk, RandomIntersectingPairs) {
  Rng rng(5150);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const ConvexPolytope a(sphere_points(rng, uniform_int(rng, 12, 200), 1.0));
    const ConvexPolytope b(sphere_points(rng, uniform_int(rng, 12, 200), uniform(rng, 0.2, 2.0)));
    const Mat3 rot = random_rotation(rng);
    const Pose b_in_a(rot, Vec3(uniform(rng, 0.0, 0.3) * random_unit(rng)));
    const Vec3 common = 0.5 * b_in_a.translation;
    if (depth(a, Pose::identity(), common) < 1e-3 || depth(b, b_in_a, common) < 1e-3) continue;
    ++checked;
    const double tol = contact_band(a, b, b_in_a);
    for (const bool enhanced : {false, true}) {
      DistanceCache cache;
      const DistanceResult r = enhanced ? enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache)
                                        : gjk_distance(a, b, b_in_a, gjk_options(), tol);
      expect_finite(r);
      EXPECT_EQ(r.status, Status::intersecting);
      EXPECT_EQ(r.distance, 0.0);
      EXPECT_EQ(r.point_a, r.point_b);
      EXPECT_LE(outside_by(a, Pose::identity(), r.point_a), tol);
      EXPECT_LE(outside_by(b, b_in_a, r.point_b), tol);
    }
  }
  EXPECT_GE(checked, 100);
}

// ---------------------------------------------------------------------------
// Enhanced GJK: tracking and caches.
// ---------------------------------------------------------------------------

// B circles A, spinning, and dips into it and out again: at every step the
// tracked Enhanced GJK gives classic GJK's answer (same status, distance
// within the band), and needs far fewer support evaluations.
TEST(EnhancedGjk, MatchesClassicAlongAMotion) {
  Rng rng(4242);
  const ConvexPolytope a(sphere_points(rng, 300, 1.0));
  const ConvexPolytope b(sphere_points(rng, 120, 0.5));
  DistanceCache cache;
  int classic_iterations = 0;
  int enhanced_iterations = 0;
  int intersecting = 0;
  const int steps = 400;
  for (int k = 0; k < steps; ++k) {
    const double s = 2.0 * M_PI * k / steps;
    const double radius = 1.7 + 0.4 * std::cos(3.0 * s);  // dips below 1.5: overlap
    const Pose b_in_a(Mat3(Eigen::AngleAxisd(4.0 * s, Vec3(1, 2, 3).normalized())),
                      Vec3(radius * std::cos(s), radius * std::sin(s), 0.3 * std::sin(2.0 * s)));
    const double tol = contact_band(a, b, b_in_a);
    const DistanceResult c = gjk_distance(a, b, b_in_a, gjk_options(), tol);
    const DistanceResult e = enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache);
    SCOPED_TRACE(testing::Message() << "step " << k);
    expect_finite(e);
    EXPECT_EQ(e.status, c.status);
    EXPECT_NEAR(e.distance, c.distance, 1e-12 * c.distance + tol);
    if (c.status == Status::separated) {
      EXPECT_NEAR((e.point_a - c.point_a).norm(), 0.0, 1e-6);  // unique closest points here
      EXPECT_LE(e.lower_bound, c.distance + tol);
    }
    classic_iterations += c.iterations;
    enhanced_iterations += e.iterations;
    intersecting += c.status == Status::intersecting;
  }
  EXPECT_GE(intersecting, 20);
  // The warm start pays: about a quarter of classic GJK's support
  // evaluations here (a cold Enhanced GJK would need as many as classic).
  EXPECT_LT(2 * enhanced_iterations, classic_iterations);
}

// The contact unit's Enhanced GJK (detail::enhanced_gjk_contact) is
// enhanced_gjk_distance without the witness features: along the same motion
// in and out of contact, each with its own tracking cache, every field but
// the features is bit for bit the same, and so is every cache field but the
// faces, step after step (a difference would let the two drift apart).
TEST(EnhancedGjk, ContactVariantIsTheQueryWithoutWitnessFeatures) {
  Rng rng(2718);
  const ConvexPolytope a(sphere_points(rng, 150, 1.0));
  const ConvexPolytope b(sphere_points(rng, 80, 0.6));
  DistanceCache full_cache;
  DistanceCache contact_cache;
  int intersecting = 0;
  const int steps = 300;
  for (int k = 0; k < steps; ++k) {
    const double s = 2.0 * M_PI * k / steps;
    const double radius = 1.5 + 0.5 * std::cos(5.0 * s);
    const Pose b_in_a(Mat3(Eigen::AngleAxisd(3.0 * s, Vec3(3, 1, 2).normalized())),
                      Vec3(radius * std::cos(s), 0.2 * std::sin(3.0 * s), radius * std::sin(s)));
    const double tol = contact_band(a, b, b_in_a);
    const DistanceResult full = enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, full_cache);
    const DistanceResult lean =
        detail::enhanced_gjk_contact(a, b, b_in_a, gjk_options(), tol, contact_cache);
    SCOPED_TRACE(testing::Message() << "step " << k);
    EXPECT_EQ(lean.status, full.status);
    EXPECT_EQ(lean.distance, full.distance);
    EXPECT_EQ(lean.lower_bound, full.lower_bound);
    EXPECT_EQ(lean.point_a, full.point_a);
    EXPECT_EQ(lean.point_b, full.point_b);
    EXPECT_EQ(lean.normal, full.normal);
    EXPECT_EQ(lean.iterations, full.iterations);
    EXPECT_EQ(lean.feature_a.vertices[0], -1);
    EXPECT_EQ(lean.feature_b.vertices[0], -1);
    EXPECT_EQ(contact_cache.vertices_a, full_cache.vertices_a);
    EXPECT_EQ(contact_cache.vertices_b, full_cache.vertices_b);
    EXPECT_EQ(contact_cache.hint_a, full_cache.hint_a);
    EXPECT_EQ(contact_cache.hint_b, full_cache.hint_b);
    EXPECT_EQ(contact_cache.face_a, -1);
    intersecting += full.status == Status::intersecting;
  }
  EXPECT_GE(intersecting, 30);
}

// The tracked overlap's certificate (detail::origin_deeper_than, behind
// encloses_origin_deeply) is origin_depth(...) > tol face by face, stopping
// at the first face that decides against: the same decision on every
// tetrahedron, around the origin or not, flat or shallow, at tolerances
// around its depth (a face test that differed from origin_depth's, or an
// early exit on the wrong side of the tolerance, makes it differ).
TEST(ContactCertificate, OriginDeeperThanIsOriginDepthAboveTheTolerance) {
  Rng rng(1414);
  int deep = 0;
  int shallow = 0;
  int refused = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::array<Vec3, 4> p;
    for (Vec3& x : p) x = uniform(rng, 0.1, 2.0) * random_unit(rng);
    if (trial % 5 == 0) {
      // Nearly flat: the fourth point a little off the plane of the others.
      const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
      p[3] = (p[0] + p[1] + p[2]) / 3.0 + uniform(rng, -1e-9, 1e-9) * n +
             0.3 * uniform(rng, -1.0, 1.0) * (p[1] - p[0]);
    }
    const double exact = detail::origin_depth(p[0], p[1], p[2], p[3], 0.0);
    const double tol = trial % 3 == 0   ? 0.0
                       : trial % 3 == 1 ? uniform(rng, 0.0, 0.5)
                                        : std::max(0.0, exact * uniform(rng, 0.5, 1.5));
    const double depth = detail::origin_depth(p[0], p[1], p[2], p[3], tol);
    const bool expected = depth > tol;
    EXPECT_EQ(detail::origin_deeper_than(p[0], p[1], p[2], p[3], tol), expected)
        << "trial " << trial << " depth " << depth << " tol " << tol;
    deep += expected;
    shallow += !expected && depth != std::numeric_limits<double>::lowest();
    refused += depth == std::numeric_limits<double>::lowest();
  }
  // The set holds each kind of answer.
  EXPECT_GE(deep, 500);
  EXPECT_GE(shallow, 500);
  EXPECT_GE(refused, 500);
}

// With the pose unchanged, the cached simplex is already the answer: one
// support evaluation confirms it.
TEST(EnhancedGjk, RepeatedQueryConfirmsInOneIteration) {
  Rng rng(99);
  for (int trial = 0; trial < 20; ++trial) {
    const ConvexPolytope a(sphere_points(rng, 200, 1.0));
    const ConvexPolytope b(sphere_points(rng, 200, 1.0));
    const Pose b_in_a(random_rotation(rng), Vec3(3.0 * random_unit(rng)));
    const double tol = contact_band(a, b, b_in_a);
    DistanceCache cache;
    const DistanceResult first = enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache);
    EXPECT_FALSE(cache.is_cold());
    const DistanceResult second = enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache);
    EXPECT_EQ(second.iterations, 1);
    EXPECT_NEAR(second.distance, first.distance, tol);
  }
}

// A cache from another pair, or full of garbage, costs iterations but never
// changes the answer; the cache written back is valid for this pair.
TEST(EnhancedGjk, ForeignAndGarbageCachesGiveTheSameAnswer) {
  Rng rng(31337);
  const ConvexPolytope other_a(sphere_points(rng, 500, 1.0));
  const ConvexPolytope other_b(sphere_points(rng, 500, 1.0));
  DistanceCache foreign;
  enhanced_gjk_distance(other_a, other_b, Pose::from_translation(Vec3(2.5, 0, 0)), gjk_options(), 1e-13, foreign);
  for (int trial = 0; trial < 100; ++trial) {
    const ConvexPolytope a(random_body(rng, 60));
    const ConvexPolytope b(random_body(rng, 60));
    const Pose b_in_a(random_rotation(rng), Vec3(uniform(rng, 0.0, 3.5) * random_unit(rng)));
    const double tol = contact_band(a, b, b_in_a);
    const DistanceResult reference = gjk_distance(a, b, b_in_a, gjk_options(), tol);

    DistanceCache garbage;
    for (std::size_t k = 0; k < 4; ++k) {
      garbage.vertices_a[k] = static_cast<std::int32_t>(uniform_int(rng, -1000, 1000));
      garbage.vertices_b[k] = static_cast<std::int32_t>(uniform_int(rng, -1000, 1000));
    }
    garbage.hint_a = trial % 2 == 0 ? std::numeric_limits<std::int32_t>::max() : -17;
    garbage.hint_b = static_cast<std::int32_t>(uniform_int(rng, -1000, 1000));
    DistanceCache in_range;  // valid ids, meaningless for this pose
    for (std::size_t k = 0; k < 4; ++k) {
      in_range.vertices_a[k] = static_cast<std::int32_t>(uniform_int(rng, 0, a.vertex_count() - 1));
      in_range.vertices_b[k] = static_cast<std::int32_t>(uniform_int(rng, 0, b.vertex_count() - 1));
    }
    DistanceCache foreign_copy = foreign;
    for (DistanceCache* cache : {&garbage, &in_range, &foreign_copy}) {
      const DistanceResult r = enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, *cache);
      SCOPED_TRACE(testing::Message() << "trial " << trial);
      expect_finite(r);
      EXPECT_EQ(r.status, reference.status);
      EXPECT_NEAR(r.distance, reference.distance, 1e-12 * reference.distance + tol);
      for (std::size_t k = 0; k < 4; ++k) {
        EXPECT_GE(cache->vertices_a[k], -1);
        EXPECT_LT(cache->vertices_a[k], a.vertex_count());
        EXPECT_GE(cache->vertices_b[k], -1);
        EXPECT_LT(cache->vertices_b[k], b.vertex_count());
      }
      EXPECT_GE(cache->hint_a, 0);
      EXPECT_LT(cache->hint_a, a.vertex_count());
      EXPECT_GE(cache->hint_b, 0);
      EXPECT_LT(cache->hint_b, b.vertex_count());
    }
  }
}

// ---------------------------------------------------------------------------
// Regressions, found by the accuracy suite (distance_accuracy_test) and held
// to the accuracy standard against the exact oracle.
// ---------------------------------------------------------------------------

void expect_within_standard(const std::vector<Vec3>& points_a, const std::vector<Vec3>& points_b) {
  test::ExactOracle oracle;
  const std::optional<test::ExactDistance> exact = oracle.distance(points_a, points_b);
  ASSERT_TRUE(exact) << oracle.last_error();
  const ConvexPolytope a(points_a);
  const ConvexPolytope b(points_b);
  const double band = contact_band(a, b, Pose::identity());
  ASSERT_FALSE(test::sqrt_at_most(exact->distance_squared, 2.0 * band));  // clearly separated
  DistanceCache cache;
  for (const DistanceResult& r : {gjk_distance(a, b, Pose::identity(), gjk_options(), band),
                                  enhanced_gjk_distance(a, b, Pose::identity(), gjk_options(), band, cache)}) {
    expect_finite(r);
    EXPECT_EQ(r.status, Status::separated) << to_string(r.status);
    EXPECT_TRUE(test::within_bound(r.distance, exact->distance_squared, 1e-12, band))
        << "distance " << r.distance << ", exact " << exact->distance();
    EXPECT_LE(r.lower_bound, exact->distance() + band);
  }
}

// A needle (six nearly collinear points, 5e-8 thick) 4.06e-13 from a point.
// The tetrahedron GJK built of needle vertices has sliver faces; the plain
// cross product of two nearly parallel edges cancels to a normal tilted by
// ~1e-9, which put the origin on the wrong side of a face 4e-13 away: the
// query was reported intersecting. Fixed by face_normal's accurate path.
TEST(GjkRegression, NeedleAgainstAPoint) {
  expect_within_standard({Vec3(0.91205002599172835, -0.055305202885795962, 0.40633248039290326),
                          Vec3(-0.91205002599172835, 0.055305202885795962, -0.40633248039290326),
                          Vec3(0.32267324960043692, -0.01956641887695702, 0.14375593974487805),
                          Vec3(-0.40442624436303626, 0.024523689551102342, -0.1801781859965603),
                          Vec3(0.49351066950109757, -0.029925619868540743, 0.2198666955276031),
                          Vec3(-0.81928182393689297, 0.049679884060418164, -0.36500284290197688)},
                         {Vec3(0.11104981746311303, -0.0067338408186590759, 0.049474430621343261)});
}

// A sliver tetrahedron (fourth vertex 1.5e-10 off the opposite face) and a
// point between the two planes. v = sum(lambda w) was 1e-10 long but
// rebuilt from points of size 1, so its direction was off by ~1e-6: the
// support missed the sliver's vertex and GJK stopped at 1.03e-10 for
// d* = 5.19e-11. Fixed by taking v as the projection along the normal.
TEST(GjkRegression, SliverAgainstAPoint) {
  expect_within_standard({Vec3(-0.40438775831825102, 0.23076554094979265, -0.43956547411334446),
                          Vec3(0.63168403894713576, 0.21847978064173706, -0.056937337399740606),
                          Vec3(-0.035506566231792588, -0.43993134724703892, 0.55244881524339629),
                          Vec3(0.027250437085004194, 0.0029873187824893993, 0.0058120199934300716)},
                         {Vec3(0.064152657460483986, 0.14959607398764491, -0.16941706013489832)});
}

// Unit boxes face to face, one turned by 1e-7 rad, 1e-9 apart: a vertex
// against a nearly parallel face. The signed-volume cofactors of the flat
// tetrahedra (rounding u |w|^3 against volumes near that) had random signs
// and GJK stopped at 2.6e-9 for d* = 1e-9. Fixed by face heights.
TEST(GjkRegression, KissingBoxesWithTinyRotatedGap) {
  expect_within_standard(box(Vec3::Constant(-0.5), Vec3::Constant(0.5)),
                         {Vec3(0.50000000427028424, -0.49999997302253646, -0.49999998246323579),
                          Vec3(1.5000000042702799, -0.50000006532127439, -0.49999997919294786),
                          Vec3(0.50000009656902222, 0.50000002697745849, -0.5000000208070513),
                          Vec3(1.5000000965690179, 0.49999993467872067, -0.50000001753676349),
                          Vec3(0.50000000099999997, -0.49999993467872067, 0.50000001753676349),
                          Vec3(1.5000000009999956, -0.50000002697745849, 0.5000000208070513),
                          Vec3(0.50000009329873796, 0.50000006532127439, 0.49999997919294786),
                          Vec3(1.5000000932987336, 0.49999997302253646, 0.49999998246323579)});
}

// ---------------------------------------------------------------------------
// Limits.
// ---------------------------------------------------------------------------

// Regression (issue 25, repro gjk_touch_far.py): a box's vertex placed on
// the end of a segment 1e12 from the origin, the box first. GJK's simplex
// mixed points of A - B near the origin with points 2e12 away; its solver
// could not resolve the step that brought |v| from 16.65 to 0 (700 bands),
// stalled with a lower bound of 0 and answered `touching` at distance
// 16.65 (swapped, it answered 0). The stalled simplex is now polished by the
// closed-form kernels on its hull vertices (polish_stalled in gjk.cpp).
TEST(GjkRegression, TouchingFarFromTheOrigin) {
  const ConvexPolytope segment(std::vector<Vec3>{Vec3(-688382873359.9867, 1705734364702.0273, 333218255102.6336),
      Vec3(-1021122306432.1952, 87003358780.82507, -8473866307.86056)});
  const ConvexPolytope box(std::vector<Vec3>{Vec3(-61.08071682972654, -15.6226471992511, -37.98999450136053),
      Vec3(-61.08071682972654, -15.6226471992511, 37.98999450136053),
      Vec3(-61.08071682972654, 15.6226471992511, -37.98999450136053),
      Vec3(-61.08071682972654, 15.6226471992511, 37.98999450136053),
      Vec3(61.08071682972654, -15.6226471992511, -37.98999450136053),
      Vec3(61.08071682972654, -15.6226471992511, 37.98999450136053),
      Vec3(61.08071682972654, 15.6226471992511, -37.98999450136053),
      Vec3(61.08071682972654, 15.6226471992511, 37.98999450136053)});
  Mat3 rotation;
  rotation << 0.5322460407755973, -0.776140333215319, -0.3381129030887686,
              0.3415844782257567, -0.16854816761794855, 0.9246142760242617,
              -0.7746187425527082, -0.6076164072414814, 0.17540839585668477;
  const Pose box_pose(rotation, Vec3(-688382873326.7572, 1705734364685.1323, 333218255039.163));
  // R: the largest coordinate, the segment's (the box is placed next to it).
  const double band = 64 * kUnitRoundoff * 1705734364702.0273;
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk, Algorithm::hybrid}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool box_first : {true, false}) {
      SCOPED_TRACE(std::string(to_string(alg)) + (box_first ? ", box first" : ", segment first"));
      const DistanceResult r =
          box_first ? distance(box, box_pose, segment, Pose::identity(), options)
                    : distance(segment, Pose::identity(), box, box_pose, options);
      EXPECT_EQ(r.status, Status::touching);
      EXPECT_LE(r.distance, band);
      EXPECT_LE((r.point_a - r.point_b).norm(), 2 * band);
      EXPECT_LE(r.lower_bound, r.distance);
    }
  }
}

// Regression (issue 25, the soak: seed 7, episode 13878): a flat cloud of
// size 1e-12 (7 vertices, 1e-22 thick) touching a cloud of size 0.015.
// GJK's simplex stalled at |v| = 9.7e-14, 820 contact bands above the
// distance of 0, with a lower bound of 0; polishing it by the closed-form
// kernels gave up because the stalled simplex's three vertex pairs and the
// new support point held four vertices on each body (the kernels take at
// most three), and the answer was `touching` at 9.7e-14. The polish now
// takes a side of four vertices as its four triangles (closest_of_features
// in gjk.cpp) and reaches the band. (Episodes 497, 7499 of seed 7 and 7712
// of seed 8 were the same stall with a polygon or a cloud: `touching` at 31
// to 31,000 bands.)
TEST(GjkRegression, StalledSimplexWithAFourthVertex) {
  const ConvexPolytope a(std::vector<Vec3>{
        Vec3(7.048753078524891e-14, -2.0640761693274487e-14, 1.811551084939803e-22),
        Vec3(4.173232217988277e-13, -1.4364384794049487e-13, -3.4494972850935313e-22),
        Vec3(-2.1139637109354276e-13, 1.3106197155833975e-13, 1.7696082563206885e-22),
        Vec3(-8.247563543056869e-13, -8.41131566539924e-14, 5.40904992047616e-22),
        Vec3(5.003574452096257e-13, 4.638133759303659e-13, -6.116672600118903e-22),
        Vec3(-6.639801741810738e-14, -5.5213856272522626e-14, -3.3272905147878665e-24),
        Vec3(1.2246109245804076e-13, -2.7235866775726114e-13, 9.831932285680862e-23)});
  Mat3 rotation_a;
  rotation_a << 0.7164372346042263, -0.46025447222314336, -0.5242933431498487, -0.508724631488739, 0.16961048622587294, -0.8440565930545589, 0.47740647061942476, 0.8714345091633787, -0.1126275190612199;
  const Pose pose_a(rotation_a, Vec3(0.0052665031113651, -0.011950554971258439, 0.01068747746281215));
  const ConvexPolytope b(std::vector<Vec3>{
        Vec3(0.008692302856429697, 0.0044956169881763325, -0.01284748237818674),
        Vec3(0.0034797427376785034, 0.00590221457341216, -0.014759145382915291),
        Vec3(0.013919895962502657, -0.008013060089170363, 5.45616431401899e-05),
        Vec3(0.014321090284855922, -0.0026208421592914975, -0.006641044073320606),
        Vec3(-0.004029667742202371, -0.013687273372450098, -0.00776495567645758),
        Vec3(0.0034925554054006515, 0.0008029503339048172, 0.01649753403441831),
        Vec3(0.006682888872280707, -0.012494046982586922, 0.008164376417799213),
        Vec3(-0.009022904983844749, 0.0038711451497693747, -0.013374203176474734),
        Vec3(0.011047430675902345, -0.011266412381611508, -0.002701289658873045),
        Vec3(0.004540896582837412, -0.00761871270713659, -0.013325228448164974),
        Vec3(-0.010305731973199889, 0.009603757041629864, -0.009206792547275968),
        Vec3(0.0092975167364581, 0.003498524689544357, 0.013445182483746237),
        Vec3(-0.016459776258845694, -0.0038388660131690186, 0.0014925689439280632),
        Vec3(-0.006938222663629632, 0.013775155367390051, -0.00684690839257989),
        Vec3(-0.006872731343189685, 0.011043231572428936, 0.011288162550283224),
        Vec3(0.00786122083590995, -0.006583258950794991, 0.01298886096816794),
        Vec3(-0.0012281362944319204, -0.014984259154663972, 0.00674661328287816),
        Vec3(0.01513384526980241, -0.004531027184335334, -0.002740162394288016),
        Vec3(0.011829227358912979, -0.002715513751257173, -0.010393233308868703),
        Vec3(-0.015251704455395972, 0.005245533087588775, -0.005244438124468584)});
  Mat3 rotation_b;
  rotation_b << -0.8728738603015842, -0.26194807897791333, -0.411672719428907, -0.20151308022537015, -0.5748566411002531, 0.7930525333677576, -0.44439138436776, 0.775192263959539, 0.4489913711832223;
  const Pose pose_b(rotation_b, Vec3(0.0, 0.0, 0.0));
  double r = 0.0;  // R of the standard: the placed vertices' largest coordinate
  for (const Vec3& x : a.vertices()) r = std::max(r, pose_a.apply(x).cwiseAbs().maxCoeff());
  for (const Vec3& y : b.vertices()) r = std::max(r, pose_b.apply(y).cwiseAbs().maxCoeff());
  const double band = 64 * kUnitRoundoff * r;
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk, Algorithm::hybrid}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool swapped : {false, true}) {
      SCOPED_TRACE(std::string(to_string(alg)) + (swapped ? ", swapped" : ""));
      const DistanceResult d = swapped ? distance(b, pose_b, a, pose_a, options)
                                       : distance(a, pose_a, b, pose_b, options);
      EXPECT_EQ(d.status, Status::touching);
      EXPECT_LE(d.distance, band);
      EXPECT_LE(d.lower_bound, d.distance);
    }
  }
}

// Regression (issue 25, the soak: seed 10, episode 6125): a point at 3e93
// in its own frame, placed by a translation that cancels it to within
// 3.7e77 of a box of size 100 at the origin. GJK worked in a unit near R
// (1e94), where the box, which is A - B, was 1e-92 in size; the solver's
// squared face normals (fourth powers, 1e-368) underflowed to zero, no
// triangle around the origin's projection was ever found, and GJK and
// Enhanced GJK stopped at the iteration cap with distance 0 (their
// certificate [-2e79, 0] excluded the exact 3.7e77; the hybrid answered
// it). The unit now follows the spread of A - B (gjk_frame.h).
TEST(GjkRegression, CancelledTranslationConverges) {
  const Vec3 half(25.830336028769672, 34.169303400112128, 51.946510876643764);
  const ConvexPolytope box_body(box(-half, half));
  const Vec3 local(1.865208878257629e+93, -2.4178279444583283e+93, 2.8539780796806809e+93);
  const ConvexPolytope point(std::vector<Vec3>{local});
  Mat3 rotation_box;
  rotation_box << -0.30748909473401476, -0.76927650256259694, 0.56005724638175591,
      -0.078777707468663749, 0.60713240863883933, 0.79068597507884442, -0.94828504650534162,
      0.19900728877470825, -0.24728843399743172;
  Mat3 rotation_point;
  rotation_point << 0.10138475302065772, -0.35623199399934591, 0.92888099254220402,
      0.16043002374613988, -0.91561734389905791, -0.36865578393949966, 0.9818265322019738,
      0.18639647529522699, -0.035679331016186699;
  const Pose pose_box(rotation_box, Vec3::Zero());
  const Pose pose_point(rotation_point, Vec3(-3.7014174026033021e+93, -1.4609051788294062e+93,
                                             -1.2788089294368173e+93));
  // The placed point exactly (rationals): the box is within its
  // circumradius of the origin, so d* is within it of the point's norm.
  mpq_class norm2 = 0;
  for (int i = 0; i < 3; ++i) {
    mpq_class c = pose_point.translation[i];
    for (int j = 0; j < 3; ++j) c += mpq_class(pose_point.rotation(i, j)) * mpq_class(local[j]);
    norm2 += c * c;
  }
  const double centre_distance = std::sqrt(norm2.get_d());
  const double circumradius = half.norm();
  // R of the standard counts the translation (docs/accuracy.md).
  const double band = 64 * kUnitRoundoff * pose_point.translation.cwiseAbs().maxCoeff();
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk, Algorithm::hybrid}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool swapped : {false, true}) {
      SCOPED_TRACE(std::string(to_string(alg)) + (swapped ? ", swapped" : ""));
      const DistanceResult r = swapped ? distance(point, pose_point, box_body, pose_box, options)
                                       : distance(box_body, pose_box, point, pose_point, options);
      expect_finite(r);
      EXPECT_NE(r.status, Status::iteration_cap);
      EXPECT_LT(r.iterations, 16);
      // Within the standard (64 u R, R the translation), and the
      // certificate holds the exact distance within that band.
      EXPECT_LE(std::abs(r.signed_distance()), centre_distance + circumradius + band);
      EXPECT_LE(r.signed_lower_bound(), centre_distance + circumradius + band);
      EXPECT_GE(r.signed_upper_bound(), centre_distance - circumradius - band);
    }
  }
}

// Regression (issue 25, found with ForeignCache.FlatContactTetrahedron...
// of status_band_test): a pyramid with its apex at the origin and B that
// point (d* = 0), its base a few bands above and nearly flat (one corner
// lifted by a few u), Enhanced GJK warm-started from the base. The
// origin's foot on the base is on its diagonal, so the kernels reduce the
// base to that edge; the direction across it, left by the closest points'
// difference, is rounding (u R / |v|, 1e-3 here), and the support along it
// came back from the base instead of the apex. Enhanced GJK stopped at
// 16-19 bands with a lower bound of 0 and answered `touching` there. The
// polish now searches once along the normal of the features it searched
// (the base's) and reaches the apex.
TEST(GjkRegression, FlatFaceAboveATouchingApexReachesIt) {
  test::Rng rng(5);
  int queries = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const double size = test::log_uniform(rng, 1e-9, 1e3);
    const double band = 64.0 * kUnitRoundoff * size;
    const double h = test::uniform(rng, 2.0, 20.0) * band;
    const double lift = test::uniform_int(rng, 0, 8) * kUnitRoundoff * size;
    const Mat3 rot = test::random_rotation(rng);
    const test::Points base = {rot * Vec3(size, size, h), rot * Vec3(-size, size, h),
                               rot * Vec3(-size, -size, h), rot * Vec3(size, -size, h + lift)};
    test::Points a = base;
    a.push_back(Vec3::Zero());
    const ConvexPolytope pa(a);
    const ConvexPolytope pb(test::Points{Vec3::Zero()});
    DistanceCache cache;
    for (std::size_t k = 0; k < 4; ++k) {
      for (int v = 0; v < pa.vertex_count(); ++v) {
        if (pa.vertex(v) == base[k]) cache.vertices_a[k] = v;
      }
      cache.vertices_b[k] = 0;
    }
    if (std::find(cache.vertices_a.begin(), cache.vertices_a.end(), -1) != cache.vertices_a.end())
      continue;
    DistanceOptions options;
    options.algorithm = Algorithm::enhanced_gjk;
    const DistanceResult r = distance(pa, Pose{}, pb, Pose{}, options, &cache);
    ++queries;
    EXPECT_EQ(r.status, Status::touching) << "trial " << trial;
    EXPECT_LE(r.distance, band) << "trial " << trial << ": " << r.distance / band << " bands";
  }
  EXPECT_GT(queries, 100);
}

// Regression (issue 25, the 10^7-query soak: seed 15, episode 18168): a
// segment (two vertices) against a point whose exact distance, about
// 2.2e-14, is inside the band (4.7e-13), poses as the soak drew them.
// Plain GJK ran to its cap of 64 iterations and answered `iteration_cap`;
// Enhanced GJK and the hybrid answered `touching`.
TEST(GjkRegression, SegmentAgainstAPointInTheBand) {
  const ConvexPolytope segment(std::vector<Vec3>{
      Vec3(-2.1957053245359854, -0.20772433606387436, -3.1749476909626524),
      Vec3(0.80635862618445708, 0.60743791173750117, 3.5526115208256339)});
  const ConvexPolytope point(
      std::vector<Vec3>{Vec3(-0.037849993504155861, -66.588346848257814, -34.010020936431658)});
  Mat3 rot_a;
  rot_a << 0.32527856930103372, -0.58752728268295551, -0.74094908357906419,
           0.09160406957269987, 0.79945318910817087, -0.59370303423723136,
           0.94117083826008585, 0.12524492216436442, 0.31386487965500331;
  Mat3 rot_b;
  rot_b << 0.62195251239646476, -0.30954734634362957, -0.71927429586725988,
           0.67831406792236282, -0.24595579376443497, 0.69238412227052371,
           -0.3912353480736907, -0.91852391797128752, 0.056997495842662935;
  const Pose pose_a(rot_a, Vec3::Zero());
  const Pose pose_b(rot_b, Vec3(-43.290936617042682, 8.7136576244506863, -62.328366280845387));
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk, Algorithm::hybrid}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool segment_first : {true, false}) {
      SCOPED_TRACE(std::string(to_string(alg)) + (segment_first ? ", segment first" : ", point first"));
      const DistanceResult r = segment_first ? distance(segment, pose_a, point, pose_b, options)
                                             : distance(point, pose_b, segment, pose_a, options);
      EXPECT_EQ(r.status, Status::touching) << r.iterations << " iterations, distance " << r.distance;
      EXPECT_LE(r.lower_bound, r.distance);
      EXPECT_LT(r.iterations, options.max_iterations);
    }
  }
}

TEST(Gjk, IterationCapIsReportedWithValidBounds) {
  Rng rng(8);
  const ConvexPolytope a(sphere_points(rng, 500, 1.0));
  const ConvexPolytope b(sphere_points(rng, 500, 1.0));
  const Pose b_in_a(random_rotation(rng), Vec3(2.2, 0.3, -0.1));
  const double reference = brute_force_distance(a, b, b_in_a);
  DistanceOptions capped = gjk_options();
  capped.max_iterations = 2;
  DistanceCache cache;
  for (const DistanceResult& r : {gjk_distance(a, b, b_in_a, capped, 1e-13),
                                  enhanced_gjk_distance(a, b, b_in_a, capped, 1e-13, cache)}) {
    expect_finite(r);
    EXPECT_EQ(r.status, Status::iteration_cap);
    EXPECT_EQ(r.iterations, 2);
    // Still bounds: the upper bound is a pair of hull points, the lower
    // bound certified.
    EXPECT_GE(r.distance, reference - 1e-14);
    EXPECT_LE(r.lower_bound, reference + 1e-14);
    EXPECT_LE(outside_by(a, Pose::identity(), r.point_a), 1e-14);
    EXPECT_LE(outside_by(b, b_in_a, r.point_b), 1e-14);
  }
}

// A contact still undecided at the cap says so: the classification's
// support evaluations count against options.max_iterations too.
TEST(Gjk, IterationCapHoldsInContacts) {
  const ConvexPolytope cube(unit_cube());
  const Pose poses[] = {Pose::identity(), Pose::from_translation(Vec3(1, 0, 0)),
                        Pose::from_translation(Vec3(0.5, 0.5, 0.5))};
  for (const Pose& b_in_a : poses) {
    const double tol = contact_band(cube, cube, b_in_a);
    for (int cap = 1; cap <= 12; ++cap) {
      DistanceOptions o = gjk_options();
      o.max_iterations = cap;
      DistanceCache cache;
      for (const DistanceResult& r : {gjk_distance(cube, cube, b_in_a, o, tol),
                                      enhanced_gjk_distance(cube, cube, b_in_a, o, tol, cache)}) {
        expect_finite(r);
        EXPECT_LE(r.iterations, cap);
        EXPECT_NE(r.status, Status::separated);
        EXPECT_LE(r.lower_bound, tol);  // d* = 0
        if (r.status != Status::iteration_cap) {
          EXPECT_LE(r.distance, tol);
        }
        if (cap == 12) {  // enough for all three contacts
          EXPECT_NE(r.status, Status::iteration_cap);
        }
      }
    }
  }
}

// The paper's stress scales (tiny and huge bodies) and one beyond where the
// signed volumes' cubic terms would overflow without the unit rescaling: the
// answer scales with the bodies.
TEST(Gjk, ScaleInvariance) {
  const std::vector<Vec3> tet = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  const Mat3 rot(Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()));
  const Vec3 offset(1.1, 0.9, 1.3);
  const ConvexPolytope a1(tet);
  const ConvexPolytope b1(tet);
  const DistanceResult base = gjk_distance(a1, b1, Pose(rot, offset), gjk_options(), 1e-14);
  ASSERT_EQ(base.status, Status::separated);
  for (const double s : {0x1p-76, 1e-23, 1e39, 1e120}) {
    std::vector<Vec3> scaled;
    for (const Vec3& p : tet) scaled.push_back(p * s);
    const ConvexPolytope a(scaled);
    const ConvexPolytope b(scaled);
    const Pose b_in_a(rot, Vec3(offset * s));
    const double tol = contact_band(a, b, b_in_a);
    DistanceCache cache;
    for (const DistanceResult& r : {gjk_distance(a, b, b_in_a, gjk_options(), tol),
                                    enhanced_gjk_distance(a, b, b_in_a, gjk_options(), tol, cache)}) {
      SCOPED_TRACE(testing::Message() << "scale " << s);
      expect_finite(r);
      EXPECT_EQ(r.status, Status::separated);
      EXPECT_NEAR(r.distance / s, base.distance, 1e-12 * base.distance + 64 * kUnitRoundoff * 4);
      EXPECT_NEAR(r.lower_bound / s, base.lower_bound, 1e-12);
      EXPECT_EQ(r.feature_a.type, base.feature_a.type);
      EXPECT_EQ(r.feature_b.type, base.feature_b.type);
    }
  }
}

// ---------------------------------------------------------------------------
// Touching pairs must not be called separated.
//
// A seeded sweep of near-touching pairs: cubes, tetrahedra, small point
// clouds, needles, slivers, thin boxes and flat polygons, rotated, scaled
// by 1e-3 .. 1e6 (the two bodies up to 1e3 apart in size), half of them far
// from the origin
// (a common translation up to 1e4 sizes), placed vertex on face (along a
// face normal of A), face on face (a copy of A spun about that normal) or
// along a random direction (vertex-vertex, edge-edge, edge-face), then moved
// by the exact oracle to d* = t x 64 u R with t in [1e-3, 2]. Every answer
// of GJK and Enhanced GJK (through distance()) is checked against d*:
// separated only when d* > 64 u R, the accuracy standard's rule.
struct TouchingCase {
  test::Points a, b;
  double d_star = 0.0;  // exact distance, rounded
  double band = 0.0;    // 64 u R, R of the placed points
  std::string kind;
};

// d* by the oracle's brute force over supporting features, exact and
// certified: the bodies here have at most 12 points (CGAL's quadratic
// program stalled for minutes on some face-on-face placements).
std::optional<test::ExactDistance> exact_distance(const test::Points& a, const test::Points& b) {
  return test::brute_force_distance(a, b, test::to_rational(a), test::to_rational(b), nullptr);
}

std::optional<TouchingCase> touching_case(test::Rng& rng) {
  const double size = test::log_uniform(rng, 1e-3, 1e6);
  const int shape_a = test::uniform_int(rng, 0, 6);
  const int shape_b = test::uniform_int(rng, 0, 6);
  const double size_b =
      size * (test::uniform01(rng) < 0.5 ? 1.0 : test::log_uniform(rng, 1e-3, 1e3));
  const auto shape = [&](int kind, double edge) {
    switch (kind) {
      case 0:
        return test::cube(edge);
      case 1:
        return test::regular_tetrahedron(edge);
      case 2:
        return test::points_on_sphere(rng, test::uniform_int(rng, 5, 12), edge / 2);
      case 3:
        return test::needle(rng, edge, edge * test::log_uniform(rng, 1e-9, 1e-3));
      case 4:
        return test::scaled(test::sliver(rng, test::log_uniform(rng, 1e-9, 1e-3)), edge);
      case 5:
        return test::box(Vec3(edge, edge * test::log_uniform(rng, 1e-6, 1e-2), edge / 2));
      default:
        return test::scaled(test::flat_polygon(rng, test::uniform_int(rng, 3, 8)), edge);
    }
  };
  const Mat3 rot_a = test::random_rotation(rng);
  const Vec3 far =
      test::uniform01(rng) < 0.5
          ? Vec3(size * test::log_uniform(rng, 1.0, 1e4) * test::random_unit_vector(rng))
          : Vec3::Zero();
  TouchingCase c;
  c.a = test::transformed(shape(shape_a, size), rot_a, far);
  const ConvexPolytope hull_a(c.a);
  const int placement = test::uniform_int(rng, 0, 2);
  Vec3 n = test::random_unit_vector(rng);
  test::Points b;
  if (placement == 2 || hull_a.face_count() == 0) {
    c.kind = "random direction";
    b = test::transformed(shape(shape_b, size_b), test::random_rotation(rng), far);
  } else {
    n = hull_a.face_plane(test::uniform_int(rng, 0, hull_a.face_count() - 1)).normal;
    if (placement == 0) {
      c.kind = "vertex on face";
      b = test::transformed(shape(shape_b, size_b), test::random_rotation(rng), far);
    } else {
      c.kind = "face on face";
      const Mat3 spin(Eigen::AngleAxisd(test::uniform(rng, 0, 6.3), n));
      b = test::transformed(shape(shape_a, size_b), spin * rot_a, far);
    }
  }
  b = test::place_along(c.a, b, n, size * 1e-3);
  const double r = std::max(test::max_abs_coordinate(c.a), test::max_abs_coordinate(b));
  c.band = 64 * kUnitRoundoff * r;
  // Moved straight towards A to the target gap (tighten_to_gap, by brute
  // force).
  const std::optional<test::ExactDistance> placed = exact_distance(c.a, b);
  if (!placed || placed->is_zero()) return std::nullopt;
  const Vec3 dir =
      (test::to_double(placed->point_b) - test::to_double(placed->point_a)).normalized();
  const double gap = test::log_uniform(rng, 1e-3, 2.0) * c.band;
  c.b = test::translated(b, -(placed->distance() - gap) * dir);
  const double r2 = std::max(test::max_abs_coordinate(c.a), test::max_abs_coordinate(c.b));
  c.band = 64 * kUnitRoundoff * r2;
  const std::optional<test::ExactDistance> exact = exact_distance(c.a, c.b);
  if (!exact) return std::nullopt;
  c.d_star = exact->distance();
  return c;
}

// The number of GJK and Enhanced GJK answers that call a pair with
// d* <= 64 u R separated, over `count` cases from `seed`; each is printed.
int separated_touching_pairs(std::uint64_t seed, int count, int* touching_cases = nullptr) {
  test::Rng rng(seed);
  int wrong = 0;
  for (int i = 0; i < count; ++i) {
    const std::optional<TouchingCase> c = touching_case(rng);
    if (!c) continue;
    const bool touching = c->d_star <= c->band;
    if (touching && touching_cases != nullptr) ++*touching_cases;
    const ConvexPolytope a(c->a);
    const ConvexPolytope b(c->b);
    for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk}) {
      DistanceOptions options;
      options.algorithm = alg;
      const DistanceResult r = distance(a, Pose::identity(), b, Pose::identity(), options);
      if (touching && r.status == Status::separated) {
        ++wrong;
        ADD_FAILURE() << to_string(alg) << " called a touching pair separated (case " << i << ", "
                      << c->kind << "): d* = " << c->d_star / c->band << " bands, distance "
                      << r.distance / c->band << " bands, lower bound " << r.lower_bound / c->band
                      << " bands\nA " << test::format_points(c->a) << "\nB "
                      << test::format_points(c->b);
      }
    }
  }
  return wrong;
}

TEST(GjkTouching, DISABLED_LongSweepOfNearTouchingPairs) {
  const char* env = std::getenv("PROXIMA_SWEEP_CASES");
  const int cases = env != nullptr ? std::atoi(env) : 100000;
  const char* seed_env = std::getenv("PROXIMA_SWEEP_SEED");
  const std::uint64_t seed = seed_env != nullptr ? std::strtoull(seed_env, nullptr, 10) : 1;
  EXPECT_EQ(separated_touching_pairs(seed, cases), 0);
}

// A short run of the sweep for every build (a quarter of it under the
// sanitizers); the long one (disabled, cases and seed from
// PROXIMA_SWEEP_CASES and PROXIMA_SWEEP_SEED) found the two regressions
// below in 2,000 cases.
TEST(GjkTouching, SweepOfNearTouchingPairs) {
  const int cases = test::sanitized_count(40, 4);
  int touching = 0;
  EXPECT_EQ(separated_touching_pairs(9, cases, &touching), 0);
  EXPECT_GT(touching, cases / 2);  // the sweep really reaches the band
}

// GJK and Enhanced GJK (through distance()) on a pair whose exact distance
// is within the band: not separated.
void expect_not_separated(const test::Points& a, const test::Points& b) {
  const std::optional<test::ExactDistance> exact = exact_distance(a, b);
  ASSERT_TRUE(exact);
  const double band =
      64 * kUnitRoundoff * std::max(test::max_abs_coordinate(a), test::max_abs_coordinate(b));
  ASSERT_LE(exact->distance(), band);  // the premise: touching
  const ConvexPolytope pa(a);
  const ConvexPolytope pb(b);
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk}) {
    DistanceOptions options;
    options.algorithm = alg;
    const DistanceResult r = distance(pa, Pose::identity(), pb, Pose::identity(), options);
    EXPECT_NE(r.status, Status::separated)
        << to_string(alg) << ": distance " << r.distance / band << " bands, lower bound "
        << r.lower_bound / band << " bands, d* " << exact->distance() / band << " bands";
    EXPECT_LE(r.lower_bound, band) << to_string(alg);
  }
}

// Story (issue 9, found by the sweep above, seed 2, case 719): two needles
// side by side, d* = 6e-5 bands. The Minkowski difference is nearly flat;
// GJK's segment passed 1.8e-10 (56,000 bands) from the origin, the support
// point beyond it improved |v| only below rounding, GJK stopped there
// ("rounding has taken over") with a lower bound of 0 and called the pair
// separated. Now a stalled GJK tries the plane of its last simplex for a
// lower bound and reports separated only when one certifies it.
TEST(GjkTouching, NeedlesSideBySideTouch) {
  expect_not_separated({Vec3(3.2373982772939152, -2.7835848549293236, 2.3290728952413882),
                        Vec3(3.2399032411110107, -2.7845024680382378, 2.3322259280010171),
                        Vec3(3.239593947308288, -2.7843891681654576, 2.3318366155855381),
                        Vec3(3.2391957277667367, -2.7842432932035019, 2.3313353711315332),
                        Vec3(3.2389604055651491, -2.7841570904746518, 2.3310391678323041),
                        Vec3(3.2388533589588375, -2.7841178774010062, 2.3309044267423693),
                        Vec3(3.2374844630430593, -2.7836164263495884, 2.3291813784599089),
                        Vec3(3.2387330561807706, -2.7840738083568808, 2.3307529999883325)},
                       {Vec3(2.9540599052029797, -2.9703024772589894, 1.7954813894160513),
                        Vec3(3.5232416109977769, -2.5977848466145512, 2.8658174353138595),
                        Vec3(3.0852813111793065, -2.8844207893768075, 2.0422409004258082),
                        Vec3(3.2285982623984584, -2.7906228112394884, 2.3117458748038637),
                        Vec3(3.2890742545942211, -2.7510425251745012, 2.4254699045178034),
                        Vec3(3.4982695674100519, -2.614128529220503, 2.8188579502450088),
                        Vec3(3.0268385150591319, -2.9226703833767185, 1.9323402709478863),
                        Vec3(3.0222748708772791, -2.9256571928742439, 1.9237584160379899)});
}

// The needles of GjkTouching.NeedlesSideBySideTouch, d* = 6e-5 bands.
test::Points crossing_needle_a() {
  return {Vec3(3.2373982772939152, -2.7835848549293236, 2.3290728952413882),
          Vec3(3.2399032411110107, -2.7845024680382378, 2.3322259280010171),
          Vec3(3.239593947308288, -2.7843891681654576, 2.3318366155855381),
          Vec3(3.2391957277667367, -2.7842432932035019, 2.3313353711315332),
          Vec3(3.2389604055651491, -2.7841570904746518, 2.3310391678323041),
          Vec3(3.2388533589588375, -2.7841178774010062, 2.3309044267423693),
          Vec3(3.2374844630430593, -2.7836164263495884, 2.3291813784599089),
          Vec3(3.2387330561807706, -2.7840738083568808, 2.3307529999883325)};
}
test::Points crossing_needle_b() {
  return {Vec3(2.9540599052029797, -2.9703024772589894, 1.7954813894160513),
          Vec3(3.5232416109977769, -2.5977848466145512, 2.8658174353138595),
          Vec3(3.0852813111793065, -2.8844207893768075, 2.0422409004258082),
          Vec3(3.2285982623984584, -2.7906228112394884, 2.3117458748038637),
          Vec3(3.2890742545942211, -2.7510425251745012, 2.4254699045178034),
          Vec3(3.4982695674100519, -2.614128529220503, 2.8188579502450088),
          Vec3(3.0268385150591319, -2.9226703833767185, 1.9323402709478863),
          Vec3(3.0222748708772791, -2.9256571928742439, 1.9237584160379899)};
}

// Regression (issue 25): the needles above, d* = 6e-5 bands. GJK's
// stalled simplex was polished to the pair of edges {1, 6} of A and {0, 4}
// of B, 6,840 bands apart, and the support along their closest points'
// difference came back from those edges with the gap open: that
// difference, of points each rounded by u R, was 3e-10 long and tilted by
// 2e-6, which along needles 0.6 long moved the support value 30 times the
// distance. The polish stopped with a lower bound of 0, and distance()
// answered `touching` at 11,850 bands with a certificate [0, 11850] bands
// (the status right by luck, the distance 10^4 times outside the
// standard). The polish now searches along the features' own normal
// (certifying_direction in gjk.cpp) and reaches the distance.
TEST(GjkRegression, StalledNeedlesReachTheDistance) {
  const test::Points a = crossing_needle_a();
  const test::Points b = crossing_needle_b();
  const std::optional<test::ExactDistance> exact = exact_distance(a, b);
  ASSERT_TRUE(exact);
  const double band =
      64 * kUnitRoundoff * std::max(test::max_abs_coordinate(a), test::max_abs_coordinate(b));
  const ConvexPolytope pa(a);
  const ConvexPolytope pb(b);
  for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk}) {
    DistanceOptions options;
    options.algorithm = alg;
    for (const bool swapped : {false, true}) {
      SCOPED_TRACE(std::string(to_string(alg)) + (swapped ? ", swapped" : ""));
      const DistanceResult r = swapped ? distance(pb, Pose::identity(), pa, Pose::identity(), options)
                                       : distance(pa, Pose::identity(), pb, Pose::identity(), options);
      EXPECT_EQ(r.status, Status::touching);
      EXPECT_LE(std::abs(r.distance - exact->distance()), band);
      EXPECT_LE(r.lower_bound, exact->distance() + band);
      EXPECT_LE((r.point_a - r.point_b).norm(), 2 * band);
    }
  }
}

// GJK's status follows what its answer certifies, on every exit of the
// loop, the polish and the contact classification (gjk.cpp,
// bounded_status): separated only with a lower bound above the band or a
// gap closed to the standard; touching only within kExtendedBands bands
// (where distance() recomputes the witness pair and decides); beyond,
// iteration_cap; and every answer's bounds hold the distance. Driven
// through every iteration cap from 1 on the stalls of the regressions
// above (needles, the flat pyramid warm-started from its base, a box on a
// segment's end 1e12 from the origin) and on random near-contact pairs:
// a cap cuts the loop, the polish or the classification wherever it
// falls. Before the polish searched along the features' normal, the
// needles ended `touching` 11,848 bands from contact here.
TEST(GjkStatus, FollowsTheCertifiedBoundsOnEveryExit) {
  struct Case {
    ConvexPolytope a, b;
    Pose b_in_a;
    DistanceCache warm;
  };
  std::vector<Case> cases;
  cases.push_back({ConvexPolytope(crossing_needle_a()), ConvexPolytope(crossing_needle_b()),
                   Pose::identity(), {}});
  test::Rng rng(25);
  {  // the pyramid of FlatFaceAboveATouchingApexReachesIt, warm from its base
    const double size = 10.0;
    const double h = 9.0 * 64.0 * kUnitRoundoff * size;
    const Mat3 rot = test::random_rotation(rng);
    const test::Points base = {rot * Vec3(size, size, h), rot * Vec3(-size, size, h),
                               rot * Vec3(-size, -size, h),
                               rot * Vec3(size, -size, h + 3 * kUnitRoundoff * size)};
    test::Points a = base;
    a.push_back(Vec3::Zero());
    Case c{ConvexPolytope(a), ConvexPolytope(test::Points{Vec3::Zero()}), Pose::identity(), {}};
    for (std::size_t k = 0; k < 4; ++k) {
      for (int v = 0; v < c.a.vertex_count(); ++v) {
        if (c.a.vertex(v) == base[k]) c.warm.vertices_a[k] = v;
      }
      c.warm.vertices_b[k] = 0;
    }
    cases.push_back(c);
  }
  for (int k = 0; k < 8; ++k) {  // near contact, up to 1e6 from the origin
    const Vec3 far = test::log_uniform(rng, 1.0, 1e6) * test::random_unit_vector(rng);
    const ConvexPolytope a(test::transformed(random_body(rng, 12), test::random_rotation(rng), far));
    const ConvexPolytope b(random_body(rng, 12));
    const Vec3 n = test::random_unit_vector(rng);
    // B's support towards A just touching A's support along n, then moved
    // off by 0 to 40 bands.
    const double sa = a.vertex(support_brute_force(a.vertices(), n)).dot(n);
    const double sb = b.vertex(support_brute_force(b.vertices(), -n)).dot(n);
    const double gap = test::uniform(rng, 0.0, 40.0) * 64.0 * kUnitRoundoff * (far.norm() + 2.0);
    cases.push_back({a, b, Pose::from_translation((sa - sb + gap) * n), {}});
  }
  int undecided = 0;
  for (const Case& c : cases) {
    const double band = contact_band(c.a, c.b, c.b_in_a);
    const double reference = brute_force_distance(c.a, c.b, c.b_in_a);
    for (int cap = 1; cap <= 24; ++cap) {
      DistanceOptions options = gjk_options();
      options.max_iterations = cap;
      DistanceCache warm = c.warm;
      for (const DistanceResult& r : {gjk_distance(c.a, c.b, c.b_in_a, options, band),
                                      enhanced_gjk_distance(c.a, c.b, c.b_in_a, options, band, warm)}) {
        SCOPED_TRACE("cap " + std::to_string(cap) + ": " + to_string(r.status) + ", distance " +
                     std::to_string(r.distance / band) + " bands, lower bound " +
                     std::to_string(r.lower_bound / band) + ", d* " +
                     std::to_string(reference / band));
        expect_finite(r);
        EXPECT_LE(r.iterations, cap);
        EXPECT_LE(r.lower_bound, reference + band);
        EXPECT_GE(r.distance, reference - band);
        switch (r.status) {
          case Status::separated:
            EXPECT_GT(r.distance, band);
            EXPECT_TRUE(r.lower_bound > band ||
                        r.distance - r.lower_bound <= 1e-12 * r.distance + band);
            break;
          case Status::touching:
            EXPECT_LE(r.distance, detail::kExtendedBands * band);
            break;
          case Status::intersecting:
            EXPECT_EQ(r.distance, 0.0);
            break;
          case Status::iteration_cap:
            ++undecided;
            break;
        }
      }
    }
  }
  EXPECT_GT(undecided, 0);  // the caps really cut runs short
}

// Story (issue 9, "found at 21.5 x 64 u R where the exact distance is below
// 0.011 x 64 u R"; the sweep's seed 2, case 1829): two thin plates face on
// face far from the origin, d* = 0.02 bands. GJK stalled the same way at
// 1.5 bands with a lower bound of 0 and said separated.
TEST(GjkTouching, ThinPlatesFaceOnFaceTouch) {
  expect_not_separated({Vec3(2378.0349709273542, -45095.004400438222, 34875.524948756443),
                        Vec3(42566.158649478792, 35869.779378260791, -12529.875411676241),
                        Vec3(2378.0679113908809, -45095.077121629613, 34875.428671959286),
                        Vec3(42566.191589942318, 35869.706657069401, -12529.971688473399),
                        Vec3(-42566.191589942318, -35869.706657069401, 12529.971688473399),
                        Vec3(-2378.0679113908809, 45095.077121629613, -34875.428671959286),
                        Vec3(-42566.158649478792, -35869.779378260791, 12529.875411676241),
                        Vec3(-2378.0349709273542, 45095.004400438222, -34875.524948756443)},
                       {Vec3(-282247.83099965163, -402944.49285554112, 343062.47725361836),
                        Vec3(236169.86779226852, 416322.08048925764, -361413.45377570699),
                        Vec3(-281114.09435352584, -407096.78274457779, 339067.90051670559),
                        Vec3(237303.60443839442, 412169.79060022096, -365408.03051261976),
                        Vec3(-809966.68706226163, -294624.38269938395, 80689.071213969612),
                        Vec3(-291548.98827034148, 524642.19064541475, -623786.85981535574),
                        Vec3(-808832.95041613583, -298776.67258842062, 76694.49447705684),
                        Vec3(-290415.25162421569, 520489.90075637813, -627781.43655226845)});
}

}  // namespace
}  // namespace proxima
