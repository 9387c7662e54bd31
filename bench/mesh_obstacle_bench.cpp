// A robot's link meshes against convex obstacles (issue 26): the
// mesh-convex distance (proxima/query/mesh_distance.h, distance(TriangleMesh,
// ConvexPolytope)) on the Franka Panda's nine link meshes as given
// (examples/panda_arm.h) against three boxes (a table, a shelf above it, a
// post beside the arm), every link against every obstacle (27 pairs), along
// the example's trajectory (160 configurations, link origins moving a few mm
// a step) and on 160 random configurations.
//
//   ./build/release/bench/mesh_obstacle_bench [--repeat R] [mesh directory]   (R = 5)
//
// Per configuration, timed separately: the 27 queries tracked (one MeshCache
// per pair carried along) and cold (no cache). Times: the median over all
// configurations of all repetitions of one configuration's time; the
// passes alternate in every repetition. Answers: on the first repetition
// every answer against the referee distance_all_pairs (every triangle
// against the box): the status, and the distance within the accuracy
// standard (1e-12 relative plus 64 u R) for separated pairs; the output
// counts the answers outside it (none may be).
#include <proxima/io.h>
#include <proxima/query/distance.h>
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

#ifndef PROXIMA_PANDA_MESH_DIR
#define PROXIMA_PANDA_MESH_DIR "examples/data/panda"
#endif

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kLinks = 9;
constexpr double kUnit = 0x1p-53;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Obstacle {
  std::shared_ptr<const proxima::ConvexPolytope> box;
  proxima::Pose pose;
};

std::shared_ptr<const proxima::ConvexPolytope> box(double x, double y, double z) {
  std::vector<proxima::Vec3> v;
  for (int k = 0; k < 8; ++k)
    v.emplace_back((k & 1) ? x : -x, (k & 2) ? y : -y, (k & 4) ? z : -z);
  return std::make_shared<const proxima::ConvexPolytope>(v);
}

void run_case(const std::vector<std::shared_ptr<const proxima::TriangleMesh>>& links,
              const std::vector<Obstacle>& obstacles, const char* motion,
              const std::vector<std::array<proxima::Pose, kLinks>>& poses, int repeat) {
  const std::size_t pairs = links.size() * obstacles.size();
  std::vector<proxima::MeshCache> caches(pairs);
  std::vector<double> tracked_times, cold_times;
  long tested_tracked = 0, tested_cold = 0, queries = 0;
  int wrong = 0, checked = 0, intersecting = 0;
  double sink = 0.0;
  for (int r = 0; r < repeat; ++r) {
    for (int pass = 0; pass < 2; ++pass) {
      const bool tracked = (pass + r) % 2 == 0;
      for (const auto& pose : poses) {
        const auto start = Clock::now();
        std::size_t k = 0;
        for (std::size_t i = 0; i < links.size(); ++i) {
          for (const Obstacle& o : obstacles) {
            const proxima::MeshResult m = proxima::distance(
                *links[i], pose[i], *o.box, o.pose, {}, tracked ? &caches[k] : nullptr);
            sink += m.distance;
            if (r == 0) {
              (tracked ? tested_tracked : tested_cold) += m.pairs_tested;
              if (tracked) ++queries;
            }
            ++k;
          }
        }
        (tracked ? tracked_times : cold_times)
            .push_back(std::chrono::duration<double>(Clock::now() - start).count());
      }
    }
  }
  // The referee, once, outside the timings, against the tracked answers of
  // a fresh pass.
  std::vector<proxima::MeshCache> check(pairs);
  for (const auto& pose : poses) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < links.size(); ++i) {
      for (const Obstacle& o : obstacles) {
        const proxima::MeshResult m =
            proxima::distance(*links[i], pose[i], *o.box, o.pose, {}, &check[k++]);
        const proxima::MeshResult ref =
            proxima::distance_all_pairs(*links[i], pose[i], *o.box, o.pose);
        ++checked;
        const double R = std::max(proxima::magnitude_bound(pose[i], links[i]->scale()),
                                  proxima::magnitude_bound(o.pose, o.box->scale()));
        if (ref.status == proxima::Status::intersecting) {
          ++intersecting;
          wrong += m.status == proxima::Status::intersecting ? 0 : 1;
        } else {
          wrong += std::abs(m.distance - ref.distance) <= 1e-12 * ref.distance + 64 * kUnit * R
                       ? 0
                       : 1;
        }
      }
    }
  }
  std::printf("\n%s: %zu configurations x %d repetitions, %zu pairs each\n", motion, poses.size(),
              repeat, pairs);
  std::printf("  tracked %8.2f us per configuration (%.2f triangles per query)\n",
              1e6 * median(tracked_times), double(tested_tracked) / double(queries));
  std::printf("  cold    %8.2f us per configuration (%.2f triangles per query)\n",
              1e6 * median(cold_times), double(tested_cold) / double(queries));
  std::printf("  referee: %d answers checked (%d intersecting), %d outside the standard "
              "(checksum %.6g)\n",
              checked, intersecting, wrong, sink);
}

int run(int repeat, const std::string& mesh_dir) {
  std::vector<std::shared_ptr<const proxima::TriangleMesh>> links;
  for (int i = 0; i < kLinks; ++i) {
    const std::string path = mesh_dir + "/" + panda::kLinkNames[i] + ".stl";
    links.push_back(std::make_shared<const proxima::TriangleMesh>(proxima::load_mesh(path).mesh));
  }
  const auto at = [](double x, double y, double z) {
    return proxima::Pose(proxima::Mat3::Identity(), proxima::Vec3(x, y, z));
  };
  const std::vector<Obstacle> obstacles = {
      {box(0.4, 0.6, 0.02), at(0.8, 0.0, 0.0)},    // a table in front of the arm
      {box(0.15, 0.3, 0.01), at(0.6, 0.0, 0.7)},   // a shelf above it
      {box(0.03, 0.03, 0.5), at(0.3, 0.5, 0.5)}};  // a post beside the arm
  std::printf("Panda link meshes against 3 boxes (mesh-convex distance)\n");
  std::vector<std::array<proxima::Pose, kLinks>> trajectory, random;
  for (const auto& q : panda::trajectory(2026, 5, 40)) trajectory.push_back(panda::link_poses(q));
  for (const auto& q : panda::trajectory(7, 161, 1)) random.push_back(panda::link_poses(q));
  run_case(links, obstacles, "trajectory", trajectory, repeat);
  run_case(links, obstacles, "random configurations", random, repeat);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int repeat = 5;
    std::string mesh_dir = PROXIMA_PANDA_MESH_DIR;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--repeat" && i + 1 < argc) {
        repeat = std::atoi(argv[++i]);
        if (repeat < 1) {
          std::fprintf(stderr, "mesh_obstacle_bench: --repeat needs a positive count\n");
          return 2;
        }
      } else {
        mesh_dir = arg;
      }
    }
    return run(repeat, mesh_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mesh_obstacle_bench: %s\n", e.what());
    return 1;
  }
}
