// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Python bindings: PairBatch, K different pairs of polytopes answered in one
// call (C++'s distance_batch over BatchPair), their caches kept across calls
// inside the object, numpy in and numpy out, the GIL released. A planner
// checking 1,000 link pairs per configuration pays the Python call once,
// not 1,000 times.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "convert.h"
#include "proxima/batch.h"

namespace proxima::python {
namespace {

struct PairBatchState {
  std::vector<std::shared_ptr<const ConvexPolytope>> held;  // keeps the polytopes alive
  std::vector<BatchPair> pairs;
  std::vector<DistanceCache> caches;
  std::vector<DistanceResult> results;
  double last_call_seconds = 0.0;
};
using PyPairBatch = Guarded<PairBatchState>;

std::vector<std::shared_ptr<const ConvexPolytope>> polytope_list(py::handle list,
                                                                 const std::string& name) {
  if (!py::isinstance<py::sequence>(list) || py::isinstance<py::str>(list))
    value_error(name + ": expected a list of ConvexPolytope");
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(list);
  std::vector<std::shared_ptr<const ConvexPolytope>> out;
  out.reserve(py::len(seq));
  for (std::size_t i = 0; i < py::len(seq); ++i) {
    const py::object item = seq[i];
    if (!py::isinstance<ConvexPolytope>(item))
      value_error(name + "[" + std::to_string(i) + "] is not a ConvexPolytope");
    out.push_back(item.cast<std::shared_ptr<ConvexPolytope>>());
  }
  return out;
}

}  // namespace

void bind_pair_batch(py::module_& m) {
  const DistanceOptions defaults;
  py::class_<PyPairBatch>(
      m, "PairBatch",
      "K pairs of ConvexPolytope (a[k], b[k]), answered together by distance(): one Python "
      "call, the queries on the thread pool without the GIL, each pair's DistanceCache kept "
      "inside the object from call to call (tracking). Use from one thread at a time.")
      .def(py::init([](py::object a, py::object b) {
             const auto list_a = polytope_list(a, "a");
             const auto list_b = polytope_list(b, "b");
             if (list_a.size() != list_b.size()) {
               value_error("PairBatch: " + std::to_string(list_a.size()) + " bodies a but " +
                           std::to_string(list_b.size()) + " bodies b");
             }
             auto state = std::make_unique<PyPairBatch>();
             state->pairs.reserve(list_a.size());
             for (std::size_t k = 0; k < list_a.size(); ++k) {
               state->pairs.push_back(BatchPair{list_a[k].get(), list_b[k].get()});
               state->held.push_back(list_a[k]);
               state->held.push_back(list_b[k]);
             }
             state->caches.resize(list_a.size());
             state->results.resize(list_a.size());
             return state;
           }),
           py::arg("a"), py::arg("b"),
           "a, b: lists of K ConvexPolytope (the same polytope may appear in many pairs).")
      .def(
          "distance",
          [](PyPairBatch& s, py::object poses_a, py::object poses_b, int threads,
             const std::string& algorithm, double relative_tolerance, double absolute_tolerance,
             int max_iterations, bool penetration) {
            const InUse in_use(s, "PairBatch");
            const DistanceOptions options = make_options(
                algorithm, relative_tolerance, absolute_tolerance, max_iterations, penetration);
            const auto k = static_cast<py::ssize_t>(s.pairs.size());
            const std::vector<Pose> pa = to_poses(poses_a, k, "poses_a");
            const std::vector<Pose> pb = to_poses(poses_b, k, "poses_b");
            {
              py::gil_scoped_release release;
              const auto start = std::chrono::steady_clock::now();
              distance_batch(s.pairs, pa, pb, s.results, s.caches, options, threads);
              s.last_call_seconds =
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
            return batch_dict(s.results);
          },
          py::arg("poses_a"), py::arg("poses_b"), py::arg("threads") = 0,
          py::arg("algorithm") = to_string(defaults.algorithm),
          py::arg("relative_tolerance") = defaults.relative_tolerance,
          py::arg("absolute_tolerance") = defaults.absolute_tolerance,
          py::arg("max_iterations") = defaults.max_iterations,
          py::arg("penetration") = defaults.penetration,
          R"doc(Distance of every pair k at poses_a[k], poses_b[k], tracked from the previous call.

poses_a, poses_b: (K, 4, 4) or (K, 3, 4) arrays of rigid matrices, or one pose (or None) for all K.
threads: 0 for all cores, 1 for the calling thread only, n for n threads.
Returns the dict of distance_batch: arrays with K rows (status, distance, lower_bound,
signed_distance and its bounds, point_a,
point_b, normal, features, iterations). Row k equals
distance(a[k], poses_a[k], b[k], poses_b[k], cache=<pair k's cache>).)doc")
      .def(
          "reset",
          [](PyPairBatch& s) {
            const InUse in_use(s, "PairBatch");
            for (DistanceCache& c : s.caches) c.reset();
          },
          "Makes every pair's cache cold (the next call tracks nothing).")
      .def_property_readonly(
          "last_call_seconds",
          [](const PyPairBatch& s) {
            const InUse in_use(s, "PairBatch");
            return s.last_call_seconds;
          },
          "Seconds the last distance() spent in the C++ batch itself (GIL released), without "
          "the Python call and the numpy conversions: what the same batch costs from C++.")
      .def("__len__",
           [](const PyPairBatch& s) {
             const InUse in_use(s, "PairBatch");
             return s.pairs.size();
           })
      .def("__repr__", [](const PyPairBatch& s) {
        const InUse in_use(s, "PairBatch");
        return "proxima.PairBatch(pairs=" + std::to_string(s.pairs.size()) + ")";
      });
}

}  // namespace proxima::python
