// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// core layer: rigid poses and the one contract every caller's pose meets, in
// one place. The C++ queries, CompoundBody, Scene, batch queries, Python and
// the CLI all check poses here, so they accept the same poses and refuse
// the others with the same words.
//
// A pose is accepted when
//   - every entry of its rotation and translation is finite,
//   - its rotation is orthonormal within kRotationTolerance:
//     max |(R^T R - I)_ij| <= 1e-6 (rotations that went through float32,
//     as poses from graphics and mesh tools do, are off by a few 1e-7),
//   - det R > 0 (a rotation, not a reflection).
// An accepted rotation that is not orthonormal to machine precision (more
// than kOrthonormalUlps u off) is replaced by the rotation of its
// quaternion before any use, so that every answer is exact for a rigid
// motion within 1e-6 of the given one (the queries invert a pose by its
// transpose, which is only right for an orthonormal R).
#pragma once

#include <Eigen/Geometry>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace proxima {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Isometry3 = Eigen::Isometry3d;

// Unit roundoff of double, u = 2^-53. The accuracy standard of DESIGN.md is
// written in units of u times the largest coordinate magnitude R.
inline constexpr double kUnitRoundoff = 0x1p-53;

// The contract's tolerance on max |(R^T R - I)_ij| (see the top of this file).
inline constexpr double kRotationTolerance = 1e-6;

// Rotations built from a unit quaternion, an angle-axis or a product of a
// few of them are orthonormal to a few u; beyond 32 u a rotation is
// re-orthonormalized (pose_test pins both sides).
inline constexpr double kOrthonormalUlps = 32.0;

// Thrown for bad input (no points, NaN coordinates, non-rigid poses). The
// message names what is wrong and where (e.g. the vertex index).
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Thrown when the library finds a defect of its own (a construction that
// should be exact produced an inconsistent result). Not an InvalidInput:
// a caller that rejects bad user data by catching InvalidInput must not
// swallow a library bug. Please report the input that raised it.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// True when x is neither NaN nor infinite. Tests the exponent bits (all ones
// for both) with integer operations: no floating-point comparison that could
// raise FE_INVALID under a caller's traps.
inline bool is_finite_bits(double x) {
  constexpr std::uint64_t kExponent = 0x7ff0000000000000ULL;
  return (std::bit_cast<std::uint64_t>(x) & kExponent) != kExponent;
}

// The unit quaternion of q, at any magnitude: q is first divided by its
// largest component (exact scaling of the direction), so that neither
// 1e200 (1, 0, 0, 1) (whose squared norm overflows) nor 3e-162 (1, 0, 0, 1)
// (whose squared norm is subnormal and has lost its digits) loses its
// rotation. Throws InvalidInput naming `what` for a zero or non-finite q:
// neither is a rotation, and neither is silently taken as the identity.
Quat unit_quaternion(const Quat& q, std::string_view what = "quaternion");

// The two orders in which quaternions are written: (w, x, y, z), scalar
// first (Eigen, this library's Pose(Quat, ...) and its defaults), and
// (x, y, z, w), scalar last (ROS, scipy's as_quat(), PyBullet). Four numbers
// read in the wrong order are another rotation (ROS's identity (0, 0, 0, 1)
// read scalar first is a half turn about z), so every reader of four
// numbers names its order.
enum class QuaternionOrder { wxyz, xyzw };

// "wxyz" or "xyzw", as the CLI's flag and Python spell them.
inline const char* to_string(QuaternionOrder order) {
  return order == QuaternionOrder::wxyz ? "wxyz" : "xyzw";
}

// The quaternion of four numbers q[0..3] written in `order` (not
// normalized: unit_quaternion does that).
inline Quat quaternion_in_order(const double* q, QuaternionOrder order) {
  return order == QuaternionOrder::wxyz ? Quat(q[0], q[1], q[2], q[3])
                                        : Quat(q[3], q[0], q[1], q[2]);
}

// What four numbers q[0..3] mean in each order, for the refusal of a bare
// quaternion that does not name its order: "as (w, x, y, z) a turn of 180
// degrees about (0, 0, 1); as (x, y, z, w) (ROS, scipy) the identity".
// Throws InvalidInput naming `what` for a zero or non-finite q (as
// unit_quaternion), so that such a q is refused for what it is.
std::string quaternion_readings(const double* q, std::string_view what);

// A rigid motion x -> rotation x + translation.
struct Pose {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();

  Pose() = default;
  // As given; checked against the contract where a query uses it.
  Pose(const Mat3& r, const Vec3& t) : rotation(r), translation(t) {}
  // Normalized by unit_quaternion: throws InvalidInput for a zero or
  // non-finite quaternion.
  Pose(const Quat& q, const Vec3& t)
      : rotation(unit_quaternion(q, "Pose").toRotationMatrix()), translation(t) {}
  Pose(const Isometry3& iso)
      : rotation(iso.linear()),
        translation(iso.translation()) {}  // NOLINT(google-explicit-constructor)

  static Pose identity() { return {}; }
  static Pose from_translation(const Vec3& t) { return {Mat3::Identity(), t}; }

  Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  Pose inverse() const {
    return {Mat3(rotation.transpose()), Vec3(-(rotation.transpose() * translation))};
  }
  // (this * other).apply(p) == this->apply(other.apply(p))
  Pose operator*(const Pose& other) const {
    return {Mat3(rotation * other.rotation), Vec3(rotation * other.translation + translation)};
  }
  // No NaN or infinity in any entry (integer tests of the exponent bits).
  bool is_finite() const {
    bool finite = true;
    for (int i = 0; i < 9; ++i) finite &= is_finite_bits(rotation.data()[i]);
    for (int i = 0; i < 3; ++i) finite &= is_finite_bits(translation[i]);
    return finite;
  }
};

namespace detail {
// The slow side of checked_pose: throws the contract's refusal, or returns
// the pose with its rotation re-orthonormalized.
Pose checked_pose_slow(const Pose& pose, std::string_view what);
}  // namespace detail

namespace detail {
// True when `pose` needs nothing: finite, orthonormal to kOrthonormalUlps u
// and det > 0. O(1), the common case of every query.
inline bool is_rigid(const Pose& pose) {
  // Bounds first, on the bits, so that the arithmetic below raises no
  // FE_INVALID (inf * 0, inf - inf) under a caller's traps:
  //  - every rotation entry below 2 in magnitude: exactly when bit 62 (the
  //    top exponent bit) is clear in each, i.e. in their bitwise or (NaN and
  //    infinity have all exponent bits set). An entry of 2 or more fails the
  //    orthonormality test below anyway (its column's squared norm is >= 4),
  //    so the decision is the one of the full test;
  //  - every translation entry finite: for a magnitude's bits e,
  //    e + (2^63 - bits of inf) has its top bit set exactly when e >= inf.
  const double* m = pose.rotation.data();  // column-major: column k at m + 3 k
  constexpr std::uint64_t kMagnitude = 0x7fffffffffffffffULL;
  constexpr std::uint64_t kTop = 0x8000000000000000ULL;
  constexpr std::uint64_t kInfinity = 0x7ff0000000000000ULL;  // the bits of +inf
  std::uint64_t rotation_bits = 0;
  for (int k = 0; k < 9; ++k) rotation_bits |= std::bit_cast<std::uint64_t>(m[k]);
  std::uint64_t out_of_range = rotation_bits << 1;
  for (int k = 0; k < 3; ++k) {
    out_of_range |=
        (std::bit_cast<std::uint64_t>(pose.translation[k]) & kMagnitude) + (kTop - kInfinity);
  }
  if ((out_of_range & kTop) != 0) [[unlikely]]
    return false;
  // The six distinct entries of R^T R - I, and the sign of det R; written
  // out, since this runs twice in every query.
  const auto dot = [m](int i, int j) {
    return m[3 * i] * m[3 * j] + m[3 * i + 1] * m[3 * j + 1] + m[3 * i + 2] * m[3 * j + 2];
  };
  const double d00 = std::abs(dot(0, 0) - 1.0), d11 = std::abs(dot(1, 1) - 1.0),
               d22 = std::abs(dot(2, 2) - 1.0);
  const double d01 = std::abs(dot(0, 1)), d02 = std::abs(dot(0, 2)), d12 = std::abs(dot(1, 2));
  const double skew =
      std::max(std::max(std::max(d00, d11), std::max(d22, d01)), std::max(d02, d12));
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  return skew <= kOrthonormalUlps * kUnitRoundoff && det > 0.0;
}

// is_rigid(a) && is_rigid(b), the same decision bit for bit, with the two
// poses in the two lanes of SSE2 registers where the target has them (every
// x86-64): one pass of the arithmetic for both poses instead of two, half
// the instructions of the check that every query pays.
inline bool are_rigid(const Pose& pose_a, const Pose& pose_b) {
#if defined(__SSE2__)
  const double* ma = pose_a.rotation.data();
  const double* mb = pose_b.rotation.data();
  const auto pair = [](const double& x, const double& y) {
    return _mm_loadh_pd(_mm_load_sd(&x), &y);
  };
  __m128d r[9];
  for (int k = 0; k < 9; ++k) r[k] = pair(ma[k], mb[k]);
  // The bounds of is_rigid on the bits, lane-wise: the or of the rotation's
  // entries shifted so that bit 62 is the top bit, or'ed with the
  // translations' finiteness tests.
  __m128i rotation_bits = _mm_castpd_si128(r[0]);
  for (int k = 1; k < 9; ++k) rotation_bits = _mm_or_si128(rotation_bits, _mm_castpd_si128(r[k]));
  __m128i out_of_range = _mm_slli_epi64(rotation_bits, 1);
  const __m128i magnitude = _mm_set1_epi64x(0x7fffffffffffffffLL);
  const __m128i finite =
      _mm_set1_epi64x(static_cast<long long>(0x8000000000000000ULL - 0x7ff0000000000000ULL));
  for (int k = 0; k < 3; ++k) {
    const __m128d t = pair(pose_a.translation[k], pose_b.translation[k]);
    out_of_range = _mm_or_si128(
        out_of_range, _mm_add_epi64(_mm_and_si128(_mm_castpd_si128(t), magnitude), finite));
  }
  if (_mm_movemask_pd(_mm_castsi128_pd(out_of_range)) != 0) [[unlikely]]
    return false;
  // The arithmetic of is_rigid, operation for operation in each lane.
  const auto dot = [&r](int i, int j) {
    return _mm_add_pd(
        _mm_add_pd(_mm_mul_pd(r[3 * i], r[3 * j]), _mm_mul_pd(r[3 * i + 1], r[3 * j + 1])),
        _mm_mul_pd(r[3 * i + 2], r[3 * j + 2]));
  };
  const __m128d one = _mm_set1_pd(1.0);
  const __m128d no_sign = _mm_castsi128_pd(magnitude);
  const auto abs = [no_sign](__m128d x) { return _mm_and_pd(x, no_sign); };
  const __m128d d00 = abs(_mm_sub_pd(dot(0, 0), one)), d11 = abs(_mm_sub_pd(dot(1, 1), one)),
                d22 = abs(_mm_sub_pd(dot(2, 2), one));
  const __m128d d01 = abs(dot(0, 1)), d02 = abs(dot(0, 2)), d12 = abs(dot(1, 2));
  const __m128d skew =
      _mm_max_pd(_mm_max_pd(_mm_max_pd(d00, d11), _mm_max_pd(d22, d01)), _mm_max_pd(d02, d12));
  const auto minor = [&r](int i, int j, int k, int l) {
    return _mm_sub_pd(_mm_mul_pd(r[i], r[j]), _mm_mul_pd(r[k], r[l]));
  };
  const __m128d det = _mm_add_pd(
      _mm_sub_pd(_mm_mul_pd(r[0], minor(4, 8, 5, 7)), _mm_mul_pd(r[1], minor(3, 8, 5, 6))),
      _mm_mul_pd(r[2], minor(3, 7, 4, 6)));
  // Both comparisons are ordered: the values are finite here.
  const __m128d ok = _mm_and_pd(_mm_cmple_pd(skew, _mm_set1_pd(kOrthonormalUlps * kUnitRoundoff)),
                                _mm_cmpgt_pd(det, _mm_setzero_pd()));
  return _mm_movemask_pd(ok) == 3;
#else
  return is_rigid(pose_a) && is_rigid(pose_b);
#endif
}
}  // namespace detail

// The pose to use for `pose` under the contract above: `pose` itself when its
// rotation is orthonormal to kOrthonormalUlps u (the common case, O(1)),
// else the re-orthonormalized pose when within kRotationTolerance; otherwise
// throws InvalidInput "<what> is not finite ...", "<what>: rotation is not
// orthonormal ..." or "<what>: rotation is a reflection ...".
inline Pose checked_pose(const Pose& pose, std::string_view what) {
  if (detail::is_rigid(pose)) [[likely]]
    return pose;
  return detail::checked_pose_slow(pose, what);
}

// The same, with the name built only when needed (`what()` returns a
// string): for callers on a hot path whose name is not a literal.
template <class What>
requires std::invocable<What> Pose checked_pose(const Pose& pose, What&& what) {
  if (detail::is_rigid(pose)) [[likely]]
    return pose;
  return detail::checked_pose_slow(pose, what());
}

// A pose checked once against the contract above, for a caller that asks
// many queries of one pose (a body against all its neighbours, a planner's
// configuration against every obstacle): built by checked_pose (the same
// refusal, naming `what`; a rotation within kRotationTolerance of
// orthonormal is re-orthonormalized), then read-only, so that it stays under
// the contract and a query given two of them does not check them again.
// A plain Pose is still checked by every query that takes it.
class RigidPose {
 public:
  RigidPose() = default;  // the identity
  explicit RigidPose(const Pose& pose, std::string_view what = "RigidPose")
      : pose_(checked_pose(pose, what)) {}
  const Pose& pose() const { return pose_; }

 private:
  Pose pose_;
};

// Throws as checked_pose does; for callers that only validate (the pose is
// checked again, and re-orthonormalized if needed, by the query that uses it).
inline void check_pose(const Pose& pose, std::string_view what) { (void)checked_pose(pose, what); }
template <class What>
requires std::invocable<What>
void check_pose(const Pose& pose, What&& what) {
  (void)checked_pose(pose, std::forward<What>(what));
}

}  // namespace proxima
