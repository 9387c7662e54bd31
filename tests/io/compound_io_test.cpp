// Tests of load_compound and compound_from_cloud (io.h): OBJ groups become
// the pieces in file order with their names; a file without groups is one
// piece; a non-convex group is reported (interior points counted), not
// refused; the body answers distance queries like the hulls of its groups;
// a group that cannot be hulled, and a hand-made cloud with a bad group
// layout, are FileErrors naming the file and the group.
#include <gtest/gtest.h>

#include <array>
#include <charconv>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "proxima/io.h"
#include "support/generators.h"
#include "support/temp_dir.h"

namespace proxima {
namespace {

using test::Points;
using test::Rng;

class CompoundIoTest : public test::TempDirTest {};

// Shortest text that reads back as exactly `v`.
std::string text(double v) {
  std::array<char, 64> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), end);
}

std::string obj_vertices(const Points& pts) {
  std::string s;
  for (const Vec3& p : pts) s += "v " + text(p.x()) + " " + text(p.y()) + " " + text(p.z()) + "\n";
  return s;
}

TEST_F(CompoundIoTest, GroupsBecomePiecesInFileOrder) {
  Rng rng(11);
  const Points p0 = test::translated(test::points_on_sphere(rng, 20), Vec3(-3, 0, 0));
  // Group 1 is not convex as given: a cube cloud with interior points.
  const Points p1 = test::points_in_cube(rng, 40);
  const Points p2 = test::translated(test::cube(1.0), Vec3(3, 0, 0));
  const std::string obj = "# three parts\n" + obj_vertices(p0) + "o middle part\n" +
                          obj_vertices(p1) + "g right\n" + obj_vertices(p2);
  const LoadedCompound loaded = load_compound(write("parts.obj", obj));
  ASSERT_EQ(loaded.body.piece_count(), 3);
  ASSERT_EQ(loaded.pieces.size(), 3u);
  EXPECT_EQ(loaded.pieces[0].name, "");
  EXPECT_EQ(loaded.pieces[1].name, "middle part");
  EXPECT_EQ(loaded.pieces[2].name, "right");
  EXPECT_EQ(loaded.pieces[0].input_points, 20);
  EXPECT_EQ(loaded.pieces[1].input_points, 40);
  EXPECT_EQ(loaded.pieces[2].input_points, 8);
  EXPECT_TRUE(loaded.pieces[0].input_was_convex);
  EXPECT_FALSE(loaded.pieces[1].input_was_convex);
  EXPECT_GT(loaded.pieces[1].interior_points, 0);
  EXPECT_EQ(loaded.pieces[1].interior_points, 40 - loaded.body.piece(1).polytope->vertex_count());
  EXPECT_TRUE(loaded.pieces[2].input_was_convex);

  // The body answers as the hulls of its groups do: a point probe at the
  // far right is closest to group 2, at the distance of that hull alone.
  const ConvexPolytope probe(Points{Vec3(10, 0.1, 0.2)});
  const CompoundBody probe_body(
      {{std::make_shared<const ConvexPolytope>(Points{Vec3(10, 0.1, 0.2)}), Pose()}});
  const CompoundResult r = distance(loaded.body, Pose(), probe_body, Pose());
  EXPECT_EQ(r.piece_a, 2);
  EXPECT_EQ(r.distance, distance(ConvexPolytope(p2), Pose(), probe, Pose()).distance);
  EXPECT_EQ(r.distance, distance_all_pairs(loaded.body, Pose(), probe_body, Pose()).distance);
}

// Issue 9: in OBJ the vertices are global and `g`/`o` group the faces. The
// reader took each group's points from the `v` lines after its statement, so
// a file that lists every vertex first, then each group's faces, became one
// piece of every point (its hull spanning both parts). Each piece is now
// made of the vertices its faces reference, relative indices included.
TEST_F(CompoundIoTest, VerticesFirstThenFacesSplitByGroup) {
  const Points left = test::cube(1.0);
  const Points right = test::translated(test::cube(1.0), Vec3(5, 0, 0));
  // Each cube's hull triangles, as 1-based OBJ indices (from the hull).
  const auto faces = [](const Points& pts, int first, bool relative, int total) {
    const ConvexPolytope hull(pts);
    std::string out;
    for (const auto& t : hull.triangles()) {
      out += "f";
      for (const std::int32_t k : t) {
        const int index = first + hull.input_index()[static_cast<std::size_t>(k)];
        out += ' ';
        out += std::to_string(relative ? index - total - 1 : index);
        out += "/1/1";
      }
      out += "\n";
    }
    return out;
  };
  const std::string obj = obj_vertices(left) + obj_vertices(right) +
                          "vt 0 0\nvn 0 0 1\ng left part\n" + faces(left, 1, false, 16) +
                          "o right\n" + faces(right, 9, true, 16);
  const LoadedCompound loaded = load_compound(write("split.obj", obj));
  ASSERT_EQ(loaded.body.piece_count(), 2);
  EXPECT_EQ(loaded.pieces[0].name, "left part");
  EXPECT_EQ(loaded.pieces[1].name, "right");
  EXPECT_EQ(loaded.pieces[0].input_points, 8);
  EXPECT_EQ(loaded.pieces[1].input_points, 8);
  EXPECT_TRUE(loaded.pieces[0].input_was_convex);
  EXPECT_TRUE(loaded.pieces[1].input_was_convex);
  EXPECT_EQ(loaded.body.piece(0).polytope->vertex_count(), 8);
  EXPECT_EQ(loaded.body.piece(1).polytope->vertex_count(), 8);
  EXPECT_LT(loaded.body.piece(0).polytope->vertices()[0].x(), 2.0);
  EXPECT_GT(loaded.body.piece(1).polytope->vertices()[0].x(), 2.0);
}

TEST_F(CompoundIoTest, AFoldedGroupIsReportedNotConvex) {
  const Points pts = test::cube(1.0);
  const ConvexPolytope hull(pts);
  std::string cube_faces;
  for (const auto& t : hull.triangles()) {
    cube_faces += "f";
    for (const std::int32_t k : t)
      cube_faces += " " + std::to_string(hull.input_index()[static_cast<std::size_t>(k)] + 1);
    cube_faces += "\n";
  }
  // Three corners with no coordinate in common lie on no face of the cube:
  // their triangle cuts through it.
  std::string fold;
  for (int i = 0; i < 8 && fold.empty(); ++i) {
    for (int j = 0; j < 8 && fold.empty(); ++j) {
      for (int k = 0; k < 8 && fold.empty(); ++k) {
        const auto& p = pts;
        bool shared = i == j || j == k || i == k;
        for (int axis = 0; axis < 3; ++axis) {
          shared = shared || (p[i][axis] == p[j][axis] && p[j][axis] == p[k][axis]);
        }
        if (!shared)
          fold = "f " + std::to_string(i + 1) + " " + std::to_string(j + 1) + " " +
                 std::to_string(k + 1) + "\n";
      }
    }
  }
  ASSERT_FALSE(fold.empty());
  const std::string obj =
      obj_vertices(pts) + "g whole\n" + cube_faces + "g folded\n" + cube_faces + fold;
  const LoadedCompound loaded = load_compound(write("folded.obj", obj));
  ASSERT_EQ(loaded.pieces.size(), 2u);
  EXPECT_EQ(loaded.pieces[1].name, "folded");
  EXPECT_TRUE(loaded.pieces[0].input_was_convex);
  EXPECT_FALSE(loaded.pieces[1].input_was_convex);
  EXPECT_EQ(loaded.pieces[1].interior_points, 0);
}

TEST_F(CompoundIoTest, FileWithoutGroupsIsOnePiece) {
  Rng rng(12);
  const Points pts = test::points_on_sphere(rng, 30);
  for (const std::string name : {"ball.obj", "ball.xyz"}) {
    std::string bytes = obj_vertices(pts);
    if (name.ends_with(".xyz")) {
      bytes.clear();
      for (const Vec3& p : pts) bytes += text(p.x()) + " " + text(p.y()) + " " + text(p.z()) + "\n";
    }
    const LoadedCompound loaded = load_compound(write(name, bytes));
    ASSERT_EQ(loaded.body.piece_count(), 1);
    EXPECT_EQ(loaded.pieces[0].name, "");
    EXPECT_EQ(loaded.pieces[0].input_points, 30);
    EXPECT_TRUE(loaded.pieces[0].input_was_convex);
    EXPECT_EQ(loaded.body.piece(0).polytope->vertex_count(), 30);
  }
}

TEST_F(CompoundIoTest, ErrorsNameTheFileAndTheGroup) {
  // A hand-made cloud: a NaN point in group 1 cannot be hulled.
  PointCloud cloud;
  cloud.source = "hand.obj";
  cloud.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 0, 0),
                  Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)};
  cloud.group_names = {"left", "broken"};
  cloud.group_offsets = {0, 3};
  try {
    compound_from_cloud(cloud);
    ADD_FAILURE() << "no exception";
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), "hand.obj");
    EXPECT_NE(e.problem().find("group 1 'broken'"), std::string::npos) << e.what();
  }
  // Bad layouts: offsets not from 0, decreasing, past the end, names and
  // offsets of different lengths; no points at all.
  cloud.points[4] = Vec3(6, 0, 0);
  for (const std::vector<std::int32_t>& offsets :
       {std::vector<std::int32_t>{1, 3}, std::vector<std::int32_t>{0, 0},
        std::vector<std::int32_t>{0, 9}}) {
    cloud.group_offsets = offsets;
    EXPECT_THROW(compound_from_cloud(cloud), FileError);
  }
  cloud.group_offsets = {0, 3};
  EXPECT_EQ(compound_from_cloud(cloud).body.piece_count(), 2);
  cloud.group_names = {"only one name"};
  EXPECT_THROW(compound_from_cloud(cloud), FileError);
  cloud.points.clear();
  cloud.group_names.clear();
  cloud.group_offsets.clear();
  EXPECT_THROW(compound_from_cloud(cloud), FileError);

  // A file the reader refuses keeps the reader's message (file and line).
  const std::string path = write("bad.obj", "v 0 0 0\ng part\nv 1 x 0\n");
  try {
    load_compound(path);
    ADD_FAILURE() << "no exception";
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 3);
  }
  EXPECT_THROW(load_compound((dir_ / "missing.obj").string()), FileError);
}

}  // namespace
}  // namespace proxima
