// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 6: non-convex bodies as unions of convex pieces (the paper's
// section 2), and the distance between two such bodies.
//
// A CompoundBody holds convex pieces, each a ConvexPolytope placed by its own
// local pose in the body's frame, under a bounding-volume hierarchy built
// once. distance() over two compounds is the minimum of the convex query over
// piece pairs, found by branch and bound: the hierarchy's lower bounds prune
// every node pair that cannot beat the best pair found so far.
//
//   proxima::CompoundBody chair = proxima::CompoundBody::from_point_sets(sets);
//   proxima::CompoundCache cache;                      // cold; keep it per pair
//   for each step:
//     auto r = proxima::distance(chair, pose_a, table, pose_b, {}, &cache);
//     r.distance, r.piece_a, r.piece_b, r.point_a, ...
//
// Thread safety: a CompoundBody is immutable after construction and may be
// shared between threads (its pieces are shared, immutable polytopes). A
// CompoundCache belongs to one pair of bodies at a time, like DistanceCache.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "proxima/polytope.h"
#include "proxima/types.h"

namespace proxima {

// One convex piece: a shared, immutable hull and where it sits in the body.
struct CompoundPiece {
  std::shared_ptr<const ConvexPolytope> polytope;
  Pose pose;  // piece frame -> body frame
};

class CompoundBody {
 public:
  // A node of the bounding-volume hierarchy, in the body's frame. A leaf
  // holds a run of pieces, piece_order()[first .. first + count); an inner
  // node has count == 0 and two children.
  struct Node {
    Vec3 center = Vec3::Zero();  // bounding sphere of every piece below
    double radius = 0.0;
    std::int32_t left = -1;  // child node ids, -1 for a leaf
    std::int32_t right = -1;
    std::int32_t first = 0;  // leaf: first index into piece_order()
    std::int32_t count = 0;  // leaf: number of pieces
  };

  // Throws InvalidInput naming the piece index: no pieces, a null polytope,
  // a non-finite pose, a pose whose rotation is not orthonormal (to 1e-12)
  // or is a reflection, or placed vertices that overflow.
  explicit CompoundBody(std::vector<CompoundPiece> pieces);

  // One piece per point set, each hulled (identity piece poses). Throws
  // InvalidInput naming the piece and the point (from ConvexPolytope).
  static CompoundBody from_point_sets(std::span<const std::vector<Vec3>> point_sets);

  int piece_count() const { return static_cast<int>(pieces_.size()); }
  const CompoundPiece& piece(int i) const { return pieces_[static_cast<std::size_t>(i)]; }
  std::span<const CompoundPiece> pieces() const { return pieces_; }

  // The hierarchy: nodes()[0] is the root.
  std::span<const Node> nodes() const { return nodes_; }
  std::span<const std::int32_t> piece_order() const { return piece_order_; }

  // Bounding sphere of piece i in the body's frame: center at the placed
  // centroid, radius holding every placed vertex (inflated by a few u so that
  // containment holds in floating point).
  struct PieceSphere {
    Vec3 center = Vec3::Zero();
    double radius = 0.0;
  };
  const PieceSphere& piece_sphere(int i) const {
    return piece_spheres_[static_cast<std::size_t>(i)];
  }

  // Bounding sphere of the whole body, in its frame (the root's).
  const Vec3& center() const { return nodes_.front().center; }
  double bounding_radius() const { return nodes_.front().radius; }

  // Largest scale() of a placed piece: the R of the accuracy standard for
  // the body in its own frame.
  double scale() const { return scale_; }

  // Bytes held (pieces' polytopes counted once each).
  std::size_t memory_bytes() const;

 private:
  std::int32_t build_node(std::int32_t first, std::int32_t last);

  std::vector<CompoundPiece> pieces_;
  std::vector<PieceSphere> piece_spheres_;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> piece_order_;
  double scale_ = 0.0;
};

// Coherence between compound queries of one pair, owned by the caller.
// Default-constructed means cold. It keeps the best piece pair of the last
// answer (tried first: its distance is the first upper bound of the branch and
// bound) and the feature cache of each near piece pair, so that a tracked
// query of a compound costs about one tracked convex query per near pair. A
// cache from another pair of bodies is range-checked: at worst slower, never
// wrong.
struct CompoundCache {
  struct Entry {
    std::int32_t piece_a = -1;
    std::int32_t piece_b = -1;
    DistanceCache cache;
  };
  std::int32_t piece_a = -1;  // best pair of the last answer
  std::int32_t piece_b = -1;
  std::vector<Entry> near;  // sorted by (piece_a, piece_b); bounded in size
  bool is_cold() const { return piece_a < 0 && near.empty(); }
  void reset() { *this = CompoundCache{}; }
};

// The convex result of the closest piece pair (points and normal in world
// frame, features in the pieces' hull ids), plus which pieces and how much
// work the branch and bound did.
struct CompoundResult : DistanceResult {
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
  int pairs_tested = 0;  // convex queries run
};

// Minimum distance between two compound bodies. Status is the convex
// status of the reported pair. The distance is the twin's within the
// accuracy standard, R being the largest coordinate of both bodies' placed
// vertices; which pair is reported may differ from the twin's when two
// pairs are that close. Throws InvalidInput for non-finite poses or bad
// options.
//
// Signed distance: the minimum over piece pairs of the convex signed
// distance (the piecewise definition FCL and Coal use for unions). When
// pieces overlap it is minus the depth of the deepest overlapping piece
// pair, reported with that pair's deepest points, normal, features and
// certificate (which brackets that pair's signed distance). It is NOT the
// penetration depth of the two unions: moving B by that pair's depth along
// its normal separates that pair but may leave other pieces overlapping
// (the union's depth is at least every pair's depth). With the depth
// (DistanceOptions::penetration, the default) the search goes on after the
// first overlapping pair, pruning node pairs whose sphere bound (a lower
// bound on the signed distance as well) cannot beat the deepest pair found;
// without it, it stops at the first overlapping pair as a status query
// should.
CompoundResult distance(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                        const Pose& pose_b, const DistanceOptions& options = {},
                        CompoundCache* cache = nullptr);

// The slow, obvious twin: the convex query on every piece pair, cold, and the
// minimum of the signed distance (ties broken by an intersecting pair first,
// then by the smaller (piece_a, piece_b)). For tests and benchmarks.
CompoundResult distance_all_pairs(const CompoundBody& a, const Pose& pose_a, const CompoundBody& b,
                                  const Pose& pose_b, const DistanceOptions& options = {});

}  // namespace proxima
