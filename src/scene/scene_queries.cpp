// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The queries a planner asks a scene besides step(): nearest_pair,
// pairs_within, and step()'s slow twin.
#include "scene/scene_impl.h"

namespace proxima {

std::optional<ClosePair> Scene::nearest_pair() {
  Impl& s = *impl_;
  if (s.live_count < 2) return std::nullopt;
  // Box overlap at margin m finds every pair within m. Start at the
  // scene's margin; while nothing is found, widen m up to the span of the
  // whole scene; once a pair at distance d is found, one search at margin
  // d holds every pair that could be nearer.
  Aabb all = {Vec3::Constant(std::numeric_limits<double>::infinity()),
              Vec3::Constant(-std::numeric_limits<double>::infinity())};
  for (Impl::Body& b : s.bodies) {
    if (!b.live) continue;
    const Aabb box = s.world_box(b, 0.0);
    all.lo = all.lo.cwiseMin(box.lo);
    all.hi = all.hi.cwiseMax(box.hi);
  }
  const double span = (all.hi - all.lo).norm();
  std::unique_ptr<detail::PairFinder> finder =
      detail::make_pair_finder(BroadPhase::sweep_and_prune);
  for (BodyId id = 0; static_cast<std::size_t>(id) < s.bodies.size(); ++id) {
    if (s.bodies[slot(id)].live) finder->add(id);
  }
  std::vector<Aabb> boxes(s.bodies.size());
  std::vector<std::uint64_t> keys;
  Impl::PairState scratch;
  double margin = s.options.margin;
  bool refined = false;
  // The widenings a search may take: the first widening sets the margin to
  // at least span / 64 and each next one doubles it, so the seventh reaches
  // the span, where every pair is a candidate (an infinite span is reached
  // at the first: the margin is then infinite too). Past that the span is
  // not a number, which the bodies' finite poses and boxes rule out; the
  // bound makes the loop's end independent of that argument.
  constexpr int kMaxWidenings = 7;
  int widenings = 0;
  for (;;) {
    for (std::size_t k = 0; k < s.bodies.size(); ++k) {
      if (s.bodies[k].live) boxes[k] = s.world_box(s.bodies[k], margin);
    }
    finder->find_pairs(boxes, keys);
    std::erase_if(keys, [&](std::uint64_t key) {
      return !tests_pair(detail::pair_first(key), detail::pair_second(key));
    });
    std::optional<ClosePair> best;
    for (const std::uint64_t key : keys) {
      ClosePair p = s.answer(key, scratch);
      if (!best || p.result.distance < best->result.distance ||
          (p.result.distance == best->result.distance && p.result.status == Status::intersecting &&
           best->result.status != Status::intersecting))
        best = std::move(p);
    }
    // A pair found at distance d <= margin is the nearest: any nearer pair
    // was a candidate. Found beyond the margin, one more search at margin d
    // holds every nearer pair (and is final, whatever rounding the repeated
    // queries give).
    if (best && (best->result.distance <= margin || refined)) return best;
    if (best) {
      margin = best->result.distance;
      refined = true;
      continue;
    }
    // Every pair was a candidate: none is tested.
    if (margin >= span || widenings == kMaxWidenings) return std::nullopt;
    ++widenings;
    margin = std::max({2.0 * margin, span / 64.0, std::numeric_limits<double>::min()});
  }
}

std::vector<ClosePair> Scene::pairs_within(BodyId id, double margin) {
  Impl& s = *impl_;
  s.live_body(id, "pairs_within");
  Impl::Body& body = s.bodies[slot(id)];
  detail::check_finite_non_negative(margin, "Scene::pairs_within", "margin");
  const Aabb box = s.world_box(body, margin);
  std::vector<ClosePair> out;
  Impl::PairState scratch;
  for (BodyId other = 0; static_cast<std::size_t>(other) < s.bodies.size(); ++other) {
    Impl::Body& b = s.bodies[slot(other)];
    if (other == id || !b.live || !detail::overlaps(box, s.world_box(b, margin))) continue;
    if (!tests_pair(id, other)) continue;
    ClosePair p = s.answer(detail::pair_key(std::min(id, other), std::max(id, other)), scratch);
    if (is_close(p.result, margin)) out.push_back(std::move(p));
  }
  return out;
}

std::vector<ClosePair> Scene::close_pairs_all_pairs() const {
  const Impl& s = *impl_;
  std::vector<ClosePair> out;
  const std::vector<BodyId> ids = body_ids();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Impl::Body& a = s.bodies[slot(ids[i])];
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      if (!tests_pair(ids[i], ids[j])) continue;
      const Impl::Body& b = s.bodies[slot(ids[j])];
      if (a.general || b.general) {
        ClosePair p = Impl::body_answer(
            ids[i], a, ids[j], b,
            distance(a.shape->padded, a.pose, b.shape->padded, b.pose, s.options.distance));
        if (is_close(p.result, s.options.margin)) out.push_back(std::move(p));
        continue;
      }
      CompoundResult r;
      if (a.convex && b.convex) {
        static_cast<DistanceResult&>(r) =
            distance(*a.convex, a.pose, *b.convex, b.pose, s.options.distance);
        r.piece_a = 0;
        r.piece_b = 0;
        r.pairs_tested = 1;
      } else {
        r = distance(*a.compound, a.pose, *b.compound, b.pose, s.options.distance);
      }
      if (is_close(r, s.options.margin)) out.push_back(ClosePair{ids[i], ids[j], r});
    }
  }
  return out;
}

}  // namespace proxima
