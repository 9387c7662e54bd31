// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): see face_cleaning.h.
#include "hull/face_cleaning.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include "core/power_of_two.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima::detail {
namespace {

// Union-find over faces.
class Groups {
 public:
  explicit Groups(Index n) : parent_(static_cast<std::size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  Index find(Index f) {
    while (parent_[static_cast<std::size_t>(f)] != f) {
      parent_[static_cast<std::size_t>(f)] =
          parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(f)])];
      f = parent_[static_cast<std::size_t>(f)];
    }
    return f;
  }
  void unite(Index a, Index b) {
    a = find(a), b = find(b);
    if (a != b) parent_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<Index> parent_;
};

// Three vertices of face f that are not collinear (exactly), or nothing.
// Spread out (farthest-point choice in double) to keep the filter effective.
bool face_triangle(const Cycles& faces, Index f, std::span<const Vec3> pts,
                   std::span<const Vec3> scaled, std::array<Index, 3>& tri) {
  const Index n = faces.size(f);
  const Index a = faces.at(f, 0);
  const Vec3& sa = scaled[static_cast<std::size_t>(a)];
  Index b = faces.at(f, 1);
  double best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const Index v = faces.at(f, i);
    const double d = (scaled[static_cast<std::size_t>(v)] - sa).squaredNorm();
    if (d > best) best = d, b = v;
  }
  const Vec3 line = scaled[static_cast<std::size_t>(b)] - sa;
  Index c = -1;
  best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const Index v = faces.at(f, i);
    if (v == b || collinear3d(pts[static_cast<std::size_t>(a)], pts[static_cast<std::size_t>(b)],
                              pts[static_cast<std::size_t>(v)])) {
      continue;
    }
    const double d = line.cross(scaled[static_cast<std::size_t>(v)] - sa).squaredNorm();
    if (d > best) best = d, c = v;
  }
  if (c < 0) return false;
  tri = {a, b, c};
  return true;
}


// The groups of coplanar neighbour faces that merge (union-find over face
// ids), and the convexity verdict of the edges between faces (see
// clean_faces).
Groups coplanar_groups(const Cycles& raw, const HalfEdges& he, std::span<const Vec3> pts,
                       std::span<const Vec3> scaled, bool& proven_convex) {
  const Index face_count = raw.count();
  const auto at = [&](Index v) -> const Vec3& { return pts[static_cast<std::size_t>(v)]; };
  Groups groups(face_count);
  // A face is planar when all its vertices lie on the plane of a spread
  // triangle of them (exact; zero is the expected answer, so this is where
  // the exact fallback runs, once per vertex of a non-triangular face).
  std::vector<std::array<Index, 3>> tri(static_cast<std::size_t>(face_count));
  std::vector<bool> planar(static_cast<std::size_t>(face_count), false);
  for (Index f = 0; f < face_count; ++f) {
    auto& t = tri[static_cast<std::size_t>(f)];
    if (!face_triangle(raw, f, pts, scaled, t)) continue;
    bool flat = true;
    for (Index i = 0; i < raw.size(f) && flat; ++i) {
      const Index v = raw.at(f, i);
      flat =
          v == t[0] || v == t[1] || v == t[2] || side3d(at(t[0]), at(t[1]), at(t[2]), at(v)) == 0;
    }
    planar[static_cast<std::size_t>(f)] = flat;
    proven_convex = proven_convex && flat;
  }
  // Planar neighbours f and g share the edge s -> t (in f; t -> s in g).
  // With y a vertex of f and x one of g off the line s t, side3d(s, t, y, x)
  // is the edge's convexity: negative convex, zero coplanar, positive
  // reflex (a defect of the surface). Coplanar faces merge when, in a projection
  // that keeps the plane's orientation, x and y lie on opposite sides of
  // the edge.
  for (Index h = 0; h < static_cast<Index>(raw.vertices.size()); ++h) {
    const Index twin = he.twin(h);
    if (twin < 0) continue;
    const Index f = he.face(h), g = he.face(twin);
    if (f >= g) continue;
    if (!planar[static_cast<std::size_t>(f)] || !planar[static_cast<std::size_t>(g)]) continue;
    const Index s = he.source(h), t = he.target(h);
    const auto off_line = [&](Index face) {
      for (const Index v : tri[static_cast<std::size_t>(face)]) {
        if (v != s && v != t && !collinear3d(at(s), at(t), at(v))) return v;
      }
      return Index{-1};
    };
    const Index y = off_line(f), x = off_line(g);
    if (x < 0 || y < 0) {
      proven_convex = false;
      continue;
    }
    const int side = side3d(at(s), at(t), at(y), at(x));
    if (side != 0) {
      proven_convex = proven_convex && side < 0;
      continue;
    }
    int y_side = 0, x_side = 0;
    for (int k = 0; k < 3 && y_side == 0; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      y_side = orient2d(at(s)[i], at(s)[j], at(t)[i], at(t)[j], at(y)[i], at(y)[j]);
      x_side = orient2d(at(s)[i], at(s)[j], at(t)[i], at(t)[j], at(x)[i], at(x)[j]);
    }
    if (x_side == -y_side) {
      groups.unite(f, g);
    } else {
      proven_convex = false;  // folded onto itself
    }
  }
  return groups;
}

// One face per group: the group's boundary chained into one cycle, or its
// facets unmerged when the boundary is not one simple cycle.
Cycles merge_groups(const Cycles& raw, const HalfEdges& he, Groups& groups, bool& proven_convex) {
  const Index face_count = raw.count();
  // Boundary cycle of each group: its half-edges whose twin lies in another
  // group, chained head to tail. A group that does not chain into one simple
  // cycle keeps its facets unmerged.
  std::vector<std::vector<Index>> members(static_cast<std::size_t>(face_count));
  for (Index f = 0; f < face_count; ++f) {
    const Index root = groups.find(f);
    if (root != f) members[static_cast<std::size_t>(root)].push_back(f);
  }
  Cycles merged;
  const auto add_own = [&](Index f) {
    const auto first = raw.vertices.begin() + raw.offsets[static_cast<std::size_t>(f)];
    merged.add(std::span<const Index>(&*first, static_cast<std::size_t>(raw.size(f))));
  };
  std::vector<std::pair<Index, Index>> boundary;  // (source, target)
  std::vector<Index> chain;
  for (Index root = 0; root < face_count; ++root) {
    if (groups.find(root) != root) continue;
    auto& group = members[static_cast<std::size_t>(root)];
    if (group.empty()) {
      add_own(root);
      continue;
    }
    group.push_back(root);
    boundary.clear();
    for (const Index f : group) {
      for (Index i = 0; i < raw.size(f); ++i) {
        const Index h = raw.offsets[static_cast<std::size_t>(f)] + i;
        const Index twin = he.twin(h);
        if (twin < 0 || groups.find(he.face(twin)) != root)
          boundary.emplace_back(he.source(h), he.target(h));
      }
    }
    std::sort(boundary.begin(), boundary.end());
    bool simple = boundary.size() >= 3;
    for (std::size_t k = 1; k < boundary.size() && simple; ++k)
      simple = boundary[k].first != boundary[k - 1].first;
    chain.clear();
    if (simple) {
      const auto next_of = [&](Index v) {
        const auto it = std::lower_bound(boundary.begin(), boundary.end(),
                                         std::pair<Index, Index>(v, INT32_MIN));
        return it != boundary.end() && it->first == v ? it->second : -1;
      };
      Index v = boundary.front().first;
      do {
        chain.push_back(v);
        v = next_of(v);
      } while (v >= 0 && v != boundary.front().first && chain.size() <= boundary.size());
      simple = v == boundary.front().first && chain.size() == boundary.size();
    }
    if (simple) {
      merged.add(chain);
    } else {
      proven_convex = false;
      for (const Index f : group) add_own(f);
    }
  }
  return merged;
}

// `merged` without the vertices that lie inside an edge of two faces.
Cycles drop_edge_vertices(const Cycles& merged, Index point_count, std::span<const Vec3> pts) {
  const auto at = [&](Index v) -> const Vec3& { return pts[static_cast<std::size_t>(v)]; };
  // Drop vertices inside edges. The cycles become doubly linked lists over
  // nodes (one node per slot of merged.vertices); a vertex on exactly two
  // faces remembers its two nodes.
  const auto node_count = merged.vertices.size();
  std::vector<Index> next(node_count), prev(node_count), node_face(node_count);
  std::vector<Index> face_size(static_cast<std::size_t>(merged.count()));
  for (Index f = 0; f < merged.count(); ++f) {
    const Index b = merged.offsets[static_cast<std::size_t>(f)], n = merged.size(f);
    face_size[static_cast<std::size_t>(f)] = n;
    for (Index i = 0; i < n; ++i) {
      next[static_cast<std::size_t>(b + i)] = b + (i + 1) % n;
      prev[static_cast<std::size_t>(b + i)] = b + (i + n - 1) % n;
      node_face[static_cast<std::size_t>(b + i)] = f;
    }
  }
  std::vector<Index> occurrence_count(static_cast<std::size_t>(point_count), 0);
  std::vector<std::array<Index, 2>> occurrence(static_cast<std::size_t>(point_count), {-1, -1});
  for (std::size_t node = 0; node < node_count; ++node) {
    const auto v = static_cast<std::size_t>(merged.vertices[node]);
    if (occurrence_count[v] < 2)
      occurrence[v][static_cast<std::size_t>(occurrence_count[v])] = static_cast<Index>(node);
    ++occurrence_count[v];
  }
  std::vector<bool> alive(node_count, true);
  std::vector<Index> work;
  for (Index v = 0; v < point_count; ++v) {
    if (occurrence_count[static_cast<std::size_t>(v)] == 2) work.push_back(v);
  }
  const auto vertex_of = [&](Index node) {
    return merged.vertices[static_cast<std::size_t>(node)];
  };
  while (!work.empty()) {
    const Index v = work.back();
    work.pop_back();
    if (occurrence_count[static_cast<std::size_t>(v)] != 2) continue;
    const auto [n0, n1] = occurrence[static_cast<std::size_t>(v)];
    const Index u = vertex_of(prev[static_cast<std::size_t>(n0)]);
    const Index w = vertex_of(next[static_cast<std::size_t>(n0)]);
    // The other face must run w -> v -> u: v sits on one edge of both.
    if (vertex_of(prev[static_cast<std::size_t>(n1)]) != w ||
        vertex_of(next[static_cast<std::size_t>(n1)]) != u)
      continue;
    if (face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(n0)])] <= 3 ||
        face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(n1)])] <= 3) {
      continue;
    }
    if (!collinear3d(at(u), at(v), at(w))) continue;
    for (const Index node : {n0, n1}) {
      const Index before = prev[static_cast<std::size_t>(node)],
                  after = next[static_cast<std::size_t>(node)];
      next[static_cast<std::size_t>(before)] = after;
      prev[static_cast<std::size_t>(after)] = before;
      alive[static_cast<std::size_t>(node)] = false;
      --face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(node)])];
    }
    occurrence_count[static_cast<std::size_t>(v)] = 0;
    work.push_back(u);  // their neighbours changed: check them again
    work.push_back(w);
  }

  Cycles out;
  out.vertices.reserve(node_count);
  for (Index f = 0; f < merged.count(); ++f) {
    Index start = merged.offsets[static_cast<std::size_t>(f)];
    while (!alive[static_cast<std::size_t>(start)]) ++start;  // some node survives: faces keep >= 3
    Index node = start;
    do {
      out.vertices.push_back(vertex_of(node));
      node = next[static_cast<std::size_t>(node)];
    } while (node != start);
    out.offsets.push_back(static_cast<Index>(out.vertices.size()));
  }
  return out;
}

}  // namespace

// Exact cleaning of a closed triangulated (or polygonal) surface, in the
// coordinates of the given doubles:
//  - neighbouring facets that are exactly coplanar (and lie on either side of
//    their common edge, not folded) become one face: the triangles of a
//    square;
//  - a vertex on exactly two faces and exactly collinear with its two
//    neighbours along them lies inside an edge: it is not an extreme point and
//    is dropped from both cycles (a cube's edge midpoints).
// A vertex strictly inside a face disappears with the merge, because it is on
// no boundary cycle any more.
//
// `proven_convex` tells whether the result is exactly a convex polytope's
// boundary: a closed, consistently oriented surface whose faces are planar
// and whose every edge is exactly convex (x strictly below the plane of the
// face across the edge). A closed surface that is locally convex at every
// edge bounds a convex body, so no global test is needed.
Cycles clean_faces(const Cycles& raw, Index point_count, std::span<const Vec3> pts,
                   std::span<const Vec3> scaled, bool& proven_convex) {
  const HalfEdges he(raw, point_count);
  proven_convex = he.consistent();
  Groups groups = coplanar_groups(raw, he, pts, scaled, proven_convex);
  const Cycles merged = merge_groups(raw, he, groups, proven_convex);
  return drop_edge_vertices(merged, point_count, pts);
}

}  // namespace proxima::detail
