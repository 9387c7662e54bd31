// proxima test support: run the built `proxima` binary as a user runs it
// (through a shell), capture its standard output and exit code, and give it
// temporary files. Shared by the CLI tests (cli_query_test, cli_tools_test,
// cli_scene_test). Test-only code.
// SPDX-License-Identifier: BSD-3-Clause
//
// The binary's path comes from the test target's PROXIMA_CLI_PATH
// definition (tests/CMakeLists.txt); without it the tests skip through
// REQUIRE_CLI() instead of failing, so a build without the CLI still passes.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace proxima::test {

#ifdef PROXIMA_CLI_PATH
inline constexpr const char* kCliPath = PROXIMA_CLI_PATH;
#else
inline constexpr const char* kCliPath = nullptr;
#endif

// Quotes `s` for the POSIX shell: a path with spaces or quotes stays one word.
inline std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct CliRun {
  int exit_code = -1;  // -1 when the process did not exit normally
  std::string out;     // standard output; standard error goes to the test log
};

// Runs `proxima <args>` through the shell (so args may redirect standard
// input or output); standard error is captured with standard output when
// `with_stderr`.
inline CliRun run_cli(const std::string& args, bool with_stderr = false) {
  CliRun run;
  const std::string command = shell_quote(kCliPath) + " " + args + (with_stderr ? " 2>&1" : "");
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "popen failed: " << command;
    return run;
  }
  std::array<char, 4096> buffer;
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// A path in the temp directory with the given extension (readers pick the
// format by it), removed when the test is done with it. The process id keeps
// tests that run in parallel apart.
class TempPath {
 public:
  explicit TempPath(const std::string& extension) {
    static int counter = 0;
    path_ =
        (std::filesystem::temp_directory_path() / ("proxima_cli_test_" + std::to_string(getpid()) +
                                                   "_" + std::to_string(counter++) + extension))
            .string();
  }
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;
  ~TempPath() { std::filesystem::remove(path_); }
  const std::string& path() const { return path_; }
  std::string quoted() const { return shell_quote(path_); }

 private:
  std::string path_;
};

// A temporary file holding `contents` (JSON Lines unless said otherwise).
class TempFile : public TempPath {
 public:
  explicit TempFile(const std::string& contents, const std::string& extension = ".jsonl")
      : TempPath(extension) {
    std::ofstream(path(), std::ios::binary) << contents;
  }
};

}  // namespace proxima::test

// Skips the test when the binary was not built (no PROXIMA_CLI_PATH).
#define REQUIRE_CLI()                                                                  \
  do {                                                                                 \
    if (::proxima::test::kCliPath == nullptr) GTEST_SKIP() << "built without the CLI"; \
  } while (false)
