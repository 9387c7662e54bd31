// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the distance between two triangle meshes (mesh.h). A branch
// and bound over pairs of hierarchy nodes with a running upper bound (the
// best triangle pair so far), the triangle-triangle kernel at the leaves,
// the status from exact predicates, and tracking through MeshCache. The
// pair's frame, bounds and kernels are in mesh_pair.h.
#include "proxima/query/mesh_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "query/branch_and_bound.h"
#include "query/mesh_pair.h"

namespace proxima {
using namespace detail::mesh_pair;

namespace {

// A candidate pair of a tracking list: every tested pair that may end
// within the list's margin of the best (filtered against the final best).
struct Candidate {
  std::int32_t ta, tb;
  double d2;
};

// A node pair waiting: its squared box bound and, for ties of it, the
// squared distance of the boxes' centers.
struct NodePair {
  std::int32_t na, nb;
  double lb2;
  double center2;
};

// Best first (a binary heap of node pairs, the smallest lower bound on
// top, ties to the nearer centers), each pair taken out followed by a dive
// to a leaf pair along the nearer child (detail::branch_and_bound): the
// first leaves reached are near the closest pair, so the upper bound is
// tight early and prunes most of the rest: far fewer triangle pairs than a
// depth-first stack, cold and along a motion (bench/mesh_bench, env/rob).
// A plain heap without the dive tests about as few pairs but pays heap
// work for every node pair (slower when the meshes are apart); a
// depth-first stack with the same tie rule stays slower than this.
struct Later {
  bool operator()(const NodePair& x, const NodePair& y) const {
    return x.lb2 > y.lb2 || (x.lb2 == y.lb2 && x.center2 > y.center2);
  }
};

// The branch and bound of distance() as detail::branch_and_bound takes it:
// from `best` (the last pair, or none), every node pair whose bound is
// below best + 2 margin + slack_s (scaled), collecting the tested pairs
// within that into `candidates` (while margin > 0; `overflow` past 4
// kNearCapacity). It stops when the best pair reaches stop2 (the hulls'
// bound, -1 for none; reached_hull()): the pairs left are then no closer.
class DistanceSearch {
 public:
  DistanceSearch(const Query& q, double margin, double slack_s, double stop2, Best& best,
                 int& tested, int& nodes_tested, std::vector<Candidate>& candidates,
                 bool& overflow)
      : q_(q),
        margin_(margin),
        slack_s_(slack_s),
        stop2_(stop2),
        best_(best),
        tested_(tested),
        nodes_tested_(nodes_tested),
        candidates_(candidates),
        overflow_(overflow),
        nodes_a_(q.a.nodes()),
        nodes_b_(q.b.nodes()),
        order_a_(q.a.triangle_order()),
        order_b_(q.b.triangle_order()),
        stamp_(++query_stamp()) {
    prune2_ = threshold2();
    reached_hull_ = best_.d2 <= stop2_;
  }

  bool reached_hull() const { return reached_hull_; }

  bool done() const { return best_.crossing || reached_hull_; }
  NodePair root() const { return {0, 0, 0.0, 0.0}; }
  // The pair taken out has the least bound: past the threshold, every
  // other pair's bound is as large.
  bool stale(const NodePair& e) const { return e.lb2 > prune2_; }
  bool prune(const NodePair& e) const { return e.lb2 > prune2_; }
  bool leaves(const NodePair& e) const {
    return nodes_a_[static_cast<std::size_t>(e.na)].is_leaf() &&
           nodes_b_[static_cast<std::size_t>(e.nb)].is_leaf();
  }

  void test_leaves(const NodePair& e) {
    const TriangleMesh::Node& na = nodes_a_[static_cast<std::size_t>(e.na)];
    const TriangleMesh::Node& nb = nodes_b_[static_cast<std::size_t>(e.nb)];
    const LeafSlot& leaf_a = leaf(slots_a(), e.na, na, true);
    const LeafSlot& leaf_b = leaf(slots_b(), e.nb, nb, false);
    // Each triangle against the other leaf's box first (both in the
    // query frame): a triangle farther than the limit from every
    // triangle of the other leaf skips its row or column of pairs.
    const double box_limit = std::sqrt(prune2_) + kBoxSlackUlps * kUnitRoundoff;
    unsigned columns = 0;
    for (std::int32_t j = 0; j < nb.count; ++j) {
      const Triangles& tj = leaf_b.t[static_cast<std::size_t>(j)];
      if (box_gap_squared(tj.lo, tj.hi, leaf_a.lo, leaf_a.hi) <= box_limit * box_limit)
        columns |= 1u << j;
    }
    for (std::int32_t i = 0; i < na.count && columns != 0 && !best_.crossing; ++i) {
      const Triangles& ti = leaf_a.t[static_cast<std::size_t>(i)];
      if (box_gap_squared(ti.lo, ti.hi, leaf_b.lo, leaf_b.hi) > box_limit * box_limit) continue;
      for (std::int32_t j = 0; j < nb.count; ++j) {
        if ((columns >> j & 1u) == 0) continue;
        const Triangles& tj = leaf_b.t[static_cast<std::size_t>(j)];
        const double before = best_.d2;
        const double d2 = test_pair(q_, ti, tj, best_, tested_, std::sqrt(prune2_));
        if (best_.d2 < before) prune2_ = threshold2();
        if (best_.crossing) break;
        if (margin_ > 0.0 && !overflow_ && d2 <= prune2_) {
          // Every tested pair that may end within the margin; filtered
          // against the final best at the end.
          candidates_.push_back({ti.id, tj.id, d2});
          overflow_ = candidates_.size() > 4 * kNearCapacity;
        }
      }
    }
    prune2_ = threshold2();
    reached_hull_ = best_.d2 <= stop2_;
  }

  // The children of the larger box (by the sum of half extents; an inner
  // node against a leaf: the inner one), the nearer first (Later).
  std::pair<NodePair, NodePair> split(const NodePair& e) {
    const TriangleMesh::Node& na = nodes_a_[static_cast<std::size_t>(e.na)];
    const TriangleMesh::Node& nb = nodes_b_[static_cast<std::size_t>(e.nb)];
    const Box ba = node_box(na, q_.box_unit_a);
    const Box bb = node_box(nb, q_.box_unit_b);
    const bool split_a = !na.is_leaf() && (nb.is_leaf() || ba.half.sum() >= bb.half.sum());
    NodePair c0, c1;
    if (split_a) {
      // B's box in A's frame, shared by both children.
      const Vec3 cb = q_.rotation * bb.center + q_.translation_s;
      const Vec3 extent_b = q_.abs_rotation * bb.half;
      const std::int32_t l = e.na + 1, r = na.first_or_right;
      const Box b0 = node_box(nodes_a_[static_cast<std::size_t>(l)], q_.box_unit_a);
      const Box b1 = node_box(nodes_a_[static_cast<std::size_t>(r)], q_.box_unit_a);
      c0 = {l, e.nb, lower_bound_on_a_axes(q_, b0, bb, cb, extent_b, prune2_),
            (b0.center - cb).squaredNorm()};
      c1 = {r, e.nb, lower_bound_on_a_axes(q_, b1, bb, cb, extent_b, prune2_),
            (b1.center - cb).squaredNorm()};
    } else {
      // A's box in B's frame, shared by both children.
      const Vec3 ca = q_.rotation.transpose() * (ba.center - q_.translation_s);
      const Vec3 extent_a = q_.abs_rotation.transpose() * ba.half;
      const std::int32_t l = e.nb + 1, r = nb.first_or_right;
      const Box b0 = node_box(nodes_b_[static_cast<std::size_t>(l)], q_.box_unit_b);
      const Box b1 = node_box(nodes_b_[static_cast<std::size_t>(r)], q_.box_unit_b);
      c0 = {e.na, l, lower_bound_on_b_axes(q_, ba, b0, ca, extent_a, prune2_),
            (b0.center - ca).squaredNorm()};
      c1 = {e.na, r, lower_bound_on_b_axes(q_, ba, b1, ca, extent_a, prune2_),
            (b1.center - ca).squaredNorm()};
    }
    nodes_tested_ += 2;
    if (Later{}(c0, c1)) std::swap(c0, c1);
    return {c0, c1};
  }

 private:
  // Prepared leaves, direct-mapped by node id: a dive meets the same leaf
  // against several leaves of the other mesh in a row. Per thread (the
  // query is reentrant), stamped with this query so that no leaf placed at
  // another query's pose is used. 128 slots a side (a few hundred KB per
  // thread); with the best-first traversal fewer or more slots measure the
  // same (bench/mesh_bench, env/rob): the size is not critical.
  struct LeafSlot {
    std::uint64_t stamp = 0;
    std::int32_t node = -1;
    std::array<Triangles, TriangleMesh::kLeafSize> t;
    Vec3 lo, hi;  // the union of the triangles' boxes (query frame)
  };
  static constexpr std::size_t kSlots = 128;
  using Slots = std::array<LeafSlot, kSlots>;
  static Slots& slots_a() {
    thread_local Slots slots;
    return slots;
  }
  static Slots& slots_b() {
    thread_local Slots slots;
    return slots;
  }
  static std::uint64_t& query_stamp() {
    thread_local std::uint64_t stamp = 0;
    return stamp;
  }

  const LeafSlot& leaf(Slots& slots, std::int32_t node, const TriangleMesh::Node& n,
                       bool side_a) const {
    LeafSlot& slot = slots[static_cast<std::size_t>(node) % kSlots];
    if (slot.stamp != stamp_ || slot.node != node) {
      slot.stamp = stamp_;
      slot.node = node;
      slot.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      slot.hi = -slot.lo;
      for (std::int32_t i = 0; i < n.count; ++i) {
        const auto k = static_cast<std::size_t>(n.first_or_right + i);
        Triangles& t = slot.t[static_cast<std::size_t>(i)];
        t = side_a ? a_triangle(q_, order_a_[k]) : b_triangle(q_, order_b_[k]);
        slot.lo = slot.lo.cwiseMin(t.lo);
        slot.hi = slot.hi.cwiseMax(t.hi);
      }
    }
    return slot;
  }

  double threshold2() const {
    const double t = std::sqrt(best_.d2) + 2.0 * margin_ + slack_s_;
    return t * t;
  }

  const Query& q_;
  double margin_;
  double slack_s_;
  double stop2_;
  Best& best_;
  int& tested_;
  int& nodes_tested_;
  std::vector<Candidate>& candidates_;
  bool& overflow_;
  std::span<const TriangleMesh::Node> nodes_a_, nodes_b_;
  std::span<const std::int32_t> order_a_, order_b_;
  std::uint64_t stamp_;
  double prune2_ = 0.0;
  bool reached_hull_ = false;
};

// The search of distance() (DistanceSearch); returns whether it stopped
// because the best pair reached stop2.
bool best_first_search(const Query& q, double margin, double slack_s, double stop2, Best& best,
                       int& tested, int& nodes_tested, std::vector<Candidate>& candidates,
                       bool& overflow) {
  DistanceSearch search(q, margin, slack_s, stop2, best, tested, nodes_tested, candidates,
                        overflow);
  std::vector<NodePair> heap;
  heap.reserve(256);
  detail::BestFirst<NodePair, Later> frontier(heap, Later{});
  detail::branch_and_bound(search, frontier);
  return search.reached_hull();
}

}  // namespace

MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                              const Pose& pose_b, const DistanceOptions& options) {
  const Query q = make_query(a, pose_a, b, pose_b, options);
  std::vector<Triangles> tb(static_cast<std::size_t>(b.triangle_count()));
  for (std::int32_t j = 0; j < b.triangle_count(); ++j)
    tb[static_cast<std::size_t>(j)] = b_triangle(q, j);
  Best best;
  int tested = 0;
  for (std::int32_t i = 0; i < a.triangle_count() && !best.crossing; ++i) {
    const Triangles ta = a_triangle(q, i);
    for (const Triangles& t : tb) {
      test_pair(q, ta, t, best, tested);
      if (best.crossing) break;
    }
  }
  const Containment inside = best.crossing ? Containment{} : contained(q);
  MeshResult r = finish(q, pose_a, best, inside);
  r.pairs_tested = tested;
  return r;
}

MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                    const Pose& pose_b, const DistanceOptions& options, MeshCache* cache) {
  Query q = make_query(a, pose_a, b, pose_b, options);
  const double slack_s = detail::prune_slack(std::ldexp(q.magnitude, -q.exponent));
  const double unscaled_slack = std::ldexp(slack_s, q.exponent);
  Best best;
  int tested = 0;
  int nodes_tested = 0;

  // A cache of another pair starts over (its hull state and triangles
  // belong to other meshes).
  if (cache != nullptr && (cache->mesh_a != a.id() || cache->mesh_b != b.id())) {
    cache->reset();
    cache->mesh_a = a.id();
    cache->mesh_b = b.id();
  }
  const bool same_pair = cache != nullptr;
  HullBound hull;
  if (cache != nullptr && cache->hull_wait > 0) {
    --cache->hull_wait;
  } else {
    hull = hull_bound(q, options, cache != nullptr ? &cache->hull : nullptr);
    if (cache != nullptr && hull.apart) {
      cache->hull_backoff = 0;
    } else if (cache != nullptr) {
      cache->hull_backoff = static_cast<std::uint8_t>(std::min(2 * cache->hull_backoff + 1, 32));
      cache->hull_wait = cache->hull_backoff;
    }
  }
  const auto remember = [&] {
    cache->triangle_a = best.ta;
    cache->triangle_b = best.tb;
    cache->last_rotation = q.rotation;
    cache->last_translation = q.translation;
  };

  // The last closest pair: an upper bound before any search, and the
  // answer when it reaches the hulls' lower bound.
  if (same_pair && cache->triangle_a >= 0 && cache->triangle_a < a.triangle_count() &&
      cache->triangle_b >= 0 && cache->triangle_b < b.triangle_count()) {
    test_pair(q, a_triangle(q, cache->triangle_a), b_triangle(q, cache->triangle_b), best, tested);
    if (best.d2 <= hull.stop2) {
      MeshResult r = finish(q, pose_a, best, Containment{});
      r.lower_bound = std::min(r.lower_bound, hull.lower);
      r.pairs_tested = tested;
      r.tracked = true;
      remember();
      return r;
    }
  }

  double last_step = std::numeric_limits<double>::infinity();
  if (same_pair && cache->triangle_a >= 0) {
    last_step =
        motion_bound(b, cache->last_rotation, cache->last_translation, q.rotation, q.translation);
  }

  // Tracked: the candidate pairs are enough while B moved less than the
  // margin since they were collected (see MeshCache).
  // A list that did not pay delays the next collections (MeshCache).
  const auto list_failed = [&] {
    cache->list_backoff = static_cast<std::uint8_t>(std::min(2 * cache->list_backoff + 1, 32));
    cache->list_wait = cache->list_backoff;
  };
  if (same_pair && !cache->near.empty()) {
    const double moved =
        motion_bound(b, cache->rotation, cache->translation, q.rotation, q.translation);
    if (!(moved + unscaled_slack <= cache->margin) && cache->list_uses == 0) list_failed();
    if (moved + unscaled_slack <= cache->margin) {
      cache->list_uses = static_cast<std::uint16_t>(std::min(cache->list_uses + 1, 0xffff));
      cache->list_backoff = 0;
      for (const auto& pair : cache->near) {
        test_pair(q, a_triangle(q, pair[0]), b_triangle(q, pair[1]), best, tested,
                  std::sqrt(best.d2) + slack_s);
        if (best.crossing) break;
      }
      // The containment found at the list's collection still holds while
      // B moved less than the surfaces' distance then: the contained vertex
      // cannot have crossed the other surface.
      Containment inside;
      if (!best.crossing && !hull.apart) {
        inside = moved + unscaled_slack < cache->base_distance && cache->inside >= 0
                     ? Containment{cache->inside, cache->inside_vertex}
                     : contained(q);
      }
      MeshResult r = finish(q, pose_a, best, inside);
      r.pairs_tested = tested;
      r.tracked = true;
      remember();
      return r;
    }
  }

  // The margin of a new candidate list (scaled), 0 for none.
  // Hulls apart: no list. The hulls' bound and the last pair already make
  // the tracked search the cold one with a tight first upper bound, and a
  // list's wider search costs more than it saves there (on a planner's
  // steps the closest pair wanders over near-parallel faces, whose pairs
  // within the margin overflow the list). Lists serve the pairs whose
  // hulls overlap (a body moving inside or around another).
  double margin = 0.0;
  if (hull.apart) {
    // no list
  } else if (cache != nullptr && same_pair && cache->list_wait > 0) {
    --cache->list_wait;
  } else if (cache != nullptr && same_pair && std::isfinite(last_step) &&
             kMarginSteps * last_step <= kMarginRadiusFraction * b_radius(b)) {
    margin = std::max(kMarginSteps * last_step, 4.0 * unscaled_slack) * q.factor;
  }
  std::vector<Candidate> candidates;
  bool overflow = false;
  const bool reached_hull = best_first_search(q, margin, slack_s, hull.stop2, best, tested,
                                              nodes_tested, candidates, overflow);

  // Hulls apart: no surface crosses or holds the other.
  const Containment inside = best.crossing || hull.apart ? Containment{} : contained(q);
  MeshResult r = finish(q, pose_a, best, inside);
  if (reached_hull) r.lower_bound = std::min(r.lower_bound, hull.lower);
  r.pairs_tested = tested;
  r.nodes_tested = nodes_tested;
  if (cache != nullptr) {
    remember();
    cache->near.clear();
    // A search stopped at the hulls' bound did not meet every pair within
    // the margin: no list from it.
    if (margin > 0.0 && !overflow && !best.crossing && !reached_hull) {
      // Keep the tested pairs within the margin of the final best: every
      // pair left out is farther than best + 2 margin (pruned by its
      // node pair's bound, or by its own distance here).
      const double keep = std::sqrt(best.d2) + 2.0 * margin + slack_s;
      // Closest first: a tracked query then finds its best early and skips
      // the rest by their boxes.
      std::sort(candidates.begin(), candidates.end(),
                [](const Candidate& x, const Candidate& y) { return x.d2 < y.d2; });
      for (const Candidate& c : candidates)
        if (c.d2 <= keep * keep) cache->near.push_back({c.ta, c.tb});
      if (cache->near.size() <= kNearCapacity) {
        cache->list_uses = 0;
        cache->base_distance = std::ldexp(std::sqrt(best.d2), q.exponent);
        cache->margin = std::ldexp(margin, q.exponent);
        cache->rotation = q.rotation;
        cache->translation = q.translation;
        cache->inside = inside.side;
        cache->inside_vertex = inside.vertex;
      } else {
        cache->near.clear();
        list_failed();
      }
    } else if (margin > 0.0 && overflow) {
      list_failed();
    }
  }
  return r;
}

}  // namespace proxima
