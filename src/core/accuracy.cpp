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

double placed_magnitude(const Vec3& y, const Pose& pose) {
  return pose.apply(y).cwiseAbs().maxCoeff();
}

double placed_magnitude(std::span<const Vec3> vertices, const Pose& pose) {
  double r = 0.0;
  for (const Vec3& y : vertices) r = std::max(r, placed_magnitude(y, pose));
  return r;
}

void check_distance_options(const DistanceOptions& options, const char* who, const char* path) {
  // The field's name is built only for a refusal: the queries check their
  // options on every call.
  const auto field = [path](const char* name) { return std::string(path) + "." + name; };
  if (!finite_non_negative(options.relative_tolerance))
    refuse_not_finite_non_negative(who, field("relative_tolerance").c_str(),
                                   options.relative_tolerance, nullptr);
  if (!finite_non_negative(options.absolute_tolerance))
    refuse_not_finite_non_negative(who, field("absolute_tolerance").c_str(),
                                   options.absolute_tolerance, nullptr);
  if (options.max_iterations < 1)
    refuse_below(who, field("max_iterations").c_str(), options.max_iterations, 1, nullptr);
}

void check_mesh_options(const DistanceOptions& options, const char* who, MeshOptionUse use,
                        const char* path) {
  check_distance_options(options, who, path);
  if (mesh_options_plainly_valid(options, use)) return;
  const DistanceOptions defaults;
  const auto refuse = [&](const char* field, const std::string& value, const char* why,
                          const std::string& default_value) {
    throw InvalidInput(std::string(who) + ": " + path + "." + field + " " + value +
                       " does not apply to a triangle mesh (" + why + "): leave it at " +
                       default_value);
  };
  const auto number = [](double x) {
    char s[64];
    std::snprintf(s, sizeof s, "%g", x);
    return std::string(s);
  };
  if (use == MeshOptionUse::triangle_pairs) {
    if (options.algorithm != defaults.algorithm)
      refuse("algorithm", to_string(options.algorithm),
             "its triangle pairs are solved in closed form", to_string(defaults.algorithm));
    if (options.max_iterations != defaults.max_iterations)
      refuse("max_iterations", std::to_string(options.max_iterations),
             "its triangle pairs are solved in closed form, without iterations",
             std::to_string(defaults.max_iterations));
    if (options.extended_precision)
      refuse("extended_precision", "true",
             "its triangle pairs' kernels have no extended recomputation; a mesh against a convex "
             "body has it",
             "false");
  }
  refuse("relative_tolerance", number(options.relative_tolerance),
         "its search stops at the bound of its hull to the relative tolerance 1e-12",
         number(defaults.relative_tolerance));
}

}  // namespace proxima::detail
