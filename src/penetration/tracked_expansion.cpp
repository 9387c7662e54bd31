// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer: the expanding polytope kept across a turning B (see
// tracked_expansion.h for the certificate).
#include "penetration/tracked_expansion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "proxima/shape/support.h"

namespace proxima::detail {
namespace {

// The rounding of a vertex's placement a_i s - (R (b_j s) + t s) at the
// anchor and now (a few u of the scaled magnitude each), and of `moved`
// itself (the Frobenius norm of the rounded R - R_G, a few u relative,
// times a reach of at most the magnitude), in u of the scaled magnitude:
// generously above their sum, as the contact band is.
constexpr double kMovedUlps = 64.0;

// A kept surface past this many triangles is dropped (the next query
// starts from the octahedron): a long walk keeps refining P where the
// answer's facet goes, and re-placing all of it at every new anchor would
// cost more than a cold expansion.
constexpr std::size_t kMaxSurfaceTriangles = 1024;

// The lazy path (tracked_expansion.h): true with `r` certified and
// converged when the kept surface answers at this pose without expanding.
bool lazy(const MinkowskiSupport& m, const TrackedPose& pose, const ExpansionSurface& s,
          ExpansionResult& r) {
  // In the query's scaled units (m.inverse, exact): keys and poses are
  // kept in A's units.
  const double inverse = m.inverse;
  const double moved = (pose.b_in_a.rotation - s.rotation).norm() * (pose.b_reach * inverse) +
                       ((pose.b_in_a.translation - s.translation) * inverse).norm() +
                       kMovedUlps * kUnitRoundoff * pose.magnitude * inverse;
  if (!(s.least * inverse > moved)) return false;
  const auto place = [&](std::int32_t v) {
    const auto& [i, j] = s.vertices[static_cast<std::size_t>(v)];
    return Vec3(m.point_a(i) - m.point_b(j));
  };
  double best = std::numeric_limits<double>::infinity();
  TrianglePlane plane;
  std::int32_t winner = -1;
  for (const std::int32_t g : s.order) {
    const ExpansionSurface::Triangle& t = s.triangles[static_cast<std::size_t>(g)];
    // Sorted by key at the anchor: every triangle after this one has a
    // bound of at least the best key found.
    if (!(t.key * inverse - moved < best)) break;
    const TrianglePlane p = triangle_plane(place(t.v[0]), place(t.v[1]), place(t.v[2]));
    const double key = p.offset - p.error;
    if (key < best) {
      best = key;
      plane = p;
      winner = g;
    }
  }
  if (winner < 0 || !(best > 0.0)) return false;
  const auto& [hint_a, hint_b] =
      s.vertices[static_cast<std::size_t>(s.triangles[static_cast<std::size_t>(winner)].v[0])];
  const int i = support_hill_climb(m.a, plane.normal, hint_a);
  const int j = support_hill_climb(m.b, m.rotation_t * (-plane.normal), hint_b);
  const Vec3 support = m.point_a(i) - m.point_b(j);
  if (!on_supporting_plane(plane, support)) return false;
  r.certified = true;
  r.converged = true;
  r.lower = best;
  r.normal = plane.normal;
  r.upper = plane.normal.dot(support);
  r.support_a = i;
  r.support_b = j;
  r.iterations = 0;
  return true;
}

// Makes the pose of this query the surface's anchor: keys in A's units,
// sorted.
void anchor(const TrackedPose& pose, ExpansionSurface& s) {
  s.order.resize(s.triangles.size());
  for (std::size_t g = 0; g < s.triangles.size(); ++g) {
    s.triangles[g].key *= pose.unit;
    s.order[g] = static_cast<std::int32_t>(g);
  }
  std::sort(s.order.begin(), s.order.end(), [&](std::int32_t x, std::int32_t y) {
    return s.triangles[static_cast<std::size_t>(x)].key <
           s.triangles[static_cast<std::size_t>(y)].key;
  });
  s.least = s.triangles[static_cast<std::size_t>(s.order.front())].key;
  s.rotation = pose.b_in_a.rotation;
  s.translation = pose.b_in_a.translation;
}

}  // namespace

ExpansionResult track_expansion(const MinkowskiSupport& m, const TrackedPose& pose,
                                ExpansionSurface& surface, int max_iterations, bool& warm) {
  ExpansionResult r;
  warm = !surface.empty() && lazy(m, pose, surface, r);
  if (warm) return r;
  r = expand_kept_polytope(m, max_iterations, surface);
  if (surface.triangles.size() > kMaxSurfaceTriangles) surface.clear();
  if (!surface.empty()) anchor(pose, surface);
  return r;
}

}  // namespace proxima::detail
