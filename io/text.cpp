// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: the shared text parsing (see text.h).
#include "text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace proxima::io_detail {

// 'token' for a message: printable ASCII kept, the rest as \xNN, cut to
// kQuoteLength characters.
std::string quote(std::string_view token) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kQuoteLength; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (token.size() > kQuoteLength) out += "...";
  out += "'";
  return out;
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto ca = static_cast<unsigned char>(a[i]);
    const auto cb = static_cast<unsigned char>(b[i]);
    if (std::tolower(ca) != std::tolower(cb)) return false;
  }
  return true;
}

// Decimal text to the nearest double (std::from_chars: correctly rounded,
// independent of the C locale). A leading '+' is allowed, as in C's strtod.
NumberStatus parse_double(std::string_view token, double* value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '+' && token[1] != '-')
    token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  if (ptr != end || token.empty()) return NumberStatus::not_a_number;
  if (ec == std::errc::result_out_of_range) return NumberStatus::out_of_range;
  if (ec != std::errc()) return NumberStatus::not_a_number;
  return NumberStatus::ok;
}

bool parse_count(std::string_view token, std::uint64_t* value) {
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  return ec == std::errc() && ptr == end && !token.empty();
}

std::string coordinate_label(int axis, std::size_t vertex) {
  return std::string(axis_name(axis)) + " of vertex " + std::to_string(vertex) + " (0-based)";
}

// Coordinate `axis` of vertex `vertex` from a text token; refuses (with the
// line) anything that is not a finite double.
double text_coordinate(const Source& src, std::int64_t line, std::string_view token, int axis,
                       std::size_t vertex) {
  double v = 0.0;
  switch (parse_double(token, &v)) {
    case NumberStatus::not_a_number:
      src.fail_line(line, "non-numeric token " + quote(token) + " where the " +
                              coordinate_label(axis, vertex) + " was expected");
    case NumberStatus::out_of_range:
      src.fail_line(line, "coordinate " + quote(token) + " (" + coordinate_label(axis, vertex) +
                              ") is outside the range of double");
    case NumberStatus::ok:
      break;
  }
  // std::isnan / std::isinf classify without an ordered comparison, so they
  // raise no FE_INVALID on a NaN.
  if (std::isnan(v))
    src.fail_line(line,
                  "NaN coordinate " + quote(token) + " (" + coordinate_label(axis, vertex) + ")");
  if (std::isinf(v)) {
    src.fail_line(
        line, "infinite coordinate " + quote(token) + " (" + coordinate_label(axis, vertex) + ")");
  }
  return v;
}

// The first three tokens of `tokens` as the point with index `vertex`; the
// rest of the line is not read (OBJ's w, colours, XYZ's extra columns).
Vec3 text_point(const Source& src, std::int64_t line, Tokens tokens, std::size_t vertex) {
  Vec3 p;
  for (int axis = 0; axis < 3; ++axis) {
    std::string_view token;
    if (!tokens.next(&token)) {
      src.fail_line(line, "expected 3 coordinates for vertex " + std::to_string(vertex) +
                              " (0-based), found " + std::to_string(axis));
    }
    p[axis] = text_coordinate(src, line, token, axis, vertex);
  }
  return p;
}

bool next_content_line(LineReader& lines, std::string_view* line) {
  while (lines.next(line)) {
    *line = strip_comment(*line);
    if (!std::all_of(line->begin(), line->end(), is_blank)) return true;
  }
  return false;
}

}  // namespace proxima::io_detail
