// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 2: closed-form closest points between two simplices of at most three
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

#include <Eigen/Geometry>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "proxima/types.h"

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

// A triangle prepared once for one or many point queries: edges from t0,
// their normal n = E0 x E1 and det = |n|^2 = a*c - b^2 (Lagrange's identity).
// It refers to the caller's vertices, which must outlive it.
template <class S>
struct TriangleFrame {
  const Vec3T<S>& t0;
  const Vec3T<S>& t1;
  const Vec3T<S>& t2;
  Vec3T<S> e0, e1, n;  // E0 = t1 - t0, E1 = t2 - t0, n = E0 x E1
  S a, c, det;         // a = E0.E0, c = E1.E1, det = n.n
  bool degenerate;     // det <= min_sin_squared * a * c: treated as its longest edge

  TriangleFrame(const Vec3T<S>& v0, const Vec3T<S>& v1, const Vec3T<S>& v2,
                const KernelTolerance<S>& tol)
      : t0(v0),
        t1(v1),
        t2(v2),
        e0(v1 - v0),
        e1(v2 - v0),
        n(detail::cross(e0, e1)),
        a(detail::norm2(e0)),
        c(detail::norm2(e1)),
        det(detail::norm2(n)),
        degenerate(det <= tol.min_sin_squared * a * c) {}
};

// Closest point of a triangle to p: barycentric weights (w0, w1, w2) and the point.
template <class S>
struct TriangleFoot {
  std::array<S, 3> w;
  Vec3T<S> point;
};

template <class S>
TriangleFoot<S> triangle_edge_foot(const TriangleFrame<S>& f, const Vec3T<S>& p, int i, int j,
                                   const S& min_length_squared) {
  const Vec3T<S>* v[3] = {&f.t0, &f.t1, &f.t2};
  const EdgeFoot<S> e = edge_foot(p, *v[i], *v[j], min_length_squared);
  TriangleFoot<S> out{{}, e.point};
  put_edge(out.w, i, j, e.lambda);
  return out;
}

// The foot on edge (i, j), and, if it clamps to one of the edge's ends, the
// foot on the other edge through that vertex, whichever is closer. In exact
// arithmetic the region analysis already chose the edge holding the minimum
// and Q is strictly convex, so a clamped end is the minimum and the second
// foot returns that same vertex: nothing changes. In floating point a region
// decided by rounding (a sliver, a point close to an edge line) may have
// picked the wrong edge through a vertex, and the second foot repairs it. A
// clamped foot does not divide, so this keeps one division per answer.
template <class S>
TriangleFoot<S> triangle_edge_or_corner(const TriangleFrame<S>& f, const Vec3T<S>& p, int i, int j,
                                        const S& min_length_squared) {
  TriangleFoot<S> foot = triangle_edge_foot(f, p, i, j, min_length_squared);
  const int corner = foot.w[static_cast<std::size_t>(i)] == S(1)   ? i
                     : foot.w[static_cast<std::size_t>(j)] == S(1) ? j
                                                                   : -1;
  if (corner < 0) return foot;
  TriangleFoot<S> other = triangle_edge_foot(f, p, corner, 3 - i - j, min_length_squared);
  return detail::norm2(other.point - p) < detail::norm2(foot.point - p) ? other : foot;
}

// A triangle with dependent edges lies within its height of its longest edge,
// and is exactly that edge when det == 0; its closest point is taken there.
template <class S>
TriangleFoot<S> longest_edge_foot(const TriangleFrame<S>& f, const Vec3T<S>& p,
                                  const S& min_length_squared) {
  const S l12 = detail::norm2(f.t2 - f.t1);
  if (f.a >= f.c && f.a >= l12) return triangle_edge_foot(f, p, 0, 1, min_length_squared);
  if (f.c >= l12) return triangle_edge_foot(f, p, 0, 2, min_length_squared);
  return triangle_edge_foot(f, p, 1, 2, min_length_squared);
}

// Derivation (Eberly's "Distance Between Point and Triangle in 3D", in our
// names). The triangle is T(s, t) = t0 + s*E0 + t*E1 with s, t >= 0,
// s + t <= 1. With D = t0 - p,
//   Q(s, t) = |T(s, t) - p|^2 = a s^2 + 2 b s t + c t^2 + 2 d s + 2 e t + f,
//   a = E0.E0, b = E0.E1, c = E1.E1, d = E0.D, e = E1.D, f = D.D.
// grad Q = 0 gives the projection of p on the plane, (s, t) = (sn, tn) / det
// with det = a c - b^2, sn = b e - c d, tn = b d - a e. Lagrange's identity
// (A x B).(C x D) = (A.C)(B.D) - (A.D)(B.C) rewrites them with n = E0 x E1
// and m = n x (p - t0) as
//   det = n.n,   sn = E1.m,   tn = -E0.m.
// sn is |n| |E1| times the signed distance of p's projection to the line
// t0 t2 (positive on t1's side), tn likewise for the line t0 t1, and
// det - sn - tn for the line t1 t2. Their signs give Eberly's seven regions:
//
//          t
//     2    |
//      `.  |
//        `.|
//          * t2
//          |`.
//     3    |  `.     1
//          | 0  `.
//   -------*------*------ s
//     4    t0     t1  6
//              5
//
//  0: the projection is inside; its (s, t) are the answer.
//  1, 3, 5: p is outside exactly one edge line; the closest point of a
//     triangle to a point outside exactly one of its edge lines lies on that
//     edge (the segment to any other point of the triangle would cross it).
//  2, 4, 6: p is outside the two edge lines through a vertex; the closest
//     point is on one of those two edges. Q is convex, so if Q decreases when
//     leaving the vertex along one edge, the minimum is on that edge, and
//     otherwise on the other one (both cannot decrease: that would contradict
//     the positive definiteness of [a b; b c] at a vertex region). The
//     directional derivatives are E.(vertex - p) dot products.
// Each edge is then the one-variable problem of edge_foot (one division);
// a foot clamped to a vertex also tries the vertex's other edge
// (triangle_edge_or_corner), which changes nothing in exact arithmetic.
//
// Region 0 divides once, by a*det (detail::substitute): t = tn / det as
// above, and s from the first normal equation a s + b t = E0.(p - t0), i.e.
// s = (E0.(p - t0) - b t) / a. In exact arithmetic this is sn / det. In
// floating point it makes the point the exact foot of p on the line
// {t0 + s E0 + t E1 : s}, so the error of t (large on a sliver, where the
// lines of constant s and of constant t are nearly parallel) moves the point
// along the triangle instead of off the answer. If rounding puts s
// outside [0, 1 - t] (never in exact arithmetic) the nearer edge is taken.
template <class S>
TriangleFoot<S> triangle_foot(const TriangleFrame<S>& f, const Vec3T<S>& p,
                              const S& min_length_squared) {
  if (f.degenerate) return longest_edge_foot(f, p, min_length_squared);
  const Vec3T<S> dp = p - f.t0;
  const Vec3T<S> m = detail::cross(f.n, dp);
  const S sn = detail::dot(f.e1, m);
  const S tn = -detail::dot(f.e0, m);
  if (sn + tn <= f.det) {
    if (sn < S(0)) {
      if (tn < S(0)) {  // region 4: vertex t0, leave it along E0 if E0.(t0 - p) < 0
        return detail::dot(f.e0, dp) > S(0)
                   ? triangle_edge_or_corner(f, p, 0, 1, min_length_squared)
                   : triangle_edge_or_corner(f, p, 0, 2, min_length_squared);
      }
      return triangle_edge_or_corner(f, p, 0, 2, min_length_squared);  // region 3: s = 0
    }
    if (tn < S(0))
      return triangle_edge_or_corner(f, p, 0, 1, min_length_squared);  // region 5: t = 0
    // Region 0.
    S s, t;
    if (!substitute(f.a, f.det, tn, detail::dot(f.e0, dp), detail::dot(f.e0, f.e1), s, t)) {
      return longest_edge_foot(f, p, min_length_squared);  // |E0|^2 underflowed (double)
    }
    if (s < S(0)) return triangle_edge_or_corner(f, p, 0, 2, min_length_squared);
    const S s_plus_t = s + t;
    if (s_plus_t > S(1)) return triangle_edge_or_corner(f, p, 1, 2, min_length_squared);
    return {{S(1) - s_plus_t, s, t}, Vec3T<S>(f.t0 + s * f.e0 + t * f.e1)};
  }
  const Vec3T<S> e2 = f.t2 - f.t1;
  if (sn < S(0)) {  // region 2: vertex t2, leave it towards t1 if E2.(t2 - p) > 0
    return detail::dot(e2, f.t2 - p) > S(0)
               ? triangle_edge_or_corner(f, p, 1, 2, min_length_squared)
               : triangle_edge_or_corner(f, p, 0, 2, min_length_squared);
  }
  if (tn < S(0)) {  // region 6: vertex t1, leave it towards t2 if E2.(t1 - p) < 0
    return detail::dot(e2, p - f.t1) > S(0)
               ? triangle_edge_or_corner(f, p, 1, 2, min_length_squared)
               : triangle_edge_or_corner(f, p, 0, 1, min_length_squared);
  }
  return triangle_edge_or_corner(f, p, 1, 2, min_length_squared);  // region 1: s + t = 1
}

// A segment crossing a triangle's plane strictly (its ends on opposite sides)
// meets the plane at X = a0 + lambda (a1 - a0), lambda = sa / (sa - sb) with
// sa, sb the ends' signed distances times |n|; lambda is in (0, 1) and the
// difference has no cancellation. The candidate pairs X with the triangle's
// closest point to X: zero distance iff X is in the triangle. In floating
// point X is off the plane by rounding only, and the pair stays a valid
// (point on A, point on B) candidate whatever the rounding. Returns false
// when the ends do not straddle the plane or the triangle is degenerate
// (a segment crossing a degenerate triangle crosses one of its edges).
//
// The heights use n made orthogonal to the triangle's longest edge L,
// n - (n.L / L.L) L, which is n itself in exact arithmetic. In floating point
// the rounding of E0 x E1 has a component along L of relative size u / sin
// (sin: the triangle's smallest angle); it tilts the plane about an axis
// across L and puts the heights of points far along L (a segment running
// along a sliver) off by more than the heights themselves. Removing it
// leaves the tilt about L, which only scales with the distance from L.
// (ClosestPointRegression.SegmentAlongASliverPiercesIt: a sliver of sines
// 1e-8 to 4e-8 pierced by a segment along it at 1.7e-8 radians to its plane,
// whose crossing came out 6.6 units away along the segment.)
template <class S>
bool crossing_candidate(const Vec3T<S>& a0, const Vec3T<S>& a1, const TriangleFrame<S>& f,
                        const KernelTolerance<S>& tol, ClosestPoints<S>& out) {
  if (f.degenerate) return false;
  const Vec3T<S> e2 = f.t2 - f.t1;
  const S l12 = detail::norm2(e2);
  const Vec3T<S>& longest = f.a >= f.c ? (f.a >= l12 ? f.e0 : e2) : (f.c >= l12 ? f.e1 : e2);
  const Vec3T<S> n = f.n - (detail::dot(f.n, longest) / detail::norm2(longest)) * longest;
  const S sa = detail::dot(n, a0 - f.t0);
  const S sb = detail::dot(n, a1 - f.t0);
  if (!((sa < S(0) && sb > S(0)) || (sa > S(0) && sb < S(0)))) return false;
  const S lambda = sa / (sa - sb);
  out.point_a = a0 + lambda * (a1 - a0);
  out.coef_a = {S(1) - lambda, lambda, S(0)};
  const TriangleFoot<S> foot = triangle_foot(f, out.point_a, tol.min_length_squared);
  out.point_b = foot.point;
  out.coef_b = foot.w;
  finish(out);
  return true;
}

// The segment-triangle reduction on a prepared triangle. See
// closest_segment_triangle for the derivation.
template <class S>
ClosestPoints<S> segment_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1, const TriangleFrame<S>& f,
                                  const KernelTolerance<S>& tol);

}  // namespace detail

// Derivation: |p - q|^2, both vertices active.
template <class S>
ClosestPoints<S> closest_point_point(const Vec3T<S>& p, const Vec3T<S>& q) {
  ClosestPoints<S> r;
  r.point_a = p;
  r.point_b = q;
  r.coef_a[0] = S(1);
  r.coef_b[0] = S(1);
  return detail::finish(r);
}

// a = point p, b = segment [s0, s1]. Derivation: the segment is s0 + t M,
// t in [0, 1], M = s1 - s0; Q(t) = |s0 + t M - p|^2 = a t^2 + 2 d t + f with
// a = M.M, d = M.(s0 - p). Q'(t) = 0 at t = -d / a; Q is convex, so the
// constrained minimum is that t clamped to [0, 1], decided by comparing -d
// with 0 and a before the only division (detail::edge_foot). A segment with
// a <= tol.min_length_squared is its first vertex.
template <class S>
ClosestPoints<S> closest_point_segment(const Vec3T<S>& p, const Vec3T<S>& s0, const Vec3T<S>& s1,
                                       const KernelTolerance<S>& tol = {}) {
  ClosestPoints<S> r;
  r.point_a = p;
  r.coef_a[0] = S(1);
  const detail::EdgeFoot<S> e = detail::edge_foot(p, s0, s1, tol.min_length_squared);
  r.point_b = e.point;
  detail::put_edge(r.coef_b, 0, 1, e.lambda);
  return detail::finish(r);
}

// a = point p, b = triangle (t0, t1, t2). Derivation: see detail::triangle_foot
// (Eberly's seven regions with triple-product numerators, one division). A
// triangle with det = a c - b^2 <= tol.min_sin_squared * a c is its longest
// edge (a point if that edge is shorter than the length tolerance).
template <class S>
ClosestPoints<S> closest_point_triangle(const Vec3T<S>& p, const Vec3T<S>& t0, const Vec3T<S>& t1,
                                        const Vec3T<S>& t2, const KernelTolerance<S>& tol = {}) {
  const detail::TriangleFrame<S> f(t0, t1, t2, tol);
  const detail::TriangleFoot<S> foot = detail::triangle_foot(f, p, tol.min_length_squared);
  ClosestPoints<S> r;
  r.point_a = p;
  r.coef_a[0] = S(1);
  r.point_b = foot.point;
  r.coef_b = foot.w;
  return detail::finish(r);
}

// a = segment [a0, a1], b = segment [b0, b1]. Derivation (Eberly's "Distance
// Between Two Line Segments in 3D", in our names, the paper's eqs. 16-18).
// A(s) = a0 + s M0, B(t) = b0 + t M1, s, t in [0, 1], D = a0 - b0,
//   Q(s, t) = |A(s) - B(t)|^2 = a s^2 + 2 b s t + c t^2 + 2 d s + 2 e t + f,
//   a = M0.M0, b = -M0.M1, c = M1.M1, d = M0.D, e = -M1.D, f = D.D.
// det = a c - b^2 = |M0 x M1|^2 (Lagrange) is zero iff the segments are
// parallel. Otherwise Q is strictly convex with minimum (sn, tn) / det,
// sn = b e - c d, tn = b d - a e, which Lagrange's identity turns into
// triple products with n = M0 x M1 and m = n x D:
//   sn = -M1.m,   tn = -M0.m,
// accurate to u |D| |n| |M| where b e - c d loses a further factor 1 / sin.
// The signs of sn, tn and of det - sn, det - tn give nine regions of the
// (s, t) plane around the unit square:
//
//     t
//     ^   4  |   3   |  2
//   1 +------+-------+
//         5  |   0   |  1
//   0 +------+-------+
//         6  |   7   |  8
//            0       1  --> s
//
//  0: the unconstrained minimum is inside; it is the answer.
//  1, 3, 5, 7: the minimum over the square is on the edge facing the region
//     (from any other point of the square, the direction towards the
//     unconstrained minimum stays inside the square and decreases Q). That
//     edge is a point-segment problem, e.g. s = 1: the foot of a1 on B.
//  2, 4, 6, 8: the minimum is on one of the two edges through the corner.
//     With the corner's gradient g = H (corner - minimum), the two inward
//     directional derivatives cannot both be negative (H positive definite),
//     so: if Q decreases entering along the t-edge, take that edge, else the
//     s-edge. The derivative along s is M0.(A(s) - B(t)) at the corner.
// Region 0 divides once, by a*det (detail::substitute): t = tn / det, and s
// from the first normal equation a s - (M0.M1) t = -M0.D, i.e. A(s) is the
// exact foot of B(t) on line A. In exact arithmetic this is sn / det; in floating point, for nearly
// parallel segments, it keeps the error of t along the valley of Q, where
// the distance is flat, instead of pulling the two points apart. If rounding
// puts s outside [0, 1] (never in exact arithmetic) the facing edge is taken.
// Parallel segments (det <= tol.min_sin_squared * a c): Q is constant along
// the common direction, so a minimum lies on the boundary of the square, i.e.
// at an end of one segment: the best of the four end-to-segment feet, ties
// going to the smaller feature pair. A segment with |M|^2 <=
// tol.min_length_squared is its first vertex.
template <class S>
ClosestPoints<S> closest_segment_segment(const Vec3T<S>& a0, const Vec3T<S>& a1, const Vec3T<S>& b0,
                                         const Vec3T<S>& b1, const KernelTolerance<S>& tol = {}) {
  const Vec3T<S> m0 = a1 - a0;
  const Vec3T<S> m1 = b1 - b0;
  const S a = detail::norm2(m0);
  const S c = detail::norm2(m1);
  if (a <= tol.min_length_squared) return closest_point_segment(a0, b0, b1, tol);
  if (c <= tol.min_length_squared) return detail::swapped(closest_point_segment(b0, a0, a1, tol));

  // The foot of one end of A on B (edge s = 0 or 1), or of one end of B on A.
  const auto end_of_a = [&](bool at_a1) {
    ClosestPoints<S> r = closest_point_segment(at_a1 ? a1 : a0, b0, b1, tol);
    if (at_a1) std::swap(r.coef_a[0], r.coef_a[1]);
    return detail::finish(r);
  };
  const auto end_of_b = [&](bool at_b1) {
    ClosestPoints<S> r = detail::swapped(closest_point_segment(at_b1 ? b1 : b0, a0, a1, tol));
    if (at_b1) std::swap(r.coef_b[0], r.coef_b[1]);
    return detail::finish(r);
  };

  // A foot clamped to an end of the other segment sits at a corner of the
  // square; the minimum may then lie on the other edge through that corner.
  // In exact arithmetic the region analysis picked the right edge and Q is
  // strictly convex, so the second foot returns the same corner and nothing
  // changes. In floating point, for nearly parallel segments whose (sn, tn)
  // are mostly rounding, the picked edge can miss the valley of Q by a whole
  // segment length (ClosestPointExact.NearlyParallelSegments found one at
  // sine 9u: antiparallel segments overlapping at their ends, off by 2.6% of
  // their length); the corner's other edge then holds the answer. A clamped
  // foot does not divide, so an answer still costs at most one division.
  const auto corner_safe = [&](ClosestPoints<S> r, bool from_a) {
    const std::uint8_t other_side = from_a ? r.active_b : r.active_a;
    if (other_side == 3) return r;  // the foot is inside the other segment
    ClosestPoints<S> other = from_a ? end_of_b(other_side == 2) : end_of_a(other_side == 2);
    return detail::improves(other, r) ? other : r;
  };
  const auto from_end_of_a = [&](bool at_a1) { return corner_safe(end_of_a(at_a1), true); };
  const auto from_end_of_b = [&](bool at_b1) { return corner_safe(end_of_b(at_b1), false); };

  const Vec3T<S> n = detail::cross(m0, m1);
  const S det = detail::norm2(n);
  if (det <= tol.min_sin_squared * a * c) {
    ClosestPoints<S> best = end_of_a(false);
    for (int k = 1; k < 4; ++k) {
      ClosestPoints<S> cand = k == 1 ? end_of_a(true) : end_of_b(k == 3);
      if (detail::improves(cand, best)) best = std::move(cand);
    }
    return best;
  }

  const Vec3T<S> dd = a0 - b0;
  const Vec3T<S> m = detail::cross(n, dd);
  const S sn = -detail::dot(m1, m);
  const S tn = -detail::dot(m0, m);
  const int s_side = sn < S(0) ? 0 : (sn > det ? 2 : 1);  // 0: s < 0, 1: inside, 2: s > 1
  const int t_side = tn < S(0) ? 0 : (tn > det ? 2 : 1);
  if (s_side == 1 && t_side == 1) {  // region 0
    S s, t;
    if (detail::substitute(a, det, tn, S(-detail::dot(m0, dd)), S(-detail::dot(m0, m1)), s, t)) {
      if (t > S(1)) t = S(1);  // tn <= det: an excess is rounding
      if (s < S(0)) return from_end_of_a(false);
      if (s > S(1)) return from_end_of_a(true);
      ClosestPoints<S> r;
      r.point_a = a0 + s * m0;
      r.point_b = b0 + t * m1;
      r.coef_a = {S(1) - s, s, S(0)};
      r.coef_b = {S(1) - t, t, S(0)};
      return detail::finish(r);
    }
  }
  // Regions 5 (s = 0) and 1 (s = 1); region 0 only if |M0|^2 underflowed.
  if (t_side == 1) return from_end_of_a(s_side == 2);
  if (s_side == 1) return from_end_of_b(t_side == 2);  // regions 7 (t = 0) and 3 (t = 1)
  // Corner regions 2, 4, 6, 8: corner (s, t) = (s_side / 2, t_side / 2).
  const Vec3T<S>& corner_a = s_side == 2 ? a1 : a0;
  const Vec3T<S>& corner_b = t_side == 2 ? b1 : b0;
  const S slope_s = detail::dot(m0, corner_a - corner_b);  // dQ/ds / 2 at the corner
  // Entering the square along the t-edge means decreasing s at s = 1 and
  // increasing it at s = 0.
  const bool along_t_edge = s_side == 2 ? slope_s > S(0) : slope_s < S(0);
  return along_t_edge ? from_end_of_b(t_side == 2) : from_end_of_a(s_side == 2);
}

namespace detail {

template <class S>
ClosestPoints<S> segment_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1, const TriangleFrame<S>& f,
                                  const KernelTolerance<S>& tol) {
  // A piercing at exactly zero distance cannot be improved on, and its pair
  // is minimal: the segment's ends are strictly off the plane, and the
  // triangle side is point_triangle's minimal set. Otherwise the piercing is
  // one candidate among the others: in floating point a sliver's normal is
  // mostly rounding, and its "piercing" may be far from the answer.
  ClosestPoints<S> crossing;
  const bool crosses = crossing_candidate(a0, a1, f, tol, crossing);
  if (crosses && crossing.distance_squared == S(0)) return crossing;

  const Vec3T<S>* v[3] = {&f.t0, &f.t1, &f.t2};
  ClosestPoints<S> best;
  bool have = false;
  const auto consider = [&](ClosestPoints<S>&& cand) {
    if (!have || improves(cand, best)) {
      best = std::move(cand);
      have = true;
    }
  };
  if (crosses) consider(std::move(crossing));
  for (int k = 0; k < 2; ++k) {  // segment ends against the triangle
    const Vec3T<S>& p = k == 0 ? a0 : a1;
    const TriangleFoot<S> foot = triangle_foot(f, p, tol.min_length_squared);
    ClosestPoints<S> cand;
    cand.point_a = p;
    cand.coef_a[static_cast<std::size_t>(k)] = S(1);
    cand.point_b = foot.point;
    cand.coef_b = foot.w;
    consider(std::move(finish(cand)));
  }
  constexpr int kEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (const auto& edge : kEdges) {  // segment against the triangle's edges
    ClosestPoints<S> cand = closest_segment_segment(a0, a1, *v[edge[0]], *v[edge[1]], tol);
    const S w0 = cand.coef_b[0], w1 = cand.coef_b[1];
    cand.coef_b = {S(0), S(0), S(0)};
    cand.coef_b[static_cast<std::size_t>(edge[0])] = w0;
    cand.coef_b[static_cast<std::size_t>(edge[1])] = w1;
    cand.active_b = nonzero_bits(cand.coef_b);
    consider(std::move(cand));
  }
  return best;
}

}  // namespace detail

// a = segment [a0, a1], b = triangle (t0, t1, t2). Derivation by reduction:
// minimize |A(u) - T(s, t)|^2 over the segment's u and the triangle's (s, t).
// At a minimizer with u inside (0, 1) and (s, t) inside the triangle, the
// gradient vanishes: the difference v is orthogonal to the segment and to the
// plane. If v != 0 the segment is parallel to the plane and sliding along it
// keeps the distance until u or (s, t) reaches a boundary, so a minimizer
// exists on the boundary: a segment end against the triangle (two
// point-triangle problems) or the segment against an edge (three
// segment-segment problems). If v = 0 the segment pierces the triangle:
// detected by crossing_candidate, distance 0. The best candidate wins, ties
// going to the smaller feature pair.
template <class S>
ClosestPoints<S> closest_segment_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1,
                                          const Vec3T<S>& t0, const Vec3T<S>& t1,
                                          const Vec3T<S>& t2, const KernelTolerance<S>& tol = {}) {
  return detail::segment_triangle(a0, a1, detail::TriangleFrame<S>(t0, t1, t2, tol), tol);
}

// a = triangle (a0, a1, a2), b = triangle (b0, b1, b2). Derivation by
// reduction, as for closest_segment_triangle: a minimizer of
// |A(s, t) - B(s', t')|^2 with both parameters inside their triangles has
// v orthogonal to both planes; if v != 0 the planes are parallel and sliding
// reaches a boundary, so some minimizer has a point on an edge of A or of B,
// and, repeating the argument on that edge, is a vertex of one against the
// other triangle (six point-triangle problems) or an edge against an edge
// (nine segment-segment problems). If v = 0 the triangles intersect: either
// an edge of one pierces the other's interior (the six piercing tests,
// distance 0) or they meet on their boundaries, where the fifteen problems
// find 0. All candidates are pairs of points on the two triangles, so in
// floating point too the smallest one is an upper bound within rounding.
template <class S>
ClosestPoints<S> closest_triangle_triangle(const Vec3T<S>& a0, const Vec3T<S>& a1,
                                           const Vec3T<S>& a2, const Vec3T<S>& b0,
                                           const Vec3T<S>& b1, const Vec3T<S>& b2,
                                           const KernelTolerance<S>& tol = {}) {
  const detail::TriangleFrame<S> fa(a0, a1, a2, tol);
  const detail::TriangleFrame<S> fb(b0, b1, b2, tol);
  const Vec3T<S>* va[3] = {&a0, &a1, &a2};
  const Vec3T<S>* vb[3] = {&b0, &b1, &b2};
  constexpr int kEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  // Moves the edge weights held in coef[0], coef[1] to the edge's vertices.
  const auto spread = [](std::array<S, 3>& coef, const int(&edge)[2]) {
    const S w0 = coef[0], w1 = coef[1];
    coef = {S(0), S(0), S(0)};
    coef[static_cast<std::size_t>(edge[0])] = w0;
    coef[static_cast<std::size_t>(edge[1])] = w1;
  };

  ClosestPoints<S> best;
  bool have = false;
  const auto consider = [&](ClosestPoints<S>& cand) {
    detail::finish(cand);
    if (!have || detail::improves(cand, best)) {
      best = std::move(cand);
      have = true;
    }
  };
  // Piercings are candidates like the others (no early answer: in floating
  // point a sliver's normal is mostly rounding, see segment_triangle).
  for (int side = 0; side < 2; ++side) {
    for (const auto& edge : kEdges) {
      ClosestPoints<S> cand;
      const bool crosses =
          side == 0 ? detail::crossing_candidate(*va[edge[0]], *va[edge[1]], fb, tol, cand)
                    : detail::crossing_candidate(*vb[edge[0]], *vb[edge[1]], fa, tol, cand);
      if (!crosses) continue;
      if (side == 1) cand = detail::swapped(std::move(cand));
      spread(side == 0 ? cand.coef_a : cand.coef_b, edge);
      consider(cand);
    }
  }
  for (int side = 0; side < 2; ++side) {  // vertices of one triangle against the other
    const detail::TriangleFrame<S>& other = side == 0 ? fb : fa;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3T<S>& p = side == 0 ? *va[k] : *vb[k];
      const detail::TriangleFoot<S> foot = detail::triangle_foot(other, p, tol.min_length_squared);
      ClosestPoints<S> cand;
      cand.point_a = p;
      cand.coef_a[k] = S(1);
      cand.point_b = foot.point;
      cand.coef_b = foot.w;
      if (side == 1) cand = detail::swapped(std::move(cand));
      consider(cand);
    }
  }
  for (const auto& ea : kEdges) {  // edges against edges
    for (const auto& eb : kEdges) {
      ClosestPoints<S> cand =
          closest_segment_segment(*va[ea[0]], *va[ea[1]], *vb[eb[0]], *vb[eb[1]], tol);
      spread(cand.coef_a, ea);
      spread(cand.coef_b, eb);
      consider(cand);
    }
  }
  return best;
}

// A and B are 1..3 points each (point, segment, triangle; na, nb outside
// 1..3 are a precondition violation). Dispatches to the kernels above,
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
