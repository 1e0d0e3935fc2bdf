// Small scenes with specular surfaces for the two-pass tests.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

namespace test {

namespace rad = radiosity;

/// Adds a quad turned so that its normal points along `facing`.
inline void add_quad(rad::Scene& scene, std::vector<glm::vec3> q, const glm::vec3& facing, rad::MaterialId m,
                     const char* group) {
  const glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
  if (glm::dot(n, facing) < 0.0f) std::reverse(q.begin(), q.end());
  scene.add_polygon(q, m, group);
}

/// An axis-aligned box [lo, hi] of six outward-facing quads.
inline void add_box(rad::Scene& scene, const glm::vec3& lo, const glm::vec3& hi, rad::MaterialId m, const char* group) {
  const glm::vec3 a = lo, b = hi;
  add_quad(scene, {{a.x, a.y, a.z}, {a.x, b.y, a.z}, {a.x, b.y, b.z}, {a.x, a.y, b.z}}, {-1, 0, 0}, m, group);
  add_quad(scene, {{b.x, a.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {b.x, a.y, b.z}}, {1, 0, 0}, m, group);
  add_quad(scene, {{a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, a.y, b.z}, {a.x, a.y, b.z}}, {0, -1, 0}, m, group);
  add_quad(scene, {{a.x, b.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}}, {0, 1, 0}, m, group);
  add_quad(scene, {{a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {a.x, b.y, a.z}}, {0, 0, -1}, m, group);
  add_quad(scene, {{a.x, a.y, b.z}, {b.x, a.y, b.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}}, {0, 0, 1}, m, group);
}

}  // namespace test
