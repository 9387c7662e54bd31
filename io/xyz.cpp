// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the XYZ point-list reader (see formats.h, include/proxima/io.h).
#include <algorithm>

#include "formats.h"
#include "limits.h"
#include "text.h"

namespace proxima::io_detail {

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

}  // namespace proxima::io_detail
