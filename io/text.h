// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: the text shared by OBJ, OFF, XYZ, ASCII STL
// and ASCII PLY: lines, tokens, correctly rounded numbers, and quoting a
// token in a message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "proxima/core/types.h"
#include "source.h"

namespace proxima::io_detail {

// A token quoted in a message is cut to this many characters: a corrupt file
// can put megabytes of junk on one "line", and the message must stay short.
constexpr std::size_t kQuoteLength = 40;

// Separators within a line: blanks, and commas too for XYZ (often written
// as CSV). Tested char by char: string_view::find_first_of calls memchr once
// per character, which made it the hot spot of reading text.
constexpr bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
enum class Separators : std::uint8_t { blanks, blanks_and_commas };

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

inline const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

// 'token' for a message: printable ASCII kept, the rest as \xNN, cut to
// kQuoteLength characters.
std::string quote(std::string_view token);

// ASCII case-insensitive equality (STL keywords).
bool iequals(std::string_view a, std::string_view b);

inline std::string_view strip_bom(std::string_view text) {
  if (text.substr(0, kUtf8Bom.size()) == kUtf8Bom) text.remove_prefix(kUtf8Bom.size());
  return text;
}

inline std::string_view strip_comment(std::string_view line) {
  return line.substr(0, line.find('#'));
}

// Splits text into lines at "\n", "\r\n" or a lone "\r" (old Mac files).
// A NUL byte means the file is not text: refused with its line.
class LineReader {
 public:
  LineReader(const Source& src, std::string_view text) : src_(src), text_(text) {}

  bool next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    ++number_;
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r' && text_[end] != '\0')
      ++end;
    if (end < text_.size() && text_[end] == '\0')
      src_.fail_line(number_, "NUL byte: this is not a text file");
    *line = text_.substr(pos_, end - pos_);
    pos_ = end;
    if (pos_ < text_.size() && text_[pos_] == '\r') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '\n' && (pos_ == end || text_[pos_ - 1] == '\r'))
      ++pos_;
    return true;
  }

  std::int64_t number() const { return number_; }
  std::size_t bytes_left() const { return text_.size() - pos_; }

 private:
  const Source& src_;
  std::string_view text_;
  std::size_t pos_ = 0;
  std::int64_t number_ = 0;
};

// Tokens of one line.
class Tokens {
 public:
  explicit Tokens(std::string_view line, Separators separators = Separators::blanks)
      : rest_(line), commas_(separators == Separators::blanks_and_commas) {}

  bool next(std::string_view* token) {
    std::size_t b = 0;
    while (b < rest_.size() && is_separator(rest_[b])) ++b;
    if (b == rest_.size()) {
      rest_ = {};
      return false;
    }
    std::size_t e = b;
    while (e < rest_.size() && !is_separator(rest_[e])) ++e;
    *token = rest_.substr(b, e - b);
    rest_.remove_prefix(e);
    return true;
  }

 private:
  bool is_separator(char c) const { return is_blank(c) || (commas_ && c == ','); }

  std::string_view rest_;
  bool commas_;
};

enum class NumberStatus : std::uint8_t { ok, not_a_number, out_of_range };

// Decimal text to the nearest double (std::from_chars: correctly rounded,
// independent of the C locale). A leading '+' is allowed, as in C's strtod.
NumberStatus parse_double(std::string_view token, double* value);

// A non-negative integer count (headers, list lengths).
bool parse_count(std::string_view token, std::uint64_t* value);

// "x of vertex 3 (0-based)", for messages.
std::string coordinate_label(int axis, std::size_t vertex);

// Coordinate `axis` of vertex `vertex` from a text token; refuses (with the
// line) anything that is not a finite double.
double text_coordinate(const Source& src, std::int64_t line, std::string_view token, int axis,
                       std::size_t vertex);

// The first three tokens of `tokens` as the point with index `vertex`; the
// rest of the line is not read (OBJ's w, colours, XYZ's extra columns).
Vec3 text_point(const Source& src, std::int64_t line, Tokens tokens, std::size_t vertex);

// The next line with something besides a '#' comment and blanks, the
// comment stripped.
bool next_content_line(LineReader& lines, std::string_view* line);

}  // namespace proxima::io_detail
