// Light groups: the membership rule (light_groups.hpp).
#include "solver/light_groups.hpp"

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

}  // namespace radiosity::detail
