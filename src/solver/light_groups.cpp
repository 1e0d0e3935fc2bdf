// Light groups: the membership rule (light_groups.hpp) and the emitters' weights of one group's
// contribution to a solution.
#include "solver/light_groups.hpp"

#include <algorithm>

#include "core/color.hpp"
#include "scene/emission.hpp"

namespace radiosity::detail {

std::vector<LightGroupMembers> light_group_members(const Scene& scene, const std::vector<Rgb>* emission) {
  const std::vector<Polygon>& polygons = scene.polygons();
  const std::vector<Light>& lights = scene.lights();
  std::vector<LightGroupMembers> out;
  auto named = [&](const std::string& name) -> LightGroupMembers& {
    for (LightGroupMembers& g : out)
      if (g.name == name) return g;
    out.push_back(LightGroupMembers{name, std::vector<char>(scene.groups().size(), 0),
                                    std::vector<char>(lights.size(), 0)});
    return out.back();
  };
  // Emitting polygons by their group, in GroupId order; then the lights by their light group
  // (else their name, else "light N"), joining a light group of the same name.
  std::vector<char> emits(scene.groups().size(), 0);
  for (PolygonId p = 0; p < polygons.size(); ++p)
    if (max_channel(polygon_emission(scene, p, emission)) > 0.0f) emits[polygons[p].group] = 1;
  for (GroupId g = 0; g < emits.size(); ++g)
    if (emits[g]) named(scene.groups()[g]).groups[g] = 1;
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const Light& l = lights[k];
    named(!l.light_group.empty() ? l.light_group : !l.name.empty() ? l.name : "light " + std::to_string(k)).lights[k] = 1;
  }
  return out;
}

void check_light_group(const Solution& solution, int light_group, const std::string& caller) {
  const std::size_t count = solution.light_groups().size();
  if (light_group == -1 || (light_group >= 0 && static_cast<std::size_t>(light_group) < count)) return;
  if (count == 0)
    throw Error(ErrorCode::invalid_argument, caller + ": light group " + std::to_string(light_group) +
                                                 " asked for, but the solution has no light groups (solve with "
                                                 "SolveOptions::separate_light_groups)");
  throw Error(ErrorCode::invalid_argument, caller + ": light group " + std::to_string(light_group) +
                                               " does not exist (the solution has " + std::to_string(count) +
                                               " light groups: 0 to " + std::to_string(count - 1) + ", or -1 for all)");
}

EmitterWeights emitter_weights(const Scene& scene, const Solution& solution, int light_group, const std::string& caller) {
  check_light_group(solution, light_group, caller);
  EmitterWeights out{std::vector<Rgb>(scene.polygons().size(), Rgb(1.0f)),
                     std::vector<Rgb>(scene.lights().size(), Rgb(1.0f))};
  const std::vector<Rgb>& weights = solution.light_group_weights();
  if (light_group < 0 && std::all_of(weights.begin(), weights.end(), [](const Rgb& w) { return w == Rgb(1.0f); }))
    return out;

  const std::vector<LightGroupMembers> members = light_group_members(scene, nullptr);
  const std::vector<LightGroupSolution>& solved = solution.light_groups();
  const bool same = members.size() == solved.size() &&
                    std::equal(members.begin(), members.end(), solved.begin(),
                               [](const LightGroupMembers& m, const LightGroupSolution& s) { return m.name == s.name; });
  if (!same) {
    auto list = [](auto begin, auto end) {
      std::string names;
      for (auto it = begin; it != end; ++it) names += (names.empty() ? "" : ", ") + it->name;
      return names;
    };
    throw Error(ErrorCode::invalid_argument,
                caller + ": the solution's light groups (" + list(solved.begin(), solved.end()) +
                    ") are not those of the scene's emitters and lights (" + list(members.begin(), members.end()) +
                    "): was it solved from another scene, or with other emission?");
  }
  // Every emitter at its light group's weight; light group k alone: the others at 0.
  std::vector<Rgb> group_weight(scene.groups().size(), Rgb(0.0f));
  std::fill(out.light.begin(), out.light.end(), Rgb(0.0f));
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (light_group >= 0 && k != static_cast<std::size_t>(light_group)) continue;
    for (GroupId g = 0; g < group_weight.size(); ++g)
      if (members[k].groups[g]) group_weight[g] = weights[k];
    for (std::size_t l = 0; l < out.light.size(); ++l)
      if (members[k].lights[l]) out.light[l] = weights[k];
  }
  for (PolygonId p = 0; p < scene.polygons().size(); ++p) out.polygon[p] = group_weight[scene.polygons()[p].group];
  return out;
}

}  // namespace radiosity::detail
