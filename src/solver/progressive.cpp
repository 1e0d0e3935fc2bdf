// Progressive refinement radiosity: shoot the largest unshot power first.
// Based on: Cohen, Chen, Wallace & Greenberg, "A progressive refinement approach to fast
// radiosity image generation", SIGGRAPH 1988; Cohen & Wallace 1993, sec. 5.3 (the corrected
// per-element update using reciprocity).
//
// Shooting from patch i, element e receives
//   dB_e = rho_e dB_i F(i -> e) A_i / A_e  =  rho_e dB_i F(e -> i)         (reciprocity),
// so one column F(. -> i) of the element-to-patch matrix serves a shot: O(m) per step. The
// received radiosity is added to e's patch's unshot radiosity, area-weighted, and the shooter's
// unshot radiosity is set to zero before distributing, so nothing is counted twice.
//
// Diffuse transmission (system.hpp): the backs of translucent patches are shooters too, and a
// column reports arrivals at the backs of translucent elements. A side receiving irradiance
// dH reflects rho dH from itself and transmits tau dH from its other side.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/parallel.hpp"
#include "solver/exposure.hpp"
#include "solver/system.hpp"

namespace radiosity::detail {

namespace {

double sum3(const Rgb& c) { return static_cast<double>(c.x) + c.y + c.z; }

}  // namespace

SolverResult solve_progressive(const SolverContext& ctx, ColumnStore& store) {
  const RadiositySystem& sys = ctx.system;
  const std::size_t m = sys.unknowns(), n = sys.patches();
  SolverResult result;
  // Monte Carlo and ray-cast columns are means over each receiving side's whole area, its
  // buried part receiving nothing (under a block standing on it): measured by points, so that
  // a side's values are its open part's (the columns divided by it) and a patch sends its open
  // part's mean (RadiositySystem::Weights). A hemicube column is the receiver's centre's: only
  // weighted. The analytic estimator sees no occlusion.
  const FormFactorMethod method = ctx.options.form_factors.method;
  if (method != FormFactorMethod::analytic)
    result.exposure = unknown_exposure(ctx.scene, ctx.hierarchy, sys, ctx.options.threads);
  const bool divide = method != FormFactorMethod::hemicube;
  const RadiositySystem::Weights weights = sys.weights(result.exposure);
  const std::vector<Rgb> source = sys.exposed_source(result.exposure);
  result.B = source;
  result.H.assign(m, Rgb(0.0f));

  // Unshot radiosity per patch starts as the patch's mean emission (with the lights' first shot).
  std::vector<Rgb> unshot;
  sys.patch_means(source, unshot, weights);

  // Columns are kept once computed while they fit the memory budget: a patch is usually shot
  // several times, and recomputing its column is the whole cost of a step.
  // Sparse estimators (monte_carlo) give sparse columns, so a step costs O(entries).
  // Columns with backs come from the sparse calls (the dense ones keep to fronts).
  // They are kept in `store` for the next solve of the same Problem (relighting), unless the
  // leaves changed since they were computed.
  const bool sparse = ctx.estimator->sparse() || sys.has_backs();
  if (store.leaf_count != sys.fronts() || store.columns.size() != n) {
    store = ColumnStore{};
    store.columns.resize(n);
    store.cached.assign(n, 0);
    store.leaf_count = sys.fronts();
  }
  std::vector<FactorVector>& cache = store.columns;
  std::vector<std::uint8_t>& cached = store.cached;  // a column may be cached and empty (a patch that sees nothing)
  std::size_t& cached_bytes = store.bytes;
  std::size_t peak_scratch = 0;
  FactorVector scratch;
  std::vector<std::uint32_t> batch, candidates;
  std::vector<SparseFactors> fetched;
  // Sparse columns fetched per batch: up to 8 per thread, fewer where a batch would take more
  // than about 15 ms (BlockSizer), so that progress and cancel are not held up by it.
  const std::size_t threads = static_cast<std::size_t>(thread_count(ctx.options.threads));
  BlockSizer prefetch(2 * threads, 1, 8 * threads);

  // Ambient radiosity: the unshot power spread over the whole scene area and multiplied by the
  // interreflection factor (Cohen et al. 1988, eqs. 5-6). For display only; it tends to 0.
  auto ambient = [&] {
    glm::dvec3 sum(0.0);
    for (std::size_t j = 0; j < n; ++j) sum += weights.target[j] * glm::dvec3(unshot[j]);
    return Rgb(sum / sys.total_area) * sys.interreflection;
  };
  auto report = [&](Progress p, bool force) {
    if (!ctx.progress.due(p.phase, force)) return true;  // the ambient term is an O(n) sum
    p.hierarchy = &ctx.hierarchy;
    p.leaf_radiosity = result.B.data();
    p.ambient = ambient();
    return ctx.progress.report(p, force);
  };

  auto t0 = std::chrono::steady_clock::now();
  result.status = SolveStatus::iteration_cap;
  // Unshot power per patch, dB_j A_j summed over channels, kept up to date as patches receive,
  // so choosing the shooter is a scan of one array. Its sum (the residual's numerator) is
  // recomputed in that scan, so no error accumulates.
  std::vector<double> power(n);
  for (std::size_t j = 0; j < n; ++j) power[j] = sum3(unshot[j]) * weights.target[j];
  for (int step = 1;; ++step) {
    // Four independent partial sums and maxima keep the scan from waiting on one add chain;
    // ties go to the lowest index, as in a plain scan.
    double sum4[4] = {0.0, 0.0, 0.0, 0.0}, best4[4] = {-1.0, -1.0, -1.0, -1.0};
    std::size_t arg4[4] = {0, 0, 0, 0};
    std::size_t j = 0;
    for (; j + 4 <= n; j += 4)
      for (std::size_t l = 0; l < 4; ++l) {
        sum4[l] += power[j + l];
        if (power[j + l] > best4[l]) best4[l] = power[j + l], arg4[l] = j + l;
      }
    for (; j < n; ++j) {
      sum4[j & 3] += power[j];
      if (power[j] > best4[j & 3]) best4[j & 3] = power[j], arg4[j & 3] = j;
    }
    std::size_t shooter = arg4[0];
    double best = best4[0];
    for (std::size_t l = 1; l < 4; ++l)
      if (best4[l] > best || (best4[l] == best && arg4[l] < shooter)) best = best4[l], shooter = arg4[l];
    const double total_unshot = (sum4[0] + sum4[1]) + (sum4[2] + sum4[3]);
    const double residual = total_unshot / sys.emitted;
    if (step > 1) {
      result.residual = residual;
      result.residual_history.push_back(residual);
      result.time_history.push_back(seconds_since(t0));
      Progress p{Phase::solving, std::clamp(std::log(residual) / std::log(ctx.options.tolerance), 0.0, 1.0),
                 step - 1, residual};
      if (residual >= ctx.options.tolerance && !report(p, false)) {
        result.status = SolveStatus::cancelled;
        break;
      }
    }
    if (residual < ctx.options.tolerance) {
      result.residual = residual;
      result.status = SolveStatus::converged;
      report(Progress{Phase::solving, 1.0, result.iterations, residual}, true);
      break;
    }
    if (step > ctx.options.max_iterations) break;

    const FactorVector* F = &cache[shooter];
    if (!cached[shooter]) {
      auto tf = std::chrono::steady_clock::now();
      if (sparse) {
        // Sparse columns are cheap to keep: fetch the shooter's together with those of the next
        // brightest patches whose columns are missing, so that the estimator can compute them in
        // parallel. Columns do not depend on which batch computes them.
        batch.assign(1, static_cast<std::uint32_t>(shooter));
        if (cached_bytes < ctx.options.memory_budget_bytes / 2) {
          candidates.clear();
          for (std::size_t c = 0; c < n; ++c)
            if (!cached[c] && c != shooter && power[c] > 0.0) candidates.push_back(static_cast<std::uint32_t>(c));
          const std::size_t extra = std::min(candidates.size(), prefetch.size() - 1);
          std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(extra), candidates.end(),
                           [&](std::uint32_t a, std::uint32_t b) { return power[a] > power[b] || (power[a] == power[b] && a < b); });
          batch.insert(batch.end(), candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(extra));
        }
        prefetch.start();  // the time since the last batch was the shooting's
        ctx.estimator->sparse_patch_columns(batch, sys.leaves, fetched);
        prefetch.done(batch.size());
        for (std::size_t k = 0; k < batch.size(); ++k) {
          FactorVector column;
          column.index = std::move(fetched[k].index);
          column.value = std::move(fetched[k].value);
          column.index.shrink_to_fit();
          column.value.shrink_to_fit();
          if (cached_bytes + column.bytes() <= ctx.options.memory_budget_bytes) {
            cached_bytes += column.bytes();
            cache[batch[k]] = std::move(column);
            cached[batch[k]] = 1;
          } else if (k == 0) {
            scratch = std::move(column);
            peak_scratch = std::max(peak_scratch, scratch.bytes());
          }
        }
        F = cached[shooter] ? &cache[shooter] : &scratch;
      } else {
        scratch.value.resize(sys.fronts());
        ctx.estimator->patch_column(static_cast<std::uint32_t>(shooter), sys.leaves, scratch.value.data());
        if (cached_bytes + scratch.bytes() <= ctx.options.memory_budget_bytes) {
          cached_bytes += scratch.bytes();
          cache[shooter] = std::move(scratch);
          scratch = FactorVector{};
          cached[shooter] = 1;
          F = &cache[shooter];
        } else {
          peak_scratch = std::max(peak_scratch, scratch.bytes());
          F = &scratch;
        }
      }
      result.seconds_form_factors += seconds_since(tf);
    }

    auto exposed = [&](std::uint32_t u) { return divide && !result.exposure.empty() && result.exposure[u] > 0.0f; };
    const Rgb shot = unshot[shooter];
    unshot[shooter] = Rgb(0.0f);
    power[shooter] = 0.0;
    auto receive = [&](std::uint32_t u, const Rgb& dB) {
      result.B[u] += dB;
      const std::uint32_t p = sys.patch[u];
      unshot[p] += static_cast<float>(weights.side[u] / weights.target[p]) * dB;
      power[p] = sum3(unshot[p]) * weights.target[p];
    };
    F->for_each([&](std::size_t k, float f) {
      if (f <= 0.0f) return;
      const std::uint32_t u = sys.column_unknown(k);
      if (u == kNone) return;
      // Irradiance arriving at side u from this shot (onto its open part).
      const Rgb incident = shot * (exposed(u) ? f / result.exposure[u] : f);
      result.H[u] += incident;
      receive(u, sys.reflectance[u] * incident);
      if (sys.twin[u] != kNone) receive(sys.twin[u], sys.transmittance[u] * incident);
    });

    result.iterations = step;
  }
  // The last allowed step may itself have reached the tolerance.
  if (result.status == SolveStatus::iteration_cap && result.residual < ctx.options.tolerance)
    result.status = SolveStatus::converged;
  result.form_factor_bytes = cached_bytes + peak_scratch;
  result.ambient = ambient();
  return result;
}

}  // namespace radiosity::detail
