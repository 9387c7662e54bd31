// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// An answer's distance recomputed in double-double (query/extended_distance.h).
//
// Double-double. A value is an unevaluated sum hi + lo with |lo| <= ulp(hi)
// / 2. Sums and products of doubles are exact as such pairs (Knuth's
// two-sum; the fused multiply-add gives a product's rounding error), and
// the pair operations below (Dekker 1971; the accurate forms of Bailey's
// QD library) each round relative to about 2^-104 of their result. The placed coordinates R y + t (three products and a sum) are
// then within a few 2^-104 of their magnitude R of the exact ones, where
// in double they are within u R; the closed forms below take a few dozen
// such operations, so the recomputed distance is within about 2^-96 R of
// the exact distance of the features' affine hulls, and the certified
// gap likewise: a distance of 1e-9 R has 1e7 times the relative accuracy
// of one computed in double, and the status against 64 u R follows the
// exact distance, not its rounding.
//
// Certificate. For any direction n, no pair x in A, y in B is closer than
// (min over B of n.y - max over A of n.x) / |n|. Along the feature pair's
// own normal (a face's, the edges' cross product, or the perpendicular of
// a vertex to an edge) and with the true supports, that gap equals the
// pair's distance exactly when the pair realizes the bodies' distance; so
// the recomputed distance is taken only when the gap, computed in
// double-double, agrees with it (kAgreeUlps): a wrong feature pair is
// refused, never reported.
#include "query/extended_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/power_of_two.h"
#include "proxima/shape/support.h"

namespace proxima::detail {
namespace {

struct Dd {
  double hi = 0.0;
  double lo = 0.0;
};

// s + e == a + b exactly, s = fl(a + b).
Dd two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
// |b| <= |a| (or a == 0).
Dd fast_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}
Dd two_prod(double a, double b) {
  const double p = a * b;
  return {p, std::fma(a, b, -p)};
}
Dd operator+(Dd x, Dd y) {
  const Dd s = two_sum(x.hi, y.hi);
  const Dd t = two_sum(x.lo, y.lo);
  Dd r = fast_two_sum(s.hi, s.lo + t.hi);
  return fast_two_sum(r.hi, r.lo + t.lo);
}
Dd operator-(Dd x) { return {-x.hi, -x.lo}; }
Dd operator-(Dd x, Dd y) { return x + (-y); }
Dd operator*(Dd x, Dd y) {
  const Dd p = two_prod(x.hi, y.hi);
  return fast_two_sum(p.hi, p.lo + (x.hi * y.lo + x.lo * y.hi));
}
Dd operator/(Dd x, Dd y) {
  const double q1 = x.hi / y.hi;
  const Dd r = x - y * Dd{q1, 0.0};
  const double q2 = r.hi / y.hi;
  const Dd r2 = r - y * Dd{q2, 0.0};
  const double q3 = r2.hi / y.hi;
  const Dd q = fast_two_sum(q1, q2);
  return q + Dd{q3, 0.0};
}
Dd sqrt(Dd x) {
  if (!(x.hi > 0.0)) return {};
  const double s = std::sqrt(x.hi);
  // One Newton step: s + (x - s^2) / (2 s).
  const Dd e = x - two_prod(s, s);
  return fast_two_sum(s, e.hi / (2.0 * s));
}
Dd abs(Dd x) { return x.hi < 0.0 || (x.hi == 0.0 && x.lo < 0.0) ? -x : x; }
bool negative(Dd x) { return x.hi < 0.0 || (x.hi == 0.0 && x.lo < 0.0); }
bool less(Dd x, Dd y) { return x.hi < y.hi || (x.hi == y.hi && x.lo < y.lo); }

using DdVec = std::array<Dd, 3>;
DdVec operator-(const DdVec& v, const DdVec& w) { return {v[0] - w[0], v[1] - w[1], v[2] - w[2]}; }
DdVec scaled(const DdVec& v, Dd s) { return {v[0] * s, v[1] * s, v[2] * s}; }
Dd dot(const DdVec& v, const DdVec& w) { return v[0] * w[0] + v[1] * w[1] + v[2] * w[2]; }
DdVec cross(const DdVec& v, const DdVec& w) {
  return {v[1] * w[2] - v[2] * w[1], v[2] * w[0] - v[0] * w[2], v[0] * w[1] - v[1] * w[0]};
}

// (R y + t) s of the pose, s a power of two that brings the coordinates
// near 1 (exact: the products and squares below neither overflow nor
// underflow at any scale), each coordinate to a few 2^-104 of the largest
// term.
DdVec placed(const Pose& pose, const Vec3& y, double s) {
  DdVec out;
  for (int i = 0; i < 3; ++i) {
    Dd sum{pose.translation[i] * s, 0.0};
    for (int j = 0; j < 3; ++j) sum = sum + two_prod(pose.rotation(i, j), y[j] * s);
    out[static_cast<std::size_t>(i)] = sum;
  }
  return out;
}

// A feature's vertices placed in the world frame: 1..3 of them.
struct PlacedFeature {
  std::array<DdVec, 3> p;
  int n = 0;
};
PlacedFeature place(const ConvexPolytope& poly, const Pose& pose, const Feature& f, double s) {
  PlacedFeature out;
  for (const std::int32_t v : f.vertices) {
    if (v < 0 || v >= poly.vertex_count()) break;
    out.p[static_cast<std::size_t>(out.n++)] = placed(pose, poly.vertex(v), s);
  }
  return out;
}

// The distance of the features' affine hulls and a normal along which it
// is realized (unnormalized, from A towards B).
struct PairDistance {
  Dd distance;
  DdVec normal;
};

// Point x to the line through q0 along e: the perpendicular from the line
// to x, and its length. False for an edge of length 0 in these units.
bool point_line(const DdVec& x, const DdVec& q0, const DdVec& e, bool x_on_b, PairDistance& out) {
  const Dd ee = dot(e, e);
  if (!(ee.hi > 0.0)) return false;
  const DdVec w = x - q0;
  const DdVec perp = w - scaled(e, dot(w, e) / ee);
  out = {sqrt(dot(perp, perp)), x_on_b ? perp : DdVec{-perp[0], -perp[1], -perp[2]}};
  return true;
}

// The least distance of the points `xs` (one side) to the plane of the
// triangle t (the other side); `xs_on_b` tells which side is B. False for
// a triangle without a normal in these units.
bool points_plane(const PlacedFeature& xs, const PlacedFeature& t, bool xs_on_b, PairDistance& out) {
  const DdVec normal = cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
  const Dd length = sqrt(dot(normal, normal));
  if (!(length.hi > 0.0)) return false;
  Dd best_s;
  for (int k = 0; k < xs.n; ++k) {
    const Dd s = dot(xs.p[static_cast<std::size_t>(k)] - t.p[0], normal);
    if (k == 0 || less(abs(s), abs(best_s))) best_s = s;
  }
  // Along the normal from A's side to B's.
  const bool flip = negative(best_s) == xs_on_b;
  out = {abs(best_s) / length, flip ? DdVec{-normal[0], -normal[1], -normal[2]} : normal};
  return true;
}

// Edges whose cross product is below this share of their lengths' product
// (as squares) are taken as parallel: their lines' distance is then the
// distance of one end to the other line (point_line), and the cross
// product, of a few roundings, would give no direction.
constexpr double kParallelSquared = 0x1p-60;

bool pair_distance(const PlacedFeature& fa, const PlacedFeature& fb, PairDistance& out) {
  if (fa.n == 0 || fb.n == 0) return false;
  if (fa.n == 3) return points_plane(fb, fa, true, out);
  if (fb.n == 3) return points_plane(fa, fb, false, out);
  if (fa.n == 1 && fb.n == 1) {
    const DdVec v = fb.p[0] - fa.p[0];
    out = {sqrt(dot(v, v)), v};
    return true;
  }
  if (fa.n == 1) return point_line(fa.p[0], fb.p[0], fb.p[1] - fb.p[0], false, out);
  if (fb.n == 1) return point_line(fb.p[0], fa.p[0], fa.p[1] - fa.p[0], true, out);
  const DdVec ea = fa.p[1] - fa.p[0], eb = fb.p[1] - fb.p[0];
  const DdVec c = cross(ea, eb);
  const Dd cc = dot(c, c);
  if (!(cc.hi > kParallelSquared * (dot(ea, ea).hi * dot(eb, eb).hi)))
    return point_line(fb.p[0], fa.p[0], ea, true, out);
  const Dd s = dot(fb.p[0] - fa.p[0], c);
  out = {abs(s) / sqrt(cc), negative(s) ? DdVec{-c[0], -c[1], -c[2]} : c};
  return true;
}

// A vertex whose double support value along a direction is within this
// many u of the body's scale of the best one's may be the exact support:
// the double values are within about 14 u of the scale of the exact ones
// along the double-double direction (the direction's rounding to double
// and its rotation into the body's frame, 4 u each, and the dot product's
// own, times |y| <= sqrt(3) scale), twice that bounds the gap between the
// exact maximizer's double value and the best double value.
constexpr double kTieUlps = 64.0;

// The largest value of n.x over the body placed at `pose` (sign +1), or
// the least (sign -1), in double-double: the double support along n in
// the body's frame, then every vertex tied with it (connected through
// vertices within the tie, as in the penetration depth's refinement: the
// exact maximizer is among them by support_hill_climb_through_plateaus'
// argument), evaluated in double-double.
Dd extreme(const ConvexPolytope& poly, const Pose& pose, double s, const DdVec& n, double sign,
           int hint, std::vector<int>& ids) {
  const Vec3 world(n[0].hi, n[1].hi, n[2].hi);
  const Vec3 local = pose.rotation.transpose() * (sign * world);
  const int top = support_hill_climb_through_plateaus(poly, local, hint);
  const double tie = kTieUlps * kUnitRoundoff * poly.scale() * local.norm();
  const double top_value = local.dot(poly.vertex(top));
  ids.assign(1, top);
  for (std::size_t head = 0; head < ids.size(); ++head)
    for (const std::int32_t w : poly.neighbors(ids[head]))
      if (std::find(ids.begin(), ids.end(), w) == ids.end() &&
          local.dot(poly.vertex(w)) >= top_value - tie)
        ids.push_back(w);
  Dd best;
  bool have = false;
  for (const int i : ids) {
    const Dd value = dot(n, placed(pose, poly.vertex(i), s));
    if (!have || (sign > 0 ? less(best, value) : less(value, best))) best = value;
    have = true;
  }
  return best;
}

// The recomputed distance and the certified gap agree within this many
// 2^-104 of the coordinates' magnitude (the closed forms and the gap's
// sums, a few dozen double-double operations each): the feature pair
// realizes the distance.
constexpr double kAgreeUlps = 4096.0;

// The double nearest to x, and the largest double not above it.
double nearest(Dd x) { return x.hi + x.lo; }
double round_down(Dd x) { return x.lo < 0.0 ? std::nextafter(x.hi, -HUGE_VAL) : x.hi; }
// The smallest double not below x.
double round_up(Dd x) { return x.lo > 0.0 ? std::nextafter(x.hi, HUGE_VAL) : x.hi; }

// The power-of-two unit of the two bodies placed at their poses: a bound
// on their world coordinates (magnitude_bound's terms), brought near 1.
double placed_bound(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                    const Pose& pose_b) {
  return std::max(pose_a.translation.cwiseAbs().maxCoeff() + std::sqrt(3.0) * a.scale(),
                  pose_b.translation.cwiseAbs().maxCoeff() + std::sqrt(3.0) * b.scale());
}

}  // namespace

ExtendedOutcome refine_distance_extended(const ConvexPolytope& a, const Pose& pose_a,
                                         const ConvexPolytope& b, const Pose& pose_b,
                                         DistanceResult& result, Vec3& normal,
                                         bool certify_lower_bound) {
  const double magnitude = placed_bound(a, pose_a, b, pose_b);
  if (!(magnitude > 0.0)) return ExtendedOutcome::unchanged;
  const detail::PowerOfTwoUnit unit = detail::power_of_two_unit(magnitude);
  const double s = unit.inverse;
  const PlacedFeature fa = place(a, pose_a, result.feature_a, s);
  const PlacedFeature fb = place(b, pose_b, result.feature_b, s);
  PairDistance pair;
  if (!pair_distance(fa, fb, pair)) return ExtendedOutcome::unchanged;
  const Dd length = sqrt(dot(pair.normal, pair.normal));
  // A pair at distance 0 (or below any direction's rounding) certifies
  // nothing beyond the answer it came with.
  if (!(length.hi > 0.0)) return ExtendedOutcome::unchanged;
  std::vector<int> ids;
  const int hint_a = std::max<std::int32_t>(result.feature_a.vertices[0], 0);
  const int hint_b = std::max<std::int32_t>(result.feature_b.vertices[0], 0);
  const Dd top_a = extreme(a, pose_a, s, pair.normal, 1.0, hint_a, ids);
  const Dd bottom_b = extreme(b, pose_b, s, pair.normal, -1.0, hint_b, ids);
  const Dd gap = (bottom_b - top_a) / length;
  // In units of s: the coordinates are below 2.
  const double agree = kAgreeUlps * 0x1p-104 * 2.0;
  // The pair's unit normal (world frame, from A towards B), along which
  // the gap is certified.
  const Vec3 n(nearest(pair.normal[0] / length), nearest(pair.normal[1] / length),
               nearest(pair.normal[2] / length));
  normal = n / n.norm();
  // The gap is a lower bound whatever the pair; it must meet the pair's
  // distance for that distance to be the bodies'.
  if (!(std::abs(nearest(pair.distance - gap)) <= agree)) {
    // Not the pair that realizes the distance (or not within this
    // precision: the four vertices of a face rounded off its plane). The
    // gap less its rounding bound is still a lower bound, certified where
    // the one in double is up to rounding.
    const double certified =
        std::clamp(round_down(gap - Dd{agree, 0.0}) * unit.unit, 0.0, result.distance);
    if (certify_lower_bound && result.lower_bound > 0.0) {
      result.lower_bound = std::min(certified, result.lower_bound);
      return ExtendedOutcome::unchanged;
    }
    // A contact answer's lower bound 0 (the algorithm stopped at the band
    // without a support gap) takes a positive certified one.
    if (result.lower_bound == 0.0 && certified > 0.0) {
      result.lower_bound = certified;
      return ExtendedOutcome::lower_bound_only;
    }
    return ExtendedOutcome::unchanged;
  }
  const Dd distance = less(pair.distance, gap) ? gap : pair.distance;
  result.distance = nearest(distance) * unit.unit;
  // The gap less its own rounding bound: a contact at exactly 0 must not
  // come out with a positive lower bound, a gap it does not have (a rounded
  // body trusts the normal of a core answer with a positive lower bound,
  // BodyOracle.TouchingCoresTakeTheNormalOfTheirContact).
  result.lower_bound =
      std::clamp(round_down(gap - Dd{agree, 0.0}) * unit.unit, 0.0, result.distance);
  return ExtendedOutcome::refined;
}

bool refine_depth_extended(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                           const Pose& pose_b, const DistanceOptions& options,
                           DistanceResult& result) {
  const double magnitude = placed_bound(a, pose_a, b, pose_b);
  if (!(magnitude > 0.0) || !(result.depth > 0.0)) return false;
  const double band =
      contact_band(std::max(magnitude_bound(pose_a, a.scale()), magnitude_bound(pose_b, b.scale())),
                   options.absolute_tolerance);
  const double relative = std::max(kStandardRelative, options.relative_tolerance);
  const detail::PowerOfTwoUnit unit = detail::power_of_two_unit(magnitude);
  const double s = unit.inverse;
  const PlacedFeature fa = place(a, pose_a, result.feature_a, s);
  const PlacedFeature fb = place(b, pose_b, result.feature_b, s);
  PairDistance pair;
  if (!pair_distance(fa, fb, pair)) return false;
  const Dd length = sqrt(dot(pair.normal, pair.normal));
  if (!(length.hi > 0.0)) return false;
  // N along the answer's normal (world frame, from A towards B), so that
  // the overlap along it is h_A(N) + h_B(-N).
  DdVec normal = pair.normal;
  const Vec3 answer = pose_a.rotation * result.normal;
  const double side = answer.dot(Vec3(normal[0].hi, normal[1].hi, normal[2].hi));
  if (!(side != 0.0)) return false;
  if (side < 0.0) normal = {-normal[0], -normal[1], -normal[2]};
  std::vector<int> ids;
  const int hint_a = std::max<std::int32_t>(result.feature_a.vertices[0], 0);
  const int hint_b = std::max<std::int32_t>(result.feature_b.vertices[0], 0);
  const Dd top_a = extreme(a, pose_a, s, normal, 1.0, hint_a, ids);
  const Dd bottom_b = extreme(b, pose_b, s, normal, -1.0, hint_b, ids);
  const Dd overlap = (top_a - bottom_b) / length;
  // The rounding bound of the overlap and of the face's offset, as the
  // distance's gap (in units of s).
  const double agree = kAgreeUlps * 0x1p-104 * 2.0;
  // An upper bound on the exact depth whatever the face: the depth is the
  // least overlap over unit directions (the origin's distance to the
  // boundary of A - B).
  const double upper = round_up(overlap + Dd{agree, 0.0}) * unit.unit;
  if (!(std::abs(nearest(pair.distance - overlap)) <= agree)) {
    // Not a face of A - B along N within this precision: its overlap
    // still bounds the depth from above, where that is no looser.
    if (upper >= result.depth && upper < result.depth_upper_bound) result.depth_upper_bound = upper;
    return false;
  }
  const double depth = nearest(overlap) * unit.unit;
  // The double depth is within its tolerance of the exact one; a face
  // farther from it than that is not the deepest (a face whose value
  // ties with the least in double, beyond this precision's reach).
  if (!(std::abs(depth - result.depth) <= 2.0 * (relative * result.depth + band))) {
    if (upper >= result.depth && upper < result.depth_upper_bound) result.depth_upper_bound = upper;
    return false;
  }
  result.depth = depth;
  result.depth_upper_bound = upper;
  result.depth_lower_bound = std::min(result.depth_lower_bound, depth);
  const Vec3 n(nearest(normal[0] / length), nearest(normal[1] / length),
               nearest(normal[2] / length));
  result.normal = pose_a.rotation.transpose() * (n / n.norm());
  return true;
}

}  // namespace proxima::detail
