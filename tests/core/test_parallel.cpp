// The shared parallel loop (src/core/parallel.hpp): every index once, and a loop nested in
// another's body runs in the enclosing loop's threads.
#include <doctest/doctest.h>

#include <atomic>
#include <vector>

#include <tbb/task_arena.h>

#include "core/parallel.hpp"

namespace core = radiosity::detail;

TEST_SUITE("core") {
  TEST_CASE("a nested parallel_for covers every index once and stays within the outer thread count") {
    // The inner loops ask for more threads than the outer one has: they run in its arena, so
    // no body sees more concurrency than the outer count (an arena per nested call would).
    for (const unsigned outer : {0u, 2u}) {
      CAPTURE(outer);
      constexpr std::size_t n = 64, m = 256;
      std::vector<std::atomic<int>> hits(n * m);
      std::atomic<int> widest{0};
      const int limit = core::thread_count(outer);
      core::parallel_for(outer, n, 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          core::parallel_for(3, m, 8, [&](std::size_t b, std::size_t e) {
            int w = tbb::this_task_arena::max_concurrency();
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
}
