// A small host renderer's bake loop: the host keeps its own indexed meshes, hands them to the
// library without copying them into library types, makes lightmap UVs where it has none, solves
// once, reads the irradiance back onto its own vertices and lightmap texels, and relights for a
// dimmed lamp without computing the form factors again.
// Writes floor_lightmap.exr (linear irradiance, W/m^2) and floor_lightmap.png into the current
// folder (or the folder given as the first argument).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <radiosity/lightmap.hpp>
#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// The host's mesh: its buffers, and what it wants back.
struct HostMesh {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::vector<glm::vec2> lightmap_uv;  ///< empty until it has lightmap coordinates
  std::vector<rad::Rgb> irradiance;    ///< per vertex, filled by the bake
  rad::MeshId id = 0;

  /// Adds a quad a, b, c, d (counter-clockwise seen from its front) as two triangles.
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c, d});
    indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
};

/// A floor of n x n quads over [0, size]^2 at y = 0, facing up, with lightmap UVs of its own.
HostMesh make_floor(float size, int n) {
  HostMesh m{"floor", {}, {}, {}, {}, 0};
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(n), v = static_cast<float>(j) / static_cast<float>(n);
      m.positions.emplace_back(u * size, 0.0f, v * size);
      m.lightmap_uv.emplace_back(0.02f + 0.96f * u, 0.02f + 0.96f * v);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i), b = a + 1, c = a + static_cast<std::uint32_t>(n + 1),
                 d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, d, a, d, b});  // counter-clockwise seen from +y
    }
  return m;
}

/// An axis-aligned box [lo, hi] whose faces look inwards (a room) or outwards (a block).
HostMesh make_box(const std::string& name, glm::vec3 lo, glm::vec3 hi, bool inwards, bool with_floor) {
  HostMesh m{name, {}, {}, {}, {}, 0};
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  // Outward-facing faces; reversed for a room.
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3}, {1, 2, 6, 5}, {3, 7, 6, 2}, {0, 1, 5, 4}};
  for (int f = 0; f < 6; ++f) {
    if (f == 5 && !with_floor) continue;  // the bottom face (y = lo.y)
    const int* q = faces[f];
    if (inwards)
      m.quad(c[q[3]], c[q[2]], c[q[1]], c[q[0]]);
    else
      m.quad(c[q[0]], c[q[1]], c[q[2]], c[q[3]]);
  }
  return m;
}

rad::MeshDesc describe(const HostMesh& m, rad::MaterialId material) {
  rad::MeshDesc d;
  d.positions = m.positions.data();
  d.vertex_count = m.positions.size();
  d.indices = m.indices.data();
  d.index_count = m.indices.size();
  d.material = material;
  d.group = m.name;
  d.uv1 = m.lightmap_uv.empty() ? nullptr : m.lightmap_uv.data();
  return d;
}

double mean_luminance(const std::vector<rad::Rgb>& values) {
  double sum = 0.0;
  for (const rad::Rgb& v : values) sum += 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path folder = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(folder);

  // The host's level: a 4 x 3 x 4 m room without floor, a tiled floor, a block on it, a lamp.
  std::vector<HostMesh> level;
  level.push_back(make_floor(4.0f, 8));
  level.push_back(make_box("walls", {0, 0, 0}, {4, 3, 4}, true, false));
  level.push_back(make_box("block", {1.4f, 0.0f, 1.4f}, {2.2f, 0.8f, 2.2f}, false, false));
  level.push_back(make_box("lamp", {1.5f, 2.9f, 1.5f}, {2.5f, 2.95f, 2.5f}, false, true));

  rad::Scene scene;
  rad::Material plaster;
  plaster.reflectance = rad::Rgb(0.7f, 0.68f, 0.62f);
  rad::Material wood;
  wood.reflectance = rad::Rgb(0.45f, 0.3f, 0.18f);
  rad::Material lamp;
  lamp.reflectance = rad::Rgb(0.8f);
  lamp.emission = rad::Rgb(60.0f, 55.0f, 45.0f);  // W/m^2
  const rad::MaterialId materials[] = {scene.add_material(wood), scene.add_material(plaster),
                                       scene.add_material(plaster), scene.add_material(lamp)};
  for (std::size_t k = 0; k < level.size(); ++k) level[k].id = scene.add_mesh(describe(level[k], materials[k]));

  // Meshes without lightmap UVs get charts made for them; the host adopts the split vertices.
  for (HostMesh& m : level) {
    if (!m.lightmap_uv.empty()) continue;
    const rad::LightmapUvs uvs = rad::generate_lightmap_uvs(scene, m.id);
    std::vector<glm::vec3> positions;
    for (std::uint32_t origin : uvs.vertex_origin) positions.push_back(m.positions[origin]);
    m.positions = std::move(positions);
    m.indices = uvs.indices;
    m.lightmap_uv = uvs.uv1;
    std::printf("%-6s lightmap UVs made: %zu charts, %.1f texels/m at 1024^2\n", m.name.c_str(), uvs.chart_count,
                uvs.texels_per_unit);
  }

  // One Problem: the form factors are computed once and kept for relighting.
  rad::Problem problem(scene);
  const rad::Solution lit = problem.solve();
  std::printf("solved: %zu elements, form factors %.2f s, solve %.2f s\n", lit.report().element_count,
              lit.report().seconds_form_factors, lit.report().seconds_solving);

  // Results on the host's own vertices and texels.
  for (HostMesh& m : level) {
    m.irradiance = lit.mesh_vertex_values(m.id, rad::Quantity::irradiance);
    std::printf("%-6s %3zu vertices, mean irradiance %7.2f W/m^2\n", m.name.c_str(), m.positions.size(),
                mean_luminance(m.irradiance));
  }
  rad::LightmapOptions lo;
  lo.width = lo.height = 256;
  lo.final_gather = true;  // shadows at texel resolution
  lo.gather_rays = 64;
  const rad::Lightmap floor_map = rad::bake_lightmap(scene, lit, level[0].id, lo);
  rad::write_exr(floor_map.image, folder / "floor_lightmap.exr");
  rad::write_png(floor_map.image, folder / "floor_lightmap.png", rad::PngOptions{1.0f / 4.0f});
  // The texel under the block's centre (1.8, 0, 1.8) is in its shadow.
  const int x = static_cast<int>((0.02f + 0.96f * 1.8f / 4.0f) * 256.0f), y = x;
  std::printf("floor lightmap %dx%d: %zu texels covered, %zu dilated, %.2f s; under the block %.2f, open floor %.2f "
              "W/m^2\n",
              floor_map.image.width, floor_map.image.height, floor_map.covered, floor_map.dilated, floor_map.seconds,
              floor_map.image.at(x, y).y, floor_map.image.at(30, 30).y);

  // The lamp dimmed to half: same form factors, only the sweeps again.
  std::vector<rad::Rgb> emission(scene.polygons().size(), rad::Rgb(0.0f));
  for (rad::PolygonId p = 0; p < scene.polygons().size(); ++p)
    emission[p] = 0.5f * scene.material(scene.polygons()[p].material).emission;
  const rad::Solution dimmed = problem.solve(emission);
  std::printf("dimmed: solve %.3f s, form factors %.3f s; floor mean irradiance %.2f -> %.2f W/m^2\n",
              dimmed.report().seconds_solving, dimmed.report().seconds_form_factors, mean_luminance(level[0].irradiance),
              mean_luminance(dimmed.mesh_vertex_values(level[0].id, rad::Quantity::irradiance)));
  return 0;
}
