// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the OFF reader (see formats.h, include/proxima/io.h).
#include <algorithm>
#include <string>

#include "formats.h"
#include "limits.h"
#include "text.h"

namespace proxima::io_detail {

// OFF: "OFF" (or COFF, NOFF, CNOFF, STOFF, ...), then "nv nf [ne]" (on the
// keyword's line or the next), then nv vertex lines (extra columns, such as
// colours, ignored), then faces (ignored). '#' starts a comment.

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

}  // namespace proxima::io_detail
