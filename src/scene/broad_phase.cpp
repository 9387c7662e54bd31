// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The scene's two pair finders (broad_phase.h says what they promise). Both
// end with the same closed-box test on the caller's boxes, which is why they
// return the same pairs; tests/scene/broad_phase_test.cpp compares them with the
// all-pairs loop, and bench/broad_phase_bench.cpp times them.
#include "scene/broad_phase.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "proxima/shape/support.h"
#include "query/parallel_ranges.h"

namespace proxima::detail {
namespace {

std::size_t index(std::int32_t id) { return static_cast<std::size_t>(id); }

// Membership shared by both finders: which ids are in the set now, and the
// ids added since the last find_pairs (an id may be added, removed and added
// again between two calls; only its state at the call matters).
class Membership {
 public:
  void add(std::int32_t id) {
    grow(id);
    member_[index(id)] = 1;
    pending_.push_back(id);
  }
  void remove(std::int32_t id) {
    grow(id);
    member_[index(id)] = 0;
  }
  bool member(std::int32_t id) const {
    return index(id) < member_.size() && member_[index(id)] != 0;
  }
  std::vector<std::int32_t>& pending() { return pending_; }

 private:
  void grow(std::int32_t id) {
    if (index(id) >= member_.size()) member_.resize(index(id) + 1, 0);
  }
  std::vector<std::uint8_t> member_;
  std::vector<std::int32_t> pending_;
};

// ---------------------------------------------------------------------------
// Sweep and prune.

// Switch the sweep axis only when another axis spreads the centers this much
// more (in variance): switching costs a full sort, and two axes of nearly
// equal spread prune nearly equally well.
constexpr double kAxisSwitchRatio = 1.5;

// Shifts an insertion sort may make, per entry, before it gives up for a full
// sort: coherent motion moves each box past a few neighbours at most, while
// a scene that was shuffled (many bodies added, a big jump) would make the
// insertion sort quadratic.
constexpr std::size_t kInsertionShiftsPerEntry = 4;

class SweepAndPrune final : public PairFinder {
 public:
  void add(std::int32_t id) override {
    members_.add(id);
    if (index(id) >= in_entries_.size()) in_entries_.resize(index(id) + 1, 0);
  }
  void remove(std::int32_t id) override { members_.remove(id); }

  void find_pairs(std::span<const Aabb> boxes, std::vector<std::uint64_t>& pairs,
                  int /*threads*/) override {
    update_entries(boxes);
    sort_entries();
    // The sweep reads the sorted lower ends as a packed array (the inner
    // loop runs over every box that starts before the current one ends,
    // tens to hundreds of them in a dense scene) and the other two axes only
    // for those.
    const std::size_t n = entries_.size();
    sweep_lo_.resize(n);
    others_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Entry& e = entries_[k];
      sweep_lo_[k] = e.lo;
      others_[k] = {e.lo1, e.hi1, e.lo2, e.hi2};
    }
    pairs.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const double end = entries_[i].hi;
      const Others a = others_[i];
      for (std::size_t j = i + 1; j < n && sweep_lo_[j] <= end; ++j) {
        const Others& b = others_[j];
        if (a.lo1 <= b.hi1 && b.lo1 <= a.hi1 && a.lo2 <= b.hi2 && b.lo2 <= a.hi2) {
          const std::int32_t x = entries_[i].id;
          const std::int32_t y = entries_[j].id;
          pairs.push_back(x < y ? pair_key(x, y) : pair_key(y, x));
        }
      }
    }
    std::sort(pairs.begin(), pairs.end());
  }

 private:
  // One box, its sweep axis first (lo, hi), then the two others.
  struct Entry {
    double lo, hi, lo1, hi1, lo2, hi2;
    std::int32_t id;
  };

  void update_entries(std::span<const Aabb> boxes) {
    // Drop removed ids, append new ones (at the end: the sort places them).
    std::size_t kept = 0;
    for (const Entry& e : entries_) {
      if (members_.member(e.id)) {
        entries_[kept++] = e;
      } else {
        in_entries_[index(e.id)] = 0;
      }
    }
    entries_.resize(kept);
    for (const std::int32_t id : members_.pending()) {
      if (members_.member(id) && in_entries_[index(id)] == 0) {
        in_entries_[index(id)] = 1;
        entries_.push_back(Entry{0, 0, 0, 0, 0, 0, id});
      }
    }
    members_.pending().clear();
    centers_.resize(entries_.size());
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const Aabb& b = boxes[index(entries_[k].id)];
      centers_[k] = 0.5 * b.lo + 0.5 * b.hi;  // halves first: no overflow near the double range
    }
    choose_axis();
    refresh_values(boxes);
  }

  void refresh_values(std::span<const Aabb> boxes) {
    const int a0 = axis_, a1 = (axis_ + 1) % 3, a2 = (axis_ + 2) % 3;
    for (Entry& e : entries_) {
      const Aabb& b = boxes[index(e.id)];
      e.lo = b.lo[a0];
      e.hi = b.hi[a0];
      e.lo1 = b.lo[a1];
      e.hi1 = b.hi[a1];
      e.lo2 = b.lo[a2];
      e.hi2 = b.hi[a2];
    }
  }

  // The axis along which the centers spread most: the one where sorted
  // intervals overlap least. Computed on centers scaled by their largest
  // magnitude, so that squares neither overflow nor underflow.
  //
  // kMinSpreadScale: centers all below it in magnitude keep the current
  // axis. The scale factor 1 / largest must be finite (it overflows for
  // largest below 1 / DBL_MAX, about 5.6e-309, subnormal centers); 1e-300
  // keeps a margin above that. The axis only orders the sweep, any axis
  // finds the same pairs (PairFinderTest.MatchesAllPairsWhileBoxesMoveAndMembersChange
  // compares with all pairs; SweepAndPrune.TinyCentersKeepTheirAxis pins
  // the threshold).
  static constexpr double kMinSpreadScale = 1e-300;
  void choose_axis() {
    const std::size_t n = centers_.size();
    if (n < 2) return;
    double largest = 0.0;
    for (const Vec3& c : centers_) largest = std::max(largest, c.cwiseAbs().maxCoeff());
    if (!(largest > kMinSpreadScale) || !std::isfinite(largest)) return;
    const double s = 1.0 / largest;
    Vec3 mean = Vec3::Zero();
    for (const Vec3& c : centers_) mean += s * c;
    mean /= static_cast<double>(n);
    Vec3 variance = Vec3::Zero();
    for (const Vec3& c : centers_) variance += (s * c - mean).cwiseAbs2();
    int best = axis_;
    for (int k = 0; k < 3; ++k) {
      if (variance[k] > kAxisSwitchRatio * variance[axis_] && variance[k] > variance[best])
        best = k;
    }
    if (best != axis_) {
      axis_ = best;
      needs_full_sort_ = true;
    }
  }

  void sort_entries() {
    const auto by_lo = [](const Entry& x, const Entry& y) { return x.lo < y.lo; };
    if (!needs_full_sort_) {
      // Insertion sort: linear when the order barely changed since the last
      // step; abandoned for a full sort past its budget.
      const std::size_t budget = kInsertionShiftsPerEntry * entries_.size() + 64;
      std::size_t shifts = 0;
      for (std::size_t i = 1; i < entries_.size() && shifts <= budget; ++i) {
        const Entry e = entries_[i];
        std::size_t j = i;
        while (j > 0 && entries_[j - 1].lo > e.lo && shifts <= budget) {
          entries_[j] = entries_[j - 1];
          --j;
          ++shifts;
        }
        entries_[j] = e;
      }
      if (shifts <= budget) return;
    }
    std::sort(entries_.begin(), entries_.end(), by_lo);
    needs_full_sort_ = false;
  }

  struct Others {
    double lo1, hi1, lo2, hi2;
  };

  Membership members_;
  std::vector<std::uint8_t> in_entries_;
  std::vector<Entry> entries_;
  std::vector<double> sweep_lo_;  // entries_[k].lo, packed
  std::vector<Others> others_;    // entries_[k]'s other two axes
  std::vector<Vec3> centers_;
  int axis_ = 0;
  bool needs_full_sort_ = false;
};

// ---------------------------------------------------------------------------
// Dynamic AABB tree.

// A leaf's fat box is its box grown by this fraction of its largest extent
// on every side: a body moving less than that per step stays in its leaf for
// several steps. Larger fat boxes move leaves less often but let more pairs
// of fat boxes through to the box test. The value is the best of a sweep
// of fractions in bench/broad_phase_bench, whose bodies move about 2% of
// their size per step, as a scene's bodies do between steps.
constexpr double kFatFraction = 0.25;

// Fixed chunks of the tree's parallel loops (parallel_ranges.h): ids checked
// against their fat boxes, moved leaves that query the tree, and fat pairs
// tested on the boxes. Each chunk's output is its own list, joined in chunk
// order, so the pairs come out the same on any number of threads.
constexpr std::size_t kIdChunk = 1024;
constexpr std::size_t kQueryChunk = 32;
constexpr std::size_t kPairChunk = 4096;

Aabb merged(const Aabb& a, const Aabb& b) { return {a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; }

// Half the surface area: the insertion cost of the surface-area heuristic
// (the chance that a random ray or box hits the node grows with it). The
// half perimeter (Box2D v3's choice) cannot overflow, but made the tree's
// steps slower (bench/broad_phase_bench); the products overflow to inf
// only in scenes spanning more than ~1e154, and growth() below keeps
// inf - inf from becoming NaN there.
double cost_of(const Aabb& b) {
  const Vec3 e = b.hi - b.lo;
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

// after - before for costs after >= before, with overflowed (infinite)
// areas taken as the largest double: 0 when both overflowed, where the
// difference would be NaN. Clamping, not a branch around the subtraction:
// a compiler may evaluate both sides of a branch (clang does, unless told
// that floating-point exceptions may trap), and inf - inf raises the
// invalid-operation flag that the tests trap.
double growth(double after, double before) {
  constexpr double kLargest = std::numeric_limits<double>::max();
  return std::min(after, kLargest) - std::min(before, kLargest);
}

bool contains(const Aabb& outer, const Aabb& inner) {
  return outer.lo.x() <= inner.lo.x() && outer.lo.y() <= inner.lo.y() &&
         outer.lo.z() <= inner.lo.z() && inner.hi.x() <= outer.hi.x() &&
         inner.hi.y() <= outer.hi.y() && inner.hi.z() <= outer.hi.z();
}

Aabb fattened(const Aabb& b) {
  const double grow = kFatFraction * (b.hi - b.lo).maxCoeff();
  return {(b.lo.array() - grow).matrix(), (b.hi.array() + grow).matrix()};
}

class AabbTree final : public PairFinder {
 public:
  void add(std::int32_t id) override {
    members_.add(id);
    grow(id);
  }

  void remove(std::int32_t id) override {
    members_.remove(id);
    grow(id);
    const std::int32_t leaf = leaf_of_[index(id)];
    if (leaf >= 0) {
      remove_leaf(leaf);
      free_node(leaf);
      leaf_of_[index(id)] = -1;
      mark_moved(id);
    }
  }

  void find_pairs(std::span<const Aabb> boxes, std::vector<std::uint64_t>& pairs,
                  int threads) override {
    for (const std::int32_t id : members_.pending()) {
      if (members_.member(id) && leaf_of_[index(id)] < 0) {
        const std::int32_t leaf = allocate_node();
        set_fat_box(id, leaf, boxes[index(id)]);
        nodes_[index(leaf)].id = id;
        leaf_of_[index(id)] = leaf;
        insert_leaf(leaf);
        mark_moved(id);
      }
    }
    members_.pending().clear();
    // Leaves whose box left the fat box move in the tree: found in parallel
    // (a read of the id-ordered fat boxes), moved in id order.
    parallel_gather(leaf_of_.size(), kIdChunk, threads, chunk_out_, left_fat_,
                    [&](std::size_t begin, std::size_t end, std::vector<std::uint64_t>& out) {
                      for (std::size_t k = begin; k < end; ++k) {
                        if (leaf_of_[k] >= 0 && !contains(fat_[k], boxes[k])) out.push_back(k);
                      }
                    });
    for (const std::uint64_t k : left_fat_) {
      const auto id = static_cast<std::int32_t>(k);
      const std::int32_t leaf = leaf_of_[k];
      remove_leaf(leaf);
      set_fat_box(id, leaf, boxes[k]);
      insert_leaf(leaf);
      mark_moved(id);
    }
    if (!moved_list_.empty()) update_fat_pairs(threads);
    // The fat pairs whose boxes overlap.
    parallel_gather(fat_pairs_.size(), kPairChunk, threads, chunk_out_, pairs,
                    [&](std::size_t begin, std::size_t end, std::vector<std::uint64_t>& out) {
                      for (std::size_t k = begin; k < end; ++k) {
                        const std::uint64_t key = fat_pairs_[k];
                        if (overlaps(boxes[index(pair_first(key))], boxes[index(pair_second(key))]))
                          out.push_back(key);
                      }
                    });
  }

 private:
  struct Node {
    Aabb box;
    std::int32_t parent = -1;  // also the next free node while free
    std::int32_t left = -1;
    std::int32_t right = -1;
    std::int32_t height = 0;  // leaf 0
    std::int32_t id = -1;     // leaf: body id
    bool leaf() const { return left < 0; }
  };

  void grow(std::int32_t id) {
    if (index(id) >= leaf_of_.size()) {
      leaf_of_.resize(index(id) + 1, -1);
      moved_.resize(index(id) + 1, 0);
      fat_.resize(index(id) + 1);
    }
  }

  // A leaf's fat box lives in its node (for the tree) and by id in fat_
  // (read in id order by find_pairs' containment test).
  void set_fat_box(std::int32_t id, std::int32_t leaf, const Aabb& box) {
    fat_[index(id)] = fattened(box);
    nodes_[index(leaf)].box = fat_[index(id)];
  }

  void mark_moved(std::int32_t id) {
    if (moved_[index(id)] == 0) {
      moved_[index(id)] = 1;
      moved_list_.push_back(id);
    }
  }

  // Every pair of overlapping fat boxes, kept sorted: the pairs of leaves
  // that did not move are still right; those of moved leaves are dropped and
  // found again by querying the tree with each moved leaf's fat box.
  // The moved leaves query the tree in parallel chunks (the tree is only
  // read), each chunk into its own list.
  void update_fat_pairs(int threads) {
    std::size_t kept = 0;
    for (const std::uint64_t key : fat_pairs_) {
      if (moved_[index(pair_first(key))] == 0 && moved_[index(pair_second(key))] == 0) {
        fat_pairs_[kept++] = key;
      }
    }
    fat_pairs_.resize(kept);
    const std::size_t moved = moved_list_.size();
    if (stacks_.size() < chunk_count(moved, kQueryChunk))
      stacks_.resize(chunk_count(moved, kQueryChunk));
    parallel_gather(moved, kQueryChunk, threads, chunk_out_, new_pairs_,
                    [&](std::size_t begin, std::size_t end, std::vector<std::uint64_t>& out) {
                      std::vector<std::int32_t>& stack = stacks_[begin / kQueryChunk];
                      for (std::size_t m = begin; m < end; ++m) {
                        const std::int32_t id = moved_list_[m];
                        const std::int32_t leaf = leaf_of_[index(id)];
                        if (leaf < 0) continue;  // removed
                        const Aabb query = nodes_[index(leaf)].box;
                        stack.clear();
                        stack.push_back(root_);
                        while (!stack.empty()) {
                          const Node& node = nodes_[index(stack.back())];
                          stack.pop_back();
                          if (!overlaps(node.box, query)) continue;
                          if (!node.leaf()) {
                            stack.push_back(node.left);
                            stack.push_back(node.right);
                            continue;
                          }
                          const std::int32_t other = node.id;
                          // Two moved leaves find each other twice: keep the smaller id's find.
                          if (other == id || (moved_[index(other)] != 0 && other < id)) continue;
                          out.push_back(id < other ? pair_key(id, other) : pair_key(other, id));
                        }
                      }
                    });
    std::sort(new_pairs_.begin(), new_pairs_.end());
    merged_pairs_.resize(fat_pairs_.size() + new_pairs_.size());
    std::merge(fat_pairs_.begin(), fat_pairs_.end(), new_pairs_.begin(), new_pairs_.end(),
               merged_pairs_.begin());
    fat_pairs_.swap(merged_pairs_);
    for (const std::int32_t id : moved_list_) moved_[index(id)] = 0;
    moved_list_.clear();
  }

  std::int32_t allocate_node() {
    if (free_ >= 0) {
      const std::int32_t n = free_;
      free_ = nodes_[index(n)].parent;
      nodes_[index(n)] = Node{};
      return n;
    }
    nodes_.push_back(Node{});
    return static_cast<std::int32_t>(nodes_.size() - 1);
  }

  void free_node(std::int32_t n) {
    nodes_[index(n)] = Node{};
    nodes_[index(n)].parent = free_;
    free_ = n;
  }

  Node& at(std::int32_t n) { return nodes_[index(n)]; }

  // Surface-area heuristic: walk down towards the sibling whose pairing with
  // the new leaf adds the least area to the tree, counting the growth of
  // every ancestor on the way (the "inherited" cost). Stop where making a new
  // parent here costs less than going further down.
  void insert_leaf(std::int32_t leaf) {
    if (root_ < 0) {
      root_ = leaf;
      at(leaf).parent = -1;
      return;
    }
    const Aabb box = at(leaf).box;
    std::int32_t sibling = root_;
    while (!at(sibling).leaf()) {
      const Node& node = at(sibling);
      const double combined = cost_of(merged(node.box, box));
      const double here = 2.0 * combined;
      const double inherited = 2.0 * growth(combined, cost_of(node.box));
      const auto descend_cost = [&](std::int32_t child) {
        const Node& c = at(child);
        const double with_leaf = cost_of(merged(c.box, box));
        return (c.leaf() ? with_leaf : growth(with_leaf, cost_of(c.box))) + inherited;
      };
      const double cost_left = descend_cost(node.left);
      const double cost_right = descend_cost(node.right);
      if (here < cost_left && here < cost_right) break;
      sibling = cost_left <= cost_right ? node.left : node.right;
    }
    const std::int32_t old_parent = at(sibling).parent;
    const std::int32_t parent = allocate_node();
    at(parent).parent = old_parent;
    at(parent).box = merged(at(sibling).box, box);
    at(parent).height = at(sibling).height + 1;
    at(parent).left = sibling;
    at(parent).right = leaf;
    at(sibling).parent = parent;
    at(leaf).parent = parent;
    replace_child(old_parent, sibling, parent);
    refit_upwards(old_parent);
  }

  void remove_leaf(std::int32_t leaf) {
    if (leaf == root_) {
      root_ = -1;
      return;
    }
    const std::int32_t parent = at(leaf).parent;
    const std::int32_t grand = at(parent).parent;
    const std::int32_t sibling = at(parent).left == leaf ? at(parent).right : at(parent).left;
    at(sibling).parent = grand;
    replace_child(grand, parent, sibling);
    free_node(parent);
    at(leaf).parent = -1;
    refit_upwards(grand);
  }

  // Points `parent`'s link to `old_child` at `new_child` (or the root when
  // there is no parent).
  void replace_child(std::int32_t parent, std::int32_t old_child, std::int32_t new_child) {
    if (parent < 0) {
      root_ = new_child;
    } else if (at(parent).left == old_child) {
      at(parent).left = new_child;
    } else {
      at(parent).right = new_child;
    }
  }

  void refit(std::int32_t n) {
    Node& node = at(n);
    node.box = merged(at(node.left).box, at(node.right).box);
    node.height = 1 + std::max(at(node.left).height, at(node.right).height);
  }

  void refit_upwards(std::int32_t n) {
    while (n >= 0) {
      n = balance(n);
      refit(n);
      n = at(n).parent;
    }
  }

  // AVL rotation: when one child of `a` is more than one level taller than
  // the other, the taller child takes a's place, a becomes its child, and the
  // taller grandchild stays up. Returns the node now at a's place.
  std::int32_t balance(std::int32_t a) {
    if (at(a).leaf() || at(a).height < 2) return a;
    const std::int32_t b = at(a).left;
    const std::int32_t c = at(a).right;
    const std::int32_t skew = at(c).height - at(b).height;
    if (skew > 1) return rotate_up(a, c, /*from_right=*/true);
    if (skew < -1) return rotate_up(a, b, /*from_right=*/false);
    return a;
  }

  // Child `up` of `a` (its right child if from_right) takes a's place. Of
  // up's children, the taller stays under `up` (beside a); the shorter goes
  // to a, where `up` was.
  std::int32_t rotate_up(std::int32_t a, std::int32_t up, bool from_right) {
    const std::int32_t f = at(up).left;
    const std::int32_t g = at(up).right;
    const std::int32_t taller = at(f).height > at(g).height ? f : g;
    const std::int32_t shorter = taller == f ? g : f;
    const std::int32_t parent = at(a).parent;
    at(up).parent = parent;
    replace_child(parent, a, up);
    at(a).parent = up;
    at(up).left = a;
    at(up).right = taller;
    if (from_right) {
      at(a).right = shorter;
    } else {
      at(a).left = shorter;
    }
    at(shorter).parent = a;
    refit(a);
    refit(up);
    return up;
  }

  Membership members_;
  std::vector<Node> nodes_;
  std::int32_t root_ = -1;
  std::int32_t free_ = -1;
  std::vector<std::int32_t> leaf_of_;  // by id, -1 when not in the tree
  std::vector<std::uint8_t> moved_;    // by id: re-inserted, added or removed since last time
  std::vector<std::int32_t> moved_list_;
  std::vector<std::uint64_t> fat_pairs_;
  std::vector<std::uint64_t> new_pairs_;
  std::vector<std::uint64_t> merged_pairs_;
  std::vector<Aabb> fat_;                              // by id: the leaf's fat box
  std::vector<std::uint64_t> left_fat_;                // ids whose box left the fat box
  std::vector<std::vector<std::uint64_t>> chunk_out_;  // per chunk of a parallel loop
  std::vector<std::vector<std::int32_t>> stacks_;      // per chunk of the tree queries
};

}  // namespace

Aabb sphere_box(const ConvexPolytope& body, const Pose& pose) {
  const Vec3 center = pose.apply(body.centroid());
  const double r = body.bounding_radius();
  return {(center.array() - r).matrix(), (center.array() + r).matrix()};
}

namespace {

// The rounding of one computed dot product d.x of a direction (|d| within
// rounding of 1: a rotation's row) with a vertex (|x| <= sqrt(3) scale) is
// below 3 u |d| |x| (the standard bound for a sum of three products); in
// units of u sqrt(3) scale, with room to spare.
constexpr double kDotErrorUlps = 8.0;

// Magnitudes between which the certificate's squares and differences stay
// far from overflow and underflow; outside, no certificate (every call
// climbs).
constexpr double kCertifiedScaleMin = 0x1p-400;
constexpr double kCertifiedScaleMax = 0x1p400;

// allowance_of's margin shrunk by 2^-30 (below): its own rounding (a
// division and a root, a few u relative) and that of the caller's
// comparison of |d' - d|^2 with its square are far below 2^-30 relative,
// and an allowance a hair short only makes a climb run that could have
// been skipped.
constexpr double kAllowanceShrink = 1.0 - 0x1p-30;

// The allowance of vertex v as the support in direction d (v the climb's
// answer, v_dot its computed dot product): how far (Euclidean) another
// direction d' may be from d with no neighbour's computed dot product
// exceeding v's, so that the climb from v at d' stays at v.
//
// Why. For a neighbour w, let g be the computed gap v_dot - d.w and e the
// bound on one dot product's rounding. Exactly, d.(v - w) >= g - 2e - u g
// (the two dots and the subtraction), so d'.(v - w) = d.(v - w) +
// (d' - d).(v - w) >= g - 2e - u g - |d' - d| |v - w|, and the computed d'.w
// cannot exceed the computed d'.v while that stays above 2e:
// |d' - d| < (g - 4e - u g) / |v - w|. The least of these over the
// neighbours, shrunk by 2^-30 (kAllowanceShrink) for its own rounding and
// that of the caller's |d' - d|^2. -1 when a neighbour leaves no margin (a
// plateau: coplanar neighbours tie); infinite for a vertex without
// neighbours.
double allowance_of(const ConvexPolytope& body, const Vec3& d, std::int32_t v, double v_dot) {
  const double scale = body.scale();
  if (!(scale > kCertifiedScaleMin && scale < kCertifiedScaleMax)) return -1.0;
  const Vec3* vertices = body.vertices().data();
  const Vec3& x = vertices[v];
  const double e = kDotErrorUlps * kUnitRoundoff * std::sqrt(3.0) * scale;
  double least = std::numeric_limits<double>::infinity();
  for (const std::int32_t w : body.neighbors(v)) {
    const double gap = v_dot - d.dot(vertices[w]);
    const double margin = gap - 4.0 * e - kUnitRoundoff * gap;
    if (!(margin > 0.0)) return -1.0;
    const double length2 = (vertices[w] - x).squaredNorm();
    if (!(length2 > 0.0)) return -1.0;  // an edge too short to square
    least = std::min(least, margin / std::sqrt(length2));
  }
  return least * kAllowanceShrink;
}
}  // namespace

Aabb support_box(const ConvexPolytope& body, const Pose& pose, BoxHints& hints) {
  Aabb box;
  for (int k = 0; k < 3; ++k) {
    // World axis k seen from the body: row k of the rotation.
    const Vec3 row = pose.rotation.row(k).transpose();
    for (int side = 0; side < 2; ++side) {
      const auto i = static_cast<std::size_t>(2 * k + side);
      const Vec3 dir = side == 0 ? row : Vec3(-row);
      const std::int32_t hint = hints.vertex[i];
      const double allowance = hints.allowance[i];
      const bool held = hint >= 0 && hint < body.vertex_count() && allowance >= 0.0 &&
                        (dir - hints.direction[i]).squaredNorm() < allowance * allowance;
      if (!held) {
        const std::int32_t v = support_hill_climb(body, dir, hint);
        hints.vertex[i] = v;
        hints.direction[i] = dir;
        hints.allowance[i] = allowance_of(body, dir, v, dir.dot(body.vertex(v)));
      }
    }
    box.hi[k] = pose.translation[k] + row.dot(body.vertex(hints.vertex[2 * k]));
    box.lo[k] = pose.translation[k] + row.dot(body.vertex(hints.vertex[2 * k + 1]));
  }
  return box;
}

std::unique_ptr<PairFinder> make_pair_finder(BroadPhase kind) {
  if (kind == BroadPhase::sweep_and_prune) return std::make_unique<SweepAndPrune>();
  return std::make_unique<AabbTree>();
}

}  // namespace proxima::detail
