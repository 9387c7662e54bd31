// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The cold signed-distance queries of bench/penetration_peers' sweep (the
// same hulls and poses: bench/support/penetration_sweep.h), for
// callgrind's instruction counts and for timing one build against another
// without the peers:
//
//   valgrind --tool=callgrind --toggle-collect='proxima::distance(*'
//     build/release/bench/cold_instructions 64 7
// (one command line)
//
// runs distance() without a cache on every 7th pose (the second argument,
// default 7) and prints the queries, how many overlap, and the sum of the
// signed distances (printed to the last bit, so that two builds can be
// compared); instructions per query = the collected total / the queries.
// A third argument `overlapping` keeps only the overlapping poses;
// `tracked` runs the same poses in sweep order with one DistanceCache (the
// tracked depth, for comparison; stride 1 is penetration_peers' tracked
// sweep). With `--passes P` first, it also times P passes (thread CPU
// time) and prints the median ns per query. A last argument `extended`
// asks every query for DistanceOptions::extended_precision (its cost
// against the same run without it).
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "proxima/query/distance.h"
#include "support/penetration_sweep.h"

namespace {

double thread_cpu_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e9 + static_cast<double>(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace proxima;
  int passes = 0;
  int arg = 1;
  const bool extended = argc > 2 && std::strcmp(argv[argc - 1], "extended") == 0;
  if (extended) --argc;
  if (argc > 2 && std::strcmp(argv[1], "--passes") == 0) {
    passes = std::atoi(argv[2]);
    arg = 3;
  }
  if (argc - arg < 1 || argc - arg > 3 ||
      (argc - arg == 3 && std::strcmp(argv[arg + 2], "overlapping") != 0 &&
       std::strcmp(argv[arg + 2], "tracked") != 0)) {
    std::fprintf(
        stderr,
        "usage: cold_instructions [--passes P] N [stride] [overlapping|tracked] [extended]\n");
    return 2;
  }
  const int n = std::atoi(argv[arg]);
  const int stride = argc - arg >= 2 ? std::atoi(argv[arg + 1]) : 7;
  if (n < 4 || stride < 1 || passes < 0) {
    std::fprintf(stderr, "cold_instructions: N >= 4, stride >= 1 and passes >= 0 needed\n");
    return 2;
  }
  const bool overlapping_only = argc - arg == 3 && argv[arg + 2][0] == 'o';
  const bool tracked = argc - arg == 3 && argv[arg + 2][0] == 't';
  const bench::SweepBodies bodies = bench::penetration_sweep_bodies(n);
  const std::vector<Pose> sweep = bench::penetration_sweep();
  std::vector<Pose> poses;
  for (std::size_t i = static_cast<std::size_t>(stride) / 2; i < sweep.size();
       i += static_cast<std::size_t>(stride)) {
    if (overlapping_only &&
        distance(bodies.a, Pose::identity(), bodies.b, sweep[i]).status != Status::intersecting)
      continue;
    poses.push_back(sweep[i]);
  }
  // A cold query is distance() without a cache.
  DistanceCache cache;
  DistanceCache* const cache_or_null = tracked ? &cache : nullptr;
  DistanceOptions options;
  options.extended_precision = extended;
  double sum = 0.0;
  int overlapping = 0;
  for (const Pose& p : poses) {
    const DistanceResult r =
        distance(bodies.a, Pose::identity(), bodies.b, p, options, cache_or_null);
    sum += r.signed_distance();
    overlapping += r.status == Status::intersecting ? 1 : 0;
  }
  std::printf("N = %d: %zu %s queries, %d overlapping, sum of signed distances %a\n", n,
              poses.size(), tracked ? "tracked" : "cold", overlapping, sum);
  if (passes > 0) {
    std::vector<double> ns;
    for (int k = 0; k < passes; ++k) {
      const double t0 = thread_cpu_ns();
      double s = 0.0;
      cache.reset();
      for (const Pose& p : poses)
        s += distance(bodies.a, Pose::identity(), bodies.b, p, options, cache_or_null)
                 .signed_distance();
      ns.push_back((thread_cpu_ns() - t0) / static_cast<double>(poses.size()));
      if (s != sum) std::printf("pass %d: the sum differs (%a)\n", k, s);
    }
    std::nth_element(ns.begin(), ns.begin() + passes / 2, ns.end());
    std::printf("median over %d passes: %.0f ns per query\n", passes, ns[static_cast<std::size_t>(passes / 2)]);
  }
  return 0;
}
