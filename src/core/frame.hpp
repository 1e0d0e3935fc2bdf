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

}  // namespace radiosity::detail
