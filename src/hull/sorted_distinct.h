// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// hull layer (internal): the indices of a point list sorted by a key, one per
// distinct key. Shared by the hull's removal of duplicate points (3D keys)
// and the polygon hull's removal of points with one projection (2D keys).
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

#include "hull/half_edges.h"

namespace proxima::detail {

// The indices 0..n-1 sorted by key(i), ties by index, and of each run of
// equal keys only the first (the smallest index) kept.
template <class Key>
std::vector<Index> sorted_distinct(std::size_t n, const Key& key) {
  std::vector<Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](Index l, Index r) {
    const auto kl = key(l), kr = key(r);
    return kl != kr ? kl < kr : l < r;
  });
  order.erase(
      std::unique(order.begin(), order.end(), [&](Index l, Index r) { return key(l) == key(r); }),
      order.end());
  return order;
}

}  // namespace proxima::detail
