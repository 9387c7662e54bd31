// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: closest points between two triangles.
#pragma once

#include "proxima/detail/geometry/closest_point_common.h"
#include "proxima/detail/geometry/triangle_foot.h"
#include "proxima/geometry/closest_segment_segment.h"
#include "proxima/geometry/closest_segment_triangle.h"

namespace proxima {

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

}  // namespace proxima
