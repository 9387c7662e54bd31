// proxima test support: the exact oracle's definitions (see exact_oracle.h
// for the certificate and the candidates). Test-only code, compiled once.
// SPDX-License-Identifier: BSD-3-Clause

#include "support/exact_oracle.h"


// CGAL's Polytope_distance_d default-constructs a coordinate iterator from
// an uninitialized temporary (Access_coordinates_begin_3.h); GCC 12 warns
// about it in optimized sanitizer builds. Harmless (the dummy is never
// read) and not ours to fix.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)  // a GCC-only warning; clang would warn about the pragma
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <CGAL/Gmpzf.h>
#include <CGAL/Polytope_distance_d.h>
#include <CGAL/Polytope_distance_d_traits_3.h>
#include <CGAL/Simple_cartesian.h>
#pragma GCC diagnostic pop

#include <boost/multiprecision/eigen.hpp>
#include <boost/multiprecision/gmp.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <exception>

#include "proxima/geometry/closest_point.h"

namespace proxima::test {

std::optional<ExactDistance> certify(const std::vector<QPoint>& a, const std::vector<QPoint>& b,
                                            ConvexCombination coef_a, ConvexCombination coef_b,
                                            OracleMethod method, std::string* why) {
  auto combine = [why](const std::vector<QPoint>& pts, const ConvexCombination& coef,
                       const char* side) -> std::optional<QPoint> {
    QPoint p{0, 0, 0};
    mpq_class sum = 0;
    if (coef.empty()) {
      if (why) *why = std::string("no coefficients on ") + side;
      return std::nullopt;
    }
    for (const auto& [i, c] : coef) {
      if (i < 0 || static_cast<std::size_t>(i) >= pts.size() || sgn(c) < 0) {
        if (why) *why = std::string("bad coefficient on ") + side;
        return std::nullopt;
      }
      for (int k = 0; k < 3; ++k) p[static_cast<std::size_t>(k)] += c * pts[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
      sum += c;
    }
    if (sum != 1) {
      if (why) *why = std::string("coefficients do not sum to 1 on ") + side;
      return std::nullopt;
    }
    return p;
  };
  const std::optional<QPoint> pa = combine(a, coef_a, "A");
  const std::optional<QPoint> pb = combine(b, coef_b, "B");
  if (!pa || !pb) return std::nullopt;
  const QPoint w = difference(*pb, *pa);
  const mpq_class w2 = squared_norm(w);
  if (sgn(w2) != 0) {
    const mpq_class sa = dot(w, *pa);
    for (std::size_t i = 0; i < a.size(); ++i)
      if (dot(w, a[i]) > sa) {
        if (why) *why = "A point beyond the separating plane: index " + std::to_string(i);
        return std::nullopt;
      }
    const mpq_class sb = dot(w, *pb);
    for (std::size_t j = 0; j < b.size(); ++j)
      if (dot(w, b[j]) < sb) {
        if (why) *why = "B point beyond the separating plane: index " + std::to_string(j);
        return std::nullopt;
      }
  }
  ExactDistance r;
  r.distance_squared = w2;
  r.point_a = *pa;
  r.point_b = *pb;
  r.coef_a = std::move(coef_a);
  r.coef_b = std::move(coef_b);
  r.method = method;
  return r;
}

std::optional<ConvexCombination> convex_coefficients(const std::vector<QPoint>& pts,
                                                            const std::vector<int>& ids, const QPoint& target) {
  const int k = static_cast<int>(ids.size());
  if (k == 0 || k > 10) return std::nullopt;
  std::vector<unsigned> masks;
  for (unsigned m = 1; m < (1u << k); ++m) masks.push_back(m);
  std::stable_sort(masks.begin(), masks.end(),
                   [](unsigned x, unsigned y) { return std::popcount(x) < std::popcount(y); });
  for (const unsigned mask : masks) {
    std::vector<int> sub;
    for (int i = 0; i < k; ++i)
      if (mask & (1u << i)) sub.push_back(ids[static_cast<std::size_t>(i)]);
    const int n = static_cast<int>(sub.size());
    if (n > 4) break;  // more than 4 points in 3D are affinely dependent
    // Augmented matrix, 4 rows (x, y, z, 1), n unknowns.
    std::vector<std::vector<mpq_class>> m(4, std::vector<mpq_class>(static_cast<std::size_t>(n + 1)));
    for (int c = 0; c < n; ++c) {
      const QPoint& p = pts[static_cast<std::size_t>(sub[static_cast<std::size_t>(c)])];
      for (int r = 0; r < 3; ++r) m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] = p[static_cast<std::size_t>(r)];
      m[3][static_cast<std::size_t>(c)] = 1;
    }
    for (int r = 0; r < 3; ++r) m[static_cast<std::size_t>(r)][static_cast<std::size_t>(n)] = target[static_cast<std::size_t>(r)];
    m[3][static_cast<std::size_t>(n)] = 1;
    // Row reduction; full column rank required (affine independence).
    bool independent = true;
    int row = 0;
    for (int c = 0; c < n; ++c, ++row) {
      int piv = -1;
      for (int r = row; r < 4; ++r)
        if (sgn(m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]) != 0) {
          piv = r;
          break;
        }
      if (piv < 0) {
        independent = false;
        break;
      }
      std::swap(m[static_cast<std::size_t>(row)], m[static_cast<std::size_t>(piv)]);
      for (int r = 0; r < 4; ++r) {
        if (r == row || sgn(m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]) == 0) continue;
        const mpq_class f = m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] /
                            m[static_cast<std::size_t>(row)][static_cast<std::size_t>(c)];
        for (int cc = c; cc <= n; ++cc)
          m[static_cast<std::size_t>(r)][static_cast<std::size_t>(cc)] -= f * m[static_cast<std::size_t>(row)][static_cast<std::size_t>(cc)];
      }
    }
    if (!independent) continue;
    bool consistent = true;  // rows below the pivots must read 0 = 0
    for (int r = n; r < 4; ++r)
      if (sgn(m[static_cast<std::size_t>(r)][static_cast<std::size_t>(n)]) != 0) consistent = false;
    if (!consistent) continue;
    ConvexCombination coef;
    bool nonnegative = true;
    for (int c = 0; c < n; ++c) {
      const mpq_class l = m[static_cast<std::size_t>(c)][static_cast<std::size_t>(n)] /
                          m[static_cast<std::size_t>(c)][static_cast<std::size_t>(c)];
      if (sgn(l) < 0) nonnegative = false;
      if (sgn(l) != 0) coef.emplace_back(sub[static_cast<std::size_t>(c)], l);
    }
    if (nonnegative && !coef.empty()) return coef;
  }
  return std::nullopt;
}

namespace {

// CGAL::Gmpzf (mantissa * 2^exp) to an exact rational.
inline mpq_class to_rational(const CGAL::Gmpzf& z) {
  mpq_class q;
  mpq_set_z(q.get_mpq_t(), z.man());
  const long e = z.exp();
  if (e >= 0)
    mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  else
    mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  return q;
}

}  // namespace

// (The pragmas: see the CGAL includes above; the warning is issued where
// the solver is instantiated, here.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)  // a GCC-only warning; clang would warn about the pragma
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
std::optional<ExactDistance> cgal_distance(const Points& a, const Points& b, const std::vector<QPoint>& qa,
                                                  const std::vector<QPoint>& qb, std::string* why) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Polytope_distance_d_traits_3<Kernel, CGAL::Gmpzf, CGAL::Gmpzf>;
  using PolytopeDistance = CGAL::Polytope_distance_d<Traits>;
  const ScopedFpTrapsOff traps_off;
  try {
    std::vector<Kernel::Point_3> pa, pb;
    for (const Vec3& p : a) pa.emplace_back(p.x(), p.y(), p.z());
    for (const Vec3& p : b) pb.emplace_back(p.x(), p.y(), p.z());
    const PolytopeDistance pd(pa.begin(), pa.end(), pb.begin(), pb.end());
    auto realizing = [](auto first) {
      // Homogeneous coordinates: x, y, z, then the common denominator.
      const mpq_class den = to_rational(first[3]);
      return QPoint{mpq_class(to_rational(first[0]) / den), mpq_class(to_rational(first[1]) / den),
                    mpq_class(to_rational(first[2]) / den)};
    };
    const QPoint ra = realizing(pd.realizing_point_p_coordinates_begin());
    const QPoint rb = realizing(pd.realizing_point_q_coordinates_begin());
    const std::vector<int> ids_a(pd.support_points_p_indices_begin(), pd.support_points_p_indices_end());
    const std::vector<int> ids_b(pd.support_points_q_indices_begin(), pd.support_points_q_indices_end());
    std::optional<ConvexCombination> ca = convex_coefficients(qa, ids_a, ra);
    std::optional<ConvexCombination> cb = convex_coefficients(qb, ids_b, rb);
    if (!ca || !cb) {
      if (why) *why = "CGAL realizing point not in the hull of its support points";
      return std::nullopt;
    }
    std::optional<ExactDistance> r = certify(qa, qb, std::move(*ca), std::move(*cb), OracleMethod::cgal, why);
    if (r && r->distance_squared != to_rational(pd.squared_distance_numerator()) /
                                         to_rational(pd.squared_distance_denominator())) {
      if (why) *why = "CGAL squared distance differs from its realizing points";
      return std::nullopt;
    }
    return r;
  } catch (const std::exception& e) {
    if (why) *why = std::string("CGAL threw: ") + e.what();
    return std::nullopt;
  }
}
#pragma GCC diagnostic pop

namespace {


// The exact scalar for the kernels: Boost's GMP rational without expression
// templates (a templated kernel may hold intermediate results in `auto`,
// which gmpxx's expression templates would leave dangling).
using KernelRational = boost::multiprecision::number<boost::multiprecision::gmp_rational,
                                                     boost::multiprecision::et_off>;

inline KernelRational to_kernel(const mpq_class& q) { return KernelRational(q.get_mpq_t()); }
inline mpq_class from_kernel(const KernelRational& k) { return mpq_class(k.backend().data()); }


// Sign of det[a - d, b - d, c - d] (the side of plane abc that d is on, up
// to orientation). In double first: with differences rounded once and the
// 3x3 determinant summed from six products, the computed value is within
// about 7 u of the permanent (the same sum of absolute products; Shewchuk's
// orient3d error bound); 16 u leaves room for the rounding of the permanent
// itself. Undecided (or possibly underflowed) cases go to exact rationals.
inline int orientation(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const QPoint& qa,
                       const QPoint& qb, const QPoint& qc, const QPoint& qd) {
  const Vec3 ad = a - d, bd = b - d, cd = c - d;
  const double m1 = bd.y() * cd.z() - bd.z() * cd.y();
  const double m2 = bd.z() * cd.x() - bd.x() * cd.z();
  const double m3 = bd.x() * cd.y() - bd.y() * cd.x();
  const double det = ad.x() * m1 + ad.y() * m2 + ad.z() * m3;
  const double permanent = std::abs(ad.x()) * (std::abs(bd.y() * cd.z()) + std::abs(bd.z() * cd.y())) +
                           std::abs(ad.y()) * (std::abs(bd.z() * cd.x()) + std::abs(bd.x() * cd.z())) +
                           std::abs(ad.z()) * (std::abs(bd.x() * cd.y()) + std::abs(bd.y() * cd.x()));
  const double bound = 16 * kUnitRoundoff * permanent;
  if (permanent > 1e-250 && std::abs(det) > bound) return det > 0 ? 1 : -1;
  const QPoint e1 = difference(qa, qd), e2 = difference(qb, qd), e3 = difference(qc, qd);
  const mpq_class x = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) + e1[1] * (e2[2] * e3[0] - e2[0] * e3[2]) +
                      e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
  return sgn(x);
}

inline bool collinear(const QPoint& a, const QPoint& b, const QPoint& c) {
  const QPoint u = difference(b, a), v = difference(c, a);
  return u[1] * v[2] == u[2] * v[1] && u[2] * v[0] == u[0] * v[2] && u[0] * v[1] == u[1] * v[0];
}

}  // namespace

std::vector<std::array<int, 3>> supporting_features(const Points& pts, const std::vector<QPoint>& q) {
  std::vector<int> ids;  // distinct points
  for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
    bool seen = false;
    for (const int j : ids) seen = seen || pts[static_cast<std::size_t>(j)] == pts[static_cast<std::size_t>(i)];
    if (!seen) ids.push_back(i);
  }
  const auto P = [&](int i) -> const Vec3& { return pts[static_cast<std::size_t>(i)]; };
  const auto Q = [&](int i) -> const QPoint& { return q[static_cast<std::size_t>(i)]; };
  std::vector<std::array<int, 3>> out;
  const int n = static_cast<int>(ids.size());
  if (n == 1) return {{ids[0], -1, -1}};
  for (int x = 0; x < n; ++x)
    for (int y = x + 1; y < n; ++y)
      for (int z = y + 1; z < n; ++z) {
        const int i = ids[static_cast<std::size_t>(x)], j = ids[static_cast<std::size_t>(y)],
                  k = ids[static_cast<std::size_t>(z)];
        if (collinear(Q(i), Q(j), Q(k))) continue;
        bool pos = false, neg = false;
        for (const int l : ids) {
          const int o = orientation(P(i), P(j), P(k), P(l), Q(i), Q(j), Q(k), Q(l));
          pos = pos || o > 0;
          neg = neg || o < 0;
          if (pos && neg) break;
        }
        if (!(pos && neg)) out.push_back({i, j, k});
      }
  if (out.empty())  // collinear: every pair (the extreme pair among them)
    for (int x = 0; x < n; ++x)
      for (int y = x + 1; y < n; ++y) out.push_back({ids[static_cast<std::size_t>(x)], ids[static_cast<std::size_t>(y)], -1});
  return out;
}

std::optional<ConvexCombination> containment(const std::vector<QPoint>& q,
                                                    const std::vector<std::array<int, 3>>& features,
                                                    const QPoint& x) {
  if (features.empty() || features[0][2] < 0) return std::nullopt;
  const int apex = features[0][0];
  for (const auto& t : features) {
    if (t[0] == apex || t[1] == apex || t[2] == apex) continue;
    std::optional<ConvexCombination> c = convex_coefficients(q, {apex, t[0], t[1], t[2]}, x);
    if (c) return c;
  }
  return std::nullopt;
}

std::optional<ExactDistance> brute_force_distance(const Points& a, const Points& b,
                                                         const std::vector<QPoint>& qa,
                                                         const std::vector<QPoint>& qb, std::string* why) {
  auto distinct = [](const Points& p) {
    Points s = p;
    std::sort(s.begin(), s.end(), [](const Vec3& u, const Vec3& v) {
      return std::lexicographical_compare(u.data(), u.data() + 3, v.data(), v.data() + 3);
    });
    return static_cast<int>(std::unique(s.begin(), s.end()) - s.begin());
  };
  if (distinct(a) > kBruteForceMaxPoints || distinct(b) > kBruteForceMaxPoints) {
    if (why) *why = "too many points for brute force";
    return std::nullopt;
  }
  const auto sa = supporting_features(a, qa);
  const auto sb = supporting_features(b, qb);
  auto load = [](const std::vector<QPoint>& q, const std::array<int, 3>& s, Vec3T<KernelRational>* out) {
    int n = 0;
    for (int k = 0; k < 3 && s[static_cast<std::size_t>(k)] >= 0; ++k, ++n) {
      const QPoint& p = q[static_cast<std::size_t>(s[static_cast<std::size_t>(k)])];
      out[n] = Vec3T<KernelRational>(to_kernel(p[0]), to_kernel(p[1]), to_kernel(p[2]));
    }
    return n;
  };
  std::optional<ClosestPoints<KernelRational>> best;
  std::array<int, 3> best_a{}, best_b{};
  Vec3T<KernelRational> fa[3], fb[3];
  for (const auto& s : sa) {
    const int na = load(qa, s, fa);
    for (const auto& t : sb) {
      const int nb = load(qb, t, fb);
      ClosestPoints<KernelRational> c = closest_points<KernelRational>(fa, na, fb, nb);
      if (!best || c.distance_squared < best->distance_squared) {
        best = std::move(c);
        best_a = s;
        best_b = t;
      }
    }
  }
  auto combination = [](const std::array<int, 3>& s, const std::array<KernelRational, 3>& coef) {
    ConvexCombination c;
    for (int k = 0; k < 3 && s[static_cast<std::size_t>(k)] >= 0; ++k)
      if (coef[static_cast<std::size_t>(k)] != 0)
        c.emplace_back(s[static_cast<std::size_t>(k)], from_kernel(coef[static_cast<std::size_t>(k)]));
    return c;
  };
  std::string reason;
  std::optional<ExactDistance> r = certify(qa, qb, combination(best_a, best->coef_a),
                                           combination(best_b, best->coef_b), OracleMethod::brute_force, &reason);
  if (r) return r;
  // Overlapping without boundary contact: a vertex of the inner hull lies in
  // the outer one. Any input point that is a hull vertex will do; the first
  // point of a feature is one.
  for (int side = 0; side < 2; ++side) {
    const int probe = (side == 0 ? sa : sb)[0][0];
    const QPoint& x = (side == 0 ? qa : qb)[static_cast<std::size_t>(probe)];
    std::optional<ConvexCombination> in = containment(side == 0 ? qb : qa, side == 0 ? sb : sa, x);
    if (!in) continue;
    const ConvexCombination self{{probe, mpq_class(1)}};
    r = side == 0 ? certify(qa, qb, self, *in, OracleMethod::brute_force, &reason)
                  : certify(qa, qb, *in, self, OracleMethod::brute_force, &reason);
    if (r) return r;
  }
  if (why) *why = "brute force not certified: " + reason;
  return std::nullopt;
}

std::optional<ExactDistance> ExactOracle::distance(const Points& a, const Points& b) {
  ++stats_.queries;
  const std::vector<QPoint> qa = to_rational(a), qb = to_rational(b);
  std::string why;
  std::optional<ExactDistance> r = cgal_distance(a, b, qa, qb, &why);
  if (r) {
    ++stats_.cgal_certified;
    return r;
  }
  ++stats_.cgal_rejected;
  last_error_ = "cgal: " + why;
  r = brute_force_distance(a, b, qa, qb, &why);
  if (r) {
    ++stats_.brute_force_certified;
    return r;
  }
  ++stats_.failed;
  last_error_ += "; " + why;
  return std::nullopt;
}

std::optional<Points> tighten_to_gap(ExactOracle& oracle, const Points& a, const Points& b, double gap) {
  const std::optional<ExactDistance> r = oracle.distance(a, b);
  if (!r || r->is_zero()) return std::nullopt;
  const double d = r->distance();
  const Vec3 n = (to_double(r->point_b) - to_double(r->point_a)).normalized();
  return translated(b, -(d - gap) * n);
}

}  // namespace proxima::test
