// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: little-endian binary loads (STL, PLY).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "source.h"

namespace proxima::io_detail {

inline std::uint64_t load_le(std::string_view bytes, std::size_t offset, std::size_t size) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < size; ++i) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[offset + i])) << (8 * i);
  }
  return v;
}

// A binary coordinate: refuses NaN and infinity from the bit pattern (all
// exponent bits set), before the value is converted or compared. `label()`
// names the coordinate; it is only built for a message.
// `base` is the file offset of bytes[0], for messages (STL is read from a
// file in chunks).
template <class Label>
double binary_float(const Source& src, std::string_view bytes, std::size_t offset, bool is_double,
                    Label&& label, std::size_t base = 0) {
  if (is_double) {
    const std::uint64_t bits = load_le(bytes, offset, 8);
    constexpr std::uint64_t kExponent = 0x7ffULL << 52;
    constexpr std::uint64_t kMantissa = (1ULL << 52) - 1;
    if ((bits & kExponent) == kExponent) {
      src.fail_byte(base + offset, std::string((bits & kMantissa) != 0 ? "NaN" : "infinite") +
                                       " coordinate (" + label() + ")");
    }
    return std::bit_cast<double>(bits);
  }
  const auto bits = static_cast<std::uint32_t>(load_le(bytes, offset, 4));
  constexpr std::uint32_t kExponent = 0xffU << 23;
  constexpr std::uint32_t kMantissa = (1U << 23) - 1;
  if ((bits & kExponent) == kExponent) {
    src.fail_byte(base + offset, std::string((bits & kMantissa) != 0 ? "NaN" : "infinite") +
                                     " coordinate (" + label() + ")");
  }
  return static_cast<double>(std::bit_cast<float>(bits));
}

}  // namespace proxima::io_detail
