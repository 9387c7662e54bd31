// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: the limits that keep them safe on hostile
// input, in one place.
//
// How the readers stay safe on hostile input:
// - every read is bounds-checked against the bytes actually present;
// - a count announced by a header (vertices, triangles, list lengths) is
//   checked against what the remaining bytes can hold before it sizes an
//   allocation, and a loop it drives consumes at least one byte or token per
//   step, so it ends with the file;
// - numbers are parsed by std::from_chars (correctly rounded, locale-free);
//   binary floats are checked for NaN and infinity on their bit patterns,
//   before any arithmetic or conversion touches them (a signalling NaN would
//   raise FE_INVALID when converted from float to double).
// - no more than ReadOptions::max_file_bytes is read (io.h);
// - point and triangle ids fit std::int32_t.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "proxima/core/types.h"
#include "source.h"

namespace proxima::io_detail {

// Point ids are std::int32_t downstream (hull input_index, group offsets).
constexpr std::size_t kMaxPoints =
    static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());

// The shortest text line that can hold a vertex ("0 0 0\n"): bounds how many
// vertices a header may announce for the bytes that follow, so that a lying
// count cannot size an allocation.
constexpr std::size_t kMinTextVertexBytes = 6;

inline void push_point(const Source& src, std::vector<Vec3>& points, const Vec3& p) {
  if (points.size() >= kMaxPoints)
    src.fail("more than " + std::to_string(kMaxPoints) + " vertices");
  points.push_back(p);
}

[[noreturn]] inline void fail_too_large(const Source& src, const std::string& what,
                                        std::uint64_t limit) {
  src.fail("file too large: " + what + " more than the limit of " + std::to_string(limit) +
           " bytes (ReadOptions::max_file_bytes)");
}

}  // namespace proxima::io_detail
