// Diffuse transmission in pass 1 (Material::diffuse_transmittance; Rushmeier & Torrance's
// backward form factors): a translucent sheet has a radiosity on each side, and each side sends
// on tau times what the other receives.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"
#include "support/build.hpp"

namespace rad = radiosity;

namespace {

/// One patch and one element per polygon, so the discrete system is the closed form below.
/// `rays`: Monte Carlo factors with that many rays per element; 0 = ray_cast factors, 1 =
/// hemicube factors (16 hemicubes of resolution 512 per element).
rad::SolveOptions one_element(rad::SolverMethod method, std::uint32_t rays) {
  rad::SolveOptions o;
  o.method = method;
  o.form_factors.method = rays > 1    ? rad::FormFactorMethod::monte_carlo
                          : rays == 1 ? rad::FormFactorMethod::hemicube
                                      : rad::FormFactorMethod::ray_cast;
  if (rays > 1) o.form_factors.hemisphere_rays = rays;
  if (rays == 1) {
    o.form_factors.source_samples = 16;
    o.form_factors.hemicube_resolution = 512;
  }
  o.mesh.max_patch_area = 10.0f;
  o.mesh.max_element_area = 10.0f;
  o.tolerance = 1e-7;
  return o;
}

struct Stack {
  rad::Scene scene;
  rad::Material panel;
};

/// Three unit squares on the z axis: a lamp at z = 2 facing down, a translucent panel at z = 1
/// facing down (its back towards the lamp) and a tile at z = 0 facing up. The panel hides the
/// lamp from the tile, so all the tile's light has passed through the panel.
Stack lamp_panel_tile(rad::Material panel) {
  Stack s;
  s.panel = panel;
  rad::Material lamp, tile;
  lamp.name = "lamp";
  lamp.emission = rad::Rgb(10.0f);
  lamp.reflectance = rad::Rgb(0.0f);
  tile.name = "tile";
  tile.reflectance = rad::Rgb(0.5f);
  const rad::MaterialId l = s.scene.add_material(lamp), p = s.scene.add_material(panel),
                        t = s.scene.add_material(tile);
  rad::add_quad(s.scene, {0, 1, 2}, {1, 0, 0}, {0, -1, 0}, l, "lamp");
  rad::add_quad(s.scene, {0, 1, 1}, {1, 0, 0}, {0, -1, 0}, p, "panel");
  rad::add_quad(s.scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, "tile");
  return s;
}

/// lamp_panel_tile() with a one-sided paper panel (rho 0.2, tau 0.5).
Stack paper_stack() {
  rad::Material panel;
  panel.name = "paper";
  panel.reflectance = rad::Rgb(0.2f);
  panel.diffuse_transmittance = rad::Rgb(0.5f);
  return lamp_panel_tile(panel);
}

double relative(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

/// The unit box of test::closed_box(wall) with an emitting ceiling, split at x = 0.5 by a
/// one-sided partition of `paper` facing -x, inset 0.02 from the walls: the half x < 0.5 is lit
/// through the partition's front, the other half only through it and round its edges.
rad::Scene partitioned_box(const rad::Material& wall, const rad::Material& ceiling, const rad::Material& paper) {
  rad::Scene scene = test::closed_box(wall);
  rad::Scene out;
  const rad::MaterialId w = out.add_material(wall), c = out.add_material(ceiling), p = out.add_material(paper);
  for (std::size_t i = 0; i < scene.polygons().size(); ++i) {
    const std::string group = scene.groups()[scene.polygons()[i].group];
    out.add_polygon(scene.polygons()[i].vertices, group == "z1" ? c : w, group);
  }
  rad::add_quad(out, {0.5f, 0.02f, 0.02f}, {0, 0, 0.96f}, {0, 0.96f, 0}, p, "paper");
  return out;
}

/// partitioned_box() with grey walls, a ceiling of exitance 2 and a coloured paper.
rad::Scene paper_box() {
  rad::Material wall, ceiling, paper;
  wall.name = "wall";
  wall.reflectance = rad::Rgb(0.6f, 0.5f, 0.4f);
  ceiling.name = "ceiling";
  ceiling.emission = rad::Rgb(2.0f);
  ceiling.reflectance = rad::Rgb(0.2f);
  paper.name = "paper";
  paper.reflectance = rad::Rgb(0.3f);
  paper.diffuse_transmittance = rad::Rgb(0.5f, 0.3f, 0.1f);
  return partitioned_box(wall, ceiling, paper);
}

/// 4096 rays per element, elements of 0.05, tolerance 1e-6.
rad::SolveOptions box_options(rad::SolverMethod method) {
  rad::SolveOptions o;
  o.method = method;
  o.form_factors.method = rad::FormFactorMethod::monte_carlo;
  o.form_factors.hemisphere_rays = 4096;
  o.mesh.max_patch_area = 0.1f;
  o.mesh.max_element_area = 0.05f;
  o.tolerance = 1e-6;
  return o;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("translucent panel: lamp light reaches the tile through it as tau E F and every solver agrees") {
    // F between parallel unit squares at distance 1 (Howell C-11) is every factor involved:
    // panel back -> lamp, panel front -> tile and back. With the lamp's E, the panel's rho and
    // tau and the tile's rho_t the one-element system solves in closed form:
    //   B_panel = tau E F / (1 - rho rho_t F^2) (rho = 0 for a one-sided panel's back only;
    //   its front reflects rho), B_tile = rho_t F B_panel,
    //   B_back = rho' E F + tau F B_tile, rho' = rho for a two-sided panel, else 0.
    // Monte Carlo noise with 2^16 rays per element is about 0.8 % per factor (0.55 % measured
    // at worst): 3 % tolerance. Ray-cast factors are exact here (the shaft test clears the pairs
    // the panel cannot shadow, and every ray from the tile to the lamp is blocked): measured
    // 4e-6, tolerance 0.1 %. Hemicubes (16 of resolution 512 per element): measured 0.02 %,
    // tolerance 1 %.
    const double F = test::parallel_rectangles(1.0, 1.0, 1.0);
    for (std::uint32_t rays : {1u << 16, 0u, 1u})
    for (bool two_sided : {false, true}) {
      CAPTURE(rays);
      CAPTURE(two_sided);
      rad::Material panel;
      panel.name = "paper";
      panel.reflectance = rad::Rgb(0.3f, 0.2f, 0.1f);
      panel.diffuse_transmittance = rad::Rgb(0.5f, 0.4f, 0.6f);
      panel.two_sided = two_sided;
      const Stack s = lamp_panel_tile(panel);
      for (rad::SolverMethod method :
           {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
        CAPTURE(static_cast<int>(method));
        const rad::Solution sol = rad::solve(s.scene, one_element(method, rays));
        REQUIRE(sol.status() == rad::SolveStatus::converged);
        const double tolerance = rays == 0 ? 1e-3 : rays == 1 ? 0.01 : 0.03;
        const auto& patches = sol.hierarchy().patches();
        REQUIRE(patches.size() == 3);
        REQUIRE(sol.back_radiosity().size() == sol.radiosity().size());
        const rad::Rgb panel_front = sol.patch_radiosity(1), tile = sol.patch_radiosity(2);
        const rad::Rgb panel_back = sol.back_radiosity()[patches[1].root];
        for (int c = 0; c < 3; ++c) {
          CAPTURE(c);
          const double E = 10.0, rho = panel.reflectance[c], tau = panel.diffuse_transmittance[c], rho_t = 0.5;
          const double B_panel = tau * E * F / (1.0 - rho * rho_t * F * F);
          const double B_tile = rho_t * F * B_panel;
          const double B_back = (two_sided ? rho : 0.0) * E * F + tau * F * B_tile;
          CHECK(relative(panel_front[c], B_panel) < tolerance);
          CHECK(relative(tile[c], B_tile) < tolerance);
          CHECK(relative(panel_back[c], B_back) < tolerance);
        }
        // Opaque polygons have no back radiosity.
        CHECK(sol.back_radiosity()[patches[0].root] == rad::Rgb(0.0f));
        CHECK(sol.back_radiosity()[patches[2].root] == rad::Rgb(0.0f));
      }
    }
  }

  TEST_CASE("translucent partition in a closed box: absorbed power equals emitted and the solvers agree"
            * test::release_only) {
    // A closed grey box with an emitting ceiling, split by a one-sided translucent partition.
    // In a closed enclosure every ray lands on a side that keeps a radiosity, so all the power
    // is absorbed: by the walls (1 - rho) H and by the partition's sides (1 - rho - tau) H.
    const rad::Scene scene = paper_box();

    rad::Solution by[3];
    const rad::SolverMethod methods[3] = {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel,
                                          rad::SolverMethod::progressive};
    for (int k = 0; k < 3; ++k) {
      CAPTURE(k);
      by[k] = rad::solve(scene, box_options(methods[k]));
      REQUIRE(by[k].status() == rad::SolveStatus::converged);
      const rad::SolveReport& r = by[k].report();
      for (int c = 0; c < 3; ++c) CHECK(relative(r.absorbed_power[c], r.emitted_power[c]) < 0.01);
    }
    // Ray-cast factors: the rows' sums are off 1 by the visibility rays' noise where the
    // partition shadows (measured 0.31 % of the power at worst); the hemicube's by its
    // aliasing at the partition's edges (measured 0.31 %).
    rad::SolveOptions ro = box_options(rad::SolverMethod::gauss_seidel);
    ro.form_factors.method = rad::FormFactorMethod::ray_cast;
    const rad::Solution ray_cast = rad::solve(scene, ro);
    for (int c = 0; c < 3; ++c)
      CHECK(relative(ray_cast.report().absorbed_power[c], ray_cast.report().emitted_power[c]) < 0.005);
    ro.form_factors.method = rad::FormFactorMethod::hemicube;
    const rad::Solution hemicube = rad::solve(scene, ro);
    for (int c = 0; c < 3; ++c)
      CHECK(relative(hemicube.report().absorbed_power[c], hemicube.report().emitted_power[c]) < 0.005);
    // The far side (x1) is lit only through the paper; Jacobi and Gauss-Seidel share their rows
    // and converge to the same values; progressive shoots columns with other rays (MC noise);
    // ray-cast and hemicube factors are other estimates of the same factors (measured within
    // 0.36 % and 0.72 %).
    for (const char* group : {"x0", "x1", "z0", "paper"}) {
      CAPTURE(group);
      const rad::Rgb gs = by[1].group_radiosity(group);
      for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        CHECK(gs[c] > 0.0f);
        CHECK(relative(by[0].group_radiosity(group)[c], gs[c]) < 1e-4);
        CHECK(relative(by[2].group_radiosity(group)[c], gs[c]) < 0.01);
        CHECK(relative(ray_cast.group_radiosity(group)[c], gs[c]) < 0.01);
        CHECK(relative(hemicube.group_radiosity(group)[c], gs[c]) < 0.01);
      }
    }
  }

  TEST_CASE("translucent solves are bit-identical at 1 and 2 threads") {
    const rad::Scene scene = paper_box();
    for (rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::SolveOptions o = box_options(method);
      o.form_factors.hemisphere_rays = 256;
      o.threads = 1;
      const rad::Solution one = rad::solve(scene, o);
      o.threads = 2;
      const rad::Solution two = rad::solve(scene, o);
      CHECK(one.radiosity() == two.radiosity());
      CHECK(one.back_radiosity() == two.back_radiosity());
    }
  }

  TEST_CASE("adaptive subdivision keeps both sides of translucent elements" * test::release_only) {
    // The partitioned box refined where radiosity varies fast: the matrix methods compute front
    // and back rows for the new elements, progressive gathers both sides for them. Every leaf of
    // the paper ends with a back radiosity, and the two agree.
    const rad::Scene scene = paper_box();
    rad::Solution by[2];
    const rad::SolverMethod methods[2] = {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive};
    for (int k = 0; k < 2; ++k) {
      CAPTURE(k);
      rad::SolveOptions o = box_options(methods[k]);
      o.adaptive.enabled = true;
      o.adaptive.threshold = 0.1f;
      by[k] = rad::solve(scene, o);
      const rad::GroupId paper_group = *scene.find_group("paper");
      auto paper_leaves = [&](const rad::PatchHierarchy& h) {
        std::vector<std::uint32_t> out;
        for (std::uint32_t e : h.leaves())
          if (h.patches()[h.element(e).patch].group == paper_group) out.push_back(e);
        return out;
      };
      const rad::PatchHierarchy& h = by[k].hierarchy();
      const std::vector<std::uint32_t> leaves = paper_leaves(h);
      CHECK(leaves.size() > paper_leaves(rad::PatchHierarchy(scene, o.mesh)).size());  // some were split
      for (std::uint32_t e : leaves) CHECK(by[k].back_radiosity()[e].x > 0.0f);
      if (k == 0) {
        const rad::SolveReport& r = by[k].report();
        CHECK(relative(r.absorbed_power.x, r.emitted_power.x) < 0.01);
      }
    }
    for (const char* group : {"x0", "x1", "paper"}) {
      CAPTURE(group);
      CHECK(relative(by[1].group_radiosity(group).x, by[0].group_radiosity(group).x) < 0.01);
    }
  }

  TEST_CASE("without diffuse transmission the far side of an opaque partition gets less light") {
    // A lamp on the x0 wall facing the partition: with tau = 0 the x1 wall gets only light
    // that went round the partition's edges, and no back radiosity is kept.
    auto far_wall = [](float tau) {
      rad::Material wall, lamp, paper;
      wall.reflectance = rad::Rgb(0.5f);
      lamp.emission = rad::Rgb(20.0f);
      paper.reflectance = rad::Rgb(0.3f);
      paper.diffuse_transmittance = rad::Rgb(tau);
      rad::Scene scene = partitioned_box(wall, wall, paper);
      const rad::MaterialId l = scene.add_material(lamp);
      rad::add_quad(scene, {0.01f, 0.35f, 0.35f}, {0, 0, 0.3f}, {0, 0.3f, 0}, l, "lamp");  // faces +x
      rad::SolveOptions o;
      o.form_factors.method = rad::FormFactorMethod::monte_carlo;
      o.mesh.max_patch_area = 0.1f;
      const rad::Solution sol = rad::solve(scene, o);
      CHECK(sol.back_radiosity().empty() == (tau == 0.0f));
      return sol.group_radiosity("x1").x;
    };
    CHECK(far_wall(0.5f) > 1.5f * far_wall(0.0f));
  }

  TEST_CASE("render shows the back of a translucent sheet at its back radiosity over pi") {
    // A lamp above a translucent panel that faces it; from below, the camera sees the panel's
    // back, which sends tau times the front's irradiance: tau E F for the one-element mesh.
    rad::Scene scene;
    rad::Material lamp, paper;
    lamp.name = "lamp";
    lamp.emission = rad::Rgb(10.0f);
    lamp.reflectance = rad::Rgb(0.0f);
    paper.name = "paper";
    paper.reflectance = rad::Rgb(0.0f);
    paper.diffuse_transmittance = rad::Rgb(0.5f);
    const rad::MaterialId l = scene.add_material(lamp), p = scene.add_material(paper);
    rad::add_quad(scene, {0, 1, 2}, {1, 0, 0}, {0, -1, 0}, l, "lamp");   // faces down
    rad::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, p, "paper");   // faces up
    const rad::Solution sol = rad::solve(scene, one_element(rad::SolverMethod::gauss_seidel, 1u << 16));
    const double expected = 0.5 * 10.0 * test::parallel_rectangles(1.0, 1.0, 1.0) / 3.14159265358979;
    rad::RenderOptions ro;
    ro.width = ro.height = 8;
    ro.spp = 1;
    rad::Camera camera;
    camera.eye = {0.5f, 0.5f, -1.0f};
    camera.look_at = {0.5f, 0.5f, 1.0f};
    camera.fov_deg = 20.0f;
    ro.camera = camera;
    const rad::Image image = rad::render(scene, sol, ro);
    CHECK(relative(image.at(4, 4).x, expected) < 0.03);
    // The front (seen from above, between lamp and panel, looking down) reflects nothing.
    camera.eye = {0.5f, 0.5f, 1.5f};
    camera.look_at = {0.5f, 0.5f, 0.0f};
    ro.camera = camera;
    CHECK(rad::render(scene, sol, ro).at(4, 4).x == 0.0f);
  }

  TEST_CASE("backward form factors: exact to emitters and numbered after the patches") {
    // Lamp (patch 0), panel (1, translucent: its back is target 3) and tile (2), one element
    // each. The panel's back sees the lamp with the C-11 factor F: an emitting target, so the
    // entry is exact (analytic factor, visibility 1). The lamp's front row reaches the panel's
    // back by rays (2^16: 0.8 % noise), and the lamp's column reports the same arrival exactly.
    // Ray-cast factors are exact everywhere here (0.1 %), hemicubes (16 of resolution 512 per
    // element) within 1 %.
    const Stack s = paper_stack();
    const double F = test::parallel_rectangles(1.0, 1.0, 1.0);
    for (rad::FormFactorMethod method :
         {rad::FormFactorMethod::monte_carlo, rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::hemicube}) {
    CAPTURE(static_cast<int>(method));
    const double by_rays = method == rad::FormFactorMethod::monte_carlo ? 0.03
                           : method == rad::FormFactorMethod::hemicube  ? 0.01
                                                                        : 1e-3;
    const double exact = method == rad::FormFactorMethod::hemicube ? 0.01 : 1e-3;
    rad::FormFactorOptions f;
    f.method = method;
    f.diffuse_transmission = true;
    f.hemisphere_rays = 1u << 16;
    f.source_samples = 16;
    f.hemicube_resolution = 512;
    const rad::PatchHierarchy h(s.scene, rad::MeshOptions{10.0f, 10.0f});
    const auto estimator = rad::make_form_factor_estimator(s.scene, h, f);
    const std::vector<std::uint32_t> leaves = h.leaves();
    REQUIRE(leaves.size() == 3);
    const std::uint32_t lamp = h.patches()[0].root, paper = h.patches()[1].root, tile = h.patches()[2].root;

    std::vector<rad::SparseFactors> rows;
    estimator->sparse_back_rows({paper}, rows);
    REQUIRE(rows[0].index == std::vector<std::uint32_t>{0});  // the lamp only (the tile is in front)
    CHECK(relative(rows[0].value[0], F) < exact);

    estimator->sparse_element_rows({lamp, tile}, rows);
    REQUIRE(rows[0].index == std::vector<std::uint32_t>{3});  // the lamp sees the panel's back
    CHECK(relative(rows[0].value[0], F) < by_rays);
    REQUIRE(rows[1].index == std::vector<std::uint32_t>{1});  // the tile sees the panel's front
    CHECK(relative(rows[1].value[0], F) < by_rays);

    // Columns: arrivals at the back of leaves[k] are index leaves.size() + k.
    const auto position = [&](std::uint32_t e) {
      return static_cast<std::uint32_t>(std::find(leaves.begin(), leaves.end(), e) - leaves.begin());
    };
    rad::SparseFactors column;
    estimator->sparse_patch_column(0, leaves, column);
    REQUIRE(column.index == std::vector<std::uint32_t>{static_cast<std::uint32_t>(leaves.size()) + position(paper)});
    CHECK(relative(column.value[0], F) < exact);
    estimator->sparse_patch_column(3, leaves, column);  // shot from the panel's back
    REQUIRE(column.index == std::vector<std::uint32_t>{position(lamp)});
    CHECK(relative(column.value[0], F) < by_rays);
    }
  }

  TEST_CASE("every estimator numbers the backs of translucent patches and only those have back rows") {
    const Stack s = paper_stack();
    const rad::PatchHierarchy h(s.scene, rad::MeshOptions{10.0f, 10.0f});  // a patch per polygon
    std::vector<rad::SparseFactors> rows;
    for (rad::FormFactorMethod method : {rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::hemicube,
                                         rad::FormFactorMethod::analytic, rad::FormFactorMethod::monte_carlo}) {
      CAPTURE(static_cast<int>(method));
      rad::FormFactorOptions f;
      f.method = method;
      f.diffuse_transmission = true;
      const auto estimator = rad::make_form_factor_estimator(s.scene, h, f);
      REQUIRE(estimator->translucent_patches() == std::vector<std::uint32_t>{1});
      CHECK(estimator->target_count() == h.patches().size() + 1);
      CHECK(estimator->patches_with_backs() == estimator->translucent_patches());
      // Targets by name: every index round-trips; the back of patch 1 follows the fronts, and
      // an opaque patch's back is no target.
      const auto n = static_cast<std::uint32_t>(h.patches().size());
      for (std::uint32_t t = 0; t < estimator->target_count(); ++t)
        CHECK(estimator->target_index(estimator->target(t)) == t);
      CHECK(estimator->target(n) == rad::Target{1, rad::Side::back});
      CHECK(estimator->target_index(rad::Target{1, rad::Side::back}) == n);
      CHECK(estimator->target_index(rad::Target{0, rad::Side::front}) == 0);
      CHECK(estimator->target_index(rad::Target{0, rad::Side::back}) == rad::kNone);
      CHECK(estimator->target_index(rad::Target{n, rad::Side::front}) == rad::kNone);
      CHECK(estimator->target(n + 1).patch == rad::kNone);
      CHECK_NOTHROW(estimator->sparse_back_rows({h.patches()[1].root}, rows));
      CHECK_THROWS_WITH_AS(estimator->sparse_back_rows({h.patches()[0].root}, rows),
                           "sparse_back_rows: element 0 is not an element of a translucent patch", rad::Error);
      // Without the option: no backs, and asking for back rows is an error.
      f.diffuse_transmission = false;
      const auto plain = rad::make_form_factor_estimator(s.scene, h, f);
      CHECK(plain->translucent_patches().empty());
      CHECK(plain->target_count() == h.patches().size());
      CHECK_THROWS_AS(plain->sparse_back_rows({h.patches()[1].root}, rows), rad::Error);
    }
  }
}
