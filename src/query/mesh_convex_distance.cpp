// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// query layer: the distance between a triangle mesh and a convex polytope
// (mesh.h): the mesh's hierarchy against the polytope's box, the convex
// query at the leaves on each near triangle as a polytope of its vertices.
#include <algorithm>
#include <cmath>
#include <limits>

#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"

namespace proxima {
namespace {

// Slack of a box gap before it prunes, in units of u R: the boxes are
// rounded outwards (float, stored) or formed from transformed vertices (a
// few u R each), and the convex query answers within 64 u R of the exact
// distance; a pruned triangle must be farther than the best in exact
// arithmetic too.
constexpr double kPruneSlackUlps = 128.0;

struct ConvexQuery {
  const TriangleMesh& a;
  const ConvexPolytope& b;
  Pose pose_a, pose_b;
  Mat3 rotation;  // B in A's frame
  Vec3 translation;
  Vec3 lo, hi;  // B's box in A's frame
  double slack = 0.0;
  DistanceOptions options;
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
                options};
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
  const double magnitude =
      std::max({magnitude_bound(q.pose_a, a.scale()), magnitude_bound(q.pose_b, b.scale()),
                a.scale(), magnitude_bound(rel, b.scale())});
  q.slack = kPruneSlackUlps * kUnitRoundoff * magnitude;
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

struct Best {
  DistanceResult result;
  std::int32_t triangle = -1;
  bool have = false;
};

// The convex query between triangle t and the polytope; lowers `best`.
void test_triangle(const ConvexQuery& q, std::int32_t t, Best& best, int& tested) {
  const auto& tri = q.a.triangle(t);
  const std::array<Vec3, 3> v = {q.a.vertex(static_cast<int>(tri[0])),
                                 q.a.vertex(static_cast<int>(tri[1])),
                                 q.a.vertex(static_cast<int>(tri[2]))};
  ++tested;
  const ConvexPolytope piece(v);
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

MeshResult finish(const ConvexQuery& q, const Best& best, int tested, int nodes) {
  MeshResult r;
  static_cast<DistanceResult&>(r) = best.result;
  r.triangle_a = best.triangle;
  r.triangle_b = -1;
  r.pairs_tested = tested;
  r.nodes_tested = nodes;
  bool inside = false;
  if (r.status != Status::intersecting && q.a.is_closed())
    inside = q.a.contains(q.rotation * q.b.vertex(0) + q.translation);
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

}  // namespace

MeshResult distance_all_pairs(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                              const Pose& pose_b, const DistanceOptions& options) {
  const ConvexQuery q = make_query(a, pose_a, b, pose_b, options);
  Best best;
  int tested = 0;
  for (std::int32_t t = 0; t < a.triangle_count(); ++t) {
    test_triangle(q, t, best, tested);
    if (best.result.status == Status::intersecting) break;
  }
  return finish(q, best, tested, 0);
}

MeshResult distance(const TriangleMesh& a, const Pose& pose_a, const ConvexPolytope& b,
                    const Pose& pose_b, const DistanceOptions& options, MeshCache* cache) {
  const ConvexQuery q = make_query(a, pose_a, b, pose_b, options);
  Best best;
  int tested = 0, nodes = 0;
  if (cache != nullptr && cache->triangle_a >= 0 && cache->triangle_a < a.triangle_count())
    test_triangle(q, cache->triangle_a, best, tested);
  const auto bound = [&] {
    return best.have ? best.result.distance + q.slack : std::numeric_limits<double>::infinity();
  };
  std::vector<std::pair<std::int32_t, double>> stack;
  stack.reserve(64);
  stack.emplace_back(0, 0.0);
  const auto nodes_a = a.nodes();
  const auto order = a.triangle_order();
  while (!stack.empty() && best.result.status != Status::intersecting) {
    const auto [id, lb] = stack.back();
    stack.pop_back();
    if (lb > bound()) continue;
    const TriangleMesh::Node& n = nodes_a[static_cast<std::size_t>(id)];
    if (n.is_leaf()) {
      for (std::int32_t k = 0; k < n.count; ++k) {
        const std::int32_t t = order[static_cast<std::size_t>(n.first_or_right + k)];
        if (best.have && t == best.triangle) continue;
        const auto& tri = a.triangle(t);
        const Vec3& p0 = a.vertex(static_cast<int>(tri[0]));
        const Vec3& p1 = a.vertex(static_cast<int>(tri[1]));
        const Vec3& p2 = a.vertex(static_cast<int>(tri[2]));
        if (gap(q, p0.cwiseMin(p1).cwiseMin(p2), p0.cwiseMax(p1).cwiseMax(p2)) > bound()) continue;
        test_triangle(q, t, best, tested);
        if (best.result.status == Status::intersecting) break;
      }
      continue;
    }
    const std::int32_t children[2] = {id + 1, n.first_or_right};
    double lbs[2];
    for (int c = 0; c < 2; ++c) {
      Vec3 lo, hi;
      a.box(children[c], lo, hi);
      lbs[c] = gap(q, lo, hi);
    }
    nodes += 2;
    const int near = lbs[0] <= lbs[1] ? 0 : 1;
    if (lbs[1 - near] <= bound()) stack.emplace_back(children[1 - near], lbs[1 - near]);
    if (lbs[near] <= bound()) stack.emplace_back(children[near], lbs[near]);
  }
  MeshResult r = finish(q, best, tested, nodes);
  if (cache != nullptr) {
    cache->triangle_a = best.triangle;
    cache->triangle_b = -1;
  }
  return r;
}

}  // namespace proxima
