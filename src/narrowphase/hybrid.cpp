// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The paper's hybrid algorithm (sections 4-5), as DESIGN.md reads it.
//
// State: a feature pair (FA, FB), each one to three hull vertices. The local
// method gives the closest points XA in conv(FA) and XB in conv(FB) in closed
// form, with barycentric coefficients; vertices whose coefficient is zero are
// dropped, so the pair is always the minimal one realizing d = |XB - XA|.
//
// With w = XB - XA, the support points a* = argmax_A w.x and
// b* = argmin_B w.y bound the distance from below:
//     lower = (w.b* - w.a*) / |w|   (the slab between the two support planes)
// and d is an upper bound. We stop when d - lower <= Re d (+ rounding), when
// d falls in the contact band, or when no support point can improve the pair
// any more (the answer is at machine precision).
//
// Otherwise one body is updated at a time: its support point joins its
// feature, the local distance is recomputed and the pair reduced. Moving XA
// towards a* decreases |w| at first order whenever w.(a* - XA) > 0, so an
// accepted update strictly decreases d; a pair is never visited twice (the
// paper's recycling) because d only decreases, and a hard cap bounds the loop.
//
// Everything happens in A's frame: B's vertices are mapped on demand, the
// direction is rotated into B's frame for B's support search.
#include "proxima/detail/narrowphase/hybrid.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

#include "core/accuracy.h"
#include "core/power_of_two.h"
#include "narrowphase/hybrid_rules.h"
#include "narrowphase/witness_features.h"
#include "proxima/detail/geometry/tetrahedron_coordinates.h"
#include "proxima/detail/narrowphase/contact.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/shape/support.h"

namespace proxima {
namespace {

// The termination test's rounding slack (core/accuracy.h) is in units of
// u * R: the support values w.a* and w.b* each carry an error of a few u |w| R.
using detail::kMaxUnscaled;
using detail::kMinUnscaled;
using detail::kTerminationGapUlps;
using detail::kWitnessFarBands;
using detail::minus_transpose_times;
using detail::moved_far;

// A squared distance below this has lost digits to subnormal squares (the
// smallest subnormal 2^-1074 is 2^-114 of it): the distance and the normal
// are then taken from point_b - point_a through a power of two
// (length_and_direction). A tetrahedron of 1e-101 touching a hull of 1e58
// is 1e-159 from it in scaled units: the normal v / sqrt(|v|^2) had length
// 1.00002 (DistanceRegression.TinyBodyTouchingHugeOneHasUnitNormal).
constexpr double kSquaresLoseDigits = 0x1p-960;

// The distance and the normal of a result whose squared distance lost
// digits (kSquaresLoseDigits), from its points. Out of line: off the
// tracked queries' path.
[[gnu::noinline]] void tiny_distance_from_points(DistanceResult& result) {
  const detail::LengthAndDirection v = detail::length_and_direction(result.point_b - result.point_a);
  if (!(v.length > 0.0)) return;
  result.distance = v.length;
  result.lower_bound = std::min(result.lower_bound, v.length);
  result.normal = v.direction;
}

// Bodies of at most this many vertices are scanned (support_brute_force)
// in the loop of a query that started cold, whose hints are the supports
// along the line of centres: no better than a scan's start, and the climb's
// walk ends at a different step every time, a mispredicted branch per
// search. Up to 16 vertices the fixed scan beats the climb on cold random
// poses; at 32 the climb is as fast or faster (bench/distance_bench's cold
// queries; the figures are in CHANGELOG.md). A tracked query's hint is its
// answer or next to it: it climbs.
constexpr int kColdLoopScanVertices = 16;

// A support search of the loop: the scan or the climb (above). The scan is
// out of line: inlined here it costs the tracked query instructions, and
// the cold query time, because its compare becomes a branch.
[[gnu::always_inline]] inline int support_point(const ConvexPolytope& p, const Vec3& dir, int hint,
                                                bool scan) {
  if (scan) [[unlikely]]
    return support_brute_force(p.vertices(), dir);
  return support_hill_climb(p, dir, hint);
}

// A feature of one body: up to three hull vertex ids (a fourth slot for the
// support point being added), with their positions in A's frame. The slots
// from n on hold -1, so that the cache takes the ids as they are.
struct FeatureSet {
  std::array<std::int32_t, 4> id = {-1, -1, -1, -1};
  std::array<Vec3, 4> p;
  int n = 0;

  void clear() {
    id = {-1, -1, -1, -1};
    n = 0;
  }
  bool contains(std::int32_t v) const {
    for (int i = 0; i < n; ++i) {
      if (id[static_cast<std::size_t>(i)] == v) return true;
    }
    return false;
  }
  void push(std::int32_t v, const Vec3& x) {
    id[static_cast<std::size_t>(n)] = v;
    p[static_cast<std::size_t>(n)] = x;
    ++n;
  }
  // Undoes the last push.
  void pop() {
    --n;
    id[static_cast<std::size_t>(n)] = -1;
  }
  // Keeps the vertices whose bit is set in `active`, in order.
  void reduce(std::uint8_t active) {
    if (active == (1u << n) - 1u) return;  // all kept: the tracked case
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (active & (1u << i)) {
        id[static_cast<std::size_t>(k)] = id[static_cast<std::size_t>(i)];
        p[static_cast<std::size_t>(k)] = p[static_cast<std::size_t>(i)];
        ++k;
      }
    }
    for (int i = k; i < n; ++i) id[static_cast<std::size_t>(i)] = -1;
    n = k;
  }
};

// The local method's answer: the kernel's own result, used in place (the
// tracked query's one kernel call is not copied into another struct).
using Local = ClosestPoints<double>;

// Closest points of conv(fa) and conv(fb) when one of them has four vertices.
// A fourth vertex only appears on the side that just received its
// support point (index 3): the feature is then a tetrahedron whose closest
// point to the other feature lies on one of the three triangles through the
// new vertex (the old triangle was the previous answer, which the new vertex
// improves on), so the minimum over those three is the answer.
[[gnu::noinline]] Local tetrahedron_distance(const FeatureSet& fa, const FeatureSet& fb,
                                             const KernelTolerance<double>& tol) {
  const bool on_a = fa.n == 4;
  const FeatureSet& four = on_a ? fa : fb;
  const FeatureSet& other = on_a ? fb : fa;
  // The other feature may lie inside the tetrahedron (the bodies overlap):
  // then no triangle is closest and the distance is 0. It suffices to test
  // one of its vertices: if the feature crosses the boundary instead, a
  // triangle below finds the crossing at distance 0.
  if (const auto inside = detail::tetrahedron_coordinates(four.p, other.p[0])) {
    Local hit;
    hit.distance_squared = 0.0;
    hit.point_a = other.p[0];
    hit.point_b = other.p[0];
    std::uint8_t tet_bits = 0;
    for (int i = 0; i < 4; ++i) {
      if ((*inside)[static_cast<std::size_t>(i)] != 0.0)
        tet_bits = static_cast<std::uint8_t>(tet_bits | (1u << i));
    }
    hit.active_a = on_a ? tet_bits : std::uint8_t{1};
    hit.active_b = on_a ? std::uint8_t{1} : tet_bits;
    return hit;
  }
  static constexpr std::array<std::array<int, 3>, 3> kTriangles = {
      {{0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
  Local best{};
  bool have = false;
  for (const auto& tri : kTriangles) {
    const std::array<Vec3, 3> pts = {four.p[static_cast<std::size_t>(tri[0])],
                                     four.p[static_cast<std::size_t>(tri[1])],
                                     four.p[static_cast<std::size_t>(tri[2])]};
    const ClosestPoints<double> c =
        on_a ? closest_points<double>(pts.data(), 3, other.p.data(), other.n, tol)
             : closest_points<double>(other.p.data(), other.n, pts.data(), 3, tol);
    if (have && c.distance_squared >= best.distance_squared) continue;
    const std::uint8_t tri_bits = on_a ? c.active_a : c.active_b;
    std::uint8_t mapped = 0;
    for (int i = 0; i < 3; ++i) {
      if (tri_bits & (1u << i))
        mapped = static_cast<std::uint8_t>(mapped | (1u << tri[static_cast<std::size_t>(i)]));
    }
    best = c;
    if (on_a) {
      best.active_a = mapped;
    } else {
      best.active_b = mapped;
    }
    have = true;
  }
  return best;
}

// Closest points of conv(fa) and conv(fb). Sizes 1..3 (every query's first
// call, and all of a tracked one) go straight to the closed-form kernels,
// whose result is the answer.
inline Local local_distance(const FeatureSet& fa, const FeatureSet& fb,
                            const KernelTolerance<double>& tol) {
  if (fa.n <= 3 && fb.n <= 3) [[likely]]
    return closest_points<double>(fa.p.data(), fa.n, fb.p.data(), fb.n, tol);
  return tetrahedron_distance(fa, fb, tol);
}

// 0 <= id < count, in one comparison (count >= 0).
bool valid_id(std::int32_t id, int count) {
  return static_cast<std::uint32_t>(id) < static_cast<std::uint32_t>(count);
}

// Loads a cached feature (ids range-checked, duplicates dropped). Returns
// false when nothing usable is cached. Written out for the three slots: a
// later id repeats an earlier one only if that one was valid and loaded.
template <class MapPoint>
bool load_feature(const std::array<std::int32_t, 4>& cached, int count, FeatureSet& f,
                  MapPoint map_point) {
  const std::int32_t v0 = cached[0];
  const std::int32_t v1 = cached[1];
  const std::int32_t v2 = cached[2];
  int n = 0;
  if (valid_id(v0, count)) {
    f.id[0] = v0;
    f.p[0] = map_point(v0);
    n = 1;
  }
  if (valid_id(v1, count) && v1 != v0) {
    f.id[static_cast<std::size_t>(n)] = v1;
    f.p[static_cast<std::size_t>(n)] = map_point(v1);
    ++n;
  }
  if (valid_id(v2, count) && v2 != v0 && v2 != v1) {
    f.id[static_cast<std::size_t>(n)] = v2;
    f.p[static_cast<std::size_t>(n)] = map_point(v2);
    ++n;
  }
  f.n = n;
  return n > 0;
}

// The cache's copy of a final feature: its first three ids, -1 where unused
// (FeatureSet keeps unused slots at -1).
void store_feature(const FeatureSet& f, std::array<std::int32_t, 4>& out) {
  out = {f.id[0], f.id[1], f.id[2], -1};
}

// The pair a query starts from: the cached features, unless B moved far
// since (then the pair says nothing: moved_far), or the support points
// along the line of centres (a cold cache fails the first load and skips
// the test of its pose, which a cold query would pay for nothing). Returns
// whether the start was warm.
template <bool kScaled, class APoint, class BPoint>
[[gnu::always_inline]] inline bool start_pair(const ConvexPolytope& a, const ConvexPolytope& b,
                                              const Pose& b_in_a, const DistanceCache& cache,
                                              double scale, const APoint& a_point,
                                              const BPoint& b_point, FeatureSet& fa,
                                              FeatureSet& fb, std::int32_t& hint_a,
                                              std::int32_t& hint_b) {
  const int count_a = a.vertex_count();
  const int count_b = b.vertex_count();
  const bool warm = load_feature(cache.vertices_a, count_a, fa, a_point) &&
                    load_feature(cache.vertices_b, count_b, fb, b_point) &&
                    !moved_far(a, b, b_in_a, cache);
  if (!warm) {
    // Moved far: exactly the cold query (the stale hints are not used).
    // In scaled units too: its dot products with vertices must not overflow.
    const Mat3& rot = b_in_a.rotation;
    Vec3 towards_b = rot * b.centroid() + b_in_a.translation - a.centroid();
    if constexpr (kScaled) towards_b *= scale;
    const Vec3 dir = towards_b.squaredNorm() > 0.0 ? towards_b : Vec3::UnitX();
    hint_a = support_without_hint(a, dir);
    hint_b = support_without_hint(b, minus_transpose_times(rot, dir));
    fa.clear();
    fb.clear();
    fa.push(hint_a, a_point(hint_a));
    fb.push(hint_b, b_point(hint_b));
  }
  return warm;
}

// The support bounds of the loop below, in local units: contact at
// `contact_tolerance`; the margin query's proofs (hybrid_within) at
// `yes_at` and `no_above`; and u R, the unit of the termination slack.
struct LoopLimits {
  double contact_tolerance;
  double yes_at;
  double no_above;
  double ulp_r;
};

// How the loop ended: the certified support gap, the last search direction,
// the iterations, and whether it stopped in contact or at the cap.
struct LoopEnd {
  double lower = 0.0;
  Vec3 last_direction = Vec3::UnitX();
  int iterations = 0;
  bool contact = false;
  bool capped = false;
};

// The paper's loop (DESIGN.md steps 2-3): from the pair (fa, fb) and its
// local answer `loc`, the support points along the closest points'
// direction give the certified lower bound (van den Bergen's test), and the
// body whose support point is further out joins its feature first, kept
// only when the local distance strictly decreases; it ends in contact, at
// the termination test, at the cap, or when neither body improves (the
// pair is optimal at machine precision).
//
// kResume: when `resume_direction` is given, the first pass takes it as its
// search direction and the hints as the supports along it (what a declined
// certified tracked pair computed, certified_pair.h), instead of computing
// them again.
template <bool kMargin, bool kResume = false, class APoint, class BPoint>
[[gnu::always_inline]] inline LoopEnd iterate(const ConvexPolytope& a, const ConvexPolytope& b,
                                              const Mat3& rot, const DistanceOptions& options,
                                              const KernelTolerance<double>& tol,
                                              const LoopLimits& limits, bool scan_a, bool scan_b,
                                              const APoint& a_point, const BPoint& b_point,
                                              FeatureSet& fa, FeatureSet& fb, Local& loc,
                                              std::int32_t& hint_a, std::int32_t& hint_b,
                                              const Vec3* resume_direction = nullptr) {
  LoopEnd e;
  for (;;) {
    const double d = std::sqrt(loc.distance_squared);
    if constexpr (kMargin) {
      if (d <= limits.yes_at) break;
    }
    if (d <= limits.contact_tolerance) {
      e.contact = true;
      break;
    }
    const bool resumed = kResume && resume_direction != nullptr;
    const Vec3 w = resumed ? *resume_direction
                           : detail::search_direction(fa.p.data(), fa.n, fb.p.data(), fb.n,
                                                      loc.point_b - loc.point_a,
                                                      d);  // unit, from A towards B
    e.last_direction = w;
    if (resumed) {
      resume_direction = nullptr;
    } else {
      hint_a = support_point(a, w, hint_a, scan_a);
      hint_b = support_point(b, minus_transpose_times(rot, w), hint_b, scan_b);
    }
    const Vec3 pa = a_point(hint_a);
    const Vec3 pb = b_point(hint_b);
    const double wa = w.dot(pa);
    const double wb = w.dot(pb);
    e.lower = std::max(e.lower, wb - wa);
    if constexpr (kMargin) {
      if (e.lower > limits.no_above) break;
    }
    // The margin query converges only to machine precision: a gap within
    // Re d proves nothing about the margin.
    if (d - e.lower <= (kMargin ? 0.0 : options.relative_tolerance * d) + kTerminationGapUlps * limits.ulp_r) break;
    if (e.iterations >= options.max_iterations) {
      e.capped = true;
      break;
    }
    ++e.iterations;

    // Try the body whose support point is further out first, then the other.
    const double gain_a = fa.contains(hint_a) ? 0.0 : wa - w.dot(loc.point_a);
    const double gain_b = fb.contains(hint_b) ? 0.0 : w.dot(loc.point_b) - wb;
    bool improved = false;
    for (int attempt = 0; attempt < 2 && !improved; ++attempt) {
      const bool use_a = (attempt == 0) == (gain_a >= gain_b);
      if ((use_a ? gain_a : gain_b) <= 0.0) continue;
      // The support point joins its feature in place, and leaves it again
      // if the pair does not improve (no copies of the feature sets).
      FeatureSet& grown = use_a ? fa : fb;
      grown.push(use_a ? hint_a : hint_b, use_a ? pa : pb);
      const Local next = local_distance(fa, fb, tol);
      if (!(next.distance_squared < loc.distance_squared)) {
        grown.pop();
        continue;  // unstable: no progress at this precision
      }
      fa.reduce(next.active_a);
      fb.reduce(next.active_b);
      loc = next;
      improved = true;
    }
    if (!improved) break;  // the pair is optimal at machine precision
  }
  return e;
}

// The algorithm on coordinates multiplied by `scale`, a power of two, when
// kScaled (see hybrid_distance); `band` and `magnitude` (R in A's frame) are
// in the caller's units, like the result returned. The unscaled instance is
// the hot path and multiplies by nothing.
//
// kMargin: the margin query (hybrid_within): the loop stops at the first
// proof about `margin` instead of converging (see hybrid_within), and the
// answer skips what only a distance answer needs (contact classification,
// witness features, cross-check).
//
// kFromPair: the loop goes on from `*start`, the pair a declined certified
// tracked pair evaluated (certified_pair.h), unscaled: its reduced pair,
// closed-form answer and supports replace the cache's pair, the local
// method's first call and the hints.
template <bool kScaled, bool kMargin = false, bool kFromPair = false>
[[gnu::always_inline]] inline DistanceResult run_hybrid(
    const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
    const DistanceOptions& options, double band, DistanceCache& cache, double magnitude,
    double scale, double margin = 0.0, const detail::TrackedPairStart* start = nullptr) {
  static_assert(!(kFromPair && (kScaled || kMargin)), "the pair is evaluated unscaled");
  const double contact_tolerance = kScaled ? band * scale : band;
  const double r_local = kScaled ? magnitude * scale : magnitude;
  const Mat3& rot = b_in_a.rotation;
  const Vec3& tr = b_in_a.translation;
  const auto b_point = [&](std::int32_t v) -> Vec3 {
    if constexpr (kScaled) {
      return (rot * b.vertex(v) + tr) * scale;
    } else {
      return rot * b.vertex(v) + tr;
    }
  };
  const auto a_point = [&](std::int32_t v) -> Vec3 {
    if constexpr (kScaled) {
      return a.vertex(v) * scale;
    } else {
      return a.vertex(v);
    }
  };
  const double ulp_r = kUnitRoundoff * r_local;
  // The margin query's two proofs (hybrid_within), in local units: a
  // witness pair at most margin + band apart, or a support gap above the
  // margin by more than its rounding.
  const double yes_at = kScaled ? (margin + band) * scale : margin + band;
  const double no_above = (kScaled ? margin * scale : margin) + kTerminationGapUlps * ulp_r;
  // Features shorter or flatter than a few u R are reduced (closest_point.h).
  const KernelTolerance<double> tol = kernel_tolerance(r_local);

  const int count_a = a.vertex_count();
  const int count_b = b.vertex_count();
  std::int32_t hint_a = valid_id(cache.hint_a, count_a) ? cache.hint_a : 0;
  std::int32_t hint_b = valid_id(cache.hint_b, count_b) ? cache.hint_b : 0;

  FeatureSet fa;
  FeatureSet fb;
  if constexpr (kFromPair) {
    for (int i = 0; i < start->n_a; ++i)
      fa.push(start->id_a[static_cast<std::size_t>(i)], start->p_a[static_cast<std::size_t>(i)]);
    for (int j = 0; j < start->n_b; ++j)
      fb.push(start->id_b[static_cast<std::size_t>(j)], start->p_b[static_cast<std::size_t>(j)]);
    hint_a = start->support_a;
    hint_b = start->support_b;
  }
  const bool warm = kFromPair || start_pair<kScaled>(a, b, b_in_a, cache, scale, a_point, b_point,
                                                     fa, fb, hint_a, hint_b);

  // After a cold start small bodies are scanned (kColdLoopScanVertices).
  const bool scan_a = !warm && count_a <= kColdLoopScanVertices;
  const bool scan_b = !warm && count_b <= kColdLoopScanVertices;
  Local loc = [&]() -> Local {
    if constexpr (kFromPair) {
      Local from_pair;
      from_pair.distance_squared = start->distance_squared;
      from_pair.point_a = start->point_a;
      from_pair.point_b = start->point_b;
      return from_pair;
    } else {
      return local_distance(fa, fb, tol);
    }
  }();
  if constexpr (!kFromPair) {
    fa.reduce(loc.active_a);
    fb.reduce(loc.active_b);
  }

  DistanceResult result;
  const LoopEnd end = iterate<kMargin, kFromPair>(
      a, b, rot, options, tol, LoopLimits{contact_tolerance, yes_at, no_above, ulp_r}, scan_a,
      scan_b, a_point, b_point, fa, fb, loc, hint_a, hint_b,
      kFromPair && start->has_direction ? &start->direction : nullptr);
  const double lower = end.lower;
  const Vec3& last_direction = end.last_direction;
  const int iterations = end.iterations;
  const bool contact = end.contact;
  if (end.capped) result.status = Status::iteration_cap;

  const double d = std::sqrt(loc.distance_squared);
  result.iterations = iterations;
  result.point_a = loc.point_a;
  result.point_b = loc.point_b;
  result.distance = d;
  result.lower_bound = std::min(std::max(lower, 0.0), d);
  result.normal = d > 0.0 ? Vec3((loc.point_b - loc.point_a) / d) : last_direction;
  if (loc.distance_squared < kSquaresLoseDigits) [[unlikely]]
    tiny_distance_from_points(result);
  if (contact) {
    // In contact at machine precision. Whether the bodies only touch or
    // overlap is decided by the contact unit (hybrid_distance, contact.h).
    result.status = Status::touching;
    result.lower_bound = 0.0;
  } else if (result.status != Status::iteration_cap) {
    result.status = Status::separated;
  }
  const double unit = kScaled ? 1.0 / scale : 1.0;  // exact: a power of two
  store_feature(fa, cache.vertices_a);
  store_feature(fb, cache.vertices_b);
  cache.hint_a = hint_a;
  cache.hint_b = hint_b;
  cache.rotation = rot;
  cache.translation = tr;
  if constexpr (kScaled) {
    result.point_a *= unit;
    result.point_b *= unit;
    result.distance *= unit;
    result.lower_bound *= unit;
  }
  if constexpr (kMargin) {
    // The support gap with its rounding slack taken off: certified. The
    // faces of the last distance answer no longer describe the cached pair.
    result.lower_bound = std::max(0.0, (lower - kTerminationGapUlps * ulp_r) * unit);
    cache.face_a = -1;
    cache.face_b = -1;
    return result;
  }
  // The hybrid reports contact without telling touching from overlapping:
  // the contact unit (proxima/detail/narrowphase/contact.h) decides, in the caller's units,
  // before the witness features, which an intersecting answer reports
  // without rule 3's walk (witness_features.h).
  if (result.status == Status::touching)
    classify_contact(a, b, b_in_a, options, band, cache, result);
  const bool locate = result.status != Status::intersecting;

  // The witness features by the rule all algorithms share
  // (witness_features.h), in each hull's own frame and units.
  detail::witness_pair<kScaled>(a, b, b_in_a, fa, fb, loc, r_local, unit, locate, cache, result);

  // An answer the hybrid could not certify is cross-checked (contact.h).
  if (needs_cross_check(result, options, magnitude)) [[unlikely]]
    cross_check_separation(a, b, b_in_a, options, band, result);
  return result;
}

// The hybrid on coordinates times the power of two that brings R in A's
// frame near 1 (outside 2^-64..2^64 squares would overflow or underflow).
DistanceResult run_scaled(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                          const DistanceOptions& options, double contact_tolerance,
                          DistanceCache& cache, double r_local) {
  const double scale = detail::power_of_two_unit(r_local).inverse;
  return run_hybrid<true>(a, b, b_in_a, options, contact_tolerance, cache, r_local, scale);
}

}  // namespace

DistanceResult hybrid_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                               const DistanceOptions& options, double contact_tolerance,
                               DistanceCache& cache) {
  // R in A's frame, B's coordinates bounded without mapping its vertices.
  const double r_local = std::max(a.scale(), magnitude_bound(b_in_a, b.scale()));
  if ((r_local >= kMinUnscaled && r_local <= kMaxUnscaled) || !(r_local > 0.0) ||
      !std::isfinite(r_local)) [[likely]] {
    return run_hybrid<false>(a, b, b_in_a, options, contact_tolerance, cache, r_local, 1.0);
  }
  return run_scaled(a, b, b_in_a, options, contact_tolerance, cache, r_local);
}

DistanceResult hybrid_distance_from_pair(const ConvexPolytope& a, const ConvexPolytope& b,
                                         const Pose& b_in_a, const DistanceOptions& options,
                                         double contact_tolerance, DistanceCache& cache,
                                         const detail::TrackedPairStart& start) {
  const double r_local = std::max(a.scale(), magnitude_bound(b_in_a, b.scale()));
  return run_hybrid<false, false, true>(a, b, b_in_a, options, contact_tolerance, cache, r_local,
                                        1.0, 0.0, &start);
}

DistanceResult hybrid_within(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                             const DistanceOptions& options, double contact_tolerance,
                             double margin, DistanceCache& cache) {
  const double r_local = std::max(a.scale(), magnitude_bound(b_in_a, b.scale()));
  if ((r_local >= kMinUnscaled && r_local <= kMaxUnscaled) || !(r_local > 0.0) ||
      !std::isfinite(r_local)) [[likely]] {
    return run_hybrid<false, true>(a, b, b_in_a, options, contact_tolerance, cache, r_local, 1.0,
                                   margin);
  }
  const double scale = detail::power_of_two_unit(r_local).inverse;
  return run_hybrid<true, true>(a, b, b_in_a, options, contact_tolerance, cache, r_local, scale,
                                margin);
}

}  // namespace proxima
