// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Conservative advancement on the tracked distance query
// (proxima/motion/time_of_impact.h).
#include "proxima/motion/time_of_impact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "proxima/geometry/closest_point.h"
#include "proxima/query/compound_distance.h"
#include "proxima/shape/support.h"
#include "time_of_impact.h"

namespace proxima {

namespace detail {

// sin x and cos x for x in [0, pi/2], the range of a sweep's half angle
// when it turns the shorter way (angle <= pi, 0 < t < 1): Taylor polynomials on [0, pi/4], their
// truncation below 1e-19 there, and the cofunctions of pi/2 - x above it
// (pi/2 - x exact by Sterbenz with pi/2's head, then its tail added). A
// few ulps, as the library's, in far fewer instructions than glibc's
// sincos, whose argument reduction covers every double; one pair per body
// and step. Outside the range: std::sin and std::cos.
void sin_cos_quadrant(double x, double& sine, double& cosine) {
  constexpr double kHalfPiHead = 1.5707963267948966;
  constexpr double kHalfPiTail = 6.123233995736766e-17;
  if (!(x >= 0.0 && x <= kHalfPiHead)) {
    sine = std::sin(x);
    cosine = std::cos(x);
    return;
  }
  const bool high = x > 0.5 * kHalfPiHead;
  const double y = high ? (kHalfPiHead - x) + kHalfPiTail : x;
  const double z = y * y;
  // sin y = y (1 - z/3! + z^2/5! - ... + z^8/17!), cos y = 1 - z/2! + ... + z^9/18!.
  const double s =
      y + y * z *
              (-1.0 / 6 +
               z * (1.0 / 120 + z * (-1.0 / 5040 +
                                     z * (1.0 / 362880 + z * (-1.0 / 39916800 +
                                                              z * (1.0 / 6227020800 +
                                                                   z * (-1.0 / 1307674368000 +
                                                                        z / 355687428096000)))))));
  const double c =
      1.0 +
      z * (-0.5 + z * (1.0 / 24 +
                       z * (-1.0 / 720 +
                            z * (1.0 / 40320 +
                                 z * (-1.0 / 3628800 +
                                      z * (1.0 / 479001600 + z * (-1.0 / 87178291200 +
                                                                  z * (1.0 / 20922789888000 -
                                                                       z / 6402373705728000))))))));
  sine = high ? c : s;
  cosine = high ? s : c;
}

}  // namespace detail

namespace {

// By classification, not Eigen's allFinite: that computes x - x, which
// raises FE_INVALID on an infinity, and a caller's trap would turn the
// refusal of an overflowing motion into SIGFPE
// (TimeOfImpact.VelocitiesNearTheLargestDoubleAreAnsweredOrRefusedByName).
bool finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Norms here and below without overflow or underflow of their squares
// (stableNorm, fast_norm): speeds and sizes near 1e-300 and 1e300 are
// valid.

// How far the hull of A reaches along the unit direction n (world frame),
// and how far B's hull starts, at the placed poses: max over A of n.x and
// min over B of n.y, found by hill climbing from the cache's hints (exact
// maximizers). B's minus A's is the gap between the support planes, a lower
// bound on the distance whatever n is.
struct SupportPlanes {
  double top_a = 0.0;
  double bottom_b = 0.0;
  int vertex_a = 0;  // the support vertices
  int vertex_b = 0;
  Vec3 direction_a = Vec3::Zero();  // n seen from each body
  Vec3 direction_b = Vec3::Zero();
};

SupportPlanes support_planes(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                             const Pose& pose_b, const Vec3& n, const DistanceCache& cache) {
  const Vec3 na = pose_a.rotation.transpose() * n;
  const Vec3 nb = pose_b.rotation.transpose() * n;
  const int ia = support_hill_climb(a, na, cache.hint_a);
  const int ib = support_hill_climb(b, -nb, cache.hint_b);
  return {n.dot(pose_a.apply(a.vertex(ia))), n.dot(pose_b.apply(b.vertex(ib))), ia, ib, na, nb};
}

// A bound on how a body's support plane along a fixed unit n moves while
// the body turns by w about its reference point, good for a time span:
// from `value`, at `rate` (per unit t, towards +n) at first, with a
// magnitude of acceleration at most `acceleration`, for `span`.
//
// Why. Take a set S of vertices that holds the support vertex along
// +sign n (the witness feature: a vertex, an edge, a face's vertices, and
// the support vertex found by hill climbing); the support plane is S's
// highest vertex as long as that is a local maximum of the hull's vertex
// graph (the hull being convex, then a global one). A vertex q of S, r = R q
// its offset from the reference point, moves along n at exactly
// sign n.(v + w x r) now, and its rotation part accelerates by at most
// |w|^2 |r| (the centripetal term; the translation is linear): the highest
// of S rises at most at the largest rate with the largest acceleration.
// It stays the highest vertex while no neighbour y outside S overtakes any
// q of S: the direction seen from the body moves by at most |w x n| per
// unit t, and y stays below q while that is less than margin_y = sign n.(q
// - y) / |q - y| (world frame). So the bound holds for the smallest margin
// over |w x n| (none when a margin is negative: S does not hold the
// support). A contact at a vertex then closes at second order in the turn
// (the vertex's rate along the normal is about 0), a face-on contact at the
// true rates of the face's corners, where the bound |w x n| reach charged
// both first order at the full reach.
struct PlaneBound {
  double value = 0.0;
  double rate = 0.0;
  double acceleration = 0.0;
  double span = 0.0;
};

// Cone margins a hair inside the computed ones, for their rounding: a
// margin is a root of a ratio of dot products, off by a few u relative
// (far below 1e-9), and the bounds it limits only need it not to be
// larger than the true one; 1e-9 of a margin shortens a span by as little.
constexpr double kConeMarginShrink = 1.0 - 1e-9;

// The largest face taken whole into S (bigger faces: S is the witness
// feature's vertices and the support vertex only). The margin loop costs
// |S| times the degree times |S|.
constexpr std::size_t kMaxFeatureVertices = 16;

// Squares below this bound are taken as they are (their root in one
// sqrt): a sum of three squares below 2^1000 cannot have overflowed, and
// its root is as accurate as the stable norm's; from 2^1000 up (and in the
// subnormals, where the squares lose bits) the norms and ratios below take
// the stable way.
constexpr double kSquareInRange = 0x1p1000;

// |x| from its square where that neither overflows nor underflows (the
// common case, one sqrt), else the stable norm.
// Inlined: with the mesh traversal in this file GCC stopped inlining it,
// a call for three multiplies and a root on every bound (callgrind).
[[gnu::always_inline]] inline double fast_norm(const Vec3& x) {
  const double squared = x.squaredNorm();
  if (squared >= std::numeric_limits<double>::min() && squared < kSquareInRange)
    return std::sqrt(squared);
  return x.stableNorm();
}

// S: the witness feature's vertices (a face's whole polygon when it is
// small) and the support vertex, without repeats.
struct VertexSet {
  std::array<std::int32_t, kMaxFeatureVertices + 4> ids;  // the first `size` only
  std::size_t size = 0;
  // Bit v mod 64 set for each vertex v of S: a vertex whose bit is clear
  // is not in S (the common answer of has(), without the loop).
  std::uint64_t bits = 0;
  static std::uint64_t bit(std::int32_t v) {
    return std::uint64_t{1} << (static_cast<std::uint32_t>(v) & 63u);
  }
  // A vertex known not to be in S yet (a face's own, distinct, into an
  // empty S).
  void push(std::int32_t v) {
    ids[size++] = v;
    bits |= bit(v);
  }
  void add(std::int32_t v) {
    if (v < 0 || has(v)) return;
    push(v);
  }
  bool same(const VertexSet& o) const {
    return size == o.size &&
           std::equal(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(size), o.ids.begin());
  }
  // The bit first, then a plain loop (std::find's unrolled one costs more:
  // S holds a few vertices).
  bool has(std::int32_t v) const {
    if ((bits & bit(v)) == 0) return false;
    for (std::size_t k = 0; k < size; ++k) {
      if (ids[k] == v) return true;
    }
    return false;
  }
};

VertexSet feature_set(const ConvexPolytope& body, const Feature& feature, int support) {
  VertexSet set;
  if (feature.type == FeatureType::face && feature.face >= 0 && feature.face < body.face_count() &&
      body.face(feature.face).size() <= kMaxFeatureVertices) {
    for (const std::int32_t v : body.face(feature.face)) set.push(v);
  } else {
    for (const std::int32_t v : feature.vertices) {
      if (v < body.vertex_count()) set.add(v);
    }
  }
  set.add(support);
  return set;
}

// feature_set of the last step, kept while the witness feature and the
// support vertex stay (near a contact they do from step to step).
struct FeatureSetMemo {
  Feature feature;
  int support = -1;  // -1: none yet
  VertexSet set;

  const VertexSet& of(const ConvexPolytope& body, const Feature& f, int s) {
    if (s != support || f.type != feature.type || f.face != feature.face ||
        f.vertices != feature.vertices) {
      set = feature_set(body, f, s);
      feature = f;
      support = s;
    }
    return set;
  }
};

// A feature margin computed at an earlier step, kept for the next ones:
// each edge's ratio sign d.(q - y) / |q - y| is 1-Lipschitz in the unit
// direction d, and so is their minimum, so for the same vertex set the
// margin along d' is at least the kept one less |d' - d|. Near a contact
// the features stay and the direction barely moves: the margin loop runs
// once instead of on every step (it was about an eighth of a query's
// time at N = 8, toi_bench).
struct MarginMemo {
  VertexSet set;
  Vec3 direction = Vec3::Zero();
  double margin = -1.0;  // none yet
};

// What a kept margin loses besides |d' - d|: the rounding of |d' - d|
// (unit vectors, a few u) and of the kept margin's ratios (a few u
// relative, of a margin <= 1): 1e-14 is about 45 u, far above both.
constexpr double kMarginSlack = 1e-14;

// Squared cone margins below this count as none: a square in the
// subnormals may have been rounded up (margins below 2^-450, whose spans
// are no use anyway).
constexpr double kSmallestSquaredMargin = 0x1p-900;

// How far the unit direction seen from a body (`direction`, times `sign`)
// may turn, as |e(t) - e(0)|, before a neighbour of the vertex set S may
// overtake S's highest vertex: the smallest margin of PlaneBound's comment,
// a hair inside, >= 0 (0 when S does not hold the support).
double cone_margin(const ConvexPolytope& body, const VertexSet& set, const Vec3& direction,
                   double sign) {
  // Each edge's ratio on its own and the smallest kept: no chain of
  // divisions through a running margin (that chain, not the arithmetic,
  // was the cost of a step). A falling edge (rise < 0) ends it at 0.
  // The ratios squared, rise^2 / length^2 where length^2 is in range, one
  // root at the end: no root per edge. rise <= length, so rise^2 does not
  // overflow; a square in the subnormals may be rounded up, so squares
  // below 2^-900 (margins below 2^-450) count as no margin.
  double margin2 = 1.0;
  const Vec3 d = sign * direction;
  for (std::size_t k = 0; k < set.size; ++k) {
    const Vec3& q = body.vertex(set.ids[k]);
    for (const std::int32_t y : body.neighbors(set.ids[k])) {
      if (set.has(y)) continue;
      const Vec3 edge = q - body.vertex(y);
      const double rise = d.dot(edge);
      if (rise < 0.0) return 0.0;
      const double length2 = edge.squaredNorm();
      if (length2 >= std::numeric_limits<double>::min() && length2 < kSquareInRange) [[likely]] {
        margin2 = std::min(margin2, rise * rise / length2);
      } else {
        const double length = edge.stableNorm();
        const double ratio = length > 0.0 ? rise / length : 1.0;
        margin2 = std::min(margin2, ratio * ratio);
      }
    }
  }
  if (!(margin2 >= kSmallestSquaredMargin)) return 0.0;
  return std::sqrt(margin2) * kConeMarginShrink;
}

// The witness feature's plane of one body at one step. Its value, rate and
// acceleration cost O(|S|) and are computed at once; its span (the margin
// loop, O(|S| degree |S|)) only when a pair of planes could take a longer
// step with it than the best found so far (span()), which far from
// contact (the balls' planes win) is seldom. `direction` is n seen from
// the body (pose.rotation^T n), `turn` |w x n|.
class FeaturePlane {
 public:
  FeaturePlane(const ConvexPolytope& body, const Pose& pose, const Vec3& origin,
               const VertexSet& set, const Vec3& n, const Vec3& direction, double sign,
               const Vec3& v, const Vec3& w, double turn, MarginMemo& memo)
      : body_(&body), set_(&set), direction_(direction), sign_(sign), turn_(turn), memo_(&memo) {
    // Vertex q at r = R (q - o) from the reference point (o, `origin`, the
    // reference point in the hull's frame): n.(x) = n.t + (R^T n).q, and
    // its rotation part moves along n at (w x r).n = r.(n x w) =
    // (R^T (n x w)).(q - o); |r| = |q - o|. Dot products with the hull's
    // own vertices, no rotation of each.
    const Vec3 spin = pose.rotation.transpose() * n.cross(w);
    double top = -std::numeric_limits<double>::infinity();
    double rise = -std::numeric_limits<double>::infinity();
    // The longest arm from its square (one root), where no square over- or
    // underflows; else arm by arm without overflow.
    double arm2 = 0.0;
    for (std::size_t k = 0; k < set.size; ++k) {
      const Vec3& q = body.vertex(set.ids[k]);
      top = std::max(top, sign * direction.dot(q));
      rise = std::max(rise, sign * spin.dot(q));
      arm2 = std::max(arm2, (q - origin).squaredNorm());
    }
    double arm = std::sqrt(arm2);
    if (!(arm2 >= std::numeric_limits<double>::min() && arm2 < kSquareInRange)) {
      arm = 0.0;
      for (std::size_t k = 0; k < set.size; ++k)
        arm = std::max(arm, (body.vertex(set.ids[k]) - origin).stableNorm());
    }
    bound_.value = sign * n.dot(pose.translation) + top;
    bound_.rate = sign * (n.dot(v) - spin.dot(origin)) + rise;
    bound_.acceleration = w.squaredNorm() * arm;
    bound_.span = std::numeric_limits<double>::infinity();
  }

  // value, rate and acceleration (span: see span()).
  const PlaneBound& bound() const { return bound_; }

  // How far the direction seen from the body may turn (as |e(t) - e(0)|)
  // before a neighbour of S may overtake it: the smallest margin of the
  // header comment, a hair inside, >= 0. The margin loop, O(|S| degree
  // |S|), runs on the first call only.
  // `need`: the margin that would not limit the caller's step; a kept
  // margin that reaches it is as good as a fresh one there.
  double margin(double need) {
    if (fresh_ || margin_ >= need) return margin_;
    // From the kept margin while it is at least half of what it was, or
    // while it does not limit the step.
    if (margin_ < 0.0 && memo_->margin > 0.0 && memo_->set.same(*set_)) {
      const double kept = memo_->margin - fast_norm(direction_ - memo_->direction) - kMarginSlack;
      if (kept >= 0.0) margin_ = kept;
      if (kept >= 0.5 * memo_->margin || kept >= need) return margin_;
    }
    margin_ = fresh_margin();
    fresh_ = true;
    *memo_ = {*set_, direction_, margin_};
    return margin_;
  }
  // The span, for a step of `step` (unbounded without a turn).
  double span(double step) {
    return turn_ > 0.0 ? margin(step * turn_) / turn_ : std::numeric_limits<double>::infinity();
  }

  const VertexSet& set() const { return *set_; }

 private:
  double fresh_margin() const { return cone_margin(*body_, *set_, direction_, sign_); }

  const ConvexPolytope* body_;
  const VertexSet* set_;  // the caller's, outliving the plane
  Vec3 direction_;
  double sign_;
  double turn_;
  PlaneBound bound_;
  MarginMemo* memo_;
  double margin_ = -1.0;  // not computed yet
  bool fresh_ = false;    // margin_ is cone_margin's own (else kept or none)
};

// The first time in [0, span] at which a gap gap0 closing at `rate` with
// acceleration at most `acceleration` can reach 0 (gap0 > 0): the smaller
// root of gap0 - rate t - acceleration t^2 / 2, capped at span; infinity
// when it never closes and span is unbounded.
double first_closing(double gap0, double rate, double acceleration, double span) {
  double t = std::numeric_limits<double>::infinity();
  if (acceleration > 0.0) {
    // Written without cancellation: 2 gap0 / (rate + sqrt(rate^2 + 2 a gap0)).
    const double root = std::sqrt(rate * rate + 2.0 * acceleration * gap0);
    t = rate + root > 0.0 ? 2.0 * gap0 / (rate + root) : std::numeric_limits<double>::infinity();
  } else if (rate > 0.0) {
    t = gap0 / rate;
  }
  return std::min(t, span);
}

// The longest safe step, nearly, of a gap gap0 > 0 closing at `rate` whose
// acceleration over [0, s] is at most acceleration(s), a bound that grows
// with s (it charges the motion over the whole span: the farther the bodies
// may move, the more the planes may turn), for s up to `span`. For any
// S <= span, first_closing with acceleration(S) capped at S is safe: if its
// root r(S) is at least S the bound holds up to S; if it is shorter, the
// bound over [0, S] holds over [0, r(S)] too. So S is best taken near the
// step itself, not the span: near a contact the step is a small fraction
// of the span, and so is the acceleration the motion can build up over it.
// S = gap0 / rate (the step without acceleration, longer than every root)
// gives a root at least that of the span at the cost of one division, and
// close to the best S where the gap closes mostly at its rate (a contact
// near): a smaller constant of the quadratic convergence, fewer steps
// (toi_bench, N = 8: 6.38 to 5.97 distance queries per contact).
template <class Acceleration>
double widest_closing(double gap0, double rate, const Acceleration& acceleration, double span) {
  const double s = rate > 0.0 ? std::min(span, gap0 / rate) : span;
  return first_closing(gap0, rate, acceleration(s), s);
}

// The step that a plane fixed in one body allows. Take body F's support
// plane along the unit d at time t (F below it, at height `plane`; the
// other body M above) and let it move with F: F never crosses it (F's
// support along a direction fixed in F is always the same vertex), so
// while the vertex set S of M holds M's lowest vertex along the plane's
// turning normal d(s) (the caller's span: the direction seen from M turns
// at most at |w_F - w_M|), the gap min over S of d(s).(x_q(s) - x_F(s))
// bounds the distance from below (x_F a point of the plane). For q in S,
// with u = x_q - T_F and r = x_q - T_M (T the reference points) and
// g(s) = d(s).u(s): d' = w_F x d, u' = v_M + w_M x r - v_F, so
//   g'(0) = d.(v_M + w_M x r - v_F - w_F x u),
// the exact rate of q along d in F's frame (a vertex-face contact closes at
// second order), and g'' = d''.u + 2 d'.u' + d.u'' with |d''| <= |w_F|^2,
// |u'| <= V = |v_M - v_F| + |w_M| |r|, |u''| <= |w_M|^2 |r| and
// |u(s)| <= |u(0)| + V s: over s <= S (S <= horizon),
//   |g''| <= |w_F|^2 (|u(0)| + V S) + 2 |w_F| V + |w_M|^2 |r|.
// The step is the first closing over S of the gap less `keep_off` (the
// band and the target), at most `horizon`, with S chosen by
// widest_closing; the caller applies the span.
double fixed_plane_step(double plane, const Vec3& d, const Vec3& origin_f, const Vec3& v_f,
                        const Vec3& w_f, const ConvexPolytope& m, const Pose& pose_m,
                        const Vec3& origin_m, const Vec3& v_m, const Vec3& w_m,
                        const VertexSet& set, double keep_off, double horizon) {
  const Vec3 dv = v_m - v_f;
  const double speed = fast_norm(dv);
  const double wf = fast_norm(w_f);
  const double wm2 = w_m.squaredNorm();
  const double wm = std::sqrt(wm2);
  double step = horizon;
  for (std::size_t k = 0; k < set.size; ++k) {
    const Vec3 x = pose_m.apply(m.vertex(set.ids[k]));
    const double gap = d.dot(x) - plane - keep_off;
    if (!(gap > 0.0)) return 0.0;
    const Vec3 u = x - origin_f;
    const Vec3 r = x - origin_m;
    const double arm = fast_norm(r);
    const double closing = -d.dot(dv + w_m.cross(r) - w_f.cross(u));
    const double v = speed + wm * arm;
    const double still = wf * wf * fast_norm(u) + 2.0 * wf * v + wm2 * arm;
    const auto acceleration = [&](double span) { return still + wf * wf * v * span; };
    step = std::min(step, widest_closing(gap, closing, acceleration, horizon));
  }
  return step;
}

// The step that the plane through two edges allows (an edge-edge witness
// pair), exact at first order where the planes above charge the edges'
// fastest ends. Let e_a(s), e_b(s) be the two edges' unit directions
// turning with their bodies, c = e_a x e_b, rho = |c| and m = c / rho
// (oriented from A to B). m stays perpendicular to both edges, so while
// A's edge holds A's support along m and B's edge B's lowest along m, the
// gap between the support planes along m is exactly
//   l(s) = m(s).D(s),  D = y(s) - x(s),
// x a point of A's edge line and y one of B's carried by their bodies (the
// witness points p and q: D(0) = q - p, of length the distance d), a lower
// bound on the distance (any plane's gap is). Its rate is exact,
//   l'(0) = m'.D + m.D'  with  m' = (I - m m^T) c' / rho,
//   c' = (w_a x e_a) x e_b + e_a x (w_b x e_b),
// so an edge-edge contact closes at second order. The second derivative,
// l'' = m''.D + 2 m'.D' + m.D'', with W = |w_a| + |w_b|: |c'| <= W,
// |c''| <= W^2, |m'| <= |c'| / rho and (differentiating m = c / rho twice)
// |m''| <= 2 |c''| / rho + 5 |c'|^2 / rho^2; |D'| <= V = |v_b - v_a| +
// |w_a| |p - T_a| + |w_b| |q - T_b| (T the reference points), |D(s)| <=
// |D(0)| + V s, |D''| <= |w_a|^2 |p - T_a| + |w_b|^2 |q - T_b|. rho
// depends only on the relative turn w_r = w_b - w_a: rho(s) >= rho(0) -
// |w_r| s, kept >= rho(0) / 2 by the horizon. Seen from either body, m
// turns at most at |w_r| / rho (the other edge turns at |w_r| about it),
// so by time s it has turned at most -ln(1 - |w_r| s / rho(0)) (as an
// arc, more than the chord of the cone margins): each edge holds its
// body's support while that is below the edge's cone margin (cone_margin
// of its two vertices along m), i.e. for s <= rho(0) (1 - e^-margin) /
// |w_r|. The witness points are the query's (off the edge lines by a few
// u R in the body frames, which stays so as they move: inside the band),
// and m(0) comes from edges nearly perpendicular only (rho(0) >= 1/2), so
// that its rounding, times |D| and the edges' lengths, stays inside the
// band too; `keep_off` (twice the band, and the target) is kept off.
// Returns 0 where the bound does not apply, and the step before the
// spans' limit where that is not longer than `best` (no use then).
// What edge_pair_step takes from the whole interval: the motions' speeds,
// the hulls' reaches (bounds on |p - T_a| and |q - T_b|), and the edges'
// cone margins of an earlier step, kept while the same edges are the
// witnesses (1-Lipschitz in the direction, as MarginMemo).
struct EdgePairs {
  double turn_a = 0.0;    // |w_a|
  double turn_b = 0.0;    // |w_b|
  double relative = 0.0;  // |w_b - w_a|
  double speed = 0.0;     // |v_b - v_a|
  double reach_a = 0.0;
  double reach_b = 0.0;
  std::array<std::int32_t, 4> edges = {-1, -1, -1, -1};
  Vec3 direction_a = Vec3::Zero();
  Vec3 direction_b = Vec3::Zero();
  double margin_a = -1.0;
  double margin_b = -1.0;
};

// The smallest sine of the angle between the two edges for which their
// plane is used: m = c / rho's rounding grows as 1 / rho, and at rho >=
// 1/2 it stays a few u (inside the band that keep_off keeps off); the
// horizon keeps rho >= rho(0) / 2 too, so that the bound on |m''| (which
// grows as 1 / rho^2) stays within 16 times its value at right angles.
constexpr double kMinEdgePairSine = 0.5;

double edge_pair_step(const ConvexPolytope& a, const Pose& pa, const Vec3& origin_a, const Vec3& va,
                      const Vec3& wa, const Feature& fa, const Vec3& p, const ConvexPolytope& b,
                      const Pose& pb, const Vec3& origin_b, const Vec3& vb, const Vec3& wb,
                      const Feature& fb, const Vec3& q, const Vec3& n, double keep_off,
                      double horizon, double best, EdgePairs& k) {
  const std::int32_t a1 = fa.vertices[0], a2 = fa.vertices[1];
  const std::int32_t b1 = fb.vertices[0], b2 = fb.vertices[1];
  if (a1 < 0 || a2 < 0 || b1 < 0 || b2 < 0 || a1 >= a.vertex_count() || a2 >= a.vertex_count() ||
      b1 >= b.vertex_count() || b2 >= b.vertex_count())
    return 0.0;
  const Vec3 edge_a = pa.rotation * (a.vertex(a2) - a.vertex(a1));
  const Vec3 edge_b = pb.rotation * (b.vertex(b2) - b.vertex(b1));
  // e_a x e_b of the unit edges: one root for both lengths (out of range:
  // no bound).
  const double lengths2 = edge_a.squaredNorm() * edge_b.squaredNorm();
  if (!(lengths2 >= std::numeric_limits<double>::min() && lengths2 < kSquareInRange)) return 0.0;
  const double inverse = 1.0 / std::sqrt(lengths2);
  const Vec3 c = edge_a.cross(edge_b) * inverse;
  const double rho = std::sqrt(c.squaredNorm());
  if (!(rho >= kMinEdgePairSine)) return 0.0;
  Vec3 m = c / rho;
  if (m.dot(n) < 0.0) m = -m;
  const Vec3 d0 = q - p;
  const double gap = m.dot(d0) - keep_off;
  if (!(gap > 0.0)) return 0.0;

  // The rate: l'(0) = m'.D + m.D' (closing: its negative).
  const Vec3 c_dot = (wa.cross(edge_a).cross(edge_b) + edge_a.cross(wb.cross(edge_b))) * inverse;
  const Vec3 m_dot = (c_dot - m * m.dot(c_dot)) / rho;
  const Vec3 d_dot = (vb + wb.cross(q - origin_b)) - (va + wa.cross(p - origin_a));
  const double closing = -(m_dot.dot(d0) + m.dot(d_dot));
  // The second derivative's bound over [0, s] for s up to the horizon and
  // while rho stays >= rho(0) / 2 (the spans of the edges' supports may end
  // it sooner: the bound holds over the shorter span too), narrowed to the
  // step by widest_closing.
  const double wr = k.relative;
  double span = wr > 0.0 ? std::min(horizon, 0.5 * rho / wr) : horizon;
  const double na = k.turn_a, nb = k.turn_b;
  const double w = na + nb;
  const double speed = k.speed + na * k.reach_a + nb * k.reach_b;
  // Over [0, s]: rho >= rho(0) - |w_r| s (>= rho(0) / 2 within the span).
  const double distance0 = fast_norm(d0);
  const double turning = na * na * k.reach_a + nb * nb * k.reach_b;
  const auto acceleration = [&](double s) {
    const double rho_min = rho - wr * s;
    const double m_ddot = (2.0 * w * w + 5.0 * w * w / rho_min) / rho_min;
    return m_ddot * (distance0 + speed * s) + 2.0 * (w / rho_min) * speed + turning;
  };
  const double step = widest_closing(gap, closing, acceleration, span);
  // The supports' spans (the cone margins, O(degree) each) only where the
  // step could beat `best`: s <= rho(0) (1 - e^-margin) / |w_r|, with
  // 1 - e^-x >= x (1 - x / 2) (margins are <= 1).
  if (!(step > best) || !(wr > 0.0)) return step;
  const Vec3 direction_a = pa.rotation.transpose() * m;
  const Vec3 direction_b = pb.rotation.transpose() * m;
  const std::array<std::int32_t, 4> edges = {a1, a2, b1, b2};
  double margin_a = -1.0, margin_b = -1.0;
  if (a1 == k.edges[0] && a2 == k.edges[1] && b1 == k.edges[2] && b2 == k.edges[3] &&
      k.margin_a > 0.0 && k.margin_b > 0.0) {
    margin_a = k.margin_a - fast_norm(direction_a - k.direction_a) - kMarginSlack;
    margin_b = k.margin_b - fast_norm(direction_b - k.direction_b) - kMarginSlack;
    if (!(margin_a >= 0.5 * k.margin_a) || !(margin_b >= 0.5 * k.margin_b)) margin_a = -1.0;
  }
  if (margin_a < 0.0) {
    VertexSet set_a, set_b;
    set_a.add(a1);
    set_a.add(a2);
    set_b.add(b1);
    set_b.add(b2);
    margin_a = cone_margin(a, set_a, direction_a, 1.0);
    margin_b = cone_margin(b, set_b, direction_b, -1.0);
    k.edges = edges;
    k.direction_a = direction_a;
    k.direction_b = direction_b;
    k.margin_a = margin_a;
    k.margin_b = margin_b;
  }
  const double margin = std::min(margin_a, margin_b);
  if (!(margin > 0.0)) return 0.0;
  span = std::min(span, margin * (1.0 - 0.5 * margin) * rho / wr);
  return std::min(step, span);
}

// A motion with its turn precomputed (Motion::at would convert the rotation
// to an angle and an axis on every call; a time of impact takes poses at a
// dozen times). The turn's angle and axis are the angular velocity's when
// the motion has one (any angle, several turns included), else the
// shorter way's from start to end (an angle in [0, pi]). The turn by
// phi = t angle about the unit axis k is
// Rodrigues' I + sin(phi) K + (1 - cos(phi)) K^2 (K the cross product
// matrix of k), so the pose's rotation is R0 + sin(phi) (K R0) +
// (1 - cos(phi)) (K^2 R0): the two products are made once, and each pose
// costs one sincos (of phi / 2: sin(phi) = 2 s c and 1 - cos(phi) = 2 s^2,
// without the cancellation of 1 - cos for small phi) and 18 multiply-adds.
class Sweep {
 public:
  explicit Sweep(const Motion& m) : motion_(m) {
    if (m.angular) {
      angle_ = m.angular->stableNorm();
      if (angle_ > 0.0) axis_ = *m.angular / angle_;
    } else {
      const Eigen::AngleAxisd turn(Mat3(m.end.rotation * m.start.rotation.transpose()));
      angle_ = turn.angle();
      axis_ = turn.axis();
    }
    // K x = axis x x, column by column.
    for (int j = 0; j < 3; ++j) {
      k_r0_.col(j) = axis_.cross(m.start.rotation.col(j));
      kk_r0_.col(j) = axis_.cross(Vec3(k_r0_.col(j)));
    }
  }
  Pose at(double t) const {
    if (t <= 0.0) return motion_.start;
    if (t >= 1.0) return motion_.end;
    Pose p;
    p.rotation = turned(t);
    p.translation =
        motion_.start.translation + t * (motion_.end.translation - motion_.start.translation);
    return p;
  }
  // The rotation at t by the turn's formula (at t = 1 too, where at() gives
  // the end pose as stored).
  Mat3 turned(double t) const {
    if (!(angle_ > 0.0)) return motion_.start.rotation;
    const double half = 0.5 * t * angle_;
    double s, c;
    detail::sin_cos_quadrant(half, s, c);
    return motion_.start.rotation + (2.0 * s * c) * k_r0_ + (2.0 * s * s) * kk_r0_;
  }
  Vec3 angular_velocity() const { return motion_.angular ? *motion_.angular : angle_ * axis_; }
  double angle() const { return angle_; }
  Vec3 linear_velocity() const { return motion_.linear_velocity(); }

 private:
  Motion motion_;
  double angle_ = 0.0;
  Vec3 axis_ = Vec3::UnitX();
  Mat3 k_r0_ = Mat3::Zero();
  Mat3 kk_r0_ = Mat3::Zero();
};

double body_size(const Body& body) {
  switch (body.kind()) {
    case Body::Kind::convex:
      return body.convex()->bounding_radius() + body.radius();
    case Body::Kind::compound:
      return body.compound()->bounding_radius() + body.radius();
    case Body::Kind::mesh:
      return body.mesh()->bounding_radius() + body.radius();
  }
  return 0.0;
}

}  // namespace

namespace detail {

void check_impact_options(const ImpactOptions& options, const char* who) {
  const double target = options.target_separation;
  if (!std::isfinite(target) || target < 0.0) {
    throw InvalidInput(std::string(who) +
                       ": options.target_separation must be finite and >= 0, not " +
                       std::to_string(target));
  }
  if (!std::isfinite(options.tolerance) || options.tolerance < 0.0) {
    throw InvalidInput(std::string(who) +
                       ": options.tolerance must be finite and >= 0 (0: default)");
  }
  if (options.max_iterations < 1) {
    throw InvalidInput(std::string(who) + ": options.max_iterations must be at least 1");
  }
}

}  // namespace detail

// The fastest turn followed, radians per unit t: beyond it consecutive
// doubles of the angle t |w| are more than a radian apart (u |w| > 1/2),
// so the pose at t is not defined by the motion, only by rounding; below
// it |w|^2 and its products with the bodies' sizes stay far from
// overflowing in the bounds.
constexpr double kMaxTurnRate = 0x1p52;

Motion Motion::from_velocity(const Pose& pose, const Vec3& linear, const Vec3& angular,
                             double duration) {
  if (!finite(linear) || !finite(angular) || !std::isfinite(duration) || !(duration > 0.0)) {
    throw InvalidInput(
        "Motion::from_velocity: the velocities must be finite and the duration finite and > 0");
  }
  // The turn per unit t, kept: the end pose alone cannot say how many
  // turns the body made, nor which way past a half turn.
  Motion m{pose, pose, Vec3(duration * angular)};
  m.end.translation = pose.translation + duration * linear;
  if (!finite(*m.angular) || !(m.angular->stableNorm() <= kMaxMagnitude) ||
      !finite(m.end.translation)) {
    throw InvalidInput(
        "Motion::from_velocity: the turn or the end translation over the duration is beyond "
        "the supported magnitude 2^1018 (about 2.8e306)");
  }
  m.end.rotation = Sweep(m).turned(1.0);
  return m;
}

Vec3 Motion::angular_velocity() const {
  if (angular) return *angular;
  const Eigen::AngleAxisd turn(Mat3(end.rotation * start.rotation.transpose()));
  return turn.angle() * turn.axis();
}

Pose Motion::at(double t) const { return Sweep(*this).at(t); }

namespace {


// checked_sweep's checks after the pose contract's, on rigid poses.
Sweep limited_sweep(const Motion& m, double scale, const char* name) {
  const Motion& checked = m;
  const auto refuse = [&](const std::string& what) {
    throw InvalidInput(std::string(name) + what);
  };
  if (m.angular && !(finite(*m.angular) && std::isfinite(m.angular->stableNorm())))
    refuse(".angular is not finite (NaN or infinite, or its length overflows)");
  if (m.angular && !(m.angular->stableNorm() <= kMaxTurnRate)) {
    char what[240];
    std::snprintf(what, sizeof what,
                  ".angular turns at %.3g rad per unit t, beyond the supported %.3g (2^52), where "
                  "the angle t |w| is not known to a radian in doubles: scale the motion's time down",
                  m.angular->stableNorm(), kMaxTurnRate);
    refuse(what);
  }
  for (const Pose* end : {&checked.start, &checked.end}) {
    const double magnitude = magnitude_bound(*end, scale);
    if (!(magnitude <= kMaxMagnitude)) {
      char what[220];
      std::snprintf(what, sizeof what,
                    ".%s reaches coordinates of magnitude %.3g (vertices and pose translation), "
                    "beyond the supported %.3g where differences of coordinates may overflow",
                    end == &checked.start ? "start" : "end", magnitude, kMaxMagnitude);
      refuse(what);
    }
  }
  Sweep sweep(checked);
  if (m.angular) {
    // The turn must end where the motion says it does: the angle's
    // rounding (a few u of it, a rotation a few u off) is far inside the
    // pose contract's tolerance, which a different end (a motion built
    // with one angular velocity and another end pose) is not.
    const double off = (sweep.turned(1.0) - checked.end.rotation).cwiseAbs().maxCoeff();
    if (!(off <= kRotationTolerance)) {
      refuse(".end.rotation is not where .angular turns .start.rotation at t = 1 (off by " +
             std::to_string(off) + "): give the end pose that angular velocity reaches, as " +
             "Motion::from_velocity does");
    }
  }
  return sweep;
}

// A motion under the pose contract (re-orthonormalized where the contract
// allows it), its angular velocity (when given) finite and ending at
// end.rotation, and both ends within the coordinate magnitude the distance
// queries accept, for a body of `scale` (its coordinates' largest
// magnitude in its own frame). `name`: "time_of_impact: motion_a".
Sweep checked_sweep(const Motion& m, double scale, const char* name) {
  // Both ends' check at once (the common case), else each end's own.
  if (detail::are_rigid(m.start, m.end)) [[likely]]
    return limited_sweep(m, scale, name);
  return limited_sweep(Motion{checked_pose(m.start, std::string(name) + ".start"),
                              checked_pose(m.end, std::string(name) + ".end"), m.angular},
                       scale, name);
}

// The motions' closing speed bound |v_b - v_a| + |w_a| reach_a + |w_b|
// reach_b, each reach bounded by sqrt(3) scale (the farthest a body's
// point is from its reference point): finite, or the motions are refused
// (every step's bounds would overflow to infinity and no step could be
// taken).
void check_closing_speed(const Sweep& ma, double scale_a, const Sweep& mb, double scale_b) {
  const double speed = (mb.linear_velocity() - ma.linear_velocity()).stableNorm() +
                       ma.angle() * std::sqrt(3.0) * scale_a +
                       mb.angle() * std::sqrt(3.0) * scale_b;
  if (!std::isfinite(speed)) {
    throw InvalidInput(
        "time_of_impact: the motions' closing speed bound |v_b - v_a| + |w_a| reach_a + "
        "|w_b| reach_b overflows doubles (velocities times sizes beyond about 1.8e308): "
        "scale the motions' time down");
  }
}

// A step that is safe from time t: no contact before t + step, or none at
// all before the end (never).
struct SafeStep {
  double step = 0.0;
  bool never = false;
};

// The tolerance is at least this many contact bands at the poses of a
// step (ImpactOptions::tolerance says so): the steps keep one band off
// the planes' gaps and two off the edge pair's (the query's rounding and
// the plane's own), and the gaps are the distance within a band of
// rounding, so a distance within a few bands of the target may allow no
// step at all; above four bands every gap still exceeds what is kept off,
// and the step is positive. A finer tolerance would end at the iteration
// cap with the distance already as close as doubles can tell.
constexpr double kMinToleranceBands = 4.0;

// The advancement loop shared by every body kind, over [t_begin, t_end]
// (no contact before t_begin is known): `poses(t)` the two poses at t,
// `query(pa, pb)` the distance query at them (its signed distance and
// status decide contact), `band(pa, pb)` the contact band there (the
// tolerance's floor, kMinToleranceBands), `safe_step(r, pa, pb)` how far
// time may advance after answer r. Safe up to t_end < 1: status separated
// at t = t_end, no query there (a caller that already has a contact at
// t_end).
template <class Poses, class Query, class Band, class Step>
ImpactResult advance(const Poses& poses, const ImpactOptions& options, double tolerance,
                     const Query& query, const Band& band, const Step& safe_step,
                     double t_begin = 0.0, double t_end = 1.0) {
  const double target = options.target_separation;
  const auto in_contact = [&](const DistanceResult& r, const Pose& pa, const Pose& pb) {
    return r.status == Status::intersecting || r.status == Status::touching ||
           r.signed_distance() <=
               target + std::max(tolerance, kMinToleranceBands * band(pa, pb));
  };
  ImpactResult out;
  double t = t_begin;
  for (;;) {
    // Named poses, not a structured binding: the lambda below captures
    // them, which clang (the fuzz build) refuses for bindings before C++20's
    // P1091 support.
    const auto placed = poses(t);
    const Pose& pa = placed.first;
    const Pose& pb = placed.second;
    const DistanceResult r = query(pa, pb);
    ++out.iterations;
    // The answer at t (copied out only when the loop stops there).
    const auto stop_here = [&](ImpactStatus status) {
      out.status = status;
      out.t = t;
      out.pose_a = pa;
      out.pose_b = pb;
      out.at_t = r;
      return out;
    };
    if (in_contact(r, pa, pb)) {
      // At t = 0: overlapping when the bodies overlap or are strictly within
      // the offset; touching (or at the offset) is a contact at t = 0.
      return stop_here(t == 0.0 &&
                               (r.status == Status::intersecting || r.signed_distance() < target)
                           ? ImpactStatus::intersecting
                           : ImpactStatus::contact);
    }
    if (out.iterations >= options.max_iterations) return stop_here(ImpactStatus::iteration_cap);
    const SafeStep s = safe_step(r, pa, pb, t);
    if (t_end < 1.0 && (s.never || t + s.step >= t_end)) {
      out.status = ImpactStatus::separated;
      out.t = t_end;
      return out;
    }
    if (s.never || t + s.step >= 1.0) {
      // Safe up to the end: the answer at t = 1.
      std::tie(out.pose_a, out.pose_b) = poses(1.0);
      out.at_t = query(out.pose_a, out.pose_b);
      ++out.iterations;
      out.t = 1.0;
      out.status = in_contact(out.at_t, out.pose_a, out.pose_b) ? ImpactStatus::contact
                                                                : ImpactStatus::separated;
      return out;
    }
    if (!(t + s.step > t)) {
      // No safe progress at this precision (bounds within rounding of the
      // target while the distance is not): stop, t is still safe.
      return stop_here(ImpactStatus::iteration_cap);
    }
    t += s.step;
  }
}

// The step that the certified lower bound allows, closing no faster than
// `speed` (the fastest any point of B moves relative to any point of A:
// the distance is 1-Lipschitz in the bodies' motion).
SafeStep lower_bound_step(double lower, double target, double speed) {
  if (!(lower > target)) return {};
  if (!(speed > 0.0)) return {0.0, true};
  return {(lower - target) / speed, false};
}

// A convex hull carried by a moving body: the hull placed in the body's
// frame by `local` (a compound's piece; the identity for a convex body),
// the body moving by `sweep`. The bounds below need the body's reference
// point in the hull's frame (`origin`, local^-1 of the body's origin), the
// lever of the hull's centroid about it and the reach of its vertices.
struct MovingHull {
  MovingHull(const ConvexPolytope& hull_, const Sweep& sweep_, const Pose* local_ = nullptr)
      : hull(&hull_), sweep(&sweep_), local(local_) {
    if (local != nullptr) origin = -(local->rotation.transpose() * local->translation);
    lever = (hull->centroid() - origin).stableNorm();
    reach = lever + hull->bounding_radius();
  }
  // The hull's pose when the body is at `body`.
  Pose placed(const Pose& body) const { return local != nullptr ? body * *local : body; }

  const ConvexPolytope* hull;
  const Sweep* sweep;
  const Pose* local;
  Vec3 origin = Vec3::Zero();
  double lever = 0.0;
  double reach = 0.0;
};

// Conservative advancement of two moving hulls over [t_begin, t_end] (see
// advance), towards options.target_separation, stopping within
// `tolerance` of it.
ImpactResult advance_hulls(const MovingHull& ha, const MovingHull& hb, const ImpactOptions& options,
                           double tolerance, DistanceCache& c, double t_begin = 0.0,
                           double t_end = 1.0) {
  const ConvexPolytope& a = *ha.hull;
  const ConvexPolytope& b = *hb.hull;
  const double target = options.target_separation;
  const Vec3 va = ha.sweep->linear_velocity();
  const Vec3 vb = hb.sweep->linear_velocity();
  const Vec3 wa = ha.sweep->angular_velocity();
  const Vec3 wb = hb.sweep->angular_velocity();
  const double reach_a = ha.reach;
  const double reach_b = hb.reach;
  const double any_speed = (vb - va).stableNorm() + fast_norm(wa) * reach_a + fast_norm(wb) * reach_b;

  const auto poses = [&](double t) {
    return std::pair<Pose, Pose>(ha.placed(ha.sweep->at(t)), hb.placed(hb.sweep->at(t)));
  };
  const auto query = [&](const Pose& pa, const Pose& pb) {
    return distance(a, pa, b, pb, options.distance, &c);
  };
  // Safe steps; the longest is taken. Along the normal n: the gap between
  // a plane that bounds A from above along n and one that bounds B from
  // below, each moving no faster than a bound (PlaneBound), so that the gap
  // is a certified lower bound on the distance until it closes to the
  // target. Three such planes per body: its hull's support plane, which
  // moves along n no faster than the body's speed along n plus the turn's
  // |w x n| times the reach (a point r from the reference point moves along
  // n at (w x r).n = (r x n).w, at most |w x n| |r|: a spin about the
  // normal does not approach); the support plane of its bounding ball (the
  // hull stays inside the ball as it turns), whose lever is only the
  // distance of the ball's center from the reference point: a round body
  // turning about its middle approaches at its linear speed only, so far
  // from contact the ball's planes give the longer step; and the support
  // feature's own plane (FeaturePlane: the true rates of its vertices
  // while they hold the support), which gives the longer step near a
  // contact. In any direction: the certified lower bound closes no
  // faster than any_speed. All keep off the contact band of the accuracy
  // standard at these poses (the rounding of the query's coordinates).
  const double relative_turn = fast_norm(wa - wb);
  MarginMemo memo_a, memo_b;
  FeatureSetMemo sets_a, sets_b;
  EdgePairs edge_pairs;
  edge_pairs.turn_a = fast_norm(wa);
  edge_pairs.turn_b = fast_norm(wb);
  edge_pairs.relative = relative_turn;
  edge_pairs.speed = fast_norm(vb - va);
  edge_pairs.reach_a = reach_a;
  edge_pairs.reach_b = reach_b;
  const auto contact_band_at = [&](const Pose& pa, const Pose& pb) {
    return contact_band(std::max(magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale())));
  };
  const auto safe_step = [&](const DistanceResult& r, const Pose& pa, const Pose& pb, double t) {
    const double band = contact_band_at(pa, pb);
    const Vec3& n = r.normal;
    const SupportPlanes hull = support_planes(a, pa, b, pb, n, c);
    const double turn_a = fast_norm(wa.cross(n));
    const double turn_b = fast_norm(wb.cross(n));
    const double inf = std::numeric_limits<double>::infinity();
    // A's top along n, and B's bottom as -(min along n): both rising at
    // `rate` at most bring them closer. The hull's and the ball's planes
    // have no span limit and no acceleration.
    // The balls' centers along n as the hull's vertices: n.t + (R^T n).c.
    const double along_a = n.dot(pa.translation), along_b = n.dot(pb.translation);
    const double speed_a = va.dot(n), speed_b = vb.dot(n);
    const PlaneBound top_a[2] = {
        {hull.top_a, speed_a + turn_a * reach_a, 0.0, inf},
        {along_a + hull.direction_a.dot(a.centroid()) + a.bounding_radius(),
         speed_a + turn_a * ha.lever, 0.0, inf}};
    const PlaneBound bottom_b[2] = {
        {-hull.bottom_b, -speed_b + turn_b * reach_b, 0.0, inf},
        {-(along_b + hull.direction_b.dot(b.centroid()) - b.bounding_radius()),
         -speed_b + turn_b * hb.lever, 0.0, inf}};
    SafeStep best = lower_bound_step(r.lower_bound - band, target, any_speed);
    // The step of planes x and y without their span limit, or 0 when their
    // gap is already closed.
    const auto unlimited = [&](const PlaneBound& x, const PlaneBound& y) {
      const double gap = -y.value - x.value - band - target;
      if (!(gap > 0.0)) return 0.0;
      return first_closing(gap, x.rate + y.rate, x.acceleration + y.acceleration, inf);
    };
    const auto take = [&](double step) {
      if (step == inf) {
        best.never = true;
      } else {
        best.step = std::max(best.step, step);
      }
    };
    for (const PlaneBound& x : top_a) {
      for (const PlaneBound& y : bottom_b) take(unlimited(x, y));
    }
    if (best.never) return best;
    const double horizon = 1.0 - t;
    // The reference points (a convex body's is its pose's translation).
    const Vec3 origin_a = ha.local != nullptr ? pa.apply(ha.origin) : pa.translation;
    const Vec3 origin_b = hb.local != nullptr ? pb.apply(hb.origin) : pb.translation;
    // The plane through two edges (edge_pair_step): an edge-edge contact
    // closes at its true rate, at second order. Before the feature planes,
    // whose spans it then mostly spares.
    if (r.feature_a.type == FeatureType::edge && r.feature_b.type == FeatureType::edge) {
      const double step = edge_pair_step(a, pa, origin_a, va, wa, r.feature_a, r.point_a, b, pb,
                                         origin_b, vb, wb, r.feature_b, r.point_b, n,
                                         2.0 * band + target, horizon, best.step, edge_pairs);
      if (step > best.step) take(step);
    }
    // The pairs with a feature's plane: its span (costly) only where the
    // step before the span limit beats the best so far.
    const VertexSet& set_a = sets_a.of(a, r.feature_a, hull.vertex_a);
    const VertexSet& set_b = sets_b.of(b, r.feature_b, hull.vertex_b);
    FeaturePlane feature_a(a, pa, ha.origin, set_a, n, hull.direction_a, 1.0, va, wa, turn_a,
                           memo_a);
    FeaturePlane feature_b(b, pb, hb.origin, set_b, n, hull.direction_b, -1.0, vb, wb, turn_b,
                           memo_b);
    const PlaneBound& fa = feature_a.bound();
    const PlaneBound& fb = feature_b.bound();
    const auto with_span = [&](double step, FeaturePlane* x, FeaturePlane* y) {
      if (!(step > best.step)) return;
      if (x != nullptr) step = std::min(step, x->span(step));
      if (y != nullptr) step = std::min(step, y->span(step));
      take(step);
    };
    with_span(unlimited(fa, fb), &feature_a, &feature_b);
    for (const PlaneBound& y : bottom_b) with_span(unlimited(fa, y), &feature_a, nullptr);
    for (const PlaneBound& x : top_a) with_span(unlimited(x, fb), nullptr, &feature_b);
    // The planes fixed in one body (fixed_plane_step), A's top and B's
    // bottom along n, over the rest of the interval; the span of the other
    // body's feature under the relative turn. Only where that body's witness
    // feature is a face, whose plane the support plane then is: a vertex
    // or an edge against it closes at its true rate (second order), where
    // the planes along a fixed n charge the fastest vertex of both
    // features. Against an edge or a vertex the gain is small and the cost
    // shows (bench/toi_bench at N = 8).
    const auto fixed = [&](double step, FeaturePlane& moving) {
      if (!(step > best.step)) return;
      if (relative_turn > 0.0)
        step = std::min(step, moving.margin(step * relative_turn) / relative_turn);
      take(step);
    };
    if (r.feature_a.type == FeatureType::face) {
      fixed(fixed_plane_step(hull.top_a, n, origin_a, va, wa, b, pb, origin_b, vb, wb,
                             feature_b.set(), band + target, horizon),
            feature_b);
    }
    if (r.feature_b.type == FeatureType::face) {
      fixed(fixed_plane_step(-hull.bottom_b, -n, origin_b, vb, wb, a, pa, origin_a, va, wa,
                             feature_a.set(), band + target, horizon),
            feature_a);
    }
    return best;
  };
  return advance(poses, options, tolerance, query, contact_band_at, safe_step, t_begin, t_end);
}

// A ball carried by a moving body: its center in the body's frame.
struct Ball {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};

// Ball steps at most per node or piece pair before the hulls are looked at.
constexpr int kMaxBallSteps = 8;
// The balls' gap, as a fraction of their radii, below which their pair is
// taken as it is (the children's balls, or the hulls' advancement, go on
// from there): closer balls bound the hulls too loosely to be worth more
// steps.
constexpr double kBallCloseEnough = 0.25;

// Two motions' poses at the last time asked for: the candidates split from
// one node pair all start at its time.
class PosesAt {
 public:
  PosesAt(const Sweep& ma, const Sweep& mb) : ma_(&ma), mb_(&mb) {}
  const std::pair<Pose, Pose>& at(double t) {
    if (!(t == t_)) {
      t_ = t;
      poses_ = {ma_->at(t), mb_->at(t)};
    }
    return poses_;
  }

 private:
  const Sweep* ma_;
  const Sweep* mb_;
  double t_ = std::numeric_limits<double>::quiet_NaN();
  std::pair<Pose, Pose> poses_;
};

// One step of the bounds' advancement below, from t by gap / speed: t
// itself when the gap is within `close_enough` (the bounds are close: where
// they are is still a lower bound), infinity when nothing closes or the
// step passes t_end, the next time (> t) otherwise.
[[gnu::always_inline]] inline double advance_by_gap(double t, double gap, double close_enough,
                                                    double speed, double t_end) {
  if (!(gap > close_enough)) return t;
  const double never = std::numeric_limits<double>::infinity();
  if (!(speed > 0.0)) return never;
  const double next = t + gap / speed;
  if (!(next < t_end)) return never;
  return next > t ? next : t;
}

// The earliest time in [t, t_end] at which balls ba (moving with body A)
// and bb (with B) can come within `target` of each other, or infinity when
// they cannot before t_end: conservative advancement on the balls' gap
// |x_b - x_a| - radii, which closes no faster than the centers' relative
// speed, at most |v_b - v_a| + |w_a| |c_a| + |w_b| |c_b| (c the centers'
// offsets from the reference points; `speeds` holds |v_b - v_a|, |w_a|,
// |w_b|). The hulls inside the balls are no closer before that time.
// Stops early once the balls are close (kBallCloseEnough): the time
// returned is then where they are, still a lower bound.
[[gnu::always_inline]] inline double earliest_ball_contact(PosesAt& poses, const Vec3& speeds,
                                                           const Ball& ba, const Ball& bb,
                                                           double target, double t, double t_end) {
  const double speed =
      speeds[0] + speeds[1] * fast_norm(ba.center) + speeds[2] * fast_norm(bb.center);
  const double radii = ba.radius + bb.radius;
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxBallSteps; ++step) {
    const auto& [pa, pb] = poses.at(t);
    const Vec3 xa = pa.apply(ba.center);
    const Vec3 xb = pb.apply(bb.center);
    // Off the rounding of the centers' coordinates.
    const double band =
        contact_band(std::max(xa.cwiseAbs().maxCoeff(), xb.cwiseAbs().maxCoeff()) + radii);
    const double gap = fast_norm(xb - xa) - radii - target - band;
    const double next = advance_by_gap(t, gap, kBallCloseEnough * radii, speed, t_end);
    if (!(next > t && next < never)) return next;
    t = next;
  }
  return t;
}

// A node's or a piece's bound in its body's frame: its ball, and for a
// mesh the node's box or the piece's triangle itself, far closer to what
// it holds than the ball where that is flat (a floor's triangles, and the
// boxes around them).
struct Bound {
  enum class Shape : std::uint8_t { ball, box, triangle };
  explicit Bound(const Ball& b) : ball(b) {}
  Bound(const Ball& b, Shape s, const std::array<Vec3, 3>& c) : ball(b), shape(s), corners(c) {}

  Ball ball;
  Shape shape = Shape::ball;
  std::array<Vec3, 3> corners;  // box: lo, hi; triangle: its corners (unset for a ball)

  // The distance from q (body frame) to the box or the triangle, and the
  // largest coordinate magnitude of q and of the shape (for the rounding).
  double distance_to(const Vec3& q, double& magnitude) const {
    magnitude = q.cwiseAbs().maxCoeff();
    if (shape == Shape::box) {
      magnitude =
          std::max({magnitude, corners[0].cwiseAbs().maxCoeff(), corners[1].cwiseAbs().maxCoeff()});
      return fast_norm((corners[0] - q).cwiseMax(q - corners[1]).cwiseMax(0.0));
    }
    for (const Vec3& x : corners) magnitude = std::max(magnitude, x.cwiseAbs().maxCoeff());
    const ClosestPoints<double> c =
        closest_point_triangle(q, corners[0], corners[1], corners[2], kernel_tolerance(magnitude));
    return fast_norm(c.point_b - q);
  }
};

// earliest_ball_contact where one side's bound is a box or a triangle
// (A's if both are): the gap from the other side's ball to that shape,
// dist(x_o, S) - r_o, is 1-Lipschitz in the ball's center and in the
// shape's points, which (relative to the reference point of the shape's
// body, whose translation the center's speed already counts) move at most
// at |w| (|c| + r) (the shape inside its ball, c its center): it closes no
// faster than |v_b - v_a| + |w_s| (|c_s| + r_s) + |w_o| |c_o|. The same
// rules otherwise: a lower bound on the first time the hulls inside can
// come within the target, infinity when not before t_end.
double earliest_contact(PosesAt& poses, const Vec3& speeds, const Bound& ba, const Bound& bb,
                        double target, double t, double t_end) {
  if (ba.shape == Bound::Shape::ball && bb.shape == Bound::Shape::ball)
    return earliest_ball_contact(poses, speeds, ba.ball, bb.ball, target, t, t_end);
  const bool on_a = ba.shape != Bound::Shape::ball;
  const Bound& shape = on_a ? ba : bb;
  const Ball& other = on_a ? bb.ball : ba.ball;
  const double speed = speeds[0] +
                       speeds[on_a ? 1 : 2] * (fast_norm(shape.ball.center) + shape.ball.radius) +
                       speeds[on_a ? 2 : 1] * fast_norm(other.center);
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxBallSteps; ++step) {
    const auto& [pa, pb] = poses.at(t);
    const Pose& ps = on_a ? pa : pb;
    const Pose& po = on_a ? pb : pa;
    const Vec3 x = po.apply(other.center);
    const Vec3 q = ps.rotation.transpose() * (x - ps.translation);
    double magnitude = 0.0;
    const double d = shape.distance_to(q, magnitude);
    // Off the rounding of the center's coordinates in both frames and of
    // the distance kernel.
    const double band = contact_band(
        std::max({magnitude, x.cwiseAbs().maxCoeff(), ps.translation.cwiseAbs().maxCoeff()}) +
        shape.ball.radius + other.radius);
    const double gap = d - other.radius - target - band;
    const double next = advance_by_gap(t, gap, kBallCloseEnough * other.radius, speed, t_end);
    if (!(next > t && next < never)) return next;
    t = next;
  }
  return t;
}

// A node pair or a piece pair of two compounds, and the earliest time its
// balls allow a contact.
struct Candidate {
  double t = 0.0;
  bool pieces = false;  // a piece pair (a, b piece ids), else a node pair
  std::int32_t a = 0;
  std::int32_t b = 0;
  bool operator>(const Candidate& o) const { return t > o.t; }
};

bool is_identity(const Pose& p) {
  return p.rotation == Mat3::Identity() && p.translation == Vec3::Zero();
}

// One side of the branch and bound over piece pairs: a Body's convex
// pieces under its hierarchy, each node and piece bounded in the body's
// frame. Two kinds, each its own class so that the branch and bound is
// compiled for each pair of kinds (a compound pair pays for no mesh test):
// a compound's pieces (a convex body as its one piece) under its sphere
// tree, bounded by balls (CompoundTree); a mesh's triangles under its box
// tree (MeshTree), each triangle the flat hull of its three corners (a
// segment or a point where it is degenerate), built when its pair is first
// advanced: a mesh's surface first comes within the target where one of
// its triangles does.
class CompoundTree {
 public:
  static constexpr bool kMesh = false;
  explicit CompoundTree(const Body& body) : owner_(body.compound()), c_(owner_.get()) {}

  Ball node_bound(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return {node.center, node.radius};
  }
  bool is_leaf(std::int32_t n) const { return c_->nodes()[static_cast<std::size_t>(n)].left < 0; }
  std::pair<std::int32_t, std::int32_t> children(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return {node.left, node.right};
  }
  // A leaf's pieces: the ids order[first .. first + count).
  std::span<const std::int32_t> pieces(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return c_->piece_order().subspan(static_cast<std::size_t>(node.first),
                                     static_cast<std::size_t>(node.count));
  }
  Ball piece_bound(std::int32_t p) const {
    const auto& sphere = c_->piece_sphere(p);
    return {sphere.center, sphere.radius};
  }
  // The piece's hull and its pose in the body (null: the body's frame).
  const ConvexPolytope& hull(std::int32_t p) { return *c_->piece(p).polytope; }
  const Pose* local(std::int32_t p) const {
    const Pose& pose = c_->piece(p).pose;
    return is_identity(pose) ? nullptr : &pose;
  }
  // The lowest value of n.y over the piece's points y at the body's pose
  // (n unit, world frame): the hull's support vertex along -n by hill
  // climbing (from the last one found: the same piece meets many
  // triangles).
  double lowest(std::int32_t p, const Pose& pose, const Vec3& n) {
    const CompoundPiece& piece = c_->piece(p);
    const Pose placed = pose * piece.pose;
    hint_ = support_hill_climb(*piece.polytope, -(placed.rotation.transpose() * n), hint_);
    return n.dot(placed.apply(piece.polytope->vertex(hint_)));
  }
  // A bound on the distance of the piece's points from the body's
  // reference point (its frame's origin).
  double reach(std::int32_t p) const {
    const auto& sphere = c_->piece_sphere(p);
    return sphere.center.stableNorm() + sphere.radius;
  }

 private:
  std::shared_ptr<const CompoundBody> owner_;
  const CompoundBody* c_;
  int hint_ = 0;  // lowest()'s last support vertex
};

// A triangle's radius and reach computed in doubles are off by a few u
// relative; the speed bounds need every corner inside them, so both are
// taken this hair larger (1e-12 is thousands of u, and costs nothing).
constexpr double kTriangleRadiusGrowth = 1.0 + 1e-12;

class MeshTree {
 public:
  static constexpr bool kMesh = true;
  explicit MeshTree(const Body& body) : mesh_(body.mesh().get()) {}

  Bound node_bound(std::int32_t n) const {
    // The box, and its ball: its center and half diagonal (the rounding of
    // both, a few u of the coordinates, is inside the contact band that
    // earliest_contact keeps off).
    Vec3 lo, hi;
    mesh_->box(n, lo, hi);
    return {Ball{0.5 * (lo + hi), 0.5 * (hi - lo).stableNorm()}, Bound::Shape::box, {lo, hi, hi}};
  }
  bool is_leaf(std::int32_t n) const {
    return mesh_->nodes()[static_cast<std::size_t>(n)].is_leaf();
  }
  std::pair<std::int32_t, std::int32_t> children(std::int32_t n) const {
    return {n + 1, mesh_->nodes()[static_cast<std::size_t>(n)].first_or_right};
  }
  std::span<const std::int32_t> pieces(std::int32_t n) const {
    const TriangleMesh::Node& node = mesh_->nodes()[static_cast<std::size_t>(n)];
    return mesh_->triangle_order().subspan(static_cast<std::size_t>(node.first_or_right),
                                           static_cast<std::size_t>(node.count));
  }
  Bound piece_bound(std::int32_t p) const {
    // The triangle, and its ball about its centroid (the radius a hair
    // out, for its rounding: the speed bound needs every corner inside).
    const auto corners = triangle_corners(p);
    const Vec3 center = (corners[0] + corners[1] + corners[2]) / 3.0;
    double radius = 0.0;
    for (const Vec3& x : corners) radius = std::max(radius, (x - center).stableNorm());
    return {Ball{center, radius * kTriangleRadiusGrowth}, Bound::Shape::triangle, corners};
  }
  const ConvexPolytope& hull(std::int32_t p) {
    auto it = triangles_.find(p);
    if (it == triangles_.end()) {
      const auto corners = triangle_corners(p);
      it = triangles_.emplace(p, ConvexPolytope(std::span<const Vec3>(corners))).first;
    }
    return it->second;
  }
  const Pose* local(std::int32_t) const { return nullptr; }
  double lowest(std::int32_t p, const Pose& pose, const Vec3& n) const {
    double low = std::numeric_limits<double>::infinity();
    for (const Vec3& x : triangle_corners(p)) low = std::min(low, n.dot(pose.apply(x)));
    return low;
  }
  double reach(std::int32_t p) const {
    double r = 0.0;
    for (const Vec3& x : triangle_corners(p)) r = std::max(r, x.stableNorm());
    return r * kTriangleRadiusGrowth;
  }
  std::array<Vec3, 3> triangle_corners(std::int32_t p) const {
    const TriangleMesh::Triangle& t = mesh_->triangle(p);
    return {mesh_->vertex(static_cast<int>(t[0])), mesh_->vertex(static_cast<int>(t[1])),
            mesh_->vertex(static_cast<int>(t[2]))};
  }

 private:
  const TriangleMesh* mesh_;
  // The triangles' hulls built so far (a map: references stay valid).
  std::unordered_map<std::int32_t, ConvexPolytope> triangles_;
};

const Ball& ball_of(const Ball& b) { return b; }
const Ball& ball_of(const Bound& b) { return b.ball; }

// earliest_contact for the bounds of either tree: two balls as
// earliest_ball_contact, else with the box or the triangle.
[[gnu::always_inline]] inline double earliest_of(PosesAt& poses, const Vec3& speeds, const Ball& ba,
                                                 const Ball& bb, double target, double t,
                                                 double t_end) {
  return earliest_ball_contact(poses, speeds, ba, bb, target, t, t_end);
}
template <class BA, class BB>
double earliest_of(PosesAt& poses, const Vec3& speeds, const BA& ba, const BB& bb, double target,
                   double t, double t_end) {
  const auto bound = [](const auto& x) {
    if constexpr (std::is_same_v<std::decay_t<decltype(x)>, Ball>) {
      return Bound(x);
    } else {
      return x;
    }
  };
  return earliest_contact(poses, speeds, bound(ba), bound(bb), target, t, t_end);
}

// Plane steps at most per triangle pair before its hull is built.
constexpr int kMaxPlaneSteps = 4;

// The first time from t that a mesh's triangle (piece `ps` of tree `s`,
// moving by `ms`) and a piece of the other body (`po` of `o`, moving by
// `mo`) can come within `target`, or infinity when not before t_end, by
// conservative advancement on the planes of the triangle's normal n (the
// side towards the other piece's ball): the triangle's highest corner and
// the other piece's lowest point along n bound the distance from below by
// their gap, and along a fixed n a point r from its body's reference point
// moves at most at v.n + |w x n| |r| (as the hulls' planes of
// advance_hulls). Where the triangle faces the other piece (a body landing
// on a floor) this settles most pairs before their triangle's hull is
// built, which costs more than their advancement (exact predicates on
// three coplanar points). Stops at the first step that does not, or after
// kMaxPlaneSteps: the time reached is still a lower bound.
template <class Other>
double triangle_plane_advance(const MeshTree& s, std::int32_t ps, const Sweep& ms, Other& o,
                              std::int32_t po, const Sweep& mo, const Vec3& other_center,
                              double target, double t, double t_end) {
  const auto corners = s.triangle_corners(ps);
  const Vec3 normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  const double length = normal.stableNorm();
  if (!(length > 0.0)) return t;  // a degenerate triangle: its hull decides
  const Vec3 unit = normal / length;
  const double reach_s = s.reach(ps), reach_o = o.reach(po);
  const Vec3 vs = ms.linear_velocity(), vo = mo.linear_velocity();
  const Vec3 ws = ms.angular_velocity(), wo = mo.angular_velocity();
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxPlaneSteps; ++step) {
    const Pose pose_s = ms.at(t), pose_o = mo.at(t);
    const std::array<Vec3, 3> placed = {pose_s.apply(corners[0]), pose_s.apply(corners[1]),
                                        pose_s.apply(corners[2])};
    const Vec3 center = pose_o.apply(other_center);
    // Off the rounding of the placed coordinates.
    const double band = contact_band(std::max(pose_s.translation.cwiseAbs().maxCoeff() + reach_s,
                                              pose_o.translation.cwiseAbs().maxCoeff() + reach_o));
    // Two normals: the triangle's, and the one from its closest point to
    // the other piece's ball center (where the triangle's plane cuts the
    // other piece beside the triangle); the longer step of the two.
    std::array<Vec3, 2> normals = {pose_s.rotation * unit, Vec3::Zero()};
    if (normals[0].dot(center - placed[0]) < 0.0) normals[0] = -normals[0];
    const Vec3 foot = closest_point_triangle(center, placed[0], placed[1], placed[2],
                                             kernel_tolerance(band / kUnitRoundoff))
                          .point_b;
    const double apart = fast_norm(center - foot);
    const int count = apart > 0.0 ? 2 : 1;
    if (count == 2) normals[1] = (center - foot) / apart;
    double longest = 0.0;
    for (int k = 0; k < count; ++k) {
      const Vec3& n = normals[static_cast<std::size_t>(k)];
      double top = -std::numeric_limits<double>::infinity();
      for (const Vec3& x : placed) top = std::max(top, n.dot(x));
      const double gap = o.lowest(po, pose_o, n) - top - target - band;
      if (!(gap > 0.0)) continue;
      const double rate =
          (vs - vo).dot(n) + fast_norm(ws.cross(n)) * reach_s + fast_norm(wo.cross(n)) * reach_o;
      if (!(rate > 0.0)) return never;
      longest = std::max(longest, gap / rate);
    }
    const double next = t + longest;
    if (!(next < t_end)) return never;
    if (!(next > t)) return t;
    t = next;
  }
  return t;
}

// Time of impact of two Bodies made of convex pieces (CompoundTree,
// MeshTree: compounds, a convex body as its one piece, meshes' triangles):
// the earliest over piece pairs of their convex advancement, by branch and
// bound over the two hierarchies. Candidates (node or piece pairs) are
// taken in order of the earliest time their moving bounds allow a contact
// (earliest_of); a node pair is split into its children's pairs, a piece
// pair is first advanced on its triangle's planes where one side is a mesh
// (triangle_plane_advance), then advanced as two hulls (from the time
// reached on, and only up to the best time found, since a later contact
// changes nothing); everything from the best time on is pruned. Each rule keeps the
// guarantee: a pruned pair cannot come within the target before the
// reported t, and every pair advanced is advanced safely.
template <class TreeA, class TreeB>
ImpactResult pieces_time_of_impact(const Body& a, const Sweep& ma, const Body& b, const Sweep& mb,
                                   const ImpactOptions& options, double tolerance, BodyCache& c) {
  TreeA ta(a);
  TreeB tb(b);
  ImpactOptions pair_options = options;
  pair_options.target_separation += a.radius() + b.radius();
  pair_options.tolerance = tolerance;
  const double target = pair_options.target_separation;

  ImpactResult best;               // separated at 1 until a pair says otherwise
  bool met = false;                // a pair's advancement stopped before the end
  CompoundCache::Entry best_pair;  // its pieces and its cache at best.t
  int iterations = 0, pairs = 0;
  // Whether a pair whose contact cannot come before t may still change the
  // answer: before the best time, or at 0 while the best is a contact at 0
  // (an overlapping pair there is the answer).
  const auto may_beat = [&](double t) {
    return t < best.t || (t == 0.0 && best.t == 0.0 && best.status == ImpactStatus::contact);
  };
  // The better of two answers at the same time: overlapping, then contact,
  // then the iteration cap.
  const auto rank = [](ImpactStatus s) {
    return s == ImpactStatus::intersecting ? 0 : s == ImpactStatus::contact ? 1 : 2;
  };

  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
  PosesAt poses(ma, mb);
  // |v_b - v_a|, |w_a|, |w_b|: the balls' speeds.
  const Vec3 speeds((mb.linear_velocity() - ma.linear_velocity()).stableNorm(),
                    fast_norm(ma.angular_velocity()), fast_norm(mb.angular_velocity()));
  const auto push = [&](Candidate k, const auto& ba, const auto& bb) {
    k.t = earliest_of(poses, speeds, ba, bb, target, k.t, best.t);
    if (may_beat(k.t)) queue.push(k);
  };
  push({0.0, false, 0, 0}, ta.node_bound(0), tb.node_bound(0));
  while (!queue.empty()) {
    const Candidate k = queue.top();
    queue.pop();
    if (!may_beat(k.t)) break;  // every later candidate starts later still
    if (k.pieces) {
      // A mesh's triangle: its planes first (triangle_plane_advance).
      double from = k.t;
      if constexpr (TreeA::kMesh) {
        from = triangle_plane_advance(ta, k.a, ma, tb, k.b, mb, ball_of(tb.piece_bound(k.b)).center,
                                      target, from, best.t);
      } else if constexpr (TreeB::kMesh) {
        from = triangle_plane_advance(tb, k.b, mb, ta, k.a, ma, ball_of(ta.piece_bound(k.a)).center,
                                      target, from, best.t);
      }
      if (!may_beat(from)) continue;
      const MovingHull ha(ta.hull(k.a), ma, ta.local(k.a));
      const MovingHull hb(tb.hull(k.b), mb, tb.local(k.b));
      DistanceCache pair_cache;
      ImpactResult r = advance_hulls(ha, hb, pair_options, tolerance, pair_cache, from, best.t);
      iterations += r.iterations;
      ++pairs;
      if (r.status != ImpactStatus::separated &&
          (r.t < best.t || (r.t == best.t && (best.status == ImpactStatus::separated ||
                                              rank(r.status) < rank(best.status))))) {
        best.t = r.t;
        best.status = r.status;
        met = true;
        best_pair = {k.a, k.b, std::move(pair_cache)};
      }
      continue;
    }
    const auto na = ta.node_bound(k.a);
    const auto nb = tb.node_bound(k.b);
    const bool leaf_a = ta.is_leaf(k.a), leaf_b = tb.is_leaf(k.b);
    if (leaf_a && leaf_b) {
      for (const std::int32_t pa : ta.pieces(k.a)) {
        const auto ba = ta.piece_bound(pa);
        for (const std::int32_t pb : tb.pieces(k.b))
          push({k.t, true, pa, pb}, ba, tb.piece_bound(pb));
      }
    } else if (leaf_b || (!leaf_a && ball_of(na).radius >= ball_of(nb).radius)) {
      const auto [left, right] = ta.children(k.a);
      for (const std::int32_t child : {left, right})
        push({k.t, false, child, k.b}, ta.node_bound(child), nb);
    } else {
      const auto [left, right] = tb.children(k.b);
      for (const std::int32_t child : {left, right})
        push({k.t, false, k.a, child}, na, tb.node_bound(child));
    }
  }

  // The answer at the best time (1 when no pair met): the Bodies' query
  // there, whose closest pair and features describe it. Between compounds
  // the pair that met seeds the query's cache (tried first, with its
  // features at that time): its distance is the first bound of the query's
  // branch and bound.
  if (met && !TreeA::kMesh && !TreeB::kMesh) {
    c.compound.piece_a = best_pair.piece_a;
    c.compound.piece_b = best_pair.piece_b;
    const auto less = [](const CompoundCache::Entry& x, const CompoundCache::Entry& y) {
      return std::pair(x.piece_a, x.piece_b) < std::pair(y.piece_a, y.piece_b);
    };
    auto& near = c.compound.near;
    if (std::is_sorted(near.begin(), near.end(), less)) {
      const auto it = std::lower_bound(near.begin(), near.end(), best_pair, less);
      if (it != near.end() && it->piece_a == best_pair.piece_a &&
          it->piece_b == best_pair.piece_b) {
        *it = std::move(best_pair);
      } else {
        near.insert(it, std::move(best_pair));
      }
    }
  }
  const Pose pose_a = ma.at(best.t);
  const Pose pose_b = mb.at(best.t);
  const BodyResult at = distance(a, pose_a, b, pose_b, options.distance, &c);
  ImpactResult out;
  out.t = best.t;
  out.status = best.status;
  out.pose_a = pose_a;
  out.pose_b = pose_b;
  out.at_t = at;
  out.piece_a = a.kind() == Body::Kind::mesh ? at.triangle_a : at.piece_a;
  out.piece_b = b.kind() == Body::Kind::mesh ? at.triangle_b : at.piece_b;
  out.iterations = iterations + 1;
  out.pairs_advanced = pairs;
  if (!met && (at.status == Status::intersecting || at.status == Status::touching ||
               at.signed_distance() <= options.target_separation + tolerance)) {
    // No pair met before 1, and the bodies are within the tolerance at 1.
    out.status = ImpactStatus::contact;
  }
  return out;
}

}  // namespace

ImpactResult time_of_impact(const ConvexPolytope& a, const Motion& motion_a,
                            const ConvexPolytope& b, const Motion& motion_b,
                            const ImpactOptions& options, DistanceCache* cache) {
  detail::check_impact_options(options, "time_of_impact");
  const Sweep ma = checked_sweep(motion_a, a.scale(), "time_of_impact: motion_a");
  const Sweep mb = checked_sweep(motion_b, b.scale(), "time_of_impact: motion_b");
  check_closing_speed(ma, a.scale(), mb, b.scale());
  const double tolerance = options.tolerance > 0.0
                               ? options.tolerance
                               : detail::kDefaultImpactTolerance *
                                     (a.bounding_radius() + b.bounding_radius());
  DistanceCache local;
  return advance_hulls(MovingHull(a, ma), MovingHull(b, mb), options, tolerance,
                       cache != nullptr ? *cache : local);
}

ImpactResult time_of_impact(const Body& a, const Motion& motion_a, const Body& b,
                            const Motion& motion_b, const ImpactOptions& options,
                            BodyCache* cache) {
  detail::check_impact_options(options, "time_of_impact");
  BodyCache local;
  BodyCache& c = cache != nullptr ? *cache : local;
  const double ra = a.radius();
  const double rb = b.radius();
  const double default_tolerance = detail::kDefaultImpactTolerance * (body_size(a) + body_size(b));
  if (a.kind() == Body::Kind::convex && b.kind() == Body::Kind::convex) {
    // The cores, with the radii added to the target; then the answer at t
    // moved onto the rounded surfaces.
    ImpactOptions cores = options;
    cores.target_separation += ra + rb;
    if (cores.tolerance == 0.0) cores.tolerance = default_tolerance;
    ImpactResult r = time_of_impact(*a.convex(), motion_a, *b.convex(), motion_b, cores, &c.convex);
    r.at_t = distance(a, r.pose_a, b, r.pose_b, options.distance, &c);
    return r;
  }

  const Sweep ma = checked_sweep(motion_a, a.scale(), "time_of_impact: motion_a");
  const Sweep mb = checked_sweep(motion_b, b.scale(), "time_of_impact: motion_b");
  check_closing_speed(ma, a.scale(), mb, b.scale());
  const double tolerance = options.tolerance > 0.0 ? options.tolerance : default_tolerance;
  // A closed mesh has an inside: a body that starts there overlaps it
  // without touching a triangle. Otherwise the surfaces first come within
  // the target where two pieces do (a body outside a closed mesh enters
  // it only through a triangle), which the branch and bound finds.
  const auto closed = [](const Body& body) {
    return body.kind() == Body::Kind::mesh && body.mesh()->is_closed();
  };
  if (closed(a) || closed(b)) {
    const Pose pa = ma.at(0.0);
    const Pose pb = mb.at(0.0);
    const BodyResult at = distance(a, pa, b, pb, options.distance, &c);
    const double target = options.target_separation;
    if (at.status == Status::intersecting || at.signed_distance() < target) {
      ImpactResult out;
      out.status = ImpactStatus::intersecting;
      out.t = 0.0;
      out.pose_a = pa;
      out.pose_b = pb;
      out.at_t = at;
      out.piece_a = a.kind() == Body::Kind::mesh ? at.triangle_a : at.piece_a;
      out.piece_b = b.kind() == Body::Kind::mesh ? at.triangle_b : at.piece_b;
      out.iterations = 1;
      return out;
    }
  }
  const bool mesh_a = a.kind() == Body::Kind::mesh, mesh_b = b.kind() == Body::Kind::mesh;
  if (mesh_a && mesh_b)
    return pieces_time_of_impact<MeshTree, MeshTree>(a, ma, b, mb, options, tolerance, c);
  if (mesh_a)
    return pieces_time_of_impact<MeshTree, CompoundTree>(a, ma, b, mb, options, tolerance, c);
  if (mesh_b)
    return pieces_time_of_impact<CompoundTree, MeshTree>(a, ma, b, mb, options, tolerance, c);
  return pieces_time_of_impact<CompoundTree, CompoundTree>(a, ma, b, mb, options, tolerance, c);
}

}  // namespace proxima
