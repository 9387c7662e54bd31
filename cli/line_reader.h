// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: reading JSON Lines with a bound on a line's size. A stream has
// no size to cap (a pipe of queries may run for days), but one line must
// fit in memory together with its parsed JSON (several times its bytes):
// std::getline on /dev/zero, or on a file without newlines, grows until
// std::bad_alloc. Every line-reading command reads through here.
#pragma once

#include <cstdint>
#include <istream>
#include <string>

namespace proxima::cli {

// 256 MiB: a query line with an inline mesh of several million triangles
// fits; the parsed JSON of a longer one would take gigabytes.
inline constexpr std::uint64_t kDefaultMaxLineBytes = std::uint64_t{1} << 28;

enum class LineRead {
  line,      // `line` holds the next line, without its '\n'
  end,       // the stream ended (or broke: check in.bad()) before any byte
  too_long,  // more than max_bytes before a '\n': reading stopped there
};

// The next line of `in`, as std::getline reads it (a last line without
// '\n' included), or too_long as soon as it passes max_bytes, having
// consumed max_bytes + 1 bytes of it: the rest of such a line cannot be
// skipped without reading it, which may never end (/dev/zero), so a caller
// stops reading.
LineRead read_line(std::istream& in, std::string& line, std::uint64_t max_bytes);

// "line N is longer than the limit of M bytes (--max-line-size)".
std::string too_long_message(long line_number, std::uint64_t max_bytes);

}  // namespace proxima::cli
