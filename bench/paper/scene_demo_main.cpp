// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The `scene_demo` benchmark executable (build/<preset>/bench/scene_demo):
// many moving bodies through proxima::Scene, per-step statistics.
//   scene_demo [--bodies N] [--steps S] [--margin M] [--seed K] [--threads T] [--every E]
// Before issue 9 this was `proxima scene-demo`; its scenario lives with the
// benchmarks (scene_scenario.h), which the shipped CLI must not link.
//
// Exit codes: 0 ok, 1 bad values (e.g. a negative margin), 2 usage errors.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "paper/scene_demo.h"

namespace {
// Upper end of --threads: it only keeps a typo from starting a million threads.
constexpr int kMaxThreads = 1024;
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "scene_demo: run a seeded scene of moving random convex bodies through proxima::Scene and "
      "print per-step statistics (candidate, close and intersecting pairs, time per step)"};
  proxima::bench::SceneDemoOptions options;
  app.add_option("--bodies", options.bodies, "Number of bodies")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  app.add_option("--steps", options.steps, "Number of steps")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  app.add_option("--margin", options.margin,
                 "Pairs at distance <= margin are reported (bodies have radius 1)")
      ->capture_default_str();
  app.add_option("--seed", options.seed, "Seed of the scene")->capture_default_str();
  app.add_option("--threads", options.threads, "Narrow-phase threads (0: all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  app.add_option("--every", options.every,
                 "A statistics row every this many steps (0: about ten rows)")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  app.footer(
      "Example:\n  build/release/bench/scene_demo --bodies 2000 --steps 100 --margin 0.05 --every "
      "10");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return proxima::bench::run_scene_demo(options, std::cout, std::cerr,
                                          ::isatty(STDERR_FILENO) != 0);
  } catch (const std::exception& e) {
    std::cerr << "scene_demo: " << e.what() << "\n";
    return 1;
  }
}
