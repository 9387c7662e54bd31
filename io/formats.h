// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: the entry point of each format (one file
// each: obj.cpp, off.cpp, stl.cpp, ply.cpp, xyz.cpp), and what readers.cpp
// needs of them to pick a format. Each reads the whole content given and
// returns the points (and, for OBJ and STL, the triangles and groups), or
// throws a FileError naming `src`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string_view>

#include "proxima/io.h"
#include "source.h"

namespace proxima::io_detail {

// OBJ (obj.cpp).
PointCloud read_obj(const Source& src, std::string_view text);
// Whether `word` begins an OBJ statement (for sniffing the format).
bool is_obj_statement(std::string_view word);

// OFF (off.cpp).
PointCloud read_off(const Source& src, std::string_view text);
// 0: not an OFF keyword; 1: a supported one; -1: a 4-D or binary variant.
int off_keyword(std::string_view token);

// XYZ (xyz.cpp).
PointCloud read_xyz(const Source& src, std::string_view text);

// PLY, ascii or binary_little_endian as the header says (ply.cpp).
PointCloud read_ply(const Source& src, std::string_view bytes);

// STL (stl.cpp).
constexpr std::size_t kStlHeaderBytes = 80;
constexpr std::size_t kStlPreambleBytes = 84;  // header and the uint32 triangle count
constexpr std::size_t kStlTriangleBytes = 50;  // normal, 3 corners (12 floats), uint16 attribute

// Binary by the size rule (84 + 50 n bytes for the n announced), else ASCII
// when the text begins with "solid" and holds no NUL byte.
bool stl_is_binary(std::string_view bytes);
// The preamble's announced triangle count, checked against the file's size.
std::uint64_t stl_binary_count(const Source& src, std::string_view preamble,
                               std::uint64_t file_bytes);
// The bytes [offset, offset + size) of a binary STL file, asked for in order.
using StlFetch = std::function<std::string_view(std::size_t offset, std::size_t size)>;
// The n triangles of a binary STL whose size stl_binary_count checked, read
// in chunks through `fetch`.
PointCloud read_stl_binary_triangles(const Source& src, std::uint64_t n, const StlFetch& fetch);
PointCloud read_stl_binary(const Source& src, std::string_view bytes);
PointCloud read_stl_ascii(const Source& src, std::string_view text);

}  // namespace proxima::io_detail
