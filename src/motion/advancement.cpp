// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Conservative advancement of two moving convex hulls: the safe steps
// from the closing bounds of closing_bounds.h.
#include "advancement.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "closing_bounds.h"

namespace proxima::detail::toi {

ImpactResult advance_hulls(const MovingHull& ha, const MovingHull& hb, const ImpactOptions& options,
                           double tolerance, DistanceCache& c, double t_begin, double t_end) {
  const ConvexPolytope& a = *ha.hull;
  const ConvexPolytope& b = *hb.hull;
  const double target = options.target_separation;
  const Vec3 va = ha.sweep->linear_velocity();
  const Vec3 vb = hb.sweep->linear_velocity();
  const Vec3 wa = ha.sweep->angular_velocity();
  const Vec3 wb = hb.sweep->angular_velocity();
  const double reach_a = ha.reach;
  const double reach_b = hb.reach;
  const double any_speed = (vb - va).stableNorm() + fast_norm(wa) * reach_a + fast_norm(wb) * reach_b;

  const auto poses = [&](double t) {
    return std::pair<Pose, Pose>(ha.placed(ha.sweep->at(t)), hb.placed(hb.sweep->at(t)));
  };
  const auto query = [&](const Pose& pa, const Pose& pb) {
    return distance(a, pa, b, pb, options.distance, &c);
  };
  // Safe steps; the longest is taken. Along the normal n: the gap between
  // a plane that bounds A from above along n and one that bounds B from
  // below, each moving no faster than a bound (PlaneBound), so that the gap
  // is a certified lower bound on the distance until it closes to the
  // target. Three such planes per body: its hull's support plane, which
  // moves along n no faster than the body's speed along n plus the turn's
  // |w x n| times the reach (a point r from the reference point moves along
  // n at (w x r).n = (r x n).w, at most |w x n| |r|: a spin about the
  // normal does not approach); the support plane of its bounding ball (the
  // hull stays inside the ball as it turns), whose lever is only the
  // distance of the ball's center from the reference point: a round body
  // turning about its middle approaches at its linear speed only, so far
  // from contact the ball's planes give the longer step; and the support
  // feature's own plane (FeaturePlane: the true rates of its vertices
  // while they hold the support), which gives the longer step near a
  // contact. In any direction: the certified lower bound closes no
  // faster than any_speed. All keep off the contact band of the accuracy
  // standard at these poses (the rounding of the query's coordinates).
  const double relative_turn = fast_norm(wa - wb);
  MarginMemo memo_a, memo_b;
  FeatureSetMemo sets_a, sets_b;
  EdgePairs edge_pairs;
  edge_pairs.turn_a = fast_norm(wa);
  edge_pairs.turn_b = fast_norm(wb);
  edge_pairs.relative = relative_turn;
  edge_pairs.speed = fast_norm(vb - va);
  edge_pairs.reach_a = reach_a;
  edge_pairs.reach_b = reach_b;
  const auto contact_band_at = [&](const Pose& pa, const Pose& pb) {
    return contact_band(std::max(magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale())));
  };
  const auto safe_step = [&](const DistanceResult& r, const Pose& pa, const Pose& pb, double t) {
    const double band = contact_band_at(pa, pb);
    const Vec3& n = r.normal;
    const SupportPlanes hull = support_planes(a, pa, b, pb, n, c);
    const double turn_a = fast_norm(wa.cross(n));
    const double turn_b = fast_norm(wb.cross(n));
    const double inf = std::numeric_limits<double>::infinity();
    // A's top along n, and B's bottom as -(min along n): both rising at
    // `rate` at most bring them closer. The hull's and the ball's planes
    // have no span limit and no acceleration.
    // The balls' centers along n as the hull's vertices: n.t + (R^T n).c.
    const double along_a = n.dot(pa.translation), along_b = n.dot(pb.translation);
    const double speed_a = va.dot(n), speed_b = vb.dot(n);
    const PlaneBound top_a[2] = {
        {hull.top_a, speed_a + turn_a * reach_a, 0.0, inf},
        {along_a + hull.direction_a.dot(a.centroid()) + a.bounding_radius(),
         speed_a + turn_a * ha.lever, 0.0, inf}};
    const PlaneBound bottom_b[2] = {
        {-hull.bottom_b, -speed_b + turn_b * reach_b, 0.0, inf},
        {-(along_b + hull.direction_b.dot(b.centroid()) - b.bounding_radius()),
         -speed_b + turn_b * hb.lever, 0.0, inf}};
    SafeStep best = lower_bound_step(r.lower_bound - band, target, any_speed);
    // The step of planes x and y without their span limit, or 0 when their
    // gap is already closed.
    const auto unlimited = [&](const PlaneBound& x, const PlaneBound& y) {
      const double gap = -y.value - x.value - band - target;
      if (!(gap > 0.0)) return 0.0;
      return first_closing(gap, x.rate + y.rate, x.acceleration + y.acceleration, inf);
    };
    const auto take = [&](double step) {
      if (step == inf) {
        best.never = true;
      } else {
        best.step = std::max(best.step, step);
      }
    };
    for (const PlaneBound& x : top_a) {
      for (const PlaneBound& y : bottom_b) take(unlimited(x, y));
    }
    if (best.never) return best;
    const double horizon = 1.0 - t;
    // The reference points (a convex body's is its pose's translation).
    const Vec3 origin_a = ha.local != nullptr ? pa.apply(ha.origin) : pa.translation;
    const Vec3 origin_b = hb.local != nullptr ? pb.apply(hb.origin) : pb.translation;
    // The plane through two edges (edge_pair_step): an edge-edge contact
    // closes at its true rate, at second order. Before the feature planes,
    // whose spans it then mostly spares.
    if (r.feature_a.type == FeatureType::edge && r.feature_b.type == FeatureType::edge) {
      const double step = edge_pair_step(a, pa, origin_a, va, wa, r.feature_a, r.point_a, b, pb,
                                         origin_b, vb, wb, r.feature_b, r.point_b, n,
                                         2.0 * band + target, horizon, best.step, edge_pairs);
      if (step > best.step) take(step);
    }
    // The pairs with a feature's plane: its span (costly) only where the
    // step before the span limit beats the best so far.
    const VertexSet& set_a = sets_a.of(a, r.feature_a, hull.vertex_a);
    const VertexSet& set_b = sets_b.of(b, r.feature_b, hull.vertex_b);
    FeaturePlane feature_a(a, pa, ha.origin, set_a, n, hull.direction_a, 1.0, va, wa, turn_a,
                           memo_a);
    FeaturePlane feature_b(b, pb, hb.origin, set_b, n, hull.direction_b, -1.0, vb, wb, turn_b,
                           memo_b);
    const PlaneBound& fa = feature_a.bound();
    const PlaneBound& fb = feature_b.bound();
    const auto with_span = [&](double step, FeaturePlane* x, FeaturePlane* y) {
      if (!(step > best.step)) return;
      if (x != nullptr) step = std::min(step, x->span(step));
      if (y != nullptr) step = std::min(step, y->span(step));
      take(step);
    };
    with_span(unlimited(fa, fb), &feature_a, &feature_b);
    for (const PlaneBound& y : bottom_b) with_span(unlimited(fa, y), &feature_a, nullptr);
    for (const PlaneBound& x : top_a) with_span(unlimited(x, fb), nullptr, &feature_b);
    // The planes fixed in one body (fixed_plane_step), A's top and B's
    // bottom along n, over the rest of the interval; the span of the other
    // body's feature under the relative turn. Only where that body's witness
    // feature is a face, whose plane the support plane then is: a vertex
    // or an edge against it closes at its true rate (second order), where
    // the planes along a fixed n charge the fastest vertex of both
    // features. Against an edge or a vertex the gain is small and the cost
    // shows (bench/toi_bench at N = 8).
    const auto fixed = [&](double step, FeaturePlane& moving) {
      if (!(step > best.step)) return;
      if (relative_turn > 0.0)
        step = std::min(step, moving.margin(step * relative_turn) / relative_turn);
      take(step);
    };
    if (r.feature_a.type == FeatureType::face) {
      fixed(fixed_plane_step(hull.top_a, n, origin_a, va, wa, b, pb, origin_b, vb, wb,
                             feature_b.set(), band + target, horizon),
            feature_b);
    }
    if (r.feature_b.type == FeatureType::face) {
      fixed(fixed_plane_step(-hull.bottom_b, -n, origin_b, vb, wb, a, pa, origin_a, va, wa,
                             feature_a.set(), band + target, horizon),
            feature_a);
    }
    return best;
  };
  return advance(poses, options, tolerance, query, contact_band_at, safe_step, t_begin, t_end);
}

}  // namespace proxima::detail::toi
