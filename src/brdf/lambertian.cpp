// Ideal diffuse (Lambertian) reflection.
//
// Based on:
//   Lambert, J. H. (1760). Photometria, sive de mensura et gradibus luminis, colorum et umbrae.
//   Shirley, P. & Chiu, K. (1997). A low distortion map between disk and square.
//     Journal of Graphics Tools 2(3), 45-52. (cosine-weighted sampling via the concentric map)

#include <memory>
#include <optional>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

namespace {

class LambertianBrdf final : public Brdf {
 public:
  explicit LambertianBrdf(const Rgb& reflectance) : rho_(reflectance), f_(reflectance / db::kPi) {}

  Rgb eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    return (wo.z > 0.0f && wi.z > 0.0f) ? f_ : Rgb(0.0f);
  }

  float pdf(const glm::vec3& wo, const glm::vec3& wi) const override { return db::cosine_lobe_pdf(wo, wi); }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u) const override {
    const std::optional<glm::vec3> wi = db::sample_cosine_lobe(wo, u);
    if (!wi) return std::nullopt;
    // f cos / pdf = (rho / pi) cos / (cos / pi) = rho.
    return BrdfSample{*wi, rho_, db::cosine_hemisphere_pdf(*wi), false};
  }

  Rgb albedo(const glm::vec3& wo) const override { return wo.z > 0.0f ? rho_ : Rgb(0.0f); }

 private:
  Rgb rho_;
  Rgb f_;
};

}  // namespace

std::unique_ptr<Brdf> make_lambertian(Rgb reflectance) {
  db::check_unit_rgb("make_lambertian", "reflectance", reflectance);
  return std::make_unique<LambertianBrdf>(reflectance);
}

}  // namespace v1
}  // namespace radiosity
