// proxima benchmarks: the exact reference of the robustness experiments.
// SPDX-License-Identifier: BSD-3-Clause
//
// The method and the certificate are described at the top of
// exact_reference.h. Implementation notes:
// - Boost's cpp_rational (header-only, no GMP in the product binary) with
//   expression templates off: the templated kernels may keep intermediate
//   results in `auto`, which expression templates would leave dangling.
// - The exact kernels cost about a millisecond per call on cpp_rational at
//   these magnitudes, so they run only down the double-precision ranking of
//   the pairs, until one certifies (usually the first). The ranking cannot
//   make the answer wrong: only a certified answer is accepted.
#include "paper/exact_reference.h"

#include <algorithm>
#include <array>
#include <boost/multiprecision/cpp_int.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "proxima/geometry/closest_point.h"

namespace proxima::bench {
namespace {

using Rational = boost::multiprecision::number<boost::multiprecision::cpp_rational_backend,
                                               boost::multiprecision::et_off>;
using RVec = Vec3T<Rational>;

// The accuracy standard of DESIGN.md: contact band and point tolerance
// 64 u R, relative distance tolerance 1e-12.
constexpr double kStandardUlps = 64.0;
constexpr double kStandardRelative = 1e-12;

Rational dot(const RVec& x, const RVec& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; }
RVec sub(const RVec& x, const RVec& y) { return RVec(x[0] - y[0], x[1] - y[1], x[2] - y[2]); }
RVec cross(const RVec& x, const RVec& y) {
  return RVec(x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]);
}
RVec exact(const Vec3& v) { return RVec(Rational(v.x()), Rational(v.y()), Rational(v.z())); }
Vec3 rounded(const RVec& v) {
  return {static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2])};
}

// R x + t, exactly, from the doubles of the pose and of the vertex.
RVec place(const Pose& pose, const Vec3& x) {
  RVec out;
  for (int i = 0; i < 3; ++i) {
    Rational s(pose.translation[i]);
    for (int j = 0; j < 3; ++j) s += Rational(pose.rotation(i, j)) * Rational(x[j]);
    out[i] = s;
  }
  return out;
}

// A piece of one hull's boundary: 1 (vertex), 2 (edge) or 3 (triangle)
// vertex ids.
struct Piece {
  std::array<int, 3> v{-1, -1, -1};
  int n = 0;
};

struct Body {
  const ConvexPolytope* polytope = nullptr;
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::array<std::int32_t, 2>> edges;
  // Per solved case:
  std::vector<RVec> exact;       // world vertices, exact
  std::vector<Vec3> approx;      // the same rounded (ranking only)
  std::vector<RVec> tri_normal;  // (v1 - v0) x (v2 - v0), outward

  explicit Body(const ConvexPolytope& p)
      : polytope(&p), triangles(p.triangles()), edges(p.edges()) {
    if (p.dimension() != 3)
      throw std::invalid_argument("ExactReference: the experiments use solid bodies");
  }

  void place_all(const Pose& pose) {
    exact.clear();
    approx.clear();
    for (const Vec3& v : polytope->vertices()) {
      exact.push_back(place(pose, v));
      approx.push_back(rounded(exact.back()));
    }
    tri_normal.clear();
    for (const auto& t : triangles) {
      const RVec& v0 = exact[static_cast<std::size_t>(t[0])];
      tri_normal.push_back(cross(sub(exact[static_cast<std::size_t>(t[1])], v0),
                                 sub(exact[static_cast<std::size_t>(t[2])], v0)));
    }
  }

  // Pieces for the brute force: vertices, hull edges, face triangles.
  std::vector<Piece> pieces(int dimension) const {
    std::vector<Piece> out;
    if (dimension == 0) {
      for (int i = 0; i < static_cast<int>(exact.size()); ++i) out.push_back({{i, -1, -1}, 1});
    } else if (dimension == 1) {
      for (const auto& e : edges) out.push_back({{e[0], e[1], -1}, 2});
    } else {
      for (const auto& t : triangles) out.push_back({{t[0], t[1], t[2]}, 3});
    }
    return out;
  }

  int load(const Piece& p, RVec* out) const {
    for (int k = 0; k < p.n; ++k)
      out[k] = exact[static_cast<std::size_t>(p.v[static_cast<std::size_t>(k)])];
    return p.n;
  }

  // Whether point x lies within distance sqrt(tol2) of the hull (see the
  // header for why the visible triangles suffice).
  bool within(const RVec& x, const Rational& tol2) const {
    std::vector<std::size_t> visible;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Rational s =
          dot(tri_normal[t], sub(x, exact[static_cast<std::size_t>(triangles[t][0])]));
      if (s <= 0) continue;
      // Outside this plane by more than tol: farther than tol from the hull.
      if (s * s > tol2 * dot(tri_normal[t], tri_normal[t])) return false;
      visible.push_back(t);
    }
    if (visible.empty()) return true;
    for (const std::size_t t : visible) {
      RVec tri[3];
      for (int k = 0; k < 3; ++k)
        tri[k] = exact[static_cast<std::size_t>(triangles[t][static_cast<std::size_t>(k)])];
      if (closest_points<Rational>(&x, 1, tri, 3).distance_squared <= tol2) return true;
    }
    return false;
  }
};

// A convex combination of a piece's vertices from kernel coefficients:
// checks l >= 0, sum l = 1 and returns sum l_i v_i (nullopt-like: false).
bool combine(const Body& body, const Piece& piece, const std::array<Rational, 3>& coef,
             RVec& point) {
  Rational sum = 0;
  point = RVec(Rational(0), Rational(0), Rational(0));
  for (int k = 0; k < piece.n; ++k) {
    const Rational& l = coef[static_cast<std::size_t>(k)];
    if (l < 0) return false;
    sum += l;
    const RVec& v = body.exact[static_cast<std::size_t>(piece.v[static_cast<std::size_t>(k)])];
    for (int i = 0; i < 3; ++i) point[i] += l * v[i];
  }
  return sum == 1;
}

}  // namespace

struct ExactReference::Impl {
  Body a;
  Body b;
  ExactCase current;
  Rational d2;   // exact d*^2 of the current case
  Rational tol;  // 64 u R, exact
  Rational tol2;

  Impl(const ConvexPolytope& pa, const ConvexPolytope& pb) : a(pa), b(pb) {}

  // The certificate of the header; sets d2 when it holds.
  bool certify(const RVec& pa, const RVec& pb) {
    const RVec w = sub(pb, pa);
    const Rational wa = dot(w, pa);
    const Rational wb = dot(w, pb);
    for (const RVec& v : a.exact) {
      if (dot(w, v) > wa) return false;
    }
    for (const RVec& v : b.exact) {
      if (dot(w, v) < wb) return false;
    }
    d2 = dot(w, w);
    return true;
  }

  ExactCase solve(const Pose& pose_a, const Pose& pose_b) {
    a.place_all(pose_a);
    b.place_all(pose_b);
    double r = 0.0;
    for (const Body* body : {&a, &b}) {
      for (const RVec& v : body->exact) {
        for (int i = 0; i < 3; ++i) r = std::max(r, std::abs(static_cast<double>(v[i])));
      }
    }
    current = ExactCase{};
    current.magnitude = r;
    current.tolerance = kStandardUlps * kUnitRoundoff * r;  // a power of two times r: exact
    tol = Rational(current.tolerance);
    tol2 = tol * tol;

    // Every vertex-triangle, triangle-vertex and edge-edge pair, ranked by
    // its distance computed with the same kernels in double. The exact work
    // then goes down that ranking and stops at the first pair whose exact
    // answer certifies (any pair that realizes d* does). Ranking in double
    // only decides the order: near ties (nearly parallel faces) just cost a
    // few more exact evaluations.
    struct Candidate {
      double distance_squared;
      Piece pa, pb;
    };
    std::vector<Candidate> candidates;
    auto add_pairs = [&](int dim_a, int dim_b) {
      for (const Piece& x : a.pieces(dim_a)) {
        Vec3 fa[3];
        for (int k = 0; k < x.n; ++k)
          fa[k] = a.approx[static_cast<std::size_t>(x.v[static_cast<std::size_t>(k)])];
        for (const Piece& y : b.pieces(dim_b)) {
          Vec3 fb[3];
          for (int k = 0; k < y.n; ++k)
            fb[k] = b.approx[static_cast<std::size_t>(y.v[static_cast<std::size_t>(k)])];
          candidates.push_back({closest_points<double>(fa, x.n, fb, y.n).distance_squared, x, y});
        }
      }
    };
    add_pairs(0, 2);  // vertex of A, triangle of B
    add_pairs(2, 0);  // triangle of A, vertex of B
    add_pairs(1, 1);  // edge-edge
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& x, const Candidate& y) {
                       return x.distance_squared < y.distance_squared;
                     });

    bool ok = false;
    for (const Candidate& c : candidates) {
      RVec fa[3], fb[3];
      const int na = a.load(c.pa, fa);
      const int nb = b.load(c.pb, fb);
      const ClosestPoints<Rational> cp = closest_points<Rational>(fa, na, fb, nb);
      RVec pa, pb;
      if (combine(a, c.pa, cp.coef_a, pa) && combine(b, c.pb, cp.coef_b, pb) && certify(pa, pb)) {
        ok = true;
        break;
      }
    }
    current.certified = ok;
    current.distance = std::sqrt(static_cast<double>(d2));
    current.separated = d2 > tol2;
    return current;
  }

  Verdict judge(const SystemAnswer& answer) const {
    Verdict v;
    v.finite =
        std::isfinite(answer.distance) && answer.point_a.allFinite() && answer.point_b.allFinite();
    v.status_ok = answer.answered && answer.separated == current.separated;
    if (!v.finite) {
      v.relative_error = std::numeric_limits<double>::infinity();
      return v;
    }
    const double d = answer.distance;
    v.relative_error = current.distance > 0.0 ? std::abs(d - current.distance) / current.distance
                                              : std::abs(d - current.distance);
    const Rational rd(d);
    // d* in [(d - tol) / (1 + rel), (d + tol) / (1 - rel)], squared exactly.
    const Rational lo = (rd - tol) / (Rational(1) + Rational(kStandardRelative));
    const Rational hi = (rd + tol) / (Rational(1) - Rational(kStandardRelative));
    v.distance_ok = (lo <= 0 || lo * lo <= d2) && hi >= 0 && d2 <= hi * hi;

    const RVec xa = exact(answer.point_a);
    const RVec xb = exact(answer.point_b);
    const RVec w = sub(xb, xa);
    const Rational gap2 = dot(w, w);
    const Rational below = rd - tol;
    const Rational above = rd + tol;
    const bool gap_ok =
        (below <= 0 || below * below <= gap2) && above >= 0 && gap2 <= above * above;
    v.points_ok = gap_ok && a.within(xa, tol2) && b.within(xb, tol2);
    return v;
  }
};

ExactReference::ExactReference(const ConvexPolytope& a, const ConvexPolytope& b)
    : impl_(std::make_unique<Impl>(a, b)) {}

ExactReference::~ExactReference() = default;

ExactCase ExactReference::solve(const Pose& pose_a, const Pose& pose_b) {
  return impl_->solve(pose_a, pose_b);
}

Verdict ExactReference::judge(const SystemAnswer& answer) const { return impl_->judge(answer); }

}  // namespace proxima::bench
