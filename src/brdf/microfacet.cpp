// GGX microfacet reflection with Smith masking-shadowing and Schlick's Fresnel.
//
// Based on:
//   Walter, B., Marschner, S. R., Li, H. & Torrance, K. E. (2007). Microfacet models for
//     refraction through rough surfaces. Proc. EGSR 2007, 195-206. (GGX distribution, eq. 33;
//     microfacet BRDF, eq. 20)
//   Heitz, E. (2014). Understanding the masking-shadowing function in microfacet-based BRDFs.
//     Journal of Computer Graphics Techniques 3(2), 48-107. (anisotropic GGX Lambda, eq. 86;
//     height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)), eq. 99)
//   Heitz, E. (2018). Sampling the GGX distribution of visible normals. Journal of Computer
//     Graphics Techniques 7(4), 1-13. (visible-normal sampling; pdf = G1(wo) D(h) / (4 cos theta_o))
//   Schlick, C. (1994). An inexpensive BRDF model for physically-based rendering. Computer
//     Graphics Forum 13(3), 233-246. (F = f0 + (1 - f0)(1 - cos)^5)

#include <cmath>
#include <memory>
#include <optional>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

namespace {

class MicrofacetBrdf final : public Brdf {
 public:
  MicrofacetBrdf(const Rgb& f0, float alpha_x, float alpha_y) : f0_(f0), ax_(alpha_x), ay_(alpha_y) {}

  Rgb eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return Rgb(0.0f);
    const glm::vec3 h = glm::normalize(wo + wi);
    const float wo_h = glm::dot(wo, h);
    if (!(wo_h > 0.0f)) return Rgb(0.0f);
    // Walter et al. (2007) eq. 20: f = F G D / (4 cos_o cos_i).
    const float g2 = 1.0f / (1.0f + lambda(wo) + lambda(wi));
    return fresnel(wo_h) * (ndf(h) * g2 / (4.0f * wo.z * wi.z));
  }

  float pdf(const glm::vec3& wo, const glm::vec3& wi) const override {
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    const glm::vec3 h = glm::normalize(wo + wi);
    if (!(glm::dot(wo, h) > 0.0f)) return 0.0f;
    // Visible normals D_wo(h) = G1(wo) max(0, wo.h) D(h) / cos_o (Heitz 2018 eq. 2), times the
    // reflection Jacobian 1 / (4 wo.h).
    return g1(wo) * ndf(h) / (4.0f * wo.z);
  }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u_in) const override {
    if (!(wo.z > 0.0f)) return std::nullopt;
    const glm::vec3 h = sample_visible_normal(wo, db::clamp01(u_in));
    const float wo_h = glm::dot(wo, h);
    if (!(wo_h > 0.0f)) return std::nullopt;
    const glm::vec3 wi = db::reflect_about(wo, h);
    if (!(wi.z > 0.0f)) return std::nullopt;
    const float p = pdf(wo, wi);
    if (!(p > 0.0f) || !std::isfinite(p)) return std::nullopt;
    // f cos_i / pdf = F G2 / G1(wo): D and the cosines cancel.
    const float g2 = 1.0f / (1.0f + lambda(wo) + lambda(wi));
    return BrdfSample{wi, fresnel(wo_h) * (g2 / g1(wo)), p, false};
  }

 private:
  /// Anisotropic GGX distribution of normals, Walter et al. (2007) eq. 33 generalised:
  /// D(h) = 1 / (pi ax ay h_z^4 (1 + (h_x^2 / ax^2 + h_y^2 / ay^2) / h_z^2)^2).
  float ndf(const glm::vec3& h) const {
    if (!(h.z > 0.0f)) return 0.0f;
    const float sx = h.x / ax_;
    const float sy = h.y / ay_;
    const float e = sx * sx + sy * sy + h.z * h.z;  // = h_z^2 (1 + tan^2 theta_h * ...)
    return 1.0f / (db::kPi * ax_ * ay_ * e * e);
  }

  /// Smith Lambda for anisotropic GGX (Heitz 2014 eq. 86):
  /// (-1 + sqrt(1 + (ax^2 w_x^2 + ay^2 w_y^2) / w_z^2)) / 2.
  float lambda(const glm::vec3& w) const {
    const float t2 = (ax_ * ax_ * w.x * w.x + ay_ * ay_ * w.y * w.y) / (w.z * w.z);
    return 0.5f * (std::sqrt(1.0f + t2) - 1.0f);
  }

  float g1(const glm::vec3& w) const { return 1.0f / (1.0f + lambda(w)); }

  Rgb fresnel(float cos_theta) const {
    const float m = std::max(0.0f, 1.0f - cos_theta);
    const float m2 = m * m;
    return f0_ + (Rgb(1.0f) - f0_) * (m2 * m2 * m);
  }

  /// Heitz (2018), listing 1, written out: stretch wo to the configuration where the microsurface
  /// has unit roughness, sample the projected hemisphere (a disk whose upper half is squashed by
  /// the visible fraction), and unstretch the normal.
  glm::vec3 sample_visible_normal(const glm::vec3& wo, const glm::vec2& u) const {
    const glm::vec3 v = glm::normalize(glm::vec3(ax_ * wo.x, ay_ * wo.y, wo.z));
    const float len2 = v.x * v.x + v.y * v.y;
    const glm::vec3 t1 = len2 > 0.0f ? glm::vec3(-v.y, v.x, 0.0f) / std::sqrt(len2) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 t2 = glm::cross(v, t1);
    // Uniform point on the unit disk, then the half facing away from v is compressed.
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * db::kPi * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + v.z);
    p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
    // Lift onto the hemisphere around v, then undo the stretch (normals transform inversely).
    const glm::vec3 n = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * v;
    return glm::normalize(glm::vec3(ax_ * n.x, ay_ * n.y, std::max(0.0f, n.z)));
  }

  Rgb f0_;
  float ax_;
  float ay_;
};

}  // namespace

std::unique_ptr<Brdf> make_microfacet(Rgb f0, float roughness_x, float roughness_y) {
  constexpr const char* kWhere = "make_microfacet";
  db::check_unit_rgb(kWhere, "f0", f0);
  db::check_positive(kWhere, "roughness_x", roughness_x);
  db::check_positive(kWhere, "roughness_y", roughness_y);
  return std::make_unique<MicrofacetBrdf>(f0, roughness_x, roughness_y);
}

}  // namespace v1
}  // namespace radiosity
