// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Disabled-pair proposals from sampled configurations
// (proxima/robot/srdf_proposal.h).
#include "proxima/robot/srdf_proposal.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "proxima/robot/robot_distance.h"
#include "core/accuracy.h"

namespace proxima {

const char* to_string(DisableReason reason) {
  switch (reason) {
    case DisableReason::adjacent:
      return "Adjacent";
    case DisableReason::default_pose:
      return "Default";
    case DisableReason::always:
      return "Always";
    case DisableReason::never:
      return "Never";
  }
  return "Unknown";
}

namespace {

// The robot's kinematics and geometry with only the adjacent pairs
// excluded: its own disabled pairs are what is being proposed.
Robot without_disabled_pairs(const Robot& robot) {
  RobotDescription description;
  description.name = robot.name();
  description.links = robot.links();
  description.joints = robot.joints();
  description.geometries = robot.geometries();
  description.exclude_adjacent = true;
  return Robot(std::move(description));
}

// What the samples saw of one pair of links.
struct LinkPairRecord {
  bool within = false;        // some sample within the margin
  int overlapping = 0;        // samples where they overlap
  int last_sample = -1;       // the sample `overlapping` last counted
  bool default_overlap = false;
};

}  // namespace

SrdfProposal propose_disabled_pairs(const Robot& robot, const SrdfProposalOptions& options) {
  if (options.configurations.size() == 0)
    detail::check_at_least(options.samples, 1, "SRDF proposal", "options.samples",
                           "without options.configurations");
  detail::check_finite_non_negative(options.margin, "SRDF proposal", "options.margin");
  const Robot bare = without_disabled_pairs(robot);
  const auto n_links = static_cast<std::size_t>(bare.links().size());
  std::vector<LinkPairRecord> records(n_links * n_links);
  const auto record = [&](std::int32_t a, std::int32_t b) -> LinkPairRecord& {
    const auto [lo, hi] = std::minmax(a, b);
    return records[static_cast<std::size_t>(lo) * n_links + static_cast<std::size_t>(hi)];
  };

  RobotQueryOptions query;
  query.margin = options.margin;
  query.environment = false;
  // Only the sign matters for "overlap": the depth of overlapping hulls is
  // not needed (their status says intersecting).
  query.distance.penetration = false;
  RobotQueryState state;
  const auto& geometries = bare.geometries();
  const auto link_of = [&](std::int32_t g) { return geometries[static_cast<std::size_t>(g)].link; };
  const auto visit = [&](std::span<const double> q, int sample) {
    const RobotDistances r = robot_distances(bare, q, {}, query, &state);
    for (const RobotPairResult& pair : r.close_pairs) {
      LinkPairRecord& rec = record(link_of(pair.geometry_a), link_of(pair.geometry_b));
      const bool overlap = pair.result.status != Status::separated;
      if (sample < 0) {
        rec.default_overlap = rec.default_overlap || overlap;
        continue;
      }
      rec.within = true;
      if (overlap && rec.last_sample != sample) {
        ++rec.overlapping;
        rec.last_sample = sample;
      }
    }
  };

  const Eigen::VectorXd lower = bare.lower_limits(), upper = bare.upper_limits();
  const auto dof = static_cast<std::size_t>(bare.dof());
  std::vector<double> q(dof);
  for (std::size_t v = 0; v < dof; ++v) {
    const auto i = static_cast<Eigen::Index>(v);
    q[v] = std::clamp(0.0, lower[i], upper[i]);
  }
  visit(q, -1);
  const auto& given = options.configurations;
  if (given.size() > 0) {
    if (given.cols() != bare.dof()) {
      throw InvalidInput("SRDF proposal: the configurations have " + std::to_string(given.cols()) +
                         " columns, the robot " + std::to_string(bare.dof()) + " variables");
    }
    for (Eigen::Index k = 0; k < given.rows(); ++k) {
      visit(std::span<const double>(given.row(k).data(), dof), static_cast<int>(k));
    }
  }
  const int samples = given.size() > 0 ? static_cast<int>(given.rows()) : options.samples;
  std::mt19937_64 rng(options.seed);
  for (int sample = 0; given.size() == 0 && sample < options.samples; ++sample) {
    for (std::size_t v = 0; v < dof; ++v) {
      const auto i = static_cast<Eigen::Index>(v);
      const double lo = std::isfinite(lower[i]) ? lower[i] : -std::numbers::pi;
      const double hi = std::isfinite(upper[i]) ? upper[i] : std::numbers::pi;
      q[v] = lo == hi ? lo : std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    visit(q, sample);
  }

  SrdfProposal out;
  out.samples = samples;
  for (std::int32_t a = 0; a < static_cast<std::int32_t>(n_links); ++a) {
    if (bare.link_geometries(a).empty()) continue;
    for (std::int32_t b = a + 1; b < static_cast<std::int32_t>(n_links); ++b) {
      if (bare.link_geometries(b).empty()) continue;
      ++out.link_pairs;
      const LinkPairRecord& rec = record(a, b);
      DisabledLinkPair pair{a, b, DisableReason::never};
      if (!bare.link_pair_enabled(a, b)) {
        pair.reason = DisableReason::adjacent;
      } else if (rec.default_overlap) {
        pair.reason = DisableReason::default_pose;
      } else if (rec.overlapping == samples) {
        pair.reason = DisableReason::always;
      } else if (!rec.within) {
        pair.reason = DisableReason::never;
      } else {
        ++out.enabled;
        continue;
      }
      out.pairs.push_back(pair);
    }
  }
  return out;
}

std::string write_srdf(const Robot& robot, const SrdfProposal& proposal) {
  tinyxml2::XMLPrinter printer;
  printer.PushHeader(false, true);
  const std::string note = " Proposed by proxima from " + std::to_string(proposal.samples) +
                           " sampled configurations: " + std::to_string(proposal.pairs.size()) +
                           " of " + std::to_string(proposal.link_pairs) +
                           " link pairs disabled ";
  printer.PushComment(note.c_str());
  printer.OpenElement("robot");
  printer.PushAttribute("name", robot.name().c_str());
  for (const DisabledLinkPair& pair : proposal.pairs) {
    printer.OpenElement("disable_collisions");
    printer.PushAttribute("link1", robot.links()[static_cast<std::size_t>(pair.link_a)].name.c_str());
    printer.PushAttribute("link2", robot.links()[static_cast<std::size_t>(pair.link_b)].name.c_str());
    printer.PushAttribute("reason", to_string(pair.reason));
    printer.CloseElement();
  }
  printer.CloseElement();
  return printer.CStr();
}

}  // namespace proxima
