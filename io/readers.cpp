// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: mesh file readers (see include/proxima/io.h): FileError, picking
// the format, and reading a file or bytes within ReadOptions. The formats
// are in obj.cpp, off.cpp, stl.cpp, ply.cpp and xyz.cpp (formats.h), the
// shared text parsing in text.h, the limits in limits.h, the convexity
// report in convexity.cpp and the loaders in loaders.cpp.
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "binary.h"
#include "formats.h"
#include "limits.h"
#include "proxima/io.h"
#include "text.h"

namespace proxima {

namespace {

std::string compose_message(const std::string& file, std::int64_t line, std::int64_t byte_offset,
                            const std::string& problem) {
  if (line > 0) return file + ", line " + std::to_string(line) + ": " + problem;
  if (byte_offset >= 0) return file + ", byte " + std::to_string(byte_offset) + ": " + problem;
  return file + ": " + problem;
}

}  // namespace

FileError::FileError(std::string file, std::int64_t line, std::int64_t byte_offset,
                     std::string problem)
    : InvalidInput(compose_message(file, line, byte_offset, problem)),
      file_(std::move(file)),
      line_(line),
      byte_offset_(byte_offset),
      problem_(std::move(problem)) {}

FileError FileError::at_line(std::string file, std::int64_t line, std::string problem) {
  return FileError(std::move(file), line, -1, std::move(problem));
}
FileError FileError::at_byte(std::string file, std::int64_t byte_offset, std::string problem) {
  return FileError(std::move(file), 0, byte_offset, std::move(problem));
}
FileError FileError::in_file(std::string file, std::string problem) {
  return FileError(std::move(file), 0, -1, std::move(problem));
}

const char* to_string(MeshFormat format) {
  switch (format) {
    case MeshFormat::obj:
      return "obj";
    case MeshFormat::off:
      return "off";
    case MeshFormat::stl_ascii:
      return "stl_ascii";
    case MeshFormat::stl_binary:
      return "stl_binary";
    case MeshFormat::ply_ascii:
      return "ply_ascii";
    case MeshFormat::ply_binary_le:
      return "ply_binary_le";
    case MeshFormat::xyz:
      return "xyz";
    case MeshFormat::unknown:
      return "unknown";
  }
  return "unknown";
}

namespace {

using namespace io_detail;

// ---------------------------------------------------------------------------
// Format from the extension, or from the content.

bool all_numbers(Tokens tokens, int n) {
  for (int i = 0; i < n; ++i) {
    std::string_view token;
    double v = 0.0;
    if (!tokens.next(&token) || parse_double(token, &v) != NumberStatus::ok) return false;
  }
  return true;
}

MeshFormat sniff_format(std::string_view bytes) {
  if (bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n")
    return MeshFormat::ply_ascii;
  // Binary STL only by the exact size rule here: without a .stl extension,
  // a size mismatch says nothing about the format.
  if (bytes.size() >= kStlPreambleBytes &&
      kStlPreambleBytes + kStlTriangleBytes * load_le(bytes, kStlHeaderBytes, 4) == bytes.size()) {
    return MeshFormat::stl_binary;
  }
  if (bytes.find('\0') != std::string_view::npos) return MeshFormat::unknown;
  const std::string_view text = strip_bom(bytes);
  if (!stl_is_binary(text)) return MeshFormat::stl_ascii;
  // The first statement that is not a comment decides.
  const Source quiet{""};
  LineReader lines(quiet, text);
  std::string_view line;
  if (!next_content_line(lines, &line)) return MeshFormat::unknown;
  Tokens tokens(line, Separators::blanks_and_commas);
  std::string_view word;
  tokens.next(&word);
  if (off_keyword(word) != 0) return MeshFormat::off;
  if (is_obj_statement(word)) return MeshFormat::obj;
  if (all_numbers(Tokens(line, Separators::blanks_and_commas), 3)) return MeshFormat::xyz;
  return MeshFormat::unknown;
}

MeshFormat format_from_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".stl") return MeshFormat::stl_binary;  // ASCII or binary: decided by stl_is_binary
  if (ext == ".ply") return MeshFormat::ply_ascii;   // the header says which encoding
  if (ext == ".xyz" || ext == ".txt" || ext == ".pts") return MeshFormat::xyz;
  return MeshFormat::unknown;
}

PointCloud read_as(const Source& src, std::string_view bytes, MeshFormat format) {
  switch (format) {
    case MeshFormat::obj:
      return read_obj(src, strip_bom(bytes));
    case MeshFormat::off:
      return read_off(src, strip_bom(bytes));
    case MeshFormat::stl_ascii:
      return read_stl_ascii(src, strip_bom(bytes));
    case MeshFormat::stl_binary:
      return read_stl_binary(src, bytes);
    case MeshFormat::ply_ascii:
    case MeshFormat::ply_binary_le:
      return read_ply(src, bytes);
    case MeshFormat::xyz:
      return read_xyz(src, strip_bom(bytes));
    case MeshFormat::unknown:
      break;
  }
  src.fail("unknown format: the content is not recognized as OBJ, OFF, STL, PLY or XYZ");
}

PointCloud finish(const Source& src, PointCloud cloud) {
  if (cloud.points.empty()) src.fail("empty mesh (no vertices)");
  cloud.source = src.name;
  return cloud;
}

}  // namespace

PointCloud read_points_from_memory(std::string_view bytes, MeshFormat format,
                                   const std::string& name, const ReadOptions& options) {
  const Source src{name};
  if (bytes.size() > options.max_file_bytes) {
    fail_too_large(src, std::to_string(bytes.size()) + " bytes,", options.max_file_bytes);
  }
  if (format == MeshFormat::unknown) format = sniff_format(bytes);
  return finish(src, read_as(src, bytes, format));
}

PointCloud read_points(const std::string& path, const ReadOptions& options) {
  const Source src{path};
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    const bool missing = !ec || ec == std::errc::no_such_file_or_directory;
    src.fail("cannot open: " + (missing ? std::string("no such file") : ec.message()));
  }
  if (std::filesystem::is_directory(status)) src.fail("cannot open: is a directory");
  const std::uint64_t limit = options.max_file_bytes;
  std::uint64_t file_bytes = 0;
  const bool regular = std::filesystem::is_regular_file(status);
  if (regular) {
    file_bytes = std::filesystem::file_size(path, ec);
    if (ec) src.fail("cannot read the size: " + ec.message());
    if (file_bytes > limit) fail_too_large(src, std::to_string(file_bytes) + " bytes,", limit);
  }
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) src.fail(std::string("cannot open: ") + std::strerror(errno));
  MeshFormat format = format_from_extension(path);

  // Binary STL from a regular file is read in chunks: the largest files
  // are binary STL, and their corners alone take 36 bytes per triangle.
  if (regular && format == MeshFormat::stl_binary && file_bytes >= kStlPreambleBytes) {
    std::string preamble(kStlPreambleBytes, '\0');
    if (std::fread(preamble.data(), 1, preamble.size(), file.get()) != preamble.size())
      src.fail("read error");
    if (kStlPreambleBytes + kStlTriangleBytes * load_le(preamble, kStlHeaderBytes, 4) ==
        file_bytes) {
      const std::uint64_t n = stl_binary_count(src, preamble, file_bytes);
      std::string chunk;
      std::uint64_t at = kStlPreambleBytes;
      PointCloud cloud =
          read_stl_binary_triangles(src, n, [&](std::size_t offset, std::size_t size) {
            if (offset != at) throw std::logic_error("binary STL chunks out of order");
            chunk.resize(size);
            if (std::fread(chunk.data(), 1, size, file.get()) != size)
              src.fail_byte(offset, "read error (the file shrank?)");
            at += size;
            return std::string_view(chunk);
          });
      return finish(src, std::move(cloud));
    }
    std::rewind(file.get());
  }

  std::string bytes;
  if (regular) bytes.reserve(static_cast<std::size_t>(file_bytes));
  std::array<char, 1 << 16> buffer{};
  std::size_t got = 0;
  while ((got = std::fread(buffer.data(), 1, buffer.size(), file.get())) > 0) {
    if (got > limit - bytes.size()) fail_too_large(src, "read", limit);
    bytes.append(buffer.data(), got);
  }
  if (std::ferror(file.get()) != 0) src.fail("read error");

  if (format == MeshFormat::stl_binary && !stl_is_binary(bytes)) format = MeshFormat::stl_ascii;
  if (format == MeshFormat::unknown) {
    format = sniff_format(bytes);
    if (format == MeshFormat::unknown) {
      src.fail("unknown format: the extension " +
               quote(std::filesystem::path(path).extension().string()) +
               " is none of .obj .off .stl .ply .xyz .txt .pts, and the content is not recognized");
    }
  }
  return finish(src, read_as(src, bytes, format));
}

}  // namespace proxima
