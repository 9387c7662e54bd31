// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The `scene_demo` benchmark executable (bench/paper/scene_demo_main.cpp;
// before issue 9 it was `proxima scene-demo`, but the scenario lives with the
// benchmarks and the shipped CLI must not link them). The scene of the scene
// benchmark (bench/paper/scene_scenario.h) run through proxima::Scene alone: each
// step moves every body and asks for every pair within the margin. Rows are
// plain whitespace-separated columns so that a script (and
// tests/cli/cli_scene_test.cpp) can read them; the progress line goes to its own
// stream so that it never mixes with them.
#include "scene_demo.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "paper/scene_scenario.h"
#include "proxima/scene/scene.h"

namespace proxima::bench {
namespace {

using Clock = std::chrono::steady_clock;

// Statistics rows when the caller leaves `every` at 0.
constexpr int kDefaultRows = 10;
// Progress: rewritten at most this often on a terminal, a new line at most
// this often otherwise (as the `paper` executable does in its long parts).
constexpr double kTerminalProgressSeconds = 0.2;
constexpr double kLogProgressSeconds = 5.0;

double seconds_between(Clock::time_point t0, Clock::time_point t1) {
  return std::chrono::duration<double>(t1 - t0).count();
}

// The q-quantile (0..1) by the nearest rank of a non-empty list.
double quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

std::string format(const char* pattern, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), pattern, v);
  return buffer;
}

}  // namespace

int run_scene_demo(const SceneDemoOptions& options, std::ostream& out, std::ostream& progress,
                   bool progress_is_terminal) {
  // The library would refuse these too, but in its own words (the
  // scenario's option names); a user typed --margin.
  if (!std::isfinite(options.margin) || options.margin < 0.0) {
    throw InvalidInput("scene_demo: --margin must be finite and >= 0, got " +
                       format("%g", options.margin));
  }
  SceneScenarioOptions so;
  so.bodies = options.bodies;
  so.seed = options.seed;
  so.margin = options.margin;
  const SceneScenario scenario(so);

  SceneOptions scene_options;
  scene_options.margin = options.margin;
  scene_options.threads = options.threads;
  Scene scene(scene_options);
  std::vector<Pose> poses = scenario.step(0);
  std::vector<BodyId> ids;
  ids.reserve(poses.size());
  for (int i = 0; i < scenario.body_count(); ++i) {
    ids.push_back(scene.add(scenario.body_shape(i), poses[static_cast<std::size_t>(i)]));
  }

  const int every = options.every > 0 ? options.every : std::max(1, options.steps / kDefaultRows);
  out << "scene_demo: " << options.bodies << " bodies (random convex polytopes of " << so.min_points
      << "-" << so.max_points << " points, radius " << kBodyRadius << ", " << so.shape_pool
      << " distinct hulls), cube " << format("%.1f", scenario.cube_size()) << ", margin "
      << options.margin << ", " << options.steps << " steps, seed " << options.seed << ", threads "
      << options.threads << "\n";
  out << "  step  candidates  close  intersecting  queries  ms\n";
  out.flush();

  std::vector<double> step_ms;
  step_ms.reserve(static_cast<std::size_t>(options.steps));
  long long queries = 0;
  double close_sum = 0.0;
  double step_seconds = 0.0;
  const auto start = Clock::now();
  auto last_progress = start;
  bool progress_shown = false;
  for (int k = 0; k < options.steps; ++k) {
    scenario.step(k, poses);  // the scenario's motion, not the scene's work: outside the timing
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < ids.size(); ++i) scene.set_pose(ids[i], poses[i]);
    const std::span<const ClosePair> pairs = scene.step();
    const auto t1 = Clock::now();
    const double seconds = seconds_between(t0, t1);
    step_seconds += seconds;
    step_ms.push_back(1e3 * seconds);
    const SceneStats& stats = scene.stats();
    queries += stats.convex_queries;
    close_sum += stats.close_pairs;

    if (k % every == 0 || k + 1 == options.steps) {
      const auto intersecting = std::count_if(pairs.begin(), pairs.end(), [](const ClosePair& p) {
        return p.result.status == Status::intersecting;
      });
      if (progress_shown && progress_is_terminal) {
        progress << "\r\033[K";  // the row replaces the progress line on a shared terminal
        progress.flush();
        progress_shown = false;
      }
      char row[128];
      std::snprintf(row, sizeof(row), "  %4d  %10d  %5d  %12ld  %7d  %.3f\n", k,
                    stats.candidate_pairs, stats.close_pairs, static_cast<long>(intersecting),
                    stats.convex_queries, 1e3 * seconds);
      out << row;
      out.flush();
    }

    const auto now = Clock::now();
    const double since = seconds_between(last_progress, now);
    if (since > (progress_is_terminal ? kTerminalProgressSeconds : kLogProgressSeconds)) {
      last_progress = now;
      const double elapsed = seconds_between(start, now);
      const double left = elapsed / (k + 1) * (options.steps - k - 1);
      progress << (progress_is_terminal ? "\r\033[K" : "") << "  step " << k + 1 << " / "
               << options.steps << ", " << format("%.1f", elapsed) << " s, about "
               << format("%.0f", left) << " s left" << (progress_is_terminal ? "" : "\n");
      progress.flush();
      progress_shown = true;
    }
  }
  if (progress_shown && progress_is_terminal) {
    progress << "\r\033[K";
    progress.flush();
  }

  const double steps = static_cast<double>(options.steps);
  out << "summary: " << options.steps << " steps, median " << format("%.3f", quantile(step_ms, 0.5))
      << " ms/step, p90 " << format("%.3f", quantile(step_ms, 0.9)) << " ms/step, "
      << format("%.1f", close_sum / steps) << " close pairs/step, "
      << format("%.0f", step_seconds > 0.0 ? static_cast<double>(queries) / step_seconds : 0.0)
      << " queries/s (wall time of set_pose + step)\n";
  return 0;
}

}  // namespace proxima::bench
