// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The library's own rules of the accuracy standard (DESIGN.md), one
// definition each, for every query and algorithm that applies them. The
// rules a caller sees (the unit roundoff, the contact band, the magnitude
// bound) are public in proxima/core/pose.h and proxima/core/types.h; these
// are the internal ones: the largest magnitude accepted, the exact R, the
// termination and pruning slacks, and the checks of DistanceOptions.
#pragma once

#include <bit>
#include <cstdint>
#include <span>

#include "core/checks.h"
#include "proxima/core/types.h"

namespace proxima::detail {

// Largest coordinate magnitude (bounded as magnitude_bound does) accepted by
// a query. The algorithms take differences of coordinates and map B into
// A's frame (|R y + t| up to sqrt(3) |y| + |t|), and the hybrid and GJK then
// work in units of a power of two near that magnitude; beyond 2^1018
// (2.8e306) those intermediate values can overflow to inf, and differences
// of infinities are NaN. Such input is refused by name instead of answered
// with NaN (Accuracy.MagnitudesBeyondTheLimitAreRefusedByName pins
// both sides of the limit; BodyRefusals.BadPosesAreNamed the rounded body's). A rounded body's
// core plus radius is held to the same limit, so that no sum of radii,
// signed distance or offset point can overflow either.
using proxima::kMaxMagnitude;  // defined in proxima/core/types.h

// The largest coordinate magnitude of vertex y placed at `pose`.
double placed_magnitude(const Vec3& y, const Pose& pose);

// The largest coordinate magnitude of `vertices` placed at `pose`: the exact
// R of the accuracy standard for one body, as every query computes it (the
// O(1) magnitude_bound is an upper bound on it). O(N), so only computed when
// a distance falls between the contact bands of the two; out of line, off
// the hot path of the queries that may call it.
double placed_magnitude(std::span<const Vec3> vertices, const Pose& pose);

// Rounding slack of the algorithms' termination test (the gap between the
// upper bound and the support's certified lower bound), in units of u times
// the magnitude of the coordinates it is computed from: the hybrid's support
// values w.a* and w.b*, and GJK's v.w with v rebuilt from the simplex
// points, each carry an error of a few u of that magnitude, so a gap below
// this slack cannot be resolved by more iterations. Well inside the 64 u R
// contact band (kContactBandUlps). Pinned by the certified answers at every
// scale of Gjk.ScaleInvariance and DistanceAccuracy.ScalesAndFarFromOrigin.
inline constexpr double kTerminationGapUlps = 16.0;

// Answers of distance() whose distance is within this many contact bands
// of zero have their witness pair's distance recomputed in double-double
// and their status decided from it (query/extended_distance.h): there a
// double's error of a few u R is a sizeable share of the band, while well
// above it the status cannot change and the standard's absolute term
// already bounds the error. The tracked fast path (d far above the band)
// pays one comparison. GJK labels an answer it could not certify by the
// same range (gjk.cpp, bounded_status): touching within it, where the
// recomputation decides, undecided beyond.
inline constexpr double kExtendedBands = 16.0;

// The standard's relative term (DESIGN.md: |distance - d*| <= 1e-12 d* +
// 64 u R): how far an answer computed in double may be from the exact
// distance besides the band, which an answer recomputed in extended
// precision must not contradict (query/distance.cpp, refine_near_band).
inline constexpr double kStandardRelative = 1e-12;

// Slack of a pruning test in a hierarchy traversal (compound pieces, mesh
// triangles and boxes), in units of u times the query's magnitude R (the
// largest of the bodies' magnitude bounds): a pair is pruned only when its
// rounded lower bound exceeds the best distance found by more than this, so
// that a pruned pair is farther than the best in exact arithmetic too. The
// bound (a box or sphere gap formed from transformed coordinates, a few u R
// each) and the best distance (a convex query's answer, within the 64 u R
// band of the exact one, or a triangle kernel's, within 32 u R) are each a
// few tens of u R off. 512 u R is at least the slack each traversal derived
// for itself (the compound's 256 u (R_a + R_b), the mesh-convex's 128 u R,
// the mesh-mesh's 64 u in units below 2 R), so no traversal prunes a pair it
// kept before, and it still prunes everything farther than 6e-14 R. Pinned
// by the brute-force twins: Compound.RandomCompoundsAgreeWithTheTwin,
// MeshDistanceTraversal.MatchesBruteForceAtAnyScale.
inline constexpr double kPruneSlackUlps = 512.0;

// The slack above for a query of magnitude R.
inline double prune_slack(double magnitude) { return kPruneSlackUlps * kUnitRoundoff * magnitude; }

// The checks of DistanceOptions, the same for every entry point that takes
// them (core/checks.h's rules and wording): relative_tolerance and
// absolute_tolerance finite and >= 0 (-0.0 included), max_iterations at
// least 1. Throws InvalidInput naming `who`, the options' `path` and the
// field ("distance: options.max_iterations must be at least 1, got 0";
// "Scene: options.distance.relative_tolerance ...").
void check_distance_options(const DistanceOptions& options, const char* who,
                            const char* path = "options");

// What a query on triangle meshes takes of DistanceOptions. Its triangle
// pairs are solved in closed form (no algorithm, no iterations), and its
// search stops at the hull's bound to the relative tolerance 1e-12
// (mesh_pair.h, kHullStopRelative): it honours absolute_tolerance, and
// penetration false (it computes no depth: the default true is answered as
// false is, documented at MeshResult). A query whose leaves are the convex
// query between each triangle and a polytope (distance(TriangleMesh,
// ConvexPolytope)) honours algorithm, max_iterations and extended_precision
// there too (the triangle pairs' closed-form kernels have no extended
// recomputation).
enum class MeshOptionUse : std::uint8_t {
  triangle_pairs,  // mesh-mesh, a Body pair with a mesh, the mesh margin queries
  convex_leaves,   // distance(TriangleMesh, ConvexPolytope)
};

// True when the fields that `use` cannot honour are at their defaults
// (compared on the bits: no floating-point comparison). O(1), for the hot
// path: call check_mesh_options only when it fails.
inline bool mesh_options_plainly_valid(const DistanceOptions& options, MeshOptionUse use) {
  const DistanceOptions defaults;
  return std::bit_cast<std::uint64_t>(options.relative_tolerance) ==
             std::bit_cast<std::uint64_t>(defaults.relative_tolerance) &&
         (use == MeshOptionUse::convex_leaves || (options.algorithm == defaults.algorithm &&
                                                  options.max_iterations == defaults.max_iterations &&
                                                  !options.extended_precision));
}

// check_distance_options, then the refusal of a non-default value of a
// field that `use` cannot honour, naming the field, its value and the body
// kind ("mesh distance: options.algorithm gjk does not apply to a triangle
// mesh ..."). Never ignored: a caller who set it expects it to act.
void check_mesh_options(const DistanceOptions& options, const char* who, MeshOptionUse use,
                        const char* path = "options");

// True when every DistanceOptions check passes, decided on the bits with no
// floating-point comparison (a NaN compared raises FE_INVALID, which a
// caller's trap would turn into SIGFPE instead of the refusal): both
// tolerances have their sign clear and their exponent below all ones (so
// does their bitwise or), and at least one iteration. -0.0 fails this
// sufficient test and is accepted by check_distance_options. O(1), for the
// hot path: call check_distance_options only when it fails.
inline bool distance_options_plainly_valid(const DistanceOptions& options) {
  return (std::bit_cast<std::uint64_t>(options.relative_tolerance) |
          std::bit_cast<std::uint64_t>(options.absolute_tolerance)) < 0x7ff0000000000000ULL &&
         options.max_iterations >= 1;
}

}  // namespace proxima::detail
