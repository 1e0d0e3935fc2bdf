// SolverMethod::hierarchical (issue #15, docs/HIERARCHICAL.md): closed forms through the link
// hierarchy at several epsilons, the furnace, energy balance, agreement with Gauss-Seidel,
// thread determinism and cancel.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "city.hpp"
#include "support/build.hpp"
#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

rad::SolveOptions hierarchical(float epsilon) {
  rad::SolveOptions o;
  o.method = rad::SolverMethod::hierarchical;
  o.hierarchical.epsilon = epsilon;
  o.tolerance = 1e-6;
  return o;
}

/// The options of the closed rooms' comparisons: `method` (hierarchical at epsilon 0.05) to a
/// tolerance of 1e-4, so that what the solvers' answers differ by is not the sweeps'.
rad::SolveOptions closed_room_options(rad::SolverMethod method) {
  rad::SolveOptions o = hierarchical(0.05f);
  o.method = method;
  o.tolerance = 1e-4f;
  return o;
}

/// The power a solution's surfaces absorb over the power its emitters send (green channel).
double absorbed_share(const rad::Solution& s) {
  return static_cast<double>(s.report().absorbed_power.y) / s.report().emitted_power.y;
}

/// A closed 4 x 3 x 4 room of reflectance 0.9 (test::closed_box(), its walls' groups "x0" ..
/// "z1") with a one-sided 1 m^2 lamp (E = 5, rho 0.5) facing down `gap` under its ceiling.
rad::Scene room_with_lamp(float gap) {
  rad::Material wall, lamp;
  wall.name = "wall";
  wall.reflectance = rad::Rgb(0.9f);
  lamp.name = "lamp";
  lamp.reflectance = rad::Rgb(0.5f);
  lamp.emission = rad::Rgb(5.0f);
  rad::Scene scene = test::closed_box(wall, glm::vec3(4.0f, 3.0f, 4.0f));
  rad::add_quad(scene, {1.5f, 3.0f - gap, 1.5f}, {1, 0, 0}, {0, 0, 1}, scene.add_material(lamp), "lamp");
  REQUIRE(scene.polygons().back().normal.y < -0.99f);
  return scene;
}

/// The power room_with_lamp()'s walls send (green channel), W.
double room_power(const rad::Solution& s) {
  double power = 0.0;
  for (const char* g : {"x0", "x1", "y0", "y1", "z0", "z1"}) power += s.group_radiosity(g).y * s.group_area(g);
  return power;
}

/// A closed unit box whose walls all emit `emission` and reflect `reflectance` (the furnace).
rad::Scene furnace(const rad::Rgb& emission, const rad::Rgb& reflectance) {
  rad::Material m;
  m.name = "furnace";
  m.emission = emission;
  m.reflectance = reflectance;
  return test::closed_box(m);
}

/// Two unit squares: an emitter (E = 1, rho = 0) at z = 1 facing down and a receiver at z = 0
/// facing up (rho 0.5), either parallel and opposite or, with `perpendicular`, the emitter
/// standing on the receiver's edge x = 0 (x = 0 plane, facing +x).
rad::Scene plates(bool perpendicular) {
  rad::Scene scene;
  rad::Material lamp, floor;
  lamp.name = "lamp";
  lamp.emission = rad::Rgb(1.0f);
  lamp.reflectance = rad::Rgb(0.0f);
  floor.name = "floor";
  floor.reflectance = rad::Rgb(0.5f);
  const rad::MaterialId L = scene.add_material(lamp), F = scene.add_material(floor);
  scene.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, F, "receiver");
  if (perpendicular)
    scene.add_polygon({{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, L, "emitter");
  else
    scene.add_polygon({{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, L, "emitter");
  return scene;
}

/// The mean of f(x) over a leaf element (a parallelogram) by a 16 x 16 midpoint rule.
template <typename F>
double leaf_mean(const rad::PatchHierarchy& h, std::uint32_t leaf, const F& f) {
  const rad::Element& e = h.element(leaf);
  const glm::vec3 c0 = h.vertices()[e.corners[0]], c1 = h.vertices()[e.corners[1]], c3 = h.vertices()[e.corners[3]];
  double sum = 0.0;
  constexpr int n = 16;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec2 uv((static_cast<float>(i) + 0.5f) / n, (static_cast<float>(j) + 0.5f) / n);
      sum += f(c0 + uv.x * (c1 - c0) + uv.y * (c3 - c0));
    }
  return sum / (n * n);
}

/// The exact mean irradiance over a receiver leaf from the emitter polygon (E = 1): the
/// point-to-polygon closed form integrated over the leaf (leaf_mean()).
double exact_leaf_irradiance(const rad::PatchHierarchy& h, std::uint32_t leaf, const rad::Scene& scene) {
  const rad::Polygon& emitter = scene.polygons()[1];
  return leaf_mean(h, leaf, [&](const glm::vec3& x) {
    return rad::point_to_polygon_factor(x, glm::vec3(0, 0, 1), emitter.vertices.data(),
                                        static_cast<int>(emitter.vertices.size()));
  });
}

/// RMS over the receiver's leaves (group 0) of `error(H, exact)` for each leaf's irradiance H
/// against `exact(leaf)`, and the relative error of the receiver's mean, for `scene` solved at
/// `epsilon` with patches of `patch_area` and 16 x 16 leaves per unit square.
struct PlateError {
  double rms = 0.0, mean = 0.0;
  std::size_t links = 0, leaves = 0;
};
template <typename Exact, typename Error>
PlateError receiver_error(const rad::Scene& scene, float epsilon, float patch_area, const Exact& exact, const Error& error) {
  rad::SolveOptions o = hierarchical(epsilon);
  o.mesh.max_patch_area = patch_area;
  o.mesh.max_element_area = 1.0f / 256.0f;  // 16 x 16 leaves per plate
  const rad::Solution sol = rad::solve(scene, o);
  const rad::PatchHierarchy& h = sol.hierarchy();
  double sq = 0.0, got = 0.0, want = 0.0;
  std::size_t n = 0;
  for (std::uint32_t leaf : h.leaves()) {
    if (scene.polygons()[h.patches()[h.element(leaf).patch].polygon].group != 0) continue;
    const double E = exact(h, leaf), H = sol.irradiance()[leaf].x;
    sq += error(H, E) * error(H, E);
    got += H * h.element(leaf).area;
    want += E * h.element(leaf).area;
    ++n;
  }
  return {std::sqrt(sq / static_cast<double>(n)), got / want - 1.0, sol.report().link_count, n};
}
PlateError plate_error(bool perpendicular, float epsilon, float patch_area = 0.25f) {
  const rad::Scene scene = plates(perpendicular);
  return receiver_error(
      scene, epsilon, patch_area,
      [&](const rad::PatchHierarchy& h, std::uint32_t leaf) { return exact_leaf_irradiance(h, leaf, scene); },
      [](double H, double exact) { return H / exact - 1.0; });
}

/// plates(false) with a black strip between them (x in [0.4, 0.6] at z = 0.5, longer than the
/// plates in y), which hides from a receiver point x0 the band x in [0.8 - x0, 1.2 - x0] of
/// the emitter, over its whole width.
rad::Scene plates_with_strip() {
  rad::Scene scene = plates(false);
  rad::Material black;
  black.name = "black";
  black.reflectance = rad::Rgb(0.0f);
  scene.add_polygon({{0.4f, -1, 0.5f}, {0.4f, 2, 0.5f}, {0.6f, 2, 0.5f}, {0.6f, -1, 0.5f}}, scene.add_material(black),
                    "strip");
  return scene;
}

/// The exact mean irradiance over a receiver leaf of plates_with_strip() (E = 1): the
/// point-to-polygon closed form of the emitter's visible parts (up to two rectangles),
/// integrated over the leaf by a 16 x 16 midpoint rule.
double exact_shadowed_irradiance(const rad::PatchHierarchy& h, std::uint32_t leaf) {
  auto band = [](const glm::vec3& x, float a, float b) {
    if (!(b > a)) return 0.0;
    const std::array<glm::vec3, 4> q = {glm::vec3(a, 0, 1), glm::vec3(a, 1, 1), glm::vec3(b, 1, 1), glm::vec3(b, 0, 1)};
    return rad::point_to_polygon_factor(x, glm::vec3(0, 0, 1), q.data(), 4);
  };
  return leaf_mean(h, leaf, [&](const glm::vec3& x) {
    return band(x, 0.0f, std::min(1.0f, 0.8f - x.x)) + band(x, std::max(0.0f, 1.2f - x.x), 1.0f);
  });
}

}  // namespace

double relative(double a, double b) { return std::abs(a / b - 1.0); }

/// Gauss-Seidel over Monte Carlo rows at 16384 rays (their noise on a group mean is below
/// 0.1 %), patches = elements of `element_area`, to tolerance 1e-5: the reference of the
/// agreement tests.
rad::Solution gauss_seidel_reference(const rad::Scene& scene, float element_area) {
  rad::SolveOptions o;
  o.form_factors.method = rad::FormFactorMethod::monte_carlo;
  o.form_factors.hemisphere_rays = 16384;
  o.tolerance = 1e-5;
  o.mesh.max_patch_area = o.mesh.max_element_area = element_area;
  return rad::solve(scene, o);
}

/// The hierarchical solve at `epsilon` on gauss_seidel_reference()'s mesh, converged.
rad::Solution hierarchical_on(const rad::Scene& scene, float element_area, float epsilon, std::uint64_t seed = 1) {
  rad::SolveOptions h = hierarchical(epsilon);
  h.seed = seed;
  h.tolerance = 1e-5;
  h.mesh.max_patch_area = h.mesh.max_element_area = element_area;
  rad::Solution out = rad::solve(scene, h);
  REQUIRE(out.status() == rad::SolveStatus::converged);
  return out;
}

/// Every named group's channels, averaged over `solutions` (solves that differ only in their
/// seed), within `tolerance` (relative) of the reference's, and the share of the emitted power
/// that escapes within `escaped` (absolute). Over several seeds the check measures the solver's
/// bias rather than one random stream's luck: on the Cornell box at 100 mm elements a single
/// seed's group means scatter by about 1 % (session 20, six seeds).
void check_agreement(const rad::Scene& scene, const rad::Solution& reference,
                     const std::vector<const rad::Solution*>& solutions, double tolerance, double escaped) {
  REQUIRE(!solutions.empty());
  const double n = static_cast<double>(solutions.size());
  for (const std::string& g : scene.groups()) {
    if (g.empty()) continue;
    CAPTURE(g);
    const rad::Rgb a = reference.group_radiosity(g);
    glm::dvec3 b(0.0);
    for (const rad::Solution* s : solutions) b += glm::dvec3(s->group_radiosity(g)) / n;
    for (int c = 0; c < 3; ++c) CHECK(relative(b[c], a[c]) < tolerance);
  }
  const rad::SolveReport& ra = reference.report();
  double share = 0.0;
  for (const rad::Solution* s : solutions) share += s->report().escaped_power.y / s->report().emitted_power.y / n;
  CHECK(std::abs(share - ra.escaped_power.y / ra.emitted_power.y) < escaped);
}
void check_agreement(const rad::Scene& scene, const rad::Solution& reference, const std::vector<rad::Solution>& solutions,
                     double tolerance, double escaped) {
  std::vector<const rad::Solution*> all;
  for (const rad::Solution& s : solutions) all.push_back(&s);
  check_agreement(scene, reference, all, tolerance, escaped);
}
void check_agreement(const rad::Scene& scene, const rad::Solution& reference, const rad::Solution& solution,
                     double tolerance, double escaped) {
  check_agreement(scene, reference, std::vector<const rad::Solution*>{&solution}, tolerance, escaped);
}


TEST_SUITE("solver") {
  TEST_CASE("hierarchical: parallel and perpendicular plates match Howell C-11 and C-14, closer as epsilon shrinks") {
    // 16 x 16 leaves per plate; each receiver leaf's irradiance against the exact mean over
    // it of the point-to-polygon closed form (whose integral over the plate is Howell's
    // factor). The leaves take the links into their ancestors by the final gather's kernel push
    // (docs/HIERARCHICAL.md, "The final gather"). Measured RMS over the leaves at epsilon 0.5,
    // 0.1, 0.02, 0.004: 0.0080, 0.0073, 0.0034, 0.0025 % (parallel) and 0.025, 0.015, 0.0056,
    // 0.0014 % (perpendicular), plate means within 0.006 %; with the sweeps' linear push
    // (before session 45) 1.17, 0.67, 0.15, 0.085 % and 1.66, 0.96, 0.35, 0.14 %; with the push
    // uniform within each node (before session 22) 7.6, 6.2, 3.1, 2.2 % and 12.6, 9.8, 5.1,
    // 2.0 %. Held to about twice the measured figures.
    const std::array<float, 4> epsilons = {0.5f, 0.1f, 0.02f, 0.004f};
    const std::array<std::array<double, 4>, 2> rms_at_most = {{{2e-4, 1.5e-4, 7e-5, 4e-5}, {5e-4, 3e-4, 1.2e-4, 3e-5}}};
    for (bool perpendicular : {false, true}) {
      CAPTURE(perpendicular);
      double previous = 1.0;
      for (std::size_t k = 0; k < epsilons.size(); ++k) {
        const float eps = epsilons[k];
        CAPTURE(eps);
        const PlateError e = plate_error(perpendicular, eps);
        MESSAGE("plates, perpendicular " << perpendicular << ", epsilon " << eps << ": leaf RMS " << e.rms << ", mean "
                                         << e.mean << ", links " << e.links);
        CHECK(e.rms <= previous);
        CHECK(e.rms < rms_at_most[perpendicular ? 1 : 0][k]);
        CHECK(std::abs(e.mean) < 0.005);
        previous = e.rms;
      }
    }
    // The plate means are Howell's factors (the exact leaf means above integrate to them).
    const double F[2] = {test::parallel_rectangles(1, 1, 1), test::perpendicular_rectangles(1, 1, 1)};
    for (int k = 0; k < 2; ++k) {
      const rad::Scene scene = plates(k == 1);
      rad::SolveOptions o = hierarchical(0.004f);
      o.mesh.max_patch_area = 0.25f;
      o.mesh.max_element_area = 1.0f / 256.0f;
      const rad::Solution sol = rad::solve(scene, o);
      const rad::Rgb b = sol.group_radiosity("receiver");
      CHECK(relative(b.x, 0.5 * F[k]) < 0.005);
    }
  }

  TEST_CASE("hierarchical: plates of one patch per leaf - a cluster tree above them - match the closed form per leaf") {
    // As the test above, with each leaf its own patch: the links join clusters of patches, and
    // the linear push within a cluster takes the gradient from the moments' directions
    // (directional_q()) for the sweeps, and the final gather evaluates the kernel at each leaf.
    // Measured leaf RMS at epsilon 0.5, 0.1, 0.02, 0.004: 0.12, 0.12, 0.0045, 0.0003 %
    // (parallel) and 0.16, 0.071, 0.0069, 0.0007 % (perpendicular), most of it the plate's mean
    // (the links' totals); with the linear push alone (before session 45) 0.85, 0.80, 0.34,
    // 0.16 % and 1.92, 1.50, 1.00, 0.42 %; with the clusters' directions left out of the
    // gradient (before session 23: a wall cluster's light taken as falling off only as
    // 1 / d^2, so a floor beside it got it alike up to the contact, the first row of leaves 6 %
    // too bright) 2.88, 2.90, 2.11, 1.12 % and 4.29, 3.50, 2.11, 0.83 %. Held to about twice
    // the new figures.
    const std::array<float, 4> epsilons = {0.5f, 0.1f, 0.02f, 0.004f};
    const std::array<std::array<double, 4>, 2> rms_at_most = {{{0.0025, 0.0025, 1e-4, 1e-5}, {0.0032, 0.0015, 1.4e-4, 1.5e-5}}};
    for (bool perpendicular : {false, true}) {
      CAPTURE(perpendicular);
      for (std::size_t k = 0; k < epsilons.size(); ++k) {
        const float eps = epsilons[k];
        CAPTURE(eps);
        const PlateError e = plate_error(perpendicular, eps, 1.0f / 256.0f);
        MESSAGE("one patch per leaf, perpendicular " << perpendicular << ", epsilon " << eps << ": leaf RMS " << e.rms
                                                      << ", mean " << e.mean << ", links " << e.links);
        CHECK(e.rms < rms_at_most[perpendicular ? 1 : 0][k]);
        CHECK(std::abs(e.mean) < 0.005);
      }
    }
  }

  TEST_CASE("hierarchical: plates with a strip between them match the closed form of the emitter's visible part per leaf") {
    // plates_with_strip(): 16 x 16 receiver leaves, under 4 patches or one patch each; each
    // leaf's irradiance against the exact mean over it of the emitter's visible part, the
    // errors in units of the unshadowed plate's mean irradiance (about 0.2). Measured leaf RMS
    // at epsilon 0.5, 0.1, 0.02 (session 46, the final gather's visibility rays per leaf,
    // kLeafRayShare): 1.9, 1.6, 1.1 % (4 patches) and 1.8, 0.79, 0.30 % (a patch per leaf);
    // before them (each link's one visible fraction spread over its leaves) 3.4, 3.3, 1.4 % and
    // 2.1, 0.84, 0.30 %; with one ray per leaf for every link 8.5, 5.6, 1.8 % (a binary ray is
    // noise where one link is much of a leaf's light). Held to about 1.25 times the figures.
    const rad::Scene scene = plates_with_strip();
    const std::array<float, 3> epsilons = {0.5f, 0.1f, 0.02f};
    const std::array<float, 2> patch_areas = {0.25f, 1.0f / 256.0f};
    const std::array<std::array<double, 3>, 2> rms_at_most = {{{0.024, 0.020, 0.014}, {0.023, 0.0099, 0.0038}}};
    for (std::size_t a = 0; a < patch_areas.size(); ++a) {
      CAPTURE(patch_areas[a]);
      for (std::size_t k = 0; k < epsilons.size(); ++k) {
        CAPTURE(epsilons[k]);
        const PlateError e = receiver_error(scene, epsilons[k], patch_areas[a], exact_shadowed_irradiance,
                                            [](double H, double exact) { return (H - exact) / 0.25; });
        REQUIRE(e.leaves == 256);
        MESSAGE("strip, patch area " << patch_areas[a] << ", epsilon " << epsilons[k] << ": leaf RMS " << e.rms
                                     << ", mean " << e.mean << ", links " << e.links);
        CHECK(e.rms < rms_at_most[a][k]);
        CHECK(std::abs(e.mean) < 0.005);
      }
    }
  }

  TEST_CASE("hierarchical: the furnace gives B = E / (1 - rho) and a closed box absorbs what it emits") {
    rad::Material m;
    m.name = "furnace";
    m.emission = rad::Rgb(1.0f, 2.0f, 0.5f);
    m.reflectance = rad::Rgb(0.5f, 0.8f, 0.2f);
    const rad::Scene scene = test::closed_box(m);
    const rad::Rgb expected = m.emission / (rad::Rgb(1.0f) - m.reflectance);
    // A link's error is a share of its transport, and rho = 0.8 multiplies the rows' error by
    // up to 1 / (1 - 0.8) = 5. Measured at epsilon 0.05 / 0.004: worst leaf 8.2 % / 0.50 %,
    // mean 1.05 % / 0.30 %, absorbed / emitted 1.013 / 1.0038 (green channel).
    struct Case {
      float eps;
      double worst, mean, balance;
    };
    for (const Case& k : {Case{0.05f, 0.12, 0.012, 0.015}, Case{0.004f, 0.01, 0.005, 0.006}}) {
      CAPTURE(k.eps);
      rad::SolveOptions o = hierarchical(k.eps);
      o.mesh.max_patch_area = 0.26f;
      o.mesh.max_element_area = 0.07f / 4;
      const rad::Solution sol = rad::solve(scene, o);
      REQUIRE(sol.status() == rad::SolveStatus::converged);
      for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        double worst = 0.0, mean = 0.0;
        for (std::uint32_t e : sol.hierarchy().leaves()) {
          worst = std::max(worst, relative(sol.radiosity()[e][c], expected[c]));
          mean += sol.radiosity()[e][c] / expected[c] - 1.0;
        }
        mean /= static_cast<double>(sol.hierarchy().leaves().size());
        CHECK(worst < k.worst);
        CHECK(std::abs(mean) < k.mean);
        const rad::SolveReport& r = sol.report();
        CHECK(relative(r.absorbed_power[c], r.emitted_power[c]) < k.balance);
      }
    }
  }

  TEST_CASE("hierarchical: in a black closed box every leaf's irradiance from B = 1 walls is 1 (the rows sum to 1)") {
    // rho = 0: H is the sum of the links' factors over everything the leaf sees, which is the
    // whole box. Measured: worst leaf 9.4 % / 0.24 %, mean 0.11 % / 0.08 % at epsilon 0.1 / 0.004.
    rad::Material m;
    m.emission = rad::Rgb(1.0f);
    m.reflectance = rad::Rgb(0.0f);
    const rad::Scene scene = test::closed_box(m);
    for (float eps : {0.1f, 0.004f}) {
      CAPTURE(eps);
      rad::SolveOptions o = hierarchical(eps);
      o.mesh.max_patch_area = 0.26f;
      o.mesh.max_element_area = 0.07f / 4;
      const rad::Solution sol = rad::solve(scene, o);
      double worst = 0.0, mean = 0.0;
      for (std::uint32_t e : sol.hierarchy().leaves()) {
        worst = std::max(worst, std::abs(sol.irradiance()[e].y - 1.0));
        mean += sol.irradiance()[e].y - 1.0;
      }
      mean /= static_cast<double>(sol.hierarchy().leaves().size());
      CHECK(worst < (eps > 0.01f ? 0.12 : 0.005));
      CHECK(std::abs(mean) < 0.002);
    }
  }

  TEST_CASE("hierarchical: the Cornell box agrees with Gauss-Seidel over element-to-element factors"
            * test::not_under_thread_sanitizer) {
    // The reference's targets are the elements themselves (patches = elements), as the links'
    // finest ends are: with element-to-patch factors a patch half hidden under a block sends its
    // mean radiosity from its visible half too, an error of the reference of up to 40 % on the
    // leaves next to the blocks (measured). The group means averaged over eight seeds, which
    // measures the bias, and each seed's alone, which measures the visibility rays' noise.
    // Measured worst group and channel at 100 mm elements, session 28 (links weighed by the
    // power they carry, kLinkPowerShare: cluster links refined, strong links' rays): the mean
    // 0.35 % at epsilon 0.05 and at 0.005, a single seed 0.67 % and 0.69 % (the floor). Before
    // session 28, over four seeds: 0.69 % and 0.31 % (session 24, the linear pull and the
    // centroid rule's curvature correction for far element pairs; with the pull alone 0.91 % and
    // 0.50 %; session 22, after the oracle near grazing and the linear push, 0.91 % and 0.86 %;
    // before them 1.04 % and 0.97 %), and a single seed's floor up to 2.6 % off (seed 7: a few
    // strong links of the lamp into floor elements in a block's penumbra, 12 rays each). The
    // mean is held to the goal, 0.5 % (docs/HIERARCHICAL.md, "Where it stands"), a
    // single seed to 1 %.
    const rad::Scene scene = rad::cornell_box();
    const rad::Solution gs = gauss_seidel_reference(scene, 10000.0f);  // 100 mm
    CHECK(gs.report().gather_rays == 0);
    CHECK(gs.report().link_rays == 0);
    for (float eps : {0.05f, 0.005f}) {
      CAPTURE(eps);
      std::vector<rad::Solution> seeds;
      for (std::uint64_t seed = 1; seed <= 8; ++seed) {
        CAPTURE(seed);
        const rad::Solution& hr = seeds.emplace_back(hierarchical_on(scene, 10000.0f, eps, seed));
        CHECK(hr.report().link_count > 0);
        CHECK(hr.report().link_pairs_examined >= hr.report().link_count);  // every link was a pair looked at
        CHECK(hr.report().link_rays >= 2 * hr.report().link_count);         // a pilot and an estimate each
        CHECK(hr.report().gather_rays > 0);  // the final gather's rays to the leaves below cluster receivers
        check_agreement(scene, gs, hr, 0.01, 0.01);
      }
      // The open front lets out about 31 % of the light in both.
      check_agreement(scene, gs, seeds, 0.005, 0.01);
    }
  }

  TEST_CASE("hierarchical: the Cornell box turned 30 degrees about y agrees with Gauss-Seidel as the upright one does"
            * test::release_only) {
    // Every wall off the axes. Receiving and sending clusters kept their moments on the axes,
    // where a tilted surface gets light from behind and sends part of its own backwards: at 50 mm
    // elements every group came out 6-15 % too bright (the back wall +13.9 %, the green wall
    // +15.3 %) and the upright box's blocks 8 % (measured, session 19). With one moment per
    // direction a cluster faces (MomentBasis), measured: worst group 0.92 % turned, 0.99 %
    // upright (the short block); with the linear pull (session 24) 0.60 % and 0.64 % (the ceiling),
    // and the centroid rule's curvature correction 0.44 % and 0.46 %; with the power share
    // (kLinkPowerShare, session 28) 0.35 % and 0.32 % (the ceiling): held to 0.5 %.
    for (const float degrees : {0.0f, 30.0f}) {
      CAPTURE(degrees);
      const rad::Scene scene = test::turned_about_y(rad::cornell_box(), degrees, glm::vec3(278.0f, 0.0f, 280.0f));
      const rad::Solution gs = gauss_seidel_reference(scene, 2500.0f);  // 50 mm
      check_agreement(scene, gs, hierarchical_on(scene, 2500.0f, 0.05f), 0.005, 0.005);
    }
  }

  TEST_CASE("hierarchical: a lamp's light on the walls beside it, seen near grazing, agrees with Gauss-Seidel"
            * test::release_only) {
    // The Cornell box with its blocks raised 50 mm and every surface but the lamp of reflectance
    // 0.001: nearly only the lamp's direct light, which the walls' tops see from just below the
    // ceiling's plane. The oracle judged a link's spread by the lamp's intensity toward the
    // receiver's centre, near grazing a small fraction of what it shows the receiver's lower
    // parts, and kept links whose transport came out 10 % low. Measured before
    // intensity_bound(), at ~1000 elements: green wall -1.45 %, back wall -0.68 % (at 4000: the
    // green wall -2.0 %, its upper third -12 %); after: 0.16 % and 0.18 %, every wall within
    // 0.21 %. (With reflectance 0.01 the threshold, which follows the scene's mean radiosity,
    // links this mesh otherwise and both pass.)
    const rad::Scene box = rad::cornell_box();
    rad::Scene scene;
    for (rad::Material m : box.materials()) {
      if (m.emission == rad::Rgb(0.0f)) m.reflectance = rad::Rgb(0.001f);
      scene.add_material(m);
    }
    for (const rad::Polygon& p : box.polygons()) {
      const std::string& group = box.groups()[p.group];
      std::vector<glm::vec3> v = p.vertices;
      if (group == "short_block" || group == "tall_block")
        for (glm::vec3& x : v) x.y += 50.0f;
      scene.add_polygon(v, p.material, group);
    }
    const float element_area = static_cast<float>(scene.total_area() / 1000.0);
    const rad::Solution gs = gauss_seidel_reference(scene, element_area);
    const rad::Solution hr = hierarchical_on(scene, element_area, 0.05f);
    for (const std::string wall : {"back_wall", "green_wall", "red_wall", "floor"}) {
      CAPTURE(wall);
      CHECK(relative(hr.group_radiosity(wall).y, gs.group_radiosity(wall).y) < 0.005);
    }
  }

  TEST_CASE("hierarchical: a wall of one polygon meshed into elements takes the light of the ground before it row by "
            "row as the exact factors give it" * test::release_only) {
    // A 20 x 10 x 20 m box of black walls, each one polygon meshed into 64 elements of 2.5 x
    // 1.25 m, standing on a 90 m ground of 2.25 m facets that emits 10 W/m^2 and reflects
    // nothing: every wall element's irradiance is 10 F(element -> ground), one gather. Ground far
    // away sees a wall at grazing and lights it about in proportion to height; that light comes
    // through the wall's element quadtree, whose linear push clamped the gradient by each
    // element's bounding sphere and passed its relative gradient down: measured (a probe with
    // 8 192 rays per element), the lowest row +4.1 %, the next -2.8 %. Since session 44 the push
    // clamps per axis of the element's box and a child inherits the gradient itself
    // (docs/HIERARCHICAL.md, "The push at a wall's foot"): within 0.3 % on every row.
    namespace cd = bench::city_detail;
    rad::Scene s;
    rad::Material glow;
    glow.reflectance = rad::Rgb(0.0f);
    glow.emission = rad::Rgb(10.0f);
    rad::Material black;
    black.reflectance = rad::Rgb(0.0f);
    const rad::MaterialId ground = s.add_material(glow), wall = s.add_material(black);
    constexpr int kCells = 40;
    constexpr float kStep = 90.0f / kCells;
    cd::add_lattice(s, kCells, kCells, [&](int i, int j) { return glm::vec3(-45.0f + kStep * j, 0.0f, -45.0f + kStep * i); },
                    ground, cd::whole("ground"));
    const glm::vec3 lo(-10.0f, 0.0f, -10.0f), hi(10.0f, 10.0f, 10.0f);
    s.add_polygon({{lo.x, 0.0f, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, 0.0f, lo.z}}, wall, "walls");
    s.add_polygon({{lo.x, 0.0f, hi.z}, {hi.x, 0.0f, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}}, wall, "walls");
    s.add_polygon({{lo.x, 0.0f, lo.z}, {lo.x, 0.0f, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}}, wall, "walls");
    s.add_polygon({{hi.x, 0.0f, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, 0.0f, hi.z}}, wall, "walls");
    s.add_polygon({{lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}}, wall, "roof");
    rad::SolveOptions o;
    o.method = rad::SolverMethod::hierarchical;
    o.mesh.max_patch_area = 400.0f;  // a wall is one patch
    o.mesh.max_element_area = kStep * kStep;
    const rad::Solution hr = rad::solve(s, o);
    // The exact factors of the same elements (the element level meshes as the solve does).
    rad::ViewFactorOptions v;
    v.level = rad::ViewFactorLevel::element;
    v.mesh = o.mesh;
    v.groups = {"walls", "ground"};
    v.form_factors.method = rad::FormFactorMethod::ray_cast;
    const rad::ViewFactorMatrix exact = rad::view_factor_matrix(s, v);
    const rad::PatchHierarchy& h = hr.hierarchy();
    auto group_of = [&](std::uint32_t element) { return s.groups()[h.patches()[h.element(element).patch].group]; };
    // Per row of the walls' elements (by height): the area-weighted mean irradiance, from the
    // solve and from the exact factors.
    const std::vector<rad::Rgb> H = hr.element_values(rad::Quantity::irradiance);
    std::array<double, 8> solved{}, expected{}, solved_area{}, expected_area{};
    auto row_of = [&](const glm::vec3& c) { return std::min<std::size_t>(7, static_cast<std::size_t>(c.y / 1.25f)); };
    for (const std::uint32_t e : h.leaves()) {
      if (group_of(e) != "walls" || h.normal(e).y != 0.0f) continue;
      const std::size_t r = row_of(h.element(e).centroid);
      solved[r] += h.element(e).area * static_cast<double>(H[e].x);
      solved_area[r] += h.element(e).area;
    }
    for (std::size_t i = 0; i < exact.rows(); ++i) {
      if (group_of(exact.ids[i]) != "walls" || h.normal(exact.ids[i]).y != 0.0f) continue;
      double f = 0.0;
      for (std::uint64_t k = exact.row_offsets[i]; k < exact.row_offsets[i + 1]; ++k)
        if (group_of(exact.ids[exact.columns[k]]) == "ground") f += static_cast<double>(exact.values[k]);
      const std::size_t r = row_of(h.element(exact.ids[i]).centroid);
      expected[r] += exact.area[i] * 10.0 * f;
      expected_area[r] += exact.area[i];
    }
    for (std::size_t r = 0; r < 8; ++r) {
      CAPTURE(r);
      REQUIRE(solved_area[r] > 0.0);
      REQUIRE(expected_area[r] == doctest::Approx(solved_area[r]));
      const double ratio = (solved[r] / solved_area[r]) / (expected[r] / expected_area[r]);
      MESSAGE("row " << r << " (" << 1.25 * static_cast<double>(r) << "-" << 1.25 * static_cast<double>(r + 1)
                     << " m): irradiance " << solved[r] / solved_area[r] << " against " << expected[r] / expected_area[r]
                     << " (" << 100.0 * (ratio - 1.0) << " %)");
      CHECK(std::fabs(ratio - 1.0) < 0.01);
    }
  }

  TEST_CASE("hierarchical: bit-identical at 1 and 2 threads") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o = hierarchical(0.05f);
    o.tolerance = 1e-4;
    o.threads = 1;
    const rad::Solution one = rad::solve(scene, o);
    o.threads = 2;
    const rad::Solution two = rad::solve(scene, o);
    REQUIRE(one.radiosity().size() == two.radiosity().size());
    CHECK(one.report().link_count == two.report().link_count);
    bool same = true;
    for (std::size_t i = 0; i < one.radiosity().size(); ++i)
      same &= one.radiosity()[i] == two.radiosity()[i] && one.irradiance()[i] == two.irradiance()[i];
    CHECK(same);
  }

  TEST_CASE("hierarchical: cancel in linking, in the sweeps or in a later linking returns a consistent estimate") {
    const rad::Scene scene = furnace(rad::Rgb(1.0f), rad::Rgb(0.5f));
    // Stops: in the first linking, in the sweeps, and in a later linking (multigridding),
    // whose links taken out for refinement must go back.
    for (int stop = 0; stop < 3; ++stop) {
      CAPTURE(stop);
      rad::SolveOptions o = hierarchical(0.05f);
      o.mesh.max_patch_area = 0.26f;
      o.mesh.max_element_area = 0.07f / 4;
      int calls = 0;
      bool swept = false;
      o.on_progress = [&](const rad::Progress& p) {
        ++calls;
        swept = swept || p.phase == rad::Phase::solving;
        if (stop == 0) return p.phase != rad::Phase::form_factors;
        if (stop == 1) return p.phase != rad::Phase::solving;
        return !(swept && p.phase == rad::Phase::form_factors);
      };
      const rad::Solution sol = rad::solve(scene, o);
      CHECK(sol.status() == rad::SolveStatus::cancelled);
      CHECK(calls > 0);
      // At least the emission, at most about the converged 2 (and finite).
      for (std::uint32_t e : sol.hierarchy().leaves()) {
        CHECK(sol.radiosity()[e].x >= 1.0f);
        CHECK(sol.radiosity()[e].x <= 2.2f);
      }
    }
  }

  TEST_CASE("hierarchical: lights, two-sided and translucent sides as the matrix solvers have them") {
    // A closed box lit by a point light inside; a translucent partition splits it; its other
    // walls are two-sided. Gauss-Seidel over ray-cast factors is the reference.
    rad::Material wall, paper;
    wall.name = "wall";
    wall.reflectance = rad::Rgb(0.5f, 0.3f, 0.7f);
    wall.two_sided = true;
    paper.name = "paper";
    paper.reflectance = rad::Rgb(0.3f);
    paper.diffuse_transmittance = rad::Rgb(0.4f);
    rad::Scene scene = test::closed_box(wall);
    const rad::MaterialId p = scene.add_material(paper);
    scene.add_polygon({{0.5f, 0, 0}, {0.5f, 1, 0}, {0.5f, 1, 1}, {0.5f, 0, 1}}, p, "paper");
    rad::Light light;
    light.intensity = 2.0f;
    light.position = {0.25f, 0.6f, 0.45f};
    scene.add_light(light);
    rad::SolveOptions o;
    o.form_factors.method = rad::FormFactorMethod::ray_cast;
    o.mesh.max_patch_area = 1.0f / 16.0f;
    o.mesh.max_element_area = 1.0f / 64.0f;
    o.tolerance = 1e-6;
    const rad::Solution gs = rad::solve(scene, o);
    o.method = rad::SolverMethod::hierarchical;
    o.hierarchical.epsilon = 0.01f;
    const rad::Solution hr = rad::solve(scene, o);
    REQUIRE(hr.status() == rad::SolveStatus::converged);
    REQUIRE(!hr.back_radiosity().empty());
    // Measured: within 1.7 % on every group, side and channel; 0.05-0.29 % of the power
    // escapes: a cluster's moments send a little of the inside's light to the outer backs of
    // two-sided walls (a link's direction is taken between the nodes' centroids).
    for (const std::string& g : scene.groups()) {
      CAPTURE(g);
      for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        CHECK(relative(hr.group_radiosity(g)[c], gs.group_radiosity(g)[c]) < 0.025);
        const double back = gs.group_back_radiosity(g)[c];
        if (back > 0.0) CHECK(relative(hr.group_back_radiosity(g)[c], back) < 0.025);
      }
    }
    // What the lights put on the sides is the same first shot; a closed box absorbs it all.
    for (int c = 0; c < 3; ++c) {
      CHECK(relative(hr.report().light_power[c], gs.report().light_power[c]) < 1e-6);
      CHECK(std::abs(hr.report().escaped_power[c]) < 0.006 * hr.report().emitted_power[c]);
    }
  }

  TEST_CASE("hierarchical: with adaptive subdivision refinement splits elements and stays within the limits") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o = hierarchical(0.02f);
    o.adaptive.enabled = true;
    o.adaptive.max_depth = 2;
    o.adaptive.max_elements = 4000;
    const rad::Solution sol = rad::solve(scene, o);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::SolveReport& r = sol.report();
    CHECK(r.refined_elements > 0);
    CHECK(r.element_count == sol.hierarchy().leaves().size());
    CHECK(r.element_count <= 4000 + 3);
    // Every new leaf got its share of the light: B = E + rho H holds on every leaf.
    for (std::uint32_t e : sol.hierarchy().leaves()) {
      const rad::Material& mat = scene.material(scene.polygons()[sol.hierarchy().patches()[sol.hierarchy().element(e).patch].polygon].material);
      CHECK(sol.radiosity()[e].x == doctest::Approx(mat.emission.x + mat.reflectance.x * sol.irradiance()[e].x).epsilon(1e-3));
    }
  }

  TEST_CASE("hierarchical: options are checked") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o = hierarchical(0.0f);
    CHECK_THROWS_AS(rad::solve(scene, o), rad::Error);
    o = hierarchical(0.05f);
    o.hierarchical.max_passes = 0;
    CHECK_THROWS_AS(rad::solve(scene, o), rad::Error);
    o = hierarchical(0.05f);
    o.form_factors.specular_depth = 1;
    CHECK_THROWS_AS(rad::solve(scene, o), rad::Error);
  }

  // Not under ThreadSanitizer (60 s there): the sweeps' and the hold's parallel loops are the
  // ones the lighter hierarchical tests run there; the Release and ASan builds run this one.
  TEST_CASE("hierarchical: links that gain energy are held to the maximum principle and converge, with a warning" *
            test::not_under_thread_sanitizer) {
    // Outward winding, Kd 1 (clamped to 0.99), a degenerate face, a box resting on the floor (its
    // bottom face on the floor: coincident surfaces, which a receiver inside the box sees twice):
    // made two-sided, a closed room of reflectance 0.99 whose links pass on more light than they
    // receive. Before the hold the sweeps diverged after 619 of them (radiosity::Error). Now they
    // converge, the report says why they were held, and the room's inside agrees with
    // Gauss-Seidel within 8 %: measured 18.243 against 18.277 (0.19 %) in session 15, 18.06
    // against 18.26 at the start of session 28, and 17.09 (-6.4 %) since its refinement of
    // cluster links by power (kLinkPowerShare: 1.5 times the links here), which moves the links
    // from gaining light to losing it; at reflectance 0.99 a loss of 0.06 % of the light a
    // bounce carries is 6 % of the radiosity. The balancing (the default, below) is what holds a
    // closed region's rows to 1: -1.4 % there (-0.8 % before session 28). The inside of the box
    // is lit only
    // through the coincident floor (Gauss-Seidel 10.2, hierarchical 30.4: the model's ambiguity,
    // which the z-fighting warning names), and every radiosity stays below the bound max E /
    // (1 - rho_max) = 3142.
    // The balancing of closed regions, on by default, removes the gain (below); the hold is
    // what remains for regions it does not reach, so it is tested with the balancing off.
    rad::Scene scene = rad::load_scene(std::string(RADIOSITY_TEST_DATA) + "/exported_room.obj");
    scene.make_two_sided();
    rad::SolveOptions unbalanced = hierarchical(0.05f);
    unbalanced.hierarchical.balance_closed_regions = false;
    const rad::Solution sol = rad::solve(scene, unbalanced);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    auto held = [](const rad::Solution& s) {
      for (const std::string& w : s.report().warnings)
        if (w.find("maximum principle") != std::string::npos) return true;
      return false;
    };
    CHECK(held(sol));
    const float bound = 31.416f / (1.0f - 0.99f) * 1.001f;
    for (const rad::Rgb& b : sol.radiosity()) CHECK(std::max({b.x, b.y, b.z}) < bound);
    for (const rad::Rgb& b : sol.back_radiosity()) CHECK(std::max({b.x, b.y, b.z}) < bound);
    // The sanitizer builds check the hold's code paths; the comparison's Gauss-Seidel solve at
    // reflectance 0.99 would double their time, and is the Release build's.
    if (test::kSanitizerBuild) return;
    rad::SolveOptions gs;
    gs.method = rad::SolverMethod::gauss_seidel;
    gs.tolerance = 1e-6;
    const rad::Solution ref = rad::solve(scene, gs);
    const double inside = sol.group_back_radiosity("room").y, expected = ref.group_back_radiosity("room").y;
    MESSAGE("inside of the room: hierarchical " << inside << ", gauss-seidel " << expected);
    CHECK(relative(inside, expected) < 0.08);
    // Balanced (the default): no gain to hold, the room's inside and the box's outside within
    // 2 % of Gauss-Seidel (measured -1.4 % and -0.8 %), the box's inside (lit only through the
    // coincident floor: the model's ambiguity) 10 % off instead of three times too bright.
    const rad::Solution balanced = rad::solve(scene, hierarchical(0.05f));
    REQUIRE(balanced.status() == rad::SolveStatus::converged);
    CHECK_FALSE(held(balanced));
    MESSAGE("balanced: room inside " << balanced.group_back_radiosity("room").y << ", box "
                                     << balanced.group_radiosity("box").y << " (gauss-seidel "
                                     << ref.group_radiosity("box").y << "), box inside "
                                     << balanced.group_back_radiosity("box").y << " ("
                                     << ref.group_back_radiosity("box").y << ")");
    CHECK(relative(balanced.group_back_radiosity("room").y, expected) < 0.02);
    CHECK(relative(balanced.group_radiosity("box").y, ref.group_radiosity("box").y) < 0.02);
    CHECK(relative(balanced.group_back_radiosity("box").y, ref.group_back_radiosity("box").y) < 0.6);
  }

  // Release only (44 s under ThreadSanitizer, 29 s under AddressSanitizer, the slowest test there
  // since session 28's power rule made the closed room's solve longer): its unbalanced solve at
  // reflectance 0.99 is what the hold test above runs in the sanitizer builds, and the
  // warning's check is a few sums.
  TEST_CASE("hierarchical: light the links lose in a closed room is reported, and only there" * test::release_only) {
    // A room as an exporter writes it (outward winding, Kd 1 clamped to 0.99), made two-sided,
    // a lamp panel 0.2 m under the ceiling: closed, so no light can leave, and rho = 0.99 turns
    // every 0.1 % the links lose or gain per bounce into about 10 % of the power. Without the
    // balancing of closed regions the links lost 8.7 % of the emitted power here (6.7 % in
    // session 15), and the solve said so; since session 22 keeps zero links for the next pass
    // ("Zero links" in docs/HIERARCHICAL.md) they gained 1.2 % instead, and since session 28's
    // refinement of cluster links by power (kLinkPowerShare) 2.5 % (the three channels together;
    // measured, held to 5 %), so the warning must stay silent, as it must for the open Cornell box
    // (31 % leaves through its front) and for Gauss-Seidel on the room. Balanced (the default),
    // the loss is under 1 % (measured -0.01 %) and the room and the crate within 5 % of
    // Gauss-Seidel (measured 0.3 % low; 3.0 % before session 28).
    auto warned = [](const rad::Solution& sol) {
      for (const std::string& w : sol.report().warnings)
        if (w.find("unaccounted for") != std::string::npos) return true;
      return false;
    };
    rad::Scene room = rad::load_scene(std::string(RADIOSITY_TEST_DATA) + "/room_lamp_under_ceiling.obj");
    room.make_two_sided();
    rad::SolveOptions unbalanced = hierarchical(0.05f);
    unbalanced.hierarchical.balance_closed_regions = false;
    const rad::Solution sol = rad::solve(room, unbalanced);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    // The warning's measure: the loss over the three channels together.
    auto escaped_share = [](const rad::SolveReport& r) {
      return (r.escaped_power.x + r.escaped_power.y + r.escaped_power.z) /
             (r.emitted_power.x + r.emitted_power.y + r.emitted_power.z);
    };
    const double escaped = escaped_share(sol.report());
    MESSAGE("closed room, hierarchical: escaped " << escaped);
    CHECK(std::abs(escaped) < 0.05);
    CHECK(warned(sol) == (escaped > 0.01));  // the warning says a loss over 1 %, and only that
    const rad::Solution open = rad::solve(rad::cornell_box(), hierarchical(0.05f));
    CHECK(open.report().escaped_power.y > 0.2f * open.report().emitted_power.y);
    CHECK_FALSE(warned(open));
    rad::SolveOptions gs;
    gs.method = rad::SolverMethod::gauss_seidel;
    const rad::Solution ref = rad::solve(room, gs);
    CHECK(std::abs(ref.report().escaped_power.y) < 0.01f * ref.report().emitted_power.y);
    CHECK_FALSE(warned(ref));
    const rad::Solution balanced = rad::solve(room, hierarchical(0.05f));
    REQUIRE(balanced.status() == rad::SolveStatus::converged);
    MESSAGE("balanced: escaped " << balanced.report().escaped_power.y / balanced.report().emitted_power.y
                                 << ", room inside " << balanced.group_back_radiosity("room").y << " (gauss-seidel "
                                 << ref.group_back_radiosity("room").y << "), crate " << balanced.group_radiosity("crate").y
                                 << " (" << ref.group_radiosity("crate").y << ")");
    CHECK(std::abs(balanced.report().escaped_power.y) < 0.01f * balanced.report().emitted_power.y);
    CHECK_FALSE(warned(balanced));
    for (int c = 0; c < 3; ++c) {
      CHECK(relative(balanced.group_back_radiosity("room")[c], ref.group_back_radiosity("room")[c]) < 0.05);
      CHECK(relative(balanced.group_radiosity("crate")[c], ref.group_radiosity("crate")[c]) < 0.05);
    }
  }

  TEST_CASE("hierarchical: a closed room with a lamp 1 cm under its ceiling, finely meshed, agrees with Gauss-Seidel" *
            test::release_only) {
    // 9 300 elements of 0.01 m^2, reflectance 0.99, made two-sided. Without the balancing the
    // links gained energy here: the room's inside came out 60 % too bright (19.2 against 11.7)
    // and absorbed / emitted was 1.5, with no warning. Balanced: measured -1.0 % (green), the
    // crate +1.4 %, absorbed / emitted 1.0004.
    rad::Scene room = rad::load_scene(std::string(RADIOSITY_TEST_DATA) + "/room_lamp_1cm_under_ceiling.obj");
    room.make_two_sided();
    rad::SolveOptions o = hierarchical(0.05f);
    o.tolerance = 1e-4;  // rho 0.99: about 1 % from the converged answer, for both solvers
    o.mesh.max_patch_area = 0.01f;
    o.mesh.max_element_area = 0.01f;
    const rad::Solution sol = rad::solve(room, o);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    rad::SolveOptions gs = o;
    gs.method = rad::SolverMethod::gauss_seidel;
    const rad::Solution ref = rad::solve(room, gs);
    REQUIRE(ref.status() == rad::SolveStatus::converged);
    MESSAGE("room inside " << sol.group_back_radiosity("room").y << " (gauss-seidel " << ref.group_back_radiosity("room").y
                           << "), crate " << sol.group_radiosity("crate").y << " (" << ref.group_radiosity("crate").y
                           << "), absorbed / emitted " << sol.report().absorbed_power.y / sol.report().emitted_power.y);
    CHECK(std::abs(sol.report().escaped_power.y) < 0.03f * sol.report().emitted_power.y);
    for (int c = 0; c < 3; ++c) {
      CHECK(relative(sol.group_back_radiosity("room")[c], ref.group_back_radiosity("room")[c]) < 0.05);
      CHECK(relative(sol.group_radiosity("crate")[c], ref.group_radiosity("crate")[c]) < 0.12);
    }
  }

  TEST_CASE("hierarchical: a lamp facing a ceiling 5 cm away in a black room delivers what it emits, once") {
    // A 4 x 3 x 4 room, everything black, a 1 m^2 lamp facing up 5 cm under the ceiling: its
    // light lands on the ceiling (and the walls' top 5 cm) and is absorbed there. The lamp's
    // side is enclosed and closed (its rays meet only the ceiling, a wholly enclosed polygon
    // side); the ceiling, which also sees the floor past the lamp's back (a side that takes no
    // light), is enclosed but not closed. The balancing counted as the lamp's delivery only
    // what reached closed sides, 0.15 of it, and scaled the lamp up to its bound: the ceiling
    // received 3.1 times what the lamp emits (escaped -208 %). Now 0 to rounding.
    rad::Material black;
    black.name = "black";
    black.reflectance = rad::Rgb(0.0f);
    rad::Scene room = test::closed_box(black, glm::vec3(4.0f, 3.0f, 4.0f));
    rad::Material lamp;
    lamp.name = "lamp";
    lamp.emission = rad::Rgb(10.0f);
    lamp.reflectance = rad::Rgb(0.0f);
    const rad::MaterialId L = room.add_material(lamp);
    room.add_polygon({{1.5f, 2.95f, 1.5f}, {1.5f, 2.95f, 2.5f}, {2.5f, 2.95f, 2.5f}, {2.5f, 2.95f, 1.5f}}, L, "lamp");
    REQUIRE(room.polygons().back().normal.y > 0.99f);
    const rad::Solution sol = rad::solve(room, hierarchical(0.05f));
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::SolveReport& r = sol.report();
    MESSAGE("escaped / emitted " << r.escaped_power.y / r.emitted_power.y);
    CHECK(std::abs(r.escaped_power.y) < 0.002f * r.emitted_power.y);
    rad::SolveOptions gs;
    gs.method = rad::SolverMethod::gauss_seidel;
    const rad::Solution ref = rad::solve(room, gs);
    // The ceiling's irradiance: a black receiver's radiosity is 0, so its power is its gather.
    const auto ceiling = [](const rad::Solution& s) {
      double power = 0.0;
      for (std::uint32_t e : s.hierarchy().leaves())
        if (s.hierarchy().patches()[s.hierarchy().element(e).patch].polygon == 3)
          power += static_cast<double>(s.irradiance()[e].y) * s.hierarchy().element(e).area;
      return power;
    };
    CHECK(relative(ceiling(sol), ceiling(ref)) < 0.01);
  }

  TEST_CASE("hierarchical: parallel plates 5 cm apart, one emitting, reflecting 0.9, agree with Gauss-Seidel") {
    // The clusters above the two 1 m plates hold parts of both. In the first pass the reflecting
    // plate is dark, so a cluster's points, drawn by the power its patches send, all lay on the
    // emitting plate, coplanar with a receiver on it: no facing pair, and the pair was dropped,
    // never to be looked at again, though the reflector sends through it later. Both plates
    // came out 15 % dark against Gauss-Seidel (2.89 and 2.40 against 3.40 and 2.85); measured now
    // -1.7 % and -2.1 %. The plates' own mesh (3 cm elements, 5 cm apart) keeps the two solvers
    // apart by about that: with both plates emitting they differ by 2.5 %, before and after.
    rad::Scene scene;
    rad::Material lamp, plate;
    lamp.name = "lamp";
    lamp.emission = rad::Rgb(1.0f);
    lamp.reflectance = rad::Rgb(0.9f);
    plate.name = "plate";
    plate.reflectance = rad::Rgb(0.9f);
    const rad::MaterialId L = scene.add_material(lamp), P = scene.add_material(plate);
    scene.add_polygon({{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, L, "emitting");
    scene.add_polygon({{0, 0.05f, 0}, {1, 0.05f, 0}, {1, 0.05f, 1}, {0, 0.05f, 1}}, P, "reflecting");
    REQUIRE(scene.polygons()[0].normal.y > 0.99f);
    REQUIRE(scene.polygons()[1].normal.y < -0.99f);
    const rad::Solution sol = rad::solve(scene, hierarchical(0.05f));
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    rad::SolveOptions gs;
    gs.method = rad::SolverMethod::gauss_seidel;
    gs.form_factors.method = rad::FormFactorMethod::ray_cast;
    gs.tolerance = 1e-6;
    const rad::Solution ref = rad::solve(scene, gs);
    for (const char* g : {"emitting", "reflecting"}) {
      MESSAGE(std::string(g) << ": hierarchical " << sol.group_radiosity(g).y << ", gauss-seidel " << ref.group_radiosity(g).y);
      CHECK(relative(sol.group_radiosity(g).y, ref.group_radiosity(g).y) < 0.03);
    }
  }

  TEST_CASE("hierarchical: a furnished room absorbs no more than its lamp emits") {
    // tests/data/furnished_room.obj: a closed 4 x 3 x 4 room of reflectance 0.9, wound inward,
    // furnished as people model it: a one-sided lamp facing down 2 cm under the ceiling, a shelf
    // 1 cm from a wall, a table whose legs are open tubes, a crate without a bottom; all
    // one-sided. What meets a back (the lamp's, in the pocket above it) is lost, so the room
    // absorbs less than the lamp emits: Gauss-Seidel 0.984 of it at this mesh. The balancing
    // gained energy here (1.011, the room +2.8 % against Gauss-Seidel): its adjoint took an inner
    // element's value as its children's area mean where the sweeps take their open-area mean,
    // and the ceiling's leaves straddling the lamp's edge (partly taken for buried, in the pocket
    // above the lamp) sent 2-3 times their open power, which nothing bounded. Now 0.997, the
    // room +1.4 %. (The same scene built in another polygon order gained less, 0.994: how much
    // depends on where the elements fall.) Against the reference path tracer, the mean of a
    // 96 x 72 view of the room (1024 paths a pixel, the lamp left out): Gauss-Seidel -3.5 %,
    // hierarchical -2.3 % (-0.9 % before); at 0.01 m^2 elements -1.3 % and -0.6 % (+2.1 %).
    const rad::Scene scene = rad::load_scene(std::string(RADIOSITY_TEST_DATA) + "/furnished_room.obj");
    const rad::Solution sol = rad::solve(scene, closed_room_options(rad::SolverMethod::hierarchical));
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::Solution ref = rad::solve(scene, closed_room_options(rad::SolverMethod::gauss_seidel));
    const double absorbed = absorbed_share(sol), reference = absorbed_share(ref);
    MESSAGE("absorbed / emitted: hierarchical " << absorbed << ", gauss-seidel " << reference);
    CHECK(absorbed < 1.003);
    CHECK(absorbed > reference - 0.01);
    const float room = sol.group_radiosity("room").y, room_reference = ref.group_radiosity("room").y;
    MESSAGE("the room's radiosity: hierarchical " << room << ", gauss-seidel " << room_reference);
    CHECK(relative(room, room_reference) < 0.025);
  }

  TEST_CASE("hierarchical: the walls of a room see a lamp's back and deliver what they measure") {
    // A closed 4 x 3 x 4 room of reflectance 0.9 and a one-sided 1 m^2 lamp facing down 2 cm
    // under its ceiling. The walls see the lamp's back (which takes no light in) from below its
    // height only at grazing angles: about 97 % of their leaves are enclosed, balanced to deliver
    // all they send, and the rest were left with the links' estimate, though they send about
    // 0.999 of it. Such a polygon side's open leaves now deliver what their rays measure,
    // pooled. Measured against Gauss-Seidel: the room's power +1.4 % -> +0.6 %, absorbed /
    // emitted 1.000 -> 0.992 (Gauss-Seidel 0.986). (Against the reference path tracer, a view
    // of the same room built as an OBJ: Gauss-Seidel -1.1 %, hierarchical +0.8 % -> 0.0 %.)
    const rad::Scene scene = room_with_lamp(0.02f);
    const rad::Solution sol = rad::solve(scene, closed_room_options(rad::SolverMethod::hierarchical));
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::Solution ref = rad::solve(scene, closed_room_options(rad::SolverMethod::gauss_seidel));
    const double absorbed = absorbed_share(sol), reference = absorbed_share(ref);
    MESSAGE("absorbed / emitted: hierarchical " << absorbed << ", gauss-seidel " << reference);
    CHECK(absorbed < 1.0);
    const double power = room_power(sol), reference_power = room_power(ref);
    MESSAGE("the room's power: hierarchical " << power << ", gauss-seidel " << reference_power);
    CHECK(relative(power, reference_power) < 0.011);
  }

  TEST_CASE("hierarchical: the ceiling above a lamp's back delivers what its rays measure" * doctest::timeout(120) *
            test::release_only) {
    // The room of the test above with the lamp 50 cm under the ceiling, 0.01 m^2 elements
    // (10 000). The ceiling sees the lamp's back over much of its area: few of its leaves are
    // enclosed, and the rest kept the links' estimate of what they deliver, 0.3 % over what
    // their rays measure (0.9526 against 0.9492 of the power sent). None of those rays leaves
    // the room, so their pooled share is taken instead. Measured: the room's power against
    // Gauss-Seidel +1.9 % -> +0.6 % (against the reference path tracer, a view of the same
    // room built as an OBJ: Gauss-Seidel -0.1 %, hierarchical +2.0 % -> +1.0 %). Release only
    // (session 30: 49 s under ThreadSanitizer, 24 s under AddressSanitizer, the slowest there);
    // the sanitizers run the same balancing in "the walls of a room see a lamp's back".
    const rad::Scene scene = room_with_lamp(0.5f);
    rad::SolveOptions options = closed_room_options(rad::SolverMethod::hierarchical);
    rad::SolveOptions gs = closed_room_options(rad::SolverMethod::gauss_seidel);
    for (rad::SolveOptions* o : {&options, &gs}) {
      o->mesh.max_element_area = 0.01f;
      o->mesh.max_patch_area = 0.04f;
    }
    const rad::Solution sol = rad::solve(scene, options);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::Solution ref = rad::solve(scene, gs);
    const double power = room_power(sol), reference_power = room_power(ref);
    MESSAGE("the room's power: hierarchical " << power << ", gauss-seidel " << reference_power);
    CHECK(relative(power, reference_power) < 0.01);
  }

  TEST_CASE("hierarchical: a furnace of reflectance 0.99 converges to E / (1 - rho) on every leaf") {
    // B = E / (1 - rho) = 100 E: every per cent the links gain or lose is multiplied by up to 100.
    // Balanced (every side of the closed box delivers what it sends and gathers 1 from uniform
    // radiosity): measured mean 99.988, leaves 99.9875-99.990 (session 24's end; 99.9924,
    // 99.992-99.994 with the linear pull alone;
    // before it 99.9992, 99.92-100.41; with the linear push's shares left out of the balancing's
    // adjoint, the mean was 99.38; with the pull but without its power keeping, 99.57). Before the balancing the links
    // gained about 1 % here (absorbed / emitted 1.013 at rho 0.8), so the sweeps grew and were
    // held: mean 94.6, largest 99.9987 (before the hold: mean 159 after one pass held and the
    // next not, or divergence).
    const rad::Scene scene = furnace(rad::Rgb(1.0f), rad::Rgb(0.99f));
    rad::SolveOptions o = hierarchical(0.05f);
    o.tolerance = 1e-5;  // about 1150 sweeps at rho 0.99
    o.max_iterations = 4000;
    o.mesh.max_patch_area = 0.26f;
    o.mesh.max_element_area = 0.07f / 4;
    const rad::Solution sol = rad::solve(scene, o);
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    double mean = 0.0, largest = 0.0, smallest = 1e30;
    for (std::uint32_t e : sol.hierarchy().leaves()) {
      mean += sol.radiosity()[e].y;
      largest = std::max(largest, static_cast<double>(sol.radiosity()[e].y));
      smallest = std::min(smallest, static_cast<double>(sol.radiosity()[e].y));
    }
    mean /= static_cast<double>(sol.hierarchy().leaves().size());
    MESSAGE("furnace at rho 0.99: mean " << mean << ", leaves " << smallest << " to " << largest
                                         << " (exact 100), warnings " << sol.report().warnings.size());
    CHECK(sol.report().warnings.empty());  // not held
    CHECK(std::abs(mean - 100.0) < 0.1);
    CHECK(largest < 100.1);
    CHECK(smallest > 99.9);
  }
}
