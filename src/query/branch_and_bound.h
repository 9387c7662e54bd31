// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The branch and bound over pairs of hierarchy nodes that the compound and
// mesh searches share (docs/architecture.md): a frontier of node pairs
// waiting, each taken out and followed down along its nearer child pair to
// a pair of leaves, the farther child pair left waiting. What differs
// between the searches is a parameter: the frontier (a stack, depth first;
// or a heap on the bound, best first), and the search itself, which
// bounds, splits and tests (below).
//
// Soundness is the search's: a node pair is pruned only when its bound,
// its rounding slack taken off, is above the search's threshold (the best
// answer so far, or the margin), so that every leaf pair below it is truly
// beyond; the skeleton prunes nothing on its own.
#pragma once

#include <algorithm>
#include <utility>
#include <vector>

namespace proxima::detail {

// The node pairs waiting, last in first out: depth first, the nearer
// child pair of each split followed first. The storage is the caller's, so
// that a search reuses its capacity from one query to the next.
template <class Entry>
class DepthFirst {
 public:
  // A waiting pair whose bound the threshold has passed prunes only itself.
  static constexpr bool kOrdered = false;
  explicit DepthFirst(std::vector<Entry>& storage) : entries_(storage) { entries_.clear(); }
  bool empty() const { return entries_.empty(); }
  void push(const Entry& e) { entries_.push_back(e); }
  Entry pop() {
    const Entry e = entries_.back();
    entries_.pop_back();
    return e;
  }

 private:
  std::vector<Entry>& entries_;
};

// The node pairs waiting, the least bound first (`Later(x, y)`: x comes
// after y), a binary heap.
template <class Entry, class Later>
class BestFirst {
 public:
  // The pair taken out has the least bound: once the threshold passed it,
  // it passed every pair waiting.
  static constexpr bool kOrdered = true;
  BestFirst(std::vector<Entry>& storage, Later later) : entries_(storage), later_(later) {
    entries_.clear();
  }
  bool empty() const { return entries_.empty(); }
  void push(const Entry& e) {
    entries_.push_back(e);
    std::push_heap(entries_.begin(), entries_.end(), later_);
  }
  Entry pop() {
    std::pop_heap(entries_.begin(), entries_.end(), later_);
    const Entry e = entries_.back();
    entries_.pop_back();
    return e;
  }

 private:
  std::vector<Entry>& entries_;
  Later later_;
};

// The branch and bound. `Search` gives, for its Entry (a node pair with
// what it needs of its bound):
//   Entry root()                    the roots' pair
//   bool done()                     the answer is in hand: stop
//   bool stale(const Entry&)        a waiting pair whose bound the
//                                   threshold has passed since it was pushed
//   bool prune(const Entry&)        a new pair whose bound is above the
//                                   threshold (recorded, where the
//                                   answer's certificate needs it)
//   bool leaves(const Entry&)       both nodes are leaves
//   void test_leaves(const Entry&)  the leaf pairs' queries; may lower the
//                                   threshold or end the search
//   std::pair<Entry, Entry> split(const Entry&)
//                                   the two child pairs of the larger node,
//                                   the nearer first
// A dive follows the nearer child pair at once instead of pushing it and
// taking it out again: for a stack the same order, for a heap the leaves
// near the answer early, so that the threshold tightens before most pairs
// are looked at.
template <class Search, class Frontier>
void branch_and_bound(Search& search, Frontier& frontier) {
  {
    const auto root = search.root();
    if (!search.prune(root)) frontier.push(root);
  }
  while (!frontier.empty() && !search.done()) {
    auto e = frontier.pop();
    if (search.stale(e)) {
      if constexpr (Frontier::kOrdered) {
        break;
      } else {
        continue;
      }
    }
    while (true) {
      if (search.leaves(e)) {
        search.test_leaves(e);
        break;
      }
      const auto [near, far] = search.split(e);
      if (!search.prune(far)) frontier.push(far);
      if (search.prune(near)) break;
      e = near;
    }
  }
}

}  // namespace proxima::detail
