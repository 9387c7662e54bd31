// proxima test support: the exact oracle for the penetration depth of two
// convex hulls. Test-only code.
// SPDX-License-Identifier: BSD-3-Clause
//
// M = A - B, the hull of the differences a_i - b_j of the given doubles,
// built by CGAL's convex_hull_3 on the exact kernel (every difference is
// exact: Epeck's numbers are exact for sums of doubles, and its predicates
// are exact). When M is solid and the origin strictly inside it,
//   depth*^2 = min over M's facets (triangles p0 p1 p2, outward) of
//              ((N . p0)^2 / |N|^2),  N = (p1 - p0) x (p2 - p0),
// exactly; a flat M (coplanar or lower-dimensional) has depth* = 0. Nothing
// of proxima is used: not its hulls, not its normals.
//
// Compiled once (penetration_oracle.cpp, the proxima_test_oracle library):
// the header declares the oracle in GMP's rationals only, without CGAL.
#pragma once

#include <gmpxx.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "support/exact_oracle.h"
#include "support/generators.h"

namespace proxima::test {

enum class OriginInM : std::uint8_t { inside, boundary, outside };

struct ExactDepth {
  bool flat = false;  // M has no interior: depth* = 0
  OriginInM origin = OriginInM::outside;
  mpq_class depth_squared = 0;  // when solid and inside, exact
  Vec3 normal = Vec3::Zero();   // the nearest facet's outward normal (rounded)
  // depth* rounded: through depth_squared / 4^e (e the magnitude exponent
  // of the points), so that depths near 1e-300 or 1e300 do not underflow
  // or overflow on the way.
  int exponent = 0;
  double depth() const;
};

// The exact depth* of conv(a) - conv(b) (see above).
ExactDepth exact_depth(const Points& a, const Points& b);

// The exact signed distance of conv(a) placed at pose_a and conv(b) placed
// at pose_b, the poses as the library's rigid-pose contract takes them
// (checked_pose: a rotation orthonormal to kOrthonormalUlps u as given,
// one within kRotationTolerance re-orthonormalized): the world points
// R a_i + t exactly (products and sums of doubles, exact in Epeck), M the
// exact hull of their differences, and
//   origin inside M:          sd* = -depth*  (the least facet offset),
//   origin on M's boundary:   sd* = 0,
//   origin outside M:         sd* = +distance from the origin to M (the
//                             least exact distance to M's facet triangles).
// Solid M only (`flat` set otherwise, sd* not computed).
struct ExactSignedDistance {
  bool flat = false;
  OriginInM origin = OriginInM::outside;
  mpq_class squared = 0;  // sd*^2, exact; the sign is the origin's side
  int exponent = 0;       // as ExactDepth::exponent
  // sd* rounded (through squared / 4^exponent, as ExactDepth::depth).
  double value() const;
  // Exactly: lower <= sd* <= upper.
  bool within(double lower, double upper) const;
};
ExactSignedDistance exact_signed_distance(const Points& a, const Pose& pose_a, const Points& b,
                                          const Pose& pose_b);

// The exact first time of contact of the hull of `a` (fixed) and the hull of
// `b` translated by t u, t in [0, 1]: the ray t u entering M = A - B (the
// exact hull of the differences of the given doubles), or nothing when it
// misses M or enters after t = 1. Exact rationals throughout; rounded once
// at the end.
std::optional<double> exact_translation_toi(const Points& a, const Points& b, const Vec3& u);

}  // namespace proxima::test
