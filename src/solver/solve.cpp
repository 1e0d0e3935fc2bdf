// The solve() facade: mesh, form factors, solver, Solution.
#include <chrono>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "form_factors/estimators.hpp"
#include "scene/overlap.hpp"
#include "radiosity/solver.hpp"
#include "scene/emitter_check.hpp"
#include "form_factors/pass1_material.hpp"
#include "solver/system.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using detail::seconds_since;

constexpr std::size_t kDefaultMemoryBudget = std::size_t{4} << 30;

}  // namespace

void validate(const SolveOptions& o) {
  if (!(o.tolerance > 0.0) || !std::isfinite(o.tolerance))
    throw Error(ErrorCode::invalid_argument, "tolerance must be finite and > 0, got " + std::to_string(o.tolerance));
  if (o.max_iterations < 0)
    throw Error(ErrorCode::invalid_argument, "max_iterations must be >= 0 (0 = default), got " +
                                                 std::to_string(o.max_iterations));
  auto check_area = [](float a, const char* name) {
    if (!(a >= 0.0f) || !std::isfinite(a))
      throw Error(ErrorCode::invalid_argument,
                  std::string("mesh.") + name + " must be finite and >= 0 (0 = derive), got " + std::to_string(a));
  };
  check_area(o.mesh.max_patch_area, "max_patch_area");
  check_area(o.mesh.max_element_area, "max_element_area");
  if (o.adaptive.enabled) {
    if (!(o.adaptive.threshold > 0.0f && o.adaptive.threshold <= 1.0f))
      throw Error(ErrorCode::invalid_argument,
                  "adaptive.threshold must be in (0, 1], got " + std::to_string(o.adaptive.threshold));
    if (o.adaptive.max_passes < 1)
      throw Error(ErrorCode::invalid_argument,
                  "adaptive.max_passes must be >= 1, got " + std::to_string(o.adaptive.max_passes));
    if (o.adaptive.max_depth < 1)
      throw Error(ErrorCode::invalid_argument,
                  "adaptive.max_depth must be >= 1, got " + std::to_string(o.adaptive.max_depth));
  }
  detail::resolve(o.form_factors);
}

Solution solve(const Scene& scene, const SolveOptions& options) {
  validate(options);
  if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "solve: the scene has no polygons");

  SolveOptions o = options;
  if (o.memory_budget_bytes == 0) o.memory_budget_bytes = kDefaultMemoryBudget;
  // Translucent and two-sided materials in use switch the back sides on.
  for (const Polygon& polygon : scene.polygons())
    if (detail::pass1_has_back(scene.material(polygon.material))) {
      o.form_factors.diffuse_transmission = true;
      break;
    }
  o.form_factors.seed = o.seed;
  // The estimator inherits the solve's thread count unless it was given one of its own.
  if (o.form_factors.threads == 0) o.form_factors.threads = o.threads;

  detail::ProgressGate gate(o.on_progress);
  SolveReport report;
  report.warnings = scene.warnings();
  // Contact and interpenetration are lit correctly; only same-facing coincident surfaces are
  // ambiguous.
  for (std::string& w : detail::z_fighting_warnings(scene)) report.warnings.push_back(std::move(w));

  auto t0 = std::chrono::steady_clock::now();
  PatchHierarchy hierarchy(scene, o.mesh);
  report.seconds_meshing = seconds_since(t0);
  report.patch_count = hierarchy.patches().size();
  report.element_count = hierarchy.leaves().size();
  report.specular_depth = o.form_factors.specular_depth;
  o.form_factors.method = choose_form_factor_method(hierarchy, o.form_factors);
  report.form_factor_method = o.form_factors.method;
  if (o.max_iterations == 0)
    o.max_iterations = o.method == SolverMethod::progressive ? static_cast<int>(100 * report.patch_count) : 1000;

  const bool translucency = o.form_factors.diffuse_transmission;
  std::optional<detail::RadiositySystem> system(std::in_place, scene, hierarchy, translucency);
  std::vector<Rgb> B_elements(hierarchy.elements().size(), Rgb(0.0f));
  // Per element id, with diffuse transmission: the backs' radiosity (empty without).
  std::vector<Rgb> B_back(translucency ? hierarchy.elements().size() : 0, Rgb(0.0f));
  std::vector<std::string> groups = scene.groups();

  if (!gate.report(Progress{Phase::meshing, 1.0, 0, 1.0}, true))
    return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), SolveStatus::cancelled,
                    std::move(report), Rgb(0.0f), {}, std::move(B_back));

  if (system->emitted <= 0.0) {
    // Nothing emits: B = 0 is the exact answer.
    report.warnings.push_back("the scene emits no light; every radiosity is 0");
    return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), SolveStatus::converged,
                    std::move(report), Rgb(0.0f), {}, std::move(B_back));
  }

  auto estimator = make_form_factor_estimator(scene, hierarchy, o.form_factors);
  if (estimator->target_count() != system->patches())
    throw Error(ErrorCode::internal, "solve: the estimator and the system number the translucent patches differently");
  detail::MatrixStore store;
  const bool progressive = o.method == SolverMethod::progressive;
  auto t1 = std::chrono::steady_clock::now();

  // Per element id, so values survive the re-indexing of unknowns when leaves are split.
  std::vector<Rgb> H_elements(hierarchy.elements().size(), Rgb(0.0f)), H_back;
  auto resize = [&] {
    const std::size_t count = hierarchy.elements().size();
    B_elements.resize(count, Rgb(0.0f));
    H_elements.resize(count, Rgb(0.0f));
    if (translucency) {
      B_back.resize(count, Rgb(0.0f));
      H_back.resize(count, Rgb(0.0f));
    }
  };
  // Side u's values, per element id.
  auto B_of = [&](std::size_t u) -> Rgb& { return (u < system->fronts() ? B_elements : B_back)[system->element(u)]; };
  auto H_of = [&](std::size_t u) -> Rgb& { return (u < system->fronts() ? H_elements : H_back)[system->element(u)]; };
  auto keep = [&](const detail::SolverResult& res) {
    resize();
    for (std::size_t i = 0; i < system->unknowns(); ++i) {
      B_of(i) = res.B[i];
      H_of(i) = res.H[i];
    }
    report.iterations += res.iterations;
    report.residual = res.residual;
    const double offset = report.time_history.empty() ? 0.0 : report.time_history.back();
    report.residual_history.insert(report.residual_history.end(), res.residual_history.begin(),
                                   res.residual_history.end());
    for (double t : res.time_history) report.time_history.push_back(offset + t);
    report.form_factor_bytes = std::max(report.form_factor_bytes, res.form_factor_bytes);
    report.seconds_form_factors += res.seconds_form_factors;
  };

  detail::SolverResult r;
  {
    detail::SolverContext context{scene, hierarchy, *system, *estimator, o, gate};
    r = progressive ? detail::solve_progressive(context)
                    : detail::solve_matrix(context, o.method == SolverMethod::gauss_seidel, store, {});
  }
  keep(r);
  SolveStatus status = r.status;

  if (o.adaptive.enabled && status != SolveStatus::cancelled) {
    std::uint8_t initial_depth = 0;
    for (std::uint32_t e : hierarchy.leaves()) initial_depth = std::max(initial_depth, hierarchy.element(e).depth);
    const auto max_depth = static_cast<std::uint8_t>(std::min(250, initial_depth + o.adaptive.max_depth));
    const std::size_t budget =
        o.adaptive.max_elements > 0 ? o.adaptive.max_elements : 4 * hierarchy.leaves().size();
    for (int pass = 1; pass <= o.adaptive.max_passes; ++pass) {
      const std::vector<std::uint32_t> split =
          detail::leaves_to_refine(hierarchy, B_elements, o.adaptive, max_depth, budget);
      if (split.empty()) break;
      std::vector<std::uint32_t> created;
      for (std::uint32_t e : split) {
        store.release(e);
        const std::uint32_t first = hierarchy.subdivide(e);
        for (std::uint32_t c = first; c < first + 4; ++c) created.push_back(c);
      }
      // Children start from their parent's value (a warm start for the next sweeps).
      resize();
      for (std::uint32_t c : created) {
        const std::uint32_t parent = hierarchy.element(c).parent;
        B_elements[c] = B_elements[parent];
        H_elements[c] = H_elements[parent];
        if (translucency) {
          B_back[c] = B_back[parent];
          H_back[c] = H_back[parent];
        }
      }
      report.refined_elements += split.size();
      report.refinement_passes = pass;
      system.emplace(scene, hierarchy, translucency);
      Progress p{Phase::refining, static_cast<double>(pass) / o.adaptive.max_passes, pass, report.residual};
      if (!gate.report(p, true)) {
        status = SolveStatus::cancelled;
        break;
      }

      if (!progressive) {
        // Matrix methods: rows for the new elements only, then sweeps from the warm start.
        std::vector<Rgb> B0(system->unknowns());
        for (std::size_t i = 0; i < system->unknowns(); ++i) B0[i] = B_of(i);
        detail::SolverContext context{scene, hierarchy, *system, *estimator, o, gate};
        r = detail::solve_matrix(context, o.method == SolverMethod::gauss_seidel, store, B0);
        keep(r);
        status = r.status;
        if (status == SolveStatus::cancelled) break;
      } else {
        // Progressive: substructuring's gather. Each new element takes its radiosity from the
        // target radiosities it sees, B_c = E_c + rho_c H_c (+ tau_c H_c' with a back), with
        // H_c = sum_t F_ct B_t over its front row (and H_c' over its back row); no matrix is kept.
        std::vector<Rgb> patch_B;
        std::vector<Rgb> B_now(system->unknowns());
        for (std::size_t i = 0; i < system->unknowns(); ++i) B_now[i] = B_of(i);
        system->patch_means(B_now, patch_B);
        std::vector<SparseFactors> rows, back_rows;
        std::vector<std::uint32_t> backs;
        if (translucency)
          for (std::uint32_t c : created)
            if (detail::pass1_has_back(scene.material(hierarchy.patches()[hierarchy.element(c).patch].material)))
              backs.push_back(c);
        auto tf = std::chrono::steady_clock::now();
        estimator->sparse_element_rows(created, rows);
        if (!backs.empty()) estimator->sparse_back_rows(backs, back_rows);
        report.seconds_form_factors += seconds_since(tf);
        auto gather = [&](const SparseFactors& row) {
          Rgb h(0.0f);
          for (std::size_t k = 0; k < row.index.size(); ++k) h += row.value[k] * patch_B[row.index[k]];
          return h;
        };
        for (std::size_t k = 0; k < created.size(); ++k) H_elements[created[k]] = gather(rows[k]);
        for (std::size_t k = 0; k < backs.size(); ++k) H_back[backs[k]] = gather(back_rows[k]);
        for (std::uint32_t c : created) {
          const Material& mat = scene.material(hierarchy.patches()[hierarchy.element(c).patch].material);
          B_elements[c] = mat.emission + mat.reflectance * H_elements[c];
        }
        for (std::uint32_t c : backs) {
          const Material& mat = scene.material(hierarchy.patches()[hierarchy.element(c).patch].material);
          const Rgb tau = mat.diffuse_transmittance;
          B_elements[c] += tau * H_back[c];
          B_back[c] =
              detail::pass1_back_emission(mat) + detail::pass1_back_reflectance(mat) * H_back[c] + tau * H_elements[c];
        }
      }
    }
  }
  const double total = seconds_since(t1);
  report.seconds_solving = total - report.seconds_form_factors;
  report.element_count = hierarchy.leaves().size();

  // Power balance: a side absorbs what it neither reflects nor transmits, (1 - rho - tau) H.
  // With extended form factors the light that a mirror, window or glass passes on is counted
  // where it lands, so it is not absorbed at the specular surface, on either side (pass1_* are
  // channel means).
  glm::dvec3 emitted(0.0), absorbed(0.0);
  for (std::size_t i = 0; i < system->unknowns(); ++i) {
    const double a = system->area[i];
    emitted += a * glm::dvec3(system->emission[i]);
    double passed_on = 0.0;
    if (o.form_factors.specular_depth > 0) {
      const Material& m = scene.material(hierarchy.patches()[hierarchy.element(system->element(i)).patch].material);
      passed_on = static_cast<double>(detail::pass1_mirror(m) + detail::pass1_window(m) + detail::pass1_glass(m));
    }
    absorbed += a *
                glm::max(glm::dvec3(1.0 - passed_on) - glm::dvec3(system->reflectance[i]) -
                             glm::dvec3(system->transmittance[i]),
                         glm::dvec3(0.0)) *
                glm::dvec3(H_of(i));
  }
  report.emitted_power = Rgb(emitted);
  report.absorbed_power = Rgb(absorbed);
  report.escaped_power = Rgb(emitted - absorbed);
  // Inner nodes (split elements) hold the mean of their children from here on.
  hierarchy.aggregate(B_elements);
  if (translucency) hierarchy.aggregate(B_back);
  std::vector<Rgb> ambient_elements;
  if (r.ambient != Rgb(0.0f)) {
    // The ambient reaches both sides of a translucent element, and each side sends on
    // (rho + tau) of it; the backs' share is not displayed.
    ambient_elements.assign(hierarchy.elements().size(), Rgb(0.0f));
    for (std::size_t i = 0; i < system->fronts(); ++i)
      ambient_elements[system->leaves[i]] = (system->reflectance[i] + system->transmittance[i]) * r.ambient;
    hierarchy.aggregate(ambient_elements);
  }
  for (std::string& w : detail::escaped_light_warnings(scene, report.emitted_power, report.escaped_power,
                                                       status == SolveStatus::converged, o.threads))
    report.warnings.push_back(std::move(w));
  return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), status, std::move(report),
                  r.ambient, std::move(ambient_elements), std::move(B_back));
}

}  // namespace v1
}  // namespace radiosity
