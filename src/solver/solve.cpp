// The solve() facade and the Problem it is made of: mesh once, make the estimator once, keep
// the form factors, and solve for the materials' emission or any other.
#include <chrono>
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>

#include "form_factors/estimators.hpp"
#include "scene/emission.hpp"
#include "core/memory_budget.hpp"
#include "scene/overlap.hpp"
#include "scene/winding_check.hpp"
#include "radiosity/render.hpp"
#include "radiosity/solver.hpp"
#include "scene/emitter_check.hpp"
#include "form_factors/pass1_material.hpp"
#include "solver/exposure.hpp"
#include "solver/hierarchical/link_hierarchy.hpp"
#include "solver/light_groups.hpp"
#include "solver/light_shot.hpp"
#include "solver/split_solve.hpp"
#include "solver/system.hpp"
#include "core/assert.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using detail::seconds_since;

/// Direct irradiance per front unknown, H_d(u) = sum over targets t of F(u -> t) E_t with E_t
/// the target's mean emission, plus the lights' first shot H_light(u): the light that arrives
/// straight from the emitters and the lights. The matrix
/// methods have every row in `store`; progressive refinement takes the emitting targets'
/// columns, from `columns` when it holds them for these leaves, else from the estimator.
/// Split among processes (Jacobi), each has the rows of its block of unknowns
/// (solve_matrix()): each computes its block, and the blocks are gathered. `exposure` as
/// SolverResult::exposure: the open parts' irradiance (the columns divided by it when
/// `divide_columns`, as solve_progressive() divides them).
std::vector<Rgb> direct_irradiance(const detail::RadiositySystem& sys, const FormFactorEstimator& estimator,
                                   bool progressive, const detail::MatrixStore& store,
                                   const detail::ColumnStore& columns, const detail::Communicator* split,
                                   const std::vector<float>& exposure, bool divide_columns) {
  std::vector<Rgb> patch_E;
  sys.patch_means(sys.emission, patch_E, sys.weights(exposure));
  std::vector<Rgb> out(sys.fronts(), Rgb(0.0f));
  if (!sys.light.empty())
    for (std::size_t u = 0; u < sys.fronts(); ++u) out[u] = sys.exposed_light(u, exposure);
  if (!progressive) {
    // The fronts of this process's block of unknowns (solve_matrix()'s), or all of them.
    std::vector<std::size_t> blocks = split ? detail::even_blocks(sys.unknowns(), split->size())
                                            : std::vector<std::size_t>{0, sys.unknowns()};
    for (std::size_t& b : blocks) b = std::min(b, sys.fronts());
    const std::size_t rank = split ? static_cast<std::size_t>(split->rank()) : 0;
    for (std::size_t u = blocks[rank]; u < blocks[rank + 1]; ++u) {
      const std::uint32_t slot = store.slot[sys.element(u)];
      RADIOSITY_ASSERT(slot != kNone);  // solve_matrix() made a row for every unknown of the block
      out[u] += store.rows[slot].dot(patch_E);
    }
    if (split) split->all_gather(out, blocks);
    return out;
  }
  const bool kept = columns.leaf_count == sys.fronts() && columns.columns.size() == sys.patches();
  std::vector<std::uint32_t> missing;
  // Columns are means over each receiver, as the progressive solve divides them (but the
  // hemicube's, its centre's).
  auto add = [&](std::uint32_t target, const detail::FactorVector& column) {
    column.for_each([&](std::size_t k, float f) {
      const std::uint32_t u = sys.column_unknown(k);
      if (u >= sys.fronts()) return;
      const bool open = divide_columns && !exposure.empty() && exposure[u] > 0.0f;
      out[u] += (open ? f / exposure[u] : f) * patch_E[target];
    });
  };
  for (std::uint32_t t = 0; t < sys.patches(); ++t) {
    if (patch_E[t] == Rgb(0.0f)) continue;
    if (kept && columns.cached[t])
      add(t, columns.columns[t]);
    else
      missing.push_back(t);
  }
  if (!missing.empty()) {
    std::vector<SparseFactors> fetched;
    estimator.sparse_patch_columns(missing, sys.leaves, fetched);
    for (std::size_t k = 0; k < missing.size(); ++k) {
      detail::FactorVector column;
      column.index = std::move(fetched[k].index);
      column.value = std::move(fetched[k].value);
      add(missing[k], column);
    }
  }
  return out;
}

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
  if (!(o.mesh.crease_angle_deg >= 0.0f && o.mesh.crease_angle_deg < 180.0f))
    throw Error(ErrorCode::invalid_argument,
                "mesh.crease_angle_deg must be in [0, 180) (0 = no vertices shared between polygons), got " +
                    std::to_string(o.mesh.crease_angle_deg));
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
  if (o.sky_rays < 5)
    throw Error(ErrorCode::invalid_argument, "sky_rays must be >= 5, got " + std::to_string(o.sky_rays));
  if (o.method == SolverMethod::hierarchical) {
    if (!(o.hierarchical.epsilon > 0.0f && o.hierarchical.epsilon <= 1.0f))
      throw Error(ErrorCode::invalid_argument,
                  "hierarchical.epsilon must be in (0, 1], got " + std::to_string(o.hierarchical.epsilon));
    if (o.hierarchical.max_passes < 1)
      throw Error(ErrorCode::invalid_argument,
                  "hierarchical.max_passes must be >= 1, got " + std::to_string(o.hierarchical.max_passes));
    if (o.form_factors.specular_depth > 0)
      throw Error(ErrorCode::invalid_argument,
                  "form_factors.specular_depth > 0 (mirror and window paths between diffuse surfaces) needs the "
                  "Monte Carlo rows of the matrix or progressive methods; SolverMethod::hierarchical's links do "
                  "not carry them");
  }
  detail::resolve(o.form_factors);
}

struct Problem::Impl {
  const Scene& scene;
  SolveOptions options;  ///< resolved (see Problem::options())
  /// SolverMethod::automatic: chosen by the first solve (choose_method()), said in every report.
  bool automatic_method = false;
  std::string method_choice;
  /// SpecularPaths::automatic: what the constructor and choose_method() did with the specular
  /// depth, and the estimator asked for before it (the drop back to depth 0 resolves that one).
  std::string specular_depth_choice;
  bool automatic_specular_paths = false;
  FormFactorMethod given_form_factors = FormFactorMethod::automatic;
  PatchHierarchy hierarchy;
  std::vector<std::string> warnings;  ///< the scene's and the z-fighting check's, for every report
  double seconds_meshing = 0.0;       ///< reported by the first solve only
  bool meshed_reported = false;
  /// The callback cancelled the meshing (in the constructor): every solve returns cancelled.
  bool meshing_cancelled = false;
  /// Adaptive subdivision's limits stay those of the initial mesh however often it refines.
  std::uint8_t initial_depth = 0;
  std::size_t initial_leaves = 0;
  std::unique_ptr<FormFactorEstimator> estimator;  ///< made by the first solve with emission
  detail::MatrixStore store;                       ///< the matrix methods' rows, kept
  detail::ColumnStore columns;                     ///< progressive refinement's columns, kept
  /// The lights' first shot (made by the first solve of a scene with lights) and its values per
  /// element, kept: the lights and the geometry do not change between solves.
  std::unique_ptr<detail::LightShooter> light_shooter;
  detail::LightShot light_shot;
  /// SolverMethod::hierarchical's links, kept (after light_shooter: they share its ray scene).
  std::unique_ptr<detail::LinkHierarchy> links;
  /// During a light group's solve: that group's lights alone (solve_light_groups()).
  const detail::LightShot* group_light_shot = nullptr;
  /// The processes a Jacobi solve is split among (detail::solve_split(), docs/MPI.md), or null.
  /// Split, every process holds the whole problem, computes the rows of its block of unknowns
  /// and its share of the lights' first shot and gathers the rest, so each returns the single process's
  /// solution; on_progress then never cancels at once (a process cannot stop alone): a cancel
  /// is agreed on at the end of the form factors and of each sweep.
  const detail::Communicator* processes = nullptr;

  Impl(const Scene& s, const SolveOptions& options, const detail::Communicator* split_among = nullptr);
  /// One solve; `emission` per polygon or null (the materials'). With `last` the hierarchy is
  /// moved into the Solution (the facade's single solve: no copy).
  Solution solve(const std::vector<Rgb>* emission, bool last);
  Solution solve_once(const std::vector<Rgb>* emission, bool last);
  /// Each light group's own solve (SolveOptions::separate_light_groups) on the current
  /// hierarchy, without refinement; empty when one is cancelled.
  std::vector<LightGroupSolution> solve_light_groups(const std::vector<Rgb>* emission);
  /// SpecularPaths::automatic, in the constructor: the extended first pass on a scene with
  /// mirror or glass materials, where the options let it run (SpecularPaths).
  void choose_specular_depth();
  /// SolverMethod::automatic, at the first solve: Gauss-Seidel while its rows fit the memory
  /// budget, else hierarchical (dropping specular paths under SpecularPaths::automatic; given
  /// ones need the rows). Makes the estimator.
  void choose_method();
  /// The Gauss-Seidel rows' bytes at most with the estimator (made here if there is none yet),
  /// and whether they are sparse.
  std::pair<std::size_t, bool> row_cost();
  /// What choose_method() costed: the rows' bytes, sparse or not, and their estimator.
  std::size_t costed_bytes = 0;
  bool costed_sparse = false;
  FormFactorMethod costed_method = FormFactorMethod::automatic;
  /// The lights' first shot for `elements` that lack it; false when cancelled.
  bool shoot_lights(const std::vector<std::uint32_t>& elements, detail::ProgressGate& gate);
  /// light_shooter->shoot(elements, shot, gate, only), or, split, each process's share of the
  /// elements that lack a value (dealt out in turn), gathered.
  bool shoot(const std::vector<std::uint32_t>& elements, detail::LightShot& shot, detail::ProgressGate& gate,
             const std::vector<char>* only = nullptr);
};

void Problem::Impl::choose_specular_depth() {
  SolveOptions& o = options;
  if (o.specular_paths != SpecularPaths::automatic || !needs_extended_first_pass(scene)) return;
  automatic_specular_paths = true;
  given_form_factors = o.form_factors.method;
  // A depth given is kept (with no choice to report), but under SolverMethod::automatic dropped
  // over the budget as a chosen one is (choose_method()).
  if (o.form_factors.specular_depth > 0) return;
  const FormFactorMethod f = o.form_factors.method;
  if (f != FormFactorMethod::automatic && f != FormFactorMethod::monte_carlo) {
    specular_depth_choice = std::string("0 (automatic: the ") + to_string(f) +
                            " estimator carries no mirror or glass paths; light reaching them stops there)";
    return;
  }
  if (o.method == SolverMethod::hierarchical) {
    specular_depth_choice = "0 (automatic: the hierarchical links carry no mirror or glass paths; light reaching them "
                            "stops there)";
    return;
  }
  // No photon pass follows a solve of its own, so the emitters' light through glass is counted
  // here; render_two_pass() leaves it out of its caustics (SolveReport::emitted_through_glass).
  o.form_factors.method = FormFactorMethod::monte_carlo;
  o.form_factors.specular_depth = 1;
  o.form_factors.emitted_through_glass = true;
  specular_depth_choice = "1 (automatic: the scene has mirror or glass materials)";
}

std::pair<std::size_t, bool> Problem::Impl::row_cost() {
  const SolveOptions& o = options;
  if (!estimator) estimator = make_form_factor_estimator(scene, hierarchy, o.form_factors);
  // The rows solve_matrix() would hold: one per leaf, and one per back of a translucent or
  // two-sided leaf (rows over every target, sparse).
  std::size_t rows = hierarchy.leaves().size();
  bool sparse = estimator->sparse();
  if (o.form_factors.diffuse_transmission) {
    std::vector<char> has_back(hierarchy.patches().size(), 0);
    for (std::uint32_t p : detail::find_back_patches(scene, hierarchy)) has_back[p] = 1;
    for (std::uint32_t e : hierarchy.leaves()) rows += has_back[hierarchy.element(e).patch] ? 1 : 0;
    sparse = true;
  }
  return {detail::row_memory_bytes(rows, estimator->target_count(), sparse, estimator->max_row_entries()), sparse};
}

void Problem::Impl::choose_method() {
  if (!automatic_method || !method_choice.empty()) return;
  SolveOptions& o = options;
  const auto [bytes, sparse] = row_cost();
  costed_bytes = bytes;
  costed_sparse = sparse;
  costed_method = o.form_factors.method;
  auto mib = [](std::size_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
  const std::string figure = mib(bytes) + (bytes > o.memory_budget_bytes ? ", over" : ", within") +
                             " the memory budget of " + mib(o.memory_budget_bytes);
  if (bytes > o.memory_budget_bytes && o.form_factors.specular_depth > 0 && automatic_specular_paths) {
    // The hierarchical links carry no specular paths: without them, rather than no solve.
    warnings.push_back("specular depth 0 after all: the rows with mirror and glass paths could need " + figure +
                       "; light reaching mirrors and glass stops there (SpecularPaths::automatic)");
    specular_depth_choice = "0 (automatic: the rows with mirror and glass paths could need " + figure + ")";
    o.form_factors.specular_depth = 0;
    o.form_factors.emitted_through_glass = false;
    // The estimator asked for before choose_specular_depth(), resolved at depth 0 (the report's).
    o.form_factors.method = given_form_factors;
    o.form_factors.method = choose_form_factor_method(hierarchy, o.form_factors);
  }
  if (bytes > o.memory_budget_bytes && o.form_factors.specular_depth == 0) {
    o.method = SolverMethod::hierarchical;
    estimator.reset();  // links need none
    method_choice = "the Gauss-Seidel rows could need " + figure;
  } else {
    method_choice = std::string("its rows need ") + (sparse ? "up to " : "") + figure;
  }
}

bool Problem::Impl::shoot_lights(const std::vector<std::uint32_t>& elements, detail::ProgressGate& gate) {
  if (scene.lights().empty()) return true;
  if (!light_shooter)
    light_shooter =
        std::make_unique<detail::LightShooter>(scene, hierarchy, options.seed, options.threads, options.sky_rays,
                                               options.form_factors.specular_depth > 0);
  return shoot(elements, light_shot, gate);
}

bool Problem::Impl::shoot(const std::vector<std::uint32_t>& elements, detail::LightShot& shot,
                          detail::ProgressGate& gate, const std::vector<char>* only) {
  if (!processes) return light_shooter->shoot(elements, shot, gate, only);
  // Every process has the same `done` flags, so the same elements to shoot. They are dealt out
  // in turn (element k to process k mod P): an element's cost varies by orders of magnitude (a
  // roof sees all the sky and needs no ray, a street between towers a thousand), and neighbours
  // in the list cost alike, so contiguous blocks would leave one process all the work. Who
  // shoots an element does not matter: each element side and light has its own stream.
  const std::vector<std::uint32_t> todo = shot.pending(elements, hierarchy.elements().size());
  const auto P = static_cast<std::size_t>(processes->size()), rank = static_cast<std::size_t>(processes->rank());
  // Process r shoots todo[r], todo[r + P], ...: a block of its own in the gathered arrays.
  std::vector<std::size_t> blocks(P + 1, 0);
  for (std::size_t r = 0; r < P; ++r) blocks[r + 1] = blocks[r] + (todo.size() + P - 1 - r) / P;
  std::vector<std::uint32_t> mine;
  for (std::size_t k = rank; k < todo.size(); k += P) mine.push_back(todo[k]);
  const std::uint64_t rays = shot.rays;
  const bool completed = light_shooter->shoot(mine, shot, gate, only);
  std::vector<Rgb> front(todo.size(), Rgb(0.0f)), back(todo.size(), Rgb(0.0f));
  for (std::size_t j = 0; j < mine.size(); ++j) {
    front[blocks[rank] + j] = shot.front[mine[j]];
    back[blocks[rank] + j] = shot.back[mine[j]];
  }
  processes->all_gather(front, blocks);
  processes->all_gather(back, blocks);
  for (std::size_t r = 0; r < P; ++r)
    for (std::size_t j = 0; j < blocks[r + 1] - blocks[r]; ++j) {
      const std::uint32_t e = todo[r + j * P];
      shot.front[e] = front[blocks[r] + j];
      shot.back[e] = back[blocks[r] + j];
      shot.done[e] = 1;
    }
  shot.rays = rays + processes->sum(shot.rays - rays);
  return completed;
}

Problem::Impl::Impl(const Scene& s, const SolveOptions& given, const detail::Communicator* split_among)
    : scene(s), options(given), processes(split_among) {
  validate(given);
  if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "solve: the scene has no polygons");

  SolveOptions& o = options;
  if (processes) {
    // A process cannot stop alone (the others would wait for it): the callback's cancel is
    // remembered and agreed on at the end of the form factors and of each sweep.
    if (o.method != SolverMethod::jacobi)
      throw Error(ErrorCode::invalid_argument,
                  "mpi::solve: method must be SolverMethod::jacobi, the one whose sweeps split among processes bit "
                  "for bit (Gauss-Seidel's sweep runs through the unknowns in turn; progressive and hierarchical "
                  "are not split)");
    if (o.on_progress)
      o.on_progress = [callback = given.on_progress, split_among](const Progress& p) {
        if (!callback(p)) split_among->cancel_requested = true;
        return true;
      };
  }
  o.memory_budget_bytes = detail::resolve_memory_budget(o.memory_budget_bytes);
  // Automatic starts as Gauss-Seidel; the first solve, which knows the rows' size, may switch.
  if (o.method == SolverMethod::automatic) {
    automatic_method = true;
    o.method = SolverMethod::gauss_seidel;
  }
  // Translucent and two-sided materials in use switch the back sides on.
  for (const Polygon& polygon : scene.polygons())
    if (detail::pass1_has_back(scene.material(polygon.material))) {
      o.form_factors.diffuse_transmission = true;
      break;
    }
  o.form_factors.seed = o.seed;
  // The estimator inherits the solve's thread count unless it was given one of its own.
  if (o.form_factors.threads == 0) o.form_factors.threads = o.threads;

  // Meshing, and the z-fighting check before it, report Phase::meshing and can be cancelled
  // (then every solve returns cancelled).
  ProgressFn meshing_progress;
  if (o.on_progress)
    meshing_progress = [this](const Progress& p) {
      if (options.on_progress(p)) return true;
      meshing_cancelled = true;
      return false;
    };
  detail::ProgressGate gate(meshing_progress);
  auto t0 = std::chrono::steady_clock::now();
  warnings = scene.warnings();
  if (gate.report(Progress{Phase::meshing, 0.0}, true)) {
    // Contact and interpenetration are lit correctly; only same-facing coincident surfaces are
    // ambiguous.
    const detail::KeepGoing poll = [&] { return gate.report(Progress{Phase::meshing, 0.0}); };
    for (std::string& w : detail::z_fighting_warnings(scene, meshing_progress ? poll : detail::KeepGoing()))
      warnings.push_back(std::move(w));
    // A face of a mesh wound against its neighbours comes out black with no other sign.
    // (Not after a cancel seen by the overlap search: the callback is called no more then.)
    if (!meshing_cancelled) {
      const InconsistentWinding inconsistent =
          detail::inconsistent_winding(scene, meshing_progress ? poll : detail::KeepGoing());
      for (std::string& w : detail::inconsistent_winding_warnings(scene, inconsistent)) warnings.push_back(std::move(w));
    }
  }
  if (!meshing_cancelled)
    hierarchy = meshing_progress ? PatchHierarchy(scene, o.mesh, meshing_progress) : PatchHierarchy(scene, o.mesh);
  seconds_meshing = seconds_since(t0);
  choose_specular_depth();
  o.form_factors.method = choose_form_factor_method(hierarchy, o.form_factors);
  if (o.max_iterations == 0)
    o.max_iterations =
        o.method == SolverMethod::progressive ? static_cast<int>(100 * hierarchy.patches().size()) : 1000;
  for (std::uint32_t e : hierarchy.leaves()) initial_depth = std::max(initial_depth, hierarchy.element(e).depth);
  initial_leaves = hierarchy.leaves().size();
}

namespace {

/// The scene's meshes as a Solution keeps them (SolvedMesh).
std::vector<SolvedMesh> solved_meshes(const Scene& scene) {
  std::vector<SolvedMesh> out;
  out.reserve(scene.meshes().size());
  for (const Mesh& m : scene.meshes()) out.push_back(SolvedMesh{m.positions, m.indices, m.triangle_polygon});
  return out;
}

}  // namespace

Solution Problem::Impl::solve(const std::vector<Rgb>* emission, bool last) {
  // With light groups the hierarchy is needed after the joint solve, which therefore gets a copy.
  const bool groups = options.separate_light_groups;
  Solution solution = solve_once(emission, last && !groups);
  if (groups && solution.status() != SolveStatus::cancelled) solution.set_light_groups(solve_light_groups(emission));
  // Cancelled while meshing, the solution has no elements, and nothing to align with the
  // meshes (whose copy would take a host's million triangles some 0.1 s after the cancel).
  if (!meshing_cancelled) solution.set_meshes(solved_meshes(scene));
  solution.set_origin(scene.origin());
  return solution;
}

std::vector<LightGroupSolution> Problem::Impl::solve_light_groups(const std::vector<Rgb>* emission) {
  // Superposition: B is linear in the sources, so each group's solve with only its emitters and
  // lights on gives its share, and the shares add up to the joint solve. The matrix methods'
  // rows and progressive refinement's columns are kept, so a group's solve is its sweeps (or
  // its shots) only; a group's lights are shot again on their own (each light's value is the
  // same as in the joint shot: its own random stream).
  const std::vector<Polygon>& polygons = scene.polygons();
  const std::vector<Light>& lights = scene.lights();
  const std::vector<detail::LightGroupMembers> groups = detail::light_group_members(scene, emission);

  // The joint solve refined the hierarchy; the groups are solved on it as it is.
  struct KeepAdaptive {
    SolveOptions& o;
    AdaptiveOptions saved;
    const detail::LightShot*& group_shot;
    ~KeepAdaptive() {
      o.adaptive = saved;
      group_shot = nullptr;
    }
  } keep{options, options.adaptive, group_light_shot};
  options.adaptive.enabled = false;
  detail::ProgressGate gate(options.on_progress);
  std::vector<LightGroupSolution> out;
  std::vector<Rgb> group_emission(polygons.size());
  detail::LightShot shot;
  for (const detail::LightGroupMembers& g : groups) {
    for (PolygonId p = 0; p < polygons.size(); ++p)
      group_emission[p] = g.groups[polygons[p].group] ? detail::polygon_emission(scene, p, emission) : Rgb(0.0f);
    if (!lights.empty()) {
      shot = detail::LightShot{};
      if (!light_shooter && !shoot_lights({}, gate)) return {};  // makes the shooter
      if (!shoot(hierarchy.leaves(), shot, gate, &g.lights)) return {};
      group_light_shot = &shot;
    }
    const Solution part = solve_once(&group_emission, false);
    if (part.status() == SolveStatus::cancelled) return {};
    out.push_back(LightGroupSolution{g.name, part.radiosity(), part.back_radiosity(), part.irradiance(),
                                     part.direct_irradiance()});
  }
  return out;
}

Solution Problem::Impl::solve_once(const std::vector<Rgb>* emission, bool last) {
  const SolveOptions& o = options;
  detail::ProgressGate gate(o.on_progress);
  SolveReport report;
  report.warnings = warnings;
  report.seconds_meshing = meshed_reported ? 0.0 : seconds_meshing;
  report.patch_count = hierarchy.patches().size();
  report.element_count = hierarchy.leaves().size();
  report.specular_depth = o.form_factors.specular_depth;
  report.form_factor_method = o.form_factors.method;
  report.method = o.method;
  // The Solution owns its hierarchy: the facade's only solve hands over this one, a kept
  // Problem a copy.
  auto result_hierarchy = [&] { return last ? std::move(hierarchy) : PatchHierarchy(hierarchy); };

  const bool translucency = o.form_factors.diffuse_transmission;
  const bool lights = !scene.lights().empty();
  const detail::LightShot* light_shot_of = !lights ? nullptr : group_light_shot ? group_light_shot : &light_shot;
  std::vector<Rgb> B_elements(hierarchy.elements().size(), Rgb(0.0f));
  // Per element id, with diffuse transmission: the backs' radiosity (empty without).
  std::vector<Rgb> B_back(translucency ? hierarchy.elements().size() : 0, Rgb(0.0f));
  std::vector<std::string> groups = scene.groups();

  // The meshing phase was reported by the constructor.
  meshed_reported = true;
  if (meshing_cancelled) {
    std::vector<Rgb> no_irradiance(hierarchy.elements().size(), Rgb(0.0f));
    return Solution(result_hierarchy(), std::move(B_elements), std::move(groups), SolveStatus::cancelled,
                    std::move(report), Rgb(0.0f), {}, std::move(B_back), std::move(no_irradiance));
  }

  // The matrix methods' memory is known before the lights' first shot, which can take as long
  // as the form factors: a scene that cannot fit is refused at once, by the figure
  // solve_matrix() would give (one row per leaf; with backs, whose rows solve_matrix() counts
  // itself, only there).
  choose_method();
  report.method = o.method;
  report.method_choice = method_choice;
  report.warnings = warnings;  // choose_method() may add one
  report.specular_depth = o.form_factors.specular_depth;
  report.emitted_through_glass = o.form_factors.specular_depth > 0 && o.form_factors.emitted_through_glass;
  report.specular_depth_choice = specular_depth_choice;
  report.form_factor_method = o.form_factors.method;
  const bool hierarchical = o.method == SolverMethod::hierarchical;
  if (!estimator && !hierarchical) estimator = make_form_factor_estimator(scene, hierarchy, o.form_factors);
  if (o.method != SolverMethod::progressive && !hierarchical && store.rows.empty() && !translucency) {
    // Split, a process holds the rows of its block only.
    const std::size_t leaves = hierarchy.leaves().size();
    std::size_t rows = leaves;
    if (processes) {
      const std::vector<std::size_t> blocks = detail::even_blocks(leaves, processes->size());
      const auto rank = static_cast<std::size_t>(processes->rank());
      rows = blocks[rank + 1] - blocks[rank];
    }
    detail::check_row_memory(rows, leaves, estimator->target_count(), estimator->sparse(),
                             estimator->max_row_entries(), o.memory_budget_bytes);
  }

  // The lights' first shot (once per Problem): their direct irradiance on every element.
  const double light_seconds = light_shot.seconds;
  const std::uint64_t light_rays = light_shot.rays;
  const bool shot = group_light_shot != nullptr || shoot_lights(hierarchy.leaves(), gate);
  report.seconds_lights = light_shot.seconds - light_seconds;
  report.light_rays = light_shot.rays - light_rays;
  if (!shot) {
    std::vector<Rgb> no_irradiance(hierarchy.elements().size(), Rgb(0.0f));
    return Solution(result_hierarchy(), std::move(B_elements), std::move(groups), SolveStatus::cancelled,
                    std::move(report), Rgb(0.0f), {}, std::move(B_back), std::move(no_irradiance));
  }
  std::optional<detail::RadiositySystem> system(std::in_place, scene, hierarchy, translucency, emission, light_shot_of);

  if (system->emitted <= 0.0) {
    // Nothing emits and no light reaches a surface: B = 0 is the exact answer.
    report.warnings.push_back(lights ? "nothing emits and the scene's lights reach no surface (the back of a "
                                       "one-sided polygon absorbs what reaches it: check the winding, or use "
                                       "two-sided materials); every radiosity is 0"
                                     : "the scene emits no light; every radiosity is 0");
    std::vector<Rgb> no_irradiance(hierarchy.elements().size(), Rgb(0.0f));
    std::vector<Rgb> no_direct = no_irradiance;
    return Solution(result_hierarchy(), std::move(B_elements), std::move(groups), SolveStatus::converged,
                    std::move(report), Rgb(0.0f), {}, std::move(B_back), std::move(no_irradiance),
                    std::move(no_direct));
  }

  // Both number the backs with find_back_patches().
  RADIOSITY_ASSERT(hierarchical || estimator->target_count() == system->patches());
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
  // Kept per element side (2 e + 1 for its back), as unknowns are renumbered when leaves split;
  // empty when the solver has none.
  std::vector<float> side_exposure;
  // Per unknown of the system as it stands, from side_exposure (empty: every side open).
  auto current_exposure = [&] {
    std::vector<float> x;
    if (side_exposure.empty()) return x;
    x.resize(system->unknowns());
    for (std::size_t u = 0; u < x.size(); ++u) {
      const std::size_t k = 2 * std::size_t{system->element(u)} + (u < system->fronts() ? 0 : 1);
      x[u] = k < side_exposure.size() ? side_exposure[k] : 1.0f;
    }
    return x;
  };
  // Per element id, the share of it that is not buried (Solution::exposure()), from `per_unknown`
  // (current_exposure()): the leaves' fronts, inner nodes their children's area-weighted mean;
  // empty when the solver has none.
  auto exposure_by_element = [&](const std::vector<float>& per_unknown) {
    std::vector<float> out;
    if (per_unknown.empty()) return out;
    out.assign(hierarchy.elements().size(), 1.0f);
    for (std::size_t u = 0; u < system->fronts(); ++u) out[system->leaves[u]] = per_unknown[u];
    for (std::size_t e = out.size(); e-- > 0;) {  // children before parents
      const Element& el = hierarchy.element(static_cast<std::uint32_t>(e));
      if (el.is_leaf()) continue;
      double area = 0.0, open = 0.0;
      for (std::uint32_t k = 0; k < 4; ++k) {
        const double a = hierarchy.element(el.first_child + k).area;
        area += a;
        open += a * static_cast<double>(out[el.first_child + k]);
      }
      out[e] = area > 0.0 ? static_cast<float>(open / area) : 1.0f;
    }
    return out;
  };
  // Side u's values, per element id.
  auto B_of = [&](std::size_t u) -> Rgb& { return (u < system->fronts() ? B_elements : B_back)[system->element(u)]; };
  auto H_of = [&](std::size_t u) -> Rgb& { return (u < system->fronts() ? H_elements : H_back)[system->element(u)]; };
  // Per unknown, the share of it that is not buried, where the solver has it (every method but
  // over analytic rows: RadiositySystem::Weights); B and H are the open parts'.
  auto keep = [&](const detail::SolverResult& res) {
    resize();
    side_exposure.clear();
    if (!res.exposure.empty()) {
      side_exposure.assign(2 * hierarchy.elements().size(), 1.0f);
      for (std::size_t u = 0; u < system->unknowns(); ++u)
        side_exposure[2 * std::size_t{system->element(u)} + (u < system->fronts() ? 0 : 1)] = res.exposure[u];
    }
    const std::vector<float>& exposure = res.exposure;
    // The solvers' irradiance is from surfaces; the lights' first shot arrives as well.
    for (std::size_t i = 0; i < system->unknowns(); ++i) {
      B_of(i) = res.B[i];
      H_of(i) = system->light.empty() ? res.H[i] : res.H[i] + system->exposed_light(i, exposure);
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

  // New leaves (the children of `split`, just subdivided) become unknowns: they start from
  // their parent's values (a warm start), get their share of the lights, and the system is
  // made again. False when the lights' shot was cancelled.
  auto adopt_children = [&](const std::vector<std::uint32_t>& split) {
    std::vector<std::uint32_t> created;
    for (std::uint32_t e : split)
      for (std::uint32_t c = hierarchy.element(e).first_child; c < hierarchy.element(e).first_child + 4; ++c)
        created.push_back(c);
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
    // The new leaves' share of the lights (their parents' values averaged them).
    const double before = light_shot.seconds;
    const std::uint64_t rays_before = light_shot.rays;
    const bool lit = shoot_lights(created, gate);
    report.seconds_lights += light_shot.seconds - before;
    report.light_rays += light_shot.rays - rays_before;
    if (!lit) {
      // Cancelled: the parents' values stand for their children in this solution's balance
      // (a later solve computes them).
      for (std::uint32_t c : created) {
        const std::uint32_t parent = hierarchy.element(c).parent;
        light_shot.done[c] = 0;
        light_shot.front[c] = light_shot.front[parent];
        light_shot.back[c] = light_shot.back[parent];
      }
    }
    system.emplace(scene, hierarchy, translucency, emission, light_shot_of);
    return std::make_pair(lit, std::move(created));
  };
  // Side values per unknown, for a warm start.
  auto current_B = [&] {
    std::vector<Rgb> B0(system->unknowns());
    for (std::size_t i = 0; i < system->unknowns(); ++i) B0[i] = B_of(i);
    return B0;
  };

  detail::SolverResult r;
  SolveStatus status = SolveStatus::converged;
  if (hierarchical) {
    // Links refined against the emitted light, solved, refined again against the solution
    // (multigridding) until no link changes (docs/HIERARCHICAL.md).
    if (!links)
    {
      links = std::make_unique<detail::LinkHierarchy>(scene, o.seed, o.threads,
                                                      light_shooter ? &light_shooter->occluders() : nullptr);
      links->set_memory_budget(o.memory_budget_bytes, "SolveOptions::memory_budget_bytes");
      links->set_balancing(o.hierarchical.balance_closed_regions);
    }
    detail::SubdivisionLimits limits;
    if (o.adaptive.enabled) {
      limits.max_depth = static_cast<std::uint8_t>(std::min(250, initial_depth + o.adaptive.max_depth));
      limits.max_leaves = o.adaptive.max_elements > 0 ? o.adaptive.max_elements : 4 * initial_leaves;
    }
    std::vector<Rgb> B_now = system->source;
    // held: an earlier pass's sweeps grew and were held (the maximum principle); later passes
    // start held, and the warning below is given once.
    bool solved = false, held = false;
    // The oracle's scale: the scene's mean radiosity estimate, power emitted (lights
    // included) per area times the mean interreflection factor.
    auto radiosity_scale = [&] {
      double source_power = 0.0;
      for (std::size_t u = 0; u < system->unknowns(); ++u)
        source_power += system->area[u] * (system->source[u].x + system->source[u].y + system->source[u].z) / 3.0;
      const Rgb& k = system->interreflection;
      return source_power / system->total_area * (k.x + k.y + k.z) / 3.0;
    };
    for (int pass = 1; pass <= o.hierarchical.max_passes; ++pass) {
      const auto threshold = static_cast<float>(o.hierarchical.epsilon * radiosity_scale());
      std::vector<std::uint32_t> split;
      detail::RefineStats stats;
      const auto tf = std::chrono::steady_clock::now();
      const bool refined = links->refine(hierarchy, *system, B_now, threshold, limits, gate, split, stats);
      report.seconds_form_factors += seconds_since(tf);
      report.link_pairs_examined += stats.examined;
      report.link_rays += stats.rays;
      bool lit = true;
      if (!split.empty()) {
        lit = adopt_children(split).first;
        report.refined_elements += split.size();
      }
      if (!refined || !lit) {
        status = SolveStatus::cancelled;
        if (!solved) {
          // Nothing solved yet: the emitted light alone is this solution (consistent).
          r = detail::SolverResult{};
          r.B = system->source;
          r.H.assign(system->unknowns(), Rgb(0.0f));
          keep(r);
        }
        break;
      }
      if (solved && split.empty() && stats.links_replaced == 0) break;  // nothing changed
      report.refinement_passes = pass;
      detail::SolverContext context{scene, hierarchy, *system, nullptr, o, gate, nullptr};
      r = links->solve(context, solved ? current_B() : std::vector<Rgb>{}, held, false);
      if (r.held && !held) {
        held = true;
        report.warnings.push_back(
            "hierarchical: the links passed on more light than they received (a closed region of reflectance near 1, "
            "or coincident surfaces seen twice), so the sweeps grew; they were run again with each irradiance held "
            "to the largest radiosity it comes from (the maximum principle), which bounds them but biases the "
            "radiosity low by up to a few per cent: SolverMethod::gauss_seidel (where its rows fit), a smaller "
            "hierarchical.epsilon or lower reflectances avoid it");
      }
      keep(r);
      status = r.status;
      solved = true;
      if (status == SolveStatus::cancelled) break;
      B_now = r.B;
    }
    // The final gather: the irradiance of the radiosity kept, once, with the links as they
    // stand (those of its solve, or after a cancelled pass those restored, over any elements it
    // split), each leaf taking the links into its ancestors by the kernel at the leaf and
    // shadow rays to it rather than the sweeps' linear push, and the radiosity it gives
    // (B = E + rho H + tau H'): one sweep more, for the display (docs/HIERARCHICAL.md, "The
    // final gather", "Visibility per leaf"). The passes'
    // solves leave it to here, each a gather fewer (the 246k city's three passes: 9 gathers
    // -> 7).
    if (solved) {
      std::uint64_t gather_rays = 0;
      const std::vector<Rgb> H = links->final_gather(hierarchy, *system, current_B(),
                                                     static_cast<float>(radiosity_scale()), held, &gather_rays);
      report.gather_rays += gather_rays;
      const std::vector<float> exposure = current_exposure();
      const std::vector<Rgb> source = system->exposed_source(exposure);
      for (std::size_t i = 0; i < system->unknowns(); ++i) {
        H_of(i) = system->light.empty() ? H[i] : H[i] + system->exposed_light(i, exposure);
        B_of(i) = system->radiosity_of(i, source[i], H);
      }
    }
    report.link_count = links->link_count();
    report.form_factor_bytes = std::max(report.form_factor_bytes, links->bytes());
  } else {
    detail::SolverContext context{scene, hierarchy, *system, estimator.get(), o, gate, processes};
    r = progressive ? detail::solve_progressive(context, columns)
                    : detail::solve_matrix(context, o.method == SolverMethod::gauss_seidel, store, {});
    keep(r);
    status = r.status;
  }

  if (o.adaptive.enabled && !hierarchical && status != SolveStatus::cancelled) {
    const auto max_depth = static_cast<std::uint8_t>(std::min(250, initial_depth + o.adaptive.max_depth));
    const std::size_t budget =
        o.adaptive.max_elements > 0 ? o.adaptive.max_elements : 4 * initial_leaves;
    for (int pass = 1; pass <= o.adaptive.max_passes; ++pass) {
      const std::vector<std::uint32_t> split = detail::leaves_to_refine(
          hierarchy, B_elements, exposure_by_element(current_exposure()), o.adaptive, max_depth, budget);
      if (split.empty()) break;
      for (std::uint32_t e : split) {
        store.release(e);
        hierarchy.subdivide(e);
      }
      report.refined_elements += split.size();
      report.refinement_passes = pass;
      auto [lit, created] = adopt_children(split);
      if (!lit) {
        status = SolveStatus::cancelled;
        break;
      }
      Progress p{Phase::refining, static_cast<double>(pass) / o.adaptive.max_passes, pass, report.residual};
      if (!gate.report(p, true)) {
        status = SolveStatus::cancelled;
        break;
      }

      if (!progressive) {
        // Matrix methods: rows for the new elements only, then sweeps from the warm start.
        detail::SolverContext context{scene, hierarchy, *system, estimator.get(), o, gate, processes};
        r = detail::solve_matrix(context, o.method == SolverMethod::gauss_seidel, store, current_B());
        keep(r);
        status = r.status;
        if (status == SolveStatus::cancelled) break;
      } else {
        // Progressive: substructuring's gather. Each new element takes its radiosity from the
        // target radiosities it sees, B_c = E_c + rho_c H_c (+ tau_c H_c' with a back), with
        // H_c = sum_t F_ct B_t over its front row (and H_c' over its back row); no matrix is kept.
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
        // Where the solve measured exposure, the new leaves' comes from their rows, and their
        // values are their open parts' (RadiositySystem::Weights).
        if (!side_exposure.empty()) {
          side_exposure.resize(2 * hierarchy.elements().size(), 1.0f);
          for (std::size_t k = 0; k < created.size(); ++k)
            side_exposure[2 * std::size_t{created[k]}] = detail::effective_exposure(rows[k].exposed);
          for (std::size_t k = 0; k < backs.size(); ++k)
            side_exposure[2 * std::size_t{backs[k]} + 1] = detail::effective_exposure(back_rows[k].exposed);
        }
        const std::vector<float> exposure = current_exposure();
        const std::vector<Rgb> source = system->exposed_source(exposure);
        std::vector<Rgb> patch_B;
        std::vector<Rgb> B_now(system->unknowns());
        for (std::size_t i = 0; i < system->unknowns(); ++i) B_now[i] = B_of(i);
        system->patch_means(B_now, patch_B, system->weights(exposure));
        auto gather = [&](const SparseFactors& row, std::size_t u) {
          Rgb h(0.0f);
          for (std::size_t k = 0; k < row.index.size(); ++k) h += row.value[k] * patch_B[row.index[k]];
          return !exposure.empty() && exposure[u] > 0.0f ? h / exposure[u] : h;
        };
        for (std::size_t k = 0; k < created.size(); ++k)
          H_elements[created[k]] = gather(rows[k], hierarchy.leaf_index(created[k]));
        for (std::size_t k = 0; k < backs.size(); ++k)
          H_back[backs[k]] = gather(back_rows[k], system->twin[hierarchy.leaf_index(backs[k])]);
        // The system's source is E_c (with the lights' first shot, rho and tau of it).
        for (std::uint32_t c : created) {
          const std::uint32_t u = hierarchy.leaf_index(c);
          B_elements[c] = source[u] + system->reflectance[u] * H_elements[c];
        }
        for (std::uint32_t c : backs) {
          const std::uint32_t u = hierarchy.leaf_index(c), back = system->twin[u];
          B_elements[c] += system->transmittance[u] * H_back[c];
          B_back[c] = source[back] + system->reflectance[back] * H_back[c] + system->transmittance[back] * H_elements[c];
        }
        if (!system->light.empty()) {
          for (std::uint32_t c : created) H_elements[c] += system->exposed_light(hierarchy.leaf_index(c), exposure);
          for (std::uint32_t c : backs)
            H_back[c] += system->exposed_light(system->twin[hierarchy.leaf_index(c)], exposure);
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
  // The lights count as emitted with the power they put onto the sides (docs/LIGHTS.md).
  const std::vector<float> final_exposure = current_exposure();
  glm::dvec3 emitted(0.0), absorbed(0.0), lit(0.0);
  for (std::size_t i = 0; i < system->unknowns(); ++i) {
    const double a = system->area[i];
    emitted += a * glm::dvec3(system->emission[i]);
    if (!system->light.empty()) {
      lit += a * glm::dvec3(system->light[i]);
      emitted += a * glm::dvec3(system->light[i]);
    }
    double passed_on = 0.0;
    if (o.form_factors.specular_depth > 0) {
      const Material& m = scene.material(hierarchy.patches()[hierarchy.element(system->element(i)).patch].material);
      passed_on = static_cast<double>(detail::pass1_mirror(m) + detail::pass1_window(m) + detail::pass1_glass(m));
    }
    // Over the open part only: H_of is its irradiance.
    const double open = final_exposure.empty() ? a : a * static_cast<double>(final_exposure[i]);
    absorbed += open *
                glm::max(glm::dvec3(1.0 - passed_on) - glm::dvec3(system->reflectance[i]) -
                             glm::dvec3(system->transmittance[i]),
                         glm::dvec3(0.0)) *
                glm::dvec3(H_of(i));
  }
  report.emitted_power = Rgb(emitted);
  report.light_power = Rgb(lit);
  report.absorbed_power = Rgb(absorbed);
  report.escaped_power = Rgb(emitted - absorbed);
  // Inner nodes' values are then their open parts' means, as the leaves' are.
  std::vector<float> element_exposure = exposure_by_element(final_exposure);
  auto aggregate = [&](std::vector<Rgb>& values) {
    if (element_exposure.empty())
      hierarchy.aggregate(values);
    else
      detail::aggregate_open(hierarchy, values, [&](std::uint32_t e) { return element_exposure[e]; });
  };

  // What arrived straight from the emitters; not for a cancelled solve, which may lack rows.
  std::vector<Rgb> H_direct;
  if (status != SolveStatus::cancelled) {
    std::vector<Rgb> direct;
    if (hierarchical) {
      // What the emitters alone send along the links, plus the lights' first shot.
      direct = links->irradiance(hierarchy, *system, system->emission);
      direct.resize(system->fronts());
      if (!system->light.empty())
        for (std::size_t u = 0; u < system->fronts(); ++u) direct[u] += system->exposed_light(u, final_exposure);
    } else {
      direct = direct_irradiance(*system, *estimator, progressive, store, columns, processes, final_exposure,
                                 o.form_factors.method != FormFactorMethod::hemicube);
    }
    H_direct.assign(hierarchy.elements().size(), Rgb(0.0f));
    for (std::size_t u = 0; u < system->fronts(); ++u) H_direct[system->leaves[u]] = direct[u];
    aggregate(H_direct);
  }
  // Inner nodes (split elements) hold the mean of their children from here on.
  aggregate(B_elements);
  aggregate(H_elements);
  if (translucency) aggregate(B_back);
  std::vector<Rgb> ambient_elements;
  if (r.ambient != Rgb(0.0f)) {
    // The ambient reaches both sides of a translucent element, and each side sends on
    // (rho + tau) of it; the backs' share is not displayed.
    ambient_elements.assign(hierarchy.elements().size(), Rgb(0.0f));
    for (std::size_t i = 0; i < system->fronts(); ++i)
      ambient_elements[system->leaves[i]] = (system->reflectance[i] + system->transmittance[i]) * r.ambient;
    hierarchy.aggregate(ambient_elements);
  }
  // The balance tells outward winding from an open scene only for the emitters' light: the
  // lights' reflected light leaves open scenes (a sunlit courtyard) as a matter of course, and
  // their light that meets the backs of one-sided polygons is not counted at all.
  const bool balance_diagnoses = status == SolveStatus::converged && report.light_power == Rgb(0.0f);
  for (std::string& w : detail::escaped_light_warnings(scene, report.emitted_power, report.escaped_power,
                                                       balance_diagnoses, o.threads, emission))
    report.warnings.push_back(std::move(w));
  // The links lose or gain a few per cent of what they carry (docs/HIERARCHICAL.md, "A room as
  // an exporter writes it"), which in a closed scene of reflectance near 1 becomes many per cent
  // of the radiosity; there no light can leave, so the balance's "escaped" measures it. Gains
  // are held (the warning above); losses are said here, once they pass 1 % of the emitted power.
  if (hierarchical && status == SolveStatus::converged && r.B.size() == system->unknowns()) {
    const double sent = (emitted.x + emitted.y + emitted.z) / 3.0;
    const double lost = (emitted.x + emitted.y + emitted.z - absorbed.x - absorbed.y - absorbed.z) / 3.0;
    if (sent > 0.0 && lost > 0.01 * sent && links->enclosed_power_share(hierarchy, *system, r.B) > 0.99) {
      char share[32];
      std::snprintf(share, sizeof share, "%.1f", 100.0 * lost / sent);
      report.warnings.push_back(
          std::string("hierarchical: ") + share +
          " % of the emitted power is unaccounted for, though the surfaces that send the light are enclosed (no light "
          "can leave): the links lost it, and every bounce compounds the loss (near reflectance 1 the radiosity comes "
          "out many times that per cent low); SolverMethod::gauss_seidel (where its rows fit) or a smaller "
          "hierarchical.epsilon is more accurate");
    }
  }
  if (status == SolveStatus::converged)
    for (std::string& w : detail::back_lit_warnings(scene, hierarchy, B_elements, B_back))
      report.warnings.push_back(std::move(w));
  Solution out(result_hierarchy(), std::move(B_elements), std::move(groups), status, std::move(report), r.ambient,
               std::move(ambient_elements), std::move(B_back), std::move(H_elements), std::move(H_direct));
  if (!element_exposure.empty()) out.set_exposure(std::move(element_exposure));
  return out;
}

Problem::Problem(const Scene& scene, const SolveOptions& options) : impl_(std::make_unique<Impl>(scene, options)) {}
Problem::~Problem() = default;
Problem::Problem(Problem&&) noexcept = default;
Problem& Problem::operator=(Problem&&) noexcept = default;

const Scene& Problem::scene() const { return impl_->scene; }
const SolveOptions& Problem::options() const { return impl_->options; }
const PatchHierarchy& Problem::hierarchy() const { return impl_->hierarchy; }
std::size_t Problem::form_factor_bytes() const {
  return impl_->store.bytes() + impl_->columns.bytes + (impl_->links ? impl_->links->bytes() : 0);
}

SolvePlan Problem::plan() {
  Impl& m = *impl_;
  const SolveOptions& o = m.options;
  SolvePlan plan;
  if (!m.meshing_cancelled) {
    if (m.automatic_method) {
      m.choose_method();
      plan.row_bytes = m.costed_bytes;
      plan.sparse_rows = m.costed_sparse;
      plan.row_form_factor_method = m.costed_method;
    } else if (o.method == SolverMethod::gauss_seidel || o.method == SolverMethod::jacobi) {
      std::tie(plan.row_bytes, plan.sparse_rows) = m.row_cost();
      plan.row_form_factor_method = o.form_factors.method;
    }
  }
  plan.method = o.method;
  plan.method_choice = m.method_choice;
  plan.form_factor_method = o.form_factors.method;
  plan.specular_depth = o.form_factors.specular_depth;
  plan.specular_depth_choice = m.specular_depth_choice;
  return plan;
}

Solution Problem::solve() { return impl_->solve(nullptr, false); }

Solution Problem::solve(const std::vector<Rgb>& polygon_emission) {
  const std::size_t n = impl_->scene.polygons().size();
  if (polygon_emission.size() != n)
    throw Error(ErrorCode::invalid_argument, "Problem::solve: polygon_emission has " +
                                                 std::to_string(polygon_emission.size()) +
                                                 " values; the scene has " + std::to_string(n) + " polygons");
  for (std::size_t p = 0; p < n; ++p) {
    const Rgb& e = polygon_emission[p];
    for (int c = 0; c < 3; ++c)
      if (!(e[c] >= 0.0f) || !std::isfinite(e[c]))
        throw Error(ErrorCode::invalid_argument, "Problem::solve: polygon_emission[" + std::to_string(p) +
                                                     "] must be finite and >= 0, got (" + std::to_string(e.x) + ", " +
                                                     std::to_string(e.y) + ", " + std::to_string(e.z) + ")");
  }
  return impl_->solve(&polygon_emission, false);
}

Solution solve(const Scene& scene, const SolveOptions& options) {
  Problem::Impl problem(scene, options);
  return problem.solve(nullptr, true);
}

}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

struct SplitSolve {
  static Solution solve(const Scene& scene, const SolveOptions& options, const Communicator& split) {
    Problem::Impl problem(scene, options, &split);
    return problem.solve(nullptr, true);
  }
};

Solution solve_split(const Scene& scene, const SolveOptions& options, const Communicator& split) {
  return SplitSolve::solve(scene, options, split);
}

}  // namespace radiosity::detail
