// The material models shared by the scene readers (material_mapping.hpp). The metallic-roughness
// mapping follows the glTF 2.0 specification's BRDF appendix (Khronos, "glTF 2.0 Specification",
// Appendix B: F0 = mix(0.04, base, metallic) for ior 1.5, alpha = roughness^2), which the MTL PBR
// extension (Pr/Pm, as tinyobjloader and Blender read it) takes over; the GGX model is Walter et
// al. 2007 (brdf.hpp).
#include "io/readers/material_mapping.hpp"

#include <algorithm>
#include <sstream>

#include <glm/common.hpp>

#include "core/color.hpp"
#include "io/readers/reader_warnings.hpp"

namespace radiosity::detail {

std::string describe(const Rgb& c) {
  std::ostringstream s;
  s << '(' << c.x << ", " << c.y << ", " << c.z << ')';
  return s.str();
}

Rgb clamp_colour(Rgb c, float upper, float at_or_above, ReaderWarnings& warnings, std::string_view kind,
                 const std::string& where, const std::string& what, const char* meaning, const char* range) {
  Rgb out = c;
  for (int i = 0; i < 3; ++i) out[i] = c[i] < 0.0f ? 0.0f : c[i] >= at_or_above ? upper : c[i];
  if (out != c)
    warnings.forgive(kind, ErrorCode::invalid_scene, where,
                     what + " " + describe(c) + " is " + meaning + " and must be " + range + " per channel",
                     "clamped to " + describe(out));
  return out;
}

std::shared_ptr<const Brdf> albedo_mixture(float a, float b,
                                           const std::function<std::shared_ptr<const Brdf>(float)>& build_first,
                                           const std::function<std::shared_ptr<const Brdf>(float)>& build_second) {
  if (a <= 0.0f) return build_second(1.0f);
  if (b <= 0.0f) return build_first(1.0f);
  const float w = b / (a + b);
  return make_mix(build_first(1.0f / (1.0f - w)), build_second(1.0f / w), w);
}

void set_dielectric(Material& m, Rgb transmittance, float ior, Rgb reflection_tint) {
  m.transmittance = transmittance;
  m.ior = ior;
  if (reflection_tint == Rgb(1.0f)) return;  // make_brdf() derives the plain interface
  const Rgb kd = m.reflectance;
  m.brdf = albedo_mixture(
      max_channel(kd), max_channel(glm::max(transmittance, reflection_tint)),
      [&](float scale) { return std::shared_ptr<const Brdf>(make_lambertian(glm::min(kd * scale, Rgb(1.0f)))); },
      [&](float scale) {
        return std::shared_ptr<const Brdf>(make_dielectric(ior, glm::min(transmittance * scale, Rgb(1.0f)),
                                                           glm::min(reflection_tint * scale, Rgb(1.0f))));
      });
}

void set_transmission(Material& m, Rgb base, float transmission, float ior) {
  m.reflectance = base * (1.0f - transmission);
  set_dielectric(m, base * transmission, ior, Rgb(1.0f));
}

void set_metallic_roughness(Material& m, Rgb base, float metallic, float roughness, float ior) {
  const float f0_dielectric = ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f));
  const Rgb f0 = glm::mix(Rgb(f0_dielectric), base, metallic);
  const float w = std::clamp(max_channel(f0), 1e-3f, 0.999f);
  const Rgb diffuse = glm::min(base * (1.0f - metallic), Rgb((1.0f - w) * kMaxForgivenAlbedo));
  const float alpha = std::max(roughness * roughness, 1e-3f);
  m.reflectance = diffuse;
  // A mixture keeps each part's albedo when the coat is built with f0 / w at weight w; its rise
  // towards grazing angles is then scaled by w too.
  if (max_channel(diffuse) <= 0.0f)
    m.brdf = make_microfacet(f0, alpha, alpha);
  else
    m.brdf = make_mix(make_lambertian(diffuse / (1.0f - w)), make_microfacet(glm::min(f0 / w, Rgb(1.0f)), alpha, alpha), w);
}

void set_thin_pane(Material& m, float opacity, Rgb tint) {
  m.reflectance *= opacity;
  m.specular *= opacity;
  m.transmittance = (1.0f - opacity) * tint;
  m.ior = 1.0f;
}

}  // namespace radiosity::detail
