// Matrix radiosity: all element-to-patch form factors computed once, then Jacobi or
// Gauss-Seidel sweeps of B = E + rho F B.
// Based on: Goral, Torrance, Greenberg & Battaile, SIGGRAPH 1984; Cohen & Greenberg, "The
// hemi-cube", SIGGRAPH 1985 (Gauss-Seidel); Cohen, Greenberg, Immel & Brock, "An efficient
// radiosity approach for realistic image synthesis", IEEE CG&A 1986 (element-to-patch
// substructuring: m x n factors, never element to element).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/assert.hpp"
#include "core/color.hpp"
#include "core/parallel.hpp"
#include "solver/exposure.hpp"
#include "solver/system.hpp"

namespace radiosity::detail {

std::size_t row_memory_bytes(std::size_t rows, std::size_t patches, bool sparse, std::size_t max_row_entries) {
  const std::size_t row_bytes = sparse ? std::min(patches, max_row_entries) * 2 * sizeof(float) : patches * sizeof(float);
  return rows * row_bytes;
}

void check_row_memory(std::size_t rows, std::size_t unknowns, std::size_t patches, bool sparse,
                      std::size_t max_row_entries, std::size_t budget) {
  const std::size_t bytes = row_memory_bytes(rows, patches, sparse, max_row_entries);
  if (bytes <= budget) return;
  std::ostringstream s;
  s << "the form-factor matrix of " << unknowns << " elements x " << patches << " patches needs "
    << (sparse ? "up to " : "") << bytes / (1024.0 * 1024.0) << " MiB, more than the memory budget of "
    << budget / (1024.0 * 1024.0) << " MiB (SolveOptions::memory_budget_bytes); use SolverMethod::hierarchical, SolverMethod::progressive"
    << (sparse ? "" : ", FormFactorMethod::monte_carlo (sparse rows)") << " or a coarser mesh";
  throw Error(ErrorCode::memory_budget, s.str());
}

bool end_sweep(const SolverContext& ctx, SolverResult& result, int it, double change, double seconds) {
  result.iterations = it;
  result.residual = change / ctx.system.emitted;
  // A sweep that passes on more light than it received diverges: say so rather than return
  // infinite radiosity. (Hierarchical links can gain energy; LinkHierarchy::solve() holds its
  // sweeps to the maximum principle when they grow, so they should not reach this.)
  if (!std::isfinite(result.residual))
    throw Error(ErrorCode::internal,
                "the solve diverged after " + std::to_string(it) +
                    " sweeps (its radiosity grew without bound): the form factors of a closed scene of "
                    "reflectance near 1 pass on more light than they receive; try another solver or form-factor "
                    "method, or lower reflectances");
  result.residual_history.push_back(result.residual);
  result.time_history.push_back(seconds);
  const bool done = result.residual < ctx.options.tolerance;
  if (done) result.status = SolveStatus::converged;
  Progress p;
  p.phase = Phase::solving;
  p.iteration = it;
  p.residual = result.residual;
  p.fraction = done ? 1.0 : std::clamp(std::log(result.residual) / std::log(ctx.options.tolerance), 0.0, 1.0);
  p.hierarchy = &ctx.hierarchy;
  p.leaf_radiosity = result.B.data();
  if (!ctx.progress.report(p, done)) {
    result.status = SolveStatus::cancelled;
    return true;
  }
  return done;
}

SolverResult solve_matrix(const SolverContext& ctx, bool gauss_seidel, MatrixStore& store,
                          const std::vector<Rgb>& B0) {
  const RadiositySystem& sys = ctx.system;
  const std::size_t m = sys.unknowns(), n = sys.patches();
  SolverResult result;
  result.B = B0.empty() ? sys.source : B0;
  result.H.assign(m, Rgb(0.0f));

  // Which sides still need a row (unknowns, fronts first), and where it goes.
  const std::size_t elements = ctx.hierarchy.elements().size();
  if (store.slot.size() < elements) store.slot.resize(elements, kNone);
  if (store.back_slot.size() < elements) store.back_slot.resize(elements, kNone);
  auto slot_of = [&](std::size_t u) -> std::uint32_t& {
    return (u < sys.fronts() ? store.slot : store.back_slot)[sys.element(u)];
  };
  // This process's unknowns: all of them, or its block when the solve is split among processes
  // (Jacobi only: its sweeps read nothing of the sweep they are in). The rows of other unknowns
  // (a split process's block before adaptive subdivision renumbered the unknowns) are freed.
  const Communicator* split = ctx.split;
  RADIOSITY_ASSERT(split == nullptr || !gauss_seidel);
  const std::vector<std::size_t> blocks = split ? even_blocks(m, split->size()) : std::vector<std::size_t>{0, m};
  const std::size_t own_first = split ? blocks[static_cast<std::size_t>(split->rank())] : 0;
  const std::size_t own_last = split ? blocks[static_cast<std::size_t>(split->rank()) + 1] : m;
  if (split)
    for (std::size_t u = 0; u < m; ++u) {
      std::uint32_t& slot = slot_of(u);
      if ((u >= own_first && u < own_last) || slot == kNone) continue;
      store.rows[slot] = FactorVector{};
      store.free_slots.push_back(slot);
      slot = kNone;
    }
  std::vector<std::uint32_t> missing;
  for (std::size_t u = own_first; u < own_last; ++u)
    if (slot_of(u) == kNone) missing.push_back(static_cast<std::uint32_t>(u));
  // Memory, stated before anything is computed. Rows with backs come from the sparse calls
  // (the dense ones keep to fronts).
  const bool sparse = ctx.estimator->sparse() || sys.has_backs();
  std::size_t rows_held = 0;
  for (const FactorVector& r : store.rows) rows_held += r.empty() ? 0 : 1;
  check_row_memory(rows_held + missing.size(), m, n, sparse, ctx.estimator->max_row_entries(),
                   ctx.options.memory_budget_bytes);
  std::vector<std::uint32_t> slots(missing.size());
  for (std::size_t k = 0; k < missing.size(); ++k) {
    if (!store.free_slots.empty()) {
      slots[k] = store.free_slots.back();
      store.free_slots.pop_back();
    } else {
      slots[k] = static_cast<std::uint32_t>(store.rows.size());
      store.rows.emplace_back();
    }
  }
  store.exposure.resize(store.rows.size(), 1.0f);

  // Exposure by points where the rows do not measure it (solver/exposure.hpp): a ray-cast row
  // is a mean over its element as a Monte Carlo row is, so it is divided as that one is; a
  // hemicube row is its centre's, so the exposure only weighs it in its target's mean.
  const FormFactorMethod method = ctx.options.form_factors.method;
  const bool probe = !missing.empty() && method != FormFactorMethod::monte_carlo && method != FormFactorMethod::analytic;
  const std::vector<float> probed =
      probe ? unknown_exposure(ctx.scene, ctx.hierarchy, sys, ctx.options.threads) : std::vector<float>{};
  auto keep_exposure = [&](std::size_t u, float reported, FactorVector& r) {
    const float x = probed.empty() ? (probe ? 1.0f : effective_exposure(reported)) : probed[u];
    if (x > 0.0f && x < 1.0f && method != FormFactorMethod::hemicube)
      for (float& v : r.value) v /= x;
    return x;
  };

  // Form factors, in chunks so that progress is reported and cancel is honoured: about 15 ms
  // each (BlockSizer; a row does not depend on its chunk), from 8 to 16384 rows.
  auto t0 = std::chrono::steady_clock::now();
  BlockSizer chunk(64, 8, 16384);
  std::vector<std::uint32_t> rows, backs;
  std::vector<SparseFactors> sparse_rows, back_rows;
  std::vector<float> buffer;
  for (std::size_t begin = 0, end = 0; begin < missing.size(); begin = end) {
    end = std::min(missing.size(), begin + chunk.size());
    rows.clear();
    backs.clear();
    for (std::size_t k = begin; k < end; ++k)
      (missing[k] < sys.fronts() ? rows : backs).push_back(sys.element(missing[k]));
    if (sparse) {
      ctx.estimator->sparse_element_rows(rows, sparse_rows);
      if (!backs.empty()) ctx.estimator->sparse_back_rows(backs, back_rows);
      std::size_t front = 0, back = 0;  // fronts come before backs in `missing`
      for (std::size_t k = begin; k < end; ++k) {
        SparseFactors& from = missing[k] < sys.fronts() ? sparse_rows[front++] : back_rows[back++];
        FactorVector& r = store.rows[slots[k]];
        r.index = std::move(from.index);
        r.value = std::move(from.value);
        r.index.shrink_to_fit();
        r.value.shrink_to_fit();
        // The open part's factors (RadiositySystem::Weights).
        store.exposure[slots[k]] = keep_exposure(missing[k], from.exposed, r);
        slot_of(missing[k]) = slots[k];
      }
    } else {
      buffer.resize(rows.size() * n);
      ctx.estimator->element_rows(rows, buffer.data());
      for (std::size_t k = begin; k < end; ++k) {
        FactorVector& r = store.rows[slots[k]];
        r.index.clear();
        r.value.assign(buffer.data() + (k - begin) * n, buffer.data() + (k - begin + 1) * n);
        store.exposure[slots[k]] = keep_exposure(missing[k], 1.0f, r);
        slot_of(missing[k]) = slots[k];
      }
    }
    chunk.done(end - begin);
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = static_cast<double>(end) / static_cast<double>(missing.size());
    if (!ctx.progress.report(p, end == missing.size())) {
      // Leaves without a row would be read below: forget the partial work and stop here with
      // the starting estimate, which is consistent.
      for (std::size_t k = 0; k < missing.size(); ++k)
        if (slot_of(missing[k]) == kNone) store.free_slots.push_back(slots[k]);
      result.status = SolveStatus::cancelled;
      result.seconds_form_factors = seconds_since(t0);
      result.form_factor_bytes = store.bytes();
      return result;
    }
  }
  result.seconds_form_factors = seconds_since(t0);
  result.form_factor_bytes = store.bytes();
  // Split: a cancel asked for on any process stops every one, here with the starting estimate.
  if (split && split->any(split->cancel_requested)) {
    result.status = SolveStatus::cancelled;
    return result;
  }
  std::vector<const FactorVector*> row_of(m, nullptr);
  for (std::size_t u = own_first; u < own_last; ++u) row_of[u] = &store.rows[slot_of(u)];
  auto row = [&](std::size_t i) -> const FactorVector& { return *row_of[i]; };
  // Exposure (RadiositySystem::Weights): every process's, for the targets' means.
  bool buried = false;
  {
    std::vector<Rgb> exposure(m, Rgb(1.0f));
    for (std::size_t u = own_first; u < own_last; ++u) {
      exposure[u] = Rgb(store.exposure[slot_of(u)]);
      buried = buried || exposure[u].x < 1.0f;
    }
    if (split) {
      split->all_gather(exposure, blocks);
      for (const Rgb& x : exposure) buried = buried || x.x < 1.0f;
    }
    if (buried) {
      result.exposure.resize(m);
      for (std::size_t u = 0; u < m; ++u) result.exposure[u] = exposure[u].x;
    }
  }
  const RadiositySystem::Weights weights = sys.weights(result.exposure);
  const std::vector<Rgb> source = sys.exposed_source(result.exposure);
  if (buried && B0.empty()) result.B = source;
  // B_u = E_u + rho_u H_u + tau_u H_twin (system.hpp; E_u with the lights' first shot); opaque
  // sides have no twin.
  auto radiosity = [&](std::size_t i, const Rgb& h) {
    Rgb b = source[i] + sys.reflectance[i] * h;
    if (sys.twin[i] != kNone) b += sys.transmittance[i] * result.H[sys.twin[i]];
    return b;
  };

  // Sweeps. Residual: power that the last sweep changed, over the emitted power.
  std::vector<Rgb> patch_B, next(m);
  const int max_iterations = ctx.options.max_iterations;
  result.status = SolveStatus::iteration_cap;
  for (int it = 1; it <= max_iterations; ++it) {
    sys.patch_means(result.B, patch_B, weights);
    double change = 0.0;
    if (!gauss_seidel) {
      // Jacobi: every side from the previous sweep's patch radiosity; rows are independent.
      // Translucent sides need the other side's irradiance, so all of H comes first.
      // Split: this process's block of H, then every block from the others (12 bytes per
      // unknown), and B and the residual over every unknown in this order on every process.
      parallel_for(ctx.options.threads, own_last - own_first, 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = own_first + begin; i < own_first + end; ++i) result.H[i] = row(i).dot(patch_B);
      });
      if (split) split->all_gather(result.H, blocks);
      for (std::size_t i = 0; i < m; ++i) next[i] = radiosity(i, result.H[i]);
      for (std::size_t i = 0; i < m; ++i) change += sys.area[i] * channel_l1(next[i] - result.B[i]);
      result.B.swap(next);
    } else {
      // Gauss-Seidel: each side sees the patch means already updated by earlier sides. A new
      // irradiance changes the twin's radiosity too (it transmits it), so that is updated at
      // once: otherwise a sweep could change only irradiances and look converged.
      auto set = [&](std::size_t i) {
        const Rgb b = radiosity(i, result.H[i]);
        const Rgb d = b - result.B[i];
        change += sys.area[i] * channel_l1(d);
        patch_B[sys.patch[i]] += static_cast<float>(weights.side[i] / weights.target[sys.patch[i]]) * d;
        result.B[i] = b;
      };
      for (std::size_t i = 0; i < m; ++i) {
        result.H[i] = row(i).dot(patch_B);
        set(i);
        if (sys.twin[i] != kNone) set(sys.twin[i]);
      }
    }
    // Form factors included in the time: the first sweep waits for them.
    const bool stop = end_sweep(ctx, result, it, change, seconds_since(t0));
    // Split: every process has the same residual, so they agree on convergence; a cancel is
    // agreed on here (one all-reduce of a flag per sweep).
    if (split && split->any(split->cancel_requested)) {
      result.status = SolveStatus::cancelled;
      break;
    }
    if (stop) break;
  }

  // Irradiance for the energy balance: H_e = sum_j F_ej B_j with the final radiosity.
  sys.patch_means(result.B, patch_B, weights);
  parallel_for(ctx.options.threads, own_last - own_first, 256, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = own_first + begin; i < own_first + end; ++i) result.H[i] = row(i).dot(patch_B);
  });
  if (split) split->all_gather(result.H, blocks);
  return result;
}

}  // namespace radiosity::detail
