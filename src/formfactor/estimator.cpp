// Choosing and configuring a form-factor estimator.
#include <string>

#include "formfactor/estimators.hpp"
#include "geometry/overlap.hpp"

namespace radiosity::detail {

FormFactorOptions resolve(const FormFactorOptions& options) {
  FormFactorOptions o = options;
  if (o.source_samples == 0) o.source_samples = o.method == FormFactorMethod::analytic ? 16 : 4;
  if (o.visibility_rays == 0) o.visibility_rays = 4;
  if (o.hemicube_resolution == 0) o.hemicube_resolution = 256;
  if (o.hemicube_resolution < 2 || o.hemicube_resolution > 8192)
    throw Error(ErrorCode::invalid_argument, "form_factors.hemicube_resolution must be in [2, 8192] (0 = 256), got " +
                                                 std::to_string(o.hemicube_resolution));
  if (o.source_samples > 64)
    throw Error(ErrorCode::invalid_argument, "form_factors.source_samples must be in [1, 64] (0 = default), got " +
                                                 std::to_string(o.source_samples));
  if (o.visibility_rays > 64)
    throw Error(ErrorCode::invalid_argument,
                "form_factors.visibility_rays must be in [1, 64] (0 = 4), got " + std::to_string(o.visibility_rays));
  return o;
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                                const FormFactorOptions& options) {
  const FormFactorOptions o = detail::resolve(options);
  // Coincident or interpenetrating surfaces would give factors that are wrong without a sign.
  detail::check_no_overlaps(scene, "form factors");
  switch (o.method) {
    case FormFactorMethod::ray_cast: return detail::make_ray_cast_estimator(scene, hierarchy, o);
    case FormFactorMethod::analytic: return detail::make_analytic_estimator(scene, hierarchy, o);
    case FormFactorMethod::hemicube: return detail::make_hemicube_estimator(scene, hierarchy, o);
  }
  throw Error(ErrorCode::invalid_argument, "form_factors.method is not one of ray_cast, hemicube, analytic (got " +
                                               std::to_string(static_cast<int>(o.method)) + ")");
}

}  // namespace v1
}  // namespace radiosity
