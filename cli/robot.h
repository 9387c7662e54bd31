// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 9: `proxima robot`, a robot from its URDF answering JSON Lines of
// configurations (docs/robotics.md):
//
//   {"id": 1, "q": [0, -0.78, 0, -2.35, 0, 1.57, 0.78, 0.01]}
//   {"id": 2, "q": {"panda_joint1": 0.1, ...}}       (every joint named)
//
// Each line gets one answer line, in order: the minimum signed distance
// (self and environment), the pairs within the margin with their closest
// points, normal and gradient, and the minimum's gradient. The robot's
// per-pair caches are kept from line to line (a trajectory is tracked). A
// bad line gets {"id": ..., "error": "line N: ..."} and the run goes on.
// With --environment the robot's geometries are also measured against the
// obstacles of that file; with --view the last configuration is drawn as a
// viewer page (proxima/viewer): only tested pairs are drawn, so adjacent
// and SRDF-disabled links never show as collisions.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace proxima::cli {

struct RobotCommand {
  std::string urdf;
  std::string srdf;
  std::vector<std::string> package_dirs;
  std::string mesh_as = "hull";
  double margin = 0.0;
  bool gradients = false;
  std::string file = "-";
  // JSON Lines of environment bodies, one per line in the format of a
  // query's body ("vertices", optional "triangles", "radius", "pose"; see
  // docs/query-format.md) with an optional "name": the obstacles of every
  // configuration. Empty: none.
  std::string environment;
  // A viewer page of the last configuration answered (the robot's
  // geometries, the obstacles and the close pairs); empty: none.
  std::string view_out;
};

// Exit code: 0 when the robot loaded and every line was read (bad lines
// included: they are answered), 1 when the robot or the input cannot be
// read.
int run_robot(const RobotCommand& command, std::istream& in, std::ostream& out, std::ostream& err);

}  // namespace proxima::cli
