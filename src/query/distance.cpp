// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The query API: checks the poses, moves the problem into A's frame (only
// B's relative pose is formed, never transformed vertex arrays), picks the
// contact band from the accuracy standard, runs the chosen algorithm (whole:
// the hybrid's cross-check and contact classification are its own,
// proxima/detail/narrowphase/contact.h) and maps its answer back to the world frame.
#include "proxima/query/distance.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/accuracy.h"
#include "core/magnitude_limit.h"
#include "core/paired_pose.h"
#include "proxima/detail/narrowphase/certified_pair.h"
#include "proxima/detail/narrowphase/gjk.h"
#include "proxima/detail/narrowphase/hybrid.h"
#include "query/extended_distance.h"
#include "query/signed_distance.h"

namespace proxima {
namespace {

// Upper bound on the largest coordinate magnitude of a body placed at
// `pose` (types.h). O(1).
double world_magnitude_bound(const ConvexPolytope& p, const Pose& pose) {
  return magnitude_bound(pose, p.scale());
}

// The largest coordinate magnitude of the placed vertices themselves: the R
// of the accuracy standard (core/accuracy.h).
double world_magnitude(const ConvexPolytope& p, const Pose& pose) {
  return detail::placed_magnitude(p.vertices(), pose);
}

// A lower bound on world_magnitude(p, pose) from a few vertices (ids out of
// range skipped), computed as world_magnitude computes them: a distance
// inside the band of this R is inside the band of the exact R. O(1).
template <std::size_t kCount>
double world_magnitude_floor(const ConvexPolytope& p, const Pose& pose,
                             const std::array<std::int32_t, kCount>& ids) {
  double r = 0.0;
  for (const std::int32_t id : ids) {
    if (id >= 0 && id < p.vertex_count()) r = std::max(r, detail::placed_magnitude(p.vertex(id), pose));
  }
  return r;
}

DistanceResult run(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                   const DistanceOptions& options, double contact_tolerance, DistanceCache& cache) {
  switch (options.algorithm) {
    case Algorithm::gjk:
      return gjk_distance(a, b, b_in_a, options, contact_tolerance);
    case Algorithm::enhanced_gjk:
      return enhanced_gjk_distance(a, b, b_in_a, options, contact_tolerance, cache);
    case Algorithm::hybrid:
      break;
  }
  return hybrid_distance(a, b, b_in_a, options, contact_tolerance, cache);
}

// The contact band of a lower bound on R_w taken from the cached features
// and support hints. Most contacts (overlapping bodies) end with a
// distance of a few roundings, inside this band, where the exact R_w could
// not change the answer, and it is not computed. O(1).
double band_floor(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                  const Pose& pose_b, const DistanceOptions& options, const DistanceCache& c) {
  const std::array ids_a = {c.vertices_a[0], c.vertices_a[1], c.vertices_a[2], c.hint_a};
  const std::array ids_b = {c.vertices_b[0], c.vertices_b[1], c.vertices_b[2], c.hint_b};
  const double r_floor =
      std::max(world_magnitude_floor(a, pose_a, ids_a), world_magnitude_floor(b, pose_b, ids_b));
  return contact_band(r_floor, options.absolute_tolerance);
}

// An answer within a few bands of touching (detail::kExtendedBands): its
// witness pair's distance recomputed in double-double
// (query/extended_distance.h), and the status decided from it against the
// band of R_w: the cheap bounds on that band first (`band_floor`, a lower
// one from a few vertices, and `band_bound`), the exact R_w (O(N)) only
// between them. `result` in A's frame. Out of line: off the tracked path.
[[gnu::noinline]] void refine_near_band(const ConvexPolytope& a, const Pose& pose_a,
                                        const ConvexPolytope& b, const Pose& pose_b,
                                        const DistanceOptions& options, double band_bound,
                                        const DistanceCache& c, DistanceResult& result) {
  Vec3 normal;
  const DistanceResult in_double = result;
  const detail::ExtendedOutcome outcome = detail::refine_distance_extended(
      a, pose_a, b, pose_b, result, normal, options.extended_precision);
  if (outcome == detail::ExtendedOutcome::lower_bound_only) {
    // Positive: certified along `normal`, the answer's normal now (a
    // rounded body trusts the normal of a core answer whose lower bound
    // is positive).
    result.normal = pose_a.rotation.transpose() * normal;
    return;
  }
  if (outcome != detail::ExtendedOutcome::refined) return;
  const double d = result.distance;
  // The answer in double is within its tolerance (relative_tolerance, at
  // least the standard's relative term) and the band of the exact
  // distance; a recomputed distance farther from it than that is not the
  // bodies' (the affine hulls of a wrong feature pair can come closer than
  // the features, with a gap that agrees): keep the answer in double.
  const double relative = std::max(detail::kStandardRelative, options.relative_tolerance);
  if (!(std::abs(d - in_double.distance) <= 2.0 * (relative * in_double.distance + band_bound))) {
    result = in_double;
    return;
  }
  bool separated = d > band_bound;
  if (!separated && d > band_floor(a, pose_a, b, pose_b, options, c)) {
    const double r_exact = std::max(world_magnitude(a, pose_a), world_magnitude(b, pose_b));
    separated = d > contact_band(r_exact, options.absolute_tolerance);
  }
  result.status = separated ? Status::separated : Status::touching;
  // The lower bound is the gap along the pair's normal: the answer's
  // normal must be that one (a rounded body trusts the normal of a core
  // answer whose lower bound is positive, BodyOracle.TouchingCores...).
  result.normal = pose_a.rotation.transpose() * normal;
}

// The result's points and normal from A's frame to the world frame, in
// place (core/paired_pose.h).
[[gnu::always_inline]] inline void to_world(const Pose& pose_a, DistanceResult& result) {
  detail::to_frame(pose_a, result.point_a, result.point_b, result.normal);
}

// The end of a query after its algorithm's answer `result` (A's frame, the
// cheap contact band `band_bound`): the exact band where it matters, the
// signed distance, the world frame. In place, so that distance() builds the
// answer in its caller's return slot (below).
[[gnu::always_inline]] inline void finish_query(const ConvexPolytope& a, const Pose& pose_a,
                                                const ConvexPolytope& b, const Pose& pose_b,
                                                const Pose& b_in_a, const DistanceOptions& options,
                                                double band_bound, DistanceCache& c,
                                                DistanceResult& result) {
  // A touching answer above the band of the exact R is re-solved with that
  // band, the algorithm's cross-check and contact classification included,
  // so that whichever stage answers decides with it
  // (StatusBand.VertexJustAboveAFaceIsSeparatedOutsideTheExactBand: the
  // cross-check used the cheap band and turned the refined separated answer
  // back into touching).
  if (result.status == Status::touching && result.distance > 0.0 &&
      result.distance > band_floor(a, pose_a, b, pose_b, options, c)) {
    const double r_exact = std::max(world_magnitude(a, pose_a), world_magnitude(b, pose_b));
    const double exact_band = contact_band(r_exact, options.absolute_tolerance);
    if (exact_band < band_bound && result.distance > exact_band) {
      result = run(a, b, b_in_a, options, exact_band, c);
    }
  }
  if ((result.distance <= detail::kExtendedBands * band_bound || options.extended_precision) &&
      (result.status == Status::separated || result.status == Status::touching)) [[unlikely]] {
    refine_near_band(a, pose_a, b, pose_b, options, band_bound, c, result);
  }
  // The signed distance: nothing to add when separated (the depth fields
  // stay 0); a contact gets its penetration depth, computed only now, and
  // an uncertified answer its bounds (src/query/signed_distance.cpp).
  if (result.status != Status::separated) [[unlikely]] {
    detail::finish_signed_distance(a, pose_a, b, pose_b, b_in_a, options, c, result);
  }
  // Back to the world frame, in place.
  to_world(pose_a, result);
}

// The query of a pair that was penetrating: the tracked depth first, and
// when it certifies the overlap, its answer without the algorithm's
// (src/query/signed_distance.cpp). Out of line, so that the common path returns
// one object only (below).
[[gnu::noinline]] DistanceResult penetrating_query(const ConvexPolytope& a, const Pose& pose_a,
                                                   const ConvexPolytope& b, const Pose& pose_b,
                                                   const Pose& b_in_a,
                                                   const DistanceOptions& options,
                                                   double band_bound, DistanceCache& c) {
  // One named result (NRVO, as distance_in_frame): the tracked answer is
  // built in the caller's slot, not copied there.
  DistanceResult result;
  if (detail::tracked_overlap(a, b, b_in_a, band_bound, c, result)) [[likely]] {
    to_world(pose_a, result);
    return result;
  }
  result = run(a, b, b_in_a, options, band_bound, c);
  finish_query(a, pose_a, b, pose_b, b_in_a, options, band_bound, c, result);
  return result;
}

// The query for poses under the contract, with the caller's cache or a cold
// one. Its one named result is the caller's return slot itself (NRVO): with
// the penetrating pair's answer a second named object here, the algorithm
// wrote a local that was then copied out, field by field, and to_world's
// stores went through the stack (bench/tracked_instructions under
// callgrind).
[[gnu::always_inline]] inline DistanceResult distance_in_frame(
    const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b, const Pose& pose_b,
    const DistanceOptions& options, DistanceCache& c) {
  if (!detail::distance_options_plainly_valid(options)) [[unlikely]] {
    detail::check_distance_options(options, "distance");
  }

  // The contact band 64 u R + Ae, first with a cheap bound on R. A distance
  // found inside that band but above 0 may still be outside the band of the
  // exact R; then the exact R is computed and the query resumed from its own
  // cache with the exact band, so that "separated" means d > 64 u R exactly
  // (finish_query).
  const double r_bound = detail::magnitude_bound_pair(pose_a, a.scale(), pose_b, b.scale());
  if (!(r_bound <= kMaxMagnitude)) [[unlikely]] {
    throw InvalidInput(detail::beyond_magnitude(
        world_magnitude_bound(a, pose_a) >= world_magnitude_bound(b, pose_b) ? "distance: body a"
                                                                              : "distance: body b",
        r_bound, "vertices and pose translation"));
  }
  const Pose b_in_a = detail::relative_pose(pose_a, pose_b);
  const double band_bound = contact_band(r_bound, options.absolute_tolerance);

  // One named result, returned from one place: GCC 12 elides the copy of
  // a named result only when every return names it. A pair whose last
  // depth was not penetrating (one that overlapped once and separated
  // since) takes the common path: the tracked depth would not be tried for
  // it. A tracked separated pair is answered by its certified cached pair
  // (proxima/detail/narrowphase/certified_pair.h) when it certifies, far
  // from the band: nothing of finish_query applies to such an answer.
  DistanceResult result;
  detail::TrackedPairStart start;
  if (detail::overlap_trackable(options, c)) [[unlikely]] {
    result = penetrating_query(a, pose_a, b, pose_b, b_in_a, options, band_bound, c);
  } else if (detail::certified_tracked_distance(a, b, b_in_a, options, band_bound, c, result,
                                                start)) [[likely]] {
    to_world(pose_a, result);
  } else {
    // A declined pair's evaluation is not done again (certified_pair.h).
    result = start.valid ? hybrid_distance_from_pair(a, b, b_in_a, options, band_bound, c, start)
                         : run(a, b, b_in_a, options, band_bound, c);
    finish_query(a, pose_a, b, pose_b, b_in_a, options, band_bound, c, result);
  }
  return result;
}

// distance() with a cold cache of its own, out of line: the cache's
// destructor (it may own penetration state, types.h) then needs no cleanup
// in distance() itself, whose tracked path would otherwise pay a frame
// pointer and a spill for it on every query (bench/tracked_instructions
// under callgrind).
[[gnu::noinline]] DistanceResult distance_with_cold_cache(const ConvexPolytope& a,
                                                          const Pose& pose_a,
                                                          const ConvexPolytope& b,
                                                          const Pose& pose_b,
                                                          const DistanceOptions& options) {
  DistanceCache cold;
  return distance(a, pose_a, b, pose_b, options, &cold);
}

// distance_of_rigid_poses with a cold cache of its own (see
// distance_with_cold_cache).
[[gnu::noinline]] DistanceResult distance_of_rigid_poses_cold(const ConvexPolytope& a,
                                                              const Pose& pose_a,
                                                              const ConvexPolytope& b,
                                                              const Pose& pose_b,
                                                              const DistanceOptions& options) {
  DistanceCache cold;
  return distance_in_frame(a, pose_a, b, pose_b, options, cold);
}

}  // namespace

DistanceResult distance(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                        const Pose& pose_b, const DistanceOptions& options, DistanceCache* cache) {
  // The poses as the contract takes them (proxima/core/pose.h): the caller's own
  // when rigid to machine precision, else re-orthonormalized copies, or the
  // contract's refusal.
  if (cache == nullptr) return distance_with_cold_cache(a, pose_a, b, pose_b, options);
  if (!detail::are_rigid(pose_a, pose_b)) [[unlikely]] {
    return detail::distance_of_rigid_poses(a, checked_pose(pose_a, "distance: pose_a"), b,
                                           checked_pose(pose_b, "distance: pose_b"), options,
                                           cache);
  }
  return distance_in_frame(a, pose_a, b, pose_b, options, *cache);
}

DistanceResult distance(const ConvexPolytope& a, const RigidPose& pose_a, const ConvexPolytope& b,
                        const RigidPose& pose_b, const DistanceOptions& options,
                        DistanceCache* cache) {
  // Under the contract by construction (RigidPose).
  if (cache == nullptr) [[unlikely]]
    return distance_of_rigid_poses_cold(a, pose_a.pose(), b, pose_b.pose(), options);
  return distance_in_frame(a, pose_a.pose(), b, pose_b.pose(), options, *cache);
}

namespace detail {

DistanceResult distance_of_rigid_poses(const ConvexPolytope& a, const Pose& pose_a,
                                       const ConvexPolytope& b, const Pose& pose_b,
                                       const DistanceOptions& options, DistanceCache* cache) {
  // A cold cache is built only when there is no caller's cache, out of line
  // (the scene's, the bodies' and the compounds' tracked queries come here
  // with their own, and would pay for initializing and destroying an
  // unused cold one on every query).
  if (cache == nullptr) [[unlikely]]
    return distance_of_rigid_poses_cold(a, pose_a, b, pose_b, options);
  return distance_in_frame(a, pose_a, b, pose_b, options, *cache);
}

}  // namespace detail
}  // namespace proxima
