// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 6: the boolean and margin queries. "Do these bodies intersect?" and
// "are they within distance m?", the questions a motion planner asks for
// every edge of every candidate path, answered with a certificate and
// stopped at the first proof:
//
//   proxima::BodyCache cache;                                  // the distance query's
//   auto r = proxima::within_margin(link_a, pose_a, link_b, pose_b, 0.05, {}, &cache);
//   if (r.is_within()) ...  // r.point_a, r.point_b: a witness pair at most 5 cm apart
//   auto c = proxima::intersects(link_a, pose_a, link_b, pose_b, {}, &cache);
//
// The verdict follows the accuracy standard's contact band (DESIGN.md):
// with band = 64 u R + options.absolute_tolerance, R bounding the largest
// coordinate magnitude of the two bodies in the query (|t|_inf + sqrt(3)
// scale per body, at most 2.8 times the exact R), "within" is proved by a
// witness pair closer than margin + band and "beyond" by a certified lower
// bound above the margin; bodies whose distance lies within the band of the
// margin may get either verdict, each with its proof. intersects() is the
// margin 0: touching and intersecting bodies are within, as the distance
// query's status separated is exactly "beyond".
//
// How each kind stops at the first proof:
//   convex    the hybrid's loop (proxima/detail/narrowphase/hybrid.h, hybrid_within) stops as
//             soon as its closest points fall within margin + band, or its
//             support gap rises above the margin;
//   rounded   the cores' query with the margin plus both radii (exact:
//             a rounded body's distance is its core's minus the radii);
//   compound  the sphere hierarchies: a node pair whose bound is above the
//             margin is pruned, and the first piece pair proved within
//             ends the traversal;
//   mesh      the same over the box hierarchies, triangle pair by triangle
//             pair, then the inside test of closed meshes (a surface inside
//             a closed mesh is within any margin).
// Tracking: the caches are the distance query's (DistanceCache,
// CompoundCache, MeshCache, BodyCache) and a margin query keeps them warm
// for either query.
//
// Thread safety: as for distance() (the bodies are shared, a cache belongs
// to one pair at a time).
#pragma once

#include <cstdint>
#include <limits>

#include "proxima/core/types.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/body.h"
#include "proxima/shape/compound.h"
#include "proxima/shape/mesh.h"
#include "proxima/shape/polytope.h"

namespace proxima {

enum class MarginStatus : std::uint8_t {
  within,     // proved: a witness pair at most margin + band apart
  beyond,     // proved: lower_bound > margin
  undecided,  // neither proof at the iteration cap (both bounds reported)
};

inline const char* to_string(MarginStatus s) {
  switch (s) {
    case MarginStatus::within:
      return "within";
    case MarginStatus::beyond:
      return "beyond";
    case MarginStatus::undecided:
      return "undecided";
  }
  return "unknown";
}

// The answer of a margin (or boolean) query, world frame.
struct MarginResult {
  MarginStatus status = MarginStatus::beyond;
  double margin = 0.0;  // the margin asked for
  // Certified: lower_bound <= the bodies' distance; above the margin when
  // beyond. A within answer reports the bound it had when it stopped (0
  // when none was needed).
  double lower_bound = 0.0;
  // |point_a - point_b|, an upper bound on the distance (+infinity when
  // the query stopped before finding any pair).
  double upper_bound = std::numeric_limits<double>::infinity();
  // Within: the witness, a point of A (on or in it, within the band) and
  // one of B at most margin + band apart (the same point when the bodies
  // overlap and it was found that way). Otherwise the closest pair met.
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  // Where the witness lies: pieces of compounds, triangles of meshes (-1
  // for another kind, or when no pair was met).
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
  std::int32_t triangle_a = -1;
  std::int32_t triangle_b = -1;
  // The work done: leaf queries (convex pairs, triangle pairs) and the
  // hybrid's iterations.
  int pairs_tested = 0;
  int iterations = 0;

  bool is_within() const { return status == MarginStatus::within; }
};

// Whether two convex hulls are within `margin` (finite, >= 0) of each
// other. With Algorithm::hybrid (the default) the loop stops at the first
// proof; GJK and Enhanced GJK answer through their full distance query.
// Throws InvalidInput for a bad margin, pose or options (named). `cache`
// may be null (cold). options.penetration does not apply (a margin answer
// has no depth): either value gives the same answer. The queries with a
// triangle mesh below take the mesh query's options (proxima/core/types.h,
// DistanceOptions): another algorithm, relative_tolerance or max_iterations
// than the defaults is refused with InvalidInput naming the field.
MarginResult within_margin(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options = {},
                           DistanceCache* cache = nullptr);
MarginResult within_margin(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options = {},
                           CompoundCache* cache = nullptr);
// Between the surfaces of two meshes (and their insides when closed), as
// the mesh distance query measures them (proxima/query/mesh_distance.h).
MarginResult within_margin(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options = {},
                           MeshCache* cache = nullptr);
// Any two bodies (rounded, compound, mesh, mixed), as distance() on Bodies
// measures them (proxima/query/body_distance.h).
MarginResult within_margin(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                           double margin, const DistanceOptions& options = {},
                           BodyCache* cache = nullptr);

// The boolean query: within_margin with margin 0 (touching or intersecting
// bodies are within).
inline MarginResult intersects(const ConvexPolytope& a, const Pose& pose_a,
                               const ConvexPolytope& b, const Pose& pose_b,
                               const DistanceOptions& options = {},
                               DistanceCache* cache = nullptr) {
  return within_margin(a, pose_a, b, pose_b, 0.0, options, cache);
}
inline MarginResult intersects(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                               const Pose& pose_b, const DistanceOptions& options = {},
                               CompoundCache* cache = nullptr) {
  return within_margin(a, pose_a, b, pose_b, 0.0, options, cache);
}
inline MarginResult intersects(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                               const Pose& pose_b, const DistanceOptions& options = {},
                               MeshCache* cache = nullptr) {
  return within_margin(a, pose_a, b, pose_b, 0.0, options, cache);
}
inline MarginResult intersects(const Body& a, const Pose& pose_a, const Body& b,
                               const Pose& pose_b, const DistanceOptions& options = {},
                               BodyCache* cache = nullptr) {
  return within_margin(a, pose_a, b, pose_b, 0.0, options, cache);
}

namespace detail {
// The convex margin query for poses already under the contract (a
// compound's placed pieces, a scene's stored poses), margin and options
// already checked.
MarginResult within_margin_of_rigid_poses(const ConvexPolytope& a, const Pose& pose_a,
                                          const ConvexPolytope& b, const Pose& pose_b,
                                          double margin, const DistanceOptions& options,
                                          DistanceCache& cache);
// The mesh margin query for poses already under the contract, margin and
// options already checked (a Body's meshes, a batch's rows).
MarginResult within_margin_of_rigid_poses(const TriangleMesh& a, const Pose& pose_a,
                                          const TriangleMesh& b, const Pose& pose_b,
                                          double margin, const DistanceOptions& options,
                                          MeshCache* cache);
// The Body margin query for poses already under the contract, margin and
// options already checked (a batch's rows of rigid poses).
MarginResult within_margin_of_rigid_poses(const Body& a, const Pose& pose_a, const Body& b,
                                          const Pose& pose_b, double margin,
                                          const DistanceOptions& options, BodyCache& cache);
// A certified lower bound on the distance between two balls (world
// centers and radii, each holding its body up to the rounding of the
// radius): the gap |c_a - c_b| - r_a - r_b less a slack for the rounding of
// the placed centers, the radii and the norm. O(1): the first test of every
// margin query, which ends it for bodies far apart.
double sphere_gap_lower_bound(const Vec3& center_a, double radius_a, const Vec3& center_b,
                              double radius_b);
}  // namespace detail

}  // namespace proxima
