// The pinhole camera model shared by the renderers (render.cpp, path_tracer.cpp), so the
// radiosity display and the path-traced reference see exactly the same rays.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// Camera rays for an image of width x height pixels: `fov_deg` is the vertical field of view,
/// square pixels. Thread safety: immutable, direction() may be called concurrently.
struct PinholeCamera {
  glm::vec3 eye, forward, right, up;
  float tan_half_fov, aspect;

  PinholeCamera(const Camera& c, int width, int height)
      : eye(c.eye),
        forward(glm::normalize(c.look_at - c.eye)),
        right(glm::normalize(glm::cross(forward, c.up))),
        up(glm::cross(right, forward)),
        tan_half_fov(std::tan(glm::radians(0.5f * c.fov_deg))),
        aspect(static_cast<float>(width) / static_cast<float>(height)) {}

  /// Direction through image position (sx, sy) in [0,1]^2, (0,0) the top-left corner.
  glm::vec3 direction(float sx, float sy) const {
    float px = (2.0f * sx - 1.0f) * tan_half_fov * aspect;
    float py = (1.0f - 2.0f * sy) * tan_half_fov;
    return glm::normalize(forward + px * right + py * up);
  }
};

}  // namespace radiosity::detail
