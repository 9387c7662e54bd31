// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the STL reader, ASCII and binary (see formats.h, include/proxima/io.h).
#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "binary.h"
#include "formats.h"
#include "limits.h"
#include "text.h"

namespace proxima::io_detail {

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
PointCloud read_stl_binary_triangles(const Source& src, std::uint64_t n, const StlFetch& fetch) {
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

}  // namespace proxima::io_detail
