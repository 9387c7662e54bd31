// proxima benchmarks: a scene of many moving bodies in FCL 0.7.
// SPDX-License-Identifier: BSD-3-Clause
//
// Why FCL is driven this way (the list itself is at the top of fcl_scene.h):
// - DynamicAABBTreeCollisionManager is FCL's recommended broad phase for
//   moving objects (its own benchmarks rank it first), and its distance()
//   with a user callback is how an FCL user asks for the distances of the
//   pairs the traversal finds. The callback calls fcl::distance on the two
//   CollisionObjects, as FCL's DefaultDistanceFunction does.
// - The margin. FCL's distance traversal looks for the single nearest pair:
//   it keeps a running bound (the callback's `dist` argument, which FCL's
//   default callback sets to the distance it found) and skips every pair of
//   tree nodes whose boxes are at least that far apart. A callback that
//   returned the pair's distance would shrink the bound to the nearest pair
//   found so far, and FCL would skip close pairs farther apart than that. So
//   the callback sets the bound to the margin (to the next double above it,
//   as FCL prunes at box distance >= bound) after every pair: FCL then
//   visits exactly the pairs whose boxes are closer than the margin, the
//   broad phase that proxima::Scene runs with its margin, and the callback
//   keeps those whose exact distance is at most the margin. Before the first
//   callback the bound is FCL's initial max(): the first descent is not
//   pruned, a few dozen box tests.
// - FCL's boxes: CollisionObject::computeAABB boxes a rotated object by the
//   bounding sphere of its local box (centre plus or minus the local box's
//   half diagonal in every axis), looser than the object's own box; that is
//   what FCL users get and it adds candidate pairs, counted as such. The
//   FclBoxes::tight variant replaces it by the tight box of the transformed
//   vertices, to show how much of the difference the loose box makes.
// - The solver: GST_LIBCCD by default. In the paper experiments' cold queries
//   (make run's cold.csv) it is FCL's faster solver from 16 to 4096 vertices
//   and the more accurate one; a broad-phase callback is
//   a cold query (FCL 0.7's DistanceRequest has no cached guess, and no
//   per-pair state survives a traversal).
// - distance_tolerance stays at FCL's default 1e-6 (absolute), as in
//   fcl_peer.cpp: it lets FCL stop earlier than proxima's relative 1e-12.
// - Floating-point traps: FCL's libccd solver divides by zero and makes
//   NaNs on its way (on degenerate simplices of touching and overlapping
//   pairs) and copes with them; under a caller's traps (the test main turns
//   them on) that would stop the process. So the calls into FCL run with the
//   caller's floating-point environment saved, traps off, and restored,
//   flags included, afterwards (as paper.cpp does for every peer): once per
//   step, not per pair.
// - set_poses() is setTransform plus computeAABB (setTransform alone does
//   not move the object's box; FclBoxes::tight: fcl::computeBV of the
//   Convex instead) for every object; step() is update() (refits the tree
//   to the new boxes and rebalances it) and distance().
#include "peers/fcl_scene.h"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/utility.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cfenv>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "peers/fcl_convex.h"

namespace proxima::bench {
namespace {

// A CollisionObject whose world box can be set to the tight box of its
// transformed vertices (FclBoxes::tight): FCL keeps the box in a protected
// member and offers no setter.
class FclObject : public fcl::CollisionObjectd {
 public:
  using fcl::CollisionObjectd::CollisionObjectd;
  void compute_tight_aabb(const fcl::Convexd& convex) {
    fcl::computeBV(convex, getTransform(), aabb);
  }
};

// What the callback needs: the request, the margin, where the pairs go.
struct CallbackData {
  fcl::DistanceRequestd request;
  double margin = 0.0;
  double bound = 0.0;  // the next double above the margin
  std::vector<FclClosePair>* pairs = nullptr;
  int candidates = 0;
  int intersecting = 0;
};

// The caller's floating-point environment saved, traps off for the scope,
// the environment (traps and flags) restored at its end.
class FclFloatingPoint {
 public:
  FclFloatingPoint() {
    std::fegetenv(&saved_);
    fedisableexcept(FE_ALL_EXCEPT);
  }
  ~FclFloatingPoint() { std::fesetenv(&saved_); }
  FclFloatingPoint(const FclFloatingPoint&) = delete;
  FclFloatingPoint& operator=(const FclFloatingPoint&) = delete;

 private:
  std::fenv_t saved_{};
};

int body_index(const fcl::CollisionObjectd* o) {
  return *static_cast<const int*>(o->getUserData());
}

// One fcl::distance between two objects into a fresh result
// (DistanceResult::update keeps the minimum over calls). Returns whether
// the pair is within the margin, filling `pair` with a < b.
bool measure(const fcl::CollisionObjectd* o1, const fcl::CollisionObjectd* o2,
             const fcl::DistanceRequestd& request, double margin, FclClosePair& pair) {
  fcl::DistanceResultd result;
  fcl::distance(o1, o2, request, result);
  if (!(result.min_distance <= margin)) return false;
  pair.a = body_index(o1);
  pair.b = body_index(o2);
  pair.distance = result.min_distance;
  pair.point_a = result.nearest_points[0];
  pair.point_b = result.nearest_points[1];
  if (pair.a > pair.b) {
    std::swap(pair.a, pair.b);
    std::swap(pair.point_a, pair.point_b);
  }
  return true;
}

bool close_pair_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* cdata,
                         double& dist) {
  auto* data = static_cast<CallbackData*>(cdata);
  ++data->candidates;
  FclClosePair pair;
  if (measure(o1, o2, data->request, data->margin, pair)) {
    if (pair.distance < 0.0) ++data->intersecting;
    data->pairs->push_back(pair);
  }
  dist = data->bound;  // keep FCL looking at every box pair closer than the margin
  return false;        // never stop the traversal early
}

}  // namespace

struct FclScene::Impl {
  double margin = 0.0;
  FclSolver solver = FclSolver::libccd;
  FclBoxes boxes = FclBoxes::fcl;
  std::vector<std::shared_ptr<fcl::Convexd>> convexes;
  std::vector<int> shape_of;
  std::vector<int> ids;  // user data of object i points at ids[i] == i
  std::vector<std::unique_ptr<FclObject>> objects;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::vector<FclClosePair> pairs;
  FclSceneStats stats;

  void compute_box(std::size_t i) {
    if (boxes == FclBoxes::tight) {
      objects[i]->compute_tight_aabb(*convexes[static_cast<std::size_t>(shape_of[i])]);
    } else {
      objects[i]->computeAABB();
    }
  }

  fcl::DistanceRequestd request() const {
    fcl::DistanceRequestd r;
    r.enable_nearest_points = true;
    r.gjk_solver_type = solver == FclSolver::libccd ? fcl::GST_LIBCCD : fcl::GST_INDEP;
    return r;
  }
};

FclScene::FclScene(std::span<const std::shared_ptr<const ConvexPolytope>> shapes,
                   std::span<const int> shape_of, std::span<const Pose> poses, double margin,
                   FclSolver solver, FclBoxes boxes)
    : impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(margin) || margin < 0.0) {
    throw InvalidInput("FclScene: margin must be finite and >= 0");
  }
  if (shape_of.size() != poses.size()) {
    throw InvalidInput("FclScene: " + std::to_string(shape_of.size()) + " shape indices but " +
                       std::to_string(poses.size()) + " poses");
  }
  Impl& s = *impl_;
  s.margin = margin;
  s.solver = solver;
  s.boxes = boxes;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (!shapes[k]) throw InvalidInput("FclScene: shape " + std::to_string(k) + " is null");
    s.convexes.push_back(fcl_convex(*shapes[k], "FclScene: shape " + std::to_string(k)));
  }
  const std::size_t n = shape_of.size();
  s.ids.resize(n);
  s.objects.reserve(n);
  std::vector<fcl::CollisionObjectd*> raw;
  raw.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int k = shape_of[i];
    if (k < 0 || static_cast<std::size_t>(k) >= s.convexes.size()) {
      throw InvalidInput("FclScene: body " + std::to_string(i) + " uses shape " +
                         std::to_string(k) + " of " + std::to_string(s.convexes.size()));
    }
    if (!poses[i].is_finite()) {
      throw InvalidInput("FclScene: pose of body " + std::to_string(i) + " is not finite");
    }
    s.ids[i] = static_cast<int>(i);
    s.shape_of.push_back(k);
    auto object = std::make_unique<FclObject>(s.convexes[static_cast<std::size_t>(k)],
                                              fcl_transform(poses[i]));
    object->setUserData(&s.ids[i]);
    raw.push_back(object.get());
    s.objects.push_back(std::move(object));
    s.compute_box(i);
  }
  const FclFloatingPoint fp;
  s.manager.registerObjects(raw);
  s.manager.setup();
  s.stats.bodies = static_cast<int>(n);
}

FclScene::~FclScene() = default;

int FclScene::body_count() const { return static_cast<int>(impl_->objects.size()); }

double FclScene::margin() const { return impl_->margin; }

void FclScene::set_poses(std::span<const Pose> poses) {
  Impl& s = *impl_;
  if (poses.size() != s.objects.size()) {
    throw InvalidInput("FclScene: " + std::to_string(poses.size()) + " poses for " +
                       std::to_string(s.objects.size()) + " bodies");
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!poses[i].is_finite()) {
      throw InvalidInput("FclScene: pose of body " + std::to_string(i) + " is not finite");
    }
    s.objects[i]->setTransform(fcl_transform(poses[i]));
    s.compute_box(i);
  }
}

std::span<const FclClosePair> FclScene::step() {
  Impl& s = *impl_;
  s.pairs.clear();
  CallbackData data;
  data.request = s.request();
  data.margin = s.margin;
  data.bound = std::nextafter(s.margin, std::numeric_limits<double>::infinity());
  data.pairs = &s.pairs;
  const FclFloatingPoint fp;
  s.manager.update();
  s.manager.distance(&data, close_pair_callback);
  s.stats.candidate_pairs = data.candidates;
  s.stats.close_pairs = static_cast<int>(s.pairs.size());
  s.stats.intersecting_pairs = data.intersecting;
  return s.pairs;
}

const FclSceneStats& FclScene::stats() const { return impl_->stats; }

std::vector<FclClosePair> FclScene::close_pairs_all_pairs() const {
  const Impl& s = *impl_;
  const fcl::DistanceRequestd request = s.request();
  const FclFloatingPoint fp;
  std::vector<FclClosePair> out;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    for (std::size_t j = i + 1; j < s.objects.size(); ++j) {
      FclClosePair pair;
      if (measure(s.objects[i].get(), s.objects[j].get(), request, s.margin, pair)) {
        out.push_back(pair);
      }
    }
  }
  return out;
}

void sort_by_bodies(std::vector<FclClosePair>& pairs) {
  std::sort(pairs.begin(), pairs.end(), [](const FclClosePair& x, const FclClosePair& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
}

PairSetDifference compare_close_pairs(std::span<const FclClosePair> fcl,
                                      std::span<const ReferencePair> reference, double margin,
                                      double relative_tolerance, double absolute_tolerance,
                                      std::vector<std::array<int, 2>>* mismatched) {
  auto tolerance = [&](double d) { return relative_tolerance * d + absolute_tolerance; };
  auto near_margin = [&](double d) {
    return std::abs(std::max(d, 0.0) - margin) <= tolerance(margin);
  };
  PairSetDifference diff;
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < fcl.size() || j < reference.size()) {
    const bool take_fcl =
        j == reference.size() ||
        (i < fcl.size() &&
         (fcl[i].a != reference[j].a ? fcl[i].a < reference[j].a : fcl[i].b < reference[j].b));
    const bool same = i < fcl.size() && j < reference.size() && fcl[i].a == reference[j].a &&
                      fcl[i].b == reference[j].b;
    if (same) {
      ++diff.common;
      const double d_ref = reference[j].distance;
      const double error = std::abs(std::max(fcl[i].distance, 0.0) - d_ref);
      diff.worst_absolute = std::max(diff.worst_absolute, error);
      if (d_ref > 0.0) diff.worst_relative = std::max(diff.worst_relative, error / d_ref);
      if (error > tolerance(d_ref)) {
        ++diff.distance_mismatches;
        if (mismatched) mismatched->push_back({fcl[i].a, fcl[i].b});
      }
      ++i;
      ++j;
    } else if (take_fcl) {
      ++diff.only_fcl;
      if (near_margin(fcl[i].distance)) {
        ++diff.boundary;
      } else if (mismatched) {
        mismatched->push_back({fcl[i].a, fcl[i].b});
      }
      ++i;
    } else {
      ++diff.only_reference;
      if (near_margin(reference[j].distance)) {
        ++diff.boundary;
      } else if (mismatched) {
        mismatched->push_back({reference[j].a, reference[j].b});
      }
      ++j;
    }
  }
  return diff;
}

}  // namespace proxima::bench
