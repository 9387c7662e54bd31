// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Power-of-two scaling, one definition for every part that works in units
// near the bodies' magnitude: the hull build (its heuristics, farthest
// points and Newell sums, run on scaled copies so that no square
// overflows; exact decisions use the original doubles), the compound
// hierarchy's spheres, GJK and the hybrid. Multiplying by a power of two is
// exact, so the scaled problem has the same answer.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

#include "proxima/core/types.h"

namespace proxima::detail {

// The exponent e with max|x| < 2^e (0 for an all-zero input): frexp's
// exponent, read from the bits for a normal double (libm's frexp is an
// out-of-line call that handles every case; the penetration query asks for
// two per query).
inline int magnitude_exponent(double max_abs) {
  if (max_abs == 0.0) return 0;
  const auto biased = static_cast<int>((std::bit_cast<std::uint64_t>(max_abs) >> 52) & 0x7ff);
  if (biased != 0 && biased != 0x7ff) return biased - 1022;  // 2^(b-1023) <= x < 2^(b-1022)
  int e = 0;
  std::frexp(max_abs, &e);  // subnormal (inf and NaN: frexp's unspecified e)
  return e;
}

// 2^e, exactly (0 or inf where 2^e is out of the doubles' range).
inline double pow2(int e) {
  if (e >= -1022 && e <= 1023)
    return std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52);
  return std::ldexp(1.0, e);
}

// p * 2^e per component: exact unless a component underflows. Through the
// factor 2^e (built from its bits) when it is a normal double: the product
// by a power of two is the correctly rounded p 2^e, the same as ldexp's,
// at a multiplication's cost (face_plane calls this per face vertex: ldexp
// was half of a cold penetration query). Through ldexp otherwise, when
// |e| > 1022 (inputs near the largest doubles, or subnormal ones).
inline Vec3 times_pow2(const Vec3& p, int e) {
  if (e >= -1022 && e <= 1023) {
    return p * pow2(e);
  }
  return {std::ldexp(p.x(), e), std::ldexp(p.y(), e), std::ldexp(p.z(), e)};
}

inline double max_abs_coordinate(std::span<const Vec3> pts) {
  double m = 0.0;
  for (const Vec3& p : pts) m = std::max(m, p.cwiseAbs().maxCoeff());
  return m;
}

// The largest exponent e of an inverse unit 2^e. A magnitude in the
// subnormal range (below 2^-1022) would need up to 2^1074, which overflows
// to inf (SubnormalInput.AnswersAreFiniteAndWithinTheStandard: NaN from the
// hybrid, inf from GJK). Capped here, the scaled magnitude is at least
// 2^-74 (the smallest subnormal is 2^-1074), far from underflow in the
// algorithms' squares and cubes.
inline constexpr int kMaxInverseUnitExponent = 1000;

// magnitude_exponent(magnitude) clamped to [-kMaxInverseUnitExponent,
// kMaxInverseUnitExponent], so that the scale factor 2^-e and its inverse
// are both normal doubles: products with them are exact (or underflow,
// which only lowers a bound) and cost one multiplication, not a call of
// ldexp per coordinate. For the traversals that scale a whole query
// (compound and mesh distances); the magnitudes they accept (kMaxMagnitude)
// keep the scaled ones below 2^20.
inline int clamped_magnitude_exponent(double magnitude) {
  return std::clamp(magnitude_exponent(magnitude), -kMaxInverseUnitExponent,
                    kMaxInverseUnitExponent);
}

// A unit 2^e near `magnitude` (magnitude < unit <= 2 magnitude) and its
// exact reciprocal; (1, 1) for a zero or non-finite magnitude.
struct PowerOfTwoUnit {
  double unit = 1.0;
  double inverse = 1.0;
};

inline PowerOfTwoUnit power_of_two_unit(double magnitude) {
  if (!std::isfinite(magnitude) || !(magnitude > 0.0))
    return {};  // NaN never compared: quiet under traps
  // magnitude = f 2^e, 1/2 <= f < 1
  const int e = std::max(magnitude_exponent(magnitude), -kMaxInverseUnitExponent);
  return {pow2(e), pow2(-e)};
}

// v times a power of two (exact) that brings its largest coordinate into
// [1/2, 1): the same direction, whose squared norm and cross products
// neither underflow nor overflow. A vector whose squared norm falls below
// 2^-1022 keeps only the digits above 2^-1074 there, so v / v.norm() is no
// longer unit (0.94 for an edge of 1e-159 in the penetration query's scaled
// units), and below 2^-1074 the norm is zero.
inline Vec3 exponent_free(const Vec3& v) {
  return times_pow2(v, -magnitude_exponent(v.cwiseAbs().maxCoeff()));
}

// |v| and v / |v| through exponent_free (a zero v: length 0, direction 0).
struct LengthAndDirection {
  double length = 0.0;
  Vec3 direction = Vec3::Zero();
};
inline LengthAndDirection length_and_direction(const Vec3& v) {
  const int e = magnitude_exponent(v.cwiseAbs().maxCoeff());
  const Vec3 w = times_pow2(v, -e);
  const double n = w.norm();
  if (!(n > 0.0)) return {};
  return {std::ldexp(n, e), w / n};
}

}  // namespace proxima::detail
