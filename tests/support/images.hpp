// Image comparisons shared by the rendering tests.
#pragma once

#include <cmath>
#include <cstddef>

#include <radiosity/render.hpp>

namespace test {

/// Relative RMSE as issues #4 and #6 define it: sqrt(mean over pixels and channels of
/// (a - b)^2) divided by the mean of b over pixels and channels (b is the reference).
inline double relative_rmse(const radiosity::Image& a, const radiosity::Image& b) {
  double se = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < b.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a.pixels[i][c]) - b.pixels[i][c];
      se += d * d;
      sum += b.pixels[i][c];
    }
  const double n = 3.0 * static_cast<double>(b.pixels.size());
  return std::sqrt(se / n) / (sum / n);
}

/// Mean of a over the mean of b, over pixels and channels.
inline double mean_ratio(const radiosity::Image& a, const radiosity::Image& b) {
  double sa = 0.0, sb = 0.0;
  for (std::size_t i = 0; i < b.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      sa += a.pixels[i][c];
      sb += b.pixels[i][c];
    }
  return sa / sb;
}

}  // namespace test
