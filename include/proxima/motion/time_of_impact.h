// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// motion layer: continuous collision. The first time at which two moving convex
// bodies come within a target separation of each other, never later than
// the true one: a thin or fast body cannot pass through another between two
// poses unnoticed (tunnelling).
//
//   proxima::Motion ma{pose_a0, pose_a1}, mb{pose_b0, pose_b1};
//   auto r = proxima::time_of_impact(a, ma, b, mb);
//   if (r.status == proxima::ImpactStatus::contact) { /* at r.t, r.pose_a, r.pose_b */ }
//
// The motion of a body over t in [0, 1] (Motion): its reference point (the
// origin of its frame, where its pose's translation puts it) moves at
// constant velocity from start.translation to end.translation, and the body
// turns at constant angular velocity about that point. A motion given by
// velocities (Motion::from_velocity, which keeps the angular velocity in
// Motion::angular) turns at that rate through any angle, several turns
// included: a spinning wheel, a body tumbling over a long step. A motion
// given by its end poses alone turns from start.rotation to end.rotation
// by the shorter way (the rotation R1 R0^T as an angle in [0, pi] about a
// world axis; a half turn is ambiguous and takes either axis). FCL's
// interpolated motion and Box3D's sweep move the same way about their own
// reference points.
//
// The method: conservative advancement (Mirtich) on the tracked distance
// query. At time t the query's normal n (unit, A towards B) and the support
// planes of the two hulls along n bound the distance from below by their
// gap s; no point of B approaches A's plane along n faster than
//   mu = (v_a - v_b).n + |w_a x n| rho_a + |w_b x n| rho_b,
// rho being the farthest hull vertex from the body's reference point, so
// the distance stays above the target until t + (s - target) / mu, and the
// time advances there. Two more planes per body bound longer steps where
// they can (src/motion/time_of_impact.cpp says why each is safe): its bounding
// ball's, whose lever under the turn is the ball center's distance from
// the reference point, and its witness feature's own, which moves at the
// true rates of the feature's vertices while they hold the support (at
// second order in the turn for a vertex). Where a body's witness feature
// is a face, its support plane moving with the body bounds the gap too:
// that body never crosses it, and the other body's feature vertices
// approach it at their true rates in its frame (a vertex-face contact
// closes at second order). Where both witness features are edges, the
// plane through both edges (its normal e_a x e_b turning with them) bounds
// the gap at the edges' true closing rate, so an edge-edge contact closes
// at second order too. The cache carried from step to step makes each
// step a tracked query (a few hundred nanoseconds).
//
// Thread safety: as distance(); the cache belongs to one pair.
#pragma once

#include <optional>

#include "proxima/core/types.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// A body's motion over t in [0, 1] (see above).
struct Motion {
  Motion() = default;
  Motion(const Pose& start_pose, const Pose& end_pose) : start(start_pose), end(end_pose) {}
  Motion(const Pose& start_pose, const Pose& end_pose, const std::optional<Vec3>& angular_velocity)
      : start(start_pose), end(end_pose), angular(angular_velocity) {}

  Pose start;
  Pose end;
  // The angular velocity (world frame, radians per unit t) of a motion
  // given by velocities: the body turns at this rate through any angle,
  // and end.rotation is where that turn ends (time_of_impact refuses an
  // end.rotation that is not, beyond the pose contract's kRotationTolerance).
  // Unset: the turn from start.rotation to end.rotation the shorter way.
  std::optional<Vec3> angular;

  // A body that does not move.
  static Motion fixed(const Pose& pose) { return {pose, pose}; }
  // From `pose`, moving its reference point at `linear` (units per unit
  // time) and turning at `angular` (radians per unit time, about the world
  // axis angular / |angular|, through any angle) for `duration`; t = 1 is
  // the end of it. Throws InvalidInput for a non-finite velocity or
  // duration, a duration <= 0, or an end pose or a turn per unit t that
  // overflows doubles.
  static Motion from_velocity(const Pose& pose, const Vec3& linear, const Vec3& angular,
                              double duration = 1.0);

  // The pose at time t (0 <= t <= 1; clamped outside).
  Pose at(double t) const;
  // The reference point's velocity (units per unit t) and the angular
  // velocity (world frame, radians per unit t): `angular` when set, else
  // the shorter way's.
  Vec3 linear_velocity() const { return end.translation - start.translation; }
  Vec3 angular_velocity() const;
};

enum class ImpactStatus : std::uint8_t {
  separated,      // no contact over [0, 1]: the distance stays above the target
  contact,        // the distance reaches the target (within tolerance) at t
  intersecting,   // already intersecting (or strictly within the target) at t = 0
  iteration_cap,  // stopped at options.max_iterations; t is still safe
};

inline const char* to_string(ImpactStatus s) {
  switch (s) {
    case ImpactStatus::separated:
      return "separated";
    case ImpactStatus::contact:
      return "contact";
    case ImpactStatus::intersecting:
      return "intersecting";
    case ImpactStatus::iteration_cap:
      return "iteration_cap";
  }
  return "unknown";
}

struct ImpactOptions {
  // The separation at which the bodies count as in contact (a contact
  // offset, as simulators use); >= 0.
  double target_separation = 0.0;
  // How close to the target the distance must come before contact is
  // reported: at the reported t, target <= distance <= target + tolerance
  // (up to the contact band 64 u R of the accuracy standard). >= 0; 0: the
  // default, relative to the bodies' size (bounding radii): 1e-6 of it. A
  // tolerance below 4 contact bands at the poses of a step (4 x 64 u R,
  // R the largest coordinate magnitude there) is raised to that there:
  // the distance is not known more finely, and the advancement keeps the
  // band off its steps.
  double tolerance = 0.0;
  // Cap on advancement steps (each one distance query).
  int max_iterations = 256;
  // Options of the distance queries of each step.
  DistanceOptions distance;
};

struct ImpactResult {
  ImpactStatus status = ImpactStatus::separated;
  // The time reached: for contact, the time of impact; never after the true
  // first time t* at which the distance reaches the target. 1 when
  // separated, 0 when overlapping.
  double t = 1.0;
  Pose pose_a;  // the bodies' poses at t
  Pose pose_b;
  // The distance query at t: closest points, normal, features, certificate.
  DistanceResult at_t;
  int iterations = 0;  // advancement steps (distance queries)
  // Bodies with compounds or meshes: the pieces of at_t's closest pair, a
  // compound's piece index or a mesh's triangle index (at_t's features are
  // theirs: BodyResult's piece_a / triangle_a), -1 for a convex body; and
  // the piece pairs (a mesh's pieces being its triangles) whose convex
  // advancement ran (the others were pruned by their bounding balls).
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
  int pairs_advanced = 0;
};

// First time of contact of hull a moving by `motion_a` and hull b moving by
// `motion_b` over t in [0, 1]. Guarantee: the reported t <= t*, the first
// time the exact distance comes within the target separation (no contact is
// ever missed, whatever the speeds and thicknesses), and for status contact
// the distance at t is within options.tolerance of the target. Throws
// InvalidInput for bad poses (the pose contract of proxima/core/pose.h at both
// ends), a Motion::angular that is not finite or does not end at
// end.rotation, motions that cannot be followed in doubles (a turn faster
// than 2^52 (4.5e15) rad per unit t, whose angle doubles cannot tell to a
// radian; an end pose
// beyond the supported coordinate magnitude 2^1018, about 2.8e306, as
// distance(); or a closing speed |v_b - v_a| + |w_a| reach_a + |w_b|
// reach_b that overflows), or options (negative target, tolerance < 0 or
// not finite, max_iterations < 1). `cache` (may be null) is carried from step to step
// and left as the last query's, so that a next interval tracks on.
ImpactResult time_of_impact(const ConvexPolytope& a, const Motion& motion_a,
                            const ConvexPolytope& b, const Motion& motion_b,
                            const ImpactOptions& options = {}, DistanceCache* cache = nullptr);

// The same for Bodies of any kinds (proxima/query/body_distance.h): a rounded body's
// radius adds to the target separation (the cores' distance must stay
// above the target plus both radii), and at_t describes the rounded bodies
// (BodyResult's conventions, sliced to a DistanceResult: points on the
// rounded surfaces). Compounds and meshes: the earliest over pairs of
// convex pieces (a compound's pieces, a convex body as its one piece, each
// triangle of a mesh as the flat hull of its corners) of their convex
// advancement, by branch and bound over the two hierarchies: pairs are
// taken in order of the earliest time their moving bounding balls can meet
// and pruned from the best time found on, so that only the pieces that can
// be hit first are advanced (pairs_advanced). A body that starts inside a
// closed mesh is overlapping at t = 0. `cache` may be null.
ImpactResult time_of_impact(const Body& a, const Motion& motion_a, const Body& b,
                            const Motion& motion_b, const ImpactOptions& options = {},
                            BodyCache* cache = nullptr);

}  // namespace proxima
