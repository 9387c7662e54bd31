// proxima benchmarks: a scene of many moving bodies in FCL 0.7, the peer of
// proxima::Scene in the scene benchmark (issue 6).
// SPDX-License-Identifier: BSD-3-Clause
//
// What FCL runs, as an FCL user would write it (the reasons are at the top
// of fcl_scene.cpp):
//   bodies        one fcl::CollisionObjectd per body, its geometry an
//                 fcl::Convexd built from the SAME hull as proxima's (as in
//                 fcl_peer.cpp); bodies of one pool shape share one Convexd.
//   broad phase   fcl::DynamicAABBTreeCollisionManagerd, all objects
//                 registered once.
//   each step     setTransform + computeAABB for every object (set_poses),
//                 then manager.update() and manager.distance(&data,
//                 callback) (step).
//   callback      fcl::distance(o1, o2, request, result) on the candidate
//                 pair (enable_nearest_points, GST_LIBCCD by default: FCL's
//                 faster and more accurate solver on cold queries of 20 to
//                 200 vertices in the paper experiments, and a broad-phase callback
//                 is a cold query), records the pair when its distance is at
//                 most the margin, and returns the margin as its running
//                 bound so that FCL visits every pair of boxes closer than
//                 the margin, not only the nearest pair.
// FCL's own code makes NaNs and divides by zero on its way (libccd on
// degenerate simplices): every call into FCL runs with the caller's
// floating-point traps off, and the caller's environment is restored after.
// FCL's headers stay in fcl_scene.cpp.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <vector>

#include "peers/fcl_peer.h"
#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::bench {

// How each object's world box is computed every step.
enum class FclBoxes {
  // CollisionObject::computeAABB, what FCL users get: for a rotated object,
  // the bounding sphere of its local box (centre +- the local box's half
  // diagonal), up to sqrt(3) times wider than the body.
  fcl,
  // The tight box of the transformed hull vertices (fcl::computeBV), set
  // through a CollisionObject subclass: not something FCL's API offers for
  // a CollisionObject, but it shows how much of the difference is the box.
  tight,
};

// One pair of bodies within the margin, as FCL reports it.
struct FclClosePair {
  int a = -1;  // body indices, a < b
  int b = -1;
  // FCL's min_distance; -1 when FCL's solver reports the bodies in collision.
  double distance = 0.0;
  Vec3 point_a = Vec3::Zero();  // FCL's nearest points, world frame
  Vec3 point_b = Vec3::Zero();
};

// What the last step did.
struct FclSceneStats {
  int bodies = 0;
  int candidate_pairs = 0;     // pairs FCL's traversal handed to the callback
  int close_pairs = 0;         // of those, at distance <= margin (or colliding)
  int intersecting_pairs = 0;  // of those, colliding (distance -1)
};

class FclScene {
 public:
  // Body i uses shapes[shape_of[i]] at poses[i]. The polytopes are copied
  // into FCL's geometry; they need not outlive the scene. Throws
  // InvalidInput for a negative or non-finite margin, mismatched sizes, a
  // shape index out of range or a shape that is not solid (fcl::Convex
  // needs dimension 3).
  FclScene(std::span<const std::shared_ptr<const ConvexPolytope>> shapes,
           std::span<const int> shape_of, std::span<const Pose> poses, double margin,
           FclSolver solver = FclSolver::libccd, FclBoxes boxes = FclBoxes::fcl);
  ~FclScene();
  FclScene(const FclScene&) = delete;
  FclScene& operator=(const FclScene&) = delete;

  int body_count() const;
  double margin() const;

  // Moves every body: setTransform and the box (computeAABB, or the tight
  // box) on each object. Throws
  // InvalidInput when the count differs from body_count().
  void set_poses(std::span<const Pose> poses);
  // manager.update() and manager.distance(): the close pairs in the order
  // FCL's traversal found them (not sorted; sort_by_bodies sorts them
  // outside the timed work). Valid until the next step().
  std::span<const FclClosePair> step();
  const FclSceneStats& stats() const;

  // The slow, obvious twin of step(): fcl::distance with the same request on
  // every pair of bodies, no broad phase; sorted by (a, b). For tests.
  std::vector<FclClosePair> close_pairs_all_pairs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Sorts close pairs by (a, b), the order of proxima::Scene::step().
void sort_by_bodies(std::vector<FclClosePair>& pairs);

// A close pair of another system (proxima), for the comparison below:
// distance 0 for intersecting or touching bodies.
struct ReferencePair {
  int a = -1;
  int b = -1;
  double distance = 0.0;
};

// How FCL's close pairs differ from a reference set of the same step. Two
// distances agree when |max(fcl, 0) - reference| <= tolerance(reference),
// with tolerance(d) = relative_tolerance * d + absolute_tolerance (FCL's
// own stopping rule is absolute: distance_tolerance 1e-6 by default, and
// FCL reports a colliding pair as -1). A pair in one set only is a
// `boundary` pair when its distance lies within that tolerance of the
// margin, where FCL's error alone can decide the side; any other pair in
// one set only is a real mismatch.
struct PairSetDifference {
  int common = 0;
  int only_fcl = 0;
  int only_reference = 0;
  int boundary = 0;             // of only_fcl + only_reference, within tolerance of the margin
  int distance_mismatches = 0;  // common pairs whose distances disagree
  double worst_absolute = 0.0;  // largest |max(fcl, 0) - reference| over common pairs
  double worst_relative = 0.0;  // largest of those divided by the reference distance (> 0 only)
  int mismatches() const { return only_fcl + only_reference - boundary + distance_mismatches; }
};

// Both spans sorted by (a, b). With `mismatched`, appends each mismatched
// pair (not the boundary ones) as (a, b).
PairSetDifference compare_close_pairs(std::span<const FclClosePair> fcl,
                                      std::span<const ReferencePair> reference, double margin,
                                      double relative_tolerance, double absolute_tolerance,
                                      std::vector<std::array<int, 2>>* mismatched = nullptr);

}  // namespace proxima::bench
