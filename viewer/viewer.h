// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: the viewer's page writer, shared by `proxima view` (cli/view.cpp)
// and proxima.view() (python/view.cpp). It turns bodies, their poses and a
// distance answer into one self-contained HTML page: three.js, our viewer
// code (viewer.js) and the data inline, so that the page opens from a file
// with no network. docs/viewer.md says what the page shows.
//
// The data travels as one JSON object (the page's <script id="proxima-data">):
// every body as world-frame triangles, edges and vertices per convex piece,
// the answer's points, normal, bounds and witness features, or the close
// pairs of a scene step.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/core/types.h"

namespace proxima::viewer {

// False when the build found no three.js (viewer/CMakeLists.txt, option
// PROXIMA_VIEWER): the page writers then throw ViewerUnavailable.
bool available();
// The embedded three.js's version ("0.170.0"), empty when unavailable.
std::string three_version();

class ViewerUnavailable : public std::runtime_error {
 public:
  ViewerUnavailable();
};

// A body as the page draws it: its convex pieces placed at `pose` (a convex
// body is one piece). The radius of a rounded body is written in the label;
// the core is drawn.
struct ShownBody {
  std::string name;
  Body body;
  Pose pose;
};

// What the label says about a pair: the numbers of a `proxima query` answer
// (docs/query-format.md), whether computed here or read from an answer line.
struct PairAnswer {
  std::string status;  // "separated", "touching", "intersecting", ...
  double distance = 0.0;
  double signed_distance = 0.0;
  double signed_lower_bound = 0.0;
  double signed_upper_bound = 0.0;
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();
};

PairAnswer answer_of(const DistanceResult& r);

// The page of one pair. `witness` gives the witness features (and, for
// compounds, the pieces) to highlight: the answer of
// distance(a.body, a.pose, b.body, b.pose); `answer` the numbers shown.
// Throws ViewerUnavailable, or InvalidInput for a feature id outside its hull.
std::string pair_page(const ShownBody& a, const ShownBody& b, const BodyResult& witness,
                      const PairAnswer& answer, const std::string& title);

// One close pair of a scene step; a and b index the `bodies` of scene_page.
struct ScenePair {
  int a = -1;
  int b = -1;
  CompoundResult result;
};

// The page of one scene step: every body, and each close pair as a segment
// between its closest points, coloured by its distance from 0 (red) to the
// margin (blue). Throws ViewerUnavailable, or InvalidInput for a pair index
// outside `bodies`.
std::string scene_page(std::span<const ShownBody> bodies, std::span<const ScenePair> pairs,
                       double margin, const std::string& title);

}  // namespace proxima::viewer
