// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The motions time_of_impact follows: Motion's members, and the checks of
// a motion and of the options before any step.
#include "sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/accuracy.h"
#include "time_of_impact.h"

namespace proxima {

namespace detail {

void check_impact_options(const ImpactOptions& options, const char* who) {
  check_finite_non_negative(options.target_separation, who, "options.target_separation");
  check_finite_non_negative(options.tolerance, who, "options.tolerance", "0: the default");
  check_at_least(options.max_iterations, 1, who, "options.max_iterations");
  // The distance queries of the steps would refuse them too, but only
  // after the first steps: refused before any, by their full name.
  check_distance_options(options.distance, who, "options.distance");
}

}  // namespace detail

using detail::toi::finite;
using detail::toi::kMaxTurnRate;
using detail::toi::Sweep;

Motion Motion::from_velocity(const Pose& pose, const Vec3& linear, const Vec3& angular,
                             double duration) {
  if (!finite(linear) || !finite(angular) || !std::isfinite(duration) || !(duration > 0.0)) {
    throw InvalidInput(
        "Motion::from_velocity: the velocities must be finite and the duration finite and > 0");
  }
  // The turn per unit t, kept: the end pose alone cannot say how many
  // turns the body made, nor which way past a half turn.
  Motion m{pose, pose, Vec3(duration * angular)};
  m.end.translation = pose.translation + duration * linear;
  if (!finite(*m.angular) || !(m.angular->stableNorm() <= kMaxMagnitude) ||
      !finite(m.end.translation)) {
    throw InvalidInput(
        "Motion::from_velocity: the turn or the end translation over the duration is beyond "
        "the supported magnitude 2^1018 (about 2.8e306)");
  }
  m.end.rotation = Sweep(m).turned(1.0);
  return m;
}

Vec3 Motion::angular_velocity() const {
  if (angular) return *angular;
  const Eigen::AngleAxisd turn(Mat3(end.rotation * start.rotation.transpose()));
  return turn.angle() * turn.axis();
}

Pose Motion::at(double t) const { return Sweep(*this).at(t); }

namespace detail::toi {

double body_size(const Body& body) {
  switch (body.kind()) {
    case Body::Kind::convex:
      return body.convex()->bounding_radius() + body.radius();
    case Body::Kind::compound:
      return body.compound()->bounding_radius() + body.radius();
    case Body::Kind::mesh:
      return body.mesh()->bounding_radius() + body.radius();
  }
  return 0.0;
}

namespace {

// checked_sweep's checks after the pose contract's, on rigid poses.
Sweep limited_sweep(const Motion& m, double scale, const char* name) {
  const Motion& checked = m;
  const auto refuse = [&](const std::string& what) {
    throw InvalidInput(std::string(name) + what);
  };
  if (m.angular && !(finite(*m.angular) && std::isfinite(m.angular->stableNorm())))
    refuse(".angular is not finite (NaN or infinite, or its length overflows)");
  if (m.angular && !(m.angular->stableNorm() <= kMaxTurnRate)) {
    char what[240];
    std::snprintf(what, sizeof what,
                  ".angular turns at %.3g rad per unit t, beyond the supported %.3g (2^52), where "
                  "the angle t |w| is not known to a radian in doubles: scale the motion's time down",
                  m.angular->stableNorm(), kMaxTurnRate);
    refuse(what);
  }
  for (const Pose* end : {&checked.start, &checked.end}) {
    const double magnitude = magnitude_bound(*end, scale);
    if (!(magnitude <= kMaxMagnitude)) {
      char what[220];
      std::snprintf(what, sizeof what,
                    ".%s reaches coordinates of magnitude %.3g (vertices and pose translation), "
                    "beyond the supported %.3g where differences of coordinates may overflow",
                    end == &checked.start ? "start" : "end", magnitude, kMaxMagnitude);
      refuse(what);
    }
  }
  Sweep sweep(checked);
  if (m.angular) {
    // The turn must end where the motion says it does: the angle's
    // rounding (a few u of it, a rotation a few u off) is far inside the
    // pose contract's tolerance, which a different end (a motion built
    // with one angular velocity and another end pose) is not.
    const double off = (sweep.turned(1.0) - checked.end.rotation).cwiseAbs().maxCoeff();
    if (!(off <= kRotationTolerance)) {
      refuse(".end.rotation is not where .angular turns .start.rotation at t = 1 (off by " +
             std::to_string(off) + "): give the end pose that angular velocity reaches, as " +
             "Motion::from_velocity does");
    }
  }
  return sweep;
}

// A motion under the pose contract (re-orthonormalized where the contract
// allows it), its angular velocity (when given) finite and ending at
// end.rotation, and both ends within the coordinate magnitude the distance

}  // namespace

Sweep checked_sweep(const Motion& m, double scale, const char* name) {
  // Both ends' check at once (the common case), else each end's own.
  if (detail::are_rigid(m.start, m.end)) [[likely]]
    return limited_sweep(m, scale, name);
  return limited_sweep(Motion{checked_pose(m.start, std::string(name) + ".start"),
                              checked_pose(m.end, std::string(name) + ".end"), m.angular},
                       scale, name);
}

void check_closing_speed(const Sweep& ma, double scale_a, const Sweep& mb, double scale_b) {
  const double speed = (mb.linear_velocity() - ma.linear_velocity()).stableNorm() +
                       ma.angle() * std::sqrt(3.0) * scale_a +
                       mb.angle() * std::sqrt(3.0) * scale_b;
  if (!std::isfinite(speed)) {
    throw InvalidInput(
        "time_of_impact: the motions' closing speed bound |v_b - v_a| + |w_a| reach_a + "
        "|w_b| reach_b overflows doubles (velocities times sizes beyond about 1.8e308): "
        "scale the motions' time down");
  }
}

}  // namespace detail::toi

}  // namespace proxima
