// Scene::add_group_meshes(): the polygons that came without a mesh (the built-in scenes, OBJ and
// JSON files) become one welded indexed mesh per group, without changing any solve, so mesh
// values, lightmaps and `radiosity bake` reach them.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

TEST_SUITE("scene") {
  TEST_CASE("add_group_meshes: the Cornell box gets one welded mesh per group and solves as before") {
    rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.tolerance = 1e-4;
    const rad::Solution before = rad::solve(scene, o);
    const std::vector<rad::MeshId> made = scene.add_group_meshes();
    REQUIRE(made.size() == scene.groups().size());
    CHECK(scene.add_group_meshes().empty());  // every polygon belongs to a mesh now
    for (const rad::MeshId id : made) {
      const rad::Mesh& m = scene.meshes()[id];
      CAPTURE(scene.groups()[m.group]);
      std::set<rad::PolygonId> polygons;
      std::size_t corners = 0;
      for (std::size_t t = 0; t < m.triangle_polygon.size(); ++t) {
        const rad::Polygon& p = scene.polygons()[m.triangle_polygon[t]];
        CHECK(p.group == m.group);
        CHECK(p.mesh == id);
        // Each triangle lies on its polygon (its corners are corners of the polygon).
        for (int k = 0; k < 3; ++k) {
          const glm::vec3 c = m.positions[m.indices[3 * t + static_cast<std::size_t>(k)]];
          CHECK(std::find(p.vertices.begin(), p.vertices.end(), c) != p.vertices.end());
        }
        if (polygons.insert(m.triangle_polygon[t]).second) corners += p.vertices.size();
      }
      // Welded: fewer vertices than polygon corners wherever polygons share corners.
      CHECK(m.positions.size() <= corners);
      if (scene.groups()[m.group] == "short_block") CHECK(m.positions.size() < corners);
    }
    const rad::Solution after = rad::solve(scene, o);
    CHECK(after.radiosity() == before.radiosity());
    // A group's area-weighted triangle values give its mean radiosity.
    const std::vector<rad::Rgb> tri = after.mesh_triangle_values(made[0], rad::Quantity::radiosity);
    const rad::Mesh& m = scene.meshes()[made[0]];
    double sum = 0.0, area = 0.0;
    std::set<rad::PolygonId> seen;
    for (std::size_t t = 0; t < tri.size(); ++t)
      if (seen.insert(m.triangle_polygon[t]).second) {
        const double a = scene.polygons()[m.triangle_polygon[t]].area;
        sum += a * tri[t].y;
        area += a;
      }
    CHECK(sum / area == doctest::Approx(after.group_radiosity(scene.groups()[m.group]).y).epsilon(1e-5));
  }

  TEST_CASE("add_group_meshes: OBJ faces that share v indices share mesh vertices") {
    const std::filesystem::path path = std::filesystem::path(RADIOSITY_TEST_TMP) / "group_meshes.obj";
    std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\n"
                           "g left\nf 1 4 5 2\ng right\nf 2 5 6 3\nf 2 5 6\n";
    rad::Scene scene = rad::load_scene(path);
    const std::vector<rad::MeshId> made = scene.add_group_meshes();
    REQUIRE(made.size() == 2);
    CHECK(scene.meshes()[made[0]].positions.size() == 4);
    CHECK(scene.meshes()[made[0]].indices.size() == 6);  // a quad: two triangles
    CHECK(scene.meshes()[made[1]].positions.size() == 4);  // the quad and the triangle share 3 corners
    CHECK(scene.meshes()[made[1]].indices.size() == 9);
  }
}
