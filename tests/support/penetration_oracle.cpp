// proxima test support: the exact penetration-depth oracle's definitions
// (see penetration_oracle.h). Test-only code, compiled once.
// SPDX-License-Identifier: BSD-3-Clause

#include "support/penetration_oracle.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/convex_hull_3.h>
#include <CGAL/squared_distance_3.h>

#include <algorithm>
#include <array>
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

// The facets of the exact hull of m as CGAL's convex_hull_3 builds them
// (triangles), each its first three vertices in CGAL's outward order.
std::vector<std::array<ExactPoint, 3>> facet_triangles(const std::vector<ExactPoint>& m) {
  CGAL::Polyhedron_3<ExactKernel> hull;
  CGAL::convex_hull_3(m.begin(), m.end(), hull);
  std::vector<std::array<ExactPoint, 3>> triangles;
  for (auto f = hull.facets_begin(); f != hull.facets_end(); ++f) {
    auto h = f->facet_begin();
    const ExactPoint& p0 = h->vertex()->point();
    ++h;
    const ExactPoint& p1 = h->vertex()->point();
    ++h;
    triangles.push_back({p0, p1, h->vertex()->point()});
  }
  return triangles;
}

// A facet's plane: N = (p1 - p0) x (p2 - p0), offset N . p0.
FacetPlane facet_plane(const std::array<ExactPoint, 3>& t) {
  const auto n = CGAL::cross_product(t[1] - t[0], t[2] - t[0]);
  return {n, n * (t[0] - ExactPoint(0, 0, 0))};
}

std::vector<FacetPlane> facet_planes(const std::vector<ExactPoint>& m) {
  std::vector<FacetPlane> planes;
  for (const auto& t : facet_triangles(m)) planes.push_back(facet_plane(t));
  return planes;
}

// Whether m holds four affinely independent points.
bool solid(const std::vector<ExactPoint>& m) {
  std::size_t i1 = 0, i2 = 0, i3 = 0;
  for (i1 = 1; i1 < m.size() && m[i1] == m[0]; ++i1) {
  }
  if (i1 < m.size())
    for (i2 = i1 + 1; i2 < m.size() && CGAL::collinear(m[0], m[i1], m[i2]); ++i2) {
    }
  if (i1 < m.size() && i2 < m.size())
    for (i3 = i2 + 1; i3 < m.size() && CGAL::coplanar(m[0], m[i1], m[i2], m[i3]); ++i3) {
    }
  return i1 < m.size() && i2 < m.size() && i3 < m.size();
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
  if (!solid(m)) {
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

namespace {

// R p + t for every point, exact (Epeck's sums of products of doubles).
std::vector<ExactPoint> placed_exactly(const Points& pts, const Pose& pose) {
  const Mat3& r = pose.rotation;
  const Vec3& t = pose.translation;
  std::vector<ExactPoint> out;
  out.reserve(pts.size());
  for (const Vec3& p : pts) {
    ExactFT c[3];
    for (int i = 0; i < 3; ++i)
      c[i] = ExactFT(r(i, 0)) * ExactFT(p.x()) + ExactFT(r(i, 1)) * ExactFT(p.y()) +
             ExactFT(r(i, 2)) * ExactFT(p.z()) + ExactFT(t[i]);
    out.emplace_back(c[0], c[1], c[2]);
  }
  return out;
}

// sqrt(q) / 2^e rounded, times 2^e (as ExactDepth::depth).
double scaled_root(const mpq_class& squared, int exponent) {
  mpq_class scaled = squared;
  if (exponent >= 0)
    mpq_div_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<mp_bitcnt_t>(2 * exponent));
  else
    mpq_mul_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<mp_bitcnt_t>(-2 * exponent));
  return std::ldexp(sqrt_to_double(scaled), exponent);
}

}  // namespace

double ExactSignedDistance::value() const {
  const double magnitude = scaled_root(squared, exponent);
  return origin == OriginInM::inside ? -magnitude : magnitude;
}

bool ExactSignedDistance::within(double lower, double upper) const {
  // With sd* = s sqrt(q) (s the origin's side), each comparison of a bound
  // with sd* is one of signs or, on the same side, of squares.
  const bool inside = origin == OriginInM::inside;
  bool lower_ok = std::isinf(lower) && lower < 0.0;
  if (!lower_ok) {
    const mpq_class l(lower);
    lower_ok = inside ? (lower < 0.0 && l * l >= squared) : (lower <= 0.0 || l * l <= squared);
  }
  bool upper_ok = std::isinf(upper) && upper > 0.0;
  if (!upper_ok) {
    const mpq_class h(upper);
    upper_ok = inside ? (upper >= 0.0 || h * h <= squared) : (upper >= 0.0 && h * h >= squared);
  }
  return lower_ok && upper_ok;
}

ExactSignedDistance exact_signed_distance(const Points& a, const Pose& pose_a, const Points& b,
                                          const Pose& pose_b) {
  ScopedFpTrapsOff traps_off;
  const std::vector<ExactPoint> wa = placed_exactly(a, checked_pose(pose_a, "pose_a"));
  const std::vector<ExactPoint> wb = placed_exactly(b, checked_pose(pose_b, "pose_b"));
  std::vector<ExactPoint> m;
  m.reserve(wa.size() * wb.size());
  for (const ExactPoint& x : wa)
    for (const ExactPoint& y : wb) m.push_back(ExactPoint(CGAL::ORIGIN + (x - y)));
  ExactSignedDistance r;
  double magnitude = 0.0;
  for (const ExactPoint& x : m)
    magnitude = std::max({magnitude, std::abs(CGAL::to_double(x.x())),
                          std::abs(CGAL::to_double(x.y())), std::abs(CGAL::to_double(x.z()))});
  std::frexp(magnitude, &r.exponent);
  if (!solid(m)) {
    r.flat = true;
    return r;
  }
  const ExactPoint origin(0, 0, 0);
  bool outside = false, boundary = false, first = true;
  ExactFT least_offset = 0, least_distance = 0;
  for (const auto& t : facet_triangles(m)) {
    const auto [n, offset] = facet_plane(t);
    if (offset < 0) outside = true;
    if (offset == 0) boundary = true;
    const ExactFT d2 = offset * offset / n.squared_length();
    const ExactFT e2 = CGAL::squared_distance(origin, ExactKernel::Triangle_3(t[0], t[1], t[2]));
    if (first || d2 < least_offset) least_offset = d2;
    if (first || e2 < least_distance) least_distance = e2;
    first = false;
  }
  r.origin = outside ? OriginInM::outside : boundary ? OriginInM::boundary : OriginInM::inside;
  r.squared = r.origin == OriginInM::inside    ? to_mpq(least_offset)
              : r.origin == OriginInM::outside ? to_mpq(least_distance)
                                               : mpq_class(0);
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
