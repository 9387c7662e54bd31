// `proxima robot` (cli/robot.cpp): the Panda from its URDF answering JSON
// Lines of configurations, the same answers as robot_distances() in C++,
// and bad lines answered with errors naming the problem while the run goes
// on. Skips when ../shared/robots (from the repository root) is absent.
#include <gtest/gtest.h>
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/srdf_proposal.h>
#include <proxima/robot/urdf.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_cli.h"

namespace {

using proxima::test::run_cli;
using proxima::test::shell_quote;
using proxima::test::TempPath;
using Json = nlohmann::json;

const std::string kRobots = std::string(PROXIMA_SOURCE_DIR) + "/../shared/robots";
const std::string kUrdf = kRobots + "/robots/panda_description/urdf/panda.urdf";
const std::string kSrdf = kRobots + "/robots/panda_description/srdf/panda.srdf";

std::vector<Json> answers(const std::string& out) {
  std::vector<Json> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) lines.push_back(Json::parse(line));
  return lines;
}

TEST(CliRobot, AnswersConfigurationsAsTheLibraryDoesAndBadLinesWithErrors) {
  if (!std::filesystem::exists(kUrdf)) GTEST_SKIP() << kRobots << " absent";
  const TempPath input(".jsonl");
  const std::vector<double> ready = {0, -0.785, 0, -2.356, 0, 1.571, 0.785, 0.01};
  {
    std::ofstream file(input.path());
    file << Json{{"id", 1}, {"q", ready}}.dump() << "\n";
    file << R"({"id": "short", "q": [0, 0]})"
         << "\n";
    file << "{not json\n";
    file << R"({"id": 4, "q": {"panda_joint1": 0}})"
         << "\n";
    file << R"({"id": 5, "q": [0, 0, 0, -0.1, 0, 0, 0, "x"]})"
         << "\n";
    file << Json{{"id", 6}, {"q", ready}}.dump() << "\n";
  }
  const proxima::test::CliRun run =
      run_cli("robot " + shell_quote(input.path()) + " --urdf " + shell_quote(kUrdf) + " --srdf " +
              shell_quote(kSrdf) + " --package-dir " +
              shell_quote("example-robot-data=" + kRobots) + " --margin 0.05 --gradients");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<Json> lines = answers(run.out);
  ASSERT_EQ(lines.size(), 6u);

  proxima::RobotLoadOptions options;
  options.package_dirs = {"example-robot-data=" + kRobots};
  const proxima::Robot robot = proxima::load_robot(kUrdf, kSrdf, options);
  proxima::RobotQueryOptions query;
  query.margin = 0.05;
  query.gradients = true;
  const proxima::RobotDistances expected = proxima::robot_distances(robot, ready, {}, query);
  for (const Json& answer : {lines[0], lines[5]}) {
    EXPECT_NEAR(answer["min_signed_distance"].get<double>(), expected.min_signed_distance, 1e-12);
    EXPECT_EQ(answer["pairs"].size(), expected.close_pairs.size());
    const std::vector<double> gradient = answer["gradient"].get<std::vector<double>>();
    ASSERT_EQ(gradient.size(), 8u);
    for (int v = 0; v < 8; ++v) EXPECT_NEAR(gradient[v], expected.closest.gradient[v], 1e-12);
  }
  EXPECT_EQ(lines[1]["id"], "short");
  EXPECT_NE(lines[1]["error"].get<std::string>().find("line 2: q has 2 entries"),
            std::string::npos);
  EXPECT_NE(lines[2]["error"].get<std::string>().find("line 3: not valid JSON"), std::string::npos);
  EXPECT_NE(lines[3]["error"].get<std::string>().find("panda_joint2"), std::string::npos);
  EXPECT_NE(lines[4]["error"].get<std::string>().find("q[7]"), std::string::npos);
}

TEST(CliRobot, AnUnreadableRobotIsAnErrorNamingTheFile) {
  const proxima::test::CliRun run =
      run_cli("robot --urdf /nonexistent/robot.urdf < /dev/null", true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("/nonexistent/robot.urdf"), std::string::npos) << run.out;
}

}  // namespace

namespace {

// `proxima robot-srdf` (cli/robot_srdf.cpp) on the Panda shipped with the
// examples: the SRDF it writes is the library's proposal for the same
// options, load_robot reads it back, and a bad option or URDF is an error
// naming it.
TEST(CliRobotSrdf, WritesTheLibrarysProposalAsAnSrdfThatLoads) {
  const std::string urdf = std::string(PROXIMA_SOURCE_DIR) + "/examples/data/panda/panda.urdf";
  const TempPath srdf(".srdf");
  const proxima::test::CliRun run =
      run_cli("robot-srdf --urdf " + shell_quote(urdf) + " --samples 100 --margin 0.01 --seed 3 -o " +
                  shell_quote(srdf.path()),
              true);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("link pairs disabled"), std::string::npos) << run.out;

  const proxima::Robot robot = proxima::load_robot(urdf);
  proxima::SrdfProposalOptions options;
  options.samples = 100;
  options.margin = 0.01;
  options.seed = 3;
  const proxima::SrdfProposal proposal = proxima::propose_disabled_pairs(robot, options);
  std::ifstream file(srdf.path());
  const std::string written((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, proxima::write_srdf(robot, proposal));
  const proxima::Robot reloaded = proxima::load_robot(urdf, srdf.path());
  EXPECT_LT(reloaded.self_pairs().size(), robot.self_pairs().size());

  const proxima::test::CliRun bad = run_cli("robot-srdf --urdf /nonexistent.urdf", true);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.out.find("nonexistent.urdf"), std::string::npos) << bad.out;
  const proxima::test::CliRun no_samples =
      run_cli("robot-srdf --urdf " + shell_quote(urdf) + " --samples 0", true);
  EXPECT_EQ(no_samples.exit_code, 2) << no_samples.out;
}

}  // namespace
