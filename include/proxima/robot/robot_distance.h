// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: a robot's signed distances at a configuration q: to itself (the
// enabled self pairs, Robot::self_pairs) and to an environment of obstacles
// (any proxima Bodies with world poses), the pairs within a margin with
// their closest points, normals and features, and each pair's gradient with
// respect to q.
//
//   proxima::RobotQueryState state;          // cold; keep it along a trajectory
//   proxima::RobotQueryOptions options;
//   options.margin = 0.05;
//   options.gradients = true;
//   for (const auto& q : trajectory) {
//     auto r = proxima::robot_distances(robot, q, obstacles, options, &state);
//     r.min_signed_distance, r.closest.gradient, r.close_pairs ...
//   }
//
// Every pair is a tracked distance() (proxima/query/body_distance.h) whose cache lives in
// the state: along a trajectory, a pair whose closest features did not
// change costs one local computation. A pair is not queried when a lower
// bound on its signed distance exceeds both the margin and the smallest
// signed distance found so far (in its category: self or environment): it
// cannot be the closest nor within the margin. The bounds: the bounding
// spheres' distance (a geometry's sphere against an obstacle's box), and,
// the gap between the two bodies' boxes (each geometry's core box,
// oriented with it, grown by its radius) along two axes, the line of their
// centres and the pair's normal at its last query; and, along a trajectory,
// the pair's certified lower bound at its last query minus how far any
// point of either body has moved since (conservative advancement's bound:
// the centre's displacement plus the rotation's change times the radius). The answer is that of the slow path, a cold distance()
// on every pair, within the accuracy standard.
//
// The gradient of a pair's signed distance s = n . (p_b - p_a) (n the unit
// normal from A towards B, p_a and p_b the witness points) with respect to
// q is, by the envelope theorem (proxima/query/signed_distance.h), the motion of
// the witness points along the normal:
//   ds/dq = n^T (J_b(p_b) - J_a(p_a)),
// J the point Jacobians of the links (Robot::point_jacobian), zero for an
// obstacle. The radius of a rounded body moves its witness point along n,
// which changes nothing in n^T J. Where the witness pair is not unique the
// gradient is that of one active pair (a subgradient), as for poses.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/robot/robot.h"

namespace proxima {

// A body that does not move with the robot, at a world pose.
struct Obstacle {
  Obstacle(Body body, const Pose& pose, std::string name = "");
  Body body;
  Pose pose;
  std::string name;
  // Bounding sphere in world coordinates, and the core's bounding box in
  // the body's frame (from the body and the pose).
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
  BoundingBox box;
};

struct RobotQueryOptions {
  // Every pair whose signed distance is at most `margin` is reported in
  // close_pairs (0: the touching and overlapping ones).
  double margin = 0.0;
  // Whether each reported pair (and the closest) carries its gradient.
  bool gradients = false;
  // Only the minimum (a collision check, an optimizer's one constraint):
  // close_pairs stays empty and the margin is not read, so a pair is
  // queried only while its lower bound is below the smallest signed
  // distance of its category found so far (an overlapping pair whose
  // bounds show it cannot be the deepest costs no penetration depth).
  // min_signed_distance, min_self, min_environment and closest are those
  // of the full query.
  bool minimum_only = false;
  // Which pairs are tested.
  bool self = true;
  bool environment = true;
  // The root link's pose in the world (where the robot stands).
  Pose base;
  DistanceOptions distance;
};

struct RobotPairResult {
  std::int32_t geometry_a = -1;  // a robot geometry (Robot::geometries())
  // Another robot geometry, or for an environment pair the obstacle's index.
  std::int32_t geometry_b = -1;
  bool environment = false;
  BodyResult result;  // world frame, A the robot's geometry
  // d signed_distance / d q (length dof) when asked for; empty otherwise,
  // and zero for an overlap whose depth is not computed (a mesh's, see
  // proxima/query/body_distance.h), which has no gradient (has_gradient false).
  Eigen::VectorXd gradient;
  bool has_gradient = false;
  double signed_distance() const { return result.signed_distance(); }
};

struct RobotDistances {
  // The smallest signed distance over the tested pairs, over self pairs and
  // over environment pairs; +infinity when there is no pair.
  double min_signed_distance = std::numeric_limits<double>::infinity();
  double min_self = std::numeric_limits<double>::infinity();
  double min_environment = std::numeric_limits<double>::infinity();
  // The pair of min_signed_distance (geometry_a -1 when there is no pair),
  // with its gradient when asked for.
  RobotPairResult closest;
  // Every pair within the margin: self pairs in self_pairs() order, then
  // environment pairs by geometry and obstacle.
  std::vector<RobotPairResult> close_pairs;
  // How many pairs got a distance query (the others were pruned by their
  // bounding spheres).
  int pairs_queried = 0;
};

namespace detail {
class RobotQuery;  // one robot_distances call (robot/robot_distance.cpp)
}  // namespace detail

// The coherence of one robot's queries, owned by the caller;
// default-constructed means cold. Sized for the robot and obstacle count
// of the query it is given to (and reset when they change). One thread at a
// time.
class RobotQueryState {
 public:
  void reset() { *this = RobotQueryState{}; }
  // The link poses of the last query (world from link).
  const std::vector<Pose>& link_poses() const { return link_poses_; }

 private:
  friend class detail::RobotQuery;
  const Robot* robot_ = nullptr;
  std::size_t obstacles_ = 0;
  std::vector<BodyCache> self_;
  std::vector<BodyCache> environment_;  // geometry major
  std::vector<Pose> link_poses_;
  std::vector<Pose> geometry_poses_;
  std::vector<Vec3> centers_;
  std::vector<Vec3> box_centers_;           // per geometry, world
  std::vector<Vec3> obstacle_box_centers_;  // per obstacle, world
  // Per pair: the unit normal of its last query (world; zero before the
  // first), the axis of its box bound.
  std::vector<Vec3> self_normal_;
  std::vector<Vec3> environment_normal_;
  // Per pair: a lower bound on its signed distance at the last query (the
  // bookkeeping of conservative advancement, see above), and what it was
  // measured against.
  std::vector<double> self_bound_;
  std::vector<double> environment_bound_;
  std::vector<Pose> previous_link_poses_;
  std::vector<double> motion_;  // per geometry, since the last query
  std::vector<Pose> obstacle_poses_;
  std::vector<const void*> obstacle_cores_;
  std::vector<double> obstacle_radii_;
  std::vector<double> obstacle_motion_;
  std::int32_t last_self_ = -1;
  std::int32_t last_environment_ = -1;
};

// The query above. Throws InvalidInput for a joint vector of the wrong
// length or with a non-finite entry (naming the joint), a negative or NaN
// margin, or a bad base pose. `state` may be null (cold).
RobotDistances robot_distances(const Robot& robot, std::span<const double> q,
                               std::span<const Obstacle> obstacles,
                               const RobotQueryOptions& options = {},
                               RobotQueryState* state = nullptr);

// K configurations at once, one per row of `q` (K x dof): each row's
// smallest signed distance and, with options.gradients, its gradient (row k
// of `gradient`, K x dof; empty otherwise). Rows are split into runs of
// consecutive configurations spread over `threads` threads (0: all cores);
// each run is tracked in its own state, so a batch along a trajectory is
// cheap. close_pairs are not collected. The answers are those of
// robot_distances on each row, within the accuracy standard.
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
struct RobotBatchDistances {
  Eigen::VectorXd min_signed_distance;
  RowMatrixXd gradient;
};
RobotBatchDistances robot_distances_batch(const Robot& robot, const RowMatrixXd& q,
                                          std::span<const Obstacle> obstacles,
                                          const RobotQueryOptions& options = {}, int threads = 0);

}  // namespace proxima
