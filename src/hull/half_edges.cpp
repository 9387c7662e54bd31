// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): see half_edges.h.
#include "hull/half_edges.h"

namespace proxima::detail {

// Vertex adjacency from face cycles, each vertex's neighbours in
// counter-clockwise order seen from outside. Rotation: if v -> w is in face F
// and u -> v precedes it in F, then v -> u is the next edge counter-clockwise
// about v (for a counter-clockwise polygon the interior angle at v sweeps
// from the outgoing to the incoming edge), and it lies in the face across
// u -> v. Returns false if the cycles are not a closed surface whose every
// vertex has one disk of faces around it.
bool build_adjacency(const Cycles& cycles, Index vertex_count, Adjacency& out) {
  const HalfEdges he(cycles, vertex_count);
  if (!he.consistent()) return false;
  out.offsets.assign(1, 0);
  out.neighbors.clear();
  out.faces.clear();
  out.neighbors.reserve(cycles.vertices.size());
  out.faces.reserve(cycles.vertices.size());
  for (Index v = 0; v < vertex_count; ++v) {
    const auto outgoing = he.outgoing(v);
    if (outgoing.empty()) return false;  // a vertex on no face
    const Index start = outgoing.front();
    Index h = start;
    for (std::size_t step = 0; step < outgoing.size(); ++step) {
      if (step > 0 && h == start) return false;  // more than one fan around v
      out.neighbors.push_back(he.target(h));
      out.faces.push_back(he.face(h));
      h = he.find(v, he.source(he.prev(h)));
      if (h < 0) return false;
    }
    if (h != start) return false;
    out.offsets.push_back(static_cast<Index>(out.neighbors.size()));
  }
  return true;
}

}  // namespace proxima::detail
