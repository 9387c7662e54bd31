// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Python bindings: PairBatch, K different pairs of bodies answered in one
// call (C++'s distance_batch), their caches kept across calls inside the
// object, numpy in and numpy out, the GIL released. A planner checking 1,000
// link pairs per configuration pays the Python call once, not 1,000 times.
// Pairs of plain polytopes take the BatchPair batch (the fastest); as soon
// as one body is something else (a Body: rounded, compound, primitive) every
// pair becomes a BodyPair.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "convert.h"
#include "proxima/query/batch.h"

namespace proxima::python {
namespace {

struct PairBatchState {
  // Polytope pairs (when every body is a ConvexPolytope).
  std::vector<std::shared_ptr<const ConvexPolytope>> held;  // keeps the polytopes alive
  std::vector<BatchPair> pairs;
  std::vector<DistanceCache> caches;
  std::vector<DistanceResult> results;
  // Body pairs (otherwise); `bodies` is never resized after the pointers
  // into it are taken.
  std::vector<Body> bodies;
  std::vector<BodyPair> body_pairs;
  std::vector<BodyCache> body_caches;
  std::vector<BodyResult> body_results;
  // The poses of the last call, converted; kept so that a call allocates
  // nothing for them.
  std::vector<Pose> poses_a;
  std::vector<Pose> poses_b;
  std::vector<MarginResult> margin_results;  // of the last margin call
  double last_call_seconds = 0.0;

  std::size_t size() const { return pairs.size() + body_pairs.size(); }
};
using PyPairBatch = Guarded<PairBatchState>;

// distance_batch's refusal as PairBatch.distance's: the poses are checked
// there (the pose contract, once, by the batch itself), so its message
// names the pose (poses_a[k]) or the pair; only the caller's name differs.
std::string in_python_words(std::string_view message, std::string_view batch = "distance_batch",
                            std::string_view method = "distance") {
  const std::string prefix = std::string(batch) + ": ";
  if (message.starts_with(prefix)) message.remove_prefix(prefix.size());
  return "PairBatch." + std::string(method) + ": " + std::string(message);
}

// PairBatch.within_margin and PairBatch.intersects: the margin batch on the
// pairs' own caches (the distance query's: the three methods keep each
// other warm), poses checked by the batch itself.
py::dict margin_call(PyPairBatch& s, py::object poses_a, py::object poses_b, double margin,
                     int threads, const DistanceOptions& options, const char* method) {
  const InUse in_use(s, "PairBatch");
  const auto k = static_cast<py::ssize_t>(s.size());
  to_poses(poses_a, k, "poses_a", PoseCheck::by_the_batch, s.poses_a);
  to_poses(poses_b, k, "poses_b", PoseCheck::by_the_batch, s.poses_b);
  s.margin_results.resize(s.size());
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    try {
      if (!s.body_pairs.empty()) {
        within_margin_batch(s.body_pairs, s.poses_a, s.poses_b, margin, s.margin_results,
                            s.body_caches, options, threads);
      } else {
        within_margin_batch(s.pairs, s.poses_a, s.poses_b, margin, s.margin_results, s.caches,
                            options, threads);
      }
    } catch (const InvalidInput& e) {
      throw InvalidInput(in_python_words(e.what(), "within_margin_batch", method));
    }
    s.last_call_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return margin_dict(s.margin_results);
}

py::sequence body_list(py::handle list, const std::string& name) {
  if (!py::isinstance<py::sequence>(list) || py::isinstance<py::str>(list))
    value_error(name + ": expected a list of bodies (ConvexPolytope, CompoundBody or Body)");
  return py::reinterpret_borrow<py::sequence>(list);
}

bool all_polytopes(const py::sequence& seq) {
  for (std::size_t i = 0; i < py::len(seq); ++i) {
    if (!py::isinstance<ConvexPolytope>(seq[i])) return false;
  }
  return true;
}

// The PairBatch's construction and distance().
void bind_pair_batch_distance(py::class_<PyPairBatch>& batch) {
  const DistanceOptions defaults;
  batch
      .def(
          py::init([](py::object a, py::object b) {
            const py::sequence list_a = body_list(a, "a");
            const py::sequence list_b = body_list(b, "b");
            const std::size_t k = py::len(list_a);
            if (k != py::len(list_b)) {
              value_error("PairBatch: " + std::to_string(k) + " bodies a but " +
                          std::to_string(py::len(list_b)) + " bodies b");
            }
            auto state = std::make_unique<PyPairBatch>();
            if (all_polytopes(list_a) && all_polytopes(list_b)) {
              state->pairs.reserve(k);
              for (std::size_t i = 0; i < k; ++i) {
                const py::object item_a = list_a[i];
                const py::object item_b = list_b[i];
                state->held.push_back(item_a.cast<std::shared_ptr<ConvexPolytope>>());
                state->held.push_back(item_b.cast<std::shared_ptr<ConvexPolytope>>());
                state->pairs.push_back(
                    BatchPair{state->held[2 * i].get(), state->held[2 * i + 1].get()});
              }
              state->caches.resize(k);
              state->results.resize(k);
              return state;
            }
            state->bodies.reserve(2 * k);
            for (std::size_t i = 0; i < k; ++i) {
              state->bodies.push_back(to_body(list_a[i], ("a[" + std::to_string(i) + "]").c_str()));
              state->bodies.push_back(to_body(list_b[i], ("b[" + std::to_string(i) + "]").c_str()));
            }
            for (std::size_t i = 0; i < k; ++i) {
              state->body_pairs.push_back(
                  BodyPair{&state->bodies[2 * i], &state->bodies[2 * i + 1]});
            }
            state->body_caches.resize(k);
            state->body_results.resize(k);
            return state;
          }),
          py::arg("a"), py::arg("b"),
          "a, b: lists of K bodies, each a ConvexPolytope, a CompoundBody or a Body (rounded, "
          "primitive); the same body may appear in many pairs. All polytopes: the polytope "
          "batch; otherwise every pair is answered as distance(Body, Body), and the result dict "
          "also has piece_a and piece_b.")
      .def(
          "distance",
          [](PyPairBatch& s, py::object poses_a, py::object poses_b, int threads,
             const std::string& algorithm, double relative_tolerance, double absolute_tolerance,
             int max_iterations, bool penetration, py::object out) -> py::object {
            const InUse in_use(s, "PairBatch");
            const DistanceOptions options = make_options(
                algorithm, relative_tolerance, absolute_tolerance, max_iterations, penetration);
            const auto k = static_cast<py::ssize_t>(s.size());
            const bool bodies = !s.body_pairs.empty();
            // Everything is checked before any cache or array of `out`
            // changes: the shapes and out here, the pose contract by
            // distance_batch before its first query (so not twice: the
            // conversion only copies the poses).
            to_poses(poses_a, k, "poses_a", PoseCheck::by_the_batch, s.poses_a);
            to_poses(poses_b, k, "poses_b", PoseCheck::by_the_batch, s.poses_b);
            const BatchColumnData columns =
                out.is_none() ? BatchColumnData{} : batch_columns_of(out, k, bodies, "out");
            {
              py::gil_scoped_release release;
              const auto start = std::chrono::steady_clock::now();
              try {
                if (bodies) {
                  distance_batch(s.body_pairs, s.poses_a, s.poses_b, s.body_results, s.body_caches,
                                 options, threads);
                } else {
                  distance_batch(s.pairs, s.poses_a, s.poses_b, s.results, s.caches, options,
                                 threads);
                }
              } catch (const InvalidInput& e) {
                throw InvalidInput(in_python_words(e.what()));
              }
              s.last_call_seconds =
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
            if (out.is_none()) return bodies ? batch_dict(s.body_results) : batch_dict(s.results);
            if (bodies) {
              write_batch_rows(std::span<const BodyResult>(s.body_results), columns);
            } else {
              write_batch_rows(std::span<const DistanceResult>(s.results), columns);
            }
            return out;
          },
          py::arg("poses_a"), py::arg("poses_b"), py::arg("threads") = 0,
          py::arg("algorithm") = to_string(defaults.algorithm),
          py::arg("relative_tolerance") = defaults.relative_tolerance,
          py::arg("absolute_tolerance") = defaults.absolute_tolerance,
          py::arg("max_iterations") = defaults.max_iterations,
          py::arg("penetration") = defaults.penetration, py::arg("out") = py::none(),
          R"doc(Distance of every pair k at poses_a[k], poses_b[k], tracked from the previous call.

poses_a, poses_b: (K, 4, 4) or (K, 3, 4) arrays of rigid matrices, or one pose (or None) for all K.
threads: 0 for all cores, 1 for the calling thread only, n for n threads.
Returns the dict of distance_batch: arrays with K rows (status, distance, lower_bound,
signed_distance and its bounds, point_a,
point_b, normal, features, iterations). Row k equals
distance(a[k], poses_a[k], b[k], poses_b[k], cache=<pair k's cache>).
out: None (new arrays), or the dict of an earlier answer of this batch: its arrays are
filled again in place and the same dict is returned, so that a loop allocates nothing
(a bad out raises ValueError before any cache or array changes).)doc");
}

// The PairBatch's margin checks, reset and readers.
void bind_pair_batch_margins(py::class_<PyPairBatch>& batch) {
  const DistanceOptions defaults;
  batch
      .def(
          "within_margin",
          [](PyPairBatch& s, py::object poses_a, py::object poses_b, double margin, int threads,
             const std::string& algorithm, double relative_tolerance, double absolute_tolerance,
             int max_iterations) {
            const DistanceOptions options = make_options(algorithm, relative_tolerance,
                                                         absolute_tolerance, max_iterations, false);
            return margin_call(s, std::move(poses_a), std::move(poses_b), margin, threads,
                               options, "within_margin");
          },
          py::arg("poses_a"), py::arg("poses_b"), py::arg("margin"), py::arg("threads") = 0,
          py::arg("algorithm") = to_string(defaults.algorithm),
          py::arg("relative_tolerance") = defaults.relative_tolerance,
          py::arg("absolute_tolerance") = defaults.absolute_tolerance,
          py::arg("max_iterations") = defaults.max_iterations,
          R"doc(Whether each pair k is within `margin` at poses_a[k], poses_b[k], each query stopped at its first proof.

Tracked on the pairs' caches, the same ones distance() uses (either keeps them warm for the
other). poses and threads as in distance(). Returns a dict of arrays with K rows: status
('within', 'beyond', 'undecided'), within (bool), lower_bound (certified; > margin when
beyond), upper_bound (|point_a - point_b|), point_a and point_b (K, 3; the witness when
within), piece_a, piece_b, triangle_a, triangle_b (-1 where not a compound / mesh),
pairs_tested, iterations. Row k equals within_margin(a[k], poses_a[k], b[k], poses_b[k],
margin, cache=<pair k's cache>).)doc")
      .def(
          "intersects",
          [](PyPairBatch& s, py::object poses_a, py::object poses_b, int threads,
             const std::string& algorithm, double relative_tolerance, double absolute_tolerance,
             int max_iterations) {
            const DistanceOptions options = make_options(algorithm, relative_tolerance,
                                                         absolute_tolerance, max_iterations, false);
            return margin_call(s, std::move(poses_a), std::move(poses_b), 0.0, threads, options,
                               "intersects");
          },
          py::arg("poses_a"), py::arg("poses_b"), py::arg("threads") = 0,
          py::arg("algorithm") = to_string(defaults.algorithm),
          py::arg("relative_tolerance") = defaults.relative_tolerance,
          py::arg("absolute_tolerance") = defaults.absolute_tolerance,
          py::arg("max_iterations") = defaults.max_iterations,
          "Whether each pair k touches or intersects: within_margin with margin 0 (same "
          "arguments otherwise, same dict).")
      .def(
          "reset",
          [](PyPairBatch& s) {
            const InUse in_use(s, "PairBatch");
            for (DistanceCache& c : s.caches) c.reset();
            for (BodyCache& c : s.body_caches) c.reset();
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
             return s.size();
           })
      .def("__repr__", [](const PyPairBatch& s) {
        const InUse in_use(s, "PairBatch");
        return "proxima.PairBatch(pairs=" + std::to_string(s.size()) + ")";
      });
}

}  // namespace

void bind_pair_batch(py::module_& m) {
  py::class_<PyPairBatch> batch(
      m, "PairBatch",
      "K pairs of bodies (a[k], b[k]), answered together by distance(): one Python "
      "call, the queries on the thread pool without the GIL, each pair's cache kept "
      "inside the object from call to call (tracking). Use from one thread at a time.");
  bind_pair_batch_distance(batch);
  bind_pair_batch_margins(batch);
}

}  // namespace proxima::python
