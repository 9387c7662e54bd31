// proxima test support: the pieces the scene tests of general bodies share
// (scene_body_test.cpp, scene_margin_test.cpp). Test-only code.
// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <vector>

#include "proxima/scene/scene.h"
#include "proxima/shape/body.h"
#include "proxima/shape/mesh.h"

namespace proxima::test {

// Axis-aligned box [lo, hi] as a closed mesh, counter-clockwise seen from
// outside.
inline TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k)
    v.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
  const std::vector<TriangleMesh::Triangle> t = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                                 {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                                 {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return TriangleMesh(v, t);
}

// One body of a scene: the Body as added, its padding, its pose.
struct SceneEntry {
  Body body;
  double padding = 0.0;
  Pose pose;
  Body padded() const { return body.with_radius(body.radius() + padding); }
};

// The same scene in each broad phase on 1 and 2 threads, to be stepped in
// lockstep: their answers must agree bit for bit.
inline std::vector<Scene> lockstep_scenes(double margin) {
  std::vector<Scene> scenes;
  for (const BroadPhase bp : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
    for (const int threads : {1, 2}) {
      SceneOptions o;
      o.margin = margin;
      o.broad_phase = bp;
      o.threads = threads;
      scenes.emplace_back(o);
    }
  }
  return scenes;
}

}  // namespace proxima::test
