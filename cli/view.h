// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: `proxima view`, one self-contained HTML page of a query
// (viewer/viewer.h writes it; docs/viewer.md). Three inputs:
//   proxima view A B [--pose-a ...] [--pose-b ...] --out page.html
//   proxima view --query FILE --out page.html     a query line, and its answer line or not
//   proxima view --scene FILE --margin M --out page.html   one step of a Scene
#pragma once

#include <cstdint>
#include <ostream>
#include <optional>
#include <string>
#include <vector>

#include "proxima/io.h"
#include "proxima/core/types.h"

namespace proxima::cli {

struct ViewCommand {
  // Two mesh files (each file's OBJ groups are a compound's pieces) ...
  std::string file_a;
  std::string file_b;
  std::vector<std::string> pose_a;  // as `proxima distance` takes them
  std::vector<std::string> pose_b;
  // How the files become bodies: "mesh", "hull" or "pieces", or "" for the
  // default of `proxima distance` (load_body_named).
  std::string as;
  // ... or a file of JSON Lines: a query line (docs/query-format.md), then
  // optionally its answer line; without one, the query is answered here ...
  std::string query_file;
  // ... or a file of JSON Lines, one body per line ({"vertices": ...,
  // "rotation": ..., "translation": ...}), for one step of a Scene with this
  // margin.
  std::string scene_file;
  double margin = 0.0;
  std::optional<QuaternionOrder> quaternion_order;  // none: quaternions name their order
  DistanceOptions options;
  std::uint64_t max_file_bytes = kDefaultMaxFileBytes;
  std::string out_file;  // "-" writes the page to `out`
};

// Writes the page; problems with the input go to `err` naming the file and
// line or option. Returns 0, or 1 for bad input or a build without the viewer.
int run_view(const ViewCommand& command, std::ostream& out, std::ostream& err);

}  // namespace proxima::cli
