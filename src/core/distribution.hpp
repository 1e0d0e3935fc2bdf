// Choosing one of n items with probability proportional to a weight: an emitter by its power
// (the path tracer, the two-pass view), a fan triangle by its area (PolygonFan). The inverse-CDF
// method over a cumulative table (pbrt-v4's PiecewiseConstant1D, discrete case).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/assert.hpp"

namespace radiosity::detail {

/// Index i with cdf[i-1] <= u < cdf[i] in a normalised cumulative table (last entry 1); the last
/// index for u >= 1.
inline std::size_t sample_cdf(const std::vector<float>& cdf, float u) {
  RADIOSITY_ASSERT(!cdf.empty());
  auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
  return std::min(static_cast<std::size_t>(it - cdf.begin()), cdf.size() - 1);
}

/// The distribution of weights w_i >= 0 (with a positive sum): probability(i) = w_i / sum w,
/// in double; sample(u) for u uniform in [0, 1) returns i with that probability. Sums run in
/// double in index order, and the table ends at exactly 1, so the last item is never lost to
/// rounding. Thread safety: immutable after construction.
class DiscreteDistribution {
 public:
  DiscreteDistribution() = default;
  explicit DiscreteDistribution(const std::vector<double>& weights) {
    double total = 0.0;
    for (double w : weights) total += w;
    RADIOSITY_ASSERT(weights.empty() || total > 0.0);
    double running = 0.0;
    probability_.reserve(weights.size());
    cdf_.reserve(weights.size());
    for (double w : weights) {
      const double p = w / total;
      running += p;
      probability_.push_back(p);
      cdf_.push_back(static_cast<float>(running));
    }
    if (!cdf_.empty()) cdf_.back() = 1.0f;
  }

  bool empty() const { return cdf_.empty(); }
  std::size_t size() const { return cdf_.size(); }
  double probability(std::size_t i) const { return probability_[i]; }
  std::size_t sample(float u) const { return sample_cdf(cdf_, u); }

 private:
  std::vector<double> probability_;
  std::vector<float> cdf_;
};

}  // namespace radiosity::detail
