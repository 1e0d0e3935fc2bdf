// Ideal specular models (delta distributions): the mirror and the smooth dielectric interface.
//
// Based on:
//   Born, M. & Wolf, E. (1999). Principles of Optics, 7th ed., Cambridge Univ. Press, sec. 1.5.
//     (law of reflection, Snell's law, Fresnel equations)
//   Veach, E. (1997). Robust Monte Carlo Methods for Light Transport Simulation. PhD thesis,
//     Stanford University, ch. 5. (non-symmetric scattering at refraction: radiance scales by
//     (eta_i / eta_t)^2, importance does not)
//   Whitted, T. (1980). An improved illumination model for shaded display. Communications of the
//     ACM 23(6), 343-349. (choosing reflection or refraction in a ray tracer)

#include <cmath>
#include <memory>
#include <optional>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

namespace {

class MirrorBrdf final : public Brdf {
 public:
  explicit MirrorBrdf(const Rgb& reflectance) : r_(reflectance) {}

  Rgb eval(const glm::vec3&, const glm::vec3&) const override { return Rgb(0.0f); }
  float pdf(const glm::vec3&, const glm::vec3&) const override { return 0.0f; }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2&) const override {
    if (!(wo.z > 0.0f)) return std::nullopt;
    // f = r delta(wi - reflect(wo)) / cos_i, so f cos_i / (discrete probability 1) = r.
    return BrdfSample{db::reflect_z(wo), r_, 1.0f, true};
  }

  Rgb albedo(const glm::vec3& wo) const override { return wo.z > 0.0f ? r_ : Rgb(0.0f); }
  bool is_delta() const override { return true; }

 private:
  Rgb r_;
};

/// Smooth interface between the medium above (index 1 relative) and below (index eta).
class DielectricBrdf final : public Brdf {
 public:
  DielectricBrdf(float eta, const Rgb& tint, const Rgb& reflection_tint)
      : eta_(eta), tint_(tint), reflection_tint_(reflection_tint) {}

  Rgb eval(const glm::vec3&, const glm::vec3&) const override { return Rgb(0.0f); }
  float pdf(const glm::vec3&, const glm::vec3&) const override { return 0.0f; }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u_in) const override {
    const float cos_o = wo.z;
    if (cos_o == 0.0f || !std::isfinite(cos_o)) return std::nullopt;
    const glm::vec2 u = db::clamp01(u_in);
    // Choose reflection with probability R (exactly 1 under total internal reflection), so that
    // the weight of either event is its Fresnel factor over its probability (1 or tint),
    // times its tint.
    const float R = fresnel_dielectric(cos_o, eta_);
    if (u.x < R) return BrdfSample{db::reflect_z(wo), reflection_tint_, R, true};

    // Snell's law, eta_rel = eta_t / eta_i seen from wo's side; n is the normal on wo's side.
    const float eta_rel = cos_o > 0.0f ? eta_ : 1.0f / eta_;
    const float cos_i = std::abs(cos_o);
    const float sin2_t = (1.0f - cos_i * cos_i) / (eta_rel * eta_rel);
    if (sin2_t >= 1.0f) return BrdfSample{db::reflect_z(wo), reflection_tint_, 1.0f, true};  // R rounded below 1
    const float cos_t = std::sqrt(1.0f - sin2_t);
    const glm::vec3 n(0.0f, 0.0f, cos_o > 0.0f ? 1.0f : -1.0f);
    // Refracted direction: tangential part -wo_t / eta_rel, normal part -cos_t n.
    const glm::vec3 wi = -wo / eta_rel + (cos_i / eta_rel - cos_t) * n;
    return BrdfSample{glm::normalize(wi), tint_, 1.0f - R, true};
  }

  Rgb albedo(const glm::vec3& wo) const override {
    if (wo.z == 0.0f || !std::isfinite(wo.z)) return Rgb(0.0f);
    const float R = fresnel_dielectric(wo.z, eta_);
    return R * reflection_tint_ + (1.0f - R) * tint_;
  }

  bool is_delta() const override { return true; }

 private:
  float eta_;
  Rgb tint_;
  Rgb reflection_tint_;
};

}  // namespace

std::unique_ptr<Brdf> make_mirror(Rgb reflectance) {
  db::check_unit_rgb("make_mirror", "reflectance", reflectance);
  return std::make_unique<MirrorBrdf>(reflectance);
}

std::unique_ptr<Brdf> make_dielectric(float eta, Rgb tint) { return make_dielectric(eta, tint, Rgb(1.0f)); }

std::unique_ptr<Brdf> make_dielectric(float eta, Rgb tint, Rgb reflection_tint) {
  constexpr const char* kWhere = "make_dielectric";
  db::check_positive(kWhere, "eta", eta);
  db::check_unit_rgb(kWhere, "tint", tint);
  db::check_unit_rgb(kWhere, "reflection_tint", reflection_tint);
  return std::make_unique<DielectricBrdf>(eta, tint, reflection_tint);
}

}  // namespace v1
}  // namespace radiosity
