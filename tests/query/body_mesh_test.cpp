// Tests of mesh bodies through the one call for any two bodies (body.h):
// a TriangleMesh against a convex, rounded, compound or mesh Body. The
// referees: a convex body's answer against the same convex body given as a
// closed mesh (the convex query, exact at the standard), and the brute force
// over every triangle pair of the mesh query (distance_all_pairs, tested
// against exact rationals in mesh_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "proxima/query/batch.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/query/signed_distance.h"
#include "proxima/shape/primitives.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::Rng;

// An axis-aligned box [-h, h]^3 as 12 triangles, counter-clockwise seen
// from outside (closed), or without its +z face (open: 10 triangles).
TriangleMesh box_mesh(double h, bool closed = true) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  std::vector<TriangleMesh::Triangle> t = {
      {0, 2, 1}, {1, 2, 3},  // -z
      {0, 1, 4}, {1, 5, 4},  // -y
      {0, 4, 2}, {2, 4, 6},  // -x
      {1, 3, 5}, {3, 7, 5},  // +x
      {2, 6, 3}, {3, 6, 7},  // +y
  };
  if (closed) {
    t.push_back({4, 5, 6});  // +z
    t.push_back({5, 7, 6});
  }
  return TriangleMesh(v, t);
}

// An L-shaped (non-convex) closed prism: the L in the xy plane, z in [0, 1].
TriangleMesh l_mesh() {
  const std::vector<Vec3> outline = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0},
                                     {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  std::vector<Vec3> v = outline;
  for (const Vec3& p : outline) v.push_back(p + Vec3(0, 0, 1));
  std::vector<TriangleMesh::Triangle> t = {
      // bottom (seen from below: clockwise in xy), as two quads and a triangle
      {0, 2, 1},
      {0, 3, 2},
      {0, 5, 3},
      {3, 5, 4},
      // top
      {6, 7, 8},
      {6, 8, 9},
      {6, 9, 11},
      {9, 10, 11}};
  for (std::uint32_t i = 0; i < 6; ++i) {  // sides
    const std::uint32_t j = (i + 1) % 6;
    t.push_back({i, j, j + 6});
    t.push_back({i, j + 6, i + 6});
  }
  return TriangleMesh(v, t);
}

Pose random_pose(Rng& rng, double spread) {
  return {test::random_quaternion(rng),
          test::drawn([&] { return test::uniform(rng, -spread, spread); })};
}

TEST(BodyMesh, TheTestMeshesAreWhatTheySay) {
  EXPECT_TRUE(box_mesh(1.0).is_closed());
  EXPECT_FALSE(box_mesh(1.0, false).is_closed());
  EXPECT_TRUE(l_mesh().is_closed());
}

// A convex body against a mesh equals the same convex body against the mesh
// of a convex polytope given as a polytope: the convex query is the
// referee. Random separated and overlapping poses, convex and rounded.
TEST(BodyMesh, MeshOfAConvexShapeAgreesWithTheConvexQuery) {
  Rng rng(1125);
  const Body box_as_mesh(box_mesh(0.5));
  const Body box_as_polytope = make_box(Vec3(0.5, 0.5, 0.5));
  int apart = 0;
  for (int k = 0; k < 200; ++k) {
    const ConvexPolytope other(test::points_on_sphere(rng, 30));
    const double radius = k % 3 == 0 ? 0.1 : 0.0;
    const Body b(std::make_shared<const ConvexPolytope>(other), radius);
    const Pose pa = random_pose(rng, 0.5);
    const Pose pb = random_pose(rng, 2.0);
    const BodyResult want = distance(box_as_polytope, pa, b, pb);
    const BodyResult got = distance(box_as_mesh, pa, b, pb);
    if (want.intersecting) {
      // The mesh answer has no depth: intersecting, signed <= -radius.
      EXPECT_EQ(got.status, Status::intersecting) << k;
      EXPECT_TRUE(got.intersecting) << k;
      EXPECT_LE(got.signed_upper_bound(), -radius) << k;
      EXPECT_EQ(got.signed_lower_bound(), -std::numeric_limits<double>::infinity()) << k;
      continue;
    }
    ++apart;
    EXPECT_NEAR(got.signed_distance(), want.signed_distance(), 1e-12 * 4) << k;
    EXPECT_EQ(got.status, want.status) << k;
    EXPECT_LE(got.signed_lower_bound(), want.signed_distance() + 1e-12) << k;
    EXPECT_NEAR((got.point_b - got.point_a).norm(), std::abs(got.signed_distance()), 1e-12) << k;
    EXPECT_GE(got.triangle_a, 0) << k;
    EXPECT_EQ(got.triangle_b, -1) << k;
  }
  EXPECT_GT(apart, 50);  // premise: many separated poses
}

// A convex body inside a closed mesh overlaps it (no surfaces cross); inside
// the same mesh opened (one face removed) it is separated from the surface
// by the distance to the nearest wall. And a closed mesh inside a convex
// body: the hull's mesh is closed too.
TEST(BodyMesh, InsideAClosedMeshIsIntersectingInsideAnOpenOneIsNot) {
  const Body room(box_mesh(2.0));
  const Body open_room(box_mesh(2.0, false));
  const Body ball = make_sphere(0.5);
  const Pose at(Mat3::Identity(), Vec3(0.3, -0.2, 0.1));
  const BodyResult closed = distance(room, Pose::identity(), ball, at);
  EXPECT_EQ(closed.status, Status::intersecting);
  EXPECT_LT(closed.signed_distance(), 0.0);
  const BodyResult open = distance(open_room, Pose::identity(), ball, at);
  EXPECT_EQ(open.status, Status::separated);
  // The nearest wall of the open room: x = 2 (1.7 away) or y = -2 (1.8) ...
  // the ball's center at x = 0.3: 2 - 0.3 - 0.5 = 1.2 to x = 2; 1.3 to
  // y = -2; 2.1 - 0.5 = 1.6 to z = -2. The open top (z = 2) is not there.
  EXPECT_NEAR(open.signed_distance(), 1.2, 1e-12);
  // A small closed mesh inside a big convex box.
  const Body small(box_mesh(0.1));
  const Body big = make_box(Vec3(3, 3, 3));
  EXPECT_EQ(distance(small, at, big, Pose::identity()).status, Status::intersecting);
  EXPECT_EQ(distance(big, Pose::identity(), small, at).status, Status::intersecting);
}

// Regression (issue 25, exact_cases.jsonl line 4): a mesh inside a convex
// solid (no surfaces crossing) was `intersecting` with distance 0 but with
// the surfaces' closest points, 0.056 apart on that case: points that
// realize no answer of distance 0. They are now one common point, the
// contained vertex, through every path: the Body call (a convex body as its
// hull's closed mesh), the mesh-mesh and mesh-polytope queries, both
// orders, cold and tracked.
TEST(BodyMesh, AMeshInsideASolidAnswersWithACommonPoint) {
  const double h_small = 0.1;
  const double h_big = 3.0;
  const auto inside_box = [](const Vec3& p, double h) {
    return (p.cwiseAbs().array() <= h * (1 + 1e-12)).all();
  };
  const Pose at(Mat3::Identity(), Vec3(0.3, -0.2, 0.1));
  const double band = 64 * kUnitRoundoff * 4.0;
  const auto check = [&](const DistanceResult& r, const Pose& small_pose, const Pose& big_pose) {
    EXPECT_EQ(r.status, Status::intersecting);
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_LE((r.point_a - r.point_b).norm(), band);
    // On the small box (its surface) and inside the big one, in the world.
    EXPECT_TRUE(inside_box(small_pose.inverse().apply(r.point_a), h_small)) << r.point_a.transpose();
    EXPECT_TRUE(inside_box(big_pose.inverse().apply(r.point_a), h_big)) << r.point_a.transpose();
  };
  const Body small(box_mesh(h_small));
  const Body big_convex = make_box(Vec3(h_big, h_big, h_big));
  {
    SCOPED_TRACE("Body: mesh first");
    check(distance(small, at, big_convex, Pose::identity()), at, Pose::identity());
  }
  {
    SCOPED_TRACE("Body: convex first");
    check(distance(big_convex, Pose::identity(), small, at), at, Pose::identity());
  }
  const TriangleMesh small_mesh = box_mesh(h_small);
  const TriangleMesh big_mesh = box_mesh(h_big);
  const ConvexPolytope small_hull(std::vector<Vec3>(small_mesh.vertices().begin(),
                                                    small_mesh.vertices().end()));
  {
    SCOPED_TRACE("mesh-mesh, inner first");
    check(distance(small_mesh, at, big_mesh, Pose::identity()), at, Pose::identity());
  }
  {
    SCOPED_TRACE("mesh-mesh, outer first");
    check(distance(big_mesh, Pose::identity(), small_mesh, at), at, Pose::identity());
  }
  {
    SCOPED_TRACE("mesh-polytope, the polytope inside the closed mesh");
    check(distance(big_mesh, Pose::identity(), small_hull, at), at, Pose::identity());
  }
  {
    SCOPED_TRACE("mesh-mesh, tracked");
    MeshCache cache;
    for (int step = 0; step < 6; ++step) {
      const Pose moved(Mat3::Identity(), at.translation + Vec3(1e-3 * step, 0, 0));
      const MeshResult r = distance(small_mesh, moved, big_mesh, Pose::identity(), {}, &cache);
      check(r, moved, Pose::identity());
    }
  }
}

// A non-convex mesh: a sphere in the notch of the L is nearer to the L than
// to its hull; the answer equals the brute force over all triangle pairs
// (the mesh twin) against the sphere's center as a one-point mesh, minus
// the radius.
TEST(BodyMesh, NonConvexMeshAgainstARoundedPointEqualsTheTwin) {
  const auto l = std::make_shared<const TriangleMesh>(l_mesh());
  const Body body(l);
  const Body ball = make_sphere(0.2);
  const std::vector<Vec3> center = {Vec3::Zero()};
  const std::vector<TriangleMesh::Triangle> one = {{0, 0, 0}};
  const TriangleMesh point(center, one);
  Rng rng(7);
  for (int k = 0; k < 100; ++k) {
    const Pose pb(Mat3::Identity(), test::drawn([&] { return test::uniform(rng, 1.2, 3); },
                                                [&] { return test::uniform(rng, 1.2, 3); },
                                                [&] { return test::uniform(rng, -0.5, 1.5); }));
    const BodyResult got = distance(body, Pose::identity(), ball, pb);
    const MeshResult twin = distance_all_pairs(*l, Pose::identity(), point, pb);
    if (twin.status == Status::intersecting) continue;
    EXPECT_NEAR(got.signed_distance(), twin.distance - 0.2, 1e-12) << k;
    // A closest triangle: the twin's, or one at its distance (the point
    // is often closest to a vertex or an edge that several triangles share,
    // and the search stops at the first that reaches the hulls' bound).
    ASSERT_GE(got.triangle_a, 0) << k;
    const auto& tri = l->triangle(got.triangle_a);
    const std::vector<TriangleMesh::Triangle> just = {tri};
    const TriangleMesh alone(l->vertices(), std::span<const TriangleMesh::Triangle>(just));
    EXPECT_NEAR(distance_all_pairs(alone, Pose::identity(), point, pb).distance, twin.distance,
                1e-12)
        << k;
  }
  // In the notch, at (1.5, 1.5, 0.5): 0.5 from the L (its inner corner
  // edge at x = 1 or y = 1), while the hull contains the point.
  const BodyResult notch =
      distance(body, Pose::identity(), ball, Pose(Mat3::Identity(), Vec3(1.5, 1.5, 0.5)));
  EXPECT_EQ(notch.status, Status::separated);
  EXPECT_NEAR(notch.signed_distance(), 0.5 - 0.2, 1e-12);
}

// A compound against a mesh: the smallest over its pieces, with the piece
// and the hull face of the answer.
TEST(BodyMesh, CompoundAgainstAMeshIsTheNearestPiece) {
  Rng rng(9);
  std::vector<CompoundPiece> pieces;
  for (int i = 0; i < 4; ++i) {
    pieces.push_back({std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 12)),
                      Pose(Mat3::Identity(), Vec3(3.0 * i, 0, 0))});
  }
  const CompoundBody compound(pieces);
  const Body body(compound);
  const Body mesh(box_mesh(0.5));
  for (int k = 0; k < 50; ++k) {
    const Pose pm = random_pose(rng, 6.0);
    const BodyResult got = distance(body, Pose::identity(), mesh, pm);
    double nearest = std::numeric_limits<double>::infinity();
    int piece = -1;
    bool overlap = false;
    for (int i = 0; i < 4; ++i) {
      const Body one(pieces[static_cast<std::size_t>(i)].polytope);
      const BodyResult r = distance(one, pieces[static_cast<std::size_t>(i)].pose, mesh, pm);
      overlap = overlap || r.status == Status::intersecting;
      if (r.distance < nearest) {
        nearest = r.distance;
        piece = i;
      }
    }
    if (overlap) {
      EXPECT_EQ(got.status, Status::intersecting) << k;
      continue;
    }
    EXPECT_NEAR(got.distance, nearest, 1e-12 * 16) << k;
    EXPECT_EQ(got.piece_a, piece) << k;
    if (got.feature_a.type == FeatureType::face) {
      EXPECT_GE(got.feature_a.face, 0) << k;
      EXPECT_LT(got.feature_a.face, pieces[static_cast<std::size_t>(piece)].polytope->face_count())
          << k;
    }
  }
}

// Tracking through the BodyCache along a motion equals the cold query; a
// batch of mesh pairs equals the loop.
TEST(BodyMesh, TrackedEqualsColdAndBatchEqualsLoop) {
  const Body l(l_mesh(), 0.05);
  const Body room(box_mesh(0.4));
  const Body capsule = make_capsule(0.3, 0.1);
  BodyCache cache;
  std::vector<BodyPair> pairs;
  std::vector<Pose> poses_a, poses_b;
  for (int step = 0; step < 200; ++step) {
    const double t = 0.02 * step;
    const Pose pb(Eigen::AngleAxisd(t, Vec3(0, 0, 1)).toRotationMatrix(),
                  Vec3(3.0 - t, 0.5 + 0.3 * std::sin(t), 0.5));
    const BodyResult tracked = distance(l, Pose::identity(), room, pb, {}, &cache);
    const BodyResult cold = distance(l, Pose::identity(), room, pb);
    EXPECT_EQ(tracked.status, cold.status) << step;
    EXPECT_NEAR(tracked.signed_distance(), cold.signed_distance(), 1e-12) << step;
    pairs.push_back(step % 2 ? BodyPair{&l, &room} : BodyPair{&capsule, &l});
    poses_a.push_back(Pose::identity());
    poses_b.push_back(pb);
  }
  EXPECT_FALSE(cache.is_cold());
  std::vector<BodyResult> batch(pairs.size());
  distance_batch(pairs, poses_a, poses_b, batch, {}, {}, 2);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const BodyResult one = distance(*pairs[k].a, poses_a[k], *pairs[k].b, poses_b[k]);
    EXPECT_EQ(batch[k].signed_distance(), one.signed_distance()) << k;
    EXPECT_EQ(batch[k].status, one.status) << k;
  }
}

TEST(BodyMesh, ANullMeshIsRefused) {
  EXPECT_THROW(Body(std::shared_ptr<const TriangleMesh>()), InvalidInput);
  const Body m(box_mesh(1.0));
  EXPECT_EQ(m.kind(), Body::Kind::mesh);
  EXPECT_EQ(m.compound(), nullptr);
  EXPECT_EQ(m.convex(), nullptr);
  EXPECT_NEAR(m.scale(), 1.0, 0.0);
}

// Regression (issue 26): the gradient of a mesh overlap was refused with a
// message that blamed DistanceOptions::penetration (which was on); no depth
// is defined for an overlap with a mesh, and the message now says so and
// what to use instead. Convex bodies that overlap still have their gradient.
TEST(BodyMesh, GradientOfAMeshOverlapNamesTheRealReason) {
  const Body room(box_mesh(1.0));
  const Body ball = make_sphere(0.5);
  const Pose at(Mat3::Identity(), Vec3(0.9, 0.0, 0.0));
  const BodyResult r = distance(room, Pose::identity(), ball, at);
  ASSERT_EQ(r.status, Status::intersecting);
  try {
    signed_distance_gradient(r, Pose::identity(), at);
    ADD_FAILURE() << "a mesh overlap has no gradient";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("triangle mesh"), std::string::npos) << what;
    EXPECT_NE(what.find("hull"), std::string::npos) << what;
    EXPECT_EQ(what.find("penetration false"), std::string::npos) << what;
  }
  // The same bodies as convex ones overlap with a depth: a gradient.
  const Body box = make_box(Vec3(1.0, 1.0, 1.0));
  EXPECT_NO_THROW(signed_distance_gradient(distance(box, Pose::identity(), ball, at),
                                           Pose::identity(), at));
  // Apart, the mesh pair's gradient is the distance's.
  const Pose far(Mat3::Identity(), Vec3(3.0, 0.0, 0.0));
  EXPECT_NO_THROW(signed_distance_gradient(distance(room, Pose::identity(), ball, far),
                                           Pose::identity(), far));
}

}  // namespace
}  // namespace proxima
