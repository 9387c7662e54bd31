// Robots from their URDF (proxima/robot/): time per configuration of
// robot_distances on the Panda (self pairs plus a table and a shelf) along a
// smooth trajectory and on random configurations, hulls and meshes, tracked
// and cold, distance only and with gradients, beside FCL on the same pairs
// at the poses of the same forward kinematics (robot_fcl.h), with both
// systems' largest difference from an exact referee and their wrong
// collision verdicts; Talos self-collision; and a batch of 10^4 random
// configurations on 1 and 2 threads. Each figure is
// the median of 5 runs, the runs of the variants alternated. Single-thread
// figures are the thread's CPU time (on a shared machine, wall time counts
// the other processes' turns too); the batch's are wall time, which is what
// threads shorten.
//
//   robot_urdf_bench [robots directory]   (default: ../shared/robots from the
//                                          repository root)
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/urdf.h>
#include <proxima/shape/primitives.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "robot_fcl.h"

#ifndef PROXIMA_SOURCE_DIR
#define PROXIMA_SOURCE_DIR "."
#endif

namespace {

using proxima::Pose;
using proxima::Robot;
using proxima::Vec3;
using Configs = std::vector<std::vector<double>>;

std::vector<double> random_q(const Robot& robot, std::mt19937_64& rng) {
  const Eigen::VectorXd lo = robot.lower_limits(), hi = robot.upper_limits();
  std::vector<double> q(static_cast<std::size_t>(robot.dof()));
  for (int v = 0; v < robot.dof(); ++v) {
    const double a = std::isfinite(lo[v]) ? lo[v] : -std::numbers::pi;
    const double b = std::isfinite(hi[v]) ? hi[v] : std::numbers::pi;
    q[static_cast<std::size_t>(v)] = std::uniform_real_distribution<double>(a, b)(rng);
  }
  return q;
}

// Straight joint-space segments between random waypoints, 100 steps each:
// consecutive configurations a few milliradians apart, as an optimizer's or
// a controller's.
Configs smooth_trajectory(const Robot& robot, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Configs path;
  std::vector<double> from = random_q(robot, rng);
  while (path.size() < n) {
    const std::vector<double> to = random_q(robot, rng);
    for (int s = 0; s < 100 && path.size() < n; ++s) {
      std::vector<double> q(from.size());
      for (std::size_t v = 0; v < q.size(); ++v) q[v] = from[v] + (to[v] - from[v]) * s / 100.0;
      path.push_back(q);
    }
    from = to;
  }
  return path;
}

Configs random_configs(const Robot& robot, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Configs configs;
  for (std::size_t k = 0; k < n; ++k) configs.push_back(random_q(robot, rng));
  return configs;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Variant {
  std::string name;
  std::function<void()> run;  // one pass over its configurations
  double per_pass = 1;        // configurations per pass
  std::vector<double> seconds;
  bool wall = false;  // wall time (threads) instead of the thread's CPU time
  // With wall: the CPU time of all the process's threads, which says
  // whether the threads share the work without overhead when the machine
  // has no second core free to run them at once.
  std::vector<double> process_seconds{};
};

// Runs every variant 5 times, alternated, and prints each median in us per
// configuration.
void run_alternated(std::vector<Variant>& variants) {
  for (Variant& v : variants) v.run();  // warm-up: caches, pages, the mesh wrappers
  for (int repeat = 0; repeat < 5; ++repeat) {
    for (Variant& v : variants) {
      const double start = v.wall ? wall_seconds() : cpu_seconds();
      const double process_start = process_cpu_seconds();
      v.run();
      v.seconds.push_back((v.wall ? wall_seconds() : cpu_seconds()) - start);
      v.process_seconds.push_back(process_cpu_seconds() - process_start);
    }
  }
  for (const Variant& v : variants) {
    std::printf("  %-58s %9.2f us/config", v.name.c_str(), 1e6 * median(v.seconds) / v.per_pass);
    if (v.wall) {
      std::printf("  (CPU of all threads %.2f us/config)",
                  1e6 * median(v.process_seconds) / v.per_pass);
    }
    std::printf("\n");
  }
}

// What a pass saw: pairs queried per configuration, and the time spent on
// configurations in collision (some pair overlaps: a penetration depth is
// computed) and on the others, per configuration.
struct PassStats {
  double queried = 0;
  double colliding = 0, free = 0;  // configurations
  double colliding_seconds = 0, free_seconds = 0;
};

// A pass of robot_distances over `configs`, tracked (one state kept) or
// cold (a new state per configuration).
std::function<void()> pass(const Robot& robot, const Configs& configs,
                           const std::vector<proxima::Obstacle>& obstacles,
                           proxima::RobotQueryOptions options, bool tracked, double* sink,
                           PassStats* stats) {
  return [&robot, &configs, &obstacles, options, tracked, sink, stats] {
    proxima::RobotQueryState state;
    PassStats s;
    for (const std::vector<double>& q : configs) {
      if (!tracked) state.reset();
      const double start = cpu_seconds();
      const proxima::RobotDistances r =
          proxima::robot_distances(robot, q, obstacles, options, &state);
      const double seconds = cpu_seconds() - start;
      *sink += r.min_signed_distance;
      s.queried += r.pairs_queried;
      (r.min_signed_distance < 0 ? s.colliding : s.free) += 1;
      (r.min_signed_distance < 0 ? s.colliding_seconds : s.free_seconds) += seconds;
    }
    s.queried /= static_cast<double>(configs.size());
    *stats = s;
  };
}

// A pass of FCL over `configs` (robot_fcl.h: every pair, signed).
std::function<void()> fcl_pass(proxima::bench::FclRobot& fcl, const Configs& configs,
                               double* sink) {
  return [&fcl, &configs, sink] {
    for (const std::vector<double>& q : configs) *sink += fcl.distance(q).min_signed_distance;
  };
}

// Each system's answers on `configs` against the referee's (robot_fcl.h):
// the largest difference of the smallest signed distance, over the
// configurations the referee finds collision-free and over the others, and
// the configurations whose collision verdict differs from the referee's.
// proxima's is robot_distances tracked along `configs`; its verdict is its
// closest pair's status, FCL's a signed distance <= 0.
void compare_with_referee(const char* name, const Robot& robot, const Configs& configs,
                          const std::vector<proxima::Obstacle>& obstacles,
                          proxima::bench::FclRobot& fcl) {
  struct Errors {
    double free = 0, colliding = 0;
    int wrong = 0;
  };
  Errors ours, theirs;
  int colliding = 0;
  proxima::RobotQueryState state;
  proxima::RobotQueryOptions options;
  options.margin = 0.05;
  for (const std::vector<double>& q : configs) {
    const proxima::bench::RobotMinimum referee = proxima::bench::referee_minimum(robot, q, obstacles);
    const proxima::RobotDistances r = proxima::robot_distances(robot, q, obstacles, options, &state);
    const proxima::bench::RobotMinimum f = fcl.distance(q);
    colliding += referee.colliding ? 1 : 0;
    const auto add = [&](Errors& e, double value, bool verdict) {
      double& worst = referee.colliding ? e.colliding : e.free;
      worst = std::max(worst, std::abs(value - referee.min_signed_distance));
      e.wrong += verdict != referee.colliding ? 1 : 0;
    };
    add(ours, r.min_signed_distance, r.closest.result.status != proxima::Status::separated);
    add(theirs, f.min_signed_distance, f.colliding);
  }
  std::printf("  %s: %zu configurations, %d in collision (referee: cold distance() on every pair)\n",
              name, configs.size(), colliding);
  std::printf("    %-34s %14s %14s %8s\n", "largest |min - referee| (m)", "collision-free",
              "in collision", "wrong");
  std::printf("    %-34s %14.3g %14.3g %8d\n", "proxima robot_distances, tracked", ours.free,
              ours.colliding, ours.wrong);
  std::printf("    %-34s %14.3g %14.3g %8d\n", "FCL distance (signed, libccd)", theirs.free,
              theirs.colliding, theirs.wrong);
}

void print_stats(const std::vector<Variant>& variants, const std::vector<PassStats>& stats) {
  std::printf(
      "  (last run of each: pairs queried per configuration; us per collision-free / "
      "colliding configuration)\n");
  for (std::size_t i = 0; i < stats.size(); ++i) {  // the variants that keep stats come first
    const PassStats& s = stats[i];
    std::printf("  %-58s %6.1f pairs  free %8.2f us (%4.0f)  colliding %8.2f us (%4.0f)\n",
                variants[i].name.c_str(), s.queried, 1e6 * s.free_seconds / std::max(1.0, s.free),
                s.free, 1e6 * s.colliding_seconds / std::max(1.0, s.colliding), s.colliding);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string robots =
      argc > 1 ? argv[1] : std::string(PROXIMA_SOURCE_DIR) + "/../shared/robots";
  if (!std::filesystem::exists(robots + "/robots/panda_description/urdf/panda.urdf")) {
    std::printf("robot_urdf_bench: %s has no robots; give the directory as argument\n",
                robots.c_str());
    return 0;
  }
  proxima::RobotLoadOptions options;
  options.package_dirs = {"example-robot-data=" + robots};
  const std::string panda_urdf = robots + "/robots/panda_description/urdf/panda.urdf";
  const std::string panda_srdf = robots + "/robots/panda_description/srdf/panda.srdf";
  const Robot panda = proxima::load_robot(panda_urdf, panda_srdf, options);
  proxima::RobotLoadOptions mesh_options = options;
  mesh_options.mesh_as = proxima::LoadAs::mesh;
  const Robot panda_meshes = proxima::load_robot(panda_urdf, panda_srdf, mesh_options);

  std::vector<proxima::Obstacle> obstacles;
  obstacles.emplace_back(proxima::make_box(Vec3(0.6, 0.6, 0.02)),
                         Pose(proxima::Mat3::Identity(), Vec3(0.3, 0, -0.021)), "table");
  obstacles.emplace_back(proxima::make_box(Vec3(0.2, 0.4, 0.01)),
                         Pose(proxima::Mat3::Identity(), Vec3(0.5, 0, 0.4)), "shelf");

  const Configs path = smooth_trajectory(panda, 2000, 2026);
  const Configs random = random_configs(panda, 2000, 2027);
  std::printf(
      "Panda: %d variables, %zu geometries, %zu enabled self pairs + %zu x %zu "
      "environment pairs\n",
      panda.dof(), panda.geometries().size(), panda.self_pairs().size(), panda.geometries().size(),
      obstacles.size());

  proxima::RobotQueryOptions distance_only;
  distance_only.margin = 0.05;
  proxima::RobotQueryOptions with_gradients = distance_only;
  with_gradients.gradients = true;
  double sink = 0;
  proxima::RobotQueryOptions minimum_only;
  minimum_only.minimum_only = true;
  proxima::RobotQueryOptions minimum_gradients = minimum_only;
  minimum_gradients.gradients = true;
  std::vector<PassStats> queried(10);  // the proxima variants, in the order below
  const Configs mesh_path(path.begin(), path.begin() + 200);
  std::vector<Variant> panda_variants = {
      {"hulls, trajectory, tracked, distance only",
       pass(panda, path, obstacles, distance_only, true, &sink, &queried[0]),
       2000.0,
       {}},
      {"hulls, trajectory, tracked, with gradients (margin 5 cm)",
       pass(panda, path, obstacles, with_gradients, true, &sink, &queried[1]),
       2000.0,
       {}},
      {"hulls, trajectory, cold, distance only",
       pass(panda, path, obstacles, distance_only, false, &sink, &queried[2]),
       2000.0,
       {}},
      {"hulls, random, tracked, distance only",
       pass(panda, random, obstacles, distance_only, true, &sink, &queried[3]),
       2000.0,
       {}},
      {"hulls, random, cold, distance only",
       pass(panda, random, obstacles, distance_only, false, &sink, &queried[4]),
       2000.0,
       {}},
      {"hulls, random, tracked, with gradients",
       pass(panda, random, obstacles, with_gradients, true, &sink, &queried[5]),
       2000.0,
       {}},
      {"meshes, trajectory (first 200), tracked, distance only",
       pass(panda_meshes, mesh_path, obstacles, distance_only, true, &sink, &queried[6]),
       200.0,
       {}},
      {"meshes, trajectory (first 200), cold, distance only",
       pass(panda_meshes, mesh_path, obstacles, distance_only, false, &sink, &queried[7]),
       200.0,
       {}},
  };
  panda_variants.push_back({"hulls, trajectory, tracked, minimum only",
                            pass(panda, path, obstacles, minimum_only, true, &sink, &queried[8]),
                            2000.0, {}});
  panda_variants.push_back(
      {"hulls, trajectory, tracked, minimum only, with its gradient",
       pass(panda, path, obstacles, minimum_gradients, true, &sink, &queried[9]), 2000.0, {}});
  proxima::bench::FclRobot fcl_hulls(panda, obstacles), fcl_meshes(panda_meshes, obstacles);
  panda_variants.push_back({"FCL, hulls (fcl::Convex), trajectory, every pair",
                            fcl_pass(fcl_hulls, path, &sink), 2000.0, {}});
  panda_variants.push_back({"FCL, hulls (fcl::Convex), random, every pair",
                            fcl_pass(fcl_hulls, random, &sink), 2000.0, {}});
  panda_variants.push_back({"FCL, meshes (BVHModel<OBBRSS>), trajectory (first 200)",
                            fcl_pass(fcl_meshes, mesh_path, &sink), 200.0, {}});
  run_alternated(panda_variants);
  print_stats(panda_variants, queried);
  const auto ratio = [&](std::size_t fcl, std::size_t ours) {
    return median(panda_variants[fcl].seconds) / panda_variants[fcl].per_pass /
           (median(panda_variants[ours].seconds) / panda_variants[ours].per_pass);
  };
  std::printf(
      "  FCL's time over proxima's (tracked, distance only): hulls trajectory %.1fx, hulls random "
      "%.1fx, meshes trajectory %.1fx\n",
      ratio(10, 0), ratio(11, 3), ratio(12, 6));
  std::printf("  FCL's time over proxima's minimum only (hulls trajectory): %.1fx\n", ratio(10, 8));
  std::printf("Panda against the exact referee:\n");
  compare_with_referee("hulls, trajectory", panda, path, obstacles, fcl_hulls);
  compare_with_referee("hulls, random", panda, random, obstacles, fcl_hulls);
  compare_with_referee("meshes, trajectory (first 200)", panda_meshes, mesh_path, obstacles,
                       fcl_meshes);

  const Robot talos = proxima::load_robot(robots + "/robots/talos_data/robots/talos_full_v2.urdf",
                                          robots + "/robots/talos_data/srdf/talos.srdf", options);
  const Configs talos_path = smooth_trajectory(talos, 2000, 2028);
  const Configs talos_random = random_configs(talos, 2000, 2029);
  std::printf("Talos: %d variables, %zu geometries, %zu enabled self pairs\n", talos.dof(),
              talos.geometries().size(), talos.self_pairs().size());
  proxima::RobotQueryOptions talos_options;
  proxima::RobotQueryOptions talos_minimum;
  talos_minimum.minimum_only = true;
  std::vector<PassStats> talos_queried(4);
  std::vector<Variant> talos_variants = {
      {"hulls, self, trajectory, tracked",
       pass(talos, talos_path, {}, talos_options, true, &sink, &talos_queried[0]),
       2000.0,
       {}},
      {"hulls, self, trajectory, cold",
       pass(talos, talos_path, {}, talos_options, false, &sink, &talos_queried[1]),
       2000.0,
       {}},
      {"hulls, self, random, tracked",
       pass(talos, talos_random, {}, talos_options, true, &sink, &talos_queried[2]),
       2000.0,
       {}},
      {"hulls, self, trajectory, tracked, minimum only",
       pass(talos, talos_path, {}, talos_minimum, true, &sink, &talos_queried[3]),
       2000.0,
       {}},
  };
  run_alternated(talos_variants);
  print_stats(talos_variants, talos_queried);

  const Configs batch_configs = random_configs(panda, 10000, 2030);
  proxima::RowMatrixXd batch(10000, panda.dof());
  for (Eigen::Index k = 0; k < batch.rows(); ++k) {
    for (int v = 0; v < panda.dof(); ++v) {
      batch(k, v) = batch_configs[static_cast<std::size_t>(k)][static_cast<std::size_t>(v)];
    }
  }
  proxima::RobotQueryOptions batch_options;
  batch_options.gradients = true;
  std::printf("Panda batch of 10^4 random configurations (minimum and its gradient):\n");
  std::vector<Variant> batch_variants;
  for (int threads : {1, 2}) {
    batch_variants.push_back({std::to_string(threads) + " thread" + (threads > 1 ? "s" : ""),
                              [&panda, &batch, &obstacles, batch_options, threads, &sink] {
                                sink += proxima::robot_distances_batch(panda, batch, obstacles,
                                                                       batch_options, threads)
                                            .min_signed_distance.sum();
                              },
                              10000.0,
                              {},
                              true});
  }
  run_alternated(batch_variants);
  std::printf("  speed-up on 2 threads: %.2fx\n",
              median(batch_variants[0].seconds) / median(batch_variants[1].seconds));
  std::printf("(checksum %.6g)\n", sink);
  return 0;
}
