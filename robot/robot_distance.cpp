// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A robot's self and environment signed distances with their joint-space
// gradients (proxima/robot/robot_distance.h).
#include "proxima/robot/robot_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/accuracy.h"
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
// (in the box's frame, the body's radius around it): the signed distance
// from the centre to the box, minus both radii. Signed: with the centre
// inside the box, the overlap can be as deep as the centre's distance to
// the box's boundary plus the radii (moving the sphere out through the
// nearest face separates them), so that distance is subtracted too.
double sphere_bound(const Vec3& center_a, double radius_a, const Vec3& center_b, double radius_b) {
  return (center_a - center_b).norm() - radius_a - radius_b;
}

double obstacle_box_bound(const Vec3& center, double radius, const Obstacle& obstacle) {
  const Vec3 local = obstacle.pose.rotation.transpose() * (center - obstacle.pose.translation);
  const Vec3 excess = (local - obstacle.box.center).cwiseAbs() - obstacle.box.half_extents;
  const double to_box = excess.maxCoeff() < 0 ? excess.maxCoeff() : excess.cwiseMax(0.0).norm();
  return to_box - radius - obstacle.body.radius();
}

// A body's box in the world: its core's box (centre, the columns of `axes`
// and the half extents), every point of the body within `radius` of it.
// Its support along a unit n is n.center + sum_i |n.axes_i| half_i + radius.
struct WorldBox {
  Vec3 center;
  const Mat3* axes;
  const Vec3* half_extents;
  double radius;
  double reach() const { return center.norm() + half_extents->norm() + radius; }
};

// The rounding of the box bound below, relative to the boxes' reach (the
// magnitudes it adds): its few dot products err by a few u of it, and a
// normal read from a result is unit within a few u. The same margin as the
// bounding spheres' (kBoundingSphereSlack in robot.cpp), far above both.
constexpr double kBoxBoundSlack = 1e-9;

// A lower bound on the signed distance of two bodies within boxes a and b:
// for any unit n, A lies in the half-space n.x <= h_A(n) and B in n.x >=
// -h_B(-n), so their distance is at least the gap n.(c_b - c_a) - (A's
// extent along n) - (B's), and when they overlap their depth (the least
// overlap over all directions) is at most minus that gap.
double box_gap(const WorldBox& a, const WorldBox& b, const Vec3& n) {
  const double extent_a = (a.axes->transpose() * n).cwiseAbs().dot(*a.half_extents) + a.radius;
  const double extent_b = (b.axes->transpose() * n).cwiseAbs().dot(*b.half_extents) + b.radius;
  return n.dot(b.center - a.center) - extent_a - extent_b;
}

// The box gap along the centres' line and along the pair's last normal
// (zero before the first query), whichever is larger. The gap is a bound
// only along a unit axis: both are normalized here, whatever a result held.
double box_bound(const WorldBox& a, const WorldBox& b, const Vec3& last_normal) {
  double bound = -kInfinity;
  const Vec3 line = b.center - a.center;
  const double length = line.norm();
  if (length > 0) bound = box_gap(a, b, line / length);
  const double norm = last_normal.norm();
  if (norm > 0.5 && norm < 2) bound = std::max(bound, box_gap(a, b, last_normal / norm));
  return bound - kBoxBoundSlack * (a.reach() + b.reach());
}

// A margin on |R_after - R_before|_2 for rotations that are orthonormal to
// a few u (poses are re-orthonormalized by checked_pose, and forward
// kinematics multiplies a few of them): the identity below holds for exact
// rotations, and this covers the departure of rounded ones many times over.
constexpr double kRotationSlack = 1e-9;

// How far any point within `radius` of a body's sphere centre (`local`, in
// the frame that moved from `before` to `after`) has moved: the centre's
// displacement plus |R_after - R_before|_2 radius. For two rotations,
// R_after - R_before = R_before (R - I), R a turn by some angle t, whose
// singular values are 2 sin(t/2) twice and 0: the spectral norm is the
// Frobenius norm over sqrt(2).
double motion(const Pose& before, const Pose& after, const Vec3& local, double radius) {
  const double turn = (after.rotation - before.rotation).norm() * std::numbers::sqrt2 / 2;
  return (after.apply(local) - before.apply(local)).norm() + (turn + kRotationSlack) * radius;
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
  detail::check_finite_non_negative(options.margin, "robot query", "options.margin");
  detail::check_distance_options(options.distance, "robot query", "options.distance");
  // A pair with a mesh is answered by the mesh query, which cannot honour
  // every distance option: refused before any pair, not at the first mesh
  // pair queried (only when an option differs from what meshes take).
  if (!detail::mesh_options_plainly_valid(options.distance, detail::MeshOptionUse::triangle_pairs)) {
    const auto refuse_for_meshes = [&](const Body& body) {
      if (body.kind() == Body::Kind::mesh)
        detail::check_mesh_options(options.distance, "robot query",
                                   detail::MeshOptionUse::triangle_pairs, "options.distance");
    };
    for (const RobotGeometry& g : robot.geometries()) refuse_for_meshes(g.body);
    for (const Obstacle& o : obstacles) refuse_for_meshes(o.body);
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
    s.self_normal_.assign(pairs.size(), Vec3::Zero());
    s.environment_normal_.assign(n_geometries * obstacles.size(), Vec3::Zero());
  }
  std::swap(s.link_poses_, s.previous_link_poses_);
  robot.forward_kinematics(q, options.base, s.link_poses_);
  const bool moved_before = s.previous_link_poses_.size() == s.link_poses_.size();
  const auto& spheres = robot.geometry_spheres();
  s.geometry_poses_.resize(n_geometries);
  s.centers_.resize(n_geometries);
  s.box_centers_.resize(n_geometries);
  const auto& boxes = robot.geometry_boxes();
  for (std::size_t g = 0; g < n_geometries; ++g) {
    const auto link = static_cast<std::size_t>(geometries[g].link);
    s.geometry_poses_[g] = s.link_poses_[link] * geometries[g].origin;
    s.box_centers_[g] = s.geometry_poses_[g].apply(boxes[g].center);
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
  s.obstacle_box_centers_.resize(obstacles.size());
  for (std::size_t o = 0; o < obstacles.size(); ++o) {
    s.obstacle_box_centers_[o] = obstacles[o].pose.apply(obstacles[o].box.center);
  }
  const auto geometry_box = [&](std::size_t g) {
    return WorldBox{s.box_centers_[g], &s.geometry_poses_[g].rotation, &boxes[g].half_extents,
                    geometries[g].body.radius()};
  };

  RobotDistances out;
  const auto report = [&](RobotPairResult&& pair, double& category_min, std::int32_t index,
                          std::int32_t& last) {
    const double sd = pair.result.signed_distance();
    const bool closest = sd < out.min_signed_distance;
    if (sd < category_min) {
      category_min = sd;
      last = index;
    }
    const bool within = !options.minimum_only && sd <= options.margin;
    if (!closest && !within) return;
    if (options.gradients) fill_gradient(robot, s.link_poses_, pair);
    if (closest) {
      out.min_signed_distance = sd;
      out.closest = pair;
    }
    if (within) out.close_pairs.push_back(std::move(pair));
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
      const double threshold = options.minimum_only ? out.min_self
                                                    : std::max(options.margin, out.min_self);
      if (bound > threshold) continue;
      bound = std::max(
          bound, sphere_bound(s.centers_[a], spheres[a].radius, s.centers_[b], spheres[b].radius));
      if (bound > threshold) continue;
      Vec3& normal = s.self_normal_[static_cast<std::size_t>(p)];
      bound = std::max(bound, box_bound(geometry_box(a), geometry_box(b), normal));
      if (bound > threshold) continue;
      ++out.pairs_queried;
      RobotPairResult result;
      result.geometry_a = pair.a;
      result.geometry_b = pair.b;
      result.result =
          distance(geometries[a].body, s.geometry_poses_[a], geometries[b].body,
                   s.geometry_poses_[b], options.distance, &s.self_[static_cast<std::size_t>(p)]);
      bound = result.result.signed_lower_bound();
      normal = result.result.normal;
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
      const double threshold = options.minimum_only
                                   ? out.min_environment
                                   : std::max(options.margin, out.min_environment);
      if (bound > threshold) continue;
      bound = std::max(bound, obstacle_box_bound(s.centers_[g], spheres[g].radius, obstacles[o]));
      if (bound > threshold) continue;
      Vec3& normal = s.environment_normal_[static_cast<std::size_t>(p)];
      const WorldBox obstacle_box{s.obstacle_box_centers_[o], &obstacles[o].pose.rotation,
                                  &obstacles[o].box.half_extents, obstacles[o].body.radius()};
      bound = std::max(bound, box_bound(geometry_box(g), obstacle_box, normal));
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
      normal = result.result.normal;
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
  detail::check_at_least(threads, 0, "robot batch", "threads", "0: all cores");
  RobotBatchDistances out;
  const auto k = static_cast<std::size_t>(q.rows());
  out.min_signed_distance.resize(q.rows());
  if (options.gradients) out.gradient = RowMatrixXd::Zero(q.rows(), robot.dof());
  RobotQueryOptions run_options = options;
  run_options.minimum_only = true;
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
