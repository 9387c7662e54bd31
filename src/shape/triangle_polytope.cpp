// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: the scratch triangle polytope (triangle_polytope.h).
#include "shape/triangle_polytope.h"

#include <array>

#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima::detail {

TrianglePolytope::TrianglePolytope()
    : polytope_(std::array<Vec3, 3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}) {
  if (polytope_.dimension() != 2 || polytope_.vertex_count() != 3 ||
      polytope_.face_count() != 2 || polytope_.edge_count() != 3) {
    throw InternalError("TrianglePolytope: the reference triangle is not a polygon of 3 vertices");
  }
  // The reference's hull order may be any rotation or reflection of its
  // input order; the structure is the same under every relabeling (the
  // header), so vertex k is simply the k-th point assigned.
  polytope_.identity_input_ = true;
}

bool TrianglePolytope::assign(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  if (collinear3d(p0, p1, p2)) return false;
  Vec3* v = reinterpret_cast<Vec3*>(polytope_.data_.get());
  v[0] = p0;
  v[1] = p1;
  v[2] = p2;
  polytope_.measure();
  return true;
}

}  // namespace proxima::detail
