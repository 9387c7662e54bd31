// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the Python side of bodies with a radius and of the primitives
// (Body, BodyCache, BodyResult, box, sphere, capsule, cylinder, cone,
// polygon_sides) and the distance overload for any two bodies: a
// ConvexPolytope, a CompoundBody or a Body on either side. Same conventions
// as module.cpp: names one for one with C++ (the primitives without the
// make_ prefix), arrays are numpy copies, enums are strings, queries
// release the GIL.
#include "proxima/query/body_distance.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "convert.h"
#include "proxima/query/compound_distance.h"
#include "proxima/shape/primitives.h"

namespace proxima::python {
// A Body from a Body, a ConvexPolytope or a CompoundBody (radius 0): the
// core is shared, not copied. Anything else is a TypeError naming the
// argument and its type (declared in convert.h).
Body to_body(py::handle obj, const char* name) {
  if (py::isinstance<Body>(obj)) return obj.cast<const Body&>();
  if (py::isinstance<ConvexPolytope>(obj)) {
    return Body(std::shared_ptr<const ConvexPolytope>(obj.cast<std::shared_ptr<ConvexPolytope>>()));
  }
  if (py::isinstance<CompoundBody>(obj)) {
    return Body(std::shared_ptr<const CompoundBody>(obj.cast<std::shared_ptr<CompoundBody>>()));
  }
  if (py::isinstance<TriangleMesh>(obj)) {
    return Body(std::shared_ptr<const TriangleMesh>(obj.cast<std::shared_ptr<TriangleMesh>>()));
  }
  throw py::type_error(
      std::string(name) +
      ": expected a ConvexPolytope, a CompoundBody, a TriangleMesh or a Body, got " +
      py::str(py::type::handle_of(obj).attr("__name__")).cast<std::string>());
}

namespace {


const char* kind_name(const Body& b) {
  switch (b.kind()) {
    case Body::Kind::convex:
      return "convex";
    case Body::Kind::compound:
      return "compound";
    case Body::Kind::mesh:
      return "mesh";
  }
  return "?";
}

// The core of Body(core, radius): a polytope, a compound, a Body (its core)
// or an (N, 3) array of points (hulled).
Body core_body(py::handle obj) {
  if (py::isinstance<Body>(obj) || py::isinstance<ConvexPolytope>(obj) ||
      py::isinstance<CompoundBody>(obj) || py::isinstance<TriangleMesh>(obj)) {
    return to_body(obj, "core");
  }
  return Body(std::make_shared<const ConvexPolytope>(to_points(obj)));
}

}  // namespace

void bind_bodies(py::module_& m) {
  py::class_<Body>(
      m, "Body",
      "A convex, compound or mesh core plus a radius: the Minkowski sum of the core with a "
      "ball (a sphere is a point with a radius, a capsule a segment with one). "
      "Immutable; shares its core; shareable between threads.")
      .def(py::init([](py::object core, double radius) {
             const Body body = core_body(core);
             return Body(body).with_radius(radius);
           }),
           py::arg("core"), py::arg("radius") = 0.0,
           "core: a ConvexPolytope, a CompoundBody (every piece gets the radius), a TriangleMesh, "
           "a Body (its "
           "core) or an (N, 3) array of points (hulled). radius: finite and >= 0, in the "
           "core's units; raises InvalidInput otherwise.")
      .def_property_readonly(
          "kind", [](const Body& b) { return kind_name(b); }, "'convex', 'compound' or 'mesh'.")
      .def_property_readonly(
          "mesh",
          [](const Body& b) -> py::object {
            if (!b.mesh()) return py::none();
            return py::cast(std::const_pointer_cast<TriangleMesh>(b.mesh()));
          },
          "The mesh core (TriangleMesh), or None for another kind.")
      .def_property_readonly(
          "convex",
          [](const Body& b) -> py::object {
            if (!b.convex()) return py::none();
            return py::cast(std::const_pointer_cast<ConvexPolytope>(b.convex()));
          },
          "The convex core (ConvexPolytope), or None for another kind.")
      .def_property_readonly(
          "compound",
          [](const Body& b) { return std::const_pointer_cast<CompoundBody>(b.compound()); },
          "The compound core; for a convex body, its one-piece compound; None for a mesh.")
      .def_property_readonly("radius", &Body::radius, "The radius (>= 0).")
      .def_property_readonly(
          "approximation_error", &Body::approximation_error,
          "How far the body may be from the true shape it stands for (cylinder, cone): 0 for "
          "exact bodies.")
      .def_property_readonly("scale", &Body::scale,
                             "Largest absolute coordinate of the core plus the radius.")
      .def("with_radius", &Body::with_radius, py::arg("radius"),
           "The same core with another radius.")
      .def("__repr__", [](const Body& b) {
        return std::string("proxima.Body(") + kind_name(b) +
               ", radius=" + py::repr(py::float_(b.radius())).cast<std::string>() + ")";
      });

  m.def(
      "box",
      [](py::object half_extents, double radius) {
        return make_box(to_vec3(half_extents, "half_extents"), radius);
      },
      py::arg("half_extents"), py::arg("radius") = 0.0,
      "A box spanning [-h, h] on each axis (h = half_extents), rounded by radius (it then "
      "reaches h + radius).");
  m.def("sphere", &make_sphere, py::arg("radius"), "A ball at the origin: a point with a radius.");
  m.def("capsule", &make_capsule, py::arg("half_length"), py::arg("radius"),
        "The segment from (0, 0, -half_length) to (0, 0, half_length) with a radius.");
  m.def("cylinder", &make_cylinder, py::arg("radius"), py::arg("half_length"), py::arg("tolerance"),
        "A cylinder about z (|z| <= half_length) as a prism over a regular polygon around the "
        "circle: it holds the true cylinder and strays from it by at most tolerance "
        "(Body.approximation_error, the exact deviation).");
  m.def("cone", &make_cone, py::arg("radius"), py::arg("half_length"), py::arg("tolerance"),
        "A cone about z: base disc of radius at z = -half_length, apex at z = half_length, as a "
        "pyramid over the cylinder's polygon (same tolerance rule).");
  m.def(
      "polygon_sides",
      [](double radius, double tolerance) {
        const PolygonApproximation p = polygon_sides(radius, tolerance);
        return py::make_tuple(p.sides, p.circumradius, p.deviation);
      },
      py::arg("radius"), py::arg("tolerance"),
      "(sides, circumradius, deviation) of the polygon that cylinder and cone use.");

  py::class_<PyBodyCache>(
      m, "BodyCache",
      "Coherence between Body queries of one pair (the convex or compound cache, and the "
      "penetration cache while cores overlap). A new cache is cold; one per pair, from one "
      "thread at a time.")
      .def(py::init<>(), "A cold cache.")
      .def(
          "is_cold",
          [](const PyBodyCache& c) {
            const InUse in_use(c, "BodyCache");
            return c.is_cold();
          },
          "True when the cache holds nothing.")
      .def(
          "reset",
          [](PyBodyCache& c) {
            const InUse in_use(c, "BodyCache");
            c.reset();
          },
          "Makes the cache cold again.")
      .def("__repr__", [](const PyBodyCache& c) {
        const InUse in_use(c, "BodyCache");
        return std::string("proxima.BodyCache(") + (c.is_cold() ? "cold" : "warm") + ")";
      });

  py::class_<BodyResult, DistanceResult>(
      m, "BodyResult",
      "The answer for two bodies with radii: distance, points (on the rounded surfaces), "
      "normal, status and signed distance (with its bounds) of the rounded bodies; features of "
      "the cores.")
      .def_readonly("piece_a", &BodyResult::piece_a, "Piece of A (compound), else -1.")
      .def_readonly("piece_b", &BodyResult::piece_b, "Piece of B (compound), else -1.")
      .def_readonly("triangle_a", &BodyResult::triangle_a,
                    "Closest triangle of A (mesh), else -1.")
      .def_readonly("triangle_b", &BodyResult::triangle_b,
                    "Closest triangle of B (mesh), else -1.")
      .def_readonly("intersecting", &BodyResult::intersecting,
                    "Whether the cores themselves overlap (the value is then from their "
                    "penetration depth).")
      .def_readonly("approximation_error", &BodyResult::approximation_error,
                    "Both bodies' approximation_error: the answer is within this of the true "
                    "shapes' answer.")
      .def("__repr__", [](const BodyResult& r) {
        return std::string("proxima.BodyResult(status='") + to_string(r.status) +
               "', signed_distance=" +
               py::repr(py::float_(r.signed_distance())).cast<std::string>() + ")";
      });

  const DistanceOptions defaults;
  m.def(
      "distance",
      [](py::object a, py::object pose_a, py::object b, py::object pose_b, PyBodyCache* cache,
         const std::string& algorithm, double relative_tolerance, double absolute_tolerance,
         int max_iterations, bool penetration) {
        const DistanceOptions options = make_options(
            algorithm, relative_tolerance, absolute_tolerance, max_iterations, penetration);
        const Body body_a = to_body(a, "a");
        const Body body_b = to_body(b, "b");
        const Pose pa = to_pose(pose_a, "pose_a");
        const Pose pb = to_pose(pose_b, "pose_b");
        std::optional<InUse> in_use;
        if (cache != nullptr) in_use.emplace(*cache, "BodyCache");
        py::gil_scoped_release release;
        return distance(body_a, pa, body_b, pb, options, static_cast<BodyCache*>(cache));
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      py::arg("penetration") = defaults.penetration,
      "Any two bodies: a ConvexPolytope, a CompoundBody, a TriangleMesh or a Body on either side "
      "(two polytopes "
      "or two compounds take the overloads above). cache: a BodyCache or None. Returns a "
      "BodyResult. penetration=False skips the depth of overlapping cores: their signed value "
      "is then 0 with bounds [-inf, 0] (signed distance minus the radii). With a TriangleMesh on "
      "either side the triangle pairs are solved in closed form: only absolute_tolerance applies, "
      "another algorithm, relative_tolerance or max_iterations than the defaults is refused "
      "(InvalidInput naming the field), and an overlap has no depth. A ConvexPolytope met "
      "with a compound is wrapped on every call (O(N)): for "
      "tracked queries, wrap it once as a Body.");
}

}  // namespace proxima::python
