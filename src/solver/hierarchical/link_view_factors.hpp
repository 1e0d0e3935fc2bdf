// View factors from hierarchical radiosity's links (ViewFactorMethod::hierarchical).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/progress.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "solver/hierarchical/link_hierarchy.hpp"

namespace radiosity::detail {

/// The links of `hierarchy`'s scene refined for unit radiosity on every front against
/// `epsilon` (a view factor), without the balancing (the view factors have their own
/// correction) and without subdividing the meshed elements; with `rows`, ready for
/// view_factor_rows() (a gather more). `rays` gets their visibility rays. Null when `gate`
/// cancels. Deterministic for a seed at any thread count.
std::unique_ptr<LinkHierarchy> view_factor_links(const Scene& scene, PatchHierarchy& hierarchy, float epsilon,
                                                 std::uint64_t seed, unsigned threads, std::size_t memory_budget,
                                                 ProgressGate& gate, std::uint64_t& rays, bool rows);

/// What link_group_transport() found.
struct LinkGroupTransport {
  /// groups x groups, row-major: sum over the fronts e of row group i of A_e F(e -> group k),
  /// scene units squared (not yet made reciprocal).
  std::vector<double> transport;
  std::size_t link_count = 0;
  std::uint64_t link_rays = 0;
  bool cancelled = false;  ///< `gate` said stop: transport is incomplete
};

/// Refines the links of `hierarchy`'s scene for unit radiosity on every surface against
/// `epsilon` (a view factor), then gathers once per group: the transport between the groups
/// that `slot` gives each scene GroupId (row and column, or kNone for a group not reported),
/// `groups` of them. Progress goes through `gate` (Phase::form_factors). Deterministic for a
/// seed at any thread count, as the links are.
LinkGroupTransport link_group_transport(const Scene& scene, PatchHierarchy& hierarchy,
                                        const std::vector<std::size_t>& slot, std::size_t groups, float epsilon,
                                        std::uint64_t seed, unsigned threads, std::size_t memory_budget,
                                        ProgressGate& gate);

}  // namespace radiosity::detail
