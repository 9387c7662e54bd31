// Tests of the boolean and margin queries (margin.h) against their slow
// twin, the full distance query compared with the margin: for convex,
// rounded, compound, mesh and mixed pairs, on random poses, on margins equal
// to the distance (the band's edge), and on degenerate contacts (coplanar
// faces, crossing triangles, a body inside a closed mesh). Every answer is
// checked for its certificate (a witness pair within margin + band, or a
// lower bound above the margin and below the distance), and its verdict
// against the twin's wherever the twin's distance is outside the accuracy
// band of the margin.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/primitives.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::Rng;

// An axis-aligned box [-h, h]^3 as 12 triangles, counter-clockwise seen
// from outside (closed), or without its +z face (open).
std::shared_ptr<const TriangleMesh> box_mesh(double h, bool closed = true) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  std::vector<TriangleMesh::Triangle> t = {{0, 2, 1}, {1, 2, 3}, {0, 1, 4}, {1, 5, 4},
                                           {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5},
                                           {2, 6, 3}, {3, 6, 7}};
  if (closed) {
    t.push_back({4, 5, 6});
    t.push_back({5, 7, 6});
  }
  return std::make_shared<const TriangleMesh>(v, t);
}

// A random hull's closed triangle mesh (non-trivial hierarchy).
std::shared_ptr<const TriangleMesh> hull_mesh(Rng& rng, int n) {
  return Body(ConvexPolytope(test::points_on_sphere(rng, n))).meshes().front().mesh;
}

Pose random_pose(Rng& rng, double spread) {
  return {test::random_quaternion(rng),
          test::drawn([&] { return test::uniform(rng, -spread, spread); })};
}

// The contact band of the margin query: 64 u R, R bounded per body.
double band_of(const Body& a, const Pose& pa, const Body& b, const Pose& pb) {
  return contact_band(std::max(magnitude_bound(pa, a.scale()), magnitude_bound(pb, b.scale())));
}

// The twin's answer: the full distance query's distance and whether its
// status is a contact.
struct Twin {
  double distance;
  bool contact;
};
Twin twin_of(const Body& a, const Pose& pa, const Body& b, const Pose& pb) {
  const BodyResult r = distance(a, pa, b, pb);
  return {r.distance, r.status != Status::separated};
}

// The certificate and, outside the band of the margin, the twin's verdict.
// Returns whether the twin's distance was in the band (either verdict
// accepted there).
bool expect_agrees(const MarginResult& got, double margin, const Twin& twin, double band,
                   const char* what, int k) {
  EXPECT_NE(got.status, MarginStatus::undecided) << what << " " << k;
  EXPECT_EQ(got.margin, margin) << what << " " << k;
  // The full query is within 1e-12 d + 64 u R of the exact distance, the
  // margin query decides within band of it: together a few bands.
  const double zone = 3.0 * band + 1e-11 * std::max(twin.distance, margin);
  if (got.status == MarginStatus::within) {
    EXPECT_LE(got.upper_bound, margin + 2.0 * band) << what << " " << k;
    EXPECT_NEAR((got.point_b - got.point_a).norm(), got.upper_bound, 4.0 * band) << what << k;
    EXPECT_GE(got.upper_bound, twin.distance - zone) << what << " " << k;
  } else if (got.status == MarginStatus::beyond) {
    EXPECT_GT(got.lower_bound, margin) << what << " " << k;
    EXPECT_LE(got.lower_bound, twin.distance + zone) << what << " " << k;
  }
  const bool in_band = !twin.contact && std::abs(twin.distance - margin) <= zone;
  if (!in_band) {
    const bool twin_within = twin.contact || twin.distance <= margin;
    EXPECT_EQ(got.status == MarginStatus::within, twin_within)
        << what << " " << k << ": twin distance " << twin.distance << " margin " << margin;
  }
  return in_band;
}

// The margins tried per pose: 0, random ones, and the twin's distance
// itself and just around it (the band's edge).
std::vector<double> margins_for(Rng& rng, double d) {
  return {0.0, test::uniform(rng, 0.0, 0.6), test::uniform(rng, 0.0, 0.05), d,
          d * (1.0 + 1e-9), d * (1.0 - 1e-9), std::nextafter(d, 0.0)};
}

// Random convex pairs, plain and rounded, at spreads that give overlapping,
// near and far poses: every verdict outside the band is the twin's.
TEST(Margin, ConvexAndRoundedAgreeWithTheFullQuery) {
  Rng rng(2601);
  int within = 0, beyond = 0, overlapping = 0;
  for (int k = 0; k < 300; ++k) {
    const double ra = k % 3 == 0 ? 0.05 : 0.0;
    const double rb = k % 4 == 0 ? 0.1 : 0.0;
    const Body a(std::make_shared<const ConvexPolytope>(test::points_on_sphere(rng, 6 + k % 40)),
                 ra);
    const Body b(std::make_shared<const ConvexPolytope>(test::points_in_cube(rng, 8 + k % 30, 0.5)),
                 rb);
    const Pose pa = random_pose(rng, 0.3);
    const Pose pb = random_pose(rng, 1.6);
    const Twin twin = twin_of(a, pa, b, pb);
    overlapping += twin.contact;
    const double band = band_of(a, pa, b, pb);
    for (const double m : margins_for(rng, twin.distance)) {
      const MarginResult got = within_margin(a, pa, b, pb, m);
      expect_agrees(got, m, twin, band, "convex", k);
      (got.is_within() ? within : beyond) += 1;
      // The convex overload (no radii) answers the cores.
      if (ra == 0.0 && rb == 0.0) {
        const MarginResult core = within_margin(*a.convex(), pa, *b.convex(), pb, m);
        EXPECT_EQ(core.status, got.status) << k;
      }
    }
  }
  // Premise: both verdicts and overlapping poses are well represented.
  EXPECT_GT(within, 300);
  EXPECT_GT(beyond, 300);
  EXPECT_GT(overlapping, 30);
}

// The early exit: a margin far above or below the distance is proved in
// fewer iterations than the full query needs.
// Long thin hulls (a robot's links), whose bounding spheres reach far
// beyond them: the boxes' bound decides many poses the spheres cannot
// (no hull query: pairs_tested 0), at scales from 2^-300 to 2^300, and
// every verdict and bound is the twin's.
TEST(Margin, BoxesOfLongHullsProveBeyondWithoutTheHulls) {
  Rng rng(2609);
  int by_boxes = 0, within = 0;
  for (int k = 0; k < 100; ++k) {
    const double unit = std::ldexp(1.0, 200 * (k % 4) - 300);
    const auto rod = [&](double length) {
      // On a sphere, so that every point is a vertex: hulls of more than
      // kTableMinVertices vertices keep a box (polytope.h).
      test::Points p = test::points_on_sphere(rng, 48);
      for (Vec3& v : p) v = unit * Vec3(length * v.x(), 0.1 * v.y(), 0.1 * v.z());
      return Body(ConvexPolytope(p));
    };
    const Body a = rod(test::uniform(rng, 1.0, 3.0));
    const Body b = rod(test::uniform(rng, 1.0, 3.0));
    const Pose pa(test::random_rotation(rng), unit * Vec3(test::uniform(rng, -1, 1), 0.0, 0.0));
    // The translation first, the order gcc gives the call (see drawn()).
    const auto across = [&] { return test::uniform(rng, -2.5, 2.5); };
    const Vec3 at =
        unit * test::drawn(across, across, [&] { return test::uniform(rng, -1.0, 1.0); });
    const Pose pb(test::random_rotation(rng), at);
    const Twin twin = twin_of(a, pa, b, pb);
    const double band = band_of(a, pa, b, pb);
    for (const double m : {0.0, unit * test::uniform(rng, 0.0, 0.3)}) {
      const MarginResult got = within_margin(a, pa, b, pb, m);
      expect_agrees(got, m, twin, band, "rods", k);
      const ConvexPolytope& ca = *a.convex();
      const ConvexPolytope& cb = *b.convex();
      const double sphere = detail::sphere_gap_lower_bound(
          pa.apply(ca.centroid()), ca.bounding_radius(), pb.apply(cb.centroid()),
          cb.bounding_radius());
      if (got.status == MarginStatus::beyond && got.pairs_tested == 0 && !(sphere > m)) ++by_boxes;
      within += got.is_within() ? 1 : 0;
    }
  }
  EXPECT_GT(by_boxes, 30);
  EXPECT_GT(within, 6);
}

TEST(Margin, StopsAtTheFirstProof) {
  Rng rng(2602);
  int fewer = 0;
  for (int k = 0; k < 100; ++k) {
    const ConvexPolytope a(test::points_on_sphere(rng, 200));
    const ConvexPolytope b(test::points_on_sphere(rng, 200));
    const Pose pa = random_pose(rng, 0.1);
    const Pose pb(test::random_quaternion(rng), Vec3(3.0, 0.0, 0.0));
    const DistanceResult full = distance(a, pa, b, pb);
    const MarginResult far = within_margin(a, pa, b, pb, 0.1);
    const MarginResult near = within_margin(a, pa, b, pb, 2.0);
    EXPECT_EQ(far.status, MarginStatus::beyond) << k;
    EXPECT_EQ(near.status, MarginStatus::within) << k;
    fewer += far.iterations < full.iterations && near.iterations < full.iterations;
  }
  EXPECT_GT(fewer, 50);
}

// Compounds of random pieces: the twin is the compound distance query.
TEST(Margin, CompoundsAgreeWithTheFullQuery) {
  Rng rng(2603);
  const auto compound = [&](int pieces) {
    std::vector<std::vector<Vec3>> sets;
    for (int i = 0; i < pieces; ++i) {
      const Vec3 at = test::drawn([&] { return test::uniform(rng, -1, 1); });
      sets.push_back(test::translated(test::points_on_sphere(rng, 12, 0.3), at));
    }
    return std::make_shared<const CompoundBody>(CompoundBody::from_point_sets(sets));
  };
  int within = 0, beyond = 0;
  for (int k = 0; k < 60; ++k) {
    const Body a(compound(2 + k % 7), k % 2 == 0 ? 0.0 : 0.05);
    const Body b = k % 3 == 0 ? Body(ConvexPolytope(test::points_on_sphere(rng, 20)))
                              : Body(compound(1 + k % 5));
    const Pose pa = random_pose(rng, 0.3);
    const Pose pb = random_pose(rng, 3.0);
    const Twin twin = twin_of(a, pa, b, pb);
    const double band = band_of(a, pa, b, pb);
    BodyCache cache;
    for (const double m : margins_for(rng, twin.distance)) {
      const MarginResult got = within_margin(a, pa, b, pb, m, {}, &cache);
      expect_agrees(got, m, twin, band, "compound", k);
      (got.is_within() ? within : beyond) += 1;
      if (got.is_within() && a.kind() == Body::Kind::compound) {
        EXPECT_GE(got.piece_a, 0) << k;
      }
    }
    // The cache the margin queries left serves the distance query.
    EXPECT_NEAR(distance(a, pa, b, pb, {}, &cache).distance, twin.distance, band + 1e-12) << k;
  }
  EXPECT_GT(within, 60);
  EXPECT_GT(beyond, 60);
}

// Meshes against meshes, convex, rounded and compound bodies.
TEST(Margin, MeshPairsAgreeWithTheFullQuery) {
  Rng rng(2604);
  int within = 0, beyond = 0;
  for (int k = 0; k < 60; ++k) {
    const Body a(hull_mesh(rng, 20 + k % 50), k % 4 == 0 ? 0.05 : 0.0);
    Body b = make_sphere(0.2);
    switch (k % 3) {
      case 0:
        b = Body(hull_mesh(rng, 30));
        break;
      case 1:
        b = Body(std::make_shared<const ConvexPolytope>(test::points_in_cube(rng, 12, 0.4)), 0.02);
        break;
      default:
        b = Body(CompoundBody::from_point_sets(std::vector<std::vector<Vec3>>{
            test::points_on_sphere(rng, 10, 0.3),
            test::translated(test::points_on_sphere(rng, 10, 0.3), Vec3(0.8, 0, 0))}));
    }
    const Pose pa = random_pose(rng, 0.3);
    const Pose pb = random_pose(rng, 1.8);
    const Twin twin = twin_of(a, pa, b, pb);
    const double band = band_of(a, pa, b, pb);
    BodyCache cache;
    for (const double m : margins_for(rng, twin.distance)) {
      const MarginResult got = within_margin(a, pa, b, pb, m, {}, &cache);
      expect_agrees(got, m, twin, band, "mesh", k);
      (got.is_within() ? within : beyond) += 1;
      if (got.is_within() && got.upper_bound > 0.0) {
        EXPECT_GE(got.triangle_a, 0) << k;
      }
    }
  }
  EXPECT_GT(within, 60);
  EXPECT_GT(beyond, 60);
}

// Two mesh bodies take their own path to the mesh query (no pieces, no
// placements): the answer is the mesh query's, field by field, cold and
// tracked along a motion (one BodyCache against one MeshCache), and a
// rounded pair's verdict is the cores' with the margin plus both radii.
TEST(Margin, MeshBodiesAnswerAsTheirMeshes) {
  Rng rng(2608);
  const auto mesh_a = hull_mesh(rng, 60);
  const auto mesh_b = hull_mesh(rng, 40);
  const Body a(mesh_a), b(mesh_b);
  const Body rounded_a(mesh_a, 0.03), rounded_b(mesh_b, 0.02);
  BodyCache body_cache;
  MeshCache mesh_cache;
  int within = 0, beyond = 0;
  Pose pb(test::random_rotation(rng), Vec3(2.4, 0.1, -0.2));
  const Mat3 turn = test::random_small_rotation(rng, 0.03);
  for (int step = 0; step < 100; ++step) {
    pb.translation.x() -= 0.03;
    pb.rotation = checked_pose(Pose(turn * pb.rotation, pb.translation), "step").rotation;
    const double m = step % 3 == 0 ? 0.0 : 0.04 * (step % 3);
    for (const bool tracked : {false, true}) {
      const MarginResult got = within_margin(a, Pose::identity(), b, pb, m, {},
                                             tracked ? &body_cache : nullptr);
      const MarginResult want = within_margin(*mesh_a, Pose::identity(), *mesh_b, pb, m, {},
                                              tracked ? &mesh_cache : nullptr);
      EXPECT_EQ(got.status, want.status) << step;
      EXPECT_EQ(got.lower_bound, want.lower_bound) << step;
      EXPECT_EQ(got.upper_bound, want.upper_bound) << step;
      EXPECT_EQ(got.point_a, want.point_a) << step;
      EXPECT_EQ(got.point_b, want.point_b) << step;
      EXPECT_EQ(got.triangle_a, want.triangle_a) << step;
      EXPECT_EQ(got.triangle_b, want.triangle_b) << step;
      EXPECT_EQ(got.piece_a, -1);
      EXPECT_EQ(got.piece_b, -1);
      EXPECT_EQ(got.pairs_tested, want.pairs_tested) << step;
      (got.is_within() ? within : beyond) += 1;
    }
    const MarginResult rounded = within_margin(rounded_a, Pose::identity(), rounded_b, pb, m);
    const MarginResult cores = within_margin(*mesh_a, Pose::identity(), *mesh_b, pb, m + 0.05);
    EXPECT_EQ(rounded.status, cores.status) << step;
    EXPECT_EQ(rounded.margin, m);
  }
  EXPECT_GT(within, 20);
  EXPECT_GT(beyond, 20);
  // The tracked queries kept the body's one mesh cache warm.
  ASSERT_EQ(body_cache.mesh.size(), 1u);
  EXPECT_FALSE(body_cache.mesh.front().is_cold());
}

// Degenerate contacts, hand-computed: boxes whose faces are coplanar
// (touching exactly), two triangles crossing, and a body inside a closed
// mesh (no surfaces meet) against the same inside an open one.
TEST(Margin, CoplanarCrossingAndInsideAClosedMesh) {
  // Faces at x = 0.5 of both unit boxes: touching, distance 0.
  const Body box_a = make_box(Vec3(0.5, 0.5, 0.5));
  const Body box_b(box_mesh(0.5));
  const Pose at_one(Mat3::Identity(), Vec3(1.0, 0.3, 0.0));
  for (const Body* b : {&box_a, &box_b}) {
    const MarginResult touching = intersects(box_a, Pose::identity(), *b, at_one);
    EXPECT_EQ(touching.status, MarginStatus::within);
    EXPECT_LE(touching.upper_bound, 1e-14);
    const Pose apart(Mat3::Identity(), Vec3(1.001, 0.3, 0.0));
    const MarginResult beyond = intersects(box_a, Pose::identity(), *b, apart);
    EXPECT_EQ(beyond.status, MarginStatus::beyond);
    EXPECT_GT(beyond.lower_bound, 0.0);
    EXPECT_LE(beyond.lower_bound, 1e-3 + 1e-14);
    EXPECT_EQ(within_margin(box_a, Pose::identity(), *b, apart, 1.001e-3).status,
              MarginStatus::within);
    EXPECT_EQ(within_margin(box_a, Pose::identity(), *b, apart, 0.999e-3).status,
              MarginStatus::beyond);
  }
  // Two open one-triangle meshes crossing through each other's interior.
  const std::vector<Vec3> tv = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  const std::vector<TriangleMesh::Triangle> one = {{0, 1, 2}};
  const Body tri(TriangleMesh(tv, one));
  const Pose crossing(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix(),
                      Vec3(0.0, -0.2, 0.0));
  EXPECT_EQ(distance(tri, Pose::identity(), tri, crossing).status, Status::intersecting);
  const MarginResult cross = intersects(tri, Pose::identity(), tri, crossing);
  EXPECT_EQ(cross.status, MarginStatus::within);
  EXPECT_LE(cross.upper_bound, 1e-14);
  // A small box inside a closed room: within any margin; inside the room
  // opened at its top, 1.5 from the nearest wall.
  const Body small = make_box(Vec3(0.5, 0.5, 0.5));
  const Body room(box_mesh(2.0));
  const Body open_room(box_mesh(2.0, false));
  const MarginResult inside = intersects(room, Pose::identity(), small, Pose::identity());
  EXPECT_EQ(inside.status, MarginStatus::within);
  EXPECT_EQ(inside.upper_bound, 0.0);
  EXPECT_EQ(intersects(open_room, Pose::identity(), small, Pose::identity()).status,
            MarginStatus::beyond);
  const MarginResult wall = within_margin(open_room, Pose::identity(), small, Pose::identity(), 1.4);
  EXPECT_EQ(wall.status, MarginStatus::beyond);
  EXPECT_GT(wall.lower_bound, 1.4);
  EXPECT_EQ(within_margin(open_room, Pose::identity(), small, Pose::identity(), 1.5).status,
            MarginStatus::within);
  // The mesh overload directly: a closed mesh inside another.
  const MarginResult nested =
      intersects(*box_mesh(2.0), Pose::identity(), *box_mesh(0.5), Pose::identity());
  EXPECT_EQ(nested.status, MarginStatus::within);
}

// A tracked sequence (one cache, small steps through contact and out)
// gives the cold verdicts; the caches stay usable by the distance query.
TEST(Margin, TrackedAnswersAreTheColdOnes) {
  Rng rng(2605);
  const Body convex(ConvexPolytope(test::points_on_sphere(rng, 60)));
  const Body mesh(hull_mesh(rng, 80));
  const Body compound(CompoundBody::from_point_sets(std::vector<std::vector<Vec3>>{
      test::points_on_sphere(rng, 16, 0.4),
      test::translated(test::points_on_sphere(rng, 16, 0.4), Vec3(0.7, 0, 0))}));
  const std::vector<std::pair<const Body*, const Body*>> pairs = {
      {&convex, &convex}, {&compound, &convex}, {&mesh, &convex}, {&mesh, &mesh}, {&compound, &mesh}};
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const Body& a = *pairs[p].first;
    const Body& b = *pairs[p].second;
    BodyCache cache;
    const Mat3 turn = test::random_small_rotation(rng, 0.02);
    Pose pb(test::random_rotation(rng), Vec3(3.0, 0.2, -0.1));
    for (int step = 0; step < 120; ++step) {
      pb.translation.x() -= 0.025;
      pb.rotation = checked_pose(Pose(turn * pb.rotation, pb.translation), "step").rotation;
      const double m = step % 2 == 0 ? 0.0 : 0.05;
      const MarginResult tracked = within_margin(a, Pose::identity(), b, pb, m, {}, &cache);
      const MarginResult cold = within_margin(a, Pose::identity(), b, pb, m);
      const Twin twin = twin_of(a, Pose::identity(), b, pb);
      const double band = band_of(a, Pose::identity(), b, pb);
      if (!expect_agrees(tracked, m, twin, band, "tracked", static_cast<int>(p * 1000 + step))) {
        EXPECT_EQ(tracked.status, cold.status) << p << " " << step;
      }
      if (step % 10 == 5) {
        // The distance query on the same cache.
        EXPECT_NEAR(distance(a, Pose::identity(), b, pb, {}, &cache).distance, twin.distance,
                    band + 1e-12)
            << p << " " << step;
      }
    }
  }
}

TEST(Margin, BadMarginsAndOptionsAreRefusedByName) {
  const Body a = make_sphere(1.0);
  const ConvexPolytope& core = *a.convex();
  for (const double m : {-1.0, std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(within_margin(a, Pose::identity(), a, Pose::identity(), m), InvalidInput);
    EXPECT_THROW(within_margin(core, Pose::identity(), core, Pose::identity(), m), InvalidInput);
    try {
      within_margin(a, Pose::identity(), a, Pose::identity(), m);
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("margin"), std::string::npos) << e.what();
    }
  }
  DistanceOptions bad;
  bad.max_iterations = 0;
  EXPECT_THROW(within_margin(a, Pose::identity(), a, Pose::identity(), 0.0, bad), InvalidInput);
  Pose nan_pose = Pose::identity();
  nan_pose.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(intersects(a, Pose::identity(), a, nan_pose), InvalidInput);
  EXPECT_THROW(intersects(*box_mesh(1.0), Pose::identity(), *box_mesh(1.0), nan_pose),
               InvalidInput);
}

// The other algorithms answer through their full query, the same verdicts.
TEST(Margin, GjkAndEnhancedGjkGiveTheSameVerdicts) {
  Rng rng(2606);
  for (int k = 0; k < 100; ++k) {
    const ConvexPolytope a(test::points_on_sphere(rng, 30));
    const ConvexPolytope b(test::points_on_sphere(rng, 30));
    const Pose pa = random_pose(rng, 0.2);
    const Pose pb = random_pose(rng, 2.0);
    const double m = test::uniform(rng, 0.0, 0.5);
    const DistanceResult full = distance(a, pa, b, pb);
    if (full.status == Status::separated && std::abs(full.distance - m) < 1e-9) continue;
    const MarginStatus want = within_margin(a, pa, b, pb, m).status;
    for (const Algorithm alg : {Algorithm::gjk, Algorithm::enhanced_gjk}) {
      DistanceOptions o;
      o.algorithm = alg;
      EXPECT_EQ(within_margin(a, pa, b, pb, m, o).status, want) << k;
    }
  }
}

}  // namespace
}  // namespace proxima
