// Light groups (SolveOptions::separate_light_groups, Solution::relight()): each emitting group
// solved on its own shares the form factors; by superposition the groups add up to the joint
// solve, and a relit solution equals a solve with the emitters scaled (weight 0: switched off).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// The Cornell box with a second, orange lamp on the back wall (group "wall_lamp").
rad::Scene two_lamps() {
  rad::Scene scene = rad::cornell_box();
  rad::Material lamp;
  lamp.reflectance = rad::Rgb(0.5f);
  lamp.emission = rad::Rgb(8.0f, 4.0f, 1.0f);
  // Facing the room (-z) just in front of the back wall at z = 559.2.
  rad::add_quad(scene, {200.0f, 300.0f, 559.0f}, {0.0f, 100.0f, 0.0f}, {150.0f, 0.0f, 0.0f}, scene.add_material(lamp),
                "wall_lamp");
  return scene;
}

rad::SolveOptions options(rad::SolverMethod method) {
  rad::SolveOptions o;
  o.method = method;
  o.tolerance = 1e-7;
  o.mesh.max_patch_area = 20000.0f;
  o.separate_light_groups = true;
  return o;
}

/// Largest difference between two per-element fields, relative to the largest value of `b`.
double relative_difference(const std::vector<rad::Rgb>& a, const std::vector<rad::Rgb>& b) {
  REQUIRE(a.size() == b.size());
  double largest = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      largest = std::max(largest, static_cast<double>(std::abs(b[i][c])));
      diff = std::max(diff, static_cast<double>(std::abs(a[i][c] - b[i][c])));
    }
  return largest > 0.0 ? diff / largest : diff;
}

std::vector<rad::Rgb> sum_of(const std::vector<rad::LightGroupSolution>& groups,
                             std::vector<rad::Rgb> rad::LightGroupSolution::*field) {
  std::vector<rad::Rgb> sum((groups.front().*field).size(), rad::Rgb(0.0f));
  for (const rad::LightGroupSolution& g : groups)
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += (g.*field)[i];
  return sum;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("light groups: the groups add up to the joint solve within 1e-4") {
    const rad::Scene scene = two_lamps();
    for (rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      const rad::Solution sol = rad::solve(scene, options(method));
      REQUIRE(sol.light_groups().size() == 2);
      CHECK(sol.light_groups()[0].name == "light");
      CHECK(sol.light_groups()[1].name == "wall_lamp");
      CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::radiosity), sol.radiosity()) < 1e-4);
      CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::irradiance), sol.irradiance()) <
            1e-4);
      CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::direct_irradiance),
                                sol.direct_irradiance()) < 1e-4);
      // Each group is lit: the wall lamp's group carries orange light, the ceiling light's white.
      const rad::Rgb wall = sol.light_groups()[1].radiosity[sol.hierarchy().patches().back().root];
      CHECK(wall.x > 2.0f * wall.z);
    }
  }

  TEST_CASE("light groups: relight with weight 0 equals a solve without the group and 0.5 a dimmed one") {
    const rad::Scene scene = two_lamps();
    const rad::SolveOptions o = options(rad::SolverMethod::gauss_seidel);
    const rad::Solution sol = rad::solve(scene, o);
    for (float w : {0.0f, 0.5f}) {
      CAPTURE(w);
      const rad::Solution relit = sol.relight({rad::Rgb(1.0f), rad::Rgb(w)});
      // The reference solves the same Problem (the same form factors: the Monte Carlo estimator
      // picks its exact emitters from the materials) with the wall lamp's emission scaled.
      rad::SolveOptions plain = o;
      plain.separate_light_groups = false;
      rad::Problem problem(scene, plain);
      std::vector<rad::Rgb> emission;
      for (const rad::Polygon& p : scene.polygons())
        emission.push_back((scene.groups()[p.group] == "wall_lamp" ? w : 1.0f) * scene.material(p.material).emission);
      const rad::Solution reference = problem.solve(emission);
      CHECK(relative_difference(relit.radiosity(), reference.radiosity()) < 1e-4);
      CHECK(relative_difference(relit.irradiance(), reference.irradiance()) < 1e-4);
      // The relit solution shares the solved groups and keeps the weights.
      REQUIRE(relit.light_groups().size() == 2);
      CHECK(&relit.light_groups()[0] == &sol.light_groups()[0]);
      CHECK(relit.light_group_weights()[1] == rad::Rgb(w));
      CHECK(relit.light_group_radiosity(1, "floor").y ==
            doctest::Approx(w * sol.light_group_radiosity(1, "floor").y).epsilon(1e-6));
      // Weights are absolute: relighting the relit solution at 1, 1 gives the solve back.
      CHECK(relative_difference(relit.relight({rad::Rgb(1.0f), rad::Rgb(1.0f)}).radiosity(), sol.radiosity()) < 1e-6);
      CHECK(relit.group_radiosity("floor").y == doctest::Approx(reference.group_radiosity("floor").y).epsilon(1e-4));
    }
    // A colour weight tints: doubling the ceiling light's red only.
    const rad::Solution tinted = sol.relight({rad::Rgb(2.0f, 1.0f, 1.0f), rad::Rgb(1.0f)});
    const rad::Rgb ceiling_only = sol.light_groups()[0].radiosity[sol.hierarchy().patches().front().root];
    const rad::Rgb base = sol.radiosity()[sol.hierarchy().patches().front().root];
    const rad::Rgb now = tinted.radiosity()[sol.hierarchy().patches().front().root];
    CHECK(now.x == doctest::Approx(base.x + ceiling_only.x).epsilon(1e-5));
    CHECK(now.y == doctest::Approx(base.y).epsilon(1e-5));
  }

  TEST_CASE("light groups: lights join them - a point light in the lamp group and a bulb of its own add up and switch off") {
    // The Cornell box's light, a point light in the group "light" (it joins the ceiling lamp's
    // group) and a bulb of its own, added last so that the other light keeps its index (and so
    // its random stream) in the scene without the bulb.
    auto scene_with = [](bool point_on) {
      rad::Scene scene = rad::cornell_box();
      rad::Light second;
      second.type = rad::LightType::point;
      second.name = "second";
      second.light_group = "light";
      second.intensity = 1e4f;
      second.color = rad::Rgb(0.2f, 0.4f, 1.0f);
      second.position = {400.0f, 200.0f, 300.0f};
      scene.add_light(second);
      if (point_on) {
        rad::Light bulb;
        bulb.type = rad::LightType::point;
        bulb.name = "bulb";
        bulb.intensity = 2e4f;
        bulb.position = {150.0f, 300.0f, 250.0f};
        scene.add_light(bulb);
      }
      return scene;
    };
    const rad::Scene scene = scene_with(true);
    const rad::Solution sol = rad::solve(scene, options(rad::SolverMethod::gauss_seidel));
    REQUIRE(sol.light_groups().size() == 2);
    CHECK(sol.light_groups()[0].name == "light");
    CHECK(sol.light_groups()[1].name == "bulb");
    CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::radiosity), sol.radiosity()) < 1e-4);
    CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::direct_irradiance),
                              sol.direct_irradiance()) < 1e-4);
    // The bulb switched off equals the scene without it (lights do not change the form factors).
    rad::SolveOptions plain = options(rad::SolverMethod::gauss_seidel);
    plain.separate_light_groups = false;
    const rad::Solution without = rad::solve(scene_with(false), plain);
    const rad::Solution off = sol.relight({rad::Rgb(1.0f), rad::Rgb(0.0f)});
    CHECK(relative_difference(off.radiosity(), without.radiosity()) < 1e-4);
    CHECK(relative_difference(off.irradiance(), without.irradiance()) < 1e-4);
  }

  TEST_CASE("light groups: the stats JSON gives each light group's share of each group") {
    const rad::Scene scene = two_lamps();
    const rad::Solution sol = rad::solve(scene, options(rad::SolverMethod::gauss_seidel));
    const std::filesystem::path path = std::filesystem::path(RADIOSITY_TEST_TMP) / "light_groups_stats.json";
    rad::write_stats_json(sol, path);
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(path));
    REQUIRE(j.contains("light_groups"));
    CHECK(j["light_groups"].size() == 2);
    double floor_green = 0.0;
    for (const char* lg : {"light", "wall_lamp"}) floor_green += j["light_groups"][lg]["groups"]["floor"]["radiosity"][1].get<double>();
    CHECK(floor_green == doctest::Approx(j["groups"]["floor"]["radiosity"][1].get<double>()).epsilon(1e-4));
    CHECK(j["light_groups"]["wall_lamp"]["groups"]["floor"]["area"] == j["groups"]["floor"]["area"]);
  }

  TEST_CASE("light groups: adaptive subdivision refines once and the groups share its hierarchy") {
    const rad::Scene scene = two_lamps();
    rad::SolveOptions o = options(rad::SolverMethod::gauss_seidel);
    o.adaptive.enabled = true;
    o.adaptive.max_passes = 2;
    const rad::Solution sol = rad::solve(scene, o);
    CHECK(sol.report().refined_elements > 0);
    REQUIRE(sol.light_groups().size() == 2);
    CHECK(sol.light_groups()[0].radiosity.size() == sol.hierarchy().elements().size());
    CHECK(relative_difference(sum_of(sol.light_groups(), &rad::LightGroupSolution::radiosity), sol.radiosity()) < 1e-4);
  }

  TEST_CASE("light groups: none without the option and relight errors name the problem") {
    rad::SolveOptions o = options(rad::SolverMethod::gauss_seidel);
    o.separate_light_groups = false;
    const rad::Solution plain = rad::solve(rad::cornell_box(), o);
    CHECK(plain.light_groups().empty());
    CHECK_THROWS_WITH_AS(plain.relight({rad::Rgb(1.0f)}),
                         doctest::Contains("1 weights for 0 light groups"), rad::Error);
    o.separate_light_groups = true;
    const rad::Solution sol = rad::solve(rad::cornell_box(), o);
    REQUIRE(sol.light_groups().size() == 1);
    CHECK_THROWS_WITH_AS(sol.relight({rad::Rgb(NAN)}), doctest::Contains("'light' is not finite"), rad::Error);
    rad::Solution copy = sol.relight({rad::Rgb(1.0f)});
    CHECK(copy.light_group_weights() == std::vector<rad::Rgb>{rad::Rgb(1.0f)});
    std::vector<rad::LightGroupSolution> bad = copy.light_groups();
    bad[0].irradiance.pop_back();
    CHECK_THROWS_WITH_AS(copy.set_light_groups(bad), doctest::Contains("irradiance values for"), rad::Error);
  }
}
