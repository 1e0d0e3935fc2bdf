// DiscreteDistribution: probabilities proportional to the weights, and sample() hitting each
// item with its probability (each item's share of a fine uniform grid of u is its probability
// up to the grid step), zero-weight items never chosen, the table ending at exactly 1.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "core/distribution.hpp"

namespace rd = radiosity::detail;

TEST_SUITE("core") {
  TEST_CASE("DiscreteDistribution: each item is chosen with probability weight / sum") {
    const std::vector<double> weights{3.0, 0.0, 1.0, 6.0, 1e-9};
    const rd::DiscreteDistribution d(weights);
    REQUIRE(d.size() == weights.size());
    double total = 0.0;
    for (double w : weights) total += w;
    for (std::size_t i = 0; i < weights.size(); ++i) CHECK(d.probability(i) == doctest::Approx(weights[i] / total));

    // A uniform grid of u: item i gets about probability(i) of it, within one grid step.
    constexpr int kSteps = 1 << 20;
    std::vector<int> count(weights.size(), 0);
    for (int k = 0; k < kSteps; ++k) ++count[d.sample((static_cast<float>(k) + 0.5f) / kSteps)];
    for (std::size_t i = 0; i < weights.size(); ++i)
      CHECK(std::abs(static_cast<double>(count[i]) / kSteps - d.probability(i)) <= 2.0 / kSteps);
    CHECK(count[0] == doctest::Approx(0.3 * kSteps).epsilon(1e-4));
    CHECK(count[1] == 0);  // zero weight: never chosen
    CHECK(count[2] == doctest::Approx(0.1 * kSteps).epsilon(1e-4));
    CHECK(count[3] == doctest::Approx(0.6 * kSteps).epsilon(1e-4));
    // u at or beyond 1 (rounding upstream) still names an item: the last.
    CHECK(d.sample(1.0f) == weights.size() - 1);
    CHECK(d.sample(0.0f) == 0);
  }

  TEST_CASE("DiscreteDistribution: a single item takes every u") {
    const rd::DiscreteDistribution d(std::vector<double>{2.5});
    CHECK(d.probability(0) == 1.0);
    for (float u : {0.0f, 0.25f, 0.999999f}) CHECK(d.sample(u) == 0);
    CHECK(rd::DiscreteDistribution().empty());
  }
}
