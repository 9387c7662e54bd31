// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 9 (an edge: it reads files): a Robot (proxima/robot/robot.h) from
// its URDF, read by the ROS URDF parser (urdfdom), and optionally an SRDF,
// read with tinyxml2, for its disable_collisions pairs. Library
// proxima::robot.
//
//   proxima::RobotLoadOptions options;
//   options.package_dirs = {"example-robot-data=/path/to/example-robot-data"};
//   proxima::Robot panda = proxima::load_robot("panda.urdf", "panda.srdf", options);
//
// What is read:
//   - links, and joints of type revolute, continuous, prismatic and fixed
//     with their <origin xyz rpy>, <axis>, <limit lower upper> and <mimic
//     joint multiplier offset>; a floating or planar joint is an error.
//     The joint vector's order is the order of the <joint> elements in the
//     file (proxima/robot/robot.h says which joints are variables).
//   - every <collision> of every link, with its <origin>: <box size>,
//     <sphere radius>, <cylinder radius length> (a prism circumscribing the
//     cylinder within RobotLoadOptions::cylinder_tolerance,
//     proxima/shape/primitives.h) and <mesh filename scale> (STL, OBJ, OFF, PLY, through
//     proxima/io.h; the scale applied to the points, a mirroring scale
//     included). <visual> elements are ignored.
//   - mesh file names: `package://NAME/rest` (and `package:///NAME/rest`,
//     as some descriptions write it) through RobotLoadOptions::package_dirs;
//     `file:///abs/path`; a relative path from the URDF's folder.
//   - the SRDF's <disable_collisions link1 link2>; its other elements are
//     ignored.
// Errors are InvalidInput (a FileError for a file that cannot be read)
// naming the file and the link, joint or element.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "proxima/io.h"
#include "proxima/robot/robot.h"

namespace proxima {

// The default polygon tolerance for URDF cylinders, in metres (URDF's
// unit): 0.1 mm, far below the millimetre at which collision meshes are
// modelled, and it gives the Talos's cylinders (radii of 2 to 3 cm) prisms
// of about 50 sides.
inline constexpr double kDefaultCylinderTolerance = 1e-4;

struct RobotLoadOptions {
  // Where packages are: each entry either "NAME=DIR" (package NAME is the
  // directory DIR) or a directory searched as ROS_PACKAGE_PATH is
  // (package NAME is DIR/NAME, or DIR itself when its last component is
  // NAME). Entries are tried in order.
  std::vector<std::string> package_dirs;
  // How a mesh becomes a body (proxima/io.h LoadAs): its convex hull (the
  // default, conservative for planning), the mesh as given, or one convex
  // piece per OBJ group. `link_mesh_as` overrides it per link name (a name
  // that is not a link is an error).
  LoadAs mesh_as = LoadAs::hull;
  std::map<std::string, LoadAs> link_mesh_as;
  double cylinder_tolerance = kDefaultCylinderTolerance;
  // Whether adjacent links are excluded from the self pairs
  // (Robot::self_pairs).
  bool exclude_adjacent = true;
  ReadOptions read;
};

// The description read from a URDF file (and an SRDF file when
// `srdf_path` is not empty), before the Robot's checks.
RobotDescription read_urdf(const std::string& urdf_path, const std::string& srdf_path = "",
                           const RobotLoadOptions& options = {});
// The same from the URDF's text; relative mesh paths are taken from
// `base_dir`, and `name` stands for the file in messages.
RobotDescription read_urdf_string(const std::string& urdf_xml, const std::string& base_dir,
                                  const std::string& name, const RobotLoadOptions& options = {});
// The disable_collisions pairs of an SRDF file.
std::vector<std::pair<std::string, std::string>> read_srdf_disabled_pairs(
    const std::string& srdf_path);

// Robot(read_urdf(...)).
Robot load_robot(const std::string& urdf_path, const std::string& srdf_path = "",
                 const RobotLoadOptions& options = {});

// Where `uri` (a URDF mesh filename) is on disk, by the rules above;
// InvalidInput naming the URI when a package is not found.
std::string resolve_robot_uri(const std::string& uri, const std::string& base_dir,
                              const std::vector<std::string>& package_dirs);

}  // namespace proxima
