// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal (motion layer): conservative advancement, the loop shared by
// every body kind, and its instance on two moving convex hulls.
#pragma once

#include <algorithm>
#include <tuple>
#include <utility>

#include "proxima/motion/time_of_impact.h"
#include "proxima/query/distance.h"
#include "sweep.h"

namespace proxima::detail::toi {

// A step that is safe from time t: no contact before t + step, or none at
// all before the end (never).
struct SafeStep {
  double step = 0.0;
  bool never = false;
};

// The tolerance is at least this many contact bands at the poses of a
// step (ImpactOptions::tolerance says so): the steps keep one band off
// the planes' gaps and two off the edge pair's (the query's rounding and
// the plane's own), and the gaps are the distance within a band of
// rounding, so a distance within a few bands of the target may allow no
// step at all; above four bands every gap still exceeds what is kept off,
// and the step is positive. A finer tolerance would end at the iteration
// cap with the distance already as close as doubles can tell.
inline constexpr double kMinToleranceBands = 4.0;

// The advancement loop shared by every body kind, over [t_begin, t_end]
// (no contact before t_begin is known): `poses(t)` the two poses at t,
// `query(pa, pb)` the distance query at them (its signed distance and
// status decide contact), `band(pa, pb)` the contact band there (the
// tolerance's floor, kMinToleranceBands), `safe_step(r, pa, pb)` how far
// time may advance after answer r. Safe up to t_end < 1: status separated
// at t = t_end, no query there (a caller that already has a contact at
// t_end).
template <class Poses, class Query, class Band, class Step>
ImpactResult advance(const Poses& poses, const ImpactOptions& options, double tolerance,
                     const Query& query, const Band& band, const Step& safe_step,
                     double t_begin = 0.0, double t_end = 1.0) {
  const double target = options.target_separation;
  const auto in_contact = [&](const DistanceResult& r, const Pose& pa, const Pose& pb) {
    return r.status == Status::intersecting || r.status == Status::touching ||
           r.signed_distance() <=
               target + std::max(tolerance, kMinToleranceBands * band(pa, pb));
  };
  ImpactResult out;
  double t = t_begin;
  for (;;) {
    // Named poses, not a structured binding: the lambda below captures
    // them, which clang (the fuzz build) refuses for bindings before C++20's
    // P1091 support.
    const auto placed = poses(t);
    const Pose& pa = placed.first;
    const Pose& pb = placed.second;
    const DistanceResult r = query(pa, pb);
    ++out.iterations;
    // The answer at t (copied out only when the loop stops there).
    const auto stop_here = [&](ImpactStatus status) {
      out.status = status;
      out.t = t;
      out.pose_a = pa;
      out.pose_b = pb;
      out.at_t = r;
      return out;
    };
    if (in_contact(r, pa, pb)) {
      // At t = 0: overlapping when the bodies overlap or are strictly within
      // the offset; touching (or at the offset) is a contact at t = 0.
      return stop_here(t == 0.0 &&
                               (r.status == Status::intersecting || r.signed_distance() < target)
                           ? ImpactStatus::intersecting
                           : ImpactStatus::contact);
    }
    if (out.iterations >= options.max_iterations) return stop_here(ImpactStatus::iteration_cap);
    const SafeStep s = safe_step(r, pa, pb, t);
    if (t_end < 1.0 && (s.never || t + s.step >= t_end)) {
      out.status = ImpactStatus::separated;
      out.t = t_end;
      return out;
    }
    if (s.never || t + s.step >= 1.0) {
      // Safe up to the end: the answer at t = 1.
      std::tie(out.pose_a, out.pose_b) = poses(1.0);
      out.at_t = query(out.pose_a, out.pose_b);
      ++out.iterations;
      out.t = 1.0;
      out.status = in_contact(out.at_t, out.pose_a, out.pose_b) ? ImpactStatus::contact
                                                                : ImpactStatus::separated;
      return out;
    }
    if (!(t + s.step > t)) {
      // No safe progress at this precision (bounds within rounding of the
      // target while the distance is not): stop, t is still safe.
      return stop_here(ImpactStatus::iteration_cap);
    }
    t += s.step;
  }
}

// The step that the certified lower bound allows, closing no faster than
// `speed` (the fastest any point of B moves relative to any point of A:
// the distance is 1-Lipschitz in the bodies' motion).
inline SafeStep lower_bound_step(double lower, double target, double speed) {
  if (!(lower > target)) return {};
  if (!(speed > 0.0)) return {0.0, true};
  return {(lower - target) / speed, false};
}

// A convex hull carried by a moving body: the hull placed in the body's
// frame by `local` (a compound's piece; the identity for a convex body),
// the body moving by `sweep`. The bounds below need the body's reference
// point in the hull's frame (`origin`, local^-1 of the body's origin), the
// lever of the hull's centroid about it and the reach of its vertices.
struct MovingHull {
  MovingHull(const ConvexPolytope& hull_, const Sweep& sweep_, const Pose* local_ = nullptr)
      : hull(&hull_), sweep(&sweep_), local(local_) {
    if (local != nullptr) origin = -(local->rotation.transpose() * local->translation);
    lever = (hull->centroid() - origin).stableNorm();
    reach = lever + hull->bounding_radius();
  }
  // The hull's pose when the body is at `body`.
  Pose placed(const Pose& body) const { return local != nullptr ? body * *local : body; }

  const ConvexPolytope* hull;
  const Sweep* sweep;
  const Pose* local;
  Vec3 origin = Vec3::Zero();
  double lever = 0.0;
  double reach = 0.0;
};


// Conservative advancement of two moving hulls over [t_begin, t_end] (see
// advance), towards options.target_separation, stopping within
// `tolerance` of it.
ImpactResult advance_hulls(const MovingHull& ha, const MovingHull& hb, const ImpactOptions& options,
                           double tolerance, DistanceCache& c, double t_begin = 0.0,
                           double t_end = 1.0);

}  // namespace proxima::detail::toi
