// Solution::irradiance(): the light arriving at each element before its reflectance. Checked
// against the closed form on a black floor under a lamp (where (B - E) / rho is undefined),
// against B = E + rho H where rho > 0, and against the absorbed power of the energy balance.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

TEST_SUITE("solver") {
  TEST_CASE("irradiance: a black floor under a lamp receives E times the exact element-to-lamp factor within 0.5 %") {
    rad::Scene scene;
    rad::Material black, lamp;
    black.reflectance = rad::Rgb(0.0f);
    lamp.reflectance = rad::Rgb(0.0f);
    lamp.emission = rad::Rgb(10.0f, 5.0f, 2.0f);
    const rad::MaterialId mb = scene.add_material(black), ml = scene.add_material(lamp);
    rad::add_quad(scene, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, mb, "floor");  // facing +y
    const glm::vec3 lamp_corners[] = {{0.4f, 0.5f, 0.4f}, {0.6f, 0.5f, 0.4f}, {0.6f, 0.5f, 0.6f}, {0.4f, 0.5f, 0.6f}};
    rad::add_quad(scene, lamp_corners[0], {0.2f, 0, 0}, {0, 0, 0.2f}, ml, "lamp");  // facing -y
    rad::SolveOptions o;
    o.form_factors.method = rad::FormFactorMethod::ray_cast;
    o.mesh.max_patch_area = 1.0f / 16.0f;
    o.mesh.max_element_area = 1.0f / 64.0f;
    const rad::Solution sol = rad::solve(scene, o);
    const rad::PatchHierarchy& h = sol.hierarchy();
    REQUIRE(sol.irradiance().size() == h.elements().size());
    std::size_t checked = 0;
    for (std::uint32_t e : h.leaves()) {
      const rad::Element& el = h.element(e);
      if (h.patches()[el.patch].group != 0) continue;  // the floor's leaves
      // The element's mean point factor to the lamp, by an 8 x 8 midpoint rule over the element.
      double F = 0.0;
      constexpr int kN = 8;
      for (int i = 0; i < kN; ++i)
        for (int k = 0; k < kN; ++k) {
          const glm::vec3 x = h.sample_point(e, glm::vec2((i + 0.5f) / kN, (k + 0.5f) / kN));
          F += rad::point_to_polygon_factor(x, glm::vec3(0, 1, 0), lamp_corners, 4);
        }
      F /= kN * kN;
      const rad::Rgb H = sol.irradiance()[e];
      for (int c = 0; c < 3; ++c) CHECK(H[c] == doctest::Approx(F * lamp.emission[c]).epsilon(5e-3));
      // Nothing reflects: all of it came straight from the lamp.
      for (int c = 0; c < 3; ++c) CHECK(sol.direct_irradiance()[e][c] == doctest::Approx(H[c]).epsilon(1e-6));
      CHECK(sol.radiosity()[e] == rad::Rgb(0.0f));  // black: it reflects nothing of it
      ++checked;
    }
    CHECK(checked == 64);
  }

  TEST_CASE("irradiance: B = E + rho H within the solver's tolerance and the absorbed power is sum A (1 - rho) H, for every method") {
    const rad::Scene scene = rad::cornell_box();
    for (rad::SolverMethod method :
         {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::SolveOptions o;
      o.method = method;
      o.mesh.max_patch_area = 20000.0f;
      o.adaptive.enabled = true;  // refined leaves get their irradiance too
      // The matrix methods' H gathers the final B, one half-sweep past the B it made: the two
      // agree to the residual.
      o.tolerance = 1e-6;
      const rad::Solution sol = rad::solve(scene, o);
      const rad::PatchHierarchy& h = sol.hierarchy();
      REQUIRE(sol.irradiance().size() == h.elements().size());
      double absorbed = 0.0;
      for (std::uint32_t e : h.leaves()) {
        const rad::Material& m = scene.material(h.patches()[h.element(e).patch].material);
        const rad::Rgb& H = sol.irradiance()[e];
        const rad::Rgb& B = sol.radiosity()[e];
        for (int c = 0; c < 3; ++c) {
          CHECK(H[c] >= 0.0f);
          CHECK(B[c] == doctest::Approx(m.emission[c] + m.reflectance[c] * H[c]).epsilon(1e-4));
        }
        // H is the irradiance of the element's open part (Solution::exposure(): the floor
        // around the blocks is partly buried).
        const double open = sol.exposure().empty() ? 1.0 : sol.exposure()[e];
        absorbed += h.element(e).area * open * (1.0 - m.reflectance.x) * H.x;
      }
      CHECK(absorbed == doctest::Approx(sol.report().absorbed_power.x).epsilon(1e-4));
      // An inner node holds the mean of its children weighted by their open area (area x
      // exposure), and its exposure is their area-weighted mean.
      auto exposure = [&](std::uint32_t e) { return sol.exposure().empty() ? 1.0f : sol.exposure()[e]; };
      for (std::uint32_t p = 0; p < h.patches().size(); ++p) {
        const rad::Element& root = h.element(h.patches()[p].root);
        if (root.is_leaf()) continue;
        double sum = 0.0, open = 0.0;
        for (std::uint32_t c = 0; c < 4; ++c) {
          const double w = static_cast<double>(h.element(root.first_child + c).area) * exposure(root.first_child + c);
          sum += w * sol.irradiance()[root.first_child + c].x;
          open += w;
        }
        REQUIRE(open > 0.0);
        CHECK(sol.irradiance()[h.patches()[p].root].x == doctest::Approx(sum / open).epsilon(1e-4));
        CHECK(exposure(h.patches()[p].root) == doctest::Approx(open / root.area).epsilon(1e-5));
      }
    }
  }

  TEST_CASE("direct irradiance: what the scene with every reflectance 0 receives, and at most the irradiance, for every method") {
    const rad::Scene scene = rad::cornell_box();
    // The same polygons with black materials that keep their emission: only direct light.
    rad::Scene black;
    for (const rad::Material& m : scene.materials()) {
      rad::Material b = m;
      b.reflectance = rad::Rgb(0.0f);
      black.add_material(b);
    }
    for (const rad::Polygon& p : scene.polygons())
      black.add_polygon(p.vertices, p.material, scene.groups()[p.group]);
    REQUIRE(black.polygons().size() == scene.polygons().size());
    for (rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      rad::SolveOptions o;
      o.method = method;
      o.form_factors.method = rad::FormFactorMethod::ray_cast;  // the same factors for both scenes
      o.mesh.max_patch_area = 20000.0f;
      o.tolerance = 1e-6;
      const rad::Solution lit = rad::solve(scene, o), direct_only = rad::solve(black, o);
      REQUIRE(lit.direct_irradiance().size() == lit.hierarchy().elements().size());
      double direct = 0.0, total = 0.0;
      for (std::uint32_t e : lit.hierarchy().leaves()) {
        const rad::Rgb& Hd = lit.direct_irradiance()[e];
        for (int c = 0; c < 3; ++c) {
          CHECK(Hd[c] == doctest::Approx(direct_only.irradiance()[e][c]).epsilon(1e-4));
          CHECK(Hd[c] <= lit.irradiance()[e][c] * (1.0f + 1e-5f) + 1e-6f);
        }
        direct += lit.hierarchy().element(e).area * Hd.x;
        total += lit.hierarchy().element(e).area * lit.irradiance()[e].x;
      }
      // In the closed-ish Cornell box the walls reflect a good share: indirect light is a
      // substantial part of the total (a direct part equal to the total would mean no bounce).
      CHECK(direct < 0.8 * total);
      CHECK(direct > 0.3 * total);
    }
  }
}
