// proxima tests: penetration depth between bodies of very different sizes,
// where the scaled edges of the small one are so short that their squared
// norms leave the normal doubles' range.
// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>

#include <cmath>

#include "proxima/detail/penetration/penetration.h"
#include "proxima/query/distance.h"
#include "support/penetration_oracle.h"

namespace proxima::test {
namespace {

Points scaled(const Points& p, double s) {
  Points out;
  for (const Vec3& x : p) out.push_back(x * s);
  return out;
}

// The soak's rare case (issue 25, soak.py 11 360): a tetrahedron of size
// 1e-101 inside a hull of size 1e58. In the query's units (about 1 / 1e58)
// A's edges are about 1e-159 long; an edge pair's normal n / n.norm() went
// through a squared norm of about 1e-318, a subnormal with a few digits
// left, so that the normal had length 0.99992 and the depth was 8e-5 short
// of the exact one (-4.9610e57 against -4.9614e57, the certificate
// excluding it), with point_a and point_b farther apart than the depth.
// Swapped, the same pair was right. Found by tools/soak's convex episodes
// at scales 1e+-150 as well.
TEST(PenetrationRegression, TinyBodyInHugeOneHasUnitNormal) {
  const Points a = scaled({{-2, -3, -4}, {-1, -4, 4}, {0, -1, -4}, {-4, -2, -1}}, 1e-101);
  const Points b = scaled({{3, 1, -4}, {0, 3, 3}, {0, -3, -4}, {-1, 4, 4}, {-1, -4, 4}, {0, 0, 1}}, 1e58);
  const ConvexPolytope pa(a), pb(b);
  const ExactDepth exact = exact_depth(a, b);
  ASSERT_EQ(exact.origin, OriginInM::inside);
  const double band = kContactBandUlps * kUnitRoundoff * 4e58;
  PenetrationCache cache;
  for (const PenetrationResult& r : {penetration_depth(pa, pb, Pose::identity(), cache),
                                     penetration_depth_brute_force(pa, pb, Pose::identity())}) {
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
    EXPECT_TRUE(within_bound(r.depth, exact.depth_squared, 1e-12, band))
        << r.depth << " against " << exact.depth();
    EXPECT_LE(r.lower_bound, exact.depth() * (1 + 1e-12) + band);
    EXPECT_GE(r.upper_bound, exact.depth() * (1 - 1e-12) - band);
    EXPECT_LE((r.point_b + r.depth * r.normal - r.point_a).norm(), 2 * band);
  }
  // The public query, both ways round.
  const DistanceResult ab = distance(pa, Pose::identity(), pb, Pose::identity());
  const DistanceResult ba = distance(pb, Pose::identity(), pa, Pose::identity());
  for (const DistanceResult& r : {ab, ba}) {
    EXPECT_EQ(r.status, Status::intersecting);
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
    EXPECT_TRUE(within_bound(-r.signed_distance(), exact.depth_squared, 1e-12, band))
        << r.signed_distance() << " against " << -exact.depth();
    EXPECT_NEAR((r.point_a - r.point_b).norm(), -r.signed_distance(), 2 * band);
  }
}

}  // namespace
}  // namespace proxima::test
