// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The kinematic tree of a Robot (proxima/robot/robot.h): its checks, the
// forward pass, point Jacobians and the self pairs.
#include "proxima/robot/robot.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

namespace proxima {

const char* to_string(JointType type) {
  switch (type) {
    case JointType::fixed:
      return "fixed";
    case JointType::revolute:
      return "revolute";
    case JointType::continuous:
      return "continuous";
    case JointType::prismatic:
      return "prismatic";
  }
  return "unknown";
}

namespace {

// Built by appending: GCC 12 warns falsely (-Wrestrict) on "\"" + name +
// "\"". Not named `quoted`: std::quoted would win overload resolution for a
// std::string argument (found by argument-dependent lookup).
std::string in_quotes(std::string_view name) {
  std::string out;
  out.reserve(name.size() + 2);
  out += '"';
  out += name;
  out += '"';
  return out;
}

std::unordered_map<std::string, std::int32_t> index_names(const std::vector<std::string>& names,
                                                          const std::string& robot,
                                                          const char* kind) {
  std::unordered_map<std::string, std::int32_t> index;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty()) {
      throw InvalidInput("robot " + in_quotes(robot) + ": " + kind + " " + std::to_string(i) +
                         " has no name");
    }
    if (!index.emplace(names[i], static_cast<std::int32_t>(i)).second) {
      throw InvalidInput("robot " + in_quotes(robot) + ": two " + kind + "s named " +
                         in_quotes(names[i]));
    }
  }
  return index;
}

}  // namespace

// The centre of the box around the body's points, and the largest distance
// from it, widened by kBoundingSphereSlack of the sphere's reach (|centre| +
// radius) so that rounding in the pose products and in the distance of two
// spheres never puts a point of the body outside its sphere.
namespace {
constexpr double kBoundingSphereSlack = 1e-9;

BoundingSphere sphere_of_points(std::span<const Vec3> points) {
  Vec3 low = points[0], high = points[0];
  for (const Vec3& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const Vec3 center = (low + high) / 2;
  double radius = 0.0;
  for (const Vec3& p : points) radius = std::max(radius, (p - center).norm());
  return {center, radius};
}
}  // namespace

BoundingBox bounding_box(const Body& body) {
  Vec3 low, high;
  const auto cover = [&](std::span<const Vec3> points) {
    low = points[0];
    high = points[0];
    for (const Vec3& p : points) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  };
  if (body.kind() == Body::Kind::convex) {
    cover(body.convex()->vertices());
  } else if (body.kind() == Body::Kind::mesh) {
    cover(body.mesh()->vertices());
  } else {
    const CompoundBody::Node& root = body.compound()->nodes()[0];
    low = root.center - Vec3::Constant(root.radius);
    high = root.center + Vec3::Constant(root.radius);
  }
  BoundingBox box{(low + high) / 2, (high - low) / 2};
  box.half_extents +=
      Vec3::Constant(kBoundingSphereSlack * (box.center.norm() + box.half_extents.norm()));
  return box;
}

BoundingSphere bounding_sphere(const Body& body) {
  BoundingSphere sphere;
  if (body.kind() == Body::Kind::convex) {
    sphere = sphere_of_points(body.convex()->vertices());
  } else if (body.kind() == Body::Kind::mesh) {
    sphere = sphere_of_points(body.mesh()->vertices());
  } else {
    const CompoundBody::Node& root = body.compound()->nodes()[0];
    sphere = {root.center, root.radius};
  }
  sphere.radius += body.radius();
  sphere.radius += kBoundingSphereSlack * (sphere.center.norm() + sphere.radius);
  return sphere;
}

Robot::Robot(RobotDescription description)
    : name_(std::move(description.name)),
      links_(std::move(description.links)),
      joints_(std::move(description.joints)),
      geometries_(std::move(description.geometries)) {
  const std::string where = "robot " + in_quotes(name_);
  const auto n_links = static_cast<std::int32_t>(links_.size());
  if (n_links == 0) throw InvalidInput(where + ": no links");
  std::vector<std::string> link_names, joint_names;
  for (const RobotLink& link : links_) link_names.push_back(link.name);
  for (const RobotJoint& joint : joints_) joint_names.push_back(joint.name);
  const auto link_of = index_names(link_names, name_, "link");
  const auto joint_of = index_names(joint_names, name_, "joint");

  // The tree: each link has at most one parent joint, exactly one has none.
  parent_link_.assign(links_.size(), -1);
  std::vector<std::int32_t> parent_joint(links_.size(), -1);
  std::vector<std::vector<std::int32_t>> child_joints(links_.size());
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    RobotJoint& joint = joints_[j];
    const std::string at = where + ", joint " + in_quotes(joint.name);
    if (joint.parent < 0 || joint.parent >= n_links || joint.child < 0 || joint.child >= n_links) {
      throw InvalidInput(at + ": its parent or child is not a link of the robot");
    }
    if (joint.parent == joint.child) throw InvalidInput(at + ": its parent is its child");
    if (parent_joint[static_cast<std::size_t>(joint.child)] >= 0) {
      throw InvalidInput(
          at + ": link " + in_quotes(links_[static_cast<std::size_t>(joint.child)].name) +
          " already has the parent joint " +
          in_quotes(
              joints_[static_cast<std::size_t>(parent_joint[static_cast<std::size_t>(joint.child)])]
                  .name));
    }
    parent_joint[static_cast<std::size_t>(joint.child)] = static_cast<std::int32_t>(j);
    parent_link_[static_cast<std::size_t>(joint.child)] = joint.parent;
    child_joints[static_cast<std::size_t>(joint.parent)].push_back(static_cast<std::int32_t>(j));
    joint.origin = checked_pose(joint.origin, [&] { return at + ": origin"; });
    if (joint.type != JointType::fixed) {
      const double norm = joint.axis.norm();
      if (!std::isfinite(norm) || norm == 0.0) {
        throw InvalidInput(at + ": axis (" + std::to_string(joint.axis.x()) + ", " +
                           std::to_string(joint.axis.y()) + ", " + std::to_string(joint.axis.z()) +
                           ") is not a direction");
      }
      joint.axis /= norm;
    }
    if (joint.type == JointType::continuous) {
      joint.lower = -std::numeric_limits<double>::infinity();
      joint.upper = std::numeric_limits<double>::infinity();
    }
    if (std::isnan(joint.lower) || std::isnan(joint.upper) || joint.lower > joint.upper) {
      throw InvalidInput(at + ": limits [" + std::to_string(joint.lower) + ", " +
                         std::to_string(joint.upper) + "] are not an interval");
    }
    if (!std::isfinite(joint.multiplier) || !std::isfinite(joint.offset)) {
      throw InvalidInput(at + ": mimic multiplier or offset is not finite");
    }
  }
  for (std::int32_t l = 0; l < n_links; ++l) {
    if (parent_joint[static_cast<std::size_t>(l)] >= 0) continue;
    if (root_ >= 0) {
      throw InvalidInput(where + ": two root links (no parent joint), " +
                         in_quotes(links_[static_cast<std::size_t>(root_)].name) + " and " +
                         in_quotes(links_[static_cast<std::size_t>(l)].name));
    }
    root_ = l;
  }
  if (root_ < 0) throw InvalidInput(where + ": every link has a parent joint (a cycle)");

  // Variables: the moving joints that mimic none, in the joints' order.
  std::vector<std::int32_t> variable_of(joints_.size(), -1);
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    if (joints_[j].type != JointType::fixed && joints_[j].mimic.empty()) {
      variable_of[j] = static_cast<std::int32_t>(variable_joints_.size());
      variable_joints_.push_back(static_cast<std::int32_t>(j));
    }
  }

  // The forward pass's order: breadth first from the root, children in the
  // joints' order. A link not reached hangs on a cycle.
  parent_step_.assign(links_.size(), -1);
  std::vector<std::int32_t> queue{root_};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    for (std::int32_t j : child_joints[static_cast<std::size_t>(queue[head])]) {
      const RobotJoint& joint = joints_[static_cast<std::size_t>(j)];
      Step step{j, joint.parent, joint.child, variable_of[static_cast<std::size_t>(j)], 1.0, 0.0};
      if (joint.type != JointType::fixed && !joint.mimic.empty()) {
        // Follow the chain of mimics to a variable, composing the maps
        // x -> multiplier x + offset.
        std::int32_t at = j;
        for (std::size_t hops = 0;; ++hops) {
          const RobotJoint& follower = joints_[static_cast<std::size_t>(at)];
          const std::string here = where + ", joint " + in_quotes(follower.name);
          if (hops > joints_.size()) throw InvalidInput(here + ": its mimic chain is a cycle");
          const auto found = joint_of.find(follower.mimic);
          if (found == joint_of.end()) {
            throw InvalidInput(here + ": mimics " + in_quotes(follower.mimic) +
                               ", which is not a joint of the robot");
          }
          const RobotJoint& leader = joints_[static_cast<std::size_t>(found->second)];
          if (leader.type == JointType::fixed) {
            throw InvalidInput(here + ": mimics the fixed joint " + in_quotes(leader.name));
          }
          step.offset = step.multiplier * follower.offset + step.offset;
          step.multiplier *= follower.multiplier;
          at = found->second;
          if (leader.mimic.empty()) break;
        }
        step.variable = variable_of[static_cast<std::size_t>(at)];
      }
      parent_step_[static_cast<std::size_t>(joint.child)] =
          static_cast<std::int32_t>(steps_.size());
      steps_.push_back(step);
      queue.push_back(joint.child);
    }
  }
  if (queue.size() != links_.size()) {
    for (std::int32_t l = 0; l < n_links; ++l) {
      if (l != root_ && parent_step_[static_cast<std::size_t>(l)] < 0) {
        throw InvalidInput(where + ": link " + in_quotes(links_[static_cast<std::size_t>(l)].name) +
                           " is not reached from the root " +
                           in_quotes(links_[static_cast<std::size_t>(root_)].name) + " (a cycle)");
      }
    }
  }

  link_geometries_.assign(links_.size(), {});
  for (std::size_t g = 0; g < geometries_.size(); ++g) {
    RobotGeometry& geometry = geometries_[g];
    if (geometry.link < 0 || geometry.link >= n_links) {
      throw InvalidInput(where + ", geometry " + in_quotes(geometry.name) +
                         ": its link is not a link of the robot");
    }
    geometry.origin = checked_pose(geometry.origin, [&] {
      return where + ", geometry " + in_quotes(geometry.name) + ": origin";
    });
    link_geometries_[static_cast<std::size_t>(geometry.link)].push_back(
        static_cast<std::int32_t>(g));
    BoundingSphere sphere = bounding_sphere(geometry.body);
    sphere.center = geometry.origin.apply(sphere.center);
    geometry_spheres_.push_back(sphere);
    geometry_boxes_.push_back(bounding_box(geometry.body));
  }

  // Enabled link pairs: all but a link with itself, adjacent links, and the
  // disabled pairs.
  const auto n = static_cast<std::size_t>(n_links);
  pair_enabled_.assign(n * n, 1);
  for (std::size_t l = 0; l < n; ++l) pair_enabled_[l * n + l] = 0;
  const auto disable = [&](std::int32_t a, std::int32_t b) {
    pair_enabled_[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)] = 0;
    pair_enabled_[static_cast<std::size_t>(b) * n + static_cast<std::size_t>(a)] = 0;
  };
  if (description.exclude_adjacent) {
    // From each link with geometry, search the tree's edges through links
    // without geometry; each link with geometry met is adjacent to it.
    std::vector<std::vector<std::int32_t>> neighbours(n);
    for (std::int32_t l = 0; l < n_links; ++l) {
      const std::int32_t p = parent_link_[static_cast<std::size_t>(l)];
      if (p >= 0) {
        neighbours[static_cast<std::size_t>(l)].push_back(p);
        neighbours[static_cast<std::size_t>(p)].push_back(l);
      }
    }
    std::vector<std::int32_t> seen(n, -1);
    for (std::int32_t l = 0; l < n_links; ++l) {
      if (link_geometries_[static_cast<std::size_t>(l)].empty()) continue;
      std::vector<std::int32_t> stack{l};
      seen[static_cast<std::size_t>(l)] = l;
      while (!stack.empty()) {
        const std::int32_t at = stack.back();
        stack.pop_back();
        for (std::int32_t next : neighbours[static_cast<std::size_t>(at)]) {
          if (seen[static_cast<std::size_t>(next)] == l) continue;
          seen[static_cast<std::size_t>(next)] = l;
          if (link_geometries_[static_cast<std::size_t>(next)].empty()) {
            stack.push_back(next);
          } else {
            disable(l, next);
          }
        }
      }
    }
  }
  for (const auto& [first, second] : description.disabled_pairs) {
    const auto a = link_of.find(first);
    const auto b = link_of.find(second);
    if (a == link_of.end() || b == link_of.end()) {
      throw InvalidInput(where + ": disabled pair (" + in_quotes(first) + ", " + in_quotes(second) +
                         ") names " + in_quotes(a == link_of.end() ? first : second) +
                         ", which is not a link of the robot");
    }
    disable(a->second, b->second);
  }
  for (std::size_t a = 0; a < geometries_.size(); ++a) {
    for (std::size_t b = a + 1; b < geometries_.size(); ++b) {
      if (link_pair_enabled(geometries_[a].link, geometries_[b].link)) {
        self_pairs_.push_back({static_cast<std::int32_t>(a), static_cast<std::int32_t>(b)});
      }
    }
  }
}

std::vector<std::string> Robot::variable_names() const {
  std::vector<std::string> names;
  for (std::int32_t j : variable_joints_)
    names.push_back(joints_[static_cast<std::size_t>(j)].name);
  return names;
}

Eigen::VectorXd Robot::lower_limits() const {
  Eigen::VectorXd lower(dof());
  for (int v = 0; v < dof(); ++v) {
    lower[v] =
        joints_[static_cast<std::size_t>(variable_joints_[static_cast<std::size_t>(v)])].lower;
  }
  return lower;
}

Eigen::VectorXd Robot::upper_limits() const {
  Eigen::VectorXd upper(dof());
  for (int v = 0; v < dof(); ++v) {
    upper[v] =
        joints_[static_cast<std::size_t>(variable_joints_[static_cast<std::size_t>(v)])].upper;
  }
  return upper;
}

std::int32_t Robot::link_index(std::string_view name) const {
  for (std::size_t l = 0; l < links_.size(); ++l) {
    if (links_[l].name == name) return static_cast<std::int32_t>(l);
  }
  throw InvalidInput("robot " + in_quotes(name_) + " has no link " + in_quotes(name));
}

std::int32_t Robot::joint_index(std::string_view name) const {
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    if (joints_[j].name == name) return static_cast<std::int32_t>(j);
  }
  throw InvalidInput("robot " + in_quotes(name_) + " has no joint " + in_quotes(name));
}

bool Robot::link_pair_enabled(std::int32_t link_a, std::int32_t link_b) const {
  const auto n = links_.size();
  return pair_enabled_[static_cast<std::size_t>(link_a) * n + static_cast<std::size_t>(link_b)] !=
         0;
}

Pose Robot::joint_motion(const Step& step, double position) const {
  const RobotJoint& joint = joints_[static_cast<std::size_t>(step.joint)];
  switch (joint.type) {
    case JointType::fixed:
      return {};
    case JointType::revolute:
    case JointType::continuous:
      return {Mat3(Eigen::AngleAxisd(position, joint.axis)), Vec3::Zero()};
    case JointType::prismatic:
      return {Mat3::Identity(), Vec3(position * joint.axis)};
  }
  return {};
}

void Robot::forward_kinematics(std::span<const double> q, const Pose& base,
                               std::vector<Pose>& poses) const {
  if (q.size() != variable_joints_.size()) {
    throw InvalidInput("robot " + in_quotes(name_) + ": the joint vector has " +
                       std::to_string(q.size()) + " entries, the robot " +
                       std::to_string(variable_joints_.size()) + " variables");
  }
  for (std::size_t v = 0; v < q.size(); ++v) {
    if (!std::isfinite(q[v])) {
      throw InvalidInput("robot " + in_quotes(name_) + ": joint " +
                         in_quotes(joints_[static_cast<std::size_t>(variable_joints_[v])].name) +
                         " (entry " + std::to_string(v) + " of the joint vector) is not finite");
    }
  }
  poses.resize(links_.size());
  poses[static_cast<std::size_t>(root_)] = checked_pose(base, "robot base pose");
  for (const Step& step : steps_) {
    const RobotJoint& joint = joints_[static_cast<std::size_t>(step.joint)];
    Pose& child = poses[static_cast<std::size_t>(step.child)];
    child = poses[static_cast<std::size_t>(step.parent)] * joint.origin;
    if (step.variable >= 0) {
      child =
          child * joint_motion(step, step.multiplier * q[static_cast<std::size_t>(step.variable)] +
                                         step.offset);
    }
  }
}

std::vector<Pose> Robot::forward_kinematics(std::span<const double> q, const Pose& base) const {
  std::vector<Pose> poses;
  forward_kinematics(q, base, poses);
  return poses;
}

bool Robot::within_limits(std::span<const double> q) const {
  if (q.size() != variable_joints_.size()) return false;
  for (std::size_t v = 0; v < q.size(); ++v) {
    const RobotJoint& joint = joints_[static_cast<std::size_t>(variable_joints_[v])];
    if (!(q[v] >= joint.lower && q[v] <= joint.upper)) return false;
  }
  return true;
}

// A joint's motion about (or along) its axis a, in world coordinates
// R_child a (the motion about a leaves a fixed, so the child's rotation
// maps it as the joint frame's does). A turn by dθ about a through the
// child's origin o moves a point p by (a x (p - o)) dθ; a slide by ds
// moves it by a ds. A mimic joint's position moves multiplier times its
// variable.
void Robot::add_directional_derivative(std::span<const Pose> poses, std::int32_t link,
                                       const Vec3& point, const Vec3& direction, double scale,
                                       std::span<double> gradient) const {
  for (std::int32_t s = parent_step_[static_cast<std::size_t>(link)]; s >= 0;
       s = parent_step_[static_cast<std::size_t>(steps_[static_cast<std::size_t>(s)].parent)]) {
    const Step& step = steps_[static_cast<std::size_t>(s)];
    if (step.variable < 0) continue;
    const RobotJoint& joint = joints_[static_cast<std::size_t>(step.joint)];
    const Pose& child = poses[static_cast<std::size_t>(step.child)];
    const Vec3 axis = child.rotation * joint.axis;
    const Vec3 motion =
        joint.type == JointType::prismatic ? axis : Vec3(axis.cross(point - child.translation));
    gradient[static_cast<std::size_t>(step.variable)] +=
        scale * step.multiplier * direction.dot(motion);
  }
}

Eigen::Matrix<double, 3, Eigen::Dynamic> Robot::point_jacobian(std::span<const Pose> poses,
                                                               std::int32_t link,
                                                               const Vec3& point) const {
  Eigen::Matrix<double, 3, Eigen::Dynamic> jacobian =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, dof());
  for (int k = 0; k < 3; ++k) {
    Eigen::VectorXd row = Eigen::VectorXd::Zero(dof());
    add_directional_derivative(poses, link, point, Vec3::Unit(k), 1.0,
                               std::span<double>(row.data(), static_cast<std::size_t>(row.size())));
    jacobian.row(k) = row.transpose();
  }
  return jacobian;
}

}  // namespace proxima
