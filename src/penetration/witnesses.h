// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the supporting regions along the answer's normal and the result built from them (witness points and features).
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include <span>
#include "penetration/candidates.h"
#include "proxima/geometry/closest_point.h"

namespace proxima {
namespace {

// The supporting region of `poly` (mapped by `point`) in direction d, from
// its support vertex v: the vertices whose value is within `tie` of v's,
// found by a walk over the adjacency (the region is connected: it is a face
// of the hull thickened by rounding), as simplices to search for witness
// points, appended to `out`: every face all of whose vertices are in the
// region (fan triangles), else every edge in it, else v. Nearly coplanar
// faces (a polygon whose doubles are not exactly planar, a coplanar
// face-face contact) are all in, so the witness is found wherever it is.
// The walk's lists live in `memory` (a buffer on the stack: six heap
// allocations were a tenth of a tracked query at N = 8).
template <class PointOf, class Out>
void support_region(const ConvexPolytope& poly, PointOf&& point, const Vec3& d, int v, double tie,
                    std::pmr::memory_resource* memory, Out& out) {
  const auto simplex = [](FeatureType type, int v0, int v1, int v2, int face) {
    Feature f;
    f.type = type;
    f.vertices = {v0, v1, v2};
    f.face = face;
    return f;
  };
  const double top = d.dot(point(v));
  const auto in = [&](int w) { return d.dot(point(w)) >= top - tie; };
  std::pmr::vector<int> region({v}, memory);
  // Bounded by the vertex count: each vertex enters once.
  for (std::size_t head = 0; head < region.size(); ++head)
    for (const std::int32_t w : poly.neighbors(region[head]))
      if (std::find(region.begin(), region.end(), w) == region.end() && in(w)) region.push_back(w);
  // A vertex, or an edge (the BFS joined its two ends along it): no face
  // has all its vertices in (what the general case below finds, without
  // evaluating the faces around it).
  if (region.size() == 1) {
    out.push_back(simplex(FeatureType::vertex, v, -1, -1, -1));
    return;
  }
  if (region.size() == 2) {
    out.push_back(simplex(FeatureType::edge, std::min(region[0], region[1]),
                          std::max(region[0], region[1]), -1, -1));
    return;
  }
  // A face's vertices are all within the tie exactly when they are all in
  // the region: its boundary runs along hull edges, so they are connected
  // to the region's vertex it was found from.
  const auto in_region = [&](int w) {
    return std::find(region.begin(), region.end(), w) != region.end();
  };
  const std::size_t first = out.size();
  std::pmr::vector<int> faces_seen(memory);
  const auto faces = poly.adjacency_faces();
  for (const int x : region) {
    const auto offset =
        static_cast<std::size_t>(poly.adjacency_offsets()[static_cast<std::size_t>(x)]);
    const auto nbrs = poly.neighbors(x);
    for (std::size_t k = 0; k < nbrs.size(); ++k) {
      const int f = faces[offset + k];
      if (f < 0 || std::find(faces_seen.begin(), faces_seen.end(), f) != faces_seen.end()) continue;
      faces_seen.push_back(f);
      const auto cycle = poly.face(f);
      bool all = true;
      for (const std::int32_t w : cycle) all = all && in_region(w);
      if (!all) continue;
      for (std::size_t i = 1; i + 1 < cycle.size(); ++i)
        out.push_back(simplex(FeatureType::face, cycle[0], cycle[i], cycle[i + 1], f));
    }
  }
  if (out.size() > first) return;
  for (const int x : region)
    for (const std::int32_t w : poly.neighbors(x))
      if (x < w && in_region(w)) out.push_back(simplex(FeatureType::edge, x, w, -1, -1));
  if (out.size() > first) return;
  out.push_back(simplex(FeatureType::vertex, v, -1, -1, -1));
}

// The supporting regions of the winning candidate: A's along its normal n,
// B's along -n, appended to `ta` and `tb`.
template <class Out>
void support_regions(const Query& q, const Candidate& best, std::pmr::memory_resource* memory,
                     Out& ta, Out& tb) {
  const double tie = kTieUlps * kUnitRoundoff;
  support_region(
      q.a, [&](int i) { return q.point_a(i); }, best.normal, best.support_a, tie, memory, ta);
  support_region(
      q.b, [&](int j) { return q.point_b(j); }, Vec3(-best.normal), best.support_b, tie, memory,
      tb);
}

// A tracking cache's regions for the winning candidate, walked again
// (out of line: its buffer is not paid for by the queries that read them).
[[gnu::noinline]] void remember_regions(const Query& q, const Candidate& best,
                                        PenetrationCache::Witnesses& memo) {
  std::array<std::byte, 1024> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  memo.id = best.id;
  memo.normal = best.normal;
  memo.a.clear();
  memo.b.clear();
  support_regions(q, best, &memory, memo.a, memo.b);
}

bool same_face(const MinkowskiFaceId& x, const MinkowskiFaceId& y) {
  return x.kind == y.kind && x.a0 == y.a0 && x.a1 == y.a1 && x.b0 == y.b0 && x.b1 == y.b1;
}

// Builds the result from the winning candidate and the supporting regions
// along its normal n: A's simplices `ta`, B's `tb`.
[[gnu::always_inline]] inline PenetrationResult finish_with_regions(
    const Query& q, const Candidate& best, double lower_scaled, int candidates, bool tracked,
    std::span<const Feature> ta, std::span<const Feature> tb) {
  PenetrationResult r;
  r.candidates = candidates;
  r.tracked = tracked;
  r.face = best.id;
  const double band = contact_band(q.magnitude);
  const Vec3& n = best.normal;
  const double value = best.value;  // scaled
  r.normal = n;
  // Witnesses: a pair of points of the supporting features that differ by
  // value * n: the closest points of feature A and feature B moved by
  // value * n (the first least pair of simplices).
  const Vec3 shift = std::max(value, 0.0) * n;
  ClosestPoints<double> closest;
  closest.point_a = closest.point_b = Vec3::Zero();
  closest.distance_squared = std::numeric_limits<double>::infinity();
  const Feature* best_ta = nullptr;
  const Feature* best_tb = nullptr;
  for (const Feature& s : ta) {
    Vec3 pa[3];
    const int na = s.vertex_count();
    for (int i = 0; i < na; ++i) pa[i] = q.point_a(s.vertices[static_cast<std::size_t>(i)]);
    for (const Feature& t : tb) {
      Vec3 pb[3];
      const int nb = t.vertex_count();
      for (int j = 0; j < nb; ++j)
        pb[j] = q.point_b(t.vertices[static_cast<std::size_t>(j)]) + shift;
      const ClosestPoints<double> c = closest_points<double>(pa, na, pb, nb);
      if (c.distance_squared < closest.distance_squared) {
        closest = c;
        best_ta = &s;
        best_tb = &t;
      }
    }
  }
  const double residual = std::sqrt(closest.distance_squared) * q.unit;
  r.point_a = closest.point_a * q.unit;
  r.point_b = (closest.point_b - shift) * q.unit;
  if (best_ta != nullptr) {
    r.feature_a = *best_ta;
    r.feature_b = *best_tb;
  }
  const double depth = value * q.unit;
  if (depth < -band || (residual > band && depth <= band)) {
    // Separated: a plane separates them (depth < 0), or the supporting
    // features along the nearest plane do not meet (a flat M whose plane
    // holds the origin outside M; solve_cold first tries the faces tied
    // with it). Not for a value above the band: then the origin is inside
    // a solid M deeper than the band (every face's value is above it),
    // and features that do not meet only mean that a face tied with this
    // one within rounding holds the witness (a sliver's nearly coplanar
    // faces: the origin's foot on this face's plane lies outside it), not
    // that the hulls are apart (PenetrationRegression.SliverWithNearlyCoplanarFaces).
    r.status = PenetrationStatus::separated;
    r.depth = r.lower_bound = r.upper_bound = 0.0;
    return r;
  }
  r.status = depth > band ? PenetrationStatus::intersecting : PenetrationStatus::touching;
  r.depth = std::max(depth, 0.0);
  // The overlap along n, evaluated in double from B's vertices rounded
  // into A's frame and supports found in double, is within a few u R of
  // the exact overlap h_A(n) + h_B(-n) / |n| of the given doubles, which
  // bounds the exact depth from above: the value itself may fall below
  // the exact depth by that much (issue 25, exact_cases.jsonl line 2: an
  // upper bound 2e-21 below an exact depth of 1.05e-6, R 2e-5), so the
  // bound adds the value's slack, as the lower bound subtracts it.
  r.upper_bound = r.depth + band;
  r.lower_bound = std::max(0.0, std::min(lower_scaled, value) * q.unit - contact_band(q.magnitude));
  return r;
}

// Builds the result from the winning candidate. `memo` (a tracking cache's,
// or null) keeps the supporting regions of the answer's direction: a
// tracked answer along the same face of A - B (same id, same normal: B
// only translated) reads them instead of walking the hulls again.
// Without a cache (cold queries): the regions on the stack, out of line so
// that the tracked path's frame does not hold their buffer.
[[gnu::noinline]] PenetrationResult finish_untracked(const Query& q, const Candidate& best,
                                                     double lower_scaled, int candidates,
                                                     bool tracked) {
  std::array<std::byte, 2048> buffer;
  std::pmr::monotonic_buffer_resource memory(buffer.data(), buffer.size());
  std::pmr::vector<Feature> ta(&memory), tb(&memory);
  support_regions(q, best, &memory, ta, tb);
  return finish_with_regions(q, best, lower_scaled, candidates, tracked, ta, tb);
}

PenetrationResult finish(const Query& q, const Candidate& best, double lower_scaled, int candidates,
                         bool tracked, PenetrationCache::Witnesses* memo = nullptr) {
  if (memo == nullptr) return finish_untracked(q, best, lower_scaled, candidates, tracked);
  if (memo->a.empty() || !same_face(memo->id, best.id) || memo->normal != best.normal)
    remember_regions(q, best, *memo);
  return finish_with_regions(q, best, lower_scaled, candidates, tracked, memo->a, memo->b);
}

// Both hulls of dimension <= 1 with no crossing edges (points, parallel or
// collinear segments): M is a point or a segment, flat, depth 0. Touching
// when it holds the origin (the two hulls meet), else separated.
PenetrationResult finish_without_candidates(const Query& q) {
  Vec3 pa[2], pb[2];
  const int na = std::min(q.a.vertex_count(), 2), nb = std::min(q.b.vertex_count(), 2);
  for (int i = 0; i < na; ++i) pa[i] = q.point_a(i);
  for (int j = 0; j < nb; ++j) pb[j] = q.point_b(j);
  const ClosestPoints<double> c = closest_points<double>(pa, na, pb, nb);
  PenetrationResult r;
  r.point_a = c.point_a * q.unit;
  r.point_b = c.point_b * q.unit;
  r.feature_a.vertices = {0, na > 1 ? 1 : -1, -1};
  r.feature_a.type = na > 1 ? FeatureType::edge : FeatureType::vertex;
  r.feature_b.vertices = {0, nb > 1 ? 1 : -1, -1};
  r.feature_b.type = nb > 1 ? FeatureType::edge : FeatureType::vertex;
  // A normal orthogonal to M's direction (any, if M is a point).
  Vec3 along = na > 1 ? Vec3(pa[1] - pa[0]) : nb > 1 ? Vec3(pb[1] - pb[0]) : Vec3::UnitZ();
  along.normalize();
  r.normal = along.cross(std::abs(along.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY()).normalized();
  const double distance = std::sqrt(c.distance_squared) * q.unit;
  r.status = distance > contact_band(q.magnitude) ? PenetrationStatus::separated
                                                  : PenetrationStatus::touching;
  return r;
}

}  // namespace
}  // namespace proxima
