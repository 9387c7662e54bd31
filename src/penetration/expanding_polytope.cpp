// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer: the expanding polytope (see expanding_polytope.h for
// the certificate).
#include "penetration/expanding_polytope.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory_resource>
#include <utility>
#include <vector>

#include "proxima/shape/support.h"

namespace proxima::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Rounding of a triangle's offset n.v0, n the normalized rounded cross
// product c of its rounded edges e1 = v1 - v0, e2 = v2 - v0: each edge is
// within u of the exact one componentwise (a subtraction), so c is within
// about 8 u |e1||e2| of the exact cross product and the unit normal within
// 8 u |e1||e2| / |c| plus the normalization's few u of the exact one; the
// dot product with v0 adds a few u |v0|. Doubled: 16 for both terms,
// |v0| read as its 1-norm (no square root, at least the 2-norm).
constexpr double kOffsetAngleUlps = 16.0;
constexpr double kOffsetUlps = 16.0;

// A support s is not beyond a triangle when n.s exceeds its offset by at
// most the offset's rounding bound plus this many u |s|_1 (the rounding of
// n.s): s is then on the triangle's plane up to rounding, and the triangle
// on M's supporting plane along n.
constexpr double kBeyondUlps = 8.0;

struct Vertex {
  Vec3 p;
  int a, b;
};

struct Triangle {
  std::array<int, 3> v;
  std::array<int, 3> adjacent;  // across the edge v[i] -> v[i + 1]
  Vec3 normal;
  double offset;
  double error;  // bound on the offset's rounding
  double normal_error;  // bound on the normal's (TrianglePlane)
  bool alive;
};

// triangle_plane's computation, inline in the expansion's loop (a call per
// triangle added otherwise).
inline TrianglePlane plane_of(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const Vec3 e1 = p1 - p0;
  const Vec3 e2 = p2 - p0;
  const Vec3 c = e1.cross(e2);
  const double length = c.norm();
  TrianglePlane t;
  if (length > 0.0 && std::isfinite(length)) {
    t.normal = c / length;
    t.offset = t.normal.dot(p0);
    const double ratio = std::sqrt(e1.squaredNorm() * e2.squaredNorm()) / length;
    t.normal_error = (kOffsetAngleUlps * ratio + kOffsetUlps) * kUnitRoundoff;
    t.error = t.normal_error * p0.lpNorm<1>();
  }
  return t;
}

// A triangle's key (its plane's offset less the offset's rounding bound)
// in the min-heap of the triangles to expand. Ties go to the older
// triangle (the lower index): the order std::greater gave the pairs
// (key, index), spelled out: the pair's synthesized three-way comparison
// of doubles (a partial ordering) is several instructions per step of the
// heap. Keys are never NaN (finite points, or -infinity for a
// degenerate triangle).
struct HeapEntry {
  double key;
  int index;
};
struct KeyAbove {
  bool operator()(const HeapEntry& x, const HeapEntry& y) const {
    return x.key > y.key || (x.key == y.key && x.index > y.index);
  }
};

class Expansion {
 public:
  Expansion(const MinkowskiSupport& m, std::pmr::memory_resource* memory)
      : m_(m),
        vertices_(memory),
        triangles_(memory),
        heap_(memory),
        horizon_(memory),
        stack_(memory),
        starts_(memory) {
    vertices_.reserve(64);
    triangles_.reserve(128);
    heap_.reserve(128);
    horizon_.reserve(32);
    stack_.reserve(32);
    starts_.reserve(64);
  }

  // The octahedron on the supports along +-x, +-y, +-z; false when two of
  // them are the same point of M (then the octahedron is not a surface of
  // six distinct vertices: M is small or thin along an axis).
  bool start() {
    for (int k = 0; k < 6; ++k) {
      Vec3 d = Vec3::Zero();
      d[k / 2] = k % 2 == 0 ? 1.0 : -1.0;
      vertices_.push_back(support(d, -1, -1));
    }
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < i; ++j)
        if (vertices_[i].a == vertices_[j].a && vertices_[i].b == vertices_[j].b) return false;
    // Octant (sx, sy, sz), sign bit 1 for minus: vertices 2 * axis + bit.
    // (+x, +y, +z) is counter-clockwise seen from outside; each minus sign
    // mirrors the octant, flipping the orientation.
    for (int o = 0; o < 8; ++o) {
      const int sx = o & 1, sy = (o >> 1) & 1, sz = (o >> 2) & 1;
      std::array<int, 3> t = {0 + sx, 2 + sy, 4 + sz};
      if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
      add_triangle(t);
    }
    // Adjacency: the triangle across an edge is the one holding the edge
    // reversed (owner[u][w]: the triangle holding u -> w).
    std::array<std::array<int, 6>, 6> owner{};
    for (int g = 0; g < 8; ++g)
      for (int i = 0; i < 3; ++i) {
        const Triangle& t = triangles_[static_cast<std::size_t>(g)];
        owner[static_cast<std::size_t>(t.v[static_cast<std::size_t>(i)])]
             [static_cast<std::size_t>(t.v[static_cast<std::size_t>((i + 1) % 3)])] = g;
      }
    for (Triangle& t : triangles_)
      for (std::size_t i = 0; i < 3; ++i)
        t.adjacent[i] = owner[static_cast<std::size_t>(t.v[(i + 1) % 3])][static_cast<std::size_t>(t.v[i])];
    return true;
  }

  // Writes the live triangles and the vertices they use to `surface`,
  // renumbered densely (keys in scaled units).
  void keep(ExpansionSurface& surface) {
    surface.clear();
    std::pmr::vector<int> triangle_at(triangles_.size(), -1, triangles_.get_allocator());
    std::pmr::vector<int> vertex_at(vertices_.size(), -1, vertices_.get_allocator());
    for (std::size_t g = 0; g < triangles_.size(); ++g) {
      if (!triangles_[g].alive) continue;
      triangle_at[g] = static_cast<int>(surface.triangles.size());
      surface.triangles.push_back({});
      for (const int v : triangles_[g].v)
        if (vertex_at[static_cast<std::size_t>(v)] < 0) {
          vertex_at[static_cast<std::size_t>(v)] = static_cast<int>(surface.vertices.size());
          const Vertex& x = vertices_[static_cast<std::size_t>(v)];
          surface.vertices.push_back({x.a, x.b});
        }
    }
    for (std::size_t g = 0; g < triangles_.size(); ++g) {
      const Triangle& t = triangles_[g];
      if (!t.alive) continue;
      ExpansionSurface::Triangle& out = surface.triangles[static_cast<std::size_t>(triangle_at[g])];
      for (std::size_t k = 0; k < 3; ++k) {
        out.v[k] = vertex_at[static_cast<std::size_t>(t.v[k])];
        out.adjacent[k] = triangle_at[static_cast<std::size_t>(t.adjacent[k])];
      }
      out.normal = t.normal;
      out.normal_error = t.normal_error;
      out.key = t.offset - t.error;
    }
  }

  // The tetrahedron of the seed's points, oriented outwards by the sign of
  // its volume; false (P left empty) when an id is out of range, two
  // points are the same pair, or a key is not positive (the origin not
  // strictly inside beyond rounding, or a volume too flat for its sign).
  bool start(const DepthSeed& seed) {
    for (std::size_t k = 0; k < 4; ++k) {
      if (seed.a[k] < 0 || seed.a[k] >= m_.a.vertex_count() || seed.b[k] < 0 ||
          seed.b[k] >= m_.b.vertex_count())
        return false;
      for (std::size_t l = 0; l < k; ++l)
        if (seed.a[k] == seed.a[l] && seed.b[k] == seed.b[l]) return false;
    }
    for (std::size_t k = 0; k < 4; ++k)
      vertices_.push_back({m_.point_a(seed.a[k]) - m_.point_b(seed.b[k]), seed.a[k], seed.b[k]});
    const Vec3& p0 = vertices_[0].p;
    const double volume =
        (vertices_[1].p - p0).dot((vertices_[2].p - p0).cross(vertices_[3].p - p0));
    // Positive volume: (0 2 1), (0 1 3), (0 3 2), (1 2 3) are
    // counter-clockwise seen from outside (the unit tetrahedron checks it);
    // a negative one swaps vertices 1 and 2.
    const int i1 = volume > 0.0 ? 1 : 2, i2 = volume > 0.0 ? 2 : 1;
    const std::array<std::array<int, 3>, 4> faces = {
        {{0, i2, i1}, {0, i1, 3}, {0, 3, i2}, {i1, i2, 3}}};
    for (const auto& f : faces) {
      const int g = add_triangle(f);
      const Triangle& t = triangles_[static_cast<std::size_t>(g)];
      if (!(t.offset - t.error > 0.0)) {
        vertices_.clear();
        triangles_.clear();
        heap_.clear();
        return false;
      }
    }
    // Adjacency as for the octahedron: the triangle holding the edge
    // reversed.
    std::array<std::array<int, 4>, 4> owner{};
    for (int g = 0; g < 4; ++g)
      for (std::size_t i = 0; i < 3; ++i) {
        const Triangle& t = triangles_[static_cast<std::size_t>(g)];
        owner[static_cast<std::size_t>(t.v[i])][static_cast<std::size_t>(t.v[(i + 1) % 3])] = g;
      }
    for (Triangle& t : triangles_)
      for (std::size_t i = 0; i < 3; ++i)
        t.adjacent[i] = owner[static_cast<std::size_t>(t.v[(i + 1) % 3])][static_cast<std::size_t>(t.v[i])];
    return true;
  }

  // Out of line: inlined into expand_polytope beside the two starts, its
  // loop was compiled into more instructions per iteration (callgrind).
  [[gnu::noinline]] ExpansionResult run(int max_iterations) {
    ExpansionResult r;
    for (; r.iterations < max_iterations; ++r.iterations) {
      const int f = pop();
      if (f < 0) return r;
      const Triangle& t = triangles_[static_cast<std::size_t>(f)];
      const double key = t.offset - t.error;
      if (!std::isfinite(key)) return r;
      const Vertex s = support(t.normal, t.v);
      const double h = t.normal.dot(s.p);
      if (h < r.upper) r.upper = h;
      r.normal = t.normal;
      r.support_a = s.a;
      r.support_b = s.b;
      r.lower = key;
      if (h - t.offset <= t.error + kBeyondUlps * kUnitRoundoff * s.p.lpNorm<1>()) {
        // On M's supporting plane: the least key is final.
        r.certified = key > 0.0;
        r.converged = true;
        return r;
      }
      if (!expand(f, s)) return r;
    }
    // The cap: certified with the least key so far when it is positive.
    const int f = pop();
    if (f >= 0) {
      const Triangle& t = triangles_[static_cast<std::size_t>(f)];
      r.lower = t.offset - t.error;
      r.normal = t.normal;
      r.certified = r.lower > 0.0;
    }
    return r;
  }

 private:
  // Without hints (-1): support_without_hint's climb from the hull's table
  // (ConvexPolytope::support_start), which on a large round hull starts a
  // step or two from the support where a climb from vertex 0 crosses half
  // of it.
  Vertex support(const Vec3& n, int hint_a, int hint_b) const {
    const Vec3 n_b = m_.rotation_t * (-n);
    const int i = hint_a < 0 ? support_without_hint(m_.a, n) : support_hill_climb(m_.a, n, hint_a);
    const int j =
        hint_b < 0 ? support_without_hint(m_.b, n_b) : support_hill_climb(m_.b, n_b, hint_b);
    return {m_.point_a(i) - m_.point_b(j), i, j};
  }

  // Along a triangle's normal: each hull's climb starts at the best along
  // it of the triangle's three vertices (supports along nearby directions
  // once P is fine) and the hull's table start (support_start: a step or
  // two away on a round hull, whatever the triangle; the better start on
  // P's first, large triangles). Four dot products against the climb's
  // steps of a whole ring each.
  Vertex support(const Vec3& n, const std::array<int, 3>& v) const {
    const Vec3 n_b = m_.rotation_t * (-n);
    int hint_a = m_.a.support_start(n), hint_b = m_.b.support_start(n_b);
    double best_a = hint_a < 0 ? -kInfinity : n.dot(m_.a.vertex(hint_a));
    double best_b = hint_b < 0 ? -kInfinity : n_b.dot(m_.b.vertex(hint_b));
    for (const int k : v) {
      const Vertex& x = vertices_[static_cast<std::size_t>(k)];
      const double da = n.dot(m_.a.vertex(x.a)), db = n_b.dot(m_.b.vertex(x.b));
      if (da > best_a) best_a = da, hint_a = x.a;
      if (db > best_b) best_b = db, hint_b = x.b;
    }
    const int i = support_hill_climb(m_.a, n, hint_a);
    const int j = support_hill_climb(m_.b, n_b, hint_b);
    return {m_.point_a(i) - m_.point_b(j), i, j};
  }

  int edge_index(int g, int u, int w) const {
    const Triangle& t = triangles_[static_cast<std::size_t>(g)];
    for (int i = 0; i < 3; ++i)
      if (t.v[static_cast<std::size_t>(i)] == u && t.v[static_cast<std::size_t>((i + 1) % 3)] == w)
        return i;
    return -1;
  }

  int add_triangle(const std::array<int, 3>& v) {
    const TrianglePlane plane = plane_of(vertices_[static_cast<std::size_t>(v[0])].p,
                                               vertices_[static_cast<std::size_t>(v[1])].p,
                                               vertices_[static_cast<std::size_t>(v[2])].p);
    const int index = static_cast<int>(triangles_.size());
    // Built in place (no copy of the triangle per call: a large share of
    // an expansion's work is adding triangles).
    Triangle& t = triangles_.emplace_back();
    t.v = v;
    t.adjacent = {-1, -1, -1};
    t.normal = plane.normal;
    t.offset = plane.offset;
    t.error = plane.error;
    t.normal_error = plane.normal_error;
    t.alive = true;
    heap_.push_back({plane.offset - plane.error, index});
    std::push_heap(heap_.begin(), heap_.end(), KeyAbove{});
    return index;
  }

  // The live triangle of least key, or -1.
  int pop() {
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), KeyAbove{});
      const int f = heap_.back().index;
      heap_.pop_back();
      if (triangles_[static_cast<std::size_t>(f)].alive) return f;
    }
    return -1;
  }

  // Replaces the triangles whose planes s is beyond, from f on, by the fan
  // from s to their boundary. False (P left as it was only in part: the
  // caller stops) when the boundary is not simple (a vertex starting or
  // ending two boundary edges). An s that is a vertex already (P not convex through
  // rounding) needs no check: on the boundary it makes a triangle of zero
  // area, whose key (-infinity) stops the expansion uncertified; elsewhere
  // P stays a closed surface of points of M.
  bool expand(int f, const Vertex& s) {
    const int apex = static_cast<int>(vertices_.size());
    vertices_.push_back(s);
    horizon_.clear();
    stack_.assign(1, f);
    triangles_[static_cast<std::size_t>(f)].alive = false;
    while (!stack_.empty()) {
      const int g = stack_.back();
      stack_.pop_back();
      for (int i = 0; i < 3; ++i) {
        const Triangle& t = triangles_[static_cast<std::size_t>(g)];
        const int across = t.adjacent[static_cast<std::size_t>(i)];
        Triangle& n = triangles_[static_cast<std::size_t>(across)];
        if (!n.alive) continue;
        if (n.normal.dot(s.p) > n.offset) {
          n.alive = false;
          stack_.push_back(across);
        } else {
          const int u = t.v[static_cast<std::size_t>(i)], w = t.v[static_cast<std::size_t>((i + 1) % 3)];
          horizon_.push_back({u, w, across, edge_index(across, w, u)});
        }
      }
    }
    // Boundary edges whose triangle across was removed after the edge was
    // recorded are inside the removed region: drop them.
    std::erase_if(horizon_, [&](const Edge& e) {
      return !triangles_[static_cast<std::size_t>(e.outside)].alive;
    });
    if (horizon_.size() < 3) return false;
    // starts_[v]: the fan triangle whose boundary edge starts at v, -1
    // outside this call (reset below for the boundary's vertices).
    starts_.resize(vertices_.size(), -1);
    const auto clear_starts = [&] {
      for (const Edge& e : horizon_) starts_[static_cast<std::size_t>(e.u)] = -1;
    };
    const int first = static_cast<int>(triangles_.size());
    for (const Edge& e : horizon_) {
      if (e.at < 0 || starts_[static_cast<std::size_t>(e.u)] >= 0) {
        clear_starts();
        return false;
      }
      const int g = add_triangle({e.u, e.w, apex});
      starts_[static_cast<std::size_t>(e.u)] = g;
      triangles_[static_cast<std::size_t>(g)].adjacent[0] = e.outside;
    }
    for (const Edge& e : horizon_) {
      const int g = starts_[static_cast<std::size_t>(e.u)];
      triangles_[static_cast<std::size_t>(e.outside)].adjacent[static_cast<std::size_t>(e.at)] = g;
      // Edge w -> apex of g is apex -> w of the fan triangle starting at w.
      const int next = starts_[static_cast<std::size_t>(e.w)];
      if (next < 0) {
        clear_starts();
        return false;
      }
      triangles_[static_cast<std::size_t>(g)].adjacent[1] = next;
      triangles_[static_cast<std::size_t>(next)].adjacent[2] = g;
    }
    clear_starts();
    // Each fan edge apex -> w once in each direction: a vertex ending two
    // boundary edges (distinct starts do not exclude it) would leave an
    // edge held twice the same way, P no longer a closed surface, and the
    // certificate void.
    for (int g = first; g < static_cast<int>(triangles_.size()); ++g) {
      const int next = triangles_[static_cast<std::size_t>(g)].adjacent[1];
      if (triangles_[static_cast<std::size_t>(next)].adjacent[2] != g) return false;
    }
    return true;
  }

  const MinkowskiSupport& m_;
  std::pmr::vector<Vertex> vertices_;
  std::pmr::vector<Triangle> triangles_;
  std::pmr::vector<HeapEntry> heap_;
  // A boundary edge u -> w of a removed triangle, the kept triangle
  // across it and the edge's index there.
  struct Edge {
    int u, w, outside, at;
  };
  std::pmr::vector<Edge> horizon_;
  std::pmr::vector<int> stack_;
  std::pmr::vector<int> starts_;
};

}  // namespace

TrianglePlane triangle_plane(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  return plane_of(p0, p1, p2);
}

bool on_supporting_plane(const TrianglePlane& t, const Vec3& s) {
  return t.normal.dot(s) - t.offset <= t.error + kBeyondUlps * kUnitRoundoff * s.lpNorm<1>();
}

ExpansionResult expand_kept_polytope(const MinkowskiSupport& m, int max_iterations,
                                     ExpansionSurface& surface, const DepthSeed& seed) {
  std::array<std::byte, 24576> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  Expansion e(m, &memory);
  surface.clear();
  if (!e.start(seed) && !e.start()) return {};
  const ExpansionResult r = e.run(max_iterations);
  if (r.certified && r.converged) e.keep(surface);
  return r;
}

ExpansionResult expand_polytope(const MinkowskiSupport& m, int max_iterations,
                                const DepthSeed& seed) {
  // The scratch lists on the stack: a cold query's expansion is a few
  // dozen iterations, and heap allocations would cost as much as they.
  std::array<std::byte, 24576> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  Expansion e(m, &memory);
  if (!e.start(seed) && !e.start()) return {};
  return e.run(max_iterations);
}

}  // namespace proxima::detail
