// Numbers in messages, one way everywhere.
#pragma once

#include <cstdio>
#include <string>

#include <glm/vec3.hpp>

namespace radiosity::detail {

/// "(x, y, z)" with 6 significant digits, for warnings and reasons that name a place.
inline std::string point_text(const glm::vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", static_cast<double>(p.x), static_cast<double>(p.y),
                static_cast<double>(p.z));
  return text;
}

/// The same for a place in a scene read with a local origin (Scene::origin()), in the file's
/// coordinates: `p` + `origin`, with 10 significant digits when the origin is not (0, 0, 0)
/// (georeferenced coordinates such as 5700456.7 need them).
inline std::string point_text(const glm::vec3& p, const glm::dvec3& origin) {
  if (origin == glm::dvec3(0.0)) return point_text(p);
  char text[128];
  std::snprintf(text, sizeof text, "(%.10g, %.10g, %.10g)", static_cast<double>(p.x) + origin.x,
                static_cast<double>(p.y) + origin.y, static_cast<double>(p.z) + origin.z);
  return text;
}

}  // namespace radiosity::detail
