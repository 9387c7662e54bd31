// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Python bindings: the boolean and margin queries (proxima/query/margin.h):
// MarginResult, within_margin and intersects for one pair, and the dict of
// arrays a margin batch answers with (PairBatch.within_margin,
// PairBatch.intersects in pair_batch.cpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "convert.h"
#include "proxima/query/margin.h"

namespace proxima::python {
namespace {

// The names of the margin statuses by their codes (to_string), and the
// width of the longest.
const std::array<std::string_view, 3>& margin_status_names() {
  static const std::array<std::string_view, 3> names = {to_string(MarginStatus::within),
                                                        to_string(MarginStatus::beyond),
                                                        to_string(MarginStatus::undecided)};
  return names;
}

constexpr const char* kWithinDoc = R"doc(Whether bodies a and b are within `margin` (finite, >= 0) of each other, stopped at the first proof.

a, b: ConvexPolytope (with cache a DistanceCache), or any bodies (ConvexPolytope, CompoundBody,
TriangleMesh, Body) with cache a BodyCache; cache None is cold. The caches are the distance
query's: one kept by distance() serves this query and the other way round.
Returns a MarginResult: status 'within' (point_a, point_b: a witness pair at most margin + band
apart, band = 64 u R + absolute_tolerance), 'beyond' (lower_bound > margin, certified) or
'undecided' (neither proof at the iteration cap). Poses and options as in distance(): with a
TriangleMesh on either side, another algorithm, relative_tolerance or max_iterations than the
defaults is refused (InvalidInput naming the field), since its triangle pairs are solved in
closed form.)doc";

constexpr const char* kIntersectsDoc =
    R"doc(Whether bodies a and b touch or intersect: within_margin with margin 0 (same arguments, same MarginResult).)doc";

}  // namespace

py::dict margin_dict(std::span<const MarginResult> results) {
  const auto k = static_cast<py::ssize_t>(results.size());
  py::dict out;
  std::size_t width = 1;
  for (const std::string_view n : margin_status_names()) width = std::max(width, n.size());
  py::array status(py::dtype("<U" + std::to_string(width)), std::vector<py::ssize_t>{k});
  py::array_t<bool> within(k);
  py::array_t<double> lower(k), upper(k), point_a({k, py::ssize_t{3}}), point_b({k, py::ssize_t{3}});
  py::array_t<std::int32_t> piece_a(k), piece_b(k), triangle_a(k), triangle_b(k), pairs(k),
      iterations(k);
  auto* s = static_cast<char32_t*>(status.mutable_data());
  for (py::ssize_t i = 0; i < k; ++i) {
    const MarginResult& r = results[static_cast<std::size_t>(i)];
    const std::string_view name = margin_status_names()[static_cast<std::size_t>(r.status)];
    for (std::size_t c = 0; c < width; ++c)
      s[static_cast<std::size_t>(i) * width + c] = c < name.size() ? char32_t(name[c]) : 0;
    within.mutable_at(i) = r.is_within();
    lower.mutable_at(i) = r.lower_bound;
    upper.mutable_at(i) = r.upper_bound;
    for (py::ssize_t j = 0; j < 3; ++j) {
      point_a.mutable_at(i, j) = r.point_a[j];
      point_b.mutable_at(i, j) = r.point_b[j];
    }
    piece_a.mutable_at(i) = r.piece_a;
    piece_b.mutable_at(i) = r.piece_b;
    triangle_a.mutable_at(i) = r.triangle_a;
    triangle_b.mutable_at(i) = r.triangle_b;
    pairs.mutable_at(i) = r.pairs_tested;
    iterations.mutable_at(i) = r.iterations;
  }
  out["status"] = status;
  out["within"] = within;
  out["lower_bound"] = lower;
  out["upper_bound"] = upper;
  out["point_a"] = point_a;
  out["point_b"] = point_b;
  out["piece_a"] = piece_a;
  out["piece_b"] = piece_b;
  out["triangle_a"] = triangle_a;
  out["triangle_b"] = triangle_b;
  out["pairs_tested"] = pairs;
  out["iterations"] = iterations;
  return out;
}

void bind_margin_result(py::module_& m) {
  py::class_<MarginResult>(m, "MarginResult",
                           "The answer of a margin (or boolean) query, world frame.")
      .def_property_readonly(
          "status", [](const MarginResult& r) { return to_string(r.status); },
          "'within' (proved: a witness pair at most margin + band apart), 'beyond' (proved: "
          "lower_bound > margin) or 'undecided' (neither proof at the iteration cap).")
      .def_property_readonly("within", &MarginResult::is_within, "status == 'within'.")
      .def_readonly("margin", &MarginResult::margin, "The margin asked for.")
      .def_readonly("lower_bound", &MarginResult::lower_bound,
                    "Certified lower bound on the distance (above the margin when beyond).")
      .def_readonly("upper_bound", &MarginResult::upper_bound,
                    "|point_a - point_b|, an upper bound on the distance (inf when no pair was "
                    "met).")
      .def_property_readonly(
          "point_a", [](const MarginResult& r) { return vec3_array(r.point_a); },
          "Within: the witness point of A; otherwise the closest pair met.")
      .def_property_readonly(
          "point_b", [](const MarginResult& r) { return vec3_array(r.point_b); },
          "Within: the witness point of B; otherwise the closest pair met.")
      .def_readonly("piece_a", &MarginResult::piece_a, "Piece of A (compound) of the witness, else -1.")
      .def_readonly("piece_b", &MarginResult::piece_b, "Piece of B (compound) of the witness, else -1.")
      .def_readonly("triangle_a", &MarginResult::triangle_a,
                    "Triangle of A (mesh) of the witness, else -1.")
      .def_readonly("triangle_b", &MarginResult::triangle_b,
                    "Triangle of B (mesh) of the witness, else -1.")
      .def_readonly("pairs_tested", &MarginResult::pairs_tested,
                    "Leaf queries run (convex pairs, triangle pairs).")
      .def_readonly("iterations", &MarginResult::iterations, "The hybrid's iterations.")
      .def("__bool__", &MarginResult::is_within, "True when within.")
      .def("__repr__", [](const MarginResult& r) {
        return std::string("proxima.MarginResult(status='") + to_string(r.status) +
               "', margin=" + py::repr(py::float_(r.margin)).cast<std::string>() +
               ", lower_bound=" + py::repr(py::float_(r.lower_bound)).cast<std::string>() +
               ", upper_bound=" + py::repr(py::float_(r.upper_bound)).cast<std::string>() + ")";
      });
}

void bind_margin_queries(py::module_& m) {
  const DistanceOptions defaults;
  // Two polytopes with a DistanceCache, then any two bodies with a
  // BodyCache (as distance()).
  const auto convex = [](const ConvexPolytope& a, py::object pose_a, const ConvexPolytope& b,
                         py::object pose_b, double margin, PyDistanceCache* cache,
                         const std::string& algorithm, double relative_tolerance,
                         double absolute_tolerance, int max_iterations) {
    const DistanceOptions options =
        make_options(algorithm, relative_tolerance, absolute_tolerance, max_iterations, false);
    const Pose pa = to_pose(pose_a, "pose_a");
    const Pose pb = to_pose(pose_b, "pose_b");
    std::optional<InUse> in_use;
    if (cache != nullptr) in_use.emplace(*cache, "DistanceCache");
    return within_margin(a, pa, b, pb, margin, options, static_cast<DistanceCache*>(cache));
  };
  const auto bodies = [](py::object a, py::object pose_a, py::object b, py::object pose_b,
                         double margin, PyBodyCache* cache, const std::string& algorithm,
                         double relative_tolerance, double absolute_tolerance,
                         int max_iterations) {
    const DistanceOptions options =
        make_options(algorithm, relative_tolerance, absolute_tolerance, max_iterations, false);
    const Body body_a = to_body(a, "a");
    const Body body_b = to_body(b, "b");
    const Pose pa = to_pose(pose_a, "pose_a");
    const Pose pb = to_pose(pose_b, "pose_b");
    std::optional<InUse> in_use;
    if (cache != nullptr) in_use.emplace(*cache, "BodyCache");
    py::gil_scoped_release release;
    return within_margin(body_a, pa, body_b, pb, margin, options, static_cast<BodyCache*>(cache));
  };
  m.def("within_margin", convex, py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
        py::arg("margin"), py::arg("cache") = py::none(),
        py::arg("algorithm") = to_string(defaults.algorithm),
        py::arg("relative_tolerance") = defaults.relative_tolerance,
        py::arg("absolute_tolerance") = defaults.absolute_tolerance,
        py::arg("max_iterations") = defaults.max_iterations, kWithinDoc);
  m.def("within_margin", bodies, py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
        py::arg("margin"), py::arg("cache") = py::none(),
        py::arg("algorithm") = to_string(defaults.algorithm),
        py::arg("relative_tolerance") = defaults.relative_tolerance,
        py::arg("absolute_tolerance") = defaults.absolute_tolerance,
        py::arg("max_iterations") = defaults.max_iterations, kWithinDoc);
  m.def(
      "intersects",
      [convex](const ConvexPolytope& a, py::object pose_a, const ConvexPolytope& b,
               py::object pose_b, PyDistanceCache* cache, const std::string& algorithm,
               double relative_tolerance, double absolute_tolerance, int max_iterations) {
        return convex(a, std::move(pose_a), b, std::move(pose_b), 0.0, cache, algorithm,
                      relative_tolerance, absolute_tolerance, max_iterations);
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations, kIntersectsDoc);
  m.def(
      "intersects",
      [bodies](py::object a, py::object pose_a, py::object b, py::object pose_b,
               PyBodyCache* cache, const std::string& algorithm, double relative_tolerance,
               double absolute_tolerance, int max_iterations) {
        return bodies(std::move(a), std::move(pose_a), std::move(b), std::move(pose_b), 0.0,
                      cache, algorithm, relative_tolerance, absolute_tolerance, max_iterations);
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations, kIntersectsDoc);
}

}  // namespace proxima::python
