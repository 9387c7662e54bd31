// proxima: the shared rules of src/core/accuracy.h, as every entry point
// applies them: the largest magnitude accepted, and the checks of
// DistanceOptions (one function, one message, for every query that takes
// them).
// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
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
  // -0.0 is a tolerance of zero, accepted everywhere.
  DistanceOptions zero;
  zero.relative_tolerance = -0.0;
  zero.absolute_tolerance = -0.0;
  EXPECT_EQ(distance(cube, Pose(), cube, apart, zero).status, Status::separated);
  EXPECT_EQ(distance(mesh, Pose(), mesh, apart, zero).status, Status::separated);
  SceneOptions scene;
  scene.distance = zero;
  EXPECT_NO_THROW(Scene{scene});
}

}  // namespace
}  // namespace proxima
