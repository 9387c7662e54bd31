// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the tree over the cached faces' normals and its branch-and-bound search (PenetrationCache::Node).
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include "penetration/query.h"

namespace proxima {
namespace {

// The rounding of a lower bound moved by delta (entry_value, bound): c.delta
// with |c| <= 1, the min and the sums, a few u of |delta| in all; taken as
// 2^-44 = 512 u of |delta|, far above it, so that a moved bound never
// exceeds the values it bounds.
constexpr double kMovedBoundSlack = 0x1p-44;
// A node's normal-ball radius rounded up by this, relative and absolute:
// the computed norm |n - c| is within a few u of the exact one (unit
// normals: |n - c| <= 2), and 2^-48 = 32 u covers it.
constexpr double kRadiusRoundUp = 0x1p-48;

// B's translation since the enumeration: delta = t - t_enumeration and its
// length (computed in the query's unit: no overflow, no underflow); t and
// the unit for the groups, each anchored at its own translation.
struct Moved {
  Vec3 delta;
  double length;
  Vec3 t = Vec3::Zero();
  double inverse = 1.0, unit = 1.0;
};

// The value at B's translation t of a cached face: its offset at the
// enumeration moved by -n.(t - t_enumeration), one rounding whatever the
// path.
double entry_value(const PenetrationCache::Facet& f, const Moved& m) {
  return f.enumerated_offset - f.normal.dot(m.delta);
}
// A lower bound at t on the values of a pruned group's faces: with delta
// = t - its anchor (correctly rounded: within u |delta|), each normal n has
// n.delta <= c.delta + spread |delta| (|n - c| <= spread) and <= |delta|
// (unit), plus the rounding of c.delta (|c| <= 1) and of the sums, a few
// u of |delta|.
double entry_value(const PenetrationCache::Bound& b, const Moved& m) {
  const Vec3 delta = m.t - b.anchor;
  const double length = (delta * m.inverse).norm() * m.unit;
  return b.lower - std::min(length, b.center.dot(delta) + b.spread * length) -
         kMovedBoundSlack * length;
}
const Vec3& entry_normal(const PenetrationCache::Facet& f) { return f.normal; }
const Vec3& entry_normal(const PenetrationCache::Bound& b) { return b.center; }
double entry_spread(const PenetrationCache::Bound& b) { return b.spread; }

// Fills node `at` (already allocated) over entries[begin, end) (the cached
// faces or the pruned groups): the ball around their normals (and their
// balls) and their least value at B's translation t (its anchor; `moved`
// from the enumeration to t); not split.
template <class Entry>
void make_node(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
               int at, int begin, int end, const Vec3& t, const Moved& moved) {
  const auto first = entries.begin() + begin;
  const auto last = entries.begin() + end;
  Vec3 lo = entry_normal(*first), hi = entry_normal(*first);
  double least = std::numeric_limits<double>::infinity();
  for (auto f = first; f != last; ++f) {
    lo = lo.cwiseMin(entry_normal(*f));
    hi = hi.cwiseMax(entry_normal(*f));
    least = std::min(least, entry_value(*f, moved));
  }
  const Vec3 center = 0.5 * (lo + hi);
  double radius = 0.0;
  if constexpr (std::is_same_v<Entry, PenetrationCache::Facet>) {
    double radius2 = 0.0;
    for (auto f = first; f != last; ++f)
      radius2 = std::max(radius2, (f->normal - center).squaredNorm());
    radius = std::sqrt(radius2);
  } else {
    for (auto f = first; f != last; ++f)
      radius = std::max(radius, (entry_normal(*f) - center).norm() + entry_spread(*f));
  }
  // Rounded up: the norm is within a few u of the exact one (normals are
  // unit, so |n - c| <= 2), and the query adds its own slack.
  radius = radius * (1.0 + kRadiusRoundUp) + kRadiusRoundUp;
  PenetrationCache::Node& node = nodes[static_cast<std::size_t>(at)];
  node.center = center;
  node.radius = radius;
  node.least_offset = least;
  node.anchor = t;
  node.begin = begin;
  node.end = end;
  node.left = -1;
}

// Splits node `at` (more than kLeaf entries, no children yet) at the
// median of its normals' coordinate of largest spread: O(its entries).
// Children come after their parent in nodes.
template <class Entry>
void split_node(std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes, int at,
                const Vec3& t, const Moved& moved) {
  const PenetrationCache::Node node = nodes[static_cast<std::size_t>(at)];
  const auto first = entries.begin() + node.begin;
  const auto last = entries.begin() + node.end;
  Vec3 lo = entry_normal(*first), hi = entry_normal(*first);
  for (auto f = first; f != last; ++f) {
    lo = lo.cwiseMin(entry_normal(*f));
    hi = hi.cwiseMax(entry_normal(*f));
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const int middle = node.begin + (node.end - node.begin) / 2;
  std::nth_element(first, entries.begin() + middle, last, [axis](const Entry& x, const Entry& y) {
    return entry_normal(x)[axis] < entry_normal(y)[axis];
  });
  const int left = static_cast<int>(nodes.size());
  nodes.resize(nodes.size() + 2);
  nodes[static_cast<std::size_t>(at)].left = left;
  make_node(entries, nodes, left, node.begin, middle, t, moved);
  make_node(entries, nodes, left + 1, middle, node.end, t, moved);
}

// The tree's root over all entries (the searches split it), anchored at
// B's translation t; their count.
template <class Entry>
std::int32_t build_tree(const std::vector<Entry>& entries,
                        std::vector<PenetrationCache::Node>& nodes, const Vec3& t,
                        const Moved& moved) {
  nodes.clear();
  if (entries.empty()) return 0;
  nodes.reserve(4 * entries.size() / PenetrationCache::kLeaf + 2);
  nodes.resize(1);
  make_node(entries, nodes, 0, 0, static_cast<int>(entries.size()), t, moved);
  return static_cast<std::int32_t>(entries.size());
}

// The forest over entries (PenetrationCache::roots): one tree over all
// when there is none (or when the nodes left behind by merges outnumber
// the live ones: a tree split to its leaves has about 2 n / kLeaf nodes).
template <class Entry>
void ensure_forest(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
                   std::vector<std::int32_t>& roots, const Vec3& t, const Moved& moved) {
  if (!roots.empty() && nodes.size() <= 8 * entries.size() / PenetrationCache::kLeaf + 256) return;
  roots.clear();
  if (build_tree(entries, nodes, t, moved) > 0) roots.push_back(0);
}

// A tree over entries[begin, end) (appended by an expansion) added to the
// forest, then merged with the tree before it (one new root over both
// runs, contiguous) while that one is at most twice as large.
template <class Entry>
void add_tree(const std::vector<Entry>& entries, std::vector<PenetrationCache::Node>& nodes,
              std::vector<std::int32_t>& roots, int begin, const Vec3& t, const Moved& moved) {
  const int end = static_cast<int>(entries.size());
  if (roots.empty() || begin >= end) return;  // the next search builds the whole forest
  const auto size = [&](std::int32_t r) {
    const PenetrationCache::Node& n = nodes[static_cast<std::size_t>(r)];
    return n.end - n.begin;
  };
  int first = begin;
  while (!roots.empty() && size(roots.back()) <= 2 * (end - first)) {
    first = nodes[static_cast<std::size_t>(roots.back())].begin;
    roots.pop_back();
  }
  const auto at = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  make_node(entries, nodes, at, first, end, t, moved);
  roots.push_back(at);
}

// A translation-only tracked query: the least of the cached faces' values
// at B's translation t (facet_value), by branch and bound on the tree
// (PenetrationCache::Node), starting from the last answer's face. A node's
// bound at t: its least value at its anchor less the most any of its
// normals can gain, c.delta + rho |delta| and at most |delta| (delta = t -
// anchor), rounded up; it is skipped when that is at least the best value
// found: every face skipped has a value at least the best (up to the
// rounding of the values themselves, which the certificate's slack
// covers). A node the search enters is re-anchored at t: a leaf with the
// least of its faces' values, an inner node with the lesser of its
// children's bounds at t (each a lower bound there), so the nodes near the
// answer stay tight however far B goes, and the ones far from it, never
// entered, keep their anchors (their bounds loosen by at most the distance
// moved, and only one node's gain per level of the tree is ever chained).
// A node not split yet is split when the search enters it.
// The same search over the pruned groups (PenetrationCache::Bound), from
// the faces' best value, finds whether any group's bound is below it; with
// `found` set, it collects every entry below `best` instead (best fixed).
template <class Entry>
struct TreeSearch {
  std::vector<Entry>& entries;
  std::vector<PenetrationCache::Node>& nodes;
  Vec3 t;                            // B's translation
  Moved moved;                       // from the enumeration to t
  double inverse = 1.0, unit = 1.0;  // the query's power-of-two unit
  double best = 0.0;
  Entry winner;
  int work = 0;
  std::vector<int>* found = nullptr;

  // A lower bound at t on the values of the faces under node `at` (its
  // bound, or after entering it the least found).
  double bound(const PenetrationCache::Node& node) const {
    const Vec3 delta = t - node.anchor;
    const double length = (delta * inverse).norm() * unit;
    // Rounding of c.delta (|c| <= 1) and of the sum: a few u of |delta|.
    const double gain = std::min(length, node.center.dot(delta) + node.radius * length);
    return node.least_offset - gain - kMovedBoundSlack * length;
  }

  double visit(int at, double node_bound) {
    ++work;
    if (!(node_bound < best)) return node_bound;
    {
      const PenetrationCache::Node& node = nodes[static_cast<std::size_t>(at)];
      if (node.left < 0 && node.end - node.begin > PenetrationCache::kLeaf)
        split_node(entries, nodes, at, t, moved);
    }
    // A copy: splitting below appends to nodes.
    const PenetrationCache::Node node = nodes[static_cast<std::size_t>(at)];
    double least = std::numeric_limits<double>::infinity();
    if (node.left < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const Entry& f = entries[static_cast<std::size_t>(i)];
        const double value = entry_value(f, moved);
        ++work;
        least = std::min(least, value);
        if (value < best) {
          if (found != nullptr) {
            found->push_back(i);
          } else {
            best = value;
            winner = f;
          }
        }
      }
    } else {
      const int l = node.left;
      const double bl = bound(nodes[static_cast<std::size_t>(l)]);
      const double br = bound(nodes[static_cast<std::size_t>(l) + 1]);
      // The nearer child first.
      if (bl <= br) {
        least = visit(l, bl);
        least = std::min(least, visit(l + 1, br));
      } else {
        least = visit(l + 1, br);
        least = std::min(least, visit(l, bl));
      }
    }
    PenetrationCache::Node& stored = nodes[static_cast<std::size_t>(at)];
    stored.least_offset = least;
    stored.anchor = t;
    return least;
  }
};

}  // namespace
}  // namespace proxima
