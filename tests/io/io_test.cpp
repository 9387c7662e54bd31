// Tests of the mesh file readers (include/proxima/io.h).
//
// Every file is generated here, into a fresh temporary directory: seeded
// random points written in each format with round-trip precision must come
// back as the very same doubles; the errors must name the file, the line or
// byte, and the problem; and seeded mutations of valid files may only ever
// raise InvalidInput (a small, always-on sibling of fuzz/readers_fuzz.cpp).
#include "proxima/io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "support/temp_dir.h"

namespace proxima {
namespace {

// ---------------------------------------------------------------------------
// Helpers: files, number formatting, binary writers.

class IoTest : public test::TempDirTest {};

// Shortest text that reads back as exactly `v` (std::to_chars guarantees it).
std::string text(double v) {
  std::array<char, 64> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  EXPECT_EQ(ec, std::errc());
  return std::string(buf.data(), end);
}

std::string text(const Vec3& p) { return text(p.x()) + " " + text(p.y()) + " " + text(p.z()); }

// Seeded points whose magnitudes span the paper's stress range (edges of
// 1e-23 up to coordinates of 1e39), with full 53-bit mantissas so that
// every digit of the text matters, plus signed zeros. Points meant for
// float formats stay below 2^120 (floats end near 2^128).
std::vector<Vec3> random_points(std::uint64_t seed, int count, int max_exponent = 130) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> exponent(-80, max_exponent);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      const double sign = (rng() & 1U) != 0 ? -1.0 : 1.0;
      p[k] = sign * std::ldexp(mantissa(rng), exponent(rng));
    }
    points.push_back(p);
  }
  points.push_back(Vec3(0.0, -0.0, 0.1));
  return points;
}

void expect_same_points(const std::vector<Vec3>& got, const std::vector<Vec3>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      // Bitwise: a correctly rounded reader gives back the written double.
      EXPECT_EQ(std::bit_cast<std::uint64_t>(got[i][k]), std::bit_cast<std::uint64_t>(want[i][k]))
          << "point " << i << " axis " << k << ": got " << text(got[i][k]) << ", want "
          << text(want[i][k]);
    }
  }
}

template <class T>
void put(std::string& out, T value) {
  std::array<char, sizeof(T)> bytes{};
  std::memcpy(bytes.data(), &value, sizeof(T));
  static_assert(std::endian::native == std::endian::little,
                "the binary writers assume a little-endian host");
  out.append(bytes.data(), bytes.size());
}

constexpr int kFloatExponent = 120;

// The points rounded to float, as a float format stores them. The rounding
// goes through a volatile: GCC 12.2 at -O2 (its SLP vectorizer) compiles
// `p[k] = double(float(p[k]))` over x and y as a no-op, leaving those lanes
// unrounded (a compiler bug; the z lane, done in scalar code, is rounded).
std::vector<Vec3> to_floats(std::vector<Vec3> points) {
  for (Vec3& p : points) {
    for (int k = 0; k < 3; ++k) {
      const volatile float rounded = static_cast<float>(p[k]);
      p[k] = static_cast<double>(rounded);
    }
  }
  return points;
}

// The corners of `tris` in file order without exact duplicates (first
// appearance kept): what the STL readers give.
std::vector<Vec3> unique_corners(const std::vector<std::array<Vec3, 3>>& tris) {
  std::vector<Vec3> out;
  for (const auto& t : tris) {
    for (const Vec3& p : t) {
      if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
    }
  }
  return out;
}

// Triangles (as corner triples) over `points`, so every point is a corner and
// many are shared, as in a real STL.
std::vector<std::array<Vec3, 3>> triangles_over(const std::vector<Vec3>& points) {
  std::vector<std::array<Vec3, 3>> tris;
  const std::size_t n = points.size();
  for (std::size_t i = 0; i < n; ++i)
    tris.push_back({points[i], points[(i + 1) % n], points[(i + 5) % n]});
  return tris;
}

std::string stl_binary(const std::vector<std::array<Vec3, 3>>& tris,
                       const std::string& header_text) {
  std::string out = header_text;
  out.resize(80, ' ');
  put(out, static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) put(out, 0.0F);  // normal, unused
    for (const Vec3& p : t) {
      for (int k = 0; k < 3; ++k) put(out, static_cast<float>(p[k]));
    }
    put(out, std::uint16_t{0});
  }
  return out;
}

std::string stl_ascii(const std::vector<std::array<Vec3, 3>>& tris) {
  std::string out = "solid test\n";
  for (const auto& t : tris) {
    out += "  facet normal 0 0 1\n    outer loop\n";
    for (const Vec3& p : t) out += "      vertex " + text(p) + "\n";
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid test\n";
}

std::string cube_corner_text(int i) {
  return std::string((i & 1) != 0 ? "1" : "-1") + " " + ((i & 2) != 0 ? "1" : "-1") + " " +
         ((i & 4) != 0 ? "1" : "-1");
}

// Runs `read` and returns the FileError it must throw.
template <class F>
FileError expect_file_error(F&& read) {
  try {
    read();
  } catch (const FileError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-FileError: " << e.what();
    throw;
  }
  ADD_FAILURE() << "no FileError thrown";
  throw std::logic_error("no FileError thrown");
}

void expect_message(const FileError& e, std::initializer_list<std::string> parts) {
  const std::string what = e.what();
  for (const std::string& part : parts)
    EXPECT_NE(what.find(part), std::string::npos) << "'" << part << "' not in: " << what;
}

// ---------------------------------------------------------------------------
// Round trips: the same doubles back, in every format.

TEST_F(IoTest, RandomPointsSpanTheStressRange) {
  // The round-trip tests below are only as hard as their points: check that
  // they reach both ends of the paper's range and carry full mantissas.
  const auto points = random_points(1, 200);
  double smallest = std::numeric_limits<double>::infinity();
  double largest = 0.0;
  int full_mantissas = 0;
  for (const Vec3& p : points) {
    for (int k = 0; k < 3; ++k) {
      if (p[k] != 0.0) smallest = std::min(smallest, std::abs(p[k]));
      largest = std::max(largest, std::abs(p[k]));
      if (text(p[k]).size() >= 17) ++full_mantissas;
    }
  }
  EXPECT_LT(smallest, 1e-20);
  EXPECT_GT(largest, 1e35);
  EXPECT_GT(full_mantissas, 300);
}

TEST_F(IoTest, ObjRoundTripIsExactAndKeepsGroups) {
  const auto points = random_points(2, 30);
  std::string obj = "# made by io_test\nmtllib none.mtl\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i == 4) obj += "o first\n";
    if (i == 4) obj += "g first_part\n";  // no vertex since 'o': renames the group
    if (i == 10) obj += "g second two\n";
    if (i == 20) obj += "o third\nvn 0 0 1\nvt 0.5 0.5\n";
    obj += (i % 2 == 0 ? "v " : "  v\t") + text(points[i]) + (i % 3 == 0 ? " 1.0" : "") + "\n";
  }
  // No `f` lines: a point-cloud OBJ, grouped by its `v` lines (with faces,
  // the groups hold faces: ObjFacesAreGroupedWithGlobalVertices).
  obj += "g trailing_empty\n";
  const PointCloud cloud = read_points(write("mesh.obj", obj));
  EXPECT_EQ(cloud.format, MeshFormat::obj);
  expect_same_points(cloud.points, points);
  EXPECT_EQ(cloud.group_names, (std::vector<std::string>{"", "first_part", "second two", "third"}));
  EXPECT_EQ(cloud.group_offsets, (std::vector<std::int32_t>{0, 4, 10, 20}));
}

TEST_F(IoTest, ObjWithoutGroupsHasNone) {
  const PointCloud cloud =
      read_points_from_memory("v 0 0 0\nv 1 0 0\r\nv 0 1 0\rv 0 0 1", MeshFormat::obj, "plain");
  EXPECT_EQ(cloud.points.size(), 4U);
  EXPECT_TRUE(cloud.group_names.empty());
  EXPECT_TRUE(cloud.group_offsets.empty());
  EXPECT_EQ(cloud.source, "plain");
}

TEST_F(IoTest, OffRoundTripIsExact) {
  const auto points = random_points(3, 25);
  std::string off = "OFF\n# comment line\n" + std::to_string(points.size()) + " 1 0\n";
  for (const Vec3& p : points) off += text(p) + "  # trailing comment\n";
  off += "3 0 1 2\n";
  const PointCloud cloud = read_points(write("mesh.off", off));
  EXPECT_EQ(cloud.format, MeshFormat::off);
  expect_same_points(cloud.points, points);

  // COFF: colour columns after each vertex; counts on the keyword's line.
  std::string coff = "COFF " + std::to_string(points.size()) + " 0 0\n";
  for (const Vec3& p : points) coff += text(p) + " 255 0 0 255\n";
  expect_same_points(read_points(write("colour.off", coff)).points, points);
}

TEST_F(IoTest, XyzRoundTripIsExact) {
  const auto points = random_points(4, 25);
  std::string xyz = "# x y z intensity\r\n\r\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    xyz += i % 2 == 0 ? text(p) + " 0.5 label\r\n"
                      : text(p.x()) + "," + text(p.y()) + ", " + text(p.z()) + "\r\n";
  }
  const PointCloud cloud = read_points(write("cloud.xyz", xyz));
  EXPECT_EQ(cloud.format, MeshFormat::xyz);
  expect_same_points(cloud.points, points);
}

TEST_F(IoTest, StlAsciiRoundTripMergesRepeatedCorners) {
  const auto tris = triangles_over(random_points(5, 20));
  const PointCloud cloud = read_points(write("mesh.stl", stl_ascii(tris)));
  EXPECT_EQ(cloud.format, MeshFormat::stl_ascii);
  // Each point is a corner of three triangles; it must appear once.
  EXPECT_EQ(cloud.points.size(), 21U);
  expect_same_points(cloud.points, unique_corners(tris));
}

TEST_F(IoTest, StlBinaryIsDetectedBySizeEvenWithASolidHeader) {
  // Some exporters begin the binary header with "solid": the size rule, not
  // the prefix, must decide.
  const auto tris = triangles_over(to_floats(random_points(6, 20, kFloatExponent)));
  const PointCloud cloud =
      read_points(write("mesh.stl", stl_binary(tris, "solid written by a binary exporter")));
  EXPECT_EQ(cloud.format, MeshFormat::stl_binary);
  EXPECT_EQ(cloud.points.size(), 21U);
  expect_same_points(cloud.points, unique_corners(tris));
  // -0.0 and +0.0 are one corner.
  const std::vector<std::array<Vec3, 3>> signed_zeros = {
      {Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)},
      {Vec3(-0.0, 0.0, -0.0), Vec3(0.0, 1.0, 0.0), Vec3(0.0, 0.0, 1.0)}};
  EXPECT_EQ(read_points_from_memory(stl_binary(signed_zeros, ""), MeshFormat::stl_binary, "z")
                .points.size(),
            4U);
}

// A PLY whose vertex element is preceded by another element (with a list) and
// carries properties of every type around x, y, z: all must be skipped by
// their type for the coordinates to come out right.
struct PlySample {
  std::string header;
  std::vector<Vec3> points;  // as stored (y is a float)
};

PlySample ply_sample(std::uint64_t seed, const std::string& format) {
  PlySample s;
  s.points = random_points(seed, 12, kFloatExponent);
  for (Vec3& p : s.points) p.y() = to_floats({p})[0].y();
  s.header =
      "ply\nformat " + format +
      " 1.0\ncomment generated by io_test\nobj_info nothing\n"
      "element material 2\nproperty uchar id\nproperty list uchar int indices\nproperty float "
      "shine\n"
      "element vertex " +
      std::to_string(s.points.size()) +
      "\nproperty uchar red\nproperty double x\nproperty list ushort short tags\nproperty float y\n"
      "property int16 s\nproperty uint u\nproperty char c\nproperty double z\nproperty float64 "
      "extra\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  return s;
}

TEST_F(IoTest, PlyAsciiSkipsOtherPropertiesAndElements) {
  const PlySample s = ply_sample(7, "ascii");
  std::string ply = s.header + "0 3 1 2 3 0.5\n1 0 0.25\n";
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3& p = s.points[i];
    ply += "200 " + text(p.x()) + " " + std::to_string(i % 3) + (i % 3 > 0 ? " -7" : "") +
           (i % 3 > 1 ? " 9" : "") + " " + text(p.y()) + " -3 4000000000 -100 " + text(p.z()) +
           " 1e300\n";
  }
  ply += "3 0 1 2\n";
  const PointCloud cloud = read_points(write("mesh.ply", ply));
  EXPECT_EQ(cloud.format, MeshFormat::ply_ascii);
  expect_same_points(cloud.points, s.points);
}

TEST_F(IoTest, PlyBinarySkipsOtherPropertiesAndElements) {
  const PlySample s = ply_sample(8, "binary_little_endian");
  std::string ply = s.header;
  for (std::uint8_t m = 0; m < 2; ++m) {
    put(ply, m);
    put(ply, std::uint8_t{m});  // m indices
    for (std::uint8_t j = 0; j < m; ++j) put(ply, std::int32_t{-1});
    put(ply, 0.5F);
  }
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3& p = s.points[i];
    put(ply, std::uint8_t{200});
    put(ply, p.x());
    put(ply, static_cast<std::uint16_t>(i % 3));
    for (std::size_t j = 0; j < i % 3; ++j) put(ply, std::int16_t{-7});
    put(ply, static_cast<float>(p.y()));
    put(ply, std::int16_t{-3});
    put(ply, std::uint32_t{4000000000U});
    put(ply, std::int8_t{-100});
    put(ply, p.z());
    put(ply, 1e300);
  }
  put(ply, std::uint8_t{3});
  for (std::int32_t k = 0; k < 3; ++k) put(ply, k);
  const PointCloud cloud = read_points(write("mesh.ply", ply));
  EXPECT_EQ(cloud.format, MeshFormat::ply_binary_le);
  expect_same_points(cloud.points, s.points);
}

TEST_F(IoTest, PlyIntegerCoordinatesAreRead) {
  std::string ply =
      "ply\r\nformat binary_little_endian 1.0\r\nelement vertex 2\r\nproperty int x\r\n"
      "property short y\r\nproperty uchar z\r\nend_header\r\n";
  put(ply, std::int32_t{-2000000000});
  put(ply, std::int16_t{-32768});
  put(ply, std::uint8_t{255});
  put(ply, std::int32_t{7});
  put(ply, std::int16_t{32767});
  put(ply, std::uint8_t{0});
  const PointCloud cloud = read_points_from_memory(ply, MeshFormat::ply_binary_le, "ints.ply");
  expect_same_points(cloud.points, {Vec3(-2000000000.0, -32768.0, 255.0), Vec3(7.0, 32767.0, 0.0)});
}

TEST_F(IoTest, CoordinatesAreCorrectlyRounded) {
  // Decimal strings that a naive parser (mantissa * 10^e, digit by digit)
  // gets wrong in the last bit; the compiler's own conversion of the same
  // literal is the oracle. 9007199254740993 = 2^53 + 1 is a tie: to even.
  const std::string xyz =
      "0.1 0.2 0.30000000000000004\n"
      "2.2250738585072011e-308 1.7976931348623157e308 4.9406564584124654e-324\n"
      "9007199254740993 1.2345678901234567e-23 -3.0000000000000001e39\n"
      "+123456789012345678901234567890 .5e-1 7.\n";
  const PointCloud cloud = read_points_from_memory(xyz, MeshFormat::xyz, "literals");
  expect_same_points(
      cloud.points, {Vec3(0.1, 0.2, 0.30000000000000004),
                     Vec3(2.2250738585072011e-308, 1.7976931348623157e308, 4.9406564584124654e-324),
                     Vec3(0x1p53, 1.2345678901234567e-23, -3.0000000000000001e39),
                     Vec3(123456789012345678901234567890.0, 0.05, 7.0)});
}

TEST_F(IoTest, FormatIsSniffedWhenTheExtensionSaysNothing) {
  const auto points = random_points(9, 10);
  std::string obj;
  std::string xyz;
  std::string off = "OFF\n" + std::to_string(points.size()) + " 0 0\n";
  for (const Vec3& p : points) {
    obj += "v " + text(p) + "\n";
    xyz += text(p) + "\n";
    off += text(p) + "\n";
  }
  const auto tris = triangles_over(to_floats(random_points(9, 10, kFloatExponent)));
  const PlySample ply = ply_sample(10, "ascii");
  std::string ply_text = ply.header + "0 0 0.5\n1 0 0.5\n";
  for (const Vec3& p : ply.points)
    ply_text += "1 " + text(p.x()) + " 0 " + text(p.y()) + " 0 0 0 " + text(p.z()) + " 0\n";

  const std::vector<std::pair<std::string, MeshFormat>> cases = {
      {"# comment\n" + obj, MeshFormat::obj},
      {xyz, MeshFormat::xyz},
      {off, MeshFormat::off},
      {stl_ascii(tris), MeshFormat::stl_ascii},
      {stl_binary(tris, "solid"), MeshFormat::stl_binary},
      {ply_text, MeshFormat::ply_ascii}};
  int i = 0;
  for (const auto& [bytes, format] : cases) {
    SCOPED_TRACE(to_string(format));
    EXPECT_EQ(read_points(write("mesh" + std::to_string(i++) + ".dat", bytes)).format, format);
    EXPECT_EQ(read_points_from_memory(bytes, MeshFormat::unknown, "memory").format, format);
  }
}

TEST_F(IoTest, ExtensionIsCaseInsensitive) {
  EXPECT_EQ(read_points(write("UPPER.OBJ", "v 1 2 3\n")).format, MeshFormat::obj);
  EXPECT_EQ(read_points(write("points.TXT", "1 2 3\n")).format, MeshFormat::xyz);
}

// Issue 9: the groups of an OBJ file with faces were taken from the order of
// its `v` lines, as if each group owned the vertices listed after its
// statement. In OBJ the vertices are global and `g`/`o` group the faces: a
// file that lists every vertex first and then each group's faces (a common
// exporter layout) came back as one group "" of every point.
TEST_F(IoTest, ObjFacesAreGroupedWithGlobalVertices) {
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\n"
      "g left\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2/7/1 3//2 4/1\n"
      "o right\nf -4 -2 -3 # relative indices: vertices 5 7 6\nf 5 6 8 7\n";
  const PointCloud cloud = read_points_from_memory(obj, MeshFormat::obj, "split.obj");
  EXPECT_EQ(cloud.points.size(), 8U);
  EXPECT_EQ(cloud.group_names, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(cloud.group_offsets, (std::vector<std::int32_t>{0, 4}));
  using Tri = std::array<std::int32_t, 3>;
  ASSERT_EQ(cloud.triangles.size(), 7U);  // the quad is a fan of two
  EXPECT_EQ(cloud.triangles[3], (Tri{1, 2, 3}));
  EXPECT_EQ(cloud.triangles[4], (Tri{4, 6, 5}));
  EXPECT_EQ(cloud.triangles[5], (Tri{4, 5, 7}));
  EXPECT_EQ(cloud.triangles[6], (Tri{4, 7, 6}));
}

TEST_F(IoTest, ObjFaceErrorsNameTheLine) {
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", MeshFormat::obj,
                                           "f.obj");
                 }),
                 {"f.obj, line 4", "'4'", "3 vertices read so far"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::obj,
                                           "f.obj");
                 }),
                 {"line 4", "start at 1"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", MeshFormat::obj,
                                           "f.obj");
                 }),
                 {"line 4", "'-4'"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\nv 1 0 0\nf 1 2\n", MeshFormat::obj, "f.obj");
                 }),
                 {"line 3", "face with 2 vertices"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 2\n", MeshFormat::obj,
                                           "f.obj");
                 }),
                 {"line 4", "'x'", "not an integer"});
}

// ---------------------------------------------------------------------------
// Size limit.

// Issue 9: `proxima hull /dev/zero` grew its buffer until bad_alloc. Every
// read now stops at ReadOptions::max_file_bytes, counted as read for files
// whose size is not known in advance.
TEST_F(IoTest, FilesLargerThanTheLimitAreRefused) {
  ReadOptions small;
  small.max_file_bytes = 1 << 20;
  if (std::filesystem::exists("/dev/zero")) {
    expect_message(expect_file_error([&] { read_points("/dev/zero", small); }),
                   {"/dev/zero", "file too large", "1048576 bytes"});
  }
  small.max_file_bytes = 10;
  const std::string path = write("eleven.xyz", "0 0 0\n1 1 \n");
  expect_message(expect_file_error([&] { read_points(path, small); }),
                 {"eleven.xyz", "file too large", "11 bytes", "10 bytes"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("0 0 0\n1 1 1\n", MeshFormat::xyz, "m", small);
                 }),
                 {"m: file too large", "10 bytes"});
  small.max_file_bytes = 11;
  EXPECT_THROW(read_points(path, small),
               FileError);  // read, and refused for its content (a short line)
  EXPECT_EQ(kDefaultMaxFileBytes, std::uint64_t{1} << 30);
}

// ---------------------------------------------------------------------------
// load_convex.

TEST_F(IoTest, CubeWithAnInteriorPointReportsOneInteriorPoint) {
  std::string cube;
  for (int i = 0; i < 8; ++i) cube += "v " + cube_corner_text(i) + "\n";
  const LoadedPolytope convex = load_convex(write("cube.obj", cube));
  EXPECT_EQ(convex.input_points, 8);
  EXPECT_EQ(convex.interior_points, 0);
  EXPECT_TRUE(convex.input_was_convex);
  EXPECT_EQ(convex.polytope.vertex_count(), 8);

  const LoadedPolytope with_inside =
      load_convex(write("cube_inside.obj", cube + "v 0.25 -0.5 0.125\n"));
  EXPECT_EQ(with_inside.input_points, 9);
  EXPECT_EQ(with_inside.interior_points, 1);
  EXPECT_FALSE(with_inside.input_was_convex);
  EXPECT_EQ(with_inside.polytope.vertex_count(), 8);
}

// input_was_convex means the input surface is convex (io.h). Issue 9: it
// meant "every input point is a hull vertex", so a mesh whose vertices are
// all on its hull but whose faces fold inwards reported convex (the Panda's
// collision meshes, below), and a point on a hull face reported not convex.
std::string cube_obj_with_faces(const std::string& extra_faces) {
  std::string obj;
  for (int i = 0; i < 8; ++i) obj += "v " + cube_corner_text(i) + "\n";
  // Outward triangles of the cube whose corner i has bits (x, y, z).
  obj +=
      "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf "
      "2 4 8\nf 2 8 6\n";
  return obj + extra_faces;
}

TEST_F(IoTest, FoldedMeshIsNotConvexThoughEveryVertexIsOnTheHull) {
  const LoadedPolytope cube = load_convex(write("cube.obj", cube_obj_with_faces("")));
  EXPECT_EQ(cube.interior_points, 0);
  EXPECT_TRUE(cube.input_was_convex);
  // A triangle through the inside of the cube, between three hull vertices.
  const LoadedPolytope folded = load_convex(write("folded.obj", cube_obj_with_faces("f 1 4 6\n")));
  EXPECT_EQ(folded.interior_points, 0);
  EXPECT_FALSE(folded.input_was_convex);
}

TEST_F(IoTest, DentedFaceIsNotConvexAFlatSubdividedFaceIs) {
  // The top face (z = 1) split into four triangles around its centre. At
  // z = 1 the centre lies on the hull's face: convex, though it is not a hull
  // vertex. Pushed in by 1e-3 (a fold like the Panda's), it is not.
  const std::string sides =
      "f 1 3 4\nf 1 4 2\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
  const std::string top = "f 5 6 9\nf 6 8 9\nf 8 7 9\nf 7 5 9\n";
  std::string corners;
  for (int i = 0; i < 8; ++i) corners += "v " + cube_corner_text(i) + "\n";
  const LoadedPolytope flat = load_convex(write("flat.obj", corners + "v 0 0 1\n" + sides + top));
  EXPECT_EQ(flat.interior_points, 1);
  EXPECT_TRUE(flat.input_was_convex);
  const LoadedPolytope dented =
      load_convex(write("dented.obj", corners + "v 0 0 0.999\n" + sides + top));
  EXPECT_FALSE(dented.input_was_convex);
}

TEST_F(IoTest, IcosahedronIsConvexAsObjAndAsFloatStl) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v;
  for (const double a : {-1.0, 1.0}) {
    for (const double b : {-phi, phi}) {
      v.emplace_back(0, a, b);
      v.emplace_back(a, b, 0);
      v.emplace_back(b, 0, a);
    }
  }
  // The 20 faces: triples of mutually adjacent vertices (edge length 2).
  std::vector<std::array<int, 3>> faces;
  const auto adjacent = [&](int i, int j) {
    return std::abs((v[static_cast<std::size_t>(i)] - v[static_cast<std::size_t>(j)]).norm() -
                    2.0) < 1e-9;
  };
  for (int i = 0; i < 12; ++i) {
    for (int j = i + 1; j < 12; ++j) {
      for (int k = j + 1; k < 12; ++k) {
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) faces.push_back({i, j, k});
      }
    }
  }
  ASSERT_EQ(faces.size(), 20U);
  std::string obj;
  for (const Vec3& p : v) obj += "v " + text(p) + "\n";
  std::vector<std::array<Vec3, 3>> tris;
  for (const auto& f : faces) {
    obj += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " +
           std::to_string(f[2] + 1) + "\n";
    tris.push_back({v[static_cast<std::size_t>(f[0])], v[static_cast<std::size_t>(f[1])],
                    v[static_cast<std::size_t>(f[2])]});
  }
  EXPECT_TRUE(load_convex(write("ico.obj", obj)).input_was_convex);
  EXPECT_TRUE(load_convex(write("ico.stl", stl_binary(tris, "ico"))).input_was_convex);
}

TEST_F(IoTest, PointCloudIsConvexWhenEveryPointIsOnTheHullBoundary) {
  std::string xyz;
  for (int i = 0; i < 8; ++i) xyz += cube_corner_text(i) + "\n";
  EXPECT_TRUE(load_convex(write("on_face.xyz", xyz + "0.25 -1 0.125\n1 1 0.5\n")).input_was_convex);
  EXPECT_FALSE(load_convex(write("inside.xyz", xyz + "0.25 -0.999 0.125\n")).input_was_convex);
}

// The Panda's collision meshes (binary STL, metres; shipped in
// examples/data/panda) fold inwards by up to 1 mm: not convex.
TEST_F(IoTest, PandaLinkIsNotConvex) {
  const std::filesystem::path dir = PROXIMA_PANDA_MESH_DIR;
  const LoadedPolytope link = load_convex((dir / "link1.stl").string());
  EXPECT_EQ(link.polytope.dimension(), 3);
  EXPECT_FALSE(link.input_was_convex);
}

TEST_F(IoTest, ConvexStlIsConvexDespiteRepeatedCorners) {
  // 12 triangles, 36 corners, 8 distinct points: convex.
  std::vector<Vec3> c;
  for (int i = 0; i < 8; ++i)
    c.emplace_back((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
  const std::vector<std::array<int, 3>> faces = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5},
                                                 {0, 4, 5}, {0, 5, 1}, {2, 3, 7}, {2, 7, 6},
                                                 {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  std::vector<std::array<Vec3, 3>> tris;
  for (const auto& f : faces)
    tris.push_back({c[static_cast<std::size_t>(f[0])], c[static_cast<std::size_t>(f[1])],
                    c[static_cast<std::size_t>(f[2])]});
  for (const std::string& bytes : {stl_binary(tris, "cube"), stl_ascii(tris)}) {
    const LoadedPolytope loaded = load_convex(write("cube.stl", bytes));
    EXPECT_EQ(loaded.input_points, 8);
    EXPECT_TRUE(loaded.input_was_convex);
    EXPECT_EQ(loaded.polytope.vertex_count(), 8);
  }
}

// ---------------------------------------------------------------------------
// Errors: file, place, problem.

TEST_F(IoTest, MissingFileAndDirectory) {
  const std::string missing = (dir_ / "nowhere.obj").string();
  FileError e = expect_file_error([&] { read_points(missing); });
  expect_message(e, {missing, "no such file"});
  EXPECT_EQ(e.file(), missing);
  EXPECT_EQ(e.line(), 0);
  EXPECT_EQ(e.byte_offset(), -1);
  expect_message(expect_file_error([&] { read_points(dir_.string()); }),
                 {dir_.string(), "directory"});
  expect_message(expect_file_error([&] { load_convex(missing); }), {missing, "no such file"});
}

TEST_F(IoTest, UnknownFormat) {
  const std::string path = write("notes.foo", "hello world\nthis is not a mesh\n");
  expect_message(expect_file_error([&] { read_points(path); }),
                 {"notes.foo", "unknown format", "'.foo'"});
  expect_message(
      expect_file_error([&] { read_points_from_memory("hello", MeshFormat::unknown, "blob"); }),
      {"blob", "unknown format"});
}

TEST_F(IoTest, TruncatedBinaryStl) {
  const std::string full =
      stl_binary(triangles_over(to_floats(random_points(11, 11, kFloatExponent))), "binary");
  ASSERT_EQ(full.size(), 84U + 50U * 12U);
  const std::string path = write("cut.stl", full.substr(0, 600));
  const FileError e = expect_file_error([&] { read_points(path); });
  expect_message(e, {"cut.stl", "byte 600", "truncated binary STL", "12 triangles",
                     "expected 684 bytes", "got 600"});
  EXPECT_EQ(e.byte_offset(), 600);
  EXPECT_EQ(e.line(), 0);

  expect_message(expect_file_error([&] {
                   read_points_from_memory(full.substr(0, 50), MeshFormat::stl_binary, "s");
                 }),
                 {"truncated binary STL", "at least 84 bytes", "got 50"});
  expect_message(
      expect_file_error([&] { read_points_from_memory(full + "xx", MeshFormat::stl_binary, "s"); }),
      {"byte 684", "size mismatch", "got 686"});
}

TEST_F(IoTest, NonNumericTokenNamesTheLine) {
  // The bad token sits on line 7 of every text format (line 9 in PLY, whose
  // header alone takes 7 lines).
  const std::vector<std::tuple<std::string, std::string, std::int64_t>> files = {
      {"bad.obj", "# 1\n# 2\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\nv 1 abc 3\n", 7},
      {"bad.xyz", "0 0 0\n1 0 0\n0 1 0\n\n# five\n1 1 1\n1 abc 3\n", 7},
      {"bad.off", "OFF\n# c\n5 0 0\n0 0 0\n1 0 0\n0 1 0\n1 abc 3\n0 0 1\n", 7},
      {"bad.stl",
       "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex "
       "1 abc 3\n",
       7},
      {"bad.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "end_header\n0 0 0 1\n0 0 1 abc 3\n",
       9}};
  for (const auto& [name, bytes, line] : files) {
    SCOPED_TRACE(name);
    const std::string path = write(name, bytes);
    const FileError e = expect_file_error([&] { read_points(path); });
    expect_message(e, {name, "line " + std::to_string(line), "non-numeric token 'abc'"});
    EXPECT_EQ(e.line(), line);
  }
}

TEST_F(IoTest, NanAndInfiniteCoordinatesNameLineAndVertex) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n# the next is vertex 3\nv 0.5 nan 0\n";
  const FileError e = expect_file_error([&] { read_points(write("nan.obj", obj)); });
  expect_message(e, {"nan.obj", "line 5", "NaN coordinate", "y of vertex 3"});
  expect_message(expect_file_error([&] { read_points(write("inf.xyz", "0 0 0\n1 2 -inf\n")); }),
                 {"inf.xyz", "line 2", "infinite coordinate", "z of vertex 1"});
  expect_message(expect_file_error([&] { read_points(write("big.xyz", "1e999 0 0\n")); }),
                 {"line 1", "'1e999'", "outside the range of double"});

  // Binary: the byte offset of the bad float or double.
  std::vector<std::array<Vec3, 3>> tris = {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                                           {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)}};
  tris[1][2].z() =
      std::numeric_limits<double>::quiet_NaN();  // written as a float NaN, no arithmetic
  const std::size_t nan_offset = 84 + 50 + 12 + 2 * 12 + 8;
  const FileError s =
      expect_file_error([&] { read_points(write("nan.stl", stl_binary(tris, "b"))); });
  expect_message(s, {"nan.stl", "byte " + std::to_string(nan_offset), "NaN coordinate",
                     "z of corner 2 of triangle 1"});
  EXPECT_EQ(s.byte_offset(), static_cast<std::int64_t>(nan_offset));

  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double "
      "y\n"
      "property double z\nend_header\n";
  const std::size_t header = ply.size();
  for (double v : {0.0, 1.0, 2.0, 3.0, -std::numeric_limits<double>::infinity(), 5.0}) put(ply, v);
  expect_message(
      expect_file_error(
          [&] { read_points_from_memory(ply, MeshFormat::ply_binary_le, "inf.ply"); }),
      {"inf.ply", "byte " + std::to_string(header + 32), "infinite coordinate", "y of vertex 1"});
}

TEST_F(IoTest, EmptyMesh) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"empty.obj", "# nothing\nvn 0 0 1\ng empty\n"},
      {"empty.xyz", ""},
      {"empty.off", "OFF\n0 0 0\n"},
      {"empty.stl", "solid nothing\nendsolid nothing\n"},
      {"empty.ply",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty "
       "float z\nend_header\n"}};
  for (const auto& [name, bytes] : files) {
    SCOPED_TRACE(name);
    const std::string path = write(name, bytes);
    expect_message(expect_file_error([&] { read_points(path); }),
                   {name, "empty mesh (no vertices)"});
  }
  expect_message(expect_file_error([&] { read_points(write("zero.stl", stl_binary({}, "zero"))); }),
                 {"zero.stl", "empty mesh"});
}

TEST_F(IoTest, PlyHeaderErrors) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::vector<std::tuple<std::string, std::int64_t, std::string>> cases = {
      {"plx\nformat ascii 1.0\n", 1, "not a PLY file"},
      {"ply\nformat binary_big_endian 1.0\nelement vertex 1\n" + xyz + "end_header\n", 2,
       "binary_big_endian is not supported"},
      {"ply\nformat ascii 2.0\n", 2, "unsupported PLY version '2.0'"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n", 4,
       "unknown PLY type 'float128'"},
      {"ply\nformat ascii 1.0\nproperty float x\n", 3, "property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex -5\n", 3,
       "element count '-5' is not a non-negative integer"},
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz, 6, "no end_header"},
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz + "0 0 0\n", 7,
       "unknown PLY header keyword '0' (is end_header missing?)"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n3 0 1 2\n", 5,
       "no 'vertex' element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 "
       "0\n",
       3, "no property 'z'"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\n", 5,
       "duplicate PLY property 'x'"},
      {"ply\nformat ascii 1.0\nelement f 1\nproperty list float int v\n", 4, "not an integer type"},
      {"ply\nelement vertex 1\n" + xyz + "end_header\n0 0 0\n", 6, "no format line"},
      {"ply\nformat ascii 1.0\nvertex 3\n", 3, "unknown PLY header keyword 'vertex'"},
  };
  for (const auto& [bytes, line, problem] : cases) {
    SCOPED_TRACE(problem);
    const std::string path = write("header.ply", bytes);
    const FileError e = expect_file_error([&] { read_points(path); });
    expect_message(e, {"header.ply", "line " + std::to_string(line), problem});
    EXPECT_EQ(e.line(), line);
  }
}

TEST_F(IoTest, CountMismatches) {
  expect_message(
      expect_file_error([&] {
        read_points(write("short.off", "OFF\n8 6 12\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"));
      }),
      {"short.off", "line 7", "(line 2) announces 8 vertices", "ends after 5"});
  expect_message(
      expect_file_error([&] {
        read_points(
            write("short.ply",
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"));
      }),
      {"short.ply", "line 10", "ends inside 'vertex' element 3", "of the 4 the header announces"});

  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  const std::size_t header = ply.size();
  for (int i = 0; i < 8; ++i) put(ply, 1.0F);
  expect_message(expect_file_error(
                     [&] { read_points_from_memory(ply, MeshFormat::ply_binary_le, "short.ply"); }),
                 {"short.ply", "byte " + std::to_string(header + 32), "truncated PLY",
                  "3 'vertex' elements of at least 12 bytes", "only 32 bytes follow"});

  expect_message(
      expect_file_error([&] {
        read_points(write("quad.stl",
                          "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                          "vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid q\n"));
      }),
      {"quad.stl", "line 8", "facet at line 2 has 4 vertices", "triangles"});
  expect_message(
      expect_file_error([&] {
        read_points(write("open.stl",
                          "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"));
      }),
      {"open.stl", "line 5", "ends inside the facet opened at line 2"});
  expect_message(expect_file_error([&] { read_points(write("two.xyz", "0 0 0\n1 2\n")); }),
                 {"two.xyz", "line 2", "expected 3 coordinates for vertex 1", "found 2"});
  expect_message(expect_file_error(
                     [&] { read_points(write("bad.stl", "solid q\nfacet normal 0 0 1\nloop\n")); }),
                 {"bad.stl", "line 3", "unexpected 'loop'", "'outer loop'"});
}

TEST_F(IoTest, LyingHeaderCountsAreRefusedWithoutAllocating) {
  // Counts far beyond what the file can hold: refused from the size, fast,
  // with no allocation sized by the count (ASan would report a huge one).
  std::string stl(84, ' ');
  stl[80] = stl[81] = stl[82] = stl[83] = '\xff';
  expect_message(
      expect_file_error([&] { read_points_from_memory(stl, MeshFormat::stl_binary, "liar.stl"); }),
      {"liar.stl", "truncated binary STL", "4294967295 triangles", "expected 214748364834 bytes",
       "got 84"});

  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement face 4000000000\nproperty list uint int v\n"
      "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  put(ply, 1.0);
  expect_message(
      expect_file_error(
          [&] { read_points_from_memory(ply, MeshFormat::ply_binary_le, "liar.ply"); }),
      {"liar.ply", "truncated PLY", "4000000000 'face' elements", "only 8 bytes follow"});

  std::string list =
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uint int v\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  const std::size_t header = list.size();
  put(list, std::uint32_t{3000000000U});
  for (int i = 0; i < 3; ++i) put(list, 1.0F);
  expect_message(expect_file_error(
                     [&] { read_points_from_memory(list, MeshFormat::ply_binary_le, "list.ply"); }),
                 {"byte " + std::to_string(header), "list 'v'", "3000000000 items"});

  expect_message(expect_file_error([&] {
                   read_points_from_memory(
                       "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n0 0 0\n",
                       MeshFormat::ply_ascii, "many.ply");
                 }),
                 {"many.ply", "line 3", "99999999999 vertices, more than 2147483647"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory(
                       "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n0 0 0\n",
                       MeshFormat::ply_ascii, "ascii.ply");
                 }),
                 {"ascii.ply", "line 8", "ends inside 'vertex' element 1"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("OFF\n2000000000 0 0\n1 2 3\n", MeshFormat::off,
                                           "liar.off");
                 }),
                 {"liar.off", "announces 2000000000 vertices", "ends after 1"});
  // An element without properties takes no bytes, whatever its count.
  std::string hollow =
      "ply\nformat binary_little_endian 1.0\nelement nothing 18446744073709551615\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (int i = 0; i < 3; ++i) put(hollow, 2.0F);
  EXPECT_EQ(read_points_from_memory(hollow, MeshFormat::ply_binary_le, "hollow.ply").points.size(),
            1U);
}

TEST_F(IoTest, TextErrorsInOddFiles) {
  // NUL byte: not text. Old Mac line ends still count lines.
  expect_message(expect_file_error([&] {
                   read_points_from_memory(std::string("v 0 0 0\nv 1\0 2 3\n", 17), MeshFormat::obj,
                                           "nul.obj");
                 }),
                 {"nul.obj", "line 2", "NUL byte"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("v 0 0 0\rv 1 0 0\rv 0 x 0\r", MeshFormat::obj,
                                           "mac.obj");
                 }),
                 {"mac.obj", "line 3", "'x'"});
  // A long junk token is cut in the message.
  const FileError e = expect_file_error([&] {
    read_points_from_memory("1 2 " + std::string(5000, 'q') + "\n", MeshFormat::xyz, "junk");
  });
  EXPECT_LT(std::string(e.what()).size(), 200U);
  expect_message(e, {"junk", "line 1", "'qqqq", "...'"});
  expect_message(expect_file_error([&] {
                   read_points_from_memory("4OFF\n1 0 0\n1 2 3 4\n", MeshFormat::off, "4d.off");
                 }),
                 {"4d.off", "line 1", "unsupported OFF variant '4OFF'"});
  expect_message(expect_file_error(
                     [&] { read_points_from_memory("OFF\nabc 0 0\n", MeshFormat::off, "c.off"); }),
                 {"c.off", "line 2", "vertex count 'abc'"});
}

// ---------------------------------------------------------------------------
// Robustness: seeded mutations of valid files, every format. Only
// InvalidInput may come out; whatever is read must be finite and the groups
// well formed. The test main's floating-point traps make an invalid
// operation inside a reader fail here too.

std::vector<std::string> valid_samples() {
  const auto points = random_points(12, 6, kFloatExponent);
  std::string obj = "v 0 0 0\no a\n";
  std::string xyz;
  std::string off = "OFF\n" + std::to_string(points.size()) + " 0 0\n";
  for (const Vec3& p : points) {
    obj += "v " + text(p) + "\ng b c\n";
    xyz += text(p) + "\n";
    off += text(p) + "\n";
  }
  const auto tris = triangles_over(to_floats(points));
  const PlySample ascii = ply_sample(13, "ascii");
  std::string ply_text = ascii.header + "0 1 7 0.5\n1 0 0.5\n";
  for (const Vec3& p : ascii.points)
    ply_text += "1 " + text(p.x()) + " 1 3 " + text(p.y()) + " 0 0 0 " + text(p.z()) + " 0\n";
  std::string ply_binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty uchar k\n"
      "property list uchar short l\nproperty double y\nproperty float z\nend_header\n";
  for (int i = 0; i < 3; ++i) {
    put(ply_binary, 1.5F * static_cast<float>(i));
    put(ply_binary, std::uint8_t{1});
    put(ply_binary, std::uint8_t{1});
    put(ply_binary, std::int16_t{-1});
    put(ply_binary, 0.25 * i);
    put(ply_binary, 2.0F);
  }
  return {obj, xyz, off, stl_ascii(tris), stl_binary(tris, "solid"), ply_text, ply_binary};
}

TEST_F(IoTest, MutatedFilesRaiseOnlyInvalidInput) {
  const std::vector<std::string> samples = valid_samples();
  for (const std::string& s : samples)
    ASSERT_NO_THROW(read_points_from_memory(s, MeshFormat::unknown, "sample"));

  constexpr std::array<MeshFormat, 8> kFormats = {MeshFormat::obj,       MeshFormat::off,
                                                  MeshFormat::stl_ascii, MeshFormat::stl_binary,
                                                  MeshFormat::ply_ascii, MeshFormat::ply_binary_le,
                                                  MeshFormat::xyz,       MeshFormat::unknown};
  using namespace std::string_literals;
  const std::string interesting = " \n\r\t0123456789.-+eE#nafiNAF,\0\xff"s;
  std::mt19937_64 rng(20240601);
  int read_ok = 0;
  int refused = 0;
  for (int round = 0; round < 400; ++round) {
    for (const std::string& sample : samples) {
      std::string bytes = sample;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < edits && !bytes.empty(); ++k) {
        const std::size_t at = rng() % bytes.size();
        switch (rng() % 5) {
          case 0:
            bytes[at] = static_cast<char>(rng());
            break;
          case 1:
            bytes[at] = interesting[rng() % interesting.size()];
            break;
          case 2:
            bytes.insert(at, 1, interesting[rng() % interesting.size()]);
            break;
          case 3:
            bytes.erase(at, 1 + rng() % 8);
            break;
          default:
            bytes.resize(at);
            break;
        }
      }
      for (const MeshFormat format : kFormats) {
        try {
          const PointCloud cloud = read_points_from_memory(bytes, format, "mutant");
          ASSERT_FALSE(cloud.points.empty());
          for (const Vec3& p : cloud.points) ASSERT_TRUE(p.allFinite());
          ASSERT_EQ(cloud.group_names.size(), cloud.group_offsets.size());
          for (std::size_t g = 0; g < cloud.group_offsets.size(); ++g) {
            ASSERT_EQ(cloud.group_offsets[g] == 0, g == 0);
            // Groups range over the triangles when there are any, else the points.
            const std::size_t items =
                cloud.triangles.empty() ? cloud.points.size() : cloud.triangles.size();
            ASSERT_LT(cloud.group_offsets[g], static_cast<std::int32_t>(items));
            if (g > 0) {
              ASSERT_LT(cloud.group_offsets[g - 1], cloud.group_offsets[g]);
            }
          }
          ++read_ok;
        } catch (const InvalidInput&) {
          ++refused;
        }
      }
    }
  }
  // Both outcomes must occur often, or the mutations test nothing (most
  // mutants are read as the wrong format and refused: 770 of 22400 read).
  EXPECT_GT(read_ok, 300);
  EXPECT_GT(refused, 10000);
}

// Issue 12: a file as a triangle mesh, as given. A closed cube mesh is
// closed; the same without two faces is open; a point cloud or a format
// whose faces are not read is refused with the reason; a bad face index
// names the file and the triangle.
TEST_F(IoTest, LoadMeshKeepsTheFacesAndRefusesWhatHasNone) {
  const LoadedMesh cube = load_mesh(write("cube_mesh.obj", cube_obj_with_faces("")));
  EXPECT_EQ(cube.mesh.triangle_count(), 12);
  EXPECT_EQ(cube.input_points, 8);
  EXPECT_TRUE(cube.closed);
  EXPECT_EQ(cube.degenerate_triangles, 0);
  std::string open = cube_obj_with_faces("");
  open = open.substr(0, open.rfind("f 2 4 8"));
  const LoadedMesh opened = load_mesh(write("open_mesh.obj", open));
  EXPECT_EQ(opened.mesh.triangle_count(), 10);
  EXPECT_FALSE(opened.closed);
  const LoadedMesh sliver = load_mesh(write("sliver.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"));
  EXPECT_EQ(sliver.degenerate_triangles, 1);

  const auto message = [](auto&& run) -> std::string {
    try {
      run();
    } catch (const FileError& e) {
      return e.what();
    }
    return "no FileError";
  };
  const std::string cloud = write("cloud.xyz", "0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_NE(message([&] { load_mesh(cloud); }).find("no faces to make a mesh of"),
            std::string::npos)
      << message([&] { load_mesh(cloud); });
  const std::string off = write("tet.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n");
  EXPECT_NE(message([&] { load_mesh(off); }).find("reads points only"), std::string::npos)
      << message([&] { load_mesh(off); });
  const std::string no_faces = write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_NE(message([&] { load_mesh(no_faces); }).find("load it as its hull"), std::string::npos);
}

}  // namespace
}  // namespace proxima
