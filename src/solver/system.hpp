// The discrete radiosity system shared by the solvers: per-leaf data in the hierarchy's leaf
// order, plus the bookkeeping every solver does (progress with cancel, residual history).
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "radiosity/form_factors.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"
#include "core/communicator.hpp"
#include "core/progress.hpp"
#include "solver/light_shot.hpp"

namespace radiosity::detail {

/// B_e = E_e + rho_e sum_j F_ej B_j over the leaves e and patches j, B_j the area-weighted
/// mean of patch j's leaves.
///
/// With diffuse transmission (Rushmeier & Torrance 1990) the unknowns are sides: first the
/// fronts of all leaves (index = position in `leaves`), then the backs of the leaves of
/// translucent patches. A side u gathers H_u = sum_t F_ut B_t over the targets t (the patches,
/// then the backs of translucent patches, numbered as FormFactorEstimator::
/// translucent_patches() numbers them) and leaves
///   B_u = E_u + rho_u H_u + tau_u H_twin(u):
/// what it reflects plus what its other side receives and transmits. The back of a one-sided
/// material reflects nothing (rho 0), as in the path tracer; a two-sided one reflects like the
/// front. Emission leaves the front only.
///
/// The scene's lights (Light) are the first shot: each side's direct irradiance from them,
/// H_light (solver/light_shot.hpp), is reflected and transmitted like any received light, so
/// the solvers start from and add `source` = E + rho H_light + tau H_light(twin) where they
/// would use E, and report the irradiance from surfaces only (solve() adds H_light).
struct RadiositySystem {
  std::vector<std::uint32_t> leaves;  ///< element ids of the fronts: the estimators' element list
  std::vector<float> area;            ///< per unknown
  std::vector<Rgb> emission, reflectance, transmittance;  ///< per unknown; tau = 0 when opaque
  /// Per unknown: the lights' direct irradiance H_light, W/m^2; empty when the scene has no lights.
  std::vector<Rgb> light;
  /// Per unknown: what the solvers emit, E + rho H_light + tau H_light(twin); `emission` when
  /// there are no lights.
  std::vector<Rgb> source;
  std::vector<std::uint32_t> patch;   ///< per unknown: its target (patch, or patches() + k for a back)
  std::vector<std::uint32_t> twin;    ///< per unknown: the other side's unknown, or kNone (opaque)
  std::vector<float> patch_area;      ///< per target
  /// sum_u A_u (E_r + E_g + E_b + H_light,r + H_light,g + H_light,b), the residual's
  /// denominator: the lights count with the power they put onto the surfaces.
  double emitted = 0.0;
  /// 1 / (1 - area-weighted mean of rho + tau over the sides), per channel: the
  /// interreflection factor of the ambient term (Cohen et al. 1988, eq. 6).
  Rgb interreflection{1.0f};
  double total_area = 0.0;            ///< of all sides

  /// `diffuse_transmission`: give translucent and two-sided patches (pass1_has_back()) their backs.
  /// `polygon_emission`: one value per polygon in place of the materials' emission, or null.
  /// `lights`: the lights' first shot, computed for every leaf (and back), or null for none.
  RadiositySystem(const Scene& scene, const PatchHierarchy& hierarchy, bool diffuse_transmission,
                  const std::vector<Rgb>* polygon_emission = nullptr, const LightShot* lights = nullptr);
  std::size_t unknowns() const { return area.size(); }
  std::size_t fronts() const { return leaves.size(); }
  std::size_t patches() const { return patch_area.size(); }  ///< targets, backs included
  bool has_backs() const { return unknowns() > fronts(); }
  /// The element of unknown u (either side).
  std::uint32_t element(std::size_t u) const { return leaves[u < fronts() ? u : twin[u]]; }
  /// Target radiosity from side radiosity (area-weighted means).
  void patch_means(const std::vector<Rgb>& B, std::vector<Rgb>& patch_B) const;

  /// Exposure: per unknown, the share of its area that is not buried (inside a solid standing
  /// on it: geometry/burial.hpp), from the Monte Carlo rows (SparseFactors::exposed) or by
  /// points (solver/exposure.hpp); empty when the solver does not have it (every side taken as
  /// exposed). The rows' factors are
  /// means over the whole element, so a floor element half under a block gathers half of what
  /// its open half receives; divided by the exposure they are the open part's (solve_matrix()).
  /// And a target's radiosity, as the rays that reach its open part see it, is the mean of its
  /// sides weighted by their exposed areas, not the mean with its dark buried part.
  struct Weights {
    std::vector<float> side;     ///< per unknown: area x exposure
    std::vector<double> target;  ///< per target: the sum of its sides', or its area where that is 0 (wholly buried)
  };
  Weights weights(const std::vector<float>& exposure) const;
  /// Target radiosity from side radiosity, weighted by `w`.
  void patch_means(const std::vector<Rgb>& B, std::vector<Rgb>& patch_B, const Weights& w) const;
  /// The lights' first shot onto unknown u's open part: light[u] / exposure[u] (as the rows).
  Rgb exposed_light(std::size_t u, const std::vector<float>& exposure) const {
    return u < exposure.size() && exposure[u] > 0.0f ? light[u] / exposure[u] : light[u];
  }
  /// `source` with the lights' first shot onto the open parts (exposed_light()).
  std::vector<Rgb> exposed_source(const std::vector<float>& exposure) const;
  /// The radiosity of unknown `u` from its source term and the irradiance per unknown `H`:
  /// B_u = source_u + rho_u H_u + tau_u H_twin (opaque sides have no twin).
  Rgb radiosity_of(std::size_t u, const Rgb& source_u, const std::vector<Rgb>& H) const {
    Rgb b = source_u + reflectance[u] * H[u];
    if (twin[u] != kNone) b += transmittance[u] * H[twin[u]];
    return b;
  }
  /// The unknown at position `index` of an estimator's column over `leaves`: the front for
  /// index < fronts(), the back of leaves[index - fronts()] beyond (kNone if it has none).
  std::uint32_t column_unknown(std::size_t index) const {
    return index < fronts() ? static_cast<std::uint32_t>(index) : twin[index - fronts()];
  }
};

/// What a solver hands back to solve().
struct SolverResult {
  std::vector<Rgb> B;          ///< per unknown
  std::vector<Rgb> H;          ///< irradiance per unknown (for the absorbed power), onto its open part
  /// Per unknown (RadiositySystem::Weights), or empty: every side exposed. B and H are the
  /// sides' open parts'.
  std::vector<float> exposure;
  Rgb ambient{0.0f};           ///< progressive refinement's ambient radiosity at the end
  SolveStatus status = SolveStatus::converged;
  int iterations = 0;
  double residual = 0.0;
  std::vector<double> residual_history, time_history;
  std::size_t form_factor_bytes = 0;
  double seconds_form_factors = 0.0;
  /// Hierarchical: the sweeps grew, and were run again with the irradiance held to the maximum
  /// principle (LinkHierarchy::solve()).
  bool held = false;
};

struct SolverContext {
  const Scene& scene;
  const PatchHierarchy& hierarchy;
  const RadiositySystem& system;
  const FormFactorEstimator* estimator;  ///< null for SolverMethod::hierarchical (no form factors)
  const SolveOptions& options;  ///< with max_iterations and memory_budget_bytes resolved
  ProgressGate& progress;
  /// The processes the solve is split among (Jacobi only, docs/MPI.md), or null for this one
  /// alone: each computes and keeps the rows of its block of unknowns (even_blocks()) and the
  /// blocks of each sweep's irradiance are gathered, so every process holds all of B.
  const Communicator* split;
};

/// The end of sweep `it` of a sweeping solver (the matrix methods, hierarchical): records the
/// residual `change` / emitted power and the time, marks convergence, and reports
/// Phase::solving with the current estimate (result.B, one value per unknown). Returns true
/// when the sweeps should stop: converged, or cancelled (result.status says which).
bool end_sweep(const SolverContext& context, SolverResult& result, int it, double change, double seconds);

/// One row F(element -> patches) or column F(elements -> patch) of the form-factor matrix:
/// dense (`index` empty, one value per patch / element) or sparse (the non-zero entries), as the
/// estimator produces it (FormFactorEstimator::sparse()).
struct FactorVector {
  std::vector<std::uint32_t> index;
  std::vector<float> value;

  bool empty() const { return value.empty(); }
  std::size_t bytes() const { return (index.capacity() + value.capacity()) * sizeof(float); }
  /// Calls f(position, factor) for every entry that may be non-zero.
  template <typename F>
  void for_each(const F& f) const {
    if (index.empty()) {
      for (std::size_t k = 0; k < value.size(); ++k) f(k, value[k]);
    } else {
      for (std::size_t k = 0; k < index.size(); ++k) f(std::size_t{index[k]}, value[k]);
    }
  }
  /// sum_j F_j x_j.
  Rgb dot(const std::vector<Rgb>& x) const {
    Rgb sum(0.0f);
    for_each([&](std::size_t j, float f) { sum += f * x[j]; });
    return sum;
  }
};

/// The exposure a solver uses for an element whose rows report `exposed`
/// (SparseFactors::exposed): the same, except that a sliver left open, less than
/// kMinExposure of the element, is taken as wholly exposed (its rows not divided), because its
/// few open rays would make its radiosity noisy where it shows beside its neighbours. A wholly
/// buried element (0) keeps 0: it sends nothing into its target's mean.
inline constexpr float kMinExposure = 0.125f;
inline float effective_exposure(float exposed) { return exposed == 0.0f || exposed >= kMinExposure ? exposed : 1.0f; }

/// Rows F(element -> every target) kept across adaptive refinement passes, so a pass computes
/// rows only for the elements it created. A subdivided element's row slots are reused by its
/// children. The backs of translucent elements have rows of their own.
struct MatrixStore {
  std::vector<FactorVector> rows;        ///< by slot, divided by their exposure
  std::vector<float> exposure;           ///< by slot: effective_exposure() of its row's element side
  std::vector<std::uint32_t> slot;       ///< element id -> slot of its front row, kNone when it has none
  std::vector<std::uint32_t> back_slot;  ///< element id -> slot of its back row, kNone when it has none
  std::vector<std::uint32_t> free_slots; ///< slots of elements that were subdivided

  std::size_t bytes() const {
    std::size_t sum = rows.capacity() * sizeof(FactorVector);
    for (const FactorVector& r : rows) sum += r.bytes();
    return sum;
  }
  /// Frees the rows of an element that was subdivided.
  void release(std::uint32_t element) {
    for (std::vector<std::uint32_t>* s : {&slot, &back_slot})
      if (element < s->size() && (*s)[element] != kNone) {
        free_slots.push_back((*s)[element]);
        (*s)[element] = kNone;
      }
  }
};

/// Columns F(every side -> target) that progressive refinement computed, by target, kept across
/// the solves of one Problem while they fit the memory budget. They are positions over the
/// leaves they were computed for; subdivision changes the leaf count (a split adds three), so a
/// different count means other leaves and the columns are dropped.
struct ColumnStore {
  std::vector<FactorVector> columns;
  std::vector<std::uint8_t> cached;  ///< per target: 1 when columns[t] holds its column (maybe empty)
  std::size_t bytes = 0;
  std::size_t leaf_count = 0;
};

/// The memory of `rows` form-factor rows over `patches` targets (dense: a float per target;
/// sparse: an index and a float per entry, at most `max_row_entries`), checked against
/// `budget` before anything is computed. Throws Error{memory_budget} naming the figure, the
/// budget and what to do instead.
void check_row_memory(std::size_t rows, std::size_t unknowns, std::size_t patches, bool sparse,
                      std::size_t max_row_entries, std::size_t budget);
/// The figure check_row_memory() checks: bytes of `rows` rows at most.
std::size_t row_memory_bytes(std::size_t rows, std::size_t patches, bool sparse, std::size_t max_row_entries);

/// Jacobi or Gauss-Seidel sweeps. Computes the rows `store` lacks for the system's leaves (all
/// of them on the first call), then iterates from `B0` (per unknown; empty = start from E).
/// Split among processes (context.split, Jacobi only), a process computes and keeps the rows of
/// its block of unknowns only (and frees those of other unknowns), gathers each sweep's
/// irradiance from the others and computes B and the residual over every unknown in the
/// single process's order: the result is bit for bit one process's, on every process.
SolverResult solve_matrix(const SolverContext& context, bool gauss_seidel, MatrixStore& store,
                          const std::vector<Rgb>& B0);
/// Progressive refinement, reusing and adding to the columns in `store`.
SolverResult solve_progressive(const SolverContext& context, ColumnStore& store);

/// Adaptive subdivision (Cohen, Greenberg, Immel & Brock 1986): the leaves whose radiosity
/// differs from the interpolated values at their corners (i.e. from their neighbours) by more
/// than `threshold`, relative, and that may still be split. `exposure` (per element id, or
/// empty: every leaf open) is the share of each leaf not buried under a solid standing on it:
/// the corners weigh leaves by open area (PatchHierarchy::vertex_values()) and a wholly buried
/// leaf is never split, so the floor under a block is not refined for the step from its 0 to
/// the light beside it, which no one sees.
std::vector<std::uint32_t> leaves_to_refine(const PatchHierarchy& hierarchy, const std::vector<Rgb>& B_elements,
                                            const std::vector<float>& exposure, const AdaptiveOptions& options,
                                            std::uint8_t max_depth, std::size_t element_budget);

}  // namespace radiosity::detail
