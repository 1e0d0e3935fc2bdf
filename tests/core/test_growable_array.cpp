// The shared core's GrowableArray (src/core/growable_array.hpp): values survive growing and
// shrinking across the size where a block becomes its own mapping, and moves hand the block over.
#include <doctest/doctest.h>

#include <cstdint>
#include <utility>

#include "core/growable_array.hpp"

namespace core = radiosity::detail;

TEST_SUITE("core") {
  TEST_CASE("GrowableArray keeps its values through growing, shrinking and moving") {
    core::GrowableArray<std::uint32_t> a;
    CHECK(a.empty());
    // 100 values (heap), 1M (4 MiB: a mapping of its own on Linux), 3M, back to 1000 (heap).
    std::size_t filled = 0;
    for (const std::size_t n : {std::size_t{100}, std::size_t{1} << 20, std::size_t{3} << 20}) {
      a.resize(n);
      REQUIRE(a.size() == n);
      for (std::size_t i = filled; i < n; ++i) a[i] = static_cast<std::uint32_t>(i * 2654435761u);
      filled = n;
      bool same = true;
      for (std::size_t i = 0; i < n; ++i) same &= a[i] == static_cast<std::uint32_t>(i * 2654435761u);
      CHECK(same);
    }
    a.resize(1000);
    bool same = true;
    for (std::size_t i = 0; i < a.size(); ++i) same &= a[i] == static_cast<std::uint32_t>(i * 2654435761u);
    CHECK(same);
    CHECK(a.size() == 1000);

    core::GrowableArray<std::uint32_t> b = std::move(a);
    CHECK(a.empty());  // NOLINT(bugprone-use-after-move): the moved-from array is empty by contract
    CHECK(b.size() == 1000);
    CHECK(b[999] == static_cast<std::uint32_t>(999u * 2654435761u));
    b.clear();
    CHECK(b.empty());
    CHECK(b.data() == nullptr);
  }
}
