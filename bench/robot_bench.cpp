// Robot self-distance benchmark (issue 11): the robotics example's arm (the
// Franka Panda's seven links and hand, each the hull of its collision mesh,
// examples/panda_arm.h) along the example's trajectory (160 configurations
// within the joint limits), proxima against FCL 0.7.
//
//   ./build/release/bench/robot_bench [--repeat R] [mesh directory]   (R = 20 by default)
//
// Per configuration, every non-adjacent pair of links (28 of the 36 pairs;
// the 8 adjacent ones overlap by construction), timed separately in the same
// loop so that machine noise falls on every system:
//   proxima scene, all pairs  Scene (tracked caches, 1 thread) with a margin
//                             of 100 m, so that step() runs and reports all 28
//                             pairs: the same work as FCL's rows;
//   proxima scene, 5 cm       the example's scene: margin 0.05, the broad
//                             phase drops far pairs (what a planner would run);
//   proxima cold              distance() on each pair, no cache;
//   FCL GST_LIBCCD            fcl::distance(geometry, transform, ...) on each
//                             pair, fcl::Convexd of the same hull (same
//                             vertices and faces), FCL's default
//                             DistanceRequest (its default solver is
//                             GST_LIBCCD, distance_tolerance 1e-6);
//   FCL GST_INDEP             the same with FCL's own GJK;
//   FCL GST_LIBCCD, tol 1e-12 GST_LIBCCD with distance_tolerance 1e-12
//                             (FCL's default 1e-6 is absolute; here it let
//                             libccd stop 3 mm from the distance).
// Times: the median over all configurations of all repetitions of the time
// of one configuration (placing the bodies included). Accuracy: each pair's
// distance against the referee, proxima's cold query (certified by its lower
// bound), at every configuration of the first repetition; the largest
// difference over pairs the referee reports separated, and the pairs where a
// system says overlap and the referee does not (or the reverse).
#include <fcl/narrowphase/distance.h>
#include <proxima/query/distance.h>
#include <proxima/io.h>
#include <proxima/scene/scene.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "panda_arm.h"
#include "peers/fcl_convex.h"

#ifndef PROXIMA_PANDA_MESH_DIR
#define PROXIMA_PANDA_MESH_DIR "examples/data/panda"
#endif

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kBodies = 9;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Accuracy of one system against the referee.
struct Agreement {
  double largest = 0;  // largest |distance - referee| over separated pairs
  double worst_distance = 0, worst_referee = 0;  // the pair where it was reached
  // Says overlapping (distance <= 0) where the referee is separated, or the reverse.
  int overlap_wrong = 0;
  int pairs = 0;
  void add(double distance, const proxima::DistanceResult& referee) {
    ++pairs;
    const bool referee_overlaps = referee.status == proxima::Status::intersecting;
    if (referee_overlaps != (distance <= 0)) {
      ++overlap_wrong;
      return;
    }
    if (!referee_overlaps && std::abs(distance - referee.distance) > largest) {
      largest = std::abs(distance - referee.distance);
      worst_distance = distance;
      worst_referee = referee.distance;
    }
  }
};

int run(int repeat, const std::string& mesh_dir) {
  std::vector<std::shared_ptr<const proxima::ConvexPolytope>> hulls;
  std::vector<std::shared_ptr<fcl::Convexd>> fcl_hulls;
  for (int i = 0; i < kBodies; ++i) {
    const std::string path = mesh_dir + "/" + panda::kLinkNames[i] + ".stl";
    hulls.push_back(
        std::make_shared<const proxima::ConvexPolytope>(proxima::load_convex(path).polytope));
    fcl_hulls.push_back(proxima::bench::fcl_convex(*hulls.back(), path));
  }
  std::vector<std::pair<int, int>> pairs;  // the non-adjacent pairs
  for (int a = 0; a < kBodies; ++a)
    for (int b = a + 2; b < kBodies; ++b) pairs.emplace_back(a, b);

  const std::vector<std::array<double, 7>> path = panda::trajectory(2026, 5, 40);
  std::vector<std::array<proxima::Pose, kBodies>> poses;
  for (const auto& q : path) poses.push_back(panda::link_poses(q));

  auto make_scene = [&](double margin) {
    proxima::SceneOptions options;
    options.margin = margin;
    auto scene = std::make_unique<proxima::Scene>(options);
    // Link i is body i: a new scene numbers its bodies 0, 1, ... (checked).
    for (int i = 0; i < kBodies; ++i) {
      if (scene->add(hulls[i], poses[0][i]) != i) throw std::logic_error("robot_bench: body ids");
    }
    for (int i = 0; i + 1 < kBodies; ++i) scene->exclude_pair(i, i + 1);
    return scene;
  };
  const auto all_pairs = make_scene(100.0);
  const auto near_pairs = make_scene(0.05);

  fcl::DistanceRequestd libccd_request;  // FCL's defaults: GST_LIBCCD
  fcl::DistanceRequestd indep_request;
  indep_request.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceRequestd tight_request;  // GST_LIBCCD with a tolerance at proxima's scale
  tight_request.distance_tolerance = 1e-12;

  enum { scene_all, scene_near, cold, fcl_libccd, fcl_indep, fcl_tight, systems };
  const std::array<const char*, systems> names = {
      "proxima scene, all pairs", "proxima scene, 5 cm", "proxima cold",
      "FCL GST_LIBCCD",           "FCL GST_INDEP",       "FCL GST_LIBCCD, tol 1e-12"};
  std::array<std::vector<double>, systems> times;
  std::array<Agreement, systems> agreement;
  double sink = 0;
  double certificate_gap = 0;  // the referee's largest distance - lower_bound
  double gjk_gap = 0;          // largest |proxima's GJK - referee|

  for (int r = 0; r < repeat; ++r) {
    for (const auto& pose : poses) {
      const bool check = r == 0;
      std::vector<proxima::DistanceResult> referee;
      if (check) {
        for (const auto& [a, b] : pairs) {
          referee.push_back(proxima::distance(*hulls[a], pose[a], *hulls[b], pose[b]));
          certificate_gap =
              std::max(certificate_gap, referee.back().distance - referee.back().lower_bound);
          // An independent second opinion: classic GJK with brute-force support.
          proxima::DistanceOptions gjk;
          gjk.algorithm = proxima::Algorithm::gjk;
          const proxima::DistanceResult second =
              proxima::distance(*hulls[a], pose[a], *hulls[b], pose[b], gjk);
          gjk_gap = std::max(gjk_gap, std::abs(second.distance - referee.back().distance));
        }
      }

      for (int s : {scene_all, scene_near}) {
        proxima::Scene& scene = s == scene_all ? *all_pairs : *near_pairs;
        const auto start = Clock::now();
        for (int i = 0; i < kBodies; ++i) scene.set_pose(i, pose[i]);
        const auto close = scene.step();
        times[s].push_back(seconds_since(start));
        if (s == scene_all && close.size() != pairs.size()) {
          std::fprintf(stderr, "robot_bench: the all-pairs scene reported %zu pairs, not %zu\n",
                       close.size(), pairs.size());
          return 1;
        }
        if (check) {
          for (const proxima::ClosePair& p : close) {
            const std::size_t k = static_cast<std::size_t>(
                std::find(pairs.begin(), pairs.end(), std::pair<int, int>(p.a, p.b)) -
                pairs.begin());
            agreement[s].add(p.result.distance, referee[k]);
          }
        }
      }

      auto start = Clock::now();
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto [a, b] = pairs[k];
        const proxima::DistanceResult d = proxima::distance(*hulls[a], pose[a], *hulls[b], pose[b]);
        sink += d.distance;
        if (check) agreement[cold].add(d.distance, referee[k]);
      }
      times[cold].push_back(seconds_since(start));

      for (int s : {fcl_libccd, fcl_indep, fcl_tight}) {
        const fcl::DistanceRequestd& request = s == fcl_libccd  ? libccd_request
                                               : s == fcl_indep ? indep_request
                                                                : tight_request;
        start = Clock::now();
        std::array<fcl::Transform3d, kBodies> tf;
        for (int i = 0; i < kBodies; ++i) tf[i] = proxima::bench::fcl_transform(pose[i]);
        for (std::size_t k = 0; k < pairs.size(); ++k) {
          const auto [a, b] = pairs[k];
          fcl::DistanceResultd result;
          const double d =
              fcl::distance(fcl_hulls[a].get(), tf[a], fcl_hulls[b].get(), tf[b], request, result);
          sink += d;
          if (check) agreement[s].add(d, referee[k]);
        }
        times[s].push_back(seconds_since(start));
      }
    }
  }

  std::printf("Panda self-distance: %zu configurations x %d repetitions, %zu non-adjacent pairs\n",
              poses.size(), repeat, pairs.size());
  std::printf("%-26s %12s %14s %12s %s\n", "system", "us/config", "x proxima all", "pairs checked",
              "largest |d - referee| (m), overlap disagreements");
  const double base = median(times[scene_all]);
  for (int s = 0; s < systems; ++s) {
    const double t = median(times[s]);
    std::printf("%-26s %12.2f %14.2f %12d %.3g, %d", names[s], 1e6 * t, t / base,
                agreement[s].pairs, agreement[s].largest, agreement[s].overlap_wrong);
    if (s == cold) std::printf(" (the referee)");
    if (agreement[s].largest > 0) {
      std::printf(" (%.9f against %.9f)", agreement[s].worst_distance, agreement[s].worst_referee);
    }
    std::printf("\n");
  }
  std::printf(
      "referee: proxima's cold query; its largest distance - certified lower bound %.3g m; "
      "proxima's classic GJK (brute-force support) within %.3g m of it; checksum %.6f\n",
      certificate_gap, gjk_gap, sink);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int repeat = 20;
    std::string mesh_dir = PROXIMA_PANDA_MESH_DIR;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--repeat" && i + 1 < argc) {
        repeat = std::atoi(argv[++i]);
        if (repeat < 1) {
          std::fprintf(stderr, "robot_bench: --repeat needs a positive count, got '%s'\n", argv[i]);
          return 2;
        }
      } else if (!arg.empty() && arg[0] == '-') {
        std::fprintf(stderr, "usage: robot_bench [--repeat R] [mesh directory]\n");
        return 2;
      } else {
        mesh_dir = arg;
      }
    }
    return run(repeat, mesh_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot_bench: %s\n", e.what());
    return 2;
  }
}
