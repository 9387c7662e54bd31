// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: a convex polytope built once from a point list.
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

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <memory>
#include <span>
#include <vector>

#include "proxima/core/types.h"

namespace proxima {

namespace detail {
class TrianglePolytope;
}  // namespace detail

struct Plane {
  Vec3 normal;    // unit, outward
  double offset;  // normal.dot(x) == offset on the plane
};

// ConvexPolytope::input_index(): for each hull vertex, the index of the
// input point it came from. Held only when it is not the identity (when
// some input point is a duplicate or not a hull vertex); the identity, the
// common case of a point list that is already a hull, costs nothing.
class InputIndex {
 public:
  InputIndex() = default;
  InputIndex(const std::int32_t* stored, std::size_t size) : stored_(stored), size_(size) {}
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::int32_t operator[](std::size_t i) const {
    return stored_ != nullptr ? stored_[i] : static_cast<std::int32_t>(i);
  }
  class iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = std::int32_t;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = std::int32_t;
    iterator() = default;
    iterator(const InputIndex* map, std::size_t i) : map_(map), i_(i) {}
    std::int32_t operator*() const { return (*map_)[i_]; }
    iterator& operator++() {
      ++i_;
      return *this;
    }
    iterator operator++(int) {
      iterator old = *this;
      ++i_;
      return old;
    }
    bool operator==(const iterator& o) const { return i_ == o.i_; }

   private:
    const InputIndex* map_ = nullptr;
    std::size_t i_ = 0;
  };
  iterator begin() const { return {this, 0}; }
  iterator end() const { return {this, size_}; }
  std::vector<std::int32_t> to_vector() const { return {begin(), end()}; }

 private:
  const std::int32_t* stored_ = nullptr;  // null: the identity
  std::size_t size_ = 0;
};

class ConvexPolytope {
 public:
  // Builds the hull of `points`. Throws InvalidInput naming the problem and
  // the input index: no points, NaN or infinite coordinates.
  explicit ConvexPolytope(std::span<const Vec3> points);
  explicit ConvexPolytope(const std::vector<Vec3>& points)
      : ConvexPolytope(std::span<const Vec3>(points.data(), points.size())) {}
  ConvexPolytope(const ConvexPolytope& other);
  ConvexPolytope& operator=(const ConvexPolytope& other);
  // A moved-from polytope has no vertices, edges or faces.
  ConvexPolytope(ConvexPolytope&& other) noexcept;
  ConvexPolytope& operator=(ConvexPolytope&& other) noexcept;
  ~ConvexPolytope() = default;

  // 0 (point), 1 (segment), 2 (polygon) or 3 (solid).
  int dimension() const { return dimension_; }

  // Hull vertices, in hull order; input_index()[i] is the index in the input
  // point list that vertex i came from.
  std::span<const Vec3> vertices() const { return {vertex_data(), size(vertex_count_)}; }
  InputIndex input_index() const {
    return {identity_input_ ? nullptr : ints() + input_index_at(), size(vertex_count_)};
  }
  int vertex_count() const { return vertex_count_; }
  const Vec3& vertex(int i) const { return vertex_data()[i]; }

  // Vertex adjacency along the hull's true edges (compressed sparse rows):
  // the neighbours of v are adjacency()[adjacency_offsets()[v] ..
  // adjacency_offsets()[v+1]). For a segment each end has the other; for a
  // polygon each vertex has its two neighbours along the boundary; a point
  // has none.
  std::span<const std::int32_t> adjacency_offsets() const {
    return {ints(), size(vertex_count_) + 1};
  }
  std::span<const std::int32_t> adjacency() const {
    return {ints() + adjacency_at(), size(adjacency_size_)};
  }
  std::span<const std::int32_t> neighbors(int v) const {
    const std::int32_t* offsets = ints();
    const auto b = size(offsets[v]);
    const auto e = size(offsets[v + 1]);
    return {ints() + adjacency_at() + b, e - b};
  }
  // Parallel to adjacency(): the face to the left of the directed edge
  // v -> adjacency()[k] (the face whose outward, counter-clockwise boundary
  // runs v -> w), or -1 when there is none (segments).
  std::span<const std::int32_t> adjacency_faces() const {
    return {ints() + adjacency_faces_at(), size(adjacency_size_)};
  }

  // Faces as polygons (compressed sparse rows), each counter-clockwise seen
  // from outside, so that the right-hand normal points outward. Coplanar
  // triangles are merged into one polygon. A polygon (dimension 2) has two
  // faces, one per side. Segments and points have none.
  int face_count() const { return face_count_; }
  std::span<const std::int32_t> face(int f) const {
    const std::size_t b = face_begin(f);
    return {ints() + face_vertices_at() + b, face_begin(f + 1) - b};
  }
  // face_count() + 1 offsets into face_vertices() (built on each call: a
  // hull of triangles only holds none, face f being 3f .. 3f + 3).
  std::vector<std::int32_t> face_offsets() const;
  std::span<const std::int32_t> face_vertices() const {
    return {ints() + face_vertices_at(), face_begin(face_count_)};
  }
  // The outward plane of face f (Newell's normal over the polygon).
  Plane face_plane(int f) const;
  // Fan triangulation of every face, outward orientation; triangle_face()[t]
  // is the face triangle t belongs to.
  std::vector<std::array<std::int32_t, 3>> triangles() const;
  std::vector<std::int32_t> triangle_face() const;
  // Every undirected hull edge once, as (smaller id, larger id).
  std::vector<std::array<std::int32_t, 2>> edges() const;
  int edge_count() const { return adjacency_size_ / 2; }

  // Mean of the hull vertices.
  const Vec3& centroid() const { return centroid_; }
  // Largest distance from the centroid to a vertex.
  double bounding_radius() const { return bounding_radius_; }
  // The box of the hull vertices in the polytope's own frame, as a center
  // and half extents (halves of the extreme coordinates, so no sum
  // overflows; within a few u of the exact box): after the sphere, the
  // first bound of a margin query. Kept by hulls of more than
  // kTableMinVertices vertices only (has_box()), in the one allocation:
  // a small hull's query costs little more than the box test would, and
  // its memory stays within twice its vertices plus adjacency.
  bool has_box() const { return box_at_ != 0; }
  Vec3 box_center() const { return Vec3(data_[box_at_], data_[box_at_ + 1], data_[box_at_ + 2]); }
  Vec3 box_half() const {
    return Vec3(data_[box_at_ + 3], data_[box_at_ + 4], data_[box_at_ + 5]);
  }
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

  // A vertex near the support along `dir`, the start of a climb
  // (support_without_hint, the expanding polytope of the cold depth): the
  // support along the centre of dir's cell in a cube map of directions,
  // tabulated when the hull is built (see kTableVerticesPerCell). -1 when
  // the hull has no table (at most kTableMinVertices vertices) or dir is
  // zero, not finite or so large that the sum of its magnitudes overflows.
  // O(1).
  int support_start(const Vec3& dir) const;

  // Hulls of more than this many vertices get the table of support_start;
  // smaller ones are scanned (support_without_hint, kScanVertices).
  static constexpr int kTableMinVertices = 32;
  // About this many hull vertices per cell of the table: each cell then
  // spans about two vertex spacings on a round hull, so that a climb from
  // its support reaches the support along any direction of the cell in one
  // or two steps, at 4 bytes per cell (about 1% of the hull's memory).
  static constexpr int kTableVerticesPerCell = 4;

 private:
  // A scratch triangle rewrites the vertices of a polytope built once
  // (src/shape/triangle_polytope.h).
  friend class detail::TrianglePolytope;
  // Every array lives in one allocation (bench/polytope_bench.cpp measures
  // the bytes against the vertices plus the adjacency): the vertices, then
  // the 32-bit arrays in this order: adjacency offsets (vertex_count + 1),
  // adjacency, adjacency faces (adjacency_size each), face offsets
  // (face_count + 1, absent when every face is a triangle), face vertices,
  // input index (vertex_count, absent when it is the identity), the support
  // table; then, for a hull of more than kTableMinVertices vertices, the
  // box (six doubles at box_at_). Positions in the 32-bit part follow from
  // the counts.
  static std::size_t size(std::int32_t n) { return static_cast<std::size_t>(n); }
  const Vec3* vertex_data() const { return reinterpret_cast<const Vec3*>(data_.get()); }
  // The 32-bit part starts ints_at_ doubles into the allocation: a stored
  // offset (an addressing mode away), so that the hill climb's first loads
  // wait on no arithmetic.
  const std::int32_t* ints() const {
    return reinterpret_cast<const std::int32_t*>(data_.get() + ints_at_);
  }
  std::size_t adjacency_at() const { return size(vertex_count_) + 1; }
  std::size_t adjacency_faces_at() const { return adjacency_at() + size(adjacency_size_); }
  std::size_t face_offsets_at() const { return adjacency_faces_at() + size(adjacency_size_); }
  std::size_t face_vertices_at() const {
    return face_offsets_at() + (triangles_only_ ? 0 : size(face_count_) + 1);
  }
  std::size_t face_begin(int f) const {
    return triangles_only_ ? 3 * size(f) : size(ints()[face_offsets_at() + size(f)]);
  }
  std::size_t input_index_at() const { return face_vertices_at() + face_begin(face_count_); }
  // The table of support_start: 6 table_side_^2 vertex ids, cube face
  // 2 axis + (negative), then row, then column, after the input index.
  std::size_t table_at() const {
    return input_index_at() + (identity_input_ ? 0 : static_cast<std::size_t>(vertex_count_));
  }
  static int table_side_for(std::int32_t vertex_count);
  void build_table();
  std::size_t int_count() const;  // of the 32-bit part, once it is filled
  static std::size_t doubles_for(std::int32_t vertex_count, std::size_t int_count);
  void allocate(std::size_t doubles);
  void take(ConvexPolytope& other) noexcept;  // moves other's state here, leaves it empty
  // centroid_, bounding_radius_, the box and scale_ from the stored
  // vertices.
  void measure();

  std::unique_ptr<double[]> data_;
  std::int32_t vertex_count_ = 0;
  std::int32_t adjacency_size_ = 0;
  std::int32_t face_count_ = 0;
  std::int32_t interior_point_count_ = 0;
  std::uint32_t ints_at_ = 0;  // 3 vertex_count_
  std::int8_t dimension_ = 0;
  bool triangles_only_ = true;
  bool identity_input_ = true;
  std::int16_t table_side_ = 0;  // 0: no table
  // Where the box's six doubles start in the allocation, after the 32-bit
  // part (0: no box). In the padding before centroid_: no larger object.
  std::uint32_t box_at_ = 0;
  Vec3 centroid_ = Vec3::Zero();
  double bounding_radius_ = 0.0;
  double scale_ = 0.0;
};

inline int ConvexPolytope::support_start(const Vec3& dir) const {
  if (table_side_ == 0) return -1;
  // The cube face of dir's largest component, then its cell: the other two
  // components divided by it lie in [-1, 1] (no overflow, whatever dir's
  // size), so each index is in [0, side] before the clamp.
  // Refused first without comparing a NaN (an ordered comparison of a NaN
  // raises the invalid-operation flag, which the tests trap); a sum that
  // overflows is refused too (the caller's seeds then start the climb).
  const Vec3 m = dir.cwiseAbs();
  const double total = m.x() + m.y() + m.z();
  if (!std::isfinite(total) || total == 0.0) return -1;
  const int axis = m.x() >= m.y() ? (m.x() >= m.z() ? 0 : 2) : (m.y() >= m.z() ? 1 : 2);
  const double largest = m[axis];
  const int side = table_side_;
  const double half = 0.5 * side;
  const int row = std::min(side - 1, static_cast<int>((dir[(axis + 1) % 3] / largest + 1.0) * half));
  const int column =
      std::min(side - 1, static_cast<int>((dir[(axis + 2) % 3] / largest + 1.0) * half));
  const int face = 2 * axis + (dir[axis] < 0.0 ? 1 : 0);
  return ints()[table_at() + static_cast<std::size_t>((face * side + row) * side + column)];
}

}  // namespace proxima
