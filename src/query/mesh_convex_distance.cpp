// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the distance between a triangle mesh and a convex polytope
// (mesh.h): the mesh's hierarchy against the polytope's box, the convex
// query at the leaves on each near triangle, placed in one scratch triangle
// polytope (shape/triangle_polytope.h: no hull built per triangle).
//
// The mesh's hull (TriangleMesh::hull()) holds every triangle, so the
// hull-polytope distance L is a certified lower bound on the answer: the
// search stops at the first triangle within the accuracy standard of L (the
// mesh-mesh query's rule, mesh_pair.h), and the last closest triangle is
// tested first, so that a tracked query of a pair whose hull is apart from
// the polytope is one hull query and one triangle.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/accuracy.h"
#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"
#include "query/branch_and_bound.h"
#include "query/mesh_pair.h"
#include "shape/triangle_polytope.h"

namespace proxima {
namespace {

// The slack of a box gap before it prunes is detail::prune_slack of the
// query's magnitude (core/accuracy.h): the boxes are rounded outwards
// (float, stored) or formed from transformed vertices (a few u R each), and
// the convex query answers within 64 u R of the exact distance.

struct ConvexQuery {
  const TriangleMesh& a;
  const ConvexPolytope& b;
  Pose pose_a, pose_b;
  Mat3 rotation;  // B in A's frame
  Vec3 translation;
  Vec3 lo, hi;  // B's box in A's frame
  double magnitude = 0.0;
  double slack = 0.0;
  DistanceOptions options;
  // The triangle under test; rewritten by each test_triangle.
  detail::TrianglePolytope triangle;
  // Build every triangle's ConvexPolytope from its points instead (the
  // slow twin, distance_all_pairs).
  bool general_polytopes = false;
};

ConvexQuery make_query(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                       const Pose& pose_b, const DistanceOptions& options) {
  ConvexQuery q{a,
                b,
                checked_pose(pose_a, "mesh distance: pose_a"),
                checked_pose(pose_b, "mesh distance: pose_b"),
                {},
                {},
                {},
                {},
                0.0,
                0.0,
                options,
                {},
                false};
  detail::check_mesh_options(options, "mesh distance", detail::MeshOptionUse::convex_leaves);
  const Pose rel = q.pose_a.inverse() * q.pose_b;
  q.rotation = rel.rotation;
  q.translation = rel.translation;
  q.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  q.hi = -q.lo;
  for (const Vec3& v : b.vertices()) {
    const Vec3 p = rel.rotation * v + rel.translation;
    q.lo = q.lo.cwiseMin(p);
    q.hi = q.hi.cwiseMax(p);
  }
  q.magnitude =
      std::max({magnitude_bound(q.pose_a, a.scale()), magnitude_bound(q.pose_b, b.scale()),
                a.scale(), magnitude_bound(rel, b.scale())});
  q.slack = detail::prune_slack(q.magnitude);
  q.options.penetration = false;  // the status is all a leaf needs
  return q;
}

// Squared gap between an axis-aligned box and B's box, both in A's frame;
// the differences are formed in halves so that boxes near 1e300 of
// opposite signs do not overflow, then doubled after the square root.
double gap(const ConvexQuery& q, const Vec3& lo, const Vec3& hi) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max(0.5 * lo[k] - 0.5 * q.hi[k], 0.5 * q.lo[k] - 0.5 * hi[k]);
    if (g > 0.0) s += g * g;
  }
  return 2.0 * std::sqrt(s);
}

// The hull's bound: whether A's hull is apart from B, the certified lower
// bound L on the distance it gives, and the distance at which a triangle is
// the answer (L (1 + kHullStopRelative) + kHullStopUlps u R: no triangle is
// closer than L, and that one is within the accuracy standard of it).
struct HullStop {
  bool apart = false;
  double lower = 0.0;
  double stop = -1.0;  // -1: no stop (hull not apart, or not asked)
};

HullStop hull_stop(const ConvexQuery& q, MeshCache* cache) {
  // The convex query's range of placed magnitudes: beyond, the search
  // alone answers.
  if (!(q.magnitude <= kMaxMagnitude)) return {};
  DistanceCache local;
  const DistanceResult r = detail::distance_of_rigid_poses(
      q.a.hull(), q.pose_a, q.b, q.pose_b, q.options, cache != nullptr ? &cache->hull : &local);
  if (r.status != Status::separated || !(r.lower_bound > 0.0)) return {};
  HullStop h;
  h.apart = true;
  h.lower = r.lower_bound;
  h.stop = r.lower_bound * (1.0 + detail::mesh_pair::kHullStopRelative) +
           detail::mesh_pair::kHullStopUlps * kUnitRoundoff * q.magnitude;
  return h;
}

struct Best {
  DistanceResult result;
  std::int32_t triangle = -1;
  bool have = false;
};

// The convex query between triangle t and the polytope; lowers `best`. A
// proper triangle is the scratch polytope with its vertices rewritten; a
// degenerate one (a segment or a point), or every triangle of the slow
// twin, a ConvexPolytope built from its points.
void test_triangle(ConvexQuery& q, std::int32_t t, Best& best, int& tested) {
  const auto& tri = q.a.triangle(t);
  const std::array<Vec3, 3> v = {q.a.vertex(static_cast<int>(tri[0])),
                                 q.a.vertex(static_cast<int>(tri[1])),
                                 q.a.vertex(static_cast<int>(tri[2]))};
  ++tested;
  std::optional<ConvexPolytope> built;
  if (q.general_polytopes || !q.triangle.assign(v[0], v[1], v[2])) built.emplace(v);
  const ConvexPolytope& piece = built ? *built : q.triangle.polytope();
  DistanceResult r =
      detail::distance_of_rigid_poses(piece, q.pose_a, q.b, q.pose_b, q.options, nullptr);
  // Hull ids of the piece -> mesh vertex ids; the face is the triangle.
  const auto input = piece.input_index();
  for (auto& id : r.feature_a.vertices)
    if (id >= 0)
      id = static_cast<std::int32_t>(
          tri[static_cast<std::size_t>(input[static_cast<std::size_t>(id)])]);
  r.feature_a.face = r.feature_a.type == FeatureType::face ? t : -1;
  const bool better =
      !best.have ||
      (r.status == Status::intersecting && best.result.status != Status::intersecting) ||
      (best.result.status != Status::intersecting &&
       (r.distance < best.result.distance ||
        (r.distance == best.result.distance && t < best.triangle)));
  if (better) {
    best.result = r;
    best.triangle = t;
    best.have = true;
  }
}

// The answer from the best triangle; `hull` says whether A's hull is apart
// from B (then B holds no point inside A's closed mesh: the inside test is
// skipped) and, when the search stopped at its bound, the certified lower
// bound it gives.
MeshResult finish(const ConvexQuery& q, const Best& best, int tested, int nodes,
                  const HullStop& hull, bool stopped_at_hull) {
  MeshResult r;
  static_cast<DistanceResult&>(r) = best.result;
  r.triangle_a = best.triangle;
  r.triangle_b = -1;
  r.pairs_tested = tested;
  r.nodes_tested = nodes;
  // Stopped at the hull's bound, the best triangle's own lower bound does
  // not cover the triangles not tested; L does (every triangle lies in the
  // hull).
  if (stopped_at_hull) r.lower_bound = std::min(r.lower_bound, hull.lower);
  bool inside = false;
  if (r.status != Status::intersecting && q.a.is_closed() && !hull.apart)
    inside = q.a.contains(q.rotation * q.b.vertex(0) + q.translation);
  if (inside) {
    // The closest points of the surfaces are apart; B's vertex inside the
    // mesh is a point of both bodies.
    r.point_a = q.pose_b.apply(q.b.vertex(0));
    r.point_b = r.point_a;
  }
  if (r.status == Status::intersecting || inside) {
    r.status = Status::intersecting;
    r.distance = 0.0;
    r.lower_bound = 0.0;
    r.depth = 0.0;
    r.depth_lower_bound = 0.0;
    r.depth_upper_bound = std::numeric_limits<double>::infinity();
  }
  return r;
}

// The search of distance() as detail::branch_and_bound takes it: the
// mesh's nodes (one hierarchy against B's box, so an entry is one node and
// its box gap), depth first, the nearer child on top (a tie to the first),
// a node pruned when its gap is above the best distance plus the slack;
// at a leaf each triangle is pruned by its own box, then queried. It ends
// at an intersecting triangle, or at one within the hull's stop.
class MeshSearch {
 public:
  struct Entry {
    std::int32_t node;
    double lb;
  };

  MeshSearch(ConvexQuery& q, const HullStop& hull, Best& best, int& tested, int& nodes)
      : q_(q), hull_(hull), best_(best), tested_(tested), nodes_(nodes) {}

  bool stopped() const { return stopped_; }

  bool done() const { return best_.result.status == Status::intersecting || stopped_; }
  Entry root() const { return {0, 0.0}; }
  bool stale(const Entry& e) const { return e.lb > bound(); }
  bool prune(const Entry& e) const { return e.lb > bound(); }
  bool leaves(const Entry& e) const {
    return q_.a.nodes()[static_cast<std::size_t>(e.node)].is_leaf();
  }

  void test_leaves(const Entry& e) {
    const TriangleMesh& a = q_.a;
    const TriangleMesh::Node& n = a.nodes()[static_cast<std::size_t>(e.node)];
    const auto order = a.triangle_order();
    for (std::int32_t k = 0; k < n.count; ++k) {
      const std::int32_t t = order[static_cast<std::size_t>(n.first_or_right + k)];
      if (best_.have && t == best_.triangle) continue;
      const auto& tri = a.triangle(t);
      const Vec3& p0 = a.vertex(static_cast<int>(tri[0]));
      const Vec3& p1 = a.vertex(static_cast<int>(tri[1]));
      const Vec3& p2 = a.vertex(static_cast<int>(tri[2]));
      if (gap(q_, p0.cwiseMin(p1).cwiseMin(p2), p0.cwiseMax(p1).cwiseMax(p2)) > bound()) continue;
      test_triangle(q_, t, best_, tested_);
      if (best_.result.status == Status::intersecting) break;
      if (best_.have && best_.result.distance <= hull_.stop) {
        stopped_ = true;
        break;
      }
    }
  }

  std::pair<Entry, Entry> split(const Entry& e) {
    const TriangleMesh::Node& n = q_.a.nodes()[static_cast<std::size_t>(e.node)];
    const std::int32_t children[2] = {e.node + 1, n.first_or_right};
    double lbs[2];
    for (int c = 0; c < 2; ++c) {
      Vec3 lo, hi;
      q_.a.box(children[c], lo, hi);
      lbs[c] = gap(q_, lo, hi);
    }
    nodes_ += 2;
    const int near = lbs[0] <= lbs[1] ? 0 : 1;
    return {{children[near], lbs[near]}, {children[1 - near], lbs[1 - near]}};
  }

 private:
  double bound() const {
    return best_.have ? best_.result.distance + q_.slack : std::numeric_limits<double>::infinity();
  }

  ConvexQuery& q_;
  const HullStop& hull_;
  Best& best_;
  int& tested_;
  int& nodes_;
  bool stopped_ = false;
};

}  // namespace

MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                              const Pose& pose_b, const DistanceOptions& options) {
  ConvexQuery q = make_query(a, pose_a, b, pose_b, options);
  q.general_polytopes = true;
  Best best;
  int tested = 0;
  for (std::int32_t t = 0; t < a.triangle_count(); ++t) {
    test_triangle(q, t, best, tested);
    if (best.result.status == Status::intersecting) break;
  }
  return finish(q, best, tested, 0, HullStop{}, false);
}

MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                    const Pose& pose_b, const DistanceOptions& options, MeshCache* cache) {
  ConvexQuery q = make_query(a, pose_a, b, pose_b, options);
  Best best;
  int tested = 0, nodes = 0;
  // Every query asks the hull, tracked or not: unlike the mesh-mesh query
  // (whose triangle pairs cost tens of nanoseconds), a triangle here is a
  // convex query on a polytope built for it, many times a tracked hull
  // query, so skipping the hull (MeshCache::hull_wait) saves less than one
  // triangle and loses the bound whenever the hull has come apart since.
  const HullStop hull = hull_stop(q, cache);
  const auto reached_hull = [&] { return best.have && best.result.distance <= hull.stop; };
  const auto answer = [&](bool stopped_at_hull) {
    if (cache != nullptr) {
      cache->triangle_a = best.triangle;
      cache->triangle_b = -1;
    }
    return finish(q, best, tested, nodes, hull, stopped_at_hull);
  };
  if (cache != nullptr && cache->triangle_a >= 0 && cache->triangle_a < a.triangle_count()) {
    test_triangle(q, cache->triangle_a, best, tested);
    if (reached_hull()) return answer(true);
  }
  MeshSearch search(q, hull, best, tested, nodes);
  std::vector<MeshSearch::Entry> stack;
  stack.reserve(64);
  detail::DepthFirst<MeshSearch::Entry> frontier(stack);
  detail::branch_and_bound(search, frontier);
  const bool stopped = search.stopped();
  return answer(stopped);
}

}  // namespace proxima
