// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Power-of-two scaling, one definition for the algorithms that work in units
// near the bodies' magnitude (GJK, the hybrid): multiplying by a power of
// two is exact, so the scaled problem has the same answer.
#pragma once

#include <algorithm>
#include <cmath>

namespace proxima::detail {

// The largest exponent e of an inverse unit 2^e. A magnitude in the
// subnormal range (below 2^-1022) would need up to 2^1074, which overflows
// to inf (SubnormalInput.AnswersAreFiniteAndWithinTheStandard: NaN from the
// hybrid, inf from GJK). Capped here, the scaled magnitude is at least
// 2^-74 (the smallest subnormal is 2^-1074), far from underflow in the
// algorithms' squares and cubes.
inline constexpr int kMaxInverseUnitExponent = 1000;

// A unit 2^e near `magnitude` (magnitude < unit <= 2 magnitude) and its
// exact reciprocal; (1, 1) for a zero or non-finite magnitude.
struct PowerOfTwoUnit {
  double unit = 1.0;
  double inverse = 1.0;
};

inline PowerOfTwoUnit power_of_two_unit(double magnitude) {
  if (!(magnitude > 0.0) || !std::isfinite(magnitude)) return {};
  int e = 0;
  std::frexp(magnitude, &e);  // magnitude = f 2^e, 1/2 <= f < 1
  e = std::max(e, -kMaxInverseUnitExponent);
  return {std::ldexp(1.0, e), std::ldexp(1.0, -e)};
}

}  // namespace proxima::detail
