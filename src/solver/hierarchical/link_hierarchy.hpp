// Hierarchical radiosity's links (docs/HIERARCHICAL.md, issue #15): energy moves along links
// between nodes of the cluster tree and the element quadtrees, refined by an error oracle
// (docs/HIERARCHICAL.md, "Refinement") from one self-link of the root cluster, then Jacobi sweeps of gather and push-pull over them.
// Private to the library; solve() runs it for SolverMethod::hierarchical.
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991 (links, BF refinement, gather, push-pull, multigridding); B. Smits, J. Arvo &
// D. Greenberg, "A clustering algorithm for radiosity in complex environments", SIGGRAPH 1994
// (starting from the root cluster's self-link); F. Sillion, "A unified hierarchical algorithm
// for global illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995
// (cluster links as point-to-point transport between directional distributions).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/progress.hpp"
#include "geometry/ray_scene.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "solver/hierarchical/cluster_tree.hpp"
#include "solver/system.hpp"

namespace radiosity::detail {

// ---- Sides ----------------------------------------------------------------------------------

/// An element handle's side bit: the back of a two-sided or translucent element is a node of
/// its own (as the matrix solvers number backs). Element ids stay below 2^30.
inline constexpr NodeHandle kBackTag = 0x40000000u;
inline NodeHandle side_handle(std::uint32_t element, bool back) {
  RADIOSITY_ASSERT(element < kBackTag);
  return element | (back ? kBackTag : 0u);
}
inline bool is_back(NodeHandle h) { return !is_cluster(h) && (h & kBackTag) != 0; }
/// The element of an element handle (either side).
inline std::uint32_t element_of(NodeHandle h) { return h & ~(kClusterTag | kBackTag); }

/// How far refinement may split elements below the meshed ones: never when max_depth is 0.
struct SubdivisionLimits {
  std::uint8_t max_depth = 0;   ///< Element::depth of the finest element refinement may make
  std::size_t max_leaves = 0;   ///< stop splitting when the hierarchy has this many leaves
};

/// What refinement did, for the report and the benchmarks.
struct RefineStats {
  std::size_t examined = 0;   ///< pairs the oracle looked at
  std::size_t refined = 0;    ///< of those, split into their children's pairs
  std::size_t links_added = 0;
  std::size_t links_replaced = 0;  ///< existing links that a later pass refined
  std::uint64_t rays = 0;     ///< visibility rays
};

/// The links of a scene and the solve over them. Built empty; refine() makes and refines the
/// links, solve() sweeps them. Keeps the cluster tree (built by the first refine() over the
/// patches not wholly buried, which subdivision does not change), the ray scene and the links
/// between the solves of one Problem.
/// Thread safety: refine() needs exclusive access; solve() and the const members may be called
/// concurrently with each other.
class LinkHierarchy {
 public:
  /// `occluders`: the scene's polygons as a ray scene, shared with the caller (which keeps it
  /// alive as long as this), or null to build one.
  LinkHierarchy(const Scene& scene, std::uint64_t seed, unsigned threads, const RayScene* occluders = nullptr);
  ~LinkHierarchy();
  /// The most bytes refinement may hold in links and pairs (0: kDefaultMemoryBudget): a round
  /// that would pass it throws Error{memory_budget} with the figure before its arrays are made,
  /// naming `field` (a string literal: the option the user sets).
  void set_memory_budget(std::size_t bytes, const char* field);
  /// Whether refine() balances the transport of closed regions (on by default: the sweeps
  /// conserve their power; docs/HIERARCHICAL.md, "Balancing closed regions"). Off, the links'
  /// own estimates are used, as the view factors want them.
  void set_balancing(bool on);
  LinkHierarchy(const LinkHierarchy&) = delete;
  LinkHierarchy& operator=(const LinkHierarchy&) = delete;

  /// One refinement pass against the radiosity `B` of `system` (per unknown): the first call
  /// links the root cluster to itself and refines from there; later calls re-examine every link
  /// with the new radiosity and refine those that now fail the oracle against `threshold`
  /// (W/m^2 of irradiance at the receiver: docs/HIERARCHICAL.md, "Refinement"). Splits elements of `hierarchy` within `limits`; their
  /// ids are appended to `split` (the caller makes their children unknowns). Returns false when
  /// `gate` cancels: the links are then those before the call (elements split so far stay split).
  bool refine(PatchHierarchy& hierarchy, const RadiositySystem& system, const std::vector<Rgb>& B, float threshold,
              const SubdivisionLimits& limits, ProgressGate& gate, std::vector<std::uint32_t>& split,
              RefineStats& stats);

  /// Jacobi sweeps (gather, push, B = E + rho H + tau H', pull) from `B0` (per unknown) until
  /// the residual is below the tolerance or the iteration cap (SolveOptions), with progress and
  /// cancel. H in the result is the irradiance from surfaces only. Sweeps that keep growing
  /// (links that gain energy) start again with each irradiance held to the maximum principle
  /// (SolverResult::held); `hold` holds from the start (a later pass of a solve that needed it).
  /// Without `with_irradiance`, H in the result is left zero: a caller that refines and solves
  /// again takes it once at the end (irradiance()), a gather per pass saved.
  SolverResult solve(const SolverContext& context, const std::vector<Rgb>& B0, bool hold = false,
                     bool with_irradiance = true) const;

  /// The irradiance per unknown that radiosity `B` (per unknown) sends along the links: one
  /// gather and push (`hold`: held to the maximum principle, as solve() holds it). With B = the
  /// emission it is the direct irradiance from the emitters. Onto each side's open part where
  /// it is partly buried, as solve()'s H and B (SolverResult::exposure).
  std::vector<Rgb> irradiance(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                              const std::vector<Rgb>& B, bool hold = false) const;
  /// The display's final gather (docs/HIERARCHICAL.md, "The final gather"): irradiance(), but
  /// the links into open nodes with children reach each leaf by the kernel evaluated there
  /// and its visibility from the source, by shadow rays to the leaf (normalised to what the
  /// linear push delivers), not by the sweeps' linear push: the stronger a link for `scale`
  /// (the scene's radiosity scale, W/m^2: the oracle's threshold over epsilon), the more rays.
  /// A `scale` of 0 (nothing emits: every radiosity is 0) gathers as irradiance() does. Builds
  /// the point-sampling records for its rays and releases them (not to be called concurrently
  /// with anything else on this object). With `rays`, the visibility rays it cast.
  std::vector<Rgb> final_gather(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                                const std::vector<Rgb>& B, float scale, bool hold = false,
                                std::uint64_t* rays = nullptr);

  /// The share of the power that radiosity `B` (per unknown) sends from sides whose rays all
  /// meet receiving surfaces (kEnclosureRays each; estimated from sides drawn by power): near 1
  /// in a closed scene, where no light can leave, so what the power balance calls escaped is
  /// the links' own loss. Thread safety: as solve().
  double enclosed_power_share(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                              const std::vector<Rgb>& B) const;

  /// View factors from the links (ViewFactorMethod::hierarchical at polygon and element level,
  /// docs/VIEW_FACTORS.md): prepare once after refine() (the push's shares at unit radiosity on
  /// every front: a gather), then view_factor_rows() for any leaf elements: per element, its
  /// front's factors F(e -> patch) to the fronts of the patches, indices increasing. They are
  /// the transpose of the gather at that radiosity (adjoint_delivery()'s, for one receiver; the
  /// linear pull left out, as there; wholly buried sides at 0, as view_factor_links() refines):
  /// a row's sum is the irradiance the sweeps would give the element, and a cluster link
  /// spreads over every patch of its source that faces it, so rows are as dense as the links
  /// make them (up to every patch in a closed room). Rows are computed in parallel, each alone,
  /// so the same at any thread count. view_factor_rows() may be called concurrently with
  /// itself, not with prepare_view_factor_rows() or refine().
  void prepare_view_factor_rows(const PatchHierarchy& hierarchy, const RadiositySystem& system);
  /// The exposure of every leaf element side measured now (refine() measures it after its
  /// first pass), so that a first refine() can be given radiosity 0 on wholly buried sides.
  void measure_buried_parts(const PatchHierarchy& hierarchy, const RadiositySystem& system);
  /// The share of element side (`element`, `back`) that is not buried; 1 before it is measured.
  float exposure(std::uint32_t element, bool back = false) const;
  void view_factor_rows(const PatchHierarchy& hierarchy, const std::vector<std::uint32_t>& elements,
                        std::vector<SparseFactors>& rows) const;

  std::size_t link_count() const;
  /// Memory of the links, the cluster tree and the sweeps' per-node arrays, bytes.
  std::size_t bytes() const;
  /// Empty until the first refine() or measure_buried_parts().
  const ClusterTree& tree() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiosity::detail
