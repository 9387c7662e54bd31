// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Private to src/: the thread pool behind distance_batch and Scene::step,
// kept apart from the work it runs. This file's .cpp is all of proxima's TBB
// scheduling code; the top-level CMakeLists.txt compiles it without
// ThreadSanitizer, like libtbb itself (see parallel_ranges.cpp for why).
#pragma once

#include <cstddef>
#include <vector>

#if defined(__SANITIZE_THREAD__)
#define PROXIMA_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define PROXIMA_TSAN 1
#endif
#endif
#ifdef PROXIMA_TSAN
#include <sanitizer/tsan_interface.h>
#endif

namespace proxima::detail {

// Calls run(context, begin, end) on disjoint ranges that cover [0, n), each
// of at least `grain` indices unless n is smaller, on TBB's thread pool:
// `threads == 0` in the caller's current arena, otherwise in a new arena of
// `threads` threads (the caller among them). An exception thrown by `run`
// reaches the caller (TBB cancels the ranges not yet started).
void parallel_ranges(std::size_t n, std::size_t grain, int threads,
                     void (*run)(void* context, std::size_t begin, std::size_t end), void* context);

// ThreadSanitizer sees the happens-before edges of the code it instruments,
// and TBB's scheduling is hidden from it (parallel_ranges.cpp says why). The
// two edges TBB guarantees are stated to it here instead: the caller's writes
// before the parallel loop happen before every range (released on the range
// functor's address, acquired before the functor is read), and every range's
// writes happen before the loop returns or throws (released on a marker the
// caller acquires). Ranges only acquire the first and only release the
// second, so no edge between two ranges is invented: a race between ranges is
// still caught. Outside TSan these are empty.
#ifdef PROXIMA_TSAN
inline void tsan_release(void* address) { __tsan_release(address); }
inline void tsan_acquire(void* address) { __tsan_acquire(address); }
#else
inline void tsan_release(void*) {}
inline void tsan_acquire(void*) {}
#endif

// Calls a range functor through parallel_ranges' plain function pointer.
template <class Range>
void call_range(void* range, std::size_t begin, std::size_t end) {
  tsan_acquire(range);
  (*static_cast<Range*>(range))(begin, end);
}

// parallel_ranges over a functor run_range(begin, end), with the hand-off
// edges above stated to ThreadSanitizer.
template <class RunRange>
void parallel_ranges(std::size_t n, std::size_t grain, int threads, const RunRange& run_range) {
  char ranges_done = 0;  // only its address is used: the TSan marker above
  auto range = [&](std::size_t begin, std::size_t end) {
    struct RangeEnds {  // also when the range throws: the exception object is its write
      char* marker;
      ~RangeEnds() { tsan_release(marker); }
    } ends{&ranges_done};
    run_range(begin, end);
  };
  struct AfterRanges {
    char* marker;
    ~AfterRanges() { tsan_acquire(marker); }
  } after{&ranges_done};
  tsan_release(&range);
  parallel_ranges(n, grain, threads, &call_range<decltype(range)>, &range);
}

// Fixed chunks for work whose output must come out in index order (a
// parallel filter or copy): [0, n) cut into chunks of `chunk` indices (the
// last one shorter), run_chunk(c, begin, end) called once for chunk c, on
// TBB's pool as parallel_ranges above when threads != 1 and there are two
// chunks or more, in the calling thread otherwise. Chunk c's output goes to
// slot c of the caller's per-chunk storage, so joining the slots in order
// gives the sequential loop's order whatever the threads.
inline std::size_t chunk_count(std::size_t n, std::size_t chunk) { return (n + chunk - 1) / chunk; }

template <class RunChunk>
void parallel_chunks(std::size_t n, std::size_t chunk, int threads, const RunChunk& run_chunk) {
  const std::size_t chunks = chunk_count(n, chunk);
  const auto run_range = [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c < last; ++c) {
      run_chunk(c, c * chunk, c + 1 == chunks ? n : (c + 1) * chunk);
    }
  };
  if (threads == 1 || chunks < 2) {
    run_range(0, chunks);
  } else {
    parallel_ranges(chunks, 1, threads, run_range);
  }
}

// An order-preserving parallel gather: emit(begin, end, into) appends to
// `into` what the indices [begin, end) give, in order; `out` becomes the
// outputs of [0, n) in index order. With threads == 1 or a single chunk,
// emit(0, n, out) runs in the calling thread straight into `out`; else each
// chunk appends to its own list of `scratch` (kept by the caller between
// calls) and the lists are joined.
template <class T, class Emit>
void parallel_gather(std::size_t n, std::size_t chunk, int threads,
                     std::vector<std::vector<T>>& scratch, std::vector<T>& out, const Emit& emit) {
  out.clear();
  const std::size_t chunks = chunk_count(n, chunk);
  if (threads == 1 || chunks < 2) {
    emit(std::size_t{0}, n, out);
    return;
  }
  if (scratch.size() < chunks) scratch.resize(chunks);
  parallel_chunks(n, chunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    scratch[c].clear();
    emit(begin, end, scratch[c]);
  });
  std::size_t total = 0;
  for (std::size_t c = 0; c < chunks; ++c) total += scratch[c].size();
  out.reserve(total);
  for (std::size_t c = 0; c < chunks; ++c)
    out.insert(out.end(), scratch[c].begin(), scratch[c].end());
}

}  // namespace proxima::detail
