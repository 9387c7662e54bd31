// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The consumer project's program: one body from points, one from an OFF text
// through proxima::io, one distance query. Exits 0 when the answer is the
// known distance, so the CTest test fails if the installed package builds
// but links or computes wrongly.
#include <proxima/query/distance.h>
#include <proxima/io.h>
#include <proxima/shape/polytope.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  std::vector<proxima::Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const proxima::ConvexPolytope a(cube);

  // A tetrahedron whose lowest vertex is 1.5 above the cube's top face.
  const char* const kOff = "OFF\n4 0 0\n0.25 0.5 2.5\n-1 -1 4\n2 -1 4\n0.5 2 4\n";
  const proxima::PointCloud cloud = proxima::read_points_from_memory(kOff, proxima::MeshFormat::off, "tetra.off");
  const proxima::ConvexPolytope b(cloud.points);

  const proxima::DistanceResult r = proxima::distance(a, proxima::Pose::identity(), b, proxima::Pose::identity());
  std::printf("distance %.17g (%s), %d iterations\n", r.distance, proxima::to_string(r.status), r.iterations);
  // The accuracy standard: 1e-12 relative plus 64 u R with R = 4.
  const double tolerance = 1e-12 * 1.5 + 64.0 * proxima::kUnitRoundoff * 4.0;
  return std::abs(r.distance - 1.5) <= tolerance && r.status == proxima::Status::separated ? 0 : 1;
}
