// Issue #17: every estimator, solver and renderer gives bit-identical results at 1, 2 and 4
// threads (and at the default, 0) for a seed, in one parameterised test. Each case below turns the small Cornell box
// (or its mirror-and-glass variant) into a flat list of floats with the given thread count; the
// lists at 2 and 4 threads must equal the one at 1, bit for bit. 4 threads on a 2-core machine
// still interleave, so chunking and scheduling differ between the runs; in the ThreadSanitizer
// build the same runs check for data races.
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// The Cornell box coarsely meshed: a few hundred elements, so each case takes well under a second.
rad::SolveOptions coarse_solve(unsigned threads) {
  rad::SolveOptions o;
  o.mesh.max_patch_area = 20000.0f;  // mm^2
  o.mesh.max_element_area = 10000.0f;
  o.threads = threads;
  o.form_factors.hemisphere_rays = 256;
  o.sky_rays = 80;
  o.seed = 7;
  return o;
}

void append(std::vector<float>& out, const std::vector<rad::Rgb>& values) {
  for (const rad::Rgb& v : values) out.insert(out.end(), {v.x, v.y, v.z});
}

std::vector<float> solution_values(const rad::Solution& s) {
  std::vector<float> out;
  append(out, s.radiosity());
  return out;
}

std::vector<float> image_values(const rad::Image& image) {
  std::vector<float> out;
  append(out, image.pixels);
  return out;
}

const rad::Scene& cornell() {
  static const rad::Scene scene = rad::cornell_box();
  return scene;
}

/// A closed unit box with a small square hanging inside it: the exact view factors' partly
/// occluded pairs, cheaply (the Cornell box's blocks take seconds under the sanitizers).
const rad::Scene& box_with_occluder() {
  static const rad::Scene scene = [] {
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.5f);
    rad::Scene s = test::closed_box(grey);
    s.add_polygon({{0.3f, 0.3f, 0.5f}, {0.7f, 0.3f, 0.5f}, {0.7f, 0.7f, 0.5f}, {0.3f, 0.7f, 0.5f}}, 0, "occluder");
    return s;
  }();
  return scene;
}

const rad::Scene& cornell_specular() {
  static const rad::Scene scene = rad::cornell_box_specular();
  return scene;
}

struct Case {
  const char* name;
  std::function<std::vector<float>(unsigned threads)> run;
};

std::vector<float> solve_with(rad::FormFactorMethod estimator, rad::SolverMethod solver, unsigned threads) {
  rad::SolveOptions o = coarse_solve(threads);
  o.form_factors.method = estimator;
  o.method = solver;
  o.form_factors.hemicube_resolution = 64;
  return solution_values(rad::solve(cornell(), o));
}

std::vector<Case> cases() {
  using F = rad::FormFactorMethod;
  using S = rad::SolverMethod;
  std::vector<Case> c;
  for (const F f : {F::ray_cast, F::hemicube, F::analytic, F::monte_carlo})
    c.push_back({rad::to_string(f), [f](unsigned t) { return solve_with(f, S::gauss_seidel, t); }});
  c.push_back({"jacobi", [](unsigned t) { return solve_with(F::monte_carlo, S::jacobi, t); }});
  c.push_back({"progressive", [](unsigned t) { return solve_with(F::ray_cast, S::progressive, t); }});
  c.push_back({"hierarchical", [](unsigned t) { return solve_with(F::monte_carlo, S::hierarchical, t); }});
  c.push_back({"hierarchical, a closed region balanced", [](unsigned t) {
                 // A closed box with a lamp hanging inside: HierarchicalOptions::
                 // balance_closed_regions at work (enclosure rays, the adjoint, the rounds).
                 static const rad::Scene room = [] {
                   rad::Material grey, lamp;
                   grey.reflectance = rad::Rgb(0.9f);
                   lamp.emission = rad::Rgb(10.0f);
                   rad::Scene s = test::closed_box(grey);
                   const rad::MaterialId id = s.add_material(lamp);
                   s.add_polygon({{0.3f, 0.3f, 0.9f}, {0.3f, 0.7f, 0.9f}, {0.7f, 0.7f, 0.9f}, {0.7f, 0.3f, 0.9f}}, id, "lamp");
                   return s;
                 }();
                 rad::SolveOptions o = coarse_solve(t);
                 o.method = S::hierarchical;
                 o.mesh.max_patch_area = 0.05f;
                 o.mesh.max_element_area = 0.0125f;
                 return solution_values(rad::solve(room, o));
               }});
  c.push_back({"view_factor_matrix exact", [](unsigned t) {
                 rad::ViewFactorOptions o;
                 o.form_factors.method = F::ray_cast;
                 o.form_factors.threads = t;
                 o.mesh.max_patch_area = o.mesh.max_element_area = 0.26f;
                 o.level = rad::ViewFactorLevel::element;
                 return rad::view_factor_matrix(box_with_occluder(), o).values;
               }});
  c.push_back({"view_factor_matrix monte_carlo", [](unsigned t) {
                 rad::ViewFactorOptions o;
                 o.form_factors.method = F::monte_carlo;
                 o.form_factors.hemisphere_rays = 256;
                 o.form_factors.threads = t;
                 o.correction = rad::ViewFactorCorrection::reciprocity;  // the box is open at the front
                 return rad::view_factor_matrix(cornell(), o).values;
               }});
  c.push_back({"render", [](unsigned t) {
                 const rad::Solution s = rad::solve(cornell(), coarse_solve(1));
                 rad::RenderOptions o;
                 o.width = o.height = 24;
                 o.threads = t;
                 return image_values(rad::render(cornell(), s, o));
               }});
  c.push_back({"render_two_pass with caustics", [](unsigned t) {
                 rad::SolveOptions so = coarse_solve(1);
                 rad::prepare_two_pass(cornell_specular(), so);
                 so.threads = t;
                 const rad::Solution s = rad::solve(cornell_specular(), so);
                 rad::TwoPassOptions o;
                 o.width = o.height = 16;
                 o.spp = 4;
                 o.direct_samples = 16;
                 o.caustics.photons = 5000;
                 o.threads = t;
                 return image_values(rad::render_two_pass(cornell_specular(), s, o));
               }});
  c.push_back({"render_path_traced", [](unsigned t) {
                 rad::PathTraceOptions o;
                 o.width = o.height = 16;
                 o.spp = 4;
                 o.threads = t;
                 return image_values(rad::render_path_traced(cornell_specular(), o));
               }});
  return c;
}

bool bit_identical(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("determinism: every estimator, solver and renderer is bit-identical at 1, 2 and 4 threads and at the "
          "default (0)") {
  for (const Case& c : cases()) {
    CAPTURE(std::string(c.name));
    const auto start = std::chrono::steady_clock::now();
    const std::vector<float> one = c.run(1);
    REQUIRE(!one.empty());
    // Not all zero: a case that computed nothing would pass trivially.
    bool any = false;
    for (const float v : one) any |= v != 0.0f;
    CHECK(any);
    // 0 is the default (every core, in TBB's own arena rather than one of our explicit ones):
    // session 35 found results there that 1, 2 and 4 did not reproduce (a float that fell into
    // the denormals, on a scene 0.4 mm across; test_ray_cast.cpp's scale test has that case).
    for (const unsigned threads : {0u, 2u, 4u}) {
      CAPTURE(threads);
      CHECK(bit_identical(c.run(threads), one));
    }
    MESSAGE(std::string(c.name) << ": " << one.size() << " values, bit-identical at 1, 2, 4 and 0 threads in "
                   << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s");
  }
}

}  // TEST_SUITE
