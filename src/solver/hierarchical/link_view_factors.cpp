// View factors from hierarchical radiosity's links (ViewFactorMethod::hierarchical): the links
// refined for unit radiosity on every surface, then one gather per group (group level) or the
// gather's transpose per row (polygon and element levels: LinkHierarchy::view_factor_rows()).
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991 (the links as a hierarchical representation of the form-factor matrix: any
// block of it is one gather away); J. Howell, M. Menguc & R. Siegel, "Thermal Radiation Heat
// Transfer", 6th ed., 2016, ch. 4 (view-factor algebra: F(i -> j u k) = F(i -> j) + F(i -> k)).
#include "solver/hierarchical/link_view_factors.hpp"

#include "core/assert.hpp"
#include "solver/hierarchical/link_hierarchy.hpp"
#include "solver/system.hpp"

namespace radiosity::detail {

std::unique_ptr<LinkHierarchy> view_factor_links(const Scene& scene, PatchHierarchy& hierarchy, float epsilon,
                                                 std::uint64_t seed, unsigned threads, std::size_t memory_budget,
                                                 ProgressGate& gate, std::uint64_t& rays, bool rows) {
  const RadiositySystem system(scene, hierarchy, false);
  auto links = std::make_unique<LinkHierarchy>(scene, seed, threads);
  links->set_memory_budget(memory_budget, "ViewFactorOptions::memory_budget_bytes");
  // The links' own factors: the view factor options have their own enclosure correction.
  links->set_balancing(false);
  // Unit radiosity everywhere: the oracle judges the geometry alone, and its threshold (the
  // irradiance a link may get wrong) is then a view factor. But 0 on a wholly buried side (the
  // floor under a block standing on it), which sends nothing: measured first, so that no
  // shadow ray starts there. Its rays are blocked, so a link from a cluster that holds it had
  // a visible fraction that counted its burial, while the cluster's moments counted its
  // radiosity: measured on the 3 708-facet room around a block, the block's lowest facets' rows
  // were 0.87-0.92 before correction (their factors to the far wall's lowest facets half the
  // exact ones), now 0.96-0.97; the worst row of the reciprocal matrix 0.135 -> 0.063 from 1.
  // (Drawing the receivers' points by open area too, tried: the floor beside the block then
  // 1.16-1.34, as the push's exposure ratios assume a receiving cluster's visible fraction over
  // all of its area.)
  // Fronts only, as the view factors' surfaces send and receive (a two-sided material's back
  // is no surface here).
  links->measure_buried_parts(hierarchy, system);
  std::vector<Rgb> one(system.unknowns(), Rgb(0.0f));
  for (std::size_t u = 0; u < system.fronts(); ++u)
    if (links->exposure(system.element(u)) != 0.0f) one[u] = Rgb(1.0f);
  std::vector<std::uint32_t> split;
  RefineStats stats;
  if (!links->refine(hierarchy, system, one, epsilon, SubdivisionLimits{}, gate, split, stats)) return nullptr;
  RADIOSITY_ASSERT(split.empty());  // no subdivision limits: the meshed elements stay
  rays = stats.rays;
  if (rows) links->prepare_view_factor_rows(hierarchy, system);
  return links;
}

LinkGroupTransport link_group_transport(const Scene& scene, PatchHierarchy& hierarchy,
                                        const std::vector<std::size_t>& slot, std::size_t groups, float epsilon,
                                        std::uint64_t seed, unsigned threads, std::size_t memory_budget,
                                        ProgressGate& gate) {
  LinkGroupTransport out;
  out.transport.assign(groups * groups, 0.0);
  const std::unique_ptr<LinkHierarchy> linked =
      view_factor_links(scene, hierarchy, epsilon, seed, threads, memory_budget, gate, out.link_rays, false);
  if (!linked) {
    out.cancelled = true;
    return out;
  }
  const LinkHierarchy& links = *linked;
  const RadiositySystem system(scene, hierarchy, false);
  out.link_count = links.link_count();

  // Column k: the irradiance every front receives from unit radiosity on the fronts of group k
  // alone is its view factor to that group; summed over each group's fronts, times their area.
  std::vector<std::size_t> unknown_slot(system.fronts());
  for (std::size_t u = 0; u < system.fronts(); ++u) {
    // Obstruction-only polygons hide but neither send nor receive here.
    const Patch& patch = hierarchy.patches()[hierarchy.element(system.element(u)).patch];
    unknown_slot[u] = scene.polygons()[patch.polygon].obstruction_only ? kNone : slot[patch.group];
  }
  std::vector<Rgb> B(system.unknowns());
  for (std::size_t k = 0; k < groups; ++k) {
    for (std::size_t u = 0; u < B.size(); ++u) B[u] = Rgb(u < system.fronts() && unknown_slot[u] == k ? 1.0f : 0.0f);
    const std::vector<Rgb> H = links.irradiance(hierarchy, system, B);
    for (std::size_t u = 0; u < system.fronts(); ++u)
      if (unknown_slot[u] != kNone)
        out.transport[unknown_slot[u] * groups + k] += static_cast<double>(system.area[u]) * static_cast<double>(H[u].x);
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = static_cast<double>(k + 1) / static_cast<double>(groups);
    if (!gate.report(p, k + 1 == groups)) {
      out.cancelled = true;
      return out;
    }
  }
  return out;
}

}  // namespace radiosity::detail
