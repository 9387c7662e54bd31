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

struct GjkFrame {
  const ConvexPolytope& a;
  const ConvexPolytope& b;
  const Pose& b_in_a;
  double magnitude = 0.0;  // bound on the largest coordinate magnitude in A's frame
  double unit = 1.0;       // a power of two near it
  double inv_unit = 1.0;   // exact reciprocal

  GjkFrame(const ConvexPolytope& pa, const ConvexPolytope& pb, const Pose& pose)
      : a(pa), b(pb), b_in_a(pose) {
    // B's coordinates in A's frame are bounded without mapping its vertices.
    magnitude = std::max(a.scale(), magnitude_bound(pose, b.scale()));
    const PowerOfTwoUnit u = power_of_two_unit(magnitude);
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
