// The Franka Emika Panda's kinematics for the robotics example
// (robot_self_distance.cpp) and its benchmark against FCL (bench/robot_bench.cpp):
// the joint table, forward kinematics and a seeded trajectory within the
// joint limits. One copy, so that both measure the same arm on the same path.
#pragma once

#include <proxima/core/types.h>

#include <array>
#include <cstdint>
#include <numbers>
#include <vector>

namespace panda {

using proxima::Mat3;
using proxima::Pose;
using proxima::Vec3;

inline constexpr double pi = std::numbers::pi;

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
inline const std::array<Joint, 7> kJoints = {{
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
inline const Vec3 kLink8Offset(0, 0, 0.107);
inline constexpr double kHandYaw = -pi / 4;

inline const std::array<const char*, 9> kLinkNames = {"link0", "link1", "link2", "link3", "link4",
                                                      "link5", "link6", "link7", "hand"};

inline Mat3 rotation_rpy(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// Forward kinematics: each body's pose (world from body) for joint angles q,
// the base (link0) at the world origin. Bodies 0..7 are link0..link7, 8 the hand.
inline std::array<Pose, 9> link_poses(const std::array<double, 7>& q) {
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
inline double uniform01(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15u);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1p-53;
}

// A seeded trajectory: random waypoints inside the joint limits, joined by
// straight lines in joint space, `steps` configurations per segment.
inline std::vector<std::array<double, 7>> trajectory(std::uint64_t seed, int waypoints, int steps) {
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

}  // namespace panda
