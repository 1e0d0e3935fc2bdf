// One check of a pinhole camera for every place that takes one (Scene::set_camera, the three
// renderers' validate()), so that they accept and refuse the same cameras with the same words.
#pragma once

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// What makes `c` unusable, or "" when nothing does: a non-finite value, a field of view
/// outside (0, 180) degrees, look_at equal to eye, or an up vector that is zero or parallel to
/// the view direction (within 1e-6 of its length). Messages name the field ("camera.fov_deg
/// must be in (0, 180), got 190").
inline std::string camera_problem(const Camera& c) {
  auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(c.eye) || !finite(c.look_at) || !finite(c.up)) return "camera: eye, look_at and up must be finite";
  if (!(c.fov_deg > 0.0f && c.fov_deg < 180.0f))
    return "camera.fov_deg must be in (0, 180), got " + std::to_string(c.fov_deg);
  const glm::vec3 forward = c.look_at - c.eye;
  const float length = glm::length(forward);
  if (!(length > 0.0f)) return "camera.look_at must differ from camera.eye";
  if (!(glm::length(glm::cross(forward / length, c.up)) > 1e-6f * glm::length(c.up)))
    return "camera.up must be non-zero and not parallel to the view direction";
  return {};
}

}  // namespace radiosity::detail
