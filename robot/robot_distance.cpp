// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A robot's self and environment signed distances with their joint-space
// gradients (proxima/robot/robot_distance.h).
#include "proxima/robot/robot_distance.h"

#include <cmath>
#include <string>

#include "parallel_ranges.h"

namespace proxima {

Obstacle::Obstacle(Body body_in, const Pose& pose_in, std::string name_in)
    : body(std::move(body_in)),
      pose(checked_pose(pose_in, [&] { return "obstacle \"" + name_in + "\" pose"; })),
      name(std::move(name_in)) {
  const BoundingSphere sphere = bounding_sphere(body);
  center = pose.apply(sphere.center);
  radius = sphere.radius;
}

namespace {

// A pair of spheres farther apart than `threshold` holds no pair of points
// closer than it: |c_a - c_b| - r_a - r_b is a lower bound on the signed
// distance of the bodies inside (their overlap is at most the spheres').
bool spheres_beyond(const Vec3& center_a, double radius_a, const Vec3& center_b, double radius_b,
                    double threshold) {
  const double reach = radius_a + radius_b + threshold;
  return reach < 0 || (center_a - center_b).squaredNorm() > reach * reach;
}

void fill_gradient(const Robot& robot, std::span<const Pose> poses, RobotPairDistance& pair) {
  pair.gradient = Eigen::VectorXd::Zero(robot.dof());
  const BodyDistance& r = pair.result;
  // An overlap whose depth was not computed (a mesh's) has the certificate
  // [-infinity, 0] and no normal to differentiate along.
  pair.has_gradient = std::isfinite(r.signed_lower_bound());
  if (!pair.has_gradient) return;
  const std::span<double> g(pair.gradient.data(), static_cast<std::size_t>(pair.gradient.size()));
  const auto& geometries = robot.geometries();
  robot.add_directional_derivative(poses, geometries[static_cast<std::size_t>(pair.geometry_a)].link,
                                   r.point_a, r.normal, -1.0, g);
  if (!pair.environment) {
    robot.add_directional_derivative(
        poses, geometries[static_cast<std::size_t>(pair.geometry_b)].link, r.point_b, r.normal,
        1.0, g);
  }
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
  if (s.robot_ != &robot || s.obstacles_ != obstacles.size() ||
      s.self_.size() != pairs.size()) {
    s.reset();
    s.robot_ = &robot;
    s.obstacles_ = obstacles.size();
    s.self_.resize(pairs.size());
    s.environment_.resize(geometries.size() * obstacles.size());
  }
  robot.forward_kinematics(q, options.base, s.link_poses_);
  const auto& spheres = robot.geometry_spheres();
  s.geometry_poses_.resize(geometries.size());
  s.centers_.resize(geometries.size());
  for (std::size_t g = 0; g < geometries.size(); ++g) {
    const Pose& link = s.link_poses_[static_cast<std::size_t>(geometries[g].link)];
    s.geometry_poses_[g] = link * geometries[g].origin;
    s.centers_[g] = link.apply(spheres[g].center);
  }

  RobotDistances out;
  const auto report = [&](RobotPairDistance&& pair, double& category_min,
                          std::int32_t index, std::int32_t& last) {
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

  if (options.self && !pairs.empty()) {
    // The last closest pair first: its distance is likely the smallest
    // again, and it prunes the others.
    const std::int32_t first = s.last_self_ >= 0 ? s.last_self_ : 0;
    std::int32_t last = -1;
    std::vector<RobotPairDistance> found;
    const auto n = static_cast<std::int32_t>(pairs.size());
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const GeometryPair& pair = pairs[static_cast<std::size_t>(p)];
      const auto a = static_cast<std::size_t>(pair.a), b = static_cast<std::size_t>(pair.b);
      if (spheres_beyond(s.centers_[a], spheres[a].radius, s.centers_[b], spheres[b].radius,
                         std::max(options.margin, out.min_self))) {
        continue;
      }
      ++out.pairs_queried;
      RobotPairDistance result;
      result.geometry_a = pair.a;
      result.geometry_b = pair.b;
      result.result = distance(geometries[a].body, s.geometry_poses_[a], geometries[b].body,
                               s.geometry_poses_[b], options.distance,
                               &s.self_[static_cast<std::size_t>(p)]);
      report(std::move(result), out.min_self, p, last);
    }
    s.last_self_ = last;
  }
  // close_pairs of the self part were found from `first` on: put them back
  // in self_pairs() order.
  std::sort(out.close_pairs.begin(), out.close_pairs.end(),
            [](const RobotPairDistance& x, const RobotPairDistance& y) {
              return x.geometry_a != y.geometry_a ? x.geometry_a < y.geometry_a
                                                  : x.geometry_b < y.geometry_b;
            });
  const std::size_t self_reported = out.close_pairs.size();

  if (options.environment && !obstacles.empty() && !geometries.empty()) {
    const auto n_obstacles = static_cast<std::int32_t>(obstacles.size());
    const auto n = static_cast<std::int32_t>(geometries.size()) * n_obstacles;
    const std::int32_t first = s.last_environment_ >= 0 ? s.last_environment_ : 0;
    std::int32_t last = -1;
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const auto g = static_cast<std::size_t>(p / n_obstacles);
      const auto o = static_cast<std::size_t>(p % n_obstacles);
      if (spheres_beyond(s.centers_[g], spheres[g].radius, obstacles[o].center,
                         obstacles[o].radius, std::max(options.margin, out.min_environment))) {
        continue;
      }
      ++out.pairs_queried;
      RobotPairDistance result;
      result.geometry_a = static_cast<std::int32_t>(g);
      result.geometry_b = static_cast<std::int32_t>(o);
      result.environment = true;
      result.result = distance(geometries[g].body, s.geometry_poses_[g], obstacles[o].body,
                               obstacles[o].pose, options.distance,
                               &s.environment_[static_cast<std::size_t>(p)]);
      report(std::move(result), out.min_environment, p, last);
    }
    s.last_environment_ = last;
    std::sort(out.close_pairs.begin() + static_cast<std::ptrdiff_t>(self_reported),
              out.close_pairs.end(), [](const RobotPairDistance& x, const RobotPairDistance& y) {
                return x.geometry_a != y.geometry_a ? x.geometry_a < y.geometry_a
                                                    : x.geometry_b < y.geometry_b;
              });
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
