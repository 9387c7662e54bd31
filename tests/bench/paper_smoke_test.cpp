// proxima: smoke test of the paper experiments (bench/paper_experiments --quick,
// issue 4), run in-process.
// SPDX-License-Identifier: BSD-3-Clause
//
// It runs the whole quick mode (the three timing parts and the files) with
// the robustness experiments on the FULL run's case set (2 x 1,100 cases
// against the exact reference, about 25 s in release), so that it expects
// what the full run gets: before issue 9 it judged the quick run's 60
// cases, where Enhanced GJK and GJK were 100% within the standard, while
// the full run found them off on 2 of experiment 1's 1,100 cases (distance
// 9.5e-11 relative off at edge 1e-23) and the test said nothing. Under the
// sanitizers (10x slower) it judges the quick subset of the same cases.
// It checks what the run promises: every CSV file is there with the rows of
// every system, proxima's hybrid (the paper's algorithm) is 100% within the
// accuracy standard on both robustness experiments, its GJK baselines on all
// but the known cases, no proxima system crashed, hung or gave NaN, and the
// mean distances of all systems agree in every timing part (a peer adapter
// that answers another problem, e.g. a wrong frame or a forgotten margin,
// prints a WARNING; Bullet's default 0.04 margin was caught that way).
// Timing figures are not asserted: they are benchmarks, not tests.
#include <gtest/gtest.h>
#include "support/sanitizers.h"
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "paper/paper.h"

namespace {

namespace fs = std::filesystem;

// Splits one CSV line of the files run_paper writes (robustness.csv and the
// timing files have no quoted fields).
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string field;
  while (std::getline(s, field, ',')) out.push_back(field);
  return out;
}

// Rows of a CSV file as maps from the header's names.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path) {
  std::ifstream f(path);
  std::string line;
  std::vector<std::map<std::string, std::string>> rows;
  if (!std::getline(f, line)) return rows;
  const std::vector<std::string> header = split(line);
  while (std::getline(f, line)) {
    const std::vector<std::string> fields = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < fields.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

const std::set<std::string> kSystems = {
    "proxima hybrid",    "proxima Enhanced GJK", "proxima GJK", "FCL libccd",
    "FCL libccd scaled", "proxima GJK",          "FCL GJK",     "Bullet GJK"};

// One test, one run: ctest runs each discovered test in its own process, so
// a fixture shared by several tests would run the quick mode once per test.
TEST(PaperSmoke, QuickRunWritesItsFilesAndProximaMeetsTheStandard) {
  const fs::path dir =
      fs::temp_directory_path() / ("proxima_paper_smoke_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  proxima::bench::PaperOptions options;
  options.quick = true;
  options.full_robustness = !proxima::test::kUnderSanitizers;
  options.out_dir = dir.string();
  std::ostringstream log;
  const int rc = proxima::bench::run_paper(options, log);
  EXPECT_EQ(rc, 0) << log.str();

  {
    SCOPED_TRACE("every file");
    for (const char* name :
         {"robustness.csv", "robustness_failures.csv", "translation.csv", "rotation.csv",
          "cold.csv", "overlap.csv", "targets.csv", "tracking_modes.csv", "run.csv"}) {
      EXPECT_TRUE(fs::exists(dir / name)) << name;
      EXPECT_FALSE(read_csv(dir / name).empty() && std::string(name) != "robustness_failures.csv")
          << name;
    }
  }
  {
    SCOPED_TRACE("robustness: proxima within the standard, every system on both experiments");
    std::map<std::string, std::set<std::string>> systems_per_experiment;
    for (const auto& row : read_csv(dir / "robustness.csv")) {
      systems_per_experiment[row.at("experiment")].insert(row.at("system"));
      const int cases = std::stoi(row.at("cases"));
      EXPECT_GT(cases, 0) << row.at("experiment") << " " << row.at("system");
      // The full run's case set: 100 orientations + 100 rotation runs x 10 steps.
      if (options.full_robustness) {
        EXPECT_EQ(cases, 1100) << row.at("experiment");
      }
      const std::string& system = row.at("system");
      if (system.rfind("proxima", 0) == 0) {
        const int within = std::stoi(row.at("within_standard"));
        // The full run's figures at HEAD of issue 9: the hybrid 100% on
        // both; Enhanced GJK and GJK 100% on experiment 2 and 1,093 of
        // 1,100 on experiment 1 (since the exact incremental hulls: 6 or 7
        // cases of distance 2e-22 between edges of 1e-23, relative errors
        // 1.2e-12 to 9.5e-11 against the standard's 1e-12, 7 since B's
        // relative pose is formed as R_a^T (t_b - t_a); 2 cases on the
        // Qhull-built hulls before). The baselines' gap, not the hybrid's.
        const int known_gjk_misses =
            system != "proxima hybrid" && row.at("experiment") == "experiment 1" ? 7 : 0;
        EXPECT_GE(within, cases - known_gjk_misses) << row.at("experiment") << " " << system;
        EXPECT_EQ(std::stoi(row.at("crash")) + std::stoi(row.at("hang")) + std::stoi(row.at("nan")),
                  0);
      }
    }
    ASSERT_EQ(systems_per_experiment.size(), 2u);
    for (const auto& [experiment, systems] : systems_per_experiment)
      EXPECT_EQ(systems, kSystems) << experiment;
    // Every case had a certified exact reference (otherwise the run says so).
    EXPECT_EQ(log.str().find("no certified exact reference"), std::string::npos) << log.str();
  }
  {
    SCOPED_TRACE("timing: every system, at least 5 repetitions, all answering the same problem");
    for (const char* name : {"translation.csv", "rotation.csv", "cold.csv"}) {
      std::set<std::string> systems;
      for (const auto& row : read_csv(dir / name)) {
        systems.insert(row.at("system"));
        EXPECT_GT(std::stod(row.at("median_ns")), 0.0) << name << " " << row.at("system");
        EXPECT_GE(std::stoi(row.at("repetitions")), 5) << name;
      }
      EXPECT_EQ(systems, kSystems) << name;
    }
    EXPECT_EQ(log.str().find("WARNING"), std::string::npos) << log.str();
  }
  {
    SCOPED_TRACE("overlap sweep: the signed distance, proxima tracked and cold and both peers");
    std::set<std::pair<std::string, bool>> configurations;
    for (const auto& row : read_csv(dir / "overlap.csv")) {
      configurations.insert({row.at("system"), row.at("tracking") == "1"});
      EXPECT_GT(std::stod(row.at("median_ns")), 0.0) << row.at("system");
      EXPECT_GE(std::stoi(row.at("repetitions")), 5);
      // B overlaps A on most of the sweep (about three quarters of it from
      // N = 64; 8 points span a smaller hull): a system that answered the
      // distance (0 when overlapping) instead would have a mean >= 0.
      EXPECT_LT(std::stod(row.at("mean_distance")), 0.0)
          << row.at("system") << " N " << row.at("n");
    }
    const std::set<std::pair<std::string, bool>> expected = {{"proxima hybrid", true},
                                                             {"proxima hybrid", false},
                                                             {"FCL libccd signed", false},
                                                             {"Bullet GJK", false}};
    EXPECT_EQ(configurations, expected);
    EXPECT_NE(log.str().find("tracked flat in N"), std::string::npos) << log.str();
  }
  fs::remove_all(dir);
}

}  // namespace
