// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the Gauss-map arcs of the hulls' edges and their crossing test.
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include "penetration/query.h"

namespace proxima {
namespace {

// The face to the left of the directed edge v -> w, or -1.
int left_face(const ConvexPolytope& poly, int v, int w) {
  const auto offsets = poly.adjacency_offsets();
  const auto adjacency = poly.adjacency();
  const auto faces = poly.adjacency_faces();
  for (std::int32_t k = offsets[static_cast<std::size_t>(v)];
       k < offsets[static_cast<std::size_t>(v) + 1]; ++k)
    if (adjacency[static_cast<std::size_t>(k)] == w) return faces[static_cast<std::size_t>(k)];
  return -1;
}

// The Gauss-map arcs of edge v -> w (1 for a solid, 2 for a polygon, 4 for
// a segment), axis `k` (the edge vector in A's frame), endpoints from the
// face normals `nl`, `nr` (in A's frame; already negated for -B, in which
// case `negate` flips the in-plane normals the same way). Returns the count.
int edge_arcs(int dimension, const Vec3& k, const Vec3& nl, const Vec3& nr, bool negate,
              std::array<Arc, 4>& out) {
  const double tolerance = kArcTolerance * k.norm();
  const double sign = negate ? -1.0 : 1.0;
  if (dimension == 3) {
    out[0] = {nl, nr, k, tolerance};
    return 1;
  }
  const Vec3 axis = detail::exponent_free(k).normalized();
  if (dimension == 2) {
    // nl is the left side's normal (for -B: minus it); o the outward normal.
    const Vec3 left = sign * nl;  // the un-negated left normal
    const Vec3 o = axis.cross(left).normalized();
    out[0] = {sign * left, sign * o, k, tolerance};
    out[1] = {sign * o, -sign * left, k, tolerance};
    return 2;
  }
  // Segment: u, v orthonormal with u x v = axis.
  const Vec3 helper = std::abs(axis.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = axis.cross(helper).normalized();
  const Vec3 v = axis.cross(u);
  out[0] = {u, v, k, tolerance};
  out[1] = {v, -u, k, tolerance};
  out[2] = {-u, -v, k, tolerance};
  out[3] = {-v, u, k, tolerance};
  return 4;
}

// The arcs of A's edge v -> w, whose left and right faces are l and r
// (left_face's; read only for dimensions 2 and 3).
int arcs_of_a(const Query& q, int v, int w, int l, int r, std::array<Arc, 4>& out) {
  const int dim = q.a.dimension();
  const Vec3 k = q.point_a(w) - q.point_a(v);
  if (dim == 3 || dim == 2) {
    if (l < 0 || r < 0) return 0;
    return edge_arcs(dim, k, q.arc_normal_a(l), q.arc_normal_a(r), false, out);
  }
  return edge_arcs(1, k, Vec3::Zero(), Vec3::Zero(), false, out);
}

int arcs_of_a(const Query& q, int v, int w, std::array<Arc, 4>& out) {
  return arcs_of_a(q, v, w, left_face(q.a, v, w), left_face(q.a, w, v), out);
}

// The arcs of -B's edge v -> w, whose left and right faces are l and r
// (left_face's; read only for dimensions 2 and 3).
int arcs_of_b(const Query& q, int v, int w, int l, int r, std::array<Arc, 4>& out) {
  const int dim = q.b.dimension();
  const Vec3 k = q.point_b(w) - q.point_b(v);
  if (dim == 3 || dim == 2) {
    if (l < 0 || r < 0) return 0;
    return edge_arcs(dim, k, q.arc_normal_b(l), q.arc_normal_b(r), true, out);
  }
  return edge_arcs(1, k, Vec3::Zero(), Vec3::Zero(), true, out);
}

int arcs_of_b(const Query& q, int v, int w, std::array<Arc, 4>& out) {
  return arcs_of_b(q, v, w, left_face(q.b, v, w), left_face(q.b, w, v), out);
}

bool edges_may_cross(const std::array<Arc, 4>& xs, int nx, const std::array<Arc, 4>& ys, int ny) {
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      if (arcs_may_cross(xs[static_cast<std::size_t>(i)], ys[static_cast<std::size_t>(j)]))
        return true;
  return false;
}

// The side of an arc that a normal n lies on is read from the arc's middle
// only when the arc is clearly shorter than a half circle: |p + q| >= this
// (an arc of at most about 150 degrees; |p + q| = 2 cos(angle / 2)).
// Longer arcs (a plate's rim, whose two faces are nearly opposite; a
// needle's edges) have a middle made of rounding; then the other body's
// arc decides, and when both are long both n and -n are evaluated (each an
// upper bound). Pinned by PenetrationOracle.RandomOverlapsFromGrazingToContainment
// (a needle of width 1e-17 on a plate) and PenetrationDegenerate.PolygonCuttingThroughSolid.
constexpr double kClearMiddle = 0.5;

// The middle of an edge's Gauss-map arcs (from arcs_of_a / arcs_of_b), as
// a direction whose side tells which of n, -n lies on them: for a solid
// p + q, for a polygon the outward in-plane normal (both negated for -B,
// as the arcs are); zero when unclear (see kClearMiddle) or for a segment
// (its arcs make a whole circle).
Vec3 arc_middle(const std::array<Arc, 4>& arcs, int count) {
  if (count == 1) {
    const Vec3 middle = arcs[0].p + arcs[0].q;
    return middle.norm() >= kClearMiddle ? middle : Vec3::Zero();
  }
  if (count == 2) return arcs[0].q;  // o (for -B: -o)
  return Vec3::Zero();
}

}  // namespace
}  // namespace proxima
