// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The GJK baselines: classic GJK (Gilbert, Johnson & Keerthi 1988) and
// Cameron's Enhanced GJK (1997), both in A's frame.
//
// GJK in one paragraph. The distance between hulls A and B is the distance
// from the origin to their Minkowski difference C = A - B, whose vertices are
// differences a_i - b_j of hull vertices. GJK keeps a simplex Y of at most
// four points of C and the closest point v of conv(Y) to the origin. The
// support point w = argmin over C of v.x = s_A(-v) - s_B(v) then gives:
//   - a certified lower bound: every x in C has v.x >= v.w, hence
//     |x| >= v.w / |v| (the support plane through w separates the origin
//     from C by that much);
//   - an upper bound |v| (v is a point of C).
// If w does not close the gap, Y + w is solved for its closest point, which
// keeps the smallest sub-simplex realizing it; |v| strictly decreases, and as
// C has finitely many vertices the loop ends. Stopping rules (van den
// Bergen 1999): the gap |v| - v.w/|v| is within the relative tolerance (the
// same Re d test as the hybrid's eq. 19, so both stop at the same certified
// gap) plus rounding, w's vertex pair is already in Y, |v| did not decrease
// (rounding has taken over), |v| is in the contact band, or the cap.
//
// Each simplex point carries its vertex pair (i in A, j in B), so the closest
// points are sum(lambda_k a_ik) and sum(lambda_k b_jk) with the barycentric
// weights lambda of v; the ids and those points give the witness features
// (witness_features.h, the rule the hybrid uses too).
//
// Enhanced GJK differs in two places only: the support points come from hill
// climbing over the vertex adjacency, starting from the previous answers
// (near constant time under coherence), and the first simplex is the last
// query's final simplex, re-evaluated at the current pose. Any four points of
// C are a valid start for GJK (only the first closest point changes), so a
// stale or foreign cache can only cost iterations.
//
// Units. All simplex arithmetic runs on coordinates divided by a power of two
// near the bodies' magnitude: exact, and it keeps the cubic terms (face
// normals dotted with points) away from overflow and underflow whatever the
// scale.
#include "proxima/detail/narrowphase/gjk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/accuracy.h"
#include "narrowphase/gjk_contact.h"
#include "narrowphase/gjk_frame.h"
#include "narrowphase/simplex_solver.h"
#include "narrowphase/witness_features.h"
#include "proxima/geometry/closest_point.h"

namespace proxima {
namespace {

using detail::BruteForceSupport;
using detail::GjkFrame;
using detail::HillClimbSupport;
using detail::idx;
using detail::Points;
using detail::Simplex;
using detail::SupportPoint;

// The termination test's rounding slack (core/accuracy.h) is in units of
// u * max|w| (the largest simplex point seen, in scaled units): v.w and |v|
// are sums of products of coordinates of that size and v itself is rebuilt
// from the simplex points (|w| <= 2 sqrt(3) R).
using detail::kTerminationGapUlps;

// ---------------------------------------------------------------------------
// Polishing a stalled simplex.
//
// GJK works on differences a - b of hull points. When the bodies sit far
// from the origin or far apart in size, a simplex mixes points of C near
// the origin with points of C as large as the bodies, and its closest point
// is a small difference of large quantities: the solver's rounding (a few u
// of the largest point, times the conditioning of a thin simplex) can hide
// a step that would bring |v| from many bands down to 0. The loop then
// stops on "|v| did not decrease" with a lower bound of 0, and the answer
// was `touching` at a distance of 700 bands (two boxes' vertex on a
// segment's end 1e12 from the origin: GjkRegression.TouchingFarFromTheOrigin).
//
// The hull vertices behind the simplex and the stalled support point are
// the features the answer lies on. Their closest points in closed form (the
// kernels of closest_point.h, which work on the vertices themselves, not on
// their differences, and drop inactive vertices) give a new v, exact to a
// few u of the coordinates; the simplex becomes the pairs of the kernel's
// active vertices, whose weights are the products of the two sides'
// coefficients (sum l_i m_j (a_i - b_j) = sum l_i a_i - sum m_j b_j). The
// support along the new v tests the gap as the loop does; a new support
// point is polished the same way. |v| strictly decreases and each round
// costs an iteration, so it ends.
// ---------------------------------------------------------------------------

// The polished answer: the active hull vertices of each body with their
// coefficients (the final points are formed from them as from the
// simplex's weights), and how the polish ended.
struct Polished {
  bool have = false;       // the kernels improved on the stalled |v|
  bool contact = false;    // |v| reached the band
  bool certified = false;  // the gap test passed
  bool capped = false;     // stopped undecided at options.max_iterations
  std::array<std::int32_t, 3> ids_a{};
  std::array<std::int32_t, 3> ids_b{};
  std::array<double, 3> coef_a{};
  std::array<double, 3> coef_b{};
  int na = 0;
  int nb = 0;
};

// Up to four hull vertices of one body, the features of a polishing round:
// the stalled simplex's (at most three a side) and the new support point's.
using FourPoints = std::array<Vec3, 4>;

// The closest points of conv(pa[0..na)) and conv(pb[0..nb)), na and nb in
// 1..4, with the kernel's coefficients and active bits over those indices.
// A side of four vertices is the union of its four triangles' hulls' boundary
// (a tetrahedron's surface, or a flat quadrilateral, which two of them
// cover): the minimum over them is the features' distance unless the other
// feature lies inside the tetrahedron, and even then it is the distance of
// points of the two hulls, an upper bound that only the gap test certifies.
// Polishing a simplex of three vertex pairs whose support point brought a
// fourth vertex of a polygon or a cloud gave up before, and GJK answered
// `touching` 31 bands away (GjkRegression.StalledSimplexWithAFourthVertex).
struct FeatureClosest {
  ClosestPoints<double> c;              // points and squared distance
  std::array<double, 4> coef_a{}, coef_b{};
  std::uint8_t active_a = 0, active_b = 0;
};
FeatureClosest closest_of_features(const FourPoints& pa, int na, const FourPoints& pb, int nb,
                                   const KernelTolerance<double>& tol) {
  static constexpr std::array<std::array<int, 3>, 4> kTriangles = {
      {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
  static constexpr std::array<int, 3> kFirst = {0, 1, 2};
  FeatureClosest best;
  bool have = false;
  for (int i = 0; i < (na == 4 ? 4 : 1); ++i) {
    for (int j = 0; j < (nb == 4 ? 4 : 1); ++j) {
      const std::array<int, 3>& ta = na == 4 ? kTriangles[idx(i)] : kFirst;
      const std::array<int, 3>& tb = nb == 4 ? kTriangles[idx(j)] : kFirst;
      const int ma = std::min(na, 3);
      const int mb = std::min(nb, 3);
      std::array<Vec3, 3> sa;
      std::array<Vec3, 3> sb;
      for (int k = 0; k < ma; ++k) sa[idx(k)] = pa[idx(ta[idx(k)])];
      for (int k = 0; k < mb; ++k) sb[idx(k)] = pb[idx(tb[idx(k)])];
      const ClosestPoints<double> c = closest_points<double>(sa.data(), ma, sb.data(), mb, tol);
      if (have && !(c.distance_squared < best.c.distance_squared)) continue;
      have = true;
      best.c = c;
      best.coef_a = {};
      best.coef_b = {};
      best.active_a = 0;
      best.active_b = 0;
      for (int k = 0; k < ma; ++k) {
        if (!(c.active_a & (1u << k))) continue;
        best.active_a = static_cast<std::uint8_t>(best.active_a | (1u << ta[idx(k)]));
        best.coef_a[idx(ta[idx(k)])] = c.coef_a[idx(k)];
      }
      for (int k = 0; k < mb; ++k) {
        if (!(c.active_b & (1u << k))) continue;
        best.active_b = static_cast<std::uint8_t>(best.active_b | (1u << tb[idx(k)]));
        best.coef_b[idx(tb[idx(k)])] = c.coef_b[idx(k)];
      }
    }
  }
  return best;
}

// The direction along which the support of C certifies the polished
// features' distance: their closest points' difference v, made exact in
// the directions the features span. v = point_a - point_b is a difference
// of points each rounded by about u R, so its direction is off by u R / |v|;
// along a needle of length L that tilt moves the support value by L u R /
// |v|, more than |v| itself while |v| < sqrt(L u R): the gap test could
// not pass, the support point came back from the features themselves, and
// the polish stopped with a lower bound of 0 and GJK's answer 11,800 bands
// above a distance of 6e-5 bands (GjkRegression.StalledNeedlesReachTheDistance).
// The directions the closest features span are exact (differences of
// their vertices): the normal of an edge pair or of a face is their cross
// product, accurate to a few u whatever |v| (face_normal), and for a vertex
// on an edge v's component along the edge is removed. Any direction gives a
// valid lower bound (the support plane separates by that much); this one
// gives the distance of the features.
Vec3 certifying_direction(const GjkFrame& frame, const Polished& f, const Vec3& v) {
  const auto edges = [](const std::array<std::int32_t, 3>& ids, int n, auto&& point,
                        std::array<Vec3, 2>& out) {
    for (int k = 1; k < n; ++k)
      out[idx(k - 1)] = detail::exponent_free(Vec3(point(ids[idx(k)]) - point(ids[0])));
    return std::max(n - 1, 0);
  };
  std::array<Vec3, 2> ea;
  std::array<Vec3, 2> eb;
  const int ka = edges(f.ids_a, f.na, [&](std::int32_t id) { return frame.a.vertex(id); }, ea);
  const int kb = edges(f.ids_b, f.nb, [&](std::int32_t id) { return frame.b_point(id); }, eb);
  // Two spanning directions: a face's two edges, or an edge from each side.
  const Vec3* plane[2] = {nullptr, nullptr};
  if (ka == 2) {
    plane[0] = &ea[0];
    plane[1] = &ea[1];
  } else if (kb == 2) {
    plane[0] = &eb[0];
    plane[1] = &eb[1];
  } else if (ka == 1 && kb == 1) {
    plane[0] = &ea[0];
    plane[1] = &eb[0];
  }
  if (plane[0] != nullptr) {
    Vec3 n = detail::face_normal(*plane[0], *plane[1]).n;
    // Edges parallel to within the kernels' threshold span a line only.
    if (n.squaredNorm() > kParallelSinFactor * kParallelSinFactor * kUnitRoundoff * kUnitRoundoff *
                              plane[0]->squaredNorm() * plane[1]->squaredNorm()) {
      const double along = n.dot(v);
      if (along < 0.0) n = -n;
      if (along != 0.0) return n;
    }
  }
  const Vec3* line = ka >= 1 ? &ea[0] : kb >= 1 ? &eb[0] : nullptr;
  if (line != nullptr && line->squaredNorm() > 0.0) {
    const Vec3 n = v - (v.dot(*line) / line->squaredNorm()) * *line;
    if (n.squaredNorm() > 0.0) return n;
  }
  return v;
}

template <class Support>
Polished polish_stalled(const GjkFrame& frame, const DistanceOptions& options, double tol,
                        Simplex& simplex, SupportPoint w, Support& support, int& iterations,
                        double& lower, double& w_max2) {
  const KernelTolerance<double> kernel_tol = kernel_tolerance(frame.magnitude * frame.inv_unit);
  const auto add = [](std::array<std::int32_t, 4>& ids, int& n, std::int32_t id) {
    for (int k = 0; k < n; ++k)
      if (ids[idx(k)] == id) return true;
    if (n == 4) return false;  // closest_of_features takes at most four a side
    ids[idx(n++)] = id;
    return true;
  };
  Polished out;
  // The first features: the stalled simplex's vertices of each body.
  std::array<std::int32_t, 4> ids_a{};
  std::array<std::int32_t, 4> ids_b{};
  int na = 0;
  int nb = 0;
  for (int k = 0; k < simplex.size; ++k) {
    if (!add(ids_a, na, simplex.p[idx(k)].ia) || !add(ids_b, nb, simplex.p[idx(k)].ib))
      return out;
  }
  // Whether the features of the last round were already searched along
  // their certifying direction without a decrease: then nothing is left.
  bool retried = false;
  for (;;) {
    if (!add(ids_a, na, w.ia) || !add(ids_b, nb, w.ib)) return out;
    FourPoints pa;
    FourPoints pb;
    for (int k = 0; k < na; ++k) pa[idx(k)] = frame.a.vertex(ids_a[idx(k)]) * frame.inv_unit;
    for (int k = 0; k < nb; ++k) pb[idx(k)] = frame.b_point(ids_b[idx(k)]) * frame.inv_unit;
    const FeatureClosest f = closest_of_features(pa, na, pb, nb, kernel_tol);
    const ClosestPoints<double>& c = f.c;
    // The features as searched (at most three a side) and reduced to the
    // kernel's active vertices (at most three a side: the kernels take
    // triangles).
    Polished searched;
    searched.na = std::min(na, 3);
    searched.nb = std::min(nb, 3);
    std::copy_n(ids_a.begin(), searched.na, searched.ids_a.begin());
    std::copy_n(ids_b.begin(), searched.nb, searched.ids_b.begin());
    Polished features;
    for (int i = 0; i < na; ++i) {
      if (!(f.active_a & (1u << i))) continue;
      features.ids_a[idx(features.na)] = ids_a[idx(i)];
      features.coef_a[idx(features.na++)] = f.coef_a[idx(i)];
    }
    for (int j = 0; j < nb; ++j) {
      if (!(f.active_b & (1u << j))) continue;
      features.ids_b[idx(features.nb)] = ids_b[idx(j)];
      features.coef_b[idx(features.nb++)] = f.coef_b[idx(j)];
    }
    std::copy(features.ids_a.begin(), features.ids_a.end(), ids_a.begin());
    std::copy(features.ids_b.begin(), features.ids_b.end(), ids_b.begin());
    na = features.na;
    nb = features.nb;
    const bool decrease = c.distance_squared < simplex.vv;
    if (decrease) {
      retried = false;
      out = features;
      out.have = true;
      // The simplex: the pairs of active vertices, at most four of them
      // (points of C for the contact classification's seed and the cache;
      // the final points come from the coefficients above). A crossing or
      // parallel pair has more: any four are points of C all the same.
      Simplex next;
      for (int i = 0; i < na && next.size < 4; ++i) {
        for (int j = 0; j < nb && next.size < 4; ++j) {
          next.p[idx(next.size)] = frame.point(ids_a[idx(i)], ids_b[idx(j)]);
          next.lambda[idx(next.size++)] = out.coef_a[idx(i)] * out.coef_b[idx(j)];
        }
      }
      next.v = c.point_a - c.point_b;
      next.vv = c.distance_squared;
      simplex = next;
      if (simplex.vv <= tol * tol) {
        out.contact = true;
        return out;
      }
    } else if (retried) {
      return out;
    } else {
      // The features realize |v| as well as the kernels can tell, and the
      // support along v brought nothing closer: v's direction may be
      // rounding's (certifying_direction); search once along theirs, as
      // searched: a support point that the kernels put on the features'
      // face but not in their closest feature (a nearly flat face, the
      // origin's foot on its diagonal) spans the plane whose normal the
      // closest feature alone leaves undecided
      // (GjkRegression.FlatFaceAboveATouchingApexReachesIt).
      retried = true;
    }
    if (iterations >= options.max_iterations) {
      out.capped = true;
      return out;
    }
    const double v_norm = std::sqrt(simplex.vv);
    const Vec3 n = certifying_direction(frame, decrease ? features : searched,
                                        Vec3(c.point_a - c.point_b));
    w = support(-n);
    ++iterations;
    w_max2 = std::max(w_max2, w.w.squaredNorm());
    lower = std::max(lower, n.dot(w.w) / n.norm());
    // Only the gap certifies: support points already in the features with
    // the gap open mean the kernels' reductions (a needle's width below
    // 4 u R) hide the answer, not that v is optimal
    // (GjkTouching.NeedlesSideBySideTouch). The next round then finds no
    // decrease and leaves the answer uncertified.
    if (v_norm - lower <=
        options.relative_tolerance * v_norm + kTerminationGapUlps * kUnitRoundoff * std::sqrt(w_max2)) {
      out.certified = true;
      return out;
    }
  }
}

// The status of an answer that did not reach the contact band, from what
// it certifies (docs/accuracy.md): separated when its lower bound or its
// closed gap certifies the distance and that is above the band; touching
// when the distance is within the band. An answer left uncertified (a
// stall that neither the polish nor the stall plane's normal could close)
// within kExtendedBands bands is touching too: distance() recomputes its
// witness pair in double-double there and decides the status from it
// (query/extended_distance.h). Farther out nothing decides it, and its
// bounds [lower_bound, distance] are all it knows: iteration_cap, the
// status of an undecided answer whose bounds hold, never a touching
// answer thousands of bands from contact
// (GjkStatus.FollowsTheCertifiedBoundsOnEveryExit). The band there is at
// least that of GJK's own frame, so that an answer re-solved with the
// exact R's smaller band (distance.cpp, finish_query) keeps the
// refinement's range.
Status bounded_status(double distance, double contact_tolerance, const GjkFrame& frame,
                      bool separation_certified) {
  if (distance > contact_tolerance && separation_certified) return Status::separated;
  if (distance <= contact_tolerance) return Status::touching;
  const double refined = detail::kExtendedBands *
                         std::max(contact_tolerance, contact_band(frame.magnitude));
  return distance <= refined ? Status::touching : Status::iteration_cap;
}

// ---------------------------------------------------------------------------
// The loop shared by both variants.
// ---------------------------------------------------------------------------

// The state of GJK's loop: the certified lower bound (scaled units), the
// largest |w|^2 seen (the termination slack's magnitude), the last search
// direction (from A towards B), the support evaluations so far, how the
// loop ended, and on a stall the support point that did not decrease |v|
// and, when it spans one, the plane of the stalled simplex.
struct GjkLoop {
  double lower = 0.0;
  double w_max2 = 0.0;
  Vec3 direction = Vec3::UnitX();
  int iterations = 0;
  bool contact = false;
  bool capped = false;
  // The gap test passed, or the support point was already in the simplex
  // (v is then optimal up to rounding): |v| is the distance.
  bool certified = false;
  std::array<SupportPoint, 3> stall_plane;  // a triangle through v and the new point, if stalled
  bool stalled = false;
  SupportPoint stall_point;  // the support point that did not decrease |v|
  bool rounding_stall = false;
};

// The descent: the support point along -v joins the simplex while |v|
// decreases, until contact, the certified gap, the cap, or a stall.
template <class Support>
[[gnu::always_inline]] inline void descend(const DistanceOptions& options, double tol,
                                           Simplex& simplex, Support& support, GjkLoop& s) {
  double& lower = s.lower;
  double& w_max2 = s.w_max2;
  Vec3& direction = s.direction;
  int& iterations = s.iterations;
  bool& contact = s.contact;
  bool& capped = s.capped;
  bool& certified = s.certified;
  std::array<SupportPoint, 3>& stall_plane = s.stall_plane;
  bool& stalled = s.stalled;
  SupportPoint& stall_point = s.stall_point;
  bool& rounding_stall = s.rounding_stall;
  for (;;) {
    if (simplex.encloses_origin || simplex.vv <= tol * tol) {
      contact = true;
      break;
    }
    if (iterations >= options.max_iterations) {
      capped = true;
      break;
    }
    const double v_norm = std::sqrt(simplex.vv);  // > 0: vv > tol^2 >= 0
    direction = -simplex.v / v_norm;
    const SupportPoint w = support(-simplex.v);
    ++iterations;
    w_max2 = std::max(w_max2, w.w.squaredNorm());
    lower = std::max(lower, simplex.v.dot(w.w) / v_norm);
    if (v_norm - lower <=
        options.relative_tolerance * v_norm + kTerminationGapUlps * kUnitRoundoff * std::sqrt(w_max2)) {
      certified = true;
      break;
    }
    if (simplex.contains(w.ia, w.ib)) {
      // Nothing new, with the gap open: v is the simplex's closest point,
      // but its direction, a difference of rounded points, failed the
      // support test, which certifies nothing. Polished like a stall
      // (certifying_direction), it is certified or left undecided there.
      stall_point = w;
      rounding_stall = true;
      break;
    }
    Simplex next = simplex;
    next.p[idx(next.size++)] = w;
    detail::solve(next);
    if (!next.encloses_origin && next.vv >= simplex.vv) {  // rounding has taken over: keep v
      stall_point = w;
      rounding_stall = true;
      if (next.size == 3) {
        stall_plane = {next.p[0], next.p[1], next.p[2]};
        stalled = true;
      } else if (simplex.size == 2) {
        stall_plane = {simplex.p[0], simplex.p[1], w};
        stalled = true;
      } else if (simplex.size == 3) {
        stall_plane = {simplex.p[0], simplex.p[1], simplex.p[2]};
        stalled = true;
      }
      break;
    }
    simplex = next;
  }
}

// After a stall (below), one more lower bound or the polished features.
template <class Support>
[[gnu::always_inline]] inline Polished settle_stall(const GjkFrame& frame,
                                                    const DistanceOptions& options, double tol,
                                                    Simplex& simplex, Support& support,
                                                    GjkLoop& s) {
  double& lower = s.lower;
  double& w_max2 = s.w_max2;
  int& iterations = s.iterations;
  bool& contact = s.contact;
  bool& capped = s.capped;
  bool& certified = s.certified;
  const std::array<SupportPoint, 3>& stall_plane = s.stall_plane;
  const bool stalled = s.stalled;
  const SupportPoint& stall_point = s.stall_point;
  const bool rounding_stall = s.rounding_stall;
  // Stalled: the loop left because |v| did not decrease at this precision
  // while the support point beyond v was new, so |v| may be far above the
  // distance, and its lower bound from v's direction may be 0. On a flat
  // Minkowski difference (two nearly parallel needles or slivers in contact)
  // the support point beyond v improves |v| only at second order, below
  // rounding, and GJK stopped with |v| many bands above a distance of 0 and
  // called the pair separated (GjkTouching.NeedlesSideBySideTouch). The
  // plane through v's simplex and that support point is then nearly C's
  // closest face (for a vertex just above a face, exactly it), and its
  // normal gives one more lower bound (one support). Separated is reported
  // only when a lower bound certifies it (above the band); otherwise the
  // pair is in contact as far as GJK can tell, and touching is reported
  // with GJK's distance as the upper bound it is.
  Polished polished;
  if (rounding_stall && !contact && !capped && !certified) {
    polished = polish_stalled(frame, options, tol, simplex, stall_point, support, iterations,
                              lower, w_max2);
    contact = polished.contact;
    certified = polished.certified;
    capped = polished.capped;
  }
  if (!contact && !capped && !certified && stalled && iterations < options.max_iterations) {
    Vec3 n = detail::face_normal(stall_plane[1].w - stall_plane[0].w,
                                 stall_plane[2].w - stall_plane[0].w)
                 .n;
    if (n.dot(simplex.v) < 0.0) n = -n;
    const double n_norm = n.norm();
    if (n_norm > 0.0) {
      const SupportPoint w = support(-n);
      ++iterations;
      lower = std::max(lower, n.dot(w.w) / n_norm);
    }
  }
  return polished;
}

// GJK's closest points from the original coordinates, and the hull ids
// they combine (ids_used of each side, padded).
struct GjkPoints {
  Vec3 point_a = Vec3::Zero();
  Vec3 local_b = Vec3::Zero();  // in B's frame
  std::array<std::int32_t, 4> ids_a{};
  std::array<std::int32_t, 4> ids_b{};
  int ids_used = 0;
};

[[gnu::always_inline]] inline GjkPoints gjk_points(const GjkFrame& frame, const Simplex& simplex,
                                                   const Polished& polished) {
  GjkPoints out;
  Vec3& point_a = out.point_a;
  Vec3& local_b = out.local_b;
  std::array<std::int32_t, 4>& ids_a = out.ids_a;
  std::array<std::int32_t, 4>& ids_b = out.ids_b;
  int& ids_used = out.ids_used;
  // Closest points from the original coordinates (the weights are
  // unit-free): sums of hull points with weights summing to one. B's is
  // formed in B's frame and mapped once (the pose is affine).
  ids_used = simplex.size;
  if (polished.have) {
    // The polished features' own coefficients (polish_stalled). Padded
    // with repeats of the last id: the witness rule takes distinct ids.
    for (int i = 0; i < polished.na; ++i)
      point_a += polished.coef_a[idx(i)] * frame.a.vertex(polished.ids_a[idx(i)]);
    for (int j = 0; j < polished.nb; ++j)
      local_b += polished.coef_b[idx(j)] * frame.b.vertex(polished.ids_b[idx(j)]);
    ids_used = std::max(polished.na, polished.nb);
    for (int k = 0; k < ids_used; ++k) {
      ids_a[idx(k)] = polished.ids_a[idx(std::min(k, polished.na - 1))];
      ids_b[idx(k)] = polished.ids_b[idx(std::min(k, polished.nb - 1))];
    }
  } else {
    for (int k = 0; k < simplex.size; ++k) {
      const SupportPoint& sp = simplex.p[idx(k)];
      point_a += simplex.lambda[idx(k)] * frame.a.vertex(sp.ia);
      local_b += simplex.lambda[idx(k)] * frame.b.vertex(sp.ib);
      ids_a[idx(k)] = sp.ia;
      ids_b[idx(k)] = sp.ib;
    }
  }
  return out;
}

// `simplex` is solved on entry (at least one point); `iterations` counts the
// support evaluations made so far; `direction` is the search direction used
// so far (from A towards B), the normal reported when no better one exists.
// `deep` receives the contact classification's tetrahedron around the origin
// when it certifies intersection (classify_contact). `cached_face_a` and
// `cached_face_b` are a previous answer's witness faces (-1 for none).
// `witnesses` false leaves the features default (vertex -1): for a caller
// that keeps only the status, iterations and simplex (the contact unit).
template <class Support>
DistanceResult run_gjk(const GjkFrame& frame, const DistanceOptions& options,
                       double contact_tolerance, Simplex& simplex, int iterations, Vec3 direction,
                       Support& support, Points& deep, std::int32_t cached_face_a = -1,
                       std::int32_t cached_face_b = -1, bool witnesses = true) {
  const double tol = contact_tolerance * frame.inv_unit;
  GjkLoop loop;
  loop.iterations = iterations;
  for (int k = 0; k < simplex.size; ++k)
    loop.w_max2 = std::max(loop.w_max2, simplex.p[idx(k)].w.squaredNorm());
  loop.direction =
      direction.squaredNorm() > 0.0 ? Vec3(direction.normalized()) : Vec3(Vec3::UnitX());
  descend(options, tol, simplex, support, loop);
  const Polished polished = settle_stall(frame, options, tol, simplex, support, loop);
  const bool contact = loop.contact;
  const bool capped = loop.capped;
  const bool certified = loop.certified;
  const double lower = loop.lower;
  iterations = loop.iterations;
  direction = loop.direction;

  const bool separation_certified = certified || lower > tol;

  Status status = Status::separated;
  if (contact) {
    // The classification grows its polytope from any points of C. A polished
    // simplex of four points (two edges' vertex pairs) is flat, not a
    // tetrahedron around the origin: three of them seed it.
    Simplex seed = simplex;
    if (seed.size == 4 && !seed.encloses_origin) seed.size = 3;
    status = detail::classify_contact(seed, tol, support, iterations, options.max_iterations, deep);
    // A touching contact whose tetrahedron encloses the origin (by rounding,
    // or within the band): the origin is within tol of a face of it (else
    // the classification would have certified depth), so that face's
    // closest points are the witnesses. Its barycentric weights of the
    // origin would only give rounding noise from a sliver tetrahedron.
    if (status == Status::touching && simplex.encloses_origin)
      detail::apply(simplex, detail::nearest_face(simplex.p));
  }

  const GjkPoints points = gjk_points(frame, simplex, polished);
  const Vec3& point_a = points.point_a;
  const Vec3& local_b = points.local_b;
  const std::array<std::int32_t, 4>& ids_a = points.ids_a;
  const std::array<std::int32_t, 4>& ids_b = points.ids_b;
  const int ids_used = points.ids_used;
  const Vec3 point_b = frame.b_in_a.apply(local_b);

  DistanceResult result;
  result.iterations = iterations;
  if (status == Status::intersecting) {
    // A tetrahedron around the origin gives one point in both hulls
    // (sum lambda a = sum lambda b); otherwise the two are within tol.
    const Vec3 contact_point = 0.5 * (point_a + point_b);
    result.point_a = contact_point;
    result.point_b = contact_point;
    result.distance = 0.0;
    result.lower_bound = 0.0;
    result.normal = direction;
  } else {
    result.point_a = point_a;
    result.point_b = point_b;
    result.distance = ((point_b - point_a) * frame.inv_unit).norm() * frame.unit;
    result.lower_bound = std::clamp(lower * frame.unit, 0.0, result.distance);
    if (!contact) status = bounded_status(result.distance, contact_tolerance, frame, separation_certified);
    if (capped) status = Status::iteration_cap;
    // Within the band the points' difference is rounding noise: keep the
    // last search direction there.
    result.normal = (!contact && status != Status::touching && result.distance > 0.0)
                        ? Vec3((point_b - point_a) / result.distance)
                        : direction;
  }
  result.status = status;
  if (!witnesses) return result;
  // The witness features by the rule all algorithms share
  // (witness_features.h), A's in A's frame, B's in B's.
  const double witness_band = detail::witness_band(frame.magnitude);
  const std::span ids_a_used(ids_a.data(), idx(ids_used));
  const std::span ids_b_used(ids_b.data(), idx(ids_used));
  const bool locate = status != Status::intersecting;  // witness_features.h
  result.feature_a = detail::witness_feature(
      frame.a, ids_a_used, witness_band, cached_face_a,
      [&] {
        return detail::WitnessPoint{point_a, result.normal};
      },
      locate);
  result.feature_b = detail::witness_feature(
      frame.b, ids_b_used, witness_band, cached_face_b,
      [&] {
        return detail::WitnessPoint{local_b, frame.dir_in_b(-result.normal)};
      },
      locate);
  return result;
}

// The first simplex of a cold query: the support point in the direction from
// A's centroid towards B's, i.e. the point of C least far along the
// centroids' difference (a point of C near the closest one when the bodies
// are apart).
//
// The direction is taken in the unit's scale: the supports dot it with the
// vertices, and at coordinates from 1e155 on the raw difference of
// centroids times a vertex overflowed to inf and -inf, whose sum is NaN
// (DistanceRegression.ScalesFrom1eMinus300To1e300).
template <class Support>
Simplex cold_start(const GjkFrame& frame, Support& support, Vec3& direction) {
  direction = (frame.b_in_a.apply(frame.b.centroid()) - frame.a.centroid()) * frame.inv_unit;
  if (!(direction.squaredNorm() > 0.0)) direction = Vec3::UnitX();
  Simplex s;
  s.p[0] = support(direction);
  s.size = 1;
  detail::solve(s);
  return s;
}

}  // namespace

DistanceResult gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance) {
  const GjkFrame frame(a, b, b_in_a);
  BruteForceSupport support{frame};
  Vec3 direction;
  Simplex simplex = cold_start(frame, support, direction);
  Points deep;
  return run_gjk(frame, options, contact_tolerance, simplex, 1, direction, support, deep);
}

namespace {

DistanceResult run_enhanced_gjk(const ConvexPolytope& a, const ConvexPolytope& b,
                                const Pose& b_in_a, const DistanceOptions& options,
                                double contact_tolerance, DistanceCache& cache, bool witnesses) {
  const GjkFrame frame(a, b, b_in_a);
  const auto valid = [](std::int32_t id, int count) { return id >= 0 && id < count; };
  HillClimbSupport support{frame, valid(cache.hint_a, a.vertex_count()) ? cache.hint_a : 0,
                           valid(cache.hint_b, b.vertex_count()) ? cache.hint_b : 0};

  // Warm start: the cached vertex pairs, re-evaluated at the current pose.
  // Ids out of range are dropped, repeated pairs kept once.
  Simplex simplex;
  for (std::size_t k = 0; k < 4; ++k) {
    const std::int32_t ia = cache.vertices_a[k];
    const std::int32_t ib = cache.vertices_b[k];
    if (valid(ia, a.vertex_count()) && valid(ib, b.vertex_count()) && !simplex.contains(ia, ib)) {
      simplex.p[idx(simplex.size++)] = frame.point(ia, ib);
    }
  }
  int iterations = 0;
  Vec3 direction;
  if (simplex.size == 0) {
    simplex = cold_start(frame, support, direction);
    iterations = 1;
  } else {
    detail::solve(simplex);
    direction = -simplex.v;
    if (!(direction.squaredNorm() > 0.0))
      direction = (frame.b_in_a.apply(b.centroid()) - a.centroid()) * frame.inv_unit;
  }

  Points deep;
  const DistanceResult result =
      run_gjk(frame, options, contact_tolerance, simplex, iterations, direction, support, deep,
              cache.face_a, cache.face_b, witnesses);
  // run_gjk reduced `simplex` in place to the final one. An intersection
  // certified by a tetrahedron around the origin caches that tetrahedron
  // instead: while the bodies overlap by more than the band, the next query
  // starts from it enclosing the origin and certifies it again without a
  // support search.
  if (result.status == Status::intersecting && deep[0].ia >= 0) {
    simplex.p = deep;
    simplex.size = 4;
  }
  for (std::size_t k = 0; k < 4; ++k) {
    const bool used = static_cast<int>(k) < simplex.size;
    cache.vertices_a[k] = used ? simplex.p[k].ia : -1;
    cache.vertices_b[k] = used ? simplex.p[k].ib : -1;
  }
  cache.hint_a = support.hint_a;
  cache.hint_b = support.hint_b;
  cache.face_a = result.feature_a.face;
  cache.face_b = result.feature_b.face;
  return result;
}

}  // namespace

DistanceResult enhanced_gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                     const Pose& b_in_a, const DistanceOptions& options,
                                     double contact_tolerance, DistanceCache& cache) {
  return run_enhanced_gjk(a, b, b_in_a, options, contact_tolerance, cache, true);
}

DistanceResult detail::enhanced_gjk_contact(const ConvexPolytope& a, const ConvexPolytope& b,
                                            const Pose& b_in_a, const DistanceOptions& options,
                                            double contact_tolerance, DistanceCache& cache) {
  return run_enhanced_gjk(a, b, b_in_a, options, contact_tolerance, cache, false);
}

}  // namespace proxima
