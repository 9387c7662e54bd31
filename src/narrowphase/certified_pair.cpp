// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The tracked query's certified pair (certified_pair.h): the hybrid's first
// pass from the cached pair, on plain stack data, with nothing of the
// loop's machinery (feature sets, recycling, the staleness test, the loop's
// end state). What it computes, in A's frame:
//   1. B's cached vertices placed by b_in_a (R y + t), A's taken as stored;
//   2. the closed-form closest points XA, XB of the pair (closest_point.h),
//      the pair reduced to its active vertices, d = |XB - XA|;
//   3. the search direction w of the reduced pair (hybrid_rules.h: the face
//      normal, the edges' cross product, or (XB - XA) / d);
//   4. a* = argmax_A w.x and b* = argmin_B w.y by hill climbing from the
//      cached hints: on a convex polytope a vertex none of whose neighbours
//      is higher is the global support (support.h), so a tracked hint that
//      is still the support costs one look at its neighbours;
//   5. the slab between the two support planes: no point of A is beyond
//      w.a*, none of B before w.b*, so |y - x| >= w.(y - x) >= w.b* - w.a*
//      for all x in A, y in B (w unit): the lower bound, certified once its
//      rounding is taken off (kCertifiedGapUlps u R, certified_pair.h);
//   6. the hybrid's termination test on d and that gap. Passed, the
//      hybrid's loop would stop at this same first pass with this same pair,
//      so the answer is the loop's (the same kernel, direction and supports:
//      the same bits, but for the lower bound's slack); failed, the loop
//      goes on from this pair (TrackedPairStart), the cache untouched.
#include "proxima/detail/narrowphase/certified_pair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>

#include "core/accuracy.h"
#include "narrowphase/hybrid_rules.h"
#include "narrowphase/witness_features.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/shape/support.h"

namespace proxima::detail {
namespace {

// A cached feature as the hybrid stores it (hybrid.cpp, store_feature): one
// to three distinct valid ids in the first slots, -1 after them. Anything
// else (a cold cache, GJK's simplex, another pair's ids) is declined: the
// loop's own loader handles it.
struct CachedFeature {
  std::array<std::int32_t, 3> id;
  std::array<Vec3, 3> p;
  int n = 0;
};

[[gnu::always_inline]] inline bool valid_id(std::int32_t id, int count) {
  return static_cast<std::uint32_t>(id) < static_cast<std::uint32_t>(count);
}

[[gnu::always_inline]] inline int cached_count(const std::array<std::int32_t, 4>& c, int count) {
  if (!valid_id(c[0], count)) return 0;
  if (c[1] < 0) return 1;
  if (!valid_id(c[1], count) || c[1] == c[0]) return 0;
  if (c[2] < 0) return 2;
  if (!valid_id(c[2], count) || c[2] == c[0] || c[2] == c[1]) return 0;
  return 3;
}

// Keeps the vertices whose bit is set in `active`, in order (the kernel's
// minimal feature, as the hybrid's FeatureSet::reduce keeps them).
[[gnu::always_inline]] inline void reduce(CachedFeature& f, std::uint8_t active) {
  if (active == (1u << f.n) - 1u) return;  // all kept: the tracked case
  int k = 0;
  for (int i = 0; i < f.n; ++i) {
    if (active & (1u << i)) {
      f.id[static_cast<std::size_t>(k)] = f.id[static_cast<std::size_t>(i)];
      f.p[static_cast<std::size_t>(k)] = f.p[static_cast<std::size_t>(i)];
      ++k;
    }
  }
  f.n = k;
}

// The cache's copy of a feature: -1 after its vertices.
[[gnu::always_inline]] inline std::array<std::int32_t, 4> stored(const CachedFeature& f) {
  return {f.id[0], f.n > 1 ? f.id[1] : -1, f.n > 2 ? f.id[2] : -1, -1};
}

}  // namespace

bool certified_tracked_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                const Pose& b_in_a, const DistanceOptions& options,
                                double contact_tolerance, DistanceCache& cache,
                                DistanceResult& result, TrackedPairStart& start) {
  if (options.algorithm != Algorithm::hybrid || options.extended_precision) return false;
  const int count_a = a.vertex_count();
  const int count_b = b.vertex_count();
  CachedFeature fa;
  CachedFeature fb;
  fa.n = cached_count(cache.vertices_a, count_a);
  fb.n = cached_count(cache.vertices_b, count_b);
  if (fa.n == 0 || fb.n == 0) return false;
  // R in A's frame, as the hybrid bounds it; outside the unscaled range the
  // loop works on scaled coordinates (hybrid_rules.h).
  const double r_local = std::max(a.scale(), magnitude_bound(b_in_a, b.scale()));
  if (!(r_local >= kMinUnscaled && r_local <= kMaxUnscaled)) return false;

  const Mat3& rot = b_in_a.rotation;
  const Vec3& tr = b_in_a.translation;
  for (int i = 0; i < fa.n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    fa.id[k] = cache.vertices_a[k];
    fa.p[k] = a.vertex(fa.id[k]);
  }
  for (int j = 0; j < fb.n; ++j) {
    const auto k = static_cast<std::size_t>(j);
    fb.id[k] = cache.vertices_b[k];
    fb.p[k] = rot * b.vertex(fb.id[k]) + tr;
  }
  const ClosestPoints<double> loc =
      closest_points<double>(fa.p.data(), fa.n, fb.p.data(), fb.n, kernel_tolerance(r_local));
  const double d = std::sqrt(loc.distance_squared);
  reduce(fa, loc.active_a);
  reduce(fb, loc.active_b);
  std::int32_t sa = valid_id(cache.hint_a, count_a) ? cache.hint_a : 0;
  std::int32_t sb = valid_id(cache.hint_b, count_b) ? cache.hint_b : 0;
  // Declined after the pair's evaluation: the loop goes on from it, unless
  // B moved so far that the loop's cold start is the better one.
  Vec3 w = Vec3::UnitX();
  bool has_direction = false;
  const auto decline = [&] {
    if (!moved_far(a, b, b_in_a, cache))
      start = {fa.id,       fb.id,       fa.p, fb.p, fa.n, fb.n,          loc.distance_squared,
               loc.point_a, loc.point_b, w,    sa,   sb,   has_direction, true};
    return false;
  };

  // Near touching the query refines the answer (query/distance.cpp): the
  // loop answers there. Above these bands d^2 is far from subnormal.
  if (!(d > kExtendedBands * contact_tolerance)) return decline();

  w = search_direction(fa.p.data(), fa.n, fb.p.data(), fb.n, loc.point_b - loc.point_a, d);
  sa = support_hill_climb(a, w, sa);
  sb = support_hill_climb(b, minus_transpose_times(rot, w), sb);
  has_direction = true;
  const double gap = w.dot(rot * b.vertex(sb) + tr) - w.dot(a.vertex(sa));
  // The hybrid's termination test (hybrid.cpp, iterate), the same bits.
  const double ulp_r = kUnitRoundoff * r_local;
  if (!(d - gap <= options.relative_tolerance * d + kTerminationGapUlps * ulp_r)) return decline();

  result.distance = d;
  result.lower_bound = std::min(std::max(gap - kCertifiedGapUlps * ulp_r, 0.0), d);
  result.point_a = loc.point_a;
  result.point_b = loc.point_b;
  result.normal = (loc.point_b - loc.point_a) / d;

  // The witness features by the hybrid's own rule, on unscaled coordinates.
  witness_pair<false>(a, b, b_in_a, fa, fb, loc, r_local, 1.0, true, cache, result);

  cache.vertices_a = stored(fa);
  cache.vertices_b = stored(fb);
  cache.hint_a = sa;
  cache.hint_b = sb;
  cache.rotation = rot;
  cache.translation = tr;
  return true;
}

}  // namespace proxima::detail
