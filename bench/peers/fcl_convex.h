// proxima benchmarks: proxima's hulls and poses in FCL 0.7's types, shared
// by the pair peer (fcl_peer.cpp) and the scene peer (fcl_scene.cpp) so that
// both hand FCL the same body.
// SPDX-License-Identifier: BSD-3-Clause
//
// This header includes FCL's: only the FCL adapters' .cpp files include it
// (fcl_peer.h and fcl_scene.h keep FCL out of their users' builds).
#pragma once

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/convex.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::bench {

// fcl::Convexd from the hull's vertices and face polygons (FCL's face list
// [n, i0, ..., i(n-1), n, ...]): the same vertices and faces as proxima's
// hull, so both libraries see the same body. With more than 32 vertices FCL's
// support search walks the vertex adjacency it derives from these faces.
// fcl::Convex needs a solid; `what` names the polytope in the error (e.g.
// "FclScene: shape 3").
inline std::shared_ptr<fcl::Convexd> fcl_convex(const ConvexPolytope& p, const std::string& what) {
  if (p.dimension() != 3) {
    throw InvalidInput(what + " is not solid (dimension " + std::to_string(p.dimension()) +
                       "); fcl::Convex needs dimension 3");
  }
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  vertices->reserve(static_cast<std::size_t>(p.vertex_count()));
  for (const Vec3& v : p.vertices()) vertices->push_back(v);
  auto faces = std::make_shared<std::vector<int>>();
  for (int f = 0; f < p.face_count(); ++f) {
    const auto polygon = p.face(f);
    faces->push_back(static_cast<int>(polygon.size()));
    for (const std::int32_t v : polygon) faces->push_back(v);
  }
  auto convex = std::make_shared<fcl::Convexd>(vertices, p.face_count(), faces);
  convex->computeLocalAABB();
  return convex;
}

inline fcl::Transform3d fcl_transform(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation;
  tf.translation() = pose.translation;
  return tf;
}

// FCL's BVHModel<BV> of a triangle mesh: the same vertices and triangles
// (`triangles` a range of three vertex indices each).
template <class BV, class Triangles>
std::shared_ptr<fcl::BVHModel<BV>> fcl_mesh(std::span<const Vec3> vertices,
                                            const Triangles& triangles) {
  auto model = std::make_shared<fcl::BVHModel<BV>>();
  std::vector<fcl::Vector3d> v(vertices.begin(), vertices.end());
  std::vector<fcl::Triangle> t;
  t.reserve(triangles.size());
  for (const auto& tri : triangles)
    t.emplace_back(static_cast<std::size_t>(tri[0]), static_cast<std::size_t>(tri[1]),
                   static_cast<std::size_t>(tri[2]));
  model->beginModel();
  model->addSubModel(v, t);
  model->endModel();
  return model;
}

}  // namespace proxima::bench
