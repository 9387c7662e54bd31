// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The consumer of proxima::proxima alone: two bodies from points, one
// distance query and one batch (TBB inside proxima), built with Eigen as its
// only dependency. Exits 0 when the answers are the known distance.
#include <proxima/query/batch.h>
#include <proxima/query/distance.h>
#include <proxima/shape/polytope.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  std::vector<proxima::Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const proxima::ConvexPolytope a(cube);
  // A tetrahedron whose lowest vertex is 1.5 above the cube's top face.
  const proxima::ConvexPolytope b(
      std::vector<proxima::Vec3>{{0.25, 0.5, 2.5}, {-1, -1, 4}, {2, -1, 4}, {0.5, 2, 4}});

  const proxima::DistanceResult r =
      proxima::distance(a, proxima::Pose::identity(), b, proxima::Pose::identity());
  std::printf("distance %.17g (%s), %d iterations\n", r.distance, proxima::to_string(r.status),
              r.iterations);
  // The accuracy standard: 1e-12 relative plus 64 u R with R = 4.
  const double tolerance = 1e-12 * 1.5 + 64.0 * proxima::kUnitRoundoff * 4.0;
  bool ok = std::abs(r.distance - 1.5) <= tolerance && r.status == proxima::Status::separated;

  // The same pair at four poses of B, lifted by k, on two threads: 1.5 + k.
  std::vector<proxima::Pose> poses_a(4, proxima::Pose::identity());
  std::vector<proxima::Pose> poses_b;
  for (int k = 0; k < 4; ++k)
    poses_b.emplace_back(proxima::Quat::Identity(), proxima::Vec3(0, 0, k));
  std::vector<proxima::DistanceResult> results(4);
  std::vector<proxima::DistanceCache> caches(4);
  proxima::distance_batch(a, poses_a, b, poses_b, results, caches, {}, 2);
  for (int k = 0; k < 4; ++k) {
    const double expected = 1.5 + k;
    ok = ok && std::abs(results[k].distance - expected) <=
                   1e-12 * expected + 64.0 * proxima::kUnitRoundoff * 8.0;
  }
  std::printf("batch: %.17g %.17g %.17g %.17g\n", results[0].distance, results[1].distance,
              results[2].distance, results[3].distance);
  return ok ? 0 : 1;
}
