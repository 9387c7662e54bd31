// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the Python module `proxima`. Names follow the C++ API one for one
// (ConvexPolytope, DistanceCache, DistanceResult, Feature, Pose, distance,
// distance_batch, read_points, load_convex); what changes is only the
// Python side of the types: arrays are numpy arrays (copies: a result never
// aliases C++ memory that could go away), enums are strings, options are
// keyword arguments named after DistanceOptions' fields.
//
// Errors: proxima.InvalidInput and proxima.FileError (both ValueError) carry
// the C++ message; a mesh file that does not exist raises FileNotFoundError
// with the same message; a wrong array shape raises ValueError.
#include <Python.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "convert.h"
#include "proxima/query/batch.h"
#include "proxima/query/distance.h"
#include "proxima/io.h"
#include "proxima/shape/polytope.h"
#include "proxima/query/signed_distance.h"
#include "proxima/core/types.h"

namespace py = pybind11;

namespace proxima {
namespace {

const char* const kModuleDoc =
    R"doc(proxima: minimum distance, closest points and closest features between convex polyhedra.

    import numpy as np, proxima
    a = proxima.ConvexPolytope(np.random.default_rng(1).normal(size=(50, 3)))
    b = proxima.ConvexPolytope.from_file("body.obj")
    cache = proxima.DistanceCache()                       # cold; keep it for tracking
    r = proxima.distance(a, None, b, proxima.Pose.from_translation((5, 0, 0)), cache=cache)
    r.status, r.distance, r.point_a, r.point_b

Poses are None (identity), 4x4 or 3x4 rigid matrices, scipy Rotation objects,
(rotation, translation) pairs (rotation: a 3x3 matrix or a scipy Rotation) or
proxima.Pose objects. A quaternion always names its order:
Pose.from_wxyz(q, t) (scalar first) or Pose.from_xyzw(q, t) (ROS, scipy's
as_quat(), PyBullet); a bare quaternion in a pair is refused with both of its
readings, since in the other order it is another rotation. Bad input raises proxima.InvalidInput (a
ValueError) with the C++ message; a missing file raises FileNotFoundError.
)doc";

using namespace proxima::python;

// InvalidInput, FileError and NonConvexInputWarning.
void bind_exceptions(py::module_& m) {
  const auto invalid_input =
      py::register_exception<InvalidInput>(m, "InvalidInput", PyExc_ValueError);
  invalid_input.doc() =
      "Bad input (NaN, empty point list, non-finite pose, size mismatch); a ValueError.";
  py::register_exception<FileError>(m, "FileError", invalid_input).doc() =
      "A mesh file that cannot be read; the message names the file, the line or byte offset and "
      "the problem.";

  m.attr("NonConvexInputWarning") = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "proxima.NonConvexInputWarning",
      "Warned by ConvexPolytope.from_file and CompoundBody.from_file when the file's surface "
      "is not convex (see LoadedPolytope.input_was_convex): the hull of all points is used.",
      PyExc_UserWarning, nullptr));

}

// Pose.
void bind_pose(py::module_& m) {
  // --- Pose -----------------------------------------------------------------
  py::class_<Pose>(m, "Pose", "A rigid motion: x -> rotation @ x + translation.")
      .def(py::init<>(), "The identity.")
      .def(py::init([](py::object rotation, py::object translation) {
             return checked_pose(
                 Pose(to_mat3(rotation, "rotation"), to_vec3(translation, "translation")),
                 "rotation");
           }),
           py::arg("rotation"), py::arg("translation"),
           "From a 3x3 rotation matrix and a translation.")
      .def_static(
          "from_wxyz",
          [](py::object q, py::object t) {
            return pose_from_quaternion(q, t, "pose", QuaternionOrder::wxyz);
          },
          py::arg("quaternion"), py::arg("translation") = py::none(),
          "From a quaternion in the order (w, x, y, z) (scalar first: Eigen, the CLI's "
          "{\"wxyz\": ...}), normalized here, and a translation (default zero).")
      .def_static(
          "from_xyzw",
          [](py::object q, py::object t) {
            return pose_from_quaternion(q, t, "pose", QuaternionOrder::xyzw);
          },
          py::arg("quaternion"), py::arg("translation") = py::none(),
          "From a quaternion in the order (x, y, z, w) (scalar last: ROS, scipy's as_quat(), "
          "PyBullet), normalized here, and a translation (default zero).")
      .def_static(
          "from_quaternion",
          [](py::object q, py::object t, py::object order) {
            if (order.is_none()) {
              refuse_unnamed_quaternion(q, "Pose.from_quaternion",
                                        "Name it: order='wxyz' or order='xyzw' (ROS, scipy's "
                                        "as_quat()), or Pose.from_wxyz / Pose.from_xyzw");
            }
            const std::string name = py::str(order);
            if (name != "wxyz" && name != "xyzw") {
              value_error("Pose.from_quaternion: order must be 'wxyz' or 'xyzw', not " +
                          std::string(py::str(py::repr(order))));
            }
            return pose_from_quaternion(
                q, t, "pose", name == "wxyz" ? QuaternionOrder::wxyz : QuaternionOrder::xyzw);
          },
          py::arg("quaternion"), py::arg("translation") = py::none(), py::kw_only(),
          py::arg("order") = py::none(),
          "From a quaternion in the order named by the keyword order ('wxyz' or 'xyzw', "
          "required: without it the quaternion is refused with both of its readings), "
          "normalized here, and a translation (default zero).")
      .def_static(
          "from_rotation",
          [](py::object r, py::object t) {
            return Pose(to_rotation(r, "rotation"), translation_or_zero(t, "pose"));
          },
          py::arg("rotation"), py::arg("translation") = py::none(),
          "From a scipy.spatial.transform.Rotation (one) or a 3x3 rotation matrix, and a "
          "translation (default zero).")
      .def_static(
          "from_matrix", [](py::object matrix) { return to_pose(matrix, "matrix"); },
          py::arg("matrix"),
          "From a 4x4 rigid transformation matrix or its top three rows (3x4, [R | t]).")
      .def_static("identity", &Pose::identity, "The identity.")
      .def_static(
          "from_translation",
          [](py::object t) { return Pose::from_translation(to_vec3(t, "translation")); },
          py::arg("translation"), "A pure translation.")
      .def_property_readonly(
          "rotation", [](const Pose& p) { return matrix_array(p.rotation); },
          "3x3 rotation matrix (a copy).")
      .def_property_readonly(
          "translation", [](const Pose& p) { return vec3_array(p.translation); },
          "Translation (a copy).")
      .def(
          "apply",
          [](const Pose& p, py::object x) { return vec3_array(p.apply(to_vec3(x, "point"))); },
          py::arg("point"), "rotation @ point + translation.")
      .def("inverse", &Pose::inverse, "The inverse motion.")
      .def("is_finite", &Pose::is_finite, "True when no entry is NaN or infinite.")
      .def(
          "matrix",
          [](const Pose& p) {
            Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
            out.topLeftCorner<3, 3>() = p.rotation;
            out.topRightCorner<3, 1>() = p.translation;
            return matrix_array(out);
          },
          "The 4x4 homogeneous matrix.")
      .def(
          "as_wxyz",
          [](const Pose& p) {
            const Quat q(p.rotation);
            return py::array_t<double>(4, std::array<double, 4>{q.w(), q.x(), q.y(), q.z()}.data());
          },
          "The rotation as a unit quaternion (w, x, y, z).")
      .def(
          "as_xyzw",
          [](const Pose& p) {
            const Quat q(p.rotation);
            return py::array_t<double>(4, std::array<double, 4>{q.x(), q.y(), q.z(), q.w()}.data());
          },
          "The rotation as a unit quaternion (x, y, z, w), as ROS and scipy order it.")
      .def(
          "__mul__", [](const Pose& a, const Pose& b) { return a * b; }, py::arg("other"),
          "Composition: (self * other).apply(p) == self.apply(other.apply(p)).")
      .def("__repr__", [](const Pose& p) {
        return "proxima.Pose(translation=" +
               py::repr(vec3_array(p.translation)).cast<std::string>() + ")";
      });

}

// ConvexPolytope.
void bind_polytope(py::module_& m) {
  // --- ConvexPolytope -------------------------------------------------------
  // Held by shared_ptr: a Scene or a CompoundBody keeps the polytopes it is given.
  py::class_<ConvexPolytope, std::shared_ptr<ConvexPolytope>>(
      m, "ConvexPolytope",
      "A convex polytope: the convex hull of a point set, built once and immutable (shareable "
      "between threads). Lower-dimensional hulls (polygon, segment, point) are valid.")
      .def(py::init([](py::object points) {
             const std::vector<Vec3> pts = to_points(points);
             py::gil_scoped_release release;
             return ConvexPolytope(pts);
           }),
           py::arg("points"),
           "Builds the hull of an (N, 3) array of points. Raises InvalidInput (ValueError) for no "
           "points or "
           "NaN/infinite coordinates, naming the index.")
      .def_static(
          "from_file",
          [](const std::string& path) {
            LoadedPolytope loaded =
                read_file(path, [](const std::string& p) { return load_convex(p); });
            if (!loaded.input_was_convex) {
              warn_non_convex(
                  path + ": not convex (" + std::to_string(loaded.interior_points) + " of " +
                  std::to_string(loaded.input_points) +
                  " points are not hull vertices; the surface is not the hull's boundary), "
                  "the hull of all points is used");
            }
            return std::move(loaded.polytope);
          },
          py::arg("path"),
          "The hull of the points of a mesh file (OBJ, OFF, STL, PLY, XYZ). Raises FileError "
          "(ValueError) for a bad "
          "file and FileNotFoundError for a missing one. A non-convex input (its surface is not "
          "its hull's boundary, as LoadedPolytope.input_was_convex defines it) warns "
          "NonConvexInputWarning, as the CLI reports 'not convex', and gives the hull; "
          "load_convex returns the report instead, without a warning.")
      .def_property_readonly("dimension", &ConvexPolytope::dimension,
                             "0 (point), 1 (segment), 2 (polygon), 3 (solid).")
      .def_property_readonly(
          "vertices", [](const ConvexPolytope& p) { return points_array(p.vertices()); },
          "Hull vertices, (V, 3) float64, in hull order.")
      .def_property_readonly(
          "input_index",
          [](const ConvexPolytope& p) { return int32_array(p.input_index().to_vector()); },
          "input_index[i]: the index in the input points of hull vertex i, (V,) int32.")
      .def_property_readonly("vertex_count", &ConvexPolytope::vertex_count,
                             "Number of hull vertices.")
      .def_property_readonly(
          "adjacency_offsets",
          [](const ConvexPolytope& p) { return int32_array(p.adjacency_offsets()); },
          "CSR offsets of the vertex adjacency, (V + 1,) int32: neighbours of v are "
          "adjacency[adjacency_offsets[v]:adjacency_offsets[v + 1]].")
      .def_property_readonly(
          "adjacency", [](const ConvexPolytope& p) { return int32_array(p.adjacency()); },
          "Neighbour vertex ids along the hull edges, int32 (see adjacency_offsets).")
      .def_property_readonly(
          "adjacency_faces",
          [](const ConvexPolytope& p) { return int32_array(p.adjacency_faces()); },
          "Parallel to adjacency: the face left of the directed edge v -> w, or -1, int32.")
      .def(
          "neighbors",
          [](const ConvexPolytope& p, int v) {
            return int32_array(p.neighbors(check_index(v, p.vertex_count(), "vertex")));
          },
          py::arg("v"), "Neighbour vertex ids of vertex v, int32.")
      .def_property_readonly("face_count", &ConvexPolytope::face_count,
                             "Number of faces (polygons).")
      .def_property_readonly(
          "faces",
          [](const ConvexPolytope& p) {
            py::list faces;
            for (int f = 0; f < p.face_count(); ++f) faces.append(int32_array(p.face(f)));
            return faces;
          },
          "List of faces, each an int32 array of vertex ids, counter-clockwise seen from outside.")
      .def(
          "face",
          [](const ConvexPolytope& p, int f) {
            return int32_array(p.face(check_index(f, p.face_count(), "face")));
          },
          py::arg("f"), "Vertex ids of face f, counter-clockwise seen from outside.")
      .def_property_readonly(
          "face_offsets", [](const ConvexPolytope& p) { return int32_array(p.face_offsets()); },
          "CSR offsets of the faces, (F + 1,) int32.")
      .def_property_readonly(
          "face_vertices", [](const ConvexPolytope& p) { return int32_array(p.face_vertices()); },
          "All faces' vertex ids concatenated, int32 (see face_offsets).")
      .def(
          "face_plane",
          [](const ConvexPolytope& p, int f) {
            const Plane plane = p.face_plane(check_index(f, p.face_count(), "face"));
            return py::make_tuple(vec3_array(plane.normal), plane.offset);
          },
          py::arg("f"),
          "(normal, offset) of face f: unit outward normal, normal @ x == offset on the face.")
      .def(
          "triangles", [](const ConvexPolytope& p) { return index_rows(p.triangles()); },
          "Fan triangulation of the faces, (T, 3) int32, outward orientation.")
      .def(
          "triangle_face",
          [](const ConvexPolytope& p) {
            const std::vector<std::int32_t> t = p.triangle_face();
            return int32_array(t);
          },
          "triangle_face[t]: the face that triangle t belongs to, (T,) int32.")
      .def(
          "edges", [](const ConvexPolytope& p) { return index_rows(p.edges()); },
          "Every hull edge once as (smaller id, larger id), (E, 2) int32.")
      .def_property_readonly("edge_count", &ConvexPolytope::edge_count, "Number of hull edges.")
      .def_property_readonly(
          "centroid", [](const ConvexPolytope& p) { return vec3_array(p.centroid()); },
          "Mean of the hull vertices.")
      .def_property_readonly("bounding_radius", &ConvexPolytope::bounding_radius,
                             "Largest distance from the centroid to a vertex.")
      .def_property_readonly(
          "scale", &ConvexPolytope::scale,
          "Largest absolute coordinate of a hull vertex (tolerances scale with it).")
      .def_property_readonly(
          "interior_point_count", &ConvexPolytope::interior_point_count,
          "Input points that did not become hull vertices (inside, on a face, or repeated).")
      .def("memory_bytes", &ConvexPolytope::memory_bytes, "Bytes held by the C++ object.")
      .def("__repr__", [](const ConvexPolytope& p) {
        return "proxima.ConvexPolytope(dimension=" + std::to_string(p.dimension()) +
               ", vertices=" + std::to_string(p.vertex_count()) +
               ", faces=" + std::to_string(p.face_count()) + ")";
      });

}

// Reading a polytope from a file.
void bind_polytope_files(py::module_& m) {
  py::class_<LoadedPolytope>(m, "LoadedPolytope",
                             "A polytope read from a file, with how convex the input was.")
      .def_property_readonly(
          "polytope",
          [](const LoadedPolytope& l) { return std::make_shared<ConvexPolytope>(l.polytope); },
          "The hull (ConvexPolytope).")
      .def_readonly("input_points", &LoadedPolytope::input_points, "Points read from the file.")
      .def_readonly("interior_points", &LoadedPolytope::interior_points,
                    "Input points that are not hull vertices (inside, on a face, or repeated).")
      .def_readonly("input_was_convex", &LoadedPolytope::input_was_convex,
                    "Whether the input surface is convex: every face (OBJ, STL) lies on a hull "
                    "facet, or, for a point cloud, every point is on the hull's boundary (see "
                    "surface_is_convex in proxima/io.h).");

  m.def(
      "load_convex",
      [](const std::string& path) {
        return read_file(path, [](const std::string& p) { return load_convex(p); });
      },
      py::arg("path"),
      "Reads a mesh file and builds the hull of all its points; reports a non-convex input in "
      "LoadedPolytope.input_was_convex (the CLI's 'convex' field) rather than failing or "
      "warning.");
  m.def(
      "read_points",
      [](const std::string& path) {
        return read_file(path,
                         [](const std::string& p) { return points_array(read_points(p).points); });
      },
      py::arg("path"), "The points of a mesh file (OBJ, OFF, STL, PLY, XYZ) as an (N, 3) array.");

}

// The distance cache, features and results.
void bind_results(py::module_& m) {
  // --- Cache, features, results ---------------------------------------------
  py::class_<PyDistanceCache>(
      m, "DistanceCache",
      "Coherence between queries of one pair, owned by the caller. A new cache is cold; "
      "passing the same cache to the next query of the same pair is tracking. Use one cache "
      "per pair, from one thread at a time: a query or reset() on a cache that a "
      "distance_batch is using in another thread raises RuntimeError.")
      .def(py::init<>(), "A cold cache.")
      .def_readwrite("vertices_a", &DistanceCache::vertices_a,
                     "Feature (or simplex) vertex ids on A, -1 unused.")
      .def_readwrite("vertices_b", &DistanceCache::vertices_b,
                     "Feature (or simplex) vertex ids on B, -1 unused.")
      .def_readwrite("hint_a", &DistanceCache::hint_a, "Last support vertex on A (-1: none).")
      .def_readwrite("hint_b", &DistanceCache::hint_b, "Last support vertex on B (-1: none).")
      .def("is_cold", &DistanceCache::is_cold, "True when the cache holds nothing.")
      .def(
          "reset",
          [](PyDistanceCache& c) {
            const InUse in_use(c, "DistanceCache");
            c.reset();
          },
          "Makes the cache cold again.")
      .def("__copy__", [](const PyDistanceCache& c) { return PyDistanceCache(c); })
      .def("__repr__", [](const PyDistanceCache& c) {
        return std::string("proxima.DistanceCache(") + (c.is_cold() ? "cold" : "warm") + ")";
      });

  py::class_<Feature>(m, "Feature", "A witness feature: a vertex, an edge or a face of a hull.")
      .def_property_readonly(
          "type", [](const Feature& f) { return to_string(f.type); }, "'vertex', 'edge' or 'face'.")
      .def_property_readonly(
          "vertices",
          [](const Feature& f) {
            return int32_array(std::span<const std::int32_t>(
                f.vertices.data(), static_cast<std::size_t>(f.vertex_count())));
          },
          "Hull vertex ids spanning the closest point (1 to 3), int32; the C++ array without its "
          "-1 padding.")
      .def_readonly("face", &Feature::face, "The hull face id for a face feature, else -1.")
      .def("vertex_count", &Feature::vertex_count, "Number of vertex ids.")
      .def("__repr__", [](const Feature& f) {
        std::string s = std::string("proxima.Feature(") + to_string(f.type) + ", vertices=[";
        for (int i = 0; i < f.vertex_count(); ++i)
          s += (i ? ", " : "") + std::to_string(f.vertices[static_cast<std::size_t>(i)]);
        return s + "], face=" + std::to_string(f.face) + ")";
      });

  py::class_<DistanceResult>(m, "DistanceResult",
                             "The answer of a distance query, points in the world frame.")
      .def_property_readonly(
          "status", [](const DistanceResult& r) { return to_string(r.status); },
          "'separated', 'touching', 'intersecting' or 'iteration_cap'.")
      .def_readonly("distance", &DistanceResult::distance,
                    "Upper bound: |point_a - point_b| (0 when intersecting).")
      .def_readonly("lower_bound", &DistanceResult::lower_bound,
                    "Certified lower bound on the exact distance.")
      .def_property_readonly(
          "point_a", [](const DistanceResult& r) { return vec3_array(r.point_a); },
          "Closest point on A, world frame (intersecting: the deepest point of A).")
      .def_property_readonly(
          "point_b", [](const DistanceResult& r) { return vec3_array(r.point_b); },
          "Closest point on B, world frame (intersecting: the deepest point of B, "
          "point_b + depth * normal == point_a).")
      .def_property_readonly(
          "normal", [](const DistanceResult& r) { return vec3_array(r.normal); },
          "Unit normal from A towards B (intersecting: the direction that separates).")
      .def_readonly("feature_a", &DistanceResult::feature_a, "Witness feature on A (hull ids).")
      .def_readonly("feature_b", &DistanceResult::feature_b, "Witness feature on B (hull ids).")
      .def_readonly("depth", &DistanceResult::depth,
                    "Penetration depth of an intersecting answer (0 otherwise): the length of "
                    "the shortest translation of B after which the bodies only touch.")
      .def_readonly("depth_lower_bound", &DistanceResult::depth_lower_bound,
                    "Certified lower bound on the depth.")
      .def_readonly("depth_upper_bound", &DistanceResult::depth_upper_bound,
                    "Certified upper bound on the depth (inf when it was not computed).")
      .def_property_readonly("signed_distance", &DistanceResult::signed_distance,
                             "distance when apart, minus the depth when intersecting.")
      .def_property_readonly("signed_lower_bound", &DistanceResult::signed_lower_bound,
                             "Certified lower bound on the signed distance.")
      .def_property_readonly("signed_upper_bound", &DistanceResult::signed_upper_bound,
                             "Certified upper bound on the signed distance.")
      .def_readonly("iterations", &DistanceResult::iterations, "Iterations the algorithm ran.")
      .def_readonly("second_algorithm", &DistanceResult::second_algorithm,
                    "True when the hybrid needed Enhanced GJK (contact classification or a "
                    "cross-check of an uncertified answer).")
      .def("__repr__", [](const DistanceResult& r) {
        return std::string("proxima.DistanceResult(status='") + to_string(r.status) +
               "', distance=" + py::repr(py::float_(r.distance)).cast<std::string>() +
               ", signed_distance=" +
               py::repr(py::float_(r.signed_distance())).cast<std::string>() + ")";
      });

  m.def(
      "signed_distance_gradient",
      [](py::object result, py::object pose_a, py::object pose_b) {
        const Pose pa = to_pose(pose_a, "pose_a");
        const Pose pb = to_pose(pose_b, "pose_b");
        // A Body answer through its own overload: a mesh overlap is refused
        // with its reason (no depth is defined for it).
        const SignedDistanceGradient g =
            py::isinstance<BodyResult>(result)
                ? signed_distance_gradient(result.cast<const BodyResult&>(), pa, pb)
                : signed_distance_gradient(result.cast<const DistanceResult&>(), pa, pb);
        py::array_t<double> out({py::ssize_t{2}, py::ssize_t{6}});
        auto o = out.mutable_unchecked<2>();
        for (int k = 0; k < 6; ++k) {
          o(0, k) = g.a[k];
          o(1, k) = g.b[k];
        }
        return out;
      },
      py::arg("result"), py::arg("pose_a"), py::arg("pose_b"),
      R"doc(The gradient of result.signed_distance with respect to each body's pose.

result: the answer of distance() (or of the compound distance) at pose_a, pose_b (the bodies'
poses of that query). Returns a (2, 6) array: row 0 for A, row 1 for B, each the derivative
along world translations (3) then along small rotations about world axes through the body's
origin (3). Exact where the witness pair is unique, else one-sided (a subgradient); raises
InvalidInput for an intersecting answer computed without the depth, or for an overlap with a
triangle mesh (no depth is defined for it: use the mesh's hull or convex pieces).)doc");

}

// distance() and distance_batch() of two polytopes.
void bind_distance_queries(py::module_& m) {
  // --- Queries --------------------------------------------------------------
  const DistanceOptions defaults;
  m.def(
      "distance",
      [](const ConvexPolytope& a, py::object pose_a, const ConvexPolytope& b, py::object pose_b,
         PyDistanceCache* cache, const std::string& algorithm, double relative_tolerance,
         double absolute_tolerance, int max_iterations, bool penetration,
         bool extended_precision) {
        DistanceOptions options = make_options(algorithm, relative_tolerance, absolute_tolerance,
                                               max_iterations, penetration);
        options.extended_precision = extended_precision;
        const Pose pa = to_pose(pose_a, "pose_a");
        const Pose pb = to_pose(pose_b, "pose_b");
        if (cache == nullptr) return distance(a, pa, b, pb, options, nullptr);
        // The GIL is held throughout; the flag catches a distance_batch of
        // another thread that is using this cache right now.
        const InUse in_use(*cache, "DistanceCache");
        return distance(a, pa, b, pb, options, cache);
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      py::arg("penetration") = defaults.penetration,
      py::arg("extended_precision") = defaults.extended_precision,
      R"doc(Minimum distance, closest points and features of hulls a and b placed at pose_a and pose_b.

Poses: None (identity), a 4x4 or 3x4 rigid matrix, a scipy Rotation, a (rotation, translation)
pair (rotation: a 3x3 matrix or a scipy Rotation) or a Pose. A quaternion names its order:
Pose.from_wxyz(q, t) or Pose.from_xyzw(q, t) (ROS, scipy); a bare one in a pair is refused.
cache: a DistanceCache updated in place (tracking) or None (cold).
algorithm: 'hybrid' (the paper), 'gjk' or 'enhanced_gjk'. The tolerances and the iteration cap are
DistanceOptions' fields. extended_precision: full relative accuracy, the witness pair's distance
(an overlap's depth) recomputed in double-double (docs/accuracy.md). Returns a DistanceResult.)doc");

  m.def(
      "distance_batch",
      [](const ConvexPolytope& a, py::object poses_a, const ConvexPolytope& b, py::object poses_b,
         py::object caches, int threads, const std::string& algorithm, double relative_tolerance,
         double absolute_tolerance, int max_iterations, bool penetration,
         bool extended_precision) {
        DistanceOptions options = make_options(algorithm, relative_tolerance, absolute_tolerance,
                                               max_iterations, penetration);
        options.extended_precision = extended_precision;
        py::ssize_t k = batch_size(poses_a);
        if (k < 0) k = batch_size(poses_b);
        const std::vector<Pose> pa = to_poses(poses_a, k, "poses_a");
        const std::vector<Pose> pb = to_poses(poses_b, k, "poses_b");
        const auto n = pa.size();
        // Caches: copied in, run without the GIL, copied back. The list's
        // objects are held so that they outlive the call.
        std::vector<py::object> cache_objects;
        if (!caches.is_none()) {
          const py::sequence seq = py::reinterpret_borrow<py::sequence>(caches);
          if (py::len(seq) != n) {
            value_error("caches: " + std::to_string(py::len(seq)) + " caches for " +
                        std::to_string(n) + " poses");
          }
          for (std::size_t i = 0; i < n; ++i) {
            py::object c = seq[i];
            if (!py::isinstance<PyDistanceCache>(c))
              value_error("caches[" + std::to_string(i) + "] is not a DistanceCache");
            cache_objects.push_back(std::move(c));
          }
        }
        std::vector<DistanceResult> results(n);
        {
          // Each cache is marked in use from its copy in to its copy back;
          // no Python code runs in between. A cache listed twice is held
          // once (its rows run on copies and the last row's copy is kept,
          // as before): the set of our own flags is only built when a flag
          // is found taken.
          std::vector<InUse> in_use;
          in_use.reserve(cache_objects.size());
          std::unordered_set<const std::atomic<bool>*> ours;
          std::vector<DistanceCache> cache_values;
          cache_values.reserve(cache_objects.size());
          for (const py::object& c : cache_objects) {
            PyDistanceCache& cache = c.cast<PyDistanceCache&>();
            if (std::optional<InUse> hold = InUse::try_hold(cache)) {
              if (!ours.empty()) ours.insert(hold->flag());
              in_use.push_back(std::move(*hold));
            } else {
              if (ours.empty()) {
                for (const InUse& h : in_use) ours.insert(h.flag());
              }
              if (!ours.contains(&cache.in_use_flag())) InUse::throw_busy("DistanceCache");
            }
            cache_values.push_back(cache);
          }
          {
            py::gil_scoped_release release;
            distance_batch(a, pa, b, pb, results, cache_values, options, threads);
          }
          for (std::size_t i = 0; i < cache_objects.size(); ++i) {
            static_cast<DistanceCache&>(cache_objects[i].cast<PyDistanceCache&>()) =
                cache_values[i];
          }
        }
        return batch_dict(results);
      },
      py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"),
      py::arg("caches") = py::none(), py::arg("threads") = 0,
      py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      py::arg("penetration") = defaults.penetration,
      py::arg("extended_precision") = defaults.extended_precision,
      R"doc(K distance queries of one pair of polytopes, run on the thread pool without the GIL.

poses_a, poses_b: (K, 4, 4) or (K, 3, 4) arrays of rigid matrices; one of them may be a single pose (4x4, a
(quaternion, translation) pair, a Pose) or None, used for all K.
caches: None (all cold) or a list of K DistanceCache, updated in place (tracking across calls).
threads: 0 for all cores, 1 for the calling thread only, n for n threads.
Returns a dict of arrays with K rows: status (str), distance, lower_bound, signed_distance,
signed_lower_bound, signed_upper_bound, point_a (K, 3),
point_b (K, 3), normal (K, 3), feature_a_type (str), feature_a_vertices (K, 3; -1 unused),
feature_a_face, the same for b, iterations. Row k equals distance(a, poses_a[k], b, poses_b[k]).)doc");

}

}  // namespace
}  // namespace proxima

PYBIND11_MODULE(_proxima, m) {
  using namespace proxima;
  using namespace proxima::python;
  // The package proxima re-exports every name: classes and functions say they are proxima.X.
  m.attr("__name__") = "proxima";
  m.doc() = kModuleDoc;

  bind_exceptions(m);
  bind_pose(m);
  bind_polytope(m);
  bind_polytope_files(m);
  bind_results(m);
  bind_distance_queries(m);
  // Before the scene: Scene.sweep's ImpactPair holds an ImpactResult, whose
  // type must be known when its property is bound (for its signature).
  bind_time_of_impact(m);
  bind_margin_result(m);
  bind_compound_and_scene(m);
  bind_pair_batch(m);
  bind_bodies(m);
  bind_margin_queries(m);
  bind_mesh(m);
  bind_view(m);
  bind_robot(m);
}
