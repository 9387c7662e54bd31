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
#include "query/parallel_ranges.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

#include <memory>

namespace proxima::detail {
namespace {

// The arena of `threads` threads in which the calling thread runs its
// parallel loops, kept from one loop to the next (one per calling thread,
// destroyed with it). A new tbb::task_arena per loop cost 114 to 287 us on
// this machine against 4.9 us for a kept one (a loop of 16,000 trivial items
// in chunks of 1,024 on 2 threads, 20,000 times): the arena's setup and the
// workers' move into it. Scene::step runs about eight loops per step (world
// boxes, the pair finder's three, the cache merge, the narrow phase, the
// close pairs' count and copy), so at 2 threads that was a millisecond or
// more per step of the 5 ms the step is to take. A loop started inside
// another one with another thread count (a nested call) gets an arena of
// its own, as before: the kept one is in use.
class KeptArena {
 public:
  template <class Loop>
  void execute(int threads, const Loop& loop) {
    if (depth_ > 0 && threads != threads_) {
      tbb::task_arena nested(threads);
      nested.execute(loop);
      return;
    }
    if (!arena_ || threads != threads_) {
      arena_ = std::make_unique<tbb::task_arena>(threads);
      threads_ = threads;
    }
    struct InUse {  // also when the loop throws
      int& depth;
      explicit InUse(int& d) : depth(d) { ++depth; }
      ~InUse() { --depth; }
      InUse(const InUse&) = delete;
      InUse& operator=(const InUse&) = delete;
    } in_use(depth_);
    arena_->execute(loop);
  }

 private:
  std::unique_ptr<tbb::task_arena> arena_;
  int threads_ = 0;
  int depth_ = 0;  // loops of this thread running in arena_
};

}  // namespace

void parallel_ranges(std::size_t n, std::size_t grain, int threads,
                     void (*run)(void* context, std::size_t begin, std::size_t end),
                     void* context) {
  // The caller's floating-point settings (traps, rounding) as they are
  // now, for every task of this loop, the caller's own included: a kept
  // arena holds those of the call that made it and puts them on every
  // thread that enters it, so a caller that changed them since (turned traps
  // off, say) would otherwise see its tasks run under the old ones
  // (ParallelRanges.EachLoopRunsUnderTheCallersFloatingPointSettings).
  // Captured here, before the arena is entered.
  tbb::task_group_context group;
  group.capture_fp_settings();
  const auto loop = [&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, grain),
        [run, context](const tbb::blocked_range<std::size_t>& r) {
          run(context, r.begin(), r.end());
        },
        group);
  };
  if (threads == 0) {
    loop();
  } else {
    thread_local KeptArena kept;
    kept.execute(threads, loop);
  }
}

}  // namespace proxima::detail
