// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closed-form closest points between two simplices of at most three
// vertices (point, segment, triangle), the paper's "local method" (section 4,
// eqs. 10-18, after Eberly's region analysis). Every kernel returns the two
// points, their barycentric coefficients over the input vertices (eq. 20) and
// the minimal active sets: a vertex is active iff its coefficient is non-zero.
//
// The kernels are templated on the scalar S so that the tests can run the very
// same code on an exact rational type; for S = double they are the hot path
// of the hybrid algorithm (no heap, no virtual calls, at most one division on
// the main path of each elementary kernel).
//
// Conventions shared by all kernels:
//  * Distances are computed from the returned points, |point_b - point_a|^2,
//    never from the quadratic form's constant term: f - d^2/a cancels
//    catastrophically when the distance is small next to the coordinates.
//  * Every division is lazy: a numerator is compared with 0 and with its
//    denominator first, so a quotient is always in [0, 1] and no division by
//    zero can happen, whatever the input (finite) and the tolerances.
//  * Degenerate features are reduced, never divided by (KernelTolerance).
//  * Numerators of the 2x2 normal equations are evaluated as triple products
//    (Lagrange's identity, see detail::triangle_foot). In exact arithmetic
//    they equal Eberly's b*e - c*d forms; in floating point they locate the
//    query relative to the feature's edges to within u times its distance,
//    where b*e - c*d is only good to u / sin^2 of the feature's angle.
//
// Valid range for S = double: coordinates and feature extents within
// [1e-75, 1e75] in magnitude (the kernels form length^4 quantities). Below
// about 1e-77 a triangle's det underflows and it is taken as its longest edge;
// no finite input in range traps or returns NaN.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"
#include "proxima/geometry/closest_point_point.h"
#include "proxima/geometry/closest_point_segment.h"
#include "proxima/geometry/closest_point_triangle.h"
#include "proxima/geometry/closest_segment_segment.h"
#include "proxima/geometry/closest_segment_triangle.h"
#include "proxima/geometry/closest_triangle_triangle.h"

namespace proxima {

// A and B are 1..3 points each (point, segment, triangle; na, nb outside
// 1..3 are a precondition violation). Dispatches to the kernels of the
// headers above,
// swapping sides where needed so that the coefficients always refer to the
// caller's a/b order.
template <class S>
ClosestPoints<S> closest_points(const Vec3T<S>* a, int na, const Vec3T<S>* b, int nb,
                                const KernelTolerance<S>& tol = {}) {
  switch (na * 4 + nb) {
    case 1 * 4 + 1:
      return closest_point_point(a[0], b[0]);
    case 1 * 4 + 2:
      return closest_point_segment(a[0], b[0], b[1], tol);
    case 2 * 4 + 1:
      return detail::swapped(closest_point_segment(b[0], a[0], a[1], tol));
    case 1 * 4 + 3:
      return closest_point_triangle(a[0], b[0], b[1], b[2], tol);
    case 3 * 4 + 1:
      return detail::swapped(closest_point_triangle(b[0], a[0], a[1], a[2], tol));
    case 2 * 4 + 2:
      return closest_segment_segment(a[0], a[1], b[0], b[1], tol);
    case 2 * 4 + 3:
      return closest_segment_triangle(a[0], a[1], b[0], b[1], b[2], tol);
    case 3 * 4 + 2:
      return detail::swapped(closest_segment_triangle(b[0], b[1], a[0], a[1], a[2], tol));
    default:
      return closest_triangle_triangle(a[0], a[1], a[2], b[0], b[1], b[2], tol);
  }
}

}  // namespace proxima
