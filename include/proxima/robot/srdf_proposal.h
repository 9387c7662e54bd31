// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: which pairs of links a robot's self-collision queries may skip,
// proposed from sampled configurations as MoveIt's setup assistant does,
// and written as an SRDF's disable_collisions.
//
//   proxima::Robot robot = proxima::load_robot("panda.urdf");
//   proxima::SrdfProposal proposal = proxima::propose_disabled_pairs(robot);
//   std::string srdf = proxima::write_srdf(robot, proposal);
//
// A pair of links (each with collision geometry) is proposed when
//   adjacent  a joint connects them, or links without geometry do
//             (Robot::self_pairs' rule);
//   default   its geometries overlap at the default configuration (every
//             variable at 0, clamped into its limits);
//   always    they overlap in every sampled configuration;
//   never     they never come within `margin` of each other in any sampled
//             configuration (the smallest signed distance over their
//             geometry pairs stays above it).
// The first reason that applies is given, in this order. `never` is a
// statistical claim: a pair that comes close in a small part of the joint
// space may be missed by the samples (more samples, a larger margin, make
// that less likely). Configurations are drawn uniformly within the limits
// (a continuous joint over [-pi, pi]) from a seeded generator: the same
// options give the same proposal.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "proxima/robot/robot.h"
#include "proxima/robot/robot_distance.h"

namespace proxima {

enum class DisableReason : std::uint8_t { adjacent, default_pose, always, never };
// MoveIt's words for them: "Adjacent", "Default", "Always", "Never".
const char* to_string(DisableReason reason);

struct SrdfProposalOptions {
  int samples = 10000;   // sampled configurations
  double margin = 0.0;   // "never within margin"; >= 0, in the robot's unit
  std::uint64_t seed = 1;
  // The configurations to judge by (K x dof), e.g. a planner's own; when
  // not empty they replace the random samples (and `samples`, `seed`).
  RowMatrixXd configurations;
};

struct DisabledLinkPair {
  std::int32_t link_a = -1;  // link indices, link_a < link_b
  std::int32_t link_b = -1;
  DisableReason reason = DisableReason::never;
};

struct SrdfProposal {
  // Sorted by (link_a, link_b).
  std::vector<DisabledLinkPair> pairs;
  int samples = 0;
  // Pairs of links with geometry considered, and how many stay enabled.
  int link_pairs = 0;
  int enabled = 0;
};

// The proposal above for `robot`, whose own disabled pairs (an SRDF it was
// loaded with) are ignored: every pair of links with geometry is judged.
// InvalidInput for samples < 1, a negative or non-finite margin, or
// configurations whose column count is not the robot's dof (or with a
// non-finite entry, naming the joint).
SrdfProposal propose_disabled_pairs(const Robot& robot, const SrdfProposalOptions& options = {});

// An SRDF (<robot name="..."> with one <disable_collisions link1 link2
// reason> per pair) for `robot`.
std::string write_srdf(const Robot& robot, const SrdfProposal& proposal);

}  // namespace proxima
