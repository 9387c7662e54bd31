// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the Python side of compound bodies and scenes (CompoundBody,
// CompoundCache, CompoundResult, load_compound, distance over compounds,
// Scene, ClosePair, SceneStats, ImpactPair, SweepStats). Same conventions as module.cpp: names one
// for one with C++, arrays are numpy copies, enums are strings, the long
// calls release the GIL.
//
// Polytopes and compounds are held by std::shared_ptr on both sides, so that
// a body added to a Scene or used as a piece stays alive as long as either
// side needs it.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "convert.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/io.h"
#include "proxima/scene/scene.h"

namespace proxima::python {
namespace {

using PyCompoundCache = Guarded<CompoundCache>;
using PyScene = Guarded<Scene>;

// Body ids from Python: integers only (forcecast would truncate 1.5 to 1),
// within BodyId's range.
std::vector<BodyId> to_body_ids(py::handle obj, const char* what) {
  const py::array any = py::array::ensure(obj);
  if (!any || any.ndim() != 1) value_error("ids: expected a 1-D array of body ids");
  const char kind = any.dtype().kind();
  if (any.size() > 0 && kind != 'i' && kind != 'u') {
    value_error("ids: expected integer body ids, got an array of dtype " +
                py::str(any.dtype()).cast<std::string>());
  }
  const auto wide =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(any);
  if (!wide) value_error("ids: expected a 1-D array of body ids");
  std::vector<BodyId> ids(static_cast<std::size_t>(wide.shape(0)));
  for (py::ssize_t k = 0; k < wide.shape(0); ++k) {
    const std::int64_t id = wide.at(k);
    if (id < std::numeric_limits<BodyId>::min() || id > std::numeric_limits<BodyId>::max()) {
      throw InvalidInput(std::string("Scene.") + what + ": ids[" + std::to_string(k) +
                         "] = " + std::to_string(id) +
                         " is not in the scene (never added, or removed); no body was moved");
    }
    ids[static_cast<std::size_t>(k)] = static_cast<BodyId>(id);
  }
  return ids;
}

// One piece argument: a ConvexPolytope, an (N, 3) array of points (hulled
// here), or a (polytope or points, pose) pair.
CompoundPiece to_piece(py::handle obj, std::size_t index) {
  const std::string name = "pieces[" + std::to_string(index) + "]";
  const auto polytope_of = [&](py::handle p) -> std::shared_ptr<const ConvexPolytope> {
    if (py::isinstance<ConvexPolytope>(p)) return p.cast<std::shared_ptr<ConvexPolytope>>();
    try {
      return std::make_shared<ConvexPolytope>(to_points(p));
    } catch (const InvalidInput& e) {
      throw InvalidInput(name + ": " + e.what());
    } catch (const py::value_error& e) {
      value_error(name + ": " + e.what());
    }
  };
  if (py::isinstance<py::tuple>(obj) && py::len(obj) == 2) {
    return {polytope_of(obj[py::int_(0)]), to_pose(obj[py::int_(1)], name + " pose")};
  }
  return {polytope_of(obj), Pose{}};
}

BroadPhase to_broad_phase(const std::string& name) {
  for (BroadPhase b : {BroadPhase::sweep_and_prune, BroadPhase::dynamic_aabb_tree}) {
    if (name == to_string(b)) return b;
  }
  value_error("broad_phase must be 'sweep_and_prune' or 'dynamic_aabb_tree', got '" + name + "'");
}

py::list close_pair_list(std::span<const ClosePair> pairs) {
  py::list out;
  for (const ClosePair& p : pairs) out.append(py::cast(p));
  return out;
}

py::list impact_pair_list(std::span<const ImpactPair> pairs) {
  py::list out;
  for (const ImpactPair& p : pairs) out.append(py::cast(p));
  return out;
}

// Scene.set_poses and Scene.set_end_poses: every id and pose checked before
// the first body is touched, then `set(id, pose)` for each.
template <class Set>
void set_many(PyScene& s, py::object ids, py::object poses, const char* what, const Set& set) {
  const std::vector<BodyId> id_list = to_body_ids(ids, what);
  std::vector<Pose> list = to_poses(poses, static_cast<py::ssize_t>(id_list.size()), "poses");
  const InUse in_use(s, "Scene");
  for (std::size_t k = 0; k < id_list.size(); ++k) {
    if (!s.contains(id_list[k])) {
      throw InvalidInput(std::string("Scene.") + what + ": ids[" + std::to_string(k) +
                         "] = " + std::to_string(id_list[k]) +
                         " is not in the scene (never added, or removed); no body was moved");
    }
    list[k] = checked_pose(list[k], [&] {
      return std::string("Scene.") + what + ": poses[" + std::to_string(k) +
             "] (no body was moved)";
    });
  }
  for (std::size_t k = 0; k < id_list.size(); ++k) set(id_list[k], list[k]);
}

// The sweep's options from Python's keywords, with the scene's distance
// options.
ImpactOptions sweep_options(const Scene& s, double target_separation, double tolerance,
                            int max_iterations) {
  ImpactOptions options;
  options.target_separation = target_separation;
  options.tolerance = tolerance;
  options.max_iterations = max_iterations;
  options.distance = s.options().distance;
  return options;
}

// --- Compound bodies and their queries -----------------------------------------

void bind_compounds(py::module_& m) {
  py::class_<CompoundBody, std::shared_ptr<CompoundBody>>(
      m, "CompoundBody",
      "A non-convex body as a union of convex pieces, each a ConvexPolytope at its own pose in "
      "the body's frame, under a bounding-sphere hierarchy built once. Immutable; shareable "
      "between threads.")
      .def(py::init([](const py::sequence& pieces) {
             std::vector<CompoundPiece> list;
             list.reserve(py::len(pieces));
             for (std::size_t i = 0; i < py::len(pieces); ++i)
               list.push_back(to_piece(pieces[i], i));
             py::gil_scoped_release release;
             return CompoundBody(std::move(list));
           }),
           py::arg("pieces"),
           "From a list of pieces: each a ConvexPolytope, an (N, 3) array of points (hulled), or "
           "a (polytope or points, pose) pair. Raises InvalidInput naming the piece.")
      .def_static(
          "from_file",
          [](const std::string& path) {
            LoadedCompound loaded =
                read_file(path, [](const std::string& p) { return load_compound(p); });
            std::string names;
            for (const LoadedPiece& piece : loaded.pieces) {
              if (!piece.input_was_convex)
                names += (names.empty() ? "'" : ", '") + piece.name + "'";
            }
            if (!names.empty()) {
              warn_non_convex(path + ": not convex: group(s) " + names +
                              " (each piece is the hull of its group's points)");
            }
            return std::move(loaded.body);
          },
          py::arg("path"),
          "One piece per OBJ group/object (a file without groups is one piece), each hulled. A "
          "group whose surface is not convex warns NonConvexInputWarning naming it; load_compound "
          "returns the per-group report instead, without a warning.")
      .def_property_readonly("piece_count", &CompoundBody::piece_count, "Number of pieces.")
      .def(
          "piece",
          [](const CompoundBody& body, int i) {
            const CompoundPiece& p = body.piece(check_index(i, body.piece_count(), "piece"));
            return py::make_tuple(std::const_pointer_cast<ConvexPolytope>(p.polytope), p.pose);
          },
          py::arg("i"), "(ConvexPolytope, Pose) of piece i.")
      .def_property_readonly(
          "center", [](const CompoundBody& body) { return vec3_array(body.center()); },
          "Center of the body's bounding sphere, in its frame.")
      .def_property_readonly("bounding_radius", &CompoundBody::bounding_radius,
                             "Radius of the body's bounding sphere.")
      .def_property_readonly("scale", &CompoundBody::scale,
                             "Largest absolute coordinate of a placed piece vertex.")
      .def("memory_bytes", &CompoundBody::memory_bytes, "Bytes held by the C++ object.")
      .def("__len__", &CompoundBody::piece_count)
      .def("__repr__", [](const CompoundBody& body) {
        return "proxima.CompoundBody(pieces=" + std::to_string(body.piece_count()) + ")";
      });

  py::class_<LoadedPiece>(m, "LoadedPiece", "One group of a compound file and how convex it was.")
      .def_readonly("name", &LoadedPiece::name, "The OBJ group's name ('' when unnamed).")
      .def_readonly("input_points", &LoadedPiece::input_points, "Points of the group.")
      .def_readonly("interior_points", &LoadedPiece::interior_points,
                    "Points of the group that are not hull vertices.")
      .def_readonly("input_was_convex", &LoadedPiece::input_was_convex,
                    "Whether the group's surface is convex (its faces lie on its hull's facets; "
                    "without faces, its points on the hull's boundary).");

  py::class_<LoadedCompound>(m, "LoadedCompound",
                             "A compound body read from a file, per-piece reports.")
      .def_property_readonly(
          "body", [](const LoadedCompound& l) { return std::make_shared<CompoundBody>(l.body); },
          "The CompoundBody.")
      .def_readonly("pieces", &LoadedCompound::pieces, "List of LoadedPiece, one per piece.");

  m.def(
      "load_compound",
      [](const std::string& path) {
        return read_file(path, [](const std::string& p) { return load_compound(p); });
      },
      py::arg("path"),
      "Reads a mesh file as a compound body: one convex piece per OBJ group; a non-convex group "
      "is hulled and reported in its LoadedPiece.input_was_convex (no warning).");

}

void bind_compound_queries(py::module_& m) {
  // Every method holds the cache's in-use flag: the compound distance uses
  // the cache without the GIL.
  py::class_<PyCompoundCache>(
      m, "CompoundCache",
      "Coherence between compound queries of one pair (the best piece pair and each near piece "
      "pair's feature cache). A new cache is cold; one cache per pair of bodies, from one thread "
      "at a time: using a cache while another thread's query is using it raises RuntimeError.")
      .def(py::init<>(), "A cold cache.")
      .def_property_readonly(
          "piece_a",
          [](const PyCompoundCache& c) {
            const InUse in_use(c, "CompoundCache");
            return c.piece_a;
          },
          "Best piece on A of the last answer.")
      .def_property_readonly(
          "piece_b",
          [](const PyCompoundCache& c) {
            const InUse in_use(c, "CompoundCache");
            return c.piece_b;
          },
          "Best piece on B of the last answer.")
      .def_property_readonly(
          "near_pairs",
          [](const PyCompoundCache& c) {
            const InUse in_use(c, "CompoundCache");
            return c.near.size();
          },
          "Number of piece pairs whose feature caches are kept.")
      .def(
          "is_cold",
          [](const PyCompoundCache& c) {
            const InUse in_use(c, "CompoundCache");
            return c.is_cold();
          },
          "True when the cache holds nothing.")
      .def(
          "reset",
          [](PyCompoundCache& c) {
            const InUse in_use(c, "CompoundCache");
            c.reset();
          },
          "Makes the cache cold again.")
      .def("__repr__", [](const PyCompoundCache& c) {
        const InUse in_use(c, "CompoundCache");
        return std::string("proxima.CompoundCache(") + (c.is_cold() ? "cold" : "warm") + ")";
      });

  py::class_<CompoundResult, DistanceResult>(
      m, "CompoundResult",
      "A DistanceResult of the closest piece pair, plus which pieces (features are in the "
      "pieces' hull ids) and how many convex queries ran.")
      .def_readonly("piece_a", &CompoundResult::piece_a, "The closest piece of A.")
      .def_readonly("piece_b", &CompoundResult::piece_b, "The closest piece of B.")
      .def_readonly("pairs_tested", &CompoundResult::pairs_tested, "Convex queries run.")
      .def("__repr__", [](const CompoundResult& r) {
        return std::string("proxima.CompoundResult(status='") + to_string(r.status) +
               "', distance=" + py::repr(py::float_(r.distance)).cast<std::string>() +
               ", pieces=(" + std::to_string(r.piece_a) + ", " + std::to_string(r.piece_b) + "))";
      });

  const DistanceOptions defaults;
  m.def(
      "distance",
      [](const CompoundBody& a, py::object pose_a, const CompoundBody& b, py::object pose_b,
         PyCompoundCache* cache, const std::string& algorithm, double relative_tolerance,
         double absolute_tolerance, int max_iterations, bool penetration) {
        const DistanceOptions options = make_options(
            algorithm, relative_tolerance, absolute_tolerance, max_iterations, penetration);
        const Pose pa = to_pose(pose_a, "pose_a");
        const Pose pb = to_pose(pose_b, "pose_b");
        std::optional<InUse> in_use;
        if (cache != nullptr) in_use.emplace(*cache, "CompoundCache");
        py::gil_scoped_release release;
        return distance(a, pa, b, pb, options, static_cast<CompoundCache*>(cache));
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("cache") = py::none(), py::arg("algorithm") = to_string(defaults.algorithm),
      py::arg("relative_tolerance") = defaults.relative_tolerance,
      py::arg("absolute_tolerance") = defaults.absolute_tolerance,
      py::arg("max_iterations") = defaults.max_iterations,
      py::arg("penetration") = defaults.penetration,
      "Minimum distance between two CompoundBody objects (branch and bound over piece pairs); "
      "cache: a CompoundCache or None. Returns a CompoundResult.");
  m.def(
      "distance_all_pairs",
      [](const CompoundBody& a, py::object pose_a, const CompoundBody& b, py::object pose_b,
         const std::string& algorithm) {
        DistanceOptions options;
        options.algorithm = to_algorithm(algorithm);
        const Pose pa = to_pose(pose_a, "pose_a");
        const Pose pb = to_pose(pose_b, "pose_b");
        py::gil_scoped_release release;
        return distance_all_pairs(a, pa, b, pb, options);
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"),
      py::arg("algorithm") = to_string(defaults.algorithm),
      "The slow twin of the compound distance: every piece pair, cold. For checks.");

}

// --- Scenes ----------------------------------------------------------------------

// The types a Scene answers with.
void bind_scene_results(py::module_& m) {
  py::class_<ClosePair>(m, "ClosePair", "A pair of bodies within the scene's margin (a < b).")
      .def_readonly("a", &ClosePair::a, "Body id.")
      .def_readonly("b", &ClosePair::b, "Body id.")
      .def_readonly("result", &ClosePair::result, "The CompoundResult of the pair.")
      .def_readonly("triangle_a", &ClosePair::triangle_a,
                    "The closest triangle of body a when it is a mesh, else -1.")
      .def_readonly("triangle_b", &ClosePair::triangle_b,
                    "The closest triangle of body b when it is a mesh, else -1.")
      .def("__repr__", [](const ClosePair& p) {
        return "proxima.ClosePair(" + std::to_string(p.a) + ", " + std::to_string(p.b) +
               ", distance=" + py::repr(py::float_(p.result.distance)).cast<std::string>() + ")";
      });

  py::class_<MarginPair>(m, "MarginPair",
                         "A pair of bodies within the scene's margin as the margin query "
                         "proves it (a < b): Scene.step_within, Scene.first_within.")
      .def_readonly("a", &MarginPair::a, "Body id.")
      .def_readonly("b", &MarginPair::b, "Body id.")
      .def_readonly("result", &MarginPair::result,
                    "The MarginResult of the pair: status 'within' (or 'undecided' at the "
                    "iteration cap), the witness points, pieces and triangles; no distance.")
      .def("__repr__", [](const MarginPair& p) {
        return "proxima.MarginPair(" + std::to_string(p.a) + ", " + std::to_string(p.b) +
               ", status='" + to_string(p.result.status) + "')";
      });

  py::class_<ImpactPair>(m, "ImpactPair",
                         "A pair of bodies that meet during a sweep (a < b), and when.")
      .def_readonly("a", &ImpactPair::a, "Body id.")
      .def_readonly("b", &ImpactPair::b, "Body id.")
      .def_readonly("result", &ImpactPair::result,
                    "The ImpactResult of the pair (status, t, poses and distance at t).")
      .def("__repr__", [](const ImpactPair& p) {
        return "proxima.ImpactPair(" + std::to_string(p.a) + ", " + std::to_string(p.b) +
               ", status='" + to_string(p.result.status) +
               "', t=" + py::repr(py::float_(p.result.t)).cast<std::string>() + ")";
      });

  py::class_<SweepStats>(m, "SweepStats", "What the last sweep did.")
      .def_readonly("bodies", &SweepStats::bodies, "Bodies in the scene.")
      .def_readonly("moving_bodies", &SweepStats::moving_bodies,
                    "Bodies whose end pose differs from their pose.")
      .def_readonly("candidate_pairs", &SweepStats::candidate_pairs,
                    "Pairs whose swept boxes overlap, after the filters (each one a "
                    "time_of_impact).")
      .def_readonly("impact_pairs", &SweepStats::impact_pairs,
                    "Of those, the pairs not separated over the motion (reported).")
      .def_readonly("distance_queries", &SweepStats::distance_queries,
                    "Advancement steps (distance queries) of all candidate pairs.")
      .def_readonly("warm_pairs", &SweepStats::warm_pairs,
                    "Candidate pairs that started from a cache (the last sweep's or step's).")
      .def_readonly("filtered_pairs", &SweepStats::filtered_pairs,
                    "Pairs whose swept boxes overlapped but that the pair filters dropped.");

  py::class_<SceneStats>(m, "SceneStats", "What the last step did.")
      .def_readonly("bodies", &SceneStats::bodies, "Bodies in the scene.")
      .def_readonly("candidate_pairs", &SceneStats::candidate_pairs,
                    "Pairs the broad phase passed to the narrow phase.")
      .def_readonly("close_pairs", &SceneStats::close_pairs, "Pairs at distance <= margin.")
      .def_readonly("convex_queries", &SceneStats::convex_queries, "Convex queries run.")
      .def_readonly("warm_pairs", &SceneStats::warm_pairs,
                    "Candidate pairs that started from the previous step's cache.")
      .def_readonly("filtered_pairs", &SceneStats::filtered_pairs,
                    "Pairs whose boxes overlapped but that the pair filters dropped.");

}

// The Scene's construction, its bodies' addition, paddings and poses.
void bind_scene_bodies(py::class_<PyScene>& scene) {
  const DistanceOptions defaults;
  scene
      .def(py::init([](double margin, const std::string& broad_phase, int threads,
                       const std::string& algorithm, double relative_tolerance,
                       double absolute_tolerance, int max_iterations, bool penetration) {
             SceneOptions options;
             options.margin = margin;
             options.broad_phase = to_broad_phase(broad_phase);
             options.threads = threads;
             options.distance = make_options(algorithm, relative_tolerance, absolute_tolerance,
                                             max_iterations, penetration);
             return PyScene(options);
           }),
           py::arg("margin") = 0.0, py::arg("broad_phase") = to_string(SceneOptions{}.broad_phase),
           py::arg("threads") = SceneOptions{}.threads,
           py::arg("algorithm") = to_string(defaults.algorithm),
           py::arg("relative_tolerance") = defaults.relative_tolerance,
           py::arg("absolute_tolerance") = defaults.absolute_tolerance,
           py::arg("max_iterations") = defaults.max_iterations,
           py::arg("penetration") = SceneOptions{}.distance.penetration,
           "margin: pairs at distance <= margin are reported. broad_phase: 'dynamic_aabb_tree' or "
           "'sweep_and_prune'. threads: narrow-phase threads (1: the calling thread, 0: all "
           "cores). penetration: overlapping pairs get their depth (signed distance); off by "
           "default in a scene (a single distance() computes it by default), where it costs many "
           "times a tracked distance per overlapping pair and step. A scene whose options differ "
           "from the defaults in algorithm, relative_tolerance or max_iterations refuses a "
           "TriangleMesh body in add() (InvalidInput): the mesh query cannot honour them.")
      .def(
          "add",
          [](PyScene& s, py::handle body, py::object pose, double padding) {
            const Body b = to_body(body, "body");
            const Pose p = to_pose(pose, "pose");
            const InUse in_use(s, "Scene");
            return s.add(b, p, padding);
          },
          py::arg("body"), py::arg("pose") = py::none(), py::arg("padding") = 0.0,
          "Adds a body and returns its id. body: a ConvexPolytope, a CompoundBody, a "
          "TriangleMesh or a Body (rounded). padding >= 0: the scene's safety distance around "
          "the body, added to its radius in the broad and the narrow phase (so every distance "
          "reported is the padded bodies'). A pair with a rounded, padded or mesh body is "
          "answered as distance(Body, Body); sweep() refuses a scene holding a mesh.")
      .def(
          "set_padding",
          [](PyScene& s, BodyId id, double padding) {
            const InUse in_use(s, "Scene");
            s.set_padding(id, padding);
          },
          py::arg("id"), py::arg("padding"), "Changes body id's padding (>= 0).")
      .def(
          "padding",
          [](const PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            return s.padding(id);
          },
          py::arg("id"), "Body id's padding.")
      .def(
          "body",
          // py::object: Body is bound after Scene (module.cpp), and a typed
          // return would name the C++ type in the signature (and the stubs).
          [](const PyScene& s, BodyId id) -> py::object {
            const InUse in_use(s, "Scene");
            return py::cast(s.body(id));
          },
          py::arg("id"), "Body id as added (a Body: its core and radius, without the padding).")
      .def(
          "set_pose",
          [](PyScene& s, BodyId id, py::object pose) {
            const Pose p = to_pose(pose, "pose");
            const InUse in_use(s, "Scene");
            s.set_pose(id, p);
          },
          py::arg("id"), py::arg("pose"),
          "Moves body id (pose: 4x4, (quaternion, translation) or Pose).")
      .def(
          "set_poses",
          [](PyScene& s, py::object ids, py::object poses) {
            // All or nothing: every id and every pose is checked before the
            // first body moves (a proxima.Pose object is checked here too).
            set_many(s, ids, poses, "set_poses",
                     [&s](BodyId id, const Pose& p) { s.set_pose(id, p); });
          },
          py::arg("ids"), py::arg("poses"),
          "Moves many bodies at once: ids (K,) and poses (K, 4, 4). All or nothing: an unknown "
          "id or a bad pose raises before any body moves.");
}

// The Scene's pair filters, removal, membership and readers.
void bind_scene_filters(py::class_<PyScene>& scene) {
  scene
      .def(
          "set_filter",
          [](PyScene& s, BodyId id, std::uint32_t group, std::uint32_t mask) {
            const InUse in_use(s, "Scene");
            s.set_filter(id, CollisionFilter{group, mask});
          },
          py::arg("id"), py::arg("group") = CollisionFilter{}.group,
          py::arg("mask") = CollisionFilter{}.mask,
          "Pair filter of body id: bodies a and b are tested only when (a.group & b.mask) and "
          "(b.group & a.mask) are both non-zero (bit sets; default group 1, mask all ones).")
      .def(
          "filter",
          [](const PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            const CollisionFilter f = s.filter(id);
            return py::make_tuple(f.group, f.mask);
          },
          py::arg("id"), "(group, mask) of body id.")
      .def(
          "exclude_pair",
          [](PyScene& s, BodyId a, BodyId b) {
            const InUse in_use(s, "Scene");
            s.exclude_pair(a, b);
          },
          py::arg("a"), py::arg("b"),
          "Never test the pair (a, b) (e.g. a robot's adjacent links); undone by include_pair or "
          "by removing either body.")
      .def(
          "include_pair",
          [](PyScene& s, BodyId a, BodyId b) {
            const InUse in_use(s, "Scene");
            s.include_pair(a, b);
          },
          py::arg("a"), py::arg("b"), "Undoes exclude_pair(a, b).")
      .def(
          "is_excluded",
          [](const PyScene& s, BodyId a, BodyId b) {
            const InUse in_use(s, "Scene");
            return s.is_excluded(a, b);
          },
          py::arg("a"), py::arg("b"),
          "Whether exclude_pair(a, b) excluded the pair (not undone by include_pair).")
      .def(
          "tests_pair",
          [](const PyScene& s, BodyId a, BodyId b) {
            const InUse in_use(s, "Scene");
            return s.tests_pair(a, b);
          },
          py::arg("a"), py::arg("b"), "Whether step() tests the pair (filters and exclusions).")
      .def(
          "remove",
          [](PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            s.remove(id);
          },
          py::arg("id"), "Removes body id (its id may be reused).")
      .def(
          "contains",
          [](const PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            return s.contains(id);
          },
          py::arg("id"), "Whether body id is in the scene (`id in scene` says the same).")
      .def("__contains__",
           [](const PyScene& s, BodyId id) {
             const InUse in_use(s, "Scene");
             return s.contains(id);
           })
      .def("__len__",
           [](const PyScene& s) {
             const InUse in_use(s, "Scene");
             return s.body_count();
           })
      .def(
          "pose",
          [](const PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            return Pose(s.pose(id));
          },
          py::arg("id"), "The current pose of body id.")
      .def_property_readonly(
          "body_ids",
          [](const PyScene& s) {
            const InUse in_use(s, "Scene");
            const std::vector<BodyId> ids = s.body_ids();
            return int32_array(ids);
          },
          "Live body ids, increasing, int32.")
      .def_property_readonly(
          "margin",
          [](const PyScene& s) {
            const InUse in_use(s, "Scene");
            return s.options().margin;
          },
          "The query margin.");
}

// The Scene's queries: step, the margin checks, the nearest pair, a body's close pairs.
void bind_scene_queries(py::class_<PyScene>& scene) {
  scene
      .def(
          "step",
          [](PyScene& s) {
            const InUse in_use(s, "Scene");
            std::span<const ClosePair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.step();
            }
            return close_pair_list(pairs);
          },
          "Broad phase and tracked narrow phase on the current poses: the list of ClosePair, "
          "sorted by (a, b).")
      .def(
          "step_within",
          [](PyScene& s) {
            const InUse in_use(s, "Scene");
            std::span<const MarginPair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.step_within();
            }
            py::list out;
            for (const MarginPair& p : pairs) out.append(py::cast(p));
            return out;
          },
          "step()'s pairs without their distances: the same broad phase and pair caches, then "
          "the margin query on each candidate, stopped at its first proof. The list of "
          "MarginPair (status 'within', or 'undecided' at the iteration cap), sorted by (a, b); "
          "the same pairs as step() up to the contact band of the margin.")
      .def(
          "first_within",
          [](PyScene& s) -> py::object {
            const InUse in_use(s, "Scene");
            std::optional<MarginPair> hit;
            {
              py::gil_scoped_release release;
              hit = s.first_within();
            }
            if (!hit) return py::none();
            return py::cast(*hit);
          },
          "The collision check of the whole scene: the first pair found within the margin (a "
          "MarginPair; the last call's pair is asked first), or None when every pair is proved "
          "beyond it.")
      .def_property_readonly(
          "stats",
          [](const PyScene& s) {
            const InUse in_use(s, "Scene");
            return s.stats();
          },
          "SceneStats of the last step.")
      .def(
          "nearest_pair",
          [](PyScene& s) -> py::object {
            const InUse in_use(s, "Scene");
            std::optional<ClosePair> nearest;
            {
              py::gil_scoped_release release;
              nearest = s.nearest_pair();
            }
            if (!nearest) return py::none();
            return py::cast(*nearest);
          },
          "The pair of smallest distance over every pair the filters let through, however far "
          "apart (a ClosePair), or None with fewer than two bodies or no tested pair.")
      .def(
          "pairs_within",
          [](PyScene& s, BodyId id, double margin) {
            const InUse in_use(s, "Scene");
            std::vector<ClosePair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.pairs_within(id, margin);
            }
            return close_pair_list(pairs);
          },
          py::arg("id"), py::arg("margin"),
          "Every body within margin of body id (touching and intersecting included), as "
          "ClosePair (min id, max id), by increasing other id.");
}

// The Scene's motions and sweeps (time of impact), the all-pairs twins, its repr.
void bind_scene_motion(py::class_<PyScene>& scene) {
  scene
      .def(
          "set_end_pose",
          [](PyScene& s, BodyId id, py::object pose) {
            const Pose p = to_pose(pose, "pose");
            const InUse in_use(s, "Scene");
            s.set_end_pose(id, p);
          },
          py::arg("id"), py::arg("pose"),
          "Where body id moves to over the next sweep() (its motion: constant linear velocity of "
          "its frame's origin and constant angular velocity about it, the shorter way round; "
          "set_velocity for more than a half turn). set_pose ends the motion (the end pose becomes the new pose).")
      .def(
          "set_end_poses",
          [](PyScene& s, py::object ids, py::object poses) {
            set_many(s, ids, poses, "set_end_poses",
                     [&s](BodyId id, const Pose& p) { s.set_end_pose(id, p); });
          },
          py::arg("ids"), py::arg("poses"),
          "set_end_pose for many bodies at once: ids (K,) and poses (K, 4, 4). All or nothing.")
      .def(
          "set_velocity",
          [](PyScene& s, BodyId id, py::handle linear, py::handle angular) {
            const Vec3 v = to_vec3(linear, "linear");
            const Vec3 w = to_vec3(angular, "angular");
            const InUse in_use(s, "Scene");
            s.set_velocity(id, v, w);
          },
          py::arg("id"), py::arg("linear"), py::arg("angular"),
          "Body id's motion over the next sweep() by velocities instead of an end pose: its "
          "frame's origin moves at `linear` (units per unit t) and it turns at `angular` (world "
          "frame, radians per unit t) through any angle, several turns included. The end pose "
          "becomes where they take it; set_end_pose and set_pose forget the velocities.")
      .def(
          "end_pose",
          [](const PyScene& s, BodyId id) {
            const InUse in_use(s, "Scene");
            return Pose(s.end_pose(id));
          },
          py::arg("id"), "The end pose of body id (its pose when it does not move).")
      .def(
          "sweep",
          [](PyScene& s, double target_separation, double tolerance, int max_iterations) {
            const InUse in_use(s, "Scene");
            const ImpactOptions options =
                sweep_options(s, target_separation, tolerance, max_iterations);
            std::span<const ImpactPair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.sweep(options);
            }
            return impact_pair_list(pairs);
          },
          py::arg("target_separation") = ImpactOptions{}.target_separation,
          py::arg("tolerance") = ImpactOptions{}.tolerance,
          py::arg("max_iterations") = ImpactOptions{}.max_iterations,
          "Continuous collision: every body moves from its pose to its end pose over t in [0, "
          "1]; returns the ImpactPair of every pair that comes within target_separation on the "
          "way (status 'contact' at t, 'intersecting' at t = 0, or 'iteration_cap'), sorted by "
          "(a, b). No pair is missed, however fast or thin the bodies (the broad phase boxes the "
          "whole motion) and no t is after the true first contact; the filters apply. Poses are "
          "not changed. tolerance: as time_of_impact (0: 1e-6 of the bodies' size). The scene's "
          "distance options apply (penetration off by default).")
      .def_property_readonly(
          "sweep_stats",
          [](const PyScene& s) {
            const InUse in_use(s, "Scene");
            return s.sweep_stats();
          },
          "SweepStats of the last sweep.")
      .def(
          "impact_pairs_all_pairs",
          [](const PyScene& s, double target_separation, double tolerance, int max_iterations) {
            const InUse in_use(s, "Scene");
            const ImpactOptions options =
                sweep_options(s, target_separation, tolerance, max_iterations);
            std::vector<ImpactPair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.impact_pairs_all_pairs(options);
            }
            return impact_pair_list(pairs);
          },
          py::arg("target_separation") = ImpactOptions{}.target_separation,
          py::arg("tolerance") = ImpactOptions{}.tolerance,
          py::arg("max_iterations") = ImpactOptions{}.max_iterations,
          "The slow twin of sweep(): cold time_of_impact on every pair. For checks.")
      .def(
          "close_pairs_all_pairs",
          [](const PyScene& s) {
            const InUse in_use(s, "Scene");
            std::vector<ClosePair> pairs;
            {
              py::gil_scoped_release release;
              pairs = s.close_pairs_all_pairs();
            }
            return close_pair_list(pairs);
          },
          "The slow twin of step(): cold queries on every pair. For checks.")
      .def("__repr__", [](const PyScene& s) {
        const InUse in_use(s, "Scene");
        return "proxima.Scene(bodies=" + std::to_string(s.body_count()) +
               ", margin=" + py::repr(py::float_(s.options().margin)).cast<std::string>() + ")";
      });
}

}  // namespace

void bind_compound_and_scene(py::module_& m) {
  bind_compounds(m);
  bind_compound_queries(m);
  bind_scene_results(m);
  // Every method holds the scene's in-use flag (step() and
  // close_pairs_all_pairs() run without the GIL; anything else at the same
  // time would race with them).
  py::class_<PyScene> scene(
      m, "Scene",
      "Many bodies (ConvexPolytope or CompoundBody) moved by the caller; step() returns the "
      "pairs within the margin, with tracked distance queries (each pair's cache kept across "
      "steps). Use from one thread at a time: a call while another thread's call is running "
      "raises RuntimeError.");
  bind_scene_bodies(scene);
  bind_scene_filters(scene);
  bind_scene_queries(scene);
  bind_scene_motion(scene);
}

}  // namespace proxima::python
