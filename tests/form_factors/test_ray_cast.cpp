#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

// One patch and one element per polygon, so F(element -> patch) is the polygon-to-polygon factor.
double polygon_factor(const rad::Scene& scene, rad::FormFactorOptions o, std::uint32_t from, std::uint32_t to) {
  rad::MeshOptions mesh;
  mesh.max_patch_area = static_cast<float>(2.0 * scene.total_area());
  mesh.max_element_area = mesh.max_patch_area;
  rad::PatchHierarchy h(scene, mesh);
  REQUIRE(h.patches().size() == scene.polygons().size());
  auto est = rad::make_form_factor_estimator(scene, h, o);
  std::vector<float> row(h.patches().size());
  est->element_rows({h.patches()[from].root}, row.data());
  return row[to];
}

}  // namespace

TEST_SUITE("form_factors") {
  TEST_CASE("factors and radiosity do not depend on the scene's scale or the thread count: McGuire's box at 1 and at "
            "1.2e-4 of its size (0.4 mm)") {
    // Found by scaling a file we did not make: at 1.2e-4 the floor came out 3 % dark, and the
    // ray-cast rows differed between threads = 0 and 2 in 78 984 entries. The area-uniform
    // quad sampler squared terms that grow as the fourth power of the cell's size, which fell
    // into float's denormals, read as 0 on threads with flush-to-zero set (CellSampler).
    const rad::Scene original = rad::load_scene(std::string(RADIOSITY_TEST_DATA) + "/mcguire/CornellBox-Original.obj");
    auto scaled = [&](float k) {
      rad::Scene out;
      for (const rad::Material& m : original.materials()) out.add_material(m);
      for (const rad::Polygon& p : original.polygons()) {
        std::vector<glm::vec3> v(p.vertices.begin(), p.vertices.end());
        for (glm::vec3& x : v) x *= k;
        out.add_polygon(v, p.material, original.groups()[p.group]);
      }
      return out;
    };
    const rad::Scene big = scaled(1.0f), tiny = scaled(1.2e-4f);
    REQUIRE(tiny.polygons().size() == big.polygons().size());
    // Rows of every element by ray casting, threads 0 (every core, TBB's own arena) and 2.
    const rad::PatchHierarchy mesh(tiny, rad::MeshOptions{});
    std::vector<std::uint32_t> leaves(mesh.leaves().begin(), mesh.leaves().end());
    std::vector<float> any(leaves.size() * mesh.patches().size()), two(any.size());
    rad::FormFactorOptions o;
    o.method = rad::FormFactorMethod::ray_cast;
    rad::make_form_factor_estimator(tiny, mesh, o)->element_rows(leaves, any.data());
    o.threads = 2;
    rad::make_form_factor_estimator(tiny, mesh, o)->element_rows(leaves, two.data());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < any.size(); ++k) differ += any[k] != two[k] ? 1 : 0;
    CHECK(differ == 0);
    // The default solve's group radiosity, at both sizes (emission per area is the same).
    const rad::Solution a = rad::solve(big), b = rad::solve(tiny);
    for (const std::string& g : big.groups()) {
      CAPTURE(g);
      CHECK(b.group_radiosity(g).x == doctest::Approx(a.group_radiosity(g).x).epsilon(1e-3));
    }
  }

  TEST_CASE("point-to-polygon factor of a differential area under a unit square matches the closed form") {
    // Howell B-1 style: dA at distance c below the corner of an a x b rectangle, parallel.
    const double a = 1.0, b = 2.0, c = 0.5;
    const double A = a / c, B = b / c, pi = 3.14159265358979323846;
    const double exact = 1.0 / (2 * pi) *
                         (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
                          B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B)));
    glm::vec3 rect[4] = {{0, 0, 0.5f}, {1, 0, 0.5f}, {1, 2, 0.5f}, {0, 2, 0.5f}};
    CHECK(rad::point_to_polygon_factor({0, 0, 0}, {0, 0, 1}, rect, 4) == doctest::Approx(exact).epsilon(1e-6));
    // Behind the point: nothing.
    CHECK(rad::point_to_polygon_factor({0, 0, 0}, {0, 0, -1}, rect, 4) == 0.0);
  }

  TEST_CASE("parallel unit squares at distance 1: ray-cast within 0.5% of Howell C-11 (0.19982)") {
    rad::Scene s;
    auto m = s.add_material({});
    s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "bottom");
    s.add_polygon({{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, m, "top");
    const double exact = test::parallel_rectangles(1, 1, 1);
    CHECK(exact == doctest::Approx(0.1998243).epsilon(1e-5));
    rad::FormFactorOptions o;
    CHECK(polygon_factor(s, o, 0, 1) == doctest::Approx(exact).epsilon(5e-3));
    o.method = rad::FormFactorMethod::analytic;
    CHECK(polygon_factor(s, o, 0, 1) == doctest::Approx(exact).epsilon(5e-3));
  }

  TEST_CASE(
      "perpendicular unit squares sharing an edge: ray-cast and analytic within 0.5% of Howell C-14 (0.20004) at the "
      "defaults") {
    rad::Scene s;
    auto m = s.add_material({});
    s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "floor");
    s.add_polygon({{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, m, "wall");
    const double exact = test::perpendicular_rectangles(1, 1, 1);
    CHECK(exact == doctest::Approx(0.2000438).epsilon(1e-5));
    rad::FormFactorOptions o;
    CHECK(polygon_factor(s, o, 0, 1) == doctest::Approx(exact).epsilon(5e-3));
    o.method = rad::FormFactorMethod::analytic;
    CHECK(polygon_factor(s, o, 0, 1) == doctest::Approx(exact).epsilon(5e-3));
  }

  TEST_CASE("an occluder between parallel squares removes the shadowed share of the factor") {
    rad::Scene s;
    auto m = s.add_material({});
    s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "bottom");
    s.add_polygon({{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, m, "top");
    rad::FormFactorOptions o;
    const double open = polygon_factor(s, o, 0, 1);
    // A large blocker in between (facing down) hides the top completely.
    s.add_polygon({{-5, -5, 0.5f}, {-5, 5, 0.5f}, {5, 5, 0.5f}, {5, -5, 0.5f}}, m, "blocker");
    CHECK(polygon_factor(s, o, 0, 1) == doctest::Approx(0.0));
    CHECK(open > 0.19);
  }

  TEST_CASE("closed unit cube: rows sum to 1 and reciprocity A_i F_ij = A_j F_ji holds") {
    rad::Scene s = test::closed_box(rad::Material{});
    rad::MeshOptions mesh;
    mesh.max_patch_area = 0.26f;
    mesh.max_element_area = 0.26f;
    rad::PatchHierarchy h(s, mesh);
    REQUIRE(h.patches().size() == 24);
    auto est = rad::make_form_factor_estimator(s, h, rad::FormFactorOptions{});
    const std::size_t n = h.patches().size();
    std::vector<std::uint32_t> roots;
    for (const rad::Patch& p : h.patches()) roots.push_back(p.root);
    std::vector<float> F(n * n);
    est->element_rows(roots, F.data());
    for (std::size_t i = 0; i < n; ++i) {
      double sum = 0;
      for (std::size_t j = 0; j < n; ++j) sum += F[i * n + j];
      CHECK(sum == doctest::Approx(1.0).epsilon(1e-4));
      for (std::size_t j = 0; j < n; ++j)
        CHECK(h.patches()[i].area * F[i * n + j] ==
              doctest::Approx(h.patches()[j].area * F[j * n + i]).epsilon(0.05).scale(0.01));
    }
  }
}
