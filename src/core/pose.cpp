// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The rigid-pose contract (include/proxima/core/pose.h): the refusals and the
// re-orthonormalization, out of the queries' hot path.
#include "proxima/core/pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace proxima {

Quat unit_quaternion(const Quat& q, std::string_view what) {
  const Eigen::Vector4d& c = q.coeffs();
  bool finite = true;
  for (int i = 0; i < 4; ++i) finite &= is_finite_bits(c[i]);
  if (!finite) {
    throw InvalidInput(std::string(what) +
                       ": the quaternion is not finite (NaN or infinite component)");
  }
  const double largest = c.cwiseAbs().maxCoeff();
  if (largest == 0.0)
    throw InvalidInput(std::string(what) + ": the quaternion is zero: it is not a rotation");
  // After the division the largest component is 1 (exactly, up to its sign)
  // and the squared norm lies in [1, 4]: no overflow, no underflow that
  // matters (a component below 2^-1022 of the largest is 0 to the rotation).
  const Quat scaled(Eigen::Vector4d(c / largest));
  return scaled.normalized();
}

namespace {

// "the identity" or "a turn of A degrees about (x, y, z)", for a unit q. The
// angle is taken in [0, 180] (q and -q are one rotation).
std::string rotation_words(const Quat& q) {
  const double w = std::abs(q.w());
  const Vec3 v = q.w() < 0.0 ? Vec3(-q.vec()) : Vec3(q.vec());
  const double s = v.norm();
  if (s == 0.0) return "the identity";
  const Vec3 axis = v / s;
  const double degrees = 2.0 * std::atan2(s, w) * (180.0 / std::numbers::pi);
  char text[160];
  std::snprintf(text, sizeof text, "a turn of %.6g degrees about (%.6g, %.6g, %.6g)", degrees,
                axis.x() + 0.0, axis.y() + 0.0, axis.z() + 0.0);
  return text;
}

}  // namespace

std::string quaternion_readings(const double* q, std::string_view what) {
  const Quat scalar_first = unit_quaternion(quaternion_in_order(q, QuaternionOrder::wxyz), what);
  const Quat scalar_last = unit_quaternion(quaternion_in_order(q, QuaternionOrder::xyzw), what);
  return "as (w, x, y, z) it is " + rotation_words(scalar_first) +
         "; as (x, y, z, w) (ROS, scipy) it is " + rotation_words(scalar_last);
}

namespace detail {

Pose checked_pose_slow(const Pose& pose, std::string_view what) {
  if (!pose.is_finite()) {
    throw InvalidInput(std::string(what) +
                       " is not finite (NaN or infinite rotation or translation)");
  }
  const Mat3& r = pose.rotation;
  const double skew = (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff();
  char number[64];
  if (!(skew <= kRotationTolerance)) {
    std::snprintf(number, sizeof number, "%.3g", skew);
    throw InvalidInput(std::string(what) + ": rotation is not orthonormal (max |R^T R - I| = " +
                       number + ", tolerance 1e-6): not a rotation");
  }
  const double det = r.determinant();
  if (!(det > 0.0)) {
    std::snprintf(number, sizeof number, "%.3g", det);
    throw InvalidInput(std::string(what) + ": rotation is a reflection (determinant " + number +
                       "): not a rotation");
  }
  // Within the tolerance but not orthonormal to machine precision: the
  // rotation of its quaternion (Eigen's conversion reads the matrix's
  // largest diagonal combination, well conditioned for any rotation) is
  // orthonormal to a few u and within about the skew of R.
  const Quat q(r);
  return {unit_quaternion(q, what).toRotationMatrix(), pose.translation};
}

}  // namespace detail
}  // namespace proxima
