// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The largest coordinate magnitude accepted, one definition for every body
// (hulls and their poses, rounded bodies, triangle meshes), and the one
// message that refuses more.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "proxima/core/types.h"

namespace proxima::detail {

// Largest coordinate magnitude (bounded as below) accepted. The algorithms
// take differences of coordinates and map B into A's frame (|R y + t| up
// to sqrt(3) |y| + |t|), and the hybrid, GJK and the mesh traversals then
// work in units of a power of two near that magnitude; beyond 2^1018
// (2.8e306) those intermediate values can overflow to inf, and differences
// of infinities are NaN. Such input is refused by name instead of answered
// with NaN.
using proxima::kMaxMagnitude;  // defined in proxima/core/types.h

// "<who> reaches coordinates of magnitude 1.73e+308 (<what>), beyond the
// supported 2.81e+306 where differences of coordinates may overflow": the
// message of every refusal of kMaxMagnitude, with the magnitude and the
// limit in the same short format.
inline std::string beyond_magnitude(std::string_view who, double magnitude,
                                    std::string_view what) {
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, "%.3g", magnitude);
  std::string text(who);
  text += " reaches coordinates of magnitude ";
  text += numbers;
  if (!what.empty()) {
    text += " (";
    text += what;
    text += ")";
  }
  std::snprintf(numbers, sizeof numbers, "%.3g", kMaxMagnitude);
  text += ", beyond the supported ";
  text += numbers;
  text += " where differences of coordinates may overflow";
  return text;
}

}  // namespace proxima::detail
