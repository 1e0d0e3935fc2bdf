// Links the installed library, checks header/binary versions agree and runs a coarse Cornell box,
// once by solve() and once relit through a kept Problem, and adds a host's indexed mesh, makes
// its lightmap UVs and bakes a lightmap.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include <radiosity/radiosity.hpp>

int main() {
  if (std::strcmp(radiosity::version(), RADIOSITY_VERSION_STRING) != 0) {
    std::printf("header %s, library %s\n", RADIOSITY_VERSION_STRING, radiosity::version());
    return 1;
  }
  radiosity::Scene scene = radiosity::cornell_box();
  radiosity::SolveOptions opt;
  opt.mesh.max_patch_area = 20000.0f;
  opt.mesh.max_element_area = 20000.0f;
  radiosity::Solution sol = radiosity::solve(scene, opt);
  radiosity::Rgb floor = sol.group_radiosity("floor");
  std::printf("consumer: radiosity %s, floor B = (%.4g, %.4g, %.4g)\n", radiosity::version(),
              floor.x, floor.y, floor.z);
  if (!(floor.x > 0.0f && std::isfinite(floor.x))) return 1;

  // The kept stages: a Problem relit with the light at twice its emission gives twice the
  // radiosity (linearity), through the installed headers and binary.
  radiosity::Problem problem(scene, opt);
  std::vector<radiosity::Rgb> emission(scene.polygons().size(), radiosity::Rgb(0.0f));
  for (std::size_t p = 0; p < emission.size(); ++p)
    emission[p] = 2.0f * scene.material(scene.polygons()[p].material).emission;
  const radiosity::Rgb relit = problem.solve(emission).group_radiosity("floor");
  std::printf("consumer: relit at 2x, floor B = (%.4g, %.4g, %.4g)\n", relit.x, relit.y, relit.z);
  if (!(std::fabs(relit.x / floor.x - 2.0f) < 1e-3f)) return 1;

  // A host's indexed mesh through the MeshDesc contract: a quad as two triangles.
  const glm::vec3 positions[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  radiosity::Scene host;
  radiosity::MeshDesc mesh;
  mesh.positions = positions;
  mesh.vertex_count = 4;
  mesh.indices = indices;
  mesh.index_count = 6;
  mesh.material = host.add_material(radiosity::Material{});
  mesh.group = "quad";
  const radiosity::MeshId id = host.add_mesh(mesh);
  std::printf("consumer: mesh %u gave %zu polygons of total area %.3g\n", id, host.polygons().size(), host.total_area());
  if (!(host.polygons().size() == 2 && std::fabs(host.total_area() - 1.0) < 1e-6)) return 1;

  // Lightmap UVs made for it, a lamp over it, and its lightmap: every covered texel lit.
  const radiosity::LightmapUvs uvs = radiosity::generate_lightmap_uvs(host, id);
  radiosity::Material lamp;
  lamp.emission = radiosity::Rgb(10.0f);
  radiosity::add_quad(host, {0.25f, 0.25f, 1.0f}, {0.0f, 0.5f, 0.0f}, {0.5f, 0.0f, 0.0f}, host.add_material(lamp));
  const radiosity::Solution lit = radiosity::solve(host);
  radiosity::LightmapOptions lo;
  lo.width = lo.height = 64;
  const radiosity::Lightmap map = radiosity::bake_lightmap(host, lit, id, lo);
  float darkest = 1e30f;
  for (std::size_t i = 0; i < map.state.size(); ++i)
    if (map.state[i] == radiosity::TexelState::covered) darkest = std::fmin(darkest, map.image.pixels[i].y);
  std::printf("consumer: lightmap of %zu charts, %zu texels covered, darkest %.3g W/m^2\n", uvs.chart_count,
              map.covered, darkest);
  return map.covered > 1000 && darkest > 0.0f ? 0 : 1;
}
