// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): see polygon_hull.h.
#include "hull/polygon_hull.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "core/power_of_two.h"
#include "hull/sorted_distinct.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima::detail {

// The extreme points of exactly collinear, distinct points: along the line,
// any coordinate in which p0 and p1 differ is strictly monotone, so the
// smallest and largest values of that coordinate are the ends.
std::vector<Index> segment_ends(std::span<const Vec3> pts, const Frame& frame) {
  const Vec3 d = pts[static_cast<std::size_t>(frame.base[1])] - pts[0];
  int axis = 0;
  d.cwiseAbs().maxCoeff(&axis);  // nonzero: p1 != p0 exactly, and the largest |d_k| > 0
  Index lo = 0, hi = 0;
  for (Index i = 1; i < static_cast<Index>(pts.size()); ++i) {
    const double v = pts[static_cast<std::size_t>(i)][axis];
    if (v < pts[static_cast<std::size_t>(lo)][axis]) lo = i;
    if (v > pts[static_cast<std::size_t>(hi)][axis]) hi = i;
  }
  return {lo, hi};
}

// Which coordinate to drop when projecting the plane of p0, p1, p2: one where
// the normal has a nonzero component, checked exactly, preferring the largest
// (best conditioned). Projecting onto the other two axes, in cyclic order
// (k+1, k+2), is then a bijection of the plane that maps counter-clockwise
// (about the normal with positive k component) to counter-clockwise.
int projection_axis(std::span<const Vec3> pts, std::span<const Vec3> scaled, const Frame& frame) {
  const auto& b = frame.base;
  const Vec3 normal =
      (scaled[static_cast<std::size_t>(b[1])] - scaled[static_cast<std::size_t>(b[0])])
          .cross(scaled[static_cast<std::size_t>(b[2])] - scaled[static_cast<std::size_t>(b[0])]);
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](int l, int r) { return std::abs(normal[l]) > std::abs(normal[r]); });
  for (const int k : order) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Vec3& a = pts[static_cast<std::size_t>(b[0])];
    const Vec3& c = pts[static_cast<std::size_t>(b[1])];
    const Vec3& e = pts[static_cast<std::size_t>(b[2])];
    if (orient2d(a[i], a[j], c[i], c[j], e[i], e[j]) != 0) return k;
  }
  return order[0];  // unreachable for a non-collinear base triangle
}

// Strict convex hull (extreme points only), counter-clockwise in the
// projection that drops `axis`, by Andrew's monotone chain with the exact
// orient2d. Exact for coplanar points.
std::vector<Index> polygon_hull(std::span<const Vec3> pts, int axis) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  // Sorted by projection; of points that project to one 2D point (only when
  // not exactly coplanar), the first.
  std::vector<Index> order = sorted_distinct(pts.size(), [&](Index v) {
    const Vec3& p = pts[static_cast<std::size_t>(v)];
    return std::pair<double, double>(p[i], p[j]);
  });
  const auto turns_left = [&](Index a, Index b, Index c) {
    const Vec3& pa = pts[static_cast<std::size_t>(a)];
    const Vec3& pb = pts[static_cast<std::size_t>(b)];
    const Vec3& pc = pts[static_cast<std::size_t>(c)];
    return orient2d(pa[i], pa[j], pb[i], pb[j], pc[i], pc[j]) > 0;
  };
  std::vector<Index> hull;
  hull.reserve(order.size() + 1);
  for (int pass = 0; pass < 2; ++pass) {  // lower chain, then upper chain
    const std::size_t floor = hull.size();
    for (const Index v : order) {
      while (hull.size() >= floor + 2 && !turns_left(hull[hull.size() - 2], hull.back(), v))
        hull.pop_back();
      hull.push_back(v);
    }
    hull.pop_back();  // the last point starts the other chain
    std::reverse(order.begin(), order.end());
  }
  return hull;
}

}  // namespace proxima::detail
