// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The checks of arguments and options, one rule and one wording each, for
// every entry point that takes a length, a tolerance, a margin, a count or
// a number of threads: "<who>: <field> must be finite and >= 0, got <value>"
// and "<who>: <field> must be at least <least>, got <value>". Finiteness and
// sign are decided on the bits, with no floating-point comparison: a NaN
// compared raises FE_INVALID, which a caller's trap would turn into SIGFPE
// instead of the refusal (Accuracy.ChecksRefuseNaNWithoutRaisingInvalid).
#pragma once

#include <bit>
#include <cstdint>

#include "proxima/core/types.h"

namespace proxima::detail {

// Finite and >= 0, -0.0 included (a length of zero).
inline bool finite_non_negative(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  return bits < 0x7ff0000000000000ULL || bits == 0x8000000000000000ULL;
}

// Finite and > 0.
inline bool finite_positive(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  return bits - 1 < 0x7ff0000000000000ULL - 1;
}

// The refusals, out of line: the checks below inline only their test.
// `note`, when given, follows the rule in parentheses ("0: all cores").
[[noreturn]] void refuse_not_finite_non_negative(const char* who, const char* field, double value,
                                                 const char* note);
[[noreturn]] void refuse_not_finite_positive(const char* who, const char* field, double value);
[[noreturn]] void refuse_below(const char* who, const char* field, long long value,
                               long long least, const char* note);

inline double check_finite_non_negative(double value, const char* who, const char* field,
                                        const char* note = nullptr) {
  if (!finite_non_negative(value)) [[unlikely]]
    refuse_not_finite_non_negative(who, field, value, note);
  return value;
}

inline double check_finite_positive(double value, const char* who, const char* field) {
  if (!finite_positive(value)) [[unlikely]] refuse_not_finite_positive(who, field, value);
  return value;
}

inline long long check_at_least(long long value, long long least, const char* who,
                                const char* field, const char* note = nullptr) {
  if (value < least) [[unlikely]] refuse_below(who, field, value, least, note);
  return value;
}

}  // namespace proxima::detail
