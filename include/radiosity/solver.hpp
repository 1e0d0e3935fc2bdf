// Solvers and their result: matrix radiosity (Jacobi, Gauss-Seidel) and progressive refinement.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
namespace detail {
struct SplitSolve;  // the way of the MPI module (src/mpi/) into Problem; not API
}  // namespace detail
inline namespace v1 {

enum class SolverMethod {
  jacobi,        ///< all F precomputed; B' = E + rho F B from the previous sweep
  gauss_seidel,  ///< all F precomputed; each element uses the newest values
  progressive,   ///< shooting, brightest unshot power first (Cohen et al. 1988)
  /// Links between nodes of a cluster hierarchy over the patches and the element quadtrees,
  /// refined where they carry more than HierarchicalOptions::epsilon (Hanrahan, Salzman &
  /// Aupperle 1991, with clustering); Jacobi sweeps with push-pull. No form-factor matrix: the
  /// links' memory grows about linearly with the scene (docs/HIERARCHICAL.md).
  hierarchical,
  /// The default: gauss_seidel while its form-factor rows fit SolveOptions::memory_budget_bytes,
  /// else hierarchical (which keeps no rows); with form_factors.specular_depth > 0 (only the
  /// rows carry mirror paths) it does so only under SpecularPaths::automatic, dropping the
  /// specular paths, else the budget error stands. Chosen by a Problem's first solve;
  /// SolveReport::method says which ran and SolveReport::method_choice why.
  automatic,
};

/// How solve() chooses FormFactorOptions::specular_depth (mirror reflections and window and
/// glass passages carried between diffuse surfaces: the extended first pass, docs/TWO_PASS.md).
enum class SpecularPaths : std::uint8_t {
  /// The default. When form_factors.specular_depth is 0 and the scene has mirror or glass
  /// materials in use (needs_extended_first_pass()), solve() takes specular depth 1 with Monte
  /// Carlo form factors and FormFactorOptions::emitted_through_glass, unless form_factors.method
  /// names another estimator (only Monte Carlo rows carry them) or method is hierarchical (its
  /// links carry none). Without it the light that reaches a mirror or a pane stops there: a
  /// pane in a closed room takes a quarter of its lamp's power. Under SolverMethod::automatic,
  /// when the rows with specular paths (a depth chosen here or given) would exceed
  /// memory_budget_bytes, the solve goes on without them (depth 0, hierarchical) and says so in
  /// a warning. SolveReport::specular_depth_choice says what was chosen and why.
  automatic,
  /// form_factors.specular_depth and emitted_through_glass as given; over the memory budget
  /// with specular_depth > 0 the solve is refused (Error{memory_budget}).
  as_given,
};

/// SolverMethod::hierarchical's refinement (docs/HIERARCHICAL.md).
struct HierarchicalOptions {
  /// A link is refined (its larger end split) while the error of its transport (the spread
  /// of the irradiance it brings over its two nodes, and more: docs/HIERARCHICAL.md, "The
  /// oracle") exceeds epsilon x the scene's mean radiosity estimate (the emitters' and the
  /// lights' power per area times the mean interreflection factor), W/m^2. In (0, 1]; smaller
  /// is more accurate and costs more links.
  float epsilon = 0.05f;
  /// Refinement passes at most: the first links against the emitted light, each later one
  /// refines them against the radiosity solved so far (multigridding), until no link changes.
  int max_passes = 3;
  /// Balance the transport of closed regions (sides whose rays all meet surfaces): each side
  /// then delivers the power it sends and gathers 1 from uniform radiosity, as the true
  /// transport does, so that a room of reflectance near 1 neither loses nor gains light through
  /// the links' per-link errors (docs/HIERARCHICAL.md, "Balancing closed regions"). Off, the
  /// links' own estimates are used (a closed room can then come out 10-60 % off).
  bool balance_closed_regions = true;
};

/// Adaptive subdivision of elements where radiosity varies fast (shadow boundaries, near
/// lights), after the first solve: split, compute the new elements' form factors, continue.
struct AdaptiveOptions {
  bool enabled = false;
  /// Split a leaf when its luminance differs from the interpolated value at one of its corners
  /// by more than this fraction of their mean (or of a floor of 10 % of the scene's mean
  /// reflected luminance, for dark regions). In (0, 1]; smaller splits more.
  float threshold = 0.3f;
  int max_passes = 3;             ///< refinement passes at most, >= 1
  int max_depth = 3;              ///< quadtree levels below the initial elements, >= 1
  /// Leaves at most after refinement; 0 = 4 x the initial leaf count.
  std::size_t max_elements = 0;
};

/// Everything solve() needs; every field has a default.
struct SolveOptions {
  SolverMethod method = SolverMethod::automatic;
  FormFactorOptions form_factors;
  MeshOptions mesh;
  /// Stop when the residual falls below this. The residual is the power not yet propagated
  /// divided by the emitted power: for the matrix methods sum_e A_e |B_e(k) - B_e(k-1)| over
  /// elements and channels, for progressive the unshot power sum_i A_i |dB_i|.
  double tolerance = 1e-3;
  /// Sweeps (matrix) or shooting steps (progressive) at most; 0 = 1000 sweeps / 100 x patches steps.
  int max_iterations = 0;
  /// 0 = all hardware threads; 1 = the calling thread only. Also the estimator's, unless
  /// form_factors.threads is set (non-zero) itself.
  unsigned threads = 0;
  std::uint64_t seed = 1;        ///< overrides form_factors.seed
  /// The most memory the form factors may take, in bytes; 0 = 4 GiB: the matrix methods' rows
  /// (refused before they are computed, with the figure, or SolverMethod::automatic switches
  /// to hierarchical), progressive's cache of columns (it keeps what fits), hierarchical's links
  /// (refinement stops with Error{memory_budget} before a round that would pass it).
  std::size_t memory_budget_bytes = 0;
  /// Whether solve() may choose form_factors.specular_depth for the scene (SpecularPaths).
  SpecularPaths specular_paths = SpecularPaths::automatic;
  /// Shadow rays per element side toward each sky light (Light::sky) where the sky is partly
  /// covered, >= 5: a first fifth decides (all clear or all blocked: no more rays), the rest
  /// estimate the visible part. Points and directions come from one randomised 4D Halton set,
  /// whose error falls nearly as 1 / sky_rays (a stratified set's as 1 / sqrt(sky_rays)): on
  /// issue #15's 22k city the default's element error equals that of 1280 stratified rays
  /// (docs/LIGHTS.md). An occluder covering less than about 5 / sky_rays of the cosine-weighted
  /// sky can go unseen by the first fifth. Read at a Problem's first solve.
  std::uint32_t sky_rays = 640;
  /// With SolverMethod::hierarchical, refinement stays within the meshed elements
  /// (MeshOptions) unless adaptive.enabled, which lets it split elements adaptive.max_depth
  /// levels further (up to adaptive.max_elements leaves); adaptive.threshold is not used there.
  AdaptiveOptions adaptive;
  HierarchicalOptions hierarchical;
  /// Also solve each light group's contribution on its own (one more solve per group, sharing
  /// the form factors and the hierarchy), kept in the Solution (Solution::light_groups()) so
  /// that Solution::relight() recombines them for any weights without solving. The light group
  /// of an emitting polygon is its group (Scene::groups()); a Light's is Light::light_group, or
  /// its name when that is empty, or "light N" (N its index) without either; a light group of
  /// the same name as a polygon group joins it. Adaptive subdivision refines on the
  /// joint solve only; the groups are solved on its final hierarchy.
  bool separate_light_groups = false;
  ProgressFn on_progress;        ///< optional; return false to cancel
};

enum class SolveStatus { converged, iteration_cap, cancelled };

/// What Solution::mesh_vertex_values() and mesh_triangle_values() report, W/m^2 (per scene
/// unit^2) per channel.
enum class Quantity {
  radiosity,            ///< B: the light leaving the surface, emission included
  irradiance,           ///< H: the light arriving, before the reflectance (what lightmaps store)
  direct_irradiance,    ///< the part of H that came straight from the emitters and the lights
  indirect_irradiance,  ///< H minus its direct part: light reflected at least once
};

/// A mesh's triangles as the solve saw them (copied from Scene::meshes() by solve()), so that a
/// Solution can put its values back on the host's vertices and triangles.
struct SolvedMesh {
  std::vector<glm::vec3> positions;          ///< the host's vertices
  std::vector<std::uint32_t> indices;        ///< three per triangle, as the host gave them
  std::vector<PolygonId> triangle_polygon;   ///< per triangle: its polygon, or kNone (skipped)
};

/// Figures about a solve, for people and for `radiosity solve --stats`.
struct SolveReport {
  int iterations = 0;
  double residual = 0.0;
  std::vector<double> residual_history;  ///< after each sweep / step
  std::vector<double> time_history;      ///< seconds since form factors began, same indexing
  std::size_t patch_count = 0;
  std::size_t element_count = 0;         ///< leaves (after adaptive refinement)
  std::size_t refined_elements = 0;      ///< leaves split by adaptive subdivision
  int refinement_passes = 0;
  std::size_t form_factor_bytes = 0;     ///< memory held by form factors (or links) at the peak
  std::size_t link_count = 0;            ///< SolverMethod::hierarchical: links at the end (0 otherwise)
  std::size_t link_pairs_examined = 0;   ///< SolverMethod::hierarchical: node pairs the refinement oracle looked at
  std::uint64_t link_rays = 0;           ///< SolverMethod::hierarchical: the links' visibility rays (refinement)
  std::uint64_t gather_rays = 0;         ///< SolverMethod::hierarchical: the final gather's visibility rays per leaf
  /// The solver that ran (never automatic), and, when SolveOptions::method was automatic, why
  /// (e.g. "the Gauss-Seidel rows could need 7742 MiB, over the memory budget of 4096 MiB");
  /// empty otherwise.
  SolverMethod method = SolverMethod::gauss_seidel;
  std::string method_choice;
  /// The estimator that ran: SolveOptions' form_factors.method with automatic resolved
  /// (choose_form_factor_method()). SolverMethod::hierarchical runs none (its links are its
  /// own transport); there it is the options' method, resolved as for the others, and
  /// estimator_ran() is false.
  FormFactorMethod form_factor_method = FormFactorMethod::automatic;
  /// Whether form_factor_method computed the transport: false for SolverMethod::hierarchical.
  bool estimator_ran() const { return method != SolverMethod::hierarchical; }
  /// FormFactorOptions::specular_depth of the factors: how many mirror reflections and window
  /// passages the solution carries between diffuse surfaces (0: classic radiosity). The
  /// two-pass compositor reads it so that its photon map leaves those paths out.
  std::uint32_t specular_depth = 0;
  /// Whether the factors carried the emitters' light through glass
  /// (FormFactorOptions::emitted_through_glass): render_two_pass() then leaves those paths out
  /// of its caustics.
  bool emitted_through_glass = false;
  /// With SpecularPaths::automatic, what solve() did with the specular depth and why (e.g.
  /// "1 (automatic: the scene has mirror or glass materials)"); empty with SpecularPaths::as_given
  /// or when the scene has no mirror or glass in use.
  std::string specular_depth_choice;
  /// sum A E over the emitting sides plus light_power, W per channel: the scene's lights count
  /// with the power they put onto the surfaces (docs/LIGHTS.md).
  Rgb emitted_power{0.0f};
  /// The part of emitted_power that the lights (Scene::lights()) deliver straight onto the
  /// surfaces: sum over sides of A H_light, W per channel. Light that misses every surface, or
  /// reaches only the back of a one-sided polygon, is not counted.
  Rgb light_power{0.0f};
  Rgb absorbed_power{0.0f};              ///< sum A (1 - rho) H, where H is the irradiance
  /// Power that left the scene: emitted minus absorbed, W per channel (>= 0 up to solver
  /// tolerance): through openings, into the sky, or onto the backs of one-sided polygons.
  Rgb escaped_power{0.0f};
  double seconds_meshing = 0.0;
  double seconds_form_factors = 0.0;
  double seconds_solving = 0.0;
  /// The lights' first shot: every element in the first solve of a Problem, the new elements
  /// of adaptive subdivision; 0 when the values were kept from an earlier solve.
  double seconds_lights = 0.0;
  std::uint64_t light_rays = 0;  ///< the shadow rays of that first shot
  std::vector<std::string> warnings;
};

/// One light group's contribution to a solution (SolveOptions::separate_light_groups): what the
/// scene would be with only that group's emitters on, per element id (inner nodes hold the
/// area-weighted mean of their children).
struct LightGroupSolution {
  std::string name;                   ///< the emitters' group
  std::vector<Rgb> radiosity;         ///< B, front sides
  std::vector<Rgb> back_radiosity;    ///< empty when the solution has no back sides
  std::vector<Rgb> irradiance;        ///< H, front sides
  std::vector<Rgb> direct_irradiance; ///< the part of H straight from this group's emitters
};

/// The result of solve(): element radiosity on the hierarchy it was solved on.
/// Move-only value; thread safety: const member functions may be called concurrently.
class RADIOSITY_API Solution {
 public:
  Solution() = default;
  /// `radiosity`, `ambient_radiosity` and `back_radiosity` are indexed by element id (inner
  /// nodes included); `ambient_radiosity` is reflectance x ambient per element (reflectance +
  /// diffuse transmittance for a translucent one, which the ambient reaches on both sides), or
  /// empty for none; `back_radiosity` is the radiosity leaving the backs of translucent elements (0
  /// elsewhere), or empty when the scene has no translucent material; `irradiance` is the
  /// front's irradiance per element id, or empty, and `direct_irradiance` the part of it that
  /// came straight from the emitters, or empty.
  Solution(PatchHierarchy hierarchy, std::vector<Rgb> radiosity, std::vector<std::string> groups,
           SolveStatus status, SolveReport report, Rgb ambient = Rgb(0.0f),
           std::vector<Rgb> ambient_radiosity = {}, std::vector<Rgb> back_radiosity = {},
           std::vector<Rgb> irradiance = {}, std::vector<Rgb> direct_irradiance = {});
  Solution(Solution&&) noexcept = default;
  Solution& operator=(Solution&&) noexcept = default;
  Solution(const Solution&) = delete;
  Solution& operator=(const Solution&) = delete;

  SolveStatus status() const { return status_; }
  const SolveReport& report() const { return report_; }
  const PatchHierarchy& hierarchy() const { return hierarchy_; }
  /// Radiosity B (W/m^2) per element id; inner nodes hold the area-weighted mean of their
  /// children (weighted by their open area where exposure() is given). This is the front
  /// side's; a translucent element (Material::diffuse_transmittance) includes what its back
  /// receives and transmits. Where exposure() is below 1, the open part's.
  const std::vector<Rgb>& radiosity() const { return radiosity_; }
  /// Per element id, the share of its area that is not buried: not inside a solid standing on
  /// it, such as the floor under a block resting on it (docs/ARCHITECTURE.md, "Contact and
  /// light leaks"); inner nodes the area-weighted mean of their children. Empty when nothing is
  /// buried or the solve did not measure it (every method does but those over
  /// FormFactorMethod::analytic, which sees no occlusion): every element taken as open. Where an
  /// element is partly buried, its values (radiosity, irradiance) are those of its open part,
  /// which is what shows (a floor element half under a block is not shown at half its light;
  /// over the hemicube, whose rows are their element's centre's, where the centre is open),
  /// and it sends area x exposure x
  /// radiosity; group_radiosity() and mesh_triangle_values() weight by that, so that they
  /// stay power over area, a buried part counting as dark.
  const std::vector<float>& exposure() const { return exposure_; }
  /// Gives the solution its exposure() (solve() does). Throws Error{invalid_argument} when it
  /// is neither empty nor one value per element id.
  void set_exposure(std::vector<float> exposure);
  /// Back sides: the radiosity leaving the back side of each element id, rho' H_back + tau
  /// H_front: what a translucent element's back transmits (tau, diffuse_transmittance) plus
  /// what the back reflects (rho' = rho for a two-sided material, 0 for a one-sided one); 0 for
  /// one-sided opaque elements. Empty when the scene has no translucent or two-sided material:
  /// every back is black.
  const std::vector<Rgb>& back_radiosity() const { return back_radiosity_; }
  /// Irradiance H (W/m^2) arriving at the front of each element id from every surface and light, before
  /// the element's own reflectance: B = E + rho H (+ tau H' for a translucent one, H' its back's).
  /// What a lightmap stores, and defined where a channel of rho is 0 (where (B - E) / rho is
  /// not). Inner nodes hold the area-weighted mean of their children. Empty only for a Solution
  /// constructed without it; solve() always fills it (zero when nothing emits).
  const std::vector<Rgb>& irradiance() const { return irradiance_; }
  /// The part of irradiance() that arrives straight from the emitters and the lights, per
  /// element id: sum over targets t of F(e -> t) E_t plus the lights' first shot (the element's
  /// mean irradiance from Scene::lights(), by shadow rays; docs/LIGHTS.md). irradiance() minus
  /// it is the indirect part, light that has been reflected (or transmitted) at least once.
  /// Empty for a cancelled solve.
  const std::vector<Rgb>& direct_irradiance() const { return direct_irradiance_; }
  /// back_radiosity() per vertex for display (empty when it is empty); no ambient term.
  std::vector<Rgb> vertex_back_radiosity() const;
  Rgb patch_radiosity(std::uint32_t patch) const;
  /// The ambient radiosity of progressive refinement (Cohen et al. 1988): the unshot radiosity
  /// that remained, times the mean interreflection factor 1 / (1 - mean reflectance). Zero
  /// for the matrix methods and for a converged progressive solve below tolerance it is small.
  Rgb ambient() const { return ambient_; }
  /// radiosity() plus reflectance x ambient per element: the usual display of an unfinished
  /// progressive solution. Equals radiosity() when the ambient is zero.
  std::vector<Rgb> radiosity_with_ambient() const;
  /// Per-vertex radiosity for display (see PatchHierarchy::vertex_values), optionally with
  /// the ambient term.
  std::vector<Rgb> vertex_radiosity(bool with_ambient = false) const;
  /// Area-weighted mean radiosity over the patches of a group (their power over their area:
  /// buried parts count as dark, exposure()). Throws Error{invalid_argument}
  /// naming the group when the scene has no such group.
  Rgb group_radiosity(std::string_view group) const;
  /// The same over the backs of the group's patches (back_radiosity(); 0 where a patch is
  /// one-sided, and for every group when back_radiosity() is empty). Throws as group_radiosity().
  Rgb group_back_radiosity(std::string_view group) const;
  double group_area(std::string_view group) const;

  /// `quantity` per triangle of mesh `mesh` (a MeshId of the scene that was solved), in the
  /// host's triangle order: the area-weighted mean over the triangle's elements; 0 for a
  /// triangle add_mesh() skipped. Throws Error{invalid_argument} for an unknown mesh id, or a
  /// quantity the solution does not hold (direct irradiance of a cancelled solve).
  std::vector<Rgb> mesh_triangle_values(MeshId mesh, Quantity quantity) const;
  /// `quantity` per vertex of mesh `mesh`, in the host's vertex order: at each triangle corner
  /// the continuous interpolated field (as vertex_radiosity() interpolates), averaged over the
  /// triangles that share the vertex, weighted by their area; 0 for a vertex no kept triangle
  /// uses. Throws as mesh_triangle_values().
  std::vector<Rgb> mesh_vertex_values(MeshId mesh, Quantity quantity) const;
  /// `quantity` per element id (inner nodes hold the area-weighted mean of their children):
  /// radiosity(), irradiance(), direct_irradiance() or their difference, clamped at 0. Throws
  /// Error{invalid_argument} for a quantity the solution does not hold (direct irradiance of a
  /// cancelled solve).
  std::vector<Rgb> element_values(Quantity quantity) const;
  /// The light groups solved on their own (SolveOptions::separate_light_groups), in the order of
  /// the scene's groups, each as solved (weight 1); empty otherwise. A relit solution shares
  /// them with the solution it came from. radiosity() is the sum over k of
  /// light_group_weights()[k] x light_groups()[k].radiosity, within the solver's tolerance (and
  /// so are irradiance(), back_radiosity() and direct_irradiance()).
  const std::vector<LightGroupSolution>& light_groups() const;
  /// The weight of each light group in this solution: 1 each for a solve, the weights given for
  /// a relit one.
  const std::vector<Rgb>& light_group_weights() const { return light_group_weights_; }
  /// group_radiosity() of light group `light_group`'s contribution to this solution (its
  /// weight times its radiosity). Throws Error{invalid_argument} for a light group out of range
  /// or an unknown group.
  Rgb light_group_radiosity(std::size_t light_group, std::string_view group) const;
  /// element_values() of light group `light_group`'s contribution to this solution: its weight
  /// times its values (LightGroupSolution), per element id. For a light group's values on a host
  /// mesh, relight() with that group's weight alone and ask the result's mesh_vertex_values() or
  /// mesh_triangle_values(). Throws Error{invalid_argument} for a light group out of range.
  std::vector<Rgb> light_group_values(std::size_t light_group, Quantity quantity) const;
  /// Gives the solution its light groups at weight 1 (solve() does). Throws
  /// Error{invalid_argument} when an array does not have one value per element (back_radiosity:
  /// or is empty).
  void set_light_groups(std::vector<LightGroupSolution> groups);
  /// The solution with light group k weighted by weights[k] (an RGB weight each: 0 switches a
  /// group off, 0.5 dims it, a colour tints it): radiosity, back radiosity, irradiance and
  /// direct irradiance are the weighted sums of the groups'. The weights are absolute (relighting
  /// a relit solution weights the solved groups again, not the previous weights). No solve and
  /// no copy of the groups: linear in elements x groups (bench_relight: about 10 ms for 100k
  /// elements and 8 groups). The report and status are this solution's; the ambient term is
  /// dropped. Throws Error{invalid_argument} unless there is one finite weight per light group.
  Solution relight(const std::vector<Rgb>& weights) const;
  /// The meshes of the solved scene, by MeshId.
  const std::vector<SolvedMesh>& meshes() const { return meshes_; }
  /// Gives the solution its scene's meshes (solve() does), for the mesh_*_values() calls.
  void set_meshes(std::vector<SolvedMesh> meshes) { meshes_ = std::move(meshes); }
  const std::vector<std::string>& groups() const { return groups_; }
  /// The solved scene's origin (Scene::origin(); solve() sets it): the positions of
  /// hierarchy() and meshes() are relative to it, and write_ply() and write_mesh_ply() add it
  /// back, so that their files are in the scene file's coordinates.
  glm::dvec3 origin() const { return origin_; }
  void set_origin(const glm::dvec3& origin) { origin_ = origin; }

 private:
  GroupId group_id(std::string_view group) const;
  const SolvedMesh& solved_mesh(MeshId mesh) const;
  /// light_groups()[light_group]; throws Error{invalid_argument} naming `caller` when out of range.
  const LightGroupSolution& solved_light_group(std::size_t light_group, const char* caller) const;

  PatchHierarchy hierarchy_;
  std::vector<Rgb> radiosity_;
  std::vector<std::string> groups_;
  SolveStatus status_ = SolveStatus::converged;
  SolveReport report_;
  Rgb ambient_{0.0f};
  std::vector<Rgb> ambient_radiosity_;
  std::vector<Rgb> back_radiosity_;
  std::vector<Rgb> irradiance_;
  std::vector<Rgb> direct_irradiance_;
  std::vector<float> exposure_;
  std::vector<SolvedMesh> meshes_;
  glm::dvec3 origin_{0.0};
  /// Shared between a solution and the solutions relit from it (immutable); null for none.
  std::shared_ptr<const std::vector<LightGroupSolution>> light_groups_;
  std::vector<Rgb> light_group_weights_;
};

/// Checks options; throws Error{invalid_argument} naming the first bad field.
RADIOSITY_API void validate(const SolveOptions& options);

/// What the first solve() of a Problem will do, decided without solving (Problem::plan()):
/// the choices SolveReport states afterwards, and the memory figure behind them.
struct SolvePlan {
  /// The solver that will run (never automatic) and, when SolveOptions::method was automatic,
  /// why (SolveReport::method_choice).
  SolverMethod method = SolverMethod::gauss_seidel;
  std::string method_choice;
  /// The estimator (never automatic): of the rows costed below, and the one that will run
  /// unless `method` is hierarchical (SolveReport::form_factor_method).
  FormFactorMethod form_factor_method = FormFactorMethod::automatic;
  std::uint32_t specular_depth = 0;   ///< SolveReport::specular_depth
  std::string specular_depth_choice;  ///< SolveReport::specular_depth_choice
  /// Bytes that the Gauss-Seidel and Jacobi rows could need (one row per leaf, and per back of
  /// a translucent or two-sided leaf) with `row_form_factor_method`: the figure that
  /// SolverMethod::automatic compares with SolveOptions::memory_budget_bytes and a matrix method
  /// named is refused by. 0 when the method was named and holds no rows (hierarchical,
  /// progressive).
  std::size_t row_bytes = 0;
  bool sparse_rows = false;  ///< those rows are sparse (an index and a float per entry), else dense
  /// The estimator of those rows: form_factor_method, unless SolverMethod::automatic dropped
  /// the specular paths over the budget (then the one with them, which was costed).
  FormFactorMethod row_form_factor_method = FormFactorMethod::automatic;
};

/// A scene set up for solving, kept across solves: its patch hierarchy (refined in place by
/// adaptive subdivision), its form-factor estimator (with whatever it builds and caches: BVHs,
/// visibility) and the form factors the matrix methods have computed (or the hierarchical
/// solver's links, re-examined for the new radiosity). Solving it again, with the
/// materials' emission or with other emission per polygon (relighting, light groups, a lamp
/// switched off), reuses all of that: a matrix method's second solve costs its sweeps only. The
/// estimator is made on the first solve that has something to emit. The lights' first shot
/// (their direct irradiance on every element, docs/LIGHTS.md) is computed by the first solve of
/// a scene with lights and kept: a relit solve(polygon_emission) keeps the lights shining and
/// changes the polygons' emission only. Progressive refinement
/// keeps the columns it shot (within SolveOptions::memory_budget_bytes), so a relit solve
/// computes only the columns of patches not shot before.
///
///   Problem problem(scene, options);
///   Solution lit = problem.solve();                    // meshes were made in the constructor
///   std::vector<Rgb> E(scene.polygons().size(), Rgb(0.0f));
///   E[lamp] = Rgb(10.0f);
///   Solution relit = problem.solve(E);                 // same form factors, new emission
///
/// `scene` must outlive the Problem and must not change while it lives. Move-only; a
/// moved-from Problem may only be assigned to or destroyed.
/// Thread safety: solve() needs exclusive access (it may refine the hierarchy and adds factors);
/// const member functions may be called concurrently with each other.
class RADIOSITY_API Problem {
 public:
  /// Validates `options` (validate()) and meshes the scene (PatchHierarchy(scene, options.mesh)).
  /// Throws as solve(scene, options) does for bad options and a scene without polygons.
  explicit Problem(const Scene& scene, const SolveOptions& options = {});
  /// A Problem keeps a reference to its scene, so a temporary one cannot be given.
  explicit Problem(Scene&& scene, const SolveOptions& options = {}) = delete;
  ~Problem();
  Problem(Problem&&) noexcept;
  Problem& operator=(Problem&&) noexcept;
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  const Scene& scene() const;
  /// The options as they are applied: form_factors.method resolved (choose_form_factor_method()),
  /// seed, threads and diffuse_transmission filled in, iteration cap and memory budget defaulted.
  const SolveOptions& options() const;
  /// The hierarchy the next solve works on (after adaptive subdivision, the refined one).
  const PatchHierarchy& hierarchy() const;
  /// Bytes of form factors kept between solves (the matrix methods' rows, progressive
  /// refinement's columns, the hierarchical solver's links and cluster tree).
  std::size_t form_factor_bytes() const;
  /// What the first solve() will do (SolvePlan), decided now: the automatic method and
  /// specular depth chosen as solve() chooses them (solve() then keeps these choices). Costs
  /// making the estimator (a BVH of the scene for the ray estimators) unless the method is
  /// hierarchical; computes no form factors. Throws what solve() throws when making the
  /// estimator.
  SolvePlan plan();

  /// Solves with the emission of the scene's materials. The result is that of
  /// solve(scene, options) for a fresh Problem, and what solve(scene, options) documents holds
  /// here too. SolveReport::seconds_meshing counts the meshing once, in the first solve.
  Solution solve();
  /// Solves with `polygon_emission[p]` (W/m^2, per index of Scene::polygons(); leaving the
  /// front, and the back too for a two-sided material) in place of each material's emission.
  /// Throws Error{invalid_argument} unless there is one finite, non-negative value per polygon.
  /// The Monte Carlo estimator gives its exact emitter factors (FormFactorOptions::
  /// exact_emitters) to the patches that emit in the scene's materials; newly emitting patches
  /// are counted by its hemisphere rays: unbiased, but their direct light is noisier. The
  /// scene's lights shine as in solve() (their first shot is kept from an earlier solve).
  Solution solve(const std::vector<Rgb>& polygon_emission);

 private:
  struct Impl;
  friend Solution solve(const Scene& scene, const SolveOptions& options);
  friend struct detail::SplitSolve;
  std::unique_ptr<Impl> impl_;
};

/// Meshes the scene, computes form factors and solves for radiosity. Throws Error for bad
/// options or when a matrix method asked for by name would exceed memory_budget_bytes (the
/// message gives the size and suggests hierarchical, progressive or a coarser mesh; the default
/// SolverMethod::automatic takes the hierarchical solver instead), and Error{invalid_scene} naming two
/// polygons for coincident or interpenetrating surfaces (find_overlaps(); checked when the form
/// factors are set up, so a scene that emits nothing returns B = 0 without the check; a scene with
/// lights (Scene::lights()) is solved even when no polygon emits: the lights are the first shot,
/// docs/LIGHTS.md). A cancelled solve returns the last
/// consistent estimate with status cancelled (cancelled while meshing, which reports
/// Phase::meshing: a Solution without elements or meshes).
/// Light that leaves the scene is diagnosed in SolveReport::warnings: emitters that face away
/// from every surface (find_emitters_facing_away()), apart from those that lie against a
/// polygon facing them (in contact: a fixture's top against a ceiling); emitters whose light is
/// caught right in front of them (90 % of their rays meet a surface within a tenth of their
/// size: a lamp wound to face the ceiling it hangs 1 cm under), whose light does not leave but
/// hardly reaches the scene; and, for a converged
/// solve, a scene that looks closed (over 95 % of the emitters' light meets a polygon directly,
/// by rays) but loses more than half its emitted power (SolveReport::escaped_power): light that
/// arrives at the back of a one-sided polygon is lost, so its polygons probably face outwards
/// (not judged when the scene's lights reach surfaces: their reflected light leaves open scenes
/// as a matter of course); when the emitters' own light leaves too, the same is said when
/// find_polygons_facing_outward() finds most of the one-sided area wound outward.
/// The same as Problem(scene, options).solve(), without keeping the Problem.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API Solution solve(const Scene& scene, const SolveOptions& options = {});

}  // namespace v1
}  // namespace radiosity
