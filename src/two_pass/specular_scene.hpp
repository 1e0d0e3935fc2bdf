// What the second pass and the caustic photon tracer both need to know about a scene: the leaf
// elements of pass 1's hierarchy as an Embree scene, each surface split into the diffuse part
// that pass 1 carries and the specular part that is ray traced, and the emitters for sampling.
// Private to the library.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "geometry/polygon_fan.hpp"
#include "geometry/ray_scene.hpp"
#include "radiosity/brdf.hpp"
#include "radiosity/common.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "scene/lights.hpp"
#include "solver/light_groups.hpp"

namespace radiosity::detail {

/// One scene polygon as the two-pass method sees it.
struct SplitSurface {
  glm::vec3 normal{0.0f};
  glm::vec3 origin{0.0f};  ///< a vertex, to snap hit points onto the plane
  Rgb emission{0.0f};      ///< exitance E, W/m^2 (at its light group's weight)
  /// The Lambertian reflectance that pass 1 carries (Material::reflectance), or 0 when the
  /// material has its own Brdf (then pass 2 samples the whole model; see TWO_PASS.md).
  Rgb diffuse{0.0f};
  /// Everything else: the specular, glossy and transmitting parts (null for a purely diffuse
  /// surface). For a material with its own Brdf, that whole Brdf.
  std::shared_ptr<const Brdf> specular;
  bool specular_is_delta = false;  ///< specular->is_delta()
  bool two_sided = false;
  bool uses_pass1 = true;  ///< false for a material with its own Brdf
  /// What the extended first pass (FormFactorOptions::specular_depth > 0) carries through this
  /// surface: ideal-mirror reflection and straight window passage (form_factors/pass1_material.hpp),
  /// and glass (either way, when it carries the emitters' light: SolveReport::emitted_through_glass).
  bool pass1_mirror = false, pass1_window = false, pass1_glass = false;
  float ior = 1.0f;  ///< index of the back side (Material::ior), for the radiance scale across a refraction
};

/// A uniform point on an emitter and the density with which it was chosen.
struct EmitterSample {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};
  Rgb emission{0.0f};
  float pdf_area = 0.0f;  ///< P(this emitter) / its area
  std::uint32_t polygon = 0;
};

/// Scene, hierarchy and materials prepared for tracing rays. Building it validates that every
/// material's specular part can be made (make_brdf), so errors surface before any work.
/// Thread safety: immutable after construction; every const member may be called concurrently.
class SpecularScene {
 public:
  /// Each emitting polygon and light shines at its weight in `weights` (emitter_weights(): a
  /// relit solution's light groups), a polygon or light of weight 0 not at all; null: all at 1.
  /// Throws Error{invalid_argument} if the hierarchy refers to polygons `scene` does not have.
  /// `through_windows` (pass 1 was the extended one: SolveReport::specular_depth > 0): the
  /// lights' shadow rays pass windows and glass, as they did in pass 1 (PassThrough).
  SpecularScene(const Scene& scene, const PatchHierarchy& hierarchy, const EmitterWeights* weights = nullptr,
                bool through_windows = false);

  const RayScene& rays() const { return rays_; }
  const PatchHierarchy& hierarchy() const { return *hierarchy_; }
  /// The surface of a polygon, and of the element a RayScene hit reports.
  const SplitSurface& surface(PolygonId polygon) const { return surfaces_[polygon]; }
  PolygonId polygon_of_element(std::uint32_t element) const { return element_polygon_[element]; }
  bool has_specular() const { return has_specular_; }
  bool has_emitters() const { return !emitters_.empty(); }
  /// The scene's lights (Scene::lights()): point, spot and directional lights and skies.
  const SceneLights& lights() const { return lights_; }
  bool has_lights() const { return !lights_.empty(); }
  /// Sum over emitters of E * A per channel, W.
  Rgb emitted_power() const { return emitted_power_; }
  /// Ray offset: far above float rounding at the scene's scale, far below any feature.
  float epsilon() const { return epsilon_; }

  /// A point on an emitter: emitters chosen in proportion to E * A summed over channels, the
  /// point uniform on the polygon. `u` in [0,1)^3. Requires has_emitters().
  EmitterSample sample_emitter(float u_emitter, const glm::vec2& u_point) const;

  /// Estimate of the irradiance (W/m^2) that arrives at `x` (normal `n`, unit) straight from the
  /// emitters, with `samples` shadow rays (>= 1) on a stratified 1D pattern for the emitter
  /// choice, u-values from `rng_value()` (a callable returning floats in [0,1)).
  template <typename Uniform>
  Rgb direct_irradiance(const glm::vec3& x, const glm::vec3& n, int samples, Uniform&& rng_value) const;

  /// Estimate of the irradiance (W/m^2) at `x` (unit normal `n`) straight from the lights:
  /// each delta light exactly with a shadow ray, the sky by one cosine-weighted ray from
  /// `u_sky` (light_irradiance_at()).
  Rgb light_irradiance(const glm::vec3& x, const glm::vec3& n, const glm::vec2& u_sky) const {
    return light_irradiance_at(lights_, rays_, x, n, epsilon_, u_sky, through());
  }
  /// The delta lights' part of it (no random numbers).
  Rgb delta_light_irradiance(const glm::vec3& x, const glm::vec3& n) const {
    return delta_irradiance_at(lights_, rays_, x, n, epsilon_, through());
  }
  /// The sky's part of it, one cosine-weighted ray from `u_sky`.
  Rgb sky_light_irradiance(const glm::vec3& x, const glm::vec3& n, const glm::vec2& u_sky) const {
    return sky_irradiance_at(lights_, rays_, x, n, epsilon_, u_sky, through());
  }

 private:
  Rgb direct_irradiance_one(const glm::vec3& x, const glm::vec3& n, float u_emitter, const glm::vec2& u_point) const;

  struct Emitter {
    std::uint32_t polygon = 0;
    PolygonFan fan;
    float pdf_area = 0.0f;
  };

  const PatchHierarchy* hierarchy_;
  RayScene rays_;
  std::vector<SplitSurface> surfaces_;
  std::vector<PolygonId> element_polygon_;
  std::vector<Emitter> emitters_;
  DiscreteDistribution emitter_choice_;  ///< over emitters_, by power summed over channels
  SceneLights lights_;
  std::optional<PassThrough> through_;  ///< with through_windows, when some polygon passes light
  const PassThrough* through() const { return through_ ? &*through_ : nullptr; }
  Rgb emitted_power_{0.0f};
  float epsilon_ = 0.0f;
  bool has_specular_ = false;
};

template <typename Uniform>
Rgb SpecularScene::direct_irradiance(const glm::vec3& x, const glm::vec3& n, int samples, Uniform&& rng_value) const {
  if (emitters_.empty() || samples <= 0) return Rgb(0.0f);
  Rgb sum(0.0f);
  for (int s = 0; s < samples; ++s) {
    const float u = (static_cast<float>(s) + rng_value()) / static_cast<float>(samples);
    const float a = rng_value();
    sum += direct_irradiance_one(x, n, u, glm::vec2(a, rng_value()));
  }
  return sum / static_cast<float>(samples);
}

}  // namespace radiosity::detail
