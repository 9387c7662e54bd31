// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the Python side of continuous collision (Motion, ImpactResult,
// time_of_impact). Same conventions as module.cpp: names one for one with
// C++, poses in any form to_pose reads, enums as strings, the query without
// the GIL.
#include "proxima/motion/time_of_impact.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "convert.h"
#include "proxima/query/body_distance.h"

namespace proxima::python {
namespace {

// A Motion from a Motion or a (start, end) pair of poses in any form
// to_pose reads.
Motion to_motion(py::handle obj, const std::string& name) {
  if (py::isinstance<Motion>(obj)) return obj.cast<Motion>();
  if (py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) {
    const py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
    if (py::len(seq) == 2) {
      return {to_pose(seq[0], name + " start"), to_pose(seq[1], name + " end")};
    }
  }
  throw py::type_error(name + ": expected a proxima.Motion or a (start, end) pair of poses, got " +
                       std::string(py::str(py::type::of(obj).attr("__name__"))));
}

}  // namespace

void bind_time_of_impact(py::module_& m) {
  py::class_<Motion>(m, "Motion",
                     "A body's motion over t in [0, 1]: its frame's origin moves at constant "
                     "velocity from start to end and the body turns at constant angular "
                     "velocity about it: from_velocity's rate through any angle (several turns "
                     "included), or from start to end the shorter way.")
      .def(py::init([](py::object start, py::object end) {
             return Motion{to_pose(start, "start"), to_pose(end, "end")};
           }),
           py::arg("start"), py::arg("end"), "From its poses at t = 0 and t = 1 (any pose form).")
      .def_static(
          "fixed", [](py::object pose) { return Motion::fixed(to_pose(pose, "pose")); },
          py::arg("pose"), "A body that does not move.")
      .def_static(
          "from_velocity",
          [](py::object pose, py::handle linear, py::handle angular, double duration) {
            return Motion::from_velocity(to_pose(pose, "pose"), to_vec3(linear, "linear"),
                                         to_vec3(angular, "angular"), duration);
          },
          py::arg("pose"), py::arg("linear"), py::arg("angular"), py::arg("duration") = 1.0,
          "From a pose, a linear velocity of its origin and an angular velocity (world frame, "
          "radians per unit time; the body turns at it through any angle, several turns "
          "included) over `duration`; t = 1 is the end of it.")
      .def_readwrite("start", &Motion::start, "Pose at t = 0.")
      .def_readwrite("end", &Motion::end, "Pose at t = 1.")
      .def_property_readonly(
          "angular",
          [](const Motion& mo) -> py::object {
            if (!mo.angular) return py::none();
            return vec3_array(*mo.angular);
          },
          "The angular velocity from_velocity kept (world frame, radians per unit t; the body "
          "turns at it through any angle), or None: the shorter way from start to end.")
      .def("at", &Motion::at, py::arg("t"), "The pose at time t (clamped to [0, 1]).")
      .def(
          "linear_velocity", [](const Motion& mo) { return vec3_array(mo.linear_velocity()); },
          "Velocity of the frame's origin per unit t.")
      .def(
          "angular_velocity", [](const Motion& mo) { return vec3_array(mo.angular_velocity()); },
          "Angular velocity per unit t, world frame: `angular` when set, else the shorter way's.");

  py::class_<ImpactResult>(m, "ImpactResult", "The answer of time_of_impact.")
      .def_property_readonly(
          "status", [](const ImpactResult& r) { return to_string(r.status); },
          "'separated' (no contact over [0, 1]), 'contact' (at t), 'intersecting' (already at t = "
          "0) or 'iteration_cap' (stopped; t is still safe).")
      .def_readonly("t", &ImpactResult::t,
                    "Time reached: the time of impact for 'contact', never after the true first "
                    "contact; 1 when separated.")
      .def_readonly("pose_a", &ImpactResult::pose_a, "A's pose at t.")
      .def_readonly("pose_b", &ImpactResult::pose_b, "B's pose at t.")
      .def_readonly("at_t", &ImpactResult::at_t,
                    "The distance query at t (points, normal, features, bounds).")
      .def_readonly("iterations", &ImpactResult::iterations, "Distance queries made.")
      .def_readonly("piece_a", &ImpactResult::piece_a,
                    "Compound bodies: A's piece of the pair that met (at_t's features are its "
                    "hull's); a mesh: its triangle; -1 for a convex body.")
      .def_readonly("piece_b", &ImpactResult::piece_b, "B's piece of the pair that met, as piece_a.")
      .def_readonly("pairs_advanced", &ImpactResult::pairs_advanced,
                    "Piece pairs whose advancement ran; the others were pruned by their moving "
                    "bounding balls.")
      .def("__repr__", [](const ImpactResult& r) {
        return std::string("proxima.ImpactResult(status='") + to_string(r.status) +
               "', t=" + py::repr(py::float_(r.t)).cast<std::string>() + ")";
      });

  const ImpactOptions defaults;
  m.def(
      "time_of_impact",
      [](py::handle a, py::handle motion_a, py::handle b, py::handle motion_b,
         double target_separation, double tolerance, int max_iterations, py::object cache) {
        const Motion ma = to_motion(motion_a, "motion_a");
        const Motion mb = to_motion(motion_b, "motion_b");
        ImpactOptions options;
        options.target_separation = target_separation;
        options.tolerance = tolerance;
        options.max_iterations = max_iterations;
        const bool convex_pair =
            py::isinstance<ConvexPolytope>(a) && py::isinstance<ConvexPolytope>(b);
        if (convex_pair && (cache.is_none() || py::isinstance<PyDistanceCache>(cache))) {
          const ConvexPolytope& pa = a.cast<const ConvexPolytope&>();
          const ConvexPolytope& pb = b.cast<const ConvexPolytope&>();
          if (cache.is_none()) {
            const py::gil_scoped_release release;
            return time_of_impact(pa, ma, pb, mb, options, nullptr);
          }
          PyDistanceCache& c = cache.cast<PyDistanceCache&>();
          const InUse in_use(c, "DistanceCache");
          const py::gil_scoped_release release;
          return time_of_impact(pa, ma, pb, mb, options, &c);
        }
        // Any other kinds: Bodies (a BodyCache, or none).
        const Body ba = to_body(a, "a");
        const Body bb = to_body(b, "b");
        if (cache.is_none()) {
          const py::gil_scoped_release release;
          return time_of_impact(ba, ma, bb, mb, options, nullptr);
        }
        if (!py::isinstance<Guarded<BodyCache>>(cache)) {
          throw py::type_error(
              "cache: expected a DistanceCache for two ConvexPolytopes, else a "
              "BodyCache");
        }
        Guarded<BodyCache>& c = cache.cast<Guarded<BodyCache>&>();
        const InUse in_use(c, "BodyCache");
        const py::gil_scoped_release release;
        return time_of_impact(ba, ma, bb, mb, options, &c);
      },
      py::arg("a"), py::arg("motion_a"), py::arg("b"), py::arg("motion_b"),
      py::arg("target_separation") = defaults.target_separation,
      py::arg("tolerance") = defaults.tolerance,
      py::arg("max_iterations") = defaults.max_iterations, py::arg("cache") = py::none(),
      R"doc(First time of contact of body a moving by motion_a and body b moving by motion_b over t in [0, 1].

Bodies: ConvexPolytope, CompoundBody or Body (a radius adds to the target separation). Motions: a proxima.Motion or a (start, end) pair of poses. The reported t is never after the true
first time the distance comes within target_separation (no contact is missed, however fast or
thin the bodies); for status 'contact' the distance at t is within tolerance of the target
(tolerance 0: 1e-6 of the bodies' size). cache: carried from step to step, a DistanceCache for
two ConvexPolytopes, else a BodyCache.)doc");
}

}  // namespace proxima::python
