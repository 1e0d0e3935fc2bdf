// The second pass's reflection model of a scene material (make_brdf): the material's own BRDF
// when it has one, else a model assembled from its diffuse, specular and transmission fields.
#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "radiosity/brdf.hpp"
#include "radiosity/scene.hpp"
#include "core/color.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using detail::max_channel;

}  // namespace

std::shared_ptr<const Brdf> make_brdf(const Material& material) {
  if (material.brdf) return material.brdf;
  const Rgb diffuse = material.reflectance;
  const bool has_specular = max_channel(material.specular) > 0.0f;
  const bool has_transmission = max_channel(material.transmittance) > 0.0f;
  if (!has_transmission && !(has_specular && material.specular_exponent <= 0.0f)) {
    if (!has_specular) return make_lambertian(diffuse);
    return make_phong(diffuse, material.specular, material.specular_exponent);
  }

  // A delta part (mirror or glass) mixed with the rest. A mixture weights each part's BRDF by
  // w_k, so part k is built with coefficient c_k / w_k; with w_k = max(c_k) / sum_l max(c_l) the
  // mixture reproduces every c_k exactly whenever sum_l max(c_l) <= 1 (else the parts are
  // clamped to 1 and some energy is lost, which only happens for parts that peak in different
  // channels).
  struct Weighted {
    std::shared_ptr<const Brdf> brdf;
    float strength;
  };
  std::vector<Weighted> parts;
  const float d = max_channel(diffuse), s = has_specular ? max_channel(material.specular) : 0.0f,
              t = has_transmission ? max_channel(material.transmittance) : 0.0f;
  const float total = d + s + t;
  auto scaled = [&](const Rgb& c, float strength) { return glm::min(c * (total / strength), Rgb(1.0f)); };
  if (d > 0.0f) parts.push_back({make_lambertian(scaled(diffuse, d)), d});
  if (s > 0.0f) {
    const Rgb ks = scaled(material.specular, s);
    if (material.specular_exponent > 0.0f)
      parts.push_back({make_phong(Rgb(0.0f), ks, material.specular_exponent), s});
    else
      parts.push_back({make_mirror(ks), s});
  }
  if (t > 0.0f) parts.push_back({make_dielectric(material.ior, scaled(material.transmittance, t)), t});

  std::shared_ptr<const Brdf> result = parts.front().brdf;
  float accumulated = parts.front().strength;
  for (std::size_t k = 1; k < parts.size(); ++k) {
    accumulated += parts[k].strength;
    result = make_mix(std::move(result), parts[k].brdf, parts[k].strength / accumulated);
  }
  return result;
}

}  // namespace v1
}  // namespace radiosity
