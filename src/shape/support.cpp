// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: support functions, the brute-force scan and hill climbing.
#include "proxima/shape/support.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory_resource>
#include <vector>

#include "proxima/core/types.h"

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
  // The table's start (a climb of a step or two on a round hull); the
  // seeds below only for a direction the table refuses (zero, not finite).
  if (const int start = polytope.support_start(dir); start >= 0)
    return support_hill_climb(polytope, dir, start);
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


namespace {

// Twice the rounding bound of one computed d.x (Higham's gamma_3 <= 3.01 u
// for a dot product of three terms, times sum |d_i| |x_i| <= |d|_1
// scale()): the tie of support_hill_climb_through_plateaus.
constexpr double kPlateauTieUlps = 2.0 * 3.01;

// The climb of support_hill_climb from v, returning also the largest
// computed value among the last vertex's neighbours (-infinity for none),
// so that the common case (no neighbour within the tie) needs no second
// look at them.
int climb(const ConvexPolytope& polytope, const Vec3& dir, int v, double& neighbour_best) {
  const Vec3* vertices = polytope.vertices().data();
  const std::int32_t* offsets = polytope.adjacency_offsets().data();
  const std::int32_t* adjacency = polytope.adjacency().data();
  double v_dot = dir.dot(vertices[v]);
  for (;;) {
    int next = -1;
    double next_dot = v_dot;
    double runner_up = -std::numeric_limits<double>::infinity();
    for (std::int32_t k = offsets[v], end = offsets[v + 1]; k < end; ++k) {
      const std::int32_t w = adjacency[k];
      const double d = dir.dot(vertices[w]);
      runner_up = std::max(runner_up, d);
      if (d > next_dot) {
        next_dot = d;
        next = w;
      }
    }
    if (next < 0) {
      neighbour_best = runner_up;
      return v;
    }
    v = next;
    v_dot = next_dot;
  }
}

}  // namespace

int support_hill_climb_through_plateaus(const ConvexPolytope& polytope, const Vec3& dir,
                                        int hint) {
  const int n = polytope.vertex_count();
  const Vec3* vertices = polytope.vertices().data();
  const double tie = kPlateauTieUlps * kUnitRoundoff * dir.lpNorm<1>() * polytope.scale();
  double neighbour_best = 0.0;
  int v = climb(polytope, dir, hint >= 0 && hint < n ? hint : 0, neighbour_best);
  // Each pass walks the tie region of v; a vertex above v restarts the
  // climb (the values rise strictly: at most n passes). Membership by a
  // scan of the region while it is small (a face's vertices), else by a
  // mark per vertex.
  constexpr std::size_t kScanRegion = 32;
  std::array<std::byte, 1024> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  std::pmr::vector<int> region(&memory);
  std::vector<char> marked;
  for (;;) {
    const double top = dir.dot(vertices[v]);
    if (!(neighbour_best >= top - tie)) return v;
    region.assign(1, v);
    marked.clear();
    const auto in_region = [&](int w) {
      if (marked.empty()) return std::find(region.begin(), region.end(), w) != region.end();
      return marked[static_cast<std::size_t>(w)] != 0;
    };
    int above = -1;
    for (std::size_t head = 0; head < region.size() && above < 0; ++head) {
      for (const std::int32_t w : polytope.neighbors(region[head])) {
        if (in_region(w)) continue;
        const double d = dir.dot(vertices[w]);
        if (d > top) {
          above = w;
          break;
        }
        if (!(d >= top - tie)) continue;
        region.push_back(w);
        if (!marked.empty()) {
          marked[static_cast<std::size_t>(w)] = 1;
        } else if (region.size() > kScanRegion) {
          marked.assign(static_cast<std::size_t>(n), 0);
          for (const int x : region) marked[static_cast<std::size_t>(x)] = 1;
        }
      }
    }
    if (above < 0) return v;
    v = climb(polytope, dir, above, neighbour_best);
  }
}

}  // namespace proxima
