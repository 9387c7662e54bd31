// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the geometry of a GJK query (the two bodies, B's pose in
// A's frame and the power-of-two unit the simplex arithmetic runs in) and the
// support functions of the Minkowski difference C = A - B on it.
#pragma once

#include <algorithm>
#include <cstdint>

#include "core/power_of_two.h"
#include "narrowphase/simplex_solver.h"
#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"
#include "proxima/shape/support.h"

namespace proxima::detail {

// Rounding of a point of C = A - B as GJK forms it, a - (R y + t), in units
// of u times the query's magnitude R: the three products and three sums of
// R y + t (each coordinate off by at most 4 u (|R| |y| + |t|) <= 4 u R),
// the subtraction, and the same for B's placed centroid and the centroids'
// and radii's own rounding (polytope.cpp), with room to spare. It only has
// to keep the unit within a small factor of the largest computed point.
inline constexpr double kPointRoundingUlps = 16.0;

struct GjkFrame {
  const ConvexPolytope& a;
  const ConvexPolytope& b;
  const Pose& b_in_a;
  double magnitude = 0.0;  // bound on the largest coordinate magnitude in A's frame
  double unit = 1.0;       // a power of two near the largest point of C (below)
  double inv_unit = 1.0;   // exact reciprocal

  GjkFrame(const ConvexPolytope& pa, const ConvexPolytope& pb, const Pose& pose)
      : a(pa), b(pb), b_in_a(pose) {
    // B's coordinates in A's frame are bounded without mapping its vertices.
    magnitude = std::max(a.scale(), magnitude_bound(pose, b.scale()));
    // The unit follows the points GJK computes with, the differences a - b,
    // not R: they are at most the centroids' distance plus both radii (in
    // the max norm: no square to overflow near 2^1018), plus their
    // rounding. Where a pose translation cancels large local coordinates
    // (a point at 3e93 in its own frame placed at -3e93: C is a box of size
    // 50 and R is 1e94), a unit near R made C's points 1e-93 in size, the
    // solver's squared face normals (fourth powers) underflowed to zero,
    // and GJK never enclosed the origin of a box around it: it hit the
    // iteration cap (GjkRegression.CancelledTranslationConverges). With this
    // unit C's points are at most 1 and at least the rounding 16 u R, so no
    // square, cube or fourth power of them over- or underflows.
    const double spread = (a.centroid() - pose.apply(b.centroid())).cwiseAbs().maxCoeff() +
                          a.bounding_radius() + b.bounding_radius() +
                          kPointRoundingUlps * kUnitRoundoff * magnitude;
    const PowerOfTwoUnit u = power_of_two_unit(spread);
    unit = u.unit;
    inv_unit = u.inverse;
  }

  Vec3 b_point(std::int32_t ib) const { return b_in_a.apply(b.vertex(ib)); }
  SupportPoint point(std::int32_t ia, std::int32_t ib) const {
    return {(a.vertex(ia) - b_point(ib)) * inv_unit, ia, ib};
  }
  // A direction of A's frame seen in B's frame (a rotation only).
  Vec3 dir_in_b(const Vec3& d) const { return b_in_a.rotation.transpose() * d; }
};

// Support of C = A - B in direction d: argmax d.(a - b) = s_A(d) - s_B(-d),
// by linear scans (classic GJK).
struct BruteForceSupport {
  const GjkFrame& frame;
  SupportPoint operator()(const Vec3& d) const {
    const int ia = support_brute_force(frame.a.vertices(), d);
    const int ib = support_brute_force(frame.b.vertices(), frame.dir_in_b(-d));
    return frame.point(ia, ib);
  }
};

// The same by hill climbing from the last answers (Enhanced GJK).
struct HillClimbSupport {
  const GjkFrame& frame;
  std::int32_t hint_a = 0;
  std::int32_t hint_b = 0;
  SupportPoint operator()(const Vec3& d) {
    const Vec3 d_b = frame.dir_in_b(-d);
    hint_a = support_hill_climb(frame.a, d, nearer_start(frame.a, d, hint_a));
    hint_b = support_hill_climb(frame.b, d_b, nearer_start(frame.b, d_b, hint_b));
    return frame.point(hint_a, hint_b);
  }
  // The hint or the hull's table start (ConvexPolytope::support_start),
  // whichever is higher along d: GJK's directions jump between iterations,
  // and a climb from the last support can cross much of a large hull.
  static int nearer_start(const ConvexPolytope& p, const Vec3& d, int hint) {
    const int start = p.support_start(d);
    if (start < 0 || hint < 0 || hint >= p.vertex_count()) return start < 0 ? hint : start;
    return d.dot(p.vertex(start)) > d.dot(p.vertex(hint)) ? start : hint;
  }
};

}  // namespace proxima::detail
