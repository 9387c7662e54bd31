// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// TBB scheduling for distance_batch, and nothing else. Why it has a file of
// its own: ThreadSanitizer needs every piece of synchronization it is to
// trust to be instrumented, and Debian's libtbb is not. TBB's header code
// (parallel_for's task objects, the partitioner, the wait node on the
// caller's stack) is compiled into the calling file, so when that file is
// instrumented, TSan sees TBB's objects written by one thread and recycled by
// another, through atomics hidden in libtbb, and reports races that are not
// there. Under the tsan preset this file is compiled without TSan, which
// makes TBB entirely opaque to it; the work itself (in batch.cpp) stays
// instrumented, and the hand-off edges TBB guarantees (caller before the
// tasks, tasks before the return) are stated to TSan there.
#include "parallel_ranges.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

namespace proxima::detail {

void parallel_ranges(std::size_t n, std::size_t grain, int threads,
                     void (*run)(void* context, std::size_t begin, std::size_t end),
                     void* context) {
  const auto loop = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [run, context](const tbb::blocked_range<std::size_t>& r) {
                        run(context, r.begin(), r.end());
                      });
  };
  if (threads == 0) {
    loop();
  } else {
    tbb::task_arena arena(threads);
    arena.execute(loop);
  }
}

}  // namespace proxima::detail
