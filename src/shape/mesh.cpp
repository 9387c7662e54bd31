// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Triangle meshes: the build (validation, degenerate triangles, closedness,
// components, the hierarchy) and the inside test. The distance queries are
// in mesh_distance.cpp.
#include "proxima/shape/mesh.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <string>

#include "core/magnitude_limit.h"
#include "core/power_of_two.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima {
namespace {

// Coordinates beyond the one limit of every body (magnitude_limit.h) are
// refused: the queries scale both meshes by a power of two of their
// magnitude, and the inside test's rays reach 4 times it.
using detail::kMaxMagnitude;

std::atomic<std::uint64_t> next_mesh_id{1};

std::string vertex_problem(std::size_t i, const Vec3& v) {
  const bool nan = std::isnan(v.x()) || std::isnan(v.y()) || std::isnan(v.z());
  return "TriangleMesh: vertex " + std::to_string(i) + " has " +
         (nan ? "a NaN coordinate" : "an infinite coordinate");
}

// Float bounds of a double interval, rounded outwards.
float float_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float float_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Floats: they only order the triangles and rank the splits (the node boxes
// are computed from the vertices in doubles); half the bytes of doubles for
// nth_element to move, which the build of a large mesh spends its time on.
struct BuildItem {
  Eigen::Vector3f centroid;  // in units of the mesh's unit (|.| <= 1)
  std::int32_t triangle;
  Eigen::Vector3f lo, hi;  // the triangle's box, same units
};

struct Builder {
  std::span<const Vec3> vertices;
  std::span<const TriangleMesh::Triangle> triangles;
  std::vector<BuildItem> items;
  std::vector<TriangleMesh::Node>& nodes;
  // Sample size of the split search in large ranges, and its buffer.
  static constexpr std::size_t kSplitSample = 4096;
  std::vector<BuildItem> sample;
  double inv_unit;

  // Builds the subtree over items[first, last), returns its box (units).
  void build(std::int32_t first, std::int32_t last, Vec3& lo, Vec3& hi) {
    const auto id = static_cast<std::size_t>(nodes.size());
    nodes.emplace_back();
    if (last - first <= TriangleMesh::kLeafSize) {
      lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      hi = -lo;
      for (std::int32_t k = first; k < last; ++k) {
        for (const std::uint32_t v : triangles[static_cast<std::size_t>(items[k].triangle)]) {
          const Vec3 p = vertices[v] * inv_unit;
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
      }
      store(id, lo, hi);
      nodes[id].first_or_right = first;
      nodes[id].count = last - first;
      return;
    }
    // Median split of the centroids (equal halves: full leaves, so the node
    // count and the memory stay fixed) along the axis whose two halves have
    // the smallest boxes (sum of their edge lengths), rather than the longest
    // axis of the centroids' box: env's large slanted triangles are what the
    // longest axis split badly, and the smaller halves let the query prune
    // more node and triangle pairs (bench/mesh_bench, env/rob).
    const std::int32_t mid = first + (last - first) / 2;
    const auto by_axis = [](int axis) {
      return [axis](const BuildItem& x, const BuildItem& y) {
        return x.centroid[axis] < y.centroid[axis];
      };
    };
    // The axis is chosen on the range itself, or on an even sample of it
    // when large (the top levels of a big mesh: the choice needs only the
    // halves' rough boxes, and three trial partitions of the whole range
    // would dominate the build of a large mesh).
    std::span<BuildItem> trial(items.data() + first, static_cast<std::size_t>(last - first));
    if (trial.size() > kSplitSample) {
      sample.clear();
      const std::size_t stride = trial.size() / kSplitSample;
      for (std::size_t k = 0; k < trial.size(); k += stride) sample.push_back(trial[k]);
      trial = sample;
    }
    const auto extent = [](std::span<const BuildItem> part) {
      Eigen::Vector3f blo = part[0].lo, bhi = part[0].hi;
      for (const BuildItem& item : part) {
        blo = blo.cwiseMin(item.lo);
        bhi = bhi.cwiseMax(item.hi);
      }
      return static_cast<double>((bhi - blo).sum());
    };
    const std::size_t half = trial.size() / 2;
    int axis = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      std::nth_element(trial.begin(), trial.begin() + static_cast<std::ptrdiff_t>(half),
                       trial.end(), by_axis(k));
      const double cost = extent(trial.first(half)) + extent(trial.subspan(half));
      if (cost < best_cost) best_cost = cost, axis = k;
    }
    if (trial.data() != items.data() + first || axis != 2) {
      std::nth_element(items.begin() + first, items.begin() + mid, items.begin() + last,
                       by_axis(axis));
    }
    Vec3 llo, lhi, rlo, rhi;
    build(first, mid, llo, lhi);
    nodes[id].first_or_right = static_cast<std::int32_t>(nodes.size());
    build(mid, last, rlo, rhi);
    lo = llo.cwiseMin(rlo);
    hi = lhi.cwiseMax(rhi);
    store(id, lo, hi);
    nodes[id].count = 0;
  }

  void store(std::size_t id, const Vec3& lo, const Vec3& hi) {
    for (int k = 0; k < 3; ++k) {
      nodes[id].lo[static_cast<std::size_t>(k)] = float_down(lo[k]);
      nodes[id].hi[static_cast<std::size_t>(k)] = float_up(hi[k]);
    }
  }
};

// Union-find over vertex ids with path halving.
std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    auto& p = parent[static_cast<std::size_t>(x)];
    p = parent[static_cast<std::size_t>(p)];
    x = p;
  }
  return x;
}

// Why axis-aligned boxes. The query bounds a node pair by the gaps of the
// boxes' projections on A's three axes and on B's three axes (mesh_distance.cpp:
// exact for aligned boxes, a few dozen flops, no square root), and a box
// stores in 24 bytes of float, which keeps the hierarchy inside the memory
// target (twice the raw vertices and triangles). Bounding spheres of the
// same boxes are looser: on FCL's env/rob pair (bench/mesh_bench) they let
// through about twice the triangle pairs and several times the node pairs,
// and were slower (measured with an earlier traversal; the figures are in
// CHANGELOG.md). An oriented volume would be tighter around env's large
// slanted triangles (median edge 490, up to 8450, in a 6000 box) but needs
// its rotation stored per node, beyond the memory target at 4 triangles
// per leaf; it has not been tried.
//
// Fixed ray directions for the inside test, each with all components
// non-zero (no division by zero in the slab test) and one of magnitude 1
// (so that the far end leaves the mesh's box). A ray that meets an edge, a
// vertex or lies in a triangle's plane is replaced by the next.
constexpr std::array<std::array<double, 3>, 8> kRayDirections = {{
    {1.0, 0.3712890625, 0.2197265625},
    {-0.4365234375, 1.0, 0.6513671875},
    {0.5830078125, -0.7470703125, 1.0},
    {-1.0, -0.2861328125, 0.8095703125},
    {0.1357421875, 0.9228515625, -1.0},
    {1.0, -0.6181640625, -0.4443359375},
    {-0.7919921875, -1.0, -0.3330078125},
    {0.2705078125, 1.0, -0.8876953125},
}};

// The inside test's slab test against a node's box: the box is widened by
// kSlabWidening of the mesh's unit (a power of two near its scale), far
// above the rounding of the box's float coordinates (2^-24 relative) and of
// the ray's parameters, and each slab's parameter interval by
// kSlabParameterSlack, above the rounding of the divisions by the ray's
// direction (a few u). A box kept too many is only a triangle tested more,
// exactly. Pinned by MeshStatus.ContainsAgreesWithTheBoxOnRaysThroughEdges.
constexpr double kSlabWidening = 0x1p-20;
constexpr double kSlabParameterSlack = 0x1p-30;

// Whether p, in the plane of the non-degenerate triangle (a, b, c), lies in
// the closed triangle: orientations in the projection along the largest
// component of the normal (an affine bijection of the plane, so the signs
// are those in the plane), exact.
bool coplanar_point_in_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  int axis = 0;
  detail::exact_triangle_normal(a, b, c).cwiseAbs().maxCoeff(&axis);
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const int s0 = detail::orient2d(a[i], a[j], b[i], b[j], p[i], p[j]);
  const int s1 = detail::orient2d(b[i], b[j], c[i], c[j], p[i], p[j]);
  const int s2 = detail::orient2d(c[i], c[j], a[i], a[j], p[i], p[j]);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

// The triangles that the hierarchy holds: all but repeats. A triangle whose
// three corners are, as a set, the same points as an earlier triangle's
// (by index or by coordinates, in any order or orientation) is the same
// surface: it changes no distance, closest point or crossing, only the
// work. Left in, N coincident copies on each side of an overlapping pair
// are N^2 triangle pairs within the contact band that no bound can prune
// (each is at distance 0 and none crosses). The first copy (the smallest
// id) is kept, so the witness triangle is the one an all-pairs scan finds
// first. O(n log n): the corners' bits hashed, then sorted by hash.
std::vector<std::int32_t> distinct_triangles(std::span<const Vec3> vertices,
                                             std::span<const TriangleMesh::Triangle> triangles) {
  using Corners = std::array<std::array<std::uint64_t, 3>, 3>;
  const auto corners = [&](std::size_t t) {
    Corners c;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3& v = vertices[triangles[t][k]];
      // +0.0 so that -0.0 and 0.0, the same point, have the same bits.
      c[k] = {std::bit_cast<std::uint64_t>(v.x() + 0.0), std::bit_cast<std::uint64_t>(v.y() + 0.0),
              std::bit_cast<std::uint64_t>(v.z() + 0.0)};
    }
    std::sort(c.begin(), c.end());
    return c;
  };
  struct Keyed {
    std::uint64_t hash;
    std::int32_t triangle;
  };
  std::vector<Keyed> keyed(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (const auto& corner : corners(t)) {
      for (const std::uint64_t bits : corner) {
        h ^= bits + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
        h *= 0xff51afd7ed558ccdULL;
      }
    }
    keyed[t] = {h, static_cast<std::int32_t>(t)};
  }
  std::sort(keyed.begin(), keyed.end(), [](const Keyed& x, const Keyed& y) {
    return x.hash < y.hash || (x.hash == y.hash && x.triangle < y.triangle);
  });
  std::vector<char> repeat(triangles.size(), 0);
  for (std::size_t i = 0; i < keyed.size();) {
    std::size_t end = i + 1;
    while (end < keyed.size() && keyed[end].hash == keyed[i].hash) ++end;
    // Equal hashes: compare the corners themselves (a collision is not a
    // repeat). Runs are short unless the triangles really repeat.
    for (std::size_t a = i; a < end; ++a) {
      const auto ta = static_cast<std::size_t>(keyed[a].triangle);
      if (repeat[ta] != 0) continue;
      const Corners ca = corners(ta);
      for (std::size_t b = a + 1; b < end; ++b) {
        const auto tb = static_cast<std::size_t>(keyed[b].triangle);
        if (repeat[tb] == 0 && corners(tb) == ca) repeat[tb] = 1;
      }
    }
    i = end;
  }
  std::vector<std::int32_t> kept;
  kept.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (repeat[t] == 0) kept.push_back(static_cast<std::int32_t>(t));
  }
  return kept;
}

}  // namespace

TriangleMesh::TriangleMesh(std::span<const Vec3> vertices, std::span<const Triangle> triangles)
    : triangles_(triangles.begin(), triangles.end()) {
  build(vertices);
}

TriangleMesh::TriangleMesh(std::span<const Vec3> vertices,
                           std::span<const std::array<std::int32_t, 3>> triangles) {
  triangles_.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    Triangle tri{};
    for (std::size_t k = 0; k < 3; ++k) {
      if (triangles[t][k] < 0) {
        throw InvalidInput("TriangleMesh: triangle " + std::to_string(t) + " refers to vertex " +
                           std::to_string(triangles[t][k]) + " (negative index)");
      }
      tri[k] = static_cast<std::uint32_t>(triangles[t][k]);
    }
    triangles_.push_back(tri);
  }
  build(vertices);
}

void TriangleMesh::build(std::span<const Vec3> vertices) {
  constexpr auto kMaxCount = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  if (vertices.empty()) throw InvalidInput("TriangleMesh: no vertices given");
  if (triangles_.empty()) throw InvalidInput("TriangleMesh: no triangles given");
  if (vertices.size() > kMaxCount) {
    throw InvalidInput("TriangleMesh: too many vertices (" + std::to_string(vertices.size()) + ")");
  }
  if (triangles_.size() > kMaxCount / 2) {
    throw InvalidInput("TriangleMesh: too many triangles (" + std::to_string(triangles_.size()) +
                       ")");
  }
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3& v = vertices[i];
    if (!is_finite_bits(v.x()) || !is_finite_bits(v.y()) || !is_finite_bits(v.z()))
      throw InvalidInput(vertex_problem(i, v));
    const double m = v.cwiseAbs().maxCoeff();
    if (!(m <= kMaxMagnitude)) {
      throw InvalidInput(
          detail::beyond_magnitude("TriangleMesh: vertex " + std::to_string(i), m, ""));
    }
    scale_ = std::max(scale_, m);
  }
  const std::size_t n = vertices.size();
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    for (const std::uint32_t v : triangles_[t]) {
      if (v >= n) {
        throw InvalidInput("TriangleMesh: triangle " + std::to_string(t) + " refers to vertex " +
                           std::to_string(v) + ", but there are " + std::to_string(n) +
                           " vertices");
      }
    }
  }
  vertices_.assign(vertices.begin(), vertices.end());
  unit_ = scale_ > 0.0 ? std::ldexp(1.0, detail::magnitude_exponent(scale_)) : 1.0;
  id_ = next_mesh_id.fetch_add(1, std::memory_order_relaxed);

  // Degenerate triangles, exactly.
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const Triangle& tri = triangles_[t];
    if (detail::collinear3d(vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]))
      degenerate_.push_back(static_cast<std::int32_t>(t));
  }

  // Closed and consistently oriented: every directed edge once, and its
  // reverse present.
  {
    std::vector<std::uint64_t> edges;
    edges.reserve(3 * triangles_.size());
    bool repeated_index = false;
    for (const Triangle& tri : triangles_) {
      repeated_index |= tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t from = tri[static_cast<std::size_t>(k)];
        const std::uint64_t to = tri[static_cast<std::size_t>((k + 1) % 3)];
        edges.push_back(from << 32 | to);
      }
    }
    std::sort(edges.begin(), edges.end());
    closed_ = !repeated_index && std::adjacent_find(edges.begin(), edges.end()) == edges.end();
    for (std::size_t k = 0; closed_ && k < edges.size(); ++k) {
      const std::uint64_t reverse = edges[k] << 32 | edges[k] >> 32;
      closed_ = std::binary_search(edges.begin(), edges.end(), reverse);
    }
  }

  // Connected components (triangles sharing a vertex index).
  {
    std::vector<std::int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    for (const Triangle& tri : triangles_) {
      for (int k = 1; k < 3; ++k) {
        const std::int32_t x = find_root(parent, static_cast<std::int32_t>(tri[0]));
        const std::int32_t y =
            find_root(parent, static_cast<std::int32_t>(tri[static_cast<std::size_t>(k)]));
        if (x != y) parent[static_cast<std::size_t>(std::max(x, y))] = std::min(x, y);
      }
    }
    std::vector<char> seen(n, 0);
    for (const Triangle& tri : triangles_) {
      const std::int32_t r = find_root(parent, static_cast<std::int32_t>(tri[0]));
      if (seen[static_cast<std::size_t>(r)] == 0) {
        seen[static_cast<std::size_t>(r)] = 1;
        component_vertices_.push_back(static_cast<std::int32_t>(tri[0]));
      }
    }
  }

  // The hierarchy.
  const double inv_unit = 1.0 / unit_;
  Builder builder{vertices_, triangles_, {}, nodes_, {}, inv_unit};
  const std::vector<std::int32_t> distinct = distinct_triangles(vertices_, triangles_);
  builder.items.resize(distinct.size());
  for (std::size_t i = 0; i < distinct.size(); ++i) {
    const auto t = static_cast<std::size_t>(distinct[i]);
    const Triangle& tri = triangles_[t];
    const Vec3 p0 = vertices_[tri[0]] * inv_unit, p1 = vertices_[tri[1]] * inv_unit,
               p2 = vertices_[tri[2]] * inv_unit;
    builder.items[i] = {((p0 + p1 + p2) / 3.0).cast<float>(), static_cast<std::int32_t>(t),
                        p0.cwiseMin(p1).cwiseMin(p2).cast<float>(),
                        p0.cwiseMax(p1).cwiseMax(p2).cast<float>()};
  }
  nodes_.reserve(2 * (distinct.size() + TriangleMesh::kLeafSize - 1) / TriangleMesh::kLeafSize *
                 2);
  Vec3 lo, hi;
  builder.build(0, static_cast<std::int32_t>(distinct.size()), lo, hi);
  nodes_.shrink_to_fit();
  order_.resize(distinct.size());
  for (std::size_t k = 0; k < order_.size(); ++k) order_[k] = builder.items[k].triangle;
  Vec3 root_lo, root_hi;
  box(0, root_lo, root_hi);
  center_ = 0.5 * (root_lo + root_hi);
  bounding_radius_ = 0.5 * (root_hi - root_lo).stableNorm();
  // The hull of the vertices the triangles use (an unused vertex would
  // only loosen the bound).
  std::vector<char> used(vertices_.size(), 0);
  for (const Triangle& tri : triangles_)
    for (const std::uint32_t v : tri) used[v] = 1;
  std::vector<Vec3> corners;
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (used[v] != 0) corners.push_back(vertices_[v]);
  hull_ = std::make_shared<const ConvexPolytope>(corners);
}

void TriangleMesh::box(int i, Vec3& lo, Vec3& hi) const {
  const Node& node = nodes_[static_cast<std::size_t>(i)];
  for (int k = 0; k < 3; ++k) {
    lo[k] = static_cast<double>(node.lo[static_cast<std::size_t>(k)]) * unit_;
    hi[k] = static_cast<double>(node.hi[static_cast<std::size_t>(k)]) * unit_;
  }
}

std::size_t TriangleMesh::memory_bytes() const {
  return sizeof(*this) + vertices_.capacity() * sizeof(Vec3) +
         triangles_.capacity() * sizeof(Triangle) + nodes_.capacity() * sizeof(Node) +
         (order_.capacity() + degenerate_.capacity() + component_vertices_.capacity()) *
             sizeof(std::int32_t) +
         hull_->memory_bytes();
}

bool TriangleMesh::contains(const Vec3& p) const {
  if (!closed_) return false;
  if (!is_finite_bits(p.x()) || !is_finite_bits(p.y()) || !is_finite_bits(p.z())) return false;
  // Outside the root box: outside.
  Vec3 root_lo, root_hi;
  box(0, root_lo, root_hi);
  for (int k = 0; k < 3; ++k) {
    if (p[k] < root_lo[k] || p[k] > root_hi[k]) return false;
  }
  const double reach = 4.0 * std::max(scale_, p.cwiseAbs().maxCoeff());
  std::vector<std::int32_t> stack;
  stack.reserve(64);
  for (const auto& direction : kRayDirections) {
    const Vec3 d(direction[0], direction[1], direction[2]);
    const Vec3 q = p + reach * d;
    const Vec3 dq = q - p;  // non-zero in every component
    int crossings = 0;
    bool degenerate = false;
    bool on_surface = false;
    stack.clear();
    stack.push_back(0);
    while (!stack.empty() && !degenerate && !on_surface) {
      const std::int32_t id = stack.back();
      stack.pop_back();
      // Slab test of the segment p + s dq, s in [0, 1], against the box,
      // widened (kSlabWidening, kSlabParameterSlack) so that rounding never
      // drops a box the segment touches (triangle tests below are exact).
      Vec3 lo, hi;
      box(id, lo, hi);
      const double widen = kSlabWidening * unit_;
      double s0 = 0.0, s1 = 1.0;
      for (int k = 0; k < 3 && s0 <= s1; ++k) {
        double a = (lo[k] - widen - p[k]) / dq[k];
        double b = (hi[k] + widen - p[k]) / dq[k];
        if (a > b) std::swap(a, b);
        s0 = std::max(s0, a - kSlabParameterSlack);
        s1 = std::min(s1, b + kSlabParameterSlack);
      }
      if (s0 > s1) continue;
      const Node& node = nodes_[static_cast<std::size_t>(id)];
      if (!node.is_leaf()) {
        stack.push_back(id + 1);
        stack.push_back(node.first_or_right);
        continue;
      }
      for (std::int32_t k = 0; k < node.count; ++k) {
        const Triangle& tri = triangles_[static_cast<std::size_t>(
            order_[static_cast<std::size_t>(node.first_or_right + k)])];
        const Vec3& a = vertices_[tri[0]];
        const Vec3& b = vertices_[tri[1]];
        const Vec3& c = vertices_[tri[2]];
        if (detail::collinear3d(a, b, c)) continue;  // zero area: no crossing of its own
        const int sp = detail::side3d(a, b, c, p);
        const int sq = detail::side3d(a, b, c, q);
        if (sp == 0) {
          if (coplanar_point_in_triangle(a, b, c, p)) {
            on_surface = true;
            break;
          }
          if (sq == 0) degenerate = true;  // the ray lies in the plane
          continue;                        // meets the plane at p only, outside the triangle
        }
        if (sq == 0) {
          degenerate = true;
          break;
        }
        if (sp == sq) continue;
        const int o0 = detail::side3d(p, q, a, b);
        const int o1 = detail::side3d(p, q, b, c);
        const int o2 = detail::side3d(p, q, c, a);
        if ((o0 > 0 && o1 > 0 && o2 > 0) || (o0 < 0 && o1 < 0 && o2 < 0)) {
          ++crossings;
        } else if ((o0 >= 0 && o1 >= 0 && o2 >= 0) || (o0 <= 0 && o1 <= 0 && o2 <= 0)) {
          degenerate = true;  // through an edge or a vertex
          break;
        }
      }
    }
    if (on_surface) return false;
    if (!degenerate) return (crossings & 1) != 0;
  }
  // Every direction met an edge or a plane: practically unreachable for a
  // point off the surface (each direction is a measure-zero event).
  return false;
}

}  // namespace proxima
