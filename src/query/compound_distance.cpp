// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The branch-and-bound distance between two compound bodies (over the
// bounding-sphere hierarchies of src/shape/compound.cpp) and its slow twin
// over all piece pairs.
//
// Soundness of the pruning. A node pair is skipped only when its computed
// lower bound, minus a slack for the rounding of that bound, exceeds the best
// distance found so far. The exact lower bound is then above that best
// distance, so every piece pair below is truly farther than an answer already
// in hand: the pruned pairs can never hide a closer pair, and the answer is
// the minimum over the tested pairs, each within the accuracy standard.
#include "proxima/query/compound_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_set>
#include <utility>

#include "core/accuracy.h"
#include "core/power_of_two.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "query/branch_and_bound.h"

namespace proxima {

namespace {

// The slack of a node pair's lower bound is detail::prune_slack of the
// larger world magnitude bound (core/accuracy.h): the centers in the query
// frame are a pose product and a transformed point away from the stored
// doubles (a few u of the translations and coordinates each), and the convex
// query itself places the pieces through a differently rounded product.
// And relative to the bound's own terms (center distance plus radii): the
// norm and the two subtractions round by at most 4 u of them.
constexpr double kPruneRelativeUlps = 64.0;

// The farthest entries the near list keeps: the tested piece pairs of the
// last answer, closest first, up to this many. A tracked query re-tests
// about the same pairs; 64 covers every near set the tests and benchmarks
// produce (a few to a few dozen pairs) while bounding the cache's size.
constexpr std::size_t kNearCapacity = 64;

using detail::magnitude_exponent;


// Upper bound on the largest world coordinate of a body placed at `pose`:
// |R y + t|_inf <= |t|_inf + |y|_2 <= |t|_inf + sqrt(3) scale.
double world_magnitude_bound(const CompoundBody& body, const Pose& pose) {
  return magnitude_bound(pose, body.scale());
}

// Whether (signed distance, intersecting, pair) orders `r` before the
// current best: the smaller signed distance (the distance when apart, minus
// the depth when overlapping), then an intersecting pair before a touching
// one at the same value, then the smaller (piece_a, piece_b).
bool better(const DistanceResult& r, std::int32_t pa, std::int32_t pb, const CompoundResult& best) {
  const double sr = r.signed_distance();
  const double sb = best.signed_distance();
  if (sr != sb) return sr < sb;
  const bool ri = r.status == Status::intersecting;
  const bool bi = best.status == Status::intersecting;
  if (ri != bi) return ri;
  return std::pair(pa, pb) < std::pair(best.piece_a, best.piece_b);
}

void take(CompoundResult& best, const DistanceResult& r, std::int32_t pa, std::int32_t pb) {
  static_cast<DistanceResult&>(best) = r;
  best.piece_a = pa;
  best.piece_b = pb;
}

// The certificate of a search's answer `best` over every tested pair, not
// the best pair's alone: the lower bounds are the least over the tested
// pairs' (`lower`, `signed_lower`), since a tested pair that ended with a
// loose bound (an iteration cap, an uncertified depth) may hold a closer
// pair than the best reported value
// (CompoundRegression.LowerBoundCoversALooselyCertifiedPair). Pruned node
// pairs need no term: a key prunes only above the best signed distance at
// that time, which the final best's does not exceed, and that is at least
// the final best's lower bounds. Node pairs left unvisited by an early end
// (an intersection without the depth) need none either: the answer's
// bounds are then 0 and -infinity, below any key. The signed distance of
// the compounds is the least over pairs, so each tested pair's signed
// upper bound bounds it too: the upper bound is the least of them
// (`signed_upper`), tighter than the best pair's own when that pair's
// depth is loosely bounded below. It never goes below the reported value:
// each pair's upper bound is at least its value, at least the best's.
void certify_over_pairs(CompoundResult& best, double lower, double signed_lower,
                        double signed_upper) {
  best.lower_bound = std::min(best.lower_bound, lower);
  const double own_lower = best.signed_lower_bound();
  if (signed_lower < own_lower) best.depth_upper_bound += own_lower - signed_lower;
  if (signed_upper < best.signed_upper_bound() && signed_upper >= best.signed_distance())
    best.depth_lower_bound = best.distance - signed_upper;
}

struct NearEntry {
  CompoundCache::Entry entry;
  double distance;
};

bool pair_less(const CompoundCache::Entry& x, const CompoundCache::Entry& y) {
  return std::pair(x.piece_a, x.piece_b) < std::pair(y.piece_a, y.piece_b);
}

// The sphere bounds of a query (the branch and bound's and the margin
// query's). Lower bounds are computed in A's frame on copies scaled by
// 2^-e, e the exponent of the two bodies' magnitude bound, so that no
// square overflows at any scale the polytopes accept.
class SphereBounds {
 public:
  SphereBounds(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
               const Pose& pose_b) {
    const double magnitude_a = world_magnitude_bound(a, pose_a);
    const double magnitude_b = world_magnitude_bound(b, pose_b);
    // The factor 2^-e as a normal double (clamped_magnitude_exponent): an
    // underflow in a product with it only lowers a bound, never a wrong prune.
    const double magnitude = std::max(magnitude_a, magnitude_b);
    const int e = detail::clamped_magnitude_exponent(magnitude);
    factor_ = std::ldexp(1.0, -e);
    rotation_ = pose_a.rotation.transpose() * pose_b.rotation;
    translation_ =
        pose_a.rotation.transpose() * (factor_ * pose_b.translation - factor_ * pose_a.translation);
    slack_ = detail::prune_slack(factor_ * magnitude);
  }

  // 2^-e: scaled units per world unit.
  double factor() const { return factor_; }

  // The pruning key of two spheres (body frames): their scaled lower bound
  // minus its rounding slack. An overflowing distance cannot occur on scaled
  // copies; the key is -inf (never pruned) should it anyway.
  double key(const Vec3& center_a, double radius_a, const Vec3& center_b_in_a_scaled,
             double radius_b) const {
    const double d = (factor_ * center_a - center_b_in_a_scaled).norm();
    if (!std::isfinite(d)) return -std::numeric_limits<double>::infinity();
    const double ra = factor_ * radius_a;
    const double rb = factor_ * radius_b;
    return d - ra - rb - slack_ - kPruneRelativeUlps * kUnitRoundoff * (d + ra + rb);
  }
  Vec3 b_center_in_a(const Vec3& c) const { return rotation_ * (factor_ * c) + translation_; }

 private:
  double factor_ = 1.0;  // 2^-e, e the exponent of the magnitude bound
  Mat3 rotation_;        // B's frame -> A's frame
  Vec3 translation_;     // scaled by factor_
  double slack_ = 0.0;   // scaled
};

// A pair of nodes of the two hierarchies and its pruning key (scaled:
// SphereBounds::key).
struct NodePair {
  std::int32_t node_a;
  std::int32_t node_b;
  double key;
};

// The node pairs of two compounds for detail::branch_and_bound: the roots'
// pair, and the split of the larger sphere (a leaf cannot be split: it
// shrinks the bound the most per level), the nearer child pair first (a tie
// to the right child: the order the searches were measured with).
class NodePairs {
 public:
  NodePairs(const CompoundBody& a, const CompoundBody& b, const SphereBounds& bounds)
      : a_(a), b_(b), bounds_(bounds) {}

  NodePair root() const {
    const CompoundBody::Node& na = a_.nodes()[0];
    const CompoundBody::Node& nb = b_.nodes()[0];
    return {0, 0, bounds_.key(na.center, na.radius, bounds_.b_center_in_a(nb.center), nb.radius)};
  }
  bool leaves(const NodePair& e) const {
    return node_a(e).left < 0 && node_b(e).left < 0;
  }
  const CompoundBody::Node& node_a(const NodePair& e) const {
    return a_.nodes()[static_cast<std::size_t>(e.node_a)];
  }
  const CompoundBody::Node& node_b(const NodePair& e) const {
    return b_.nodes()[static_cast<std::size_t>(e.node_b)];
  }

  std::pair<NodePair, NodePair> split(const NodePair& e) const {
    const auto& nodes_a = a_.nodes();
    const auto& nodes_b = b_.nodes();
    const CompoundBody::Node& na = node_a(e);
    const CompoundBody::Node& nb = node_b(e);
    const bool leaf_a = na.left < 0;
    const bool leaf_b = nb.left < 0;
    const bool split_a = !leaf_a && (leaf_b || na.radius >= nb.radius);
    NodePair first{};
    NodePair second{};
    if (split_a) {
      const Vec3 cb = bounds_.b_center_in_a(nb.center);
      const CompoundBody::Node& l = nodes_a[static_cast<std::size_t>(na.left)];
      const CompoundBody::Node& r = nodes_a[static_cast<std::size_t>(na.right)];
      first = {na.left, e.node_b, bounds_.key(l.center, l.radius, cb, nb.radius)};
      second = {na.right, e.node_b, bounds_.key(r.center, r.radius, cb, nb.radius)};
    } else {
      const CompoundBody::Node& l = nodes_b[static_cast<std::size_t>(nb.left)];
      const CompoundBody::Node& r = nodes_b[static_cast<std::size_t>(nb.right)];
      first = {e.node_a, nb.left,
               bounds_.key(na.center, na.radius, bounds_.b_center_in_a(l.center), l.radius)};
      second = {e.node_a, nb.right,
                bounds_.key(na.center, na.radius, bounds_.b_center_in_a(r.center), r.radius)};
    }
    if (first.key < second.key) std::swap(first, second);
    return {second, first};
  }

 private:
  const CompoundBody& a_;
  const CompoundBody& b_;
  const SphereBounds& bounds_;
};

// One branch-and-bound query.
class Search {
 public:
  Search(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b, const Pose& pose_b,
         const DistanceOptions& options, CompoundCache* cache)
      : a_(a),
        b_(b),
        pose_a_(pose_a),
        pose_b_(pose_b),
        options_(options),
        cache_(cache),
        bounds_(a, pose_a, b, pose_b),
        pairs_(a, b, bounds_) {
    // A near list the caller did not keep sorted is ignored (a binary search
    // on it could miss entries): slower, never wrong.
    if (cache_ != nullptr && std::is_sorted(cache_->near.begin(), cache_->near.end(), pair_less)) {
      old_near_ = std::span<CompoundCache::Entry>(cache_->near);
    }
  }

  CompoundResult run() {
    if (cache_ != nullptr && cache_->piece_a >= 0 && cache_->piece_a < a_.piece_count() &&
        cache_->piece_b >= 0 && cache_->piece_b < b_.piece_count()) {
      hint_a_ = cache_->piece_a;
      hint_b_ = cache_->piece_b;
      test_pair(hint_a_, hint_b_);
    }
    if (!done()) traverse();
    certify();
    best_.pairs_tested = static_cast<int>(tested_.size());
    if (cache_ != nullptr) update_cache();
    return best_;
  }

 private:
  double key(const Vec3& center_a, double radius_a, const Vec3& center_b_in_a_scaled,
             double radius_b) const {
    return bounds_.key(center_a, radius_a, center_b_in_a_scaled, radius_b);
  }
  Vec3 b_center_in_a(const Vec3& c) const { return bounds_.b_center_in_a(c); }
  bool pruned(double k) const { return have_best_ && k > best_scaled_; }

  void traverse() {
    detail::DepthFirst<NodePair> frontier(stack_);
    detail::branch_and_bound(*this, frontier);
  }

 public:
  // The search as detail::branch_and_bound takes it (branch_and_bound.h).
  // An overlap ends the search only when the depth is not asked for: with
  // it, a deeper piece pair may still come (the pruning keys are lower
  // bounds on the signed distance too: a piece pair inside two spheres is
  // at most as deep as the spheres, whose depth is r_a + r_b - |c_a - c_b|,
  // depth being monotone under inclusion).
  bool done() const {
    return have_best_ && best_.status == Status::intersecting && !options_.penetration;
  }
  // The roots' pair is never pruned (a key of -infinity): its key would
  // bound nothing its children's do not. A waiting pair is looked at again
  // when taken out: the best may have come below its key since.
  NodePair root() const { return {0, 0, -std::numeric_limits<double>::infinity()}; }
  bool stale(const NodePair& e) const { return pruned(e.key); }
  bool prune(const NodePair& e) const { return pruned(e.key); }
  bool leaves(const NodePair& e) const { return pairs_.leaves(e); }
  std::pair<NodePair, NodePair> split(const NodePair& e) const { return pairs_.split(e); }
  void test_leaves(const NodePair& e) { test_leaves(pairs_.node_a(e), pairs_.node_b(e)); }

 private:
  void test_leaves(const CompoundBody::Node& na, const CompoundBody::Node& nb) {
    const auto order_a = a_.piece_order();
    const auto order_b = b_.piece_order();
    for (std::int32_t i = 0; i < na.count && !done(); ++i) {
      const std::int32_t pa = order_a[static_cast<std::size_t>(na.first + i)];
      for (std::int32_t j = 0; j < nb.count && !done(); ++j) {
        const std::int32_t pb = order_b[static_cast<std::size_t>(nb.first + j)];
        if (pa == hint_a_ && pb == hint_b_) continue;  // tested first
        if (na.count > 1 || nb.count > 1) {
          const CompoundBody::PieceSphere& sa = a_.piece_sphere(pa);
          const CompoundBody::PieceSphere& sb = b_.piece_sphere(pb);
          if (pruned(key(sa.center, sa.radius, b_center_in_a(sb.center), sb.radius))) continue;
        }
        test_pair(pa, pb);
      }
    }
  }

  void test_pair(std::int32_t pa, std::int32_t pb) {
    NearEntry& t = tested_.emplace_back();
    t.entry.piece_a = pa;
    t.entry.piece_b = pb;
    const CompoundCache::Entry probe{pa, pb, {}};
    const auto it = std::lower_bound(old_near_.begin(), old_near_.end(), probe, pair_less);
    // Moved, not copied: the near list is rebuilt from the tested pairs,
    // and a copy of a cache that holds penetration state is a deep copy.
    if (it != old_near_.end() && it->piece_a == pa && it->piece_b == pb)
      t.entry.cache = std::move(it->cache);
    const CompoundPiece& piece_a = a_.piece(pa);
    const CompoundPiece& piece_b = b_.piece(pb);
    // Both factors are under the pose contract (checked where the body and
    // this query took them), and so is their product: not checked again.
    const DistanceResult r = detail::distance_of_rigid_poses(
        *piece_a.polytope, pose_a_ * piece_a.pose, *piece_b.polytope, pose_b_ * piece_b.pose,
        options_, &t.entry.cache);
    t.distance = r.signed_distance();
    lowest_lower_ = std::min(lowest_lower_, r.lower_bound);
    lowest_signed_lower_ = std::min(lowest_signed_lower_, r.signed_lower_bound());
    lowest_signed_upper_ = std::min(lowest_signed_upper_, r.signed_upper_bound());
    if (!have_best_ || better(r, pa, pb, best_)) {
      take(best_, r, pa, pb);
      have_best_ = true;
      best_scaled_ = bounds_.factor() * r.signed_distance();
    }
  }

  // The answer's certificate over the whole search, not the best pair's
  // alone (certify_over_pairs, shared with the twin).
  void certify() {
    if (have_best_)
      certify_over_pairs(best_, lowest_lower_, lowest_signed_lower_, lowest_signed_upper_);
  }

  // The next query's warm start: the best pair, and the feature caches of
  // the closest tested pairs, sorted by pair for the binary search.
  void update_cache() {
    if (tested_.size() > kNearCapacity) {
      std::nth_element(
          tested_.begin(), tested_.begin() + static_cast<std::ptrdiff_t>(kNearCapacity) - 1,
          tested_.end(),
          [](const NearEntry& x, const NearEntry& y) { return x.distance < y.distance; });
      tested_.resize(kNearCapacity);
    }
    std::sort(tested_.begin(), tested_.end(),
              [](const NearEntry& x, const NearEntry& y) { return pair_less(x.entry, y.entry); });
    cache_->near.clear();
    for (NearEntry& t : tested_) cache_->near.push_back(std::move(t.entry));
    cache_->piece_a = best_.piece_a;
    cache_->piece_b = best_.piece_b;
  }

  const CompoundBody& a_;
  const CompoundBody& b_;
  const Pose& pose_a_;
  const Pose& pose_b_;
  const DistanceOptions& options_;
  CompoundCache* cache_;
  SphereBounds bounds_;
  NodePairs pairs_;
  std::span<CompoundCache::Entry> old_near_;
  double best_scaled_ = 0.0;  // best_.signed_distance() * bounds_.factor()
  std::int32_t hint_a_ = -1;
  std::int32_t hint_b_ = -1;
  bool have_best_ = false;
  CompoundResult best_;
  // The least lower bound, signed lower bound and signed upper bound of
  // the tested pairs.
  double lowest_lower_ = std::numeric_limits<double>::infinity();
  double lowest_signed_lower_ = std::numeric_limits<double>::infinity();
  double lowest_signed_upper_ = std::numeric_limits<double>::infinity();
  std::vector<NearEntry> tested_;
  std::vector<NodePair> stack_;
};

// The margin query (proxima/query/margin.h): the same hierarchies, depth first
// with the nearer child on top, a node pair pruned as soon as its sphere
// bound is above the margin (its key has the rounding slack taken off: a
// pruned pair is beyond in exact arithmetic too), and the first piece pair
// proved within ends the search. The last witness pair is tried first; each
// piece pair is tracked by the near list's DistanceCache, as in Search.
class MarginSearch {
 public:
  MarginSearch(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
               const Pose& pose_b, double margin, const DistanceOptions& options,
               CompoundCache* cache)
      : a_(a),
        b_(b),
        pose_a_(pose_a),
        pose_b_(pose_b),
        margin_(margin),
        options_(options),
        cache_(cache),
        bounds_(a, pose_a, b, pose_b),
        pairs_(a, b, bounds_),
        margin_scaled_(bounds_.factor() * margin) {
    if (cache_ != nullptr && std::is_sorted(cache_->near.begin(), cache_->near.end(), pair_less)) {
      old_near_ = std::span<CompoundCache::Entry>(cache_->near);
    }
    moved_.assign(old_near_.size(), false);
    result_.margin = margin;
    result_.lower_bound = std::numeric_limits<double>::infinity();
  }

  MarginResult run() {
    if (cache_ != nullptr && cache_->piece_a >= 0 && cache_->piece_a < a_.piece_count() &&
        cache_->piece_b >= 0 && cache_->piece_b < b_.piece_count()) {
      hint_a_ = cache_->piece_a;
      hint_b_ = cache_->piece_b;
      test_pair(hint_a_, hint_b_);
    }
    if (!found_) traverse();
    if (!found_) {
      result_.status = undecided_ || !(result_.lower_bound > margin_) ? MarginStatus::undecided
                                                                      : MarginStatus::beyond;
    }
    result_.pairs_tested = pairs_tested_;
    if (cache_ != nullptr) update_cache();
    return result_;
  }

 private:
  // Whether a key (scaled) proves the pair beyond; if so it lowers the
  // reported lower bound to it.
  bool prune(double key) {
    if (!(key > margin_scaled_)) return false;
    result_.lower_bound = std::min(result_.lower_bound, key / bounds_.factor());
    return true;
  }

  void traverse() {
    std::vector<NodePair> stack;
    detail::DepthFirst<NodePair> frontier(stack);
    detail::branch_and_bound(*this, frontier);
  }

 public:
  // The search as detail::branch_and_bound takes it (branch_and_bound.h):
  // the margin does not move, so a pair is pruned (and its key lowers the
  // reported bound) when first met, never again when taken out.
  bool done() const { return found_; }
  NodePair root() const { return pairs_.root(); }
  bool stale(const NodePair&) const { return false; }
  bool prune(const NodePair& e) { return prune(e.key); }
  bool leaves(const NodePair& e) const { return pairs_.leaves(e); }
  std::pair<NodePair, NodePair> split(const NodePair& e) const { return pairs_.split(e); }
  void test_leaves(const NodePair& e) { test_leaves(pairs_.node_a(e), pairs_.node_b(e)); }

 private:
  void test_leaves(const CompoundBody::Node& na, const CompoundBody::Node& nb) {
    const auto order_a = a_.piece_order();
    const auto order_b = b_.piece_order();
    for (std::int32_t i = 0; i < na.count && !found_; ++i) {
      const std::int32_t pa = order_a[static_cast<std::size_t>(na.first + i)];
      for (std::int32_t j = 0; j < nb.count && !found_; ++j) {
        const std::int32_t pb = order_b[static_cast<std::size_t>(nb.first + j)];
        if (pa == hint_a_ && pb == hint_b_) continue;  // tested first
        if (na.count > 1 || nb.count > 1) {
          const CompoundBody::PieceSphere& sa = a_.piece_sphere(pa);
          const CompoundBody::PieceSphere& sb = b_.piece_sphere(pb);
          if (prune(bounds_.key(sa.center, sa.radius, bounds_.b_center_in_a(sb.center),
                                sb.radius)))
            continue;
        }
        test_pair(pa, pb);
      }
    }
  }

  void test_pair(std::int32_t pa, std::int32_t pb) {
    CompoundCache::Entry& t = tested_.emplace_back();
    t.piece_a = pa;
    t.piece_b = pb;
    const CompoundCache::Entry probe{pa, pb, {}};
    const auto it = std::lower_bound(old_near_.begin(), old_near_.end(), probe, pair_less);
    if (it != old_near_.end() && it->piece_a == pa && it->piece_b == pb) {
      t.cache = std::move(it->cache);
      moved_[static_cast<std::size_t>(it - old_near_.begin())] = true;  // not kept twice
    }
    const CompoundPiece& piece_a = a_.piece(pa);
    const CompoundPiece& piece_b = b_.piece(pb);
    const MarginResult r = detail::within_margin_of_rigid_poses(
        *piece_a.polytope, pose_a_ * piece_a.pose, *piece_b.polytope, pose_b_ * piece_b.pose,
        margin_, options_, t.cache);
    ++pairs_tested_;
    result_.iterations += r.iterations;
    if (r.status == MarginStatus::within) {
      const double lower = result_.lower_bound;
      result_ = r;
      result_.lower_bound = std::min(lower, r.lower_bound);
      result_.piece_a = pa;
      result_.piece_b = pb;
      found_ = true;
      return;
    }
    undecided_ = undecided_ || r.status == MarginStatus::undecided;
    result_.lower_bound = std::min(result_.lower_bound, r.lower_bound);
    if (r.upper_bound < result_.upper_bound) {
      result_.upper_bound = r.upper_bound;
      result_.point_a = r.point_a;
      result_.point_b = r.point_b;
      result_.piece_a = pa;
      result_.piece_b = pb;
    }
  }

  // The tested pairs' caches join the near list (with the old entries not
  // tested, up to its capacity), sorted by pair; the witness pair is the
  // next query's first.
  void update_cache() {
    for (std::size_t i = 0; i < old_near_.size() && tested_.size() < kNearCapacity; ++i) {
      if (!moved_[i]) tested_.push_back(std::move(old_near_[i]));
    }
    if (tested_.size() > kNearCapacity) tested_.resize(kNearCapacity);
    std::sort(tested_.begin(), tested_.end(), pair_less);
    cache_->near = std::move(tested_);
    if (found_) {
      cache_->piece_a = result_.piece_a;
      cache_->piece_b = result_.piece_b;
    }
  }

  const CompoundBody& a_;
  const CompoundBody& b_;
  const Pose& pose_a_;
  const Pose& pose_b_;
  double margin_;
  const DistanceOptions& options_;
  CompoundCache* cache_;
  SphereBounds bounds_;
  NodePairs pairs_;
  double margin_scaled_;
  std::span<CompoundCache::Entry> old_near_;
  std::vector<bool> moved_;  // per old_near_ entry: its cache moved to a tested pair
  std::int32_t hint_a_ = -1;
  std::int32_t hint_b_ = -1;
  bool found_ = false;
  bool undecided_ = false;
  int pairs_tested_ = 0;
  MarginResult result_;
  std::vector<CompoundCache::Entry> tested_;
};

}  // namespace

MarginResult within_margin(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options,
                           CompoundCache* cache) {
  detail::check_finite_non_negative(margin, "within_margin", "margin");
  detail::check_distance_options(options, "within_margin");
  return MarginSearch(a, checked_pose(pose_a, "within_margin: pose_a"), b,
                      checked_pose(pose_b, "within_margin: pose_b"), margin, options, cache)
      .run();
}

CompoundResult distance(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                        const Pose& pose_b, const DistanceOptions& options, CompoundCache* cache) {
  return Search(a, checked_pose(pose_a, "distance: pose_a"), b,
                checked_pose(pose_b, "distance: pose_b"), options, cache)
      .run();
}

CompoundResult distance_all_pairs(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                                  const Pose& pose_b, const DistanceOptions& options) {
  check_pose(pose_a, "distance_all_pairs: pose_a");
  check_pose(pose_b, "distance_all_pairs: pose_b");
  CompoundResult best;
  bool have_best = false;
  double lowest_lower = std::numeric_limits<double>::infinity();
  double lowest_signed_lower = std::numeric_limits<double>::infinity();
  double lowest_signed_upper = std::numeric_limits<double>::infinity();
  for (std::int32_t pa = 0; pa < a.piece_count(); ++pa) {
    for (std::int32_t pb = 0; pb < b.piece_count(); ++pb) {
      const DistanceResult r = distance(*a.piece(pa).polytope, pose_a * a.piece(pa).pose,
                                        *b.piece(pb).polytope, pose_b * b.piece(pb).pose, options);
      lowest_lower = std::min(lowest_lower, r.lower_bound);
      lowest_signed_lower = std::min(lowest_signed_lower, r.signed_lower_bound());
      lowest_signed_upper = std::min(lowest_signed_upper, r.signed_upper_bound());
      if (!have_best || better(r, pa, pb, best)) {
        take(best, r, pa, pb);
        have_best = true;
      }
    }
  }
  // The certificate over every pair, as the search's.
  certify_over_pairs(best, lowest_lower, lowest_signed_lower, lowest_signed_upper);
  // Saturated: the product of two piece counts can exceed an int.
  best.pairs_tested = static_cast<int>(std::min<std::int64_t>(
      std::int64_t{a.piece_count()} * b.piece_count(), std::numeric_limits<int>::max()));
  return best;
}

}  // namespace proxima
