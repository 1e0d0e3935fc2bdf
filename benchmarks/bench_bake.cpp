// A level baked into one lightmap atlas at host scale (host-renderer issue): a room of about
// 100k triangles given as one indexed mesh (a tiled floor, walls and 80 UV spheres), lightmap UVs
// made by generate_lightmap_uvs(), the default solve, then bake_lightmap() at 1024^2
// interpolated and with final gather, on all cores.
//
// Usage: bench_bake [SIZE] [GATHER_RAYS]   (defaults 1024 and 64)
// Prints the triangle count and, per stage, its wall time and the process's peak resident memory
// after it; the gathered bake's cost relative to the interpolated one.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <radiosity/lightmap.hpp>
#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"

namespace rad = radiosity;

namespace {

using bench::peak_rss_mib;
using bench::seconds_since;

struct Level {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::vector<rad::MaterialId> materials;  // per triangle

  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, rad::MaterialId m) {
    indices.insert(indices.end(), {a, b, c});
    materials.push_back(m);
  }
  std::uint32_t vertex(glm::vec3 p) {
    positions.push_back(p);
    return static_cast<std::uint32_t>(positions.size() - 1);
  }
  /// A grid of n x n quads from `origin` along u and v, facing u x v.
  void grid(glm::vec3 origin, glm::vec3 u, glm::vec3 v, int n, rad::MaterialId m) {
    const std::uint32_t base = static_cast<std::uint32_t>(positions.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) vertex(origin + (float(i) / float(n)) * u + (float(j) / float(n)) * v);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::uint32_t a = base + static_cast<std::uint32_t>(j * (n + 1) + i), b = a + 1,
                            d = a + static_cast<std::uint32_t>(n + 1), c = d + 1;
        triangle(a, b, c, m);
        triangle(a, c, d, m);
      }
  }
  /// A UV sphere of `segments` x segments/2, sharing its ring vertices, facing out.
  void sphere(glm::vec3 centre, float r, int segments, rad::MaterialId m) {
    const int rings = segments / 2;
    const float pi = 3.14159265358979f;
    const std::uint32_t top = vertex(centre + glm::vec3(0, r, 0));
    const std::uint32_t first = static_cast<std::uint32_t>(positions.size());
    for (int j = 1; j < rings; ++j)
      for (int i = 0; i < segments; ++i) {
        const float theta = pi * float(j) / float(rings), phi = 2.0f * pi * float(i) / float(segments);
        vertex(centre + r * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)));
      }
    const std::uint32_t bottom = vertex(centre - glm::vec3(0, r, 0));
    auto at = [&](int j, int i) { return first + static_cast<std::uint32_t>((j - 1) * segments + (i % segments)); };
    for (int i = 0; i < segments; ++i) {
      triangle(top, at(1, i + 1), at(1, i), m);
      triangle(bottom, at(rings - 1, i), at(rings - 1, i + 1), m);
      for (int j = 1; j + 1 < rings; ++j) {
        triangle(at(j, i), at(j, i + 1), at(j + 1, i + 1), m);
        triangle(at(j, i), at(j + 1, i + 1), at(j + 1, i), m);
      }
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 1024;
  const int gather_rays = argc > 2 ? std::atoi(argv[2]) : 64;
  if (size < 16 || gather_rays < 1) {
    std::fprintf(stderr, "usage: bench_bake [SIZE >= 16] [GATHER_RAYS >= 1]\n");
    return 2;
  }

  rad::Scene scene;
  rad::Material floor_m, wall_m, ball_m, lamp_m;
  floor_m.reflectance = rad::Rgb(0.5f, 0.45f, 0.4f);
  wall_m.reflectance = rad::Rgb(0.7f);
  ball_m.reflectance = rad::Rgb(0.6f, 0.3f, 0.2f);
  lamp_m.reflectance = rad::Rgb(0.0f);
  lamp_m.emission = rad::Rgb(200.0f);
  const rad::MaterialId floor_id = scene.add_material(floor_m), wall_id = scene.add_material(wall_m),
                        ball_id = scene.add_material(ball_m), lamp_id = scene.add_material(lamp_m);

  // A 20 x 6 x 20 room: the floor tiled 100 x 100, walls and ceiling one quad each (inward).
  Level level;
  const float W = 20.0f, H = 6.0f;
  level.grid({0, 0, 0}, {0, 0, W}, {W, 0, 0}, 100, floor_id);
  level.grid({0, H, 0}, {W, 0, 0}, {0, 0, W}, 1, wall_id);
  level.grid({0, 0, 0}, {W, 0, 0}, {0, H, 0}, 1, wall_id);
  level.grid({0, 0, W}, {0, H, 0}, {W, 0, 0}, 1, wall_id);
  level.grid({0, 0, 0}, {0, H, 0}, {0, 0, W}, 1, wall_id);
  level.grid({W, 0, 0}, {0, 0, W}, {0, H, 0}, 1, wall_id);
  for (int k = 0; k < 80; ++k)
    level.sphere({2.0f + 2.0f * float(k % 9), 0.5f, 2.0f + 2.0f * float(k / 9)}, 0.5f, 32, ball_id);

  auto t0 = std::chrono::steady_clock::now();
  rad::MeshDesc d;
  d.positions = level.positions.data();
  d.vertex_count = level.positions.size();
  d.indices = level.indices.data();
  d.index_count = level.indices.size();
  d.triangle_materials = level.materials.data();
  d.group = "level";
  const rad::MeshId mesh = scene.add_mesh(d);
  rad::add_quad(scene, {8.0f, H - 0.01f, 8.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.0f}, lamp_id, "lamp");
  std::printf("scene: %zu triangles in one mesh, %zu vertices\n", level.indices.size() / 3, level.positions.size());
  std::printf("add_mesh:               %8.2f s   peak RSS %7.1f MiB\n", seconds_since(t0), peak_rss_mib());

  t0 = std::chrono::steady_clock::now();
  rad::LightmapUvOptions uo;
  uo.resolution = size;
  const rad::LightmapUvs uvs = rad::generate_lightmap_uvs(scene, mesh, uo);
  std::printf("generate_lightmap_uvs:  %8.2f s   peak RSS %7.1f MiB   %zu charts, %.1f texels/unit, %.0f %% of the atlas\n",
              seconds_since(t0), peak_rss_mib(), uvs.chart_count, uvs.texels_per_unit, 100.0 * uvs.utilisation);

  t0 = std::chrono::steady_clock::now();
  const rad::Solution sol = rad::solve(scene);
  std::printf("solve (defaults):       %8.2f s   peak RSS %7.1f MiB   %zu patches, %zu elements, %s\n",
              seconds_since(t0), peak_rss_mib(), sol.report().patch_count, sol.report().element_count,
              rad::to_string(sol.report().form_factor_method));

  rad::LightmapOptions lo;
  lo.width = lo.height = size;
  const rad::Lightmap smooth = rad::bake_lightmap(scene, sol, mesh, lo);
  std::printf("bake %dx%d interpolated: %6.2f s   peak RSS %7.1f MiB   %zu texels covered, %zu dilated\n", size, size,
              smooth.seconds, peak_rss_mib(), smooth.covered, smooth.dilated);
  lo.final_gather = true;
  lo.gather_rays = gather_rays;
  const rad::Lightmap gathered = rad::bake_lightmap(scene, sol, mesh, lo);
  std::printf("bake %dx%d final gather (%d rays): %6.2f s   peak RSS %7.1f MiB   %.2f us per texel, %.1fx interpolated\n",
              size, size, gather_rays, gathered.seconds, peak_rss_mib(),
              1e6 * gathered.seconds / static_cast<double>(gathered.covered), gathered.seconds / smooth.seconds);
  return 0;
}
