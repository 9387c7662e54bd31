// The robot benchmark's FCL side (bench/robot_urdf_bench.cpp): a robot's
// geometries and obstacles as FCL 0.7 objects (the same hulls as
// fcl::Convex through peers/fcl_convex.h, the same meshes as
// BVHModel<OBBRSS>, a sphere as fcl::Sphere), queried on the same pairs at
// the poses of the same forward kinematics (proxima::Robot's), and the
// exact referee both are compared with: proxima's cold distance() on every
// pair (the slow path of robot_distances).
// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#include <proxima/robot/robot_distance.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "peers/fcl_convex.h"

namespace proxima::bench {

// FCL's counterpart of a proxima Body: a hull (radius 0) as fcl::Convex, a
// rounded point as fcl::Sphere, a mesh as BVHModel<OBBRSS>. Other bodies
// have none here: InvalidInput naming `what`.
inline std::shared_ptr<fcl::CollisionGeometryd> fcl_body(const Body& body, const std::string& what) {
  if (body.kind() == Body::Kind::convex) {
    const ConvexPolytope& hull = *body.convex();
    if (body.radius() == 0) return fcl_convex(hull, what);
    if (hull.vertex_count() == 1 && hull.vertices()[0].isZero()) {
      return std::make_shared<fcl::Sphered>(body.radius());
    }
  } else if (body.kind() == Body::Kind::mesh && body.radius() == 0) {
    return fcl_mesh<fcl::OBBRSSd>(body.mesh()->vertices(), body.mesh()->triangles());
  }
  throw InvalidInput(what + ": no FCL counterpart in this benchmark");
}

// One configuration's answer: the smallest signed distance over the pairs
// (self pairs of Robot::self_pairs() and every geometry against every
// obstacle) and whether any pair is in collision.
struct RobotMinimum {
  double min_signed_distance = std::numeric_limits<double>::infinity();
  bool colliding = false;
};

// The robot in FCL. distance() runs fcl::distance (signed, FCL's default
// GJK solver, libccd) on every pair at the poses of Robot::forward_kinematics,
// as a user driving FCL from the same kinematics would, without pruning.
class FclRobot {
 public:
  FclRobot(const Robot& robot, std::span<const Obstacle> obstacles)
      : robot_(robot), obstacles_(obstacles) {
    for (const RobotGeometry& g : robot.geometries()) geometries_.push_back(fcl_body(g.body, g.name));
    for (const Obstacle& o : obstacles) {
      obstacle_bodies_.push_back(fcl_body(o.body, "obstacle " + o.name));
      obstacle_transforms_.push_back(fcl_transform(o.pose));
    }
    request_.enable_signed_distance = true;
  }

  RobotMinimum distance(std::span<const double> q) {
    robot_.forward_kinematics(q, Pose{}, link_poses_);
    const auto& geometries = robot_.geometries();
    transforms_.resize(geometries.size());
    for (std::size_t g = 0; g < geometries.size(); ++g) {
      transforms_[g] = fcl_transform(
          link_poses_[static_cast<std::size_t>(geometries[g].link)] * geometries[g].origin);
    }
    RobotMinimum out;
    const auto add = [&](const fcl::CollisionGeometryd* a, const fcl::Transform3d& ta,
                         const fcl::CollisionGeometryd* b, const fcl::Transform3d& tb) {
      fcl::DistanceResultd result;
      const double d = fcl::distance(a, ta, b, tb, request_, result);
      out.min_signed_distance = std::min(out.min_signed_distance, d);
      out.colliding = out.colliding || d <= 0;
    };
    for (const GeometryPair& p : robot_.self_pairs()) {
      const auto a = static_cast<std::size_t>(p.a), b = static_cast<std::size_t>(p.b);
      add(geometries_[a].get(), transforms_[a], geometries_[b].get(), transforms_[b]);
    }
    for (std::size_t g = 0; g < geometries.size(); ++g) {
      for (std::size_t o = 0; o < obstacle_bodies_.size(); ++o) {
        add(geometries_[g].get(), transforms_[g], obstacle_bodies_[o].get(),
            obstacle_transforms_[o]);
      }
    }
    return out;
  }

 private:
  const Robot& robot_;
  std::span<const Obstacle> obstacles_;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> geometries_;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> obstacle_bodies_;
  std::vector<fcl::Transform3d> obstacle_transforms_;
  std::vector<Pose> link_poses_;
  std::vector<fcl::Transform3d> transforms_;
  fcl::DistanceRequestd request_;
};

// The referee: a cold proxima distance() on every pair (no pruning, no
// cache) at the same poses. Its signed distance is certified: within
// [signed_lower_bound, signed_upper_bound] of each pair's answer.
inline RobotMinimum referee_minimum(const Robot& robot, std::span<const double> q,
                                    std::span<const Obstacle> obstacles) {
  const std::vector<Pose> links = robot.forward_kinematics(q);
  const auto& geometries = robot.geometries();
  const auto pose = [&](std::int32_t g) {
    const RobotGeometry& geometry = geometries[static_cast<std::size_t>(g)];
    return links[static_cast<std::size_t>(geometry.link)] * geometry.origin;
  };
  RobotMinimum out;
  const auto add = [&](const BodyResult& r) {
    out.min_signed_distance = std::min(out.min_signed_distance, r.signed_distance());
    out.colliding = out.colliding || r.status != Status::separated;
  };
  for (const GeometryPair& p : robot.self_pairs()) {
    add(proxima::distance(geometries[static_cast<std::size_t>(p.a)].body, pose(p.a),
                          geometries[static_cast<std::size_t>(p.b)].body, pose(p.b)));
  }
  for (std::int32_t g = 0; g < static_cast<std::int32_t>(geometries.size()); ++g) {
    for (const Obstacle& o : obstacles) {
      add(proxima::distance(geometries[static_cast<std::size_t>(g)].body, pose(g), o.body, o.pose));
    }
  }
  return out;
}

}  // namespace proxima::bench
