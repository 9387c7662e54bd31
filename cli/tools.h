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
  // Three tokens each (x y z), or seven: x y z and the quaternion in
  // `quaternion_order`, which must then be named; as typed (parsed by the
  // command so that a bad number is bad input, exit 1, not a usage error).
  std::vector<std::string> pose_a;
  std::vector<std::string> pose_b;
  std::optional<QuaternionOrder> quaternion_order;
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

// A --pose-a/--pose-b value: three tokens x y z (no rotation), or seven: x
// y z and the quaternion in `order`, normalized; no tokens is the identity.
// Seven tokens with no order named are refused with both readings of the
// quaternion. Throws std::runtime_error naming the option and the number
// ("--pose-b qw: 'x' is not a number"). Shared by `proxima distance` and
// `proxima view`.
Pose parse_pose(const std::vector<std::string>& tokens, const std::string& option,
                std::optional<QuaternionOrder> order);

// A mesh file as the body `as` names ("mesh", "hull", "pieces"), or by the
// one default of every command ("": the hull of a convex file or of a point
// cloud; a non-convex file with faces is refused, naming the choices).
// Throws FileError naming the file. Shared by `proxima distance` and
// `proxima view`, so that both read a file the same way.
Body load_body_named(const std::string& path, const std::string& as,
                     std::uint64_t max_file_bytes);

// "obj" or "off" for a path with that extension (any case), empty otherwise.
std::string export_format(const std::string& path);

}  // namespace proxima::cli
