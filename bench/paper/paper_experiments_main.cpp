// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The `paper_experiments` benchmark executable
// (build/<preset>/bench/paper_experiments): the paper's
// experiments against the peers (FCL, libccd through FCL, Bullet), the job of
// `make run`.
//   paper_experiments [--quick [--full-robustness]] [--out DIR]
// Before issue 9 this was `proxima paper`; it moved out of the shipped CLI so
// that the installed `proxima` links none of the peers.
//
// Exit codes: 0 when every part ran and its files were written, 1 when a
// part failed or the files cannot be written, 2 for usage errors.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "paper/paper.h"

int main(int argc, char** argv) {
  CLI::App app{
      "paper_experiments: reproduce the paper's experiments (robustness, figures 1-3, cold "
      "queries) for "
      "proxima, FCL and Bullet; tables on the terminal, CSV files and PNG plots in --out"};
  proxima::bench::PaperOptions options;
  app.add_flag("--quick", options.quick, "Reduced run, under a minute");
  app.add_flag(
      "--full-robustness", options.full_robustness,
      "With --quick: the robustness experiments on the full run's cases (half a minute more)");
  app.add_option("--out", options.out_dir, "Directory for the CSV files and plots")
      ->capture_default_str();
  app.footer("Example:\n  build/release/bench/paper_experiments --quick --out paper-out");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return proxima::bench::run_paper(options, std::cout) == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "paper_experiments: " << e.what() << "\n";
    return 1;
  }
}
