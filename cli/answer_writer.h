// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the writer of `proxima query` answer lines (docs/query-format.md).
// Each function appends to a line being built; every number is written with
// 17 significant digits, so that the reader gets back the very double, and
// every string is valid JSON whatever bytes it quotes.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "proxima/core/types.h"

namespace proxima::cli {

// x as "%.17g", without looking at the locale.
void append_number(std::string& out, double x);

// [x,y,z] of p.
void append_point(std::string& out, const Vec3& p);

// s as a JSON string; invalid UTF-8 becomes U+FFFD.
void append_json_string(std::string& out, const std::string& s);

// The query's id as parsed, or null when `id` is null (absent).
void append_id(std::string& out, const nlohmann::json* id);

// {"id":...,"status":"error","error":"line N: message"}.
void append_error_answer(std::string& out, const nlohmann::json* id, long line_number,
                         const std::string& message);

}  // namespace proxima::cli
