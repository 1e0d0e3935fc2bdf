// The Brdf base class, the shading frame, the mixture of two models and the Fresnel equations.
//
// Based on:
//   Duff, T., Burgess, J., Christensen, P., Hery, C., Kensler, A., Liani, M. & Villemin, R. (2017).
//     Building an orthonormal basis, revisited. Journal of Computer Graphics Techniques 6(1), 1-8.
//   Veach, E. & Guibas, L. J. (1995). Optimally combining sampling techniques for Monte Carlo
//     rendering. Proc. SIGGRAPH 95, 419-428. (one-sample model with the balance heuristic, used
//     by the mixture's sampler)
//   Born, M. & Wolf, E. (1999). Principles of Optics, 7th ed., Cambridge Univ. Press, sec. 1.5.2.
//     (Fresnel equations for a dielectric interface)

#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"
#include "core/frame.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

Brdf::~Brdf() = default;

bool Brdf::is_delta() const { return false; }

Rgb Brdf::albedo(const glm::vec3& wo) const {
  // Integral of f |cos| over wi = E[weight] for u uniform; estimated on the centres of an
  // N x N grid of u (stratified, deterministic). Accumulated in double for a fixed sum order.
  constexpr int kGrid = 128;
  double sum[3] = {0.0, 0.0, 0.0};
  for (int j = 0; j < kGrid; ++j) {
    for (int i = 0; i < kGrid; ++i) {
      const glm::vec2 u((static_cast<float>(i) + 0.5f) / kGrid, (static_cast<float>(j) + 0.5f) / kGrid);
      const std::optional<BrdfSample> s = sample(wo, u);
      if (!s) continue;
      for (int k = 0; k < 3; ++k) sum[k] += static_cast<double>(s->weight[k]);
    }
  }
  constexpr double kInvCount = 1.0 / (kGrid * kGrid);
  return Rgb(static_cast<float>(sum[0] * kInvCount), static_cast<float>(sum[1] * kInvCount),
             static_cast<float>(sum[2] * kInvCount));
}

ShadingFrame ShadingFrame::from_normal(const glm::vec3& normal) {
  const float len = glm::length(normal);
  if (!std::isfinite(len) || !(len > 0.0f)) {
    throw Error(ErrorCode::invalid_argument, "ShadingFrame::from_normal: normal is zero-length or not finite");
  }
  const glm::vec3 n = normal / len;
  // Duff et al.'s branchless basis (core/frame.hpp), right-handed (n x t = b).
  ShadingFrame f;
  detail::tangent_frame(n, f.tangent, f.bitangent);
  f.normal = n;
  return f;
}

ShadingFrame ShadingFrame::from_normal_tangent(const glm::vec3& normal, const glm::vec3& tangent) {
  if (!std::isfinite(tangent.x) || !std::isfinite(tangent.y) || !std::isfinite(tangent.z)) {
    throw Error(ErrorCode::invalid_argument, "ShadingFrame::from_normal_tangent: tangent is not finite");
  }
  ShadingFrame f = from_normal(normal);
  // Gram-Schmidt: drop the normal component of the tangent; fall back to the arbitrary tangent
  // of from_normal() when nothing (relative to the tangent's length) is left.
  const glm::vec3 t = tangent - glm::dot(tangent, f.normal) * f.normal;
  const float len_t = glm::length(t);
  if (!(len_t > 1e-6f * glm::length(tangent))) return f;
  f.tangent = t / len_t;
  f.bitangent = glm::cross(f.normal, f.tangent);
  return f;
}

float fresnel_dielectric(float cos_theta_i, float eta) {
  if (!std::isfinite(eta) || !(eta > 0.0f)) {
    throw Error(ErrorCode::invalid_argument, "fresnel_dielectric: eta must be finite and > 0");
  }
  float cos_i = std::min(std::max(cos_theta_i, -1.0f), 1.0f);
  // From below the surface the relative index is inverted.
  if (cos_i < 0.0f) {
    eta = 1.0f / eta;
    cos_i = -cos_i;
  }
  // Snell: sin t = sin i / eta; total internal reflection when that exceeds 1.
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  // Fresnel amplitude ratios for parallel and perpendicular polarisation (Born & Wolf 1.5.2,
  // eqs. 21a), averaged in power for unpolarised light.
  const float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_par * r_par + r_perp * r_perp);
}

namespace {

/// (1 - w) * first + w * second.
class MixBrdf final : public Brdf {
 public:
  MixBrdf(std::shared_ptr<const Brdf> first, std::shared_ptr<const Brdf> second, float w)
      : first_(std::move(first)), second_(std::move(second)), w_(w) {}

  Rgb eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    return (1.0f - w_) * first_->eval(wo, wi) + w_ * second_->eval(wo, wi);
  }

  float pdf(const glm::vec3& wo, const glm::vec3& wi) const override {
    return (1.0f - w_) * first_->pdf(wo, wi) + w_ * second_->pdf(wo, wi);
  }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u_in) const override {
    const glm::vec2 u = db::clamp01(u_in);
    // Choose a part with probability equal to its mixing weight and reuse u.x for it.
    const bool pick_second = u.x < w_;
    const Brdf& part = pick_second ? *second_ : *first_;
    const float p_part = pick_second ? w_ : 1.0f - w_;
    const glm::vec2 u_part(pick_second ? db::remap_below(u.x, w_) : db::remap_above(u.x, w_), u.y);
    std::optional<BrdfSample> s = part.sample(wo, u_part);
    if (!s) return std::nullopt;
    if (s->delta) {
      // The mixture's delta part is p_part * (part's delta part) and is picked with p_part:
      // the weight is the part's own, the discrete probability scales.
      s->pdf *= p_part;
      return s;
    }
    // One-sample MIS with the balance heuristic: weight with the full mixture f and pdf, so the
    // non-delta directions of both parts are covered by either sampler.
    const float p = pdf(wo, s->wi);
    if (!(p > 0.0f)) return std::nullopt;
    s->weight = eval(wo, s->wi) * (std::abs(s->wi.z) / p);
    s->pdf = p;
    return s;
  }

  Rgb albedo(const glm::vec3& wo) const override {
    return (1.0f - w_) * first_->albedo(wo) + w_ * second_->albedo(wo);
  }

  bool is_delta() const override {
    return (w_ >= 1.0f || first_->is_delta()) && (w_ <= 0.0f || second_->is_delta());
  }

 private:
  std::shared_ptr<const Brdf> first_;
  std::shared_ptr<const Brdf> second_;
  float w_;
};

}  // namespace

std::unique_ptr<Brdf> make_mix(std::shared_ptr<const Brdf> first, std::shared_ptr<const Brdf> second,
                               float weight_second) {
  constexpr const char* kWhere = "make_mix";
  if (!first) db::throw_invalid(kWhere, "first is null");
  if (!second) db::throw_invalid(kWhere, "second is null");
  if (!std::isfinite(weight_second) || weight_second < 0.0f || weight_second > 1.0f) {
    db::throw_invalid(kWhere, "weight_second = " + std::to_string(weight_second) + " is outside [0, 1]");
  }
  return std::make_unique<MixBrdf>(std::move(first), std::move(second), weight_second);
}

}  // namespace v1
}  // namespace radiosity
