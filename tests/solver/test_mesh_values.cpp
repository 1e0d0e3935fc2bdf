// Solution::mesh_triangle_values() and mesh_vertex_values(): results on the host's own
// triangles and vertices. A furnace (a closed box of uniform emission E and reflectance rho,
// given as one indexed mesh) has B = H = E / (1 - rho) and direct irradiance E everywhere, on
// every triangle and vertex; vertex values are the hierarchy's interpolated field at the
// corners; skipped triangles and unknown meshes are handled as documented.
#include <doctest/doctest.h>

#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// test::InwardCube with a 13th, degenerate triangle (two equal corners).
struct Cube : test::InwardCube {
  Cube() { indices.insert(indices.end(), {0, 0, 1}); }
};

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("mesh values: a furnace mesh has B = H = E/(1-rho) and direct irradiance E on every triangle and vertex") {
    rad::Scene scene;
    rad::Material m;
    m.emission = rad::Rgb(1.0f, 2.0f, 0.5f);
    m.reflectance = rad::Rgb(0.5f, 0.8f, 0.2f);
    const Cube cube;
    const rad::MeshId id = scene.add_mesh(cube.desc(scene.add_material(m)));
    for (rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::SolveOptions o;
      o.method = method;
      o.form_factors.method = rad::FormFactorMethod::ray_cast;
      o.mesh.max_patch_area = 0.05f;
      o.tolerance = 1e-6;
      const rad::Solution sol = rad::solve(scene, o);
      const rad::Rgb B = m.emission / (rad::Rgb(1.0f) - m.reflectance);
      auto check_all = [&](const std::vector<rad::Rgb>& values, const rad::Rgb& expected, std::size_t count,
                           bool skip_last) {
        REQUIRE(values.size() == count);
        for (std::size_t i = 0; i + (skip_last ? 1 : 0) < count; ++i)
          for (int c = 0; c < 3; ++c) CHECK(values[i][c] == doctest::Approx(expected[c]).epsilon(2e-3));
      };
      for (rad::Quantity q : {rad::Quantity::radiosity, rad::Quantity::irradiance}) {
        check_all(sol.mesh_triangle_values(id, q), B, 13, true);
        check_all(sol.mesh_vertex_values(id, q), B, 8, false);
      }
      check_all(sol.mesh_triangle_values(id, rad::Quantity::direct_irradiance), m.emission, 13, true);
      check_all(sol.mesh_vertex_values(id, rad::Quantity::indirect_irradiance), B - m.emission, 8, false);
      // The degenerate 13th triangle was skipped: it has no value.
      CHECK(sol.mesh_triangle_values(id, rad::Quantity::radiosity)[12] == rad::Rgb(0.0f));
    }
  }

  TEST_CASE("mesh values: a vertex's value is the hierarchy's interpolated field at that corner") {
    rad::Scene scene;
    rad::Material lamp, floor;
    lamp.emission = rad::Rgb(10.0f);
    const rad::MaterialId ml = scene.add_material(lamp), mf = scene.add_material(floor);
    rad::add_quad(scene, {0.4f, 0.5f, 0.4f}, {0.2f, 0, 0}, {0, 0, 0.2f}, ml, "lamp");
    const std::vector<glm::vec3> positions{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
    const std::vector<std::uint32_t> indices{0, 1, 2};  // facing +y, towards the lamp
    rad::MeshDesc d;
    d.positions = positions.data();
    d.vertex_count = 3;
    d.indices = indices.data();
    d.index_count = 3;
    d.material = mf;
    const rad::MeshId id = scene.add_mesh(d);
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.02f;
    const rad::Solution sol = rad::solve(scene, o);
    const std::vector<rad::Rgb> field = sol.hierarchy().vertex_values(sol.irradiance());
    const std::vector<rad::Rgb> at_vertices = sol.mesh_vertex_values(id, rad::Quantity::irradiance);
    for (std::size_t v = 0; v < 3; ++v) {
      // The hierarchy vertex at this corner: the nearest one.
      std::size_t nearest = 0;
      for (std::size_t k = 1; k < sol.hierarchy().vertices().size(); ++k)
        if (glm::length(sol.hierarchy().vertices()[k] - positions[v]) <
            glm::length(sol.hierarchy().vertices()[nearest] - positions[v]))
          nearest = k;
      CHECK(at_vertices[v] == field[nearest]);
      CHECK(at_vertices[v].x > 0.0f);
    }
    CHECK_THROWS_AS(sol.mesh_vertex_values(id + 1, rad::Quantity::radiosity), rad::Error);
  }
}
