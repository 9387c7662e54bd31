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

#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "proxima/batch.h"
#include "proxima/distance.h"
#include "proxima/io.h"
#include "proxima/polytope.h"
#include "proxima/types.h"

namespace py = pybind11;

namespace proxima {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int32Array = py::array_t<std::int32_t>;

// How far a 4x4 pose may be from a rigid motion and still be taken as one:
// max |R^T R - I| and max |bottom row - (0 0 0 1)|. Poses often arrive
// through float32 (graphics and mesh tools), whose rounding leaves R^T R off
// by a few 1e-7; a scale, shear or projective row any larger than this is a
// mistake, not rounding, and would be silently wrong: the query inverts the
// pose by transposing R.
constexpr double kRigidTolerance = 1e-6;

[[noreturn]] void value_error(const std::string& message) { throw py::value_error(message); }

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

DoubleArray as_double_array(py::handle obj, const std::string& name) {
  auto a = DoubleArray::ensure(obj);
  if (!a) value_error(name + ": expected an array of numbers");
  return a;
}

Vec3 to_vec3(py::handle obj, const std::string& name) {
  const DoubleArray a = as_double_array(obj, name);
  if (a.ndim() != 1 || a.shape(0) != 3)
    value_error(name + ": expected 3 numbers, got shape " + shape_of(a));
  return Vec3(a.at(0), a.at(1), a.at(2));
}

Mat3 to_mat3(py::handle obj, const std::string& name) {
  const DoubleArray a = as_double_array(obj, name);
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    value_error(name + ": expected a 3x3 matrix, got shape " + shape_of(a));
  }
  Mat3 m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m(i, j) = a.at(i, j);
  }
  return m;
}

// Numpy copies of Eigen values (row-major, as numpy prints them).
py::array_t<double> vec3_array(const Vec3& v) { return py::array_t<double>(3, v.data()); }

template <int kRows, int kCols>
py::array_t<double> matrix_array(const Eigen::Matrix<double, kRows, kCols>& m) {
  py::array_t<double> out({py::ssize_t{kRows}, py::ssize_t{kCols}});
  auto o = out.mutable_unchecked<2>();
  for (int i = 0; i < kRows; ++i) {
    for (int j = 0; j < kCols; ++j) o(i, j) = m(i, j);
  }
  return out;
}

// Rejects a finite matrix that is not a proper rotation (a non-finite one is
// left to the C++ query, whose InvalidInput says so).
void check_rigid(const Mat3& r, const Eigen::Vector4d& bottom, const std::string& name) {
  if (!r.allFinite() || !bottom.allFinite()) return;
  const double off_rigid = (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff();
  const double off_bottom = (bottom - Eigen::Vector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff();
  if (off_bottom > kRigidTolerance)
    value_error(name + ": the bottom row of a pose matrix must be (0, 0, 0, 1)");
  if (off_rigid > kRigidTolerance || r.determinant() < 0) {
    value_error(name + ": the rotation part is not a rotation (max |R^T R - I| = " +
                std::to_string(off_rigid) + ", det = " + std::to_string(r.determinant()) +
                "); proxima takes rigid motions only");
  }
}

Pose pose_from_matrix(const double* m, const std::string& name) {
  Mat3 r;
  Vec3 t;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = m[4 * i + j];
    t[i] = m[4 * i + 3];
  }
  check_rigid(r, Eigen::Vector4d(m[12], m[13], m[14], m[15]), name);
  return {r, t};
}

Pose pose_from_quaternion(py::handle q_obj, py::handle t_obj, const std::string& name) {
  const DoubleArray q = as_double_array(q_obj, name + " quaternion");
  if (q.ndim() != 1 || q.shape(0) != 4) {
    value_error(name + ": the quaternion must be 4 numbers (w, x, y, z), got shape " + shape_of(q));
  }
  const Quat quat(q.at(0), q.at(1), q.at(2), q.at(3));
  // Eigen leaves a zero quaternion unnormalized, which would be a zero
  // "rotation": refuse it here (a NaN one is left to the query's check).
  if (quat.coeffs().squaredNorm() == 0.0) value_error(name + ": the quaternion is zero");
  return {quat, to_vec3(t_obj, name + " translation")};
}

// A pose argument: None (identity), a proxima.Pose, a 4x4 matrix or a
// (quaternion wxyz, translation) pair.
Pose to_pose(py::handle obj, const std::string& name) {
  if (obj.is_none()) return Pose{};
  if (py::isinstance<Pose>(obj)) return obj.cast<Pose>();
  if ((py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) && py::len(obj) == 2) {
    return pose_from_quaternion(obj[py::int_(0)], obj[py::int_(1)], name);
  }
  const DoubleArray m = as_double_array(obj, name);
  if (m.ndim() != 2 || m.shape(0) != 4 || m.shape(1) != 4) {
    value_error(
        name +
        ": expected None, a 4x4 matrix, a (quaternion wxyz, translation) pair or a proxima.Pose; "
        "got an array of shape " +
        shape_of(m));
  }
  return pose_from_matrix(m.data(), name);
}

// K poses for a batch: None (K identities), one pose for all, or a (K, 4, 4)
// array. `k` is the batch size, or -1 when this argument decides it.
std::vector<Pose> to_poses(py::handle obj, py::ssize_t k, const std::string& name) {
  if (obj.is_none() || py::isinstance<Pose>(obj) || py::isinstance<py::tuple>(obj)) {
    if (k < 0)
      value_error(name +
                  ": give K poses as a (K, 4, 4) array (the other poses may be one pose or None)");
    return std::vector<Pose>(static_cast<std::size_t>(k), to_pose(obj, name));
  }
  const DoubleArray m = as_double_array(obj, name);
  if (m.ndim() == 2 && m.shape(0) == 4 && m.shape(1) == 4) {
    if (k < 0)
      value_error(name +
                  ": give K poses as a (K, 4, 4) array (the other poses may be one pose or None)");
    return std::vector<Pose>(static_cast<std::size_t>(k), pose_from_matrix(m.data(), name));
  }
  if (m.ndim() != 3 || m.shape(1) != 4 || m.shape(2) != 4) {
    value_error(name + ": expected a (K, 4, 4) array of poses, got shape " + shape_of(m));
  }
  if (k >= 0 && m.shape(0) != k) {
    value_error(name + ": " + std::to_string(m.shape(0)) + " poses, but the other side has " +
                std::to_string(k));
  }
  std::vector<Pose> poses;
  poses.reserve(static_cast<std::size_t>(m.shape(0)));
  for (py::ssize_t i = 0; i < m.shape(0); ++i) {
    poses.push_back(pose_from_matrix(m.data(i, 0, 0), name + "[" + std::to_string(i) + "]"));
  }
  return poses;
}

// The K of a batch from whichever pose argument is a (K, 4, 4) array.
py::ssize_t batch_size(py::handle obj) {
  if (obj.is_none() || py::isinstance<Pose>(obj) || py::isinstance<py::tuple>(obj)) return -1;
  auto m = DoubleArray::ensure(obj);
  return m && m.ndim() == 3 ? m.shape(0) : -1;
}

Algorithm to_algorithm(const std::string& name) {
  for (Algorithm a : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    if (name == to_string(a)) return a;
  }
  value_error("algorithm must be 'hybrid', 'gjk' or 'enhanced_gjk', got '" + name + "'");
}

DistanceOptions make_options(const std::string& algorithm, double relative_tolerance,
                             double absolute_tolerance, int max_iterations) {
  DistanceOptions options;
  options.algorithm = to_algorithm(algorithm);
  options.relative_tolerance = relative_tolerance;
  options.absolute_tolerance = absolute_tolerance;
  options.max_iterations = max_iterations;
  return options;
}

Int32Array int32_array(std::span<const std::int32_t> values) {
  return Int32Array(static_cast<py::ssize_t>(values.size()), values.data());
}

py::array_t<double> points_array(std::span<const Vec3> points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int j = 0; j < 3; ++j) o(static_cast<py::ssize_t>(i), j) = points[i][j];
  }
  return out;
}

template <std::size_t kColumns>
Int32Array index_rows(const std::vector<std::array<std::int32_t, kColumns>>& rows) {
  Int32Array out({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(kColumns)});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (std::size_t j = 0; j < kColumns; ++j)
      o(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = rows[i][j];
  }
  return out;
}

std::vector<Vec3> to_points(py::handle obj) {
  const DoubleArray a = as_double_array(obj, "points");
  if (a.ndim() != 2 || a.shape(1) != 3)
    value_error("points: expected an (N, 3) array, got shape " + shape_of(a));
  std::vector<Vec3> points(static_cast<std::size_t>(a.shape(0)));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    points[static_cast<std::size_t>(i)] = Vec3(r(i, 0), r(i, 1), r(i, 2));
  return points;
}

// Runs a reader; a file that does not exist becomes FileNotFoundError (with
// errno and filename set, as Python's open() does) carrying the C++ message.
template <class Read>
auto read_file(const std::string& path, Read read) {
  try {
    return read(path);
  } catch (const FileError& e) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      const py::object error =
          py::module_::import("builtins").attr("FileNotFoundError")(ENOENT, e.what(), path);
      PyErr_SetObject(PyExc_FileNotFoundError, error.ptr());
      throw py::error_already_set();
    }
    throw;
  }
}

int check_index(int i, int count, const char* what) {
  if (i < 0 || i >= count) {
    throw py::index_error(std::string(what) + " " + std::to_string(i) + " out of range [0, " +
                          std::to_string(count) + ")");
  }
  return i;
}

// The batch result as a dict of arrays (K rows each).
py::dict batch_dict(const std::vector<DistanceResult>& results) {
  const auto k = static_cast<py::ssize_t>(results.size());
  py::array_t<double> distance_(k), lower_bound(k), point_a({k, py::ssize_t{3}}),
      point_b({k, py::ssize_t{3}}), normal({k, py::ssize_t{3}});
  Int32Array iterations(k), face_a(k), face_b(k), vertices_a({k, py::ssize_t{3}}),
      vertices_b({k, py::ssize_t{3}});
  py::array_t<std::uint8_t> status_code(k), type_a(k), type_b(k);
  auto d = distance_.mutable_unchecked<1>();
  auto lb = lower_bound.mutable_unchecked<1>();
  auto pa = point_a.mutable_unchecked<2>();
  auto pb = point_b.mutable_unchecked<2>();
  auto n = normal.mutable_unchecked<2>();
  auto it = iterations.mutable_unchecked<1>();
  auto fa = face_a.mutable_unchecked<1>();
  auto fb = face_b.mutable_unchecked<1>();
  auto va = vertices_a.mutable_unchecked<2>();
  auto vb = vertices_b.mutable_unchecked<2>();
  auto sc = status_code.mutable_unchecked<1>();
  auto ta = type_a.mutable_unchecked<1>();
  auto tb = type_b.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < k; ++i) {
    const DistanceResult& r = results[static_cast<std::size_t>(i)];
    d(i) = r.distance;
    lb(i) = r.lower_bound;
    for (int j = 0; j < 3; ++j) {
      pa(i, j) = r.point_a[j];
      pb(i, j) = r.point_b[j];
      n(i, j) = r.normal[j];
      va(i, j) = r.feature_a.vertices[static_cast<std::size_t>(j)];
      vb(i, j) = r.feature_b.vertices[static_cast<std::size_t>(j)];
    }
    it(i) = r.iterations;
    fa(i) = r.feature_a.face;
    fb(i) = r.feature_b.face;
    sc(i) = static_cast<std::uint8_t>(r.status);
    ta(i) = static_cast<std::uint8_t>(r.feature_a.type);
    tb(i) = static_cast<std::uint8_t>(r.feature_b.type);
  }
  // Strings by table lookup in numpy (one fancy-indexing call instead of K
  // Python strings).
  const py::module_ np = py::module_::import("numpy");
  py::list status_names, type_names;
  for (Status s :
       {Status::separated, Status::touching, Status::intersecting, Status::iteration_cap}) {
    status_names.append(to_string(s));
  }
  for (FeatureType t : {FeatureType::vertex, FeatureType::edge, FeatureType::face})
    type_names.append(to_string(t));
  const py::object status_table = np.attr("array")(status_names);
  const py::object type_table = np.attr("array")(type_names);

  py::dict out;
  out["status"] = status_table[status_code];
  out["distance"] = distance_;
  out["lower_bound"] = lower_bound;
  out["point_a"] = point_a;
  out["point_b"] = point_b;
  out["normal"] = normal;
  out["feature_a_type"] = type_table[type_a];
  out["feature_a_vertices"] = vertices_a;
  out["feature_a_face"] = face_a;
  out["feature_b_type"] = type_table[type_b];
  out["feature_b_vertices"] = vertices_b;
  out["feature_b_face"] = face_b;
  out["iterations"] = iterations;
  return out;
}

const char* const kModuleDoc =
    R"doc(proxima: minimum distance, closest points and closest features between convex polyhedra.

    import numpy as np, proxima
    a = proxima.ConvexPolytope(np.random.default_rng(1).normal(size=(50, 3)))
    b = proxima.ConvexPolytope.from_file("body.obj")
    cache = proxima.DistanceCache()                       # cold; keep it for tracking
    r = proxima.distance(a, None, b, ((1, 0, 0, 0), (5, 0, 0)), cache=cache)
    r.status, r.distance, r.point_a, r.point_b

Poses are None (identity), 4x4 rigid matrices, (quaternion wxyz, translation)
pairs or proxima.Pose objects. Bad input raises proxima.InvalidInput (a
ValueError) with the C++ message; a missing file raises FileNotFoundError.
)doc";

}  // namespace
}  // namespace proxima

PYBIND11_MODULE(proxima, m) {
  using namespace proxima;
  m.doc() = kModuleDoc;

  const auto invalid_input =
      py::register_exception<InvalidInput>(m, "InvalidInput", PyExc_ValueError);
  invalid_input.doc() =
      "Bad input (NaN, empty point list, non-finite pose, size mismatch); a ValueError.";
  py::register_exception<FileError>(m, "FileError", invalid_input).doc() =
      "A mesh file that cannot be read; the message names the file, the line or byte offset and "
      "the problem.";

  // --- Pose -----------------------------------------------------------------
  py::class_<Pose>(m, "Pose", "A rigid motion: x -> rotation @ x + translation.")
      .def(py::init<>(), "The identity.")
      .def(py::init([](py::object rotation, py::object translation) {
             const Mat3 r = to_mat3(rotation, "rotation");
             check_rigid(r, Eigen::Vector4d(0, 0, 0, 1), "rotation");
             return Pose(r, to_vec3(translation, "translation"));
           }),
           py::arg("rotation"), py::arg("translation"),
           "From a 3x3 rotation matrix and a translation.")
      .def_static(
          "from_quaternion",
          [](py::object q, py::object t) { return pose_from_quaternion(q, t, "pose"); },
          py::arg("quaternion"), py::arg("translation"),
          "From a quaternion (w, x, y, z), normalized here, and a translation.")
      .def_static(
          "from_matrix", [](py::object m4) { return to_pose(m4, "matrix"); }, py::arg("matrix"),
          "From a 4x4 rigid transformation matrix.")
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
          "__mul__", [](const Pose& a, const Pose& b) { return a * b; }, py::arg("other"),
          "Composition: (self * other).apply(p) == self.apply(other.apply(p)).")
      .def("__repr__", [](const Pose& p) {
        return "proxima.Pose(translation=" +
               py::repr(vec3_array(p.translation)).cast<std::string>() + ")";
      });

  // --- ConvexPolytope -------------------------------------------------------
  py::class_<ConvexPolytope>(
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
            return read_file(path, [](const std::string& p) { return load_convex(p).polytope; });
          },
          py::arg("path"),
          "The hull of the points of a mesh file (OBJ, OFF, STL, PLY, XYZ). Raises FileError "
          "(ValueError) for a bad "
          "file and FileNotFoundError for a missing one.")
      .def_property_readonly("dimension", &ConvexPolytope::dimension,
                             "0 (point), 1 (segment), 2 (polygon), 3 (solid).")
      .def_property_readonly(
          "vertices", [](const ConvexPolytope& p) { return points_array(p.vertices()); },
          "Hull vertices, (V, 3) float64, in hull order.")
      .def_property_readonly(
          "input_index", [](const ConvexPolytope& p) { return int32_array(p.input_index()); },
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

  py::class_<LoadedPolytope>(m, "LoadedPolytope",
                             "A polytope read from a file, with how convex the input was.")
      .def_readonly("polytope", &LoadedPolytope::polytope, "The hull (ConvexPolytope).")
      .def_readonly("input_points", &LoadedPolytope::input_points, "Points read from the file.")
      .def_readonly("interior_points", &LoadedPolytope::interior_points,
                    "Input points that are not hull vertices (inside, on a face, or repeated).")
      .def_readonly("input_was_convex", &LoadedPolytope::input_was_convex, "interior_points == 0.");

  m.def(
      "load_convex", [](const std::string& path) { return read_file(path, load_convex); },
      py::arg("path"),
      "Reads a mesh file and builds the hull of all its points; reports a non-convex input rather "
      "than failing.");
  m.def(
      "read_points",
      [](const std::string& path) {
        return read_file(path,
                         [](const std::string& p) { return points_array(read_points(p).points); });
      },
      py::arg("path"), "The points of a mesh file (OBJ, OFF, STL, PLY, XYZ) as an (N, 3) array.");

  // --- Cache, features, results ---------------------------------------------
  py::class_<DistanceCache>(
      m, "DistanceCache",
      "Coherence between queries of one pair, owned by the caller. A new cache is cold; "
      "passing the same cache to the next query of the same pair is tracking. Use one cache "
      "per pair, from one thread at a time.")
      .def(py::init<>(), "A cold cache.")
      .def_readwrite("vertices_a", &DistanceCache::vertices_a,
                     "Feature (or simplex) vertex ids on A, -1 unused.")
      .def_readwrite("vertices_b", &DistanceCache::vertices_b,
                     "Feature (or simplex) vertex ids on B, -1 unused.")
      .def_readwrite("hint_a", &DistanceCache::hint_a, "Last support vertex on A (-1: none).")
      .def_readwrite("hint_b", &DistanceCache::hint_b, "Last support vertex on B (-1: none).")
      .def("is_cold", &DistanceCache::is_cold, "True when the cache holds nothing.")
      .def("reset", &DistanceCache::reset, "Makes the cache cold again.")
      .def("__copy__", [](const DistanceCache& c) { return c; })
      .def("__repr__", [](const DistanceCache& c) {
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
          "Closest point on A, world frame.")
      .def_property_readonly(
          "point_b", [](const DistanceResult& r) { return vec3_array(r.point_b); },
          "Closest point on B, world frame.")
      .def_property_readonly(
          "normal", [](const DistanceResult& r) { return vec3_array(r.normal); },
          "Unit normal from A towards B.")
      .def_readonly("feature_a", &DistanceResult::feature_a, "Witness feature on A (hull ids).")
      .def_readonly("feature_b", &DistanceResult::feature_b, "Witness feature on B (hull ids).")
      .def_readonly("iterations", &DistanceResult::iterations, "Iterations the algorithm ran.")
      .def("__repr__", [](const DistanceResult& r) {
        return std::string("proxima.DistanceResult(status='") + to_string(r.status) +
               "', distance=" + py::repr(py::float_(r.distance)).cast<std::string>() + ")";
      });

  // --- Queries --------------------------------------------------------------
  const DistanceOptions defaults;
  m.def(
      "distance",
      [](const ConvexPolytope& a, py::object pose_a, const ConvexPolytope& b, py::object pose_b,
         DistanceCache* cache, const std::string& algorithm, double relative_tolerance,
         double absolute_tolerance, int max_iterations) {
        const DistanceOptions options =
            make_options(algorithm, relative_tolerance, absolute_tolerance, max_iterations);
        return distance(a, to_pose(pose_a, "pose_a"), b, to_pose(pose_b, "pose_b"), options, cache);
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      R"doc(Minimum distance, closest points and features of hulls a and b placed at pose_a and pose_b.

Poses: None (identity), a 4x4 rigid matrix, a (quaternion wxyz, translation) pair or a Pose.
cache: a DistanceCache updated in place (tracking) or None (cold).
algorithm: 'hybrid' (the paper), 'gjk' or 'enhanced_gjk'. The tolerances and the iteration cap are
DistanceOptions' fields. Returns a DistanceResult.)doc");

  m.def(
      "distance_batch",
      [](const ConvexPolytope& a, py::object poses_a, const ConvexPolytope& b, py::object poses_b,
         py::object caches, int threads, const std::string& algorithm, double relative_tolerance,
         double absolute_tolerance, int max_iterations) {
        const DistanceOptions options =
            make_options(algorithm, relative_tolerance, absolute_tolerance, max_iterations);
        py::ssize_t k = batch_size(poses_a);
        if (k < 0) k = batch_size(poses_b);
        const std::vector<Pose> pa = to_poses(poses_a, k, "poses_a");
        const std::vector<Pose> pb = to_poses(poses_b, k, "poses_b");
        const auto n = pa.size();
        // Caches: copied in, run without the GIL, copied back. The list's
        // objects are held so that they outlive the call.
        std::vector<py::object> cache_objects;
        std::vector<DistanceCache> cache_values;
        if (!caches.is_none()) {
          const py::sequence seq = py::reinterpret_borrow<py::sequence>(caches);
          if (py::len(seq) != n) {
            value_error("caches: " + std::to_string(py::len(seq)) + " caches for " +
                        std::to_string(n) + " poses");
          }
          for (std::size_t i = 0; i < n; ++i) {
            py::object c = seq[i];
            if (!py::isinstance<DistanceCache>(c))
              value_error("caches[" + std::to_string(i) + "] is not a DistanceCache");
            cache_values.push_back(c.cast<const DistanceCache&>());
            cache_objects.push_back(std::move(c));
          }
        }
        std::vector<DistanceResult> results(n);
        {
          py::gil_scoped_release release;
          distance_batch(a, pa, b, pb, results, cache_values, options, threads);
        }
        for (std::size_t i = 0; i < cache_objects.size(); ++i)
          cache_objects[i].cast<DistanceCache&>() = cache_values[i];
        return batch_dict(results);
      },
      py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"),
      py::arg("caches") = py::none(), py::arg("threads") = 0,
      py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      R"doc(K distance queries of one pair of polytopes, run on the thread pool without the GIL.

poses_a, poses_b: (K, 4, 4) arrays of rigid matrices; one of them may be a single pose (4x4, a
(quaternion, translation) pair, a Pose) or None, used for all K.
caches: None (all cold) or a list of K DistanceCache, updated in place (tracking across calls).
threads: 0 for all cores, 1 for the calling thread only, n for n threads.
Returns a dict of arrays with K rows: status (str), distance, lower_bound, point_a (K, 3),
point_b (K, 3), normal (K, 3), feature_a_type (str), feature_a_vertices (K, 3; -1 unused),
feature_a_face, the same for b, iterations. Row k equals distance(a, poses_a[k], b, poses_b[k]).)doc");
}
