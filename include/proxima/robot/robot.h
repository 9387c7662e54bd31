// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: a robot as a kinematic tree of links and joints, each link
// carrying its collision geometries as proxima Bodies; forward kinematics,
// point Jacobians and the set of pairs a self-collision query tests.
//
// A Robot is built from a RobotDescription: by hand, or from a URDF and an
// SRDF (proxima/robot/urdf.h). It is immutable once built, and may be
// shared between threads.
//
//   proxima::Robot robot = proxima::load_robot("panda.urdf", options);
//   std::vector<proxima::Pose> poses = robot.forward_kinematics(q);
//   poses[robot.link_index("panda_link8")].translation   // the flange
//
// The joint vector q. Its entries are the robot's *variables*: one per
// revolute, continuous or prismatic joint that does not mimic another, in
// the order of RobotDescription::joints (for a URDF, the order of its
// `<joint>` elements in the file). variable_names() lists them. A mimic
// joint moves by multiplier * q[v] + offset, v the variable of the joint it
// follows (through any chain of mimics). A revolute or continuous joint
// turns its child by the angle about its axis (radians, right hand); a
// prismatic one translates it along its axis (the description's unit,
// metres for a URDF). Fixed joints are constant transforms.
//
// Link poses are world from link, the root link at the identity (the
// caller places the robot in the world by moving its obstacles, or by a
// base pose given to the queries, proxima/robot/robot_distance.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/shape/body.h"

namespace proxima {

enum class JointType : std::uint8_t { fixed, revolute, continuous, prismatic };
const char* to_string(JointType type);

struct RobotJoint {
  std::string name;
  JointType type = JointType::fixed;
  std::int32_t parent = -1;  // link index
  std::int32_t child = -1;   // link index
  // The joint frame in the parent link's frame; at position 0 the child
  // link's frame is the joint frame.
  Pose origin;
  // The axis in the joint frame (normalized by Robot; must be non-zero for
  // a moving joint).
  Vec3 axis = Vec3::UnitZ();
  // Position limits (revolute, prismatic). A continuous joint has none
  // (-infinity, +infinity); for a fixed joint they are not read.
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  // Mimic: the name of the joint whose position this one copies
  // (position = multiplier * that position + offset), empty for none.
  std::string mimic;
  double multiplier = 1.0;
  double offset = 0.0;
};

struct RobotLink {
  std::string name;
};

// One collision element of a link: a body placed at `origin` in the link's
// frame. `name` says where it came from (for a URDF: the link, the element's
// index and the mesh file or the primitive), for messages and the viewer.
struct RobotGeometry {
  std::int32_t link = -1;
  Body body;
  Pose origin;
  std::string name;
};

struct RobotDescription {
  std::string name;
  std::vector<RobotLink> links;
  std::vector<RobotJoint> joints;
  std::vector<RobotGeometry> geometries;
  // Pairs of link names never tested against each other (an SRDF's
  // disable_collisions), on top of the adjacent links when
  // exclude_adjacent is set (see Robot::self_pairs).
  std::vector<std::pair<std::string, std::string>> disabled_pairs;
  bool exclude_adjacent = true;
};

// A bounding sphere of a body in its own frame: every point of the body
// (radius included) is within `radius` of `center`, with a margin for
// rounding (kBoundingSphereSlack).
struct BoundingSphere {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};
BoundingSphere bounding_sphere(const Body& body);
// The box around a body's core in its own frame (axis-aligned there, the
// same slack), without the body's radius: every point of the body is
// within body.radius() of it.
struct BoundingBox {
  Vec3 center = Vec3::Zero();
  Vec3 half_extents = Vec3::Zero();
};
BoundingBox bounding_box(const Body& body);

// Two robot geometries tested against each other (indices into
// Robot::geometries(), a < b).
struct GeometryPair {
  std::int32_t a = -1;
  std::int32_t b = -1;
};

class Robot {
 public:
  // Checks the description and builds the tree. InvalidInput (naming the
  // link, joint or pair) for: duplicate link or joint names; a joint whose
  // parent or child is not a link; a link with two parent joints, or a
  // cycle; more than one root link (or none); a zero, infinite or NaN axis
  // of a moving joint; a non-rigid origin; lower > upper or NaN limits; a
  // mimic naming an unknown joint, a fixed joint, or forming a cycle; a
  // non-finite multiplier or offset; a geometry on an unknown link; a
  // disabled pair naming an unknown link.
  explicit Robot(RobotDescription description);

  const std::string& name() const { return name_; }
  const std::vector<RobotLink>& links() const { return links_; }
  const std::vector<RobotJoint>& joints() const { return joints_; }
  const std::vector<RobotGeometry>& geometries() const { return geometries_; }

  // The number of variables: the length of q.
  int dof() const { return static_cast<int>(variable_joints_.size()); }
  // The joint of each variable (indices into joints()), in q's order.
  const std::vector<std::int32_t>& variable_joints() const { return variable_joints_; }
  std::vector<std::string> variable_names() const;
  // The limits of each variable (continuous joints: -inf, +inf).
  Eigen::VectorXd lower_limits() const;
  Eigen::VectorXd upper_limits() const;

  // The index of a link or joint by name; InvalidInput naming it when there
  // is none.
  std::int32_t link_index(std::string_view name) const;
  std::int32_t joint_index(std::string_view name) const;
  // The root link (no parent joint).
  std::int32_t root() const { return root_; }

  // Each link's pose (world from link, the root at `base`), indexed like
  // links(). InvalidInput when q.size() != dof() or an entry is not finite
  // (naming the variable). Limits are not enforced (a planner may probe
  // beyond them; within_limits says).
  std::vector<Pose> forward_kinematics(std::span<const double> q, const Pose& base = {}) const;
  // The same into `poses` (resized), without allocating when it has the
  // size already.
  void forward_kinematics(std::span<const double> q, const Pose& base,
                          std::vector<Pose>& poses) const;
  bool within_limits(std::span<const double> q) const;

  // The Jacobian of a point fixed on link `link`, at world position `point`
  // in the configuration whose link poses are `poses` (from
  // forward_kinematics): column v is d point / d q[v], 3 x dof.
  Eigen::Matrix<double, 3, Eigen::Dynamic> point_jacobian(std::span<const Pose> poses,
                                                          std::int32_t link,
                                                          const Vec3& point) const;
  // gradient += scale * direction^T J, J the point Jacobian above: the
  // derivative of direction . point, without forming J (O(depth of link)).
  void add_directional_derivative(std::span<const Pose> poses, std::int32_t link, const Vec3& point,
                                  const Vec3& direction, double scale,
                                  std::span<double> gradient) const;

  // The pairs of geometries a self query tests: every pair of geometries of
  // different links, except pairs of adjacent links (when
  // exclude_adjacent) and disabled pairs. Two links are adjacent when a
  // joint connects them, or when they are connected through links without
  // geometry (the Panda's hand is adjacent to link7 through the flange
  // link8, which has none), as MoveIt's setup assistant counts them.
  const std::vector<GeometryPair>& self_pairs() const { return self_pairs_; }
  // Whether the links' pair is tested (not adjacent, not disabled).
  bool link_pair_enabled(std::int32_t link_a, std::int32_t link_b) const;

  // Each geometry's bounding sphere in its link's frame.
  const std::vector<BoundingSphere>& geometry_spheres() const { return geometry_spheres_; }
  // Each geometry's core box (bounding_box) in the geometry's own frame
  // (the link's frame times RobotGeometry::origin).
  const std::vector<BoundingBox>& geometry_boxes() const { return geometry_boxes_; }

  // The geometries of each link (indices into geometries()).
  const std::vector<std::int32_t>& link_geometries(std::int32_t link) const {
    return link_geometries_[static_cast<std::size_t>(link)];
  }

 private:
  // One step of the forward pass, in topological order: the joint placing
  // link `child` under `parent`.
  struct Step {
    std::int32_t joint;
    std::int32_t parent;
    std::int32_t child;
    std::int32_t variable;  // -1 for a fixed joint
    double multiplier;      // 1 for a joint that is its own variable
    double offset;
  };
  Pose joint_motion(const Step& step, double position) const;

  std::string name_;
  std::vector<RobotLink> links_;
  std::vector<RobotJoint> joints_;
  std::vector<RobotGeometry> geometries_;
  std::vector<std::int32_t> variable_joints_;
  std::vector<Step> steps_;                // topological order, root first
  std::vector<std::int32_t> parent_step_;  // per link: its step in steps_, -1 for the root
  std::vector<std::int32_t> parent_link_;  // per link, -1 for the root
  std::vector<std::vector<std::int32_t>> link_geometries_;
  std::vector<std::uint8_t> pair_enabled_;  // links x links
  std::vector<GeometryPair> self_pairs_;
  std::vector<BoundingSphere> geometry_spheres_;
  std::vector<BoundingBox> geometry_boxes_;
  std::int32_t root_ = -1;
};

}  // namespace proxima
