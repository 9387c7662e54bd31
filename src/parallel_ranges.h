// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Private to src/: the thread pool behind distance_batch, kept apart from the
// work it runs. This file's .cpp is all of proxima's TBB scheduling code; the
// top-level CMakeLists.txt compiles it without ThreadSanitizer, like libtbb
// itself (see parallel_ranges.cpp for why).
#pragma once

#include <cstddef>

namespace proxima::detail {

// Calls run(context, begin, end) on disjoint ranges that cover [0, n), each
// of at least `grain` indices unless n is smaller, on TBB's thread pool:
// `threads == 0` in the caller's current arena, otherwise in a new arena of
// `threads` threads (the caller among them). An exception thrown by `run`
// reaches the caller (TBB cancels the ranges not yet started).
void parallel_ranges(std::size_t n, std::size_t grain, int threads,
                     void (*run)(void* context, std::size_t begin, std::size_t end), void* context);

}  // namespace proxima::detail
