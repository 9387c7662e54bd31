// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: conversions between Python objects and proxima's C++ types,
// shared by the binding files of the Python module (module.cpp,
// compound_scene.cpp). Arrays in, arrays out (copies); a wrong shape, a
// complex or non-numeric array or a non-rigid pose raises ValueError naming
// the argument. Objects that one thread at a time may use (Scene,
// DistanceCache, CompoundCache) carry an in-use flag (Guarded, InUse).
#pragma once

#include <Python.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/margin.h"
#include "proxima/io.h"
#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int32Array = py::array_t<std::int32_t>;

[[noreturn]] inline void value_error(const std::string& message) { throw py::value_error(message); }

inline std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Real numbers only: numpy's forcecast alone would take anything, and
// silently drop the imaginary part of a complex array or parse strings. The
// natural dtype of the argument (an array as given, or what numpy makes of a
// sequence) is checked before the conversion: floating point or integer.
inline DoubleArray as_double_array(py::handle obj, const std::string& name) {
  const py::array any = py::array::ensure(obj);
  if (!any) value_error(name + ": expected an array of numbers");
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    value_error(name + ": expected real numbers (float or integer), got an array of dtype " +
                py::str(any.dtype()).cast<std::string>());
  }
  auto a = DoubleArray::ensure(any);
  if (!a) value_error(name + ": expected an array of numbers");
  return a;
}

inline Vec3 to_vec3(py::handle obj, const std::string& name) {
  const DoubleArray a = as_double_array(obj, name);
  if (a.ndim() != 1 || a.shape(0) != 3)
    value_error(name + ": expected 3 numbers, got shape " + shape_of(a));
  return Vec3(a.at(0), a.at(1), a.at(2));
}

inline Mat3 to_mat3(py::handle obj, const std::string& name) {
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
inline py::array_t<double> vec3_array(const Vec3& v) { return py::array_t<double>(3, v.data()); }

template <int kRows, int kCols>
py::array_t<double> matrix_array(const Eigen::Matrix<double, kRows, kCols>& m) {
  py::array_t<double> out({py::ssize_t{kRows}, py::ssize_t{kCols}});
  auto o = out.mutable_unchecked<2>();
  for (int i = 0; i < kRows; ++i) {
    for (int j = 0; j < kCols; ++j) o(i, j) = m(i, j);
  }
  return out;
}

// The 12 entries of a 3x4 [R | t] matrix, row-major, under the pose
// contract. `name()` gives the name for a refusal: built only then, since
// batches convert thousands of poses per call.
template <class Name>
requires std::invocable<Name> Pose pose_from_rows(const double* rows, Name&& name) {
  for (int k = 0; k < 12; ++k) {
    if (!is_finite_bits(rows[k])) [[unlikely]] {
      throw InvalidInput(std::string(name()) + " is not finite (NaN or infinite entry at row " +
                         std::to_string(k / 4) + ", column " + std::to_string(k % 4) + ")");
    }
  }
  Mat3 r;
  Vec3 t;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = rows[4 * i + j];
    t[i] = rows[4 * i + 3];
  }
  return checked_pose(Pose(r, t), name);
}
inline Pose pose_from_rows(const double* rows, const std::string& name) {
  return pose_from_rows(rows, [&name] { return name; });
}

// A 4x4 matrix under the rigid-pose contract (proxima/core/pose.h): every entry
// finite (the bottom row too), the bottom row (0, 0, 0, 1) within the
// contract's tolerance, the rest checked (and re-orthonormalized when
// needed) by checked_pose, whose refusal (InvalidInput) names `name()`.
template <class Name>
requires std::invocable<Name> Pose pose_from_matrix(const double* m, Name&& name) {
  for (int k = 12; k < 16; ++k) {
    if (!is_finite_bits(m[k])) [[unlikely]] {
      throw InvalidInput(std::string(name()) + " is not finite (NaN or infinite entry at row " +
                         std::to_string(k / 4) + ", column " + std::to_string(k % 4) + ")");
    }
  }
  const double off_bottom =
      std::max({std::abs(m[12]), std::abs(m[13]), std::abs(m[14]), std::abs(m[15] - 1.0)});
  if (off_bottom > kRotationTolerance) [[unlikely]]
    value_error(std::string(name()) + ": the bottom row of a pose matrix must be (0, 0, 0, 1)");
  return pose_from_rows(m, name);  // its top three rows, [R | t]
}
inline Pose pose_from_matrix(const double* m, const std::string& name) {
  return pose_from_matrix(m, [&name] { return name; });
}

inline const char* order_words(QuaternionOrder order) {
  return order == QuaternionOrder::wxyz ? "(w, x, y, z)" : "(x, y, z, w)";
}

// The rotation of 4 numbers read in `order`: normalized at any magnitude; a
// zero or non-finite quaternion is refused (InvalidInput naming `name`), as
// in the CLI: the same function.
inline Mat3 quaternion_rotation(py::handle q_obj, QuaternionOrder order, const std::string& name) {
  const DoubleArray q = as_double_array(q_obj, name + " quaternion");
  if (q.ndim() != 1 || q.shape(0) != 4) {
    value_error(name + ": the quaternion must be 4 numbers " + order_words(order) + ", got shape " +
                shape_of(q));
  }
  const double numbers[4] = {q.at(0), q.at(1), q.at(2), q.at(3)};
  return unit_quaternion(quaternion_in_order(numbers, order), name).toRotationMatrix();
}

inline Vec3 translation_or_zero(py::handle t_obj, const std::string& name) {
  return t_obj.is_none() ? Vec3::Zero() : to_vec3(t_obj, name + " translation");
}

inline Pose pose_from_quaternion(py::handle q_obj, py::handle t_obj, const std::string& name,
                                 QuaternionOrder order) {
  return {quaternion_rotation(q_obj, order, name), translation_or_zero(t_obj, name)};
}

// Four numbers that do not say their order (a bare quaternion in a
// (rotation, translation) pair, Pose.from_quaternion without `order`) are
// refused, with what they mean in each order: read in the other order they
// are another rotation (ROS's identity (0, 0, 0, 1) read scalar first is a
// half turn about z), so no default is safe.
[[noreturn]] inline void refuse_unnamed_quaternion(py::handle q_obj, const std::string& name,
                                                   const std::string& remedy) {
  const DoubleArray q = as_double_array(q_obj, name + " quaternion");
  if (q.ndim() != 1 || q.shape(0) != 4) {
    value_error(name + ": the rotation must be a 3x3 matrix, a scipy Rotation or a quaternion " +
                "whose order is named; got shape " + shape_of(q));
  }
  const double numbers[4] = {q.at(0), q.at(1), q.at(2), q.at(3)};
  const std::string readings = quaternion_readings(numbers, name);
  value_error(name + ": the quaternion (" + std::string(py::str(py::repr(q_obj))) +
              ") does not name its order: " + readings + ". " + remedy);
}

// A scipy.spatial.transform.Rotation, recognized by its type without
// importing scipy: its own matrix is used, so no quaternion order can be
// misread.
inline bool is_scipy_rotation(py::handle obj) {
  const py::handle type = reinterpret_cast<PyObject*>(Py_TYPE(obj.ptr()));
  if (!py::hasattr(type, "__module__")) return false;
  const std::string module = py::str(type.attr("__module__"));
  return module.rfind("scipy.spatial.transform", 0) == 0 &&
         std::string(py::str(type.attr("__name__"))) == "Rotation";
}

// A rotation argument: a scipy Rotation (one, not a stack) or a 3x3 matrix,
// under the pose contract.
inline Mat3 to_rotation(py::handle obj, const std::string& name) {
  if (is_scipy_rotation(obj)) {
    if (!py::bool_(obj.attr("single"))) {
      value_error(name + ": a stack of " + std::to_string(py::len(obj)) +
                  " scipy rotations where one rotation is expected");
    }
    return checked_pose(Pose(to_mat3(obj.attr("as_matrix")(), name), Vec3::Zero()), name).rotation;
  }
  return checked_pose(Pose(to_mat3(obj, name), Vec3::Zero()), name).rotation;
}

// A pose argument: None (identity), a proxima.Pose, a 4x4 or 3x4 matrix, a
// scipy Rotation, or a (rotation, translation) pair whose rotation is a 3x3
// matrix or a scipy Rotation. A bare quaternion in a pair is refused
// (refuse_unnamed_quaternion): Pose.from_wxyz / Pose.from_xyzw name it.
inline Pose to_pose(py::handle obj, const std::string& name) {
  if (obj.is_none()) return Pose{};
  if (py::isinstance<Pose>(obj)) return obj.cast<Pose>();
  if (is_scipy_rotation(obj)) return {to_rotation(obj, name), Vec3::Zero()};
  if ((py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) && py::len(obj) == 2) {
    const py::object first = obj[py::int_(0)];
    const py::object second = obj[py::int_(1)];
    // Routed by shape before any conversion, so that a bad quaternion is
    // refused as a quaternion.
    const py::array shaped = py::array::ensure(first);
    if (is_scipy_rotation(first) || (shaped && shaped.ndim() == 2))
      return {to_rotation(first, name + " rotation"), to_vec3(second, name + " translation")};
    refuse_unnamed_quaternion(first, name,
                              "Name it: Pose.from_wxyz(q, t) or Pose.from_xyzw(q, t) (ROS, "
                              "scipy's as_quat()), or pass a scipy Rotation or a 3x3 matrix");
  }
  const DoubleArray m = as_double_array(obj, name);
  if (m.ndim() == 2 && m.shape(0) == 3 && m.shape(1) == 4) return pose_from_rows(m.data(), name);
  if (m.ndim() != 2 || m.shape(0) != 4 || m.shape(1) != 4) {
    value_error(name +
                ": expected None, a 4x4 or 3x4 matrix, a scipy Rotation, a (rotation, "
                "translation) pair (rotation: a 3x3 matrix or a scipy Rotation) or a "
                "proxima.Pose (Pose.from_wxyz / Pose.from_xyzw for a quaternion); got an array "
                "of shape " +
                shape_of(m));
  }
  return pose_from_matrix(m.data(), name);
}

// Who checks a batch's poses under the pose contract: the conversion
// (`here`), or the C++ batch that the poses go to (`by_the_batch`:
// distance_batch checks every pose before its first query and names it, so
// the conversion only copies; a 4x4 matrix's bottom row, which the batch
// never sees, is checked here either way).
enum class PoseCheck { here, by_the_batch };

// K poses for a batch: None (K identities), one pose for all, or a (K, 4, 4)
// or (K, 3, 4) array, written into `poses` (resized to K; a caller that
// keeps the vector from call to call allocates nothing). `k` is the batch
// size, or -1 when this argument decides it. With PoseCheck::here every
// pose meets the contract of proxima/core/pose.h on return (a refusal names the
// pose, name[i]).
inline void to_poses(py::handle obj, py::ssize_t k, const std::string& name, PoseCheck check,
                     std::vector<Pose>& poses) {
  const auto one_for_all = [&] {
    if (k < 0)
      value_error(name +
                  ": give K poses as a (K, 4, 4) array (the other poses may be one pose or None)");
    poses.assign(static_cast<std::size_t>(k), to_pose(obj, name));
  };
  if (obj.is_none() || py::isinstance<Pose>(obj) || py::isinstance<py::tuple>(obj) ||
      is_scipy_rotation(obj))
    return one_for_all();
  const DoubleArray m = as_double_array(obj, name);
  if (m.ndim() == 2) return one_for_all();  // a 4x4 or 3x4 matrix, checked by to_pose
  if (m.ndim() != 3 || (m.shape(1) != 4 && m.shape(1) != 3) || m.shape(2) != 4) {
    value_error(name + ": expected a (K, 4, 4) or (K, 3, 4) array of poses, got shape " +
                shape_of(m));
  }
  if (k >= 0 && m.shape(0) != k) {
    value_error(name + ": " + std::to_string(m.shape(0)) + " poses, but the other side has " +
                std::to_string(k));
  }
  // Batches convert thousands of poses per call: the rows are copied as
  // they are, then checked two at a time by the pose contract's paired test
  // (detail::are_rigid, one pass for both); a pose that fails it goes
  // through the full conversion, which names it (name[i]), says what is
  // wrong, or re-orthonormalizes it.
  const py::ssize_t count = m.shape(0);
  const bool square = m.shape(1) == 4;
  const auto full = [&](py::ssize_t i) {
    const auto where = [&name, i] { return name + "[" + std::to_string(i) + "]"; };
    return square ? pose_from_matrix(m.data(i, 0, 0), where)
                  : pose_from_rows(m.data(i, 0, 0), where);
  };
  const double* data = m.data();
  const py::ssize_t stride = square ? 16 : 12;  // c_style: the matrices back to back
  poses.resize(static_cast<std::size_t>(count));
  for (py::ssize_t i = 0; i < count; ++i) {
    const double* rows = data + i * stride;
    Pose& pose = poses[static_cast<std::size_t>(i)];
    double* r = pose.rotation.data();  // column-major: r[3 j + i] = R(i, j) = rows[4 i + j]
    r[0] = rows[0], r[1] = rows[4], r[2] = rows[8];
    r[3] = rows[1], r[4] = rows[5], r[5] = rows[9];
    r[6] = rows[2], r[7] = rows[6], r[8] = rows[10];
    pose.translation = Vec3(rows[3], rows[7], rows[11]);
    if (square && !(rows[12] == 0.0 && rows[13] == 0.0 && rows[14] == 0.0 && rows[15] == 1.0))
      pose = full(i);  // the bottom row exactly (0, 0, 0, 1) or the full check
  }
  if (check == PoseCheck::by_the_batch) return;
  for (py::ssize_t i = 0; i < count; i += 2) {
    const py::ssize_t j = std::min(i + 1, count - 1);
    if (detail::are_rigid(poses[static_cast<std::size_t>(i)], poses[static_cast<std::size_t>(j)]))
        [[likely]]
      continue;
    poses[static_cast<std::size_t>(i)] = full(i);
    poses[static_cast<std::size_t>(j)] = full(j);
  }
}
inline std::vector<Pose> to_poses(py::handle obj, py::ssize_t k, const std::string& name) {
  std::vector<Pose> poses;
  to_poses(obj, k, name, PoseCheck::here, poses);
  return poses;
}

// The K of a batch from whichever pose argument is a (K, 4, 4) array.
inline py::ssize_t batch_size(py::handle obj) {
  if (obj.is_none() || py::isinstance<Pose>(obj) || py::isinstance<py::tuple>(obj) ||
      is_scipy_rotation(obj))
    return -1;
  // No conversion here: the pose arguments are checked (dtype, shape) by to_poses.
  const py::array m = py::array::ensure(obj);
  return m && m.ndim() == 3 ? m.shape(0) : -1;
}

inline Algorithm to_algorithm(const std::string& name) {
  for (Algorithm a : {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk}) {
    if (name == to_string(a)) return a;
  }
  value_error("algorithm must be 'hybrid', 'gjk' or 'enhanced_gjk', got '" + name + "'");
}

// `penetration`: DistanceOptions::penetration (the depth of intersecting
// answers; False skips it).
inline DistanceOptions make_options(const std::string& algorithm, double relative_tolerance,
                                    double absolute_tolerance, int max_iterations,
                                    bool penetration) {
  DistanceOptions options;
  options.penetration = penetration;
  options.algorithm = to_algorithm(algorithm);
  options.relative_tolerance = relative_tolerance;
  options.absolute_tolerance = absolute_tolerance;
  options.max_iterations = max_iterations;
  return options;
}

inline Int32Array int32_array(std::span<const std::int32_t> values) {
  return Int32Array(static_cast<py::ssize_t>(values.size()), values.data());
}

inline py::array_t<double> points_array(std::span<const Vec3> points) {
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

inline std::vector<Vec3> to_points(py::handle obj) {
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

// A loader that returns only the body (ConvexPolytope.from_file,
// CompoundBody.from_file) reports a non-convex input as the CLI's table does,
// with a proxima.NonConvexInputWarning (a UserWarning): the body is the hull
// of all points all the same. Under warnings-as-errors the warning raises.
inline void warn_non_convex(const std::string& message) {
  const py::object category = py::module_::import("proxima").attr("NonConvexInputWarning");
  if (PyErr_WarnEx(category.ptr(), message.c_str(), 1) != 0) throw py::error_already_set();
}

inline int check_index(int i, int count, const char* what) {
  if (i < 0 || i >= count) {
    throw py::index_error(std::string(what) + " " + std::to_string(i) + " out of range [0, " +
                          std::to_string(count) + ")");
  }
  return i;
}

// --- Batch answers as numpy arrays -------------------------------------------
// A batch answer (distance_batch, PairBatch.distance) is a dict of numpy
// arrays with K rows, one column per field: new arrays, or (PairBatch's
// out=) the arrays of an earlier answer filled again in place, so that a
// loop allocates nothing. The names (status, feature types) are fixed-width
// unicode arrays written straight into numpy's UCS-4 buffer: a numpy
// fancy-indexing call per name column was a large share of PairBatch's
// Python overhead (bench/python_pair_batch.py).
enum BatchColumn : int {
  kStatus,
  kDistance,
  kLowerBound,
  kSignedDistance,
  kSignedLowerBound,
  kSignedUpperBound,
  kPointA,
  kPointB,
  kNormal,
  kFeatureAType,
  kFeatureAVertices,
  kFeatureAFace,
  kFeatureBType,
  kFeatureBVertices,
  kFeatureBFace,
  kIterations,
  kPieceA,  // the last two for Bodies only
  kPieceB,
  kBatchColumns
};

// A column: its key, its numpy kind ('U' names, 'f' float64, 'i' int32)
// and its width (characters for 'U', else columns: 1 for a (K,) array).
struct BatchColumnSpec {
  const char* key;
  char kind;
  py::ssize_t width;
};

// The names of every status and feature type, by their codes (to_string).
inline const std::array<std::string_view, 4>& status_names() {
  static const std::array<std::string_view, 4> names = {
      to_string(Status::separated), to_string(Status::touching), to_string(Status::intersecting),
      to_string(Status::iteration_cap)};
  return names;
}
inline const std::array<std::string_view, 3>& feature_type_names() {
  static const std::array<std::string_view, 3> names = {
      to_string(FeatureType::vertex), to_string(FeatureType::edge), to_string(FeatureType::face)};
  return names;
}
template <std::size_t M>
py::ssize_t longest(const std::array<std::string_view, M>& names) {
  std::size_t width = 1;
  for (const std::string_view n : names) width = std::max(width, n.size());
  return static_cast<py::ssize_t>(width);
}

inline const std::array<BatchColumnSpec, kBatchColumns>& batch_columns() {
  static const py::ssize_t status = longest(status_names());
  static const py::ssize_t type = longest(feature_type_names());
  static const std::array<BatchColumnSpec, kBatchColumns> columns = {{
      {"status", 'U', status},
      {"distance", 'f', 1},
      {"lower_bound", 'f', 1},
      {"signed_distance", 'f', 1},
      {"signed_lower_bound", 'f', 1},
      {"signed_upper_bound", 'f', 1},
      {"point_a", 'f', 3},
      {"point_b", 'f', 3},
      {"normal", 'f', 3},
      {"feature_a_type", 'U', type},
      {"feature_a_vertices", 'i', 3},
      {"feature_a_face", 'i', 1},
      {"feature_b_type", 'U', type},
      {"feature_b_vertices", 'i', 3},
      {"feature_b_face", 'i', 1},
      {"iterations", 'i', 1},
      {"piece_a", 'i', 1},
      {"piece_b", 'i', 1},
  }};
  return columns;
}

inline py::ssize_t item_size(const BatchColumnSpec& c) {
  return c.kind == 'U' ? 4 * c.width : c.kind == 'f' ? 8 : 4;
}

// The numpy dtype of column i, made once (parsing "<U13" costs a
// microsecond) and never destroyed: the module outlives every call.
inline const py::dtype& column_dtype(int i) {
  static const auto* f64 = new py::dtype(py::dtype::of<double>());
  static const auto* i32 = new py::dtype(py::dtype::of<std::int32_t>());
  const auto unicode = [](int column) {
    return new py::dtype("<U" +
                         std::to_string(batch_columns()[static_cast<std::size_t>(column)].width));
  };
  static const auto* status = unicode(kStatus);
  static const auto* type = unicode(kFeatureAType);  // kFeatureBType's too
  const char kind = batch_columns()[static_cast<std::size_t>(i)].kind;
  if (kind == 'f') return *f64;
  if (kind == 'i') return *i32;
  return i == kStatus ? *status : *type;
}

// Where the rows of each column go: the data pointers (C order) and the
// arrays themselves, held so that the memory stays alive while the GIL is
// released (another thread may drop an answer's arrays meanwhile).
struct BatchColumnData {
  std::array<void*, kBatchColumns> data{};
  std::array<py::object, kBatchColumns> arrays;

  void* operator[](int column) const { return data[static_cast<std::size_t>(column)]; }
};

inline py::ssize_t batch_column_count(bool pieces) { return pieces ? kBatchColumns : kPieceA; }

// New arrays of K rows, put into `out` under their keys.
inline BatchColumnData new_batch_columns(py::ssize_t k, bool pieces, py::dict& out) {
  BatchColumnData data{};
  for (int i = 0; i < batch_column_count(pieces); ++i) {
    const BatchColumnSpec& c = batch_columns()[static_cast<std::size_t>(i)];
    py::array column = c.kind != 'U' && c.width > 1
                           ? py::array(column_dtype(i), std::vector<py::ssize_t>{k, c.width})
                           : py::array(column_dtype(i), std::vector<py::ssize_t>{k});
    data.data[static_cast<std::size_t>(i)] = column.mutable_data();
    out[c.key] = column;
    data.arrays[static_cast<std::size_t>(i)] = std::move(column);
  }
  return data;
}

// The columns of `out`, an earlier answer to be filled again (`where` names
// the argument): exactly the keys of a K-row answer (with or without the
// pieces), each a C-contiguous, aligned, writeable array of its dtype and
// shape in native byte order, no two sharing memory. Anything else raises
// ValueError naming the key, before anything is written.
inline BatchColumnData batch_columns_of(py::handle out, py::ssize_t k, bool pieces,
                                        const char* where) {
  const auto fail = [where](const std::string& what) { value_error(std::string(where) + what); };
  if (!PyDict_Check(out.ptr())) {
    fail(": expected the dict of an earlier answer of this batch, got " +
         std::string(Py_TYPE(out.ptr())->tp_name));
  }
  const py::ssize_t count = batch_column_count(pieces);
  if (PyDict_Size(out.ptr()) != count) {
    fail(": expected the " + std::to_string(count) + " arrays of an answer of this batch" +
         (pieces ? " (with piece_a and piece_b)" : " (without piece_a and piece_b)") + ", got " +
         std::to_string(PyDict_Size(out.ptr())) + " entries");
  }
  constexpr char kForeignOrder = std::endian::native == std::endian::little ? '>' : '<';
  constexpr int kFlags = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ |
                         py::detail::npy_api::NPY_ARRAY_ALIGNED_ |
                         py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  BatchColumnData data{};
  std::array<std::pair<const char*, const char*>, kBatchColumns> bytes{};  // [begin, end)
  for (int i = 0; i < count; ++i) {
    const BatchColumnSpec& c = batch_columns()[static_cast<std::size_t>(i)];
    const std::string name = std::string("['") + c.key + "']";
    PyObject* item = PyDict_GetItemString(out.ptr(), c.key);  // borrowed; no error set
    if (item == nullptr) fail(name + " is missing");
    if (!py::array::check_(item)) fail(name + ": expected a numpy array");
    auto a = py::reinterpret_borrow<py::array>(item);
    const py::dtype dtype = a.dtype();
    const bool two_d = c.kind != 'U' && c.width > 1;
    if (dtype.kind() != c.kind || dtype.itemsize() != item_size(c) ||
        dtype.byteorder() == kForeignOrder || a.ndim() != (two_d ? 2 : 1) || a.shape(0) != k ||
        (two_d && a.shape(1) != c.width)) {
      fail(name + ": expected " + py::str(py::handle(column_dtype(i))).cast<std::string>() +
           " of shape (" + std::to_string(k) + (two_d ? ", " + std::to_string(c.width) : ",") +
           "), got " + py::str(py::handle(dtype)).cast<std::string>() + " of shape " + shape_of(a));
    }
    if ((a.flags() & kFlags) != kFlags)
      fail(name + ": the array must be C-contiguous, aligned and writeable");
    auto* begin = static_cast<char*>(a.mutable_data());
    bytes[static_cast<std::size_t>(i)] = {begin, begin + a.nbytes()};
    for (int j = 0; j < i; ++j) {
      const auto& other = bytes[static_cast<std::size_t>(j)];
      if (begin < other.second && other.first < begin + a.nbytes()) {
        fail(name + " shares memory with ['" + batch_columns()[static_cast<std::size_t>(j)].key +
             "']");
      }
    }
    data.data[static_cast<std::size_t>(i)] = begin;
    data.arrays[static_cast<std::size_t>(i)] = std::move(a);
  }
  return data;
}

// The names of a column, each padded with zeros to the column's width, back
// to back: row i of the column is a copy of name code[i]'s `width` characters.
template <std::size_t M>
std::vector<char32_t> padded_names(const std::array<std::string_view, M>& names,
                                   py::ssize_t width) {
  std::vector<char32_t> padded(M * static_cast<std::size_t>(width), U'\0');
  for (std::size_t code = 0; code < M; ++code) {
    for (std::size_t c = 0; c < names[code].size(); ++c)
      padded[code * static_cast<std::size_t>(width) + c] = static_cast<char32_t>(names[code][c]);
  }
  return padded;
}

// Writes the K results into the columns; the pieces when Result has them
// (BodyResult: -1 for a convex body).
template <class Result>
void write_batch_rows(std::span<const Result> results, const BatchColumnData& data) {
  const auto& columns = batch_columns();
  const auto f64 = [&data](BatchColumn c) { return static_cast<double*>(data[c]); };
  const auto i32 = [&data](BatchColumn c) { return static_cast<std::int32_t*>(data[c]); };
  const auto chars = [&data](BatchColumn c) { return static_cast<char32_t*>(data[c]); };
  double *distance_ = f64(kDistance), *lower_bound = f64(kLowerBound),
         *signed_distance = f64(kSignedDistance), *signed_lower = f64(kSignedLowerBound),
         *signed_upper = f64(kSignedUpperBound), *point_a = f64(kPointA), *point_b = f64(kPointB),
         *normal = f64(kNormal);
  std::int32_t *vertices_a = i32(kFeatureAVertices), *face_a = i32(kFeatureAFace),
               *vertices_b = i32(kFeatureBVertices), *face_b = i32(kFeatureBFace),
               *iterations = i32(kIterations);
  char32_t *status = chars(kStatus), *type_a = chars(kFeatureAType), *type_b = chars(kFeatureBType);
  const py::ssize_t status_width = columns[kStatus].width,
                    type_width = columns[kFeatureAType].width;
  static const std::vector<char32_t> status_padded = padded_names(status_names(), status_width);
  static const std::vector<char32_t> type_padded = padded_names(feature_type_names(), type_width);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const Result& r = results[i];
    distance_[i] = r.distance;
    lower_bound[i] = r.lower_bound;
    signed_distance[i] = r.signed_distance();
    signed_lower[i] = r.signed_lower_bound();
    signed_upper[i] = r.signed_upper_bound();
    for (std::size_t j = 0; j < 3; ++j) {
      point_a[3 * i + j] = r.point_a[static_cast<Eigen::Index>(j)];
      point_b[3 * i + j] = r.point_b[static_cast<Eigen::Index>(j)];
      normal[3 * i + j] = r.normal[static_cast<Eigen::Index>(j)];
      vertices_a[3 * i + j] = r.feature_a.vertices[j];
      vertices_b[3 * i + j] = r.feature_b.vertices[j];
    }
    face_a[i] = r.feature_a.face;
    face_b[i] = r.feature_b.face;
    iterations[i] = r.iterations;
    const auto name = [i](char32_t* column, const char32_t* padded, py::ssize_t width, auto code) {
      const auto w = static_cast<std::size_t>(width);
      std::copy_n(padded + static_cast<std::size_t>(code) * w, w, column + i * w);
    };
    name(status, status_padded.data(), status_width, r.status);
    name(type_a, type_padded.data(), type_width, r.feature_a.type);
    name(type_b, type_padded.data(), type_width, r.feature_b.type);
  }
  if constexpr (std::is_same_v<Result, BodyResult>) {
    std::int32_t *piece_a = i32(kPieceA), *piece_b = i32(kPieceB);
    for (std::size_t i = 0; i < results.size(); ++i) {
      piece_a[i] = results[i].piece_a;
      piece_b[i] = results[i].piece_b;
    }
  }
}

// The batch result as a new dict of arrays (K rows each); for Bodies also
// the pieces of the closest pairs (piece_a, piece_b; -1 for a convex body).
template <class Result>
py::dict batch_dict(const std::vector<Result>& results) {
  py::dict out;
  const BatchColumnData data = new_batch_columns(static_cast<py::ssize_t>(results.size()),
                                                 std::is_same_v<Result, BodyResult>, out);
  write_batch_rows(std::span<const Result>(results), data);
  return out;
}

// --- One thread at a time -------------------------------------------------
// A Scene, a DistanceCache and a CompoundCache are mutable state that one
// thread at a time may use (the C++ contract). The calls that release the
// GIL would let a second Python thread into the same object while the first
// one runs, which corrupts memory. So each such object, as Python holds it,
// is a Guarded<T>: T plus an in-use flag, and every call that uses it holds
// an InUse for its duration; a second thread gets RuntimeError at once,
// never a race. Cost: one atomic exchange and one store per call.
template <class T>
class Guarded : public T {
 public:
  using T::T;
  Guarded() = default;
  explicit Guarded(const T& value) : T(value) {}
  // A copy (or a move) is a new object: not in use.
  Guarded(const Guarded& other) requires std::copy_constructible<T> : T(other) {}
  Guarded(Guarded&& other) noexcept requires std::move_constructible<T> : T(std::move(other)) {}
  Guarded& operator=(const Guarded&) = delete;
  Guarded& operator=(Guarded&&) = delete;
  ~Guarded() = default;

  std::atomic<bool>& in_use_flag() const { return in_use_; }

 private:
  mutable std::atomic<bool> in_use_{false};
};

// Holds a Guarded object's flag from construction to destruction; throws
// RuntimeError when another thread holds it.
class InUse {
 public:
  template <class T>
  InUse(const Guarded<T>& object, const char* type_name) : flag_(&object.in_use_flag()) {
    if (flag_->exchange(true, std::memory_order_acquire)) {
      flag_ = nullptr;
      throw_busy(type_name);
    }
  }
  // The flag when it is free, else nothing (no throw).
  template <class T>
  static std::optional<InUse> try_hold(const Guarded<T>& object) {
    std::atomic<bool>* flag = &object.in_use_flag();
    if (flag->exchange(true, std::memory_order_acquire)) return std::nullopt;
    return InUse(flag);
  }
  [[noreturn]] static void throw_busy(const char* type_name) {
    throw std::runtime_error(std::string("proxima.") + type_name +
                             " is being used by another thread (use it from one thread at a "
                             "time, or give each thread its own)");
  }
  InUse(InUse&& other) noexcept : flag_(std::exchange(other.flag_, nullptr)) {}
  InUse(const InUse&) = delete;
  InUse& operator=(const InUse&) = delete;
  InUse& operator=(InUse&&) = delete;
  ~InUse() {
    if (flag_ != nullptr) flag_->store(false, std::memory_order_release);
  }
  const std::atomic<bool>* flag() const { return flag_; }

 private:
  explicit InUse(std::atomic<bool>* flag) : flag_(flag) {}
  std::atomic<bool>* flag_;
};

using PyDistanceCache = Guarded<DistanceCache>;
using PyBodyCache = Guarded<BodyCache>;

// Registers CompoundBody, Scene and their companions (compound_scene.cpp),
// and PairBatch (pair_batch.cpp).
void bind_compound_and_scene(py::module_& m);
void bind_pair_batch(py::module_& m);
// Body, the primitives and distance for any two bodies (body.cpp).
void bind_bodies(py::module_& m);
void bind_mesh(py::module_& m);
void bind_robot(py::module_& m);
// A Body from a Body, a ConvexPolytope or a CompoundBody (body.cpp);
// TypeError naming `name` otherwise.
Body to_body(py::handle obj, const char* name);
// Motion, ImpactResult and time_of_impact (time_of_impact.cpp).
void bind_time_of_impact(py::module_& m);
// MarginResult (before the scene and PairBatch, which answer with it), and
// within_margin and intersects (after the bodies and their caches):
// margin.cpp.
void bind_margin_result(py::module_& m);
void bind_margin_queries(py::module_& m);
// A margin batch's answers as a dict of arrays with K rows (margin.cpp).
py::dict margin_dict(std::span<const MarginResult> results);
// view and view_scene, the viewer's page (view.cpp).
void bind_view(py::module_& m);

}  // namespace proxima::python
