// The built-in Cornell box, and its variant with a mirror and a glass block.
// Based on: the Cornell Box data published by the Cornell University Program of Computer
// Graphics (geometry in mm, measured reflectances), and Goral, Torrance, Greenberg & Battaile,
// "Modeling the interaction of light between diffuse surfaces", SIGGRAPH 1984.
#include <algorithm>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using Quad = std::vector<glm::vec3>;

// The published vertex order is not consistent about facing; orient each polygon so that its
// normal points towards `towards` (the room's inside) or away from `away` (a block's centre).
Quad facing(Quad q, const glm::vec3& towards) {
  glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
  if (glm::dot(n, towards - q[0]) < 0.0f) std::reverse(q.begin(), q.end());
  return q;
}

Quad facing_away(Quad q, const glm::vec3& from) {
  glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
  if (glm::dot(n, q[0] - from) < 0.0f) std::reverse(q.begin(), q.end());
  return q;
}

/// The published box; each block is white unless given its own material.
Scene build_cornell_box(const std::optional<Material>& short_block, const std::optional<Material>& tall_block) {
  Scene scene;
  Material white, red, green, light;
  white.name = "white";
  white.reflectance = Rgb(0.725f, 0.71f, 0.68f);
  red.name = "red";
  red.reflectance = Rgb(0.63f, 0.065f, 0.05f);
  green.name = "green";
  green.reflectance = Rgb(0.14f, 0.45f, 0.091f);
  light.name = "light";
  light.reflectance = Rgb(0.78f);
  // Radiance (17, 12, 4) from a Lambertian emitter is an exitance of pi times that.
  light.emission = glm::pi<float>() * Rgb(17.0f, 12.0f, 4.0f);
  const MaterialId w = scene.add_material(white), r = scene.add_material(red), g = scene.add_material(green),
                   l = scene.add_material(light);

  const glm::vec3 inside(278.0f, 274.0f, 280.0f);
  scene.add_polygon(facing({{552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f}}, inside), w, "floor");

  // The ceiling is cut around the light (x 213..343, z 227..332) so that no surfaces overlap.
  const float y = 548.8f;
  scene.add_polygon(facing({{556.0f, y, 0}, {556.0f, y, 227.0f}, {0, y, 227.0f}, {0, y, 0}}, inside), w, "ceiling");
  scene.add_polygon(facing({{556.0f, y, 332.0f}, {556.0f, y, 559.2f}, {0, y, 559.2f}, {0, y, 332.0f}}, inside), w,
                    "ceiling");
  scene.add_polygon(facing({{556.0f, y, 227.0f}, {556.0f, y, 332.0f}, {343.0f, y, 332.0f}, {343.0f, y, 227.0f}}, inside),
                    w, "ceiling");
  scene.add_polygon(facing({{213.0f, y, 227.0f}, {213.0f, y, 332.0f}, {0, y, 332.0f}, {0, y, 227.0f}}, inside), w,
                    "ceiling");
  scene.add_polygon(facing({{343.0f, y, 227.0f}, {343.0f, y, 332.0f}, {213.0f, y, 332.0f}, {213.0f, y, 227.0f}}, inside),
                    l, "light");

  scene.add_polygon(facing({{549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, y, 559.2f}, {556.0f, y, 559.2f}}, inside), w,
                    "back_wall");
  scene.add_polygon(facing({{0, 0, 559.2f}, {0, 0, 0}, {0, y, 0}, {0, y, 559.2f}}, inside), g, "green_wall");
  // The published red wall is 3 mm out of plane; add_polygon splits it into two triangles.
  scene.add_polygon(facing({{552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556.0f, y, 559.2f}, {556.0f, y, 0}}, inside), r,
                    "red_wall");

  const MaterialId short_id = short_block ? scene.add_material(*short_block) : w;
  const MaterialId tall_id = tall_block ? scene.add_material(*tall_block) : w;
  // The blocks have no bottom face: they stand on the floor, which closes them (a glass block's
  // floor is seen from inside the glass).
  auto add_block = [&](const std::vector<Quad>& faces, MaterialId material, const char* group) {
    glm::vec3 centre(0.0f);
    int n = 0;
    for (const Quad& q : faces)
      for (const glm::vec3& p : q) centre += p, ++n;
    centre /= static_cast<float>(n);
    for (const Quad& q : faces) scene.add_polygon(facing_away(q, centre), material, group);
  };
  add_block({{{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}},
             {{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}},
             {{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}},
             {{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}},
             {{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}},
            short_id, "short_block");
  add_block({{{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}},
             {{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}},
             {{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}},
             {{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}},
             {{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}},
            tall_id, "tall_block");

  Camera camera;
  camera.eye = glm::vec3(278.0f, 273.0f, -800.0f);
  camera.look_at = glm::vec3(278.0f, 273.0f, 0.0f);
  camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  camera.fov_deg = 39.3077f;
  scene.set_camera(camera);
  return scene;
}

}  // namespace

Scene cornell_box() { return build_cornell_box(std::nullopt, std::nullopt); }

Scene cornell_box_specular(CornellSpecular blocks) {
  // An ideal mirror (diffuse 0, so all of its albedo is specular) and clear glass (white tint,
  // so Fresnel reflection + transmission = 1, and no diffuse part).
  Material mirror, glass;
  mirror.name = "mirror";
  mirror.reflectance = Rgb(0.0f);
  mirror.specular = Rgb(0.95f);
  mirror.specular_exponent = 0.0f;
  glass.name = "glass";
  glass.reflectance = Rgb(0.0f);
  glass.transmittance = Rgb(1.0f);
  glass.ior = 1.5f;
  const bool with_mirror = blocks != CornellSpecular::glass, with_glass = blocks != CornellSpecular::mirror;
  return build_cornell_box(with_glass ? std::optional<Material>(glass) : std::nullopt,
                           with_mirror ? std::optional<Material>(mirror) : std::nullopt);
}

}  // namespace v1
}  // namespace radiosity
