#include "solver/system.hpp"

#include "form_factors/estimators.hpp"
#include "form_factors/pass1_material.hpp"
#include "scene/emission.hpp"
#include "core/assert.hpp"

namespace radiosity::detail {

RadiositySystem::RadiositySystem(const Scene& scene, const PatchHierarchy& hierarchy, bool diffuse_transmission,
                                 const std::vector<Rgb>* polygon_emission, const LightShot* lights)
    : leaves(hierarchy.leaves()) {
  const std::size_t m = leaves.size(), n = hierarchy.patches().size();
  // Back targets first, numbered as the estimators number them, so each back unknown knows its target.
  const std::vector<std::uint32_t> translucent_patches =
      diffuse_transmission ? find_back_patches(scene, hierarchy) : std::vector<std::uint32_t>{};
  const std::vector<std::uint32_t> back_target = back_targets(n, translucent_patches);
  patch_area.assign(n + translucent_patches.size(), 0.0f);
  auto add = [&](std::uint32_t target, float a, const Rgb& E, const Rgb& rho, const Rgb& tau, std::uint32_t other) {
    area.push_back(a);
    emission.push_back(E);
    reflectance.push_back(rho);
    transmittance.push_back(tau);
    patch.push_back(target);
    twin.push_back(other);
    // Patch areas as the sum of their leaves, so a patch mean of a constant field is exact.
    patch_area[target] += a;
    total_area += a;
  };
  std::vector<std::uint32_t> backs;  // positions in `leaves` of the leaves with a back
  for (std::size_t i = 0; i < m; ++i) {
    const Element& e = hierarchy.element(leaves[i]);
    const Material& mat = scene.material(hierarchy.patches()[e.patch].material);
    const Rgb& E = detail::polygon_emission(scene, hierarchy.patches()[e.patch].polygon, polygon_emission);
    const bool translucent = back_target[e.patch] != kNone;
    add(e.patch, e.area, E, mat.reflectance, translucent ? mat.diffuse_transmittance : Rgb(0.0f),
        translucent ? static_cast<std::uint32_t>(m + backs.size()) : kNone);
    if (translucent) backs.push_back(static_cast<std::uint32_t>(i));
    emitted += static_cast<double>(e.area) * (E.x + E.y + E.z);
  }
  for (std::uint32_t i : backs) {
    const Element& e = hierarchy.element(leaves[i]);
    const Material& mat = scene.material(hierarchy.patches()[e.patch].material);
    const Rgb E = pass1_back_emission(mat, detail::polygon_emission(scene, hierarchy.patches()[e.patch].polygon,
                                                                    polygon_emission));
    add(back_target[e.patch], e.area, E, pass1_back_reflectance(mat), mat.diffuse_transmittance, i);
    emitted += static_cast<double>(e.area) * (E.x + E.y + E.z);
  }
  if (lights != nullptr) {
    light.resize(area.size());
    for (std::size_t u = 0; u < area.size(); ++u) {
      RADIOSITY_ASSERT(element(u) < lights->front.size());
      light[u] = lights->of(element(u), u >= m);
    }
    source.resize(area.size());
    for (std::size_t u = 0; u < area.size(); ++u) {
      source[u] = emission[u] + reflectance[u] * light[u];
      if (twin[u] != kNone) source[u] += transmittance[u] * light[twin[u]];
      emitted += static_cast<double>(area[u]) * (static_cast<double>(light[u].x) + light[u].y + light[u].z);
    }
  } else {
    source = emission;
  }
  glm::dvec3 mean(0.0);
  for (std::size_t u = 0; u < area.size(); ++u)
    mean += static_cast<double>(area[u]) * glm::dvec3(reflectance[u] + transmittance[u]);
  if (total_area > 0.0) mean /= total_area;
  interreflection = Rgb(1.0 / (glm::dvec3(1.0) - mean));
}

void RadiositySystem::patch_means(const std::vector<Rgb>& B, std::vector<Rgb>& patch_B) const {
  std::vector<glm::dvec3> sum(patch_area.size(), glm::dvec3(0.0));
  for (std::size_t i = 0; i < B.size(); ++i) sum[patch[i]] += static_cast<double>(area[i]) * glm::dvec3(B[i]);
  patch_B.resize(patch_area.size());
  for (std::size_t j = 0; j < sum.size(); ++j) patch_B[j] = Rgb(sum[j] / static_cast<double>(patch_area[j]));
}

RadiositySystem::Weights RadiositySystem::weights(const std::vector<float>& exposure) const {
  Weights w;
  w.side = area;
  RADIOSITY_ASSERT(exposure.empty() || exposure.size() == area.size());
  for (std::size_t u = 0; u < exposure.size(); ++u) w.side[u] *= exposure[u];
  if (exposure.empty()) {
    w.target.assign(patch_area.begin(), patch_area.end());
    return w;
  }
  w.target.assign(patch_area.size(), 0.0);
  for (std::size_t u = 0; u < area.size(); ++u) w.target[patch[u]] += static_cast<double>(w.side[u]);
  // A wholly buried target: the plain mean (its value reaches no one).
  for (std::size_t u = 0; u < area.size(); ++u)
    if (w.target[patch[u]] <= 0.0) w.side[u] = area[u];
  for (std::size_t j = 0; j < patch_area.size(); ++j)
    if (w.target[j] <= 0.0) w.target[j] = static_cast<double>(patch_area[j]);
  return w;
}

void RadiositySystem::patch_means(const std::vector<Rgb>& B, std::vector<Rgb>& patch_B, const Weights& w) const {
  std::vector<glm::dvec3> sum(patch_area.size(), glm::dvec3(0.0));
  for (std::size_t i = 0; i < B.size(); ++i) sum[patch[i]] += static_cast<double>(w.side[i]) * glm::dvec3(B[i]);
  patch_B.resize(patch_area.size());
  for (std::size_t j = 0; j < sum.size(); ++j) patch_B[j] = Rgb(sum[j] / w.target[j]);
}

std::vector<Rgb> RadiositySystem::exposed_source(const std::vector<float>& exposure) const {
  if (exposure.empty() || light.empty()) return source;
  std::vector<Rgb> out(source.size());
  for (std::size_t u = 0; u < source.size(); ++u) {
    out[u] = emission[u] + reflectance[u] * exposed_light(u, exposure);
    if (twin[u] != kNone) out[u] += transmittance[u] * exposed_light(twin[u], exposure);
  }
  return out;
}

}  // namespace radiosity::detail
