// Issue #17: a cancel takes effect at once at every stage (tests/support/cancel_stages.hpp has
// the stages and what is measured). A cancel must be honoured (the call says it was cancelled,
// and calls the callback no more); the latency and the largest gap between calls are printed
// and held under 1 s (5 s under the sanitizers), which catches "a cancel that takes seconds" on
// any machine. The target of 100 ms for both is measured on a quiet machine by
// benchmarks/bench_cancel.cpp, as the brief keeps speed targets there.
#include <doctest/doctest.h>

#include "support/build.hpp"
#include "support/cancel_stages.hpp"

TEST_SUITE("solver") {
  TEST_CASE("cancel: every stage stops soon after the callback asks, and calls it no more") {
    const double bound = test::kSanitizerBuild ? 5.0 : 1.0;
    // 2.5 cm elements, 256-pixel images and a terrain of 600k triangles: every stage runs well
    // past the 0.15 s at which the probe cancels.
    const cancel::Stages stages(625.0f, 256, 512, 600000);
    for (const cancel::Stage& stage : stages.list()) {
      CAPTURE(stage.name);
      cancel::Probe probe{stage.phase};
      probe.run(stage.call);
      MESSAGE(stage.name << ": cancelled after " << probe.phase_seconds << " s in the phase, latency "
                         << 1e3 * probe.latency << " ms, largest gap between calls " << 1e3 * probe.largest_gap
                         << " ms");
      REQUIRE(probe.cancelled);  // the stage ran long enough to be cancelled
      CHECK(stage.reports_cancel());
      CHECK(probe.calls_after_cancel == 0);
      CHECK(probe.latency < bound);
      CHECK(probe.largest_gap < bound);
    }
  }
}
