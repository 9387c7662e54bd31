// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: support functions, the brute-force scan and hill climbing.
#include "proxima/shape/support.h"

#include <cstddef>
#include <cstdint>

namespace proxima {

int support_brute_force(std::span<const Vec3> vertices, const Vec3& dir) {
  int best = 0;
  double best_dot = dir.dot(vertices[0]);
  for (std::size_t i = 1; i < vertices.size(); ++i) {
    const double d = dir.dot(vertices[i]);
    if (d > best_dot) {  // strict: the first index wins ties
      best_dot = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

int support_without_hint(const ConvexPolytope& polytope, const Vec3& dir) {
  const int n = polytope.vertex_count();
  if (n <= kScanVertices) return support_brute_force(polytope.vertices(), dir);
  const Vec3* vertices = polytope.vertices().data();
  const int stride = n / kSupportSeeds;  // >= 1
  int seed = 0;
  double seed_dot = dir.dot(vertices[0]);
  for (int i = stride; i < n; i += stride) {
    const double d = dir.dot(vertices[i]);
    if (d > seed_dot) {
      seed_dot = d;
      seed = i;
    }
  }
  return support_hill_climb(polytope, dir, seed);
}

}  // namespace proxima
