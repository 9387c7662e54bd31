// proxima benchmarks: the seeded scene of many moving bodies (see
// scene_scenario.h for what it holds).
// SPDX-License-Identifier: BSD-3-Clause
#include "paper/scene_scenario.h"

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "support/random.h"

namespace proxima::bench {
namespace {

// Upper ends of the options: far beyond any run on these machines; they only
// keep a typo from asking for terabytes.
constexpr int kMaxBodies = 10'000'000;
constexpr int kMaxPoints = 100'000;
// A box shape's half extents are drawn in [kBoxMinAspect, 1] before scaling
// its diagonal to the body radius: boxes up to 2.5 times longer than thick,
// far enough from spheres to give faces, edges and vertices as closest
// features, not so flat that a shape is a plate.
constexpr double kBoxMinAspect = 0.4;

// Half the shapes are round (points on the sphere of radius kBodyRadius), half
// boxy (points uniform in a box whose corners lie on that sphere), so the
// hulls run from many small faces to few large ones.
std::vector<Vec3> random_shape_points(Rng& rng, int n) {
  if (rng() % 2 == 0) return points_on_sphere(rng, n, kBodyRadius);
  std::vector<Vec3> points;
  points.reserve(static_cast<std::size_t>(n));
  Vec3 half(uniform(rng, kBoxMinAspect, 1.0), uniform(rng, kBoxMinAspect, 1.0),
            uniform(rng, kBoxMinAspect, 1.0));
  half *= kBodyRadius / half.norm();
  for (int i = 0; i < n; ++i) {
    points.emplace_back(uniform(rng, -half.x(), half.x()), uniform(rng, -half.y(), half.y()),
                        uniform(rng, -half.z(), half.z()));
  }
  return points;
}

// The position of a point moving on a straight line inside [0, size] and
// bouncing off both ends: a triangle wave of period 2 size.
double reflect(double x, double size) {
  const double period = 2.0 * size;
  const double y = x - period * std::floor(x / period);
  return y > size ? period - y : y;
}

bool finite_non_negative(double x) { return std::isfinite(x) && x >= 0.0; }

void validate(const SceneScenarioOptions& o) {
  auto fail = [](const std::string& what) { throw InvalidInput("SceneScenario: " + what); };
  if (o.bodies < 1 || o.bodies > kMaxBodies) {
    fail("bodies must be in [1, " + std::to_string(kMaxBodies) + "], got " +
         std::to_string(o.bodies));
  }
  if (o.shape_pool < 1) fail("shape_pool must be >= 1, got " + std::to_string(o.shape_pool));
  if (o.min_points < 4 || o.min_points > o.max_points || o.max_points > kMaxPoints) {
    fail("points per shape must satisfy 4 <= min_points <= max_points <= " +
         std::to_string(kMaxPoints) + ", got " + std::to_string(o.min_points) + ".." +
         std::to_string(o.max_points));
  }
  if (!finite_non_negative(o.margin)) fail("margin must be finite and >= 0");
  if (!std::isfinite(o.neighbours) || !(o.neighbours > 0.0)) {
    fail("neighbours must be finite and > 0");
  }
  if (!finite_non_negative(o.max_speed)) fail("max_speed must be finite and >= 0");
  if (!finite_non_negative(o.max_angular_speed)) {
    fail("max_angular_speed must be finite and >= 0");
  }
}

}  // namespace

SceneScenario::SceneScenario(const SceneScenarioOptions& options) : options_(options) {
  validate(options_);
  Rng rng(options_.seed);

  // Shapes first, each from its own draws, so that the pool does not depend
  // on the number of bodies. Random points in general position always give
  // a solid hull; the loop only guards against a freak flat draw, which
  // FCL's Convex (and the benchmark's comparison) could not take.
  shapes_.reserve(static_cast<std::size_t>(options_.shape_pool));
  while (static_cast<int>(shapes_.size()) < options_.shape_pool) {
    const int n = uniform_int(rng, options_.min_points, options_.max_points);
    auto shape = std::make_shared<const ConvexPolytope>(random_shape_points(rng, n));
    if (shape->dimension() == 3) shapes_.push_back(std::move(shape));
  }

  // Centres within 2 kBodyRadius + margin of a body's centre fill a ball of
  // volume V; N bodies spread uniformly over a cube of side L put on average
  // (N - 1) V / L^3 of the others in it. Solve for L with N in place of
  // N - 1 (the same for large N, and never a zero-sized cube).
  const double reach = 2.0 * kBodyRadius + options_.margin;
  const double ball_volume = 4.0 / 3.0 * std::numbers::pi * reach * reach * reach;
  cube_size_ = std::cbrt(static_cast<double>(options_.bodies) * ball_volume / options_.neighbours);

  shape_of_.reserve(static_cast<std::size_t>(options_.bodies));
  bodies_.reserve(static_cast<std::size_t>(options_.bodies));
  for (int i = 0; i < options_.bodies; ++i) {
    shape_of_.push_back(uniform_int(rng, 0, options_.shape_pool - 1));
    Body b;
    b.start_position =
        Vec3(uniform(rng, 0, cube_size_), uniform(rng, 0, cube_size_), uniform(rng, 0, cube_size_));
    b.start_rotation = random_quaternion(rng);
    b.velocity = uniform(rng, 0, options_.max_speed) * random_unit_vector(rng);
    b.rotation_axis = random_unit_vector(rng);
    b.angular_speed = uniform(rng, 0, options_.max_angular_speed);
    bodies_.push_back(b);
  }
}

const std::shared_ptr<const ConvexPolytope>& SceneScenario::body_shape(int body) const {
  return shapes_[static_cast<std::size_t>(shape_of_.at(static_cast<std::size_t>(body)))];
}

Pose SceneScenario::pose(int body, int k) const {
  if (k < 0) throw InvalidInput("SceneScenario: step must be >= 0, got " + std::to_string(k));
  const Body& b = bodies_.at(static_cast<std::size_t>(body));
  const double t = static_cast<double>(k);
  const Vec3 line = b.start_position + t * b.velocity;
  const Vec3 position(reflect(line.x(), cube_size_), reflect(line.y(), cube_size_),
                      reflect(line.z(), cube_size_));
  const Quat turn(Eigen::AngleAxisd(b.angular_speed * t, b.rotation_axis));
  return Pose(turn * b.start_rotation, position);
}

void SceneScenario::step(int k, std::vector<Pose>& poses) const {
  if (k < 0) throw InvalidInput("SceneScenario: step must be >= 0, got " + std::to_string(k));
  poses.resize(bodies_.size());
  for (int i = 0; i < body_count(); ++i) poses[static_cast<std::size_t>(i)] = pose(i, k);
}

std::vector<Pose> SceneScenario::step(int k) const {
  std::vector<Pose> poses;
  step(k, poses);
  return poses;
}

}  // namespace proxima::bench
