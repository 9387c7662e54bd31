// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): face cycles (compressed rows), half-edges over them,
// and the vertex adjacency derived from them.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <vector>

namespace proxima::detail {

using Index = std::int32_t;

// Face cycles in CSR form over vertex ids 0 .. vertex_count-1.
struct Cycles {
  std::vector<Index> offsets{0};
  std::vector<Index> vertices;

  Index count() const { return static_cast<Index>(offsets.size()) - 1; }
  Index size(Index f) const {
    return offsets[static_cast<std::size_t>(f) + 1] - offsets[static_cast<std::size_t>(f)];
  }
  Index at(Index f, Index i) const {
    return vertices[static_cast<std::size_t>(offsets[static_cast<std::size_t>(f)] + i)];
  }
  template <class Range>
  void add(const Range& cycle) {
    vertices.insert(vertices.end(), cycle.begin(), cycle.end());
    offsets.push_back(static_cast<Index>(vertices.size()));
  }
};

// Half-edge h of face f at position i runs at(f, i) -> at(f, i + 1); face f
// is on its left. Half-edges are indexed by their slot in Cycles::vertices.
// They are also sorted by (source, target) in `by_source` for lookups.
class HalfEdges {
 public:
  HalfEdges(const Cycles& cycles, Index vertex_count) : cycles_(cycles) {
    const auto h_count = cycles.vertices.size();
    face_.resize(h_count);
    next_.resize(h_count);
    prev_.resize(h_count);
    for (Index f = 0; f < cycles.count(); ++f) {
      const Index b = cycles.offsets[static_cast<std::size_t>(f)], n = cycles.size(f);
      for (Index i = 0; i < n; ++i) {
        const auto h = static_cast<std::size_t>(b + i);
        face_[h] = f;
        next_[h] = b + (i + 1) % n;
        prev_[h] = b + (i + n - 1) % n;
      }
    }
    // Counting sort by source, then by target within a source.
    source_offsets_.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
    for (const Index v : cycles.vertices) ++source_offsets_[static_cast<std::size_t>(v) + 1];
    std::partial_sum(source_offsets_.begin(), source_offsets_.end(), source_offsets_.begin());
    by_source_.resize(h_count);
    std::vector<Index> fill(source_offsets_.begin(), source_offsets_.end() - 1);
    for (std::size_t h = 0; h < h_count; ++h) {
      by_source_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cycles.vertices[h])]++)] =
          static_cast<Index>(h);
    }
    for (Index v = 0; v < vertex_count; ++v) {
      auto first = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v)];
      auto last = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v) + 1];
      std::sort(first, last, [&](Index l, Index r) { return target(l) < target(r); });
      for (auto it = first; it != last && it + 1 != last; ++it) {
        if (target(*it) == target(*(it + 1))) consistent_ = false;  // a directed edge twice
      }
    }
    twin_.resize(h_count);
    for (std::size_t h = 0; h < h_count; ++h) {
      twin_[h] = find(target(static_cast<Index>(h)), source(static_cast<Index>(h)));
      if (twin_[h] < 0) consistent_ = false;  // no reverse edge
    }
  }

  // False when some directed edge appears twice or has no reverse: the
  // cycles do not bound a closed oriented surface.
  bool consistent() const { return consistent_; }

  Index source(Index h) const { return cycles_.vertices[static_cast<std::size_t>(h)]; }
  Index target(Index h) const {
    return cycles_.vertices[static_cast<std::size_t>(next_[static_cast<std::size_t>(h)])];
  }
  Index face(Index h) const { return face_[static_cast<std::size_t>(h)]; }
  Index prev(Index h) const { return prev_[static_cast<std::size_t>(h)]; }
  Index twin(Index h) const { return twin_[static_cast<std::size_t>(h)]; }

  // The half-edge v -> w, or -1.
  Index find(Index v, Index w) const {
    const auto first = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v)];
    const auto last = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v) + 1];
    const auto it =
        std::lower_bound(first, last, w, [&](Index h, Index t) { return target(h) < t; });
    return it != last && target(*it) == w ? *it : -1;
  }

  std::span<const Index> outgoing(Index v) const {
    const auto b = static_cast<std::size_t>(source_offsets_[static_cast<std::size_t>(v)]);
    const auto e = static_cast<std::size_t>(source_offsets_[static_cast<std::size_t>(v) + 1]);
    return std::span<const Index>(by_source_).subspan(b, e - b);
  }

 private:
  const Cycles& cycles_;
  std::vector<Index> face_, next_, prev_, twin_;
  std::vector<Index> source_offsets_, by_source_;
  bool consistent_ = true;
};

struct Adjacency {
  std::vector<Index> offsets, neighbors, faces;
};

// Vertex adjacency from face cycles, each vertex's neighbours in
// counter-clockwise order seen from outside. Rotation: if v -> w is in face F
// and u -> v precedes it in F, then v -> u is the next edge counter-clockwise
// about v (for a counter-clockwise polygon the interior angle at v sweeps
// from the outgoing to the incoming edge), and it lies in the face across
// u -> v. Returns false if the cycles are not a closed surface whose every
// vertex has one disk of faces around it.
bool build_adjacency(const Cycles& cycles, Index vertex_count, Adjacency& out);

}  // namespace proxima::detail
