// Directions over a hemisphere, shared by the estimators and the scene checks: cosine-weighted
// directions from stratified points, and a frame around a normal to turn them into the world.
// Based on: P. Shirley, K. Chiu, "A low distortion map between disk and square", Journal of
// Graphics Tools 2(3), 1997 (the concentric map; Malley's method lifts it to the hemisphere);
// T. Duff et al., "Building an orthonormal basis, revisited", JCGT 6(1), 2017 (the frame).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace radiosity::detail {

/// Cosine-distributed direction around +z from a point of [0,1)^2 (pdf cos(theta) / pi): the
/// concentric map to the disk, then up to the hemisphere; strata stay compact.
inline glm::vec3 cosine_direction(glm::vec2 u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f, 1.0f};
  constexpr float kQuarterPi = 0.25f * glm::pi<float>();
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = kQuarterPi * (b / a);
  } else {
    r = b;
    phi = 2.0f * kQuarterPi - kQuarterPi * (a / b);
  }
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y))};
}

/// Tangents completing a unit normal to a right-handed frame (t, b, n).
inline void tangents(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

}  // namespace radiosity::detail
