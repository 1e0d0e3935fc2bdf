// The lights' radiometry (see lights.hpp for the sources): spot falloff, sky radiance and its
// closed-form irradiance, and the one-point estimate the renderers share.
#include "scene/lights.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/assert.hpp"
#include "core/color.hpp"
#include "radiosity/brdf.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity::detail {

namespace {

/// Shadow rays to a point light stop this fraction of the segment short of it (visibility.hpp's
/// convention), so a light that sits on a surface is not hidden by that surface.
constexpr float kShadowEnd = 1.0f - 1e-4f;

PreparedLight prepare(const Light& l, LightId id) {
  PreparedLight p;
  p.type = l.type;
  p.power = l.intensity * l.color;
  p.position = l.position;
  p.direction = l.direction;
  p.id = id;
  if (l.type == LightType::spot) {
    p.cos_inner = std::cos(glm::radians(l.inner_cone_deg));
    p.cos_outer = std::cos(glm::radians(l.outer_cone_deg));
    // KHR_lights_punctual's form, including its floor on the denominator.
    p.spot_scale = 1.0f / std::max(0.001f, p.cos_inner - p.cos_outer);
    p.spot_offset = -p.cos_outer * p.spot_scale;
  }
  if (l.type == LightType::sky) {
    p.sky = l.sky;
    // E = integral of L cos over the hemisphere: pi L for the uniform sky; for the overcast
    // sky Lz / 3 (pi + 2 (2 pi / 3)) = 7 pi Lz / 9.
    p.zenith_radiance = l.sky == SkyModel::uniform ? p.power * kInvPi : p.power * (9.0f / (7.0f * kPi));
  }
  return p;
}

}  // namespace

float PreparedLight::falloff(const glm::vec3& w) const {
  if (type != LightType::spot) return 1.0f;
  const float c = glm::dot(w, direction);
  // Exactly 1 inside the inner cone and 0 outside the outer one, also where glTF's floor on the
  // denominator (inner and outer nearly equal) would leave the inner cone below 1.
  if (c >= cos_inner) return 1.0f;
  if (c <= cos_outer) return 0.0f;
  const float t = std::clamp(c * spot_scale + spot_offset, 0.0f, 1.0f);
  return t * t;
}

Rgb PreparedLight::sky_irradiance(const glm::vec3& n) const {
  // b: angle between the plane's normal and the zenith. Over the lune where both hemispheres
  // overlap, integral of (w.n) = pi (1 + cos b) / 2 and integral of (w.z)(w.n) =
  // 2/3 ((pi - b) cos b + sin b).
  const double c = std::clamp(static_cast<double>(glm::dot(n, direction)), -1.0, 1.0);
  const double b = std::acos(c), s = std::sqrt(std::max(0.0, 1.0 - c * c));
  const double pi = 3.14159265358979323846;
  const double first = 0.5 * pi * (1.0 + c);
  if (sky == SkyModel::uniform) return zenith_radiance * static_cast<float>(first);
  const double second = 2.0 / 3.0 * ((pi - b) * c + s);
  return zenith_radiance * static_cast<float>((first + 2.0 * second) / 3.0);
}

SceneLights::SceneLights(const std::vector<Light>& lights, const std::vector<Rgb>* weights) {
  for (std::size_t i = 0; i < lights.size(); ++i) {
    PreparedLight p = prepare(lights[i], static_cast<LightId>(i));
    if (weights) {
      const Rgb w = (*weights)[i];
      if (w == Rgb(0.0f)) continue;
      p.power *= w;
      p.zenith_radiance *= w;
    }
    all_.push_back(p);
    (p.delta() ? delta_ : skies_).push_back(p);
  }
}

Rgb SceneLights::sky_radiance(const glm::vec3& from) const {
  Rgb L(0.0f);
  for (const PreparedLight& s : skies_) L += s.sky_radiance(from);
  return L;
}

bool incidence(const PreparedLight& light, const glm::vec3& x, Incidence& out) {
  if (light.type == LightType::directional) {
    out.wi = -light.direction;
    out.distance = std::numeric_limits<float>::infinity();
    out.irradiance = light.power;
    return light.power != Rgb(0.0f);
  }
  RADIOSITY_ASSERT(light.type == LightType::point || light.type == LightType::spot);
  const glm::vec3 d = light.position - x;
  const float r2 = glm::dot(d, d);
  if (!(r2 > 0.0f)) return false;
  out.distance = std::sqrt(r2);
  out.wi = d / out.distance;
  const float t = light.falloff(-out.wi);
  if (!(t > 0.0f)) return false;
  out.irradiance = light.power * (t / r2);
  return light.power != Rgb(0.0f);
}

PassThrough::PassThrough(const Scene& scene, bool glass) {
  const std::vector<Polygon>& polygons = scene.polygons();
  tau_.assign(polygons.size(), Rgb(0.0f));
  ior_.assign(polygons.size(), 1.0f);
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const Material& m = scene.material(polygons[p].material);
    if (!(max_channel(m.transmittance) > 0.0f) || (m.ior != 1.0f && !glass)) continue;
    tau_[p] = m.transmittance;
    ior_[p] = m.ior;
    any_ = true;
  }
}

PassThrough::PassThrough(const Scene& scene, bool glass, const PatchHierarchy& hierarchy) : PassThrough(scene, glass) {
  std::vector<Rgb> tau(hierarchy.elements().size(), Rgb(0.0f));
  std::vector<float> ior(tau.size(), 1.0f);
  for (std::size_t e = 0; e < tau.size(); ++e) {
    const std::uint32_t polygon = hierarchy.patches()[hierarchy.element(static_cast<std::uint32_t>(e)).patch].polygon;
    tau[e] = tau_[polygon];
    ior[e] = ior_[polygon];
  }
  tau_ = std::move(tau);
  ior_ = std::move(ior);
}

std::optional<PassThrough> PassThrough::if_any(const Scene& scene, bool glass) {
  PassThrough through(scene, glass);
  if (!through.any()) return std::nullopt;
  return through;
}

std::optional<PassThrough> PassThrough::if_any(const Scene& scene, bool glass, const PatchHierarchy& hierarchy) {
  PassThrough through(scene, glass, hierarchy);
  if (!through.any()) return std::nullopt;
  return through;
}

Rgb PassThrough::transmittance(const RayScene& polygons, const glm::vec3& origin, const glm::vec3& dir, float tnear,
                               float tfar, float step) const {
  Rgb T(1.0f);
  for (int crossing = 0; crossing <= kMaxCrossings; ++crossing) {
    const std::optional<RayScene::Hit> h = polygons.intersect(origin, dir, tnear, tfar);
    if (!h) return T;
    if (crossing == kMaxCrossings) return Rgb(0.0f);
    T *= this->crossing(h->id, dir, h->geometric_normal);
    if (!(max_channel(T) > 0.0f)) return Rgb(0.0f);
    tnear = h->t + step;
  }
  return Rgb(0.0f);
}

Rgb PassThrough::crossing(std::uint32_t id, const glm::vec3& dir, const glm::vec3& geometric_normal) const {
  if (id >= tau_.size() || !(max_channel(tau_[id]) > 0.0f)) return Rgb(0.0f);
  if (ior_[id] == 1.0f) return tau_[id];
  // From outside at the ray's angle, whichever face it meets: the shadow ray is not bent
  // (monte_carlo.cpp, the glass's Fresnel reflectance, says why).
  const float cos_in = glm::dot(glm::normalize(dir), glm::normalize(geometric_normal));
  return tau_[id] * (1.0f - fresnel_dielectric(std::fabs(cos_in), ior_[id]));
}

Rgb light_transmittance(const RayScene& occluders, const PassThrough* through, const glm::vec3& origin,
                        const glm::vec3& light_position, const Incidence& in, float epsilon) {
  if (unoccluded(occluders, origin, light_position, in)) return Rgb(1.0f);
  if (!through || !through->any()) return Rgb(0.0f);
  // A directional light's or the sky's ray runs along its unit direction; a point's or spot's
  // along the segment to the light (parametric), so its step is epsilon over that length.
  if (std::isinf(in.distance))
    return through->transmittance(occluders, origin, in.wi, 0.0f, std::numeric_limits<float>::infinity(), epsilon);
  const glm::vec3 to_light = light_position - origin;
  const float length = glm::length(to_light);
  if (!(length > 0.0f)) return Rgb(0.0f);
  return through->transmittance(occluders, origin, to_light, 0.0f, kShadowEnd, epsilon / length);
}

bool unoccluded(const RayScene& occluders, const glm::vec3& origin, const glm::vec3& light_position,
                const Incidence& in) {
  if (std::isinf(in.distance)) return !occluders.occluded(origin, in.wi, 0.0f, std::numeric_limits<float>::infinity());
  return !occluders.occluded(origin, light_position - origin, 0.0f, kShadowEnd);
}

Rgb delta_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x, const glm::vec3& n,
                        float epsilon, const PassThrough* through) {
  Rgb H(0.0f);
  const glm::vec3 origin = x + epsilon * n;
  for (const PreparedLight& l : lights.delta()) {
    Incidence in;
    if (!incidence(l, x, in)) continue;
    const float cos_x = glm::dot(n, in.wi);
    if (!(cos_x > 0.0f)) continue;
    H += in.irradiance * cos_x * light_transmittance(occluders, through, origin, l.position, in, epsilon);
  }
  return H;
}

Rgb sky_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x, const glm::vec3& n,
                      float epsilon, const glm::vec2& u_sky, const PassThrough* through) {
  if (!lights.has_sky()) return Rgb(0.0f);
  // Cosine-weighted: L cos / pdf = pi L.
  const glm::vec3 w = glm::normalize(Frame(n).to_world(cosine_hemisphere(u_sky)));
  const Rgb L = lights.sky_radiance(w);
  if (L == Rgb(0.0f)) return Rgb(0.0f);
  Incidence in;
  in.wi = w;
  in.distance = std::numeric_limits<float>::infinity();
  return kPi * L * light_transmittance(occluders, through, x + epsilon * n, glm::vec3(0.0f), in, epsilon);
}

Rgb light_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x,
                        const glm::vec3& n, float epsilon, const glm::vec2& u_sky, const PassThrough* through) {
  return delta_irradiance_at(lights, occluders, x, n, epsilon, through) +
         sky_irradiance_at(lights, occluders, x, n, epsilon, u_sky, through);
}

}  // namespace radiosity::detail
