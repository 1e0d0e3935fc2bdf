// A cell (triangle or planar convex quad) as a polynomial map of the unit square, for the
// quadrature of the ray-cast and hemicube estimators (the area-uniform warp, CellSampler, is in
// core/sampling.hpp).
// Based on: the isoparametric quadrature of finite elements (O. C. Zienkiewicz & R. L. Taylor,
// "The Finite Element Method"): integrals over a cell through its parametric map and Jacobian.
#pragma once

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

}  // namespace radiosity::detail
