// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the signed distance's gradient with respect to the two poses.
//
// Every DistanceResult (and CompoundResult) carries the signed distance
// (proxima/core/types.h): the distance when the bodies are apart, minus the
// penetration depth when they overlap. Both sides have the same form,
//   sd = normal . (point_b - point_a),
// normal the unit direction from A towards B (separated: the closest
// points' direction; overlapping: the depth's separating direction), and
// point_a, point_b the witness points (closest or deepest). By the envelope
// theorem (sd is the optimum of a problem whose feasible set moves rigidly
// with each body) its derivative under a small motion of one body is the
// motion of that body's witness point along the normal:
//   B translated by d:                        d sd = normal . d
//   B rotated by w (world axes, about B's origin t_b):
//                                             d sd = w . ((point_b - t_b) x normal)
// and for A the same with -normal and point_a, t_a.
//
//   auto r = proxima::distance(a, pose_a, b, pose_b);
//   auto g = proxima::signed_distance_gradient(r, pose_a, pose_b);
//   // g.b.head<3>() = r.normal, g.b.tail<3>() = (r.point_b - t_b) x r.normal
#pragma once

#include <Eigen/Core>

#include "proxima/core/types.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/mesh_distance.h"

namespace proxima {

using Vec6 = Eigen::Matrix<double, 6, 1>;

// The gradient of the signed distance with respect to each body's pose: a
// 6-vector per body, translation first (d sd / d t, world frame), then
// rotation (d sd / d w for the pose's rotation R -> exp(w^) R, a small
// rotation about world axes through the body's origin, pose.translation).
struct SignedDistanceGradient {
  Vec6 a = Vec6::Zero();
  Vec6 b = Vec6::Zero();
};

// The gradient at the answer `result` of a query of two bodies placed at
// pose_a and pose_b (the poses of that query; for compound bodies, the
// bodies' poses, not the pieces'). Exact where the signed distance is
// differentiable: the witness pair unique (separated: a unique closest pair
// with distance > 0; overlapping: a unique deepest Minkowski face and a
// unique support point of each body along its normal). Elsewhere (parallel
// faces or edges, several faces of A - B equally deep, touching answers
// whose normal is at machine precision, a compound's tie between piece
// pairs) it is the gradient of one of the pieces the signed distance is the
// minimum of (a face of A - B or a closest pair): a one-sided derivative,
// valid as a subgradient of each active piece. Throws InvalidInput for an
// intersecting answer computed without the depth
// (DistanceOptions::penetration false: its normal is not the depth's).
SignedDistanceGradient signed_distance_gradient(const DistanceResult& result, const Pose& pose_a,
                                                const Pose& pose_b);

// The same for the answers that may involve a triangle mesh: an overlap
// with a mesh has no penetration depth (none is defined for a mesh: see
// docs/bodies.md for what to use instead, the hull or convex pieces), so an
// intersecting answer of a mesh pair is refused with that reason.
SignedDistanceGradient signed_distance_gradient(const MeshResult& result, const Pose& pose_a,
                                                const Pose& pose_b);
SignedDistanceGradient signed_distance_gradient(const BodyResult& result, const Pose& pose_a,
                                                const Pose& pose_b);

}  // namespace proxima
