// Buried points: points of a surface that lie inside a solid standing on it, such as the floor
// under a block resting on it, or the part of a prop sunk into the floor. Every estimator sees
// them dark (a ray that reaches the back of a one-sided polygon is blocked there: docs/
// FORM_FACTORS.md, "Touching, interpenetrating and coincident geometry"); the solvers need to
// know how much of an element is buried, so that an element straddling a block's edge is not
// taken for its area mean (half its open part's light) nor its buried part for a surface that
// sends light (docs/ARCHITECTURE.md, "Contact and light leaks").
#pragma once

#include <array>
#include <limits>
#include <optional>

#include <glm/vec3.hpp>

#include "core/frame.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity::detail {

/// The rays of the burial test around the unit normal `n`: the normal, and three at 60 degrees
/// from it, 120 degrees apart.
inline std::array<glm::vec3, 4> burial_directions(const glm::vec3& n) {
  const Frame frame(n);
  constexpr float kSin = 0.8660254f, kCos = 0.5f;  // 60 degrees
  return {frame.to_world(glm::vec3(0.0f, 0.0f, 1.0f)), frame.to_world(glm::vec3(kSin, 0.0f, kCos)),
          frame.to_world(glm::vec3(-0.5f * kSin, 0.8660254f * kSin, kCos)),
          frame.to_world(glm::vec3(-0.5f * kSin, -0.8660254f * kSin, kCos))};
}

/// Whether the point `x` (already lifted off its surface) is buried: every ray of
/// burial_directions() ends on a sealed surface, `sealed(hit, direction)` (the back of a
/// one-sided polygon). A point under a block standing on it sees only the block's insides every
/// way; a point under a one-sided table top sees its back above but out to the sides. Stops
/// at the first open ray, so an open point costs one ray.
template <typename Sealed>
bool buried(const RayScene& scene, const glm::vec3& x, const std::array<glm::vec3, 4>& directions,
            const Sealed& sealed) {
  for (const glm::vec3& d : directions) {
    const std::optional<RayScene::Hit> hit = scene.intersect(x, d, 0.0f, std::numeric_limits<float>::infinity());
    if (!hit || !sealed(*hit, d)) return false;
  }
  return true;
}

}  // namespace radiosity::detail
