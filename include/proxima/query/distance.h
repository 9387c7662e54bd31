// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the query API.
//
//   proxima::ConvexPolytope a(points_a), b(points_b);
//   proxima::DistanceCache cache;                 // cold
//   auto r = proxima::distance(a, pose_a, b, pose_b, {}, &cache);
//   // ... next step, bodies moved a little: pass the same cache (tracking)
//
// Thread safety: polytopes are immutable and may be shared between threads.
// A DistanceCache belongs to one pair at a time and must not be used by two
// threads at once; distinct caches may be used concurrently.
#pragma once

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

namespace proxima {

// Minimum distance, closest points and closest features of the two hulls
// placed at pose_a and pose_b. Throws InvalidInput for a non-finite pose.
// `cache` may be null (a cold query).
DistanceResult distance(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                        const Pose& pose_b, const DistanceOptions& options = {},
                        DistanceCache* cache = nullptr);

// The same for poses checked once (RigidPose, proxima/core/pose.h): the
// rigid-pose check of the overload above is not paid again; the answer is
// the one that overload gives for the RigidPoses' poses, bit for bit.
DistanceResult distance(const ConvexPolytope& a, const RigidPose& pose_a, const ConvexPolytope& b,
                        const RigidPose& pose_b, const DistanceOptions& options = {},
                        DistanceCache* cache = nullptr);

namespace detail {
// distance() for poses already under the contract of proxima/core/pose.h (checked
// and, where needed, re-orthonormalized by the caller: a Scene's stored
// poses, a compound's placed pieces), so that the check is not paid again
// on every query of a traversal or a step.
DistanceResult distance_of_rigid_poses(const ConvexPolytope& a, const Pose& pose_a,
                                       const ConvexPolytope& b, const Pose& pose_b,
                                       const DistanceOptions& options, DistanceCache* cache);
}  // namespace detail

}  // namespace proxima
