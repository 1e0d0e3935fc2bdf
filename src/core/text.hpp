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

}  // namespace radiosity::detail
