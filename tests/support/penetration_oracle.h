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
#pragma once

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/convex_hull_3.h>

#include <optional>
#include <vector>

#include "support/exact_oracle.h"
#include "support/generators.h"

namespace proxima::test {

using ExactKernel = CGAL::Exact_predicates_exact_constructions_kernel;
using ExactFT = ExactKernel::FT;
using ExactPoint = ExactKernel::Point_3;

enum class OriginInM : std::uint8_t { inside, boundary, outside };

struct ExactDepth {
  bool flat = false;  // M has no interior: depth* = 0
  OriginInM origin = OriginInM::outside;
  ExactFT depth_squared = 0;   // when solid and inside
  Vec3 normal = Vec3::Zero();  // the nearest facet's outward normal (rounded)
  // depth* rounded: through depth_squared / 4^e (e the magnitude exponent
  // of the points), so that depths near 1e-300 or 1e300 do not underflow
  // or overflow on the way.
  int exponent = 0;
  double depth() const {
    const ExactFT unit(std::ldexp(1.0, -exponent));
    return std::ldexp(std::sqrt(CGAL::to_double(depth_squared * unit * unit)), exponent);
  }
};

// |value - d| <= rel d + abs with d = sqrt(exact_sq), decided exactly (the
// same squaring argument as within_bound in exact_oracle.h).
inline bool within_bound(double value, const ExactFT& exact_sq, double rel, double abs) {
  const ExactFT v(value), r(rel), c(abs);
  const ExactFT lo = v - c;
  if (lo > 0) {
    const ExactFT k = 1 + r;
    if (lo * lo > k * k * exact_sq) return false;
  }
  const ExactFT k = 1 - r;
  const ExactFT hi = v + c;
  return k * k * exact_sq <= hi * hi;
}

inline ExactDepth exact_depth(const Points& a, const Points& b) {
  ScopedFpTrapsOff traps_off;
  std::vector<ExactPoint> m;
  m.reserve(a.size() * b.size());
  for (const Vec3& x : a)
    for (const Vec3& y : b)
      m.emplace_back(ExactFT(x.x()) - ExactFT(y.x()), ExactFT(x.y()) - ExactFT(y.y()),
                     ExactFT(x.z()) - ExactFT(y.z()));
  ExactDepth r;
  std::frexp(std::max(max_abs_coordinate(a), max_abs_coordinate(b)), &r.exponent);
  // Solid? Four affinely independent points.
  std::size_t i1 = 0, i2 = 0, i3 = 0;
  for (i1 = 1; i1 < m.size() && m[i1] == m[0]; ++i1) {
  }
  if (i1 < m.size())
    for (i2 = i1 + 1; i2 < m.size() && CGAL::collinear(m[0], m[i1], m[i2]); ++i2) {
    }
  if (i1 < m.size() && i2 < m.size())
    for (i3 = i2 + 1; i3 < m.size() && CGAL::coplanar(m[0], m[i1], m[i2], m[i3]); ++i3) {
    }
  if (i1 >= m.size() || i2 >= m.size() || i3 >= m.size()) {
    r.flat = true;
    r.origin = OriginInM::boundary;  // callers give flat M only when it holds the origin
    return r;
  }
  CGAL::Polyhedron_3<ExactKernel> hull;
  CGAL::convex_hull_3(m.begin(), m.end(), hull);
  bool first = true, boundary = false, outside = false;
  const ExactPoint origin(0, 0, 0);
  for (auto f = hull.facets_begin(); f != hull.facets_end(); ++f) {
    auto h = f->facet_begin();
    const ExactPoint& p0 = h->vertex()->point();
    ++h;
    const ExactPoint& p1 = h->vertex()->point();
    ++h;
    const ExactPoint& p2 = h->vertex()->point();
    const auto n = CGAL::cross_product(p1 - p0, p2 - p0);
    const ExactFT offset = n * (p0 - origin);
    if (offset < 0) outside = true;
    if (offset == 0) boundary = true;
    const ExactFT d2 = offset * offset / n.squared_length();
    if (first || d2 < r.depth_squared) {
      r.depth_squared = d2;
      r.normal =
          Vec3(CGAL::to_double(n.x()), CGAL::to_double(n.y()), CGAL::to_double(n.z())).normalized();
      first = false;
    }
  }
  r.origin = outside ? OriginInM::outside : boundary ? OriginInM::boundary : OriginInM::inside;
  if (r.origin != OriginInM::inside) r.depth_squared = 0;
  return r;
}

}  // namespace proxima::test
