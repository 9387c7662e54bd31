// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: non-convex bodies as unions of convex pieces (the paper's
// section 2); their distance is in proxima/query/compound_distance.h.
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

#include "proxima/core/types.h"
#include "proxima/shape/polytope.h"

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

}  // namespace proxima
