// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A robot's self and environment signed distances with their joint-space
// gradients (proxima/robot/robot_distance.h).
#include "proxima/robot/robot_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "query/parallel_ranges.h"

namespace proxima {

Obstacle::Obstacle(Body body_in, const Pose& pose_in, std::string name_in)
    : body(std::move(body_in)),
      pose(checked_pose(pose_in, [&] { return "obstacle \"" + name_in + "\" pose"; })),
      name(std::move(name_in)) {
  const BoundingSphere sphere = bounding_sphere(body);
  center = pose.apply(sphere.center);
  radius = sphere.radius;
  box = bounding_box(body);
}

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Lower bounds on a signed distance. Two spheres: |c_a - c_b| - r_a - r_b
// (the bodies' overlap is at most the spheres'). A sphere against a box
// (in the box's frame, the body's radius around it): the distance from the
// centre to the box, minus both radii.
double sphere_bound(const Vec3& center_a, double radius_a, const Vec3& center_b, double radius_b) {
  return (center_a - center_b).norm() - radius_a - radius_b;
}

double box_bound(const Vec3& center, double radius, const Obstacle& obstacle) {
  const Vec3 local = obstacle.pose.rotation.transpose() * (center - obstacle.pose.translation);
  const Vec3 outside =
      ((local - obstacle.box.center).cwiseAbs() - obstacle.box.half_extents).cwiseMax(0.0);
  return outside.norm() - radius - obstacle.body.radius();
}

// How far any point within `radius` of a body's sphere centre (`local`, in
// the frame that moved from `before` to `after`) has moved: the centre's
// displacement plus |R_after - R_before|_2 radius, bounded by the Frobenius
// norm.
double motion(const Pose& before, const Pose& after, const Vec3& local, double radius) {
  return (after.apply(local) - before.apply(local)).norm() +
         (after.rotation - before.rotation).norm() * radius;
}

const void* core_of(const Body& body) {
  if (body.convex()) return body.convex().get();
  if (body.mesh()) return body.mesh().get();
  return body.compound().get();
}

void fill_gradient(const Robot& robot, std::span<const Pose> poses, RobotPairResult& pair) {
  pair.gradient = Eigen::VectorXd::Zero(robot.dof());
  const BodyResult& r = pair.result;
  // An overlap whose depth was not computed (a mesh's) has the certificate
  // [-infinity, 0] and no normal to differentiate along.
  pair.has_gradient = std::isfinite(r.signed_lower_bound());
  if (!pair.has_gradient) return;
  const std::span<double> g(pair.gradient.data(), static_cast<std::size_t>(pair.gradient.size()));
  const auto& geometries = robot.geometries();
  robot.add_directional_derivative(poses,
                                   geometries[static_cast<std::size_t>(pair.geometry_a)].link,
                                   r.point_a, r.normal, -1.0, g);
  if (!pair.environment) {
    robot.add_directional_derivative(poses,
                                     geometries[static_cast<std::size_t>(pair.geometry_b)].link,
                                     r.point_b, r.normal, 1.0, g);
  }
}

bool by_geometries(const RobotPairResult& x, const RobotPairResult& y) {
  return x.geometry_a != y.geometry_a ? x.geometry_a < y.geometry_a : x.geometry_b < y.geometry_b;
}

}  // namespace

RobotDistances robot_distances(const Robot& robot, std::span<const double> q,
                               std::span<const Obstacle> obstacles,
                               const RobotQueryOptions& options, RobotQueryState* state) {
  if (!(options.margin >= 0) || std::isinf(options.margin)) {
    throw InvalidInput("robot query: margin " + std::to_string(options.margin) +
                       " is not a finite value >= 0");
  }
  RobotQueryState local;
  RobotQueryState& s = state != nullptr ? *state : local;
  const auto& geometries = robot.geometries();
  const auto& pairs = robot.self_pairs();
  const std::size_t n_geometries = geometries.size();
  if (s.robot_ != &robot || s.obstacles_ != obstacles.size() || s.self_.size() != pairs.size() ||
      s.motion_.size() != n_geometries) {
    s.reset();
    s.robot_ = &robot;
    s.obstacles_ = obstacles.size();
    s.self_.resize(pairs.size());
    s.environment_.resize(n_geometries * obstacles.size());
    s.self_bound_.assign(pairs.size(), -kInfinity);
    s.environment_bound_.assign(n_geometries * obstacles.size(), -kInfinity);
    s.motion_.assign(n_geometries, kInfinity);
    s.obstacle_poses_.resize(obstacles.size());
    s.obstacle_cores_.assign(obstacles.size(), nullptr);
    s.obstacle_radii_.assign(obstacles.size(), 0.0);
    s.obstacle_motion_.assign(obstacles.size(), kInfinity);
  }
  std::swap(s.link_poses_, s.previous_link_poses_);
  robot.forward_kinematics(q, options.base, s.link_poses_);
  const bool moved_before = s.previous_link_poses_.size() == s.link_poses_.size();
  const auto& spheres = robot.geometry_spheres();
  s.geometry_poses_.resize(n_geometries);
  s.centers_.resize(n_geometries);
  for (std::size_t g = 0; g < n_geometries; ++g) {
    const auto link = static_cast<std::size_t>(geometries[g].link);
    s.geometry_poses_[g] = s.link_poses_[link] * geometries[g].origin;
    s.centers_[g] = s.link_poses_[link].apply(spheres[g].center);
    s.motion_[g] = moved_before ? motion(s.previous_link_poses_[link], s.link_poses_[link],
                                         spheres[g].center, spheres[g].radius)
                                : kInfinity;
  }
  for (std::size_t o = 0; o < obstacles.size(); ++o) {
    // An obstacle replaced by another body (or radius) starts over.
    const void* core = core_of(obstacles[o].body);
    if (core != s.obstacle_cores_[o] || obstacles[o].body.radius() != s.obstacle_radii_[o]) {
      s.obstacle_cores_[o] = core;
      s.obstacle_radii_[o] = obstacles[o].body.radius();
      s.obstacle_motion_[o] = kInfinity;
    } else {
      s.obstacle_motion_[o] =
          motion(s.obstacle_poses_[o], obstacles[o].pose,
                 obstacles[o].pose.inverse().apply(obstacles[o].center), obstacles[o].radius);
    }
    s.obstacle_poses_[o] = obstacles[o].pose;
  }

  RobotDistances out;
  const auto report = [&](RobotPairResult&& pair, double& category_min, std::int32_t index,
                          std::int32_t& last) {
    const double sd = pair.result.signed_distance();
    const bool closest = sd < out.min_signed_distance;
    if (sd < category_min) {
      category_min = sd;
      last = index;
    }
    if (!closest && sd > options.margin) return;
    if (options.gradients) fill_gradient(robot, s.link_poses_, pair);
    if (closest) {
      out.min_signed_distance = sd;
      out.closest = pair;
    }
    if (sd <= options.margin) out.close_pairs.push_back(std::move(pair));
  };
  // Each pair's bound decays by the motion first (every pair, queried or
  // not, whatever options.self and options.environment say), so that it
  // stays a bound at the next query too.
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    s.self_bound_[p] -= s.motion_[static_cast<std::size_t>(pairs[p].a)] +
                        s.motion_[static_cast<std::size_t>(pairs[p].b)];
  }
  for (std::size_t g = 0; g < n_geometries; ++g) {
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
      s.environment_bound_[g * obstacles.size() + o] -= s.motion_[g] + s.obstacle_motion_[o];
    }
  }

  if (options.self && !pairs.empty()) {
    // The last closest pair first: its distance is likely the smallest
    // again, and it prunes the others.
    const std::int32_t first = s.last_self_ >= 0 ? s.last_self_ : 0;
    std::int32_t last = -1;
    const auto n = static_cast<std::int32_t>(pairs.size());
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const GeometryPair& pair = pairs[static_cast<std::size_t>(p)];
      const auto a = static_cast<std::size_t>(pair.a), b = static_cast<std::size_t>(pair.b);
      double& bound = s.self_bound_[static_cast<std::size_t>(p)];
      const double threshold = std::max(options.margin, out.min_self);
      if (bound > threshold) continue;
      bound = std::max(
          bound, sphere_bound(s.centers_[a], spheres[a].radius, s.centers_[b], spheres[b].radius));
      if (bound > threshold) continue;
      ++out.pairs_queried;
      RobotPairResult result;
      result.geometry_a = pair.a;
      result.geometry_b = pair.b;
      result.result =
          distance(geometries[a].body, s.geometry_poses_[a], geometries[b].body,
                   s.geometry_poses_[b], options.distance, &s.self_[static_cast<std::size_t>(p)]);
      bound = result.result.signed_lower_bound();
      report(std::move(result), out.min_self, p, last);
    }
    if (last >= 0) s.last_self_ = last;
  }
  // The self part was visited from `first` on: back to self_pairs() order.
  std::sort(out.close_pairs.begin(), out.close_pairs.end(), by_geometries);
  const std::size_t self_reported = out.close_pairs.size();

  if (options.environment && !obstacles.empty() && n_geometries > 0) {
    const auto n_obstacles = static_cast<std::int32_t>(obstacles.size());
    const auto n = static_cast<std::int32_t>(n_geometries) * n_obstacles;
    const std::int32_t first = s.last_environment_ >= 0 ? s.last_environment_ : 0;
    std::int32_t last = -1;
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const auto g = static_cast<std::size_t>(p / n_obstacles);
      const auto o = static_cast<std::size_t>(p % n_obstacles);
      double& bound = s.environment_bound_[static_cast<std::size_t>(p)];
      const double threshold = std::max(options.margin, out.min_environment);
      if (bound > threshold) continue;
      bound = std::max(bound, box_bound(s.centers_[g], spheres[g].radius, obstacles[o]));
      if (bound > threshold) continue;
      ++out.pairs_queried;
      RobotPairResult result;
      result.geometry_a = static_cast<std::int32_t>(g);
      result.geometry_b = static_cast<std::int32_t>(o);
      result.environment = true;
      result.result =
          distance(geometries[g].body, s.geometry_poses_[g], obstacles[o].body, obstacles[o].pose,
                   options.distance, &s.environment_[static_cast<std::size_t>(p)]);
      bound = result.result.signed_lower_bound();
      report(std::move(result), out.min_environment, p, last);
    }
    if (last >= 0) s.last_environment_ = last;
    std::sort(out.close_pairs.begin() + static_cast<std::ptrdiff_t>(self_reported),
              out.close_pairs.end(), by_geometries);
  }
  return out;
}

RobotBatchDistances robot_distances_batch(const Robot& robot, const RowMatrixXd& q,
                                          std::span<const Obstacle> obstacles,
                                          const RobotQueryOptions& options, int threads) {
  if (q.cols() != robot.dof()) {
    throw InvalidInput("robot batch: the configurations have " + std::to_string(q.cols()) +
                       " columns, the robot " + std::to_string(robot.dof()) + " variables");
  }
  if (threads < 0) throw InvalidInput("robot batch: threads " + std::to_string(threads) + " < 0");
  RobotBatchDistances out;
  const auto k = static_cast<std::size_t>(q.rows());
  out.min_signed_distance.resize(q.rows());
  if (options.gradients) out.gradient = RowMatrixXd::Zero(q.rows(), robot.dof());
  RobotQueryOptions run_options = options;
  run_options.margin = 0.0;
  // Runs long enough that tracking pays along a trajectory, short enough
  // that two threads share a batch of a few thousand evenly.
  constexpr std::size_t kRun = 64;
  detail::parallel_chunks(k, kRun, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    RobotQueryState state;
    for (std::size_t row = begin; row < end; ++row) {
      const auto r = static_cast<Eigen::Index>(row);
      const RobotDistances d = robot_distances(
          robot, std::span<const double>(q.row(r).data(), static_cast<std::size_t>(q.cols())),
          obstacles, run_options, &state);
      out.min_signed_distance[r] = d.min_signed_distance;
      if (options.gradients && d.closest.geometry_a >= 0) {
        out.gradient.row(r) = d.closest.gradient.transpose();
      }
    }
  });
  return out;
}

}  // namespace proxima
