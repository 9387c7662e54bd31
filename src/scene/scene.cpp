// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
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

namespace proxima {
namespace {

using detail::Aabb;

// Smallest index range a sweep's task runs (its time of impact queries): a
// tracked query costs a fraction of what a TBB task costs to schedule, so a
// task must run tens of them to pay for itself (as in batch.cpp).
constexpr std::size_t kGrainSize = 32;

// Fixed chunks (parallel_ranges.h) of the step's parallel loops: the world
// boxes (six warm hill climbs each, a fraction of a microsecond) and the
// narrow phase with the gathering of the close pairs, in the order of a
// sequential loop.
constexpr std::size_t kBoxChunk = 512;
// Fixed chunks of the narrow phase (candidate pairs): a chunk answers its
// pairs and counts its close ones, then copies them to their place. About
// 64 chunks per step, so that TBB, dealing them out to the threads as they
// finish, leaves at most a small fraction of the step to one thread at the
// end, and of 32 to 256 pairs: at a few tenths of a microsecond per tracked
// query, tasks of 10 to 100 microseconds against about 1 to schedule.
// 16,000 candidates (10,000 bodies) make 64 chunks of 250, 1,500 (1,000
// bodies) 47 of 32. The size depends on the candidate count only, never on
// the threads: the output is in pair order whatever it is.
constexpr std::size_t kNarrowChunkMin = 32;
constexpr std::size_t kNarrowChunkMax = 256;
constexpr std::size_t kNarrowChunks = 64;
std::size_t narrow_chunk(std::size_t pairs) {
  return std::clamp(pairs / kNarrowChunks, kNarrowChunkMin, kNarrowChunkMax);
}
// Candidate pairs per chunk of the merge that carries the caches over.
constexpr std::size_t kCarryChunk = 1024;

// Rounding slack of a world box, in units of u times the body's magnitude
// bound |t|_inf + sqrt(3) scale: 64 for the contact band of the accuracy
// standard (a pair within 64 u R is touching, and must reach the narrow
// phase even at margin 0), 64 more for the rounding of the box itself (a few
// operations on numbers of magnitude R).
constexpr double kBoxSlackUlps = 128.0;

// A swept box adds up a few more numbers of magnitude R (the boxes shifted
// by the other end's translation, the turn's sag) and numbers of the size of
// the target and the turn's sag: a few more units of rounding on each.
constexpr double kSweptBoxSlackUlps = kBoxSlackUlps + 32.0;
constexpr double kSweptPadSlackUlps = 8.0;

std::size_t slot(BodyId id) { return static_cast<std::size_t>(id); }

std::string name(BodyId id) { return "body " + std::to_string(id); }

Aabb inflated(const Aabb& box, double by) {
  return {(box.lo.array() - by).matrix(), (box.hi.array() + by).matrix()};
}

bool is_close(const DistanceResult& r, double margin) {
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

double checked_padding(double padding, const std::string& who) {
  if (!std::isfinite(padding) || padding < 0.0) {
    throw InvalidInput(who + ": padding must be finite and >= 0, got " + std::to_string(padding));
  }
  return padding;
}

}  // namespace

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

Scene::Scene(const SceneOptions& options) : impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(options.margin) || options.margin < 0.0) {
    throw InvalidInput("Scene: options.margin must be finite and >= 0, got " +
                       std::to_string(options.margin));
  }
  if (options.threads < 0) {
    throw InvalidInput("Scene: options.threads must be >= 0 (0: all cores), got " +
                       std::to_string(options.threads));
  }
  const DistanceOptions& d = options.distance;
  detail::check_distance_options(d, "Scene: options.distance");
  impl_->options = options;
  impl_->finder = detail::make_pair_finder(options.broad_phase);
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

BodyId Scene::add(std::shared_ptr<const ConvexPolytope> body, const Pose& pose) {
  if (!body) throw InvalidInput("Scene::add: the convex body is null");
  Impl::Body b;
  b.pose = checked_pose(pose, "Scene::add: pose of the new convex body");
  b.end = b.pose;
  if (impl_->compound_count > 0) b.compound = Impl::wrap(body);
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{proxima::Body(body), proxima::Body(body)});
  b.convex = std::move(body);
  return impl_->insert(std::move(b));
}

BodyId Scene::add(const proxima::Body& body, const Pose& pose, double padding) {
  checked_padding(padding, "Scene::add");
  if (body.kind() != proxima::Body::Kind::mesh && body.radius() == 0.0 && padding == 0.0) {
    // A plain body: the adds above, keeping the Body as given (its
    // approximation error, for body()).
    const BodyId id = body.kind() == proxima::Body::Kind::convex ? add(body.convex(), pose)
                                                                 : add(body.compound(), pose);
    impl_->bodies[slot(id)].shape = std::make_unique<Impl::Shape>(Impl::Shape{body, body});
    return id;
  }
  Impl::Body b;
  b.pose = checked_pose(pose, "Scene::add: pose of the new body");
  b.end = b.pose;
  if (body.kind() == proxima::Body::Kind::convex) {
    b.convex = body.convex();
    if (impl_->compound_count > 0) b.compound = Impl::wrap(b.convex);
  } else if (body.kind() == proxima::Body::Kind::compound) {
    b.compound = body.compound();
  }
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{body, body, padding});
  Impl::pad(b);
  const bool compound = body.kind() == proxima::Body::Kind::compound;
  if (compound && impl_->compound_count == 0) impl_->wrap_convex_bodies();
  const BodyId id = impl_->insert(std::move(b));
  if (compound) ++impl_->compound_count;
  return id;
}

void Scene::set_padding(BodyId id, double padding) {
  impl_->live_body(id, "set_padding");
  checked_padding(padding, "Scene::set_padding: " + name(id));
  Impl::Body& b = impl_->bodies[slot(id)];
  b.shape->padding = padding;
  Impl::pad(b);
}

double Scene::padding(BodyId id) const { return impl_->live_body(id, "padding").shape->padding; }

const proxima::Body& Scene::body(BodyId id) const {
  return impl_->live_body(id, "body").shape->given;
}

BodyId Scene::add(std::shared_ptr<const CompoundBody> body, const Pose& pose) {
  if (!body) throw InvalidInput("Scene::add: the compound body is null");
  const Pose checked = checked_pose(pose, "Scene::add: pose of the new compound body");
  if (impl_->compound_count == 0) impl_->wrap_convex_bodies();
  Impl::Body b;
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{proxima::Body(body), proxima::Body(body)});
  b.compound = std::move(body);
  b.pose = checked;
  b.end = checked;
  const BodyId id = impl_->insert(std::move(b));
  ++impl_->compound_count;
  return id;
}

void Scene::set_pose(BodyId id, const Pose& pose) {
  impl_->live_body(id, "set_pose");
  Impl::Body& b = impl_->bodies[slot(id)];
  b.pose = checked_pose(pose, [&] { return "Scene::set_pose: pose of " + name(id); });
  b.end = b.pose;
  b.angular.reset();
}

void Scene::set_end_pose(BodyId id, const Pose& end) {
  impl_->live_body(id, "set_end_pose");
  Impl::Body& b = impl_->bodies[slot(id)];
  b.end = checked_pose(end, [&] { return "Scene::set_end_pose: end pose of " + name(id); });
  b.angular.reset();
}

void Scene::set_velocity(BodyId id, const Vec3& linear, const Vec3& angular) {
  impl_->live_body(id, "set_velocity");
  Impl::Body& b = impl_->bodies[slot(id)];
  Motion m;
  try {
    m = Motion::from_velocity(b.pose, linear, angular);
  } catch (const InvalidInput& e) {
    throw InvalidInput("Scene::set_velocity: " + name(id) + ": " + e.what());
  }
  b.end = m.end;
  b.angular = m.angular;
}

std::optional<Vec3> Scene::angular_velocity(BodyId id) const {
  return impl_->live_body(id, "angular_velocity").angular;
}

const Pose& Scene::end_pose(BodyId id) const { return impl_->live_body(id, "end_pose").end; }

void Scene::remove(BodyId id) {
  impl_->live_body(id, "remove");
  Impl::Body& b = impl_->bodies[slot(id)];
  if (b.shape->given.kind() == proxima::Body::Kind::compound) --impl_->compound_count;
  b = Impl::Body{};
  // Its exclusions go with it: the id may be reused by a new body.
  std::erase_if(impl_->excluded, [id](std::uint64_t key) {
    return detail::pair_first(key) == id || detail::pair_second(key) == id;
  });
  impl_->finder->remove(id);
  impl_->free_ids.push_back(id);
  impl_->removed_since_step.push_back(id);
  if (impl_->sweep_finder) {
    impl_->sweep_finder->remove(id);
    impl_->removed_since_sweep.push_back(id);
  }
  --impl_->live_count;
}

void Scene::set_filter(BodyId id, const CollisionFilter& filter) {
  impl_->live_body(id, "set_filter");
  impl_->bodies[slot(id)].filter = filter;
}

const CollisionFilter& Scene::filter(BodyId id) const {
  return impl_->live_body(id, "filter").filter;
}

namespace {
// The key of the pair {a, b} of two distinct live bodies, checked.
std::uint64_t checked_pair(const Scene& scene, BodyId a, BodyId b, const char* what) {
  for (const BodyId id : {a, b}) {
    if (!scene.contains(id)) {
      throw InvalidInput(std::string("Scene::") + what + ": " + name(id) +
                         " is not in the scene (never added, or removed)");
    }
  }
  if (a == b) {
    throw InvalidInput(std::string("Scene::") + what + ": a pair needs two bodies, got " + name(a) +
                       " twice");
  }
  return detail::pair_key(std::min(a, b), std::max(a, b));
}
}  // namespace

void Scene::exclude_pair(BodyId a, BodyId b) {
  const std::uint64_t key = checked_pair(*this, a, b, "exclude_pair");
  auto& excluded = impl_->excluded;
  const auto at = std::lower_bound(excluded.begin(), excluded.end(), key);
  if (at == excluded.end() || *at != key) excluded.insert(at, key);
}

void Scene::include_pair(BodyId a, BodyId b) {
  const std::uint64_t key = checked_pair(*this, a, b, "include_pair");
  auto& excluded = impl_->excluded;
  const auto at = std::lower_bound(excluded.begin(), excluded.end(), key);
  if (at != excluded.end() && *at == key) excluded.erase(at);
}

bool Scene::is_excluded(BodyId a, BodyId b) const {
  return impl_->excluded_key(checked_pair(*this, a, b, "is_excluded"));
}

bool Scene::tests_pair(BodyId a, BodyId b) const {
  const std::uint64_t key = checked_pair(*this, a, b, "tests_pair");
  return !impl_->excluded_key(key) &&
         impl_->groups_meet(impl_->bodies[slot(a)], impl_->bodies[slot(b)]);
}

bool Scene::contains(BodyId id) const {
  return id >= 0 && slot(id) < impl_->bodies.size() && impl_->bodies[slot(id)].live;
}

const Pose& Scene::pose(BodyId id) const { return impl_->live_body(id, "pose").pose; }

std::vector<BodyId> Scene::body_ids() const {
  std::vector<BodyId> ids;
  ids.reserve(static_cast<std::size_t>(impl_->live_count));
  for (std::size_t k = 0; k < impl_->bodies.size(); ++k) {
    if (impl_->bodies[k].live) ids.push_back(static_cast<BodyId>(k));
  }
  return ids;
}

int Scene::body_count() const { return impl_->live_count; }

const SceneOptions& Scene::options() const { return impl_->options; }

std::span<const ClosePair> Scene::step() {
  Impl& s = *impl_;
  const int threads = s.options.threads;
  s.boxes.resize(s.bodies.size());
  detail::parallel_chunks(s.bodies.size(), kBoxChunk, threads,
                          [&s](std::size_t, std::size_t begin, std::size_t end) {
                            for (std::size_t k = begin; k < end; ++k) {
                              if (s.bodies[k].live) s.boxes[k] = s.world_box(s.bodies[k]);
                            }
                          });
  s.finder->find_pairs(s.boxes, s.candidates, threads);
  const int filtered = s.filter_candidates(s.candidates);
  s.drop_removed(s.pairs, s.removed_since_step);
  const int warm = s.carry_caches(s.candidates, s.pairs, nullptr, threads);

  // The narrow phase and the close pairs in pair order. On one thread, the
  // close answers go straight to the output. On threads, in fixed chunks of
  // pairs: each chunk answers its pairs into their result slots and counts
  // its close ones, the offsets follow, and each chunk copies its close
  // answers to its place (the count rides on the answering pass, which has
  // the answers at hand, instead of a pass of its own over every slot).
  const std::size_t n = s.pairs.size();
  const double margin = s.options.margin;
  const std::size_t chunk = narrow_chunk(n);
  const std::size_t chunks = detail::chunk_count(n, chunk);
  int convex_queries = 0;
  if (threads == 1 || chunks < 2) {
    s.close.clear();
    for (std::size_t k = 0; k < n; ++k) {
      ClosePair& p = s.close.emplace_back();
      s.query_into(s.pairs[k], p);
      convex_queries += p.result.pairs_tested;
      if (!is_close(p.result, margin)) s.close.pop_back();
    }
  } else {
    s.results.resize(n);
    s.chunk_close.assign(chunks, 0);
    s.chunk_queries.assign(chunks, 0);
    detail::parallel_chunks(n, chunk, threads,
                            [&s, margin](std::size_t c, std::size_t begin, std::size_t end) {
                              std::size_t count = 0;
                              int queries = 0;
                              for (std::size_t k = begin; k < end; ++k) {
                                ClosePair& p = s.results[k];
                                s.query_into(s.pairs[k], p);
                                count += is_close(p.result, margin) ? 1 : 0;
                                queries += p.result.pairs_tested;
                              }
                              s.chunk_close[c] = count;
                              s.chunk_queries[c] = queries;
                            });
    std::size_t total = 0;
    for (std::size_t& c : s.chunk_close) total += std::exchange(c, total);
    s.close.resize(total);
    detail::parallel_chunks(n, chunk, threads,
                            [&s, margin](std::size_t c, std::size_t begin, std::size_t end) {
                              std::size_t at = s.chunk_close[c];
                              for (std::size_t k = begin; k < end; ++k) {
                                if (is_close(s.results[k].result, margin))
                                  s.close[at++] = s.results[k];
                              }
                            });
    for (const int q : s.chunk_queries) convex_queries += q;
  }
  s.stats.bodies = s.live_count;
  s.stats.candidate_pairs = static_cast<int>(n);
  s.stats.close_pairs = static_cast<int>(s.close.size());
  s.stats.convex_queries = convex_queries;
  s.stats.warm_pairs = warm;
  s.stats.filtered_pairs = filtered;
  return s.close;
}

const SceneStats& Scene::stats() const { return impl_->stats; }

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
  if (!(margin >= 0.0) || !std::isfinite(margin)) {
    throw InvalidInput("Scene::pairs_within: margin must be finite and >= 0, got " +
                       std::to_string(margin));
  }
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
