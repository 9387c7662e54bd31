// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the witness feature of a closest point, from the hull
// vertices that span it. One rule for every algorithm (the hybrid, GJK and
// Enhanced GJK), so that their witness features agree whenever their closest
// points do.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// The closest point whose witness feature is wanted, in poly's frame.
struct WitnessPoint {
  Vec3 point = Vec3::Zero();
  Vec3 outward = Vec3::UnitX();  // for a polygon, the side to report
};

// The witness feature on hull `poly` of `point`, a point of the hull of the
// vertices `id` (1 to 4 of them, repeats allowed) that is a closest point
// of a distance query, everything in poly's own frame: the feature of least
// dimension that holds the point within `band`, and a real feature of this
// hull. The rule:
//   1. While the point is within `band` of the hull of all ids but one, that
//      one is dropped (the nearest such hull first): rounding and the
//      relative tolerance leave vertices that add nothing within the band.
//      Four left (a tetrahedron around the origin: a contact) lose the one
//      whose opposite face is nearest.
//   2. What is left names the feature: one vertex; two adjacent vertices,
//      an edge; two non-adjacent vertices or three, the hull face holding
//      them (for a polygon, of its two sides the one facing `outward`).
//   3. When no hull face holds them (the vertices straddle faces that are
//      coplanar within rounding but were not merged: a closest point within
//      the relative tolerance on a chord across them; or a contact's point
//      inside the hull), the face is located from the point itself: a walk
//      over the faces, from the one around the vertices whose plane is
//      nearest, to one whose polygon holds the point within `band`; then
//      its vertex or edge within `band` of the point if there is one, else
//      the face with the three vertices of its fan triangle nearest the
//      point. If the walk finds none, vertices are dropped as in rule 1
//      until the rest is a feature.
// The face id is a face of `poly` holding every reported vertex, always:
// `cached_face` (a previous answer's, from any pair) is used when it is one,
// which spares the lookup while a tracked feature does not change; otherwise
// the faces around the first vertex are searched. The vertex ids are
// reported in ascending order. O(1) but for that search (the faces around
// one vertex) and rule 3's walk (rare, and capped).
//
// `locate` false skips rule 3's walk (vertices are dropped at once): for an
// intersecting answer, whose point lies inside the other hull and whose
// features only name where the search stopped, the walk (which evaluates
// face planes around the vertices and along its path) would cost several
// microseconds per tracked overlapping query for nothing the answer
// promises.
Feature witness_feature_of_vertices(const ConvexPolytope& poly, std::span<const std::int32_t> id,
                                    const Vec3& point, double band, const Vec3& outward,
                                    std::int32_t cached_face, bool locate = true);

// Rule 2 for two distinct vertices u and v that rule 1 keeps: when they are
// adjacent, `f` becomes their hull edge and true is returned.
inline bool hull_edge(const ConvexPolytope& poly, std::int32_t u, std::int32_t v, Feature& f) {
  const auto nbrs = poly.neighbors(u);
  if (std::find(nbrs.begin(), nbrs.end(), v) == nbrs.end()) return false;
  f.type = FeatureType::edge;
  f.vertices = {std::min(u, v), std::max(u, v), -1};
  f.face = -1;
  return true;
}

// The same, with the point and the outward direction given by a callable
// returning a WitnessPoint, called only for two or more ids: a single vertex
// is its own feature (the tracked vertex-face query's common case), and
// mapping the point into poly's frame is then not paid for.
template <class Describe>
Feature witness_feature(const ConvexPolytope& poly, std::span<const std::int32_t> id, double band,
                        std::int32_t cached_face, const Describe& describe, bool locate = true) {
  if (id.size() == 1) {
    Feature f;
    f.vertices = {id[0], -1, -1};
    return f;
  }
  const WitnessPoint p = describe();
  // Two distinct ids at ordinary magnitudes, the tracked edge case: rules 1
  // and 2 inline (witness_feature_of_vertices applies the same ones).
  if (id.size() == 2 && id[0] != id[1] && poly.scale() > 0x1p-300 && poly.scale() < 0x1p300) {
    const double band2 = band * band;
    const double d0 = (poly.vertex(id[0]) - p.point).squaredNorm();
    const double d1 = (poly.vertex(id[1]) - p.point).squaredNorm();
    Feature f;
    if (d0 <= band2 || d1 <= band2) {
      f.vertices = {d0 <= d1 ? id[0] : id[1], -1, -1};
      return f;
    }
    if (hull_edge(poly, id[0], id[1], f)) return f;
  }
  // Three distinct ids on a solid at ordinary magnitudes that the previous
  // answer's face holds, the tracked face case: rules 1 and 2 inline. The
  // point is farther than `band` from every edge of the triangle (no vertex
  // dropped), so the feature is the face; anything else takes the general
  // path, which applies the same rules.
  if (id.size() == 3 && poly.dimension() == 3 && cached_face >= 0 &&
      cached_face < poly.face_count() && id[0] != id[1] && id[1] != id[2] && id[0] != id[2] &&
      poly.scale() > 0x1p-300 && poly.scale() < 0x1p300) {
    const Vec3 r0 = poly.vertex(id[0]) - p.point;
    const Vec3 r1 = poly.vertex(id[1]) - p.point;
    const Vec3 r2 = poly.vertex(id[2]) - p.point;
    const double band2 = band * band;
    // Squared distance from the point (the origin here) to segment [u, v].
    const auto segment2 = [](const Vec3& u, const Vec3& v) {
      const Vec3 e = v - u;
      const double ee = e.squaredNorm();
      const double t = ee > 0.0 ? std::clamp(-u.dot(e) / ee, 0.0, 1.0) : 0.0;
      return (u + t * e).squaredNorm();
    };
    const auto verts = poly.face(cached_face);
    const auto holds = [&verts](std::int32_t v) {
      return std::find(verts.begin(), verts.end(), v) != verts.end();
    };
    if (segment2(r1, r2) > band2 && segment2(r2, r0) > band2 && segment2(r0, r1) > band2 &&
        holds(id[0]) && holds(id[1]) && holds(id[2])) {
      std::array<std::int32_t, 3> sorted = {id[0], id[1], id[2]};
      std::sort(sorted.begin(), sorted.end());
      Feature f;
      f.type = FeatureType::face;
      f.vertices = sorted;
      f.face = cached_face;
      return f;
    }
  }
  return witness_feature_of_vertices(poly, id, p.point, band, p.outward, cached_face, locate);
}

// The band of rule 1 for coordinates bounded by r (the algorithms' bound on
// R): a quarter of the contact band, which leaves room for that bound
// exceeding the exact R of the accuracy standard (the reported feature must
// hold the point within the standard's 64 u R).
inline double witness_band(double r) { return 0.25 * contact_band(r); }

}  // namespace proxima::detail
