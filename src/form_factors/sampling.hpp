// The adaptive 2 x 2 Gauss rule over a cell, for the ray-cast estimator, the exact view factors
// and the hierarchical links' pairs that touch, through the cell's polynomial map of the unit
// square (CellMap, core/sampling.hpp).
// Based on: the isoparametric quadrature of finite elements (O. C. Zienkiewicz & R. L. Taylor,
// "The Finite Element Method"): integrals over a cell through its parametric map and Jacobian.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/sampling.hpp"

namespace radiosity::detail {

/// Gauss-Legendre 2-point nodes on [0,1]: 1/2 -+ 1/(2 sqrt 3).
inline constexpr float kGaussLo = 0.5f - 0.28867513459481287f, kGaussHi = 0.5f + 0.28867513459481287f;

/// The mean over the square [lo, lo + size]^2 of the unit square of f(st), whose 2x2 Gauss rule
/// is `coarse`, refined by quarters (each with its 2x2 Gauss rule) until the quarters' sum
/// agrees with the whole's within `tolerance` weighted by the square's share 4^-depth, or
/// `max_depth` is reached. Squares along the sides of the unit square flagged in `sides` (bit
/// 0: t = 0, 1: s = 1, 2: t = 1, 3: s = 0) are refined down to `side_depth` whatever their rules
/// say (a kink along that side, e.g. an occluder's edge). Used by the ray-cast estimator
/// (sides 0) and the exact view factors.
template <typename F>
double adaptive_gauss_mean(const F& f, glm::vec2 lo, float size, double coarse, int depth, int max_depth,
                           double tolerance, unsigned sides = 0, int side_depth = 0) {
  const float h = 0.5f * size;
  const glm::vec2 quarter[4] = {lo, lo + glm::vec2(h, 0.0f), lo + glm::vec2(0.0f, h), lo + glm::vec2(h, h)};
  std::array<double, 4> q{};
  double fine = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const glm::vec2 o = quarter[k];
    q[k] = 0.25 * (f(o + h * glm::vec2(kGaussLo, kGaussLo)) + f(o + h * glm::vec2(kGaussHi, kGaussLo)) +
                   f(o + h * glm::vec2(kGaussLo, kGaussHi)) + f(o + h * glm::vec2(kGaussHi, kGaussHi)));
    fine += 0.25 * q[k];
  }
  // Dyadic squares: these comparisons are exact.
  const unsigned touching = (lo.y == 0.0f ? 1u : 0u) | (lo.x + size == 1.0f ? 2u : 0u) |
                            (lo.y + size == 1.0f ? 4u : 0u) | (lo.x == 0.0f ? 8u : 0u);
  const bool forced = depth < side_depth && (touching & sides) != 0;
  if (!forced && (depth >= max_depth || std::ldexp(std::fabs(fine - coarse), -2 * depth) <= tolerance)) return fine;
  double sum = 0.0;
  for (std::size_t k = 0; k < 4; ++k)
    sum += 0.25 * adaptive_gauss_mean(f, quarter[k], h, q[k], depth + 1, std::max(max_depth, side_depth), tolerance,
                                      sides, side_depth);
  return sum;
}

}  // namespace radiosity::detail
