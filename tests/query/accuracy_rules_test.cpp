// proxima: the shared rules of src/core/accuracy.h, as every entry point
// applies them: the largest magnitude accepted, and the checks of
// DistanceOptions (one function, one message, for every query that takes
// them).
// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <limits>
#include <string>
#include <vector>

#include "proxima/motion/time_of_impact.h"
#include "proxima/query/batch.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/scene/scene.h"
#include "support/generators.h"

namespace proxima {
namespace {

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(no InvalidInput thrown)";
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

std::string number(double x) {
  char s[64];
  std::snprintf(s, sizeof s, "%g", x);
  return s;
}

// Coordinates up to 2^1018 (bound as magnitude_bound does) are answered,
// beyond are refused by name: the limit kMaxMagnitude, on both sides.
TEST(Accuracy, MagnitudesBeyondTheLimitAreRefusedByName) {
  const ConvexPolytope cube(test::cube(1.0));
  const Pose near_limit = Pose::from_translation(Vec3(0x1p1017, 0, 0));
  const DistanceResult r = distance(cube, Pose(), cube, near_limit);
  EXPECT_EQ(r.status, Status::separated);
  EXPECT_TRUE(std::isfinite(r.distance));
  const Pose beyond = Pose::from_translation(Vec3(0, -0x1.8p1018, 0));
  EXPECT_TRUE(starts_with(message_of([&] { (void)distance(cube, Pose(), cube, beyond); }),
                          "distance: body b reaches coordinates of magnitude"));
}

// Regression: the mesh query checked only absolute_tolerance (and with its
// own message); a NaN relative_tolerance or max_iterations of 0 was silently
// ignored there while distance() and Scene refused it. One check now, the
// same message after each entry point's name.
TEST(Accuracy, EveryEntryPointChecksDistanceOptionsAlike) {
  const ConvexPolytope cube(test::cube(1.0));
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<TriangleMesh::Triangle> t = {{0, 1, 2}};
  const TriangleMesh mesh(v, t);
  const Pose apart = Pose::from_translation(Vec3(0, 0, 3));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto messages = [&](const DistanceOptions& options) {
    SceneOptions scene;
    scene.distance = options;
    return std::vector<std::string>{
        message_of([&] { (void)distance(cube, Pose(), cube, apart, options); }),
        message_of([&] { (void)distance(mesh, Pose(), mesh, apart, options); }),
        message_of([&] { Scene s(scene); })};
  };
  const std::vector<std::string> who = {"distance: options.", "mesh distance: options.",
                                        "Scene: options.distance."};
  DistanceOptions relative;
  relative.relative_tolerance = nan;
  DistanceOptions absolute;
  absolute.absolute_tolerance = -1.0;
  DistanceOptions iterations;
  iterations.max_iterations = 0;
  const std::vector<std::string> r = messages(relative), a = messages(absolute),
                                  i = messages(iterations);
  for (std::size_t k = 0; k < who.size(); ++k) {
    EXPECT_EQ(r[k], who[k] + "relative_tolerance must be finite and >= 0, got nan");
    EXPECT_EQ(a[k], who[k] + "absolute_tolerance must be finite and >= 0, got -1");
    EXPECT_EQ(i[k], who[k] + "max_iterations must be at least 1, got 0");
  }
  // -0.0 is a tolerance of zero, accepted everywhere (the mesh query takes
  // no relative tolerance but its own: MeshOptions below).
  DistanceOptions zero;
  zero.relative_tolerance = -0.0;
  zero.absolute_tolerance = -0.0;
  EXPECT_EQ(distance(cube, Pose(), cube, apart, zero).status, Status::separated);
  DistanceOptions zero_absolute;
  zero_absolute.absolute_tolerance = -0.0;
  EXPECT_EQ(distance(mesh, Pose(), mesh, apart, zero_absolute).status, Status::separated);
  SceneOptions scene;
  scene.distance = zero;
  EXPECT_NO_THROW(Scene{scene});
}

// Regression: Scene::pairs_within tested its margin with !(margin >= 0),
// an ordered comparison that raises FE_INVALID on a NaN, which the test
// main traps (SIGFPE instead of the refusal); time_of_impact left its
// distance options to the first step's query, whose message named
// "distance: options" instead of the caller's field. Every check is now
// core/checks.h's, on the bits, with one wording.
TEST(Accuracy, ChecksRefuseNaNWithoutRaisingInvalid) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Scene scene;
  const BodyId id = scene.add(std::make_shared<const ConvexPolytope>(test::cube(1.0)), Pose());
  EXPECT_EQ(message_of([&] { (void)scene.pairs_within(id, nan); }),
            "Scene::pairs_within: margin must be finite and >= 0, got nan");
  SceneOptions bad_margin;
  bad_margin.margin = -1.0;
  EXPECT_EQ(message_of([&] { Scene s(bad_margin); }),
            "Scene: options.margin must be finite and >= 0, got -1");
  SceneOptions bad_threads;
  bad_threads.threads = -2;
  EXPECT_EQ(message_of([&] { Scene s(bad_threads); }),
            "Scene: options.threads must be at least 0 (0: all cores), got -2");
  const ConvexPolytope cube(test::cube(1.0));
  ImpactOptions impact;
  impact.distance.relative_tolerance = nan;
  EXPECT_EQ(message_of([&] {
              (void)time_of_impact(cube, Motion::fixed(Pose()), cube,
                                   Motion::fixed(Pose::from_translation(Vec3(3, 0, 0))), impact);
            }),
            "time_of_impact: options.distance.relative_tolerance must be finite and >= 0, got nan");
  ImpactOptions tolerance;
  tolerance.tolerance = nan;
  EXPECT_EQ(message_of([&] {
              (void)time_of_impact(cube, Motion::fixed(Pose()), cube,
                                   Motion::fixed(Pose::from_translation(Vec3(3, 0, 0))), tolerance);
            }),
            "time_of_impact: options.tolerance must be finite and >= 0 (0: the default), got nan");
}

// The queries with a triangle mesh solve triangle pairs in closed form and
// stop at their hull's bound to 1e-12: they took a DistanceOptions and
// silently ignored its algorithm, relative_tolerance and max_iterations
// (a caller asking for GJK, a looser tolerance or a tighter cap got the
// same answer as without). Each is now refused by every entry point that
// reaches a mesh query, naming the field and the triangle mesh, and
// honoured where the query can (distance(TriangleMesh, ConvexPolytope)
// runs the convex query with them at its leaves).
class MeshOptions : public ::testing::Test {
 protected:
  std::shared_ptr<const TriangleMesh> mesh = std::make_shared<const TriangleMesh>(
      std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
      std::vector<TriangleMesh::Triangle>{{0, 1, 2}});
  std::shared_ptr<const ConvexPolytope> cube =
      std::make_shared<const ConvexPolytope>(test::cube(1.0));
  Pose apart = Pose::from_translation(Vec3(0, 0, 3));

  // Every entry point that reaches a mesh query with `options`, each
  // one's message (or that none was thrown).
  std::vector<std::string> messages(const DistanceOptions& options) const {
    const Body m(mesh), c(cube);
    std::vector<std::string> out;
    out.push_back(message_of([&] { (void)distance(*mesh, Pose(), *mesh, apart, options); }));
    out.push_back(message_of([&] { (void)distance(m, Pose(), c, apart, options); }));
    out.push_back(
        message_of([&] { (void)within_margin(*mesh, Pose(), *mesh, apart, 0.1, options); }));
    out.push_back(message_of([&] { (void)within_margin(c, Pose(), m, apart, 0.1, options); }));
    // Two mesh bodies take their own path to the mesh query (margin.cpp):
    // it refused nothing when it was merged beside these checks.
    out.push_back(message_of([&] { (void)within_margin(m, Pose(), m, apart, 0.1, options); }));
    out.push_back(message_of([&] {
      const std::vector<BodyPair> pairs = {{&m, &c}};
      const std::vector<Pose> pa = {Pose()}, pb = {apart};
      std::vector<BodyResult> results(1);
      std::vector<MarginResult> hits(1);
      distance_batch(pairs, pa, pb, results, {}, options, 1);
      within_margin_batch(pairs, pa, pb, 0.1, hits, {}, options, 1);
    }));
    out.push_back(message_of([&] {
      ImpactOptions impact;
      impact.distance = options;
      (void)time_of_impact(m, Motion::fixed(Pose()), c, Motion::fixed(apart), impact);
    }));
    out.push_back(message_of([&] {
      SceneOptions scene;
      scene.distance = options;
      Scene s(scene);
      (void)s.add(c, Pose());
      (void)s.add(m, apart);
    }));
    return out;
  }

  // `field` with its value, as the message names them ("algorithm gjk").
  void expect_refused(const DistanceOptions& options, const std::string& field) const {
    for (const std::string& m : messages(options)) {
      EXPECT_NE(m.find("options."), std::string::npos) << m;
      EXPECT_NE(m.find("." + field + " does not apply"), std::string::npos) << m;
      EXPECT_NE(m.find(" does not apply to a triangle mesh"), std::string::npos) << m;
    }
  }
};

TEST_F(MeshOptions, AnotherAlgorithmIsRefusedNotIgnored) {
  for (const Algorithm algorithm : {Algorithm::gjk, Algorithm::enhanced_gjk}) {
    DistanceOptions options;
    options.algorithm = algorithm;
    expect_refused(options, std::string("algorithm ") + to_string(algorithm));
    // The mesh-convex query's leaves run the convex query with it: the
    // same answer as the hybrid's, within the standard.
    const MeshResult r = distance(*mesh, Pose(), *cube, apart, options);
    EXPECT_EQ(r.status, Status::separated);
    EXPECT_NEAR(r.distance, distance(*mesh, Pose(), *cube, apart).distance, 1e-12);
  }
  // The defaults pass everywhere.
  for (const std::string& m : messages(DistanceOptions{})) EXPECT_EQ(m, "(no InvalidInput thrown)");
}

TEST_F(MeshOptions, AnotherRelativeToleranceIsRefusedNotIgnored) {
  for (const double tolerance : {0.0, 1e-15, 1e-6}) {
    DistanceOptions options;
    options.relative_tolerance = tolerance;
    expect_refused(options, "relative_tolerance " + number(tolerance));
    // The mesh-convex query's hull stop certifies 1e-12 only: refused too.
    const std::string m =
        message_of([&] { (void)distance(*mesh, Pose(), *cube, apart, options); });
    EXPECT_NE(m.find("mesh distance: options.relative_tolerance"), std::string::npos) << m;
  }
}

TEST_F(MeshOptions, AnotherIterationCapIsRefusedNotIgnored) {
  for (const int cap : {1, 1000}) {
    DistanceOptions options;
    options.max_iterations = cap;
    expect_refused(options, "max_iterations " + std::to_string(cap));
    // The mesh-convex query caps its leaves' convex queries with it.
    EXPECT_NO_THROW((void)distance(*mesh, Pose(), *cube, apart, options));
  }
}

}  // namespace
}  // namespace proxima
