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
// weights lambda of v, and the ids with non-zero weight are the witness
// features.
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
// scale.#include "proxima/gjk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "gjk_contact.h"
#include "gjk_frame.h"
#include "simplex_solver.h"

namespace proxima {
namespace {

using detail::BruteForceSupport;
using detail::GjkFrame;
using detail::HillClimbSupport;
using detail::idx;
using detail::Points;
using detail::Simplex;
using detail::SupportPoint;

// Rounding slack of the termination test, in units of u * max|w| (the
// largest simplex point seen, in scaled units): v.w and |v| are sums of
// products of coordinates of that size and v itself is rebuilt from the
// simplex points, so the computed gap |v| - v.w/|v| carries an error of a few
// u max|w|. Below this slack more iterations cannot improve v. Well inside
// the 64 u R contact band of the accuracy standard (|w| <= 2 sqrt(3) R).
constexpr double kGapUlps = 16.0;

// ---------------------------------------------------------------------------
// Witness features.
// ---------------------------------------------------------------------------

bool face_has(const ConvexPolytope& poly, int f, std::int32_t v) {
  for (const std::int32_t x : poly.face(f)) {
    if (x == v) return true;
  }
  return false;
}

// A face containing all of ids[0..m), found among the faces around ids[0]
// (each face through a vertex is left of exactly one of its outgoing edges).
// A polygon has two, one per side: take the one facing `outward`.
int face_containing(const ConvexPolytope& poly, const std::array<std::int32_t, 4>& ids, int m,
                    const Vec3& outward) {
  const auto offsets = poly.adjacency_offsets();
  const auto left = poly.adjacency_faces();
  const auto v0 = idx(ids[0]);
  int best = -1;
  bool best_aligned = false;  // best_alignment computed (only when another face competes)
  double best_alignment = 0.0;
  for (auto k = idx(offsets[v0]); k < idx(offsets[v0 + 1]); ++k) {
    const int f = left[k];
    if (f < 0) continue;
    bool all = true;
    for (int i = 1; i < m && all; ++i) all = face_has(poly, f, ids[idx(i)]);
    if (!all) continue;
    if (best < 0) {
      best = f;
      continue;
    }
    if (!best_aligned) {
      best_alignment = poly.face_plane(best).normal.dot(outward);
      best_aligned = true;
    }
    const double alignment = poly.face_plane(f).normal.dot(outward);
    if (alignment > best_alignment) {
      best = f;
      best_alignment = alignment;
    }
  }
  return best;
}

// The feature spanned by the vertex ids that carry weight: one id is a
// vertex, two adjacent ids an edge, two non-adjacent ids or three ids a face
// (the hull face through them). When the ids span no hull face (only when
// intersecting, or when rounding kept a sliver of weight on a vertex off the
// closest face), the feature falls back to the heaviest vertex.
Feature witness_feature(const ConvexPolytope& poly, const std::array<std::int32_t, 4>& raw_ids,
                        const std::array<double, 4>& raw_weights, int count, const Vec3& outward) {
  std::array<std::int32_t, 4> ids{};
  std::array<double, 4> weights{};
  int m = 0;
  for (int k = 0; k < count; ++k) {
    int j = 0;
    while (j < m && ids[idx(j)] != raw_ids[idx(k)]) ++j;
    if (j == m) {
      ids[idx(m)] = raw_ids[idx(k)];
      weights[idx(m++)] = 0.0;
    }
    weights[idx(j)] += raw_weights[idx(k)];
  }
  if (m == 4) {  // a tetrahedron around the origin: keep the three heaviest
    int lightest = 0;
    for (int j = 1; j < 4; ++j) {
      if (weights[idx(j)] < weights[idx(lightest)]) lightest = j;
    }
    ids[idx(lightest)] = ids[3];
    weights[idx(lightest)] = weights[3];
    m = 3;
  }
  int heaviest = 0;
  for (int j = 1; j < m; ++j) {
    if (weights[idx(j)] > weights[idx(heaviest)]) heaviest = j;
  }
  const std::int32_t heaviest_id = ids[idx(heaviest)];
  for (int j = 1; j < m; ++j) {  // ascending ids (at most three: insertion)
    for (int i = j; i > 0 && ids[idx(i - 1)] > ids[idx(i)]; --i)
      std::swap(ids[idx(i - 1)], ids[idx(i)]);
  }

  Feature f;
  f.vertices = {ids[0], -1, -1};
  if (m == 1) return f;
  if (m == 2) {
    for (const std::int32_t w : poly.neighbors(ids[0])) {
      if (w == ids[1]) {
        f.type = FeatureType::edge;
        f.vertices = {ids[0], ids[1], -1};
        return f;
      }
    }
  }
  const int face = face_containing(poly, ids, m, outward);
  if (face < 0) {
    f.vertices = {heaviest_id, -1, -1};
    return f;
  }
  f.type = FeatureType::face;
  f.face = face;
  f.vertices = {ids[0], ids[1], m == 3 ? ids[2] : -1};
  return f;
}

// ---------------------------------------------------------------------------
// The loop shared by both variants.
// ---------------------------------------------------------------------------

// `simplex` is solved on entry (at least one point); `iterations` counts the
// support evaluations made so far; `direction` is the search direction used
// so far (from A towards B), the normal reported when no better one exists.
// `deep` receives the contact classification's tetrahedron around the origin
// when it certifies intersection (classify_contact).
template <class Support>
DistanceResult run_gjk(const GjkFrame& frame, const DistanceOptions& options,
                       double contact_tolerance, Simplex& simplex, int iterations, Vec3 direction,
                       Support& support, Points& deep) {
  const double tol = contact_tolerance * frame.inv_unit;
  double lower = 0.0;  // certified lower bound, scaled units
  double w_max2 = 0.0;
  for (int k = 0; k < simplex.size; ++k)
    w_max2 = std::max(w_max2, simplex.p[idx(k)].w.squaredNorm());
  direction = direction.squaredNorm() > 0.0 ? Vec3(direction.normalized()) : Vec3(Vec3::UnitX());

  bool contact = false;
  bool capped = false;
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
        options.relative_tolerance * v_norm + kGapUlps * kUnitRoundoff * std::sqrt(w_max2)) {
      break;
    }
    if (simplex.contains(w.ia, w.ib)) break;  // nothing new: v is exact for this simplex
    Simplex next = simplex;
    next.p[idx(next.size++)] = w;
    detail::solve(next);
    if (!next.encloses_origin && next.vv >= simplex.vv) break;  // rounding has taken over: keep v
    simplex = next;
  }

  Status status = Status::separated;
  if (contact) {
    status =
        detail::classify_contact(simplex, tol, support, iterations, options.max_iterations, deep);
    // A touching contact whose tetrahedron encloses the origin (by rounding,
    // or within the band): the origin is within tol of a face of it (else
    // the classification would have certified depth), so that face's
    // closest points are the witnesses. Its barycentric weights of the
    // origin would only give rounding noise from a sliver tetrahedron.
    if (status == Status::touching && simplex.encloses_origin)
      detail::apply(simplex, detail::nearest_face(simplex.p));
  }

  // Closest points from the original coordinates (the weights are
  // unit-free): sums of hull points with weights summing to one. B's is
  // formed in B's frame and mapped once (the pose is affine).
  Vec3 point_a = Vec3::Zero();
  Vec3 local_b = Vec3::Zero();
  std::array<std::int32_t, 4> ids_a{};
  std::array<std::int32_t, 4> ids_b{};
  for (int k = 0; k < simplex.size; ++k) {
    const SupportPoint& sp = simplex.p[idx(k)];
    point_a += simplex.lambda[idx(k)] * frame.a.vertex(sp.ia);
    local_b += simplex.lambda[idx(k)] * frame.b.vertex(sp.ib);
    ids_a[idx(k)] = sp.ia;
    ids_b[idx(k)] = sp.ib;
  }
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
    if (!contact)
      status = result.distance > contact_tolerance ? Status::separated : Status::touching;
    if (capped) status = Status::iteration_cap;
    // Within the band the points' difference is rounding noise: keep the
    // last search direction there.
    result.normal = (!contact && status != Status::touching && result.distance > 0.0)
                        ? Vec3((point_b - point_a) / result.distance)
                        : direction;
  }
  result.status = status;
  result.feature_a = witness_feature(frame.a, ids_a, simplex.lambda, simplex.size, result.normal);
  result.feature_b =
      witness_feature(frame.b, ids_b, simplex.lambda, simplex.size, frame.dir_in_b(-result.normal));
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

DistanceResult enhanced_gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                     const Pose& b_in_a, const DistanceOptions& options,
                                     double contact_tolerance, DistanceCache& cache) {
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
      run_gjk(frame, options, contact_tolerance, simplex, iterations, direction, support, deep);
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
  return result;
}

}  // namespace proxima
