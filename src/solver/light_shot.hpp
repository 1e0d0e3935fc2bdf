// The lights' first shot: each element's mean direct irradiance from every Light of the scene,
// which the radiosity system then takes as emission (rho H), so every solver and estimator
// carries the lights' interreflection unchanged. See docs/LIGHTS.md.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/progress.hpp"
#include "geometry/ray_scene.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "scene/lights.hpp"

namespace radiosity::detail {

/// Rays per (element side, light): a first pass, and a larger second one only when the first
/// pass's rays disagree (the element straddles a shadow edge, or sees the sky in part), the
/// two-pass idea of visibility.hpp. Delta lights need few rays (one ray decides a point); sky
/// visibility is a hemisphere's: occluders that cover less than about 5 / sky_rays of the
/// cosine-weighted sky can be missed by the first pass (a bias of at most that); the default 640
/// Halton rays give the element error 1280 independent-stratified rays did (docs/LIGHTS.md).
struct LightRayBudget {
  std::uint32_t first = 16;
  std::uint32_t penumbra = 256;
};
inline constexpr LightRayBudget kDeltaLightRays{16, 256};
/// A sky's budget from SolveOptions::sky_rays (at least 5): a fifth first, the rest second.
inline LightRayBudget sky_ray_budget(std::uint32_t sky_rays) {
  const std::uint32_t first = std::max<std::uint32_t>(1, sky_rays / 5);
  return {first, std::max<std::uint32_t>(1, sky_rays - first)};
}

/// The lights' direct irradiance per element id, kept by a Problem across solves (the lights
/// and the geometry do not change); elements made by adaptive subdivision are added as they
/// appear.
struct LightShot {
  std::vector<Rgb> front;            ///< per element id: mean irradiance over its front, W/m^2
  std::vector<Rgb> back;             ///< per element id: over its back (elements with a back only)
  std::vector<std::uint8_t> done;    ///< per element id: 1 once front (and back) are computed
  std::uint64_t rays = 0;            ///< shadow rays cast so far
  double seconds = 0.0;              ///< time spent so far

  /// Sizes the arrays for `element_count` elements (new ones not done) and returns those of
  /// `elements` not computed yet, in their order.
  std::vector<std::uint32_t> pending(const std::vector<std::uint32_t>& elements, std::size_t element_count) {
    front.resize(element_count, Rgb(0.0f));
    back.resize(element_count, Rgb(0.0f));
    done.resize(element_count, 0);
    std::vector<std::uint32_t> todo;
    for (const std::uint32_t e : elements)
      if (!done[e]) todo.push_back(e);
    return todo;
  }

  /// The irradiance of element `e`'s front (or back): 0 for one not computed.
  Rgb of(std::uint32_t e, bool back_side) const {
    const std::vector<Rgb>& v = back_side ? back : front;
    return e < v.size() ? v[e] : Rgb(0.0f);
  }
};

/// Computes LightShot values for a scene's elements.
/// Based on: the ray-cast form factor split of this library (FORM_FACTORS.md): an exact
/// unoccluded part times a visible fraction from shadow rays (Wallace, Elmquist & Haines,
/// "A ray tracing algorithm for progressive radiosity", SIGGRAPH 1989), here per light.
/// Thread safety: shoot() may be called concurrently on different LightShots.
class LightShooter {
 public:
  /// `seed` keys the random streams (Stream::light_front/light_back); `threads` and `sky_rays`
  /// as SolveOptions'. Builds a BVH over the scene's polygons (Embree). `through_windows` (the
  /// extended first pass, FormFactorOptions::specular_depth > 0): shadow rays pass windows and
  /// glass (PassThrough), else every polygon stops them.
  LightShooter(const Scene& scene, const PatchHierarchy& hierarchy, std::uint64_t seed, unsigned threads,
               std::uint32_t sky_rays, bool through_windows = false);

  bool empty() const { return lights_.empty(); }

  /// Computes every element of `elements` (ids of `hierarchy`, leaves) not done yet: its front,
  /// and its back where its patch has one (pass1_has_back()). Reports Phase::lights through
  /// `gate` between blocks of elements; returns false when cancelled (elements done so far
  /// keep their values). Deterministic: each element side and light draws from its own stream.
  /// With `only` (one flag per Scene::lights() entry) just the flagged lights shine: a light
  /// group's share (SolveOptions::separate_light_groups). Each light's value per element side is
  /// the same whatever else shines (its own random stream), so the shares add up to the whole.
  bool shoot(const std::vector<std::uint32_t>& elements, LightShot& shot, ProgressGate& gate,
             const std::vector<char>* only = nullptr) const;

  /// The mean irradiance over one side of element `e` (unit normal `n` of that side) from
  /// every light (or those flagged in `only`); `rays` counts the shadow rays.
  Rgb element_irradiance(std::uint32_t e, bool back_side, std::uint64_t& rays,
                         const std::vector<char>* only = nullptr) const;

  /// The scene's polygons as shadow-ray occluders (shared with hierarchical radiosity's links).
  const RayScene& occluders() const { return occluders_; }

 private:
  const PatchHierarchy& hierarchy_;
  SceneLights lights_;
  RayScene occluders_;
  float epsilon_ = 0.0f;
  LightRayBudget sky_budget_;
  std::uint64_t seed_ = 0;
  unsigned threads_ = 0;
  std::vector<std::uint8_t> patch_has_back_;
  std::optional<PassThrough> through_;  ///< with through_windows, when some polygon passes light
};

/// The mean over a planar triangle or convex quad (`corners`, counter-clockwise seen from its
/// front, `count` 3 or 4, area `area`) of the irradiance that delta light `light` sends onto
/// the side that unit normal `n` faces, without occlusion: I Omega / A for a point (Omega the
/// solid angle the cell subtends, exact), the same integral of the spot's falloff over the
/// solid angle (split where the cone's edges cross the cell), E max(0, n.(-d)) for a
/// directional light. Thread safety: pure.
Rgb unoccluded_cell_irradiance(const PreparedLight& light, const glm::vec3* corners, int count, float area,
                               const glm::vec3& n);

}  // namespace radiosity::detail
