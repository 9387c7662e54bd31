// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 9: proxima.Robot, a robot from its URDF (proxima/robot/), with numpy
// joint vectors and batches. The robot keeps its environment and its query
// state (the per-pair caches: tracking across calls), so one Robot object
// is used by one thread at a time (the GIL is held during a query; the
// batch releases it and runs on the thread pool with states of its own).
#include <pybind11/stl.h>

#include <map>
#include <memory>

#include "convert.h"
#include "proxima/robot/robot_distance.h"
#include "proxima/robot/urdf.h"

namespace proxima::python {

namespace {

struct PyRobot {
  std::shared_ptr<const Robot> robot;
  std::vector<Obstacle> obstacles;
  RobotQueryState state;
};

// A joint vector: a 1-D array of length dof, or a dict naming every
// variable (Robot.joint_names).
std::vector<double> to_q(const Robot& robot, py::handle obj) {
  if (py::isinstance<py::dict>(obj)) {
    const py::dict named = py::reinterpret_borrow<py::dict>(obj);
    const std::vector<std::string> names = robot.variable_names();
    std::vector<double> q(names.size());
    for (std::size_t v = 0; v < names.size(); ++v) {
      if (!named.contains(names[v])) value_error("q: joint \"" + names[v] + "\" is missing");
      q[v] = named[py::str(names[v])].cast<double>();
    }
    for (const auto& item : named) {
      const std::string key = py::str(item.first);
      if (std::find(names.begin(), names.end(), key) == names.end()) {
        value_error("q: \"" + key + "\" is not a joint variable of the robot");
      }
    }
    return q;
  }
  const DoubleArray a = as_double_array(obj, "q");
  if (a.ndim() != 1 || a.shape(0) != robot.dof()) {
    value_error("q: expected shape (" + std::to_string(robot.dof()) + ",), got " + shape_of(a));
  }
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

py::array_t<double> vector_array(const Eigen::VectorXd& v) {
  return py::array_t<double>(v.size(), v.data());
}

py::array_t<double> pose_matrices(const std::vector<Pose>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto m = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto k = static_cast<py::ssize_t>(i);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(k, r, c) = poses[i].rotation(r, c);
      m(k, r, 3) = poses[i].translation[r];
    }
    m(k, 3, 0) = m(k, 3, 1) = m(k, 3, 2) = 0.0;
    m(k, 3, 3) = 1.0;
  }
  return out;
}

RobotQueryOptions make_robot_options(double margin, bool gradients, bool self, bool environment,
                                     py::handle base) {
  RobotQueryOptions options;
  options.margin = margin;
  options.gradients = gradients;
  options.self = self;
  options.environment = environment;
  if (!base.is_none()) options.base = to_pose(base, "base");
  return options;
}

// The answers of a robot query.
void bind_robot_results(py::module_& m) {
  py::class_<RobotPairResult>(m, "RobotPair", "One pair of a robot query (Robot.distances).")
      .def_readonly("geometry_a", &RobotPairResult::geometry_a,
                    "The robot geometry (index into Robot.geometry_names).")
      .def_readonly("geometry_b", &RobotPairResult::geometry_b,
                    "Another robot geometry, or for an environment pair the obstacle's index.")
      .def_readonly("environment", &RobotPairResult::environment,
                    "Whether B is an obstacle of the environment.")
      .def_readonly("result", &RobotPairResult::result,
                    "The pair's BodyResult (world frame, A the robot's geometry).")
      .def_property_readonly("signed_distance", &RobotPairResult::signed_distance,
                             "The pair's signed distance (negative: overlap depth).")
      .def_property_readonly(
          "gradient",
          [](const RobotPairResult& p) -> py::object {
            if (p.gradient.size() == 0) return py::none();
            return vector_array(p.gradient);
          },
          "d signed_distance / d q (dof,), or None when gradients were not asked for.")
      .def_readonly("has_gradient", &RobotPairResult::has_gradient,
                    "False for an overlap whose depth is not computed (a mesh's): gradient zero.")
      .def("__repr__", [](const RobotPairResult& p) {
        return "RobotPair(" + std::to_string(p.geometry_a) + ", " + std::to_string(p.geometry_b) +
               (p.environment ? ", environment" : "") +
               ", signed_distance=" + std::to_string(p.signed_distance()) + ")";
      });

  py::class_<RobotDistances>(m, "RobotDistances", "The answer of Robot.distances.")
      .def_readonly("min_signed_distance", &RobotDistances::min_signed_distance,
                    "Smallest signed distance over the tested pairs (inf when none).")
      .def_readonly("min_self", &RobotDistances::min_self,
                    "Smallest signed distance over the self pairs (inf when none).")
      .def_readonly("min_environment", &RobotDistances::min_environment,
                    "Smallest signed distance over the environment pairs (inf when none).")
      .def_readonly("closest", &RobotDistances::closest, "The pair of min_signed_distance.")
      .def_readonly("close_pairs", &RobotDistances::close_pairs,
                    "Every pair within the margin: self pairs, then environment pairs.")
      .def_readonly("pairs_queried", &RobotDistances::pairs_queried,
                    "Pairs that got a distance query (the others were pruned by bounds).")
      .def_property_readonly(
          "gradient",
          [](const RobotDistances& r) -> py::object {
            if (r.closest.gradient.size() == 0) return py::none();
            return vector_array(r.closest.gradient);
          },
          "The gradient of min_signed_distance (the closest pair's), or None.");

}

// The Robot's construction from its URDF and its model (names, pairs, limits).
void bind_robot_model(py::class_<PyRobot>& robot) {
  robot
      .def(py::init([](const std::string& urdf, const std::optional<std::string>& srdf,
                       const std::vector<std::string>& package_dirs, const std::string& mesh_as,
                       const std::map<std::string, std::string>& link_mesh_as,
                       double cylinder_tolerance, bool exclude_adjacent) {
             RobotLoadOptions options;
             options.package_dirs = package_dirs;
             options.mesh_as = load_as_from_string(mesh_as);
             for (const auto& [link, as] : link_mesh_as) {
               options.link_mesh_as[link] = load_as_from_string(as);
             }
             options.cylinder_tolerance = cylinder_tolerance;
             options.exclude_adjacent = exclude_adjacent;
             auto loaded = std::make_unique<PyRobot>();
             loaded->robot =
                 std::make_shared<const Robot>(load_robot(urdf, srdf.value_or(""), options));
             return loaded;
           }),
           py::arg("urdf"), py::arg("srdf") = py::none(),
           py::arg("package_dirs") = std::vector<std::string>{}, py::arg("mesh_as") = "hull",
           py::arg("link_mesh_as") = std::map<std::string, std::string>{},
           py::arg("cylinder_tolerance") = kDefaultCylinderTolerance,
           py::arg("exclude_adjacent") = true)
      .def_property_readonly(
          "name", [](const PyRobot& r) { return r.robot->name(); },
          "The robot's name (the URDF's <robot name>).")
      .def_property_readonly(
          "dof", [](const PyRobot& r) { return r.robot->dof(); }, "The length of q.")
      .def_property_readonly(
          "joint_names", [](const PyRobot& r) { return r.robot->variable_names(); },
          "The joints of q, in its order.")
      .def_property_readonly(
          "link_names",
          [](const PyRobot& r) {
            std::vector<std::string> names;
            for (const RobotLink& l : r.robot->links()) names.push_back(l.name);
            return names;
          },
          "The links, in the order of forward_kinematics' poses.")
      .def_property_readonly(
          "geometry_names",
          [](const PyRobot& r) {
            std::vector<std::string> names;
            for (const RobotGeometry& g : r.robot->geometries()) {
              names.push_back(g.name);
            }
            return names;
          },
          "Each collision geometry: link/index and its mesh file or primitive.")
      .def_property_readonly(
          "geometry_links",
          [](const PyRobot& r) {
            std::vector<std::int32_t> links;
            for (const RobotGeometry& g : r.robot->geometries()) {
              links.push_back(g.link);
            }
            return int32_array(links);
          },
          "The link (index into link_names) of each geometry.")
      .def_property_readonly(
          "self_pairs",
          [](const PyRobot& r) {
            std::vector<std::array<std::int32_t, 2>> rows;
            for (const GeometryPair& p : r.robot->self_pairs()) {
              rows.push_back({p.a, p.b});
            }
            return index_rows(rows);
          },
          "(P, 2) geometry indices of the enabled self pairs.")
      .def_property_readonly(
          "lower_limits", [](const PyRobot& r) { return vector_array(r.robot->lower_limits()); },
          "Lower limit of each joint of q (-inf for a continuous joint).")
      .def_property_readonly(
          "upper_limits", [](const PyRobot& r) { return vector_array(r.robot->upper_limits()); },
          "Upper limit of each joint of q (inf for a continuous joint).");
}

// The Robot's kinematics, environment and distance queries.
void bind_robot_queries(py::class_<PyRobot>& robot) {
  robot
      .def(
          "forward_kinematics",
          [](const PyRobot& r, py::handle q, py::handle base) {
            const Pose b = base.is_none() ? Pose{} : to_pose(base, "base");
            return pose_matrices(r.robot->forward_kinematics(to_q(*r.robot, q), b));
          },
          py::arg("q"), py::arg("base") = py::none(),
          "Each link's pose (world from link) as an (n_links, 4, 4) array, in link_names order.")
      .def(
          "point_jacobian",
          [](const PyRobot& r, py::handle q, const std::string& link, py::handle point) {
            const std::vector<Pose> poses = r.robot->forward_kinematics(to_q(*r.robot, q));
            const auto j =
                r.robot->point_jacobian(poses, r.robot->link_index(link), to_vec3(point, "point"));
            py::array_t<double> out({py::ssize_t{3}, static_cast<py::ssize_t>(j.cols())});
            auto o = out.mutable_unchecked<2>();
            for (int row = 0; row < 3; ++row) {
              for (Eigen::Index c = 0; c < j.cols(); ++c) o(row, c) = j(row, c);
            }
            return out;
          },
          py::arg("q"), py::arg("link"), py::arg("point"),
          "d point / d q (3, dof) of a point fixed on `link`, given at its world position.")
      .def(
          "set_environment",
          [](PyRobot& r, py::handle obstacles) {
            std::vector<Obstacle> list;
            std::size_t i = 0;
            for (py::handle item : obstacles) {
              const std::string what = "obstacles[" + std::to_string(i++) + "]";
              const py::tuple t = py::cast<py::tuple>(item);
              if (t.size() != 2) value_error(what + ": expected (body, pose)");
              list.emplace_back(to_body(t[0], what.c_str()), to_pose(t[1], what + " pose"), what);
            }
            r.obstacles = std::move(list);
          },
          py::arg("obstacles"),
          "The environment: a list of (body, pose) (a Body, ConvexPolytope, CompoundBody or "
          "TriangleMesh and its world pose).")
      .def(
          "reset", [](PyRobot& r) { r.state.reset(); }, "Forget the per-pair caches (cold).")
      .def(
          "distances",
          [](PyRobot& r, py::handle q, double margin, bool gradients, bool self, bool environment,
             py::handle base, bool minimum_only) {
            RobotQueryOptions options =
                make_robot_options(margin, gradients, self, environment, base);
            options.minimum_only = minimum_only;
            return robot_distances(*r.robot, to_q(*r.robot, q), r.obstacles, options, &r.state);
          },
          py::arg("q"), py::arg("margin") = 0.0, py::arg("gradients") = false,
          py::arg("include_self") = true, py::arg("include_environment") = true,
          py::arg("base") = py::none(), py::arg("minimum_only") = false,
          "Signed distances at q: the minimum over self and environment pairs, every pair within "
          "`margin`, and with gradients=True each one's gradient with respect to q (tracked "
          "between calls). minimum_only=True: only the minimum and its pair (close_pairs empty, "
          "margin not read), fewer pairs queried.")
      .def(
          "distances_batch",
          [](const PyRobot& r, py::handle qs, bool gradients, int threads, bool self,
             bool environment, py::handle base) {
            const DoubleArray a = as_double_array(qs, "q");
            if (a.ndim() != 2 || a.shape(1) != r.robot->dof()) {
              value_error("q: expected shape (K, " + std::to_string(r.robot->dof()) + "), got " +
                          shape_of(a));
            }
            RowMatrixXd q = Eigen::Map<const RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
            const RobotQueryOptions options =
                make_robot_options(0.0, gradients, self, environment, base);
            RobotBatchDistances out;
            {
              py::gil_scoped_release release;
              out = robot_distances_batch(*r.robot, q, r.obstacles, options, threads);
            }
            py::array_t<double> minima = vector_array(out.min_signed_distance);
            if (!gradients) return py::make_tuple(minima, py::none());
            py::array_t<double> g({a.shape(0), a.shape(1)});
            std::copy(out.gradient.data(), out.gradient.data() + out.gradient.size(),
                      g.mutable_data());
            return py::make_tuple(minima, g);
          },
          py::arg("q"), py::arg("gradients") = true, py::arg("threads") = 0,
          py::arg("include_self") = true, py::arg("include_environment") = true,
          py::arg("base") = py::none(),
          "K configurations (K, dof) on the thread pool: (minima (K,), gradients (K, dof) or "
          "None). Row k equals distances(q[k]).min_signed_distance and its gradient.");
}

}  // namespace

void bind_robot(py::module_& m) {
  bind_robot_results(m);
  py::class_<PyRobot> robot(m, "Robot",
                      R"doc(A robot from its URDF (and SRDF): kinematics and signed distances.

    robot = proxima.Robot("panda.urdf", srdf="panda.srdf",
                          package_dirs=["example-robot-data=/path/to/example-robot-data"])
    r = robot.distances(q, margin=0.05, gradients=True)

q: a 1-D array of length dof in the order of joint_names (the URDF's <joint> order, the moving
joints that mimic none), or a dict naming every joint of joint_names.
package_dirs: "NAME=DIR" (package NAME is DIR) or a directory holding packages (ROS_PACKAGE_PATH).
mesh_as: "hull" (default), "mesh" or "pieces"; link_mesh_as: {link name: mode} overrides.
The robot keeps its environment (set_environment) and its per-pair caches between calls
(tracking along a trajectory); reset() makes it cold.)doc");
  bind_robot_model(robot);
  bind_robot_queries(robot);
}

}  // namespace proxima::python
