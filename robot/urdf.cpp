// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A RobotDescription from a URDF (urdfdom) and an SRDF (tinyxml2): see
// proxima/robot/urdf.h.
#include "proxima/robot/urdf.h"

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "proxima/shape/primitives.h"

namespace proxima {

namespace {

namespace fs = std::filesystem;

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

// urdfdom reports a parse failure through console_bridge's log and returns
// null. The handler collects the errors of one parse, so that the
// exception can say what went wrong; console_bridge's handler is global,
// hence the lock around the parse.
class CollectErrors : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      if (!errors.empty()) errors += "; ";
      errors += text;
    }
  }
  std::string errors;
};

urdf::ModelInterfaceSharedPtr parse_urdf(const std::string& xml, const std::string& name) {
  static std::mutex lock;
  const std::lock_guard<std::mutex> guard(lock);
  CollectErrors collect;
  console_bridge::useOutputHandler(&collect);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    collect.errors += e.what();
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    throw InvalidInput(
        name + ": not a valid URDF: " +
        (collect.errors.empty() ? std::string("the parser refused it") : collect.errors));
  }
  return model;
}

Pose to_pose(const urdf::Pose& p) {
  const Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  return {Mat3(q.normalized().toRotationMatrix()), Vec3(p.position.x, p.position.y, p.position.z)};
}

// The names of the <robot>'s direct <tag> children, in file order (urdfdom
// keeps links and joints in maps sorted by name; the joint vector follows
// the file).
std::vector<std::string> element_names(const tinyxml2::XMLDocument& doc, const char* tag) {
  std::vector<std::string> names;
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return names;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(tag); e != nullptr;
       e = e->NextSiblingElement(tag)) {
    const char* name = e->Attribute("name");
    names.emplace_back(name != nullptr ? name : "");
  }
  return names;
}

std::string read_text_file(const std::string& path, const ReadOptions& options) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) throw FileError::in_file(path, "no such file");
  const auto size = fs::file_size(path, error);
  if (!error && size > options.max_file_bytes) {
    throw FileError::in_file(
        path, "larger than the limit of " + std::to_string(options.max_file_bytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError::in_file(path, "cannot be opened");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

LoadAs parse_load_as_of_link(const RobotLoadOptions& options, const std::string& link) {
  const auto found = options.link_mesh_as.find(link);
  return found != options.link_mesh_as.end() ? found->second : options.mesh_as;
}

// One mesh file's body at a scale: points read once per file (Talos names
// the same file twice, mirrored), scaled, then hulled, meshed or split.
class MeshBodies {
 public:
  explicit MeshBodies(const ReadOptions& options) : options_(options) {}

  Body body(const std::string& path, const Vec3& scale, LoadAs as) {
    auto found = clouds_.find(path);
    if (found == clouds_.end()) found = clouds_.emplace(path, read_points(path, options_)).first;
    PointCloud cloud = found->second;
    for (Vec3& p : cloud.points) p = p.cwiseProduct(scale);
    if (scale.prod() < 0) {
      // A mirroring scale turns the triangles inside out: keep them
      // outward.
      for (auto& t : cloud.triangles) std::swap(t[1], t[2]);
    }
    switch (as) {
      case LoadAs::hull:
        return Body(std::make_shared<const ConvexPolytope>(cloud.points));
      case LoadAs::mesh:
        return Body(std::make_shared<const TriangleMesh>(mesh_from_cloud(cloud).mesh));
      case LoadAs::pieces:
        return Body(std::make_shared<const CompoundBody>(compound_from_cloud(cloud).body));
    }
    throw InvalidInput("unknown mesh mode");
  }

 private:
  const ReadOptions& options_;
  std::unordered_map<std::string, PointCloud> clouds_;
};

Body geometry_body(const urdf::Geometry& geometry, const std::string& where,
                   const std::string& base_dir, const RobotLoadOptions& options, LoadAs as,
                   MeshBodies& meshes, std::string& what) {
  switch (geometry.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(geometry);
      what = "box";
      return make_box(Vec3(box.dim.x, box.dim.y, box.dim.z) / 2);
    }
    case urdf::Geometry::SPHERE: {
      what = "sphere";
      return make_sphere(static_cast<const urdf::Sphere&>(geometry).radius);
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      what = "cylinder";
      return make_cylinder(cylinder.radius, cylinder.length / 2, options.cylinder_tolerance);
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
      what = mesh.filename;
      const Vec3 scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
      if (!scale.allFinite() || scale.x() == 0 || scale.y() == 0 || scale.z() == 0) {
        throw InvalidInput(where + ": mesh " + in_quotes(mesh.filename) +
                           " has a zero or non-finite scale");
      }
      const std::string path = resolve_robot_uri(mesh.filename, base_dir, options.package_dirs);
      return meshes.body(path, scale, as);
    }
  }
  throw InvalidInput(where + ": unknown geometry type");
}

}  // namespace

std::string resolve_robot_uri(const std::string& uri, const std::string& base_dir,
                              const std::vector<std::string>& package_dirs) {
  constexpr std::string_view kPackage = "package://";
  constexpr std::string_view kFile = "file://";
  if (uri.starts_with(kFile)) return uri.substr(kFile.size());
  if (!uri.starts_with(kPackage)) {
    const fs::path path(uri);
    return path.is_absolute() ? uri : (fs::path(base_dir) / path).string();
  }
  std::string rest = uri.substr(kPackage.size());
  while (rest.starts_with('/')) rest.erase(0, 1);  // package:///NAME/... as Talos writes it
  const auto slash = rest.find('/');
  const std::string package = rest.substr(0, slash);
  const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
  if (package.empty()) throw InvalidInput("mesh URI " + in_quotes(uri) + " names no package");
  for (const std::string& entry : package_dirs) {
    const auto equals = entry.find('=');
    std::error_code error;
    if (equals != std::string::npos) {
      if (entry.substr(0, equals) == package) {
        return (fs::path(entry.substr(equals + 1)) / inside).string();
      }
      continue;
    }
    const fs::path dir(entry);
    if (fs::is_directory(dir / package, error)) return (dir / package / inside).string();
    if (dir.lexically_normal().filename() == package ||
        dir.lexically_normal().parent_path().filename() == package) {
      return (dir / inside).string();
    }
  }
  throw InvalidInput("mesh URI " + in_quotes(uri) + ": package " + in_quotes(package) +
                     " is not in the package directories (give NAME=DIR or a directory holding "
                     "NAME)");
}

RobotDescription read_urdf_string(const std::string& urdf_xml, const std::string& base_dir,
                                  const std::string& name, const RobotLoadOptions& options) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf_xml.data(), urdf_xml.size()) != tinyxml2::XML_SUCCESS) {
    throw InvalidInput(name + ", line " + std::to_string(doc.ErrorLineNum()) +
                       ": not valid XML: " + doc.ErrorStr());
  }
  const urdf::ModelInterfaceSharedPtr model = parse_urdf(urdf_xml, name);

  RobotDescription description;
  description.name = model->getName();
  description.exclude_adjacent = options.exclude_adjacent;
  std::unordered_map<std::string, std::int32_t> link_of;
  for (const std::string& link : element_names(doc, "link")) {
    if (model->links_.count(link) == 0 || link_of.count(link) != 0) continue;
    link_of.emplace(link, static_cast<std::int32_t>(description.links.size()));
    description.links.push_back({link});
  }
  for (const auto& [link_name, link] : options.link_mesh_as) {
    if (link_of.count(link_name) == 0) {
      throw InvalidInput(name + ": the mesh mode is given for link " + in_quotes(link_name) +
                         ", which is not a link of the URDF");
    }
  }

  for (const std::string& joint_name : element_names(doc, "joint")) {
    const auto found = model->joints_.find(joint_name);
    if (found == model->joints_.end()) continue;
    const urdf::Joint& source = *found->second;
    const std::string where = name + ", joint " + in_quotes(joint_name);
    RobotJoint joint;
    joint.name = joint_name;
    switch (source.type) {
      case urdf::Joint::REVOLUTE:
        joint.type = JointType::revolute;
        break;
      case urdf::Joint::CONTINUOUS:
        joint.type = JointType::continuous;
        break;
      case urdf::Joint::PRISMATIC:
        joint.type = JointType::prismatic;
        break;
      case urdf::Joint::FIXED:
        joint.type = JointType::fixed;
        break;
      case urdf::Joint::FLOATING:
      case urdf::Joint::PLANAR:
      case urdf::Joint::UNKNOWN:
        throw InvalidInput(where + ": joint type " +
                           (source.type == urdf::Joint::FLOATING ? std::string("floating")
                            : source.type == urdf::Joint::PLANAR ? std::string("planar")
                                                                 : std::string("unknown")) +
                           " is not supported (revolute, continuous, prismatic, fixed)");
    }
    const auto parent = link_of.find(source.parent_link_name);
    const auto child = link_of.find(source.child_link_name);
    if (parent == link_of.end() || child == link_of.end()) {
      throw InvalidInput(where + ": its parent or child link is not in the file");
    }
    joint.parent = parent->second;
    joint.child = child->second;
    joint.origin = to_pose(source.parent_to_joint_origin_transform);
    joint.axis = Vec3(source.axis.x, source.axis.y, source.axis.z);
    if (source.limits &&
        (joint.type == JointType::revolute || joint.type == JointType::prismatic)) {
      joint.lower = source.limits->lower;
      joint.upper = source.limits->upper;
    }
    if (source.mimic) {
      joint.mimic = source.mimic->joint_name;
      joint.multiplier = source.mimic->multiplier;
      joint.offset = source.mimic->offset;
    }
    description.joints.push_back(std::move(joint));
  }

  MeshBodies meshes(options.read);
  for (std::size_t l = 0; l < description.links.size(); ++l) {
    const std::string& link_name = description.links[l].name;
    const urdf::Link& link = *model->links_.at(link_name);
    const LoadAs as = parse_load_as_of_link(options, link_name);
    for (std::size_t c = 0; c < link.collision_array.size(); ++c) {
      const urdf::Collision& collision = *link.collision_array[c];
      const std::string where =
          name + ", link " + in_quotes(link_name) + ", collision " + std::to_string(c);
      if (!collision.geometry) throw InvalidInput(where + ": no geometry");
      std::string what;
      std::optional<Body> body;
      try {
        body.emplace(
            geometry_body(*collision.geometry, where, base_dir, options, as, meshes, what));
      } catch (const FileError&) {
        throw;
      } catch (const InvalidInput& e) {
        const std::string message = e.what();
        if (message.starts_with(name)) throw;
        throw InvalidInput(where + ": " + message);
      }
      RobotGeometry geometry{static_cast<std::int32_t>(l), std::move(*body),
                             to_pose(collision.origin),
                             link_name + "/" + std::to_string(c) + " " + what};
      description.geometries.push_back(std::move(geometry));
    }
  }
  return description;
}

RobotDescription read_urdf(const std::string& urdf_path, const std::string& srdf_path,
                           const RobotLoadOptions& options) {
  const std::string xml = read_text_file(urdf_path, options.read);
  RobotDescription description =
      read_urdf_string(xml, fs::path(urdf_path).parent_path().string(), urdf_path, options);
  if (!srdf_path.empty()) description.disabled_pairs = read_srdf_disabled_pairs(srdf_path);
  return description;
}

std::vector<std::pair<std::string, std::string>> read_srdf_disabled_pairs(
    const std::string& srdf_path) {
  const std::string xml = read_text_file(srdf_path, {});
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw InvalidInput(srdf_path + ", line " + std::to_string(doc.ErrorLineNum()) +
                       ": not valid XML: " + doc.ErrorStr());
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) throw InvalidInput(srdf_path + ": no <robot> element (not an SRDF)");
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("disable_collisions"); e != nullptr;
       e = e->NextSiblingElement("disable_collisions")) {
    const char* a = e->Attribute("link1");
    const char* b = e->Attribute("link2");
    if (a == nullptr || b == nullptr) {
      throw InvalidInput(srdf_path + ", line " + std::to_string(e->GetLineNum()) +
                         ": disable_collisions without link1 and link2");
    }
    pairs.emplace_back(a, b);
  }
  return pairs;
}

Robot load_robot(const std::string& urdf_path, const std::string& srdf_path,
                 const RobotLoadOptions& options) {
  RobotDescription description = read_urdf(urdf_path, srdf_path, options);
  try {
    return Robot(std::move(description));
  } catch (const InvalidInput& e) {
    throw InvalidInput(urdf_path + (srdf_path.empty() ? "" : " with " + srdf_path) + ": " +
                       e.what());
  }
}

}  // namespace proxima
