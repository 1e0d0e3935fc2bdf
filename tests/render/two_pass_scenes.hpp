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

/// The built-in Cornell box with a mirror tall block (specular 0.9, no diffuse part) and a glass
/// short block (index 1.5, clear, no diffuse part).
inline rad::Scene cornell_specular() {
  const rad::Scene base = rad::cornell_box();
  rad::Scene scene;
  std::vector<rad::MaterialId> ids;
  for (const rad::Material& m : base.materials()) ids.push_back(scene.add_material(m));
  rad::Material mirror;
  mirror.name = "mirror";
  mirror.reflectance = rad::Rgb(0.0f);
  mirror.specular = rad::Rgb(0.9f);
  rad::Material glass;
  glass.name = "glass";
  glass.reflectance = rad::Rgb(0.0f);
  glass.transmittance = rad::Rgb(1.0f);
  glass.ior = 1.5f;
  const rad::MaterialId mirror_id = scene.add_material(mirror), glass_id = scene.add_material(glass);
  for (const rad::Polygon& p : base.polygons()) {
    const std::string& group = base.groups()[p.group];
    const rad::MaterialId m = group == "tall_block" ? mirror_id : group == "short_block" ? glass_id : ids[p.material];
    scene.add_polygon(p.vertices, m, group);
  }
  scene.set_camera(base.camera());
  return scene;
}

}  // namespace test
