// Group-to-group view factors for thermal users: element rows in bounded chunks, summed per group.
// Based on: Cohen, Greenberg, Immel & Brock, "An efficient radiosity approach for realistic
// image synthesis", IEEE CG&A 6(3), 1986 (element-to-patch substructuring: the factor of a
// surface is the area-weighted sum over its elements); Howell, Menguc & Siegel, "Thermal
// Radiation Heat Transfer", 6th ed., 2016, ch. 4 (view-factor algebra: F(i -> j ∪ k) =
// F(i -> j) + F(i -> k), A_i F(i -> j) = A_j F(j -> i)).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "form_factors/estimators.hpp"
#include "radiosity/form_factors.hpp"
#include "core/progress.hpp"
#include "solver/hierarchical/link_view_factors.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

// Rows per chunk: at most ~32 MiB of floats, and at least ~100 chunks for progress and cancel.
std::size_t chunk_rows(std::size_t elements, std::size_t patches) {
  const std::size_t by_memory = std::max<std::size_t>(1, (std::size_t{32} << 20) / (sizeof(float) * patches));
  const std::size_t by_progress = std::max<std::size_t>(16, elements / 100);
  return std::min(by_memory, by_progress);
}

}  // namespace

GroupViewFactors view_factors(const Scene& scene, const ViewFactorOptions& options) {
  FormFactorOptions ff = detail::resolve(options.form_factors);
  // Thermal users read small factors: the automatic choice is the accurate one here.
  if (ff.method == FormFactorMethod::automatic) ff.method = FormFactorMethod::ray_cast;
  if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "view_factors: the scene has no polygons");
  const bool links = options.method == ViewFactorMethod::hierarchical;
  if (links && !(options.epsilon > 0.0f && options.epsilon <= 1.0f))
    throw Error(ErrorCode::invalid_argument, "view_factors: epsilon must be in (0, 1], got " + std::to_string(options.epsilon));

  // Rows and columns: the requested groups, or all of them.
  GroupViewFactors result;
  const std::size_t scene_groups = scene.groups().size();
  std::vector<std::size_t> slot(scene_groups, kNone);  // scene GroupId -> row/column, or kNone
  if (options.groups.empty()) {
    result.groups = scene.groups();
    for (std::size_t g = 0; g < scene_groups; ++g) slot[g] = g;
  } else {
    for (const std::string& name : options.groups) {
      const std::optional<GroupId> id = scene.find_group(name);
      if (!id) throw Error(ErrorCode::invalid_argument, "view_factors: groups: the scene has no group '" + name + "'");
      if (slot[*id] != kNone)
        throw Error(ErrorCode::invalid_argument, "view_factors: groups: '" + name + "' is listed twice");
      slot[*id] = result.groups.size();
      result.groups.push_back(name);
    }
  }
  const std::size_t G = result.groups.size();

  const auto t0 = std::chrono::steady_clock::now();
  PatchHierarchy hierarchy(scene, options.mesh);
  const std::vector<Patch>& patches = hierarchy.patches();
  const std::size_t n = patches.size();
  std::vector<std::size_t> column(n);
  // Obstruction-only polygons hide but neither send nor receive here.
  auto obstruction = [&](std::size_t patch) { return scene.polygons()[patches[patch].polygon].obstruction_only; };
  for (std::size_t j = 0; j < n; ++j) column[j] = obstruction(j) ? kNone : slot[patches[j].group];

  std::vector<std::uint32_t> sources;
  result.area.assign(G, 0.0);
  for (const std::uint32_t e : hierarchy.leaves()) {
    const std::size_t g = slot[patches[hierarchy.element(e).patch].group];
    if (g == kNone || obstruction(hierarchy.element(e).patch)) continue;
    sources.push_back(e);
    result.area[g] += hierarchy.element(e).area;
  }
  result.patch_count = n;
  result.element_count = sources.size();

  // A_e F(e -> j) summed per (source group, receiver group) in element order, so the sums do not
  // depend on the thread count; chunks bound the memory to chunk x n floats.
  std::vector<double> sum(G * G, 0.0);
  // Progress: at the start, at the end, and in between at most every 50 ms; a false return
  // stops after the current chunk.
  detail::ProgressGate gate(options.on_progress);
  auto report = [&](double fraction, bool force) {
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = fraction;
    return gate.report(p, force);
  };
  result.cancelled = !report(0.0, true);
  if (links && !result.cancelled) {
    detail::LinkGroupTransport t =
        detail::link_group_transport(scene, hierarchy, slot, G, options.epsilon, ff.seed, ff.threads,
                                     options.memory_budget_bytes, gate);
    result.cancelled = t.cancelled;
    // Reciprocal by construction: each pair's transport A_i F_ij is the mean of the links' two
    // directions' estimates (each direction was refined and sampled on its own).
    for (std::size_t i = 0; i < G; ++i)
      for (std::size_t k = 0; k < G; ++k) sum[i * G + k] = 0.5 * (t.transport[i * G + k] + t.transport[k * G + i]);
    result.link_count = t.link_count;
  }
  const std::unique_ptr<FormFactorEstimator> estimator = links ? nullptr : make_form_factor_estimator(scene, hierarchy, ff);
  const std::size_t chunk = chunk_rows(sources.size(), n);
  std::vector<float> rows;
  std::vector<std::uint32_t> batch;
  for (std::size_t begin = 0; begin < sources.size() && !result.cancelled && !links; begin += chunk) {
    const std::size_t end = std::min(sources.size(), begin + chunk);
    batch.assign(sources.begin() + static_cast<std::ptrdiff_t>(begin),
                 sources.begin() + static_cast<std::ptrdiff_t>(end));
    rows.resize(batch.size() * n);
    estimator->element_rows(batch, rows.data());
    for (std::size_t k = 0; k < batch.size(); ++k) {
      const Element& el = hierarchy.element(batch[k]);
      double* out = &sum[slot[patches[el.patch].group] * G];
      const float* row = &rows[k * n];
      for (std::size_t j = 0; j < n; ++j)
        if (column[j] != kNone) out[column[j]] += static_cast<double>(el.area) * static_cast<double>(row[j]);
    }
    result.cancelled = !report(static_cast<double>(end) / static_cast<double>(sources.size()), end == sources.size());
  }

  result.factors.assign(G * G, 0.0);
  for (std::size_t i = 0; i < G; ++i) {
    if (!(result.area[i] > 0.0)) continue;
    for (std::size_t k = 0; k < G; ++k) {
      const double f = sum[i * G + k] / result.area[i];
      if (!std::isfinite(f))
        throw Error(ErrorCode::internal, "view_factors: a non-finite factor from '" + result.groups[i] + "' to '" +
                                             result.groups[k] + "' (please report this scene)");
      result.factors[i * G + k] = f;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace v1
}  // namespace radiosity
