// Factories of the concrete estimators, resolved by make_form_factor_estimator().
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "radiosity/form_factors.hpp"

namespace radiosity::detail {

/// Options with defaults filled in and checked (throws Error{invalid_argument}).
FormFactorOptions resolve(const FormFactorOptions& options);

/// The patches with a back side (pass1_has_back(): translucent or two-sided), increasing: the
/// k-th one's back is target patch count + k, for every estimator and for the solvers.
std::vector<std::uint32_t> find_back_patches(const Scene& scene, const PatchHierarchy& hierarchy);
/// Per patch: its back target (patch_count + k for translucent[k]), or kNone for an opaque patch.
std::vector<std::uint32_t> back_targets(std::size_t patch_count, const std::vector<std::uint32_t>& translucent);

/// What sparse_back_rows() accepts: throws Error{invalid_argument} naming the first element that
/// is not an element of one of estimator.translucent_patches().
void check_back_rows(const FormFactorEstimator& estimator, const PatchHierarchy& hierarchy,
                     const std::vector<std::uint32_t>& elements);
/// What sparse_patch_column() accepts: throws Error{invalid_argument} unless target <
/// estimator.target_count().
void check_target(const FormFactorEstimator& estimator, std::uint32_t target);
/// The entries of dense[0, count) that are > 0, with their positions, into `out` (cleared).
void compress(const float* dense, std::size_t count, SparseFactors& out);

/// Wallace et al.'s ray-cast estimator with the exact unoccluded part and shaft culling
/// (ray_cast.cpp). `options` must come from resolve().
std::unique_ptr<FormFactorEstimator> make_ray_cast_estimator(const Scene&, const PatchHierarchy&,
                                                             const FormFactorOptions&);
/// Cohen & Greenberg's hemicube: item buffers rasterised on the CPU at hemicube_resolution, at
/// source_samples Gauss-Legendre points per element.
std::unique_ptr<FormFactorEstimator> make_hemicube_estimator(const Scene&, const PatchHierarchy&,
                                                             const FormFactorOptions&);

/// Monte Carlo ray shooting with ray_cast's factors for emitting patches (monte_carlo.cpp).
std::unique_ptr<FormFactorEstimator> make_monte_carlo_estimator(const Scene&, const PatchHierarchy&,
                                                                const FormFactorOptions&);

/// point_to_polygon_factor() in float for up to 8 corners: about twice as fast, relative error
/// ~1e-5 for the configurations of a patch hierarchy (falls back to double when x is a corner).
float point_to_polygon_factor_fast(const glm::vec3& x, const glm::vec3& n, const glm::vec3* polygon, int vertex_count);
/// Lambert's contour sum of point_to_polygon_factor() for a polygon already clipped to the
/// hemisphere above the point: `r` holds its `m` corners relative to the point, `n` is the
/// point's unit normal. In [0, 1].
double contour_factor(const glm::dvec3* r, int m, const glm::dvec3& n);

/// What a ray-cast (or analytic) estimator has done since it was made, for benchmarks.
struct RayCastCounters {
  std::uint64_t factors = 0;   ///< element-patch factors computed
  std::uint64_t shadowed = 0;  ///< of those, pairs that the shaft test could not clear (rays cast)
  std::uint64_t rays = 0;      ///< occlusion rays cast
};
/// Fills `out` and returns true when `estimator` is a ray-cast or analytic estimator.
bool ray_cast_counters(const FormFactorEstimator& estimator, RayCastCounters& out);

/// An estimator whose sparse rows and columns, once some patches have backs (diffuse
/// transmission), run over every target and come from its own target_rows() and
/// target_column(); without backs they are FormFactorEstimator's, from the dense rows and
/// columns. The ray-cast, analytic and hemicube estimators are.
/// Thread safety: as FormFactorEstimator, const members may be called concurrently.
class TargetEstimator : public FormFactorEstimator {
 public:
  void sparse_element_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const override;
  void sparse_back_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const override;
  void sparse_patch_column(std::uint32_t target, const std::vector<std::uint32_t>& elements,
                           SparseFactors& out) const override;

 protected:
  explicit TargetEstimator(const PatchHierarchy& hierarchy)
      : FormFactorEstimator(hierarchy.patches().size()), targets_of_(hierarchy) {}
  /// The rows of the elements' fronts (backs when `back`) over every target, entries > 0 only.
  virtual void target_rows(const std::vector<std::uint32_t>& elements, bool back,
                           std::vector<SparseFactors>& out) const = 0;
  /// F(. -> target) into `column` (2 elements.size() zeros): the front of elements[k] at k, its
  /// back at elements.size() + k when its patch has one.
  virtual void target_column(std::uint32_t target, const std::vector<std::uint32_t>& elements,
                             float* column) const = 0;

 private:
  const PatchHierarchy& targets_of_;
};

/// A form-factor estimator that also gives columns from the elements' backs: the ray-cast and
/// analytic estimators, whose backward factors the Monte Carlo estimator uses (a type, so that
/// asking another estimator for them cannot compile).
/// Thread safety: as FormFactorEstimator, const members may be called concurrently.
class BackColumnEstimator : public TargetEstimator {
 public:
  /// patch_column() from the backs of the elements, each a Lambertian surface facing -normal:
  /// F(back of e -> patch) for diffuse transmission.
  virtual void back_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const = 0;

 protected:
  using TargetEstimator::TargetEstimator;
};

/// The unoccluded estimator: the ray-cast estimator's exact point-to-polygon factor integrated
/// over the element by adaptive Gauss quadrature, without visibility.
std::unique_ptr<BackColumnEstimator> make_analytic_estimator(const Scene&, const PatchHierarchy&,
                                                             const FormFactorOptions&);

}  // namespace radiosity::detail
