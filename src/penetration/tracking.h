// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the tracked query: the cached faces under a translation of B, and the expansion of pruned groups.
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include "penetration/face_tree.h"
#include "penetration/witnesses.h"

namespace proxima {
namespace {

// At most this many cached faces are searched one by one, without their
// tree: a few dozen faces are scanned faster than the tree is walked, a
// few hundred are not (bench/penetration_peers' sweep with a warm cache).
constexpr std::size_t kScanFacets = 64;

// B's translation since the enumeration, for the cached faces and groups.
Moved moved_since(const Query& q, const PenetrationCache& cache, const Pose& b_in_a) {
  const Vec3 delta = b_in_a.translation - cache.enumerated_translation;
  return {delta, (delta * q.inverse).norm() * q.unit, b_in_a.translation, q.inverse, q.unit};
}

// The tracked query (a cache of this pair at B's rotation): the least of
// the cached faces' values, certified against the pruned ones. True with
// the answer in `out`; false when a pruned group may be nearer now (then
// `best` is the least cached value, `cache.last` its face). `extra`: work
// of an expansion before it, counted in the answer's candidates.
bool track(Query& q, PenetrationCache& cache, const Pose& b_in_a, PenetrationResult& out,
           double& best_out, int extra = 0) {
  // M is the reference's M translated by -(t - t_ref): the cached facets
  // are all of its facets but the pruned ones, each offset moved by
  // -n.(t - t_ref).
  const double slack = kValueSlackUlps * kUnitRoundoff * q.magnitude;
  const Moved moved = moved_since(q, cache, b_in_a);
  const bool scan = cache.facets.size() <= kScanFacets;
  if (!scan) ensure_forest(cache.facets, cache.nodes, cache.roots, b_in_a.translation, moved);
  TreeSearch<PenetrationCache::Facet> search{cache.facets,
                                             cache.nodes,
                                             b_in_a.translation,
                                             moved,
                                             q.inverse,
                                             q.unit,
                                             entry_value(cache.last, moved),
                                             cache.last,
                                             1};
  if (scan) {
    for (const PenetrationCache::Facet& g : cache.facets) {
      const double value = entry_value(g, moved);
      if (value < search.best) {
        search.best = value;
        search.winner = g;
      }
    }
    search.work += static_cast<int>(cache.facets.size());
  } else {
    for (const std::int32_t r : cache.roots)
      search.visit(r, search.bound(cache.nodes[static_cast<std::size_t>(r)]));
  }
  const double best = search.best;
  const PenetrationCache::Facet& f = search.winner;
  int work = search.work + extra;
  cache.last = f;
  best_out = best;
  // The pruned faces: no group's bound below the best (searched on their
  // forest), or when they were not recorded, their least bound at the
  // enumeration less the distance moved since.
  bool certified = false;
  if (!cache.bounded) {
    certified = best <= cache.pruned - moved.length;
  } else {
    ensure_forest(cache.bounds, cache.bound_nodes, cache.bound_roots, b_in_a.translation, moved);
    TreeSearch<PenetrationCache::Bound> check{
        cache.bounds, cache.bound_nodes, b_in_a.translation, moved, q.inverse, q.unit, best, {}, 0};
    for (std::size_t k = 0; k < cache.bound_roots.size() && !(check.best < best); ++k) {
      const std::int32_t r = cache.bound_roots[k];
      check.visit(r, check.bound(cache.bound_nodes[static_cast<std::size_t>(r)]));
    }
    certified = !(check.best < best);
    work += check.work;
  }
  if (!certified) return false;
  // The winner's value with its true supports: the cached ones, which a
  // translation does not move (hill climbing along the same normal, with
  // B's rotation the same bits, from them stays at them: they were found by
  // it, and it moves only to a strictly larger value).
  Candidate c;
  c.id = f.id;
  c.normal = f.normal;
  c.support_a = f.support_a;
  c.support_b = f.support_b;
  c.value = f.normal.dot(q.point_a(f.support_a) - q.point_b(f.support_b));
  out = finish(q, c, (best - slack) * q.inverse, work, true, &cache.witnesses);
  return true;
}

// The margin of an expansion or of an enumeration after a translation
// outgrew the cache (PenetrationCache::prune_margin): twice the last one,
// at least this many of B's last steps and a small fraction of the bodies'
// radii, at most half of them (a B that jumps keeps pruning). A margin of
// a few steps that does not grow is outgrown again and again when B nears
// A's centre, where all the faces of A - B are near the best value: each
// expansion then reopens hundreds to thousands of groups whose bounds had
// just passed it. Doubling, from 32 steps, keeps those expansions rare
// (bench/penetration_peers' sweep, B through A and back).
constexpr double kMarginSteps = 32.0;
// The margin's floor as a share of the bodies' radii: a B that barely
// moves (its last step near 0) still keeps the faces within 1/1024 of the
// radii of the best value, so that its next small steps are tracked
// rather than enumerated again.
constexpr double kMarginRadiiShare = 0x1p-10;

double translation_margin(const ConvexPolytope& a, const ConvexPolytope& b,
                          const PenetrationCache& cache, const Pose& b_in_a) {
  const double radii = a.bounding_radius() + b.bounding_radius();
  const double step = (b_in_a.translation - cache.previous_translation).norm();
  return std::min(
      std::max({2.0 * cache.prune_margin, kMarginSteps * step, kMarginRadiiShare * radii}),
      0.5 * radii);
}

// Expands the pruned groups whose bound at B's translation is below `best`
// (the least cached value) plus `margin`: each is enumerated alone at this
// pose, by the enumeration's own loops (Query::only), pruned against the
// best value with the margin, its faces added to the cache (their offsets
// moved back to the enumeration's translation: value + n.(t -
// t_enumeration), as a cached face's) and its own pruned groups recorded,
// anchored here; the group itself is dropped (lower +infinity). Then every
// group's bound is at least the best value again, up to the faces found.
// An expansion costs at most what an enumeration would (it tests the
// groups it expands, the enumeration all of them, and evaluates no face
// twice), so it is never refused; the false return (nothing changed) is
// for no group below the threshold. The work (faces evaluated) in
// `work`.
bool expand(Query& q, PenetrationCache& cache, const Pose& b_in_a, double best, double margin,
            int& work) {
  const Moved moved = moved_since(q, cache, b_in_a);
  const double threshold = best + margin;
  std::vector<int> failing;
  ensure_forest(cache.bounds, cache.bound_nodes, cache.bound_roots, b_in_a.translation, moved);
  TreeSearch<PenetrationCache::Bound> collect{cache.bounds,
                                              cache.bound_nodes,
                                              b_in_a.translation,
                                              moved,
                                              q.inverse,
                                              q.unit,
                                              threshold,
                                              {},
                                              0,
                                              &failing};
  for (const std::int32_t r : cache.bound_roots)
    collect.visit(r, collect.bound(cache.bound_nodes[static_cast<std::size_t>(r)]));
  if (failing.empty()) return false;
  Subset subset;
  for (const int i : failing) {
    PenetrationCache::Bound& g = cache.bounds[static_cast<std::size_t>(i)];
    switch (g.kind) {
      case PenetrationCache::Group::face_a:
        subset.faces_a.push_back(g.i);
        break;
      case PenetrationCache::Group::face_b:
        subset.faces_b.push_back(g.i);
        break;
      case PenetrationCache::Group::vertex_a:
        subset.edges_a.push_back({g.i, -1});
        break;
      case PenetrationCache::Group::edge_a:
        subset.edges_a.push_back({g.i, g.j});
        break;
    }
    g.lower = kInfinity;
  }
  // In the enumeration's order (its hints for the other hull's supports
  // follow neighbouring faces).
  std::sort(subset.faces_a.begin(), subset.faces_a.end());
  std::sort(subset.faces_b.begin(), subset.faces_b.end());
  std::sort(subset.edges_a.begin(), subset.edges_a.end());
  cache.expanded += static_cast<std::int32_t>(failing.size());
  std::vector<PenetrationCache::Bound> fresh;
  // The enumeration's loops keep their lists in the query's scratch memory.
  ScratchScope scratch(q);
  q.use_shapes(cache.shapes, true);
  q.prune = true;
  q.bound = best * q.inverse;
  q.set_references(cache.last.support_a, cache.last.support_b);
  q.prune_margin = margin * q.inverse;
  q.bounds_out = &fresh;
  q.only = &subset;
  Candidates found(q.memory);
  add_face_candidates(q, found);
  if (!subset.edges_a.empty()) add_edge_candidates_walk(q, found);
  q.only = nullptr;
  q.bounds_out = nullptr;
  const Vec3 since = b_in_a.translation - cache.enumerated_translation;
  const int old_facets = static_cast<int>(cache.facets.size());
  const int old_bounds = static_cast<int>(cache.bounds.size());
  for (const Candidate& c : found)
    cache.facets.push_back(
        {c.id, c.normal, c.value * q.unit + c.normal.dot(since), c.support_a, c.support_b});
  cache.bounds.insert(cache.bounds.end(), fresh.begin(), fresh.end());
  work = static_cast<int>(found.size());
  ++cache.expansions;
  // The new entries get trees of their own in the forests; the groups are
  // compacted (and their forest built again by the next search) when the
  // expanded ones are half of them.
  add_tree(cache.facets, cache.nodes, cache.roots, old_facets, b_in_a.translation, moved);
  if (2 * static_cast<std::size_t>(cache.expanded) > cache.bounds.size()) {
    std::erase_if(cache.bounds,
                  [](const PenetrationCache::Bound& g) { return g.lower == kInfinity; });
    cache.expanded = 0;
    cache.bound_nodes.clear();
    cache.bound_roots.clear();
  } else {
    add_tree(cache.bounds, cache.bound_nodes, cache.bound_roots, old_bounds, b_in_a.translation,
             moved);
  }
  return true;
}

// The tracked query, expanding the pruned groups a translation reached
// (at most twice: the second search certifies unless rounding decided a
// group at the threshold). False when the cache needs an enumeration: the
// groups were not recorded (or two expansions did not certify); then
// `margin` is the one to enumerate with.
bool track_or_expand(Query& q, PenetrationCache& cache, const Pose& b_in_a, PenetrationResult& out,
                     double& margin) {
  double best = 0.0;
  if (track(q, cache, b_in_a, out, best)) return true;
  margin = translation_margin(q.a, q.b, cache, b_in_a);
  cache.prune_margin = margin;
  if (!cache.bounded) return false;
  int work = 0;
  for (int round = 0; round < 2; ++round) {
    int more = 0;
    if (!expand(q, cache, b_in_a, best, margin, more)) return false;
    work += more;
    if (track(q, cache, b_in_a, out, best, work)) return true;
  }
  return false;
}

}  // namespace
}  // namespace proxima
