// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Tests of `proxima distance`, `proxima hull`, `proxima query --threads`,
// the help texts and the exit codes, run as a user runs them: the built
// binary through a shell, on mesh files written by the test. Expected values
// come from the geometry of the written bodies (a known distance, known
// hull counts) or from the library called in-process on the same points.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "proxima/io.h"
#include "proxima/query/distance.h"
#include "proxima/shape/polytope.h"
#include "support/generators.h"
#include "support/run_cli.h"

namespace {

using Json = nlohmann::json;
using proxima::ConvexPolytope;
using proxima::kUnitRoundoff;
using proxima::Vec3;
using proxima::test::CliRun;
using proxima::test::drawn;
using proxima::test::run_cli;
using proxima::test::shell_quote;
using proxima::test::TempPath;

// DESIGN.md's accuracy standard for a distance d among coordinates of
// magnitude up to R: |distance - d*| <= 1e-12 d* + 64 u R.
double accuracy_bound(double d, double r) { return 1e-12 * d + 64.0 * kUnitRoundoff * r; }

std::string g17(double x) {
  std::array<char, 40> buffer{};
  std::snprintf(buffer.data(), buffer.size(), "%.17g", x);
  return buffer.data();
}

std::vector<Vec3> box(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i) {
    corners.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  }
  return corners;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Vertices only; the readers recompute the hull from the points.
void write_obj(const std::string& path, const std::vector<Vec3>& points) {
  std::string text = "# written by cli_tools_test\n";
  for (const Vec3& p : points)
    text += "v " + g17(p.x()) + " " + g17(p.y()) + " " + g17(p.z()) + "\n";
  write_text(path, text);
}

// Binary STL of the given triangles. Coordinates must be floats exactly
// (the format stores float32); the callers use dyadic values.
void write_binary_stl(const std::string& path, const std::vector<std::array<Vec3, 3>>& triangles) {
  std::string bytes(80, ' ');
  auto put_u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes += static_cast<char>((v >> (8 * i)) & 0xffU);
  };
  auto put_float = [&](double x) {
    const auto f = static_cast<float>(x);
    std::uint32_t u = 0;
    std::memcpy(&u, &f, sizeof u);
    put_u32(u);
  };
  put_u32(static_cast<std::uint32_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) put_float(0.0);  // normal: readers ignore it
    for (const Vec3& p : t) {
      for (int i = 0; i < 3; ++i) put_float(p[i]);
    }
    bytes += std::string(2, '\0');
  }
  write_text(path, bytes);
}

// A tetrahedron whose lowest vertex is `apex`, above the unit cube's top face.
const Vec3 kApex(0.25, 0.375, 2.5);
const std::array<Vec3, 4> kTetra = {Vec3(-1, -1, 4), kApex, Vec3(2, -1, 4), Vec3(0.5, 2, 4)};

void write_tetra_stl(const std::string& path) {
  write_binary_stl(path, {{{kTetra[0], kTetra[1], kTetra[2]},
                           {kTetra[0], kTetra[2], kTetra[3]},
                           {kTetra[0], kTetra[3], kTetra[1]},
                           {kTetra[1], kTetra[3], kTetra[2]}}});
}

Vec3 vec(const Json& j) {
  return Vec3(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

Json parse_json(const CliRun& run) {
  Json j = Json::parse(run.out, nullptr, /*allow_exceptions=*/false);
  EXPECT_TRUE(j.is_object()) << run.out;
  return j;
}

TEST(CliDistance, ObjCubeAndStlTetrahedronKnownDistance) {
  REQUIRE_CLI();
  const TempPath cube(".obj");
  const TempPath tetra(".stl");
  const std::vector<Vec3> cube_points = box(Vec3(0, 0, 0), Vec3(1, 1, 1));
  write_obj(cube.path(), cube_points);
  write_tetra_stl(tetra.path());

  const CliRun run = run_cli("distance " + cube.quoted() + " " + tetra.quoted() + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const Json j = parse_json(run);
  // The apex is 1.5 above the top face z = 1, inside its x-y range.
  const double expected = 1.5;
  EXPECT_EQ(j.at("status"), "separated");
  EXPECT_NEAR(j.at("distance").get<double>(), expected, accuracy_bound(expected, 4.0));
  EXPECT_LE(j.at("lower_bound").get<double>(), j.at("distance").get<double>());
  EXPECT_GE(j.at("lower_bound").get<double>(),
            expected * (1 - 1e-12) - accuracy_bound(expected, 4.0));
  EXPECT_GE(j.at("iterations").get<int>(), 0);
  EXPECT_LE((vec(j.at("point_b")) - kApex).norm(), accuracy_bound(expected, 4.0));
  EXPECT_LE((vec(j.at("point_a")) - Vec3(kApex.x(), kApex.y(), 1.0)).norm(),
            accuracy_bound(expected, 4.0));
  EXPECT_LE((vec(j.at("normal")) - Vec3(0, 0, 1)).norm(), 1e-12);
  EXPECT_EQ(j.at("algorithm"), "hybrid");

  // Witness features: B's is the apex vertex, named by its hull id and by
  // its index in the file's points; A's is the top face (or a part of it),
  // whose input points all lie on z = 1.
  const Json& fb = j.at("feature_b");
  EXPECT_EQ(fb.at("type"), "vertex");
  ASSERT_EQ(fb.at("input_indices").size(), 1U);
  const proxima::PointCloud tetra_read = proxima::read_points(tetra.path());
  const auto apex_index = fb.at("input_indices").at(0).get<std::size_t>();
  ASSERT_LT(apex_index, tetra_read.points.size());
  EXPECT_EQ(tetra_read.points[apex_index], kApex);
  const ConvexPolytope tetra_hull(tetra_read.points);
  EXPECT_EQ(tetra_hull.input_index()[fb.at("hull_vertices").at(0).get<std::size_t>()],
            static_cast<std::int32_t>(apex_index));
  const Json& fa = j.at("feature_a");
  EXPECT_EQ(fa.at("hull_vertices").size(), fa.at("input_indices").size());
  EXPECT_GE(fa.at("input_indices").size(), 1U);
  for (const Json& index : fa.at("input_indices"))
    EXPECT_EQ(cube_points.at(index.get<std::size_t>()).z(), 1.0);
  if (fa.at("type") == "face") {
    EXPECT_TRUE(fa.at("face").is_number_integer());
  } else {
    EXPECT_TRUE(fa.at("face").is_null());
  }

  EXPECT_EQ(j.at("a").at("format"), "obj");
  EXPECT_EQ(j.at("b").at("format"), "stl_binary");
  EXPECT_EQ(j.at("a").at("convex"), true);
  EXPECT_EQ(j.at("b").at("input_points"), 4);  // the STL's 12 corners, merged

  // The table says the same.
  const CliRun table = run_cli("distance " + cube.quoted() + " " + tetra.quoted());
  ASSERT_EQ(table.exit_code, 0);
  EXPECT_NE(table.out.find("status        separated\n"), std::string::npos) << table.out;
  const auto at = table.out.find("distance      ");
  ASSERT_NE(at, std::string::npos) << table.out;
  EXPECT_NEAR(std::stod(table.out.substr(at + 14)), expected, accuracy_bound(expected, 4.0));
  EXPECT_NE(
      table.out.find("feature B     vertex: hull vertices " + fb.at("hull_vertices").at(0).dump() +
                     " (input points " + std::to_string(apex_index) + ")"),
      std::string::npos)
      << table.out;
}

// The CLI with poses gives the doubles that the library gives in-process on
// the same points and pose, for every algorithm.
TEST(CliDistance, PoseFlagsMatchTheLibrary) {
  REQUIRE_CLI();
  std::mt19937_64 rng(20261122);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  auto cloud = [&](int n) {
    std::vector<Vec3> points;
    for (int i = 0; i < n; ++i) points.push_back(drawn([&] { return gauss(rng); }));
    return points;
  };
  const std::vector<Vec3> pa = cloud(40);
  const std::vector<Vec3> pb = cloud(60);
  const TempPath fa(".obj");
  const TempPath fb(".xyz");
  write_obj(fa.path(), pa);
  std::string xyz;
  for (const Vec3& p : pb) xyz += g17(p.x()) + " " + g17(p.y()) + " " + g17(p.z()) + "\n";
  write_text(fb.path(), xyz);
  const ConvexPolytope a(pa);
  const ConvexPolytope b(pb);

  const std::array<const char*, 3> algorithms = {"hybrid", "gjk", "enhanced_gjk"};
  for (int trial = 0; trial < 6; ++trial) {
    std::array<double, 7> va{};
    std::array<double, 7> vb{};
    for (double& x : va) x = uniform(rng);
    for (double& x : vb) x = uniform(rng);
    vb[0] += 8.0;                                     // mostly apart; some trials may still overlap
    if (trial == 5) vb = {0.5, 0.25, 0, 1, 0, 0, 0};  // overlapping: intersecting
    std::string flags;
    for (const auto* v : {&va, &vb}) {
      flags += v == &va ? " --pose-a" : " --pose-b";
      for (const double x : *v) {
        flags += ' ';
        flags += g17(x);
      }
    }
    const proxima::Pose pose_a(proxima::Quat(va[3], va[4], va[5], va[6]),
                               Vec3(va[0], va[1], va[2]));
    const proxima::Pose pose_b(proxima::Quat(vb[3], vb[4], vb[5], vb[6]),
                               Vec3(vb[0], vb[1], vb[2]));
    const std::string algorithm = algorithms[static_cast<std::size_t>(trial) % algorithms.size()];
    proxima::DistanceOptions options;
    options.algorithm = algorithm == "gjk"            ? proxima::Algorithm::gjk
                        : algorithm == "enhanced_gjk" ? proxima::Algorithm::enhanced_gjk
                                                      : proxima::Algorithm::hybrid;
    const proxima::DistanceResult r = proxima::distance(a, pose_a, b, pose_b, options);

    const CliRun run = run_cli("distance " + fa.quoted() + " " + fb.quoted() + flags +
                               " --algorithm " + algorithm + " --quaternion-order wxyz --json");
    ASSERT_EQ(run.exit_code, 0) << flags;
    const Json j = parse_json(run);
    EXPECT_EQ(j.at("status"), proxima::to_string(r.status)) << flags;
    EXPECT_EQ(j.at("distance").get<double>(), r.distance) << flags;
    EXPECT_EQ(j.at("lower_bound").get<double>(), r.lower_bound);
    EXPECT_EQ(vec(j.at("point_a")), r.point_a);
    EXPECT_EQ(vec(j.at("point_b")), r.point_b);
    EXPECT_EQ(vec(j.at("normal")), r.normal);
    EXPECT_EQ(j.at("iterations").get<int>(), r.iterations);
    EXPECT_EQ(j.at("algorithm"), algorithm);
    EXPECT_EQ(j.at("feature_a").at("type"), proxima::to_string(r.feature_a.type));
    EXPECT_EQ(j.at("feature_b").at("type"), proxima::to_string(r.feature_b.type));
    if (trial == 5) {
      EXPECT_EQ(j.at("status"), "intersecting");
    }
  }
}

TEST(CliDistance, NonConvexInputIsReported) {
  REQUIRE_CLI();
  std::vector<Vec3> points = box(Vec3(0, 0, 0), Vec3(2, 2, 2));
  points.emplace_back(1, 1, 1);      // inside
  points.emplace_back(0.5, 1, 1.5);  // inside
  points.emplace_back(2, 2, 2);      // a repeated corner
  const TempPath file(".obj");
  const TempPath other(".obj");
  write_obj(file.path(), points);
  write_obj(other.path(), box(Vec3(5, 0, 0), Vec3(6, 1, 1)));

  const CliRun json = run_cli("distance " + file.quoted() + " " + other.quoted() + " --json");
  ASSERT_EQ(json.exit_code, 0);
  const Json j = parse_json(json);
  EXPECT_EQ(j.at("a").at("convex"), false);
  EXPECT_EQ(j.at("a").at("points_inside"), 3);
  EXPECT_EQ(j.at("a").at("input_points"), 11);
  EXPECT_EQ(j.at("b").at("convex"), true);
  EXPECT_NEAR(j.at("distance").get<double>(), 3.0, accuracy_bound(3.0, 6.0));

  const CliRun table = run_cli("distance " + file.quoted() + " " + other.quoted());
  ASSERT_EQ(table.exit_code, 0);
  EXPECT_NE(table.out.find("not convex: 3 points are inside the hull"), std::string::npos)
      << table.out;

  const CliRun hull = run_cli("hull " + file.quoted() + " --json");
  ASSERT_EQ(hull.exit_code, 0);
  EXPECT_EQ(parse_json(hull).at("points_inside"), 3);
  EXPECT_EQ(parse_json(hull).at("convex"), false);
}

// Regression (issue 9): the CLI's "convex" counted interior points, so a
// mesh whose vertices are all on its hull but whose faces fold inwards (the
// Panda's collision meshes do, by up to 1 mm) was reported convex, unlike
// load_convex. Both now use surface_is_convex.
TEST(CliDistance, FoldedMeshIsReportedNotConvex) {
  REQUIRE_CLI();
  const TempPath folded(".obj");
  const TempPath other(".obj");
  {
    std::ofstream out(folded.path());
    for (int i = 0; i < 8; ++i)
      out << "v " << (i & 1) << " " << ((i >> 1) & 1) << " " << ((i >> 2) & 1) << "\n";
    // The cube's twelve outward triangles, and one through its inside.
    out << "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 "
           "3\n"
           "f 2 4 8\nf 2 8 6\nf 1 4 6\n";
  }
  write_obj(other.path(), box(Vec3(5, 0, 0), Vec3(6, 1, 1)));
  // Issue 12: a non-convex file is not silently replaced by its hull: the
  // caller names how to read it.
  const CliRun unsaid = run_cli("distance " + folded.quoted() + " " + other.quoted(), true);
  EXPECT_EQ(unsaid.exit_code, 1);
  EXPECT_NE(unsaid.out.find("not convex (its surface is not its hull's boundary): say how to read "
                            "it: --as mesh"),
            std::string::npos)
      << unsaid.out;
  const CliRun json =
      run_cli("distance " + folded.quoted() + " " + other.quoted() + " --as-a hull --json");
  ASSERT_EQ(json.exit_code, 0);
  const Json j = parse_json(json);
  EXPECT_EQ(j.at("a").at("points_inside"), 0);
  EXPECT_EQ(j.at("a").at("convex"), false);
  EXPECT_EQ(j.at("a").at("as"), "hull");
  EXPECT_EQ(j.at("b").at("convex"), true);
  const CliRun table = run_cli("distance " + folded.quoted() + " " + other.quoted() + " --as hull");
  EXPECT_NE(table.out.find("not convex: the surface folds inward"), std::string::npos) << table.out;
  // As a mesh: the surface as given (the inner triangle is part of it), 4
  // from the box at x = 5; closed? No: the inner triangle's edges are used
  // three times.
  const CliRun mesh =
      run_cli("distance " + folded.quoted() + " " + other.quoted() + " --as-a mesh --json");
  ASSERT_EQ(mesh.exit_code, 0);
  const Json m = parse_json(mesh);
  EXPECT_EQ(m.at("a").at("as"), "mesh");
  EXPECT_EQ(m.at("a").at("triangles"), 13);
  EXPECT_EQ(m.at("a").at("closed"), false);
  EXPECT_EQ(m.at("b").at("as"), "hull");
  EXPECT_DOUBLE_EQ(m.at("distance").get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(m.at("signed_distance").get<double>(), 4.0);
  EXPECT_GE(m.at("feature_a").at("triangle").get<int>(), 0);
  const CliRun hull = run_cli("hull " + folded.quoted() + " --json");
  EXPECT_EQ(parse_json(hull).at("convex"), false);
}

// Reads an exported OBJ's faces (1-based `f` lines).
std::vector<std::vector<int>> obj_faces(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<int>> faces;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) != 0) continue;
    std::istringstream s(line.substr(2));
    std::vector<int> face;
    int v = 0;
    while (s >> v) face.push_back(v - 1);
    faces.push_back(face);
  }
  return faces;
}

std::vector<std::array<double, 3>> sorted(const std::vector<Vec3>& points) {
  std::vector<std::array<double, 3>> out;
  for (const Vec3& p : points) out.push_back({p.x(), p.y(), p.z()});
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CliHull, CubeStatisticsAndJson) {
  REQUIRE_CLI();
  std::vector<Vec3> points = box(Vec3(-1, 0, 2), Vec3(1, 2, 4));
  points.emplace_back(0, 1, 3);  // the centre
  const TempPath file(".obj");
  write_obj(file.path(), points);
  const CliRun run = run_cli("hull " + file.quoted() + " --json");
  ASSERT_EQ(run.exit_code, 0);
  const Json j = parse_json(run);
  EXPECT_EQ(j.at("input_points"), 9);
  EXPECT_EQ(j.at("vertices"), 8);
  EXPECT_EQ(j.at("edges"), 12);
  EXPECT_EQ(j.at("faces"), 6);  // coplanar triangles merged into squares
  EXPECT_EQ(j.at("dimension"), 3);
  EXPECT_EQ(j.at("points_inside"), 1);
  EXPECT_EQ(j.at("scale").get<double>(), 4.0);
  EXPECT_NEAR(j.at("bounding_radius").get<double>(), std::sqrt(3.0), 4 * kUnitRoundoff * 4.0);
  EXPECT_EQ(vec(j.at("centroid")), Vec3(0, 1, 3));
  EXPECT_EQ(j.at("memory_bytes").get<std::size_t>(), ConvexPolytope(points).memory_bytes());
  EXPECT_EQ(j.at("format"), "obj");

  const CliRun table = run_cli("hull " + file.quoted());
  ASSERT_EQ(table.exit_code, 0);
  EXPECT_NE(table.out.find("faces         6\n"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("dimension     3 (a solid)\n"), std::string::npos) << table.out;
}

// Export, read back through proxima_io: the same vertex set, and every
// exported face is a plane of the hull with all vertices on its inner side
// (outward, counter-clockwise order).
TEST(CliHull, ExportRoundTrip) {
  REQUIRE_CLI();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss;
  std::vector<Vec3> points;
  for (int i = 0; i < 300; ++i) {
    Vec3 p = drawn([&] { return gauss(rng); });
    // Half on a sphere (hull vertices), half inside.
    points.push_back(i % 2 == 0 ? Vec3(p.normalized() * 3.0) : Vec3(p.normalized() * 1.5));
  }
  const TempPath input(".ply");
  std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(points.size()) +
                    "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  for (const Vec3& p : points) ply += g17(p.x()) + " " + g17(p.y()) + " " + g17(p.z()) + "\n";
  write_text(input.path(), ply);
  const ConvexPolytope hull(points);

  for (const char* extension : {".obj", ".off", ".OBJ"}) {
    const TempPath out(extension);
    const CliRun run = run_cli("hull " + input.quoted() + " --out " + out.quoted() + " --json");
    ASSERT_EQ(run.exit_code, 0) << extension;
    const Json j = parse_json(run);
    EXPECT_EQ(j.at("export").at("vertices"), hull.vertex_count());
    EXPECT_EQ(j.at("export").at("faces"), hull.face_count());
    const proxima::PointCloud back = proxima::read_points(out.path());
    const std::vector<Vec3> hull_vertices(hull.vertices().begin(), hull.vertices().end());
    EXPECT_EQ(sorted(back.points), sorted(hull_vertices)) << extension;
    const ConvexPolytope again(back.points);
    EXPECT_EQ(again.vertex_count(), hull.vertex_count());
    EXPECT_EQ(again.interior_point_count(), 0);
    if (std::string(extension) == ".obj") {
      const auto faces = obj_faces(out.path());
      ASSERT_EQ(static_cast<int>(faces.size()), hull.face_count());
      for (const auto& face : faces) {
        ASSERT_GE(face.size(), 3U);
        Vec3 normal = Vec3::Zero();  // Newell's normal of the polygon
        for (std::size_t k = 0; k < face.size(); ++k) {
          normal +=
              back.points.at(static_cast<std::size_t>(face[k]))
                  .cross(back.points.at(static_cast<std::size_t>(face[(k + 1) % face.size()])));
        }
        normal.normalize();
        const double offset = normal.dot(back.points.at(static_cast<std::size_t>(face[0])));
        for (const Vec3& v : back.points) EXPECT_LE(normal.dot(v) - offset, 1e-12 * 3.0);
      }
    }
  }
}

TEST(CliHull, LowerDimensionalExports) {
  REQUIRE_CLI();
  const TempPath square(".xyz");
  write_text(square.path(), "0 0 1\n2 0 1\n2 2 1\n0 2 1\n1 1 1\n");
  const TempPath square_out(".obj");
  CliRun run = run_cli("hull " + square.quoted() + " --out " + square_out.quoted() + " --json");
  ASSERT_EQ(run.exit_code, 0);
  Json j = parse_json(run);
  EXPECT_EQ(j.at("dimension"), 2);
  EXPECT_EQ(j.at("faces"), 2);  // one per side
  EXPECT_EQ(j.at("export").at("note").get<std::string>().find("polygon") != std::string::npos,
            true);
  const auto faces = obj_faces(square_out.path());
  ASSERT_EQ(faces.size(), 2U);
  std::vector<int> reversed(faces[1].rbegin(), faces[1].rend());
  std::rotate(reversed.begin(), std::find(reversed.begin(), reversed.end(), faces[0][0]),
              reversed.end());
  EXPECT_EQ(faces[0], reversed);  // the two sides are the same polygon, opposite orientation

  const TempPath segment(".xyz");
  write_text(segment.path(), "0 0 0\n1 1 1\n3 3 3\n");
  const TempPath segment_obj(".obj");
  const TempPath segment_off(".off");
  run = run_cli("hull " + segment.quoted() + " --out " + segment_obj.quoted());
  ASSERT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("segment"), std::string::npos) << run.out;
  EXPECT_EQ(sorted(proxima::read_points(segment_obj.path()).points),
            sorted({Vec3(0, 0, 0), Vec3(3, 3, 3)}));
  std::ifstream obj(segment_obj.path());
  const std::string obj_text((std::istreambuf_iterator<char>(obj)),
                             std::istreambuf_iterator<char>());
  EXPECT_NE(obj_text.find("\nl 1 2\n"), std::string::npos) << obj_text;
  run = run_cli("hull " + segment.quoted() + " --out " + segment_off.quoted() + " --json");
  ASSERT_EQ(run.exit_code, 0);
  EXPECT_EQ(parse_json(run).at("export").at("faces"), 0);
  EXPECT_EQ(sorted(proxima::read_points(segment_off.path()).points),
            sorted({Vec3(0, 0, 0), Vec3(3, 3, 3)}));
}

TEST(CliTools, BadInputExitsOneNamingTheFile) {
  REQUIRE_CLI();
  const TempPath good(".obj");
  write_obj(good.path(), box(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const std::string missing =
      (std::filesystem::temp_directory_path() / "proxima_no_such_mesh_4711.stl").string();

  CliRun run = run_cli("distance " + good.quoted() + " " + shell_quote(missing), true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find(missing), std::string::npos) << run.out;
  run = run_cli("hull " + shell_quote(missing), true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find(missing), std::string::npos) << run.out;

  // A bad number in a file: the message names the file and the line.
  const TempPath bad(".obj");
  write_text(bad.path(), "v 0 0 0\nv 1 0 zero\n");
  run = run_cli("hull " + bad.quoted(), true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find(bad.path() + ", line 2"), std::string::npos) << run.out;

  // Bad pose numbers are bad input too, named by option.
  run =
      run_cli("distance " + good.quoted() + " " + good.quoted() + " --pose-b 0 0 x", true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("--pose-b z: 'x' is not a number"), std::string::npos) << run.out;
  run =
      run_cli("distance " + good.quoted() + " " + good.quoted() +
                  " --pose-a 0 0 0 0 0 0 0 --quaternion-order wxyz", true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("--pose-a"), std::string::npos) << run.out;
  run = run_cli("distance " + good.quoted() + " " + good.quoted() + " --pose-a 0 nan 0", true);
  EXPECT_EQ(run.exit_code, 1);

  // An unwritable export path.
  run = run_cli("hull " + good.quoted() + " --out /nonexistent-dir-4711/hull.obj", true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("/nonexistent-dir-4711/hull.obj"), std::string::npos) << run.out;
}

// Issue 9: a file name that is not UTF-8 (byte 0xff) made nlohmann's dump
// throw in `--json` output, and the answer was lost. The byte is now
// written as U+FFFD and the JSON parses.
TEST(CliTools, JsonSurvivesAFileNameThatIsNotUtf8) {
  REQUIRE_CLI();
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("proxima_cli_test_" + std::to_string(getpid()) + "_\xff.obj"))
                               .string();
  write_obj(path, box(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const TempPath other(".obj");
  write_obj(other.path(), box(Vec3(3, 0, 0), Vec3(4, 1, 1)));
  const std::string replaced = "_\xef\xbf\xbd.obj";  // U+FFFD in UTF-8
  const CliRun hull = run_cli("hull " + shell_quote(path) + " --json");
  const CliRun distance =
      run_cli("distance " + shell_quote(path) + " " + other.quoted() + " --json");
  std::filesystem::remove(path);
  ASSERT_EQ(hull.exit_code, 0) << hull.out;
  EXPECT_NE(parse_json(hull).at("file").get<std::string>().find(replaced), std::string::npos);
  EXPECT_EQ(parse_json(hull).at("vertices"), 8);
  ASSERT_EQ(distance.exit_code, 0) << distance.out;
  EXPECT_NE(parse_json(distance).at("a").at("file").get<std::string>().find(replaced),
            std::string::npos);
  EXPECT_NEAR(parse_json(distance).at("distance").get<double>(), 2.0, accuracy_bound(2.0, 4.0));
}

// Issue 9: `proxima hull /dev/zero` grew until bad_alloc. --max-file-size
// (default 1 GiB) bounds what is read.
TEST(CliTools, MaxFileSizeRefusesLargerFiles) {
  REQUIRE_CLI();
  const TempPath file(".obj");
  write_obj(file.path(), box(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  CliRun run = run_cli("hull " + file.quoted() + " --max-file-size 20", true);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find(file.path() + ": file too large"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("limit of 20 bytes"), std::string::npos) << run.out;
  run = run_cli("distance " + file.quoted() + " " + file.quoted() + " --max-file-size 20", true);
  EXPECT_EQ(run.exit_code, 1);
  if (std::filesystem::exists("/dev/zero")) {
    run = run_cli("hull /dev/zero --max-file-size 1000000", true);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.out.find("/dev/zero: file too large"), std::string::npos) << run.out;
  }
  EXPECT_EQ(run_cli("hull " + file.quoted() + " --max-file-size 100000 --json").exit_code, 0);
}

TEST(CliTools, UsageErrorsExitTwo) {
  REQUIRE_CLI();
  const TempPath good(".obj");
  write_obj(good.path(), box(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const std::string g = good.quoted();
  for (const std::string& args : std::vector<std::string>{
           "", "nonsense", "distance", "distance " + g, "distance " + g + " " + g + " --bogus",
           "distance " + g + " " + g + " --algorithm best", "hull", "hull " + g + " --out hull.stl",
           "hull " + g + " --frobnicate", "query --threads 0", "query --threads two"}) {
    EXPECT_EQ(run_cli(args, true).exit_code, 2) << args;
  }
}

TEST(CliTools, HelpShowsExamples) {
  REQUIRE_CLI();
  for (const std::string command : {"", "distance ", "hull ", "query ", "demo "}) {
    const CliRun run = run_cli(command + "--help");
    EXPECT_EQ(run.exit_code, 0) << command;
    EXPECT_NE(run.out.find("Example"), std::string::npos) << command << run.out;
    EXPECT_NE(run.out.find("proxima " + (command.empty() ? std::string("distance") : command)),
              std::string::npos)
        << command << run.out;
  }
}

// --threads N answers exactly what --threads 1 answers, in the same order,
// error lines and blank lines included, from a file and from a pipe.
TEST(CliQueryThreads, SameBytesAsOneThread) {
  REQUIRE_CLI();
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  std::string text;
  for (int i = 0; i < 700; ++i) {
    switch (i % 11) {
      case 3:
        text += "{\"id\":" + std::to_string(i) + ",\"a\":{\"vertices\":[[0,0,0]]}}\n";
        break;  // no b
      case 5:
        text += "not json at all\n";
        break;
      case 7:
        text += "\n";
        break;  // blank: no answer
      case 9:
        text += "{\"id\":\"s" + std::to_string(i) +
                "\",\"a\":{\"vertices\":[]},\"b\":{\"vertices\":[[1,2,3]]}}\n";
        break;
      default: {
        Json a = Json::array();
        Json b = Json::array();
        for (int k = 0; k < 12; ++k) a.push_back({uniform(rng), uniform(rng), uniform(rng)});
        for (int k = 0; k < 9; ++k) b.push_back({uniform(rng) + 3.0, uniform(rng), uniform(rng)});
        text += Json{{"id", i}, {"a", {{"vertices", a}}}, {"b", {{"vertices", b}}}}.dump() + "\n";
      }
    }
  }
  const TempPath file(".jsonl");
  write_text(file.path(), text);
  const CliRun one = run_cli("query " + file.quoted() + " --threads 1");
  ASSERT_EQ(one.exit_code, 0);
  // 700 lines, 63 of them blank.
  EXPECT_EQ(std::count(one.out.begin(), one.out.end(), '\n'), 700 - 63);
  EXPECT_NE(one.out.find("\"status\":\"error\""), std::string::npos);
  EXPECT_NE(one.out.find("\"status\":\"separated\""), std::string::npos);
  for (const std::string& args : std::vector<std::string>{
           "query " + file.quoted() + " --threads 2", "query --threads 2 < " + file.quoted(),
           "query --threads 3 - < " + file.quoted(), "query < " + file.quoted()}) {
    const CliRun run = run_cli(args);
    EXPECT_EQ(run.exit_code, 0) << args;
    EXPECT_EQ(run.out, one.out) << args;
  }
}

}  // namespace

// Issue 11: --pose-b read scalar last with --quaternion-order xyzw (ROS's
// order) gives the library's answer for that rotation; the default reads
// the same seven numbers scalar first.
TEST(CliDistance, QuaternionOrderFlag) {
  REQUIRE_CLI();
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const TempPath file(".obj");
  write_obj(file.path(), cube);
  const ConvexPolytope hull(cube);
  const std::string pose_b = " --pose-b 3 0 0 0 0 0.3826834323650898 0.9238795325112867";
  for (const bool scalar_last : {false, true}) {
    const proxima::Quat q = scalar_last
                                ? proxima::Quat(0.9238795325112867, 0, 0, 0.3826834323650898)
                                : proxima::Quat(0, 0, 0.3826834323650898, 0.9238795325112867);
    const proxima::DistanceResult r =
        proxima::distance(hull, proxima::Pose{}, hull, proxima::Pose(q, Vec3(3, 0, 0)));
    const CliRun run = run_cli("distance " + file.quoted() + " " + file.quoted() + pose_b +
                               (scalar_last ? " --quaternion-order xyzw" : " --quaternion-order wxyz") +
                               " --json");
    ASSERT_EQ(run.exit_code, 0) << run.out;
    const Json j = parse_json(run);
    EXPECT_EQ(j.at("distance").get<double>(), r.distance) << scalar_last;
    EXPECT_EQ(vec(j.at("point_b")), r.point_b) << scalar_last;
  }
  const CliRun bad = run_cli("distance " + file.quoted() + " " + file.quoted() +
                                 " --quaternion-order xyzw --pose-b 0 0 0 0 0 0 x",
                             true);
  EXPECT_NE(bad.out.find("--pose-b qw: 'x' is not a number"), std::string::npos) << bad.out;
}

// Issue 25: `proxima distance --pose-b 3 0 0 0 0 0 1` read ROS's identity
// scalar first, a half turn about z, without a word. Seven numbers now need
// --quaternion-order (refused otherwise, with both readings); three are a
// translation and need none.
TEST(CliDistance, AnUnnamedPoseQuaternionIsRefused) {
  REQUIRE_CLI();
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const TempPath file(".obj");
  write_obj(file.path(), cube);
  const std::string files = "distance " + file.quoted() + " " + file.quoted();
  const CliRun refused = run_cli(files + " --pose-b 3 0 0 0 0 0 1 --json", true);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.out.find("--pose-b: the quaternion 0 0 0 1 does not name its order: as (w, x, "
                             "y, z) it is a turn of 180 degrees about (0, 0, 1); as (x, y, z, w) "
                             "(ROS, scipy) it is the identity. Add --quaternion-order wxyz or "
                             "--quaternion-order xyzw"),
            std::string::npos)
      << refused.out;
  const CliRun moved = run_cli(files + " --pose-b 3 0 0 --json");
  ASSERT_EQ(moved.exit_code, 0) << moved.out;
  EXPECT_EQ(parse_json(moved).at("distance").get<double>(), 2.0);
  const CliRun ros = run_cli(files + " --pose-b 3 0 0 0 0 0 1 --quaternion-order xyzw --json");
  ASSERT_EQ(ros.exit_code, 0) << ros.out;
  EXPECT_EQ(parse_json(ros).at("distance").get<double>(), 2.0);
  const CliRun four = run_cli(files + " --pose-b 3 0 0 1 --json", true);
  EXPECT_EQ(four.exit_code, 1);
  EXPECT_NE(four.out.find("--pose-b takes 3 numbers (x y z) or 7"), std::string::npos) << four.out;
}
