// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// src/core/power_of_two.h reads exponents from a double's bits and builds powers
// of two from them, where it used libm's frexp and ldexp: its twins here are
// those calls, on every exponent of the doubles, normal and subnormal.
#include "core/power_of_two.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace {

using proxima::detail::magnitude_exponent;
using proxima::detail::pow2;
using proxima::detail::power_of_two_unit;

int frexp_exponent(double x) {
  int e = 0;
  std::frexp(x, &e);
  return e;
}

// The slow twin of power_of_two_unit: the libm calls it replaced.
proxima::detail::PowerOfTwoUnit libm_unit(double magnitude) {
  if (!std::isfinite(magnitude) || !(magnitude > 0.0))
    return {};  // NaN never compared: quiet under traps
  const int e = std::max(frexp_exponent(magnitude), -proxima::detail::kMaxInverseUnitExponent);
  return {std::ldexp(1.0, e), std::ldexp(1.0, -e)};
}

// Magnitudes on every binade: each power of two, its neighbours, and random
// mantissas, from the smallest subnormal to the largest double.
std::vector<double> magnitudes() {
  std::vector<double> xs = {std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::min(),
                            std::nextafter(std::numeric_limits<double>::min(), 0.0),
                            std::numeric_limits<double>::max(),
                            1.0,
                            0.75,
                            3.0};
  std::mt19937_64 rng(20261125);
  for (int e = -1074; e <= 1023; ++e) {
    const double p = std::ldexp(1.0, e);
    xs.push_back(p);
    xs.push_back(std::nextafter(p, 0.0));
    xs.push_back(std::nextafter(p, std::numeric_limits<double>::infinity()));
    if (e >= -1022) {  // a random mantissa in this binade
      const std::uint64_t bits =
          (static_cast<std::uint64_t>(e + 1023) << 52) | (rng() & ((std::uint64_t{1} << 52) - 1));
      xs.push_back(std::bit_cast<double>(bits));
    }
  }
  return xs;
}

TEST(PowerOfTwo, MagnitudeExponentIsFrexpsOnEveryBinade) {
  for (const double x : magnitudes()) {
    ASSERT_EQ(magnitude_exponent(x), frexp_exponent(x)) << x;
    ASSERT_EQ(magnitude_exponent(-x), frexp_exponent(-x)) << -x;
  }
  EXPECT_EQ(magnitude_exponent(0.0), 0);
}

TEST(PowerOfTwo, Pow2IsLdexpOfOneOverTheWholeRange) {
  for (int e = -1100; e <= 1100; ++e) {
    const double expected = std::ldexp(1.0, e);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(pow2(e)), std::bit_cast<std::uint64_t>(expected)) << e;
  }
}

TEST(PowerOfTwo, UnitIsTheLibmUnitBitForBit) {
  std::vector<double> xs = magnitudes();
  xs.push_back(0.0);
  xs.push_back(-1.0);
  xs.push_back(std::numeric_limits<double>::infinity());
  xs.push_back(std::numeric_limits<double>::quiet_NaN());
  for (const double x : xs) {
    const auto got = power_of_two_unit(x);
    const auto want = libm_unit(x);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(got.unit), std::bit_cast<std::uint64_t>(want.unit)) << x;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(got.inverse), std::bit_cast<std::uint64_t>(want.inverse))
        << x;
    if (std::isfinite(x) && x >= 0x1p-1000) {
      EXPECT_LT(x, got.unit) << x;  // magnitude < unit <= 2 magnitude
      EXPECT_LE(got.unit, 2.0 * x) << x;
    }
  }
}

}  // namespace
