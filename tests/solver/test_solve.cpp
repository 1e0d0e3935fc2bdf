#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

rad::Material furnace_material() {
  rad::Material m;
  m.name = "furnace";
  m.emission = rad::Rgb(1.0f, 2.0f, 0.5f);
  m.reflectance = rad::Rgb(0.5f, 0.8f, 0.2f);
  return m;
}

rad::SolveOptions coarse(rad::SolverMethod method) {
  rad::SolveOptions o;
  o.method = method;
  o.mesh.max_patch_area = 0.26f;  // 4 patches per unit face
  o.mesh.max_element_area = 0.07f;
  o.tolerance = 1e-6;
  return o;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("furnace: a closed box with uniform E and rho gives B = E/(1-rho) within 0.1% for every method") {
    const rad::Material m = furnace_material();
    const rad::Scene scene = test::closed_box(m);
    const rad::Rgb expected = m.emission / (rad::Rgb(1.0f) - m.reflectance);
    for (rad::SolverMethod method :
         {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::Solution sol = rad::solve(scene, coarse(method));
      CHECK(sol.status() == rad::SolveStatus::converged);
      const auto& h = sol.hierarchy();
      for (std::uint32_t e : h.leaves())
        for (int c = 0; c < 3; ++c) CHECK(sol.radiosity()[e][c] == doctest::Approx(expected[c]).epsilon(1e-3));
      // Closed: everything emitted is absorbed.
      const rad::SolveReport& r = sol.report();
      for (int c = 0; c < 3; ++c)
        CHECK(r.absorbed_power[c] == doctest::Approx(r.emitted_power[c]).epsilon(1e-3));
    }
  }

  TEST_CASE("Jacobi - Gauss-Seidel and progressive agree on the Cornell box within 0.5%") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 12000.0f;
    o.mesh.max_element_area = 6000.0f;
    o.tolerance = 1e-5;
    o.method = rad::SolverMethod::gauss_seidel;
    rad::Solution gs = rad::solve(scene, o);
    o.method = rad::SolverMethod::jacobi;
    rad::Solution jacobi = rad::solve(scene, o);
    o.method = rad::SolverMethod::progressive;
    rad::Solution progressive = rad::solve(scene, o);
    REQUIRE(gs.status() == rad::SolveStatus::converged);
    REQUIRE(jacobi.status() == rad::SolveStatus::converged);
    REQUIRE(progressive.status() == rad::SolveStatus::converged);
    // Gauss-Seidel needs fewer sweeps than Jacobi.
    CHECK(gs.report().iterations < jacobi.report().iterations);
    for (const std::string& g : scene.groups()) {
      CAPTURE(g);
      rad::Rgb a = gs.group_radiosity(g), b = jacobi.group_radiosity(g), c = progressive.group_radiosity(g);
      for (int k = 0; k < 3; ++k) {
        CHECK(b[k] == doctest::Approx(a[k]).epsilon(5e-3));
        CHECK(c[k] == doctest::Approx(a[k]).epsilon(5e-3));
      }
    }
  }

  TEST_CASE("open Cornell box: emitted power = absorbed + escaped - with escape through the open front") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 20000.0f;
    o.tolerance = 1e-6;
    rad::Solution sol = rad::solve(scene, o);
    const rad::SolveReport& r = sol.report();
    for (int c = 0; c < 3; ++c) {
      CHECK(r.absorbed_power[c] < r.emitted_power[c]);
      CHECK(r.absorbed_power[c] > 0.5f * r.emitted_power[c]);
    }
    // The light is the brightest group and the red wall is red.
    rad::Rgb red = sol.group_radiosity("red_wall");
    CHECK(red.x > 3.0f * red.y);
    rad::Rgb green = sol.group_radiosity("green_wall");
    CHECK(green.y > 1.5f * green.x);
  }

  TEST_CASE("same seed gives bit-identical results at 1 and 2 threads") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 10000.0f;
    o.threads = 1;
    rad::Solution a = rad::solve(scene, o);
    o.threads = 2;
    rad::Solution b = rad::solve(scene, o);
    REQUIRE(a.radiosity().size() == b.radiosity().size());
    bool same = true;
    for (std::size_t i = 0; i < a.radiosity().size(); ++i) same &= a.radiosity()[i] == b.radiosity()[i];
    CHECK(same);
  }

  TEST_CASE("a progress callback that returns false cancels and leaves a consistent estimate") {
    const rad::Scene scene = test::closed_box(furnace_material());
    rad::SolveOptions o = coarse(rad::SolverMethod::progressive);
    int calls = 0;
    o.on_progress = [&](const rad::Progress& p) {
      ++calls;
      return p.phase != rad::Phase::solving;
    };
    rad::Solution sol = rad::solve(scene, o);
    CHECK(sol.status() == rad::SolveStatus::cancelled);
    CHECK(calls > 0);
    // At least the emission is there, and nothing is more than the converged answer.
    for (std::uint32_t e : sol.hierarchy().leaves()) {
      CHECK(sol.radiosity()[e].x >= 1.0f);
      CHECK(sol.radiosity()[e].x <= 2.0f + 1e-4f);
    }
  }

  TEST_CASE("bad options are rejected naming the field") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.tolerance = 0.0;
    CHECK_THROWS_WITH_AS(rad::solve(scene, o), doctest::Contains("tolerance"), rad::Error);
    o = {};
    o.mesh.max_element_area = -1.0f;
    CHECK_THROWS_WITH_AS(rad::solve(scene, o), doctest::Contains("max_element_area"), rad::Error);
    o = {};
    o.max_iterations = -3;
    CHECK_THROWS_WITH_AS(rad::solve(scene, o), doctest::Contains("max_iterations"), rad::Error);
    CHECK_THROWS_AS(rad::solve(rad::Scene{}, rad::SolveOptions{}), rad::Error);
  }

  TEST_CASE("a matrix larger than the memory budget is refused with advice - not allocated") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.method = rad::SolverMethod::gauss_seidel;  // asked for: no automatic fallback
    o.memory_budget_bytes = 1024;
    try {
      rad::solve(scene, o);
      FAIL("expected a memory budget error");
    } catch (const rad::Error& e) {
      CHECK(e.code() == rad::ErrorCode::memory_budget);
      CHECK(std::string(e.what()).find("progressive") != std::string::npos);
    }
  }

  TEST_CASE("a matrix over the budget is refused before the lights' first shot - which can take as long as the factors") {
    rad::Scene scene = rad::cornell_box();
    rad::Light sky;
    sky.type = rad::LightType::sky;
    sky.intensity = 100.0f;
    scene.add_light(sky);
    rad::SolveOptions o;
    o.method = rad::SolverMethod::gauss_seidel;
    o.memory_budget_bytes = 1024;
    bool lights_started = false;
    o.on_progress = [&](const rad::Progress& p) {
      lights_started = lights_started || p.phase == rad::Phase::lights;
      return true;
    };
    CHECK_THROWS_AS(rad::solve(scene, o), rad::Error);
    CHECK_FALSE(lights_started);
    // Within the budget the same scene shoots its lights first.
    o.memory_budget_bytes = 0;  // the default
    o.mesh.max_patch_area = 20000.0f;
    rad::solve(scene, o);
    CHECK(lights_started);
  }

  TEST_CASE("the automatic method is Gauss-Seidel within the memory budget and hierarchical beyond, and says why") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;  // SolverMethod::automatic
    o.tolerance = 1e-4;
    const rad::Solution within = rad::solve(scene, o);
    CHECK(within.report().method == rad::SolverMethod::gauss_seidel);
    CHECK(within.report().method_choice.find("within the memory budget") != std::string::npos);
    CHECK(within.report().link_count == 0);
    // The same rows (6.4 MiB) against a 4 MiB budget: the hierarchical solver (its links, 1.3
    // MiB, fit), no error, the figure given.
    o.memory_budget_bytes = 4u << 20;
    const rad::Solution beyond = rad::solve(scene, o);
    CHECK(beyond.status() == rad::SolveStatus::converged);
    CHECK(beyond.report().method == rad::SolverMethod::hierarchical);
    CHECK(beyond.report().method_choice.find("over the memory budget of 4 MiB") != std::string::npos);
    CHECK(beyond.report().link_count > 0);
    // Both are the Cornell box: group means agree within the hierarchical solver's accuracy
    // (docs/HIERARCHICAL.md; element-to-patch rows here, so up to about 8 % on the floor).
    for (const std::string& g : scene.groups())
      CHECK(beyond.group_radiosity(g).y == doctest::Approx(within.group_radiosity(g).y).epsilon(0.1));
    // A Problem keeps its choice and says it in every report.
    rad::Problem problem(scene, o);
    CHECK(problem.solve().report().method == rad::SolverMethod::hierarchical);
    CHECK(problem.options().method == rad::SolverMethod::hierarchical);
    CHECK(problem.solve().report().method_choice == beyond.report().method_choice);
    // Mirror paths need the rows: then the budget error stands.
    o.form_factors.specular_depth = 1;
    CHECK_THROWS_AS(rad::solve(scene, o), rad::Error);
    // Asked for by name, no choice is made or reported.
    o = {};
    o.method = rad::SolverMethod::jacobi;
    CHECK(rad::solve(scene, o).report().method_choice.empty());
  }

  TEST_CASE("Problem::plan() says before solving what the first solve does - within and beyond the budget, "
            "named methods") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;  // SolverMethod::automatic
    o.tolerance = 1e-4;
    // The default budget (4 GiB) and 4 MiB, which the rows (6.4 MiB) exceed.
    for (const std::size_t budget : {std::size_t{0}, std::size_t{4} << 20}) {
      o.memory_budget_bytes = budget;
      rad::Problem problem(scene, o);
      const rad::SolvePlan plan = problem.plan();
      CHECK(plan.method == (budget == 0 ? rad::SolverMethod::gauss_seidel : rad::SolverMethod::hierarchical));
      CHECK(!plan.method_choice.empty());
      // The rows costed: the Cornell box's default estimator (Monte Carlo, sparse rows of an
      // index and a float per entry, at most one entry per patch), the figure the choice gives.
      const std::size_t leaves = problem.hierarchy().leaves().size(), patches = problem.hierarchy().patches().size();
      CHECK(plan.row_form_factor_method == problem.options().form_factors.method);
      CHECK(plan.row_form_factor_method == rad::FormFactorMethod::monte_carlo);
      CHECK(plan.sparse_rows);
      CHECK(plan.row_bytes > (std::size_t{4} << 20));
      CHECK(plan.row_bytes <= leaves * patches * 2 * sizeof(float));
      CHECK(plan.method_choice.find(std::to_string((plan.row_bytes + (1u << 20) - 1) >> 20) + " MiB") !=
            std::string::npos);
      const rad::SolveReport r = problem.solve().report();
      CHECK(r.method == plan.method);
      CHECK(r.method_choice == plan.method_choice);
      CHECK(r.form_factor_method == plan.form_factor_method);
      CHECK(r.specular_depth == plan.specular_depth);
      CHECK(r.specular_depth_choice == plan.specular_depth_choice);
      // And a fresh solve() agrees with it.
      CHECK(rad::solve(scene, o).report().method_choice == plan.method_choice);
    }
    // Named: no choice; a matrix method's rows are costed (the figure it would be refused by),
    // the hierarchical solver's are not.
    o = {};
    o.method = rad::SolverMethod::jacobi;
    rad::Problem jacobi(scene, o);
    const rad::SolvePlan named = jacobi.plan();
    CHECK(named.method == rad::SolverMethod::jacobi);
    CHECK(named.method_choice.empty());
    CHECK(named.row_bytes > 0);
    o.method = rad::SolverMethod::hierarchical;
    rad::Problem links(scene, o);
    CHECK(links.plan().row_bytes == 0);
  }

  TEST_CASE("group_radiosity of an unknown group names it") {
    const rad::Scene scene = test::closed_box(furnace_material());
    rad::Solution sol = rad::solve(scene, coarse(rad::SolverMethod::gauss_seidel));
    CHECK_THROWS_WITH_AS(sol.group_radiosity("nope"), doctest::Contains("nope"), rad::Error);
    CHECK(sol.group_area("x0") == doctest::Approx(1.0));
  }

  TEST_CASE("a scene that emits nothing solves to zero with a warning") {
    rad::Material m;
    m.reflectance = rad::Rgb(0.5f);
    rad::Solution sol = rad::solve(test::closed_box(m), coarse(rad::SolverMethod::jacobi));
    CHECK(sol.group_radiosity("x0") == rad::Rgb(0.0f));
    CHECK_FALSE(sol.report().warnings.empty());
  }
}
