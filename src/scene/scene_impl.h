// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// scene layer (internal): the state of a Scene (Scene::Impl) and the helpers
// its four files share: scene.cpp (bodies, filters, step), scene_margin.cpp
// (step_within, first_within: the collision checks), scene_sweep.cpp
// (continuous collision) and scene_queries.cpp (nearest_pair,
// pairs_within, the twins).
//
// A scene of moving bodies: per step, one world box per body, the pair
// finder of broad_phase.h, then the tracked distance query on every
// candidate pair with the cache that pair left at the previous step.
//
// Pair caches live in a vector sorted by pair key, parallel to the sorted
// candidate list of the step that made them. The next step's candidates are
// also sorted, so one merge carries each surviving pair's cache over and
// drops the caches of pairs that stopped being candidates: no hash map, and
// a pair's cache is evicted the first step its boxes stop overlapping.
//
// Each candidate owns its cache and its result slot, and the bodies are only
// read, so the narrow phase runs over index ranges on any number of threads
// and gives bit-identical answers whatever that number is.
//
// A sweep (continuous collision) is the same pipeline on other boxes and
// another query: each body's box holds its whole swept volume (swept_box
// below), its own pair finder and pair list keep the sweep's coherence
// apart from the step's, and each candidate pair runs time_of_impact from
// its cache.
#pragma once

#include "proxima/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "core/accuracy.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "motion/time_of_impact.h"
#include "query/parallel_ranges.h"
#include "scene/broad_phase.h"

// The helpers live in a namespace of their own, brought into proxima's by
// the using-directive below: this header is private to the scene's four
// files, which read them unqualified as they did in one file.
namespace proxima::scene_impl {

using detail::Aabb;

// Smallest index range a sweep's task runs (its time of impact queries): a
// tracked query costs a fraction of what a TBB task costs to schedule, so a
// task must run tens of them to pay for itself (as in batch.cpp).
inline constexpr std::size_t kGrainSize = 32;

// Fixed chunks (parallel_ranges.h) of the step's parallel loops: the world
// boxes (six warm hill climbs each, a fraction of a microsecond) and the
// narrow phase with the gathering of the close pairs, in the order of a
// sequential loop.
inline constexpr std::size_t kBoxChunk = 512;
// Fixed chunks of the narrow phase (candidate pairs): a chunk answers its
// pairs and counts its close ones, then copies them to their place. About
// 64 chunks per step, so that TBB, dealing them out to the threads as they
// finish, leaves at most a small fraction of the step to one thread at the
// end, and of 32 to 256 pairs: at a few tenths of a microsecond per tracked
// query, tasks of 10 to 100 microseconds against about 1 to schedule.
// 16,000 candidates (10,000 bodies) make 64 chunks of 250, 1,500 (1,000
// bodies) 47 of 32. The size depends on the candidate count only, never on
// the threads: the output is in pair order whatever it is.
inline constexpr std::size_t kNarrowChunkMin = 32;
inline constexpr std::size_t kNarrowChunkMax = 256;
inline constexpr std::size_t kNarrowChunks = 64;
inline std::size_t narrow_chunk(std::size_t pairs) {
  return std::clamp(pairs / kNarrowChunks, kNarrowChunkMin, kNarrowChunkMax);
}
// Candidate pairs per chunk of the merge that carries the caches over.
inline constexpr std::size_t kCarryChunk = 1024;

// Rounding slack of a world box, in units of u times the body's magnitude
// bound |t|_inf + sqrt(3) scale: 64 for the contact band of the accuracy
// standard (a pair within 64 u R is touching, and must reach the narrow
// phase even at margin 0), 64 more for the rounding of the box itself (a few
// operations on numbers of magnitude R).
inline constexpr double kBoxSlackUlps = 128.0;

// A swept box adds up a few more numbers of magnitude R (the boxes shifted
// by the other end's translation, the turn's sag) and numbers of the size of
// the target and the turn's sag: a few more units of rounding on each.
inline constexpr double kSweptBoxSlackUlps = kBoxSlackUlps + 32.0;
inline constexpr double kSweptPadSlackUlps = 8.0;

inline std::size_t slot(BodyId id) { return static_cast<std::size_t>(id); }

inline std::string name(BodyId id) { return "body " + std::to_string(id); }

inline Aabb inflated(const Aabb& box, double by) {
  return {(box.lo.array() - by).matrix(), (box.hi.array() + by).matrix()};
}

inline bool is_close(const DistanceResult& r, double margin) {
  return r.status == Status::touching || r.status == Status::intersecting || r.distance <= margin;
}

// A pair's BodyCache (pairs with a rounded, padded or mesh body), on the
// heap so that the states of the plain pairs, which are moved about by every
// step's merge, stay small. Copies are deep (a sweep's pair may start from
// a copy of the step's cache).
class BodyCacheSlot {
 public:
  BodyCacheSlot() = default;
  BodyCacheSlot(const BodyCacheSlot& other)
      : cache_(other.cache_ ? std::make_unique<BodyCache>(*other.cache_) : nullptr) {}
  BodyCacheSlot& operator=(const BodyCacheSlot& other) {
    if (this != &other)
      cache_ = other.cache_ ? std::make_unique<BodyCache>(*other.cache_) : nullptr;
    return *this;
  }
  BodyCacheSlot(BodyCacheSlot&&) noexcept = default;
  BodyCacheSlot& operator=(BodyCacheSlot&&) noexcept = default;
  ~BodyCacheSlot() = default;

  BodyCache& get() {
    if (!cache_) cache_ = std::make_unique<BodyCache>();
    return *cache_;
  }
  void reset() {
    if (cache_) cache_->reset();
  }

 private:
  std::unique_ptr<BodyCache> cache_;
};

inline double checked_padding(double padding, const std::string& who) {
  return detail::check_finite_non_negative(padding, who.c_str(), "padding");
}

}  // namespace proxima::scene_impl

namespace proxima {

using namespace scene_impl;  // NOLINT(google-build-using-namespace): see above

struct Scene::Impl {
  struct Shape {
    proxima::Body given;  // as added
    // `given` with its radius plus the padding: what the narrow phase of a
    // general pair measures.
    proxima::Body padded;
    double padding = 0.0;
  };

  struct Body {
    std::shared_ptr<const ConvexPolytope> convex;  // the core of a convex body, else null
    // The compound body; for a convex body, the body as a one-piece compound,
    // made when the scene first holds a compound (plain convex-compound
    // pairs go through the compound query). Null for a mesh.
    std::shared_ptr<const CompoundBody> compound;
    // The body as a proxima::Body, on the heap: the step's loops read the
    // fields around it for every pair, and two Bodies held here would spread
    // those fields over more cache lines (a slower step in bench/scene_bench
    // at 10,000 bodies).
    std::unique_ptr<Shape> shape;
    double reach = 0.0;    // shape->padded.radius(): how far the body reaches beyond its core
    bool general = false;  // rounded, padded or a mesh: its pairs take the Body query
    Pose pose;
    Pose end;                // the end pose of the next sweep
    // The angular velocity of the next sweep when set_velocity gave it (the
    // body turns at this rate through any angle), else the shorter way.
    std::optional<Vec3> angular;
    detail::BoxHints hints;  // support_box's
    CollisionFilter filter;
    bool live = false;
  };

  // The coherence of one candidate pair: the convex cache for a pair of
  // plain convex bodies, the Body cache for a pair with a general body, the
  // compound cache otherwise.
  struct PairState {
    std::uint64_t key = 0;
    DistanceCache convex;
    CompoundCache compound;
    BodyCacheSlot body;
    void reset() {
      convex.reset();
      compound.reset();
      body.reset();
    }
  };

  SceneOptions options;
  std::vector<Body> bodies;
  std::vector<BodyId> free_ids;  // reused last removed first
  int live_count = 0;
  int compound_count = 0;
  std::unique_ptr<detail::PairFinder> finder;
  std::vector<Aabb> boxes;
  std::vector<std::uint64_t> candidates;
  std::vector<PairState> pairs;         // sorted by key: this step's candidates
  std::vector<PairState> next_pairs;    // scratch of the merge
  std::vector<std::uint64_t> excluded;  // pair keys, increasing
  std::vector<BodyId> removed_since_step;
  std::vector<std::uint8_t> removed_flag;  // by id, scratch
  std::vector<ClosePair> results;          // parallel to pairs
  std::vector<std::size_t> chunk_close;    // close pairs per chunk of pairs, then their offsets
  std::vector<int> chunk_queries;          // convex queries per chunk of pairs
  std::vector<int> chunk_warm;             // warm pairs per chunk of carry_caches
  std::vector<ClosePair> close;
  std::vector<MarginPair> margin_results;  // parallel to pairs (step_within on threads)
  std::vector<MarginPair> margin_close;
  // The pair first_within found last (0: none; no pair has key 0, whose
  // bodies would both be body 0).
  std::uint64_t last_within = 0;
  SceneStats stats;

  // The sweep's own broad phase and coherence, made by the first sweep.
  std::unique_ptr<detail::PairFinder> sweep_finder;
  std::vector<Aabb> swept_boxes;
  std::vector<std::uint64_t> sweep_candidates;
  std::vector<PairState> sweep_pairs;  // sorted by key: the last sweep's candidates
  std::vector<BodyId> removed_since_sweep;
  std::vector<int> sweep_queries;  // parallel to sweep_pairs
  std::vector<std::vector<ImpactPair>> impact_chunks;
  std::vector<ImpactPair> impacts;
  SweepStats sweep_stats;

  const Body& live_body(BodyId id, const char* what) const {
    if (id < 0 || slot(id) >= bodies.size() || !bodies[slot(id)].live) {
      throw InvalidInput(std::string("Scene::") + what + ": " + name(id) +
                         " is not in the scene (never added, or removed)");
    }
    return bodies[slot(id)];
  }

  BodyId take_id() {
    if (!free_ids.empty()) {
      const BodyId id = free_ids.back();
      free_ids.pop_back();
      return id;
    }
    bodies.emplace_back();
    return static_cast<BodyId>(bodies.size() - 1);
  }

  static std::shared_ptr<const CompoundBody> wrap(const std::shared_ptr<const ConvexPolytope>& c) {
    std::vector<CompoundPiece> pieces{CompoundPiece{c, Pose::identity()}};
    return std::make_shared<const CompoundBody>(std::move(pieces));
  }

  // From now on plain convex bodies may meet a compound: give each its
  // wrapper.
  void wrap_convex_bodies() {
    for (Body& other : bodies) {
      if (other.live && other.convex && !other.compound) other.compound = wrap(other.convex);
    }
  }

  // The padded body, reach and kind of pairs of body b after its padding
  // was set.
  static void pad(Body& b) {
    Shape& shape = *b.shape;
    const double radius = shape.given.radius() + shape.padding;
    shape.padded = shape.given.with_radius(radius);
    b.reach = radius;
    b.general = radius > 0.0 || shape.given.kind() == proxima::Body::Kind::mesh;
  }

  BodyId insert(Body body) {
    const BodyId id = take_id();
    body.live = true;
    bodies[slot(id)] = std::move(body);
    finder->add(id);
    if (sweep_finder) sweep_finder->add(id);
    ++live_count;
    return id;
  }

  // World box inflated so that box overlap means "may be within margin":
  // each box takes half the margin (and half the touching tolerance Ae).
  // Convex bodies get the exact box of their placed hull (six warm hill
  // climbs) rather than the box of their bounding sphere: fewer candidate
  // pairs reach the narrow phase, and the hill climbs cost less than the
  // tracked queries they save (bench/broad_phase_bench).
  //
  // A mesh's box is its hierarchy's root box, placed (the box of the
  // turned box); a general body's box grows by its reach (radius plus
  // padding): the box of the core grown by r holds the core plus a ball of
  // radius r.
  Aabb world_box(Body& b) const { return world_box(b, options.margin); }
  Aabb world_box(Body& b, double margin) const {
    Aabb box;
    double scale = 0.0;
    if (b.convex) {
      box = detail::support_box(*b.convex, b.pose, b.hints);
      scale = b.convex->scale();
    } else if (!b.compound) {
      const TriangleMesh& mesh = *b.shape->given.mesh();
      box = placed_root_box(mesh, b.pose);
      scale = mesh.scale();
    } else {
      // Compounds: the box of the root's bounding sphere.
      const Vec3 center = b.pose.apply(b.compound->center());
      const double r = b.compound->bounding_radius();
      box = {(center.array() - r).matrix(), (center.array() + r).matrix()};
      scale = b.compound->scale();
    }
    const double slack = kBoxSlackUlps * kUnitRoundoff * magnitude_bound(b.pose, scale + b.reach);
    return inflated(box, 0.5 * (margin + options.distance.absolute_tolerance) + b.reach + slack);
  }

  // The root box of a mesh's hierarchy at `pose`: center placed, half
  // extents through |R|. Its rounding (a few operations on numbers below
  // the mesh's magnitude bound) is inside the callers' slack.
  static Aabb placed_root_box(const TriangleMesh& mesh, const Pose& pose) {
    Vec3 lo, hi;
    mesh.box(0, lo, hi);
    const Vec3 center = pose.apply(0.5 * (lo + hi));
    const Vec3 half = Mat3(pose.rotation).cwiseAbs() * (0.5 * (hi - lo));
    return {center - half, center + half};
  }

  // The answer of distance(Body, Body) on two padded bodies in the scene's
  // terms (ClosePair): pieces 0 for a convex body, one query.
  static ClosePair body_answer(BodyId ia, const Body& a, BodyId ib, const Body& b,
                               const BodyResult& d) {
    ClosePair p{ia, ib, {}, d.triangle_a, d.triangle_b};
    static_cast<DistanceResult&>(p.result) = d;
    p.result.piece_a = a.convex ? 0 : d.piece_a;
    p.result.piece_b = b.convex ? 0 : d.piece_b;
    p.result.pairs_tested = 1;
    return p;
  }

  // The answer of pair `state` written into `p`, every field of it: the
  // narrow phase answers into its output slots, so that no answer of about
  // 280 bytes is built and then copied.
  void query_into(PairState& state, ClosePair& p) const {
    const BodyId ia = detail::pair_first(state.key);
    const BodyId ib = detail::pair_second(state.key);
    const Body& a = bodies[slot(ia)];
    const Body& b = bodies[slot(ib)];
    if (a.general || b.general) {
      p = body_answer(ia, a, ib, b,
                      distance(a.shape->padded, a.pose, b.shape->padded, b.pose, options.distance,
                               &state.body.get()));
      return;
    }
    if (a.convex && b.convex) {
      p.a = ia;
      p.b = ib;
      p.triangle_a = -1;
      p.triangle_b = -1;
      static_cast<DistanceResult&>(p.result) =
          // The stored poses were checked by add and set_pose.
          detail::distance_of_rigid_poses(*a.convex, a.pose, *b.convex, b.pose, options.distance,
                                          &state.convex);
      p.result.piece_a = 0;
      p.result.piece_b = 0;
      p.result.pairs_tested = 1;
      return;
    }
    p = ClosePair{
        ia, ib,
        distance(*a.compound, a.pose, *b.compound, b.pose, options.distance, &state.compound)};
  }

  // The margin answer of pair `state` (the scene's margin) written into
  // `p`: the margin query of the pair's kind, from and into the same cache
  // as query_into's (so step() and step_within() keep each other warm).
  void margin_into(PairState& state, MarginPair& p) const {
    p.a = detail::pair_first(state.key);
    p.b = detail::pair_second(state.key);
    const Body& a = bodies[slot(p.a)];
    const Body& b = bodies[slot(p.b)];
    const double margin = options.margin;
    if (a.general || b.general) {
      p.result = within_margin(a.shape->padded, a.pose, b.shape->padded, b.pose, margin,
                               options.distance, &state.body.get());
      return;
    }
    if (a.convex && b.convex) {
      // The stored poses were checked by add and set_pose, the margin and
      // options by the constructor.
      p.result = detail::within_margin_of_rigid_poses(*a.convex, a.pose, *b.convex, b.pose, margin,
                                                      options.distance, state.convex);
      return;
    }
    p.result =
        within_margin(*a.compound, a.pose, *b.compound, b.pose, margin, options.distance,
                      &state.compound);
    // A convex body met a compound as its one-piece wrapper: no pieces.
    if (a.convex) p.result.piece_a = -1;
    if (b.convex) p.result.piece_b = -1;
  }

  // The broad phase of a step on the current poses: the world boxes, the
  // candidate pairs, the filters, and each surviving pair's cache carried
  // over (stats' bodies, candidate, warm and filtered counts).
  void find_candidates() {
    const int threads = options.threads;
    boxes.resize(bodies.size());
    detail::parallel_chunks(bodies.size(), kBoxChunk, threads,
                            [this](std::size_t, std::size_t begin, std::size_t end) {
                              for (std::size_t k = begin; k < end; ++k) {
                                if (bodies[k].live) boxes[k] = world_box(bodies[k]);
                              }
                            });
    finder->find_pairs(boxes, candidates, threads);
    stats.filtered_pairs = filter_candidates(candidates);
    drop_removed(pairs, removed_since_step);
    stats.warm_pairs = carry_caches(candidates, pairs, nullptr, threads);
    stats.bodies = live_count;
    stats.candidate_pairs = static_cast<int>(pairs.size());
  }

  // The narrow phase of a step: `answer(state, slot)` answers one
  // candidate pair into its slot and `reported(slot)` says whether the
  // step reports it; the reported answers land in `out` in pair order.
  // Returns the leaf queries run (the answers' pairs_tested). On one
  // thread, the reported answers go straight to `out`. On threads, in fixed
  // chunks of pairs: each chunk answers its pairs into their slots of
  // `slots` and counts its reported ones, the offsets follow, and each
  // chunk copies its reported answers to its place (the count rides on
  // the answering pass, which has the answers at hand, instead of a pass
  // of its own over every slot).
  template <class Answer, class AnswerInto, class Reported>
  int narrow_phase(std::vector<Answer>& slots, std::vector<Answer>& out, AnswerInto answer,
                   Reported reported) {
    const int threads = options.threads;
    const std::size_t n = pairs.size();
    const std::size_t chunk = narrow_chunk(n);
    const std::size_t chunks = detail::chunk_count(n, chunk);
    int queries = 0;
    if (threads == 1 || chunks < 2) {
      out.clear();
      for (std::size_t k = 0; k < n; ++k) {
        Answer& p = out.emplace_back();
        answer(pairs[k], p);
        queries += p.result.pairs_tested;
        if (!reported(p)) out.pop_back();
      }
      return queries;
    }
    slots.resize(n);
    chunk_close.assign(chunks, 0);
    chunk_queries.assign(chunks, 0);
    detail::parallel_chunks(n, chunk, threads, [&](std::size_t c, std::size_t begin,
                                                   std::size_t end) {
      std::size_t count = 0;
      int work = 0;
      for (std::size_t k = begin; k < end; ++k) {
        Answer& p = slots[k];
        answer(pairs[k], p);
        count += reported(p) ? 1 : 0;
        work += p.result.pairs_tested;
      }
      chunk_close[c] = count;
      chunk_queries[c] = work;
    });
    std::size_t total = 0;
    for (std::size_t& c : chunk_close) total += std::exchange(c, total);
    out.resize(total);
    detail::parallel_chunks(n, chunk, threads,
                            [&](std::size_t c, std::size_t begin, std::size_t end) {
                              std::size_t at = chunk_close[c];
                              for (std::size_t k = begin; k < end; ++k) {
                                if (reported(slots[k])) out[at++] = slots[k];
                              }
                            });
    for (const int q : chunk_queries) queries += q;
    return queries;
  }

  ClosePair query(PairState& state) const {
    ClosePair p;
    query_into(state, p);
    return p;
  }

  bool groups_meet(const Body& a, const Body& b) const {
    return (a.filter.group & b.filter.mask) != 0 && (b.filter.group & a.filter.mask) != 0;
  }

  bool excluded_key(std::uint64_t key) const {
    return std::binary_search(excluded.begin(), excluded.end(), key);
  }

  // Drops the candidates the filters reject: one merge with the sorted
  // exclusions (both lists increase). Returns how many were dropped.
  int filter_candidates(std::vector<std::uint64_t>& keys) const {
    const bool any_groups = std::any_of(bodies.begin(), bodies.end(), [](const Body& b) {
      return b.live && (b.filter.group != 1 || b.filter.mask != 0xffffffffu);
    });
    if (!any_groups && excluded.empty()) return 0;
    std::size_t e = 0;
    const std::size_t before = keys.size();
    std::erase_if(keys, [&](std::uint64_t key) {
      while (e < excluded.size() && excluded[e] < key) ++e;
      if (e < excluded.size() && excluded[e] == key) return true;
      return !groups_meet(bodies[slot(detail::pair_first(key))],
                          bodies[slot(detail::pair_second(key))]);
    });
    return static_cast<int>(before - keys.size());
  }

  // The state of pair `key` for a query outside step(): the pair's own
  // state when it is a candidate of the last step (its cache is used and
  // updated: tracking), else `scratch`, cold.
  PairState& state_of(std::uint64_t key, PairState& scratch) {
    const auto at = std::lower_bound(pairs.begin(), pairs.end(), key,
                                     [](const PairState& p, std::uint64_t k) { return p.key < k; });
    if (at != pairs.end() && at->key == key) return *at;
    scratch.key = key;
    scratch.reset();
    return scratch;
  }

  ClosePair answer(std::uint64_t key, PairState& scratch) { return query(state_of(key, scratch)); }

  // A removed body's id may already belong to a new body: its pairs'
  // caches describe other bodies and go (a stale cache is only slower, but
  // it would also make the warm count lie).
  void drop_removed(std::vector<PairState>& list, std::vector<BodyId>& removed) {
    if (removed.empty()) return;
    removed_flag.assign(bodies.size(), 0);
    for (const BodyId id : removed) removed_flag[slot(id)] = 1;
    std::erase_if(list, [&](const PairState& p) {
      return removed_flag[slot(detail::pair_first(p.key))] != 0 ||
             removed_flag[slot(detail::pair_second(p.key))] != 0;
    });
    removed.clear();
  }

  // Makes `list` (sorted by key, the states of the last call's candidates)
  // the states of `keys` (sorted): a pair that stays keeps its state, a new
  // one starts from its state in `donor` (sorted too; may be null) when it
  // has one there, else cold. Returns how many are warm. On threads, in
  // fixed chunks of keys, each starting its merge where its first key falls
  // in `list` and `donor` (each old state moves to one key at most, so the
  // chunks touch disjoint states): the merge moved 16,000 states of about
  // 250 bytes per step at 10,000 bodies, on one thread while the other
  // waited.
  int carry_caches(const std::vector<std::uint64_t>& keys, std::vector<PairState>& list,
                   const std::vector<PairState>* donor, int threads) {
    next_pairs.resize(keys.size());
    const auto by_key = [](const PairState& p, std::uint64_t k) { return p.key < k; };
    chunk_warm.assign(detail::chunk_count(keys.size(), kCarryChunk), 0);
    detail::parallel_chunks(
        keys.size(), kCarryChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
          int warm = 0;
          auto old = static_cast<std::size_t>(
              std::lower_bound(list.begin(), list.end(), keys[begin], by_key) - list.begin());
          std::size_t given = 0;
          if (donor != nullptr) {
            given = static_cast<std::size_t>(
                std::lower_bound(donor->begin(), donor->end(), keys[begin], by_key) -
                donor->begin());
          }
          for (std::size_t k = begin; k < end; ++k) {
            const std::uint64_t key = keys[k];
            while (old < list.size() && list[old].key < key) ++old;
            PairState& next = next_pairs[k];
            if (old < list.size() && list[old].key == key) {
              next = std::move(list[old]);
              ++warm;
              continue;
            }
            if (donor != nullptr) {
              while (given < donor->size() && (*donor)[given].key < key) ++given;
              if (given < donor->size() && (*donor)[given].key == key) {
                next = (*donor)[given];
                ++warm;
                continue;
              }
            }
            next.reset();
            next.key = key;
          }
          chunk_warm[c] = warm;
        });
    list.swap(next_pairs);
    int warm = 0;
    for (const int w : chunk_warm) warm += w;
    return warm;
  }

  // The box of everything body b covers on its way from its pose to its end
  // pose, grown by `pad` (plus `size_pad` times the body's size, for a
  // tolerance relative to the bodies' sizes).
  //
  // Why it holds the swept volume. A point x of the body (x' = R0 x, from
  // the reference point c0) is at p(t) = c0 + t v + E(t) x', E(t) the turn
  // by t theta about the axis (theta <= pi). On the plane across the axis,
  // E(t) x' runs along an arc of angle theta <= pi, which stays within the
  // sag s = rho (1 - cos(theta / 2)) of its chord [x', E(1) x'] (rho <= |x'|
  // its distance from the axis), with the foot of the perpendicular on the
  // chord. So E(t) x' = x' + sigma (E(1) x' - x') + e with sigma in [0, 1],
  // |e| <= s, and p(t) - e is a convex combination of c0 + x' (the body at
  // its pose), c0 + v + E(1) x' (at its end pose), c0 + v + x' (the pose
  // moved by v) and c0 + E(1) x' (the end pose moved back by v). The box of
  // the body at those four poses is the box at each end and that box shifted
  // by the other end's v; grown by s for the farthest point, it holds the
  // swept volume. The union of the two end boxes alone is not enough: a bar
  // turning a quarter turn about its middle sweeps a disc that neither end
  // touches. s = 2 rho sin^2(theta / 4), second order in theta: a small turn
  // barely grows the box.
  //
  // A compound's box is its bounding sphere's: the sphere's center moves as
  // a point of the body, and the ball around it turns onto itself. A
  // general body's box grows by its reach: the swept volume of the core
  // plus a ball of radius r is the core's swept volume grown by r.
  Aabb swept_box(Body& b, double pad, double size_pad) const {
    Aabb start, end;
    double scale = 0.0;
    double arm = 0.0;   // bound on rho over the points (or the sphere's center) boxed
    double size = 0.0;  // bound on the body's size in any query's default tolerance
    // A body turning by velocity moves even when its end pose is its pose
    // (whole turns).
    const bool moving = b.angular.has_value() || !(b.end.translation == b.pose.translation &&
                                                   b.end.rotation == b.pose.rotation);
    if (b.convex) {
      start = detail::support_box(*b.convex, b.pose, b.hints);
      end = moving ? detail::support_box(*b.convex, b.end, b.hints) : start;
      scale = b.convex->scale();
      arm = b.convex->centroid().stableNorm() + b.convex->bounding_radius();
      size = arm;
      if (b.compound)
        size = std::max(size, b.compound->center().stableNorm() + b.compound->bounding_radius());
    } else {
      // A compound's bounding sphere, or a mesh's: its root box's center and
      // half diagonal (the box holds every vertex).
      Vec3 center_local;
      double r = 0.0;
      if (b.compound) {
        center_local = b.compound->center();
        r = b.compound->bounding_radius();
        scale = b.compound->scale();
      } else {
        const TriangleMesh& mesh = *b.shape->given.mesh();
        center_local = mesh.center();
        r = mesh.bounding_radius();
        scale = mesh.scale();
      }
      const auto sphere = [&](const Pose& p) {
        const Vec3 center = p.apply(center_local);
        return Aabb{(center.array() - r).matrix(), (center.array() + r).matrix()};
      };
      start = sphere(b.pose);
      end = moving ? sphere(b.end) : start;
      arm = center_local.stableNorm();
      size = arm + r;
    }
    size += b.reach;
    Aabb box = start;
    double sag = 0.0;
    if (moving) {
      const Vec3 v = b.end.translation - b.pose.translation;
      box.lo = start.lo.cwiseMin(end.lo).cwiseMin(start.lo + v).cwiseMin(end.lo - v);
      box.hi = start.hi.cwiseMax(end.hi).cwiseMax(start.hi + v).cwiseMax(end.hi - v);
      // The turn as time_of_impact's motion takes it: the angular velocity's
      // whole angle when set_velocity gave it, else the shorter way's (in
      // [0, pi]). A point at `arm` from the reference point sweeps an arc
      // of that angle, no farther than arm (1 - cos(theta / 2)) from its
      // chord while theta <= pi; beyond, anywhere on its circle, within
      // 2 arm of the chord's ends.
      const double theta =
          b.angular ? b.angular->stableNorm()
                    : Eigen::AngleAxisd(Mat3(b.end.rotation * b.pose.rotation.transpose())).angle();
      if (theta <= std::numbers::pi) {
        const double q = std::sin(0.25 * theta);
        sag = 2.0 * arm * q * q;
      } else {
        sag = 2.0 * arm;
      }
    }
    const double grow = pad + size_pad * size + sag + b.reach;
    const double magnitude =
        std::max(magnitude_bound(b.pose, scale), magnitude_bound(b.end, scale));
    const double slack =
        kSweptBoxSlackUlps * kUnitRoundoff * magnitude + kSweptPadSlackUlps * kUnitRoundoff * grow;
    return inflated(box, grow + slack);
  }

  // time_of_impact of bodies a and b moving from their poses to their end
  // poses: the convex query for two plain convex bodies, the Body query
  // otherwise (on the padded bodies when either is general); from and into
  // `state`'s cache when given.
  static ImpactResult impact(const Body& a, const Body& b, const ImpactOptions& impact_options,
                             PairState* state) {
    const Motion ma{a.pose, a.end, a.angular};
    const Motion mb{b.pose, b.end, b.angular};
    if (a.general || b.general) {
      return time_of_impact(a.shape->padded, ma, b.shape->padded, mb, impact_options,
                            state != nullptr ? &state->body.get() : nullptr);
    }
    if (a.convex && b.convex) {
      return time_of_impact(*a.convex, ma, *b.convex, mb, impact_options,
                            state != nullptr ? &state->convex : nullptr);
    }
    const proxima::Body ba(a.compound);
    const proxima::Body bb(b.compound);
    BodyCache cache;
    if (state != nullptr) cache.compound = std::move(state->compound);
    ImpactResult r = time_of_impact(ba, ma, bb, mb, impact_options, &cache);
    if (state != nullptr) state->compound = std::move(cache.compound);
    return r;
  }
};

}  // namespace proxima
