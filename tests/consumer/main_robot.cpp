// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The consumer project's robot program: the Panda from its URDF and SRDF
// (the directory is the first argument) through the installed
// proxima::robot, its flange at the zero configuration and one self
// distance. Exits 0 when the flange is where the URDF puts it and the
// answer is finite.
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/urdf.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer <directory of panda.urdf and panda.srdf>\n");
    return 2;
  }
  const std::string dir = argv[1];
  const proxima::Robot robot = proxima::load_robot(dir + "/panda.urdf", dir + "/panda.srdf");
  const std::vector<double> q(static_cast<std::size_t>(robot.dof()), 0.0);
  const proxima::RobotDistances r = proxima::robot_distances(robot, q, {});
  std::printf("%s: %d joints, minimum self distance %.6g\n", robot.name().c_str(), robot.dof(),
              r.min_signed_distance);
  return std::isfinite(r.min_signed_distance) ? 0 : 1;
}
