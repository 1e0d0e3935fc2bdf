// Issue #17: a progress callback that throws is handled. The callbacks run on the calling thread
// (common.hpp), and what they throw is the host's business: it must come out of the library call
// unchanged (not terminate the process from a worker thread, not be swallowed, not be turned
// into radiosity::Error), at every phase of every call that reports progress, and the library
// must stay usable after it (the next call succeeds).
#include <algorithm>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// The host's own exception type, which the library knows nothing about.
struct HostAbort {
  rad::Phase phase;
};

/// A callback that throws HostAbort at its first call in `phase`.
rad::ProgressFn throw_in(rad::Phase phase) {
  return [phase](const rad::Progress& p) {
    if (p.phase == phase) throw HostAbort{p.phase};
    return true;
  };
}

/// Whether `call` threw HostAbort for `phase`.
template <typename Call>
bool throws_host_abort(rad::Phase phase, const Call& call) {
  try {
    call();
  } catch (const HostAbort& e) {
    return e.phase == phase;
  }
  return false;
}

/// The Cornell box, coarse, with a point light besides its own lamp (so the lights' first shot
/// reports too) and a floor mesh with a lightmap UV1.
struct Fixture {
  rad::Scene scene = rad::cornell_box();
  std::vector<glm::vec3> positions{{100, 1, 100}, {450, 1, 100}, {450, 1, 450}, {100, 1, 450}};
  std::vector<std::uint32_t> indices{0, 2, 1, 0, 3, 2};
  std::vector<glm::vec2> uv1{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  rad::MeshId floor_mesh = 0;

  Fixture() {
    scene.add_light(test::point_light("bulb", 1e5f, {278, 400, 278}));
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.5f);
    floor_mesh = scene.add_mesh(test::mesh_desc(positions, indices, scene.add_material(grey), "rug", uv1));
  }

  rad::SolveOptions solve_options() const {
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 10000.0f;
    o.threads = 2;
    return o;
  }
};

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("a progress callback that throws: its exception comes out of every call at every phase, and the next call works") {
  const Fixture f;
  // solve(): each phase it reports (progressive computes its columns while solving, so it
  // reports no form-factor phase), for a matrix method, progressive and hierarchical.
  for (const rad::SolverMethod method : {rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive,
                                         rad::SolverMethod::hierarchical}) {
    CAPTURE(static_cast<int>(method));
    rad::SolveOptions o = f.solve_options();
    o.method = method;
    std::vector<rad::Phase> phases;
    o.on_progress = [&](const rad::Progress& p) {
      if (std::find(phases.begin(), phases.end(), p.phase) == phases.end()) phases.push_back(p.phase);
      return true;
    };
    (void)rad::solve(f.scene, o);
    CHECK(std::find(phases.begin(), phases.end(), rad::Phase::lights) != phases.end());
    CHECK(std::find(phases.begin(), phases.end(), rad::Phase::solving) != phases.end());
    for (const rad::Phase phase : phases) {
      CAPTURE(static_cast<int>(phase));
      o.on_progress = throw_in(phase);
      CHECK(throws_host_abort(phase, [&] { (void)rad::solve(f.scene, o); }));
    }
  }
  const rad::Solution solution = rad::solve(f.scene, f.solve_options());  // still works
  CHECK(solution.status() == rad::SolveStatus::converged);

  // The renderers, the lightmap baker and the view factors.
  rad::RenderOptions r;
  r.width = r.height = 16;
  r.on_progress = throw_in(rad::Phase::rendering);
  CHECK(throws_host_abort(rad::Phase::rendering, [&] { (void)rad::render(f.scene, solution, r); }));
  rad::PathTraceOptions pt;
  pt.width = pt.height = 16;
  pt.spp = 4;
  pt.on_progress = throw_in(rad::Phase::rendering);
  CHECK(throws_host_abort(rad::Phase::rendering, [&] { (void)rad::render_path_traced(f.scene, pt); }));
  rad::TwoPassOptions tp;
  tp.width = tp.height = 16;
  tp.spp = 4;
  tp.on_progress = throw_in(rad::Phase::rendering);
  CHECK(throws_host_abort(rad::Phase::rendering, [&] { (void)rad::render_two_pass(f.scene, solution, tp); }));
  rad::LightmapOptions lm;
  lm.width = lm.height = 16;
  lm.on_progress = throw_in(rad::Phase::rendering);
  CHECK(throws_host_abort(rad::Phase::rendering, [&] { (void)rad::bake_lightmap(f.scene, solution, f.floor_mesh, lm); }));
  rad::ViewFactorOptions vf;
  vf.on_progress = throw_in(rad::Phase::form_factors);
  CHECK(throws_host_abort(rad::Phase::form_factors, [&] { (void)rad::view_factors(f.scene, vf); }));
  CHECK(throws_host_abort(rad::Phase::form_factors, [&] { (void)rad::view_factor_matrix(f.scene, vf); }));

  // And everything still works afterwards.
  r.on_progress = nullptr;
  const rad::Image image = rad::render(f.scene, solution, r);
  CHECK(image.pixels.size() == 16u * 16u);
}

}  // TEST_SUITE
