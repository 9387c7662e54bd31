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
#include <proxima/scene.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#ifndef PROXIMA_PANDA_MESH_DIR
#define PROXIMA_PANDA_MESH_DIR "examples/data/panda"
#endif

using proxima::Mat3;
using proxima::Pose;
using proxima::Vec3;

namespace {

constexpr double pi = std::numbers::pi;

// The Panda's kinematics, copied from franka_description's franka_arm.xacro
// (franka_ros): joint i moves link i relative to link i-1. Each joint's
// <origin xyz rpy> places the joint frame in the parent link's frame, and the
// joint turns about its <axis> (z for all seven) by the joint angle. Units:
// metres and radians. The limits are joint_limits.yaml's lower and upper.
struct Joint {
  Vec3 xyz;
  Vec3 rpy;  // URDF roll, pitch, yaw: R = Rz(yaw) * Ry(pitch) * Rx(roll)
  double lower, upper;
};
const std::array<Joint, 7> kJoints = {{
    {{0, 0, 0.333}, {0, 0, 0}, -2.8973, 2.8973},              // joint1: link0 -> link1
    {{0, 0, 0}, {-pi / 2, 0, 0}, -1.7628, 1.7628},            // joint2: link1 -> link2
    {{0, -0.316, 0}, {pi / 2, 0, 0}, -2.8973, 2.8973},        // joint3: link2 -> link3
    {{0.0825, 0, 0}, {pi / 2, 0, 0}, -3.0718, -0.0698},       // joint4: link3 -> link4
    {{-0.0825, 0.384, 0}, {-pi / 2, 0, 0}, -2.8973, 2.8973},  // joint5: link4 -> link5
    {{0, 0, 0}, {pi / 2, 0, 0}, -0.0175, 3.7525},             // joint6: link5 -> link6
    {{0.088, 0, 0}, {pi / 2, 0, 0}, -2.8973, 2.8973},         // joint7: link6 -> link7
}};
// The fixed joint8 (franka_arm.xacro): link8 = link7 moved by z 0.107. The
// hand hangs from link8 turned by yaw -pi/4: franka_ros's robot xacros mount
// it with `<xacro:franka_hand rpy="0 0 ${-pi/4}" connected_to="..._link8"/>`
// (not in franka_arm.xacro).
const Vec3 kLink8Offset(0, 0, 0.107);
constexpr double kHandYaw = -pi / 4;

const std::array<const char*, 9> kLinkNames = {"link0", "link1", "link2", "link3", "link4",
                                               "link5", "link6", "link7", "hand"};

Mat3 rotation_rpy(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// Forward kinematics: each body's pose (world from body) for joint angles q,
// the base (link0) at the world origin. Bodies 0..7 are link0..link7, 8 the hand.
std::array<Pose, 9> link_poses(const std::array<double, 7>& q) {
  std::array<Pose, 9> poses;
  poses[0] = Pose::identity();
  for (int i = 0; i < 7; ++i) {
    const Pose origin(rotation_rpy(kJoints[i].rpy), kJoints[i].xyz);
    const Pose turn(Mat3(Eigen::AngleAxisd(q[i], Vec3::UnitZ())), Vec3::Zero());
    poses[i + 1] = poses[i] * origin * turn;
  }
  const Pose link8 = poses[7] * Pose::from_translation(kLink8Offset);
  poses[8] = link8 * Pose(Mat3(Eigen::AngleAxisd(kHandYaw, Vec3::UnitZ())), Vec3::Zero());
  return poses;
}

// SplitMix64 (Steele, Lea and Flood), written out so that the Python example
// draws the very same numbers: a uniform double in [0, 1).
double uniform01(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15u);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1p-53;
}

// A seeded trajectory: random waypoints inside the joint limits, joined by
// straight lines in joint space, `steps` configurations per segment.
std::vector<std::array<double, 7>> trajectory(std::uint64_t seed, int waypoints, int steps) {
  std::vector<std::array<double, 7>> points;
  for (int w = 0; w < waypoints; ++w) {
    std::array<double, 7> q;
    for (int i = 0; i < 7; ++i) {
      const double u = uniform01(seed);
      q[i] = kJoints[i].lower + u * (kJoints[i].upper - kJoints[i].lower);
    }
    points.push_back(q);
  }
  std::vector<std::array<double, 7>> path;
  for (int w = 0; w + 1 < waypoints; ++w) {
    for (int s = 0; s < steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      std::array<double, 7> q;
      for (int i = 0; i < 7; ++i) q[i] = (1 - t) * points[w][i] + t * points[w + 1][i];
      path.push_back(q);
    }
  }
  return path;
}

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

  const std::vector<std::array<double, 7>> path = trajectory(2026, 5, 40);
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
