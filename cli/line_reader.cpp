// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
#include "line_reader.h"

#include <algorithm>

namespace proxima::cli {

LineRead read_line(std::istream& in, std::string& line, std::uint64_t max_bytes) {
  line.clear();
  const std::istream::sentry ok(in, true);
  if (!ok) return LineRead::end;
  std::streambuf* buffer = in.rdbuf();
  using Traits = std::char_traits<char>;
  // Byte by byte through the stream buffer: sbumpc is an inline pointer
  // step while the buffer holds bytes (only a refill is a virtual call),
  // and no byte after the '\n' is taken from the stream, so a pipe fed one
  // query at a time is never read ahead of its answer.
  char chunk[4096];
  for (;;) {
    const std::streamsize room = static_cast<std::streamsize>(
        std::min<std::uint64_t>(sizeof chunk, max_bytes - line.size() + 1));
    std::streamsize got = 0;
    int c = Traits::eof();
    while (got < room) {
      c = buffer->sbumpc();
      if (Traits::eq_int_type(c, Traits::eof())) break;
      if (c == '\n') break;
      chunk[got++] = Traits::to_char_type(c);
    }
    line.append(chunk, static_cast<std::size_t>(got));
    if (line.size() > max_bytes) return LineRead::too_long;
    if (Traits::eq_int_type(c, Traits::eof())) {
      if (line.empty()) {
        in.setstate(std::ios::eofbit | std::ios::failbit);
        return LineRead::end;
      }
      in.setstate(std::ios::eofbit);
      return LineRead::line;
    }
    if (c == '\n') return LineRead::line;
  }
}

std::string too_long_message(long line_number, std::uint64_t max_bytes) {
  return "line " + std::to_string(line_number) + " is longer than the limit of " +
         std::to_string(max_bytes) + " bytes (--max-line-size); reading stopped there";
}

}  // namespace proxima::cli
