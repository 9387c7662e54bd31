// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// One distance call for any two bodies (proxima/shape/body.h): the cores'
// query (convex, compound or mesh; the convex query takes the penetration
// depth of overlapping convex cores or pieces), and the offset by the radii
// along the normal.
#pragma once

#include <cstdint>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/detail/penetration/penetration.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/body.h"

namespace proxima {

// Coherence between queries of one pair of Bodies, owned by the caller;
// default-constructed means cold. It holds the cache of whichever query the
// pair's kinds need (convex pair, whose DistanceCache tracks the depth of
// overlapping cores too, or compound as soon as one side is one) and the
// penetration cache of rounded convex bodies whose cores touch (their
// contact normal). A cache of another pair is at worst slower, never
// wrong.
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
struct BodyResult : DistanceResult {
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
  bool intersecting = false;
  // approximation_error() of A plus that of B: the answer's distance to the
  // true shapes' answer (distance, signed distance, and the bounds) is at
  // most this, on top of the accuracy standard.
  double approximation_error = 0.0;
};

// Distance, signed distance, closest points and features of two Bodies of
// any kinds placed at pose_a and pose_b. Throws InvalidInput for a pose
// outside the contract of proxima/core/pose.h or bad options. `cache` may be
// null (cold).
//
// Mesh bodies (proxima/query/mesh_distance.h): against any kind, the distance between the
// mesh's surface and the other body's surface (a convex core or piece as
// the closed triangle mesh of its hull, Body::meshes()), and intersecting
// when the surfaces cross or one lies inside the other, closed, one. The
// depth of an overlap involving a mesh is not computed: the cores'
// signed value is then 0 with certificate [-infinity, 0] (so
// signed_distance() is minus the radii, and signed_upper_bound() is
// certified). Each pair of meshes is tracked by its own MeshCache. Such a
// pair takes the mesh query's options (proxima/core/types.h,
// DistanceOptions): a non-default algorithm, relative_tolerance or
// max_iterations is refused with InvalidInput naming the field.
//
// Convex and compound cores: their answer is the convex query's
// (proxima/query/distance.h) or the compound query's
// (proxima/query/compound_distance.h: the smallest signed distance over
// piece pairs, the deepest overlapping pair when cores overlap) on the same
// cores and options, offset by the radii, with that query's depth and
// certificate: overlapping cores give the same bits as that query less
// r_a + r_b. Rounded bodies whose cores touch without a certified gap take
// the cores' penetration query for their normal. With options.penetration
// false the depth is skipped: overlapping cores then have the signed value
// 0 with certificate [-infinity, 0] (as a mesh overlap), status
// intersecting, and the distance query's points and normal (which do not
// separate them).
BodyResult distance(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                      const DistanceOptions& options = {}, BodyCache* cache = nullptr);

// The same for poses checked once (RigidPose, proxima/core/pose.h: a robot's
// link poses against every pair they take part in): the rigid-pose check
// of the overload above is not paid again; the answer is the one that
// overload gives for the RigidPoses' poses, bit for bit.
BodyResult distance(const Body& a, const RigidPose& pose_a, const Body& b, const RigidPose& pose_b,
                    const DistanceOptions& options = {}, BodyCache* cache = nullptr);

namespace detail {
// distance() on Bodies for poses already under the contract of
// proxima/core/pose.h (a batch's poses checked before its queries, a
// robot's placed geometries), so that the check is not paid again.
BodyResult distance_of_rigid_poses(const Body& a, const Pose& pose_a, const Body& b,
                                   const Pose& pose_b, const DistanceOptions& options,
                                   BodyCache* cache);
}  // namespace detail

}  // namespace proxima
