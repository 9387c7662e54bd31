// Disabled-pair proposals (proxima/robot/srdf_proposal.h): a hand-built
// robot whose reasons are known by construction, the Panda's proposal
// against cold per-pair queries on the same configurations (the slow
// path), the written SRDF read back by load_robot, and bad options refused.
// The Panda is read from ../shared/robots relative to the repository root;
// its tests skip when it is absent.
#include <gtest/gtest.h>
#include <proxima/robot/srdf_proposal.h>
#include <proxima/robot/urdf.h>
#include <proxima/shape/primitives.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

using proxima::DisableReason;
using proxima::Pose;
using proxima::Robot;
using proxima::Vec3;

const std::string kRobots = std::string(PROXIMA_SOURCE_DIR) + "/../shared/robots";
const std::string kPandaUrdf = kRobots + "/robots/panda_description/urdf/panda.urdf";

proxima::RobotLoadOptions packages() {
  proxima::RobotLoadOptions options;
  options.package_dirs = {"example-robot-data=" + kRobots};
  return options;
}

using Reasons = std::map<std::pair<std::string, std::string>, DisableReason>;

Reasons by_name(const Robot& robot, const proxima::SrdfProposal& proposal) {
  Reasons out;
  for (const proxima::DisabledLinkPair& p : proposal.pairs) {
    out[{robot.links()[static_cast<std::size_t>(p.link_a)].name,
         robot.links()[static_cast<std::size_t>(p.link_b)].name}] = p.reason;
  }
  return out;
}

// base carries a ball of radius 1 around its origin; arm turns about z at
// the origin and carries a small box at x = 0.5 (inside the ball); tip
// turns about z at arm's origin with a box at x = 0.3 (always inside the
// ball too); far is fixed 10 away with a small ball. So: base-arm and
// arm-tip and base-far are adjacent, base-tip overlap at the default
// configuration (and at every other), arm-far and tip-far are never within
// 1 of each other.
Robot hand_built() {
  proxima::RobotDescription d;
  d.name = "hand_built";
  d.links = {{"base"}, {"arm"}, {"tip"}, {"far"}};
  const auto joint = [](std::string name, proxima::JointType type, int parent, int child) {
    proxima::RobotJoint j;
    j.name = std::move(name);
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.lower = -3;
    j.upper = 3;
    return j;
  };
  d.joints.push_back(joint("j_arm", proxima::JointType::revolute, 0, 1));
  d.joints.push_back(joint("j_tip", proxima::JointType::revolute, 1, 2));
  d.joints.push_back(joint("j_far", proxima::JointType::fixed, 0, 3));
  d.joints.back().origin = Pose(proxima::Mat3::Identity(), Vec3(10, 0, 0));
  const auto at = [](double x) { return Pose(proxima::Mat3::Identity(), Vec3(x, 0, 0)); };
  d.geometries.push_back({0, proxima::make_sphere(1.0), Pose{}, "ball"});
  d.geometries.push_back({1, proxima::make_box(Vec3(0.05, 0.05, 0.05)), at(0.5), "arm box"});
  d.geometries.push_back({2, proxima::make_box(Vec3(0.05, 0.05, 0.05)), at(0.3), "tip box"});
  d.geometries.push_back({3, proxima::make_sphere(0.1), Pose{}, "far ball"});
  return Robot(std::move(d));
}

TEST(SrdfProposal, HandBuiltRobotGetsTheReasonsItWasBuiltFor) {
  const Robot robot = hand_built();
  proxima::SrdfProposalOptions options;
  options.samples = 50;
  options.margin = 1.0;
  const proxima::SrdfProposal proposal = proxima::propose_disabled_pairs(robot, options);
  const Reasons want = {{{"base", "arm"}, DisableReason::adjacent},
                        {{"base", "tip"}, DisableReason::default_pose},
                        {{"base", "far"}, DisableReason::adjacent},
                        {{"arm", "tip"}, DisableReason::adjacent},
                        {{"arm", "far"}, DisableReason::never},
                        {{"tip", "far"}, DisableReason::never}};
  EXPECT_EQ(by_name(robot, proposal), want);
  EXPECT_EQ(proposal.link_pairs, 6);
  EXPECT_EQ(proposal.enabled, 0);
  EXPECT_EQ(proposal.samples, 50);
}

// Every link pair's reason from cold distance() on every geometry pair at
// the same configurations: the slow twin of propose_disabled_pairs.
Reasons slow_reasons(const Robot& robot, const proxima::RowMatrixXd& configurations,
                     double margin) {
  const auto& geometries = robot.geometries();
  const auto n_links = static_cast<std::int32_t>(robot.links().size());
  // Per link pair: within the margin somewhere, overlapping in how many.
  std::map<std::pair<int, int>, std::pair<bool, int>> seen;
  std::map<std::pair<int, int>, bool> at_default;
  const auto judge = [&](std::span<const double> q, bool is_default) {
    const std::vector<Pose> links = robot.forward_kinematics(q);
    std::map<std::pair<int, int>, bool> overlap_here;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
      for (std::size_t j = i + 1; j < geometries.size(); ++j) {
        const auto [la, lb] = std::minmax(geometries[i].link, geometries[j].link);
        if (la == lb) continue;
        const proxima::BodyResult r = proxima::distance(
            geometries[i].body, links[static_cast<std::size_t>(geometries[i].link)] * geometries[i].origin,
            geometries[j].body, links[static_cast<std::size_t>(geometries[j].link)] * geometries[j].origin);
        const bool overlap = r.status != proxima::Status::separated;
        if (is_default) {
          at_default[{la, lb}] = at_default[{la, lb}] || overlap;
          continue;
        }
        seen[{la, lb}].first = seen[{la, lb}].first || r.signed_distance() <= margin;
        overlap_here[{la, lb}] = overlap_here[{la, lb}] || overlap;
      }
    }
    for (const auto& [key, overlap] : overlap_here) seen[key].second += overlap ? 1 : 0;
  };
  std::vector<double> zero(static_cast<std::size_t>(robot.dof()));
  const Eigen::VectorXd lo = robot.lower_limits(), hi = robot.upper_limits();
  for (int v = 0; v < robot.dof(); ++v) zero[static_cast<std::size_t>(v)] = std::clamp(0.0, lo[v], hi[v]);
  judge(zero, true);
  for (Eigen::Index k = 0; k < configurations.rows(); ++k) {
    judge(std::span<const double>(configurations.row(k).data(), static_cast<std::size_t>(robot.dof())),
          false);
  }
  Reasons out;
  for (std::int32_t a = 0; a < n_links; ++a) {
    for (std::int32_t b = a + 1; b < n_links; ++b) {
      if (robot.link_geometries(a).empty() || robot.link_geometries(b).empty()) continue;
      const std::pair<std::string, std::string> names = {robot.links()[static_cast<std::size_t>(a)].name,
                                                         robot.links()[static_cast<std::size_t>(b)].name};
      const auto [within, overlapping] = seen[{a, b}];
      if (!robot.link_pair_enabled(a, b)) {
        out[names] = DisableReason::adjacent;
      } else if (at_default[{a, b}]) {
        out[names] = DisableReason::default_pose;
      } else if (overlapping == configurations.rows()) {
        out[names] = DisableReason::always;
      } else if (!within) {
        out[names] = DisableReason::never;
      }
    }
  }
  return out;
}

TEST(SrdfProposal, PandaProposalMatchesColdQueriesOnTheSameConfigurations) {
  if (!std::filesystem::exists(kPandaUrdf)) GTEST_SKIP() << kRobots << " absent";
  // Without its SRDF: only adjacent pairs are excluded, as the proposal judges.
  const Robot panda = proxima::load_robot(kPandaUrdf, "", packages());
  std::mt19937_64 rng(27);
  proxima::RowMatrixXd configurations(120, panda.dof());
  const Eigen::VectorXd lo = panda.lower_limits(), hi = panda.upper_limits();
  for (Eigen::Index k = 0; k < configurations.rows(); ++k) {
    for (int v = 0; v < panda.dof(); ++v) {
      configurations(k, v) = std::uniform_real_distribution<double>(lo[v], hi[v])(rng);
    }
  }
  for (const double margin : {0.0, 0.02}) {
    proxima::SrdfProposalOptions options;
    options.margin = margin;
    options.configurations = configurations;
    const proxima::SrdfProposal proposal = proxima::propose_disabled_pairs(panda, options);
    const Reasons got = by_name(panda, proposal);
    EXPECT_EQ(got, slow_reasons(panda, configurations, margin)) << "margin " << margin;
    // The set is not trivial: some pairs of each kind but "always".
    int never = 0, adjacent = 0;
    for (const auto& [names, reason] : got) {
      never += reason == DisableReason::never ? 1 : 0;
      adjacent += reason == DisableReason::adjacent ? 1 : 0;
    }
    EXPECT_GT(never, 0);
    EXPECT_GT(adjacent, 0);
    EXPECT_GT(proposal.enabled, 0);
  }
}

TEST(SrdfProposal, WrittenSrdfDisablesExactlyTheProposedPairs) {
  if (!std::filesystem::exists(kPandaUrdf)) GTEST_SKIP() << kRobots << " absent";
  const Robot panda = proxima::load_robot(kPandaUrdf, "", packages());
  proxima::SrdfProposalOptions options;
  options.samples = 200;
  options.margin = 0.01;
  const proxima::SrdfProposal proposal = proxima::propose_disabled_pairs(panda, options);
  const std::string path =
      (std::filesystem::temp_directory_path() / "proxima_srdf_proposal_test.srdf").string();
  {
    std::ofstream file(path);
    file << proxima::write_srdf(panda, proposal);
  }
  const Robot reloaded = proxima::load_robot(kPandaUrdf, path, packages());
  std::filesystem::remove(path);
  const Reasons disabled = by_name(panda, proposal);
  for (std::int32_t a = 0; a < static_cast<std::int32_t>(panda.links().size()); ++a) {
    for (std::int32_t b = a + 1; b < static_cast<std::int32_t>(panda.links().size()); ++b) {
      if (panda.link_geometries(a).empty() || panda.link_geometries(b).empty()) continue;
      const bool proposed = disabled.count({panda.links()[static_cast<std::size_t>(a)].name,
                                            panda.links()[static_cast<std::size_t>(b)].name}) > 0;
      EXPECT_EQ(reloaded.link_pair_enabled(a, b), !proposed)
          << panda.links()[static_cast<std::size_t>(a)].name << " "
          << panda.links()[static_cast<std::size_t>(b)].name;
    }
  }
}

TEST(SrdfProposal, BadOptionsAreRefusedNamingTheProblem) {
  const Robot robot = hand_built();
  const auto message = [&](const proxima::SrdfProposalOptions& options) {
    try {
      proxima::propose_disabled_pairs(robot, options);
    } catch (const proxima::InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  proxima::SrdfProposalOptions options;
  options.samples = 0;
  EXPECT_NE(message(options).find("options.samples must be at least 1 (without options.configurations), got 0"), std::string::npos) << message(options);
  options.samples = 10;
  options.margin = -1;
  EXPECT_NE(message(options).find("margin"), std::string::npos) << message(options);
  options.margin = std::nan("");
  EXPECT_NE(message(options).find("margin"), std::string::npos) << message(options);
  options.margin = 0;
  options.configurations = proxima::RowMatrixXd::Zero(3, 5);
  EXPECT_NE(message(options).find("5 columns"), std::string::npos) << message(options);
  options.configurations = proxima::RowMatrixXd::Zero(3, 2);
  options.configurations(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_NE(message(options).find("j_tip"), std::string::npos) << message(options);
}

}  // namespace
