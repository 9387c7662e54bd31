// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The `scene_demo` benchmark executable: a scene of many moving bodies
// (issue 6; `proxima scene-demo` before issue 9).
#pragma once

#include <cstdint>
#include <ostream>

namespace proxima::bench {

struct SceneDemoOptions {
  int bodies = 1000;
  int steps = 200;
  double margin = 0.1;
  std::uint64_t seed = 1;
  int threads = 1;  // narrow-phase threads (SceneOptions::threads)
  int every = 0;    // a statistics row every `every` steps; 0: about ten rows
};

// Builds the seeded scenario of the scene benchmark (scene_scenario.h: random convex bodies of
// 20-200 points moving with small velocities in a cube), runs proxima::Scene on it for `steps`
// steps and prints to `out` a header, a statistics row every `every` steps (step, candidate pairs,
// close pairs, intersecting pairs, ms for the step) and a summary (median and 90th percentile ms
// per step, convex queries per second). A progress line goes to `progress` (rewritten in place on a
// terminal, a line every few seconds otherwise). Returns the exit code.
// Throws InvalidInput for a negative or non-finite margin.
int run_scene_demo(const SceneDemoOptions& options, std::ostream& out, std::ostream& progress,
                   bool progress_is_terminal);

}  // namespace proxima::bench
