// Scene::add_mesh() at host scale: a height-field grid of about a million triangles given as one
// indexed mesh, against the same triangles given one add_polygon() call at a time, in one run.
// Target (host-renderer issue): a million triangles added well under a second.
//
// Usage: bench_add_mesh [TRIANGLES]   (default 1000000)
// Prints the triangle count, each way's wall time and ns per triangle, their ratio, and the
// resident memory the mesh's scene holds.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"

namespace {

using bench::peak_rss_mib;
using bench::seconds_since;

}  // namespace

int main(int argc, char** argv) {
  std::size_t wanted = 1000000;
  if (argc > 1) {
    char* end = nullptr;
    wanted = std::strtoull(argv[1], &end, 10);
    if (end == argv[1] || *end != '\0' || wanted < 2) {
      std::fprintf(stderr, "usage: bench_add_mesh [TRIANGLES >= 2]\n");
      return 2;
    }
  }
  // An n x n grid of quads, two triangles each, on a gentle height field (not planar, so no
  // shortcut applies).
  const auto n = static_cast<std::uint32_t>(std::ceil(std::sqrt(static_cast<double>(wanted) / 2.0)));
  std::vector<glm::vec3> positions;
  positions.reserve(static_cast<std::size_t>(n + 1) * (n + 1));
  for (std::uint32_t j = 0; j <= n; ++j)
    for (std::uint32_t i = 0; i <= n; ++i) {
      const float x = static_cast<float>(i) / n, z = static_cast<float>(j) / n;
      positions.emplace_back(x, 0.05f * std::sin(6.0f * x) * std::cos(5.0f * z), z);
    }
  std::vector<std::uint32_t> indices;
  indices.reserve(static_cast<std::size_t>(6) * n * n);
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      indices.insert(indices.end(), {a, d, c, a, c, b});  // facing +y
    }
  const std::size_t triangles = indices.size() / 3;
  std::printf("bench_add_mesh: radiosity %s, %zu triangles (%u x %u grid), %zu vertices\n", radiosity::version(),
              triangles, n, n, positions.size());

  const double rss_before = peak_rss_mib();
  radiosity::Scene mesh_scene;
  const radiosity::MaterialId m = mesh_scene.add_material(radiosity::Material{});
  radiosity::MeshDesc desc;
  desc.positions = positions.data();
  desc.vertex_count = positions.size();
  desc.indices = indices.data();
  desc.index_count = indices.size();
  desc.material = m;
  desc.group = "terrain";
  auto t0 = std::chrono::steady_clock::now();
  mesh_scene.add_mesh(desc);
  const double mesh_seconds = seconds_since(t0);
  const double rss_mesh = peak_rss_mib();

  radiosity::Scene polygon_scene;
  polygon_scene.add_material(radiosity::Material{});
  t0 = std::chrono::steady_clock::now();
  for (std::size_t t = 0; t < triangles; ++t)
    polygon_scene.add_polygon(
        {positions[indices[3 * t]], positions[indices[3 * t + 1]], positions[indices[3 * t + 2]]}, m, "terrain");
  const double polygon_seconds = seconds_since(t0);

  if (mesh_scene.polygons().size() != polygon_scene.polygons().size()) {
    std::printf("error: %zu polygons from add_mesh, %zu from add_polygon\n", mesh_scene.polygons().size(),
                polygon_scene.polygons().size());
    return 1;
  }
  std::printf("  add_mesh     %7.3f s  %6.0f ns/triangle  (target: well under 1 s for 1M)\n", mesh_seconds,
              1e9 * mesh_seconds / static_cast<double>(triangles));
  std::printf("  add_polygon  %7.3f s  %6.0f ns/triangle  (the same triangles one call each)\n", polygon_seconds,
              1e9 * polygon_seconds / static_cast<double>(triangles));
  std::printf("  add_mesh / add_polygon time: %.3f\n", mesh_seconds / polygon_seconds);
  std::printf("  peak RSS grew %.1f MiB for the mesh's scene (%.0f bytes per triangle, host arrays copied)\n",
              rss_mesh - rss_before, (rss_mesh - rss_before) * 1048576.0 / static_cast<double>(triangles));
  return 0;
}
