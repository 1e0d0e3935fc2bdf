// The few collective operations a computation split among processes needs (docs/MPI.md): the
// solver and the lights' first shot call them, the MPI module (src/mpi/) implements them over an
// MPI communicator, so no algorithm includes <mpi.h> and a build without MPI compiles the same
// code. Every process holds the whole problem (scene, mesh, system) and computes a contiguous
// block of it; the blocks are then gathered so that every process holds the whole result.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// The processes that share a computation. Every member function is collective: each process
/// calls it, in the same order. Thread safety: the calling thread only (MPI_THREAD_FUNNELED).
class Communicator {
 public:
  virtual ~Communicator() = default;

  virtual int rank() const = 0;
  virtual int size() const = 0;

  /// `values` holds one entry per item; process r has filled in its block, items
  /// [offsets[r], offsets[r + 1]) (offsets has size() + 1 entries, as even_blocks() makes them).
  /// Afterwards every process holds every block. 12 bytes per item travel to each process.
  virtual void all_gather(std::vector<Rgb>& values, const std::vector<std::size_t>& offsets) const = 0;

  /// True on every process when `flag` is true on any.
  virtual bool any(bool flag) const = 0;

  /// The sum of `value` over the processes (integers: the same in any order).
  virtual std::uint64_t sum(std::uint64_t value) const = 0;

  /// A cancel that the progress callback asked for on this process (solve's on_progress): a
  /// process cannot stop alone, or the others would wait for it in the next collective, so the
  /// request is remembered here and agreed on with any() at the next sweep.
  mutable bool cancel_requested = false;
};

/// The blocks of `items` items among `processes`: process r gets [offsets[r], offsets[r + 1]),
/// contiguous, in order, sizes differing by at most one. processes + 1 entries.
inline std::vector<std::size_t> even_blocks(std::size_t items, int processes) {
  const auto n = static_cast<std::size_t>(processes);
  std::vector<std::size_t> offsets(n + 1);
  for (std::size_t r = 0; r <= n; ++r) offsets[r] = items / n * r + std::min(r, items % n);
  return offsets;
}

/// The blocks of `rows` rows whose cost is `weight_offsets` (rows + 1 entries: the weight of rows
/// [0, r), increasing; e.g. source elements) among `processes`: contiguous whole rows, block r
/// starting at the first row whose preceding weight reaches r / processes of the total.
inline std::vector<std::size_t> weighted_blocks(const std::vector<std::uint64_t>& weight_offsets, int processes) {
  const auto n = static_cast<std::size_t>(processes);
  const std::size_t rows = weight_offsets.size() - 1;
  const std::uint64_t total = weight_offsets.back();
  std::vector<std::size_t> offsets(n + 1, rows);
  offsets[0] = 0;
  std::size_t row = 0;
  for (std::size_t r = 1; r < n; ++r) {
    // r / n of the total weight (long double: no overflow of total x r).
    const long double target = static_cast<long double>(total) * static_cast<long double>(r) / static_cast<long double>(n);
    while (row < rows && static_cast<long double>(weight_offsets[row]) < target) ++row;
    offsets[r] = row;
  }
  return offsets;
}

}  // namespace radiosity::detail
