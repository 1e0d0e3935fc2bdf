// Thread-count control shared by the modules: with a thread count of 0 work runs in the
// caller's oneTBB arena (all hardware threads, shared with the host's own TBB work, and no
// arena to create per call); with an explicit count in an arena of its own limited to it, so
// concurrent calls with different settings do not interfere.
#pragma once

#include <algorithm>
#include <cstddef>
#include <thread>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace radiosity::detail {

inline int thread_count(unsigned requested) {
  if (requested > 0) return static_cast<int>(requested);
  return std::max(1, static_cast<int>(tbb::this_task_arena::max_concurrency()));
}

/// Runs body(begin, end) over [0, count) in chunks of `grain`, on at most `threads` threads.
/// Results must not depend on the chunking (each index computes its own values).
template <typename Body>
void parallel_for(unsigned threads, std::size_t count, std::size_t grain, const Body& body) {
  if (count == 0) return;
  const int n = thread_count(threads);
  if (n == 1) {
    body(std::size_t{0}, count);
    return;
  }
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, std::max<std::size_t>(grain, 1)),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  };
  if (threads == 0) {
    // Isolated, as an arena of its own would be: while it waits for its chunks a thread takes
    // no unrelated outer task (which could need a lock the caller holds).
    tbb::this_task_arena::isolate(run);
    return;
  }
  tbb::task_arena arena(n);
  arena.execute(run);
}

}  // namespace radiosity::detail
