// Thread-count control shared by the modules: with a thread count of 0 work runs in the
// caller's oneTBB arena (all hardware threads, shared with the host's own TBB work); with an
// explicit count in a long-lived arena limited to it, made on first use and kept for the
// process, so a loop of many small parallel calls (rows, columns, sweeps) pays for no arena
// creation and concurrent calls with different settings do not interfere.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/thread_sanitizer.hpp"

// ThreadSanitizer sees only instrumented code: oneTBB from Debian is not, so the order its
// scheduler puts between a task's writes and the waiting thread's reads is invisible to it, and
// every parallel loop would be reported as racing. Under TSan parallel_for therefore runs its
// chunks on plain std::threads (same chunks' results, since no result depends on the
// chunking), whose start and join TSan understands: what it then reports are our own races.

namespace radiosity::detail {

inline int thread_count(unsigned requested) {
  if (requested > 0) return static_cast<int>(requested);
  return std::max(1, static_cast<int>(tbb::this_task_arena::max_concurrency()));
}

/// The process's arena of `n` threads. Arenas are never destroyed (nor is the map that holds
/// them, so they stay reachable for leak checkers): a static destructor could run after
/// oneTBB's own shutdown, or while a detached thread still uses one. Thread safety: may be
/// called concurrently.
inline tbb::task_arena& arena_of(int n) {
  // Most calls ask for the count the thread asked for last: no lock then.
  thread_local int last_count = 0;
  thread_local tbb::task_arena* last_arena = nullptr;
  if (n == last_count) return *last_arena;
  static std::mutex mutex;
  static std::map<int, tbb::task_arena*>& arenas = *new std::map<int, tbb::task_arena*>();
  const std::lock_guard<std::mutex> lock(mutex);
  tbb::task_arena*& arena = arenas[n];
  if (arena == nullptr) arena = new tbb::task_arena(n);
  last_count = n;
  last_arena = arena;
  return *arena;
}

/// Runs body(begin, end) over [0, count) in chunks of `grain`, on at most `threads` threads.
/// Results must not depend on the chunking (each index computes its own values).
template <typename Body>
void parallel_for(unsigned threads, std::size_t count, std::size_t grain, const Body& body) {
  if (count == 0) return;
  const int n = thread_count(threads);
  // One thread, or one chunk: nothing to share out (nested calls are often this small).
  if (n == 1 || count <= grain) {
    body(std::size_t{0}, count);
    return;
  }
#if defined(RADIOSITY_THREAD_SANITIZER)
  // Chunks handed out by a counter to n - 1 new threads and the caller; the first exception
  // stops the handing out and is rethrown after the join, as tbb::parallel_for does.
  const std::size_t step = std::max<std::size_t>(grain, 1);
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (std::size_t begin = next.fetch_add(step); begin < count; begin = next.fetch_add(step)) {
      try {
        body(begin, std::min(count, begin + step));
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next.store(count);
      }
    }
  };
  std::vector<std::thread> helpers;
  for (int i = 1; i < n; ++i) helpers.emplace_back(work);
  work();
  for (std::thread& t : helpers) t.join();
  if (error) std::rethrow_exception(error);
#else
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, std::max<std::size_t>(grain, 1)),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  };
  // Isolated: while it waits for its chunks a thread takes no unrelated task of the same arena
  // (another call's, or an outer loop's, which could need a lock the caller holds).
  if (threads == 0) {
    tbb::this_task_arena::isolate(run);
    return;
  }
  arena_of(n).execute([&] { tbb::this_task_arena::isolate(run); });
#endif
}

}  // namespace radiosity::detail
