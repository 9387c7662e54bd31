// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 9: `proxima robot-srdf`, the disabled pairs of a robot's
// self-collision proposed from sampled configurations
// (proxima/robot/srdf_proposal.h) and written as an SRDF:
//
//   proxima robot-srdf --urdf panda.urdf --samples 10000 --margin 0.01 -o panda.srdf
//
// The SRDF goes to the output file (standard output for '-'), a summary
// line to standard error.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace proxima::cli {

struct RobotSrdfCommand {
  std::string urdf;
  std::vector<std::string> package_dirs;
  std::string mesh_as = "hull";
  int samples = 10000;
  double margin = 0.0;
  std::uint64_t seed = 1;
  std::string out_file = "-";
};

// Registers the subcommand and its options on `app`, filling `command`.
CLI::App* add_robot_srdf(CLI::App& app, RobotSrdfCommand& command);

// Exit code: 0 when the SRDF was written, 1 when the robot cannot be read
// or the output cannot be written (the message on `err`).
int run_robot_srdf(const RobotSrdfCommand& command, std::ostream& out, std::ostream& err);

}  // namespace proxima::cli
