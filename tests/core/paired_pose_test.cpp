// proxima: the paired pose arithmetic's two forms (src/core/paired_pose.h).
// SPDX-License-Identifier: BSD-3-Clause
//
// The SSE2 form that x86-64 runs and the scalar twin that other targets run
// (and -DPROXIMA_SCALAR builds) must give the same bits, and the scalar twin
// must round as Eigen's products and Pose::apply do: an answer of distance()
// may not depend on the target, and a change of Eigen's rounding order fails
// here by name instead of silently moving answers.
#include "core/paired_pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "support/generators.h"
#include "support/same_bits.h"

namespace proxima {
namespace {

using test::drawn;
using test::drawn_quaternion;
using test::same_bits;

bool same_pose(const Pose& x, const Pose& y) {
  for (int k = 0; k < 9; ++k) {
    if (!same_bits(x.rotation.data()[k], y.rotation.data()[k])) return false;
  }
  return same_bits(x.translation, y.translation);
}

// Rigid poses of every scale, from quaternions (entries with full mantissas,
// so that every rounding of a product shows), plus signed zeros and
// translations near the largest magnitude accepted.
struct Poses {
  std::mt19937 rng{24};
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> exponent{-300, 300};

  Pose next() {
    // The translation first, the order gcc gives the call (see drawn()).
    const Vec3 at = drawn([&] { return g(rng); });
    Pose p(drawn_quaternion([&] { return g(rng); }), at);
    p.translation *= std::ldexp(1.0, exponent(rng));
    return p;
  }
};

TEST(PairedPose, TheTwoFormsGiveTheSameBits) {
  Poses poses;
  const Pose axis_aligned(Mat3(Quat(0.0, 0.0, 0.0, 1.0).toRotationMatrix()), Vec3(-0.0, 0.0, 1e306));
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose a = trial == 0 ? axis_aligned : poses.next();
    const Pose b = trial == 1 ? axis_aligned : poses.next();
    const double sa = std::ldexp(std::abs(poses.g(poses.rng)), poses.exponent(poses.rng));
    const double sb = std::ldexp(std::abs(poses.g(poses.rng)), poses.exponent(poses.rng));
    ASSERT_TRUE(same_bits(detail::magnitude_bound_pair(a, sa, b, sb),
                          detail::magnitude_bound_pair_scalar(a, sa, b, sb)))
        << trial;
    ASSERT_TRUE(same_pose(detail::relative_pose(a, b), detail::relative_pose_scalar(a, b)))
        << trial;
    Vec3 p = b.translation, q = -a.translation, n = b.rotation.col(1);
    Vec3 ps = p, qs = q, ns = n;
    detail::to_frame(a, p, q, n);
    detail::to_frame_scalar(a, ps, qs, ns);
    ASSERT_TRUE(same_bits(p, ps) && same_bits(q, qs) && same_bits(n, ns)) << trial;
  }
}

TEST(PairedPose, TheScalarTwinRoundsAsEigen) {
  Poses poses;
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose a = poses.next();
    const Pose b = poses.next();
    const Pose eigen(Mat3(a.rotation.transpose() * b.rotation),
                     Vec3(a.rotation.transpose() * (b.translation - a.translation)));
    ASSERT_TRUE(same_pose(detail::relative_pose_scalar(a, b), eigen)) << trial;
    ASSERT_TRUE(same_bits(detail::magnitude_bound_pair_scalar(a, 2.0, b, 0.5),
                          std::max(magnitude_bound(a, 2.0), magnitude_bound(b, 0.5))));
    Vec3 p = b.translation, q = -a.translation, n = b.rotation.col(1);
    const Vec3 p_eigen = a.apply(p), q_eigen = a.apply(q), n_eigen = a.rotation * n;
    detail::to_frame_scalar(a, p, q, n);
    ASSERT_TRUE(same_bits(p, p_eigen) && same_bits(q, q_eigen) && same_bits(n, n_eigen)) << trial;
  }
}

}  // namespace
}  // namespace proxima
