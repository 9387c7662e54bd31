// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal (motion layer): time of impact between bodies with many pieces
// (compounds, meshes), a branch and bound over piece pairs.
#pragma once

#include "proxima/motion/time_of_impact.h"
#include "proxima/query/body_distance.h"
#include "sweep.h"

namespace proxima::detail::toi {

// The time of impact of two Bodies that are not both convex, each moving
// by its sweep, towards options.target_separation within `tolerance`:
// every piece pair whose bounds may meet before the best time so far is
// advanced (advance_hulls), from the earliest time its bounds allow.
// The answer at t is the Bodies' distance query with cache `c`.
ImpactResult advance_pieces(const Body& a, const Sweep& ma, const Body& b, const Sweep& mb,
                            const ImpactOptions& options, double tolerance, BodyCache& c);

}  // namespace proxima::detail::toi
