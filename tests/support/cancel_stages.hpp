// Cancel latency at every stage (issue #17), shared by tests/solver/test_cancel_latency.cpp
// (a sanity bound on any machine) and benchmarks/bench_cancel.cpp (the 100 ms target on a quiet
// one). For each stage (meshing: solve()'s z-fighting check, contact lines and elements; the
// lights' first shot, the form factors of each estimator, progressive, hierarchical refinement,
// each renderer, the lightmap baker, the view-factor matrix) a callback asks to cancel `after`
// seconds into the stage; the probe measures
// - the latency: from the callback returning false to the call returning;
// - the largest gap between two calls of the callback in the stage before that (how long a
//   host's cancel request can wait to be seen).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace cancel {

namespace rad = radiosity;
using Clock = std::chrono::steady_clock;

inline double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// Runs a call with a progress callback that cancels `after` seconds into `phase`.
struct Probe {
  rad::Phase phase;
  double after = 0.15;
  bool cancelled = false;
  int calls_after_cancel = 0;
  double largest_gap = 0.0;    ///< s between consecutive calls in the phase, before the cancel
  double largest_gap_end = 0.0;  ///< s into the phase when the largest gap ended
  double latency = -1.0;       ///< s from returning false to the call returning; -1: no cancel
  double phase_seconds = 0.0;  ///< s the phase ran before the cancel (or in all)

  void run(const std::function<void(const rad::ProgressFn&)>& call) {
    bool seen = false;
    Clock::time_point first{}, previous{}, cancel_at{};
    call([&](const rad::Progress& p) {
      if (cancelled) {
        ++calls_after_cancel;
        return false;
      }
      if (p.phase != phase) return true;
      const Clock::time_point now = Clock::now();
      if (!seen) {
        seen = true;
        first = previous = now;
      }
      phase_seconds = seconds_between(first, now);
      if (seconds_between(previous, now) > largest_gap) {
        largest_gap = seconds_between(previous, now);
        largest_gap_end = phase_seconds;
      }
      previous = now;
      if (phase_seconds < after) return true;
      cancelled = true;
      cancel_at = Clock::now();
      return false;
    });
    if (cancelled) latency = seconds_between(cancel_at, Clock::now());
  }
};

/// One stage: its call, the phase to cancel in, and whether the call's own result says it
/// was cancelled (read after run()).
struct Stage {
  std::string name;
  rad::Phase phase;
  std::function<void(const rad::ProgressFn&)> call;
  std::function<bool()> reports_cancel;
};

/// The Cornell box with a sky and a floor mesh with UV1, meshed at `element_area`
/// (mm^2; 625 = 2.5 cm elements, about 26k), and the stages over it; `image` is the renders'
/// width and height, `lightmap` the lightmap's. Meshing is measured on a scene of its own: a
/// height field of `terrain_triangles` triangles (one indexed mesh, as a host hands it over)
/// under a sky. Keeps what the stages refer to.
class Stages {
 public:
  Stages(float element_area, int image, int lightmap, std::size_t terrain_triangles) {
    scene_.add_light(light());
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.5f);
    floor_mesh_ = scene_.add_mesh(test::mesh_desc(positions_, indices_, scene_.add_material(grey), "rug", uv1_));
    rad::SolveOptions coarse;
    coarse.mesh.max_element_area = 2500.0f;
    solution_ = std::make_unique<rad::Solution>(rad::solve(scene_, coarse));

    // `sky_rays` 0: the default.
    auto solve_stage = [this, element_area](rad::SolverMethod method, rad::FormFactorMethod estimator,
                                            std::uint32_t sky_rays = 0) {
      return [this, element_area, method, estimator, sky_rays](const rad::ProgressFn& progress) {
        rad::SolveOptions o;
        o.method = method;
        o.form_factors.method = estimator;
        if (sky_rays > 0) o.sky_rays = sky_rays;
        o.mesh.max_element_area = element_area;
        o.threads = 2;
        o.on_progress = progress;
        solution_cancelled_ = rad::solve(scene_, o).status() == rad::SolveStatus::cancelled;
      };
    };
    auto solved = [this] { return solution_cancelled_; };
    auto always = [] { return true; };
    const auto gs = rad::SolverMethod::gauss_seidel;
    make_terrain(terrain_triangles);
    // Meshing: in solve() the z-fighting check comes first, then PatchHierarchy's contact
    // lines, then the polygons' elements (the last two alone, without the search, next).
    list_.push_back({"meshing, solve()", rad::Phase::meshing,
                     [this](const rad::ProgressFn& progress) {
                       rad::SolveOptions o;
                       o.threads = 2;
                       o.on_progress = progress;
                       solution_cancelled_ = rad::solve(terrain_, o).status() == rad::SolveStatus::cancelled;
                     },
                     solved});
    auto mesh_stage = [this](bool contacts) {
      return [this, contacts](const rad::ProgressFn& progress) {
        rad::MeshOptions m;
        m.split_at_contacts = contacts;
        if (!contacts) m.max_element_area = 1e-4f;  // 1 cm elements: a million of them
        mesh_cancelled_ = rad::PatchHierarchy(terrain_, m, progress).patches().empty();
      };
    };
    auto mesh_cancelled = [this] { return mesh_cancelled_; };
    list_.push_back({"meshing, contact lines", rad::Phase::meshing, mesh_stage(true), mesh_cancelled});
    list_.push_back({"meshing, elements", rad::Phase::meshing, mesh_stage(false), mesh_cancelled});
    // Four times the sky's default rays: with the default the first shot took 0.12-0.14 s on a
    // quiet machine (session 37), ending before the probe's 0.15 s.
    list_.push_back({"lights' first shot", rad::Phase::lights,
                     solve_stage(gs, rad::FormFactorMethod::monte_carlo, 2560), solved});
    list_.push_back({"form factors, ray_cast", rad::Phase::form_factors, solve_stage(gs, rad::FormFactorMethod::ray_cast), solved});
    list_.push_back({"form factors, hemicube", rad::Phase::form_factors, solve_stage(gs, rad::FormFactorMethod::hemicube), solved});
    list_.push_back({"form factors, monte_carlo", rad::Phase::form_factors,
                     solve_stage(gs, rad::FormFactorMethod::monte_carlo), solved});
    list_.push_back({"progressive", rad::Phase::solving,
                     solve_stage(rad::SolverMethod::progressive, rad::FormFactorMethod::monte_carlo), solved});
    list_.push_back({"hierarchical refinement", rad::Phase::form_factors,
                     solve_stage(rad::SolverMethod::hierarchical, rad::FormFactorMethod::automatic), solved});
    list_.push_back({"render", rad::Phase::rendering,
                     [this, image](const rad::ProgressFn& progress) {
                       rad::RenderOptions r;
                       r.width = r.height = 2 * image;
                       r.spp = 64;
                       r.on_progress = progress;
                       (void)rad::render(scene_, *solution_, r);
                     },
                     always});
    list_.push_back({"path tracer", rad::Phase::rendering,
                     [this, image](const rad::ProgressFn& progress) {
                       rad::PathTraceOptions p;
                       p.width = p.height = image;
                       p.spp = 256;
                       p.on_progress = progress;
                       (void)rad::render_path_traced(scene_, p);
                     },
                     always});
    list_.push_back({"two-pass", rad::Phase::rendering,
                     [this, image](const rad::ProgressFn& progress) {
                       rad::TwoPassOptions t;
                       t.width = t.height = image;
                       t.spp = 64;
                       t.on_progress = progress;
                       (void)rad::render_two_pass(scene_, *solution_, t);
                     },
                     always});
    list_.push_back({"lightmap", rad::Phase::rendering,
                     [this, lightmap](const rad::ProgressFn& progress) {
                       rad::LightmapOptions l;
                       l.width = l.height = lightmap;
                       l.final_gather = true;  // rays per texel: a stage long enough to cancel
                       l.on_progress = progress;
                       lightmap_cancelled_ = rad::bake_lightmap(scene_, *solution_, floor_mesh_, l).cancelled;
                     },
                     [this] { return lightmap_cancelled_; }});
    list_.push_back({"view-factor matrix", rad::Phase::form_factors,
                     [this, element_area](const rad::ProgressFn& progress) {
                       rad::ViewFactorOptions v;
                       v.level = rad::ViewFactorLevel::element;
                       v.mesh.max_element_area = element_area;
                       v.form_factors.method = rad::FormFactorMethod::monte_carlo;
                       v.on_progress = progress;
                       factors_cancelled_ = rad::view_factor_matrix(scene_, v).cancelled;
                     },
                     [this] { return factors_cancelled_; }});
  }
  Stages(const Stages&) = delete;
  Stages& operator=(const Stages&) = delete;

  const std::vector<Stage>& list() const { return list_; }

 private:
  // A sky through the open front: its first shot casts SolveOptions::sky_rays per element,
  // the longest of the lights'.
  static rad::Light light() {
    rad::Light l;
    l.type = rad::LightType::sky;
    l.intensity = 10.0f;
    return l;
  }

  /// A gently rolling n x n grid of quads, two triangles each, 10 m across.
  void make_terrain(std::size_t triangles) {
    const auto n = static_cast<std::uint32_t>(std::max(1.0, std::ceil(std::sqrt(static_cast<double>(triangles) / 2.0))));
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;
    positions.reserve(static_cast<std::size_t>(n + 1) * (n + 1));
    indices.reserve(static_cast<std::size_t>(n) * n * 6);
    const float step = 10.0f / static_cast<float>(n);
    for (std::uint32_t j = 0; j <= n; ++j)
      for (std::uint32_t i = 0; i <= n; ++i) {
        const float x = step * static_cast<float>(i), y = step * static_cast<float>(j);
        positions.emplace_back(x, y, 0.2f * std::sin(0.7f * x) * std::cos(0.9f * y));
      }
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
        indices.insert(indices.end(), {a, b, c, a, c, d});
      }
    rad::Material ground;
    ground.reflectance = rad::Rgb(0.3f);
    terrain_.add_mesh(test::mesh_desc(positions, indices, terrain_.add_material(ground), "terrain"));
    terrain_.add_light(light());
  }

  rad::Scene scene_ = rad::cornell_box();
  rad::Scene terrain_;
  std::vector<glm::vec3> positions_{{100, 1, 100}, {450, 1, 100}, {450, 1, 450}, {100, 1, 450}};
  std::vector<std::uint32_t> indices_{0, 2, 1, 0, 3, 2};
  std::vector<glm::vec2> uv1_{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  rad::MeshId floor_mesh_ = 0;
  std::unique_ptr<rad::Solution> solution_;
  bool solution_cancelled_ = false, mesh_cancelled_ = false, lightmap_cancelled_ = false, factors_cancelled_ = false;
  std::vector<Stage> list_;
};

}  // namespace cancel
