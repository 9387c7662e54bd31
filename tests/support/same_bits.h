// proxima test support: bit-for-bit comparison of answers, for the tests that
// require two ways of computing the same thing to agree exactly (batch_test:
// threads and chunking; scene_test: broad phases and threads). Test-only code.
// SPDX-License-Identifier: BSD-3-Clause
//
// Bits, not values: +0 and -0 differ, as they would in a caller that
// divides by them.
#pragma once

#include <bit>
#include <cstdint>

#include "proxima/core/types.h"

namespace proxima::test {

inline bool same_bits(double x, double y) {
  return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
}
inline bool same_bits(const Vec3& x, const Vec3& y) {
  return same_bits(x[0], y[0]) && same_bits(x[1], y[1]) && same_bits(x[2], y[2]);
}
inline bool same_feature(const Feature& x, const Feature& y) {
  return x.type == y.type && x.vertices == y.vertices && x.face == y.face;
}

}  // namespace proxima::test
