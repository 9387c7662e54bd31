// proxima test support: seeded generators of convex polytope inputs and poses.
// SPDX-License-Identifier: BSD-3-Clause
//
// Every generator takes the caller's Rng, so a test that seeds it reproduces
// its inputs bit for bit on every machine: only integer draws and the basic
// IEEE operations feed the coordinates (std::uniform_real_distribution and
// std::normal_distribution are implementation-defined, so they are not used).
//
// Shapes are generated around the origin at unit size unless said otherwise;
// tests move them with `transformed` (in double, so that the algorithm and
// the exact oracle see the same doubles) or pass a Pose.
#pragma once

#include "proxima/core/types.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace proxima::test {

using Rng = std::mt19937_64;
using Points = std::vector<Vec3>;

// The seed of a test's Rng: `fixed`, the one its cases were chosen on, or
// the value of the environment variable PROXIMA_TEST_SEED when set (a
// decimal integer), so that a test whose scenario must reach a count can
// be run on other seeds without editing it:
//   for s in $(seq 1 20); do PROXIMA_TEST_SEED=$s ./mesh_test --gtest_filter=...; done
inline std::uint64_t test_seed(std::uint64_t fixed) {
  const char* text = std::getenv("PROXIMA_TEST_SEED");
  if (text == nullptr || *text == '\0') return fixed;
  char* end = nullptr;
  const unsigned long long value = std::strtoull(text, &end, 10);
  if (*end != '\0') {
    std::fprintf(stderr, "PROXIMA_TEST_SEED=%s is not a decimal integer\n", text);
    std::abort();
  }
  return value;
}

// Uniform double in [0, 1) with 53 random bits: portable, unlike
// std::uniform_real_distribution whose algorithm the standard leaves open.
inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }
inline double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }
// Integer in [lo, hi], portable (std::uniform_int_distribution is not).
// The modulo bias of a 64-bit draw over ranges this small is ~1e-17.
inline int uniform_int(Rng& rng, int lo, int hi) {
  const auto span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo + 1);
  return lo + static_cast<int>(rng() % span);
}
// Log-uniform in [lo, hi] (both > 0): separations and scales spread evenly
// over the decades, so the tiny ones are as common as the large ones.
inline double log_uniform(Rng& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

// A point from three draws, the last coordinate's first: drawn(fx, fy, fz)
// calls fz, then fy, then fx. A call such as Vec3(f(rng), f(rng), f(rng))
// leaves the order of its draws to the compiler (gcc takes the last
// argument first, clang the first), so one seed gave other cases under
// each; this is gcc's order, the one every seeded case here was chosen on.
template <class Fx, class Fy, class Fz>
Vec3 drawn(Fx&& fx, Fy&& fy, Fz&& fz) {
  const double z = fz();
  const double y = fy();
  return Vec3(fx(), y, z);
}
template <class F>
Vec3 drawn(F&& f) {
  return drawn(f, f, f);
}

// A quaternion (w, x, y, z) from four draws in the order gcc gives
// Quat(fw(), fx(), fy(), fz()): fz, fy, fx, then fw (see drawn()). Not
// normalized.
template <class Fw, class Fx, class Fy, class Fz>
Quat drawn_quaternion(Fw&& fw, Fx&& fx, Fy&& fy, Fz&& fz) {
  const double z = fz();
  const double y = fy();
  const double x = fx();
  return Quat(fw(), x, y, z);
}
template <class F>
Quat drawn_quaternion(F&& f) {
  return drawn_quaternion(f, f, f, f);
}

// Uniform on the unit sphere: normalize a point drawn in the cube and kept
// only inside the ball (rejection keeps the distribution uniform without a
// normal deviate).
inline Vec3 random_unit_vector(Rng& rng) {
  for (;;) {
    const Vec3 p = drawn([&] { return uniform(rng, -1, 1); });
    const double n2 = p.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) return p / std::sqrt(n2);
  }
}

// Uniform random rotation: a uniform unit quaternion is a uniform point on
// the 3-sphere; draw it in the 4-cube with rejection like random_unit_vector.
inline Quat random_quaternion(Rng& rng) {
  for (;;) {
    // Last coordinate first, as drawn() does.
    Eigen::Vector4d q;
    for (int k = 3; k >= 0; --k) q[k] = uniform(rng, -1, 1);
    const double n2 = q.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) {
      const Eigen::Vector4d u = q / std::sqrt(n2);
      return Quat(u[0], u[1], u[2], u[3]);
    }
  }
}
inline Mat3 random_rotation(Rng& rng) { return random_quaternion(rng).toRotationMatrix(); }

// Rotation by `angle` about a random axis: small angles give the nearly
// parallel features that a uniform rotation almost never produces.
inline Mat3 random_small_rotation(Rng& rng, double angle) {
  return Eigen::AngleAxisd(angle, random_unit_vector(rng)).toRotationMatrix();
}

// r * p + t for every point, rounded in double: the result is "the given
// doubles" that both the algorithm (with identity poses) and the oracle see.
inline Points transformed(const Points& pts, const Mat3& r, const Vec3& t) {
  Points out;
  out.reserve(pts.size());
  for (const Vec3& p : pts) out.push_back(r * p + t);
  return out;
}
inline Points transformed(const Points& pts, const Pose& pose) {
  return transformed(pts, pose.rotation, pose.translation);
}
inline Points translated(const Points& pts, const Vec3& t) {
  return transformed(pts, Mat3::Identity(), t);
}
inline Points scaled(const Points& pts, double s) {
  Points out;
  out.reserve(pts.size());
  for (const Vec3& p : pts) out.push_back(p * s);
  return out;
}

// Largest absolute coordinate: the R of the accuracy standard (the largest
// coordinate magnitude is convex, so the hull's maximum is at an input point).
inline double max_abs_coordinate(const Points& pts) {
  double r = 0.0;
  for (const Vec3& p : pts) r = std::max(r, p.cwiseAbs().maxCoeff());
  return r;
}

// ---------------------------------------------------------------------------
// Shapes (unit size, centred near the origin).

inline Points points_on_sphere(Rng& rng, int n, double radius = 1.0) {
  Points pts;
  for (int i = 0; i < n; ++i) pts.push_back(radius * random_unit_vector(rng));
  return pts;
}

inline Points points_in_cube(Rng& rng, int n, double half = 1.0) {
  Points pts;
  for (int i = 0; i < n; ++i)
    pts.push_back(drawn([&] { return uniform(rng, -half, half); }));
  return pts;
}

// Integer grid points in [-g, g]^3 (divided by g): many coplanar faces,
// collinear edges and exact ties in support queries, the plateaus that hill
// climbing and the hull builder must survive.
inline Points grid_points(Rng& rng, int n, int g = 3) {
  Points pts;
  for (int i = 0; i < n; ++i)
    pts.push_back(drawn([&] { return static_cast<double>(uniform_int(rng, -g, g)); }) / g);
  return pts;
}

inline Points box(const Vec3& half) {
  Points pts;
  for (int i = 0; i < 8; ++i)
    pts.push_back(Vec3((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                       (i & 4) ? half.z() : -half.z()));
  return pts;
}
inline Points cube(double edge) { return box(Vec3::Constant(edge / 2)); }

// Regular tetrahedron of the given edge length, centred at the origin
// (alternate corners of a cube of edge edge/sqrt(2)).
inline Points regular_tetrahedron(double edge) {
  const double h = edge / (2.0 * std::sqrt(2.0));
  return {Vec3(h, h, h), Vec3(h, -h, -h), Vec3(-h, h, -h), Vec3(-h, -h, h)};
}

// A long thin body along x: aspect ratio length / thickness.
inline Points needle(Rng& rng, double length, double thickness, int n = 8) {
  Points pts{Vec3(-length / 2, 0, 0), Vec3(length / 2, 0, 0)};
  for (int i = 2; i < n; ++i)
    pts.push_back(drawn([&] { return uniform(rng, -length / 2, length / 2); },
                        [&] { return uniform(rng, -thickness, thickness); },
                        [&] { return uniform(rng, -thickness, thickness); }));
  return pts;
}

// A tetrahedron that is almost flat: a unit triangle and an apex `height`
// above a random point of it.
inline Points sliver(Rng& rng, double height) {
  Points pts{Vec3(-0.5, -0.4, 0), Vec3(0.6, -0.3, 0), Vec3(0.1, 0.7, 0)};
  pts.push_back(drawn([&] { return uniform(rng, -0.1, 0.1); }, [&] { return uniform(rng, -0.1, 0.1); },
                      [&] { return height; }));
  return pts;
}

// n points on a circle (plus a few inside) in the plane z = 0: exactly
// coplanar. Rotate with `transformed` to get a nearly flat body instead.
inline Points flat_polygon(Rng& rng, int n) {
  Points pts;
  for (int i = 0; i < n; ++i) {
    const double a = uniform(rng, 0, 2 * std::numbers::pi);
    const double r = (i % 4 == 3) ? uniform(rng, 0.1, 0.9) : 1.0;
    pts.push_back(Vec3(r * std::cos(a), r * std::sin(a), 0));
  }
  return pts;
}

// n points on one segment along a random direction (exactly collinear only
// for axis directions; callers choose): endpoints +-d/2 and points between.
inline Points segment_points(Rng& rng, const Vec3& dir, int n = 2) {
  Points pts{-0.5 * dir, 0.5 * dir};
  for (int i = 2; i < n; ++i) pts.push_back(uniform(rng, -0.5, 0.5) * dir);
  return pts;
}

inline Points single_point(const Vec3& p = Vec3::Zero()) { return {p}; }

// The same points with some repeated (exact duplicates, shuffled in).
inline Points with_duplicates(Rng& rng, Points pts, int copies) {
  const int n = static_cast<int>(pts.size());
  for (int i = 0; i < copies; ++i) pts.push_back(pts[static_cast<std::size_t>(uniform_int(rng, 0, n - 1))]);
  // Fisher-Yates with our own draws (std::shuffle's order is implementation-defined).
  for (int i = static_cast<int>(pts.size()) - 1; i > 0; --i)
    std::swap(pts[static_cast<std::size_t>(i)], pts[static_cast<std::size_t>(uniform_int(rng, 0, i))]);
  return pts;
}

// A prism: n points of a disc of `radius` about `at` in the plane
// orthogonal to the unit w (a third of them inside), and their copies moved
// by h w, all rounded: each cap is a facet that rounding splits into
// nearly coplanar faces, with nearly flat vertices.
inline Points rounded_prism(Rng& rng, const Vec3& w, double radius, double h, int n, const Vec3& at) {
  const Vec3 u = w.unitOrthogonal(), v = w.cross(u);
  Points p;
  for (int i = 0; i < n; ++i) {
    const double t = uniform(rng, 0, 2 * std::numbers::pi);
    const double r = radius * ((i % 3 == 2) ? uniform(rng, 0.3, 1.0) : 1.0);
    const Vec3 x = at + r * std::cos(t) * u + r * std::sin(t) * v;
    p.push_back(x);
    p.push_back(x + h * w);
  }
  return p;
}

// ---------------------------------------------------------------------------
// Placement.

// Largest v.p over the points: the support value, exact up to one rounding
// per product.
inline double support_value(const Points& pts, const Vec3& v) {
  double h = -INFINITY;
  for (const Vec3& p : pts) h = std::max(h, v.dot(p));
  return h;
}

// Translates B along the unit direction n so that the slab between the
// supporting planes of A (in direction n) and of B (in direction -n) has
// width `gap` (negative: overlap of that depth). The exact distance is then
// at least `gap` (the slab separates) and generally a little more, because
// the closest features need not face each other along n; rounding moves
// it by a few u R. Callers that need d* itself ask the oracle (and
// tighten_to_gap in exact_oracle.h sets it).
inline Points place_along(const Points& a, const Points& b, const Vec3& n, double gap) {
  const double ha = support_value(a, n);
  const double hb = support_value(b, -n);
  return translated(b, (ha + hb + gap) * n);
}

// ---------------------------------------------------------------------------
// Named random shapes: one call draws a shape family and its parameters.

enum class ShapeKind : std::uint8_t {
  sphere, cube_cloud, grid, box, needle, sliver, flat_polygon, tilted_polygon, segment, point,
  duplicates, tetrahedron
};
inline constexpr int kShapeKindCount = 12;

inline const char* to_string(ShapeKind k) {
  switch (k) {
    case ShapeKind::sphere: return "sphere";
    case ShapeKind::cube_cloud: return "cube_cloud";
    case ShapeKind::grid: return "grid";
    case ShapeKind::box: return "box";
    case ShapeKind::needle: return "needle";
    case ShapeKind::sliver: return "sliver";
    case ShapeKind::flat_polygon: return "flat_polygon";
    case ShapeKind::tilted_polygon: return "tilted_polygon";
    case ShapeKind::segment: return "segment";
    case ShapeKind::point: return "point";
    case ShapeKind::duplicates: return "duplicates";
    case ShapeKind::tetrahedron: return "tetrahedron";
  }
  return "unknown";
}

// A unit-size shape of the given kind with about n points (kinds with a
// fixed vertex count ignore n).
inline Points random_shape(Rng& rng, ShapeKind kind, int n) {
  n = std::max(n, 4);
  switch (kind) {
    case ShapeKind::sphere: return points_on_sphere(rng, n);
    case ShapeKind::cube_cloud: return points_in_cube(rng, n);
    case ShapeKind::grid: return grid_points(rng, n, uniform_int(rng, 1, 4));
    case ShapeKind::box:
      return box(drawn([&] { return uniform(rng, 0.05, 1); }));
    case ShapeKind::needle: return needle(rng, 2.0, log_uniform(rng, 1e-9, 1e-2), std::min(n, 12));
    case ShapeKind::sliver: return sliver(rng, log_uniform(rng, 1e-12, 1e-3));
    case ShapeKind::flat_polygon: return flat_polygon(rng, n);
    case ShapeKind::tilted_polygon:
      return transformed(flat_polygon(rng, n), random_rotation(rng), Vec3::Zero());
    case ShapeKind::segment: {
      // Axis-aligned half the time: exactly collinear interior points.
      const Vec3 dir = (rng() & 1) ? Vec3(Vec3::Unit(uniform_int(rng, 0, 2)) * 2.0) : Vec3(2.0 * random_unit_vector(rng));
      return segment_points(rng, dir, uniform_int(rng, 2, 4));
    }
    case ShapeKind::point:
      return single_point(drawn([&] { return uniform(rng, -0.1, 0.1); }, [&] { return uniform(rng, -0.1, 0.1); },
                                [] { return 0.0; }));
    case ShapeKind::duplicates: return with_duplicates(rng, points_on_sphere(rng, std::min(n, 16)), 6);
    case ShapeKind::tetrahedron: return regular_tetrahedron(1.5);
  }
  return single_point();
}

inline ShapeKind random_shape_kind(Rng& rng) {
  return static_cast<ShapeKind>(uniform_int(rng, 0, kShapeKindCount - 1));
}

// ---------------------------------------------------------------------------
// The paper's two stress experiments (section 6, "Robustness"), one random
// orientation per call. Bodies are returned as world vertex arrays, both
// rotated, B placed along a random direction with place_along, so d* is at
// least the stated gap; tighten_to_gap (exact_oracle.h) then moves B so that
// d* is the gap itself, whatever the closest features.

struct BodyPair {
  Points a;
  Points b;
};

inline constexpr double kPaperTetrahedronEdge = 1e-23;
inline constexpr double kPaperTetrahedronGap = 2e-22;
inline constexpr double kPaperCubeScale = 1e39;
inline constexpr double kPaperCubeEdgeA = 2000.0 * kPaperCubeScale;
inline constexpr double kPaperCubeEdgeB = 1e-15 * kPaperCubeScale;
inline constexpr double kPaperCubeGap = 1e-10 * kPaperCubeScale;

// Experiment 1: two regular tetrahedra of edge 1e-23, 2e-22 apart.
inline BodyPair paper_tetrahedra(Rng& rng) {
  const Points a = transformed(regular_tetrahedron(kPaperTetrahedronEdge), random_rotation(rng), Vec3::Zero());
  const Points b = transformed(regular_tetrahedron(kPaperTetrahedronEdge), random_rotation(rng), Vec3::Zero());
  return {a, place_along(a, b, random_unit_vector(rng), kPaperTetrahedronGap)};
}

// Experiment 2: cubes of edge 2000 and 1e-15, the whole scene scaled by
// 1e39, 1e-10 apart (so edges 2e42 and 1e24, gap 1e29). The small cube is
// A, at the origin, and the big one B is placed beside it: the other way
// round, the small cube's world coordinates would be ~1e42 and its
// vertices, 1e24 apart, would round to one double (1e24 / 1e42 < u).
inline BodyPair paper_cubes(Rng& rng) {
  const Points a = transformed(cube(kPaperCubeEdgeB), random_rotation(rng), Vec3::Zero());
  const Points b = transformed(cube(kPaperCubeEdgeA), random_rotation(rng), Vec3::Zero());
  return {a, place_along(a, b, random_unit_vector(rng), kPaperCubeGap)};
}

// Points printed with %.17g, in a form that pastes into a C++ test as a
// Points initializer: every failing case becomes a regression test.
inline std::string format_points(const Points& pts) {
  std::string s = "{";
  char buf[96];
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%sVec3(%.17g, %.17g, %.17g)", i ? ",\n " : "", pts[i].x(), pts[i].y(),
                  pts[i].z());
    s += buf;
  }
  return s + "}";
}

inline std::string format_pose(const Pose& p) {
  std::string s = "Pose(Mat3{";
  char buf[96];
  for (int r = 0; r < 3; ++r) {
    std::snprintf(buf, sizeof buf, "%s{%.17g, %.17g, %.17g}", r ? ", " : "", p.rotation(r, 0), p.rotation(r, 1),
                  p.rotation(r, 2));
    s += buf;
  }
  std::snprintf(buf, sizeof buf, "}, Vec3(%.17g, %.17g, %.17g))", p.translation.x(), p.translation.y(),
                p.translation.z());
  return s + buf;
}

}  // namespace proxima::test
