// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Tests of the `scene_demo` benchmark executable (bench/paper; it was
// `proxima scene-demo` before issue 9 moved it out of the shipped CLI), run
// as a user runs it: the built binary through a shell. Its rows must parse, and their pair counts
// must be those of the same seeded scene run in-process through proxima::Scene and its all-pairs
// twin; bad options exit 2, bad values 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "paper/scene_scenario.h"
#include "proxima/scene/scene.h"
#include "support/run_cli.h"

namespace {

using proxima::test::CliRun;
using proxima::test::run_cli;

struct Row {
  int step = -1;
  int candidates = -1;
  int close = -1;
  int intersecting = -1;
  int queries = -1;
  double ms = -1;
};

struct DemoOutput {
  std::string header;
  std::vector<Row> rows;
  std::string summary;
};

// Splits the demo's standard output into its header, rows and summary; a
// line that is none of them fails the test.
DemoOutput parse_demo(const std::string& text) {
  DemoOutput d;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("scene_demo:", 0) == 0) {
      d.header = line;
    } else if (line.rfind("summary:", 0) == 0) {
      d.summary = line;
    } else if (line.find("step  candidates") != std::string::npos) {
      continue;  // column titles
    } else {
      std::istringstream fields(line);
      Row r;
      std::string rest;
      fields >> r.step >> r.candidates >> r.close >> r.intersecting >> r.queries >> r.ms;
      EXPECT_TRUE(static_cast<bool>(fields)) << "unparsable row: '" << line << "'";
      EXPECT_FALSE(fields >> rest) << "extra columns: '" << line << "'";
      d.rows.push_back(r);
    }
  }
  return d;
}

// The demo's scene run in-process: close and intersecting pairs per step
// (scene_test checks Scene against its all-pairs twin).
std::map<int, std::array<int, 2>> library_counts(int bodies, int steps, double margin, int seed) {
  proxima::bench::SceneScenarioOptions so;
  so.bodies = bodies;
  so.seed = static_cast<std::uint64_t>(seed);
  so.margin = margin;
  const proxima::bench::SceneScenario scenario(so);
  proxima::SceneOptions options;
  options.margin = margin;
  proxima::Scene scene(options);
  std::vector<proxima::Pose> poses = scenario.step(0);
  std::vector<proxima::BodyId> ids;
  for (int i = 0; i < bodies; ++i)
    ids.push_back(scene.add(scenario.body_shape(i), poses[static_cast<std::size_t>(i)]));
  std::map<int, std::array<int, 2>> counts;
  for (int k = 0; k < steps; ++k) {
    scenario.step(k, poses);
    for (std::size_t i = 0; i < ids.size(); ++i) scene.set_pose(ids[i], poses[i]);
    const auto pairs = scene.step();
    const auto intersecting =
        std::count_if(pairs.begin(), pairs.end(), [](const proxima::ClosePair& p) {
          return p.result.status == proxima::Status::intersecting;
        });
    counts[k] = {static_cast<int>(pairs.size()), static_cast<int>(intersecting)};
  }
  return counts;
}

TEST(CliSceneDemo, RowsParseAndMatchTheLibrary) {
  REQUIRE_CLI();
  const CliRun run = run_cli("--bodies 60 --steps 13 --every 4 --margin 0.2 --seed 3");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const DemoOutput d = parse_demo(run.out);
  EXPECT_NE(d.header.find("60 bodies"), std::string::npos) << d.header;
  EXPECT_NE(d.header.find("margin 0.2"), std::string::npos) << d.header;
  // A row every 4 steps and one for the last step.
  std::vector<int> steps;
  for (const Row& r : d.rows) steps.push_back(r.step);
  EXPECT_EQ(steps, (std::vector<int>{0, 4, 8, 12}));
  const auto expected = library_counts(60, 13, 0.2, 3);
  int close_seen = 0;
  for (const Row& r : d.rows) {
    EXPECT_EQ(r.close, expected.at(r.step)[0]) << "step " << r.step;
    EXPECT_EQ(r.intersecting, expected.at(r.step)[1]) << "step " << r.step;
    EXPECT_GE(r.candidates, r.close);
    EXPECT_EQ(r.queries, r.candidates);  // convex bodies: one query per candidate pair
    EXPECT_GE(r.ms, 0.0);
    close_seen += r.close;
  }
  EXPECT_GT(close_seen, 0);  // the scene is dense enough to have close pairs
  double median = -1;
  double p90 = -1;
  ASSERT_EQ(std::sscanf(d.summary.c_str(), "summary: 13 steps, median %lf ms/step, p90 %lf",
                        &median, &p90),
            2)
      << d.summary;
  EXPECT_GE(median, 0.0);
  EXPECT_GE(p90, median);
  EXPECT_NE(d.summary.find("queries/s"), std::string::npos);
}

// The narrow phase on two threads gives the same pairs (its answers are
// bit-identical whatever the thread count); only the times differ.
TEST(CliSceneDemo, TwoThreadsSameCounts) {
  REQUIRE_CLI();
  const std::string args = "--bodies 50 --steps 6 --every 1 --seed 9";
  const DemoOutput one = parse_demo(run_cli(args + " --threads 1").out);
  const DemoOutput two = parse_demo(run_cli(args + " --threads 2").out);
  ASSERT_EQ(one.rows.size(), 6u);
  ASSERT_EQ(two.rows.size(), one.rows.size());
  for (std::size_t i = 0; i < one.rows.size(); ++i) {
    EXPECT_EQ(one.rows[i].candidates, two.rows[i].candidates);
    EXPECT_EQ(one.rows[i].close, two.rows[i].close);
    EXPECT_EQ(one.rows[i].intersecting, two.rows[i].intersecting);
  }
}

TEST(CliSceneDemo, BadValuesExitOneUsageErrorsExitTwo) {
  REQUIRE_CLI();
  for (const char* margin : {"-0.5", "nan", "inf"}) {
    const CliRun run = run_cli(std::string("--bodies 10 --steps 2 --margin ") + margin, true);
    EXPECT_EQ(run.exit_code, 1) << margin << ": " << run.out;
    EXPECT_NE(run.out.find("--margin"), std::string::npos) << run.out;
  }
  for (const char* args : {"--bodies 0", "--bodies many", "--steps 0", "--threads -1", "--every -2",
                           "--no-such-option", "--margin"}) {
    const CliRun run = run_cli(std::string("--steps 2 ") + args, true);
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.out;
  }
}

TEST(CliSceneDemo, HelpShowsAnExample) {
  REQUIRE_CLI();
  const CliRun run = run_cli("--help");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("Example:"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("bench/scene_demo --bodies"), std::string::npos) << run.out;
}

}  // namespace
