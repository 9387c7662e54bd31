// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Python bindings: TriangleMesh (from (V, 3) and (F, 3) numpy arrays or a
// file), and load_body, which reads a file as the kind of body the caller
// names (mesh, hull or pieces). A mesh meets any body through distance()
// (body.cpp), which answers a BodyResult with the closest triangles.
#include "proxima/query/mesh_distance.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "convert.h"
#include "proxima/io.h"

namespace proxima::python {
namespace {

// An (F, 3) array of integer vertex indices; a float array is refused (an
// index is not a coordinate), as is a negative index (named by the mesh).
std::vector<std::array<std::int32_t, 3>> to_triangles(py::handle obj) {
  const py::array raw = py::array::ensure(obj);
  if (!raw) value_error("triangles: expected an (F, 3) array of vertex indices");
  if (raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u') {
    value_error("triangles: expected integer vertex indices, got dtype " +
                py::str(raw.dtype()).cast<std::string>());
  }
  const auto a = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(raw);
  if (a.ndim() != 2 || a.shape(1) != 3)
    value_error("triangles: expected an (F, 3) array, got shape " + shape_of(a));
  std::vector<std::array<std::int32_t, 3>> out(static_cast<std::size_t>(a.shape(0)));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    for (int j = 0; j < 3; ++j) {
      const std::int64_t v = r(i, j);
      if (v < 0 || v > std::numeric_limits<std::int32_t>::max()) {
        value_error("triangles: triangle " + std::to_string(i) + " has vertex index " +
                    std::to_string(v) + ", outside [0, 2^31)");
      }
      out[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = static_cast<std::int32_t>(v);
    }
  }
  return out;
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<TriangleMesh, std::shared_ptr<TriangleMesh>>(
      m, "TriangleMesh",
      "A triangle mesh as given (non-convex, open or closed, a soup; degenerate triangles "
      "kept and measured as the segments or points they are) under a bounding-volume "
      "hierarchy. Immutable; shareable between threads. distance() takes it against any "
      "body; a closed, consistently oriented mesh has an inside (a body within it is "
      "intersecting), an open one only its surface.")
      .def(py::init([](py::object vertices, py::object triangles) {
             const std::vector<Vec3> v = to_points(vertices);
             const auto t = to_triangles(triangles);
             py::gil_scoped_release release;
             return std::make_shared<TriangleMesh>(std::span<const Vec3>(v),
                                                   std::span<const std::array<std::int32_t, 3>>(t));
           }),
           py::arg("vertices"), py::arg("triangles"),
           "vertices: (V, 3) float array; triangles: (F, 3) integer array of vertex indices. "
           "Raises InvalidInput (ValueError) naming the vertex or triangle: no vertices or "
           "triangles, NaN/infinite coordinates, an index out of range.")
      .def_static(
          "from_file",
          [](const std::string& path) {
            return std::make_shared<TriangleMesh>(
                read_file(path, [](const std::string& p) { return load_mesh(p); }).mesh);
          },
          py::arg("path"),
          "The surface of an OBJ or STL file as given. Raises FileError (ValueError) for a bad "
          "file or one without faces, FileNotFoundError for a missing one.")
      .def_property_readonly("vertex_count", &TriangleMesh::vertex_count, "Number of vertices.")
      .def_property_readonly("triangle_count", &TriangleMesh::triangle_count,
                             "Number of triangles.")
      .def_property_readonly(
          "vertices", [](const TriangleMesh& t) { return points_array(t.vertices()); },
          "(V, 3) array, a copy.")
      .def_property_readonly(
          "triangles",
          [](const TriangleMesh& t) {
            Int32Array out({static_cast<py::ssize_t>(t.triangle_count()), py::ssize_t{3}});
            auto w = out.mutable_unchecked<2>();
            for (int i = 0; i < t.triangle_count(); ++i) {
              for (int j = 0; j < 3; ++j)
                w(i, j) = static_cast<std::int32_t>(t.triangle(i)[static_cast<std::size_t>(j)]);
            }
            return out;
          },
          "(F, 3) int32 array, a copy.")
      .def_property_readonly(
          "degenerate_triangles",
          [](const TriangleMesh& t) { return int32_array(t.degenerate_triangles()); },
          "Indices of the zero-area triangles (decided exactly).")
      .def_property_readonly("is_closed", &TriangleMesh::is_closed,
                             "Every edge shared by exactly two triangles in opposite directions: "
                             "the mesh has an inside.")
      .def_property_readonly("scale", &TriangleMesh::scale, "Largest absolute coordinate.")
      .def_property_readonly("memory_bytes", &TriangleMesh::memory_bytes,
                             "Bytes held (vertices, triangles, hierarchy).")
      .def(
          "contains",
          [](const TriangleMesh& t, py::object p) { return t.contains(to_vec3(p, "p")); },
          py::arg("p"),
          "Whether point p (mesh frame) is inside this closed mesh (exact predicates); False "
          "for an open mesh or a point on the surface.")
      .def("__repr__", [](const TriangleMesh& t) {
        return "proxima.TriangleMesh(vertices=" + std::to_string(t.vertex_count()) +
               ", triangles=" + std::to_string(t.triangle_count()) +
               (t.is_closed() ? ", closed" : ", open") + ")";
      });

  m.def(
      "load_body",
      [](const std::string& path, const std::string& as, double radius) {
        const LoadAs kind = load_as_from_string(as);
        return read_file(path, [kind](const std::string& p) { return load_body(p, kind); })
            .with_radius(radius);
      },
      py::arg("path"), py::arg("as_"), py::arg("radius") = 0.0,
      "A mesh file as a Body of the kind named: as_='mesh' (the surface as given, a "
      "TriangleMesh), 'hull' (the convex hull of every point) or 'pieces' (one hull per OBJ "
      "group, a CompoundBody). Nothing is chosen for you: a non-convex file read as 'hull' is "
      "its hull.");
}

}  // namespace proxima::python
