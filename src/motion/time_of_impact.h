// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal: what time_of_impact shares with the scene's sweep and with its
// tests, not part of the public API (proxima/motion/time_of_impact.h).
#pragma once

#include "proxima/motion/time_of_impact.h"

namespace proxima::detail {

// time_of_impact's default tolerance, relative to the bodies' size: this
// fraction of the sum of their bounding radii (the scene's swept boxes
// grow by it too, so that no pair that may come within it is missed).
inline constexpr double kDefaultImpactTolerance = 1e-6;

// The checks of `options` that time_of_impact makes (InvalidInput naming
// `who` and the field), for callers that validate once before many calls
// (Scene::sweep).
void check_impact_options(const ImpactOptions& options, const char* who);

// sin x and cos x as a sweep's poses take them: a few ulps of std::sin and
// std::cos on [0, pi/2] (the half angles of a turn the shorter way) at a
// quarter of their cost, std::sin and std::cos elsewhere. Exposed for its
// twin test.
void sin_cos_quadrant(double x, double& sine, double& cosine);

}  // namespace proxima::detail
