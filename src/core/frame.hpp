// A right-handed orthonormal frame around a unit normal, for every module that turns local
// directions (around +z) into world ones.
// Based on: T. Duff, J. Burgess, P. Christensen, C. Hery, A. Kensler, M. Liani, R. Villemin,
// "Building an orthonormal basis, revisited", JCGT 6(1), 2017 (listing 3: branchless,
// continuous except on the plane n.z = 0 where the sign flips).
#pragma once

#include <cmath>

#include <glm/vec3.hpp>

namespace radiosity::detail {

/// Tangents t, b completing the unit normal n to a right-handed frame (t x b = n).
inline void tangent_frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

/// The frame of tangent_frame() as a value: local directions (z along the normal) to world
/// ones, for the modules that draw directions around a surface normal (ray-cast rows, sky and
/// enclosure rays, lights, bakes). to_world() keeps the unit length of a unit local direction.
struct Frame {
  glm::vec3 t, b, n;
  explicit Frame(const glm::vec3& normal) : n(normal) { tangent_frame(n, t, b); }
  glm::vec3 to_world(const glm::vec3& local) const { return local.x * t + local.y * b + local.z * n; }
};

}  // namespace radiosity::detail
