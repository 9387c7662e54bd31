// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The primitives as Bodies: exact point sets with a radius (box, sphere,
// capsule), and circumscribed polygonal approximations (cylinder, cone).
//
// The polygon. A regular n-gon whose edges touch a circle of radius r has
// its corners at the circumradius r / cos(pi / n); it holds the disc, and
// its farthest points from the disc are the corners, r (1 / cos(pi / n) - 1)
// away. A prism (pyramid) over it holds the cylinder (cone), and since the
// distance to a convex solid is convex, the polytope's farthest points from
// the solid are among its vertices: the corners, at that same distance (for
// the cone: the nearest point of the cone to a corner is the base circle's
// point below it, the cone's side rising inwards from there). That is the
// Hausdorff distance of the two solids, so every distance between two
// bodies, signed or not, moves by at most its sum over both.
#include "proxima/shape/primitives.h"

#include "core/checks.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace proxima {
namespace {

// Rounding of the corners: each coordinate rho cos(t), rho sin(t) is within
// a few u of its exact value (cos and sin within an ulp, one product, the
// angle 2 pi k / n within a few u), so a corner's distance from the axis is
// rho (1 +- 4 u), and an edge's distance from the axis, rho cos(pi / n) up
// to 8 u. The circumradius is raised by kCornerUlps u so that every edge
// stays outside the circle, and the reported deviation raised as much
// again so that every corner is within it.
constexpr double kCornerUlps = 16.0;

// Finite (on the bits: no comparison with a NaN, which would raise
// FE_INVALID under a caller's traps) and >= 0.
void check_length(double value, const char* function, const char* argument) {
  detail::check_finite_non_negative(value, function, argument);
}

PolygonApproximation approximation(double radius, int sides) {
  const double stretch = 1.0 + kCornerUlps * kUnitRoundoff;
  PolygonApproximation p;
  p.sides = sides;
  p.circumradius = radius / std::cos(std::numbers::pi / sides) * stretch;
  p.deviation = (p.circumradius * stretch - radius) * stretch;
  return p;
}

// The polygon's corners at height z.
void add_polygon(std::vector<Vec3>& points, const PolygonApproximation& p, double z) {
  for (int k = 0; k < p.sides; ++k) {
    const double t = 2.0 * std::numbers::pi * k / p.sides;
    points.emplace_back(p.circumradius * std::cos(t), p.circumradius * std::sin(t), z);
  }
}

}  // namespace

PolygonApproximation polygon_sides(double radius, double tolerance) {
  check_length(radius, "polygon_sides", "radius");
  detail::check_finite_positive(tolerance, "polygon_sides", "tolerance");
  if (radius == 0.0) return approximation(0.0, 3);
  // The corners reach at most twice the radius (a triangle's): refused
  // where that overflows, before an infinite corner times sin(0) is NaN.
  if (!is_finite_bits(approximation(radius, 3).circumradius)) {
    char message[160];
    std::snprintf(message, sizeof message,
                  "polygon_sides: radius %g is too large: the polygon's corners overflow", radius);
    throw InvalidInput(message);
  }
  // r (1 / cos(pi / n) - 1) <= tol  <=>  cos(pi / n) >= r / (r + tol): the
  // closed form, then up by one side while the rounded deviation is above.
  const double ratio = radius / (radius + tolerance);
  // The angle is 0 when the tolerance is below the radius's last digit (no
  // division by it: that many sides are refused below anyway).
  const double angle = std::acos(std::min(ratio, 1.0));
  if (!(angle * kMaxPolygonSides >= std::numbers::pi)) {
    char message[240];
    std::snprintf(message, sizeof message,
                  "polygon_sides: tolerance %g for radius %g needs more than %d sides; the "
                  "smallest tolerance is about %.3g",
                  tolerance, radius, kMaxPolygonSides,
                  approximation(radius, kMaxPolygonSides).deviation);
    throw InvalidInput(message);
  }
  const double first = std::ceil(std::numbers::pi / angle);
  int sides = std::max(3, static_cast<int>(first));
  // The closed form may land one side below or above (rounding of acos):
  // settle on the smallest n that meets the tolerance.
  while (sides > 3 && approximation(radius, sides - 1).deviation <= tolerance) --sides;
  while (approximation(radius, sides).deviation > tolerance) {
    if (++sides > kMaxPolygonSides) {
      char message[200];
      std::snprintf(message, sizeof message,
                    "polygon_sides: tolerance %g for radius %g needs more than %d sides", tolerance,
                    radius, kMaxPolygonSides);
      throw InvalidInput(message);
    }
  }
  return approximation(radius, sides);
}

Body make_box(const Vec3& half_extents, double radius) {
  for (int i = 0; i < 3; ++i) {
    const char* names[] = {"half_extents.x", "half_extents.y", "half_extents.z"};
    check_length(half_extents[i], "make_box", names[i]);
  }
  check_length(radius, "make_box", "radius");
  std::vector<Vec3> corners;
  for (int k = 0; k < 8; ++k) {
    corners.emplace_back((k & 1) ? half_extents.x() : -half_extents.x(),
                         (k & 2) ? half_extents.y() : -half_extents.y(),
                         (k & 4) ? half_extents.z() : -half_extents.z());
  }
  return Body(std::make_shared<const ConvexPolytope>(corners), radius);
}

Body make_sphere(double radius) {
  check_length(radius, "make_sphere", "radius");
  return Body(std::make_shared<const ConvexPolytope>(std::vector<Vec3>{Vec3::Zero()}), radius);
}

Body make_capsule(double half_length, double radius) {
  check_length(half_length, "make_capsule", "half_length");
  check_length(radius, "make_capsule", "radius");
  return Body(std::make_shared<const ConvexPolytope>(
                  std::vector<Vec3>{Vec3(0, 0, -half_length), Vec3(0, 0, half_length)}),
              radius);
}

namespace {
// polygon_sides, its refusals named after the caller.
PolygonApproximation polygon_of(double radius, double tolerance, const char* function) {
  try {
    return polygon_sides(radius, tolerance);
  } catch (const InvalidInput& e) {
    std::string message = e.what();
    message.replace(0, std::string("polygon_sides").size(), function);
    throw InvalidInput(message);
  }
}
}  // namespace

Body make_cylinder(double radius, double half_length, double tolerance) {
  check_length(radius, "make_cylinder", "radius");
  check_length(half_length, "make_cylinder", "half_length");
  const PolygonApproximation p = polygon_of(radius, tolerance, "make_cylinder");
  std::vector<Vec3> points;
  add_polygon(points, p, -half_length);
  add_polygon(points, p, half_length);
  return Body(std::make_shared<const ConvexPolytope>(points), 0.0, p.deviation);
}

Body make_cone(double radius, double half_length, double tolerance) {
  check_length(radius, "make_cone", "radius");
  check_length(half_length, "make_cone", "half_length");
  const PolygonApproximation p = polygon_of(radius, tolerance, "make_cone");
  std::vector<Vec3> points;
  add_polygon(points, p, -half_length);
  points.emplace_back(0.0, 0.0, half_length);
  return Body(std::make_shared<const ConvexPolytope>(points), 0.0, p.deviation);
}

}  // namespace proxima
