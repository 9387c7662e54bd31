// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: mesh file readers (see include/proxima/io.h).
//
// How the readers stay safe on hostile input:
// - every read is bounds-checked against the bytes actually present;
// - a count announced by a header (vertices, triangles, list lengths) is
//   checked against what the remaining bytes can hold before it sizes an
//   allocation, and a loop it drives consumes at least one byte or token per
//   step, so it ends with the file;
// - numbers are parsed by std::from_chars (correctly rounded, locale-free);
//   binary floats are checked for NaN and infinity on their bit patterns,
//   before any arithmetic or conversion touches them (a signalling NaN would
//   raise FE_INVALID when converted from float to double).
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "proxima/io.h"

namespace proxima {

namespace {

std::string compose_message(const std::string& file, std::int64_t line, std::int64_t byte_offset,
                            const std::string& problem) {
  if (line > 0) return file + ", line " + std::to_string(line) + ": " + problem;
  if (byte_offset >= 0) return file + ", byte " + std::to_string(byte_offset) + ": " + problem;
  return file + ": " + problem;
}

}  // namespace

FileError::FileError(std::string file, std::int64_t line, std::int64_t byte_offset,
                     std::string problem)
    : InvalidInput(compose_message(file, line, byte_offset, problem)),
      file_(std::move(file)),
      line_(line),
      byte_offset_(byte_offset),
      problem_(std::move(problem)) {}

FileError FileError::at_line(std::string file, std::int64_t line, std::string problem) {
  return FileError(std::move(file), line, -1, std::move(problem));
}
FileError FileError::at_byte(std::string file, std::int64_t byte_offset, std::string problem) {
  return FileError(std::move(file), 0, byte_offset, std::move(problem));
}
FileError FileError::in_file(std::string file, std::string problem) {
  return FileError(std::move(file), 0, -1, std::move(problem));
}

const char* to_string(MeshFormat format) {
  switch (format) {
    case MeshFormat::obj:
      return "obj";
    case MeshFormat::off:
      return "off";
    case MeshFormat::stl_ascii:
      return "stl_ascii";
    case MeshFormat::stl_binary:
      return "stl_binary";
    case MeshFormat::ply_ascii:
      return "ply_ascii";
    case MeshFormat::ply_binary_le:
      return "ply_binary_le";
    case MeshFormat::xyz:
      return "xyz";
    case MeshFormat::unknown:
      return "unknown";
  }
  return "unknown";
}

namespace {

// Point ids are std::int32_t downstream (hull input_index, group offsets).
constexpr std::size_t kMaxPoints =
    static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());

// A token quoted in a message is cut to this many characters: a corrupt file
// can put megabytes of junk on one "line", and the message must stay short.
constexpr std::size_t kQuoteLength = 40;

// The shortest text line that can hold a vertex ("0 0 0\n"): bounds how many
// vertices a header may announce for the bytes that follow, so that a lying
// count cannot size an allocation.
constexpr std::size_t kMinTextVertexBytes = 6;

// Separators within a line: blanks, and commas too for XYZ (often written
// as CSV). Tested char by char: string_view::find_first_of calls memchr once
// per character, which made it the hot spot of reading text.
constexpr bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
enum class Separators : std::uint8_t { blanks, blanks_and_commas };

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

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

std::string_view strip_bom(std::string_view text) {
  if (text.substr(0, kUtf8Bom.size()) == kUtf8Bom) text.remove_prefix(kUtf8Bom.size());
  return text;
}

std::string_view strip_comment(std::string_view line) { return line.substr(0, line.find('#')); }

// The file being read: its name for messages.
struct Source {
  std::string name;

  [[noreturn]] void fail_line(std::int64_t line, const std::string& problem) const {
    throw FileError::at_line(name, line, problem);
  }
  [[noreturn]] void fail_byte(std::size_t offset, const std::string& problem) const {
    throw FileError::at_byte(name, static_cast<std::int64_t>(offset), problem);
  }
  [[noreturn]] void fail(const std::string& problem) const {
    throw FileError::in_file(name, problem);
  }
};

void push_point(const Source& src, std::vector<Vec3>& points, const Vec3& p) {
  if (points.size() >= kMaxPoints)
    src.fail("more than " + std::to_string(kMaxPoints) + " vertices");
  points.push_back(p);
}

// ---------------------------------------------------------------------------
// Text: lines, tokens, numbers.

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

// ---------------------------------------------------------------------------
// Binary: little-endian loads, assembled byte by byte (host-order free).

std::uint64_t load_le(std::string_view bytes, std::size_t offset, std::size_t size) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < size; ++i) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[offset + i])) << (8 * i);
  }
  return v;
}

// A binary coordinate: refuses NaN and infinity from the bit pattern (all
// exponent bits set), before the value is converted or compared. `label()`
// names the coordinate; it is only built for a message.
// `base` is the file offset of bytes[0], for messages (STL is read from a
// file in chunks).
template <class Label>
double binary_float(const Source& src, std::string_view bytes, std::size_t offset, bool is_double,
                    Label&& label, std::size_t base = 0) {
  if (is_double) {
    const std::uint64_t bits = load_le(bytes, offset, 8);
    constexpr std::uint64_t kExponent = 0x7ffULL << 52;
    constexpr std::uint64_t kMantissa = (1ULL << 52) - 1;
    if ((bits & kExponent) == kExponent) {
      src.fail_byte(base + offset, std::string((bits & kMantissa) != 0 ? "NaN" : "infinite") +
                                       " coordinate (" + label() + ")");
    }
    return std::bit_cast<double>(bits);
  }
  const auto bits = static_cast<std::uint32_t>(load_le(bytes, offset, 4));
  constexpr std::uint32_t kExponent = 0xffU << 23;
  constexpr std::uint32_t kMantissa = (1U << 23) - 1;
  if ((bits & kExponent) == kExponent) {
    src.fail_byte(base + offset, std::string((bits & kMantissa) != 0 ? "NaN" : "infinite") +
                                     " coordinate (" + label() + ")");
  }
  return static_cast<double>(std::bit_cast<float>(bits));
}

// ---------------------------------------------------------------------------
// Exact duplicates, merged for STL (each facet repeats its corners).

// Corners of STL facets, three per triangle, as read: float triples for
// binary STL (converting them to double for storage would double the
// memory of the largest files), doubles for ASCII STL.
using FloatCorner = std::array<float, 3>;
using DoubleCorner = std::array<double, 3>;

// The distinct corners, each at its first appearance, in file order, as
// cloud.points, and the triangles over them as cloud.triangles: sort corner
// indices by corner then index, so that equal corners sit together with the
// earliest first; each corner then takes the id of the first of its run, and
// ids are given in file order. O(n log n) whatever the values (a hash table
// could be made to degrade by crafted input), and only 4 bytes per corner
// beyond the corners themselves. The corners are finite, so < orders them
// strictly, and -0.0 == +0.0 merges the two zeros.
template <class Corner>
void merge_corners(const Source& src, std::vector<Corner> corners, PointCloud& cloud) {
  if (corners.size() / 3 > kMaxPoints)
    src.fail("more than " + std::to_string(kMaxPoints) + " triangles");
  std::vector<std::uint32_t> order(corners.size());  // corners.size() <= 3 * kMaxPoints < 2^32
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (corners[a] != corners[b]) return corners[a] < corners[b];
    return a < b;
  });
  // first[c]: the first corner equal to c (first[c] <= c).
  std::vector<std::uint32_t> first(corners.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    first[order[k]] =
        k > 0 && corners[order[k]] == corners[order[k - 1]] ? first[order[k - 1]] : order[k];
  }
  order = {};
  // In place, in file order: first[c] becomes c's point id (first[c] < c is
  // already an id by then).
  std::size_t distinct = 0;
  for (std::size_t c = 0; c < corners.size(); ++c) distinct += first[c] == c ? 1 : 0;
  if (distinct > kMaxPoints)
    src.fail("more than " + std::to_string(kMaxPoints) + " distinct vertices");
  cloud.points.reserve(distinct);
  for (std::size_t c = 0; c < corners.size(); ++c) {
    if (first[c] == c) {
      first[c] = static_cast<std::uint32_t>(cloud.points.size());
      cloud.points.emplace_back(corners[c][0], corners[c][1], corners[c][2]);
    } else {
      first[c] = first[first[c]];
    }
  }
  corners = {};
  cloud.triangles.resize(first.size() / 3);
  for (std::size_t t = 0; t < cloud.triangles.size(); ++t) {
    for (std::size_t k = 0; k < 3; ++k)
      cloud.triangles[t][k] = static_cast<std::int32_t>(first[3 * t + k]);
  }
}

// ---------------------------------------------------------------------------
// OBJ: `v` lines are the vertices (global to the file), `f` lines the faces
// (polygons of 1-based vertex indices, negative ones counting back from the
// last vertex read; `v/vt/vn` forms keep the v), `g` and `o` statements group
// what follows. Every other statement (vn, vt, l, p, s, usemtl, mtllib, ...)
// is skipped. A line is classified by its first token, after leading blanks.

struct ObjStatement {
  std::string name;
  std::size_t vertices = 0;   // vertices read before it
  std::size_t triangles = 0;  // triangles read before it
};

// One corner of an `f` line: the vertex index before the first '/', as a
// 0-based index into the `vertices` read so far.
std::int32_t obj_face_corner(const Source& src, std::int64_t line, std::string_view token,
                             std::size_t vertices) {
  const std::string_view index = token.substr(0, token.find('/'));
  std::int64_t value = 0;
  const char* end = index.data() + index.size();
  const auto [ptr, ec] = std::from_chars(index.data(), end, value);
  if (index.empty() || ptr != end || ec != std::errc()) {
    src.fail_line(line, "face vertex " + quote(token) + " is not an integer vertex index");
  }
  const auto count = static_cast<std::int64_t>(vertices);
  const std::int64_t resolved = value > 0 ? value - 1 : count + value;
  if (value == 0 || resolved < 0 || resolved >= count) {
    src.fail_line(line, "face vertex index " + quote(index) + " does not name one of the " +
                            std::to_string(vertices) + " vertices read so far" +
                            (value == 0 ? " (OBJ indices start at 1)" : ""));
  }
  return static_cast<std::int32_t>(resolved);
}

// The statements become groups over `count(statement)` items (triangles for a
// file with faces, points otherwise): a statement with nothing since the
// previous one renames it; what comes before the first statement forms a
// group ""; an empty trailing group is dropped. So the groups cover the
// items, each non-empty.
template <class Count>
void obj_groups(std::vector<ObjStatement>& statements, std::size_t total, Count&& count,
                PointCloud& cloud) {
  for (ObjStatement& statement : statements) {
    const std::size_t offset = count(statement);
    if (!cloud.group_offsets.empty() &&
        static_cast<std::size_t>(cloud.group_offsets.back()) == offset) {
      cloud.group_names.back() = std::move(statement.name);
      continue;
    }
    if (cloud.group_offsets.empty() && offset > 0) {
      cloud.group_names.emplace_back();
      cloud.group_offsets.push_back(0);
    }
    cloud.group_names.push_back(std::move(statement.name));
    cloud.group_offsets.push_back(static_cast<std::int32_t>(offset));
  }
  if (!cloud.group_offsets.empty() &&
      static_cast<std::size_t>(cloud.group_offsets.back()) == total) {
    cloud.group_names.pop_back();
    cloud.group_offsets.pop_back();
  }
}

PointCloud read_obj(const Source& src, std::string_view text) {
  PointCloud cloud;
  std::vector<ObjStatement> statements;
  std::vector<std::int32_t> polygon;
  LineReader lines(src, text);
  std::string_view line;
  while (lines.next(&line)) {
    Tokens tokens(strip_comment(line));
    std::string_view keyword;
    if (!tokens.next(&keyword)) continue;
    const std::int64_t at = lines.number();
    if (keyword == "v") {
      push_point(src, cloud.points, text_point(src, at, tokens, cloud.points.size()));
    } else if (keyword == "f") {
      polygon.clear();
      std::string_view token;
      while (tokens.next(&token))
        polygon.push_back(obj_face_corner(src, at, token, cloud.points.size()));
      if (polygon.size() < 3) {
        src.fail_line(at, "face with " + std::to_string(polygon.size()) +
                              " vertices (a face needs at least 3)");
      }
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        if (cloud.triangles.size() >= kMaxPoints)
          src.fail_line(at, "more than " + std::to_string(kMaxPoints) + " triangles");
        cloud.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
      }
    } else if (keyword == "g" || keyword == "o") {
      std::string name;
      std::string_view word;
      while (tokens.next(&word)) {
        if (!name.empty()) name += ' ';
        name += word;
      }
      statements.push_back({std::move(name), cloud.points.size(), cloud.triangles.size()});
    }
  }
  if (cloud.triangles.empty()) {
    obj_groups(
        statements, cloud.points.size(), [](const ObjStatement& s) { return s.vertices; }, cloud);
  } else {
    obj_groups(
        statements, cloud.triangles.size(), [](const ObjStatement& s) { return s.triangles; },
        cloud);
  }
  cloud.format = MeshFormat::obj;
  return cloud;
}

// ---------------------------------------------------------------------------
// OFF: "OFF" (or COFF, NOFF, CNOFF, STOFF, ...), then "nv nf [ne]" (on the
// keyword's line or the next), then nv vertex lines (extra columns, such as
// colours, ignored), then faces (ignored). '#' starts a comment.

bool next_content_line(LineReader& lines, std::string_view* line) {
  while (lines.next(line)) {
    *line = strip_comment(*line);
    if (!std::all_of(line->begin(), line->end(), is_blank)) return true;
  }
  return false;
}

// 0: not an OFF keyword; 1: a supported one; -1: a 4-D or binary variant.
int off_keyword(std::string_view token) {
  if (token.size() < 3 || token.substr(token.size() - 3) != "OFF") return 0;
  std::string_view prefix = token.substr(0, token.size() - 3);
  if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
  if (prefix.substr(0, 1) == "C") prefix.remove_prefix(1);
  if (prefix.substr(0, 1) == "N") prefix.remove_prefix(1);
  if (prefix.empty()) return 1;
  if (prefix == "4" || prefix == "n" || prefix == "4n") return -1;
  return 0;
}

PointCloud read_off(const Source& src, std::string_view text) {
  LineReader lines(src, text);
  std::string_view line;
  if (!next_content_line(lines, &line))
    src.fail("empty mesh (no vertices): the file has no OFF header");
  Tokens header(line);
  std::string_view keyword;
  header.next(&keyword);
  const int kind = off_keyword(keyword);
  if (kind == 0) src.fail_line(lines.number(), "OFF header expected, found " + quote(keyword));
  if (kind < 0)
    src.fail_line(lines.number(),
                  "unsupported OFF variant " + quote(keyword) + " (only 3-D OFF is read)");

  std::string_view count_token;
  if (!header.next(&count_token)) {
    if (!next_content_line(lines, &line)) {
      src.fail_line(lines.number(), "OFF header ends before its counts (vertices faces edges)");
    }
    header = Tokens(line);
    header.next(&count_token);
  }
  if (count_token == "BINARY") src.fail_line(lines.number(), "binary OFF is not supported");
  std::uint64_t count = 0;
  if (!parse_count(count_token, &count)) {
    src.fail_line(lines.number(),
                  "OFF vertex count " + quote(count_token) + " is not a non-negative integer");
  }
  const std::int64_t count_line = lines.number();
  if (count > kMaxPoints)
    src.fail_line(count_line, "OFF header announces " + std::to_string(count) +
                                  " vertices, more than " + std::to_string(kMaxPoints));

  PointCloud cloud;
  cloud.points.reserve(std::min<std::size_t>(count, lines.bytes_left() / kMinTextVertexBytes));
  while (cloud.points.size() < count) {
    if (!next_content_line(lines, &line)) {
      src.fail_line(lines.number(), "the OFF header (line " + std::to_string(count_line) +
                                        ") announces " + std::to_string(count) +
                                        " vertices, but the file ends after " +
                                        std::to_string(cloud.points.size()));
    }
    cloud.points.push_back(text_point(src, lines.number(), Tokens(line), cloud.points.size()));
  }
  cloud.format = MeshFormat::off;
  return cloud;
}

// ---------------------------------------------------------------------------
// XYZ: one point per line, the first three numbers, '#' comments.

PointCloud read_xyz(const Source& src, std::string_view text) {
  PointCloud cloud;
  LineReader lines(src, text);
  std::string_view line;
  while (next_content_line(lines, &line)) {
    push_point(src, cloud.points,
               text_point(src, lines.number(), Tokens(line, Separators::blanks_and_commas),
                          cloud.points.size()));
  }
  cloud.format = MeshFormat::xyz;
  return cloud;
}

// ---------------------------------------------------------------------------
// STL.

constexpr std::size_t kStlHeaderBytes = 80;
constexpr std::size_t kStlPreambleBytes = 84;  // header and the uint32 triangle count
constexpr std::size_t kStlTriangleBytes = 50;  // normal, 3 corners (12 floats), uint16 attribute

// Binary by the size rule, 84 + 50 n bytes for the n the file announces; a
// header may well begin with "solid" (some exporters write it there), so the
// prefix alone decides nothing. Otherwise ASCII when the text begins with
// "solid" and holds no NUL byte; anything else is read as binary, to report
// its size mismatch.
bool stl_is_binary(std::string_view bytes) {
  if (bytes.size() >= kStlPreambleBytes) {
    const std::uint64_t n = load_le(bytes, kStlHeaderBytes, 4);
    if (kStlPreambleBytes + kStlTriangleBytes * n == bytes.size()) return true;
  }
  const std::string_view text = strip_bom(bytes);
  const std::size_t b = text.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos || !iequals(text.substr(b, 5), "solid")) return true;
  return bytes.find('\0') != std::string_view::npos;
}

// The preamble's announced triangle count, checked against the file's size.
std::uint64_t stl_binary_count(const Source& src, std::string_view preamble,
                               std::uint64_t file_bytes) {
  if (file_bytes < kStlPreambleBytes) {
    src.fail_byte(file_bytes,
                  "truncated binary STL: expected at least " + std::to_string(kStlPreambleBytes) +
                      " bytes (header and triangle count), got " + std::to_string(file_bytes));
  }
  const std::uint64_t n = load_le(preamble, kStlHeaderBytes, 4);
  const std::uint64_t expected = kStlPreambleBytes + kStlTriangleBytes * n;
  if (expected != file_bytes) {
    const std::string what =
        expected > file_bytes ? "truncated binary STL: " : "binary STL size mismatch: ";
    src.fail_byte(std::min<std::uint64_t>(expected, file_bytes),
                  what + "the header announces " + std::to_string(n) + " triangles, expected " +
                      std::to_string(expected) + " bytes (84 + 50 * " + std::to_string(n) +
                      "), got " + std::to_string(file_bytes));
  }
  return n;
}

// The n triangles of a binary STL whose size was checked; fetch(offset,
// size) gives the bytes [offset, offset + size) of the file, read in chunks
// so that a file need not be held in memory beside its corners.
template <class Fetch>
PointCloud read_stl_binary_triangles(const Source& src, std::uint64_t n, Fetch&& fetch) {
  constexpr std::size_t kChunkTriangles = 1 << 14;
  std::vector<FloatCorner> corners;
  corners.reserve(
      3 * static_cast<std::size_t>(n));  // n is bounded by the file's size, checked by the caller
  for (std::size_t t0 = 0; t0 < n; t0 += kChunkTriangles) {
    const std::size_t count = std::min<std::size_t>(kChunkTriangles, n - t0);
    const std::size_t base = kStlPreambleBytes + kStlTriangleBytes * t0;
    const std::string_view chunk = fetch(base, kStlTriangleBytes * count);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t t = t0 + i;
      const std::size_t first_corner = kStlTriangleBytes * i + 12;  // after the normal
      for (std::size_t k = 0; k < 3; ++k) {
        FloatCorner p{};
        for (std::size_t axis = 0; axis < 3; ++axis) {
          const std::size_t offset = first_corner + 12 * k + 4 * axis;
          // A float read as double: exact, and back to float exact too.
          p[axis] = static_cast<float>(binary_float(
              src, chunk, offset, false,
              [&] {
                return std::string(axis_name(static_cast<int>(axis))) + " of corner " +
                       std::to_string(k) + " of triangle " + std::to_string(t) + " (0-based)";
              },
              base));
        }
        corners.push_back(p);
      }
    }
  }
  PointCloud cloud;
  merge_corners(src, std::move(corners), cloud);
  cloud.format = MeshFormat::stl_binary;
  return cloud;
}

PointCloud read_stl_binary(const Source& src, std::string_view bytes) {
  const std::uint64_t n = stl_binary_count(src, bytes, bytes.size());
  return read_stl_binary_triangles(
      src, n, [&](std::size_t offset, std::size_t size) { return bytes.substr(offset, size); });
}

// solid / facet normal / outer loop / vertex x3 / endloop / endfacet /
// endsolid, keywords in any case. Facets must be triangles; a missing final
// endsolid is forgiven (the facets before it are complete), a file that ends
// inside a facet is not.
PointCloud read_stl_ascii(const Source& src, std::string_view text) {
  enum class State : std::uint8_t { outside, solid, facet, loop, loop_done };
  State state = State::outside;
  std::int64_t facet_line = 0;
  int facet_corners = 0;
  std::vector<DoubleCorner> corners;
  LineReader lines(src, text);
  std::string_view line;
  while (lines.next(&line)) {
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(&keyword)) continue;
    const std::int64_t at = lines.number();
    const auto unexpected = [&](const char* expected) {
      src.fail_line(at,
                    "unexpected " + quote(keyword) + " in ASCII STL (expected " + expected + ")");
    };
    switch (state) {
      case State::outside:
        if (iequals(keyword, "solid")) {
          state = State::solid;
        } else {
          unexpected("'solid'");
        }
        break;
      case State::solid:
        if (iequals(keyword, "facet")) {
          state = State::facet;
          facet_line = at;
          facet_corners = 0;
        } else if (iequals(keyword, "endsolid")) {
          state = State::outside;
        } else {
          unexpected("'facet' or 'endsolid'");
        }
        break;
      case State::facet: {
        std::string_view word;
        if (!iequals(keyword, "outer") || !tokens.next(&word) || !iequals(word, "loop"))
          unexpected("'outer loop'");
        state = State::loop;
        break;
      }
      case State::loop:
        if (iequals(keyword, "vertex")) {
          const Vec3 p = text_point(src, at, tokens, corners.size());
          corners.push_back({p.x(), p.y(), p.z()});
          ++facet_corners;
        } else if (iequals(keyword, "endloop")) {
          if (facet_corners != 3) {
            src.fail_line(at, "the facet at line " + std::to_string(facet_line) + " has " +
                                  std::to_string(facet_corners) +
                                  " vertices; STL facets are triangles (3)");
          }
          state = State::loop_done;
        } else {
          unexpected("'vertex' or 'endloop'");
        }
        break;
      case State::loop_done:
        if (iequals(keyword, "endfacet")) {
          state = State::solid;
        } else {
          unexpected("'endfacet'");
        }
        break;
    }
  }
  if (state == State::facet || state == State::loop || state == State::loop_done) {
    src.fail_line(lines.number(),
                  "the file ends inside the facet opened at line " + std::to_string(facet_line));
  }
  PointCloud cloud;
  merge_corners(src, std::move(corners), cloud);
  cloud.format = MeshFormat::stl_ascii;
  return cloud;
}

// ---------------------------------------------------------------------------
// PLY: ascii and binary_little_endian.

enum class PlyType : std::uint8_t { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

bool ply_type(std::string_view name, PlyType* type) {
  static constexpr std::array<std::pair<std::string_view, PlyType>, 16> kNames = {{
      {"char", PlyType::int8},
      {"int8", PlyType::int8},
      {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},
      {"short", PlyType::int16},
      {"int16", PlyType::int16},
      {"ushort", PlyType::uint16},
      {"uint16", PlyType::uint16},
      {"int", PlyType::int32},
      {"int32", PlyType::int32},
      {"uint", PlyType::uint32},
      {"uint32", PlyType::uint32},
      {"float", PlyType::float32},
      {"float32", PlyType::float32},
      {"double", PlyType::float64},
      {"float64", PlyType::float64},
  }};
  for (const auto& [n, t] : kNames) {
    if (n == name) {
      *type = t;
      return true;
    }
  }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::int8:
    case PlyType::uint8:
      return 1;
    case PlyType::int16:
    case PlyType::uint16:
      return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32:
      return 4;
    case PlyType::float64:
      return 8;
  }
  return 1;
}

bool ply_is_float(PlyType t) { return t == PlyType::float32 || t == PlyType::float64; }
bool ply_is_signed(PlyType t) {
  return t == PlyType::int8 || t == PlyType::int16 || t == PlyType::int32;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::int64_t line = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool binary = false;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after end_header's line
  std::int64_t lines = 0;       // header lines
};

PlyHeader read_ply_header(const Source& src, std::string_view bytes) {
  PlyHeader header;
  std::size_t pos = 0;
  bool have_format = false;
  bool ended = false;
  std::set<std::string> element_names;
  std::set<std::string> property_names;  // of the current element
  while (pos < bytes.size()) {
    // Header lines end with "\n" or "\r\n"; the binary data starts right after.
    const std::size_t nl = bytes.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? bytes.size() : nl;
    std::string_view line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    const std::int64_t at = ++header.lines;
    if (line.find('\0') != std::string_view::npos) src.fail_line(at, "NUL byte in the PLY header");
    if (at == 1) {
      if (line != "ply")
        src.fail_line(1, "not a PLY file: the first line is " + quote(line) + ", expected 'ply'");
      continue;
    }
    Tokens tokens(line);
    std::string_view word;
    if (!tokens.next(&word)) continue;
    if (word == "comment" || word == "obj_info") continue;
    if (word == "end_header") {
      ended = true;
      break;
    }
    if (word == "format") {
      std::string_view encoding;
      std::string_view version;
      if (!tokens.next(&encoding) || !tokens.next(&version))
        src.fail_line(at, "PLY format line incomplete");
      if (encoding == "ascii") {
        header.binary = false;
      } else if (encoding == "binary_little_endian") {
        header.binary = true;
      } else if (encoding == "binary_big_endian") {
        src.fail_line(
            at, "PLY binary_big_endian is not supported (ascii and binary_little_endian are)");
      } else {
        src.fail_line(at, "unknown PLY format " + quote(encoding));
      }
      if (version != "1.0")
        src.fail_line(at, "unsupported PLY version " + quote(version) + " (expected 1.0)");
      have_format = true;
    } else if (word == "element") {
      PlyElement element;
      std::string_view name;
      std::string_view count;
      if (!tokens.next(&name) || !tokens.next(&count))
        src.fail_line(at, "PLY element line needs a name and a count");
      if (!parse_count(count, &element.count)) {
        src.fail_line(at, "PLY element count " + quote(count) + " is not a non-negative integer");
      }
      element.name = std::string(name);
      if (!element_names.insert(element.name).second)
        src.fail_line(at, "duplicate PLY element " + quote(name));
      element.line = at;
      header.elements.push_back(std::move(element));
      property_names.clear();
    } else if (word == "property") {
      if (header.elements.empty()) src.fail_line(at, "PLY property before any element");
      PlyProperty property;
      std::string_view type;
      if (!tokens.next(&type)) src.fail_line(at, "PLY property line needs a type and a name");
      if (type == "list") {
        property.is_list = true;
        std::string_view count_type;
        if (!tokens.next(&count_type) || !tokens.next(&type))
          src.fail_line(at, "PLY list property needs two types");
        if (!ply_type(count_type, &property.count_type))
          src.fail_line(at, "unknown PLY type " + quote(count_type));
        if (ply_is_float(property.count_type)) {
          src.fail_line(at,
                        "PLY list length type " + quote(count_type) + " is not an integer type");
        }
      }
      if (!ply_type(type, &property.type)) src.fail_line(at, "unknown PLY type " + quote(type));
      std::string_view name;
      if (!tokens.next(&name)) src.fail_line(at, "PLY property has no name");
      property.name = std::string(name);
      // Names are unique per element (a set, not a scan: a header of a
      // million properties must not take quadratic time).
      if (!property_names.insert(property.name).second)
        src.fail_line(at, "duplicate PLY property " + quote(name));
      header.elements.back().properties.push_back(std::move(property));
    } else {
      src.fail_line(at, "unknown PLY header keyword " + quote(word) + " (is end_header missing?)");
    }
  }
  if (!ended) src.fail_line(header.lines, "PLY header has no end_header line");
  if (!have_format) src.fail_line(header.lines, "PLY header has no format line");
  header.data_offset = pos;
  return header;
}

struct VertexLayout {
  std::size_t element = 0;
  std::array<std::size_t, 3> xyz{};  // property indices of x, y, z
};

VertexLayout ply_vertex_layout(const Source& src, const PlyHeader& header) {
  VertexLayout layout;
  bool found = false;
  for (std::size_t e = 0; e < header.elements.size() && !found; ++e) {
    if (header.elements[e].name == "vertex") {
      layout.element = e;
      found = true;
    }
  }
  if (!found) src.fail_line(header.lines, "PLY header declares no 'vertex' element");
  const PlyElement& vertex = header.elements[layout.element];
  for (int axis = 0; axis < 3; ++axis) {
    const auto it = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                 [&](const PlyProperty& p) { return p.name == axis_name(axis); });
    if (it == vertex.properties.end()) {
      src.fail_line(vertex.line,
                    "PLY vertex element has no property '" + std::string(axis_name(axis)) + "'");
    }
    if (it->is_list) src.fail_line(vertex.line, "PLY vertex property '" + it->name + "' is a list");
    layout.xyz[static_cast<std::size_t>(axis)] =
        static_cast<std::size_t>(it - vertex.properties.begin());
  }
  if (vertex.count > kMaxPoints) {
    src.fail_line(vertex.line, "PLY header announces " + std::to_string(vertex.count) +
                                   " vertices, more than " + std::to_string(kMaxPoints));
  }
  return layout;
}

// Bytes of one instance counting each list as empty: the least an instance
// can take.
std::size_t ply_min_instance_bytes(const PlyElement& element) {
  std::size_t bytes = 0;
  for (const PlyProperty& p : element.properties)
    bytes += p.is_list ? ply_size(p.count_type) : ply_size(p.type);
  return bytes;
}

bool ply_has_list(const PlyElement& element) {
  return std::any_of(element.properties.begin(), element.properties.end(),
                     [](const PlyProperty& p) { return p.is_list; });
}

class PlyBinaryReader {
 public:
  PlyBinaryReader(const Source& src, std::string_view bytes, std::size_t pos)
      : src_(src), bytes_(bytes), pos_(pos) {}

  std::size_t left() const { return bytes_.size() - pos_; }
  std::size_t pos() const { return pos_; }

  // The header's count of `element` must fit in the bytes left, at the least
  // size an instance can take; checked before anything is allocated for it.
  void check_fits(const PlyElement& element) const {
    const std::size_t least = ply_min_instance_bytes(element);
    if (least > 0 && element.count > left() / least) {
      src_.fail_byte(bytes_.size(),
                     "truncated PLY: the header announces " + std::to_string(element.count) + " '" +
                         element.name + "' elements of at least " + std::to_string(least) +
                         " bytes each, but only " + std::to_string(left()) + " bytes follow");
    }
  }

  void skip_element(const PlyElement& element) {
    check_fits(element);
    if (!ply_has_list(element)) {
      pos_ += static_cast<std::size_t>(element.count) * ply_min_instance_bytes(element);
      return;
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& p : element.properties) skip_property(element, i, p);
    }
  }

  // Reads the vertex element; other properties skipped by their type.
  std::vector<Vec3> read_vertices(const PlyElement& element, const VertexLayout& layout) {
    check_fits(element);
    std::vector<Vec3> points;
    points.reserve(static_cast<std::size_t>(element.count));
    for (std::size_t i = 0; i < element.count; ++i) {
      Vec3 p = Vec3::Zero();
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const PlyProperty& property = element.properties[k];
        const auto axis = static_cast<int>(std::find(layout.xyz.begin(), layout.xyz.end(), k) -
                                           layout.xyz.begin());
        if (axis == 3) {
          skip_property(element, i, property);
          continue;
        }
        need(ply_size(property.type), element, i);
        p[axis] = scalar(property.type, [&] { return coordinate_label(axis, i); });
      }
      points.push_back(p);
    }
    return points;
  }

 private:
  void need(std::size_t n, const PlyElement& element, std::uint64_t index) const {
    if (n > left()) {
      src_.fail_byte(bytes_.size(), "truncated PLY: the data ends inside '" + element.name +
                                        "' element " + std::to_string(index) + " (0-based) of " +
                                        std::to_string(element.count));
    }
  }

  template <class Label>
  double scalar(PlyType type, Label&& label) {
    const std::size_t size = ply_size(type);
    double v = 0.0;
    if (ply_is_float(type)) {
      v = binary_float(src_, bytes_, pos_, type == PlyType::float64, label);
    } else {
      const std::uint64_t raw = load_le(bytes_, pos_, size);
      if (ply_is_signed(type)) {
        // Sign-extend from `size` bytes.
        const unsigned shift = 64U - 8U * static_cast<unsigned>(size);
        v = static_cast<double>(static_cast<std::int64_t>(raw << shift) >> shift);
      } else {
        v = static_cast<double>(raw);
      }
    }
    pos_ += size;
    return v;
  }

  void skip_property(const PlyElement& element, std::uint64_t index, const PlyProperty& p) {
    if (!p.is_list) {
      need(ply_size(p.type), element, index);
      pos_ += ply_size(p.type);
      return;
    }
    const std::size_t count_size = ply_size(p.count_type);
    need(count_size, element, index);
    const std::size_t at = pos_;
    const std::uint64_t raw = load_le(bytes_, pos_, count_size);
    pos_ += count_size;
    const bool negative = ply_is_signed(p.count_type) && ((raw >> (8 * count_size - 1)) & 1U) != 0;
    if (negative) src_.fail_byte(at, "negative length of PLY list '" + p.name + "'");
    const std::size_t item = ply_size(p.type);
    if (raw > left() / item) {
      src_.fail_byte(at, "truncated PLY: list '" + p.name + "' of '" + element.name + "' element " +
                             std::to_string(index) + " (0-based) announces " + std::to_string(raw) +
                             " items, more than the " + std::to_string(left()) +
                             " bytes left can hold");
    }
    pos_ += static_cast<std::size_t>(raw) * item;
  }

  const Source& src_;
  std::string_view bytes_;
  std::size_t pos_;
};

// ASCII PLY data: whitespace-separated tokens, instances usually one per line
// but not necessarily; lines are counted for messages.
class PlyTextReader {
 public:
  PlyTextReader(const Source& src, std::string_view bytes, std::size_t pos, std::int64_t line)
      : src_(src), bytes_(bytes), pos_(pos), line_(line + 1), last_line_(line) {}

  std::size_t left() const { return bytes_.size() - pos_; }

  void skip_element(const PlyElement& element) {
    if (element.properties.empty()) return;  // no tokens at all, whatever the count
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& p : element.properties) skip_property(element, i, p);
    }
  }

  std::vector<Vec3> read_vertices(const PlyElement& element, const VertexLayout& layout) {
    std::vector<Vec3> points;
    // Each property takes at least one character and one separator.
    points.reserve(std::min<std::size_t>(element.count, left() / (2 * element.properties.size())));
    for (std::size_t i = 0; i < element.count; ++i) {
      Vec3 p = Vec3::Zero();
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const auto axis = static_cast<int>(std::find(layout.xyz.begin(), layout.xyz.end(), k) -
                                           layout.xyz.begin());
        if (axis == 3) {
          skip_property(element, i, element.properties[k]);
          continue;
        }
        const std::string_view token = next(element, i);
        p[axis] = text_coordinate(src_, line_, token, axis, i);
      }
      points.push_back(p);
    }
    return points;
  }

 private:
  std::string_view next(const PlyElement& element, std::uint64_t index) {
    while (pos_ < bytes_.size()) {
      const char c = bytes_[pos_];
      if (c == '\n' || (c == '\r' && (pos_ + 1 == bytes_.size() || bytes_[pos_ + 1] != '\n'))) {
        ++line_;
      } else if (c == '\0') {
        src_.fail_line(line_, "NUL byte in ASCII PLY data");
      } else if (!is_blank(c) && c != '\r') {
        break;
      }
      ++pos_;
    }
    if (pos_ == bytes_.size()) {
      src_.fail_line(last_line_, "the ASCII PLY data ends inside '" + element.name + "' element " +
                                     std::to_string(index) + " (0-based) of the " +
                                     std::to_string(element.count) + " the header announces");
    }
    const std::size_t b = pos_;
    last_line_ = line_;
    while (pos_ < bytes_.size()) {
      const char c = bytes_[pos_];
      if (is_blank(c) || c == '\r' || c == '\n' || c == '\0') break;
      ++pos_;
    }
    return bytes_.substr(b, pos_ - b);
  }

  void skip_property(const PlyElement& element, std::uint64_t index, const PlyProperty& p) {
    const std::string_view token = next(element, index);
    if (!p.is_list) return;
    std::uint64_t items = 0;
    if (!parse_count(token, &items)) {
      src_.fail_line(line_, "PLY list length " + quote(token) + " of '" + p.name +
                                "' is not a non-negative integer");
    }
    for (std::uint64_t j = 0; j < items; ++j) next(element, index);
  }

  const Source& src_;
  std::string_view bytes_;
  std::size_t pos_;
  std::int64_t line_;       // the line at pos_
  std::int64_t last_line_;  // the line of the last token: where a short file is reported to end
};

PointCloud read_ply(const Source& src, std::string_view bytes) {
  const PlyHeader header = read_ply_header(src, bytes);
  const VertexLayout layout = ply_vertex_layout(src, header);
  PointCloud cloud;
  if (header.binary) {
    PlyBinaryReader reader(src, bytes, header.data_offset);
    for (std::size_t e = 0; e < layout.element; ++e) reader.skip_element(header.elements[e]);
    cloud.points = reader.read_vertices(header.elements[layout.element], layout);
    cloud.format = MeshFormat::ply_binary_le;
  } else {
    PlyTextReader reader(src, bytes, header.data_offset, header.lines);
    for (std::size_t e = 0; e < layout.element; ++e) reader.skip_element(header.elements[e]);
    cloud.points = reader.read_vertices(header.elements[layout.element], layout);
    cloud.format = MeshFormat::ply_ascii;
  }
  return cloud;
}

// ---------------------------------------------------------------------------
// Format from the extension, or from the content.

bool is_obj_statement(std::string_view word) {
  static constexpr std::array<std::string_view, 11> kWords = {
      "v", "vn", "vt", "vp", "f", "g", "o", "s", "l", "usemtl", "mtllib"};
  return std::find(kWords.begin(), kWords.end(), word) != kWords.end();
}

bool all_numbers(Tokens tokens, int n) {
  for (int i = 0; i < n; ++i) {
    std::string_view token;
    double v = 0.0;
    if (!tokens.next(&token) || parse_double(token, &v) != NumberStatus::ok) return false;
  }
  return true;
}

MeshFormat sniff_format(std::string_view bytes) {
  if (bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n")
    return MeshFormat::ply_ascii;
  // Binary STL only by the exact size rule here: without a .stl extension,
  // a size mismatch says nothing about the format.
  if (bytes.size() >= kStlPreambleBytes &&
      kStlPreambleBytes + kStlTriangleBytes * load_le(bytes, kStlHeaderBytes, 4) == bytes.size()) {
    return MeshFormat::stl_binary;
  }
  if (bytes.find('\0') != std::string_view::npos) return MeshFormat::unknown;
  const std::string_view text = strip_bom(bytes);
  if (!stl_is_binary(text)) return MeshFormat::stl_ascii;
  // The first statement that is not a comment decides.
  const Source quiet{""};
  LineReader lines(quiet, text);
  std::string_view line;
  if (!next_content_line(lines, &line)) return MeshFormat::unknown;
  Tokens tokens(line, Separators::blanks_and_commas);
  std::string_view word;
  tokens.next(&word);
  if (off_keyword(word) != 0) return MeshFormat::off;
  if (is_obj_statement(word)) return MeshFormat::obj;
  if (all_numbers(Tokens(line, Separators::blanks_and_commas), 3)) return MeshFormat::xyz;
  return MeshFormat::unknown;
}

MeshFormat format_from_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".stl") return MeshFormat::stl_binary;  // ASCII or binary: decided by stl_is_binary
  if (ext == ".ply") return MeshFormat::ply_ascii;   // the header says which encoding
  if (ext == ".xyz" || ext == ".txt" || ext == ".pts") return MeshFormat::xyz;
  return MeshFormat::unknown;
}

PointCloud read_as(const Source& src, std::string_view bytes, MeshFormat format) {
  switch (format) {
    case MeshFormat::obj:
      return read_obj(src, strip_bom(bytes));
    case MeshFormat::off:
      return read_off(src, strip_bom(bytes));
    case MeshFormat::stl_ascii:
      return read_stl_ascii(src, strip_bom(bytes));
    case MeshFormat::stl_binary:
      return read_stl_binary(src, bytes);
    case MeshFormat::ply_ascii:
    case MeshFormat::ply_binary_le:
      return read_ply(src, bytes);
    case MeshFormat::xyz:
      return read_xyz(src, strip_bom(bytes));
    case MeshFormat::unknown:
      break;
  }
  src.fail("unknown format: the content is not recognized as OBJ, OFF, STL, PLY or XYZ");
}

PointCloud finish(const Source& src, PointCloud cloud) {
  if (cloud.points.empty()) src.fail("empty mesh (no vertices)");
  cloud.source = src.name;
  return cloud;
}

[[noreturn]] void fail_too_large(const Source& src, const std::string& what, std::uint64_t limit) {
  src.fail("file too large: " + what + " more than the limit of " + std::to_string(limit) +
           " bytes (ReadOptions::max_file_bytes)");
}

// ---------------------------------------------------------------------------
// Convexity of the input surface (see surface_is_convex in io.h).

// The hull vertex of largest d.x, by hill climbing from `start` along the
// hull's edges: on a convex polytope a local maximum is global.
int climb(const ConvexPolytope& hull, const Vec3& d, int start) {
  int v = start;
  double best = d.dot(hull.vertex(v));
  for (bool moved = true; moved;) {
    moved = false;
    for (const std::int32_t w : hull.neighbors(v)) {
      const double value = d.dot(hull.vertex(w));
      if (value > best) {
        best = value;
        v = w;
        moved = true;
      }
    }
  }
  return v;
}

class SurfaceTest {
 public:
  explicit SurfaceTest(const ConvexPolytope& hull)
      : hull_(hull), tolerance_(kConvexSurfaceTolerance * hull.scale()) {
    planes_.reserve(static_cast<std::size_t>(hull.face_count()));
    for (int f = 0; f < hull.face_count(); ++f) planes_.push_back(hull.face_plane(f));
  }

  // Whether all of `corners` lie within the tolerance of one facet's plane.
  // Fast path: the facets around the hull vertex extreme in the direction
  // `hint` (the triangle's normal); then every facet.
  template <std::size_t N>
  bool on_one_facet(const std::array<Vec3, N>& corners, const Vec3& hint) {
    if (hint != Vec3::Zero()) {
      start_ = climb(hull_, hint, start_);
      const auto faces = hull_.adjacency_faces();
      const auto b =
          static_cast<std::size_t>(hull_.adjacency_offsets()[static_cast<std::size_t>(start_)]);
      const auto e =
          static_cast<std::size_t>(hull_.adjacency_offsets()[static_cast<std::size_t>(start_) + 1]);
      for (std::size_t k = b; k < e; ++k) {
        if (faces[k] >= 0 && on_plane(planes_[static_cast<std::size_t>(faces[k])], corners))
          return true;
      }
    }
    return std::any_of(planes_.begin(), planes_.end(),
                       [&](const Plane& plane) { return on_plane(plane, corners); });
  }

 private:
  // The corners are in the hull, so at or below every facet's plane up to
  // rounding: being above -tolerance is being on it.
  template <std::size_t N>
  bool on_plane(const Plane& plane, const std::array<Vec3, N>& corners) const {
    return std::all_of(corners.begin(), corners.end(), [&](const Vec3& p) {
      return plane.normal.dot(p) - plane.offset >= -tolerance_;
    });
  }

  const ConvexPolytope& hull_;
  double tolerance_;
  std::vector<Plane> planes_;
  int start_ = 0;
};

}  // namespace

bool surface_is_convex(const ConvexPolytope& hull, std::span<const Vec3> points,
                       std::span<const std::array<std::int32_t, 3>> triangles) {
  if (hull.dimension() < 3) return true;
  SurfaceTest test(hull);
  if (!triangles.empty()) {
    for (const auto& t : triangles) {
      for (const std::int32_t i : t) {
        if (i < 0 || static_cast<std::size_t>(i) >= points.size()) {
          throw InvalidInput("surface_is_convex: triangle index " + std::to_string(i) +
                             " outside the " + std::to_string(points.size()) + " points");
        }
      }
      const std::array<Vec3, 3> c = {points[static_cast<std::size_t>(t[0])],
                                     points[static_cast<std::size_t>(t[1])],
                                     points[static_cast<std::size_t>(t[2])]};
      if (!test.on_one_facet(c, (c[1] - c[0]).cross(c[2] - c[0]))) return false;
    }
    return true;
  }
  std::vector<bool> is_vertex(points.size(), false);
  for (const std::int32_t i : hull.input_index()) {
    if (i >= 0 && static_cast<std::size_t>(i) < points.size())
      is_vertex[static_cast<std::size_t>(i)] = true;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_vertex[i] &&
        !test.on_one_facet(std::array<Vec3, 1>{points[i]}, points[i] - hull.centroid()))
      return false;
  }
  return true;
}

PointCloud read_points_from_memory(std::string_view bytes, MeshFormat format,
                                   const std::string& name, const ReadOptions& options) {
  const Source src{name};
  if (bytes.size() > options.max_file_bytes) {
    fail_too_large(src, std::to_string(bytes.size()) + " bytes,", options.max_file_bytes);
  }
  if (format == MeshFormat::unknown) format = sniff_format(bytes);
  return finish(src, read_as(src, bytes, format));
}

PointCloud read_points(const std::string& path, const ReadOptions& options) {
  const Source src{path};
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    const bool missing = !ec || ec == std::errc::no_such_file_or_directory;
    src.fail("cannot open: " + (missing ? std::string("no such file") : ec.message()));
  }
  if (std::filesystem::is_directory(status)) src.fail("cannot open: is a directory");
  const std::uint64_t limit = options.max_file_bytes;
  std::uint64_t file_bytes = 0;
  const bool regular = std::filesystem::is_regular_file(status);
  if (regular) {
    file_bytes = std::filesystem::file_size(path, ec);
    if (ec) src.fail("cannot read the size: " + ec.message());
    if (file_bytes > limit) fail_too_large(src, std::to_string(file_bytes) + " bytes,", limit);
  }
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) src.fail(std::string("cannot open: ") + std::strerror(errno));
  MeshFormat format = format_from_extension(path);

  // Binary STL from a regular file is read in chunks: the largest files
  // are binary STL, and their corners alone take 36 bytes per triangle.
  if (regular && format == MeshFormat::stl_binary && file_bytes >= kStlPreambleBytes) {
    std::string preamble(kStlPreambleBytes, '\0');
    if (std::fread(preamble.data(), 1, preamble.size(), file.get()) != preamble.size())
      src.fail("read error");
    if (kStlPreambleBytes + kStlTriangleBytes * load_le(preamble, kStlHeaderBytes, 4) ==
        file_bytes) {
      const std::uint64_t n = stl_binary_count(src, preamble, file_bytes);
      std::string chunk;
      std::uint64_t at = kStlPreambleBytes;
      PointCloud cloud =
          read_stl_binary_triangles(src, n, [&](std::size_t offset, std::size_t size) {
            if (offset != at) throw std::logic_error("binary STL chunks out of order");
            chunk.resize(size);
            if (std::fread(chunk.data(), 1, size, file.get()) != size)
              src.fail_byte(offset, "read error (the file shrank?)");
            at += size;
            return std::string_view(chunk);
          });
      return finish(src, std::move(cloud));
    }
    std::rewind(file.get());
  }

  std::string bytes;
  if (regular) bytes.reserve(static_cast<std::size_t>(file_bytes));
  std::array<char, 1 << 16> buffer{};
  std::size_t got = 0;
  while ((got = std::fread(buffer.data(), 1, buffer.size(), file.get())) > 0) {
    if (got > limit - bytes.size()) fail_too_large(src, "read", limit);
    bytes.append(buffer.data(), got);
  }
  if (std::ferror(file.get()) != 0) src.fail("read error");

  if (format == MeshFormat::stl_binary && !stl_is_binary(bytes)) format = MeshFormat::stl_ascii;
  if (format == MeshFormat::unknown) {
    format = sniff_format(bytes);
    if (format == MeshFormat::unknown) {
      src.fail("unknown format: the extension " +
               quote(std::filesystem::path(path).extension().string()) +
               " is none of .obj .off .stl .ply .xyz .txt .pts, and the content is not recognized");
    }
  }
  return finish(src, read_as(src, bytes, format));
}

LoadedPolytope load_convex(const std::string& path, const ReadOptions& options) {
  PointCloud cloud = read_points(path, options);
  try {
    ConvexPolytope polytope(cloud.points);
    const int interior = polytope.interior_point_count();
    const bool convex = surface_is_convex(polytope, cloud.points, cloud.triangles);
    return LoadedPolytope{std::move(polytope), static_cast<int>(cloud.points.size()), interior,
                          convex};
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(path, e.what());
  }
}

// Compound files: one hull per group. The groups' layout is checked here
// rather than trusted, since a PointCloud may come from a caller, not only
// from the OBJ reader.
LoadedCompound compound_from_cloud(const PointCloud& cloud) {
  const auto point_count = static_cast<std::int64_t>(cloud.points.size());
  if (cloud.points.empty()) throw FileError::in_file(cloud.source, "no points");
  if (cloud.group_names.size() != cloud.group_offsets.size()) {
    throw FileError::in_file(cloud.source, "group names and group offsets differ in number (" +
                                               std::to_string(cloud.group_names.size()) + " and " +
                                               std::to_string(cloud.group_offsets.size()) + ")");
  }
  for (std::size_t t = 0; t < cloud.triangles.size(); ++t) {
    for (const std::int32_t i : cloud.triangles[t]) {
      if (i < 0 || i >= point_count) {
        throw FileError::in_file(cloud.source, "triangle " + std::to_string(t) +
                                                   " has vertex index " + std::to_string(i) +
                                                   ", outside the " + std::to_string(point_count) +
                                                   " points");
      }
    }
  }
  // With faces, groups are ranges of triangles; otherwise of points.
  const bool by_triangles = !cloud.triangles.empty() && !cloud.group_offsets.empty();
  const auto item_count =
      by_triangles ? static_cast<std::int64_t>(cloud.triangles.size()) : point_count;
  const std::size_t groups = std::max<std::size_t>(cloud.group_offsets.size(), 1);
  std::vector<CompoundPiece> pieces;
  std::vector<LoadedPiece> reports;
  pieces.reserve(groups);
  reports.reserve(groups);
  std::vector<std::int32_t> local(by_triangles ? cloud.points.size() : 0,
                                  -1);  // point -> index in the piece
  for (std::size_t g = 0; g < groups; ++g) {
    const bool grouped = !cloud.group_offsets.empty();
    const std::string name = grouped ? cloud.group_names[g] : std::string();
    const std::string label = "group " + std::to_string(g) + " '" + name + "'";
    const std::int64_t begin = grouped ? cloud.group_offsets[g] : 0;
    const std::int64_t end = grouped && g + 1 < groups ? cloud.group_offsets[g + 1] : item_count;
    if ((g == 0 && begin != 0) || begin < 0 || end > item_count || begin >= end) {
      throw FileError::in_file(
          cloud.source, label + ": bad " + (by_triangles ? "triangle" : "point") + " range [" +
                            std::to_string(begin) + ", " + std::to_string(end) + ") of " +
                            std::to_string(item_count) + (by_triangles ? " triangles" : " points") +
                            " (groups must be non-empty, in order, from 0)");
    }
    std::vector<Vec3> own_points;
    std::vector<std::array<std::int32_t, 3>> own_triangles;
    std::span<const Vec3> points;
    std::span<const std::array<std::int32_t, 3>> triangles;
    if (by_triangles) {
      // The vertices the group's faces reference, in order of first reference.
      std::vector<std::int32_t> used;
      for (std::int64_t t = begin; t < end; ++t) {
        std::array<std::int32_t, 3> tri{};
        for (std::size_t k = 0; k < 3; ++k) {
          const auto i = static_cast<std::size_t>(cloud.triangles[static_cast<std::size_t>(t)][k]);
          if (local[i] < 0) {
            local[i] = static_cast<std::int32_t>(own_points.size());
            own_points.push_back(cloud.points[i]);
            used.push_back(static_cast<std::int32_t>(i));
          }
          tri[k] = local[i];
        }
        own_triangles.push_back(tri);
      }
      for (const std::int32_t i : used) local[static_cast<std::size_t>(i)] = -1;
      points = own_points;
      triangles = own_triangles;
    } else {
      points =
          std::span<const Vec3>(cloud.points.data() + begin, static_cast<std::size_t>(end - begin));
      if (!grouped) triangles = cloud.triangles;
    }
    try {
      auto polytope = std::make_shared<const ConvexPolytope>(points);
      const int interior = polytope->interior_point_count();
      const bool convex = surface_is_convex(*polytope, points, triangles);
      reports.push_back({name, static_cast<int>(points.size()), interior, convex});
      pieces.push_back({std::move(polytope), Pose::identity()});
    } catch (const InvalidInput& e) {
      throw FileError::in_file(cloud.source, label + ": " + e.what());
    }
  }
  try {
    return LoadedCompound{CompoundBody(std::move(pieces)), std::move(reports)};
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(cloud.source, e.what());
  }
}

LoadedCompound load_compound(const std::string& path, const ReadOptions& options) {
  return compound_from_cloud(read_points(path, options));
}

}  // namespace proxima
