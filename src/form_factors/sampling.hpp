// A cell (triangle or planar convex quad) as a polynomial map of the unit square, for the
// quadrature of the ray-cast and hemicube estimators (the area-uniform warp, CellSampler, is in
// core/sampling.hpp).
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

/// A cell (triangle or planar convex quad) as a map from the unit square, for quadrature: the
/// mean of f over the cell is the integral over [0,1]^2 of f(point(s,t)) density(s,t). Quads use
/// the bilinear map (density = Jacobian / area, affine in (s,t)); triangles the collapsed square
/// p0 + s ((1-t)(p1-p0) + t(p2-p0)) (density 2s). Unlike the area-uniform warp of CellSampler
/// (a square root for triangles), both maps are polynomial, so Gauss rules keep their order.
class CellMap {
 public:
  CellMap() = default;
  CellMap(const glm::vec3* corners, int count) : count_(count) {
    for (int k = 0; k < count; ++k) c_[k] = corners[k];
    if (count == 3) {
      area_ = 0.5f * glm::length(glm::cross(c_[1] - c_[0], c_[2] - c_[0]));
    } else {
      area_ = 0.5f * glm::length(glm::cross(c_[1] - c_[0], c_[2] - c_[0]) + glm::cross(c_[2] - c_[0], c_[3] - c_[0]));
    }
  }

  glm::vec3 point(glm::vec2 st) const {
    const float s = st.x, t = st.y;
    if (count_ == 3) return c_[0] + s * ((1.0f - t) * (c_[1] - c_[0]) + t * (c_[2] - c_[0]));
    return (1.0f - s) * (1.0f - t) * c_[0] + s * (1.0f - t) * c_[1] + s * t * c_[2] + (1.0f - s) * t * c_[3];
  }

  /// Area density relative to the mean: |dP/ds x dP/dt| / area.
  float density(glm::vec2 st) const {
    if (count_ == 3) return 2.0f * st.x;
    if (!(area_ > 0.0f)) return 1.0f;
    const glm::vec3 ds = (1.0f - st.y) * (c_[1] - c_[0]) + st.y * (c_[2] - c_[3]);
    const glm::vec3 dt = (1.0f - st.x) * (c_[3] - c_[0]) + st.x * (c_[2] - c_[1]);
    return glm::length(glm::cross(ds, dt)) / area_;
  }

 private:
  glm::vec3 c_[4]{};
  int count_ = 0;
  float area_ = 0.0f;
};

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
