// Robot self-distance with the links as triangle meshes (issue 12): the
// robotics example's arm (the Franka Panda's seven links and hand,
// examples/panda_arm.h) along the example's trajectory and on 160 random
// configurations (issue 26: a planner's samples), each link its
// collision mesh as given (not its hull), proxima's TriangleMesh against
// FCL 0.7's BVHModel with fcl::distance.
//
//   ./build/release/bench/robot_mesh_bench [--repeat R] [--referee K] [mesh directory]
//   (R = 5 repetitions of the 160 configurations, K = 8 refereed configurations)
//
// Per configuration, every non-adjacent pair of links (28 of the 36 pairs),
// timed separately in the same loop so that machine noise falls on every
// system:
//   proxima tracked   distance(mesh, pose, mesh, pose, {}, &cache), one
//                     MeshCache per pair carried along the trajectory;
//   proxima cold      the same without a cache;
//   FCL OBBRSS, RSS   fcl::distance on BVHModel<OBBRSS> / <RSS> built from
//                     the same vertices and triangles, DistanceRequest with
//                     enable_nearest_points and rel_err = abs_err = 0 (exact).
// Times: the median over all configurations of all repetitions of the time
// of one configuration (28 pairs). Accuracy: on K configurations spread over
// the trajectory, each pair against the referee distance_all_pairs (every
// triangle pair with the closed-form kernel): the largest |d - referee| over
// pairs the referee reports apart, and the pairs whose overlap verdict
// differs (FCL's mesh distance reports a collision as -1).
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/distance.h>
#include <proxima/io.h>
#include <proxima/query/mesh_distance.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
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

struct Agreement {
  double largest = 0;
  int overlap_wrong = 0;
  int pairs = 0;
  void add(double distance, bool overlaps, const proxima::MeshResult& referee) {
    ++pairs;
    const bool referee_overlaps = referee.status == proxima::Status::intersecting;
    if (referee_overlaps != overlaps) {
      ++overlap_wrong;
      return;
    }
    if (!referee_overlaps) largest = std::max(largest, std::abs(distance - referee.distance));
  }
};

int run(int repeat, int referee_count, const std::string& mesh_dir) {
  std::vector<std::shared_ptr<const proxima::TriangleMesh>> meshes;
  std::vector<std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>>> fcl_obbrss;
  std::vector<std::shared_ptr<fcl::BVHModel<fcl::RSSd>>> fcl_rss;
  int triangles = 0;
  int closed = 0;
  for (int i = 0; i < kBodies; ++i) {
    const std::string path = mesh_dir + "/" + panda::kLinkNames[i] + ".stl";
    meshes.push_back(std::make_shared<const proxima::TriangleMesh>(proxima::load_mesh(path).mesh));
    triangles += meshes.back()->triangle_count();
    closed += meshes.back()->is_closed() ? 1 : 0;
    fcl_obbrss.push_back(proxima::bench::fcl_mesh<fcl::OBBRSSd>(meshes.back()->vertices(),
                                                                meshes.back()->triangles()));
    fcl_rss.push_back(
        proxima::bench::fcl_mesh<fcl::RSSd>(meshes.back()->vertices(), meshes.back()->triangles()));
  }
  std::vector<std::pair<int, int>> pairs;  // the non-adjacent pairs
  for (int a = 0; a < kBodies; ++a)
    for (int b = a + 2; b < kBodies; ++b) pairs.emplace_back(a, b);

  // The example's trajectory (link origins moving a few mm a step) and 160
  // random configurations (a planner's samples: each pose unrelated to the
  // last, so a cache carried along them is as good as cold).
  std::vector<std::array<proxima::Pose, kBodies>> trajectory, random;
  for (const auto& q : panda::trajectory(2026, 5, 40)) trajectory.push_back(panda::link_poses(q));
  for (const auto& q : panda::trajectory(7, 161, 1)) random.push_back(panda::link_poses(q));
  const auto run_case = [&](const char* motion,
                            const std::vector<std::array<proxima::Pose, kBodies>>& poses) {
    const std::size_t stride = std::max<std::size_t>(1, poses.size() / std::size_t(referee_count));

    enum { tracked, cold, fcl_obb, fcl_r, systems };
    const std::array<const char*, systems> names = {"proxima tracked", "proxima cold", "FCL OBBRSS",
                                                    "FCL RSS"};
    std::array<std::vector<double>, systems> times;
    std::array<Agreement, systems> agreement;
    std::vector<proxima::MeshCache> caches(pairs.size());
    fcl::DistanceRequestd request;
    request.enable_nearest_points = true;
    request.rel_err = 0;
    request.abs_err = 0;
    double sink = 0;
    long tracked_answers = 0, answers = 0;

    for (int r = 0; r < repeat; ++r) {
      for (std::size_t c = 0; c < poses.size(); ++c) {
        const auto& pose = poses[c];
        const bool check = r == 0 && c % stride == 0;
        std::vector<proxima::MeshResult> referee;
        if (check) {
          for (const auto& [a, b] : pairs)
            referee.push_back(proxima::distance_all_pairs(*meshes[a], pose[a], *meshes[b], pose[b]));
        }
        // Tracked and cold take turns going first: the second query of a
        // configuration finds the meshes' nodes in the processor's caches,
        // which on random configurations (where tracking saves few
        // instructions) would be a larger share than tracking itself.
        const bool tracked_first = (r + static_cast<int>(c)) % 2 == 0;
        for (int s : {tracked_first ? tracked : cold, tracked_first ? cold : tracked}) {
          const auto start = Clock::now();
          for (std::size_t k = 0; k < pairs.size(); ++k) {
            const auto [a, b] = pairs[k];
            const proxima::MeshResult d = proxima::distance(*meshes[a], pose[a], *meshes[b], pose[b],
                                                            {}, s == tracked ? &caches[k] : nullptr);
            sink += d.distance;
            if (s == tracked) {
              tracked_answers += d.tracked ? 1 : 0;
              ++answers;
            }
            if (check) {
              agreement[s].add(d.distance, d.status == proxima::Status::intersecting, referee[k]);
            }
          }
          times[s].push_back(seconds_since(start));
        }
        for (int s : {fcl_obb, fcl_r}) {
          const auto start = Clock::now();
          std::array<fcl::Transform3d, kBodies> tf;
          for (int i = 0; i < kBodies; ++i) tf[i] = proxima::bench::fcl_transform(pose[i]);
          for (std::size_t k = 0; k < pairs.size(); ++k) {
            const auto [a, b] = pairs[k];
            fcl::DistanceResultd result;
            const double d = s == fcl_obb ? fcl::distance(fcl_obbrss[a].get(), tf[a],
                                                          fcl_obbrss[b].get(), tf[b], request, result)
                                          : fcl::distance(fcl_rss[a].get(), tf[a], fcl_rss[b].get(),
                                                          tf[b], request, result);
            sink += d;
            if (check) agreement[s].add(d, d <= 0, referee[k]);
          }
          times[s].push_back(seconds_since(start));
        }
      }
    }

    std::printf(
        "\nPanda self-distance, links as meshes, %s: %d links, %d triangles (%d closed "
        "meshes), %zu configurations x %d repetitions, %zu non-adjacent pairs\n",
        motion, kBodies, triangles, closed, poses.size(), repeat, pairs.size());
    std::printf("%-18s %12s %14s %12s %s\n", "system", "us/config", "x FCL OBBRSS", "pairs checked",
                "largest |d - referee| (m), overlap disagreements");
    const double fcl_base = median(times[fcl_obb]);
    for (int s = 0; s < systems; ++s) {
      const double t = median(times[s]);
      std::printf("%-18s %12.2f %14.2f %12d %.3g, %d\n", names[s], 1e6 * t, fcl_base / t,
                  agreement[s].pairs, agreement[s].largest, agreement[s].overlap_wrong);
    }
    std::printf(
        "(x FCL OBBRSS: how many times faster than FCL OBBRSS); tracked queries answered from the "
        "cache's candidate pairs: %.1f%%; referee: distance_all_pairs on every %zu-th configuration "
        "of the first repetition; checksum %.6f\n",
        100.0 * double(tracked_answers) / double(std::max(answers, 1L)), stride, sink);
  };
  run_case("trajectory", trajectory);
  run_case("random configurations", random);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int repeat = 5;
    int referee = 8;
    std::string mesh_dir = PROXIMA_PANDA_MESH_DIR;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if ((arg == "--repeat" || arg == "--referee") && i + 1 < argc) {
        const int value = std::atoi(argv[++i]);
        if (value < 1) {
          std::fprintf(stderr, "robot_mesh_bench: %s needs a positive count, got '%s'\n",
                       arg.c_str(), argv[i]);
          return 2;
        }
        (arg == "--repeat" ? repeat : referee) = value;
      } else if (!arg.empty() && arg[0] == '-') {
        std::fprintf(stderr,
                     "usage: robot_mesh_bench [--repeat R] [--referee K] [mesh directory]\n");
        return 2;
      } else {
        mesh_dir = arg;
      }
    }
    return run(repeat, referee, mesh_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot_mesh_bench: %s\n", e.what());
    return 2;
  }
}
