// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 3: a convex polytope built once from a point list.
//
// The hull is exact for every input: every decision is an exact predicate on
// the given doubles, so every input point is inside or on the hull, every
// hull vertex is an input point and an extreme one, and faces are exactly
// planar and convex. Inputs of lower dimension are valid polytopes: a single
// point (or only duplicates), collinear points (a segment), coplanar points
// (a convex polygon with both sides as faces).
//
// Thread safety: a ConvexPolytope is immutable after construction and may be
// shared between threads without synchronization.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "proxima/types.h"

namespace proxima {

struct Plane {
  Vec3 normal;    // unit, outward
  double offset;  // normal.dot(x) == offset on the plane
};

class ConvexPolytope {
 public:
  // Builds the hull of `points`. Throws InvalidInput naming the problem and
  // the input index: no points, NaN or infinite coordinates.
  explicit ConvexPolytope(std::span<const Vec3> points);
  explicit ConvexPolytope(const std::vector<Vec3>& points)
      : ConvexPolytope(std::span<const Vec3>(points.data(), points.size())) {}

  // 0 (point), 1 (segment), 2 (polygon) or 3 (solid).
  int dimension() const { return dimension_; }

  // Hull vertices, in hull order; input_index()[i] is the index in the input
  // point list that vertex i came from.
  std::span<const Vec3> vertices() const { return vertices_; }
  std::span<const std::int32_t> input_index() const { return input_index_; }
  int vertex_count() const { return static_cast<int>(vertices_.size()); }
  const Vec3& vertex(int i) const { return vertices_[static_cast<std::size_t>(i)]; }

  // Vertex adjacency along the hull's true edges (compressed sparse rows):
  // the neighbours of v are adjacency()[adjacency_offsets()[v] ..
  // adjacency_offsets()[v+1]). For a segment each end has the other; for a
  // polygon each vertex has its two neighbours along the boundary; a point
  // has none.
  std::span<const std::int32_t> adjacency_offsets() const { return adjacency_offsets_; }
  std::span<const std::int32_t> adjacency() const { return adjacency_; }
  std::span<const std::int32_t> neighbors(int v) const {
    const auto b = static_cast<std::size_t>(adjacency_offsets_[static_cast<std::size_t>(v)]);
    const auto e = static_cast<std::size_t>(adjacency_offsets_[static_cast<std::size_t>(v) + 1]);
    return std::span<const std::int32_t>(adjacency_).subspan(b, e - b);
  }
  // Parallel to adjacency(): the face to the left of the directed edge
  // v -> adjacency()[k] (the face whose outward, counter-clockwise boundary
  // runs v -> w), or -1 when there is none (segments).
  std::span<const std::int32_t> adjacency_faces() const { return adjacency_faces_; }

  // Faces as polygons (compressed sparse rows), each counter-clockwise seen
  // from outside, so that the right-hand normal points outward. Coplanar
  // triangles are merged into one polygon. A polygon (dimension 2) has two
  // faces, one per side. Segments and points have none.
  int face_count() const { return static_cast<int>(face_offsets_.size()) - 1; }
  std::span<const std::int32_t> face(int f) const {
    const auto b = static_cast<std::size_t>(face_offsets_[static_cast<std::size_t>(f)]);
    const auto e = static_cast<std::size_t>(face_offsets_[static_cast<std::size_t>(f) + 1]);
    return std::span<const std::int32_t>(face_vertices_).subspan(b, e - b);
  }
  std::span<const std::int32_t> face_offsets() const { return face_offsets_; }
  std::span<const std::int32_t> face_vertices() const { return face_vertices_; }
  // The outward plane of face f (Newell's normal over the polygon).
  Plane face_plane(int f) const;
  // Fan triangulation of every face, outward orientation; triangle_face()[t]
  // is the face triangle t belongs to.
  std::vector<std::array<std::int32_t, 3>> triangles() const;
  std::vector<std::int32_t> triangle_face() const;
  // Every undirected hull edge once, as (smaller id, larger id).
  std::vector<std::array<std::int32_t, 2>> edges() const;
  int edge_count() const { return static_cast<int>(adjacency_.size() / 2); }

  // Mean of the hull vertices.
  const Vec3& centroid() const { return centroid_; }
  // Largest distance from the centroid to a vertex.
  double bounding_radius() const { return bounding_radius_; }
  // Largest absolute coordinate of a hull vertex (the R of the accuracy
  // standard in the polytope's own frame): the magnitude that rounding errors
  // scale with. Every tolerance is relative to it (or to bounding_radius()
  // for sizes).
  double scale() const { return scale_; }

  // Number of input points strictly inside the hull or duplicated: points
  // that did not become hull vertices.
  int interior_point_count() const { return interior_point_count_; }

  // Bytes held by this object (its own size plus its arrays).
  std::size_t memory_bytes() const;

 private:
  int dimension_ = 0;
  int interior_point_count_ = 0;
  std::vector<Vec3> vertices_;
  std::vector<std::int32_t> input_index_;
  std::vector<std::int32_t> adjacency_offsets_;
  std::vector<std::int32_t> adjacency_;
  std::vector<std::int32_t> adjacency_faces_;
  std::vector<std::int32_t> face_offsets_{0};
  std::vector<std::int32_t> face_vertices_;
  Vec3 centroid_ = Vec3::Zero();
  double bounding_radius_ = 0.0;
  double scale_ = 0.0;
};

}  // namespace proxima
