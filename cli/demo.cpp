// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima demo`. A guided tour of one query, top to bottom through
// the layers: two hulls built from points (layer 3), the closed-form closest
// points of one feature pair (layer 2), and the distance query with each
// algorithm behind the same call (layer 6). Everything is seeded and fixed,
// so two runs print the same text.
#include "demo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "proxima/geometry/closest_point.h"
#include "proxima/query/distance.h"
#include "proxima/shape/polytope.h"

namespace proxima::cli {
namespace {

// Seed of the ball's points. std::mt19937_64's output sequence is fixed by
// the C++ standard and the mapping to doubles below is ours, so the points
// (and the whole demo) are the same with every compiler and library.
constexpr std::uint64_t kSeed = 20240601;
constexpr int kBallPoints = 200;
// Points of the ball lie at radius kBallInnerRadius..1: the ones near 1 make
// a fine hull, the ones inside show up as interior points.
constexpr double kBallInnerRadius = 0.8;
constexpr double kCubeHalfSize = 0.75;

// Uniform in [-1, 1): the top 53 bits of the generator as a fraction.
double uniform_symmetric(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1p-53 * 2.0 - 1.0;
}

std::vector<Vec3> ball_points() {
  std::mt19937_64 gen(kSeed);
  std::vector<Vec3> points;
  points.reserve(kBallPoints);
  while (static_cast<int>(points.size()) < kBallPoints) {
    // Rejection sampling in the unit ball gives uniform directions; points
    // very near the centre are dropped because their direction, after
    // normalizing, would carry little of the generator's precision.
    const Vec3 p(uniform_symmetric(gen), uniform_symmetric(gen), uniform_symmetric(gen));
    const double n = p.norm();
    if (n > 1.0 || n < 0.125) continue;
    const double radius =
        kBallInnerRadius + (1.0 - kBallInnerRadius) * (0.5 + 0.5 * uniform_symmetric(gen));
    points.push_back(p * (radius / n));
  }
  return points;
}

// A cube's 8 corners, a 3x3 grid of points on each face and its centre: the
// 55 extra points are all on the boundary or inside, so a correct hull keeps
// only the corners and merges the coplanar triangles into 6 square faces.
std::vector<Vec3> cube_points() {
  const double h = kCubeHalfSize;
  std::vector<Vec3> points;
  for (const double x : {-h, h}) {
    for (const double y : {-h, h}) {
      for (const double z : {-h, h}) points.emplace_back(x, y, z);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const double side : {-h, h}) {
      for (const double s : {-0.5 * h, 0.0, 0.5 * h}) {
        for (const double t : {-0.5 * h, 0.0, 0.5 * h}) {
          Vec3 p;
          p[axis] = side;
          p[(axis + 1) % 3] = s;
          p[(axis + 2) % 3] = t;
          points.push_back(p);
        }
      }
    }
  }
  points.emplace_back(0.0, 0.0, 0.0);
  return points;
}

std::string format_point(const Vec3& p) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "(%.6f, %.6f, %.6f)", p.x(), p.y(), p.z());
  return buffer;
}

std::string format_feature(const Feature& f) {
  std::string out = to_string(f.type);
  if (f.type == FeatureType::face) {
    out += ' ';
    out += std::to_string(f.face);
  }
  out += " [";
  for (int i = 0; i < f.vertex_count(); ++i) {
    if (i > 0) out += ' ';
    out += std::to_string(f.vertices[static_cast<std::size_t>(i)]);
  }
  return out + "]";
}

void print_hull_row(const char* label, const std::string& a, const std::string& b) {
  std::printf("  %-26s %14s %14s\n", label, a.c_str(), b.c_str());
}

void print_hull_statistics(const ConvexPolytope& a, int a_inputs, const ConvexPolytope& b,
                           int b_inputs) {
  auto integer = [](long v) { return std::to_string(v); };
  auto real = [](double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.6g", v);
    return std::string(buffer);
  };
  std::printf("Hulls\n");
  print_hull_row("", "A: ball", "B: cube");
  print_hull_row("input points", integer(a_inputs), integer(b_inputs));
  print_hull_row("dimension", integer(a.dimension()), integer(b.dimension()));
  print_hull_row("vertices", integer(a.vertex_count()), integer(b.vertex_count()));
  print_hull_row("edges", integer(a.edge_count()), integer(b.edge_count()));
  print_hull_row("faces", integer(a.face_count()), integer(b.face_count()));
  // Euler's formula for a convex solid: V - E + F = 2. A quick check that
  // the face merging and the edge list agree with each other.
  print_hull_row("V - E + F", integer(a.vertex_count() - a.edge_count() + a.face_count()),
                 integer(b.vertex_count() - b.edge_count() + b.face_count()));
  print_hull_row("interior points", integer(a.interior_point_count()),
                 integer(b.interior_point_count()));
  print_hull_row("scale (max |coordinate|)", real(a.scale()), real(b.scale()));
  print_hull_row("bounding radius", real(a.bounding_radius()), real(b.bounding_radius()));
  print_hull_row("memory bytes", integer(static_cast<long>(a.memory_bytes())),
                 integer(static_cast<long>(b.memory_bytes())));
  std::printf("\n");
}

// One feature pair through the closed-form kernel: the hull edge of A
// nearest to B and the face triangle of B nearest to A, in the world frame.
// Their distance bounds the hulls' distance from above; the query below
// finds the pair that realizes it.
void print_feature_pair(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                        const Pose& pose_b) {
  const auto triangles = b.triangles();
  const auto triangle_face = b.triangle_face();
  if (a.edge_count() == 0 || triangles.empty()) return;  // lower-dimensional hulls: nothing to show
  const Vec3 a_centre = pose_a.apply(a.centroid());
  const Vec3 b_centre = pose_b.apply(b.centroid());

  std::array<std::int32_t, 2> edge{};
  double best = std::numeric_limits<double>::infinity();
  for (const auto& e : a.edges()) {
    const Vec3 mid = pose_a.apply(0.5 * (a.vertex(e[0]) + a.vertex(e[1])));
    const double d = (mid - b_centre).squaredNorm();
    if (d < best) {
      best = d;
      edge = e;
    }
  }
  std::size_t tri = 0;
  best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 c = pose_b.apply(
        (b.vertex(triangles[t][0]) + b.vertex(triangles[t][1]) + b.vertex(triangles[t][2])) / 3.0);
    const double d = (c - a_centre).squaredNorm();
    if (d < best) {
      best = d;
      tri = t;
    }
  }

  const std::array<Vec3, 2> seg = {pose_a.apply(a.vertex(edge[0])),
                                   pose_a.apply(a.vertex(edge[1]))};
  const std::array<Vec3, 3> tri_points = {pose_b.apply(b.vertex(triangles[tri][0])),
                                          pose_b.apply(b.vertex(triangles[tri][1])),
                                          pose_b.apply(b.vertex(triangles[tri][2]))};
  const ClosestPoints<double> cp = closest_points<double>(seg.data(), 2, tri_points.data(), 3);

  auto active = [](std::uint8_t mask, const auto& ids, int n) {
    std::string out = "[";
    for (int i = 0; i < n; ++i) {
      if ((mask >> i) & 1U) {
        if (out.size() > 1) out += ' ';
        out += std::to_string(ids[static_cast<std::size_t>(i)]);
      }
    }
    return out + "]";
  };
  std::printf("Closest points of one feature pair (closed-form kernel, world frame)\n");
  std::printf("  A edge [%d %d] nearest to B, B triangle [%d %d %d] of face %d nearest to A\n",
              edge[0], edge[1], triangles[tri][0], triangles[tri][1], triangles[tri][2],
              triangle_face[tri]);
  std::printf("  distance          %.17g\n", std::sqrt(cp.distance_squared));
  std::printf("  point on A        %s   coefficients %.6f %.6f\n", format_point(cp.point_a).c_str(),
              cp.coef_a[0], cp.coef_a[1]);
  std::printf("  point on B        %s   coefficients %.6f %.6f %.6f\n",
              format_point(cp.point_b).c_str(), cp.coef_b[0], cp.coef_b[1], cp.coef_b[2]);
  std::printf("  active vertices   A %s, B %s (the minimal pair realizing the distance)\n\n",
              active(cp.active_a, edge, 2).c_str(), active(cp.active_b, triangles[tri], 3).c_str());
}

void print_queries(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                   const Pose& pose_b) {
  constexpr std::array<Algorithm, 3> kAlgorithms = {Algorithm::hybrid, Algorithm::gjk,
                                                    Algorithm::enhanced_gjk};
  std::array<DistanceResult, 3> results;
  for (std::size_t i = 0; i < kAlgorithms.size(); ++i) {
    DistanceOptions options;
    options.algorithm = kAlgorithms[i];
    results[i] = distance(a, pose_a, b, pose_b, options, nullptr);
  }

  std::printf("Distance query, cold cache, world frame\n");
  std::printf("  %-13s %-13s %-24s %-24s %s\n", "algorithm", "status", "distance", "lower bound",
              "iterations");
  for (std::size_t i = 0; i < kAlgorithms.size(); ++i) {
    const DistanceResult& r = results[i];
    std::printf("  %-13s %-13s %-24.17g %-24.17g %d\n", to_string(kAlgorithms[i]),
                to_string(r.status), r.distance, r.lower_bound, r.iterations);
  }
  std::printf("\n  %-13s %-36s %s\n", "algorithm", "point on A", "point on B");
  for (std::size_t i = 0; i < kAlgorithms.size(); ++i) {
    std::printf("  %-13s %-36s %s\n", to_string(kAlgorithms[i]),
                format_point(results[i].point_a).c_str(), format_point(results[i].point_b).c_str());
  }
  std::printf("\n  %-13s %-36s %s\n", "algorithm", "feature on A (hull ids)", "feature on B");
  for (std::size_t i = 0; i < kAlgorithms.size(); ++i) {
    std::printf("  %-13s %-36s %s\n", to_string(kAlgorithms[i]),
                format_feature(results[i].feature_a).c_str(),
                format_feature(results[i].feature_b).c_str());
  }
  double low = results[0].distance;
  double high = results[0].distance;
  for (const DistanceResult& r : results) {
    low = std::min(low, r.distance);
    high = std::max(high, r.distance);
  }
  std::printf("\n  largest difference between the algorithms' distances: %.3g\n", high - low);
}

}  // namespace

int run_demo() {
  const std::vector<Vec3> ball = ball_points();
  const std::vector<Vec3> cube = cube_points();
  const ConvexPolytope a(ball);
  const ConvexPolytope b(cube);

  // B is turned 30 degrees about (1, 1, 0), so that no face of the cube is
  // parallel to anything, and moved off to the side of the ball.
  const Pose pose_a = Pose::identity();
  const Pose pose_b(
      Quat(Eigen::AngleAxisd(std::numbers::pi / 6.0, Vec3(1.0, 1.0, 0.0).normalized())),
      Vec3(2.6, 0.3, -0.2));

  std::printf("proxima demo: A, %d seeded points in a ball of radius 1 at the origin;\n",
              kBallPoints);
  std::printf("B, a cube of half-size %.2f with points on its faces, turned 30 degrees\n",
              kCubeHalfSize);
  std::printf("about (1, 1, 0) and moved to %s.\n\n", format_point(pose_b.translation).c_str());

  print_hull_statistics(a, static_cast<int>(ball.size()), b, static_cast<int>(cube.size()));
  print_feature_pair(a, pose_a, b, pose_b);
  print_queries(a, pose_a, b, pose_b);
  return 0;
}

}  // namespace proxima::cli
