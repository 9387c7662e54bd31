// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal (motion layer): a motion with its turn precomputed, and the
// checks a motion passes before time_of_impact follows it.
#pragma once

#include <cmath>
#include <limits>

#include "proxima/motion/time_of_impact.h"
#include "proxima/shape/body.h"

namespace proxima::detail {

// sin x and cos x for x in [0, pi/2], the range of a sweep's half angle
// when it turns the shorter way (angle <= pi, 0 < t < 1): Taylor polynomials on [0, pi/4], their
// truncation below 1e-19 there, and the cofunctions of pi/2 - x above it
// (pi/2 - x exact by Sterbenz with pi/2's head, then its tail added). A
// few ulps, as the library's, in far fewer instructions than glibc's
// sincos, whose argument reduction covers every double; one pair per body
// and step. Outside the range: std::sin and std::cos. Its twin test is
// TimeOfImpact's (against std::sin and std::cos).
inline void sin_cos_quadrant(double x, double& sine, double& cosine) {
  constexpr double kHalfPiHead = 1.5707963267948966;
  constexpr double kHalfPiTail = 6.123233995736766e-17;
  if (!(x >= 0.0 && x <= kHalfPiHead)) {
    sine = std::sin(x);
    cosine = std::cos(x);
    return;
  }
  const bool high = x > 0.5 * kHalfPiHead;
  const double y = high ? (kHalfPiHead - x) + kHalfPiTail : x;
  const double z = y * y;
  // sin y = y (1 - z/3! + z^2/5! - ... + z^8/17!), cos y = 1 - z/2! + ... + z^9/18!.
  const double s =
      y + y * z *
              (-1.0 / 6 +
               z * (1.0 / 120 + z * (-1.0 / 5040 +
                                     z * (1.0 / 362880 + z * (-1.0 / 39916800 +
                                                              z * (1.0 / 6227020800 +
                                                                   z * (-1.0 / 1307674368000 +
                                                                        z / 355687428096000)))))));
  const double c =
      1.0 +
      z * (-0.5 + z * (1.0 / 24 +
                       z * (-1.0 / 720 +
                            z * (1.0 / 40320 +
                                 z * (-1.0 / 3628800 +
                                      z * (1.0 / 479001600 + z * (-1.0 / 87178291200 +
                                                                  z * (1.0 / 20922789888000 -
                                                                       z / 6402373705728000))))))));
  sine = high ? c : s;
  cosine = high ? s : c;
}

}  // namespace proxima::detail

namespace proxima::detail::toi {

// By classification, not Eigen's allFinite: that computes x - x, which
// raises FE_INVALID on an infinity, and a caller's trap would turn the
// refusal of an overflowing motion into SIGFPE
// (TimeOfImpact.VelocitiesNearTheLargestDoubleAreAnsweredOrRefusedByName).
inline bool finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Squares below this bound are taken as they are (their root in one
// sqrt): a sum of three squares below 2^1000 cannot have overflowed, and
// its root is as accurate as the stable norm's; from 2^1000 up (and in the
// subnormals, where the squares lose bits) the norms and ratios below take
// the stable way.
inline constexpr double kSquareInRange = 0x1p1000;

// |x| from its square where that neither overflows nor underflows (the
// common case, one sqrt), else the stable norm.
// Always inlined: GCC stopped inlining it beside the mesh traversal, a
// call for three multiplies and a root on every bound (callgrind).
[[gnu::always_inline]] inline double fast_norm(const Vec3& x) {
  const double squared = x.squaredNorm();
  if (squared >= std::numeric_limits<double>::min() && squared < kSquareInRange)
    return std::sqrt(squared);
  return x.stableNorm();
}

// The fastest turn followed, radians per unit t: beyond it consecutive
// doubles of the angle t |w| are more than a radian apart (u |w| > 1/2),
// so the pose at t is not defined by the motion, only by rounding; below
// it |w|^2 and its products with the bodies' sizes stay far from
// overflowing in the bounds.
inline constexpr double kMaxTurnRate = 0x1p52;


// A motion with its turn precomputed (Motion::at would convert the rotation
// to an angle and an axis on every call; a time of impact takes poses at a
// dozen times). The turn's angle and axis are the angular velocity's when
// the motion has one (any angle, several turns included), else the
// shorter way's from start to end (an angle in [0, pi]). The turn by
// phi = t angle about the unit axis k is
// Rodrigues' I + sin(phi) K + (1 - cos(phi)) K^2 (K the cross product
// matrix of k), so the pose's rotation is R0 + sin(phi) (K R0) +
// (1 - cos(phi)) (K^2 R0): the two products are made once, and each pose
// costs one sincos (of phi / 2: sin(phi) = 2 s c and 1 - cos(phi) = 2 s^2,
// without the cancellation of 1 - cos for small phi) and 18 multiply-adds.
class Sweep {
 public:
  explicit Sweep(const Motion& m) : motion_(m) {
    if (m.angular) {
      angle_ = m.angular->stableNorm();
      if (angle_ > 0.0) axis_ = *m.angular / angle_;
    } else {
      const Eigen::AngleAxisd turn(Mat3(m.end.rotation * m.start.rotation.transpose()));
      angle_ = turn.angle();
      axis_ = turn.axis();
    }
    // K x = axis x x, column by column.
    for (int j = 0; j < 3; ++j) {
      k_r0_.col(j) = axis_.cross(m.start.rotation.col(j));
      kk_r0_.col(j) = axis_.cross(Vec3(k_r0_.col(j)));
    }
  }
  Pose at(double t) const {
    if (t <= 0.0) return motion_.start;
    if (t >= 1.0) return motion_.end;
    Pose p;
    p.rotation = turned(t);
    p.translation =
        motion_.start.translation + t * (motion_.end.translation - motion_.start.translation);
    return p;
  }
  // The rotation at t by the turn's formula (at t = 1 too, where at() gives
  // the end pose as stored).
  Mat3 turned(double t) const {
    if (!(angle_ > 0.0)) return motion_.start.rotation;
    const double half = 0.5 * t * angle_;
    double s, c;
    detail::sin_cos_quadrant(half, s, c);
    return motion_.start.rotation + (2.0 * s * c) * k_r0_ + (2.0 * s * s) * kk_r0_;
  }
  Vec3 angular_velocity() const { return motion_.angular ? *motion_.angular : angle_ * axis_; }
  double angle() const { return angle_; }
  Vec3 linear_velocity() const { return motion_.linear_velocity(); }

 private:
  Motion motion_;
  double angle_ = 0.0;
  Vec3 axis_ = Vec3::UnitX();
  Mat3 k_r0_ = Mat3::Zero();
  Mat3 kk_r0_ = Mat3::Zero();
};

// A motion under the pose contract (re-orthonormalized where the contract
// allows it), its angular velocity (when given) finite and ending at
// end.rotation, and both ends within the coordinate magnitude the distance
// queries accept, for a body of `scale` (its coordinates' largest
// magnitude in its own frame). `name`: "time_of_impact: motion_a".
Sweep checked_sweep(const Motion& m, double scale, const char* name);

// The motions' closing speed bound |v_b - v_a| + |w_a| reach_a + |w_b|
// reach_b, each reach bounded by sqrt(3) scale (the farthest a body's
// point is from its reference point): finite, or the motions are refused
// (every step's bounds would overflow to infinity and no step could be
// taken).
void check_closing_speed(const Sweep& ma, double scale_a, const Sweep& mb, double scale_b);

// A body's size for the default tolerance: its hull's (or hierarchy's)
// bounding radius plus its rounding radius.
double body_size(const Body& body);

}  // namespace proxima::detail::toi
