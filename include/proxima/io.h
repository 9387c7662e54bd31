// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: mesh file readers. They turn a file into a point list (and, for
// OBJ, the groups that a compound body is made of); the algorithms never see
// files.
//
// Formats: Wavefront OBJ (`v` lines; `g`/`o` statements become groups), OFF
// (and its C/N/ST variants, extra columns ignored), ASCII and binary STL,
// PLY (ascii and binary_little_endian; the vertex element's x, y, z, any
// other property skipped by its type, faces ignored) and plain XYZ (one point
// per line, at least three numbers, extra columns ignored, `#` comments).
// Faces are never used: the hull is recomputed from the points.
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
// the file's size can hold.
#pragma once

#include "proxima/compound.h"
#include "proxima/polytope.h"
#include "proxima/types.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace proxima {

enum class MeshFormat : std::uint8_t { obj, off, stl_ascii, stl_binary, ply_ascii, ply_binary_le, xyz, unknown };

const char* to_string(MeshFormat format);

struct PointCloud {
  std::vector<Vec3> points;
  MeshFormat format = MeshFormat::unknown;  // the format actually read (sniffed when asked with unknown)
  std::string source;                       // the path or name given to the reader
  // OBJ groups (`g` and `o` statements), in file order: group i holds the
  // points [group_offsets[i], group_offsets[i + 1]) (the last one runs to the
  // end). Empty when the file has no groups; otherwise the groups cover every
  // point, each is non-empty, group_offsets[0] == 0, and points read before
  // the first statement form a group named "". A later statement with no
  // points in between renames the group (so `o body` then `g part` is one
  // group "part").
  std::vector<std::string> group_names;
  std::vector<std::int32_t> group_offsets;
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
PointCloud read_points(const std::string& path);

// The same from bytes in memory; `name` stands for the file in messages.
// MeshFormat::unknown sniffs the content. stl_ascii and stl_binary read the
// content as given; ply_ascii and ply_binary_le both accept either PLY
// encoding (the header says which) and report the one read.
PointCloud read_points_from_memory(std::string_view bytes, MeshFormat format, const std::string& name);

struct LoadedPolytope {
  ConvexPolytope polytope;
  int input_points = 0;     // points read from the file
  int interior_points = 0;  // input points that are not hull vertices (inside, on a face, or repeated)
  bool input_was_convex = true;  // interior_points == 0: every input point is a hull vertex
};

// read_points, then the hull of all the points (groups are not split). A
// non-convex input is reported, not refused.
LoadedPolytope load_convex(const std::string& path);

// What became of one group of a compound file: its name and how convex its
// points were (the piece is their hull either way).
struct LoadedPiece {
  std::string name;         // the OBJ group's name; "" for points before the first group or a file without groups
  int input_points = 0;     // points of the group
  int interior_points = 0;  // of those, not hull vertices (inside, on a face, or repeated)
  bool input_was_convex = true;  // interior_points == 0
};

struct LoadedCompound {
  CompoundBody body;                // one piece per group, identity piece poses, in file order
  std::vector<LoadedPiece> pieces;  // parallel to body.pieces()
};

// read_points, then one convex piece per group (OBJ `g`/`o` groups; a file
// without groups is one piece). A non-convex group is reported in its
// LoadedPiece, not refused. A group whose points cannot build a polytope is
// a FileError naming the file and the group.
LoadedCompound load_compound(const std::string& path);

// The same from a point cloud already read (or built by hand): the groups of
// `cloud` are checked (offsets increasing from 0, inside the points, one
// name each) and hulled; errors name cloud.source and the group.
LoadedCompound compound_from_cloud(const PointCloud& cloud);

}  // namespace proxima
