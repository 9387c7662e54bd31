// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7, inside the readers: the file being read, named in every error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "proxima/io.h"

namespace proxima::io_detail {

// The file being read: its name for messages.
struct Source {
  std::string name;

  [[noreturn]] void fail_line(std::int64_t line, const std::string& problem) const {
    throw FileError::at_line(name, line, problem);
  }
  [[noreturn]] void fail_byte(std::size_t offset, const std::string& problem) const {
    throw FileError::at_byte(name, static_cast<std::int64_t>(offset), problem);
  }
  [[noreturn]] void fail(const std::string& problem) const {
    throw FileError::in_file(name, problem);
  }
};

}  // namespace proxima::io_detail
