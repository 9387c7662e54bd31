// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The query API: checks the poses, moves the problem into A's frame (only
// B's relative pose is formed, never transformed vertex arrays), picks the
// contact band from the accuracy standard, runs the chosen algorithm and maps
// its answer back to the world frame.
#include "proxima/distance.h"

#include "proxima/gjk.h"
#include "proxima/hybrid.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace proxima {
namespace {

// The contact band of the accuracy standard: a distance at or below
// 64 u R is indistinguishable from contact for doubles of magnitude R.
constexpr double kContactUlps = 64.0;

void check_pose(const Pose& pose, const char* name) {
  if (!pose.is_finite()) [[unlikely]] {
    throw InvalidInput(std::string("distance: ") + name + " is not finite (NaN or infinite rotation or translation)");
  }
}

// Upper bound on the largest coordinate magnitude of a body placed at `pose`:
// |R y + t|_inf <= |t|_inf + |y|_2 <= |t|_inf + sqrt(3) scale.
double world_magnitude(const ConvexPolytope& p, const Pose& pose) {
  return pose.translation.cwiseAbs().maxCoeff() + std::sqrt(3.0) * p.scale();
}

}  // namespace

DistanceResult distance(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                        const Pose& pose_b, const DistanceOptions& options, DistanceCache* cache) {
  check_pose(pose_a, "pose_a");
  check_pose(pose_b, "pose_b");
  if (!(options.relative_tolerance >= 0.0) || !(options.absolute_tolerance >= 0.0) ||
      !std::isfinite(options.relative_tolerance) || !std::isfinite(options.absolute_tolerance)) {
    throw InvalidInput("distance: options.relative_tolerance and options.absolute_tolerance must be finite and >= 0");
  }
  if (options.max_iterations < 1) {
    throw InvalidInput("distance: options.max_iterations must be at least 1");
  }

  const Pose b_in_a = pose_a.inverse() * pose_b;
  const double r = std::max(world_magnitude(a, pose_a), world_magnitude(b, pose_b));
  const double contact_tolerance = kContactUlps * kUnitRoundoff * r + options.absolute_tolerance;

  DistanceCache cold;
  DistanceCache& c = cache != nullptr ? *cache : cold;
  DistanceResult result = options.algorithm == Algorithm::gjk
                         ? gjk_distance(a, b, b_in_a, options, contact_tolerance)
                     : options.algorithm == Algorithm::enhanced_gjk
                         ? enhanced_gjk_distance(a, b, b_in_a, options, contact_tolerance, c)
                         : hybrid_distance(a, b, b_in_a, options, contact_tolerance, c);
  // Back to the world frame, in place.
  result.point_a = pose_a.apply(result.point_a);
  result.point_b = pose_a.apply(result.point_b);
  result.normal = pose_a.rotation * result.normal;
  return result;
}

}  // namespace proxima
