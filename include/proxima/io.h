// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: mesh file readers. They turn a file into a point list (and, for
// OBJ, the groups that a compound body is made of); the algorithms never see
// files.
//
// Formats: Wavefront OBJ (`v` and `f` lines; `g`/`o` statements group the
// faces, see PointCloud), OFF
// (and its C/N/ST variants, extra columns ignored), ASCII and binary STL,
// PLY (ascii and binary_little_endian; the vertex element's x, y, z, any
// other property skipped by its type, faces ignored) and plain XYZ (one point
// per line, at least three numbers, extra columns ignored, `#` comments).
// The hull is always recomputed from the points. Faces are read from OBJ
// (`f`, polygons fan-triangulated) and STL (the facets), for the groups and
// the convexity report; OFF and PLY faces are skipped.
//
// Every coordinate is parsed with a correctly rounded conversion, so a file
// written with round-trip precision (17 significant digits) gives back the
// very doubles that were written. STL stores each facet's corners
// separately: exact duplicates are merged (first appearance order) so that a
// convex STL is not mistaken for a point set with interior points.
//
// Errors are FileError (an InvalidInput) with one message that names the
// file, the line (text formats) or byte offset (binary formats) and the
// problem. A header count never drives an allocation or a loop beyond what
// the file's size can hold, and no file larger than ReadOptions::
// max_file_bytes is read (counted as read, so /dev/zero and pipes stop too).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/polytope.h"

namespace proxima {

enum class MeshFormat : std::uint8_t {
  obj,
  off,
  stl_ascii,
  stl_binary,
  ply_ascii,
  ply_binary_le,
  xyz,
  unknown
};

const char* to_string(MeshFormat format);

struct PointCloud {
  std::vector<Vec3> points;
  MeshFormat format =
      MeshFormat::unknown;  // the format actually read (sniffed when asked with unknown)
  std::string source;       // the path or name given to the reader
  // The faces, fan-triangulated, as indices into `points`: OBJ `f` lines
  // (indices resolved, negative ones relative to the vertices read so far)
  // and STL facets (corners merged as above). Empty for OFF, PLY and XYZ,
  // whose faces are not read, and for an OBJ file without `f` lines.
  std::vector<std::array<std::int32_t, 3>> triangles;
  // OBJ groups (`g` and `o` statements), in file order. In OBJ the vertices
  // are global and the statements group the faces, so:
  // - with faces (`triangles` non-empty), group i holds the triangles
  //   [group_offsets[i], group_offsets[i + 1]), and its piece is made of the
  //   vertices those reference, wherever in the file they were listed (a
  //   file listing every `v` first, then each group's faces, splits by
  //   group). Vertices no face references belong to no group.
  // - without faces (a point-cloud OBJ), group i holds the points
  //   [group_offsets[i], group_offsets[i + 1]): the `v` lines after its
  //   statement.
  // The last group runs to the end. Empty when the file has no groups;
  // otherwise the groups cover every triangle (or point), each is non-empty,
  // group_offsets[0] == 0, and what comes before the first statement forms a
  // group named "". A later statement with nothing in between renames the
  // group (so `o body` then `g part` is one group "part").
  std::vector<std::string> group_names;
  std::vector<std::int32_t> group_offsets;
};

// What a reader may take. max_file_bytes bounds the bytes read from a file
// or given in memory; more is refused with a FileError naming the limit
// (before reading, for a regular file; as soon as it is passed, for a pipe
// or a device such as /dev/zero).
inline constexpr std::uint64_t kDefaultMaxFileBytes = std::uint64_t{1} << 30;  // 1 GiB
struct ReadOptions {
  std::uint64_t max_file_bytes = kDefaultMaxFileBytes;
};

// A read failure. what() is "<file>, line <n>: <problem>", "<file>, byte
// <offset>: <problem>" or "<file>: <problem>".
class FileError : public InvalidInput {
 public:
  static FileError at_line(std::string file, std::int64_t line, std::string problem);
  static FileError at_byte(std::string file, std::int64_t byte_offset, std::string problem);
  static FileError in_file(std::string file, std::string problem);

  const std::string& file() const { return file_; }
  std::int64_t line() const { return line_; }                // 1-based; 0 when not about a line
  std::int64_t byte_offset() const { return byte_offset_; }  // 0-based; -1 when not about a byte
  const std::string& problem() const { return problem_; }

 private:
  FileError(std::string file, std::int64_t line, std::int64_t byte_offset, std::string problem);

  std::string file_;
  std::int64_t line_ = 0;
  std::int64_t byte_offset_ = -1;
  std::string problem_;
};

// Reads the points of a mesh file. The format comes from the extension
// (.obj .off .stl .ply .xyz .txt .pts, any case; ASCII or binary STL and PLY
// from the content); an unknown extension falls back to content sniffing.
PointCloud read_points(const std::string& path, const ReadOptions& options = {});

// The same from bytes in memory; `name` stands for the file in messages.
// MeshFormat::unknown sniffs the content. stl_ascii and stl_binary read the
// content as given; ply_ascii and ply_binary_le both accept either PLY
// encoding (the header says which) and report the one read.
PointCloud read_points_from_memory(std::string_view bytes, MeshFormat format,
                                   const std::string& name, const ReadOptions& options = {});

// Whether the input's surface is convex, i.e. already the boundary of its
// hull (`points` are the hull's input, `triangles` index them; an index
// outside them throws InvalidInput). With faces (OBJ `f`, STL facets; a
// vertex no face uses does not count): every triangle lies on the hull's
// boundary, in the plane of one hull facet: all three of its corners within
// kConvexSurfaceTolerance * hull.scale() of that facet's plane (they are in
// the hull, so then the triangle lies in the facet). A folded or dented
// mesh fails even when every vertex is a hull vertex. Without faces (a point
// cloud): every point is a hull vertex or within the same distance of the
// hull's boundary (a point on a face counts as convex, one inside does not).
// A hull of dimension below 3 is its own boundary: convex. The tolerance
// absorbs rounding, in particular STL's float32 corners (relative error
// 6e-8), and is far below real folds (the Panda's collision meshes fold by
// up to 1 mm at a scale of 0.2 m, a relative 5e-3).
inline constexpr double kConvexSurfaceTolerance = 1e-6;
bool surface_is_convex(const ConvexPolytope& hull, std::span<const Vec3> points,
                       std::span<const std::array<std::int32_t, 3>> triangles);

struct LoadedPolytope {
  ConvexPolytope polytope;
  int input_points = 0;  // points read from the file
  int interior_points =
      0;  // input points that are not hull vertices (inside, on a face, or repeated)
  bool input_was_convex =
      true;  // surface_is_convex (see above): the input surface is its hull's boundary
};

// read_points, then the hull of all the points (groups are not split). A
// non-convex input is reported, not refused.
LoadedPolytope load_convex(const std::string& path, const ReadOptions& options = {});

// What became of one group of a compound file: its name and how convex its
// points were (the piece is their hull either way).
struct LoadedPiece {
  std::string
      name;  // the OBJ group's name; "" for points before the first group or a file without groups
  int input_points =
      0;  // points of the group (with faces: the distinct vertices its faces reference)
  int interior_points = 0;       // of those, not hull vertices (inside, on a face, or repeated)
  bool input_was_convex = true;  // surface_is_convex for the group's points and faces
};

struct LoadedCompound {
  CompoundBody body;                // one piece per group, identity piece poses, in file order
  std::vector<LoadedPiece> pieces;  // parallel to body.pieces()
};

// read_points, then one convex piece per group (OBJ `g`/`o` groups, made of
// the vertices their faces reference, see PointCloud; a file without groups
// is one piece of all its points). A non-convex group is reported in its
// LoadedPiece, not refused. A group whose points cannot build a polytope is
// a FileError naming the file and the group.
LoadedCompound load_compound(const std::string& path, const ReadOptions& options = {});

// The same from a point cloud already read (or built by hand): the groups of
// `cloud` are checked (offsets increasing from 0, inside the triangles or
// the points, one name each; triangle indices inside the points) and
// hulled; errors name cloud.source and the group.
LoadedCompound compound_from_cloud(const PointCloud& cloud);

// A file as a triangle mesh (proxima/query/mesh_distance.h): its vertices and faces as
// given, nothing merged or replaced (STL corners are merged by the reader,
// see PointCloud). Degenerate triangles are kept and counted.
struct LoadedMesh {
  TriangleMesh mesh;
  int input_points = 0;          // points read (vertices of the mesh, used or not)
  int degenerate_triangles = 0;  // zero-area triangles, measured as segments or points
  bool closed = false;           // TriangleMesh::is_closed(): the mesh has an inside
};

// read_points, then the mesh of its points and triangles. A file without
// faces (a point cloud: XYZ, or OBJ without `f` lines; OFF and PLY faces are
// not read) is a FileError saying so; an index or coordinate the mesh
// refuses is a FileError naming the file and the triangle or vertex.
LoadedMesh load_mesh(const std::string& path, const ReadOptions& options = {});

// The same from a point cloud already read; errors name cloud.source.
LoadedMesh mesh_from_cloud(const PointCloud& cloud);

// How a file becomes a body; the caller says which (nothing is silently
// replaced by its hull):
//   mesh    the surface as given (load_mesh): exact for any shape
//   hull    the convex hull of every point (load_convex)
//   pieces  one convex hull per OBJ group (load_compound)
enum class LoadAs : std::uint8_t { mesh, hull, pieces };
const char* to_string(LoadAs as);
// "mesh", "hull" or "pieces"; anything else is an InvalidInput naming it.
LoadAs load_as_from_string(std::string_view name);

// The file as a Body of that kind (radius 0).
Body load_body(const std::string& path, LoadAs as, const ReadOptions& options = {});

}  // namespace proxima
