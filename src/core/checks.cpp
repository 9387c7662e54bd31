// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The refusals of core/checks.h: one wording for every entry point.
#include "core/checks.h"

#include <cstdio>
#include <string>

namespace proxima::detail {
namespace {

std::string suffix(const char* note) {
  return note != nullptr ? std::string(" (") + note + ")" : std::string();
}

}  // namespace

void refuse_not_finite_non_negative(const char* who, const char* field, double value,
                                    const char* note) {
  char number[64];
  std::snprintf(number, sizeof number, "%g", value);
  throw InvalidInput(std::string(who) + ": " + field + " must be finite and >= 0" +
                     suffix(note) + ", got " + number);
}

void refuse_not_finite_positive(const char* who, const char* field, double value) {
  char number[64];
  std::snprintf(number, sizeof number, "%g", value);
  throw InvalidInput(std::string(who) + ": " + field + " must be finite and > 0, got " + number);
}

void refuse_below(const char* who, const char* field, long long value, long long least,
                  const char* note) {
  throw InvalidInput(std::string(who) + ": " + field + " must be at least " +
                     std::to_string(least) + suffix(note) + ", got " + std::to_string(value));
}

}  // namespace proxima::detail
