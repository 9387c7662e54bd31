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
// anchor and now (a few u of the larger scaled magnitude each), and of the
// bound itself (the Frobenius norm of the rounded R - R_G, a few u
// relative, times a reach of at most the magnitude; the dot product with
// the shift), in u of the scaled magnitude: generously above their sum,
// as the contact band is.
constexpr double kMovedUlps = 64.0;

// The lazy path (tracked_expansion.h): true with `r` certified and
// converged when the kept surface answers at this pose without expanding.
bool lazy(const MinkowskiSupport& m, const TrackedPose& pose, const ExpansionSurface& s,
          ExpansionResult& r) {
  // In the query's scaled units (m.inverse, exact): keys and poses are
  // kept in A's units.
  const double inverse = m.inverse;
  const Mat3 turned = pose.b_in_a.rotation - s.rotation;
  const double turn = turned.norm() * (pose.b_radius * inverse) +
                      kMovedUlps * kUnitRoundoff * std::max(pose.magnitude, s.magnitude) * inverse;
  const Vec3 shift =
      turned * (pose.b_centroid * inverse) + (pose.b_in_a.translation - s.translation) * inverse;
  const double shift_1 = shift.lpNorm<1>();
  // The bound on a triangle's distance from the origin now, from the
  // anchor (see the header): key - turn - n.shift less the normal's error
  // on the shift.
  const auto bound = [&](const ExpansionSurface::Triangle& t) {
    return t.key * inverse - turn - t.normal.dot(shift) - t.normal_error * shift_1;
  };
  const auto place = [&](std::int32_t v) {
    const auto& [i, j] = s.vertices[static_cast<std::size_t>(v)];
    return Vec3(m.point_a(i) - m.point_b(j));
  };
  const auto evaluate = [&](const ExpansionSurface::Triangle& t) {
    return triangle_plane(place(t.v[0]), place(t.v[1]), place(t.v[2]));
  };
  // Every bound positive: the winding number held all the way (the
  // header's Winding); the least bound's triangle is evaluated first.
  double least = std::numeric_limits<double>::infinity();
  std::size_t first = 0;
  for (std::size_t g = 0; g < s.triangles.size(); ++g) {
    const double b = bound(s.triangles[g]);
    if (!(b > 0.0)) return false;
    if (b < least) {
      least = b;
      first = g;
    }
  }
  TrianglePlane plane = evaluate(s.triangles[first]);
  double best = plane.offset - plane.error;
  std::size_t winner = first;
  // Then every triangle whose bound is below the least key evaluated: the
  // others' bounds are at least it.
  for (std::size_t g = 0; g < s.triangles.size(); ++g) {
    if (g == first || !(bound(s.triangles[g]) < best)) continue;
    const TrianglePlane p = evaluate(s.triangles[g]);
    if (p.offset - p.error < best) {
      best = p.offset - p.error;
      plane = p;
      winner = g;
    }
  }
  if (!(best > 0.0)) return false;
  const auto& [hint_a, hint_b] = s.vertices[static_cast<std::size_t>(s.triangles[winner].v[0])];
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

// Makes the pose of this query the surface's anchor: keys in A's units.
void anchor(const TrackedPose& pose, ExpansionSurface& s) {
  for (ExpansionSurface::Triangle& t : s.triangles) t.key *= pose.unit;
  s.rotation = pose.b_in_a.rotation;
  s.translation = pose.b_in_a.translation;
  s.magnitude = pose.magnitude;
}

}  // namespace

ExpansionResult track_expansion(const MinkowskiSupport& m, const TrackedPose& pose,
                                ExpansionSurface& surface, int max_iterations,
                                const DepthSeed& seed, bool& warm) {
  ExpansionResult r;
  warm = !surface.empty() && lazy(m, pose, surface, r);
  if (warm) return r;
  // Not answered from the kept surface: a fresh expansion from the
  // octahedron, rather than one going on from P placed here. P has grown
  // where the answer's facet was (a hundred triangles on a robot's links),
  // and placing all of it again cost more than a fresh start on the
  // robots' hulls and on spheres up to N = 512 (instruction counts in the
  // commit that chose this).
  r = expand_kept_polytope(m, max_iterations, surface, seed);
  if (!surface.empty()) anchor(pose, surface);
  return r;
}

}  // namespace proxima::detail
