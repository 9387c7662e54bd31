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
// body. Cold queries on random poses (bench/distance_bench) are faster
// scanned up to 32 vertices, no faster at 64.
inline constexpr int kScanVertices = 32;
// Larger bodies have the table of ConvexPolytope::support_start.
static_assert(kScanVertices == ConvexPolytope::kTableMinVertices);

// Vertices at evenly spaced ids that seed support_without_hint's climb on
// larger bodies: more seeds start the climb nearer the support point, at
// the cost of a short scan (16 beat 8 and a start at vertex 0 in cold
// queries at 4096 vertices, bench/distance_bench).
inline constexpr int kSupportSeeds = 16;

// Index of a vertex maximizing dir.dot(vertex) when no hint is known (a
// cold start): support_brute_force on bodies of up to kScanVertices
// vertices; on larger ones, support_hill_climb from the polytope's table
// (support_start: the support along the centre of dir's cell, a step or
// two from dir's on a round body, where a climb from vertex 0 crosses half
// of it), or, for a direction the table refuses, from the best of
// kSupportSeeds vertices at evenly spaced ids (vertex 0 first). Exact like
// the climb (any start reaches a maximizer).
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

// support_hill_climb made robust to rounding on nearly flat vertices: the
// index of a vertex whose value d.x is within 2 delta of the exact maximum,
// delta = gamma_3 |d|_1 scale() the rounding bound of one computed d.x.
//
// Why the plain climb is not enough: its exactness argument holds for
// exact values. At a vertex whose tangent cone is nearly flat (a hull of
// nearly coplanar points: a prism's facet split by rounding into many
// faces) every edge may rise by less than the rounding of d.x, and the
// climb then stops there however far below the maximum it is: climbing
// from the bottom of such a facet along its inward normal stopped 6e-6
// below the top on a body of size 2e-5 (PenetrationRegression.
// PrismsWithCoplanarFacetsAtSmallScale).
//
// The repair: after the climb stops at v, the vertices connected to v
// through vertices of computed value >= d.v - tie (tie = 2 delta; d.v the
// computed value of v) are searched; one whose computed value is above d.v
// restarts the climb from it, and when there is none, v is returned.
// Proof that v is then within 2 delta of the maximum: let y be the vertex
// of that region with the largest exact value. If y were not a maximizer,
// an edge y-z would rise exactly (the tangent-cone argument of
// support_hill_climb), so z's computed value would be above exact(z) -
// delta > exact(y) - delta >= exact(v) - delta >= d.v - tie, and z would be
// in the region, above y. So y is a maximizer, and since no vertex of the
// region is computed above v, exact(v) >= d.v - delta >= computed(y) -
// delta >= exact(y) - 2 delta. The computed values rise strictly at every
// restart, so the loop ends.
//
// Cost over support_hill_climb: nothing when no neighbour of the climb's
// last vertex is within the tie (the climb already read them); else a walk
// over the tie region (a face of the hull when d is its normal).
int support_hill_climb_through_plateaus(const ConvexPolytope& polytope, const Vec3& dir, int hint);

}  // namespace proxima
