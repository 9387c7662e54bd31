// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer (internal): exact orientation predicates on doubles, filtered: a double
// evaluation with a forward error bound decides when it can, exact integer
// arithmetic otherwise. Internal to the library (the hull build and
// face_plane); the tests check them against GMP.
//
// orient2d(a, b, c) = (a - c).x * (b - c).y - (a - c).y * (b - c).x, positive
// when a, b, c turn counter-clockwise. side3d(a, b, c, d) = ((b - a) x (c - a))
// . (d - a), positive when d lies on the side the right-hand normal of the
// triangle a, b, c points to. Both are exact for every finite double input,
// subnormals and the largest magnitudes included (see exact_predicates.cpp).
#pragma once

#include "proxima/core/types.h"

namespace proxima::detail {

// Sign of orient2d: +1 counter-clockwise, -1 clockwise, 0 collinear (exact).
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);

// Sign of side3d: +1 when d is on the normal side of triangle abc, -1 below,
// 0 coplanar (exact).
int side3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// a, b, c on one line, exactly.
bool collinear3d(const Vec3& a, const Vec3& b, const Vec3& c);

// The direction of (b - a) x (c - a), computed exactly and then rounded (each
// component within about 2^-53 of the length); zero exactly when a, b, c
// are collinear.
Vec3 exact_triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace proxima::detail
