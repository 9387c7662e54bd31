// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The out-of-line rules of core/accuracy.h: the exact placed magnitude, and
// the checks of DistanceOptions (the hot path calls them only when
// distance_options_plainly_valid fails).
#include "core/accuracy.h"

#include <algorithm>
#include <cstdio>
#include <string>

namespace proxima::detail {
namespace {

// Finite and >= 0, -0.0 included, decided on the bits: a comparison of a
// NaN raises FE_INVALID, which a caller's trap turns into SIGFPE instead of
// the refusal (Pose.DistanceOptionsAreCheckedExactly).
bool finite_non_negative(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  return bits < 0x7ff0000000000000ULL || bits == 0x8000000000000000ULL;
}

[[noreturn]] void refuse(const char* who, const char* field, double value) {
  char what[200];
  std::snprintf(what, sizeof what, "%s.%s must be finite and >= 0, got %g", who, field, value);
  throw InvalidInput(what);
}

}  // namespace

double placed_magnitude(const Vec3& y, const Pose& pose) {
  return pose.apply(y).cwiseAbs().maxCoeff();
}

double placed_magnitude(std::span<const Vec3> vertices, const Pose& pose) {
  double r = 0.0;
  for (const Vec3& y : vertices) r = std::max(r, placed_magnitude(y, pose));
  return r;
}

void check_distance_options(const DistanceOptions& options, const char* who) {
  if (!finite_non_negative(options.relative_tolerance))
    refuse(who, "relative_tolerance", options.relative_tolerance);
  if (!finite_non_negative(options.absolute_tolerance))
    refuse(who, "absolute_tolerance", options.absolute_tolerance);
  if (options.max_iterations < 1) {
    throw InvalidInput(std::string(who) + ".max_iterations must be at least 1, got " +
                       std::to_string(options.max_iterations));
  }
}

}  // namespace proxima::detail
