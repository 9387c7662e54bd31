// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the closed surface P of an expanding
// polytope inside M = A - B (src/penetration/expanding_polytope.h), kept
// in a PenetrationCache between queries so that a B that turned does not
// start over (src/penetration/tracked_expansion.h).
//
// P's vertices are named by their pairs (i, j) of vertex ids, the point
// a_i - b_j of M: they stay points of M under any pose of B, and a query
// places them again at its own pose. Its triangles keep their
// adjacency (the integer bookkeeping that makes P a closed surface) and
// their keys at the anchor, the pose where every one of them was last
// evaluated.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "proxima/core/types.h"

namespace proxima::detail {

struct ExpansionSurface {
  struct Triangle {
    std::array<std::int32_t, 3> v;         // counter-clockwise seen from outside
    std::array<std::int32_t, 3> adjacent;  // across the edge v[k] -> v[k + 1]
    // At the anchor: the rounded unit normal, within normal_error of the
    // exact one, and the plane's offset less its rounding bound (A's
    // units), a lower bound on the exact plane's offset.
    Vec3 normal = Vec3::Zero();
    double normal_error = 0.0;
    double key = 0.0;
  };
  std::vector<std::array<std::int32_t, 2>> vertices;  // (vertex of A, vertex of B)
  std::vector<Triangle> triangles;
  // B's pose in A's frame at the anchor (A's units), and the standard's R
  // there (the vertices' placement rounded relative to it).
  Mat3 rotation = Mat3::Zero();
  Vec3 translation = Vec3::Zero();
  double magnitude = 0.0;

  bool empty() const { return triangles.empty(); }
  void clear() {
    vertices.clear();
    triangles.clear();
  }
};

}  // namespace proxima::detail
