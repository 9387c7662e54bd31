// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: any body, a convex, compound or mesh core plus a radius (one
// distance call for any two of them: proxima/query/body_distance.h).
//
// A Body is a core, a ConvexPolytope, a CompoundBody or a TriangleMesh, plus
// a radius r >= 0:
// the Minkowski sum of the core with a ball of radius r (Coal's swept-sphere
// radius, Jolt's convex radius, MuJoCo's margin). For a compound, every piece
// gets the radius. r = 0 is the plain core. A sphere is a point with a radius,
// a capsule a segment with one, a rounded box a box with one, a padded robot
// link its hull with one (proxima/shape/primitives.h builds them).
//
//   proxima::Body link(std::make_shared<const proxima::ConvexPolytope>(points), 0.03);
//   proxima::Body ball = proxima::make_sphere(0.1);
//   proxima::BodyCache cache;                             // cold; keep it per pair
//   auto r = proxima::distance(link, pose_a, ball, pose_b, {}, &cache);
//   r.signed_distance(), r.point_a, r.point_b, r.normal ...
//
// The answer is the cores' answer offset along the normal, exact: with the
// cores' distance d, closest points p_a, p_b and unit normal n (from A
// towards B), the rounded bodies are at signed distance s = d - r_a - r_b,
// and their closest points are p_a + r_a n and p_b - r_b n, on the rounded
// surfaces. When the cores themselves overlap, d is replaced by minus their
// penetration depth (proxima/detail/penetration/penetration.h) and n by its normal. Negative s
// is an overlap of |s|: translating B by -s n makes the rounded bodies touch.
//
// Thread safety: a Body is immutable, cheap to copy (it shares its core) and
// may be shared between threads. A BodyCache belongs to one pair at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>

#include "proxima/core/types.h"
#include "proxima/shape/compound.h"
#include "proxima/shape/mesh.h"
#include "proxima/shape/polytope.h"

namespace proxima {

class Body {
 public:
  enum class Kind : std::uint8_t { convex, compound, mesh };

  // Throws InvalidInput for a null core, or a radius or approximation error
  // that is negative, NaN or infinite (the message names the value).
  // `approximation_error` is how far the core may be from the shape it
  // stands for (a cylinder's polygon, see primitives.h): at most that far
  // from every point of the true shape, and containing it.
  explicit Body(std::shared_ptr<const ConvexPolytope> core, double radius = 0.0,
                double approximation_error = 0.0);
  explicit Body(std::shared_ptr<const CompoundBody> core, double radius = 0.0,
                double approximation_error = 0.0);
  // A triangle mesh (proxima/shape/mesh.h): its surface, and for a closed mesh
  // its inside, plus the radius.
  explicit Body(std::shared_ptr<const TriangleMesh> core, double radius = 0.0);
  // Copies the core into shared storage.
  explicit Body(ConvexPolytope core, double radius = 0.0);
  explicit Body(CompoundBody core, double radius = 0.0);
  explicit Body(TriangleMesh core, double radius = 0.0);

  Kind kind() const { return convex_ ? Kind::convex : compound_ ? Kind::compound : Kind::mesh; }
  // The convex core, or null for another kind.
  const std::shared_ptr<const ConvexPolytope>& convex() const { return convex_; }
  // The compound core; for a convex body, the core as a one-piece compound,
  // so that it can meet a compound: built on the first call (thread-safe)
  // and shared by every copy of the body, O(N) once. Null for a mesh.
  std::shared_ptr<const CompoundBody> compound() const;
  // The mesh core, or null for another kind.
  const std::shared_ptr<const TriangleMesh>& mesh() const { return mesh_; }

  // A convex core or piece as a closed triangle mesh, to meet a mesh: the
  // hull's faces fanned into triangles, with the hull's vertex ids, and
  // each triangle's hull face (`faces`; a segment or a point is one
  // degenerate triangle, face -1; a polygon its one side, an open mesh).
  struct MeshOfPiece {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<std::int32_t> faces;  // per triangle, the hull face id
    Pose pose;                        // the piece's pose in the body (identity for convex)
  };
  // One per piece (one for a convex body; the core itself for a mesh, faces
  // empty), built on the first call (thread-safe), shared by every copy.
  const std::vector<MeshOfPiece>& meshes() const;

  double radius() const { return radius_; }
  // The same core with another radius (padding: radius() + padding).
  Body with_radius(double radius) const;

  // Largest deviation of the core (plus radius) from the true shape it
  // approximates; 0 for exact bodies (all but cylinders and cones). Every
  // answer against this body is exact for the approximation, and within
  // this of the answer for the true shape (BodyResult::approximation_error).
  double approximation_error() const { return approximation_error_; }

  // Largest absolute coordinate of the core in its own frame, plus the
  // radius: the R of the accuracy standard for the rounded body.
  double scale() const;

 private:
  // A convex core's one-piece compound and any core's meshes, built once on
  // demand.
  struct Wrapper {
    std::once_flag once;
    std::shared_ptr<const CompoundBody> compound;
    std::once_flag meshes_once;
    std::vector<MeshOfPiece> meshes;
  };

  std::shared_ptr<const ConvexPolytope> convex_;
  std::shared_ptr<const CompoundBody> compound_;  // null for another core
  std::shared_ptr<const TriangleMesh> mesh_;      // null for another core
  std::shared_ptr<Wrapper> wrapper_;
  double radius_ = 0.0;
  double approximation_error_ = 0.0;
};

}  // namespace proxima
