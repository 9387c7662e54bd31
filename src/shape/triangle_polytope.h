// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer (internal): one triangle at a time as a ConvexPolytope, for a
// query that tests many triangles of a mesh against a convex body
// (mesh-convex distance, src/query/mesh_convex_distance.cpp).
//
// Every proper triangle has the same hull structure: three vertices, each
// adjacent to the other two, and two faces, (0 1 2) and (0 2 1), one per
// side. That structure is invariant under any relabeling of the vertices,
// so a polytope built once from a reference triangle serves every triangle
// by rewriting its three vertices (and the centroid, radius and scale that
// follow from them): no hull construction, no allocation per triangle. A
// degenerate triangle (collinear or repeated vertices, decided exactly) is a
// segment or a point, another structure: the caller builds its
// ConvexPolytope the general way.
//
// Not thread-safe: one scratch per query (or per thread).
#pragma once

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

class TrianglePolytope {
 public:
  TrianglePolytope();

  // Makes polytope() the triangle (p0, p1, p2) with vertex k = p_k (the
  // input index is the identity). False, and polytope() left as it was,
  // when the points are exactly collinear (or two are equal).
  bool assign(const Vec3& p0, const Vec3& p1, const Vec3& p2);

  const ConvexPolytope& polytope() const { return polytope_; }

 private:
  ConvexPolytope polytope_;
};

}  // namespace proxima::detail
