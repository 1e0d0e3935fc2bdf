// The memory budget that every large allocation is checked against before it is made
// (SolveOptions, ViewFactorOptions and PhotonOptions::memory_budget_bytes): a computation that
// would exceed it is refused with the figure, an Error{memory_budget} the host can act on,
// instead of a std::bad_alloc (or the system's out-of-memory killer) partway through.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

#include "radiosity/common.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace radiosity::detail {

/// The budget when an options struct leaves it at 0.
inline constexpr std::size_t kDefaultMemoryBudget = std::size_t{4} << 30;

/// `bytes`, or the default for 0.
inline std::size_t resolve_memory_budget(std::size_t bytes) { return bytes == 0 ? kDefaultMemoryBudget : bytes; }

/// "1234 MiB", "1.04 MiB": whole MiB from 10 MiB on, else two decimals (so that a figure just
/// over a small budget does not print as the budget).
inline std::string mib_text(double bytes) {
  const double mib = bytes / (1024.0 * 1024.0);
  char text[48];
  std::snprintf(text, sizeof text, mib >= 10.0 ? "%.0f MiB" : "%.2f MiB", mib);
  return text;
}

/// Throws Error{memory_budget}: "<what> needs <bytes>, over the memory budget of <budget>
/// (<field>)<advice>".
[[noreturn]] inline void refuse_memory(const std::string& what, double bytes, std::size_t budget, const char* field,
                                       const std::string& advice) {
  throw Error(ErrorCode::memory_budget, what + " needs " + mib_text(bytes) + ", over the memory budget of " +
                                            mib_text(static_cast<double>(budget)) + " (" + field + ")" + advice);
}

/// Gives the heap's free pages back to the system (glibc's malloc_trim; nothing elsewhere), after
/// a phase has freed large transient arrays. glibc keeps a freed block in the arena of the
/// thread that allocated it, and raises its mmap threshold whenever a mapped block is freed,
/// so later large blocks come from the heap as well; the next phase's arrays were then mapped
/// afresh beside resident pages that held nothing. The hierarchical solver calls it after each
/// refinement round and merge (alone, on session 26's rounds: the 246k city's peak RSS 494-512
/// -> 466 MiB; with the rounds' pairs kept in segments too, 450-464 MiB; docs/HIERARCHICAL.md).
/// Thread safety: may be called concurrently with any allocation.
inline void release_free_heap() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace radiosity::detail
