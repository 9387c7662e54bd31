// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: what is wrong with a `proxima query` line, said so that the user
// can find it: errors that name the place in the query (`b.vertices[3][1]`),
// the path at which a line stops being JSON, and the nesting limit checked
// before a line is parsed. The caller (query.cpp) adds the line number.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>

namespace proxima::cli {

using Json = nlohmann::json;

// What is wrong with one query line. The message names the place in the
// query; the caller adds the line number.
class QueryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws QueryError(message).
[[noreturn]] void fail(const std::string& message);

// The kind of a JSON value in words: "(it is a string)" reads better than
// nlohmann's bare type name.
std::string kind(const Json& v);

// path[i], e.g. indexed("a.vertices", 3) is "a.vertices[3]".
std::string indexed(const std::string& path, std::size_t i);

// The message for a line that is not valid JSON (`ex` from parsing it),
// naming the path where it broke, e.g. "not valid JSON near
// a.vertices[1][2]: syntax error ... at column 40".
std::string describe_parse_error(const std::string& line, const Json::exception& ex);

// The deepest nesting of arrays and objects a query line may have. A query
// needs 4 levels (the line, a body, its vertices, a point); the rest is room
// for ids. nlohmann parses any depth, but its dump (the id is echoed) and
// its comparisons recurse, and a line nested 100,000 deep overflowed the
// stack and killed the run (issue 9).
constexpr int kMaxJsonDepth = 64;

// The 1-based column at which `line` opens its (kMaxJsonDepth + 1)-th
// nested array or object, or 0 when it stays within the limit. Brackets
// inside strings do not count. A linear scan that keeps one counter, run
// before the parser so that a deep line never reaches it.
std::size_t nesting_overflow_column(std::string_view line);

}  // namespace proxima::cli
