// The scene's lights (Light: point, spot, directional, sky) as every stage evaluates them: the
// radiosity first shot (solver/light_shot.cpp), the path tracer, the two-pass view, render()'s
// background and the lightmap's final gather all read them through this one header, so the
// three images and the solve see the same lights. Private to the library.
// Based on:
//   The Khronos Group, "KHR_lights_punctual" glTF 2.0 extension (2018): the units of point, spot
//     and directional lights and the spot's smooth angular falloff.
//   P. Moon & D. E. Spencer, "Illumination from a non-uniform sky", Illuminating Engineering 37,
//     1942; CIE S 011/E:2003, "Spatial distribution of daylight - CIE standard general sky"
//     (type 16, the overcast sky L(theta) = Lz (1 + 2 cos theta) / 3).
//   J. Arvo, "Applications of irradiance tensors to the simulation of non-Lambertian phenomena",
//     SIGGRAPH 1995 (moments of the cosine over the lune where two hemispheres overlap: the
//     closed forms of sky_irradiance()).
//   A. van Oosterom & J. Strackee, "The solid angle of a plane triangle", IEEE Trans. Biomed.
//     Eng. 30(2), 1983 (an isotropic point's irradiance integrated over a polygon is I times
//     the solid angle the polygon subtends).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

class RayScene;

/// One light with its constants worked out once.
struct PreparedLight {
  LightType type = LightType::point;
  /// intensity x color: W/sr (point, spot), W/m^2 (directional, the sky's horizontal irradiance).
  Rgb power{0.0f};
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  ///< unit: where the light travels; a sky's zenith
  /// Spot falloff as KHR_lights_punctual writes it: t = clamp(cos a * scale + offset, 0, 1).
  float cos_outer = 0.0f, spot_scale = 1.0f, spot_offset = 0.0f;
  float cos_inner = 1.0f;
  SkyModel sky = SkyModel::uniform;
  /// sky: the radiance at the zenith, W/(m^2 sr): E / pi (uniform) or 9 E / (7 pi) (CIE overcast).
  Rgb zenith_radiance{0.0f};
  LightId id = 0;  ///< its index in Scene::lights()

  bool delta() const { return type != LightType::sky; }
  /// Spot falloff in [0, 1] for light leaving along the unit direction w (1 for a point light).
  float falloff(const glm::vec3& w) const;
  /// A sky's radiance arriving from the unit direction `from` (towards the sky), 0 below the horizon.
  Rgb sky_radiance(const glm::vec3& from) const {
    // Inline: the first shot asks it for each of hundreds of millions of sky rays.
    const float c = glm::dot(from, direction);
    if (!(c > 0.0f)) return Rgb(0.0f);
    return sky == SkyModel::uniform ? zenith_radiance : zenith_radiance * ((1.0f + 2.0f * c) / 3.0f);
  }
  /// A sky's irradiance on an unoccluded plane facing the unit normal n (closed forms: the
  /// uniform sky E (1 + cos b) / 2, the overcast sky with Arvo's lune moments, b the angle
  /// between n and the zenith). E itself for n = zenith.
  Rgb sky_irradiance(const glm::vec3& n) const;
};

/// Light from a delta light (point, spot, directional) arriving at a point.
struct Incidence {
  glm::vec3 wi{0.0f};  ///< unit, from the point towards the light
  /// Distance to the light; infinity for a directional light.
  float distance = std::numeric_limits<float>::infinity();
  /// Irradiance on a surface facing the light (the cosine at the receiver not applied):
  /// I t / r^2 for a point or spot (t the falloff), E for a directional light.
  Rgb irradiance{0.0f};
};

/// The scene's lights, split into delta lights and skies.
/// Thread safety: immutable after construction.
class SceneLights {
 public:
  SceneLights() = default;
  /// With `weights` (one per light), each light's power (a sky's radiance) is scaled by its
  /// weight, and a light of weight 0 is left out: one light group's lights (bake_lightmap()).
  explicit SceneLights(const std::vector<Light>& lights, const std::vector<Rgb>* weights = nullptr);

  bool empty() const { return delta_.empty() && skies_.empty(); }
  bool has_sky() const { return !skies_.empty(); }
  /// Point, spot and directional lights, in Scene::lights() order.
  const std::vector<PreparedLight>& delta() const { return delta_; }
  const std::vector<PreparedLight>& skies() const { return skies_; }
  /// Every light, in Scene::lights() order.
  const std::vector<PreparedLight>& all() const { return all_; }

  /// The skies' radiance arriving from the unit direction `from`, W/(m^2 sr) (0 without a sky).
  Rgb sky_radiance(const glm::vec3& from) const;

 private:
  std::vector<PreparedLight> all_, delta_, skies_;
};

/// Where delta light `light` lies from x and what it delivers there, before the cosine and the
/// shadow ray; false when it sends nothing towards x (outside a spot's cone, zero intensity, x at
/// the light).
bool incidence(const PreparedLight& light, const glm::vec3& x, Incidence& out);

/// What a light's shadow ray keeps through the scene's windows and glass, per polygon: the
/// extended first pass's treatment (FormFactorOptions::specular_depth > 0), straight on. A window
/// (a transmitting material with ior 1) passes its transmittance; refracting glass (ior != 1)
/// its transmittance times the interface's Fresnel transmission at the crossing angle, the
/// bending ignored (exact in direction for a pane's two parallel faces; the ray's displacement
/// is not); any other polygon stops the ray. Without it every polygon stops shadow rays, and a
/// glazed window kept the sun and the sky out of a room. Built once per scene; read-only after.
class PassThrough {
 public:
  /// `glass`: refracting glass passes too (else only windows: the path tracer, whose reference
  /// must stay exact, takes glass as the interface it is).
  PassThrough(const Scene& scene, bool glass);
  /// The same for a RayScene of `hierarchy`'s leaves (RayScene::from_leaves(): ids are element
  /// ids), each element as its polygon.
  PassThrough(const Scene& scene, bool glass, const PatchHierarchy& hierarchy);
  /// The same, or nothing when no polygon passes light (then shadow rays need not look for panes).
  static std::optional<PassThrough> if_any(const Scene& scene, bool glass);
  static std::optional<PassThrough> if_any(const Scene& scene, bool glass, const PatchHierarchy& hierarchy);
  /// Whether some polygon passes light (else transmittance() is never more than 0).
  bool any() const { return any_; }
  /// The most panes a ray is followed through; one that meets more is taken as blocked.
  static constexpr int kMaxCrossings = 16;
  /// The transmittance along origin + t dir, t in (tnear, tfar), through `polygons` (the
  /// RayScene whose ids this was built for): 1 when nothing is hit, 0 when a polygon that does
  /// not pass light is, else the product over the crossings (at most kMaxCrossings). `step` (parametric,
  /// > 0) moves each next search past the polygon just crossed. Thread safety: may be called
  /// concurrently.
  Rgb transmittance(const RayScene& polygons, const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                    float step) const;
  /// What a ray along `dir` keeps crossing the polygon of `id` (`geometric_normal` the hit's,
  /// any length): 0 when it passes no light.
  Rgb crossing(std::uint32_t id, const glm::vec3& dir, const glm::vec3& geometric_normal) const;

 private:
  std::vector<Rgb> tau_;     ///< per id: its polygon's transmittance, 0 where it passes nothing
  std::vector<float> ior_;   ///< per id: 1 for a window, else the glass's
  bool any_ = false;
};

/// The transmittance from `origin` (already lifted off its surface) to the light of `in`:
/// 1 or 0 as unoccluded() says, or through `through`'s windows and glass when it is given
/// (`epsilon`, in scene units, steps each search past the polygon just crossed).
Rgb light_transmittance(const RayScene& occluders, const PassThrough* through, const glm::vec3& origin,
                        const glm::vec3& light_position, const Incidence& in, float epsilon);

/// True when nothing in `occluders` lies between `origin` (a point already lifted off its
/// surface) and the light of `in`: for a point or spot up to just short of the light (the
/// shadow-ray convention of visibility.hpp, tfar = 1 - 1e-4 of the segment), for a directional
/// light or a sky direction to infinity.
bool unoccluded(const RayScene& occluders, const glm::vec3& origin, const glm::vec3& light_position,
                const Incidence& in);

/// The irradiance (W/m^2) at x, on the side its unit normal n faces, from the delta lights: each
/// exactly, with a shadow ray from x lifted by `epsilon` along n. Thread safety: may be called
/// concurrently.
/// With `through`, shadow rays pass its windows and glass (PassThrough).
Rgb delta_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x, const glm::vec3& n,
                        float epsilon, const PassThrough* through = nullptr);
/// One-sample estimate of the irradiance at x from the skies: one cosine-weighted direction from
/// `u_sky`, pi L V (unbiased); 0 without a sky. Thread safety: may be called concurrently.
Rgb sky_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x, const glm::vec3& n,
                      float epsilon, const glm::vec2& u_sky, const PassThrough* through = nullptr);

/// One-sample estimate of the irradiance (W/m^2) that arrives at x, on the side its unit normal n
/// faces, straight from the lights: every delta light exactly, with a shadow ray each (x lifted
/// by `epsilon` along n), and the sky by one cosine-weighted direction from `u_sky` (pi L V:
/// unbiased). Thread safety: may be called concurrently.
Rgb light_irradiance_at(const SceneLights& lights, const RayScene& occluders, const glm::vec3& x,
                        const glm::vec3& n, float epsilon, const glm::vec2& u_sky, const PassThrough* through = nullptr);

}  // namespace radiosity::detail
