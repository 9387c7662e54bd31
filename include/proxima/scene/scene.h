// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// scene layer: a scene of many moving bodies. The caller moves the bodies (their
// poses) each step and asks for the close pairs: every pair of bodies whose
// distance is at most the scene's margin, with the distance, the closest
// points, the witness features and (for compound bodies) the pieces.
//
// Each step runs a broad phase (bounding boxes within the margin of each
// other) and then the tracked distance query on each candidate pair; each
// pair's cache is kept across steps while the pair stays a candidate, so that
// a scene of slowly moving bodies costs about one tracked query per close
// pair.
//
//   proxima::SceneOptions options;
//   options.margin = 0.05;
//   proxima::Scene scene(options);
//   auto id = scene.add(std::make_shared<proxima::ConvexPolytope>(points), pose);
//   for each step:
//     scene.set_pose(id, new_pose);  // for every body that moved
//     for (const proxima::ClosePair& p : scene.step()) ... p.a, p.b, p.result.distance
//
// Thread safety: a Scene is one object of mutable state; use it from one
// thread at a time. step() may spread the narrow phase over a TBB pool
// (options.threads). The bodies' polytopes and compounds are shared,
// immutable, and may also be used elsewhere at the same time.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/motion/time_of_impact.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/margin.h"
#include "proxima/shape/polytope.h"

namespace proxima {

using BodyId = std::int32_t;

enum class BroadPhase : std::uint8_t {
  sweep_and_prune,    // sorted interval lists, kept sorted by insertion sort between steps
  dynamic_aabb_tree,  // fattened boxes in a balanced tree, re-inserted when they leave their fat
                      // box
};

inline const char* to_string(BroadPhase b) {
  switch (b) {
    case BroadPhase::sweep_and_prune:
      return "sweep_and_prune";
    case BroadPhase::dynamic_aabb_tree:
      return "dynamic_aabb_tree";
  }
  return "unknown";
}

struct SceneOptions {
  // Pairs at distance <= margin are reported (touching and intersecting
  // pairs included). Must be finite and >= 0.
  double margin = 0.0;
  // The narrow phase's options. Unlike a single query, a scene skips the
  // penetration depth by default (distance.penetration false): its
  // overlapping pairs then report status intersecting with distance 0 and
  // no depth (signed distance 0, bounds [-inf, 0]). With
  // distance.penetration true every overlapping pair gets its depth, but
  // the depth's tracking re-enumerates A - B whenever a body turns, so each
  // overlapping pair costs many times a tracked distance, every step
  // (bench/distance_bench TrackingOverlap), and a scene's step, where most
  // close pairs overlap, many times as long (bench/scene_bench).
  DistanceOptions distance = [] {
    DistanceOptions o;
    o.penetration = false;
    return o;
  }();
  // The tree by default: it is faster than sweep and prune (one sorted
  // axis) at 1,000 and 10,000 bodies (bench/broad_phase_bench).
  BroadPhase broad_phase = BroadPhase::dynamic_aabb_tree;
  // Narrow-phase threads: 1 runs in the caller's thread, 0 in the caller's
  // TBB arena, n > 1 in a dedicated arena, kept per calling thread (as
  // distance_batch).
  int threads = 1;
};

// Which pairs a scene tests, per body (Box2D's category and mask bits, Bullet's
// collision groups): bodies a and b are a candidate pair only when
//   (a.group & b.mask) != 0  and  (b.group & a.mask) != 0
// and the pair is not excluded (Scene::exclude_pair). The default puts every
// body in group 1 and tests it against every group: all pairs are tested.
struct CollisionFilter {
  std::uint32_t group = 1;           // the groups this body belongs to, as bits
  std::uint32_t mask = 0xffffffffu;  // the groups it is tested against, as bits
};

// One close pair: a < b, and the answer of the distance query between them
// (for two convex bodies piece_a == piece_b == 0 and pairs_tested == 1),
// with its signed distance (negative for an overlap: minus the depth, as
// distance() and the compound query define it) when
// SceneOptions::distance.penetration is set (not by default).
//
// A pair with a rounded or padded body or a mesh (Scene::add of a Body) is
// answered by distance(Body, Body) (proxima/query/body_distance.h) on the padded bodies:
// `result` is that BodyResult's DistanceResult part (distance, signed
// distance and bounds, points on the padded surfaces, normal, features),
// piece_a/piece_b its pieces (0 for a convex body, -1 for a mesh),
// pairs_tested 1, and triangle_a/triangle_b its closest triangles of mesh
// bodies (-1 for other kinds and for every other pair). Overlapping convex
// or compound cores get their depth when SceneOptions::distance.penetration
// is set (signed distance minus the depth minus the radii; as costly per
// such pair and step as for plain pairs, SceneOptions::distance); without
// it (the default), and
// for an overlap with a mesh, the cores' signed value is 0 with bounds
// [-inf, 0] (signed distance minus the radii).
struct ClosePair {
  BodyId a = -1;
  BodyId b = -1;
  CompoundResult result;
  std::int32_t triangle_a = -1;
  std::int32_t triangle_b = -1;
};

// One pair within the scene's margin as the margin query answers it
// (Scene::step_within, Scene::first_within): a < b and the MarginResult of
// within_margin (proxima/query/margin.h) on the two bodies (padded bodies as
// for step()) with the scene's margin: a witness pair at most margin + band
// apart, the pieces of compounds and triangles of meshes where it lies (-1
// for other kinds), no distance. Its status is within, or undecided for a
// pair that neither proof settled at the iteration cap (both bounds
// reported: a caller who needs a proof of "no collision" must treat it as
// within).
struct MarginPair {
  BodyId a = -1;
  BodyId b = -1;
  MarginResult result;
};

// One pair of a sweep (Scene::sweep): a < b, and the time of impact of
// body a moving from its pose to its end pose against body b doing the
// same, as time_of_impact gives it for the two bodies alone.
struct ImpactPair {
  BodyId a = -1;
  BodyId b = -1;
  ImpactResult result;
};

// What the last sweep did.
struct SweepStats {
  int bodies = 0;
  int moving_bodies = 0;     // bodies whose end pose differs from their pose, or given velocities
  int candidate_pairs = 0;   // pairs whose swept boxes overlap, after the filters
  int impact_pairs = 0;      // of those, not separated over the motion (reported)
  int distance_queries = 0;  // advancement steps of all candidate pairs
  int warm_pairs = 0;        // candidates that started from a cache (last sweep's or step's)
  int filtered_pairs = 0;    // pairs whose swept boxes overlap but that the filters dropped
};

// What the last step did.
struct SceneStats {
  int bodies = 0;
  int candidate_pairs = 0;  // pairs the broad phase passed to the narrow phase
  int close_pairs = 0;      // of those, at distance <= margin
  int convex_queries = 0;   // convex distance queries run (compounds run several per pair; a
                            // pair through the Body query counts one)
  int warm_pairs = 0;       // candidate pairs that started from the previous step's cache
  int filtered_pairs = 0;   // pairs whose boxes overlap but that the filters dropped
};

class Scene {
 public:
  // Throws InvalidInput for a negative or non-finite margin or threads < 0.
  explicit Scene(const SceneOptions& options = {});
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // Adds a body at `pose` and returns its id (ids of removed bodies may be
  // reused). Throws InvalidInput for a null body or a non-finite pose.
  BodyId add(std::shared_ptr<const ConvexPolytope> body, const Pose& pose);
  BodyId add(std::shared_ptr<const CompoundBody> body, const Pose& pose);
  // Any body of proxima/query/body_distance.h: convex, compound or TriangleMesh, with its
  // radius, plus a `padding` >= 0 of the scene's own (a robot planner's
  // safety distance): the scene treats the body as body.with_radius(
  // body.radius() + padding) everywhere, in the broad phase (its box holds
  // the padded body) and in the narrow phase, so a padding p changes which
  // pairs are reported exactly as a radius larger by p would, and every
  // distance, signed distance and closest point reported is the padded
  // bodies'. A plain convex or compound body (radius and padding 0) is the
  // same as the two calls above (their fast paths); a pair where either
  // body is rounded, padded or a mesh is answered by distance(Body, Body)
  // with a BodyCache kept per pair (see ClosePair). Throws InvalidInput for
  // a padding that is negative, NaN or infinite, or a non-finite pose.
  BodyId add(const Body& body, const Pose& pose, double padding = 0.0);
  // Changes a body's padding (same rules; the pair caches stay valid: the
  // padding is outside the cores). Throws InvalidInput naming the id.
  void set_padding(BodyId id, double padding);
  double padding(BodyId id) const;
  // The body as added (its radius without the padding).
  const Body& body(BodyId id) const;
  // Throws InvalidInput naming the id for an unknown id or a non-finite pose.
  void set_pose(BodyId id, const Pose& pose);
  void remove(BodyId id);

  // Pair filters, applied in the broad phase before any narrow-phase work
  // (a dropped pair costs no distance query and keeps no cache). Throw
  // InvalidInput naming the id for an unknown id.
  void set_filter(BodyId id, const CollisionFilter& filter);
  const CollisionFilter& filter(BodyId id) const;
  // Never test the pair (a, b), e.g. a robot's adjacent links, which overlap
  // by construction. Both bodies must be in the scene and differ. Undone by
  // include_pair, or by the removal of either body.
  void exclude_pair(BodyId a, BodyId b);
  void include_pair(BodyId a, BodyId b);
  bool is_excluded(BodyId a, BodyId b) const;
  // Whether step() tests the pair: the filters and exclusions above.
  bool tests_pair(BodyId a, BodyId b) const;

  bool contains(BodyId id) const;
  const Pose& pose(BodyId id) const;
  // Every live body id, increasing.
  std::vector<BodyId> body_ids() const;
  int body_count() const;
  const SceneOptions& options() const;

  // Broad phase and tracked narrow phase on the current poses. The close
  // pairs, sorted by (a, b); valid until the next call of a non-const method.
  std::span<const ClosePair> step();
  const SceneStats& stats() const;

  // step()'s question without its answers, for a planner that asks only
  // "which pairs are within the margin?": the same broad phase, filters
  // and pair caches as step(), then the margin query (within_margin) on
  // each candidate pair, which stops at the first proof (a witness pair
  // within the margin, or a certified lower bound above it) instead of
  // converging to the distance. The pairs within the margin (and the
  // undecided ones, see MarginPair), sorted by (a, b); valid until the
  // next call of a non-const method. step(), step_within() and
  // first_within() share the pair caches: each keeps them warm for the
  // others. The same pairs as step() except those within the contact band
  // (64 u R) of the margin, which either may report; bit-identical
  // answers whatever options.threads. stats() describes it as a step
  // (close_pairs: the pairs reported).
  std::span<const MarginPair> step_within();
  // The collision check of the whole scene: stops at the first pair found
  // within the margin (or undecided) and returns it; nullopt when every
  // pair the filters let through is proved beyond the margin. The pair
  // found by the last call is asked first when it is still a candidate (a
  // planner's colliding pair tends to stay colliding), then the candidates
  // in (a, b) order, in the calling thread (options.threads is not used:
  // the search ends at its first proof). Candidates after the one found
  // are not queried and keep their caches as they were. stats():
  // close_pairs is 1 or 0, convex_queries the work done.
  std::optional<MarginPair> first_within();

  // Continuous collision (issue 13): each body moves over t in [0, 1] from
  // its pose to its end pose with the motion of proxima/motion/time_of_impact.h
  // (constant linear velocity of its frame's origin, constant angular
  // velocity about it: the rate set_velocity gave, through any angle, or
  // else the shorter way round to the end pose), and sweep() reports the
  // first time of contact of every pair that meets on the way, even pairs
  // that are apart at both ends (a thin or fast body passing through
  // another between two steps).
  //
  // A body's end pose is its pose (no motion) until set_end_pose gives
  // another; set_pose (and add) make it the new pose again, so that a
  // simulator that moves every body to where the sweep let it go starts
  // the next step with no stale motion. Throws InvalidInput naming the id
  // for an unknown id or a non-finite pose.
  void set_end_pose(BodyId id, const Pose& end);
  const Pose& end_pose(BodyId id) const;
  // The motion by velocities instead (Motion::from_velocity over t in
  // [0, 1]): the end pose becomes where `linear` (units per unit t) and
  // `angular` (world frame, radians per unit t) take the body, and the
  // sweep turns it at that rate through any angle, several turns included
  // (an end pose alone cannot say how many). set_end_pose, set_pose and add
  // forget it. Throws InvalidInput naming the id for an unknown id or
  // velocities Motion::from_velocity refuses.
  void set_velocity(BodyId id, const Vec3& linear, const Vec3& angular);
  // The angular velocity set_velocity gave, if it is still in force.
  std::optional<Vec3> angular_velocity(BodyId id) const;

  // Sweeps every body from its pose to its end pose: a broad phase on boxes
  // that hold each body's whole swept volume (the boxes of the body at both
  // ends, the same shifted by the other end's translation, grown by how far
  // the turn takes any point of the body off its chord), so that no pair
  // that comes within options.target_separation + tolerance of each other
  // is missed; the scene's filters; then time_of_impact (convex pairs: the
  // convex query, pairs with a compound: the Body query) on each candidate
  // pair with `options`, starting from the pair's cache of the last sweep,
  // or else of the last step, and keeping it for the next sweep. Returns
  // the pairs whose status is not separated (contact, overlapping at t = 0,
  // iteration_cap), sorted by (a, b); valid until the next call of a
  // non-const method. Poses are not changed. The same answers bit for bit
  // whatever options.threads (the scene's). Throws InvalidInput for bad
  // options (as time_of_impact). Rounded and padded bodies sweep as their
  // padded bodies (the Body query; the padding adds to the target
  // separation as a radius does). A mesh's swept box is its root box's
  // bounding sphere swept like a compound's.
  std::span<const ImpactPair> sweep(const ImpactOptions& options);
  // The same with ImpactOptions{} but the scene's distance options
  // (options().distance): by default no penetration depth for pairs that
  // overlap at t = 0 (as step(); with it, each such pair costs a depth
  // query, SceneOptions::distance).
  std::span<const ImpactPair> sweep();
  const SweepStats& sweep_stats() const;

  // The slow, obvious twin of sweep(): the cold time_of_impact on every pair
  // of bodies that tests_pair, no broad phase, no caches; the pairs not
  // separated, same order. (With options.max_iterations so small that pairs
  // far apart stop at the cap, the twin reports them and sweep() does not:
  // its broad phase certified them separated.) For tests.
  std::vector<ImpactPair> impact_pairs_all_pairs(const ImpactOptions& options) const;
  std::vector<ImpactPair> impact_pairs_all_pairs() const;  // as sweep()

  // Queries a planner asks besides step(), on the current poses, with the
  // caches the scene keeps (a pair that was a candidate of the last step
  // starts from its cache and updates it; other pairs are answered cold):
  // - nearest_pair: the pair of smallest distance over every pair the
  //   filters let through, however far apart (an intersecting pair first
  //   among pairs at distance 0); nullopt with fewer than two bodies or no
  //   tested pair.
  // - pairs_within: every body within `margin` of body `id` (touching and
  //   intersecting included), as pairs (min id, max id), by increasing
  //   other id. Throws InvalidInput for an unknown id or a bad margin.
  std::optional<ClosePair> nearest_pair();
  std::vector<ClosePair> pairs_within(BodyId id, double margin);

  // The slow, obvious twin of step() (and of step_within() and
  // first_within(), whose pairs are those of its answers within the
  // margin, up to the contact band): the cold distance query on every pair
  // of bodies that tests_pair (distance(Body, Body) on the padded bodies
  // for a pair with a general body, as step()), no broad phase, no caches;
  // same output order. For tests.
  std::vector<ClosePair> close_pairs_all_pairs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace proxima
