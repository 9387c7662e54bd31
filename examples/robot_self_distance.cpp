// A robot's self-distance, built and run by `make test`: the Franka Emika
// Panda's seven links and hand, each the convex hull of its collision mesh,
// placed by forward kinematics in a proxima::Scene. Adjacent links overlap by
// construction and are excluded; the arm moves along a seeded trajectory of
// configurations within the joint limits, and each configuration prints the
// closest pair of non-adjacent links. The scene keeps each pair's cache
// between configurations (tracking). Some configurations are checked against
// the scene's slow twin close_pairs_all_pairs() (cold queries on every pair);
// a mismatch returns 1.
//
//   robot_self_distance [mesh directory]   (default: examples/data/panda)
#include <proxima/io.h>
#include <proxima/scene/scene.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "panda_arm.h"  // the joint table (from franka_arm.xacro), forward kinematics, trajectory

#ifndef PROXIMA_PANDA_MESH_DIR
#define PROXIMA_PANDA_MESH_DIR "examples/data/panda"
#endif

using panda::kLinkNames;
using panda::link_poses;
using proxima::Pose;

namespace {

bool same_pairs(std::span<const proxima::ClosePair> fast,
                const std::vector<proxima::ClosePair>& slow) {
  if (fast.size() != slow.size()) return false;
  for (std::size_t p = 0; p < slow.size(); ++p) {
    if (fast[p].a != slow[p].a || fast[p].b != slow[p].b) return false;
    if (std::abs(fast[p].result.distance - slow[p].result.distance) >
        1e-9 * (1 + slow[p].result.distance))
      return false;
  }
  return true;
}

const char* link_name(const std::array<proxima::BodyId, 9>& ids, proxima::BodyId id) {
  return kLinkNames[static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin())];
}

int run(const std::string& mesh_dir) {
  proxima::SceneOptions options;
  options.margin = 0.05;  // report pairs of links closer than 5 cm
  proxima::Scene scene(options);

  // Each link's collision mesh, in the link's own frame, as its convex hull.
  const std::array<Pose, 9> home = link_poses({0, 0, 0, -1.5, 0, 1.5, 0});
  std::array<proxima::BodyId, 9> ids;
  for (int i = 0; i < 9; ++i) {
    const std::string path = mesh_dir + "/" + kLinkNames[i] + ".stl";
    proxima::LoadedPolytope loaded = proxima::load_convex(path);
    std::printf("%-5s %4d points, hull of %3d vertices%s\n", kLinkNames[i], loaded.input_points,
                static_cast<int>(loaded.polytope.vertices().size()),
                loaded.input_was_convex ? "" : " (the mesh is not quite convex: its hull is used)");
    ids[i] = scene.add(std::make_shared<const proxima::ConvexPolytope>(std::move(loaded.polytope)),
                       home[i]);
  }
  // Adjacent links touch at their joint: never test them.
  for (int i = 0; i + 1 < 9; ++i) scene.exclude_pair(ids[i], ids[i + 1]);

  const std::vector<std::array<double, 7>> path = panda::trajectory(2026, 5, 40);
  int mismatches = 0, checked = 0;
  double seconds = 0;
  for (std::size_t c = 0; c < path.size(); ++c) {
    const std::array<Pose, 9> poses = link_poses(path[c]);
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 9; ++i) scene.set_pose(ids[i], poses[i]);
    const std::span<const proxima::ClosePair> pairs = scene.step();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const auto closest = std::min_element(
        pairs.begin(), pairs.end(),
        [](const auto& x, const auto& y) { return x.result.distance < y.result.distance; });
    if (closest == pairs.end()) {
      std::printf("config %3zu: no pair of non-adjacent links within %.0f cm\n", c,
                  100 * options.margin);
    } else {
      std::printf("config %3zu: closest %s-%s %-12s %.4f m (%zu pairs within %.0f cm)\n", c,
                  link_name(ids, closest->a), link_name(ids, closest->b),
                  proxima::to_string(closest->result.status), closest->result.distance,
                  pairs.size(), 100 * options.margin);
    }
    if (c % 20 == 0) {  // check against the slow twin: cold queries on every tested pair
      ++checked;
      if (!same_pairs(pairs, scene.close_pairs_all_pairs())) {
        ++mismatches;
        std::printf("config %3zu: MISMATCH against close_pairs_all_pairs\n", c);
      }
    }
  }
  std::printf("%zu configurations, %.2f us per configuration (set 9 poses and step, tracked)\n",
              path.size(), 1e6 * seconds / static_cast<double>(path.size()));
  std::printf("%s: %d mismatches in %d configurations checked against close_pairs_all_pairs\n",
              mismatches == 0 ? "ok" : "FAILED", mismatches, checked);
  return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc > 1 ? argv[1] : PROXIMA_PANDA_MESH_DIR);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot_self_distance: %s\n", e.what());
    return 2;
  }
}
