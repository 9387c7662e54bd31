// A scene of moving bodies, built and run by `make test`: 30 random convex
// bodies and two L-shaped compound bodies drift and turn; every step asks for
// the pairs within the margin. Each step is checked against the slow twin
// close_pairs_all_pairs() (cold queries on every pair); a mismatch returns 1.
#include <proxima/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

using proxima::Vec3;

namespace {
std::mt19937_64 rng(7);
double uniform(double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1p-53;
}
Vec3 random_vec(double lo, double hi) {
  return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
}
std::vector<Vec3> box(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  return corners;
}
}  // namespace

int main() {
  proxima::SceneOptions options;
  options.margin = 0.2;  // report pairs at distance <= 0.2
  proxima::Scene scene(options);

  std::vector<proxima::BodyId> ids;
  std::vector<Vec3> start, velocity;
  for (int i = 0; i < 32; ++i) {
    start.push_back(random_vec(0.0, 8.0));
    velocity.push_back(random_vec(-0.03, 0.03));
    if (i < 30) {  // the hull of 30 random points in a unit cube
      std::vector<Vec3> points;
      for (int k = 0; k < 30; ++k) points.push_back(random_vec(-0.5, 0.5));
      ids.push_back(scene.add(std::make_shared<const proxima::ConvexPolytope>(points),
                              proxima::Pose::from_translation(start.back())));
    } else {  // an L-shaped bracket: two convex pieces
      const std::vector<std::vector<Vec3>> pieces = {box({0, 0, 0}, {2, 0.3, 0.3}),
                                                     box({0, 0, 0}, {0.3, 2, 0.3})};
      auto bracket = std::make_shared<const proxima::CompoundBody>(
          proxima::CompoundBody::from_point_sets(pieces));
      ids.push_back(scene.add(bracket, proxima::Pose::from_translation(start.back())));
    }
  }

  int mismatches = 0;
  for (int step = 0; step < 30; ++step) {
    const double t = step;
    for (std::size_t i = 0; i < ids.size(); ++i) {  // drift and turn about a per-body axis
      const Vec3 axis(1.0, static_cast<double>(i % 3), static_cast<double>(i % 5));
      const proxima::Quat turn(Eigen::AngleAxisd(0.02 * t, axis.normalized()));
      scene.set_pose(ids[i], proxima::Pose(turn, start[i] + t * velocity[i]));
    }
    const auto pairs = scene.step();
    const auto slow = scene.close_pairs_all_pairs();  // the obvious twin, for the check
    mismatches += pairs.size() == slow.size() ? 0 : 1;
    for (std::size_t p = 0; p < std::min(pairs.size(), slow.size()); ++p) {
      const bool same = pairs[p].a == slow[p].a && pairs[p].b == slow[p].b &&
                        std::abs(pairs[p].result.distance - slow[p].result.distance) <=
                            1e-9 * (1 + slow[p].result.distance);
      mismatches += same ? 0 : 1;
    }
    if (step % 10 != 0) continue;
    std::printf("step %d: %d candidate pairs, %d close\n", step, scene.stats().candidate_pairs,
                scene.stats().close_pairs);
    for (const proxima::ClosePair& p : pairs) {
      std::printf("  bodies %2d-%2d  %-12s distance %.6f  pieces %d/%d\n", p.a, p.b,
                  proxima::to_string(p.result.status), p.result.distance, p.result.piece_a,
                  p.result.piece_b);
    }
  }
  std::printf("%s: %d mismatches against close_pairs_all_pairs\n",
              mismatches == 0 ? "ok" : "FAILED", mismatches);
  return mismatches == 0 ? 0 : 1;
}
