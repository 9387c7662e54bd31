// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 4: support functions, the brute-force scan and hill climbing.
#include "proxima/support.h"

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

// Steepest ascent over the hull's true edges. Why it is exact: at a vertex v
// that is not a maximizer of d.x, the tangent cone of the polytope at v is
// spanned by the edge directions w - v of its neighbours, so some edge has
// d.(w - v) > 0; a vertex with no strictly improving neighbour is therefore
// a global maximizer, on a plateau (a face or edge orthogonal to d) too. The
// dot product rises strictly at every step, so the walk cannot cycle and
// ends after at most vertex_count steps. Taking the best neighbour (rather
// than the first improving one) shortens the walk from a cold hint on round
// bodies. Both twins round d.x the same way, so they agree exactly except
// where exact values differ by less than the rounding of d.x (see the test).
int support_hill_climb(const ConvexPolytope& polytope, const Vec3& dir, int hint) {
  const int n = polytope.vertex_count();
  const Vec3* vertices = polytope.vertices().data();
  const std::int32_t* offsets = polytope.adjacency_offsets().data();
  const std::int32_t* adjacency = polytope.adjacency().data();
  int v = hint >= 0 && hint < n ? hint : 0;
  double v_dot = dir.dot(vertices[v]);
  for (;;) {
    int next = -1;
    double next_dot = v_dot;
    for (std::int32_t k = offsets[v], end = offsets[v + 1]; k < end; ++k) {
      const std::int32_t w = adjacency[k];
      const double d = dir.dot(vertices[w]);
      if (d > next_dot) {
        next_dot = d;
        next = w;
      }
    }
    if (next < 0) return v;
    v = next;
    v_dot = next_dot;
  }
}

}  // namespace proxima
