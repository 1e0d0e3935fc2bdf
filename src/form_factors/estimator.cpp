// Choosing and configuring a form-factor estimator.
#include <algorithm>
#include <string>
#include <vector>

#include "form_factors/estimators.hpp"
#include "form_factors/pass1_material.hpp"

namespace radiosity::detail {

FormFactorOptions resolve(const FormFactorOptions& options) {
  FormFactorOptions o = options;
  auto in_range = [](const char* field, std::uint32_t value, std::uint32_t lo, std::uint32_t hi) {
    if (value < lo || value > hi)
      throw Error(ErrorCode::invalid_argument, std::string("form_factors.") + field + " must be in [" +
                                                   std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                                                   std::to_string(value));
  };
  in_range("source_samples", o.source_samples, 1, 64);
  in_range("visibility_rays", o.visibility_rays, 1, 64);
  in_range("hemicube_resolution", o.hemicube_resolution, 2, 8192);
  in_range("hemisphere_rays", o.hemisphere_rays, 16, 1u << 20);
  if (o.specular_depth > 16)
    throw Error(ErrorCode::invalid_argument,
                "form_factors.specular_depth must be in [0, 16], got " + std::to_string(o.specular_depth));
  if (o.specular_depth > 0 && o.method != FormFactorMethod::monte_carlo && o.method != FormFactorMethod::automatic)
    throw Error(ErrorCode::invalid_argument,
                "form_factors.specular_depth > 0 (mirror and window form factors) needs FormFactorMethod::monte_carlo");
  return o;
}

std::vector<std::uint32_t> find_back_patches(const Scene& scene, const PatchHierarchy& hierarchy) {
  std::vector<std::uint32_t> out;
  const std::vector<Patch>& patches = hierarchy.patches();
  for (std::uint32_t j = 0; j < patches.size(); ++j)
    if (pass1_has_back(scene.material(patches[j].material))) out.push_back(j);
  return out;
}

std::vector<std::uint32_t> back_targets(std::size_t patch_count, const std::vector<std::uint32_t>& translucent) {
  std::vector<std::uint32_t> out(patch_count, kNone);
  for (std::size_t k = 0; k < translucent.size(); ++k) out[translucent[k]] = static_cast<std::uint32_t>(patch_count + k);
  return out;
}

void check_back_rows(const FormFactorEstimator& estimator, const PatchHierarchy& hierarchy,
                     const std::vector<std::uint32_t>& elements) {
  const std::vector<std::uint32_t>& translucent = estimator.translucent_patches();
  for (std::uint32_t e : elements)
    if (e >= hierarchy.elements().size() ||
        !std::binary_search(translucent.begin(), translucent.end(), hierarchy.element(e).patch))
      throw Error(ErrorCode::invalid_argument,
                  "sparse_back_rows: element " + std::to_string(e) + " is not an element of a translucent patch");
}

void check_target(const FormFactorEstimator& estimator, std::uint32_t target) {
  if (target >= estimator.target_count())
    throw Error(ErrorCode::invalid_argument, "sparse_patch_column: target " + std::to_string(target) +
                                                 " out of range (" + std::to_string(estimator.target_count()) +
                                                 " targets)");
}

void TargetEstimator::sparse_element_rows(const std::vector<std::uint32_t>& elements,
                                          std::vector<SparseFactors>& out) const {
  if (translucent_patches().empty()) {
    FormFactorEstimator::sparse_element_rows(elements, out);
    return;
  }
  target_rows(elements, false, out);
}

void TargetEstimator::sparse_back_rows(const std::vector<std::uint32_t>& elements,
                                       std::vector<SparseFactors>& out) const {
  check_back_rows(*this, targets_of_, elements);
  target_rows(elements, true, out);
}

void TargetEstimator::sparse_patch_column(std::uint32_t target, const std::vector<std::uint32_t>& elements,
                                          SparseFactors& out) const {
  if (translucent_patches().empty()) {
    FormFactorEstimator::sparse_patch_column(target, elements, out);
    return;
  }
  check_target(*this, target);
  std::vector<float> column(2 * elements.size(), 0.0f);
  target_column(target, elements, column.data());
  compress(column.data(), column.size(), out);
}

void compress(const float* dense, std::size_t count, SparseFactors& out) {
  out.index.clear();
  out.value.clear();
  for (std::size_t k = 0; k < count; ++k)
    if (dense[k] > 0.0f) {
      out.index.push_back(static_cast<std::uint32_t>(k));
      out.value.push_back(dense[k]);
    }
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

void FormFactorEstimator::sparse_element_rows(const std::vector<std::uint32_t>& elements,
                                              std::vector<SparseFactors>& out) const {
  out.assign(elements.size(), SparseFactors{});
  const std::size_t n = patch_count();
  // A few hundred dense rows at a time bound the scratch memory.
  const std::size_t chunk = std::max<std::size_t>(1, (std::size_t{64} << 20) / std::max<std::size_t>(n * sizeof(float), 1));
  std::vector<float> dense;
  std::vector<std::uint32_t> batch;
  for (std::size_t begin = 0; begin < elements.size(); begin += chunk) {
    const std::size_t end = std::min(elements.size(), begin + chunk);
    batch.assign(elements.begin() + static_cast<std::ptrdiff_t>(begin), elements.begin() + static_cast<std::ptrdiff_t>(end));
    dense.resize(batch.size() * n);
    element_rows(batch, dense.data());
    for (std::size_t k = begin; k < end; ++k) {
      const float* row = dense.data() + (k - begin) * n;
      for (std::size_t j = 0; j < n; ++j)
        if (row[j] > 0.0f) {
          out[k].index.push_back(static_cast<std::uint32_t>(j));
          out[k].value.push_back(row[j]);
        }
    }
  }
}

void FormFactorEstimator::sparse_patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                                              SparseFactors& out) const {
  std::vector<float> dense(elements.size());
  patch_column(patch, elements, dense.data());
  detail::compress(dense.data(), dense.size(), out);
}

void FormFactorEstimator::sparse_patch_columns(const std::vector<std::uint32_t>& patches,
                                               const std::vector<std::uint32_t>& elements,
                                               std::vector<SparseFactors>& out) const {
  out.assign(patches.size(), SparseFactors{});
  for (std::size_t k = 0; k < patches.size(); ++k) sparse_patch_column(patches[k], elements, out[k]);
}

void FormFactorEstimator::sparse_back_rows(const std::vector<std::uint32_t>&, std::vector<SparseFactors>&) const {
  throw Error(ErrorCode::invalid_argument,
              "sparse_back_rows: this estimator was made without FormFactorOptions::diffuse_transmission");
}

bool FormFactorEstimator::sparse() const { return false; }

std::size_t FormFactorEstimator::max_row_entries() const { return target_count(); }

std::uint32_t FormFactorEstimator::target_index(Target target) const {
  if (target.patch >= patch_count_) return kNone;
  if (target.side == Side::front) return target.patch;
  // Backs follow the fronts, in the order of patches_with_backs() (increasing).
  const auto it = std::lower_bound(translucent_.begin(), translucent_.end(), target.patch);
  if (it == translucent_.end() || *it != target.patch) return kNone;
  return static_cast<std::uint32_t>(patch_count_ + static_cast<std::size_t>(it - translucent_.begin()));
}

Target FormFactorEstimator::target(std::uint32_t index) const {
  if (index < patch_count_) return Target{index, Side::front};
  if (index < target_count()) return Target{translucent_[index - patch_count_], Side::back};
  return Target{};
}

FormFactorMethod choose_form_factor_method(const PatchHierarchy& hierarchy, const FormFactorOptions& options) {
  if (options.method != FormFactorMethod::automatic) return options.method;
  if (options.specular_depth > 0) return FormFactorMethod::monte_carlo;
  const double pairs = static_cast<double>(hierarchy.leaves().size()) * static_cast<double>(hierarchy.patches().size());
  return pairs <= kAutomaticRayCastPairs ? FormFactorMethod::ray_cast : FormFactorMethod::monte_carlo;
}

const char* to_string(FormFactorMethod method) {
  switch (method) {
    case FormFactorMethod::ray_cast: return "ray-cast";
    case FormFactorMethod::hemicube: return "hemicube";
    case FormFactorMethod::analytic: return "analytic";
    case FormFactorMethod::monte_carlo: return "monte-carlo";
    case FormFactorMethod::automatic: return "auto";
  }
  return "unknown";
}

std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                                const FormFactorOptions& options) {
  FormFactorOptions o = detail::resolve(options);
  o.method = choose_form_factor_method(hierarchy, o);
  switch (o.method) {
    case FormFactorMethod::ray_cast: return detail::make_ray_cast_estimator(scene, hierarchy, o);
    case FormFactorMethod::analytic: return detail::make_analytic_estimator(scene, hierarchy, o);
    case FormFactorMethod::hemicube: return detail::make_hemicube_estimator(scene, hierarchy, o);
    case FormFactorMethod::monte_carlo: return detail::make_monte_carlo_estimator(scene, hierarchy, o);
    case FormFactorMethod::automatic: break;  // resolved above
  }
  throw Error(ErrorCode::invalid_argument,
              "form_factors.method is not one of ray_cast, hemicube, analytic, monte_carlo (got " +
                                               std::to_string(static_cast<int>(o.method)) + ")");
}

}  // namespace v1
}  // namespace radiosity
