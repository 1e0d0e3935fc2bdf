// Form factors F(element -> patch): the fraction of the energy leaving an element that arrives
// at a patch. Estimators can be used on their own (view factors for thermal work) and by the
// solvers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

/// Which estimator computes F(element -> patch). Accuracy and cost are compared in
/// docs/FORM_FACTORS.md.
enum class FormFactorMethod {
  /// The exact unoccluded factor (contour integral, adaptive quadrature over the element) times
  /// the visible fraction from Embree occlusion rays; pairs that no polygon can shadow (shaft
  /// test) cast no rays. Within 0.5 % of the closed forms at the defaults.
  ray_cast,
  /// Cohen & Greenberg 1985: z-buffered item buffers on the five faces of a cube at Gauss points
  /// of the element. Within 2 % when elements are small next to their distance from the
  /// receivers (its proximity limit); aliasing shrinks with hemicube_resolution.
  hemicube,
  /// The exact unoccluded factor only; ignores occlusion (validation, convex enclosures).
  analytic,
  /// Monte Carlo ray shooting: from each element, hemisphere_rays cosine-distributed rays leave
  /// stratified points, and F(e -> j) is the fraction that first hits patch j's front. Factors
  /// to emitting patches, whose noise would show as blotchy direct light, are computed apart:
  /// the exact unoccluded factor times the element's visible fraction of the emitting polygon
  /// (shadow rays). Rows are sparse (at most hemisphere_rays entries plus the emitting
  /// patches), so time and memory grow as elements x rays instead of elements x patches: the
  /// method for meshes of thousands of patches and more. Unbiased; a row's sum is exact in a
  /// closed enclosure, an entry's relative noise is about sqrt((1 - F) / (F hemisphere_rays)).
  monte_carlo,
  /// The default: choose_form_factor_method() picks ray_cast for small meshes (at most
  /// kAutomaticRayCastPairs element-patch pairs, where it takes milliseconds and its unoccluded
  /// factors are exact) and monte_carlo above, where at the defaults it is both faster and more
  /// accurate (docs/FORM_FACTORS.md, "Choosing an estimator"); monte_carlo whenever
  /// specular_depth > 0. view_factors() takes it as ray_cast (small factors matter there).
  automatic,
};

/// Element x patch pairs up to which FormFactorMethod::automatic chooses ray_cast.
inline constexpr double kAutomaticRayCastPairs = 1e4;

/// Options of the estimators; every field has a default. A count or resolution of 0 (or any
/// value outside its range) is an Error naming the field.
struct FormFactorOptions {
  FormFactorMethod method = FormFactorMethod::automatic;
  /// Points per source element, in [1, 64]. Ray cast: the smallest number of
  /// stratified points from which occlusion rays leave (pairs with large factors or a penumbra
  /// get more, see visibility_rays). Hemicube: the hemicubes per element, at the nodes of a
  /// g x g Gauss-Legendre rule when the count is a square g^2 (else at the centres of strata
  /// along the element). Analytic: unused.
  std::uint32_t source_samples = 4;
  /// Ray cast: occlusion rays from each source point to stratified points on the receiving
  /// patch, in [1, 64]. With n = source_samples x visibility_rays and F the pair's
  /// unoccluded factor, a pair that some polygon may shadow casts max(n, min(256 n F, 1024))
  /// rays, then, if some are blocked and some clear, max(4 n, min(1024 n F, 4096)) more.
  std::uint32_t visibility_rays = 4;
  /// Hemicube: top-face resolution in pixels, in [2, 8192]. The four side faces are
  /// resolution x resolution/2. Memory: about 8 x resolution^2 bytes per thread plus
  /// 6 x resolution^2 bytes shared.
  std::uint32_t hemicube_resolution = 256;
  /// Monte Carlo: rays per element (per patch when shooting a column, times the patch's
  /// elements), in [16, 1 << 20].
  std::uint32_t hemisphere_rays = 1024;
  /// Monte Carlo: the emitting patches that get an exact factor (unoccluded factor times shadow
  /// rays) in each element's row, at most; the others are counted by the element's hemisphere
  /// rays like any patch. Chosen per element by their estimated contribution (E A cos cos /
  /// pi r^2 between centroids), so a ceiling of hundreds of emitting facets costs what a few
  /// lamps cost. With at most this many emitting patches in the scene every one is exact (the
  /// rows are the same as without the limit). 0 = every emitting patch exact. Accuracy and
  /// cost: docs/FORM_FACTORS.md, "Many emitters".
  std::uint32_t exact_emitters = 16;
  /// Monte Carlo only: extended form factors (Wallace, Cohen & Greenberg 1987) carry light
  /// between diffuse surfaces through ideal mirrors (Material::specular with specular_exponent
  /// 0; at most this many reflections on a path, weighted by the mean specular reflectance) and
  /// through transmitting polygons, straight on: windows (ior 1, weighted by the mean
  /// transmittance) and refracting glass (ior != 1: at each interface reflected as by a mirror
  /// with the Fresnel reflectance as probability, else straight on; only light that left a
  /// non-emitting surface unless emitted_through_glass, since the second pass's photon map
  /// carries emitted light through glass as sharp caustics). The lights' first shot then
  /// passes windows and glass too (its shadow rays straight on, times each pane's transmittance
  /// and Fresnel transmission; docs/LIGHTS.md). 0 = classic radiosity: specular parts are
  /// ignored and every polygon is opaque. Glossy lobes are not carried. In [0, 16].
  std::uint32_t specular_depth = 0;
  /// With specular_depth > 0: also carry the light that emitting polygons send through
  /// refracting glass (straight on, weighted as above), which is otherwise left to the second
  /// pass's photon map. Off for render_two_pass(), whose caustics would count it twice; on where
  /// no photon pass follows (`radiosity solve` and `bake` set it): without it that light is
  /// lost, and reported as escaped (a glass pane in a closed room: 20 % of the lamp's power).
  bool emitted_through_glass = false;
  /// Back sides: diffuse transmission (Rushmeier & Torrance 1990) and two-sided surfaces, for
  /// every method. A patch whose material has diffuse_transmittance > 0 (a translucent thin
  /// sheet) or is two_sided (a single sheet that reflects on both sides: a partition wall, a
  /// table top as one quad) has two sides. Its back becomes a second Target{patch, Side::back}
  /// (FormFactorEstimator::patches_with_backs(), target_index()), which sparse rows and columns then report,
  /// and its elements get a second row over the back hemisphere (sparse_back_rows(): Rushmeier's
  /// backward form factors). The dense calls (element_rows(), patch_column()) keep to the
  /// fronts of patches. solve() sets this when the scene uses a translucent or two-sided
  /// material. false = every polygon is one-sided: its back absorbs and sees nothing.
  bool diffuse_transmission = false;
  /// Seeds every random stream (ray-cast samples, hemicube orientations).
  std::uint64_t seed = 1;
  unsigned threads = 0;  ///< 0 = all hardware threads; 1 = the calling thread only
};

/// Which side of a patch light leaves from or arrives at: the front faces the polygon's normal
/// (counter-clockwise corners seen from it), the back faces away. Only a translucent or a
/// two-sided patch has a back of its own in the form factors (FormFactorOptions::
/// diffuse_transmission); the back of a one-sided opaque patch absorbs and sees nothing.
enum class Side : std::uint8_t { front, back };

/// A receiver of light: one side of one patch (an index into PatchHierarchy::patches()). Sparse
/// rows index their entries by target: FormFactorEstimator::target_index() and target() convert
/// between the two, so no caller needs to know how the backs are numbered.
struct Target {
  std::uint32_t patch = kNone;
  Side side = Side::front;

  friend bool operator==(const Target& a, const Target& b) { return a.patch == b.patch && a.side == b.side; }
  friend bool operator!=(const Target& a, const Target& b) { return !(a == b); }
};

/// The non-zero entries of one row (or column) of the form-factor matrix, indices increasing.
/// Thread safety: a plain value.
struct SparseFactors {
  std::vector<std::uint32_t> index;  ///< patch ids (a row) or positions in the element list (a column)
  std::vector<float> value;          ///< the factors, > 0
  /// A row's element: the share of its area that is not buried, i.e. not inside a solid
  /// standing on it (the floor under a block resting on it; docs/ARCHITECTURE.md, "Contact and
  /// light leaks"), as the estimator's rays found it. The factors are means over the whole
  /// element, its buried part receiving nothing; the solvers divide them by this to have its
  /// open part's. 1 when the estimator does not measure it (every method but monte_carlo) and
  /// for columns.
  float exposed = 1.0f;
};

/// An estimator bound to one scene and hierarchy (whose geometry it captures at construction,
/// e.g. as an Embree BVH). Results are deterministic for a given seed at any thread count.
/// Thread safety: const member functions may be called concurrently.
class RADIOSITY_API FormFactorEstimator {
 public:
  virtual ~FormFactorEstimator();

  /// F(element -> patch) for each element in `elements` (leaf element ids) and every patch:
  /// writes elements.size() rows of patches().size() floats, row-major, into `out`. Each value
  /// is in [0, 1]; a row sums to at most 1 (to 1 in a closed enclosure, within the method's
  /// accuracy).
  virtual void element_rows(const std::vector<std::uint32_t>& elements, float* out) const = 0;

  /// F(element -> patch) for one patch and each element in `elements` (a column of the matrix;
  /// what a progressive solver needs to shoot from that patch). Equal to the rows' entries
  /// (the hemicube: up to depth ties at shared edges, below 1e-5). Cost per entry: about one
  /// row entry for ray_cast and analytic; for the hemicube, source_samples small rasterisations
  /// of the patch and the patches that may hide it (a shaft query), not full hemicubes.
  virtual void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                            float* out) const = 0;

  /// element_rows() with only the non-zero entries: out[k] (resized to elements.size()) is the
  /// row of elements[k], indexed by patch id (and, with diffuse transmission, by target_index():
  /// the backs of patches_with_backs() come after the fronts of all patches). The default compresses dense rows
  /// computed a few hundred at a time.
  virtual void sparse_element_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const;

  /// patch_column() with only the non-zero entries, indexed by position in `elements`. The
  /// default compresses the dense column. With diffuse transmission `patch` may be any target
  /// (target_index(Target{p, Side::back}) shoots from the back of patch p), and arrivals at the
  /// backs of elements are reported too: index k < elements.size() is the Side::front of
  /// elements[k], elements.size() + k its Side::back.
  virtual void sparse_patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                                   SparseFactors& out) const;

  /// sparse_patch_column() for several patches (out[k] for patches[k]), which an estimator may
  /// compute in parallel; the default calls sparse_patch_column() for each in turn.
  virtual void sparse_patch_columns(const std::vector<std::uint32_t>& patches, const std::vector<std::uint32_t>& elements,
                                    std::vector<SparseFactors>& out) const;

  /// True when the estimator's rows are sparse by construction (monte_carlo): the solvers then
  /// store F sparse, and the matrix methods' memory check uses max_row_entries().
  virtual bool sparse() const;

  /// An upper bound of the non-zero entries of any row; target_count() for dense estimators.
  virtual std::size_t max_row_entries() const;

  /// With FormFactorOptions::diffuse_transmission: the patches that have a back side
  /// (translucent or two-sided materials), increasing. Empty otherwise.
  const std::vector<std::uint32_t>& patches_with_backs() const { return translucent_; }
  /// The same list under its first name, which predates two-sided materials.
  const std::vector<std::uint32_t>& translucent_patches() const { return translucent_; }
  /// Fronts of all patches plus the backs of patches_with_backs(): the index range of a sparse row.
  std::size_t target_count() const { return patch_count_ + translucent_.size(); }
  /// The index of `target` in sparse rows and in sparse_patch_column()'s `patch` argument, or
  /// kNone when the patch is out of range or `target` is the back of a patch without one.
  std::uint32_t target_index(Target target) const;
  /// The target at `index` of a sparse row; Target{} (patch kNone) when index >= target_count().
  Target target(std::uint32_t index) const;

  /// F(back of element -> target) for elements of translucent patches: the fraction of the
  /// energy leaving the element's back side (a Lambertian emitter facing -normal) that
  /// arrives at each target, indexed like sparse_element_rows(). Throws Error{invalid_argument}
  /// for an estimator without diffuse transmission or an element of an opaque patch.
  virtual void sparse_back_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const;

 protected:
  /// `patch_count`: the patches of the hierarchy, the length of a dense row.
  explicit FormFactorEstimator(std::size_t patch_count) : patch_count_(patch_count) {}
  std::size_t patch_count() const { return patch_count_; }
  /// Declares the translucent patches (increasing), for estimators with diffuse transmission.
  void set_translucent_patches(std::vector<std::uint32_t> patches) { translucent_ = std::move(patches); }

 private:
  std::size_t patch_count_;
  std::vector<std::uint32_t> translucent_;
};

/// The estimator options.method names, with FormFactorMethod::automatic resolved for this mesh:
/// monte_carlo when options.specular_depth > 0 or the mesh has more than
/// kAutomaticRayCastPairs element x patch pairs, else ray_cast. Thread safety: pure function.
RADIOSITY_API FormFactorMethod choose_form_factor_method(const PatchHierarchy& hierarchy,
                                                         const FormFactorOptions& options);

/// The method's name as the command line spells it: "ray-cast", "hemicube", "analytic",
/// "monte-carlo", "auto".
RADIOSITY_API const char* to_string(FormFactorMethod method);

/// Makes the estimator named by options.method (automatic: choose_form_factor_method()). The
/// scene and hierarchy must outlive it. Throws Error{invalid_argument} naming the field for a
/// sample count, ray count or resolution outside its range (0 selects the default) or an
/// unknown method. Coincident and interpenetrating polygons are accepted (see find_overlaps()).
/// Thread safety: concurrent calls are safe.
RADIOSITY_API std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(
    const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options);

/// Where view_factors() takes its factors from.
enum class ViewFactorMethod {
  /// Element rows of the estimator that ViewFactorOptions::form_factors names: time and memory
  /// grow as elements x patches.
  estimator,
  /// Hierarchical radiosity's links (SolverMethod::hierarchical, docs/HIERARCHICAL.md), refined
  /// for unit radiosity on every surface against ViewFactorOptions::epsilon: links close to
  /// linear in the scene; the factors at every level are made reciprocal (A_i F_ij = A_j F_ji
  /// exactly) by averaging each pair's two transports.
  hierarchical,
};

/// The surfaces that view_factor_matrix() gives a row and a column each.
enum class ViewFactorLevel {
  group,    ///< the scene's groups (view_factors()'s matrix, as CSR)
  polygon,  ///< every polygon, in Scene::polygons() order (a facet mesh's facets; View3D's surfaces)
  element,  ///< every leaf element of the mesh ViewFactorOptions::mesh makes, in PatchHierarchy::leaves() order
};

/// How view_factor_matrix() corrects the estimated factors (docs/VIEW_FACTORS.md, "Correction").
enum class ViewFactorCorrection {
  /// The estimates as they are: reciprocity and row sums hold within the estimator's accuracy.
  none,
  /// A_i F_ij = A_j F_ji exactly: each pair's transport becomes the mean of its two directions'
  /// estimates (the pattern is the union of both). For open scenes; the sky view factor is the
  /// remainder 1 - sum_j F_ij.
  reciprocity,
  /// Reciprocity and rows that sum to 1, for closed enclosures: the smallest weighted
  /// least-squares change of the reciprocal transports that closes every row (van Leersum
  /// 1989), which keeps the sparsity (only non-zero factors change, each in proportion to
  /// itself).
  enclosure,
};

/// Options of view_factors() and view_factor_matrix(). Every field has a default. Thread
/// safety: a plain value.
struct ViewFactorOptions {
  ViewFactorMethod method = ViewFactorMethod::estimator;
  /// view_factor_matrix(): rows and columns per group, polygon or element.
  ViewFactorLevel level = ViewFactorLevel::polygon;
  /// view_factor_matrix(): the correction applied to the estimates.
  ViewFactorCorrection correction = ViewFactorCorrection::none;
  /// ViewFactorMethod::hierarchical: a link is refined while its transport may vary over its
  /// two ends by more than this (in units of view factor, for unit radiosity), in (0, 1].
  float epsilon = 0.02f;
  /// How finely to mesh; 0 = derive from the scene as solve() does. Finer elements make the
  /// hemicube more accurate (it treats each element as a few points) and cost time for all
  /// methods; ray_cast and analytic integrate each element adaptively and need no fine mesh.
  MeshOptions mesh;
  /// Estimator, samples, resolution, seed and threads.
  FormFactorOptions form_factors;
  /// Groups to report, as rows and columns in this order; empty = every group of the scene in
  /// GroupId order. Only the listed groups' elements are sources, but every polygon still
  /// occludes and receives.
  std::vector<std::string> groups;
  /// The most bytes the factors may take while they are made, 0 = 4 GiB: the matrix's entries
  /// (view_factor_matrix(): 8 bytes each while a block is made, 8 more in the result), or
  /// ViewFactorMethod::hierarchical's links. A computation about to pass it stops with
  /// Error{memory_budget}, naming the figure, before the allocation; at the polygon and element
  /// levels the matrix is first estimated (element rows: from 256 of its rows, of 1 024 or more;
  /// the exact mode: from a sample of 4 096 pairs) and refused then, before the rest are made.
  std::size_t memory_budget_bytes = 0;
  /// Called on the calling thread with Phase::form_factors at the start, at the end and at most
  /// every ~50 ms in between; return false to cancel (the result then has `cancelled` set).
  /// Exceptions it throws propagate out of view_factors().
  ProgressFn on_progress;
};

/// Group-to-group view factors, area-weighted over each source group:
/// F(gi -> gk) = sum over elements e of gi of A_e F(e -> patches of gk) / A(gi).
/// Rows of a closed enclosure sum to 1; A(gi) F(gi -> gk) = A(gk) F(gk -> gi) up to the
/// estimator's accuracy. A group's factor to itself is non-zero only where it can see itself
/// (a concave group). Thread safety: a plain value.
struct GroupViewFactors {
  std::vector<std::string> groups;  ///< row and column names, in order
  std::vector<double> area;         ///< A(gi), scene units squared: the sum of the group's element areas
  /// groups.size() x groups.size(), row-major: factors[i * groups.size() + k] = F(gi -> gk), in [0, 1].
  std::vector<double> factors;
  std::size_t patch_count = 0;    ///< patches of the whole scene (the receivers)
  std::size_t element_count = 0;  ///< source elements of the listed groups
  std::size_t link_count = 0;     ///< ViewFactorMethod::hierarchical: the links (0 otherwise)
  double seconds = 0.0;           ///< wall time of meshing and form factors
  /// The progress callback asked to stop: only some source elements were summed, so the rows
  /// are incomplete.
  bool cancelled = false;

  /// F(groups[from] -> groups[to]).
  double at(std::size_t from, std::size_t to) const { return factors[from * groups.size() + to]; }
};

/// Meshes the scene and computes the group-to-group view-factor matrix without ever holding
/// more than a few thousand element rows (memory O(rows x patches + groups^2), never
/// elements x elements). The same scene, options and seed give bit-identical results at any
/// thread count.
/// FormFactorMethod::automatic means ray_cast here. Throws Error{invalid_scene} for a scene
/// without polygons, Error{invalid_argument} for bad options (naming the field) or a group name
/// that the scene does not have.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API GroupViewFactors view_factors(const Scene& scene, const ViewFactorOptions& options = {});

/// What ViewFactorOptions::correction changed, and how far the estimates were from the two
/// laws before it (after it they hold to rounding). Thread safety: a plain value.
struct ViewFactorCorrectionReport {
  /// Before: the largest |F_ij - A_j F_ji / A_i|, the change of a factor that reciprocity asks
  /// for, in units of view factor.
  double reciprocity_before = 0.0;
  /// Before: the largest and the area-weighted RMS of |1 - sum_j F_ij| over the rows that see
  /// something.
  double row_sum_error_before = 0.0, row_sum_rms_before = 0.0;
  /// The largest |F'_ij - F_ij| the correction made, and its RMS over the stored factors.
  double largest_change = 0.0, rms_change = 0.0;
  /// Rows that see nothing (a floor facet covered by a block that stands on it, a polygon
  /// facing away from every other): left out of the figures above, and left open by the
  /// enclosure correction.
  std::size_t empty_rows = 0;
  /// Enclosure: factors the correction would have made negative (set to 0, and the rows
  /// solved again without them).
  std::size_t clamped = 0;
  int iterations = 0;  ///< enclosure: conjugate-gradient iterations
};

/// A view-factor matrix in compressed sparse rows: row i holds F(i -> columns[k]) = values[k]
/// for k in [row_offsets[i], row_offsets[i + 1]), columns increasing; rows and columns number
/// the same surfaces (ViewFactorLevel), so the matrix is square. Memory: 8 bytes per stored
/// factor plus 8 per row. Thread safety: a plain value.
struct ViewFactorMatrix {
  ViewFactorLevel level = ViewFactorLevel::polygon;
  /// What each row (and column) is: a PolygonId (polygon level), an element id of the mesh
  /// (element level) or a GroupId (group level).
  std::vector<std::uint32_t> ids;
  std::vector<std::string> names;      ///< group level: the group names; else empty
  std::vector<double> area;            ///< per row, scene units squared
  std::vector<std::uint64_t> row_offsets;  ///< rows + 1 entries, row_offsets[0] = 0
  std::vector<std::uint32_t> columns;
  std::vector<float> values;           ///< the factors, > 0
  /// Per row: the sky view factor, the part of the hemisphere above the row's surface (cosine-
  /// weighted) in which no polygon lies at all, estimated by ViewFactorOptions::form_factors.
  /// hemisphere_rays rays per element (every method): what urban-climate codes call the sky
  /// view factor, 0 in a closed enclosure. It is not 1 - sum_j F_ij: the rest of that
  /// remainder sees back faces, obstruction-only polygons, polygons left out by `groups`, or
  /// nothing where a surface is covered (the ground under a building sees the building's
  /// inside: remainder 1, sky 0). A surface lying on another face to face with nothing on its
  /// side (a building's bottom on the ground, with the void under a terrain) sees nothing
  /// either: sky 0 there, though its rays, starting just past the ground, would meet nothing.
  std::vector<double> sky;
  /// Per row: the binomial standard error of `sky`, sqrt(sky (1 - sky) / rays).
  std::vector<double> sky_standard_error;
  /// Per row: the estimated standard error of the row's sum from the estimator alone (Monte
  /// Carlo: binomial, sqrt(S (1 - S) / rays) over the row's rays); empty for estimators that
  /// state none (ray_cast, analytic, hemicube, hierarchical).
  std::vector<double> row_standard_error;
  ViewFactorCorrectionReport correction;
  /// What the caller should know about the result, one line each: polygons that are coincident
  /// and face the same way (z-fighting: a polygon modelled twice), which the exact mode counts
  /// twice in the rows that see them; polygons wound against the surface they belong to
  /// (find_inconsistent_winding()), whose rows look the wrong way; rows that see no surface, only
  /// the sky, in a model that looks wound outward (find_polygons_facing_outward()).
  std::vector<std::string> warnings;
  /// What may surprise the caller but is most often right, one line each: rows that see no
  /// surface because their polygons lie against others in contact (polygon level: a box's bottom
  /// on a floor), rows that see only the sky (a roof above everything else, in a model not wound
  /// outward), and rows that see nothing at all, neither a surface nor the sky (covered: a floor
  /// under a block without a bottom face).
  std::vector<std::string> notes;
  std::string method;              ///< the estimator's name as the command line spells it
  /// Why, when FormFactorMethod::automatic chose it (empty otherwise): at the polygon and element
  /// levels the exact mode (ray_cast) while its thread time, estimated by integrating a sample of
  /// 4 096 pairs, is at most a minute, Monte Carlo rows beyond (docs/VIEW_FACTORS.md, "Modes").
  std::string method_reason;
  std::size_t element_count = 0;   ///< source elements the rows were summed from
  double seconds = 0.0;            ///< wall time of meshing, form factors and correction
  bool cancelled = false;          ///< the progress callback stopped it: rows are incomplete

  std::size_t rows() const { return area.size(); }
  std::size_t non_zeros() const { return values.size(); }
  /// F(row -> column), 0 where not stored (a binary search of the row).
  double at(std::size_t row, std::uint32_t column) const;
};

/// The sparse view-factor matrix between the scene's polygons, elements or groups
/// (options.level), with the correction options.correction asks for. Rows and columns skip
/// obstruction-only polygons (they still hide) and, when options.groups is set, keep the
/// polygons of those groups only. The estimator options.form_factors.method names computes
/// every row (automatic means ray_cast: exact unoccluded factors, occlusion by rays, cost
/// rows x polygons; monte_carlo: hemisphere rays per element, cost and memory rows x rays,
/// the method for large scenes). ViewFactorMethod::hierarchical takes each row from the links
/// (the transpose of their gather at unit radiosity: a cluster link spreads over every patch
/// of its source that faces it, so rows are as dense as the view factors are, up to every
/// polygon in a closed room) and always makes them reciprocal (correction none acts as
/// reciprocity). Memory is bounded by the result plus a few thousand element rows (and the
/// links); the same scene, options and seed give bit-identical results at any thread count.
/// Throws as view_factors() does.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API ViewFactorMatrix view_factor_matrix(const Scene& scene, const ViewFactorOptions& options = {});

/// The name of a level or correction as the command line spells it ("group", "polygon",
/// "element"; "none", "reciprocity", "enclosure").
RADIOSITY_API const char* to_string(ViewFactorLevel level);
RADIOSITY_API const char* to_string(ViewFactorCorrection correction);

/// Unoccluded form factor from a differential area at `point` with unit normal `normal` to a
/// planar convex polygon of `vertex_count` corners (counter-clockwise seen from its front;
/// either orientation gives the same value) by Lambert's contour integral, in [0, 1]. Exact
/// up to rounding; the part of the polygon below the point's tangent plane is clipped away, so
/// 0 when the polygon is wholly behind. Returns 0 for fewer than 3 corners or a null pointer.
/// Thread safety: pure function.
RADIOSITY_API double point_to_polygon_factor(const glm::vec3& point, const glm::vec3& normal,
                                             const glm::vec3* polygon, int vertex_count);

}  // namespace v1
}  // namespace radiosity
