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

namespace detail {

// One robot_distances call, in the order of its concepts: the options
// checked, the state sized for this robot and its obstacles, the bodies
// placed at q (and each pair's bound decayed by the motion since the last
// query), then the self pairs and the environment pairs, each queried only
// while its bound is below what it could still change.
class RobotQuery {
 public:
  RobotQuery(const Robot& robot, std::span<const Obstacle> obstacles,
             const RobotQueryOptions& options, RobotQueryState& state)
      : robot_(robot),
        obstacles_(obstacles),
        options_(options),
        s_(state),
        geometries_(robot.geometries()),
        pairs_(robot.self_pairs()),
        spheres_(robot.geometry_spheres()),
        boxes_(robot.geometry_boxes()) {}

  RobotDistances run(std::span<const double> q) {
    check_options();
    size_state();
    place(q);
    decay_bounds();
    if (options_.self && !pairs_.empty()) self_pairs();
    // The self part was visited from the last closest pair on: back to
    // self_pairs() order.
    std::sort(out_.close_pairs.begin(), out_.close_pairs.end(), by_geometries);
    const std::size_t self_reported = out_.close_pairs.size();
    if (options_.environment && !obstacles_.empty() && !geometries_.empty()) {
      environment_pairs();
      std::sort(out_.close_pairs.begin() + static_cast<std::ptrdiff_t>(self_reported),
                out_.close_pairs.end(), by_geometries);
    }
    return std::move(out_);
  }

 private:
  void check_options() const {
    check_finite_non_negative(options_.margin, "robot query", "options.margin");
    check_distance_options(options_.distance, "robot query", "options.distance");
    // A pair with a mesh is answered by the mesh query, which cannot honour
    // every distance option: refused before any pair, not at the first mesh
    // pair queried (only when an option differs from what meshes take).
    if (!mesh_options_plainly_valid(options_.distance, MeshOptionUse::triangle_pairs)) {
      const auto refuse_for_meshes = [&](const Body& body) {
        if (body.kind() == Body::Kind::mesh)
          check_mesh_options(options_.distance, "robot query", MeshOptionUse::triangle_pairs,
                             "options.distance");
      };
      for (const RobotGeometry& g : geometries_) refuse_for_meshes(g.body);
      for (const Obstacle& o : obstacles_) refuse_for_meshes(o.body);
    }
  }

  // A state of another robot or obstacle count starts over, cold.
  void size_state() {
    const std::size_t n_geometries = geometries_.size();
    if (s_.robot_ == &robot_ && s_.obstacles_ == obstacles_.size() &&
        s_.self_.size() == pairs_.size() && s_.motion_.size() == n_geometries)
      return;
    s_.reset();
    s_.robot_ = &robot_;
    s_.obstacles_ = obstacles_.size();
    s_.self_.resize(pairs_.size());
    s_.environment_.resize(n_geometries * obstacles_.size());
    s_.self_bound_.assign(pairs_.size(), -kInfinity);
    s_.environment_bound_.assign(n_geometries * obstacles_.size(), -kInfinity);
    s_.motion_.assign(n_geometries, kInfinity);
    s_.obstacle_poses_.resize(obstacles_.size());
    s_.obstacle_cores_.assign(obstacles_.size(), nullptr);
    s_.obstacle_radii_.assign(obstacles_.size(), 0.0);
    s_.obstacle_motion_.assign(obstacles_.size(), kInfinity);
    s_.self_normal_.assign(pairs_.size(), Vec3::Zero());
    s_.environment_normal_.assign(n_geometries * obstacles_.size(), Vec3::Zero());
  }

  // Forward kinematics at q: every geometry's pose, sphere and box centre,
  // and how far it moved since the last query; each obstacle's motion.
  void place(std::span<const double> q) {
    const std::size_t n_geometries = geometries_.size();
    std::swap(s_.link_poses_, s_.previous_link_poses_);
    robot_.forward_kinematics(q, options_.base, s_.link_poses_);
    const bool moved_before = s_.previous_link_poses_.size() == s_.link_poses_.size();
    s_.geometry_poses_.resize(n_geometries);
    s_.centers_.resize(n_geometries);
    s_.box_centers_.resize(n_geometries);
    for (std::size_t g = 0; g < n_geometries; ++g) {
      const auto link = static_cast<std::size_t>(geometries_[g].link);
      s_.geometry_poses_[g] = s_.link_poses_[link] * geometries_[g].origin;
      s_.box_centers_[g] = s_.geometry_poses_[g].apply(boxes_[g].center);
      s_.centers_[g] = s_.link_poses_[link].apply(spheres_[g].center);
      s_.motion_[g] = moved_before ? motion(s_.previous_link_poses_[link], s_.link_poses_[link],
                                            spheres_[g].center, spheres_[g].radius)
                                   : kInfinity;
    }
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
      // An obstacle replaced by another body (or radius) starts over.
      const void* core = core_of(obstacles_[o].body);
      if (core != s_.obstacle_cores_[o] || obstacles_[o].body.radius() != s_.obstacle_radii_[o]) {
        s_.obstacle_cores_[o] = core;
        s_.obstacle_radii_[o] = obstacles_[o].body.radius();
        s_.obstacle_motion_[o] = kInfinity;
      } else {
        s_.obstacle_motion_[o] =
            motion(s_.obstacle_poses_[o], obstacles_[o].pose,
                   obstacles_[o].pose.inverse().apply(obstacles_[o].center), obstacles_[o].radius);
      }
      s_.obstacle_poses_[o] = obstacles_[o].pose;
    }
    s_.obstacle_box_centers_.resize(obstacles_.size());
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
      s_.obstacle_box_centers_[o] = obstacles_[o].pose.apply(obstacles_[o].box.center);
    }
  }

  // Each pair's bound decays by the motion first (every pair, queried or
  // not, whatever options.self and options.environment say), so that it
  // stays a bound at the next query too.
  void decay_bounds() {
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      s_.self_bound_[p] -= s_.motion_[static_cast<std::size_t>(pairs_[p].a)] +
                           s_.motion_[static_cast<std::size_t>(pairs_[p].b)];
    }
    for (std::size_t g = 0; g < geometries_.size(); ++g) {
      for (std::size_t o = 0; o < obstacles_.size(); ++o) {
        s_.environment_bound_[g * obstacles_.size() + o] -= s_.motion_[g] + s_.obstacle_motion_[o];
      }
    }
  }

  WorldBox geometry_box(std::size_t g) const {
    return WorldBox{s_.box_centers_[g], &s_.geometry_poses_[g].rotation, &boxes_[g].half_extents,
                    geometries_[g].body.radius()};
  }

  // Records a queried pair: its category's minimum (and the pair that gave
  // it, `last`), the closest overall, and the close pairs within the margin.
  void report(RobotPairResult&& pair, double& category_min, std::int32_t index,
              std::int32_t& last) {
    const double sd = pair.result.signed_distance();
    const bool closest = sd < out_.min_signed_distance;
    if (sd < category_min) {
      category_min = sd;
      last = index;
    }
    const bool within = !options_.minimum_only && sd <= options_.margin;
    if (!closest && !within) return;
    if (options_.gradients) fill_gradient(robot_, s_.link_poses_, pair);
    if (closest) {
      out_.min_signed_distance = sd;
      out_.closest = pair;
    }
    if (within) out_.close_pairs.push_back(std::move(pair));
  }

  void self_pairs() {
    // The last closest pair first: its distance is likely the smallest
    // again, and it prunes the others.
    const std::int32_t first = s_.last_self_ >= 0 ? s_.last_self_ : 0;
    std::int32_t last = -1;
    const auto n = static_cast<std::int32_t>(pairs_.size());
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const GeometryPair& pair = pairs_[static_cast<std::size_t>(p)];
      const auto a = static_cast<std::size_t>(pair.a), b = static_cast<std::size_t>(pair.b);
      double& bound = s_.self_bound_[static_cast<std::size_t>(p)];
      const double threshold = options_.minimum_only ? out_.min_self
                                                     : std::max(options_.margin, out_.min_self);
      if (bound > threshold) continue;
      bound = std::max(bound, sphere_bound(s_.centers_[a], spheres_[a].radius, s_.centers_[b],
                                           spheres_[b].radius));
      if (bound > threshold) continue;
      Vec3& normal = s_.self_normal_[static_cast<std::size_t>(p)];
      bound = std::max(bound, box_bound(geometry_box(a), geometry_box(b), normal));
      if (bound > threshold) continue;
      ++out_.pairs_queried;
      RobotPairResult result;
      result.geometry_a = pair.a;
      result.geometry_b = pair.b;
      result.result = distance(geometries_[a].body, s_.geometry_poses_[a], geometries_[b].body,
                               s_.geometry_poses_[b], options_.distance,
                               &s_.self_[static_cast<std::size_t>(p)]);
      bound = result.result.signed_lower_bound();
      normal = result.result.normal;
      report(std::move(result), out_.min_self, p, last);
    }
    if (last >= 0) s_.last_self_ = last;
  }

  void environment_pairs() {
    const auto n_obstacles = static_cast<std::int32_t>(obstacles_.size());
    const auto n = static_cast<std::int32_t>(geometries_.size()) * n_obstacles;
    const std::int32_t first = s_.last_environment_ >= 0 ? s_.last_environment_ : 0;
    std::int32_t last = -1;
    for (std::int32_t k = 0; k < n; ++k) {
      const std::int32_t p = k == 0 ? first : (k <= first ? k - 1 : k);
      const auto g = static_cast<std::size_t>(p / n_obstacles);
      const auto o = static_cast<std::size_t>(p % n_obstacles);
      double& bound = s_.environment_bound_[static_cast<std::size_t>(p)];
      const double threshold = options_.minimum_only
                                   ? out_.min_environment
                                   : std::max(options_.margin, out_.min_environment);
      if (bound > threshold) continue;
      bound = std::max(bound, obstacle_box_bound(s_.centers_[g], spheres_[g].radius, obstacles_[o]));
      if (bound > threshold) continue;
      Vec3& normal = s_.environment_normal_[static_cast<std::size_t>(p)];
      const WorldBox obstacle_box{s_.obstacle_box_centers_[o], &obstacles_[o].pose.rotation,
                                  &obstacles_[o].box.half_extents, obstacles_[o].body.radius()};
      bound = std::max(bound, box_bound(geometry_box(g), obstacle_box, normal));
      if (bound > threshold) continue;
      ++out_.pairs_queried;
      RobotPairResult result;
      result.geometry_a = static_cast<std::int32_t>(g);
      result.geometry_b = static_cast<std::int32_t>(o);
      result.environment = true;
      result.result =
          distance(geometries_[g].body, s_.geometry_poses_[g], obstacles_[o].body,
                   obstacles_[o].pose, options_.distance,
                   &s_.environment_[static_cast<std::size_t>(p)]);
      bound = result.result.signed_lower_bound();
      normal = result.result.normal;
      report(std::move(result), out_.min_environment, p, last);
    }
    if (last >= 0) s_.last_environment_ = last;
  }

  const Robot& robot_;
  std::span<const Obstacle> obstacles_;
  const RobotQueryOptions& options_;
  RobotQueryState& s_;
  const std::vector<RobotGeometry>& geometries_;
  const std::vector<GeometryPair>& pairs_;
  const std::vector<BoundingSphere>& spheres_;
  const std::vector<BoundingBox>& boxes_;
  RobotDistances out_;
};

}  // namespace detail

RobotDistances robot_distances(const Robot& robot, std::span<const double> q,
                               std::span<const Obstacle> obstacles,
                               const RobotQueryOptions& options, RobotQueryState* state) {
  RobotQueryState local;
  return detail::RobotQuery(robot, obstacles, options, state != nullptr ? *state : local).run(q);
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
