// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Compound bodies: validation and the bounding-sphere hierarchy (built once,
// top-down). The branch and bound over it is in src/query/compound_distance.cpp.
//
// Spheres, not boxes: a sphere is rotation-invariant, so a node's bound in the
// query frame is one transformed center and the same radius, whatever the
// body's pose; a box in the body's frame would have to be re-fitted (or
// tested as an oriented box) for every pose. bench/compound_bench.cpp
// compares the two (BM_Cold against BM_ColdBoxes, the same cold branch and
// bound on boxes re-fitted by |R| h): spheres test fewer pairs and win from
// about 50 pieces a body; at 10 the two are within noise.
#include "proxima/shape/compound.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_set>
#include <utility>

#include "core/power_of_two.h"

namespace proxima {
namespace {

// Pieces per leaf. A leaf of k pieces tests the spheres of its pairs one by
// one, so larger leaves trade node visits for sphere tests. In
// bench/compound_bench.cpp (BM_Cold, BM_Tracked) leaves of 2 and 4 pieces
// tracked no faster than leaves of 1 and tested more pairs cold, so one
// piece a leaf.
constexpr int kLeafSize = 1;

// Inflation of every stored sphere so that containment holds in floating
// point (the tests check it with plain doubles): the radius is a maximum of
// rounded norms of rounded differences, each within a few u of the exact
// value relative to the radius plus a few u of the coordinates' magnitude.
constexpr double kSphereInflationUlps = 8.0;

using detail::magnitude_exponent;
using detail::times_pow2;

// |p - q| with no intermediate overflow or underflow of the squares: the
// difference of the halves is formed (no overflow even for opposite
// coordinates near the largest double) and normed on a power-of-two scaled
// copy. Build time only.
double safe_distance(const Vec3& p, const Vec3& q) {
  const Vec3 h = 0.5 * p - 0.5 * q;
  const int e = magnitude_exponent(h.cwiseAbs().maxCoeff());
  return std::ldexp(times_pow2(h, -e).norm(), e + 1);
}

bool all_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

std::string piece_prefix(std::size_t i) {
  return "CompoundBody: piece " + std::to_string(i) + ": ";
}

// The smallest sphere holding two spheres (the classic merge: on the line
// through both centers, from the far side of one to the far side of the
// other), or the larger one if it holds the other.
Vec3 merged_center(const Vec3& c1, double r1, const Vec3& c2, double r2) {
  const double d = safe_distance(c1, c2);
  if (d + r2 <= r1) return c1;
  if (d + r1 <= r2) return c2;
  // Here d > 0 (else one radius would hold the other). The direction is
  // formed from halves: no overflow for centers of opposite signs.
  const double r = 0.5 * (d + r1 + r2);
  const double t = (r - r1) / d;
  return c1 + (2.0 * t) * (0.5 * c2 - 0.5 * c1);
}

}  // namespace

CompoundBody::CompoundBody(std::vector<CompoundPiece> pieces) : pieces_(std::move(pieces)) {
  if (pieces_.empty()) throw InvalidInput("CompoundBody: no pieces");
  if (pieces_.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() / 2)) {
    throw InvalidInput("CompoundBody: too many pieces (" + std::to_string(pieces_.size()) + ")");
  }
  const std::size_t n = pieces_.size();
  piece_spheres_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const CompoundPiece& piece = pieces_[i];
    if (!piece.polytope) throw InvalidInput(piece_prefix(i) + "null polytope");
    pieces_[i].pose = checked_pose(piece.pose, [&] { return piece_prefix(i) + "pose"; });

    // The piece's sphere and its share of the scale from its placed
    // vertices themselves: exact R, and a radius that holds every vertex
    // as the body's frame sees it.
    const Vec3 center = piece.pose.apply(piece.polytope->centroid());
    double radius = 0.0;
    double magnitude = center.cwiseAbs().maxCoeff();
    for (const Vec3& v : piece.polytope->vertices()) {
      const Vec3 placed = piece.pose.apply(v);
      if (!all_finite(placed))
        throw InvalidInput(piece_prefix(i) + "placed vertex overflows (coordinates not finite)");
      scale_ = std::max(scale_, placed.cwiseAbs().maxCoeff());
      magnitude = std::max(magnitude, placed.cwiseAbs().maxCoeff());
      radius = std::max(radius, safe_distance(placed, center));
    }
    radius = radius * (1.0 + kSphereInflationUlps * kUnitRoundoff) +
             kSphereInflationUlps * kUnitRoundoff * magnitude +
             4.0 * std::numeric_limits<double>::denorm_min();
    if (!all_finite(center) || !std::isfinite(radius)) {
      throw InvalidInput(piece_prefix(i) +
                         "bounding sphere overflows (coordinates near the largest double)");
    }
    piece_spheres_[i] = {center, radius};
  }

  piece_order_.resize(n);
  for (std::size_t i = 0; i < n; ++i) piece_order_[i] = static_cast<std::int32_t>(i);
  nodes_.reserve(2 * n);
  build_node(0, static_cast<std::int32_t>(n));
}

// Top-down: a node over piece_order_[first, last) splits its pieces at the
// median of their sphere centers along the longest axis of the centers' box.
// The median keeps the tree balanced (depth log2 n) whatever the layout.
std::int32_t CompoundBody::build_node(std::int32_t first, std::int32_t last) {
  const auto id = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  const auto begin = piece_order_.begin() + first;
  const auto end = piece_order_.begin() + last;
  std::int32_t left = -1;
  std::int32_t right = -1;
  if (last - first > kLeafSize) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    for (auto it = begin; it != end; ++it) {
      lo = lo.cwiseMin(piece_spheres_[static_cast<std::size_t>(*it)].center);
      hi = hi.cwiseMax(piece_spheres_[static_cast<std::size_t>(*it)].center);
    }
    int axis = 0;
    const Vec3 extent = 0.5 * hi - 0.5 * lo;  // halves: no overflow
    extent.maxCoeff(&axis);
    const std::int32_t middle = first + (last - first) / 2;
    // Ties by piece index: the same tree on every platform.
    std::nth_element(begin, piece_order_.begin() + middle, end,
                     [&](std::int32_t p, std::int32_t q) {
                       const double cp = piece_spheres_[static_cast<std::size_t>(p)].center[axis];
                       const double cq = piece_spheres_[static_cast<std::size_t>(q)].center[axis];
                       return cp < cq || (cp == cq && p < q);
                     });
    left = build_node(first, middle);
    right = build_node(middle, last);
  }

  // The node's sphere: of two candidate centers (the merge of the children's
  // spheres, and the center of the box around the pieces' spheres), the one
  // whose enclosing radius over the pieces below is smaller. The radius is
  // taken over the pieces' own spheres, not the children's, so it is never
  // looser than the merge and often tighter.
  std::array<Vec3, 2> candidates;
  int candidate_count = 0;
  if (left >= 0) {
    const Node& l = nodes_[static_cast<std::size_t>(left)];
    const Node& r = nodes_[static_cast<std::size_t>(right)];
    candidates[static_cast<std::size_t>(candidate_count++)] =
        merged_center(l.center, l.radius, r.center, r.radius);
  }
  {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    for (auto it = begin; it != end; ++it) {
      const PieceSphere& s = piece_spheres_[static_cast<std::size_t>(*it)];
      lo = lo.cwiseMin(s.center - Vec3::Constant(s.radius));
      hi = hi.cwiseMax(s.center + Vec3::Constant(s.radius));
    }
    candidates[static_cast<std::size_t>(candidate_count++)] = 0.5 * lo + 0.5 * hi;
  }
  double best_radius = std::numeric_limits<double>::infinity();
  Vec3 best_center = Vec3::Zero();
  for (int c = 0; c < candidate_count; ++c) {
    const Vec3& center = candidates[static_cast<std::size_t>(c)];
    double radius = 0.0;
    double magnitude = center.cwiseAbs().maxCoeff();
    for (auto it = begin; it != end; ++it) {
      const PieceSphere& s = piece_spheres_[static_cast<std::size_t>(*it)];
      radius = std::max(radius, safe_distance(s.center, center) + s.radius);
      magnitude = std::max(magnitude, s.center.cwiseAbs().maxCoeff());
    }
    radius = radius * (1.0 + kSphereInflationUlps * kUnitRoundoff) +
             kSphereInflationUlps * kUnitRoundoff * magnitude +
             4.0 * std::numeric_limits<double>::denorm_min();
    if (radius < best_radius) {
      best_radius = radius;
      best_center = center;
    }
  }
  if (!all_finite(best_center) || !std::isfinite(best_radius)) {
    throw InvalidInput(
        "CompoundBody: the pieces' bounding sphere overflows (pieces near the largest double)");
  }
  Node& node = nodes_[static_cast<std::size_t>(id)];
  node.center = best_center;
  node.radius = best_radius;
  node.left = left;
  node.right = right;
  node.first = left >= 0 ? 0 : first;
  node.count = left >= 0 ? 0 : last - first;
  return id;
}

CompoundBody CompoundBody::from_point_sets(std::span<const std::vector<Vec3>> point_sets) {
  std::vector<CompoundPiece> pieces;
  pieces.reserve(point_sets.size());
  for (std::size_t i = 0; i < point_sets.size(); ++i) {
    try {
      pieces.push_back({std::make_shared<const ConvexPolytope>(point_sets[i]), Pose::identity()});
    } catch (const InvalidInput& e) {
      throw InvalidInput(piece_prefix(i) + e.what());
    }
  }
  return CompoundBody(std::move(pieces));
}

std::size_t CompoundBody::memory_bytes() const {
  std::size_t bytes = sizeof(*this) + pieces_.capacity() * sizeof(CompoundPiece) +
                      nodes_.capacity() * sizeof(Node) +
                      piece_order_.capacity() * sizeof(std::int32_t) +
                      piece_spheres_.capacity() * sizeof(PieceSphere);
  // A polytope shared by several pieces (instances of one part) is counted once.
  std::unordered_set<const ConvexPolytope*> seen;
  for (const CompoundPiece& p : pieces_) {
    if (seen.insert(p.polytope.get()).second) bytes += p.polytope->memory_bytes();
  }
  return bytes;
}

}  // namespace proxima
