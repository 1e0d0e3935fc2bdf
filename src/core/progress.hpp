// The progress gate every long computation reports through (solvers, renderers, view factors),
// so the promise of common.hpp holds everywhere: the callback runs on the calling thread, at
// phase boundaries and at most about every 100 ms in between.
#pragma once

#include <chrono>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// Rate-limited progress reporting on the calling thread. report() returns false when the
/// callback asked to cancel. Holds a reference to the callback, which must outlive it.
class ProgressGate {
 public:
  explicit ProgressGate(const ProgressFn& fn) : fn_(fn) {}

  /// Whether report() would call the callback now: lets a caller skip building an expensive
  /// Progress that would be dropped. Phase boundaries, the first report and `force` always get
  /// through; within a phase at most one call per 100 ms.
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
  static constexpr std::chrono::milliseconds kInterval{100};
  const ProgressFn& fn_;
  std::chrono::steady_clock::time_point last_{};
  Phase phase_ = Phase::meshing;
  bool first_ = true;
};

}  // namespace radiosity::detail
