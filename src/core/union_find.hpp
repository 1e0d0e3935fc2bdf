// Union-find (disjoint sets) over the indices 0 .. n-1 of a parent array, with path halving.
// Based on: R. E. Tarjan & J. van Leeuwen, "Worst-case analysis of set union algorithms",
// JACM 31(2), 1984 (path halving). The smaller index becomes the root, so every class's root is
// its first member whatever the order of the unions: results that follow the roots do not
// depend on it. Thread safety: mutates `parent`.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace radiosity::detail {

/// `parent` as n singletons.
inline void make_sets(std::vector<std::uint32_t>& parent, std::size_t n) {
  parent.resize(n);
  std::iota(parent.begin(), parent.end(), 0u);
}

/// The root (first member) of x's class.
inline std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

/// Joins the classes of a and b.
inline void unite(std::vector<std::uint32_t>& parent, std::uint32_t a, std::uint32_t b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a < b) parent[b] = a;
  else if (b < a) parent[a] = b;
}

}  // namespace radiosity::detail
