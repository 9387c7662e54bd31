// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Scene::sweep: continuous collision over a step, and its slow twin.
#include "scene/scene_impl.h"

namespace proxima {

std::span<const ImpactPair> Scene::sweep(const ImpactOptions& options) {
  detail::check_impact_options(options, "Scene::sweep");
  Impl& s = *impl_;
  if (!s.sweep_finder) {
    s.sweep_finder = detail::make_pair_finder(s.options.broad_phase);
    for (std::size_t k = 0; k < s.bodies.size(); ++k) {
      if (s.bodies[k].live) s.sweep_finder->add(static_cast<BodyId>(k));
    }
  }
  const int threads = s.options.threads;
  // Each box takes half of what the pair may close to and still count as a
  // contact: the target, the tolerance (time_of_impact's default: relative
  // to each body's size) and the touching tolerance Ae.
  const double explicit_tolerance = options.tolerance;
  const double pad =
      0.5 * (options.target_separation + explicit_tolerance + options.distance.absolute_tolerance);
  const double size_pad = explicit_tolerance > 0.0 ? 0.0 : detail::kDefaultImpactTolerance;
  s.swept_boxes.resize(s.bodies.size());
  detail::parallel_chunks(s.bodies.size(), kBoxChunk, threads,
                          [&](std::size_t, std::size_t begin, std::size_t end) {
                            for (std::size_t k = begin; k < end; ++k) {
                              if (s.bodies[k].live)
                                s.swept_boxes[k] = s.swept_box(s.bodies[k], pad, size_pad);
                            }
                          });
  s.sweep_finder->find_pairs(s.swept_boxes, s.sweep_candidates, threads);
  const int filtered = s.filter_candidates(s.sweep_candidates);
  s.drop_removed(s.sweep_pairs, s.removed_since_sweep);
  s.drop_removed(s.pairs, s.removed_since_step);
  const int warm = s.carry_caches(s.sweep_candidates, s.sweep_pairs, &s.pairs, threads);

  // The time of impact of each candidate, the pairs not separated gathered
  // in pair order (each chunk into its own list, joined in chunk order).
  const std::size_t n = s.sweep_pairs.size();
  s.sweep_queries.assign(n, 0);
  detail::parallel_gather(
      n, kGrainSize, threads, s.impact_chunks, s.impacts,
      [&s, &options](std::size_t begin, std::size_t end, std::vector<ImpactPair>& out) {
        for (std::size_t k = begin; k < end; ++k) {
          Impl::PairState& state = s.sweep_pairs[k];
          const BodyId a = detail::pair_first(state.key);
          const BodyId b = detail::pair_second(state.key);
          ImpactResult r = s.impact(s.bodies[slot(a)], s.bodies[slot(b)], options, &state);
          s.sweep_queries[k] = r.iterations;
          if (r.status != ImpactStatus::separated) out.push_back(ImpactPair{a, b, std::move(r)});
        }
      });

  SweepStats& stats = s.sweep_stats;
  stats = SweepStats{};
  stats.bodies = s.live_count;
  for (const Impl::Body& b : s.bodies) {
    if (b.live && (b.angular.has_value() || !(b.end.translation == b.pose.translation &&
                                              b.end.rotation == b.pose.rotation)))
      ++stats.moving_bodies;
  }
  stats.candidate_pairs = static_cast<int>(n);
  stats.impact_pairs = static_cast<int>(s.impacts.size());
  for (const int q : s.sweep_queries) stats.distance_queries += q;
  stats.warm_pairs = warm;
  stats.filtered_pairs = filtered;
  return s.impacts;
}

namespace {
ImpactOptions scene_impact_options(const SceneOptions& scene) {
  ImpactOptions options;
  options.distance = scene.distance;
  return options;
}
}  // namespace

std::span<const ImpactPair> Scene::sweep() { return sweep(scene_impact_options(impl_->options)); }

std::vector<ImpactPair> Scene::impact_pairs_all_pairs() const {
  return impact_pairs_all_pairs(scene_impact_options(impl_->options));
}

const SweepStats& Scene::sweep_stats() const { return impl_->sweep_stats; }

std::vector<ImpactPair> Scene::impact_pairs_all_pairs(const ImpactOptions& options) const {
  detail::check_impact_options(options, "Scene::impact_pairs_all_pairs");
  const Impl& s = *impl_;
  std::vector<ImpactPair> out;
  const std::vector<BodyId> ids = body_ids();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      if (!tests_pair(ids[i], ids[j])) continue;
      ImpactResult r = s.impact(s.bodies[slot(ids[i])], s.bodies[slot(ids[j])], options, nullptr);
      if (r.status != ImpactStatus::separated)
        out.push_back(ImpactPair{ids[i], ids[j], std::move(r)});
    }
  }
  return out;
}

}  // namespace proxima
