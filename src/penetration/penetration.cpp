// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer: penetration depth (see proxima/detail/penetration/penetration.h for the
// definitions).
//
// Derivation. For M = A - B containing the origin, depth = min over the
// facets of M of h_M(n) (n the facet's outward unit normal), and
// h_M(n) >= depth for every unit n (the support function of a convex set
// containing a ball of radius depth about the origin is at least depth).
// The facets of M are the crossings of the Gauss maps of A and of -B: a
// vertex of A's Gauss map (a face of A, normal n) lying in a cell of -B's
// (a vertex of B), the reverse, or an arc of A (an edge, between the normals
// of its two faces) crossing an arc of -B. So
//   1. candidates: all faces of A, all faces of B, and the edge pairs whose
//      arcs cross (tested with a tolerance that errs towards inclusion);
//   2. every candidate's value is h_A(n) + h_B(-n) evaluated with
//      hill-climbing supports started at the candidate's own vertices (one
//      look at their neighbours when the candidate is a true facet; the
//      climb goes on across ties, so that rounding on nearly flat vertices
//      cannot stop it below the support), so a wrong inclusion only adds
//      an upper bound;
//   3. depth = the smallest value; its normal, supports and the Minkowski
//      face are the answer.
// The slow twin tests every pair of edges; the fast cold query walks the
// overlay: for each arc of A, the cells of -B (vertices of B) that it passes
// through form a chain linked by the B edges whose arcs it crosses, found
// from the support at the arc's start by stepping across crossing edges.
// It also prunes (pruned_by): faces whose lower bound exceeds the best value
// so far are not evaluated, which leaves the faces near the answer.
// Tracking (penetration_depth): under a translation of B the faces of M
// only translate, so the cache keeps them with their offsets and a query
// searches them by branch and bound on a tree over their normals
// (search_tree); see PenetrationCache.
//
// Arcs. For a directed edge v -> w of a solid with the face L on its left
// and R on its right (outward normals nL, nR), nL x nR points along +(w - v)
// (a cube's top edge checks it); the arc runs from nL to nR around the axis
// k = w - v. A polygon's edge has the two sides as faces (nR = -nL): its arc
// is the half circle through the outward in-plane normal o = (w - v) x nL,
// cut into the quarter arcs nL -> o -> -nL (still around k = w - v). A
// segment's arc is the whole circle orthogonal to it: four quarter arcs.
// For -B the endpoints are negated and the axis is unchanged
// ((-nL) x (-nR) = nL x nR).
//
// Crossing of two arcs X = (p1, q1, k1) and Y = (p2, q2, k2) (after
// Gregorius, "The Separating Axis Test between convex polyhedra", GDC 2013):
// with s1 = p1.k2, t1 = q1.k2, s2 = p2.k1, t2 = q2.k1, they cross when
// s1 t1 < 0 (X's ends on both sides of Y's plane), s2 t2 < 0, and
// s2 t1 > 0 (the crossing is the one on the arcs, not its antipode).
#include "proxima/detail/penetration/penetration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <memory_resource>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "core/power_of_two.h"
#include "penetration/candidates.h"
#include "penetration/expanding_polytope.h"
#include "penetration/face_tree.h"
#include "penetration/gauss_map_arcs.h"
#include "penetration/query.h"
#include "penetration/refinement.h"
#include "penetration/tracked_expansion.h"
#include "penetration/tracking.h"
#include "penetration/witnesses.h"
#include "proxima/detail/geometry/exact_predicates.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/shape/support.h"

namespace proxima {
namespace {

// The fingerprint's weight of the face count beside the vertex count: V +
// 1e6 F is an exact integer in a double and tells (V, F) pairs apart
// while V < 1e6 (hulls of more vertices may collide on it; the sums of
// coordinates are the fingerprint's other half).
constexpr double kFaceCountWeight = 1e6;

// The fingerprint of a pair: sizes and a few coordinates, so that a cache
// of another pair of polytopes built at the same addresses is not trusted.
std::array<double, 4> fingerprint(const ConvexPolytope& a, const ConvexPolytope& b) {
  const auto sum = [](const ConvexPolytope& p) {
    const Vec3& first = p.vertex(0);
    const Vec3& last = p.vertex(p.vertex_count() - 1);
    return first.x() + 2 * first.y() + 3 * first.z() + 5 * last.x() + 7 * last.y() + 11 * last.z();
  };
  return {static_cast<double>(a.vertex_count()) + kFaceCountWeight * a.face_count(),
          static_cast<double>(b.vertex_count()) + kFaceCountWeight * b.face_count(), sum(a),
          sum(b)};
}

// The faces of A - B whose values are within this many u (scaled units)
// of the least are tried for witnesses that meet when the least one's do
// not (solve_cold): twice the slack of a value (kValueSlackUlps), so that
// the face that holds the origin's foot, whose exact value is the least,
// is among them. Pinned by PenetrationRegression.SliverWithNearlyCoplanarFaces.
constexpr double kWitnessWindow = 2.0 * kValueSlackUlps;

// Whether an answer's witnesses realize its depth: point_b + depth * normal
// within the contact band of point_a (a separated answer's do not).
bool witnesses_meet(const Query& q, const PenetrationResult& r) {
  if (r.status == PenetrationStatus::separated) return false;
  // In scaled units: near 1e300 the squared norm of a gap of 1e285
  // overflows, and no answer's witnesses would meet.
  return ((r.point_b + r.depth * r.normal - r.point_a) * q.inverse).norm() <=
         contact_band(q.magnitude) * q.inverse;
}

// Writes the faces of A - B a cold query evaluated into the cache, with
// `pruned` (scaled) the least lower bound of every face it did not keep,
// the answer's face `best`; `record`: the pruned groups were recorded.
void remember_faces(const Query& q, PenetrationCache& cache, const Pose& b_in_a,
                    std::span<const Candidate> candidates, std::size_t best, double pruned,
                    bool record) {
  cache.a = &q.a;
  cache.b = &q.b;
  cache.fingerprint = fingerprint(q.a, q.b);
  cache.rotation = b_in_a.rotation;
  cache.facets.resize(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i)
    cache.facets[i] = {candidates[i].id, candidates[i].normal, candidates[i].value * q.unit,
                       candidates[i].support_a, candidates[i].support_b};
  cache.enumerated_translation = b_in_a.translation;
  cache.pruned = pruned * q.unit;
  cache.bounded = record;
  cache.expanded = 0;
  // B's rotation may have changed: its supporting features with it.
  cache.witnesses.a.clear();
  cache.witnesses.b.clear();
  // The trees are built by the first tracked query (a rotating B, which
  // enumerates every query, never pays for it); until then `last` is the
  // answer's face.
  cache.nodes.clear();
  cache.roots.clear();
  cache.last = cache.facets[best];
}

// The first direction of a cold enumeration, the centroids' difference in
// the query's scaled units (coordinates up to about 1), is replaced by an
// axis when its squared length is not above this. Any unit direction gives
// an upper bound (h_A(n) + h_B(-n) bounds the depth), so the direction only
// has to normalize to a unit one: its squared length, whose root
// normalize() divides by, must stay clear of underflow, which 2^-400 is by
// far; a difference that small is the centroids' rounding (a few u) anyway.
constexpr double kMinFirstDirectionSquared = 0x1p-400;

// `record`: keep the pruned groups in cache->bounds (PenetrationCache).
PenetrationResult solve_cold(Query& q, bool walk, PenetrationCache* cache, const Pose& b_in_a,
                             const PenetrationCache::Facet* start, bool record) {
  ScratchScope scratch(q);
  PenetrationCache::Shapes local;
  q.use_shapes(cache != nullptr ? cache->shapes : local, walk);
  if (cache != nullptr) {
    // Filled by this enumeration; until the cache is written below, the
    // last one's faces are certified by the scalar `pruned` alone.
    cache->bounds.clear();
    cache->bound_nodes.clear();
    cache->bound_roots.clear();
    cache->expanded = 0;
    cache->bounded = false;
    if (record) q.bounds_out = &cache->bounds;
  }
  Candidate first;
  if (walk) {
    // The first upper bound: the last answer's direction (a rotated B), or
    // the direction from A's centroid to B's.
    q.prune = true;
    if (cache != nullptr) q.prune_margin = cache->prune_margin * q.inverse;
    Vec3 d = start != nullptr ? start->normal : Vec3(q.centroid_b - q.centroid_a);
    if (!(d.squaredNorm() > kMinFirstDirectionSquared)) d = Vec3::UnitZ();
    d.normalize();
    first = evaluate(q, {}, d, start != nullptr ? start->support_a : -1,
                     start != nullptr ? start->support_b : -1);
    q.bound = first.value;
    q.set_references(first.support_a, first.support_b);
  }
  Candidates candidates(q.memory);
  // Every face and crossing for the slow twin; a pruned walk keeps a few
  // hundred at most on the benchmarks' spheres (reserving for all of them,
  // megabytes at N = 4096, would cost an mmap and its page faults per cold
  // query).
  const auto all = static_cast<std::size_t>(q.a.face_count() + q.b.face_count() +
                                            2 * (q.a.vertex_count() + q.b.vertex_count()));
  candidates.reserve(walk ? std::min<std::size_t>(all, 512) : all);
  add_face_candidates(q, candidates);
  if (walk)
    add_edge_candidates_walk(q, candidates);
  else
    add_edge_candidates_brute_force(q, candidates);
  // The first direction is an upper bound too (and, when every face was
  // pruned below it, a separating direction: the bodies are apart). Last,
  // so that a face of A - B wins a tie. Its id has no hull ids (-1).
  if (candidates.empty()) {
    // No face of A - B: flat (points, segments), or all pruned below a
    // separating first direction.
    if (walk && first.value < 0.0) return finish(q, first, first.value, 0, false);
    return finish_without_candidates(q);
  }
  if (walk) candidates.push_back(first);
  const int count = static_cast<int>(candidates.size());
  const auto best =
      std::min_element(candidates.begin(), candidates.end(),
                       [](const Candidate& x, const Candidate& y) { return x.value < y.value; });
  PenetrationResult r = finish(q, *best, best->value, count, false);
  if (!witnesses_meet(q, r) && !(best->value < -kValueSlackUlps * kUnitRoundoff)) {
    // The least value's features do not meet: a flat M whose plane holds
    // the origin outside M, or a face tied with the least within rounding
    // (nearly coplanar faces of A - B) holds the origin's foot. The faces
    // within kWitnessWindow of the least are tried, least first; the first
    // whose features meet gives the answer (its value is the depth within
    // the window).
    const double window = best->value + kWitnessWindow * kUnitRoundoff;
    const Candidate* tried = &*best;
    for (;;) {
      const Candidate* next = nullptr;
      for (const Candidate& c : candidates)
        if (c.value <= window && c.value >= tried->value && &c != tried &&
            (c.value > tried->value || &c > tried) &&
            (next == nullptr || c.value < next->value ||
             (c.value == next->value && &c < next)))
          next = &c;
      if (next == nullptr) break;
      const PenetrationResult alt = finish(q, *next, best->value, count, false);
      tried = next;
      if (witnesses_meet(q, alt)) {
        r = alt;
        break;
      }
    }
  }
  if (needs_refinement(q, r))
    r = refine(q, std::span<const Candidate>(candidates.data(), candidates.size()), *best, r, count);
  if (cache != nullptr) {
    remember_faces(q, *cache, b_in_a, candidates, static_cast<std::size_t>(best - candidates.begin()),
                   q.pruned, record);
    ++cache->enumerations;
  }
  return r;
}

// The cold query's fast path (issue 29): a polytope expanding inside
// A - B gives a certified lower bound on the depth and the normal of the
// facet of A - B that realizes it (expanding_polytope.h); the candidates
// of that facet are the faces of A at A's support along it, the faces of
// B at B's, and the pairs of their edges, of which those whose normals are
// the expansion's (kFacetCosine) are evaluated as the enumeration
// evaluates them: an honest upper bound each. The least of them is the
// answer when it is within kAcceptUlps u R and kAcceptRelative of the
// certified lower bound (both within the accuracy standard); anything
// else (an expansion that did not certify, a depth near the band, the
// facet not among the candidates, witnesses that do not meet) leaves the
// answer to the enumeration.
//
// The expansion's iteration cap: past it, the enumeration is cheaper (a B
// near A's centre, where many facets of A - B are near the depth). The
// enumeration's cost grows like the vertex count (every face's normal and
// pruning bound), an iteration's does not: the cap is at least
// kExpansionIterations and grows with the hulls, one iteration per
// kVerticesPerIteration vertices of the two hulls (an iteration costs
// about as much as the enumeration's work on a few vertices; past the cap
// the expansion's work is lost).
constexpr int kExpansionIterations = 256;
constexpr int kVerticesPerIteration = 8;
// The contact classification's tetrahedron (the seed) starts the expansion
// when both hulls have at most this many vertices; larger ones start from
// the octahedron of supports along the axes. The tetrahedron saves the
// octahedron's six cold supports but, flatter and from the distance
// query's directions, costs a few more iterations, whose climbs grow with
// the hulls: on the sphere hulls of bench/cold_instructions the seed saves
// instructions at 8 and 64 vertices and costs them at 512 and 4096.
constexpr int kSeedVertices = 64;
// A face or edge pair is a candidate when its normal's cosine with the
// expansion's is at least 1 - this: the facet's normal is within rounding
// of the expansion's (a few hundred u for a well-shaped triangle), and
// candidates kept by mistake only add upper bounds.
constexpr double kFacetCosine = 1e-9;
// The same for a face's rough normal (the cross product of its first two
// edges, rounded: within 1e-6 of the exact one unless the face's first
// corner is a sliver of angle below about 1e-9, where face_plane picks
// better-shaped corners), as a cheap filter before face_plane.
constexpr double kRoughCosine = 1e-6;
// The answer's upper bound may exceed the certified lower bound by this
// relative part and this many u (scaled R): half of the standard's.
constexpr double kAcceptRelative = 5e-13;
constexpr double kAcceptUlps = 0.5 * kContactBandUlps;

// The candidate of the facet of A - B with id `last` (the previous answer's)
// as solve_expanding's ring enumeration would build and evaluate it at the
// supports sa of A and sb of B along the expansion's normal n: a face of A
// holding sa (with sb), a face of B holding sb (with sa), or an edge of A
// out of sa with an edge of B out of sb, its normal kept only when within
// kFacetCosine of n. Nothing when the facet is not among the ring's (the
// supports moved to other vertices) or not near n. While B turns slowly
// the depth's facet rarely changes: this one evaluation then replaces the
// ring's (tens of cross products and a climb per candidate); any facet's
// value is an upper bound, so accepting it against the certified lower
// bound is as sound as accepting the ring's least.
std::optional<Candidate> cached_facet(const Query& q, const MinkowskiFaceId& last, const Vec3& n,
                                      int sa, int sb) {
  const auto holds = [](const ConvexPolytope& p, int f, int v) {
    if (f < 0 || f >= p.face_count()) return false;
    for (const std::int32_t u : p.face(f)) {
      if (u == v) return true;
    }
    return false;
  };
  const auto near = [&](const Vec3& normal) { return normal.dot(n) >= 1.0 - kFacetCosine; };
  switch (last.kind) {
    case MinkowskiFace::face_vertex: {
      if (!holds(q.a, last.a0, sa)) return std::nullopt;
      const Vec3 normal = q.a.face_plane(last.a0).normal;
      if (!near(normal)) return std::nullopt;
      return evaluate(q, {MinkowskiFace::face_vertex, last.a0, -1, sb, -1}, normal, sa, sb);
    }
    case MinkowskiFace::vertex_face: {
      if (!holds(q.b, last.b0, sb)) return std::nullopt;
      const Vec3 normal = -(q.rotation * q.b.face_plane(last.b0).normal);
      if (!near(normal)) return std::nullopt;
      return evaluate(q, {MinkowskiFace::vertex_face, sa, -1, last.b0, -1}, normal, sa, sb);
    }
    case MinkowskiFace::edge_edge: {
      // The ring's edges run out of sa and sb: the other ends w and x.
      const int w = last.a0 == sa ? last.a1 : last.a1 == sa ? last.a0 : -1;
      const int x = last.b0 == sb ? last.b1 : last.b1 == sb ? last.b0 : -1;
      if (w < 0 || x < 0 || w >= q.a.vertex_count() || x >= q.b.vertex_count())
        return std::nullopt;
      // As the ring computes it (the same bits: only the edges' order in
      // the ids differs, an exact negation undone by the orientation).
      Vec3 normal = (q.point_a(w) - q.point_a(sa)).cross(q.point_b(x) - q.point_b(sb));
      const double length = normal.norm();
      if (!(length > 0.0)) return std::nullopt;
      normal /= length;
      if (normal.dot(n) < 0.0) normal = -normal;
      if (!near(normal)) return std::nullopt;
      return evaluate(q,
                      {MinkowskiFace::edge_edge, std::min(sa, w), std::max(sa, w), std::min(sb, x),
                       std::max(sb, x)},
                      normal, sa, sb);
    }
  }
  return std::nullopt;
}

// `keep`: the expansion starts from the cache's kept surface and keeps its
// own there (a B that turned: tracked_expansion.h).
std::optional<PenetrationResult> solve_expanding(Query& q, PenetrationCache& cache,
                                                 const Pose& b_in_a, const DepthSeed& seed,
                                                 bool keep = false) {
  if (q.a.dimension() != 3 || q.b.dimension() != 3) return std::nullopt;
  const detail::MinkowskiSupport m{q.a, q.b, q.rotation, q.rotation_t, q.translation, q.inverse};
  const int cap = std::max(kExpansionIterations,
                           (q.a.vertex_count() + q.b.vertex_count()) / kVerticesPerIteration);
  const bool small = q.a.vertex_count() <= kSeedVertices && q.b.vertex_count() <= kSeedVertices;
  bool warm = false;
  const detail::ExpansionResult e =
      keep ? detail::track_expansion(
                 m, {b_in_a, q.unit, q.magnitude, q.b.centroid(), q.b.bounding_radius()},
                 cache.surface, cap, small ? seed : DepthSeed{}, warm)
           : detail::expand_polytope(m, cap, small ? seed : DepthSeed{});
  if (!e.certified || !e.converged || near_band(q, e.lower)) return std::nullopt;
  const Vec3& n = e.normal;
  const int sa = e.support_a, sb = e.support_b;
  // The answer from candidates[best]: accepted when its value (an upper
  // bound: h_A + h_B along any unit normal is at least the depth) is
  // within half the standard of the certified lower bound.
  const double slack = kAcceptUlps * kUnitRoundoff * q.magnitude * q.inverse;
  const auto accepted = [&](const Candidate& best) {
    return best.value - e.lower <= kAcceptRelative * best.value + slack;
  };
  const auto answer = [&](std::span<const Candidate> candidates,
                          std::size_t best) -> std::optional<PenetrationResult> {
    PenetrationResult r =
        finish(q, candidates[best], e.lower, static_cast<int>(candidates.size()), false);
    if (!witnesses_meet(q, r) || needs_refinement(q, r)) return std::nullopt;
    // Every face of A - B has a value of at least the certified bound.
    remember_faces(q, cache, b_in_a, candidates, best, e.lower, false);
    r.tracked = warm;
    return r;
  };
  // A turned B: the last answer's facet of A - B first, alone (cached_facet),
  // then the rings of the supports when it is not accepted.
  if (keep) {
    if (const std::optional<Candidate> c = cached_facet(q, cache.last.id, n, sa, sb);
        c && accepted(*c)) {
      if (std::optional<PenetrationResult> r = answer(std::span(&*c, 1), 0)) {
        ++cache.cached_facets;
        return r;
      }
    }
  }
  std::array<Candidate, 48> kept;
  std::size_t count = 0;
  const auto consider = [&](const MinkowskiFaceId& id, const Vec3& normal, int hint_a, int hint_b) {
    if (count < kept.size() && normal.dot(n) >= 1.0 - kFacetCosine)
      kept[count++] = evaluate(q, id, normal, hint_a, hint_b);
  };
  const auto ring = [](const ConvexPolytope& p, int v) {
    const auto offsets = p.adjacency_offsets();
    return std::pair<std::int32_t, std::int32_t>{offsets[static_cast<std::size_t>(v)],
                                                 offsets[static_cast<std::size_t>(v) + 1]};
  };
  const auto [a_begin, a_end] = ring(q.a, sa);
  const auto [b_begin, b_end] = ring(q.b, sb);
  // A face's rough normal (its first three vertices) first: face_plane's
  // only for the faces it leaves near n.
  // In the query's scaled units (the products of raw coordinates near
  // 1e300 would overflow).
  const auto near_face = [&](const ConvexPolytope& p, int f, const Vec3& d) {
    const auto cycle = p.face(f);
    const Vec3 v0 = p.vertex(cycle[0]) * q.inverse;
    const Vec3 c = (p.vertex(cycle[1]) * q.inverse - v0).cross(p.vertex(cycle[2]) * q.inverse - v0);
    return c.dot(d) >= (1.0 - kRoughCosine) * c.norm();
  };
  const Vec3 n_in_b = q.rotation_t * (-n);
  for (std::int32_t k = a_begin; k < a_end; ++k) {
    const int f = q.a.adjacency_faces()[static_cast<std::size_t>(k)];
    if (near_face(q.a, f, n))
      consider({MinkowskiFace::face_vertex, f, -1, sb, -1}, q.a.face_plane(f).normal, sa, sb);
  }
  for (std::int32_t k = b_begin; k < b_end; ++k) {
    const int g = q.b.adjacency_faces()[static_cast<std::size_t>(k)];
    if (near_face(q.b, g, n_in_b))
      consider({MinkowskiFace::vertex_face, sa, -1, g, -1},
               Vec3(-(q.rotation * q.b.face_plane(g).normal)), sa, sb);
  }
  for (std::int32_t k = a_begin; k < a_end; ++k) {
    const int w = q.a.adjacency()[static_cast<std::size_t>(k)];
    const Vec3 ea = q.point_a(w) - q.point_a(sa);
    for (std::int32_t l = b_begin; l < b_end; ++l) {
      const int x = q.b.adjacency()[static_cast<std::size_t>(l)];
      Vec3 normal = ea.cross(q.point_b(x) - q.point_b(sb));
      const double length = normal.norm();
      if (!(length > 0.0)) continue;
      normal /= length;
      if (normal.dot(n) < 0.0) normal = -normal;
      consider({MinkowskiFace::edge_edge, std::min(sa, w), std::max(sa, w), std::min(sb, x),
                std::max(sb, x)},
               normal, sa, sb);
    }
  }
  if (count == 0) return std::nullopt;
  const std::span<const Candidate> candidates(kept.data(), count);
  const auto best =
      std::min_element(candidates.begin(), candidates.end(),
                       [](const Candidate& x, const Candidate& y) { return x.value < y.value; });
  if (!accepted(*best)) return std::nullopt;
  return answer(candidates, static_cast<std::size_t>(best - candidates.begin()));
}

bool same_pair(const PenetrationCache& cache, const ConvexPolytope& a, const ConvexPolytope& b) {
  return cache.a == &a && cache.b == &b && cache.fingerprint == fingerprint(a, b);
}

PenetrationResult depth(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                        PenetrationCache& cache, const DepthSeed& seed) {
  Query q(a, b, b_in_a);
  const bool same_polytopes = same_pair(cache, a, b);
  if (!same_polytopes) {
    cache.reset();
  } else if (!cache.facets.empty() && cache.rotation == b_in_a.rotation) {
    PenetrationResult r;
    double margin = 0.0;
    // Else the pruned faces were not recorded, or too many are nearer now:
    // enumerate again, keeping the faces within the margin (track_or_expand
    // set cache.prune_margin to it).
    // An answer near the band is refined by an enumeration (kRefineBands).
    if (track_or_expand(q, cache, b_in_a, r, margin) && !needs_refinement(q, r)) return r;
  }
  // Enumerate, pruned by the last answer's direction when there is one. A
  // rotated B halves the margin (rotating bodies enumerate every query:
  // the fewer faces kept, the faster). The pruned groups are recorded only
  // when the cache's own faces were outgrown by a translation (the next
  // query is likely a translation again): not for a rotated B (likely
  // rotated again) nor for a cold cache (a caller that queries cold every
  // time would pay for tens of thousands of groups at N = 4096 and never
  // use them, bench/penetration_bench's Cold), whose first tracked
  // query certifies with their least bound, as an unrecorded cache does.
  const bool has_start = same_polytopes && !cache.facets.empty();
  if (!has_start)
    if (std::optional<PenetrationResult> r = solve_expanding(q, cache, b_in_a, seed)) return *r;
  const bool turned = has_start && cache.rotation != b_in_a.rotation;
  if (turned)
    if (std::optional<PenetrationResult> r = solve_expanding(q, cache, b_in_a, seed, true))
      return *r;
  if (turned) cache.prune_margin *= 0.5;
  const PenetrationCache::Facet start = has_start ? cache.last : PenetrationCache::Facet{};
  return solve_cold(q, true, &cache, b_in_a, has_start ? &start : nullptr, has_start && !turned);
}

}  // namespace

PenetrationResult penetration_depth_brute_force(const ConvexPolytope& a, const ConvexPolytope& b,
                                                const Pose& b_in_a) {
  Query q(a, b, b_in_a);
  return solve_cold(q, false, nullptr, b_in_a, nullptr, false);
}

PenetrationResult penetration_depth(const ConvexPolytope& a, const ConvexPolytope& b,
                                    const Pose& b_in_a, PenetrationCache& cache,
                                    const DepthSeed& seed) {
  PenetrationResult r = depth(a, b, b_in_a, cache, seed);
  cache.last_status = r.status;
  cache.previous_translation = b_in_a.translation;
  return r;
}

bool penetration_depth_tracked(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                               PenetrationCache& cache, PenetrationResult& out) {
  if (cache.facets.empty() || !same_pair(cache, a, b)) return false;
  if (cache.rotation != b_in_a.rotation) {
    // A turned B: the kept expansion, when there is one. When it does not
    // answer, its surface is dropped, so that penetration_depth (if the
    // caller asks) does not try it twice.
    if (cache.surface.empty()) return false;
    Query q(a, b, b_in_a);
    const std::optional<PenetrationResult> r =
        solve_expanding(q, cache, b_in_a, DepthSeed{}, true);
    cache.previous_translation = b_in_a.translation;
    if (!r) {
      cache.surface.clear();
      return false;
    }
    out = *r;
    cache.last_status = out.status;
    return true;
  }
  Query q(a, b, b_in_a);
  double margin = 0.0;
  // Near the band the answer needs an enumeration (kRefineBands): not
  // certified here.
  const bool certified =
      track_or_expand(q, cache, b_in_a, out, margin) && !needs_refinement(q, out);
  cache.previous_translation = b_in_a.translation;
  if (!certified) return false;
  cache.last_status = out.status;
  return true;
}

}  // namespace proxima
