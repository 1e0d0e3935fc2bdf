// Light groups (SolveOptions::separate_light_groups): which emitting polygons and which lights
// make up each group. The one rule that the solver (each group's own solve) and the consumers of
// a solution's groups share, so that a group means the same emitters everywhere. Private to the
// library.
#pragma once

#include <string>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/scene.hpp"

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

}  // namespace radiosity::detail
