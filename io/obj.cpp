// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the Wavefront OBJ reader (see formats.h, include/proxima/io.h).
#include <algorithm>
#include <array>
#include <charconv>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "formats.h"
#include "limits.h"
#include "text.h"

namespace proxima::io_detail {

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

bool is_obj_statement(std::string_view word) {
  static constexpr std::array<std::string_view, 11> kWords = {
      "v", "vn", "vt", "vp", "f", "g", "o", "s", "l", "usemtl", "mtllib"};
  return std::find(kWords.begin(), kWords.end(), word) != kWords.end();
}

}  // namespace proxima::io_detail
