// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: plain triangle meshes (non-convex, open or closed, soups)
// under a bounding-volume hierarchy over their triangles; their exact
// distance (proxima/query/mesh_distance.h) is a branch and bound over node
// pairs with a running upper bound.
//
//   proxima::TriangleMesh env(vertices, triangles);     // built once
//   proxima::MeshCache cache;                           // cold; one per pair
//   for each step:
//     auto r = proxima::distance(env, pose_a, robot, pose_b, {}, &cache);
//     r.distance, r.triangle_a, r.triangle_b, r.feature_a, r.point_a, ...
//
// What is measured between two meshes is the distance between their
// surfaces (the union of their triangles), plus, for a closed mesh, its
// inside: a body whose surface lies inside a closed mesh is intersecting
// (see distance() below).
//
// Thread safety: a TriangleMesh is immutable after construction and may be
// shared between threads. A MeshCache belongs to one pair of meshes at a
// time, like DistanceCache.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima {

class TriangleMesh {
 public:
  // Three vertex indices. Orientation matters only for is_closed() (and so
  // for the inside of a closed mesh): counter-clockwise seen from outside,
  // or all the other way; either works.
  using Triangle = std::array<std::uint32_t, 3>;

  // The most triangles a leaf of the hierarchy holds: the smallest leaf
  // that keeps the hierarchy inside the memory target (twice the bytes of
  // the raw vertices and triangles); smaller leaves cost more memory
  // without a faster query (bench/mesh_bench on FCL's env/rob pair; the
  // figures, from an earlier traversal, are in CHANGELOG.md).
  static constexpr std::int32_t kLeafSize = 4;

  // A node of the bounding-volume hierarchy: an axis-aligned box in the
  // mesh's frame (see mesh.cpp for why boxes), stored in float in units of
  // unit() (box() gives it in doubles), rounded outwards so that it holds
  // every vertex of the triangles below. Nodes are in depth-first order: an
  // inner node's left child is the next node, its right child is `right`.
  // A leaf holds triangle_order()[first .. first + count).
  struct Node {
    std::array<float, 3> lo;
    std::array<float, 3> hi;
    std::int32_t first_or_right = 0;  // leaf: first; inner: right child id
    std::int32_t count = 0;           // leaf: number of triangles (> 0); inner: 0
    bool is_leaf() const { return count > 0; }
  };

  // The mesh as given: vertices and triangles are copied, nothing is
  // merged, removed or reoriented (the hierarchy skips repeats, below). Throws InvalidInput naming the index: no
  // vertices, no triangles, a non-finite coordinate ("vertex 7 has a NaN
  // coordinate"), a coordinate beyond 2^1018 (2.8e306) in magnitude, a vertex index
  // out of range ("triangle 12 refers to vertex 40, but there are 38
  // vertices"), more than 2^31 - 1 vertices or triangles.
  TriangleMesh(std::span<const Vec3> vertices, std::span<const Triangle> triangles);
  // The same from int32 indices (as proxima::PointCloud holds them); a
  // negative index is refused like one out of range.
  TriangleMesh(std::span<const Vec3> vertices,
               std::span<const std::array<std::int32_t, 3>> triangles);

  int vertex_count() const { return static_cast<int>(vertices_.size()); }
  int triangle_count() const { return static_cast<int>(triangles_.size()); }
  std::span<const Vec3> vertices() const { return vertices_; }
  std::span<const Triangle> triangles() const { return triangles_; }
  const Vec3& vertex(int i) const { return vertices_[static_cast<std::size_t>(i)]; }
  const Triangle& triangle(int i) const { return triangles_[static_cast<std::size_t>(i)]; }

  // Triangles of zero area (three collinear or coincident vertices, decided
  // exactly; a repeated index included), in increasing order. They are kept
  // and measured as the segment or point they are.
  std::span<const std::int32_t> degenerate_triangles() const { return degenerate_; }

  // Every edge is shared by exactly two triangles that use it in opposite
  // directions: a closed, consistently oriented surface (which then has an
  // inside). Edges are vertex index pairs (coincident vertices with distinct
  // indices are distinct).
  bool is_closed() const { return closed_; }

  // Largest coordinate magnitude of the vertices: the R of the accuracy
  // standard for the mesh in its own frame.
  double scale() const { return scale_; }

  // A ball holding every vertex (mesh frame): the root box's center and
  // half diagonal. What sweeps, time of impact and piece pruning bound the
  // mesh by.
  const Vec3& center() const { return center_; }
  double bounding_radius() const { return bounding_radius_; }

  // The hierarchy: nodes()[0] is the root. It holds every triangle but
  // repeats: a triangle whose corners are the same points as an earlier
  // one's (by index or coordinates, any order) is left out, as the same
  // surface (triangle_order() then has fewer ids than triangle_count()).
  std::span<const Node> nodes() const { return nodes_; }
  std::span<const std::int32_t> triangle_order() const { return order_; }
  // Node boxes are stored divided by unit(), a power of two >= scale().
  double unit() const { return unit_; }
  // Node i's box in the mesh's frame, in doubles (holds its triangles).
  void box(int i, Vec3& lo, Vec3& hi) const;

  // For each connected component of the surface (triangles sharing a vertex
  // index), one of its vertices: what the inside test of the other body
  // checks.
  std::span<const std::int32_t> component_vertices() const { return component_vertices_; }

  // Whether point p (mesh frame) lies inside this closed mesh: the parity of
  // the crossings of a ray from p, each decided with exact orientation
  // predicates (a ray through an edge or a vertex, or in a triangle's
  // plane, is replaced by another). False for an open mesh, and for a point
  // on the surface. O(log n) typical through the hierarchy.
  bool contains(const Vec3& p) const;

  // The convex hull of the triangles' vertices (mesh frame), built once
  // with the mesh. It holds the surface, so the distance between two hulls
  // is a certified lower bound on the distance between the meshes, and an
  // exact one when the hulls' closest points lie on both surfaces (convex
  // regions facing each other, the common case between a robot's links):
  // the mesh queries use it to stop as soon as a triangle pair reaches it,
  // and to prove pairs of meshes apart without their hierarchies.
  const ConvexPolytope& hull() const { return *hull_; }

  // Bytes held by the mesh (vertices, triangles, hierarchy, order, lists,
  // hull).
  std::size_t memory_bytes() const;

  // An id of this mesh's content, distinct for meshes built separately
  // (copies share it): lets a MeshCache recognize its pair.
  std::uint64_t id() const { return id_; }

 private:
  void build(std::span<const Vec3> vertices);

  std::vector<Vec3> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<std::int32_t> degenerate_;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> order_;
  std::vector<std::int32_t> component_vertices_;
  // Shared by copies (immutable).
  std::shared_ptr<const ConvexPolytope> hull_;
  double scale_ = 0.0;
  double unit_ = 1.0;
  // The root box's center and half diagonal, computed once (every margin
  // query's first test reads them).
  Vec3 center_ = Vec3::Zero();
  double bounding_radius_ = 0.0;
  bool closed_ = false;
  std::uint64_t id_ = 0;
};

}  // namespace proxima
