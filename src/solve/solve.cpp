// The solve() facade: mesh, form factors, solver, Solution.
#include <chrono>
#include <cmath>
#include <string>

#include "formfactor/estimators.hpp"
#include "radiosity/solver.hpp"
#include "solve/system.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

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
  detail::resolve(o.form_factors);
}

Solution solve(const Scene& scene, const SolveOptions& options) {
  validate(options);
  if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "solve: the scene has no polygons");

  SolveOptions o = options;
  if (o.memory_budget_bytes == 0) o.memory_budget_bytes = kDefaultMemoryBudget;
  o.form_factors.seed = o.seed;
  o.form_factors.threads = o.threads;

  detail::ProgressGate gate(o.on_progress);
  SolveReport report;
  report.warnings = scene.warnings();

  auto t0 = std::chrono::steady_clock::now();
  PatchHierarchy hierarchy(scene, o.mesh);
  report.seconds_meshing = seconds_since(t0);
  report.patch_count = hierarchy.patches().size();
  report.element_count = hierarchy.leaves().size();
  if (o.max_iterations == 0)
    o.max_iterations = o.method == SolverMethod::progressive ? static_cast<int>(100 * report.patch_count) : 1000;

  detail::RadiositySystem system(scene, hierarchy);
  std::vector<Rgb> B_elements(hierarchy.elements().size(), Rgb(0.0f));
  std::vector<std::string> groups = scene.groups();

  if (!gate.report(Progress{Phase::meshing, 1.0, 0, 1.0}, true))
    return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), SolveStatus::cancelled,
                    std::move(report));

  if (system.emitted <= 0.0) {
    // Nothing emits: B = 0 is the exact answer.
    report.warnings.push_back("the scene emits no light; every radiosity is 0");
    return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), SolveStatus::converged,
                    std::move(report));
  }

  auto estimator = make_form_factor_estimator(scene, hierarchy, o.form_factors);
  detail::SolverContext context{scene, hierarchy, system, *estimator, o, gate};
  auto t1 = std::chrono::steady_clock::now();
  detail::SolverResult r = o.method == SolverMethod::progressive
                               ? detail::solve_progressive(context)
                               : detail::solve_matrix(context, o.method == SolverMethod::gauss_seidel);
  const double total = seconds_since(t1);

  report.iterations = r.iterations;
  report.residual = r.residual;
  report.residual_history = std::move(r.residual_history);
  report.time_history = std::move(r.time_history);
  report.form_factor_bytes = r.form_factor_bytes;
  report.seconds_form_factors = r.seconds_form_factors;
  report.seconds_solving = total - r.seconds_form_factors;
  glm::dvec3 emitted(0.0), absorbed(0.0);
  for (std::size_t i = 0; i < system.unknowns(); ++i) {
    const double a = system.area[i];
    emitted += a * glm::dvec3(system.emission[i]);
    absorbed += a * (glm::dvec3(1.0) - glm::dvec3(system.reflectance[i])) * glm::dvec3(r.H[i]);
    B_elements[system.leaves[i]] = r.B[i];
  }
  report.emitted_power = Rgb(emitted);
  report.absorbed_power = Rgb(absorbed);
  hierarchy.aggregate(B_elements);
  std::vector<Rgb> ambient_elements;
  if (r.ambient != Rgb(0.0f)) {
    ambient_elements.assign(hierarchy.elements().size(), Rgb(0.0f));
    for (std::size_t i = 0; i < system.unknowns(); ++i)
      ambient_elements[system.leaves[i]] = system.reflectance[i] * r.ambient;
    hierarchy.aggregate(ambient_elements);
  }
  return Solution(std::move(hierarchy), std::move(B_elements), std::move(groups), r.status, std::move(report),
                  r.ambient, std::move(ambient_elements));
}

}  // namespace v1
}  // namespace radiosity
