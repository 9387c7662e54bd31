// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Internal (motion layer): the bounds on how fast two moving hulls' support
// planes, witness features' planes and edge pairs can close, from which
// advance_hulls takes its safe steps. Inline in a header, included by
// advancement.cpp alone: the safe step calls these in its inner loop, and
// the build has no link-time optimization to inline them across files.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "proxima/geometry/closest_point.h"
#include "proxima/shape/polytope.h"
#include "proxima/shape/support.h"
#include "sweep.h"

namespace proxima::detail::toi {

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

inline SupportPlanes support_planes(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
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
inline constexpr double kConeMarginShrink = 1.0 - 1e-9;

// The largest face taken whole into S (bigger faces: S is the witness
// feature's vertices and the support vertex only). The margin loop costs
// |S| times the degree times |S|.
inline constexpr std::size_t kMaxFeatureVertices = 16;

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

inline VertexSet feature_set(const ConvexPolytope& body, const Feature& feature, int support) {
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
inline constexpr double kMarginSlack = 1e-14;

// Squared cone margins below this count as none: a square in the
// subnormals may have been rounded up (margins below 2^-450, whose spans
// are no use anyway).
inline constexpr double kSmallestSquaredMargin = 0x1p-900;

// How far the unit direction seen from a body (`direction`, times `sign`)
// may turn, as |e(t) - e(0)|, before a neighbour of the vertex set S may
// overtake S's highest vertex: the smallest margin of PlaneBound's comment,
// a hair inside, >= 0 (0 when S does not hold the support).
inline double cone_margin(const ConvexPolytope& body, const VertexSet& set, const Vec3& direction,
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
inline double first_closing(double gap0, double rate, double acceleration, double span) {
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
inline double widest_closing(double gap0, double rate, const Acceleration& acceleration, double span) {
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
inline double fixed_plane_step(double plane, const Vec3& d, const Vec3& origin_f, const Vec3& v_f,
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

// The rounding of |w_r x e| (e unit, each product a few u of |w_r|) as
// a fraction of |w_r|: 1e-14 is about 45 u, and an arc rate a few u too
// small would let an edge's support be passed by that much.
inline constexpr double kTurnRateSlack = 1e-14;

// The longest s for which the arc bound of edge_pair_step's comment (below),
// (k s + g s^2 / 2) / (rho0 - wr s), stays within `margin`: the root of
// g s^2 / 2 + (k + margin wr) s - margin rho0, written without
// cancellation (wr > 0 and margin > 0, so the denominator is positive).
inline double edge_turn_span(double k, double g, double margin, double rho0, double wr) {
  const double p = k + margin * wr;
  return 2.0 * margin * rho0 / (p + std::sqrt(p * p + 2.0 * g * margin * rho0));
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
// |w_r| s, kept >= rho(0) / 2 by the horizon. Each edge holds its body's
// support while the arc that m has turned through, seen from that body,
// is below the edge's cone margin (cone_margin of its two vertices along
// m; an arc is more than the chord the margins bound). Seen from A, e_a
// stands still and e_b turns at w_r x e_b, so m = c / rho turns at most at
// |w_r x e_b(s)| / rho(s) (the projection in m' only shortens c'); that
// is at most |w_r| / rho, so by time s the arc is at most -ln(1 - |w_r| s
// / rho(0)), and the edge holds for s <= rho(0) (1 - e^-margin) / |w_r|.
// Where the relative turn is about the other edge's own line (a bar
// spinning about an axis along the cube edge it sweeps over: w_r x e_a =
// 0, so m stands still in the bar) the arc is far shorter, and that
// matters for a sliver whose two long edges are 1e-4 rad apart: its cone
// margin is 1e-4, and the bound by |w_r| alone held each step to a turn
// of 1e-4 rad (issue 25, toi_spin_wrap.sh). The finer bound, from A
// (B alike with a and b swapped): e_b turns at |w_b|, so |w_r x e_b(s)|
// <= k + g s with k = |w_r x e_b(0)|, g = |w_r| |w_b|, and the arc is at
// most (k s + g s^2 / 2) / (rho(0) - |w_r| s) (edge_turn_span). The
// witness points are the query's (off the edge lines by a few u R in the
// body frames, which stays so as they move: inside the band),
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
inline constexpr double kMinEdgePairSine = 0.5;

inline double edge_pair_step(const ConvexPolytope& a, const Pose& pa, const Vec3& origin_a, const Vec3& va,
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
  if (!(margin_a > 0.0) || !(margin_b > 0.0)) return 0.0;
  // Each edge's span: the longer of the two arc bounds (both hold), the
  // coarse one s <= rho(0) (1 - e^-margin) / |w_r| with 1 - e^-x >= x (1 -
  // x / 2) (margins are <= 1), and edge_turn_span's.
  const Vec3 w_r = wb - wa;
  const double slack = kTurnRateSlack * wr;
  const double seen_from_a = fast_norm(w_r.cross(edge_b)) / fast_norm(edge_b) + slack;
  const double seen_from_b = fast_norm(w_r.cross(edge_a)) / fast_norm(edge_a) + slack;
  const auto edge_span = [&](double margin, double rate0, double growth) {
    return std::max(margin * (1.0 - 0.5 * margin) * rho / wr,
                    edge_turn_span(rate0, growth, margin, rho, wr));
  };
  span = std::min(
      {span, edge_span(margin_a, seen_from_a, wr * nb), edge_span(margin_b, seen_from_b, wr * na)});
  return std::min(step, span);
}

}  // namespace proxima::detail::toi
