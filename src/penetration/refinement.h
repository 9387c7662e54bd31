// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): exact refinement of an answer near the contact band.
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include <optional>
#include <span>
#include "penetration/witnesses.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima {
namespace {

// Refinement at the contact band. In double, a value's error is a few u
// R (the normal's rounding times the support points' magnitude), so a
// depth within a few bands of the band cannot be told above or below it:
// the status there would follow rounding (a depth 1.09 bands deep was
// called touching, PenetrationRegression.DepthJustAboveTheBandIsPenetrating).
// Answers whose least value is within kRefineBands bands of zero are
// refined: each face of A - B that can realize the depth (value within
// kRefineWindow of the least, plus its own normal's error times the
// points' magnitude for an edge pair, whose normal is ill-conditioned when
// the edges are nearly parallel) gets its value exactly (exact_offset: the
// face's normal N from its edge vectors in integers, the supports along N
// the exact best of the tie region along the rounded normal, which holds an
// exact maximizer by support_hill_climb_through_plateaus' argument), and
// the depth is the least exact value, rounded, its status decided exactly
// against 64 u R (R the largest coordinate of A's vertices and B's placed
// ones). Off the tracked path: a tracked answer there enumerates again.
constexpr double kRefineBands = 4.0;
// Twice a value's slack: the face that realizes the depth, whose exact
// value is the least, has a rounded value within it of the least rounded.
constexpr double kRefineWindow = 2.0 * kValueSlackUlps;

// The refined value is exact for B's vertices as placed in A's frame in
// double (or A's supports as mapped into B's frame, for a face of B), not
// for the bodies the world poses place: those differ by the rounding of
// B's pose relative to A and of its application, and by the rotations'
// distance from orthonormal that the pose contract accepts (kOrthonormalUlps
// u per entry of R^T R - I, proxima/core/pose.h), which makes R^T differ
// from R^-1. The signed distance moves by at most the points' displacement
// (docs/accuracy.md, "The refined depth's certificate", derives both
// terms, in u of the magnitude bound M of A's frame): at most
// kPlacementRoundingUlps u M for the rounding (76 for a face of B, 19
// for the others) and kSkewLeverUlps times the contract's tolerance, plus
// a relative kSkewLeverRelative times it for the change of frame, which
// is not rigid. Pinned by
// SignedDistanceOracle.CertificatesNearTheBandHoldUnderRotatedPoses.
constexpr double kPlacementRoundingUlps = 80.0;
constexpr double kSkewLeverUlps = 5.2;  // 3 sqrt(3), rounded up
constexpr double kSkewLeverRelative = 2.0;
constexpr double kRefinedPlacementUlps =
    kPlacementRoundingUlps + kSkewLeverUlps * kOrthonormalUlps;

// Whether a value (scaled units) is within kRefineBands bands of zero.
bool near_band(const Query& q, double value) {
  return std::abs(value) <= kRefineBands * kValueSlackUlps * kUnitRoundoff * q.magnitude * q.inverse;
}

// Whether an answer is one to refine: an overlap (a separated answer's
// value is below minus the band) within kRefineBands bands of zero.
bool needs_refinement(const Query& q, const PenetrationResult& r) {
  return r.status != PenetrationStatus::separated && near_band(q, r.depth * q.inverse);
}

// The vertices of `poly` (mapped by `point`) connected to v through
// vertices whose value along d is within `tie` of v's, appended to `out`.
template <class PointOf>
void tie_region(const ConvexPolytope& poly, PointOf&& point, const Vec3& d, int v, double tie,
                std::vector<int>& ids, std::vector<Vec3>& out) {
  const double top = d.dot(point(v));
  ids.assign(1, v);
  for (std::size_t head = 0; head < ids.size(); ++head)
    for (const std::int32_t w : poly.neighbors(ids[head]))
      if (std::find(ids.begin(), ids.end(), w) == ids.end() && d.dot(point(w)) >= top - tie)
        ids.push_back(w);
  out.clear();
  for (const int i : ids) out.push_back(point(i));
}

// The exact value of candidate c (scaled units) against c_band, or
// nothing for a candidate that is not a named face of A - B.
std::optional<detail::ExactOffset> exact_value(const Query& q, const Candidate& c, double c_band) {
  const MinkowskiFaceId& id = c.id;
  Vec3 u0, u1, w0, w1;
  // The normal's angle error (of the rounded normal from the exact one).
  double angle = 0.0;
  // Whether N and the supports are taken in B's frame (a face of B).
  bool in_b = false;
  if (id.kind == MinkowskiFace::face_vertex && id.a0 >= 0) {
    const auto cycle = q.a.face(id.a0);
    u0 = w0 = q.point_a(cycle[0]);
    u1 = q.point_a(cycle[1]);
    w1 = q.point_a(cycle[2]);
    angle = 16.0 * (static_cast<double>(cycle.size()) + 1.0) * kUnitRoundoff;
  } else if (id.kind == MinkowskiFace::vertex_face && id.b0 >= 0) {
    // A face of B: its normal from B's own coordinates, in B's frame
    // (exact_value_in_b); the placed ones are rounded by u R each, which
    // tilts the normal of a thin fan triangle by u R / (its height), and
    // the value by that times the points' distance from it.
    const auto cycle = q.b.face(id.b0);
    u0 = w0 = q.b.vertex(cycle[0]) * q.inverse;
    u1 = q.b.vertex(cycle[1]) * q.inverse;
    w1 = q.b.vertex(cycle[2]) * q.inverse;
    angle = (16.0 * (static_cast<double>(cycle.size()) + 1.0) + 8.0) * kUnitRoundoff;
    in_b = true;
  } else if (id.kind == MinkowskiFace::edge_edge && id.a0 >= 0 && id.b0 >= 0) {
    u0 = q.point_a(id.a0);
    u1 = q.point_a(id.a1);
    w0 = q.point_b(id.b0);
    w1 = q.point_b(id.b1);
    const Vec3 ea = detail::exponent_free(u1 - u0), eb = detail::exponent_free(w1 - w0);
    const double cross = ea.cross(eb).norm();
    if (!(cross > 0.0)) return std::nullopt;
    angle = (8.0 * ea.norm() * eb.norm() / cross + 4.0) * kUnitRoundoff;
  } else {
    return std::nullopt;
  }
  // N along the rounded normal: (u1 - u0) x (w1 - w0), or with the edges
  // swapped its negative.
  const Vec3 normal = in_b ? Vec3(q.rotation_t * c.normal) : c.normal;
  if ((u1 - u0).cross(w1 - w0).dot(normal) < 0.0) {
    std::swap(u0, w0);
    std::swap(u1, w1);
  }
  // Rounded values along c.normal are within (angle + 4 u) |x| of the
  // exact ones along N / |N| (|x| <= 2 in scaled units): twice that is the
  // tie that keeps an exact maximizer in the region.
  const double tie = 2.0 * (angle + 4.0 * kUnitRoundoff) * 2.0;
  std::vector<int> ids;
  std::vector<Vec3> xs, ys;
  tie_region(
      q.a, [&](int i) { return q.point_a(i); }, c.normal, c.support_a, tie, ids, xs);
  tie_region(
      q.b, [&](int j) { return q.point_b(j); }, Vec3(-c.normal), c.support_b, tie, ids, ys);
  if (in_b) {
    // The value in B's frame: the translation cancels from h_A(n) + h_B(-n),
    // A's supports are mapped there (rounded by a few u R, which the value
    // takes once, not times a lever) and B's are its own coordinates.
    for (Vec3& x : xs) x = q.rotation_t * (x - q.translation);
    for (std::size_t k = 0; k < ys.size(); ++k) ys[k] = q.b.vertex(ids[k]) * q.inverse;
  }
  const detail::ExactOffset e = detail::exact_offset(u0, u1, w0, w1, xs, ys, c_band);
  if (e.degenerate) return std::nullopt;
  return e;
}

// The largest coordinate of A's vertices and B's placed ones (scaled):
// the R of the standard in A's frame.
double frame_magnitude(const Query& q) {
  double r = 0.0;
  for (int i = 0; i < q.a.vertex_count(); ++i) r = std::max(r, q.point_a(i).cwiseAbs().maxCoeff());
  for (int j = 0; j < q.b.vertex_count(); ++j) r = std::max(r, q.point_b(j).cwiseAbs().maxCoeff());
  return r;
}

// Refines an answer near the band (see kRefineBands): `r` from `best`
// among `candidates`. The least exact value's candidate gives the answer,
// its status exact against the band of the frame's R.
PenetrationResult refine(const Query& q, std::span<const Candidate> candidates,
                         const Candidate& best, const PenetrationResult& r, int count) {
  const double band_scaled = contact_band(frame_magnitude(q));
  const double reach = 2.0;
  const Candidate* winner = nullptr;
  double least = kInfinity;
  bool touching = false;
  for (const Candidate& c : candidates) {
    // The window, widened by an edge pair's normal error times the points'
    // magnitude (exact_value's angle, recomputed cheaply here).
    double widen = 0.0;
    if (c.id.kind == MinkowskiFace::edge_edge && c.id.a0 >= 0 && c.id.b0 >= 0) {
      const Vec3 ea = detail::exponent_free(q.point_a(c.id.a1) - q.point_a(c.id.a0));
      const Vec3 eb = detail::exponent_free(q.point_b(c.id.b1) - q.point_b(c.id.b0));
      const double cross = ea.cross(eb).norm();
      widen = cross > 0.0 ? 8.0 * ea.norm() * eb.norm() / cross * kUnitRoundoff * reach : kInfinity;
    }
    if (!(c.value <= best.value + kRefineWindow * kUnitRoundoff + widen)) continue;
    const std::optional<detail::ExactOffset> e = exact_value(q, c, band_scaled);
    if (!e) continue;
    touching = touching || e->versus <= 0;
    if (e->offset < least) {
      least = e->offset;
      winner = &c;
    }
  }
  if (winner == nullptr) return r;
  Candidate refined = *winner;
  refined.value = least;
  PenetrationResult out = finish(q, refined, least, count, false);
  if (out.status == PenetrationStatus::separated) return out;
  // The exact value of the placed doubles is within 4 u of `least`; the
  // bodies the poses place are within kRefinedPlacementUlps u M and the
  // frame's relative distortion of it (see kRefinedPlacementUlps).
  const double depth = std::max(least, 0.0) * q.unit;
  const double relative = 8.0 * kUnitRoundoff + kSkewLeverRelative * kOrthonormalUlps * kUnitRoundoff;
  const double placement = kRefinedPlacementUlps * kUnitRoundoff * q.magnitude;
  out.status = touching ? PenetrationStatus::touching : PenetrationStatus::intersecting;
  out.depth = depth;
  out.upper_bound = depth * (1.0 + relative) + placement;
  out.lower_bound = std::max(depth * (1.0 - relative) - placement, 0.0);
  return out;
}

}  // namespace
}  // namespace proxima
