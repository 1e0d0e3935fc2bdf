// Area-uniform points on a patch or element (a triangle or a planar convex quad), with the
// per-polygon constants computed once: the estimators draw millions of them.
// Based on: G. Turk, "Generating random points in triangles", Graphics Gems (1990) (the square
// root warp for triangles); for quads
// the bilinear map's Jacobian is linear in (s, t), so inverting its marginal and conditional
// CDFs keeps (u, v) strata intact (as PatchHierarchy::sample_point does).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace radiosity::detail {

class CellSampler {
 public:
  CellSampler() = default;
  /// `count` is 3 or 4; corners counter-clockwise.
  CellSampler(const glm::vec3* corners, int count) : count_(count) {
    for (int k = 0; k < count; ++k) c_[k] = corners[k];
    if (count == 4) {
      const glm::vec3 n = glm::cross(c_[1] - c_[0], c_[2] - c_[0]) + glm::cross(c_[2] - c_[0], c_[3] - c_[0]);
      const glm::vec3 e0 = c_[1] - c_[0], e3 = c_[3] - c_[0], d = c_[0] - c_[1] + c_[2] - c_[3];
      A_ = glm::dot(n, glm::cross(e0, e3));
      B_ = glm::dot(n, glm::cross(e0, d));
      C_ = glm::dot(n, glm::cross(d, e3));
      // A parallelogram (d = 0) has a constant Jacobian: the plain affine map is uniform.
      parallelogram_ = std::fabs(B_) <= 1e-6f * std::fabs(A_) && std::fabs(C_) <= 1e-6f * std::fabs(A_);
    }
  }

  glm::vec3 operator()(glm::vec2 uv) const {
    if (count_ == 3) {
      const float su = std::sqrt(uv.x);
      return (1.0f - su) * c_[0] + (su * (1.0f - uv.y)) * c_[1] + (su * uv.y) * c_[2];
    }
    if (parallelogram_) return c_[0] + uv.x * (c_[1] - c_[0]) + uv.y * (c_[3] - c_[0]);
    const float s = linear(uv.x, A_ + 0.5f * C_, A_ + B_ + 0.5f * C_);
    const float t = linear(uv.y, A_ + B_ * s, A_ + B_ * s + C_);
    return (1.0f - s) * (1.0f - t) * c_[0] + s * (1.0f - t) * c_[1] + s * t * c_[2] + (1.0f - s) * t * c_[3];
  }

 private:
  // Inverse CDF of the density on [0,1] that is linear from f0 to f1, in a form that stays
  // exact as f1 -> f0.
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

}  // namespace radiosity::detail
