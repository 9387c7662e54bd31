// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima query`, the JSON Lines exchange. One query per input
// line, one answer per output line, in order. The format is specified in
// docs/query-format.md; this header is the seam between the CLI's argument
// parsing (main.cpp) and the stream loop (query.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "json_errors.h"
#include "line_reader.h"
#include "proxima/query/body_distance.h"
#include "proxima/motion/time_of_impact.h"
#include "proxima/core/types.h"

namespace proxima::cli {

struct QueryRunSummary {
  long answered = 0;         // answer lines written, error answers included
  long errors = 0;           // of which status "error"
  bool read_failed = false;  // the input stream broke (not its end): answers may be missing
  long too_long_line = 0;    // the line past max_line_bytes where reading stopped (0: none)
};

// Reads every line of `in`, answers each non-blank one on `out` and flushes
// after each answer, so that a caller feeding queries through a pipe one at a
// time gets each answer before it sends the next. A bad line yields an error
// answer and the loop goes on; only the stream ending stops it, or a line
// longer than max_line_bytes (its error answer is the last: the rest of such
// a line, /dev/zero's for one, cannot be skipped without reading it).
//
// With threads > 1 the lines are answered in blocks: up to kQueryBlockLines
// lines that are already available (a block never waits for input that has
// not arrived, so a pipe fed one query at a time still gets each answer),
// answered by `threads` threads, written in input order and flushed once per
// block. The output is byte for byte the one of threads == 1.
//
// A body's "rotation" names its order ({"wxyz": [w, x, y, z]} or
// {"xyzw": [x, y, z, w]}), or is four bare numbers in the order the run
// names (`order`, --quaternion-order); four bare numbers in a run that names
// none are an error answer showing both readings.
inline constexpr int kQueryBlockLines = 256;
QueryRunSummary run_queries(std::istream& in, std::ostream& out, const DistanceOptions& options,
                            int threads = 1, std::optional<QuaternionOrder> order = std::nullopt,
                            std::uint64_t max_line_bytes = kDefaultMaxLineBytes);

// One line's answer, as run_queries writes it (without the newline); the
// error answer names line 1. `proxima view` answers the query it draws.
std::string answer_query_line(const std::string& line, const DistanceOptions& options,
                              std::optional<QuaternionOrder> order = std::nullopt);

// Reads body `name` ("a" or "b") of a parsed query line into its vertices,
// triangles (empty: no "triangles", the hull of the vertices), pose, radius
// and motion (none: no motion), rotations as above: the reader of
// run_queries, shared with `proxima view`. Throws QueryError with the field
// named (`b.vertices[3][1] is not a finite number`).
void read_body(const Json& query, const std::string& name, std::optional<QuaternionOrder> order,
               std::vector<Vec3>& vertices, std::vector<std::array<std::int32_t, 3>>& triangles,
               Pose& pose, double& radius, std::optional<Motion>& motion);

// The body a query line describes: its mesh when it has triangles, else the
// hull of its vertices, with its radius. Throws QueryError naming `name`.
Body query_body(const std::vector<Vec3>& vertices,
                const std::vector<std::array<std::int32_t, 3>>& triangles, double radius,
                const std::string& name);

}  // namespace proxima::cli
