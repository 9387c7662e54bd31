// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer (internal): what the closest-point kernels share: the result type, the
// degeneracy tolerances, and the small helpers (products, active sets, the
// edge foot, guarded division). See proxima/geometry/closest_point.h for the
// conventions of all kernels.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "proxima/core/types.h"

namespace proxima {

template <class S>
using Vec3T = Eigen::Matrix<S, 3, 1>;

// Degeneracy thresholds. Exact arithmetic uses zeros. The double hot path sets
// them relative to the bodies' scale (see kernel_tolerance below).
template <class S>
struct KernelTolerance {
  // A segment with |M|^2 <= this is a point.
  S min_length_squared = S(0);
  // (a*c - b*b) <= this * a * c means dependent edges (triangle -> edge) or
  // parallel segments.
  S min_sin_squared = S(0);
};

template <class S>
struct ClosestPoints {
  S distance_squared = S(0);
  // eq. 20: sum coef_a[i]*A[i], sum coef_b[j]*B[j].
  Vec3T<S> point_a, point_b;
  // Barycentric over the input vertices, sum to 1, zero where inactive.
  std::array<S, 3> coef_a{}, coef_b{};
  // Bit i set iff vertex i has a non-zero coefficient: the minimal feature
  // realizing the distance.
  std::uint8_t active_a = 0, active_b = 0;
};

// A feature shorter than this many units of u*R (R: the largest coordinate
// magnitude) is a point. Its direction is then made of rounding only (a vertex
// transformed by a pose carries an error of a few u*R), and collapsing it
// moves the answer by at most its length, 4 u R, well inside the 64 u R of the
// accuracy standard. Pinned by ClosestPointExact.ZeroAndTinySegments.
inline constexpr double kShortFeatureFactor = 4.0;

// Two edge directions whose angle has a sine below this many units of u are
// parallel (segments) or dependent (a triangle, reduced to its longest edge).
// Below it the computed cross product is mostly rounding (its relative error
// is about 6u / sin). A triangle reduced at that threshold is dropped by at
// most its height, sin * (longest edge) <= 8u * 2*sqrt(3)*R < 28 u R, inside
// the 64 u R standard. Pinned by ClosestPointExact.SliverAndNeedleTriangles
// and ClosestPointExact.NearlyParallelSegments (accuracy next to the
// threshold) and by ClosestPointTolerance.ReducesDegenerateFeatures.
inline constexpr double kParallelSinFactor = 8.0;

// The thresholds for S = double when every input coordinate is at most
// `scale` in magnitude (the R of DESIGN.md's accuracy standard).
inline KernelTolerance<double> kernel_tolerance(double scale) {
  const double min_length = kShortFeatureFactor * kUnitRoundoff * scale;
  const double min_sin = kParallelSinFactor * kUnitRoundoff;
  return {min_length * min_length, min_sin * min_sin};
}

namespace detail {

// Dot and cross products and squared norms written out on the components.
// Eigen evaluates them on 3-vectors of double with 2-wide SSE packets and
// shuffles, which made the point-triangle kernel twice as slow as scalar
// code (40 ns against 18 ns per call in closest_point_bench's setting).
// They take any 3-vector expression; .eval() is a reference for a plain
// vector and evaluates an expression once.
template <class D1, class D2>
typename D1::Scalar dot(const Eigen::MatrixBase<D1>& x, const Eigen::MatrixBase<D2>& y) {
  const auto& u = x.eval();
  const auto& v = y.eval();
  return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

template <class D>
typename D::Scalar norm2(const Eigen::MatrixBase<D>& x) {
  const auto& u = x.eval();
  return u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
}

template <class D1, class D2>
Vec3T<typename D1::Scalar> cross(const Eigen::MatrixBase<D1>& x, const Eigen::MatrixBase<D2>& y) {
  const auto& u = x.eval();
  const auto& v = y.eval();
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

template <class S>
std::uint8_t nonzero_bits(const std::array<S, 3>& coef) {
  return static_cast<std::uint8_t>((coef[0] != S(0) ? 1u : 0u) | (coef[1] != S(0) ? 2u : 0u) |
                                   (coef[2] != S(0) ? 4u : 0u));
}

// Sets the active sets from the coefficients and the distance from the points.
template <class S>
ClosestPoints<S>& finish(ClosestPoints<S>& r) {
  r.active_a = nonzero_bits(r.coef_a);
  r.active_b = nonzero_bits(r.coef_b);
  r.distance_squared = detail::norm2(r.point_b - r.point_a);
  return r;
}

// The same answer seen from the other side.
template <class S>
ClosestPoints<S> swapped(ClosestPoints<S> r) {
  std::swap(r.point_a, r.point_b);
  std::swap(r.coef_a, r.coef_b);
  std::swap(r.active_a, r.active_b);
  return r;
}

// Candidate selection of the composite kernels: a smaller distance wins; on a
// tie, the smaller feature pair, so that the answer stays minimal.
template <class S>
bool improves(const ClosestPoints<S>& candidate, const ClosestPoints<S>& best) {
  if (candidate.distance_squared != best.distance_squared)
    return candidate.distance_squared < best.distance_squared;
  return std::popcount(static_cast<unsigned>(candidate.active_a | candidate.active_b << 3)) <
         std::popcount(static_cast<unsigned>(best.active_a | best.active_b << 3));
}

// Closest point of the segment s0 + lambda*M, lambda in [0, 1], to p.
// |s0 + lambda*M - p|^2 is a parabola in lambda with minimum at
// lambda* = M.(p - s0) / M.M; clamping lambda* to [0, 1] is the constrained
// minimum (one variable, convex). The comparisons come before the division,
// so the quotient is in (0, 1) and the ends are exact. A segment with
// M.M <= min_length_squared is its first vertex.
template <class S>
struct EdgeFoot {
  S lambda;        // weight of s1; the weight of s0 is 1 - lambda
  Vec3T<S> point;  // s0 + lambda * M
};

template <class S>
EdgeFoot<S> edge_foot(const Vec3T<S>& p, const Vec3T<S>& s0, const Vec3T<S>& s1,
                      const S& min_length_squared) {
  const Vec3T<S> m = s1 - s0;
  const S a = detail::norm2(m);
  if (a <= min_length_squared) return {S(0), s0};
  const S numer = detail::dot(m, p - s0);
  if (numer <= S(0)) return {S(0), s0};
  if (numer >= a) return {S(1), s1};
  const S lambda = numer / a;
  return {lambda, Vec3T<S>(s0 + lambda * m)};
}

// Writes an edge foot on vertices (i, j) of a feature into coefficients.
template <class S>
void put_edge(std::array<S, 3>& coef, int i, int j, const S& lambda) {
  coef = {S(0), S(0), S(0)};
  coef[static_cast<std::size_t>(i)] = S(1) - lambda;
  coef[static_cast<std::size_t>(j)] = lambda;
}

// Whether 1 / x is a finite, correctly scaled number: x positive, and for
// floating point a normal number below the overflow threshold.
template <class S>
bool usable_divisor(const S& x) {
  if constexpr (std::is_floating_point_v<S>) {
    return x >= std::numeric_limits<S>::min() && x <= std::numeric_limits<S>::max();
  } else {
    return x > S(0);
  }
}

// The interior solution of a 2x2 normal system by substitution: t = tn / det
// (Cramer) and s = (rhs - b t) / a (the first normal equation a s + b t = rhs
// solved for s given t). One division, of a*det, gives both reciprocals. That
// product is a length^6; for double extents outside about [1e-50, 1e50] it
// leaves the normal range and two divisions are used instead (same values).
// Requires det > 0; returns false only if a underflowed to 0 (double).
template <class S>
bool substitute(const S& a, const S& det, const S& tn, const S& rhs, const S& b, S& s, S& t) {
  const S a_det = a * det;
  if (usable_divisor(a_det)) {
    const S inv = S(1) / a_det;
    t = tn * (a * inv);
    s = (rhs - b * t) * (det * inv);
    return true;
  }
  if (!(a > S(0))) return false;
  t = tn / det;
  s = (rhs - b * t) / a;
  return true;
}

}  // namespace detail

}  // namespace proxima
