// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the margin query between two triangle meshes
// (proxima/query/margin.h): the hulls first, then a depth-first search
// over node pairs that stops at the first triangle pair within the margin.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "proxima/query/margin.h"
#include "query/branch_and_bound.h"
#include "query/mesh_pair.h"

namespace proxima {
namespace {

using namespace detail::mesh_pair;

// The margin query between two meshes (proxima/query/margin.h), in the scaled
// frame of the distance query: depth first over node pairs, the nearer
// child on top, a node pair pruned when its box bound exceeds the margin by
// the bound's rounding slack, and the first triangle pair within margin +
// band (test_pair's filters and kernel, limited there) ends the search.
class MarginSearch {
 public:
  MarginSearch(const Query& q, double margin) : q_(q), margin_(margin) {
    margin_s_ = margin * q.factor;  // exact scaling (make_query_of_rigid_poses)
    yes_s_ = margin_s_ + q.band_s;
    slack_s_ = detail::prune_slack(q.magnitude * q.factor);
    prune_s_ = margin_s_ + slack_s_;
    lower_s_ = std::numeric_limits<double>::infinity();
  }

  // Whether triangle pair (ta, tb) is within; tested pairs lower the bound.
  bool test(const Triangles& ta, const Triangles& tb) {
    // Marked crossing: test_pair then skips its crossing test (exact
    // predicates on every pair within the band) and its ranking, which only
    // the distance query needs; here any pair within margin + band is a
    // witness, crossing or not.
    Best witness_only;
    witness_only.crossing = true;
    const double d2 = test_pair(q_, ta, tb, witness_only, tested_, yes_s_);
    if (d2 <= yes_s_ * yes_s_) {
      witness_a_ = ta.id;
      witness_b_ = tb.id;
      return true;
    }
    // Skipped by the filters or the kernel's limit: farther than yes_s_ up
    // to their rounding (a few u, below half the band); tested: the
    // kernel's distance less its error.
    lower_s_ = std::min(lower_s_, std::isfinite(d2) ? std::sqrt(d2) - kLowerBoundUlps * kUnitRoundoff
                                                    : yes_s_ - 0.5 * q_.band_s);
    return false;
  }

  // Whether the root boxes' bound (A's and B's axes) proves every pair
  // beyond the margin; it lowers the bound as a pruned node pair does. The
  // first test of the hierarchies, before the hulls' query, which costs
  // many times more on the poses of a planner's random samples.
  bool roots_apart() {
    const double prune2 = prune_s_ * prune_s_;
    const Box ba = node_box(q_.a.nodes()[0], q_.box_unit_a);
    const Box bb = node_box(q_.b.nodes()[0], q_.box_unit_b);
    const double lb2 = lower_bound_on_a_axes(q_, ba, bb, q_.rotation * bb.center + q_.translation_s,
                                             q_.abs_rotation * bb.half, prune2);
    if (!(lb2 > prune2)) return false;
    lower_s_ = std::min(lower_s_, std::sqrt(lb2) - slack_s_);
    return true;
  }

  bool traverse() {
    found_ = false;
    detail::DepthFirst<NodePair> frontier(stack_);
    detail::branch_and_bound(*this, frontier);
    return found_;
  }

  // A pair of nodes and its squared box bound (scaled).
  struct NodePair {
    std::int32_t ia, ib;
    double lb2;
  };

  // The search as detail::branch_and_bound takes it (branch_and_bound.h):
  // the margin does not move, so a pair is pruned (and its bound lowers
  // the reported one) when first met, never again when taken out.
  bool done() const { return found_; }
  NodePair root() const { return {0, 0, 0.0}; }
  bool stale(const NodePair&) const { return false; }
  bool prune(const NodePair& e) {
    const double prune2 = prune_s_ * prune_s_;
    if (!(e.lb2 > prune2)) return false;
    lower_s_ = std::min(lower_s_, std::sqrt(e.lb2) - slack_s_);
    return true;
  }
  bool leaves(const NodePair& e) const {
    return q_.a.nodes()[static_cast<std::size_t>(e.ia)].is_leaf() &&
           q_.b.nodes()[static_cast<std::size_t>(e.ib)].is_leaf();
  }

  void test_leaves(const NodePair& e) {
    const TriangleMesh::Node& na = q_.a.nodes()[static_cast<std::size_t>(e.ia)];
    const TriangleMesh::Node& nb = q_.b.nodes()[static_cast<std::size_t>(e.ib)];
    const auto order_a = q_.a.triangle_order();
    const auto order_b = q_.b.triangle_order();
    for (std::int32_t i = 0; i < na.count; ++i)
      leaf_a_[static_cast<std::size_t>(i)] =
          a_triangle(q_, order_a[static_cast<std::size_t>(na.first_or_right + i)]);
    for (std::int32_t j = 0; j < nb.count; ++j)
      leaf_b_[static_cast<std::size_t>(j)] =
          b_triangle(q_, order_b[static_cast<std::size_t>(nb.first_or_right + j)]);
    for (std::int32_t i = 0; i < na.count; ++i) {
      for (std::int32_t j = 0; j < nb.count; ++j) {
        if (test(leaf_a_[static_cast<std::size_t>(i)], leaf_b_[static_cast<std::size_t>(j)])) {
          found_ = true;
          return;
        }
      }
    }
  }

  // The children of the larger box (by the sum of half extents; an inner
  // node against a leaf: the inner one), the nearer first (a tie to the
  // first child).
  std::pair<NodePair, NodePair> split(const NodePair& e) {
    const auto nodes_a = q_.a.nodes();
    const auto nodes_b = q_.b.nodes();
    const double prune2 = prune_s_ * prune_s_;
    const TriangleMesh::Node& na = nodes_a[static_cast<std::size_t>(e.ia)];
    const TriangleMesh::Node& nb = nodes_b[static_cast<std::size_t>(e.ib)];
    const Box ba = node_box(na, q_.box_unit_a);
    const Box bb = node_box(nb, q_.box_unit_b);
    const bool split_a = !na.is_leaf() && (nb.is_leaf() || ba.half.sum() >= bb.half.sum());
    std::array<NodePair, 2> child = {NodePair{e.ia, e.ib, 0.0}, NodePair{e.ia, e.ib, 0.0}};
    if (split_a) {
      const Vec3 cb = q_.rotation * bb.center + q_.translation_s;
      const Vec3 extent_b = q_.abs_rotation * bb.half;
      child[0].ia = e.ia + 1;
      child[1].ia = na.first_or_right;
      for (NodePair& c : child) {
        const Box box = node_box(nodes_a[static_cast<std::size_t>(c.ia)], q_.box_unit_a);
        c.lb2 = lower_bound_on_a_axes(q_, box, bb, cb, extent_b, prune2);
      }
    } else {
      const Vec3 ca = q_.rotation.transpose() * (ba.center - q_.translation_s);
      const Vec3 extent_a = q_.abs_rotation.transpose() * ba.half;
      child[0].ib = e.ib + 1;
      child[1].ib = nb.first_or_right;
      for (NodePair& c : child) {
        const Box box = node_box(nodes_b[static_cast<std::size_t>(c.ib)], q_.box_unit_b);
        c.lb2 = lower_bound_on_b_axes(q_, ba, box, ca, extent_a, prune2);
      }
    }
    nodes_tested_ += 2;
    const int near = child[0].lb2 <= child[1].lb2 ? 0 : 1;
    return {child[static_cast<std::size_t>(near)], child[static_cast<std::size_t>(1 - near)]};
  }

  double margin() const { return margin_; }
  double lower_scaled() const { return lower_s_; }
  int tested() const { return tested_; }
  int nodes_tested() const { return nodes_tested_; }
  std::int32_t witness_a() const { return witness_a_; }
  std::int32_t witness_b() const { return witness_b_; }

 private:
  const Query& q_;
  double margin_;
  double margin_s_ = 0.0, yes_s_ = 0.0, prune_s_ = 0.0, lower_s_ = 0.0, slack_s_ = 0.0;
  int tested_ = 0;
  int nodes_tested_ = 0;
  std::int32_t witness_a_ = -1, witness_b_ = -1;
  bool found_ = false;
  std::array<Triangles, TriangleMesh::kLeafSize> leaf_a_, leaf_b_;
  std::vector<NodePair> stack_;
};

}  // namespace

MarginResult within_margin(const TriangleMesh& a, const Pose& pose_a, const TriangleMesh& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options,
                           MeshCache* cache) {
  detail::check_finite_non_negative(margin, "within_margin", "margin");
  detail::check_mesh_options(options, "within_margin", detail::MeshOptionUse::triangle_pairs);
  return detail::within_margin_of_rigid_poses(a, checked_pose(pose_a, "within_margin: pose_a"), b,
                                              checked_pose(pose_b, "within_margin: pose_b"),
                                              margin, options, cache);
}

namespace detail {

MarginResult within_margin_of_rigid_poses(const TriangleMesh& a, const Pose& pa,
                                          const TriangleMesh& b, const Pose& pb, double margin,
                                          const DistanceOptions& options, MeshCache* cache) {
  MarginResult r;
  r.margin = margin;
  // Far apart: the root boxes' balls prove it without the hierarchies.
  const double gap = detail::sphere_gap_lower_bound(pa.apply(a.center()), a.bounding_radius(),
                                                    pb.apply(b.center()), b.bounding_radius());
  if (gap > margin) {
    r.lower_bound = gap;
    return r;
  }
  if (cache != nullptr && (cache->mesh_a != a.id() || cache->mesh_b != b.id())) {
    cache->reset();
    cache->mesh_a = a.id();
    cache->mesh_b = b.id();
  }
  Query q = make_query_of_rigid_poses(a, pa, b, pb, options);
  MarginSearch search(q, margin);
  const double unit = detail::pow2(q.exponent);  // scaled -> unscaled, exact
  if (search.roots_apart()) {
    r.lower_bound = std::max(0.0, search.lower_scaled() * unit);
    if (r.lower_bound > margin) return r;
  }
  // The last witness pair first, before the hulls: a pair within on the
  // last query is often still within (a planner's next step), and then
  // its one triangle pair answers without the hulls' query.
  bool found = cache != nullptr && cache->triangle_a >= 0 &&
               cache->triangle_a < a.triangle_count() && cache->triangle_b >= 0 &&
               cache->triangle_b < b.triangle_count() &&
               search.test(a_triangle(q, cache->triangle_a), b_triangle(q, cache->triangle_b));
  // The hulls hold the surfaces: hulls beyond the margin prove the meshes
  // beyond it; otherwise the hulls' closest points aim the slab bound of
  // the traversal. Only within the convex query's range of placed
  // magnitudes (as hull_bound).
  double hull_lower = 0.0;
  if (!found) {
    Vec3 hull_direction = Vec3::Zero();  // world frame
    if (std::max(magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale())) <=
        kMaxMagnitude) {
      DistanceCache local;
      const MarginResult hull = detail::within_margin_of_rigid_poses(
          a.hull(), pa, b.hull(), pb, margin, options, cache != nullptr ? cache->hull : local);
      if (hull.status == MarginStatus::beyond) {
        r.lower_bound = hull.lower_bound;
        r.pairs_tested = search.tested();
        return r;
      }
      hull_lower = hull.lower_bound;
      if (hull.upper_bound > 0.0) hull_direction = hull.point_b - hull.point_a;
    }
    if (hull_direction != Vec3::Zero()) q.set_slab(q.pose_a.rotation.transpose() * hull_direction);
    found = search.traverse();
  }
  r.pairs_tested = search.tested();
  if (found) {
    // The witness pair as the fast kernel that accepted it finds it (any
    // pair within margin + band proves the verdict; the slow twin's
    // features are not needed).
    const Triangles ta = a_triangle(q, search.witness_a());
    const Triangles tb = b_triangle(q, search.witness_b());
    const detail::Candidate<true> points = detail::triangle_closest_points(ta.fast, tb.fast, q.tol);
    r.status = MarginStatus::within;
    r.point_a = pa.apply(times_pow2(Vec3(points.on_a.x, points.on_a.y, points.on_a.z), q.exponent));
    r.point_b = pa.apply(times_pow2(Vec3(points.on_b.x, points.on_b.y, points.on_b.z), q.exponent));
    r.upper_bound = (r.point_b - r.point_a).norm();
    r.triangle_a = search.witness_a();
    r.triangle_b = search.witness_b();
    r.lower_bound = 0.0;
    if (cache != nullptr) {
      cache->triangle_a = r.triangle_a;
      cache->triangle_b = r.triangle_b;
    }
    return r;
  }
  // No pair within: within any margin still when a surface lies inside the
  // other, closed mesh (a point of both).
  Vec3 inside;
  if (contained_point(q, inside)) {
    r.status = MarginStatus::within;
    r.point_a = pa.apply(inside);
    r.point_b = r.point_a;
    r.upper_bound = 0.0;
    r.lower_bound = 0.0;
    return r;
  }
  r.lower_bound = std::max({0.0, search.lower_scaled() * unit, hull_lower});
  r.status = r.lower_bound > margin ? MarginStatus::beyond : MarginStatus::undecided;
  return r;
}

}  // namespace detail

}  // namespace proxima
