// proxima: smoke test of the paper experiments (bench/paper_experiments --quick,
// issue 4), run in-process.
// SPDX-License-Identifier: BSD-3-Clause
//
// It runs the whole quick mode (robustness against the exact reference, the
// three timing parts, the files) and checks what the run promises: every CSV
// file is there with the rows of every system, proxima's three algorithms
// are 100% within the accuracy standard on both robustness experiments, no
// system crashed or hung in a way that killed the run, and the mean
// distances of all systems agree in every timing part (a peer adapter that
// answers another problem, e.g. a wrong frame or a forgotten margin, prints
// a WARNING; Bullet's default 0.04 margin was caught that way). Timing
// figures are not asserted: they are benchmarks, not tests.
#include <gtest/gtest.h>
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
    "proxima hybrid", "proxima Enhanced GJK", "proxima GJK", "FCL libccd", "FCL GJK", "Bullet GJK"};

// One test, one run: ctest runs each discovered test in its own process, so
// a fixture shared by several tests would run the quick mode once per test.
TEST(PaperSmoke, QuickRunWritesItsFilesAndProximaMeetsTheStandard) {
  const fs::path dir =
      fs::temp_directory_path() / ("proxima_paper_smoke_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  proxima::bench::PaperOptions options;
  options.quick = true;
  options.out_dir = dir.string();
  std::ostringstream log;
  const int rc = proxima::bench::run_paper(options, log);
  EXPECT_EQ(rc, 0) << log.str();

  {
    SCOPED_TRACE("every file");
    for (const char* name :
         {"robustness.csv", "robustness_failures.csv", "translation.csv", "rotation.csv",
          "cold.csv", "targets.csv", "tracking_modes.csv", "run.csv"}) {
      EXPECT_TRUE(fs::exists(dir / name)) << name;
      EXPECT_FALSE(read_csv(dir / name).empty() && std::string(name) != "robustness_failures.csv")
          << name;
    }
  }
  {
    SCOPED_TRACE("robustness: proxima 100% within the standard, every system on both experiments");
    std::map<std::string, std::set<std::string>> systems_per_experiment;
    for (const auto& row : read_csv(dir / "robustness.csv")) {
      systems_per_experiment[row.at("experiment")].insert(row.at("system"));
      const int cases = std::stoi(row.at("cases"));
      EXPECT_GT(cases, 0) << row.at("experiment") << " " << row.at("system");
      if (row.at("system").rfind("proxima", 0) == 0) {
        EXPECT_EQ(std::stoi(row.at("within_standard")), cases)
            << row.at("experiment") << " " << row.at("system");
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
  fs::remove_all(dir);
}

}  // namespace
