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

#include "core/magnitude_limit.h"
#include "proxima/detail/narrowphase/gjk.h"
#include "proxima/detail/narrowphase/hybrid.h"
#include "query/signed_distance.h"

namespace proxima {
namespace {

using detail::kMaxMagnitude;  // magnitude_limit.h

// Upper bound on the largest coordinate magnitude of a body placed at
// `pose` (types.h). O(1).
double world_magnitude_bound(const ConvexPolytope& p, const Pose& pose) {
  return magnitude_bound(pose, p.scale());
}

// The largest coordinate magnitude of vertex y placed at `pose`.
double placed_magnitude(const Vec3& y, const Pose& pose) {
  return pose.apply(y).cwiseAbs().maxCoeff();
}

// The largest coordinate magnitude of the placed vertices themselves: the R
// of the accuracy standard. O(N), so only computed when a distance falls
// between the band of this R and the band of the bound above.
double world_magnitude(const ConvexPolytope& p, const Pose& pose) {
  double r = 0.0;
  for (const Vec3& y : p.vertices()) r = std::max(r, placed_magnitude(y, pose));
  return r;
}

// A lower bound on world_magnitude(p, pose) from a few vertices (ids out of
// range skipped), computed as world_magnitude computes them: a distance
// inside the band of this R is inside the band of the exact R. O(1).
template <std::size_t kCount>
double world_magnitude_floor(const ConvexPolytope& p, const Pose& pose,
                             const std::array<std::int32_t, kCount>& ids) {
  double r = 0.0;
  for (const std::int32_t id : ids) {
    if (id >= 0 && id < p.vertex_count()) r = std::max(r, placed_magnitude(p.vertex(id), pose));
  }
  return r;
}

// The checks of distance()'s options; throws InvalidInput naming the
// option. Out of line: distance_in_frame calls it only when a cheaper
// sufficient test on the bits fails.
[[gnu::noinline]] void check_options(const DistanceOptions& options) {
  // Finite and >= 0, -0.0 included, decided on the bits: a comparison of a
  // NaN raises FE_INVALID, which a caller's trap turns into SIGFPE instead
  // of this refusal (Pose.DistanceOptionsAreCheckedExactly).
  const auto finite_non_negative = [](double x) {
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
    return bits < 0x7ff0000000000000ULL || bits == 0x8000000000000000ULL;
  };
  if (!finite_non_negative(options.relative_tolerance) ||
      !finite_non_negative(options.absolute_tolerance)) {
    throw InvalidInput(
        "distance: options.relative_tolerance and options.absolute_tolerance must be finite and >= "
        "0");
  }
  if (options.max_iterations < 1) {
    throw InvalidInput("distance: options.max_iterations must be at least 1");
  }
}

// max(world_magnitude_bound(a, pose_a), world_magnitude_bound(b, pose_b)),
// the same value (max is exact, and each lane rounds as the scalar does),
// with SSE2 the two bounds in the two lanes of one register. The poses'
// translations are finite (the pose contract).
[[gnu::always_inline]] inline double magnitude_bounds(const ConvexPolytope& a, const Pose& pose_a,
                                                      const ConvexPolytope& b, const Pose& pose_b) {
#if defined(__SSE2__)
  const __m128d no_sign = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
  const auto pair = [no_sign](const double& x, const double& y) {
    return _mm_and_pd(_mm_loadh_pd(_mm_load_sd(&x), &y), no_sign);
  };
  const Vec3& ta = pose_a.translation;
  const Vec3& tb = pose_b.translation;
  const __m128d largest =
      _mm_max_pd(_mm_max_pd(pair(ta[0], tb[0]), pair(ta[1], tb[1])), pair(ta[2], tb[2]));
  const __m128d bounds = _mm_add_pd(
      largest, _mm_mul_pd(_mm_set1_pd(std::sqrt(3.0)), _mm_set_pd(b.scale(), a.scale())));
  return _mm_cvtsd_f64(_mm_max_sd(bounds, _mm_unpackhi_pd(bounds, bounds)));
#else
  return std::max(world_magnitude_bound(a, pose_a), world_magnitude_bound(b, pose_b));
#endif
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

// B's pose in A's frame, pose_a^-1 pose_b, formed directly (the transpose
// is the inverse of a rotation under the pose contract).
//
// With SSE2, two columns at a time: entry i of columns j and j' of
// R_a^T [R_b | d] is ((R_a(0,i) v_0 + R_a(1,i) v_1) + R_a(2,i) v_2) for
// the pair v_k = (column j, column j') entry k, so the columns (0, 1) of R_b
// and (2, d) share the nine broadcast entries of R_a, each multiplied once
// per pair of outputs. The rounding is the scalar product's, term by term.
// Eigen's 3x3 product vectorizes each length-3 dot product with horizontal
// adds instead: 127 instructions per query; the rows of R_a paired in
// lanes, one column at a time: about 90; the columns paired: 11 fewer
// (callgrind, bench/tracked_instructions translation 64).
[[gnu::always_inline]] inline Pose relative_pose(const Pose& pose_a, const Pose& pose_b) {
#if defined(__SSE2__)
  const double* ra = pose_a.rotation.data();  // column-major: R_a(k, i) = ra[3 i + k]
  const double* rb = pose_b.rotation.data();
  const double* ta = pose_a.translation.data();
  const double* tb = pose_b.translation.data();
  // d = t_b - t_a, entries 0 and 1 in a pair, entry 2 alone.
  const __m128d d01 = _mm_sub_pd(_mm_loadu_pd(tb), _mm_loadu_pd(ta));
  const __m128d d2 = _mm_sub_sd(_mm_load_sd(tb + 2), _mm_load_sd(ta + 2));
  // Entry k of columns 0 and 1 of R_b, and of column 2 of R_b and d.
  const __m128d v01[3] = {_mm_loadh_pd(_mm_load_sd(rb + 0), rb + 3),
                          _mm_loadh_pd(_mm_load_sd(rb + 1), rb + 4),
                          _mm_loadh_pd(_mm_load_sd(rb + 2), rb + 5)};
  const __m128d v2d[3] = {_mm_unpacklo_pd(_mm_load_sd(rb + 6), d01), _mm_loadl_pd(d01, rb + 7),
                          _mm_unpacklo_pd(_mm_load_sd(rb + 8), d2)};
  Pose b_in_a;  // written in place (the returned object itself)
  double* out = b_in_a.rotation.data();
  double* out_t = b_in_a.translation.data();
  for (int i = 0; i < 3; ++i) {
    const __m128d c0 = _mm_set1_pd(ra[3 * i]), c1 = _mm_set1_pd(ra[3 * i + 1]),
                  c2 = _mm_set1_pd(ra[3 * i + 2]);
    const __m128d e01 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, v01[0]), _mm_mul_pd(c1, v01[1])),
                                   _mm_mul_pd(c2, v01[2]));
    const __m128d e2d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, v2d[0]), _mm_mul_pd(c1, v2d[1])),
                                   _mm_mul_pd(c2, v2d[2]));
    _mm_storel_pd(out + i, e01);      // (i, 0)
    _mm_storeh_pd(out + 3 + i, e01);  // (i, 1)
    _mm_storel_pd(out + 6 + i, e2d);  // (i, 2)
    _mm_storeh_pd(out_t + i, e2d);    // translation i
  }
  return b_in_a;
#else
  const Vec3 d = pose_b.translation - pose_a.translation;
  return {Mat3(pose_a.rotation.transpose() * pose_b.rotation),
          Vec3(pose_a.rotation.transpose() * d)};
#endif
}

// The result's points and normal from A's frame to the world frame, in
// place: x -> R_a x + t_a and n -> R_a n, rounded as Eigen's product rounds
// them (rows 0 and 1: ((R0 x0 + R1 x1) + R2 x2) + t, with R_k column k;
// row 2: (R_20 x0 + (R_21 x1 + R_22 x2)) + t_2). With SSE2 A's pose is
// loaded once into registers before the first store: the compiler cannot
// know that the result does not alias the caller's pose, and reloaded it
// for every entry written (callgrind, bench/tracked_instructions).
[[gnu::always_inline]] inline void to_world(const Pose& pose_a, DistanceResult& result) {
#if defined(__SSE2__)
  const double* r = pose_a.rotation.data();  // column-major: column k at r + 3 k
  const double* t = pose_a.translation.data();
  const __m128d c0 = _mm_loadu_pd(r), c1 = _mm_loadu_pd(r + 3), c2 = _mm_loadu_pd(r + 6);
  const __m128d t01 = _mm_loadu_pd(t);
  const double r20 = r[2], r21 = r[5], r22 = r[8], t2 = t[2];
  const auto map = [&](Vec3& x, bool translate) {
    const double x0 = x[0], x1 = x[1], x2 = x[2];
    __m128d top =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, _mm_set1_pd(x0)), _mm_mul_pd(c1, _mm_set1_pd(x1))),
                   _mm_mul_pd(c2, _mm_set1_pd(x2)));
    double bottom = r20 * x0 + (r21 * x1 + r22 * x2);
    if (translate) {
      top = _mm_add_pd(top, t01);
      bottom += t2;
    }
    _mm_storeu_pd(x.data(), top);
    x[2] = bottom;
  };
  map(result.point_a, true);
  map(result.point_b, true);
  map(result.normal, false);
#else
  result.point_a = pose_a.apply(result.point_a);
  result.point_b = pose_a.apply(result.point_b);
  result.normal = pose_a.rotation * result.normal;
#endif
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
  // Most contacts (overlapping bodies) end with a distance of a few
  // roundings: inside the band of a lower bound on R taken from the cached
  // features and support hints, where the exact R could not change the
  // answer, and it is not computed.
  const auto band_floor = [&] {
    const std::array ids_a = {c.vertices_a[0], c.vertices_a[1], c.vertices_a[2], c.hint_a};
    const std::array ids_b = {c.vertices_b[0], c.vertices_b[1], c.vertices_b[2], c.hint_b};
    const double r_floor =
        std::max(world_magnitude_floor(a, pose_a, ids_a), world_magnitude_floor(b, pose_b, ids_b));
    return contact_band(r_floor, options.absolute_tolerance);
  };
  // A touching answer above the band of the exact R is re-solved with that
  // band, the algorithm's cross-check and contact classification included,
  // so that whichever stage answers decides with it
  // (StatusBand.VertexJustAboveAFaceIsSeparatedOutsideTheExactBand: the
  // cross-check used the cheap band and turned the refined separated answer
  // back into touching).
  if (result.status == Status::touching && result.distance > 0.0 &&
      result.distance > band_floor()) {
    const double r_exact = std::max(world_magnitude(a, pose_a), world_magnitude(b, pose_b));
    const double exact_band = contact_band(r_exact, options.absolute_tolerance);
    if (exact_band < band_bound && result.distance > exact_band) {
      result = run(a, b, b_in_a, options, exact_band, c);
    }
  }
  // The signed distance: nothing to add when separated (the depth fields
  // stay 0); a contact gets its penetration depth, computed only now, and
  // an uncertified answer its bounds (src/query/signed_distance.cpp).
  if (result.status != Status::separated) [[unlikely]] {
    detail::finish_signed_distance(a, b, b_in_a, options, c, result);
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
// stores went through the stack (about 40 instructions a query, callgrind,
// bench/tracked_instructions).
[[gnu::always_inline]] inline DistanceResult distance_in_frame(
    const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b, const Pose& pose_b,
    const DistanceOptions& options, DistanceCache& c) {
  // Both tolerances finite and >= 0, and at least one iteration: on the
  // bits first (sign clear and exponent below all ones in both, so in their
  // or), the exact test only when that fails (-0.0 is accepted there).
  if (((std::bit_cast<std::uint64_t>(options.relative_tolerance) |
        std::bit_cast<std::uint64_t>(options.absolute_tolerance)) >= 0x7ff0000000000000ULL) ||
      options.max_iterations < 1) [[unlikely]] {
    check_options(options);
  }

  // The contact band 64 u R + Ae, first with a cheap bound on R. A distance
  // found inside that band but above 0 may still be outside the band of the
  // exact R; then the exact R is computed and the query resumed from its own
  // cache with the exact band, so that "separated" means d > 64 u R exactly
  // (finish_query).
  const double r_bound = magnitude_bounds(a, pose_a, b, pose_b);
  if (!(r_bound <= kMaxMagnitude)) [[unlikely]] {
    throw InvalidInput(detail::beyond_magnitude(
        world_magnitude_bound(a, pose_a) >= world_magnitude_bound(b, pose_b) ? "distance: body a"
                                                                              : "distance: body b",
        r_bound, "vertices and pose translation"));
  }
  const Pose b_in_a = relative_pose(pose_a, pose_b);
  const double band_bound = contact_band(r_bound, options.absolute_tolerance);

  // One initialization from either call, not two returns: GCC 12 elides
  // the copy of a named result only when every return names it. A pair
  // whose last depth was not penetrating (one that overlapped once and
  // separated since) takes the common path: the tracked depth would not be
  // tried for it.
  const bool penetrating = detail::overlap_trackable(options, c);
  DistanceResult result =
      penetrating ? penetrating_query(a, pose_a, b, pose_b, b_in_a, options, band_bound, c)
                  : run(a, b, b_in_a, options, band_bound, c);
  if (!penetrating) [[likely]] {
    finish_query(a, pose_a, b, pose_b, b_in_a, options, band_bound, c, result);
  }
  return result;
}

// distance() with a cold cache of its own, out of line: the cache's
// destructor (it may own penetration state, types.h) then needs no cleanup
// in distance() itself, whose tracked path would otherwise pay a frame
// pointer and a spill for it (3 instructions a query, callgrind,
// bench/tracked_instructions).
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

namespace detail {

DistanceResult distance_of_rigid_poses(const ConvexPolytope& a, const Pose& pose_a,
                                       const ConvexPolytope& b, const Pose& pose_b,
                                       const DistanceOptions& options, DistanceCache* cache) {
  // A cold cache is built only when there is no caller's cache, out of line
  // (the scene's, the bodies' and the compounds' tracked queries come here
  // with their own: initializing and destroying an unused cold one cost
  // them about 30 instructions a query).
  if (cache == nullptr) [[unlikely]]
    return distance_of_rigid_poses_cold(a, pose_a, b, pose_b, options);
  return distance_in_frame(a, pose_a, b, pose_b, options, *cache);
}

}  // namespace detail
}  // namespace proxima
