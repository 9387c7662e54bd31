// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima distance` and `proxima hull`, the commands that work on
// mesh files (read through proxima_io, include/proxima/io.h). main.cpp parses
// the arguments; these run the commands and return the exit code.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "proxima/io.h"
#include "proxima/core/types.h"

namespace proxima::cli {

struct DistanceCommand {
  std::string file_a;
  std::string file_b;
  // Seven tokens each, x y z and the quaternion in `quaternion_order`
  // (qw qx qy qz by default), as typed (parsed by the command so that a bad
  // number is bad input, exit 1, not a usage error).
  std::vector<std::string> pose_a;
  std::vector<std::string> pose_b;
  QuaternionOrder quaternion_order = QuaternionOrder::wxyz;
  DistanceOptions options;
  bool json = false;
  std::uint64_t max_file_bytes = kDefaultMaxFileBytes;  // per input file (ReadOptions)
  // How each file becomes a body: "mesh", "hull", "pieces", or "" for the
  // default: the hull of a convex file or of a point cloud (no faces); a
  // non-convex file with faces must be named (an error says so).
  std::string as_a;
  std::string as_b;
};

// Loads both files, runs one cold query, prints a table or one JSON object
// to `out`. Problems with the input (unreadable file, bad pose numbers) go to
// `err` with the file or option named; the return value is 0 or 1.
int run_distance(const DistanceCommand& command, std::ostream& out, std::ostream& err);

struct HullCommand {
  std::string file;
  std::string out_file;  // empty: no export; otherwise .obj or .off (any case)
  bool json = false;
  std::uint64_t max_file_bytes = kDefaultMaxFileBytes;  // ReadOptions
};

// Hull statistics of one file (table or JSON) and optionally its export as
// OBJ or OFF. Returns 0 or 1 like run_distance.
int run_hull(const HullCommand& command, std::ostream& out, std::ostream& err);

// A --pose-a/--pose-b value: seven tokens x y z and the quaternion in
// `order`, normalized; no tokens is the identity. Throws std::runtime_error
// naming the option and the number ("--pose-b qw: 'x' is not a number").
// Shared by `proxima distance` and `proxima view`.
Pose parse_pose(const std::vector<std::string>& tokens, const std::string& option,
                QuaternionOrder order);

// "obj" or "off" for a path with that extension (any case), empty otherwise.
std::string export_format(const std::string& path);

}  // namespace proxima::cli
