// Sampling warps from [0,1)^2, each next to its pdf (pbrt-v4's util/sampling.h is the model),
// shared by the reflection models, the estimators, the path tracer and the photon map.
// Based on: P. Shirley, K. Chiu, "A low distortion map between disk and square", Journal of
// Graphics Tools 2(3), 1997 (the concentric map); Malley's method (T. Malley, MSc thesis,
// University of Utah, 1988): cosine-weighted directions are uniform disk points lifted to the
// hemisphere; G. Turk, "Generating random points in triangles", Graphics Gems (1990) (the square
// root warp for triangles); for quads, the bilinear map's Jacobian is linear in (s, t), so
// warping through the inverse CDFs of its marginal and conditional keeps strata intact (the
// inversion method of L. Devroye, "Non-Uniform Random Variate Generation", Springer 1986, ch. 2);
// CellMap, the polynomial maps of a cell for quadrature: the isoparametric map of finite
// elements (O. C. Zienkiewicz & R. L. Taylor, "The Finite Element Method").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/assert.hpp"
#include "core/constants.hpp"
#include "core/rng.hpp"

namespace radiosity::detail {

/// Concentric map of [0,1)^2 onto the unit disk: area-preserving (pdf 1/pi over the disk) and
/// continuous, so strata stay compact.
inline glm::vec2 concentric_disk(const glm::vec2& u) {
  const float a = 2.0f * u.x - 1.0f;
  const float b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r = 0.0f;
  float phi = 0.0f;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

/// Cosine-weighted direction around +z through the concentric disk (strata stay compact);
/// pdf cosine_hemisphere_pdf().
inline glm::vec3 cosine_hemisphere(const glm::vec2& u) {
  const glm::vec2 d = concentric_disk(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}

/// Cosine-weighted direction around +z through the polar map of the disk (r = sqrt(u.x),
/// phi = 2 pi u.y): the same density as cosine_hemisphere(), cheaper, strata stretched near
/// the pole; pdf cosine_hemisphere_pdf().
inline glm::vec3 cosine_hemisphere_polar(const glm::vec2& u) {
  const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x))};
}

/// Solid-angle density of both cosine warps at the local direction w: cos(theta) / pi above,
/// 0 below.
inline float cosine_hemisphere_pdf(const glm::vec3& w) { return w.z > 0.0f ? w.z * kInvPi : 0.0f; }

/// Area-uniform point of the triangle (c0, c1, c2) by the square-root warp: barycentrics
/// (1 - sqrt(u.x), sqrt(u.x) (1 - u.y), sqrt(u.x) u.y). Area density CellSampler::pdf().
inline glm::vec3 uniform_triangle(const glm::vec3& c0, const glm::vec3& c1, const glm::vec3& c2, const glm::vec2& u) {
  const float su = std::sqrt(u.x);
  return (1.0f - su) * c0 + (su * (1.0f - u.y)) * c1 + (su * u.y) * c2;
}

/// Area-uniform points of a cell, a triangle or a planar convex quad (corners counter-clockwise),
/// from [0,1)^2, with the per-cell constants computed once: the estimators draw millions of
/// them. Both warps are continuous and monotone, so (u,v) strata map to compact cells of equal
/// area. Quads use the bilinear map P(s,t) = (1-s)(1-t)c0 + s(1-t)c1 + st c2 + (1-s)t c3, whose
/// Jacobian J = A + B s + C t is linear for a planar quad: s is the inverse CDF of the marginal
/// density in s at u.x, t that of the conditional density in t at u.y (unlike picking one of two
/// triangles, which folds strata onto each other). A parallelogram (B = C = 0 up to rounding)
/// takes the plain affine map c0 + u.x (c1 - c0) + u.y (c3 - c0), the same map, cheaper.
/// Thread safety: a value; const members may be called concurrently.
class CellSampler {
 public:
  CellSampler() = default;
  /// `count` is 3 or 4.
  CellSampler(const glm::vec3* corners, int count) : count_(count) {
    RADIOSITY_ASSERT(count == 3 || count == 4);
    for (int k = 0; k < count; ++k) c_[k] = corners[k];
    if (count == 4) {
      const glm::vec3 n = glm::cross(c_[1] - c_[0], c_[2] - c_[0]) + glm::cross(c_[2] - c_[0], c_[3] - c_[0]);
      const glm::vec3 e0 = c_[1] - c_[0], e3 = c_[3] - c_[0], d = c_[0] - c_[1] + c_[2] - c_[3];
      // In double and divided by |n|^2: the terms grow as the fourth power of the cell's size
      // and linear() squares them, while the inverse CDF is the same for any common factor. In
      // float, a cell 0.1 mm across took f0^2 into the denormals, which a thread with
      // flush-to-zero set reads as 0: McGuire's Cornell box scaled to 0.5 mm came out 3 % dark,
      // and its rows depended on which thread computed them.
      const glm::dvec3 dn(n);
      const double scale = glm::dot(dn, dn);
      const double inverse = scale > 0.0 ? 1.0 / scale : 1.0;
      A_ = static_cast<float>(glm::dot(dn, glm::cross(glm::dvec3(e0), glm::dvec3(e3))) * inverse);
      B_ = static_cast<float>(glm::dot(dn, glm::cross(glm::dvec3(e0), glm::dvec3(d))) * inverse);
      C_ = static_cast<float>(glm::dot(dn, glm::cross(glm::dvec3(d), glm::dvec3(e3))) * inverse);
      parallelogram_ = std::fabs(B_) <= 1e-6f * std::fabs(A_) && std::fabs(C_) <= 1e-6f * std::fabs(A_);
    }
  }

  glm::vec3 operator()(const glm::vec2& u) const {
    if (count_ == 3) return uniform_triangle(c_[0], c_[1], c_[2], u);
    if (parallelogram_) return c_[0] + u.x * (c_[1] - c_[0]) + u.y * (c_[3] - c_[0]);
    const float s = linear(u.x, A_ + 0.5f * C_, A_ + B_ + 0.5f * C_);
    const float t = linear(u.y, A_ + B_ * s, A_ + B_ * s + C_);
    return (1.0f - s) * (1.0f - t) * c_[0] + s * (1.0f - t) * c_[1] + s * t * c_[2] + (1.0f - s) * t * c_[3];
  }

  /// Area density of the points: 1 / area (0 for a degenerate cell).
  float pdf() const {
    glm::vec3 n = glm::cross(c_[1] - c_[0], c_[2] - c_[0]);
    if (count_ == 4) n += glm::cross(c_[2] - c_[0], c_[3] - c_[0]);
    const float twice_area = glm::length(n);
    return twice_area > 0.0f ? 2.0f / twice_area : 0.0f;
  }

 private:
  // Inverse CDF of the density on [0,1] that is linear from f0 at 0 to f1 at 1 (both > 0), in
  // the form 2uT / (f0 + sqrt(f0^2 + 2(f1-f0)uT)), T = (f0+f1)/2, which stays exact as f1 -> f0.
  static float linear(float u, float f0, float f1) {
    const float total = 0.5f * (f0 + f1);
    const float disc = std::max(0.0f, f0 * f0 + 2.0f * (f1 - f0) * u * total);
    const float denom = f0 + std::sqrt(disc);
    return denom > 0.0f ? std::clamp(2.0f * u * total / denom, 0.0f, 1.0f) : u;
  }

  glm::vec3 c_[4]{};
  int count_ = 0;
  float A_ = 0.0f, B_ = 0.0f, C_ = 0.0f;
  bool parallelogram_ = false;
};

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

  /// The cell's area (0 for a degenerate cell).
  float area() const { return area_; }

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

/// Shuffles v[0 .. count) uniformly (Fisher-Yates): pairs one set of strata with another at
/// random (a Latin-hypercube-like padding of two stratified 2D sets into a 4D one).
template <typename T>
inline void shuffle(T* v, std::size_t count, Rng& rng) {
  for (std::size_t i = count; i > 1; --i) std::swap(v[i - 1], v[rng.below(static_cast<std::uint32_t>(i))]);
}

/// Stratified points on [0,1]^2, each of equal weight. `count` = a x b with a <= b <= 4a (the
/// factor pair closest to square; a g x g grid when count is a square): an a x b grid of equal
/// cells, one point in each (jittered, or the cell's centre). Other counts (primes, 2 x 97):
/// a Latin hypercube, `count` strata along u paired with `count` strata along v by a random
/// permutation (McKay, Beckman & Conover 1979), so both projections stay stratified. (Until
/// session 11 such counts had random v: 640 sky rays were measured no better than 320.)
inline void stratified(std::uint32_t count, Rng& rng, bool jitter, glm::vec2* out) {
  if (count == 0) return;
  auto rows = static_cast<std::uint32_t>(std::sqrt(static_cast<double>(count)));
  while (rows > 1 && count % rows != 0) --rows;
  const std::uint32_t columns = count / rows;
  if (columns <= 4 * rows) {
    for (std::uint32_t i = 0; i < rows; ++i)
      for (std::uint32_t k = 0; k < columns; ++k) {
        const glm::vec2 u = jitter ? rng.uniform2() : glm::vec2(0.5f);
        out[i * columns + k] = glm::vec2((static_cast<float>(i) + u.x) / static_cast<float>(rows),
                                         (static_cast<float>(k) + u.y) / static_cast<float>(columns));
      }
    return;
  }
  const auto n = static_cast<float>(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const glm::vec2 u = jitter ? rng.uniform2() : glm::vec2(0.5f);
    out[i] = glm::vec2((static_cast<float>(i) + u.x) / n, (static_cast<float>(i) + u.y) / n);
  }
  for (std::uint32_t i = count; i > 1; --i) std::swap(out[i - 1].y, out[rng.below(i)].y);
}

}  // namespace radiosity::detail
