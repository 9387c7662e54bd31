// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: whether an input surface is convex (surface_is_convex, see
// include/proxima/io.h).
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "proxima/io.h"

namespace proxima {

namespace {

// The hull vertex of largest d.x, by hill climbing from `start` along the
// hull's edges: on a convex polytope a local maximum is global.
int climb(const ConvexPolytope& hull, const Vec3& d, int start) {
  int v = start;
  double best = d.dot(hull.vertex(v));
  for (bool moved = true; moved;) {
    moved = false;
    for (const std::int32_t w : hull.neighbors(v)) {
      const double value = d.dot(hull.vertex(w));
      if (value > best) {
        best = value;
        v = w;
        moved = true;
      }
    }
  }
  return v;
}

class SurfaceTest {
 public:
  explicit SurfaceTest(const ConvexPolytope& hull)
      : hull_(hull), tolerance_(kConvexSurfaceTolerance * hull.scale()) {
    planes_.reserve(static_cast<std::size_t>(hull.face_count()));
    for (int f = 0; f < hull.face_count(); ++f) planes_.push_back(hull.face_plane(f));
  }

  // Whether all of `corners` lie within the tolerance of one facet's plane.
  // Fast path: the facets around the hull vertex extreme in the direction
  // `hint` (the triangle's normal); then every facet.
  template <std::size_t N>
  bool on_one_facet(const std::array<Vec3, N>& corners, const Vec3& hint) {
    if (hint != Vec3::Zero()) {
      start_ = climb(hull_, hint, start_);
      const auto faces = hull_.adjacency_faces();
      const auto b =
          static_cast<std::size_t>(hull_.adjacency_offsets()[static_cast<std::size_t>(start_)]);
      const auto e =
          static_cast<std::size_t>(hull_.adjacency_offsets()[static_cast<std::size_t>(start_) + 1]);
      for (std::size_t k = b; k < e; ++k) {
        if (faces[k] >= 0 && on_plane(planes_[static_cast<std::size_t>(faces[k])], corners))
          return true;
      }
    }
    return std::any_of(planes_.begin(), planes_.end(),
                       [&](const Plane& plane) { return on_plane(plane, corners); });
  }

 private:
  // The corners are in the hull, so at or below every facet's plane up to
  // rounding: being above -tolerance is being on it.
  template <std::size_t N>
  bool on_plane(const Plane& plane, const std::array<Vec3, N>& corners) const {
    return std::all_of(corners.begin(), corners.end(), [&](const Vec3& p) {
      return plane.normal.dot(p) - plane.offset >= -tolerance_;
    });
  }

  const ConvexPolytope& hull_;
  double tolerance_;
  std::vector<Plane> planes_;
  int start_ = 0;
};

}  // namespace

bool surface_is_convex(const ConvexPolytope& hull, std::span<const Vec3> points,
                       std::span<const std::array<std::int32_t, 3>> triangles) {
  if (hull.dimension() < 3) return true;
  SurfaceTest test(hull);
  if (!triangles.empty()) {
    for (const auto& t : triangles) {
      for (const std::int32_t i : t) {
        if (i < 0 || static_cast<std::size_t>(i) >= points.size()) {
          throw InvalidInput("surface_is_convex: triangle index " + std::to_string(i) +
                             " outside the " + std::to_string(points.size()) + " points");
        }
      }
      const std::array<Vec3, 3> c = {points[static_cast<std::size_t>(t[0])],
                                     points[static_cast<std::size_t>(t[1])],
                                     points[static_cast<std::size_t>(t[2])]};
      if (!test.on_one_facet(c, (c[1] - c[0]).cross(c[2] - c[0]))) return false;
    }
    return true;
  }
  std::vector<bool> is_vertex(points.size(), false);
  for (const std::int32_t i : hull.input_index()) {
    if (i >= 0 && static_cast<std::size_t>(i) < points.size())
      is_vertex[static_cast<std::size_t>(i)] = true;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_vertex[i] &&
        !test.on_one_facet(std::array<Vec3, 1>{points[i]}, points[i] - hull.centroid()))
      return false;
  }
  return true;
}

}  // namespace proxima
