// proxima's soak: the convex episodes (cold, swapped, across algorithms,
// tracked against cold) and the episode dispatch.
// SPDX-License-Identifier: BSD-3-Clause
#include <algorithm>
#include <cmath>
#include <memory>

#include "soak.h"
#include "soak_bodies.h"

namespace proxima::soak {

namespace {

Algorithm draw_algorithm(Draw& draw) {
  static constexpr Algorithm kAlgorithms[] = {Algorithm::hybrid, Algorithm::gjk,
                                              Algorithm::enhanced_gjk};
  return kAlgorithms[draw.integer(0, 3)];
}

DistanceOptions options_of(Algorithm algorithm) {
  DistanceOptions options;
  options.algorithm = algorithm;
  return options;
}

// The accuracy standard's R for a query: the placed bodies' largest
// coordinate, the bodies' own, and the poses' offsets (the band a caller may
// expect when the work frame is not the world's).
double query_magnitude(const ConvexPair& pair, const Pose& pose_a, const Pose& pose_b) {
  return std::max({placed_magnitude(pair.points_a, pose_a),
                   placed_magnitude(pair.points_b, pose_b), pair.scale,
                   pose_a.translation.cwiseAbs().maxCoeff(),
                   pose_b.translation.cwiseAbs().maxCoeff()});
}

double world_magnitude(const ConvexPair& pair, const Pose& pose_a, const Pose& pose_b) {
  return std::max(placed_magnitude(pair.points_a, pose_a),
                  placed_magnitude(pair.points_b, pose_b));
}

std::string reproducer(const ConvexPair& pair, const Pose& pose_a, const Pose& pose_b,
                       Algorithm algorithm) {
  return "\"algorithm\":\"" + std::string(to_string(algorithm)) + "\"," +
         query_line(pair.points_a, pose_a, 0, pair.points_b, pose_b, 0);
}

// Two answers to one question agree within twice the standard.
bool agree(double x, double y, double magnitude) {
  return std::abs(x - y) <= 2 * (1e-12 * std::abs(y) + 64 * kUnit * magnitude);
}

// Cold queries at many poses, each checked; the same pair swapped (same
// signed distance, mirrored normal) and under another algorithm.
void convex_episode(Context& c) {
  const ConvexPair pair = draw_convex_pair(c.draw);
  const int count = c.draw.integer(20, 200);
  const Pose pose_a(c.draw.rotation(),
                    Vec3(c.draw.normal3() * pair.scale * (c.draw.chance(0.3) ? 0.0 : c.draw.chance(0.5) ? 1.0 : 1e3)));
  std::vector<Pose> relative = c.draw.chance(0.7)
                                   ? c.draw.poses_about(count, pair.reach)
                                   : c.draw.touching_poses(pair.points_a, pair.points_b, count);
  const Algorithm algorithm = draw_algorithm(c.draw);
  const Algorithm other = draw_algorithm(c.draw);
  const std::string tag = std::string("convex/") + to_string(algorithm);
  for (const Pose& rel : relative) {
    const Pose pose_b = pose_a * rel;
    const double magnitude = query_magnitude(pair, pose_a, pose_b);
    const double world = world_magnitude(pair, pose_a, pose_b);
    const DistanceResult r = distance(*pair.a, pose_a, *pair.b, pose_b, options_of(algorithm));
    const DistanceResult s = distance(*pair.b, pose_b, *pair.a, pose_a, options_of(algorithm));
    const DistanceResult o = distance(*pair.a, pose_a, *pair.b, pose_b, options_of(other));
    c.ledger.queries(3);
    const std::string line = reproducer(pair, pose_a, pose_b, algorithm);
    check_answer(c, tag, r, magnitude, world, line);
    check_answer(c, tag + "/swapped", s, magnitude, world,
                 "\"algorithm\":\"" + std::string(to_string(algorithm)) + "\"," +
                     query_line(pair.points_b, pose_b, 0, pair.points_a, pose_a, 0));
    check_answer(c, std::string("convex/") + to_string(other), o, magnitude, world,
                 reproducer(pair, pose_a, pose_b, other));

    c.ledger.checked("swap:signed_distance");
    if (!agree(r.signed_distance(), s.signed_distance(), magnitude))
      c.ledger.violation("swap:signed_distance", "\"ab\":" + number(r.signed_distance()) +
                                                     ",\"ba\":" + number(s.signed_distance()) +
                                                     "," + line);
    if (r.distance > 1e-6 * magnitude && s.distance > 1e-6 * magnitude) {
      c.ledger.checked("swap:normal_mirrored");
      if ((r.normal + s.normal).norm() > 1e-6)
        c.ledger.violation("swap:normal_mirrored",
                           "\"ab\":" + vec(r.normal) + ",\"ba\":" + vec(s.normal) + "," + line);
    }
    c.ledger.checked("across_algorithms:signed_distance");
    if (!agree(r.signed_distance(), o.signed_distance(), magnitude))
      c.ledger.violation("across_algorithms:signed_distance",
                         "\"other\":\"" + std::string(to_string(other)) + "\",\"first\":" +
                             number(r.signed_distance()) + ",\"second\":" +
                             number(o.signed_distance()) + "," + line);
  }
}

// Random walks of B about A, answered through caches (one per row, or one
// shared by every row as a careless caller might) and cold: the same answer
// within the standard, and the same status away from the band's edge.
void tracked_episode(Context& c) {
  const ConvexPair pair = draw_convex_pair(c.draw);
  const int count = c.draw.integer(10, 60);
  const int steps = c.draw.integer(10, 40);
  const Algorithm algorithm = draw_algorithm(c.draw);
  const bool shared = c.draw.chance(0.25);
  const std::string tag =
      std::string("tracked/") + to_string(algorithm) + (shared ? "+shared" : "");
  std::vector<Pose> poses = c.draw.poses_about(count, pair.reach);
  std::vector<DistanceCache> caches(shared ? 1 : static_cast<std::size_t>(count));
  const double step_t = pair.reach * std::pow(10.0, c.draw.uniform(-6, -1));
  const double step_r = std::pow(10.0, c.draw.uniform(-6, -0.5));
  const Pose identity;
  for (int step = 0; step < steps; ++step) {
    for (int k = 0; k < count; ++k) {
      const Pose& pose_b = poses[static_cast<std::size_t>(k)];
      DistanceCache& cache = caches[shared ? 0 : static_cast<std::size_t>(k)];
      const DistanceResult warm =
          distance(*pair.a, identity, *pair.b, pose_b, options_of(algorithm), &cache);
      const DistanceResult cold = distance(*pair.a, identity, *pair.b, pose_b, options_of(algorithm));
      c.ledger.queries(2);
      const double magnitude = query_magnitude(pair, identity, pose_b);
      const double world = world_magnitude(pair, identity, pose_b);
      const std::string line = reproducer(pair, identity, pose_b, algorithm);
      check_answer(c, tag, warm, magnitude, world, line);
      c.ledger.checked("tracked:warm_equals_cold");
      if (!agree(warm.signed_distance(), cold.signed_distance(), magnitude))
        c.ledger.violation("tracked:warm_equals_cold",
                           "\"tag\":\"" + tag + "\",\"warm\":" + number(warm.signed_distance()) +
                               ",\"cold\":" + number(cold.signed_distance()) + "," + line);
      c.ledger.checked("tracked:warm_status");
      const double edge = std::abs(std::abs(cold.signed_distance()) - 64 * kUnit * world);
      if (warm.status != cold.status &&
          edge > 2 * (1e-12 * std::abs(cold.signed_distance()) + 64 * kUnit * magnitude))
        c.ledger.violation("tracked:warm_status",
                           "\"tag\":\"" + tag + "\",\"warm\":\"" + to_string(warm.status) +
                               "\",\"cold\":\"" + to_string(cold.status) + "\"," + line);
    }
    for (Pose& pose : poses) {
      const Mat3 turn(Eigen::AngleAxisd(step_r * c.draw.uniform(-1, 1), c.draw.unit3()));
      // Re-orthonormalized so that the poses stay rigid over the walk.
      const Quat q = Quat(Mat3(turn * pose.rotation)).normalized();
      pose = Pose(q.toRotationMatrix(), Vec3(pose.translation + c.draw.normal3() * step_t));
    }
  }
}

}  // namespace

ConvexPair draw_convex_pair(Draw& draw) {
  ConvexPair pair;
  pair.points_a = draw.points();
  pair.points_b = draw.points();
  pair.a = std::make_shared<const ConvexPolytope>(pair.points_a);
  pair.b = std::make_shared<const ConvexPolytope>(pair.points_b);
  const double sa = local_magnitude(pair.points_a), sb = local_magnitude(pair.points_b);
  pair.scale = std::max(sa, sb);
  pair.reach = sa + sb;
  return pair;
}

void run_episode(Kind kind, Context& context) {
  switch (kind) {
    case Kind::convex:
      return convex_episode(context);
    case Kind::tracked:
      return tracked_episode(context);
    case Kind::rounded:
      return rounded_episode(context);
    case Kind::compound:
      return compound_episode(context);
    case Kind::mesh:
      return mesh_episode(context);
    case Kind::toi:
      return toi_episode(context);
  }
}

}  // namespace proxima::soak
