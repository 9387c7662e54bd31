// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the exit codes every `proxima` command returns (README, "The
// command line"): 0 when it answered, 1 for bad input or a failed query, 2
// for a usage error (CLI11's own code for one).
#pragma once

namespace proxima::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

}  // namespace proxima::cli
