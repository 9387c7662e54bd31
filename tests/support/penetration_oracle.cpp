// proxima test support: the exact penetration-depth oracle's definitions
// (see penetration_oracle.h). Test-only code, compiled once.
// SPDX-License-Identifier: BSD-3-Clause

#include "support/penetration_oracle.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <sstream>
#include <type_traits>

namespace proxima::test {

namespace {

using ExactKernel = CGAL::Exact_predicates_exact_constructions_kernel;
using ExactFT = ExactKernel::FT;
using ExactPoint = ExactKernel::Point_3;

// An exact number of the kernel as a GMP rational. Which exact type Epeck
// holds depends on how CGAL was configured (mpq_class, Gmpq or Boost's
// rational); each prints as "numerator/denominator", which GMP reads back
// exactly.
template <class Exact>
mpq_class rational_of(const Exact& e) {
  if constexpr (std::is_same_v<Exact, mpq_class>) {
    return e;
  } else {
    std::ostringstream os;
    os << e;
    mpq_class q(os.str());
    q.canonicalize();
    return q;
  }
}

mpq_class to_mpq(const ExactFT& x) { return rational_of(CGAL::exact(x)); }

// The differences a_i - b_j, exact (Epeck's numbers are exact for sums of
// doubles): the points whose hull is M = A - B.
std::vector<ExactPoint> differences(const Points& a, const Points& b) {
  std::vector<ExactPoint> m;
  m.reserve(a.size() * b.size());
  for (const Vec3& x : a)
    for (const Vec3& y : b)
      m.emplace_back(ExactFT(x.x()) - ExactFT(y.x()), ExactFT(x.y()) - ExactFT(y.y()),
                     ExactFT(x.z()) - ExactFT(y.z()));
  return m;
}

// A facet of M's exact hull: its outward normal N = (p1 - p0) x (p2 - p0)
// and offset N . p0 (a point x is inside the facet's plane when N . x <= offset).
struct FacetPlane {
  ExactKernel::Vector_3 normal;
  ExactFT offset;
};

// The facets of the exact hull of m, as CGAL's convex_hull_3 builds it.
std::vector<FacetPlane> facet_planes(const std::vector<ExactPoint>& m) {
  CGAL::Polyhedron_3<ExactKernel> hull;
  CGAL::convex_hull_3(m.begin(), m.end(), hull);
  const ExactPoint origin(0, 0, 0);
  std::vector<FacetPlane> planes;
  for (auto f = hull.facets_begin(); f != hull.facets_end(); ++f) {
    auto h = f->facet_begin();
    const ExactPoint& p0 = h->vertex()->point();
    ++h;
    const ExactPoint& p1 = h->vertex()->point();
    ++h;
    const ExactPoint& p2 = h->vertex()->point();
    const auto n = CGAL::cross_product(p1 - p0, p2 - p0);
    planes.push_back({n, n * (p0 - origin)});
  }
  return planes;
}

}  // namespace

double ExactDepth::depth() const {
  mpq_class scaled = depth_squared;
  if (exponent >= 0)
    mpq_div_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<mp_bitcnt_t>(2 * exponent));
  else
    mpq_mul_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<mp_bitcnt_t>(-2 * exponent));
  return std::ldexp(sqrt_to_double(scaled), exponent);
}

ExactDepth exact_depth(const Points& a, const Points& b) {
  ScopedFpTrapsOff traps_off;
  const std::vector<ExactPoint> m = differences(a, b);
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
  ExactFT depth_squared = 0;
  bool first = true, boundary = false, outside = false;
  for (const auto& [n, offset] : facet_planes(m)) {
    if (offset < 0) outside = true;
    if (offset == 0) boundary = true;
    const ExactFT d2 = offset * offset / n.squared_length();
    if (first || d2 < depth_squared) {
      depth_squared = d2;
      r.normal =
          Vec3(CGAL::to_double(n.x()), CGAL::to_double(n.y()), CGAL::to_double(n.z())).normalized();
      first = false;
    }
  }
  r.origin = outside ? OriginInM::outside : boundary ? OriginInM::boundary : OriginInM::inside;
  if (r.origin == OriginInM::inside) r.depth_squared = to_mpq(depth_squared);
  return r;
}

std::optional<double> exact_translation_toi(const Points& a, const Points& b, const Vec3& u) {
  ScopedFpTrapsOff traps_off;
  const std::vector<ExactPoint> m = differences(a, b);
  const ExactKernel::Vector_3 ue(ExactFT(u.x()), ExactFT(u.y()), ExactFT(u.z()));
  ExactFT enter = 0;  // the ray t u is inside M for t in [enter, leave]
  std::optional<ExactFT> leave;
  for (const auto& [n, offset] : facet_planes(m)) {
    const ExactFT along = n * ue;
    if (along == 0) {
      if (offset < 0) return std::nullopt;  // parallel and outside
    } else if (along < 0) {
      enter = CGAL::max(enter, offset / along);
    } else {
      const ExactFT t = offset / along;
      leave = leave ? CGAL::min(*leave, t) : t;
    }
  }
  if ((leave && enter > *leave) || enter > 1) return std::nullopt;
  return CGAL::to_double(enter);
}

}  // namespace proxima::test
