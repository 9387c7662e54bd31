// A scene's collision checks (issue 26): Scene::step() (every pair within
// the margin with its full answer) against Scene::step_within() (the same
// pairs proved by the margin query, no distances) and Scene::first_within()
// (stop at the first pair), side by side on the same moving scene.
//
//   ./build/release/bench/scene_margin_bench [--bodies N] [--steps S] [--margin M] [--seed K]
//                                            (N = 1000, S = 300, M = 0.1, K = 1)
//
// The scene is scene_bench's (bench/paper/scene_scenario.h): N random convex
// hulls of 20 to 200 points and radius 1 in a cube sized for about 3
// neighbours each within the margin, moving a little each step and passing
// through each other (most close pairs overlap). Three Scenes hold the same
// bodies, each with its own pair caches (default options, 1 thread); each
// step every scene gets the step's poses (set_pose) and runs its query,
// in an order that rotates from step to step so that machine noise falls
// on all three. Times: the calling thread's CPU time per step (set_pose
// included), median and 90th percentile over the steps, and each mode's
// median relative to step()'s.
//
// Verdicts, every step: step_within's pairs against step()'s (a pair in one
// set only must lie within the contact band of the margin, 1e-9 here for
// bodies of size 1); first_within finds a pair exactly when step() reports
// one, and that pair is one of step()'s.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "paper/scene_scenario.h"
#include "proxima/scene/scene.h"

namespace proxima::bench {
namespace {

// Pairs whose full distance is this close to the margin may get either
// verdict (the contact band 64 u R is about 1e-13 at these sizes).
constexpr double kBandSlack = 1e-9;

double thread_cpu_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e9 + static_cast<double>(t.tv_nsec);
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

enum Mode { full, within, first, kModes };
constexpr std::array<const char*, kModes> kModeNames = {"step() (full answers)", "step_within()",
                                                        "first_within()"};

struct Options {
  int bodies = 1000;
  int steps = 300;
  double margin = 0.1;
  std::uint64_t seed = 1;
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) return false;
    const char* value = argv[++i];
    if (arg == "--bodies") {
      o.bodies = std::atoi(value);
    } else if (arg == "--steps") {
      o.steps = std::atoi(value);
    } else if (arg == "--margin") {
      o.margin = std::atof(value);
    } else if (arg == "--seed") {
      o.seed = std::strtoull(value, nullptr, 10);
    } else {
      return false;
    }
  }
  return o.bodies > 1 && o.steps > 0 && o.margin >= 0.0;
}

int run(const Options& o) {
  SceneScenarioOptions so;
  so.bodies = o.bodies;
  so.seed = o.seed;
  so.margin = o.margin;
  const SceneScenario scenario(so);
  std::vector<Pose> poses = scenario.step(0);
  SceneOptions scene_options;
  scene_options.margin = o.margin;
  scene_options.threads = 1;
  std::array<Scene, kModes> scenes = {Scene(scene_options), Scene(scene_options),
                                      Scene(scene_options)};
  for (Scene& s : scenes) {
    for (int i = 0; i < o.bodies; ++i) s.add(scenario.body_shape(i), poses[std::size_t(i)]);
  }
  std::array<std::vector<double>, kModes> ms;
  std::array<long, kModes> queries{};
  long candidates = 0, close = 0, steps_with_pairs = 0;
  int set_mismatch_out_of_band = 0, set_mismatch_in_band = 0, first_wrong = 0;
  std::vector<std::pair<BodyId, BodyId>> full_pairs;
  std::vector<double> full_distance;
  std::vector<char> full_contact;
  std::set<std::pair<BodyId, BodyId>> within_pairs;
  std::optional<MarginPair> hit;
  for (int k = 0; k < o.steps; ++k) {
    scenario.step(k, poses);
    for (int turn = 0; turn < kModes; ++turn) {
      const int m = (k + turn) % kModes;
      Scene& scene = scenes[std::size_t(m)];
      const double start = thread_cpu_ns();
      for (int i = 0; i < o.bodies; ++i) scene.set_pose(i, poses[std::size_t(i)]);
      if (m == full) {
        const std::span<const ClosePair> pairs = scene.step();
        ms[m].push_back((thread_cpu_ns() - start) * 1e-6);
        full_pairs.clear();
        full_distance.clear();
        full_contact.clear();
        for (const ClosePair& p : pairs) {
          full_pairs.emplace_back(p.a, p.b);
          full_distance.push_back(p.result.distance);
          full_contact.push_back(p.result.status != Status::separated);
        }
      } else if (m == within) {
        const std::span<const MarginPair> pairs = scene.step_within();
        ms[m].push_back((thread_cpu_ns() - start) * 1e-6);
        within_pairs.clear();
        for (const MarginPair& p : pairs) within_pairs.emplace(p.a, p.b);
      } else {
        hit = scene.first_within();
        ms[m].push_back((thread_cpu_ns() - start) * 1e-6);
      }
      queries[std::size_t(m)] += scene.stats().convex_queries;
    }
    candidates += scenes[full].stats().candidate_pairs;
    close += static_cast<long>(full_pairs.size());
    steps_with_pairs += full_pairs.empty() ? 0 : 1;
    // Verdicts (outside the timings): the pair sets, and first_within.
    std::set<std::pair<BodyId, BodyId>> seen;
    for (std::size_t i = 0; i < full_pairs.size(); ++i) {
      seen.insert(full_pairs[i]);
      if (within_pairs.contains(full_pairs[i])) continue;
      const bool in_band = !full_contact[i] && full_distance[i] >= o.margin - kBandSlack;
      (in_band ? set_mismatch_in_band : set_mismatch_out_of_band) += 1;
    }
    for (const auto& p : within_pairs) {
      // Reported within but beyond the margin for step(): only within the
      // band, and step() would then not list it: its cold distance decides.
      if (!seen.contains(p)) ++set_mismatch_in_band;
    }
    const bool hit_right =
        hit.has_value() == !full_pairs.empty() &&
        (!hit || std::find(full_pairs.begin(), full_pairs.end(), std::pair(hit->a, hit->b)) !=
                     full_pairs.end());
    first_wrong += hit_right ? 0 : 1;
  }
  std::printf("scene_margin_bench: %d bodies, %d steps, margin %g, seed %llu\n", o.bodies, o.steps,
              o.margin, static_cast<unsigned long long>(o.seed));
  std::printf("per step: %.1f candidate pairs, %.1f close pairs; %ld of %d steps have one\n",
              double(candidates) / o.steps, double(close) / o.steps, steps_with_pairs, o.steps);
  std::printf("%-24s %12s %12s %12s %16s\n", "mode", "median ms", "p90 ms", "x step()",
              "queries/step");
  const double base = quantile(ms[full], 0.5);
  for (int m = 0; m < kModes; ++m) {
    const double median = quantile(ms[std::size_t(m)], 0.5);
    std::printf("%-24s %12.3f %12.3f %12.2f %16.1f\n", kModeNames[std::size_t(m)], median,
                quantile(ms[std::size_t(m)], 0.9), base / median,
                double(queries[std::size_t(m)]) / o.steps);
  }
  std::printf("verdicts: step_within vs step(): %d pairs differ outside the band, %d inside; "
              "first_within wrong on %d steps\n",
              set_mismatch_out_of_band, set_mismatch_in_band, first_wrong);
  return set_mismatch_out_of_band == 0 && first_wrong == 0 ? 0 : 1;
}

}  // namespace
}  // namespace proxima::bench

int main(int argc, char** argv) {
  proxima::bench::Options o;
  if (!proxima::bench::parse(argc, argv, o)) {
    std::fprintf(stderr,
                 "usage: scene_margin_bench [--bodies N] [--steps S] [--margin M] [--seed K]\n");
    return 2;
  }
  return proxima::bench::run(o);
}
