// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 6: any body, and one distance call for any two of them.
//
// A Body is a core, a ConvexPolytope, a CompoundBody or a TriangleMesh, plus
// a radius r >= 0:
// the Minkowski sum of the core with a ball of radius r (Coal's swept-sphere
// radius, Jolt's convex radius, MuJoCo's margin). For a compound, every piece
// gets the radius. r = 0 is the plain core. A sphere is a point with a radius,
// a capsule a segment with one, a rounded box a box with one, a padded robot
// link its hull with one (proxima/primitives.h builds them).
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
// penetration depth (proxima/penetration.h) and n by its normal. Negative s
// is an overlap of |s|: translating B by -s n makes the rounded bodies touch.
//
// Thread safety: a Body is immutable, cheap to copy (it shares its core) and
// may be shared between threads. A BodyCache belongs to one pair at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>

#include "proxima/compound.h"
#include "proxima/mesh.h"
#include "proxima/penetration.h"
#include "proxima/polytope.h"
#include "proxima/types.h"

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
  // A triangle mesh (proxima/mesh.h): its surface, and for a closed mesh
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
  // this of the answer for the true shape (BodyDistance::approximation_error).
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

// Coherence between queries of one pair of Bodies, owned by the caller;
// default-constructed means cold. It holds the cache of whichever query the
// pair's kinds need (convex pair, or compound as soon as one side is one)
// and the penetration cache used while convex cores overlap. A cache of
// another pair is at worst slower, never wrong.
struct BodyCache {
  DistanceCache convex;
  CompoundCache compound;
  PenetrationCache penetration;
  // Mesh pairs: one per pair of meshes (piece of A, piece of B) of
  // Body::meshes(), A's index major.
  std::vector<MeshCache> mesh;
  std::int32_t mesh_closest = -1;  // the index in `mesh` of the last answer's pair
  bool is_cold() const {
    bool cold = convex.is_cold() && compound.is_cold() && penetration.is_cold();
    for (const MeshCache& m : mesh) cold = cold && m.is_cold();
    return cold;
  }
  void reset() { *this = BodyCache{}; }
};

// The answer for two Bodies. The DistanceResult fields describe the rounded
// bodies:
//   status        from signed_distance and the contact band 64 u R + Ae, R
//                 the largest coordinate magnitude of the two rounded bodies
//                 (core plus radius) in the query: separated above the
//                 band, touching within it, intersecting below -band;
//                 iteration_cap when the cores' query stopped there. With
//                 both radii 0 it is the cores' status.
//   distance      max(signed_distance, 0): the rounded bodies' distance,
//                 0 when they overlap (as for convex bodies)
//   lower_bound   max(signed_lower_bound, 0): certified, <= the exact distance
//   point_a       on A's rounded surface, world frame: the core's point
//                 plus radius_a * normal
//   point_b       on B's rounded surface: the core's point minus
//                 radius_b * normal; point_b - point_a = signed_distance *
//                 normal (up to rounding), so |point_a - point_b| = |signed|
//   normal        unit, from A towards B: the cores' normal (the closest
//                 points' direction, or the penetration normal when the
//                 cores overlap)
//   feature_a, feature_b  the cores' witness features (hull ids of the
//                 pieces piece_a, piece_b for compounds; mesh vertex ids
//                 and, for a face, the triangle index for a mesh)
// and beyond them:
struct BodyDistance : DistanceResult {
  // The signed distance of the rounded bodies and its certificate are
  // DistanceResult's signed_distance(), signed_lower_bound() and
  // signed_upper_bound() (distance - depth ...): negative when the rounded
  // bodies overlap, minus the overlap depth (the shortest translation of B
  // that makes them touch); the bounds are certified for the
  // approximations (see approximation_error) up to 64 u R.
  // The pieces of the closest (or deepest) pair, -1 for a convex body.
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
  // The closest triangles of mesh bodies (-1 for other kinds).
  std::int32_t triangle_a = -1;
  std::int32_t triangle_b = -1;
  // Whether the cores overlap (then signed_distance <= -(r_a + r_b), from
  // their penetration depth).
  bool cores_overlap = false;
  // approximation_error() of A plus that of B: the answer's distance to the
  // true shapes' answer (distance, signed distance, and the bounds) is at
  // most this, on top of the accuracy standard.
  double approximation_error = 0.0;
};

// Distance, signed distance, closest points and features of two Bodies of
// any kinds placed at pose_a and pose_b. Throws InvalidInput for a pose
// outside the contract of proxima/pose.h or bad options. `cache` may be
// null (cold).
//
// Mesh bodies (proxima/mesh.h): against any kind, the distance between the
// mesh's surface and the other body's surface (a convex core or piece as
// the closed triangle mesh of its hull, Body::meshes()), and intersecting
// when the surfaces cross or one lies inside the other, closed, one. The
// depth of an overlap involving a mesh is not computed: the cores'
// signed value is then 0 with certificate [-infinity, 0] (so
// signed_distance() is minus the radii, and signed_upper_bound() is
// certified). Each pair of meshes is tracked by its own MeshCache.
//
// Compound bodies: the signed distance is the smallest over piece pairs of
// the pair's signed distance (the deepest overlapping pair when cores
// overlap: every piece pair whose bounding spheres meet is then tested,
// cold). Convex cores that overlap cost a penetration query (tracked
// through the cache) on top of the distance query. With
// options.penetration false that depth is skipped: overlapping cores then
// have the signed value 0 with certificate [-infinity, 0] (as a mesh
// overlap), status intersecting, and the distance query's points and normal
// (which do not separate them).
BodyDistance distance(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                      const DistanceOptions& options = {}, BodyCache* cache = nullptr);

}  // namespace proxima
