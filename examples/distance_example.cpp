// The C++ example of the README, built and run by `make test`.
// Two unit cubes; B moves and turns a little at each step and the same
// cache is passed each time (tracking).
#include <proxima/query/distance.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  std::vector<proxima::Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const proxima::ConvexPolytope a(cube);
  const proxima::ConvexPolytope b(cube);

  proxima::DistanceCache cache;  // default-constructed: cold
  for (int step = 0; step < 4; ++step) {
    const proxima::Pose pose_b(proxima::Quat(Eigen::AngleAxisd(0.05 * step, proxima::Vec3::UnitZ())),
                               proxima::Vec3(2.5 + 0.01 * step, 0.2, 0.0));
    const proxima::DistanceResult r = proxima::distance(a, proxima::Pose::identity(), b, pose_b, {}, &cache);
    std::printf("step %d: %s, distance %.9f, lower bound %.9f, A's %s, B's %s, %d iterations\n", step,
                proxima::to_string(r.status), r.distance, r.lower_bound, proxima::to_string(r.feature_a.type),
                proxima::to_string(r.feature_b.type), r.iterations);
    // Step 0 is face to face, exactly 1.5 apart.
    if (step == 0 && std::abs(r.distance - 1.5) > 1e-15) return 1;
    if (r.status != proxima::Status::separated || r.lower_bound > r.distance) return 1;
  }
  return 0;
}
