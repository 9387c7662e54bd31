// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: the primitives of robotics and simulation as Bodies
// (proxima/shape/body.h), in the body's own frame, centred at its origin.
//
//   box       its 8 corners, plus an optional radius (a rounded box)
//   sphere    a point with a radius
//   capsule   a segment along z with a radius
//   cylinder  a prism along z over a regular polygon circumscribing the circle
//   cone      a pyramid along z over such a polygon (base at -z, apex at +z)
//
// Box, sphere and capsule are exact. A cylinder or cone is a polytope that
// contains the true solid and whose every point is within
// Body::approximation_error() of it: the answer is exact for the polytope,
// never above the true distance, and at most the approximation error below
// it (the same for the signed distance; BodyResult::approximation_error
// adds both bodies'). The error is the caller's `tolerance` or less; the
// number of sides is the smallest that meets it (polygon_sides).
//
// Lengths are in the caller's unit (proxima has none). Every argument must
// be finite and >= 0 (the tolerance > 0); otherwise InvalidInput names the
// function, the argument and its value.
#pragma once

#include "proxima/core/types.h"
#include "proxima/shape/body.h"

namespace proxima {

// Half extents along x, y, z (the box spans [-h, h]); the rounded box
// reaches h + radius along each axis. A zero extent gives a flat box.
Body make_box(const Vec3& half_extents, double radius = 0.0);

// A ball: a point at the origin with `radius`.
Body make_sphere(double radius);

// The segment from (0, 0, -half_length) to (0, 0, half_length) with
// `radius`: the capsule's total length is 2 (half_length + radius).
Body make_capsule(double half_length, double radius);

// A cylinder of `radius` about the z axis, from z = -half_length to
// z = half_length, as a prism over a regular polygon of polygon_sides(radius,
// tolerance) sides around the circle.
Body make_cylinder(double radius, double half_length, double tolerance);

// A cone about the z axis: base disc of `radius` at z = -half_length, apex at
// (0, 0, half_length), as a pyramid over the same polygon.
Body make_cone(double radius, double half_length, double tolerance);

// The polygon used above: the fewest sides n >= 3 whose regular polygon
// around a circle of `radius` strays at most `tolerance` from it, and that
// deviation (the corners' distance from the circle, rounding included).
// InvalidInput when the tolerance would need more than kMaxPolygonSides.
struct PolygonApproximation {
  int sides = 3;
  double circumradius = 0.0;  // the corners' distance from the axis
  double deviation = 0.0;     // circumradius - radius, rounded up
};
inline constexpr int kMaxPolygonSides = 8192;
PolygonApproximation polygon_sides(double radius, double tolerance);

}  // namespace proxima
