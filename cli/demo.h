// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima demo`, the job behind `make run`.
#pragma once

namespace proxima::cli {

// Builds two fixed, seeded polytopes, prints their hull statistics, the
// closest points of one feature pair and the distance query with every
// algorithm, to stdout. Returns the process exit code. Throws what the
// library throws.
int run_demo();

}  // namespace proxima::cli
