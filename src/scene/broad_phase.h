// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Private to src/ (the scene's broad phase), also used by its own test and
// benchmark. A pair finder keeps a set of body ids and, given one box per id,
// lists every pair of ids whose closed boxes overlap. Two finders give the
// same set by construction (the final test is the same closed-box overlap on
// the same boxes); they differ only in how they avoid testing all n^2 pairs:
//
// - sweep and prune: the boxes sorted by their lower end on one axis; a box
//   can only overlap those that start before it ends. Between steps the order
//   barely changes, so an insertion sort restores it in near linear time.
// - dynamic AABB tree: fattened leaf boxes in a balanced tree; a leaf moves in
//   the tree only when its box leaves its fat box, and only moved leaves query
//   the tree. The pairs of fat boxes that overlap are kept from step to step,
//   then filtered by the boxes themselves.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/scene/scene.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

struct Aabb {
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
};

// Closed boxes: touching faces count as overlap, so that bodies in contact
// (distance 0, margin 0) reach the narrow phase.
inline bool overlaps(const Aabb& a, const Aabb& b) {
  return a.lo.x() <= b.hi.x() && b.lo.x() <= a.hi.x() && a.lo.y() <= b.hi.y() &&
         b.lo.y() <= a.hi.y() && a.lo.z() <= b.hi.z() && b.lo.z() <= a.hi.z();
}

// A pair of ids a < b as one sortable key: (a, b) order is key order.
inline std::uint64_t pair_key(std::int32_t a, std::int32_t b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}
inline std::int32_t pair_first(std::uint64_t key) { return static_cast<std::int32_t>(key >> 32); }
inline std::int32_t pair_second(std::uint64_t key) {
  return static_cast<std::int32_t>(key & 0xffffffffULL);
}

class PairFinder {
 public:
  virtual ~PairFinder() = default;
  // Ids are >= 0. An id removed may be added again (a new body).
  virtual void add(std::int32_t id) = 0;
  virtual void remove(std::int32_t id) = 0;
  // boxes[id] is the current box of every id in the set (boxes of other ids
  // are ignored). Replaces `pairs` by the keys of every pair of ids in the
  // set whose boxes overlap, increasing. `threads` as SceneOptions::threads
  // (1: the calling thread only); the pairs are the same whatever it is.
  virtual void find_pairs(std::span<const Aabb> boxes, std::vector<std::uint64_t>& pairs,
                          int threads = 1) = 0;
};

std::unique_ptr<PairFinder> make_pair_finder(BroadPhase kind);

// World boxes of a convex body at `pose`, two ways (the scene uses one; the
// benchmark measures both):
// - sphere_box: the box of the bounding sphere (centroid placed, radius),
//   O(1) but loose: up to sqrt(3) times the exact extent for a cube seen
//   along its diagonal;
// - support_box: the exact box of the placed hull, from the support vertex in
//   +-x, +-y, +-z of the world (directions rotated into the body's frame),
//   found by hill climbing from the six hints of the last step, which it
//   updates.
// Neither adds any slack: the caller inflates for rounding and margin.
Aabb sphere_box(const ConvexPolytope& body, const Pose& pose);

// What support_box keeps of a body from one call to the next, per world
// direction (+x, -x, +y, -y, +z, -z): the support vertex found (the next
// climb's hint), the body-frame direction of the climb that found it, and
// how far a direction may be from that one (Euclidean) with the vertex
// still the climb's answer (no neighbour's dot product can exceed its own,
// rounding included; -1: no such certificate). A default BoxHints is cold.
struct BoxHints {
  std::array<std::int32_t, 6> vertex = {-1, -1, -1, -1, -1, -1};
  std::array<Vec3, 6> direction = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(),
                                   Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  std::array<double, 6> allowance = {-1.0, -1.0, -1.0, -1.0, -1.0, -1.0};
};

// The same box as hill climbing from hints.vertex (support_hill_climb in
// each direction: the same vertices, the same box to the bit), but a
// direction within its certificate's allowance of the last climb's skips
// the climb: the vertex is its answer. The rotations of a coherent scene
// (0.01 rad per step in scene_bench) keep most directions inside for many
// steps.
Aabb support_box(const ConvexPolytope& body, const Pose& pose, BoxHints& hints);

}  // namespace proxima::detail
