// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The consumer project's robot program (proxima::robot): a two-link robot
// from a URDF text (through the installed URDF parser), its two boxes a known
// distance apart. Exits 0 when the answer is that distance, so the CTest
// test fails if the installed proxima::robot builds but links or computes
// wrongly.
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/urdf.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  // Two unit cubes: one on the base, one on a link turned by the joint
  // about z through the base's origin and carried 3 along x, so the cubes'
  // facing faces are 2 apart at q = 0.
  const char* const kUrdf = R"(<robot name="two">
  <link name="base"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="3 0 0"/><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="tip"/>
  <joint name="turn" type="revolute"><parent link="base"/><child link="tip"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="mount" type="fixed"><parent link="tip"/><child link="arm"/></joint>
</robot>)";
  proxima::RobotDescription description = proxima::read_urdf_string(kUrdf, ".", "two.urdf");
  description.exclude_adjacent = false;  // base and arm are adjacent through tip
  const proxima::Robot robot(std::move(description));
  const std::vector<double> q = {0.0};
  const proxima::RobotDistances r = proxima::robot_distances(robot, q, {});
  std::printf("robot %s: %d variable, minimum %.17g\n", robot.name().c_str(), robot.dof(),
              r.min_signed_distance);
  return std::abs(r.min_signed_distance - 2.0) <= 1e-12 ? 0 : 1;
}
