// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 4: support functions. The support point of a set in direction d is
// argmax over its vertices of d.x. Two twins: a brute-force scan (the obvious
// one, O(N)) and hill climbing over the vertex adjacency from a hint vertex
// (near O(1) when the hint is the previous answer). Tests compare them.
#pragma once

#include "proxima/polytope.h"

#include <cstdint>
#include <span>

namespace proxima {

// Index of a vertex maximizing dir.dot(vertex); the first one on ties.
// `vertices` must not be empty.
int support_brute_force(std::span<const Vec3> vertices, const Vec3& dir);

// Index of a vertex maximizing dir.dot(vertex), found by walking from `hint`
// to a neighbour with a strictly larger dot product until none is larger. On
// a convex polytope with its true edges, a vertex with no improving edge is a
// global maximum (the tangent cone at a vertex is spanned by its edges), so
// the walk is exact, plateaus of coplanar faces included. `hint` out of range
// is treated as vertex 0.
//
// Inline: it runs twice per tracked query, whose budget is tens of
// nanoseconds. Steepest ascent over the hull's true edges. Why it is exact: at a vertex v
// that is not a maximizer of d.x, the tangent cone of the polytope at v is
// spanned by the edge directions w - v of its neighbours, so some edge has
// d.(w - v) > 0; a vertex with no strictly improving neighbour is therefore
// a global maximizer, on a plateau (a face or edge orthogonal to d) too. The
// dot product rises strictly at every step, so the walk cannot cycle and
// ends after at most vertex_count steps. Taking the best neighbour (rather
// than the first improving one) shortens the walk from a cold hint on round
// bodies. Both twins round d.x the same way, so they agree exactly except
// where exact values differ by less than the rounding of d.x (see the test).
inline int support_hill_climb(const ConvexPolytope& polytope, const Vec3& dir, int hint) {
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
