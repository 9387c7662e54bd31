// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Bodies of any kind: a convex, compound or mesh core plus a radius, and the
// meshes of a body's pieces (the closed triangle meshes of their hulls).
#include "proxima/shape/body.h"

#include "core/checks.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

namespace proxima {
namespace {

// A radius or an approximation error: finite and >= 0, else refused by
// name. Finiteness on the bits first: no comparison with a NaN, which
// would raise FE_INVALID under a caller's traps.
double checked_length(double value, const char* what) {
  return detail::check_finite_non_negative(value, "Body", what);
}

// A hull as a closed triangle mesh with the hull's vertex ids: each face
// fanned from its first vertex (a convex polygon, counter-clockwise seen from
// outside, so the mesh is consistently oriented), each triangle's face kept.
// A polygon (dimension 2) has no inside: one side only, an open mesh. A
// segment or a point is one degenerate triangle (the mesh measures it as
// the segment or point it is).
Body::MeshOfPiece hull_mesh(const ConvexPolytope& p, const Pose& pose) {
  std::vector<TriangleMesh::Triangle> triangles;
  std::vector<std::int32_t> faces;
  const int face_count = p.dimension() == 2 ? std::min(p.face_count(), 1) : p.face_count();
  for (int f = 0; f < face_count; ++f) {
    const std::span<const std::int32_t> face = p.face(f);
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      triangles.push_back({static_cast<std::uint32_t>(face[0]), static_cast<std::uint32_t>(face[k]),
                           static_cast<std::uint32_t>(face[k + 1])});
      faces.push_back(f);
    }
  }
  if (triangles.empty()) {  // a segment or a point
    const auto last = static_cast<std::uint32_t>(p.vertex_count() - 1);
    triangles.push_back({0, last, last});
    faces.push_back(-1);
  }
  return {std::make_shared<const TriangleMesh>(p.vertices(), triangles), std::move(faces), pose};
}

std::shared_ptr<const CompoundBody> one_piece(const std::shared_ptr<const ConvexPolytope>& core) {
  return std::make_shared<const CompoundBody>(std::vector<CompoundPiece>{{core, Pose::identity()}});
}

}  // namespace

Body::Body(std::shared_ptr<const ConvexPolytope> core, double radius, double approximation_error)
    : convex_(std::move(core)),
      wrapper_(std::make_shared<Wrapper>()),
      radius_(checked_length(radius, "radius")),
      approximation_error_(checked_length(approximation_error, "approximation_error")) {
  if (!convex_) throw InvalidInput("Body: null convex core");
}

Body::Body(std::shared_ptr<const CompoundBody> core, double radius, double approximation_error)
    : compound_(std::move(core)),
      wrapper_(std::make_shared<Wrapper>()),
      radius_(checked_length(radius, "radius")),
      approximation_error_(checked_length(approximation_error, "approximation_error")) {
  if (!compound_) throw InvalidInput("Body: null compound core");
}

Body::Body(std::shared_ptr<const TriangleMesh> core, double radius)
    : mesh_(std::move(core)),
      wrapper_(std::make_shared<Wrapper>()),
      radius_(checked_length(radius, "radius")) {
  if (!mesh_) throw InvalidInput("Body: null mesh core");
}

Body::Body(ConvexPolytope core, double radius)
    : Body(std::make_shared<const ConvexPolytope>(std::move(core)), radius) {}

Body::Body(CompoundBody core, double radius)
    : Body(std::make_shared<const CompoundBody>(std::move(core)), radius) {}

Body::Body(TriangleMesh core, double radius)
    : Body(std::make_shared<const TriangleMesh>(std::move(core)), radius) {}

Body Body::with_radius(double radius) const {
  Body copy = *this;
  copy.radius_ = checked_length(radius, "radius");
  return copy;
}

std::shared_ptr<const CompoundBody> Body::compound() const {
  if (compound_ || !convex_) return compound_;
  std::call_once(wrapper_->once, [this] { wrapper_->compound = one_piece(convex_); });
  return wrapper_->compound;
}

const std::vector<Body::MeshOfPiece>& Body::meshes() const {
  std::call_once(wrapper_->meshes_once, [this] {
    std::vector<MeshOfPiece>& out = wrapper_->meshes;
    if (mesh_) {
      out.push_back({mesh_, {}, Pose::identity()});
    } else if (convex_) {
      out.push_back(hull_mesh(*convex_, Pose::identity()));
    } else {
      for (int i = 0; i < compound_->piece_count(); ++i) {
        const CompoundPiece& piece = compound_->piece(i);
        out.push_back(hull_mesh(*piece.polytope, piece.pose));
      }
    }
  });
  return wrapper_->meshes;
}

double Body::scale() const {
  return (convex_ ? convex_->scale() : compound_ ? compound_->scale() : mesh_->scale()) + radius_;
}

}  // namespace proxima
