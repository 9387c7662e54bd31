// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Scene::sweep (continuous collision in a scene, issue 13): the time per
// sweep at 1,000 and 10,000 bodies, the pairs it tests, and Scene::step on
// the same poses beside it.
//
//   ./build/release/bench/sweep_bench                 N = 1,000 and 10,000, 50 sweeps each
//   ./build/release/bench/sweep_bench --sweeps 10     fewer sweeps
//   ./build/release/bench/sweep_bench --threads 2     also the sweep on 2 threads (wall time)
//
// The scene of scene_bench (bench/paper/scene_scenario.h: random hulls of 20
// to 200 points of radius 1, three neighbours on average within 0.1), with
// bodies moving faster: up to 0.05 per scenario step and 0.05 rad, and each
// sweep spanning `stride` = 4 scenario steps (up to 0.2 of travel and 0.2
// rad per body and sweep: a fast simulation step). Sweep k sets every
// body's pose to the scenario's step 4k and its end pose to step 4k + 4,
// then sweeps with the default ImpactOptions (target 0, tolerance 1e-6 of
// the sizes). A second scene, margin 0, runs step() at the same start poses:
// what a discrete check of the same frame costs.
//
// Times: the calling thread's CPU time (immune to another process taking
// the core), median and 90th percentile over the sweeps; with --threads T,
// a third scene with T threads sweeps the same motions, in wall time, and
// its pairs are checked identical bit for bit. Per sweep: the candidate
// pairs (swept boxes overlap, each one time_of_impact), the pairs reported
// (not separated: contact at t > 0, or overlapping at t = 0; the scenario's
// bodies pass through each other, so most are overlapping), those of them
// in contact at t, the distance
// queries of all candidates, and the candidate pairs of step() beside.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "paper/scene_scenario.h"
#include "proxima/scene/scene.h"

namespace proxima::bench {
namespace {

double thread_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

bool same_pairs(std::span<const ImpactPair> x, std::span<const ImpactPair> y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].a != y[i].a || x[i].b != y[i].b || x[i].result.status != y[i].result.status ||
        !same_bits(x[i].result.t, y[i].result.t) ||
        x[i].result.iterations != y[i].result.iterations)
      return false;
  }
  return true;
}

constexpr int kStride = 4;

void run(int bodies, int sweeps, int threads) {
  SceneScenarioOptions so;
  so.bodies = bodies;
  so.max_speed = 0.05;
  so.max_angular_speed = 0.05;
  const SceneScenario scenario(so);
  SceneOptions one;
  one.threads = 1;
  Scene sweeper(one);
  Scene stepper(one);
  std::unique_ptr<Scene> parallel;
  if (threads != 1) {
    SceneOptions many;
    many.threads = threads;
    parallel = std::make_unique<Scene>(many);
  }
  std::vector<Pose> start, end;
  scenario.step(0, start);
  for (int i = 0; i < bodies; ++i) {
    sweeper.add(scenario.body_shape(i), start[static_cast<std::size_t>(i)]);
    stepper.add(scenario.body_shape(i), start[static_cast<std::size_t>(i)]);
    if (parallel) parallel->add(scenario.body_shape(i), start[static_cast<std::size_t>(i)]);
  }
  std::vector<double> sweep_ms, step_ms, parallel_ms;
  double candidates = 0, reported = 0, contacts = 0, queries = 0, warm = 0, step_candidates = 0;
  bool identical = true;
  for (int s = 0; s < sweeps; ++s) {
    scenario.step(kStride * s, start);
    scenario.step(kStride * (s + 1), end);
    for (int i = 0; i < bodies; ++i) {
      const auto k = static_cast<std::size_t>(i);
      sweeper.set_pose(i, start[k]);
      sweeper.set_end_pose(i, end[k]);
      stepper.set_pose(i, start[k]);
      if (parallel) {
        parallel->set_pose(i, start[k]);
        parallel->set_end_pose(i, end[k]);
      }
    }
    double t0 = thread_cpu_seconds();
    const std::span<const ImpactPair> hits = sweeper.sweep();
    sweep_ms.push_back(1e3 * (thread_cpu_seconds() - t0));
    const SweepStats& st = sweeper.sweep_stats();
    candidates += st.candidate_pairs;
    reported += st.impact_pairs;
    for (const ImpactPair& p : hits) contacts += p.result.status == ImpactStatus::contact ? 1 : 0;
    queries += st.distance_queries;
    warm += st.warm_pairs;
    if (parallel) {
      t0 = wall_seconds();
      const std::span<const ImpactPair> other = parallel->sweep();
      parallel_ms.push_back(1e3 * (wall_seconds() - t0));
      identical = identical && same_pairs(hits, other);
    }
    t0 = thread_cpu_seconds();
    stepper.step();
    step_ms.push_back(1e3 * (thread_cpu_seconds() - t0));
    step_candidates += stepper.stats().candidate_pairs;
  }
  const double n = sweeps;
  std::printf("| %d | %.3f | %.3f | %.0f | %.0f | %.0f | %.2f | %.0f%% | %.3f | %.0f |", bodies,
              percentile(sweep_ms, 0.5), percentile(sweep_ms, 0.9), candidates / n, reported / n,
              contacts / n, candidates > 0 ? queries / candidates : 0.0,
              candidates > 0 ? 100.0 * warm / candidates : 0.0, percentile(step_ms, 0.5),
              step_candidates / n);
  if (parallel) {
    std::printf(" %.3f (%s) |", percentile(parallel_ms, 0.5),
                identical ? "identical" : "DIFFERENT");
  }
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace
}  // namespace proxima::bench

int main(int argc, char** argv) {
  int sweeps = 50;
  int threads = 1;
  std::vector<int> sizes = {1000, 10000};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--sweeps" && i + 1 < argc) {
      sweeps = std::atoi(argv[++i]);
    } else if (arg == "--threads" && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (arg == "--bodies" && i + 1 < argc) {
      sizes = {std::atoi(argv[++i])};
    } else {
      std::fprintf(stderr,
                   "usage: sweep_bench [--sweeps S >= 1] [--threads T >= 0] [--bodies N >= 2]\n");
      return 2;
    }
  }
  if (sweeps < 1 || threads < 0 || sizes[0] < 2) {
    std::fprintf(stderr, "sweep_bench: --sweeps >= 1, --threads >= 0, --bodies >= 2\n");
    return 2;
  }
  std::printf(
      "# Scene::sweep, %d sweeps per N, each over %d scenario steps (thread CPU ms; pairs per "
      "sweep; steps: distance queries per candidate pair)\n",
      sweeps, proxima::bench::kStride);
  std::printf(
      "| N | sweep ms median | p90 | candidate pairs | reported | of which contact | steps | warm "
      "| step() ms median | step() candidates |%s\n|---|---|---|---|---|---|---|---|---|---|%s\n",
      threads != 1 ? (" sweep ms, " + std::to_string(threads) + " threads (wall) |").c_str() : "",
      threads != 1 ? "---|" : "");
  for (const int n : sizes) proxima::bench::run(n, sweeps, threads);
  return 0;
}
