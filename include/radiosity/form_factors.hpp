// Form factors F(element -> patch): the fraction of the energy leaving an element that arrives
// at a patch. Estimators can be used on their own (view factors for thermal work) and by the
// solvers.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

enum class FormFactorMethod {
  ray_cast,  ///< point-to-polygon contour integral x visibility from Embree occlusion rays
  hemicube,  ///< Cohen & Greenberg 1985 (arrives with the form-factor issue)
  analytic,  ///< exact unoccluded polygon-to-polygon factor; ignores occlusion
};

/// Options of the estimators. 0 means "use the default" where stated.
struct FormFactorOptions {
  FormFactorMethod method = FormFactorMethod::ray_cast;
  /// Ray cast: points on the source element at which the point-to-patch factor is evaluated
  /// (stratified). 0 = 4.
  std::uint32_t source_samples = 0;
  /// Ray cast: occlusion rays from each source point to stratified points on the receiving
  /// patch; the visible fraction is weighted by the point-to-point kernel. 0 = 4.
  std::uint32_t visibility_rays = 0;
  /// Hemicube: resolution of the top face in pixels. 0 = 256.
  std::uint32_t hemicube_resolution = 0;
  std::uint64_t seed = 1;
  unsigned threads = 0;  ///< 0 = all hardware threads
};

/// An estimator bound to one scene and hierarchy (whose geometry it captures at construction,
/// e.g. as an Embree BVH). Results are deterministic for a given seed at any thread count.
/// Thread safety: const member functions may be called concurrently.
class RADIOSITY_API FormFactorEstimator {
 public:
  virtual ~FormFactorEstimator();

  /// F(element -> patch) for each element in `elements` and every patch: writes
  /// elements.size() rows of patches().size() floats, row-major, into `out`.
  virtual void element_rows(const std::vector<std::uint32_t>& elements, float* out) const = 0;

  /// F(element -> patch) for one patch and each element in `elements` (a column of the matrix;
  /// what a progressive solver needs to shoot from that patch).
  virtual void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                            float* out) const = 0;
};

/// Makes the estimator named by options.method. The scene and hierarchy must outlive it.
/// Throws Error{invalid_argument} for a sample count or resolution that is 0 after defaults.
RADIOSITY_API std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(
    const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options);

/// Unoccluded form factor from a differential area at `point` with unit normal `normal` to a
/// planar convex polygon (Lambert's contour integral). Exact; 0 when the polygon is behind.
RADIOSITY_API double point_to_polygon_factor(const glm::vec3& point, const glm::vec3& normal,
                                             const glm::vec3* polygon, int vertex_count);

}  // namespace v1
}  // namespace radiosity
