// Energy-conserving Phong and normalised Blinn-Phong reflection.
//
// Based on:
//   Phong, B. T. (1975). Illumination for computer generated pictures. Communications of the ACM
//     18(6), 311-317.
//   Lafortune, E. P. & Willems, Y. D. (1994). Using the modified Phong reflectance model for
//     physically based rendering. Technical Report CW 197, Dept. of Computer Science,
//     K.U. Leuven. (normalisation (n + 2) / (2 pi) and lobe sampling around the mirror direction)
//   Blinn, J. F. (1977). Models of light reflection for computer synthesized pictures.
//     Proc. SIGGRAPH 77, 192-198. (half-vector lobe)
//   Ashikhmin, M. & Shirley, P. (2000). An anisotropic Phong BRDF model. Journal of Graphics
//     Tools 5(2), 25-32. (normalisation (n + 1) / (8 pi) / ((k.h) max(cos, cos)), half-vector
//     sampling and its pdf)

#include <cmath>
#include <memory>
#include <optional>

#include "brdf/brdf_util.hpp"
#include "brdf/diffuse_lobe.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

namespace {

/// Lafortune & Willems (1994): lobe = ks (n + 2) / (2 pi) cos^n(alpha), alpha the angle between wi
/// and the mirror direction r of wo. Its albedo at normal incidence is exactly ks and smaller
/// elsewhere (part of the lobe falls below the horizon).
class PhongBrdf final : public db::DiffusePlusLobe {
 public:
  PhongBrdf(const Rgb& diffuse, const Rgb& specular, float exponent)
      : DiffusePlusLobe(diffuse, specular),
        ks_norm_(specular * ((exponent + 2.0f) * db::kInv2Pi)),
        n_(exponent),
        pdf_norm_((exponent + 1.0f) * db::kInv2Pi) {}

 private:
  Rgb lobe_eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    const float cos_alpha = glm::dot(wi, db::reflect_z(wo));
    return cos_alpha > 0.0f ? ks_norm_ * std::pow(cos_alpha, n_) : Rgb(0.0f);
  }

  float lobe_pdf(const glm::vec3& wo, const glm::vec3& wi) const override {
    // cos^n lobe around r normalised over the hemisphere around r: (n + 1) / (2 pi) cos^n.
    const float cos_alpha = glm::dot(wi, db::reflect_z(wo));
    return cos_alpha > 0.0f ? pdf_norm_ * std::pow(cos_alpha, n_) : 0.0f;
  }

  std::optional<glm::vec3> lobe_sample(const glm::vec3& wo, const glm::vec2& u) const override {
    // Invert the cdf of (n + 1) cos^n(alpha) sin(alpha): cos alpha = u^(1 / (n + 1)).
    const float cos_alpha = std::pow(u.x, 1.0f / (n_ + 1.0f));
    const float sin_alpha = std::sqrt(std::max(0.0f, 1.0f - cos_alpha * cos_alpha));
    const float phi = 2.0f * db::kPi * u.y;
    const ShadingFrame lobe = ShadingFrame::from_normal(db::reflect_z(wo));
    return lobe.to_world(glm::vec3(sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha));
  }

  Rgb ks_norm_;
  float n_;
  float pdf_norm_;
};

/// Ashikhmin & Shirley (2000) normalisation of the Blinn lobe (without their Fresnel factor):
/// lobe = ks (n + 1) / (8 pi) cos^n(theta_h) / ((wo.h) max(cos theta_o, cos theta_i)).
/// With half vectors drawn from (n + 1) / (2 pi) cos^n(theta_h), the sample weight of the lobe is
/// ks cos theta_i / max(cos theta_o, cos theta_i) <= ks, so the albedo never exceeds ks.
class BlinnPhongBrdf final : public db::DiffusePlusLobe {
 public:
  BlinnPhongBrdf(const Rgb& diffuse, const Rgb& specular, float exponent)
      : DiffusePlusLobe(diffuse, specular),
        ks_norm_(specular * ((exponent + 1.0f) / (8.0f * db::kPi))),
        n_(exponent),
        pdf_norm_((exponent + 1.0f) * db::kInv2Pi) {}

 private:
  Rgb lobe_eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    const glm::vec3 h = glm::normalize(wo + wi);
    const float wo_h = glm::dot(wo, h);
    if (!(h.z > 0.0f) || !(wo_h > 0.0f)) return Rgb(0.0f);
    return ks_norm_ * (std::pow(h.z, n_) / (wo_h * std::max(wo.z, wi.z)));
  }

  float lobe_pdf(const glm::vec3& wo, const glm::vec3& wi) const override {
    // Half-vector density over the hemisphere, times the reflection Jacobian
    // d omega_h / d omega_i = 1 / (4 wo.h).
    const glm::vec3 h = glm::normalize(wo + wi);
    const float wo_h = glm::dot(wo, h);
    if (!(h.z > 0.0f) || !(wo_h > 0.0f)) return 0.0f;
    return pdf_norm_ * std::pow(h.z, n_) / (4.0f * wo_h);
  }

  std::optional<glm::vec3> lobe_sample(const glm::vec3& wo, const glm::vec2& u) const override {
    const float cos_h = std::pow(u.x, 1.0f / (n_ + 1.0f));
    const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
    const float phi = 2.0f * db::kPi * u.y;
    const glm::vec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
    // A half vector facing away from wo reflects it into a direction whose own half vector is -h,
    // which has no density: reject.
    if (!(glm::dot(wo, h) > 0.0f)) return std::nullopt;
    return db::reflect_about(wo, h);
  }

  Rgb ks_norm_;
  float n_;
  float pdf_norm_;
};

void check_phong_parameters(const char* where, const Rgb& diffuse, const Rgb& specular, float exponent) {
  db::check_diffuse_specular(where, diffuse, specular);
  db::check_non_negative(where, "exponent", exponent);
}

}  // namespace

std::unique_ptr<Brdf> make_phong(Rgb diffuse, Rgb specular, float exponent) {
  check_phong_parameters("make_phong", diffuse, specular, exponent);
  return std::make_unique<PhongBrdf>(diffuse, specular, exponent);
}

std::unique_ptr<Brdf> make_blinn_phong(Rgb diffuse, Rgb specular, float exponent) {
  check_phong_parameters("make_blinn_phong", diffuse, specular, exponent);
  return std::make_unique<BlinnPhongBrdf>(diffuse, specular, exponent);
}

}  // namespace v1
}  // namespace radiosity
