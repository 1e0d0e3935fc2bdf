// Sampling warps from [0,1)^2, each next to its pdf (pbrt-v4's util/sampling.h is the model),
// shared by the reflection models, the estimators, the path tracer and the photon map.
// Based on: P. Shirley, K. Chiu, "A low distortion map between disk and square", Journal of
// Graphics Tools 2(3), 1997 (the concentric map); Malley's method (T. Malley, MSc thesis,
// University of Utah, 1988): cosine-weighted directions are uniform disk points lifted to the
// hemisphere.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/constants.hpp"

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

}  // namespace radiosity::detail
