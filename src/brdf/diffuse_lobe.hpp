// Private base for the models that are a Lambertian term plus one glossy lobe (Phong,
// Blinn-Phong, Ward): f = diffuse / pi + lobe. Sampling picks the diffuse term or the lobe in
// proportion to the mean of their reflectance parameters and weights with the combined pdf
// (one-sample MIS, balance heuristic; Veach & Guibas 1995). Not installed.
#pragma once

#include <cmath>
#include <optional>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
namespace detail {
namespace brdf {

class DiffusePlusLobe : public Brdf {
 public:
  Rgb eval(const glm::vec3& wo, const glm::vec3& wi) const final {
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return Rgb(0.0f);
    return diffuse_over_pi_ + lobe_eval(wo, wi);
  }

  float pdf(const glm::vec3& wo, const glm::vec3& wi) const final {
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    return (1.0f - p_lobe_) * cosine_hemisphere_pdf(wi) + (p_lobe_ > 0.0f ? p_lobe_ * lobe_pdf(wo, wi) : 0.0f);
  }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u_in) const final {
    if (!(wo.z > 0.0f)) return std::nullopt;
    const glm::vec2 u = clamp01(u_in);
    glm::vec3 wi;
    if (u.x < p_lobe_) {
      const std::optional<glm::vec3> w = lobe_sample(wo, glm::vec2(remap_below(u.x, p_lobe_), u.y));
      if (!w) return std::nullopt;
      wi = *w;
    } else {
      wi = sample_cosine_hemisphere(glm::vec2(remap_above(u.x, p_lobe_), u.y));
    }
    if (!(wi.z > 0.0f)) return std::nullopt;
    const float p = pdf(wo, wi);
    if (!(p > 0.0f) || !std::isfinite(p)) return std::nullopt;
    return BrdfSample{wi, eval(wo, wi) * (wi.z / p), p, false};
  }

  /// diffuse exactly, plus the lobe's albedo estimated with the lobe's own sampler on the
  /// centres of a 128 x 128 grid of u (deterministic; smoother than the mixture's weight).
  Rgb albedo(const glm::vec3& wo) const final {
    if (!(wo.z > 0.0f)) return Rgb(0.0f);
    const Rgb diffuse = diffuse_over_pi_ * kPi;
    if (!(p_lobe_ > 0.0f)) return diffuse;
    constexpr int kGrid = 128;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < kGrid; ++j) {
      for (int i = 0; i < kGrid; ++i) {
        const glm::vec2 u((static_cast<float>(i) + 0.5f) / kGrid, (static_cast<float>(j) + 0.5f) / kGrid);
        const std::optional<glm::vec3> wi = lobe_sample(wo, u);
        if (!wi || !(wi->z > 0.0f)) continue;
        const float p = lobe_pdf(wo, *wi);
        if (!(p > 0.0f) || !std::isfinite(p)) continue;
        const Rgb w = lobe_eval(wo, *wi) * (wi->z / p);
        for (int k = 0; k < 3; ++k) sum[k] += static_cast<double>(w[k]);
      }
    }
    constexpr double kInvCount = 1.0 / (kGrid * kGrid);
    return diffuse + Rgb(static_cast<float>(sum[0] * kInvCount), static_cast<float>(sum[1] * kInvCount),
                         static_cast<float>(sum[2] * kInvCount));
  }

 protected:
  DiffusePlusLobe(const Rgb& diffuse, const Rgb& specular) : diffuse_over_pi_(diffuse * kInvPi) {
    const float md = mean(diffuse);
    const float ms = mean(specular);
    p_lobe_ = (md + ms > 0.0f) ? ms / (md + ms) : 0.0f;
  }

  /// The glossy lobe's value (both directions are above the horizon when called).
  virtual Rgb lobe_eval(const glm::vec3& wo, const glm::vec3& wi) const = 0;
  /// Solid-angle density of lobe_sample() at wi (wo.z, wi.z > 0 when called).
  virtual float lobe_pdf(const glm::vec3& wo, const glm::vec3& wi) const = 0;
  /// A direction drawn from the lobe, or nullopt if the draw is invalid; may lie below the
  /// horizon (the caller rejects it; lobe_pdf() must then not count it).
  virtual std::optional<glm::vec3> lobe_sample(const glm::vec3& wo, const glm::vec2& u) const = 0;

 private:
  Rgb diffuse_over_pi_;
  float p_lobe_ = 0.0f;  ///< probability of sampling the lobe instead of the diffuse term
};

}  // namespace brdf
}  // namespace detail
}  // namespace radiosity
