// Problem: the stages of solve() kept for more solves. A kept Problem must give what solve()
// gives, reuse its form factors (no form-factor work in a second matrix solve), and relight
// by the physics: radiosity is linear in the emission (superposition), and a relit solve
// equals a fresh solve of the scene with that emission in its materials.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// A unit room open at the top, lit by two small lamps on its walls whose emission the
/// caller chooses (polygons 0 and 1; the room's faces follow).
rad::Scene two_lamp_room(rad::Rgb lamp_a, rad::Rgb lamp_b) {
  rad::Scene scene;
  rad::Material a, b, wall;
  a.name = "lamp_a";
  a.emission = lamp_a;
  a.reflectance = rad::Rgb(0.5f);
  b.name = "lamp_b";
  b.emission = lamp_b;
  b.reflectance = rad::Rgb(0.5f);
  wall.name = "wall";
  wall.reflectance = rad::Rgb(0.7f, 0.5f, 0.3f);
  const rad::MaterialId ma = scene.add_material(a), mb = scene.add_material(b), mw = scene.add_material(wall);
  // Lamps 1 cm in front of the x = 0 and x = 1 walls, facing into the room.
  rad::add_quad(scene, {0.01f, 0.3f, 0.6f}, {0.0f, 0.2f, 0.0f}, {0.0f, 0.0f, -0.2f}, ma, "lamp_a");
  rad::add_quad(scene, {0.99f, 0.3f, 0.4f}, {0.0f, 0.2f, 0.0f}, {0.0f, 0.0f, 0.2f}, mb, "lamp_b");
  // The room's inward-facing floor and four walls (no ceiling: light escapes upwards).
  rad::add_quad(scene, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, mw, "floor");
  rad::add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, mw, "back");
  rad::add_quad(scene, {0, 0, 1}, {0, 1, 0}, {1, 0, 0}, mw, "front");
  rad::add_quad(scene, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, mw, "left");
  rad::add_quad(scene, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, mw, "right");
  return scene;
}

rad::SolveOptions options(rad::SolverMethod method) {
  rad::SolveOptions o;
  o.method = method;
  o.form_factors.method = rad::FormFactorMethod::ray_cast;  // factors do not depend on emission
  o.mesh.max_patch_area = 0.05f;
  o.mesh.max_element_area = 0.0125f;
  o.tolerance = 1e-7;
  return o;
}

/// Polygon emission of two_lamp_room(): the lamps' values, 0 for the room.
std::vector<rad::Rgb> lamp_emission(const rad::Scene& scene, rad::Rgb lamp_a, rad::Rgb lamp_b) {
  std::vector<rad::Rgb> e(scene.polygons().size(), rad::Rgb(0.0f));
  e[0] = lamp_a;
  e[1] = lamp_b;
  return e;
}

double max_relative_difference(const std::vector<rad::Rgb>& a, const std::vector<rad::Rgb>& b) {
  REQUIRE(a.size() == b.size());
  double scale = 0.0, worst = 0.0;
  for (const rad::Rgb& v : a) scale = std::max(scale, static_cast<double>(std::fmax(v.x, std::fmax(v.y, v.z))));
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(static_cast<double>(a[i][c]) - b[i][c]));
  return worst / scale;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("Problem: its first solve is solve()'s, bit for bit, for every solver method") {
    const rad::Scene scene = rad::cornell_box();
    for (rad::SolverMethod method :
         {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::SolveOptions o;
      o.method = method;
      o.mesh.max_patch_area = 20000.0f;
      o.adaptive.enabled = true;
      const rad::Solution once = rad::solve(scene, o);
      rad::Problem problem(scene, o);
      const rad::Solution kept = problem.solve();
      CHECK(kept.radiosity() == once.radiosity());
      CHECK(kept.report().iterations == once.report().iterations);
      CHECK(kept.report().refined_elements == once.report().refined_elements);
      CHECK(kept.hierarchy().leaves().size() == problem.hierarchy().leaves().size());
    }
  }

  TEST_CASE("Problem: a second matrix solve computes no form factors and repeats the first exactly") {
    const rad::Scene scene = two_lamp_room(rad::Rgb(8.0f), rad::Rgb(3.0f));
    rad::SolveOptions o = options(rad::SolverMethod::gauss_seidel);
    int form_factor_reports = 0;
    o.on_progress = [&](const rad::Progress& p) {
      if (p.phase == rad::Phase::form_factors) ++form_factor_reports;
      return true;
    };
    rad::Problem problem(scene, o);
    const rad::Solution first = problem.solve();
    CHECK(form_factor_reports > 0);
    const std::size_t bytes = problem.form_factor_bytes();
    CHECK(bytes > 0);
    CHECK(first.report().seconds_meshing >= 0.0);

    form_factor_reports = 0;
    const rad::Solution again = problem.solve();
    CHECK(form_factor_reports == 0);
    CHECK(problem.form_factor_bytes() == bytes);
    CHECK(again.radiosity() == first.radiosity());
    CHECK(again.report().seconds_meshing == 0.0);
  }

  TEST_CASE("Problem: relighting equals a fresh solve of the scene with that emission (ray cast, bit for bit)") {
    const rad::Rgb a(8.0f, 6.0f, 2.0f), b(1.0f, 3.0f, 9.0f);
    for (rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      const rad::Scene lit_by_a = two_lamp_room(a, rad::Rgb(0.0f));
      rad::Problem problem(lit_by_a, options(method));
      (void)problem.solve();
      const rad::Solution relit = problem.solve(lamp_emission(lit_by_a, rad::Rgb(0.0f), b));
      const rad::Solution fresh = rad::solve(two_lamp_room(rad::Rgb(0.0f), b), options(method));
      CHECK(relit.radiosity() == fresh.radiosity());
      CHECK(relit.report().emitted_power == fresh.report().emitted_power);
    }
  }

  TEST_CASE("Problem: radiosity is linear in the emission (superposition and scaling within 1e-5)") {
    const rad::Rgb a(8.0f, 6.0f, 2.0f), b(1.0f, 3.0f, 9.0f);
    const rad::Scene scene = two_lamp_room(a, b);
    rad::Problem problem(scene, options(rad::SolverMethod::jacobi));
    const rad::Solution both = problem.solve();
    const rad::Solution only_a = problem.solve(lamp_emission(scene, a, rad::Rgb(0.0f)));
    const rad::Solution only_b = problem.solve(lamp_emission(scene, rad::Rgb(0.0f), b));
    const rad::Solution doubled = problem.solve(lamp_emission(scene, 2.0f * a, 2.0f * b));
    std::vector<rad::Rgb> sum(both.radiosity().size()), twice(both.radiosity().size());
    for (std::size_t i = 0; i < sum.size(); ++i) {
      sum[i] = only_a.radiosity()[i] + only_b.radiosity()[i];
      twice[i] = 2.0f * both.radiosity()[i];
    }
    CHECK(max_relative_difference(sum, both.radiosity()) < 1e-5);
    CHECK(max_relative_difference(twice, doubled.radiosity()) < 1e-5);
    // Switching every lamp off is exact.
    const rad::Solution dark = problem.solve(std::vector<rad::Rgb>(scene.polygons().size(), rad::Rgb(0.0f)));
    for (const rad::Rgb& v : dark.radiosity()) CHECK(v == rad::Rgb(0.0f));
  }

  TEST_CASE("Problem: adaptive subdivision refines the kept hierarchy, within the initial mesh's budget") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.adaptive.enabled = true;
    rad::Problem problem(scene, o);
    const std::size_t initial = problem.hierarchy().leaves().size();
    const rad::Solution first = problem.solve();
    REQUIRE(first.report().refined_elements > 0);
    CHECK(problem.hierarchy().leaves().size() == first.hierarchy().leaves().size());
    CHECK(problem.hierarchy().leaves().size() > initial);
    for (int k = 0; k < 3; ++k) (void)problem.solve();
    CHECK(problem.hierarchy().leaves().size() <= 4 * initial);
  }

  TEST_CASE("Problem: bad emission is refused, naming the problem") {
    const rad::Scene scene = two_lamp_room(rad::Rgb(1.0f), rad::Rgb(1.0f));
    rad::Problem problem(scene, options(rad::SolverMethod::gauss_seidel));
    auto message = [&](const std::vector<rad::Rgb>& e) {
      try {
        (void)problem.solve(e);
      } catch (const rad::Error& error) {
        CHECK(error.code() == rad::ErrorCode::invalid_argument);
        return std::string(error.what());
      }
      return std::string("no error");
    };
    CHECK(message(std::vector<rad::Rgb>(3)).find("polygon_emission has 3 values; the scene has 7 polygons") !=
          std::string::npos);
    std::vector<rad::Rgb> negative(scene.polygons().size(), rad::Rgb(0.0f));
    negative[4] = rad::Rgb(1.0f, -1.0f, 0.0f);
    CHECK(message(negative).find("polygon_emission[4] must be finite and >= 0") != std::string::npos);
    std::vector<rad::Rgb> nan(scene.polygons().size(), rad::Rgb(0.0f));
    nan[0].z = std::nanf("");
    CHECK(message(nan).find("polygon_emission[0]") != std::string::npos);
    const rad::Scene empty;
    CHECK_THROWS_AS(rad::Problem{empty}, rad::Error);
    // A temporary scene would dangle: that constructor is deleted.
    static_assert(!std::is_constructible_v<rad::Problem, rad::Scene&&>);
    static_assert(std::is_constructible_v<rad::Problem, const rad::Scene&>);
  }
}
