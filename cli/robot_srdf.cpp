// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// `proxima robot-srdf`: see robot_srdf.h.
#include "robot_srdf.h"

#include <CLI/CLI.hpp>
#include <array>
#include <fstream>
#include <iostream>
#include <optional>

#include "proxima/robot/srdf_proposal.h"
#include "proxima/robot/urdf.h"

namespace proxima::cli {

CLI::App* add_robot_srdf(CLI::App& app, RobotSrdfCommand& command) {
  CLI::App* sub = app.add_subcommand(
      "robot-srdf",
      "Propose the pairs of links a robot's self-collision queries may skip (adjacent, in "
      "collision at the default configuration, always in collision, never within the margin "
      "over sampled configurations) and write them as an SRDF (docs/robotics.md)");
  sub->add_option("--urdf", command.urdf, "The robot's URDF")->required();
  sub->add_option("--package-dir", command.package_dirs,
                  "Where package:// URIs point: NAME=DIR, or a directory holding packages "
                  "(repeatable)");
  sub->add_option("--mesh-as", command.mesh_as,
                  "How a collision mesh becomes a body: hull, mesh or pieces")
      ->check(CLI::IsMember(std::vector<std::string>{"hull", "mesh", "pieces"}))
      ->capture_default_str();
  sub->add_option("--samples", command.samples, "Sampled configurations")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--margin", command.margin,
                  "A pair that never comes within this distance is disabled ('Never')")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--seed", command.seed, "Seed of the sampled configurations")
      ->capture_default_str();
  sub->add_option("-o,--out", command.out_file, "The SRDF to write ('-': standard output)")
      ->capture_default_str();
  sub->footer(
      "Example:\n"
      "  proxima robot-srdf --urdf panda.urdf --package-dir NAME=DIR --samples 10000 "
      "--margin 0.01 -o panda.srdf");
  return sub;
}

int run_robot_srdf(const RobotSrdfCommand& command, std::ostream& out, std::ostream& err) {
  std::optional<Robot> robot;
  SrdfProposal proposal;
  try {
    RobotLoadOptions load;
    load.package_dirs = command.package_dirs;
    load.mesh_as = load_as_from_string(command.mesh_as);
    robot.emplace(load_robot(command.urdf, "", load));
    SrdfProposalOptions options;
    options.samples = command.samples;
    options.margin = command.margin;
    options.seed = command.seed;
    proposal = propose_disabled_pairs(*robot, options);
  } catch (const std::exception& e) {
    err << "proxima robot-srdf: " << e.what() << "\n";
    return 1;
  }
  const std::string srdf = write_srdf(*robot, proposal);
  if (command.out_file == "-") {
    out << srdf;
    out.flush();
    if (!out) {
      err << "proxima robot-srdf: writing the SRDF failed\n";
      return 1;
    }
  } else {
    std::ofstream file(command.out_file, std::ios::binary);
    file << srdf;
    file.close();
    if (!file) {
      err << "proxima robot-srdf: cannot write '" << command.out_file << "'\n";
      return 1;
    }
  }
  std::array<int, 4> by_reason{};
  for (const DisabledLinkPair& pair : proposal.pairs) ++by_reason[static_cast<int>(pair.reason)];
  err << "proxima robot-srdf: " << proposal.pairs.size() << " of " << proposal.link_pairs
      << " link pairs disabled (adjacent " << by_reason[0] << ", default " << by_reason[1]
      << ", always " << by_reason[2] << ", never " << by_reason[3] << "), " << proposal.enabled
      << " enabled, from " << proposal.samples << " samples\n";
  return 0;
}

}  // namespace proxima::cli
