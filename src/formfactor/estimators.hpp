// Factories of the concrete estimators, resolved by make_form_factor_estimator().
#pragma once

#include <memory>

#include "radiosity/form_factors.hpp"

namespace radiosity::detail {

/// Options with defaults filled in and checked (throws Error{invalid_argument}).
FormFactorOptions resolve(const FormFactorOptions& options);

std::unique_ptr<FormFactorEstimator> make_ray_cast_estimator(const Scene&, const PatchHierarchy&,
                                                             const FormFactorOptions&);
/// The unoccluded estimator: the point-to-polygon factor integrated over the source on a fixed
/// midpoint grid, no visibility.
std::unique_ptr<FormFactorEstimator> make_analytic_estimator(const Scene&, const PatchHierarchy&,
                                                             const FormFactorOptions&);

}  // namespace radiosity::detail
