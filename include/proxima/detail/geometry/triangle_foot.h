// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer (internal): the closest point of a prepared triangle to a point
// (Eberly's region analysis), shared by the kernels that involve a triangle.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"

namespace proxima {

namespace detail {

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

}  // namespace detail

}  // namespace proxima
