// Scene::add_mesh(): a host's indexed mesh becomes one polygon per triangle, with the host's
// arrays kept and each triangle's polygon recorded; bad input follows the readers' rules
// (errors naming mesh and vertex or triangle, degenerate triangles skipped with one warning or
// refused under strict, the scene unchanged by a throwing call); and a mesh lights exactly as
// the same triangles given one add_polygon() at a time.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// The host's side: a unit quad in z = 0 facing +z as two triangles sharing an edge, plus a
/// third, degenerate one (its corners on a line).
struct HostMesh {
  std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};
  std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3, 0, 1, 4};
  std::vector<glm::vec2> uv1{{0, 0}, {1, 0}, {1, 1}, {0, 1}, {2, 0}};

  rad::MeshDesc desc(rad::MaterialId material) const { return test::mesh_desc(positions, indices, material, "quad", uv1); }
};

std::string error_of(rad::Scene& scene, const rad::MeshDesc& desc, bool strict = false) {
  try {
    scene.add_mesh(desc, rad::LoadOptions{strict});
  } catch (const rad::Error& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("add_mesh: one polygon per triangle, the host's arrays kept, the degenerate triangle skipped and reported") {
    rad::Scene scene;
    const rad::MaterialId m = scene.add_material(rad::Material{});
    HostMesh host;
    const rad::MeshId id = scene.add_mesh(host.desc(m));
    CHECK(id == 0);
    // The host may free or reuse its buffers: the scene keeps copies.
    host.positions.assign(host.positions.size(), glm::vec3(9.0f));

    REQUIRE(scene.polygons().size() == 2);
    REQUIRE(scene.meshes().size() == 1);
    const rad::Mesh& mesh = scene.meshes()[0];
    CHECK(mesh.positions.size() == 5);
    CHECK(mesh.positions[2] == glm::vec3(1, 1, 0));
    CHECK(mesh.indices.size() == 9);
    CHECK(mesh.uv1.size() == 5);
    CHECK(mesh.uv0.empty());
    CHECK(mesh.normals.empty());
    CHECK(mesh.triangle_polygon == std::vector<rad::PolygonId>{0, 1, rad::kNone});
    CHECK(mesh.polygons.first == 0);
    CHECK(mesh.polygons.count == 2);
    CHECK(scene.groups()[mesh.group] == "quad");
    for (rad::PolygonId p = 0; p < 2; ++p) {
      const rad::Polygon& polygon = scene.polygons()[p];
      CHECK(polygon.mesh == 0);
      CHECK(polygon.mesh_triangle == p);
      CHECK(polygon.area == doctest::Approx(0.5));
      CHECK(polygon.normal.z == doctest::Approx(1.0));
      CHECK(polygon.group == mesh.group);
    }
    CHECK(scene.polygons()[1].vertices == std::vector<glm::vec3>{{0, 0, 0}, {1, 1, 0}, {0, 1, 0}});
    CHECK(scene.total_area() == doctest::Approx(1.0));
    REQUIRE(scene.warnings().size() == 1);
    CHECK(scene.warnings()[0] == "mesh 0 (group 'quad'): 1 degenerate (zero-area) triangle skipped: 2");
  }

  TEST_CASE("add_mesh: triangle_materials override the mesh's material") {
    rad::Scene scene;
    const rad::MaterialId grey = scene.add_material(rad::Material{});
    rad::Material lamp;
    lamp.emission = rad::Rgb(5.0f);
    const rad::MaterialId light = scene.add_material(lamp);
    HostMesh host;
    const std::vector<rad::MaterialId> per_triangle{light, grey, grey};
    rad::MeshDesc desc = host.desc(grey);
    desc.triangle_materials = per_triangle.data();
    desc.material = 99;  // ignored when per-triangle materials are given
    scene.add_mesh(desc);
    CHECK(scene.polygons()[0].material == light);
    CHECK(scene.polygons()[1].material == grey);
  }

  TEST_CASE("add_mesh: bad input is an error naming the mesh and the vertex or triangle, and leaves the scene unchanged") {
    rad::Scene scene;
    const rad::MaterialId m = scene.add_material(rad::Material{});
    HostMesh good;
    scene.add_mesh(good.desc(m));  // mesh 0, so the failing ones below are mesh 1
    const std::size_t polygons = scene.polygons().size(), groups = scene.groups().size();

    HostMesh host;
    host.indices[4] = 7;
    rad::MeshDesc bad_index = host.desc(m);
    bad_index.group = "new group";
    CHECK(error_of(scene, bad_index) ==
          "add_mesh: mesh 1 (group 'new group'): triangle 1: index 7 is out of range (5 vertices)");

    HostMesh nan;
    nan.positions[3].y = std::nanf("");
    CHECK(error_of(scene, nan.desc(m)) == "add_mesh: mesh 1 (group 'quad'): the position of vertex 3 is NaN or infinite");
    HostMesh huge;
    huge.positions[2].x = 1e30f;
    CHECK(error_of(scene, huge.desc(m)) == "add_mesh: mesh 1 (group 'quad'): the position of vertex 2 has a coordinate "
                                           "beyond +-1e9 (its areas and distances would overflow)");
    HostMesh inf_uv;
    inf_uv.uv1[1].x = INFINITY;
    CHECK(contains(error_of(scene, inf_uv.desc(m)), "uv1 of vertex 1 is NaN or infinite"));

    rad::MeshDesc short_indices = good.desc(m);
    short_indices.index_count = 8;
    CHECK(contains(error_of(scene, short_indices), "index_count 8 is not a multiple of 3"));
    rad::MeshDesc null_positions = good.desc(m);
    null_positions.positions = nullptr;
    CHECK(contains(error_of(scene, null_positions), "positions is null but vertex_count is 5"));
    rad::MeshDesc unknown_material = good.desc(7);
    CHECK(contains(error_of(scene, unknown_material), "material id 7 does not exist (scene has 1 materials)"));
    const std::vector<rad::MaterialId> per_triangle{0, 3, 0};
    rad::MeshDesc unknown_triangle_material = good.desc(m);
    unknown_triangle_material.triangle_materials = per_triangle.data();
    CHECK(contains(error_of(scene, unknown_triangle_material), "triangle 1: material id 3 does not exist"));

    // Strict: the degenerate triangle is refused instead of skipped.
    CHECK(error_of(scene, good.desc(m), true) == "add_mesh: mesh 1 (group 'quad'): triangle 2 is degenerate (zero area)");

    CHECK(scene.polygons().size() == polygons);
    CHECK(scene.groups().size() == groups);
    CHECK(scene.meshes().size() == 1);
    CHECK(scene.warnings().size() == 1);  // mesh 0's
    // An empty mesh is no error: it adds no polygon.
    const rad::MeshId empty = scene.add_mesh(rad::MeshDesc{});
    CHECK(scene.meshes()[empty].polygons.count == 0);
  }

  TEST_CASE("add_mesh: a closed box as one indexed mesh lights exactly as the same triangles added one by one") {
    // The unit cube facing inwards; its z = 0 face emits.
    const test::InwardCube cube;
    const std::vector<glm::vec3>& corners = cube.corners;
    const std::vector<std::uint32_t>& indices = cube.indices;
    rad::Material wall, lamp;
    wall.reflectance = rad::Rgb(0.6f, 0.5f, 0.4f);
    lamp.reflectance = rad::Rgb(0.3f);
    lamp.emission = rad::Rgb(4.0f);
    std::vector<rad::MaterialId> materials(12, 0);
    materials[0] = materials[1] = 1;  // the z = 0 face

    rad::Scene as_mesh, as_polygons;
    for (rad::Scene* s : {&as_mesh, &as_polygons}) {
      s->add_material(wall);
      s->add_material(lamp);
    }
    rad::MeshDesc desc = cube.desc(0);
    desc.triangle_materials = materials.data();
    desc.group = "box";
    as_mesh.add_mesh(desc);
    for (std::size_t t = 0; t < 12; ++t)
      as_polygons.add_polygon({corners[indices[3 * t]], corners[indices[3 * t + 1]], corners[indices[3 * t + 2]]},
                              materials[t], "box");
    REQUIRE(as_mesh.polygons().size() == 12);
    for (std::size_t p = 0; p < 12; ++p) {
      CHECK(as_mesh.polygons()[p].vertices == as_polygons.polygons()[p].vertices);
      CHECK(as_mesh.polygons()[p].normal == as_polygons.polygons()[p].normal);
      CHECK(as_mesh.polygons()[p].area == as_polygons.polygons()[p].area);
    }
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.1f;
    const rad::Solution a = rad::solve(as_mesh, o), b = rad::solve(as_polygons, o);
    CHECK(a.radiosity() == b.radiosity());
    // A closed box loses nothing: what is emitted is absorbed, within the solver's tolerance.
    CHECK(std::fabs(a.report().escaped_power.x) < 1e-2 * a.report().emitted_power.x);
  }
}

TEST_SUITE("scene") {
  TEST_CASE("reverse_winding: chosen polygons turn over with their mesh triangles - a vertex normal only when all its triangles turned - all twice is the identity") {
    rad::Scene scene;
    const rad::MaterialId m = scene.add_material(rad::Material{});
    HostMesh host;
    const std::vector<glm::vec3> normals(host.positions.size(), glm::vec3(0, 0, 1));
    rad::MeshDesc desc = host.desc(m);
    desc.normals = normals.data();
    scene.add_mesh(desc);
    rad::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, m, "lid");  // polygon 2, not a mesh's
    REQUIRE(scene.polygons().size() == 3);
    const rad::Scene before = scene;

    // Polygon 0 alone (the mesh's first triangle 0-1-2): corner 0 stays first.
    scene.reverse_winding({0});
    const rad::Polygon& p0 = scene.polygons()[0];
    CHECK(p0.normal == glm::vec3(0, 0, -1));
    CHECK(p0.area == doctest::Approx(0.5));
    CHECK(std::vector<glm::vec3>(p0.vertices) == std::vector<glm::vec3>{{0, 0, 0}, {1, 1, 0}, {1, 0, 0}});
    CHECK(scene.polygons()[1].normal == glm::vec3(0, 0, 1));
    const rad::Mesh& mesh = scene.meshes()[0];
    CHECK(mesh.indices == std::vector<std::uint32_t>{0, 2, 1, 0, 2, 3, 0, 1, 4});  // the skipped triangle as given
    // Vertex 1 belongs to the turned triangle only; 0 and 2 to both; 3 to the kept one; 4 to
    // the skipped (degenerate) one only.
    CHECK(mesh.normals == std::vector<glm::vec3>{{0, 0, 1}, {0, 0, -1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}});

    // Everything: polygon 0 back as it was, the others turned.
    scene.reverse_winding();
    CHECK(scene.polygons()[0].normal == glm::vec3(0, 0, 1));
    CHECK(scene.polygons()[1].normal == glm::vec3(0, 0, -1));
    CHECK(scene.polygons()[2].normal == -before.polygons()[2].normal);
    CHECK(mesh.indices == std::vector<std::uint32_t>{0, 1, 2, 0, 3, 2, 0, 1, 4});
    CHECK(mesh.normals == std::vector<glm::vec3>{{0, 0, -1}, {0, 0, 1}, {0, 0, -1}, {0, 0, -1}, {0, 0, 1}});

    // An unknown id throws and changes nothing.
    const std::vector<glm::vec3> corners(scene.polygons()[1].vertices);
    try {
      scene.reverse_winding({1, 3});
      FAIL("no error for polygon 3");
    } catch (const rad::Error& e) {
      CHECK(e.code() == rad::ErrorCode::invalid_argument);
      CHECK(contains(e.what(), "polygon 3 does not exist (the scene has 3)"));
    }
    CHECK(std::vector<glm::vec3>(scene.polygons()[1].vertices) == corners);

    // Back to the start: polygon 0 turned once more, then everything twice.
    scene.reverse_winding({0, 0});  // listed twice, turned once
    scene.reverse_winding();
    scene.reverse_winding();
    scene.reverse_winding();
    for (std::size_t p = 0; p < 3; ++p) {
      CHECK(std::vector<glm::vec3>(scene.polygons()[p].vertices) == std::vector<glm::vec3>(before.polygons()[p].vertices));
      CHECK(scene.polygons()[p].normal == before.polygons()[p].normal);
    }
    CHECK(scene.meshes()[0].indices == before.meshes()[0].indices);
    CHECK(scene.meshes()[0].normals == before.meshes()[0].normals);
  }

  TEST_CASE("PolygonVertices: up to four corners inline, more on the heap, read and compared like a vector") {
    const std::vector<glm::vec3> quad{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    std::vector<glm::vec3> hexagon;
    for (int k = 0; k < 6; ++k)
      hexagon.emplace_back(std::cos(1.0471976f * static_cast<float>(k)), std::sin(1.0471976f * static_cast<float>(k)), 0.0f);
    const rad::PolygonVertices a(quad), b(hexagon), c{quad[0], quad[1], quad[2]};
    CHECK(a.size() == 4);
    CHECK(b.size() == 6);
    CHECK(c.size() == 3);
    CHECK(a == quad);
    CHECK(b == hexagon);
    CHECK(a != b);
    CHECK(static_cast<std::vector<glm::vec3>>(b) == hexagon);
    CHECK(b.back() == hexagon.back());
    std::size_t n = 0;
    for (const glm::vec3& v : b) CHECK(v == hexagon[n++]);
    CHECK(n == 6);
    // Copies are deep, moves keep the corners.
    rad::PolygonVertices copy = b;
    copy[0] = glm::vec3(5.0f);
    CHECK(b[0] == hexagon[0]);
    std::vector<glm::vec3> to_move = hexagon;
    const rad::PolygonVertices moved(std::move(to_move));
    CHECK(moved == hexagon);
    // A scene keeps a hexagon as one polygon with its six corners.
    rad::Scene scene;
    scene.add_polygon(hexagon, scene.add_material(rad::Material{}));
    REQUIRE(scene.polygons().size() == 1);
    CHECK(scene.polygons()[0].vertices == hexagon);
    CHECK(scene.polygons()[0].area == doctest::Approx(1.5 * std::sqrt(3.0)).epsilon(1e-5));
  }
}

TEST_SUITE("scene") {
  TEST_CASE("set_mesh_lightmap_uvs: split vertices copy their origin and a split of other triangles is refused") {
    rad::Scene scene;
    const test::InwardCube cube;
    std::vector<glm::vec3> normals;
    for (const glm::vec3& p : cube.corners) normals.push_back(glm::normalize(glm::vec3(0.5f) - p));
    rad::MeshDesc desc = cube.desc(scene.add_material(rad::Material{}));
    desc.normals = normals.data();
    const rad::MeshId id = scene.add_mesh(desc);
    const rad::Mesh before = scene.meshes()[id];
    // The most split there is: one new vertex per corner.
    const std::vector<std::uint32_t> origin = cube.indices;
    std::vector<std::uint32_t> indices(36);
    std::vector<glm::vec2> uv1(36);
    for (std::uint32_t c = 0; c < 36; ++c) {
      indices[c] = c;
      uv1[c] = glm::vec2(float(c) / 36.0f, 0.5f);
    }

    auto refused = [&](std::uint32_t mesh, const std::vector<std::uint32_t>& o, const std::vector<std::uint32_t>& i,
                       const std::vector<glm::vec2>& uv, const char* why) {
      CAPTURE(why);
      CHECK_THROWS_WITH_AS(scene.set_mesh_lightmap_uvs(mesh, o, i, uv), doctest::Contains(why), rad::Error);
      CHECK(scene.meshes()[id].positions == before.positions);  // unchanged
      CHECK(scene.meshes()[id].indices == before.indices);
      CHECK(scene.meshes()[id].uv1.empty());
    };
    refused(3, origin, indices, uv1, "does not exist");
    refused(id, origin, {0, 1, 2}, uv1, "3 indices given, the mesh has 36");
    refused(id, origin, indices, {}, "0 uv1 entries for 36 new vertices");
    std::vector<std::uint32_t> swapped = origin;
    std::swap(swapped[0], swapped[1]);  // corners 0 and 1 are vertices 0 and 1
    refused(id, swapped, indices, uv1, "triangle 0, corner 0: new vertex 0 copies vertex 1, the corner was vertex 0");
    std::vector<std::uint32_t> beyond = indices;
    beyond[5] = 36;
    refused(id, origin, beyond, uv1, "triangle 1: index 36 is out of range");
    std::vector<std::uint32_t> bad_origin = origin;
    bad_origin[7] = 8;
    refused(id, bad_origin, indices, uv1, "copies vertex 8, out of range");
    std::vector<glm::vec2> nan = uv1;
    nan[3].x = std::nanf("");
    refused(id, origin, indices, nan, "uv1 of new vertex 3 is NaN");

    const std::vector<rad::Polygon> polygons = scene.polygons();
    scene.set_mesh_lightmap_uvs(id, origin, indices, uv1);
    const rad::Mesh& after = scene.meshes()[id];
    REQUIRE(after.positions.size() == 36);
    REQUIRE(after.normals.size() == 36);
    CHECK(after.uv0.empty());  // the mesh had none
    CHECK(after.uv1 == uv1);
    CHECK(after.indices == indices);
    CHECK(after.triangle_polygon == before.triangle_polygon);
    for (std::size_t c = 0; c < 36; ++c) {
      CHECK(after.positions[c] == cube.corners[cube.indices[c]]);
      CHECK(after.normals[c] == normals[cube.indices[c]]);
    }
    REQUIRE(scene.polygons().size() == polygons.size());
    for (std::size_t p = 0; p < polygons.size(); ++p) CHECK(scene.polygons()[p].vertices == polygons[p].vertices);
  }
}
