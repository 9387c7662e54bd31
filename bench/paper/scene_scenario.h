// proxima benchmarks: a seeded scene of many moving convex bodies, shared by
// the scene benchmark (bench/scene_bench.cpp, proxima against FCL's
// broad-phase manager) and the scene_demo executable (issue 6).
// SPDX-License-Identifier: BSD-3-Clause
//
// N bodies, each a random convex polytope of min_points..max_points points
// (on a sphere of radius 1, or in a box whose corners are at radius 1), so
// every body lies within kBodyRadius = 1 of its pose's translation. The
// shapes come from a pool of `shape_pool` distinct hulls, each reused by
// many bodies, as in a real scene (many crates, many rocks of a few kinds);
// every body has its own pose and motion.
//
// The bodies' centres start uniformly in a cube whose side is chosen for a
// density: on average each body has `neighbours` other bodies whose bounding
// spheres come within `margin` of its own (centres within 2 + margin). Each
// body moves with a constant small linear velocity (bouncing off the cube's
// walls, so the density stays constant) and a constant small angular
// velocity. Poses are a closed-form function of the step number (a
// reflected straight line, a rotation by a growing angle about a fixed
// axis), so step(k) costs the same for any k and two runs with one seed
// give the same poses on every machine: only integer draws of
// std::mt19937_64 and basic IEEE operations feed the random numbers.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::bench {

// Every body lies within this distance of its pose's translation.
inline constexpr double kBodyRadius = 1.0;

struct SceneScenarioOptions {
  int bodies = 1000;
  std::uint64_t seed = 1;
  // Distinct hulls; body i uses one drawn from the pool.
  int shape_pool = 100;
  // Points per shape, drawn uniformly in [min_points, max_points].
  int min_points = 20;
  int max_points = 200;
  // The margin the scene will use; here it only sizes the cube (with
  // `neighbours`).
  double margin = 0.1;
  // Expected number of other bodies whose bounding spheres come within
  // `margin` of a body's bounding sphere (centre distance <= 2 + margin).
  double neighbours = 3.0;
  // Largest linear speed (per step) and angular speed (rad per step); each
  // body's speeds are drawn uniformly in [0, max].
  double max_speed = 0.01;
  double max_angular_speed = 0.01;
};

class SceneScenario {
 public:
  // Builds the shape pool and every body's start pose and motion. Throws
  // InvalidInput naming the option for bodies < 1, shape_pool < 1, points
  // outside 4 <= min_points <= max_points <= 100000, a negative or
  // non-finite margin or speed, or neighbours not finite and > 0.
  explicit SceneScenario(const SceneScenarioOptions& options);

  const SceneScenarioOptions& options() const { return options_; }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  // Side of the cube the bodies' centres stay in ([0, cube_size()]^3).
  double cube_size() const { return cube_size_; }

  // The pool of distinct hulls (all solid, dimension 3).
  std::span<const std::shared_ptr<const ConvexPolytope>> shapes() const { return shapes_; }
  // Which pool shape body i uses, for every body.
  std::span<const int> shape_of() const { return shape_of_; }
  const std::shared_ptr<const ConvexPolytope>& body_shape(int body) const;

  // The poses of every body at step k (k = 0 is the start). Throws
  // InvalidInput for k < 0. The second form reuses `poses`' storage.
  std::vector<Pose> step(int k) const;
  void step(int k, std::vector<Pose>& poses) const;
  Pose pose(int body, int k) const;

 private:
  struct Body {
    Quat start_rotation;
    Vec3 start_position;
    Vec3 velocity;         // per step
    Vec3 rotation_axis;    // unit, world frame
    double angular_speed;  // rad per step
  };

  SceneScenarioOptions options_;
  double cube_size_ = 0.0;
  std::vector<std::shared_ptr<const ConvexPolytope>> shapes_;
  std::vector<int> shape_of_;
  std::vector<Body> bodies_;
};

}  // namespace proxima::bench
