// proxima tests: the hybrid's answer between bodies of very different sizes,
// where the scaled distance's square leaves the normal doubles' range.
// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "proxima/query/distance.h"

namespace proxima::test {
namespace {

std::vector<Vec3> scaled(const std::vector<Vec3>& p, double s) {
  std::vector<Vec3> out;
  for (const Vec3& x : p) out.push_back(x * s);
  return out;
}

// Found by tools/soak at scales 1e+-150 (issue 25): a tetrahedron of 1e-101
// touching a tetrahedron of 1e58 at the origin. In the hybrid's scaled
// units (about 1 / 1e58) the distance is about 1e-159 and its square a
// subnormal with a few digits left: the normal (point_b - point_a) /
// sqrt(distance_squared) had length 1.00002 (swapped, 1.000005), so that
// normal . (point_b - point_a) was not the distance to its own precision.
TEST(DistanceRegression, TinyBodyTouchingHugeOneHasUnitNormal) {
  const ConvexPolytope a(scaled({{-4, 4, 0}, {1, -3, 4}, {-1, -1, 2}, {2, 2, -2}}, 1e-101));
  const ConvexPolytope b(scaled({{1, -2, -4}, {-1, 2, -1}, {-1, 2, 4}, {3, -3, -1}}, 1e58));
  DistanceOptions options;
  options.algorithm = Algorithm::hybrid;
  const DistanceResult ab = distance(a, Pose::identity(), b, Pose::identity(), options);
  const DistanceResult ba = distance(b, Pose::identity(), a, Pose::identity(), options);
  for (const DistanceResult& r : {ab, ba}) {
    EXPECT_EQ(r.status, Status::touching);
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
    ASSERT_GT(r.distance, 0.0);
    EXPECT_NEAR((r.point_b - r.point_a).norm() / r.distance, 1.0, 1e-12);
    EXPECT_NEAR(r.normal.dot(r.point_b - r.point_a) / r.distance, 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace proxima::test
