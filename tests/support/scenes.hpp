// Small scenes and closed-form references shared by the tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

namespace test {

namespace rad = radiosity;

/// An axis-aligned box [0,sx]x[0,sy]x[0,sz] of six inward-facing quads, one material, groups
/// "x0","x1","y0","y1","z0","z1".
inline rad::Scene closed_box(const rad::Material& m, glm::vec3 s = glm::vec3(1.0f)) {
  rad::Scene scene;
  rad::MaterialId id = scene.add_material(m);
  const float X = s.x, Y = s.y, Z = s.z;
  const glm::vec3 centre = 0.5f * s;
  // Each face is listed once and turned to face the centre.
  auto add = [&](std::vector<glm::vec3> q, const char* group) {
    glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
    if (glm::dot(n, centre - q[0]) < 0.0f) std::reverse(q.begin(), q.end());
    scene.add_polygon(q, id, group);
  };
  add({{0, 0, 0}, {0, 0, Z}, {0, Y, Z}, {0, Y, 0}}, "x0");
  add({{X, 0, 0}, {X, Y, 0}, {X, Y, Z}, {X, 0, Z}}, "x1");
  add({{0, 0, 0}, {X, 0, 0}, {X, 0, Z}, {0, 0, Z}}, "y0");
  add({{0, Y, 0}, {0, Y, Z}, {X, Y, Z}, {X, Y, 0}}, "y1");
  add({{0, 0, 0}, {0, Y, 0}, {X, Y, 0}, {X, 0, 0}}, "z0");
  add({{0, 0, Z}, {X, 0, Z}, {X, Y, Z}, {0, Y, Z}}, "z1");
  return scene;
}

/// `scene`'s polygons (materials and groups kept; lights and camera not) turned by `degrees`
/// about the vertical line through `pivot`: the same scene with every wall off the axes.
inline rad::Scene turned_about_y(const rad::Scene& scene, float degrees, glm::vec3 pivot = glm::vec3(0.0f)) {
  rad::Scene out;
  for (const rad::Material& m : scene.materials()) out.add_material(m);
  const float t = degrees * 3.14159265f / 180.0f, c = std::cos(t), s = std::sin(t);
  for (const rad::Polygon& p : scene.polygons()) {
    std::vector<glm::vec3> v;
    for (const glm::vec3& x : p.vertices) {
      const glm::vec3 d = x - pivot;
      v.push_back(pivot + glm::vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z));
    }
    out.add_polygon(v, p.material, scene.groups()[p.group]);
  }
  return out;
}

/// A point light named `name` (a light group of its own) of `intensity` W/sr at `position`.
inline rad::Light point_light(const char* name, float intensity, const glm::vec3& position) {
  rad::Light l;
  l.name = name;
  l.intensity = intensity;
  l.position = position;
  return l;
}

/// A MeshDesc over the caller's arrays (which must outlive the add_mesh call), every triangle of
/// `material`, with UV1 when `uv1` is not empty.
inline rad::MeshDesc mesh_desc(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                               rad::MaterialId material, std::string_view group = {},
                               const std::vector<glm::vec2>& uv1 = {}) {
  rad::MeshDesc d;
  d.positions = positions.data();
  d.vertex_count = positions.size();
  d.indices = indices.data();
  d.index_count = indices.size();
  d.material = material;
  d.group = group;
  d.uv1 = uv1.empty() ? nullptr : uv1.data();
  return d;
}

/// The unit cube [0,1]^3 as an indexed triangle mesh facing inwards: 8 shared corners and 12
/// triangles, each face counter-clockwise seen from inside, the z = 0 face first (triangles 0
/// and 1).
struct InwardCube {
  std::vector<glm::vec3> corners{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                 {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3, 4, 7, 6, 4, 6, 5, 0, 4, 5, 0, 5, 1,
                                     3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2};

  /// Its MeshDesc (the arrays stay this object's), every triangle of `material`, group "cube".
  rad::MeshDesc desc(rad::MaterialId material) const { return mesh_desc(corners, indices, material, "cube"); }
};

/// Howell C-11: parallel, directly opposed rectangles a x b at distance c.
inline double parallel_rectangles(double a, double b, double c) {
  const double X = a / c, Y = b / c, pi = 3.14159265358979323846;
  const double x1 = std::sqrt(1 + X * X), y1 = std::sqrt(1 + Y * Y);
  return 2.0 / (pi * X * Y) *
         (std::log(x1 * y1 / std::sqrt(1 + X * X + Y * Y)) + X * y1 * std::atan(X / y1) + Y * x1 * std::atan(Y / x1) -
          X * std::atan(X) - Y * std::atan(Y));
}

/// Howell C-14: rectangles at 90 degrees sharing an edge of length l; source width w, receiver height h.
inline double perpendicular_rectangles(double l, double w, double h) {
  const double H = h / l, W = w / l, pi = 3.14159265358979323846;
  const double H2 = H * H, W2 = W * W, S = std::sqrt(H2 + W2);
  const double a = (1 + W2) * (1 + H2) / (1 + W2 + H2);
  const double b = W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2));
  const double c = H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2));
  return 1.0 / (pi * W) *
         (W * std::atan(1 / W) + H * std::atan(1 / H) - S * std::atan(1 / S) +
          0.25 * (std::log(a) + W2 * std::log(b) + H2 * std::log(c)));
}

/// Area-weighted mean of the red channel of one side's radiosity (the back when `back`) over
/// the leaves of `group` whose centre (the mean of its corners) satisfies `where`; their area
/// in `*area_out`. 0 when no leaf qualifies.
template <class Where>
double leaf_mean(const rad::Solution& sol, const rad::Scene& scene, const std::string& group, Where where,
                 bool back = false, double* area_out = nullptr) {
  const rad::PatchHierarchy& h = sol.hierarchy();
  const std::vector<rad::Rgb>& B = back ? sol.back_radiosity() : sol.radiosity();
  const rad::GroupId g = *scene.find_group(group);
  double sum = 0.0, area = 0.0;
  for (std::uint32_t leaf : h.leaves()) {
    const rad::Element& e = h.element(leaf);
    if (scene.polygons()[h.patches()[e.patch].polygon].group != g) continue;
    glm::vec3 c(0.0f);
    for (int k = 0; k < e.corner_count(); ++k) c += h.vertices()[e.corners[static_cast<std::size_t>(k)]];
    c /= static_cast<float>(e.corner_count());
    if (!where(c)) continue;
    sum += static_cast<double>(B[leaf].x) * e.area;
    area += e.area;
  }
  if (area_out) *area_out = area;
  return area > 0.0 ? sum / area : 0.0;
}

/// A room [0,1]^3 of inward-facing walls whose ceiling has a square hole [0.3, 0.7]^2 (a
/// window: four ceiling quads around it), with a camera inside at the front wall looking at the
/// floor and the far walls. Groups "floor" (reflectance `floor`), "ceiling", "left", "right",
/// "back", "front" (reflectance 0.6). No light: the caller adds one.
inline rad::Scene window_room(rad::Rgb floor = rad::Rgb(0.7f, 0.5f, 0.3f)) {
  rad::Scene scene;
  rad::Material wall, ground;
  wall.reflectance = rad::Rgb(0.6f);
  ground.reflectance = floor;
  const rad::MaterialId w = scene.add_material(wall), f = scene.add_material(ground);
  rad::add_quad(scene, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, f, "floor");   // facing +y
  rad::add_quad(scene, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, w, "left");    // +x
  rad::add_quad(scene, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, w, "right");   // -x
  rad::add_quad(scene, {0, 0, 1}, {0, 1, 0}, {1, 0, 0}, w, "back");    // -z
  rad::add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, w, "front");   // +z
  // The ceiling (facing -y) around the window.
  rad::add_quad(scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 0.3f}, w, "ceiling");
  rad::add_quad(scene, {0, 1, 0.7f}, {1, 0, 0}, {0, 0, 0.3f}, w, "ceiling");
  rad::add_quad(scene, {0, 1, 0.3f}, {0.3f, 0, 0}, {0, 0, 0.4f}, w, "ceiling");
  rad::add_quad(scene, {0.7f, 1, 0.3f}, {0.3f, 0, 0}, {0, 0, 0.4f}, w, "ceiling");
  scene.set_camera(rad::Camera{{0.5f, 0.55f, 0.03f}, {0.5f, 0.3f, 1.0f}, {0, 1, 0}, 80.0f});
  return scene;
}

}  // namespace test
