// Light groups (SolveOptions::separate_light_groups): which emitting polygons and which lights
// make up each group. The one rule that the solver (each group's own solve) and the consumers of
// a solution's groups (bake_lightmap()'s final gather of one group) share, so that a group means
// the same emitters everywhere. Private to the library.
#pragma once

#include <string>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace radiosity::detail {

/// The emitters of one light group.
struct LightGroupMembers {
  std::string name;
  std::vector<char> groups;  ///< per GroupId of the scene: 1 when the group's emitting polygons shine
  std::vector<char> lights;  ///< per Scene::lights() entry: 1 when the light shines
};

/// The light groups of `scene` when polygon p emits polygon_emission(scene, p, emission) (null:
/// the materials'), in the order of Solution::light_groups(): first every group (Scene::groups())
/// with an emitting polygon, in GroupId order and named after it; then the lights in order, each
/// in the light group named by its Light::light_group, else its name, else "light N" (N its
/// index); a light whose light group has the name of an earlier one (a polygon group's or
/// another light's) joins it. Cost: one pass over the polygons and lights.
/// Thread safety: pure.
std::vector<LightGroupMembers> light_group_members(const Scene& scene, const std::vector<Rgb>* emission);

/// Throws Error{invalid_argument}, its message starting with `caller`, unless `light_group` is
/// -1 (all) or an index of solution.light_groups(). Thread safety: pure.
void check_light_group(const Solution& solution, int light_group, const std::string& caller);

/// How much of each emitter's light counts, as an RGB factor: per polygon on its emission, per
/// light on its power.
struct EmitterWeights {
  std::vector<Rgb> polygon;  ///< per polygon of the scene
  std::vector<Rgb> light;    ///< per Scene::lights() entry
};

/// The emitters' weights in light group `light_group`'s contribution to `solution` (an index of
/// Solution::light_groups()): its weight (Solution::light_group_weights(), 1 for a solve) for the
/// group's emitting polygons and lights, 0 for every other emitter. light_group < 0: every
/// emitter at its light group's weight, all 1 when the solution has no light groups or weighs
/// them all 1 (no membership is worked out then). The groups are those of the materials'
/// emission (light_group_members(scene, nullptr)). Throws as check_light_group(), and
/// Error{invalid_argument} when the solution's light groups are not the scene's by name and
/// order (it was solved from another scene, or with other emission: Problem::solve(E)).
/// Thread safety: pure.
EmitterWeights emitter_weights(const Scene& scene, const Solution& solution, int light_group, const std::string& caller);

}  // namespace radiosity::detail
