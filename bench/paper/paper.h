// proxima: the paper's experiments, reproduced and measured against the peers
// in one run (issue 4).
// SPDX-License-Identifier: BSD-3-Clause
//
//   1. Robustness (paper section 6, experiments 1 and 2): two tetrahedra of
//      edge 1e-23 placed 2e-22 apart, and cubes of edge 2000 and 1e-15
//      scaled by 1e39 placed 1e-10 x 1e39 apart, under 100 orientations and
//      100 rotational velocities. Every system's answer is judged against an
//      exact reference (the closed-form kernels on exact rationals, brute
//      force over all feature pairs, certified) by the accuracy standard of
//      DESIGN.md. Each system runs in a child process, so a crash or a hang
//      is counted, not fatal.
//   2. Timing, the paper's figures 1 and 2: random polytopes of N = 8 ...
//      4096 vertices on a sphere, one fixed, the other translated through
//      10^4 small steps, with and without tracking.
//   3. Timing, the paper's figure 3: bodies of 50 points, one rotated through
//      10^4 steps at 0.001 ... 0.5 rad per step.
//   4. Cold queries: random poses, no coherence, N = 8 ... 4096.
//   5. The signed distance through contact (issue 10): B sweeps through A
//      and out, overlapping on about three quarters of 3,000 steps;
//      proxima tracked and cold, FCL's libccd and Bullet's EPA, N = 8 ...
//      4096.
// Timings are the median over at least 5 repetitions of the whole sequence,
// setup excluded, all systems on the same polytopes and poses, repetitions
// interleaved between systems so that machine noise falls on all of them.
//
// Writes CSV files and (through scripts/plot_paper.py and Debian's
// /usr/bin/python3 with matplotlib) PNG plots into options.out_dir.
#pragma once

#include <ostream>
#include <string>

namespace proxima::bench {

struct PaperOptions {
  // A reduced run (fewer cases, sizes and steps) that finishes in well under
  // a minute on 2 cores: the smoke test and a quick look.
  bool quick = false;
  // With quick: the robustness experiments on the full run's case set all
  // the same (2 x 1,100 cases, about half a minute in release), so that a
  // check of the quick run sees every case the full run judges.
  bool full_robustness = false;
  std::string out_dir = "out";
};

// Runs the five parts, prints tables and progress to `out`. Returns 0 when
// every part ran and its files were written, 1 otherwise (a missed timing
// target is reported, not an error; a missing plotting interpreter is a
// warning).
int run_paper(const PaperOptions& options, std::ostream& out);

}  // namespace proxima::bench
