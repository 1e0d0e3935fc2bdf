// The shared parallel loop (src/core/parallel.hpp): every index once, also for loops nested in
// another's body (an estimator used inside another estimator's loop).
#include <doctest/doctest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "core/parallel.hpp"

namespace core = radiosity::detail;

TEST_SUITE("core") {
  TEST_CASE("a nested parallel_for covers every index once and stays within the thread count") {
    for (const unsigned threads : {0u, 1u, 2u}) {
      CAPTURE(threads);
      constexpr std::size_t n = 64, m = 256;
      std::vector<std::atomic<int>> hits(n * m);
      std::atomic<int> widest{0};
      const int limit = core::thread_count(threads);
      core::parallel_for(threads, n, 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          core::parallel_for(threads, m, 8, [&](std::size_t b, std::size_t e) {
            const int w = threads == 1 ? 1 : tbb::this_task_arena::max_concurrency();
            for (int seen = widest.load(); w > seen && !widest.compare_exchange_weak(seen, w);) {
            }
            for (std::size_t k = b; k < e; ++k) ++hits[i * m + k];
          });
      });
      bool once = true;
      for (const auto& h : hits) once = once && h.load() == 1;
      CHECK(once);
      CHECK(widest.load() <= limit);
    }
  }

  TEST_CASE("an exception in one chunk of a parallel_for reaches the caller and stops the loop") {
    // The solvers and estimators rely on it: a progress callback's or an Error's exception
    // thrown inside a loop must come out of the call, at every thread count (under
    // ThreadSanitizer, where parallel_for runs on std::threads, too).
    for (const unsigned threads : {1u, 2u, 4u}) {
      CAPTURE(threads);
      constexpr std::size_t n = 100000;
      std::atomic<std::size_t> done{0};
      try {
        core::parallel_for(threads, n, 16, [&](std::size_t begin, std::size_t end) {
          if (begin <= 5000 && 5000 < end) throw std::runtime_error("chunk at 5000");
          done += end - begin;
        });
        FAIL("no exception came out of parallel_for");
      } catch (const std::runtime_error& e) {
        CHECK(std::string(e.what()) == "chunk at 5000");
      }
      CHECK(done.load() < n);  // the chunks after it were not all run
    }
  }
}
