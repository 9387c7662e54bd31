// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The collision checks of a scene: step_within (every pair within the
// margin, proved by the margin query instead of answered by the distance
// query) and first_within (the first such pair, then stop). Both run
// step()'s broad phase and keep its pair caches (scene_impl.h).
#include "scene/scene_impl.h"

namespace proxima {
namespace {

// Reported by a collision check: proved within, or not proved beyond (a
// pair undecided at the iteration cap may be within).
bool reported(const MarginPair& p) { return p.result.status != MarginStatus::beyond; }

}  // namespace

std::span<const MarginPair> Scene::step_within() {
  Impl& s = *impl_;
  s.find_candidates();
  s.stats.convex_queries = s.narrow_phase(
      s.margin_results, s.margin_close,
      [&s](Impl::PairState& state, MarginPair& p) { s.margin_into(state, p); },
      [](const MarginPair& p) { return reported(p); });
  s.stats.close_pairs = static_cast<int>(s.margin_close.size());
  return s.margin_close;
}

std::optional<MarginPair> Scene::first_within() {
  Impl& s = *impl_;
  s.find_candidates();
  s.stats.close_pairs = 0;
  s.stats.convex_queries = 0;
  // The last call's pair first, when it is still a candidate.
  const auto by_key = [](const Impl::PairState& p, std::uint64_t k) { return p.key < k; };
  const auto last = std::lower_bound(s.pairs.begin(), s.pairs.end(), s.last_within, by_key);
  const std::size_t first = last != s.pairs.end() && last->key == s.last_within
                                ? static_cast<std::size_t>(last - s.pairs.begin())
                                : s.pairs.size();
  MarginPair p;
  const auto within = [&](std::size_t k) {
    s.margin_into(s.pairs[k], p);
    s.stats.convex_queries += p.result.pairs_tested;
    if (!reported(p)) return false;
    s.last_within = s.pairs[k].key;
    s.stats.close_pairs = 1;
    return true;
  };
  if (first < s.pairs.size() && within(first)) return p;
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    if (k != first && within(k)) return p;
  }
  s.last_within = 0;
  return std::nullopt;
}

}  // namespace proxima
