// proxima test support: a test fixture with a fresh directory of its own, for
// tests that write files and read them back (io_test, compound_io_test).
// Test-only code.
// SPDX-License-Identifier: BSD-3-Clause
//
// The directory is named after the process, the suite and the test, so that
// tests run in parallel (ctest -j, one process per test) never share files,
// and it is removed with everything in it when the test ends.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace proxima::test {

class TempDirTest : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("proxima_" + std::string(info->test_suite_name()) + "_" + std::to_string(::getpid()) +
            "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;  // a failed clean-up must not fail the test
    std::filesystem::remove_all(dir_, ec);
  }

  // Writes `bytes` as they are (binary formats hold NULs) to `name` in the
  // directory; returns the file's path.
  std::string write(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
  }

  std::filesystem::path dir_;
};

}  // namespace proxima::test
