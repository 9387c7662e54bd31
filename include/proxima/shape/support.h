// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: support functions. The support point of a set in direction d is
// argmax over its vertices of d.x. Two twins: a brute-force scan (the obvious
// one, O(N)) and hill climbing over the vertex adjacency from a hint vertex
// (near O(1) when the hint is the previous answer). Tests compare them.
#pragma once

#include <cstdint>
#include <span>

#include "proxima/shape/polytope.h"

namespace proxima {

// Index of a vertex maximizing dir.dot(vertex); the first one on ties.
// `vertices` must not be empty.
int support_brute_force(std::span<const Vec3> vertices, const Vec3& dir);

// Bodies of at most this many vertices are scanned rather than climbed by
// support_without_hint: the scan is a fixed loop without a branch that
// depends on the data, while a climb ends at a different step every time,
// a mispredicted branch per search, and from a poor start crosses half the
// body (cold queries on random poses, 2000 poses, median of 7: 32 vertices
// 402 -> 380 ns against the seeded climb below, 64 vertices no faster).
inline constexpr int kScanVertices = 32;

// Vertices at evenly spaced ids that seed support_without_hint's climb on
// larger bodies (cold queries at 4096 vertices: 1440 ns from vertex 0,
// 925 from 8 seeds, 830 from 16).
inline constexpr int kSupportSeeds = 16;

// Index of a vertex maximizing dir.dot(vertex) when no hint is known (a
// cold start): support_brute_force on bodies of up to kScanVertices
// vertices; on larger ones, support_hill_climb from the best of
// kSupportSeeds vertices at evenly spaced ids (vertex 0 first), which on a
// round body is already near the support point, where a climb from vertex
// 0 crosses half of it. Exact like the climb (any start reaches a maximizer).
int support_without_hint(const ConvexPolytope& polytope, const Vec3& dir);

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
