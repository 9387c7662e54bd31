// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The distance between triangle meshes (proxima/shape/mesh.h), and between a
// mesh and a convex polytope: exact distance between the surfaces, closest
// triangles and features, with the caller-owned cache that tracks it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/shape/mesh.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// Coherence between mesh queries of one pair, owned by the caller.
// Default-constructed means cold. It keeps the closest triangle pair of the
// last answer (its distance is the first upper bound of the next search)
// and, while the motion between queries is small, the few triangle pairs
// that can still be the closest (all others were farther by a margin when
// they were collected): a tracked query then tests only those, exactly. A
// cache of another pair of meshes is recognized by the meshes' ids: at
// worst slower, never wrong.
struct MeshCache {
  std::uint64_t mesh_a = 0;  // TriangleMesh::id() of the pair
  std::uint64_t mesh_b = 0;
  std::int32_t triangle_a = -1;  // closest pair of the last answer
  std::int32_t triangle_b = -1;
  // The candidate pairs, closest first: every triangle pair whose distance
  // was within 2 margin of base_distance (the best then) when B's pose in
  // A's frame was (rotation, translation). While B has moved less than
  // `margin` from there, every other pair is farther than the best of
  // these, so a query tests only them. Empty: no list (the next query
  // searches, from the last closest pair).
  std::vector<std::array<std::int32_t, 2>> near;
  double base_distance = 0.0;
  double margin = 0.0;
  Mat3 rotation = Mat3::Zero();
  Vec3 translation = Vec3::Zero();
  // B's pose in A's frame at the last query, to measure the last step.
  Mat3 last_rotation = Mat3::Zero();
  Vec3 last_translation = Vec3::Zero();
  // The containment found when `near` was collected (-1: unknown, 0: no, 1:
  // a component of B inside A's closed mesh, 2: one of A inside B's) and
  // the contained vertex (of B for 1, of A for 2); valid while the motion
  // is below base_distance.
  std::int8_t inside = -1;
  std::int32_t inside_vertex = -1;
  // Collecting a list costs a wider search; when lists do not pay (too many
  // pairs within the margin, or the motion outran the margin before the
  // list was used once), the next collections wait `list_wait` queries, a
  // wait that doubles with each failure (up to 32) and ends with a use.
  std::uint16_t list_uses = 0;  // queries the current list has answered
  std::uint8_t list_backoff = 0;
  std::uint8_t list_wait = 0;
  // The tracking state of the query between the meshes' hulls
  // (TriangleMesh::hull()), whose lower bound certifies the closest
  // triangle pair of a tracked query when that pair reaches it.
  DistanceCache hull;
  // Hulls that overlap give no bound: after such an answer the next
  // distance queries skip the hulls for `hull_wait` queries, a wait that
  // doubles with each overlap (up to 32) and ends when the hulls are apart
  // (a body moving inside another's hull pays no hull query per step).
  std::uint8_t hull_backoff = 0;
  std::uint8_t hull_wait = 0;

  bool is_cold() const { return triangle_a < 0; }
  void reset() { *this = MeshCache{}; }
};

// The answer of a mesh query, in the conventions of DistanceResult
// (distance.h): closest points and normal in the world frame, status with
// the contact band of the accuracy standard, a certified lower bound. The
// features are those of the closest triangles, with mesh vertex ids (a
// degenerate triangle's features are its vertices and edges); `face` is the
// triangle index for a face feature. The penetration depth is not computed:
// an intersecting answer has distance 0, depth 0 and depth_upper_bound
// +infinity (as with DistanceOptions::penetration false).
struct MeshResult : DistanceResult {
  std::int32_t triangle_a = -1;  // the closest triangles (indices as given)
  std::int32_t triangle_b = -1;
  int pairs_tested = 0;  // triangle-triangle distances computed
  int nodes_tested = 0;  // node-pair bounds computed
  bool tracked = false;  // answered from the cache's candidate pairs
};

// Minimum distance between the surfaces of two meshes, each at its pose.
// Status:
//   - intersecting: the surfaces cross (an edge of one passes through the
//     other triangle's interior with its ends farther than the contact band
//     64 u R on either side of its plane, decided with exact predicates), or
//     a connected component of one surface lies inside the other mesh, when
//     that mesh is closed (TriangleMesh::contains). The points are then
//     one common point, distance 0: a crossing point, or a vertex of the
//     contained component.
//   - touching: distance <= 64 u R + options.absolute_tolerance otherwise.
//   - separated: otherwise. An open mesh has no inside: a body within an
//     open (or inconsistently oriented) mesh is separated from it by the
//     distance between the surfaces.
// The distance is that of the exact closest points of the two triangle
// sets within the accuracy standard (R the largest coordinate magnitude of
// both meshes in the world frame or in A's). Uses options.absolute_tolerance;
// a non-default algorithm, relative_tolerance or max_iterations does not
// apply and is refused with InvalidInput naming the field, as are a pose
// outside the contract of pose.h and options outside their checks.
MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                    const Pose& pose_b, const DistanceOptions& options = {},
                    MeshCache* cache = nullptr);

// The slow, obvious twin: every triangle pair, the same kernel and the same
// status rules. For tests and benchmarks.
MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                              const Pose& pose_b, const DistanceOptions& options = {});

// Minimum distance between a mesh and a convex polytope (a solid), each at
// its pose: the mesh's hierarchy against the polytope's box in the mesh's
// frame, the convex query (distance.h) between each near triangle (as a
// polytope of its three vertices) and the polytope at the leaves.
// triangle_b is -1; feature_b is the polytope's (hull vertex ids, as
// DistanceResult gives them); feature_a the triangle's, with mesh vertex
// ids. Status: intersecting when a triangle overlaps the polytope (deeper
// than the contact band, as the convex query decides: a mesh inside the
// polytope is intersecting) or when the polytope lies inside the mesh, if
// the mesh is closed; touching and separated as in the convex query. An
// intersecting answer's points are one common point (a point of the
// overlapping triangle and the polytope, or the polytope's vertex inside
// the mesh). The depth is not computed (distance 0, depth_upper_bound +infinity). A
// rounded body (core plus radius r, body.h) is the core's answer offset by
// r along the normal: the closest triangle is the same.
//
// options.algorithm and max_iterations apply to the convex query at each
// leaf; a relative_tolerance other than the default is refused (the search
// stops at A's hull's bound to 1e-12), as in the mesh-mesh query.
//
// The cache keeps the last closest triangle (triangle_a), whose distance is
// the first upper bound; any cache is range-checked (never wrong).
MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                    const Pose& pose_b, const DistanceOptions& options = {},
                    MeshCache* cache = nullptr);

// Its slow twin: the convex query against every triangle.
MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                              const Pose& pose_b, const DistanceOptions& options = {});

}  // namespace proxima
