// Two-sided surfaces in pass 1 (Material::two_sided, Scene::make_two_sided): a single sheet has a
// radiosity on each side, each side reflecting what it receives (and emitting, for an emitter),
// with every estimator and solver; a closed box wound outwards is right once two-sided.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"
#include "support/build.hpp"

namespace rad = radiosity;

namespace {

/// Factors from `method` ("ray-cast", "analytic", "hemicube", "monte-carlo"), one patch and
/// element per polygon.
rad::SolveOptions options_for(const std::string& method, rad::SolverMethod solver) {
  rad::SolveOptions o;
  o.method = solver;
  o.mesh.max_patch_area = 10.0f;
  o.mesh.max_element_area = 10.0f;
  o.tolerance = 1e-7;
  if (method == "analytic") o.form_factors.method = rad::FormFactorMethod::analytic;
  if (method == "hemicube") {
    o.form_factors.method = rad::FormFactorMethod::hemicube;
    o.form_factors.source_samples = 16;
    o.form_factors.hemicube_resolution = 512;
  }
  if (method == "monte-carlo") {
    o.form_factors.method = rad::FormFactorMethod::monte_carlo;
    o.form_factors.hemisphere_rays = 1u << 16;
  }
  return o;
}

/// The area-weighted mean of a side's radiosity over a group.
rad::Rgb group_mean(const rad::Solution& sol, const rad::Scene& scene, const std::string& group, bool back) {
  const rad::GroupId g = *scene.find_group(group);
  const rad::PatchHierarchy& h = sol.hierarchy();
  const std::vector<rad::Rgb>& B = back ? sol.back_radiosity() : sol.radiosity();
  REQUIRE(B.size() == h.elements().size());
  rad::Rgb sum(0.0f);
  double area = 0.0;
  for (const rad::Patch& p : h.patches())
    if (scene.polygons()[p.polygon].group == g) {
      sum += B[p.root] * h.element(p.root).area;
      area += h.element(p.root).area;
    }
  return sum / static_cast<float>(area);
}

double relative(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("a two-sided panel lit from both sides has the closed-form radiosity on each side") {
    // Unit squares on the z axis: lamp A at z = 2 facing down, the panel at z = 1 facing up
    // (front towards A), lamp B at z = 0 facing up. Each side sees one lamp with Howell's C-11
    // factor F, and the panel hides the lamps from each other, so B_front = rho F E_A and
    // B_back = rho F E_B exactly.
    const double F = test::parallel_rectangles(1, 1, 1);
    rad::Scene scene;
    rad::Material lamp_a, lamp_b, panel;
    lamp_a.name = "lamp_a";
    lamp_a.emission = rad::Rgb(10.0f);
    lamp_a.reflectance = rad::Rgb(0.0f);
    lamp_b.name = "lamp_b";
    lamp_b.emission = rad::Rgb(4.0f, 2.0f, 1.0f);
    lamp_b.reflectance = rad::Rgb(0.0f);
    panel.name = "panel";
    panel.reflectance = rad::Rgb(0.6f, 0.5f, 0.4f);
    panel.two_sided = true;
    const rad::MaterialId a = scene.add_material(lamp_a), b = scene.add_material(lamp_b),
                          p = scene.add_material(panel);
    rad::add_quad(scene, {0, 1, 2}, {1, 0, 0}, {0, -1, 0}, a, "lamp_a");
    rad::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, p, "panel");
    rad::add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, b, "lamp_b");
    const rad::Rgb front_expected = panel.reflectance * static_cast<float>(F) * lamp_a.emission;
    const rad::Rgb back_expected = panel.reflectance * static_cast<float>(F) * lamp_b.emission;

    // Monte Carlo entries carry ray noise: sqrt((1 - F) / (F N)) = 0.8 % at 2^16 rays.
    const struct {
      const char* method;
      double tolerance;
    } cases[] = {{"ray-cast", 1e-3}, {"analytic", 1e-4}, {"hemicube", 5e-3}, {"monte-carlo", 0.03}};
    for (const auto& c : cases)
      for (rad::SolverMethod solver : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
        CAPTURE(std::string(c.method));
        CAPTURE(static_cast<int>(solver));
        const rad::Solution sol = rad::solve(scene, options_for(c.method, solver));
        const rad::Rgb front = group_mean(sol, scene, "panel", false), back = group_mean(sol, scene, "panel", true);
        for (int k = 0; k < 3; ++k) {
          CHECK(relative(front[k], front_expected[k]) < c.tolerance);
          CHECK(relative(back[k], back_expected[k]) < c.tolerance);
        }
      }
  }

  TEST_CASE("a closed box wound outwards is black inside one-sided and gives B = E/(1 - rho) two-sided") {
    // add_box faces face out of the box: an exporter's mistake for a room. Every face emits E
    // and reflects rho.
    rad::Material m;
    m.name = "wall";
    m.emission = rad::Rgb(1.0f, 2.0f, 3.0f);
    m.reflectance = rad::Rgb(0.5f, 0.3f, 0.7f);
    rad::Scene scene;
    const rad::MaterialId id = scene.add_material(m);
    rad::add_box(scene, {0, 0, 0}, {1, 1, 1}, id, "room");
    rad::SolveOptions o = options_for("ray-cast", rad::SolverMethod::gauss_seidel);
    o.mesh.max_element_area = 0.0625f;  // 16 elements per face

    // One-sided: the fronts face into nothing, B = E; the inside (the backs) is black.
    const rad::Solution outward = rad::solve(scene, o);
    CHECK(outward.back_radiosity().empty());
    const rad::Rgb b0 = outward.group_radiosity("room");
    for (int k = 0; k < 3; ++k) CHECK(b0[k] == doctest::Approx(m.emission[k]).epsilon(1e-5));

    // Two-sided: the inside is the closed box of a one-material furnace, B = E / (1 - rho)
    // (ray-cast rows of a closed cube sum to 1 within 4e-7); the outside still B = E.
    scene.make_two_sided();
    for (const char* method : {"ray-cast", "monte-carlo"}) {
      CAPTURE(std::string(method));
      rad::SolveOptions om = options_for(method, rad::SolverMethod::gauss_seidel);
      om.mesh.max_element_area = 0.0625f;
      if (std::string(method) == "monte-carlo") om.form_factors.hemisphere_rays = 4096;
      const rad::Solution sol = rad::solve(scene, om);
      REQUIRE(!sol.back_radiosity().empty());
      const rad::Rgb inside = group_mean(sol, scene, "room", true), outside = group_mean(sol, scene, "room", false);
      for (int k = 0; k < 3; ++k) {
        const double expected = m.emission[k] / (1.0 - m.reflectance[k]);
        CHECK(relative(inside[k], expected) < 1e-3);
        CHECK(outside[k] == doctest::Approx(m.emission[k]).epsilon(1e-5));
      }
      // Every leaf's back, not just the mean (a closed Monte Carlo row sums to 1 exactly).
      double worst = 0.0;
      for (std::uint32_t leaf : sol.hierarchy().leaves())
        worst = std::max(worst, relative(sol.back_radiosity()[leaf].y, m.emission.y / (1.0 - m.reflectance.y)));
      MESSAGE(std::string(method) << ": worst leaf back radiosity off by " << worst);
      CHECK(worst < 2e-3);
    }

    // render() inside the box shows the backs (vertex radiosity / pi), and the PLY carries a
    // back face for every leaf.
    {
      rad::SolveOptions om = options_for("ray-cast", rad::SolverMethod::gauss_seidel);
      om.mesh.max_element_area = 0.0625f;
      const rad::Solution sol = rad::solve(scene, om);
      rad::RenderOptions ro;
      ro.width = 8;
      ro.height = 8;
      ro.camera = rad::Camera{{0.5f, 0.5f, 0.1f}, {0.5f, 0.5f, 1.0f}, {0, 1, 0}, 90.0f};
      const rad::Image img = rad::render(scene, sol, ro);
      double sum = 0.0;
      for (const rad::Rgb& px : img.pixels) sum += px.y;
      const double L = sum / static_cast<double>(img.pixels.size());
      CHECK(relative(L, m.emission.y / ((1.0 - m.reflectance.y) * 3.14159265358979323846)) < 1e-3);
      const std::string ply = std::string(RADIOSITY_TEST_TMP) + "/two_sided_box.ply";
      rad::write_ply(sol, ply);
      std::ifstream in(ply, std::ios::binary);
      std::string header, line;
      while (std::getline(in, line) && line != "end_header") header += line + "\n";
      // 96 quad leaves, 2 triangles each, front and back.
      CHECK(header.find("element face " + std::to_string(2 * 2 * sol.hierarchy().leaves().size())) != std::string::npos);
    }

    // The path tracer, inside the same box: every pixel sees L = E / ((1 - rho) pi), the backs
    // emitting and reflecting as in pass 1.
    rad::PathTraceOptions po;
    po.width = 8;
    po.height = 8;
    po.spp = 256;
    po.camera = rad::Camera{{0.5f, 0.5f, 0.1f}, {0.5f, 0.5f, 1.0f}, {0, 1, 0}, 90.0f};
    const rad::Image img = rad::render_path_traced(scene, po);
    for (int k = 0; k < 3; ++k) {
      double sum = 0.0;
      for (const rad::Rgb& px : img.pixels) sum += px[k];
      const double L = sum / static_cast<double>(img.pixels.size());
      const double expected = m.emission[k] / ((1.0 - m.reflectance[k]) * 3.14159265358979323846);
      MESSAGE("path tracer inside the outward two-sided box, channel " << k << ": " << L << " expected " << expected);
      CHECK(relative(L, expected) < 0.02);
    }
  }

  TEST_CASE("two-sided sheets in a room match the reference path tracer on both sides" * test::release_only) {
    // A closed room (inward) lit by a ceiling lamp, with a two-sided table top (one quad) in
    // the middle: its top is lit directly, its underside only by the floor's light. The path
    // tracer renders two-sided materials with the same rule (reflect and emit on both sides).
    rad::Material wall, lamp, table;
    wall.name = "wall";
    wall.reflectance = rad::Rgb(0.6f);
    lamp.name = "lamp";
    lamp.emission = rad::Rgb(20.0f);
    lamp.reflectance = rad::Rgb(0.0f);
    table.name = "table";
    table.reflectance = rad::Rgb(0.7f, 0.5f, 0.3f);
    table.two_sided = true;
    rad::Scene scene = test::closed_box(wall, glm::vec3(2.0f));
    rad::Scene room;
    const rad::MaterialId w = room.add_material(wall), l = room.add_material(lamp), t = room.add_material(table);
    for (const rad::Polygon& poly : scene.polygons()) room.add_polygon(poly.vertices, w, scene.groups()[poly.group]);
    rad::add_quad(room, {0.75f, 1.99f, 0.75f}, {0.5f, 0, 0}, {0, 0, 0.5f}, l, "lamp");   // facing down
    rad::add_quad(room, {0.5f, 0.8f, 0.5f}, {0, 0, 1.0f}, {1.0f, 0, 0}, t, "table");      // facing up
    rad::SolveOptions o;
    o.form_factors.method = rad::FormFactorMethod::ray_cast;
    o.mesh.max_element_area = 0.01f;
    o.tolerance = 1e-5;
    const rad::Solution sol = rad::solve(room, o);
    const rad::Rgb top = group_mean(sol, room, "table", false), under = group_mean(sol, room, "table", true);
    MESSAGE("radiosity: table top " << top.x << ", underside " << under.x);
    CHECK(top.x > 3.0f * under.x);
    CHECK(under.x > 0.0f);

    // The path tracer looks at each side from a camera: the top from above, the underside
    // from below, a small image of the table's middle only.
    auto mean_radiance = [&](glm::vec3 eye, glm::vec3 up) {
      rad::PathTraceOptions po;
      po.width = 16;
      po.height = 16;
      po.spp = 1024;
      po.camera = rad::Camera{eye, {1.0f, 0.8f, 1.0f}, up, 20.0f};
      const rad::Image img = rad::render_path_traced(room, po);
      double sum = 0.0;
      for (const rad::Rgb& px : img.pixels) sum += px.x;
      return sum / static_cast<double>(img.pixels.size());
    };
    // The radiosity of the middle of each side, against the path tracer's pi L there.
    auto middle = [&](bool back) {
      return test::leaf_mean(
          sol, room, "table", [](glm::vec3 c) { return std::fabs(c.x - 1.0f) <= 0.12f && std::fabs(c.z - 1.0f) <= 0.12f; },
          back);
    };
    const double pi = 3.14159265358979323846;
    const double top_path = pi * mean_radiance({1.0f, 1.6f, 1.0f}, {0, 0, 1}),
                 under_path = pi * mean_radiance({1.0f, 0.1f, 1.0f}, {0, 0, 1});
    const double top_rad = middle(false), under_rad = middle(true);
    MESSAGE("table middle: top radiosity " << top_rad << " path " << top_path << "; underside radiosity " << under_rad
                                           << " path " << under_path);
    CHECK(relative(top_rad, top_path) < 0.04);
    CHECK(relative(under_rad, under_path) < 0.06);
  }
}
