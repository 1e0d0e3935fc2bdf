// The progress gate every long computation reports through (solvers, renderers, view factors),
// so the promise of common.hpp holds everywhere: the callback runs on the calling thread, at
// phase boundaries and at most about every 50 ms in between, so a cancel is seen within about
// 50 ms plus the block of work under way (tests/solver/test_cancel_latency.cpp,
// benchmarks/bench_cancel.cpp: issue #17 asks for 100 ms at every stage).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// Wall-clock seconds since t0, for the timings in the reports.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Rate-limited progress reporting on the calling thread. report() returns false when the
/// callback asked to cancel. Holds a reference to the callback, which must outlive it.
class ProgressGate {
 public:
  explicit ProgressGate(const ProgressFn& fn) : fn_(fn) {}

  /// Whether report() would call the callback now: lets a caller skip building an expensive
  /// Progress that would be dropped. Phase boundaries, the first report and `force` always get
  /// through; within a phase at most one call per 50 ms.
  bool due(Phase phase, bool force = false) const {
    if (!fn_) return false;
    return force || first_ || phase != phase_ || std::chrono::steady_clock::now() - last_ >= kInterval;
  }

  /// Calls the callback with `p` when due(); returns its answer, or true when not called.
  bool report(const Progress& p, bool force = false) {
    if (!due(p.phase, force)) return true;
    first_ = false;
    phase_ = p.phase;
    last_ = std::chrono::steady_clock::now();
    return fn_(p);
  }

 private:
  static constexpr std::chrono::milliseconds kInterval{50};
  const ProgressFn& fn_;
  std::chrono::steady_clock::time_point last_{};
  Phase phase_ = Phase::meshing;
  bool first_ = true;
};

/// Sizes the blocks of work between two progress reports so that each takes about 15 ms: the
/// next block's item count from the last block's items per second, at most twice its count,
/// within [smallest, largest]. A loop whose items cost very different amounts in different scenes
/// (elements of a sky's first shot, rows of a view-factor matrix) so reports, and sees a
/// cancel, about as often as the gate allows, without a per-item check. Only for loops whose
/// results do not depend on where the blocks end (each item's work and random stream its own),
/// since the sizes follow the clock.
class BlockSizer {
 public:
  BlockSizer(std::size_t first, std::size_t smallest, std::size_t largest)
      : size_(std::clamp(first, smallest, largest)), smallest_(smallest), largest_(largest) {}

  /// Items in the next block.
  std::size_t size() const { return size_; }

  /// Restarts the clock: the next done() times from here (when other work came between).
  void start() { last_ = std::chrono::steady_clock::now(); }

  /// Call after each block of `items`: times it from the previous call (or construction).
  void done(std::size_t items) {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    if (!(seconds > 0.0) || items == 0) return;
    // At most twice the last block: items can cost far more further on (elements under a
    // partly covered sky cast five times the rays of those that see it all).
    const double next = std::min(static_cast<double>(items) * (kBlockSeconds / seconds), 2.0 * static_cast<double>(items));
    size_ = std::clamp(static_cast<std::size_t>(std::min(next, static_cast<double>(largest_))), smallest_, largest_);
  }

 private:
  static constexpr double kBlockSeconds = 0.015;
  std::size_t size_, smallest_, largest_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace radiosity::detail
