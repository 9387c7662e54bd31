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

}  // namespace proxima::detail
