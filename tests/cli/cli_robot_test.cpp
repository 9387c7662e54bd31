// `proxima robot` (cli/robot.cpp): the Panda from its URDF answering JSON
// Lines of configurations, the same answers as robot_distances() in C++,
// and bad lines answered with errors naming the problem while the run goes
// on. Skips when ../shared/robots (from the repository root) is absent.
#include <gtest/gtest.h>
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/srdf_proposal.h>
#include <proxima/robot/urdf.h>
#include <proxima/shape/primitives.h>

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
using proxima::Pose;

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

// The UR5 and Talos (package:/// URIs with three slashes) load from the
// command line as the Panda does, and answer a configuration.
TEST(CliRobot, Ur5AndTalosAnswerFromTheirUrdf) {
  if (!std::filesystem::exists(kUrdf)) GTEST_SKIP() << kRobots << " absent";
  struct Case {
    std::string urdf, srdf;
    std::size_t dof;
  };
  const Case cases[] = {
      {kRobots + "/robots/ur_description/urdf/ur5_robot.urdf",
       kRobots + "/robots/ur_description/srdf/ur5.srdf", 6},
      {kRobots + "/robots/talos_data/robots/talos_full_v2.urdf",
       kRobots + "/robots/talos_data/srdf/talos.srdf", 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.urdf);
    proxima::RobotLoadOptions options;
    options.package_dirs = {"example-robot-data=" + kRobots};
    const proxima::Robot robot = proxima::load_robot(c.urdf, c.srdf, options);
    if (c.dof != 0) {
      EXPECT_EQ(static_cast<std::size_t>(robot.dof()), c.dof);
    }
    const std::vector<double> q(static_cast<std::size_t>(robot.dof()), 0.0);
    const TempPath input(".jsonl");
    {
      std::ofstream file(input.path());
      file << Json{{"id", 1}, {"q", q}}.dump() << "\n";
    }
    const proxima::test::CliRun run =
        run_cli("robot " + shell_quote(input.path()) + " --urdf " + shell_quote(c.urdf) +
                " --srdf " + shell_quote(c.srdf) + " --package-dir " +
                shell_quote("example-robot-data=" + kRobots));
    ASSERT_EQ(run.exit_code, 0) << run.out;
    const std::vector<Json> lines = answers(run.out);
    ASSERT_EQ(lines.size(), 1u) << run.out;
    const proxima::RobotDistances expected = proxima::robot_distances(robot, q, {});
    EXPECT_EQ(lines[0].at("min_signed_distance").get<double>(), expected.min_signed_distance)
        << run.out;
  }
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

namespace {

std::string page_data(const std::string& page) {
  const std::string open = "<script id=\"proxima-data\" type=\"application/json\">";
  const std::size_t begin = page.find(open);
  if (begin == std::string::npos) return "";
  const std::size_t end = page.find("</script>", begin);
  return page.substr(begin + open.size(), end - begin - open.size());
}

// `proxima robot --environment --view` on the Panda shipped with the
// examples: the answers are robot_distances' with the same obstacles, the
// page draws every geometry and obstacle and exactly the close pairs (none
// of them between excluded links), and a bad obstacle line is an error
// naming the file, the line and the key.
TEST(CliRobot, EnvironmentObstaclesAndTheViewPage) {
  const std::string dir = std::string(PROXIMA_SOURCE_DIR) + "/examples/data/panda";
  const TempPath environment(".jsonl"), input(".jsonl"), page(".html");
  {
    std::ofstream file(environment.path());
    file << R"({"name": "table", "vertices": [[-0.3,-0.6,-0.041],[0.9,-0.6,-0.041],[0.9,0.6,-0.041],[-0.3,0.6,-0.041],[-0.3,-0.6,-0.001],[0.9,-0.6,-0.001],[0.9,0.6,-0.001],[-0.3,0.6,-0.001]]})"
         << "\n";
    file << R"({"name": "ball", "vertices": [[0,0,0]], "radius": 0.1, "translation": [0.5, 0, 0.5]})"
         << "\n";
  }
  const std::vector<double> ready = {0, -0.785, 0, -2.356, 0, 1.571, 0.785, 0.01};
  {
    std::ofstream file(input.path());
    file << Json{{"id", 1}, {"q", ready}}.dump() << "\n";
  }
  const std::string robot_args = " --urdf " + shell_quote(dir + "/panda.urdf") + " --srdf " +
                                 shell_quote(dir + "/panda.srdf") + " --margin 0.3";
  const proxima::test::CliRun run =
      run_cli("robot " + shell_quote(input.path()) + robot_args + " --environment " +
              shell_quote(environment.path()) + " --view " + shell_quote(page.path()));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<Json> lines = answers(run.out);
  ASSERT_EQ(lines.size(), 1u);

  const proxima::Robot robot = proxima::load_robot(dir + "/panda.urdf", dir + "/panda.srdf");
  std::vector<proxima::Vec3> table_corners;
  for (const double x : {-0.3, 0.9})
    for (const double y : {-0.6, 0.6})
      for (const double z : {-0.041, -0.001}) table_corners.emplace_back(x, y, z);
  std::vector<proxima::Obstacle> obstacles;
  obstacles.emplace_back(
      proxima::Body(std::make_shared<const proxima::ConvexPolytope>(table_corners)), Pose{}, "table");
  obstacles.emplace_back(proxima::make_sphere(0.1),
                         Pose(proxima::Mat3::Identity(), proxima::Vec3(0.5, 0, 0.5)), "ball");
  proxima::RobotQueryOptions options;
  options.margin = 0.3;
  const proxima::RobotDistances r = proxima::robot_distances(robot, ready, obstacles, options);
  EXPECT_NEAR(lines[0]["min_signed_distance"].get<double>(), r.min_signed_distance, 1e-12);
  ASSERT_EQ(lines[0]["pairs"].size(), r.close_pairs.size());
  int environment_pairs = 0;
  for (const Json& pair : lines[0]["pairs"]) {
    if (!pair.contains("link_b")) {
      ++environment_pairs;
      EXPECT_TRUE(pair["b"] == "table" || pair["b"] == "ball") << pair.dump();
    }
  }
  EXPECT_GT(environment_pairs, 0);

  std::ifstream file(page.path());
  const std::string html((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const Json data = Json::parse(page_data(html));
  const std::size_t n_geometries = robot.geometries().size();
  EXPECT_EQ(data["bodies"].size(), n_geometries + 2);
  ASSERT_EQ(data["pairs"].size(), r.close_pairs.size());
  for (const Json& pair : data["pairs"]) {
    const int a = pair["a"].get<int>(), b = pair["b"].get<int>();
    if (static_cast<std::size_t>(b) >= n_geometries) continue;  // an obstacle
    EXPECT_TRUE(robot.link_pair_enabled(robot.geometries()[static_cast<std::size_t>(a)].link,
                                        robot.geometries()[static_cast<std::size_t>(b)].link))
        << pair.dump();
  }

  {
    std::ofstream bad(environment.path());
    bad << R"({"vertices": [[0,0,0]], "radius": 0.1, "pose": [1, 0, 0]})"
        << "\n";
  }
  const proxima::test::CliRun misspelt = run_cli(
      "robot " + shell_quote(input.path()) + robot_args + " --environment " +
          shell_quote(environment.path()),
      true);
  EXPECT_EQ(misspelt.exit_code, 1);
  EXPECT_NE(misspelt.out.find("line 1: unknown key \"pose\""), std::string::npos) << misspelt.out;
}

}  // namespace
