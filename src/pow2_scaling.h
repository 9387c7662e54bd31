// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 3 internals: power-of-two scaling for the hull build. Heuristics
// (farthest points, Newell sums) run on copies scaled by a power of two so
// that no square overflows whatever the input's magnitude. Exact decisions
// always use the original doubles.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>

#include "proxima/types.h"

namespace proxima::detail {

// The exponent e with max|x| < 2^e (0 for an all-zero input).
inline int magnitude_exponent(double max_abs) {
  if (max_abs == 0.0) return 0;
  int e = 0;
  std::frexp(max_abs, &e);
  return e;
}

// p * 2^e per component, through ldexp: exact unless a component underflows,
// and never through the factor 2^e itself, which overflows when |e| > 1023
// (inputs near the largest doubles, or subnormal ones).
inline Vec3 times_pow2(const Vec3& p, int e) {
  return {std::ldexp(p.x(), e), std::ldexp(p.y(), e), std::ldexp(p.z(), e)};
}

inline double max_abs_coordinate(std::span<const Vec3> pts) {
  double m = 0.0;
  for (const Vec3& p : pts) m = std::max(m, p.cwiseAbs().maxCoeff());
  return m;
}

}  // namespace proxima::detail
