#include "solve/system.hpp"

namespace radiosity::detail {

RadiositySystem::RadiositySystem(const Scene& scene, const PatchHierarchy& hierarchy) : leaves(hierarchy.leaves()) {
  const std::size_t m = leaves.size();
  area.resize(m);
  emission.resize(m);
  reflectance.resize(m);
  patch.resize(m);
  // Patch areas as the sum of their leaves, so a patch mean of a constant field is exact.
  patch_area.assign(hierarchy.patches().size(), 0.0f);
  for (std::size_t i = 0; i < m; ++i) {
    const Element& e = hierarchy.element(leaves[i]);
    const Material& mat = scene.material(hierarchy.patches()[e.patch].material);
    area[i] = e.area;
    emission[i] = mat.emission;
    reflectance[i] = mat.reflectance;
    patch[i] = e.patch;
    patch_area[e.patch] += e.area;
    emitted += static_cast<double>(e.area) * (mat.emission.x + mat.emission.y + mat.emission.z);
    total_area += e.area;
  }
  glm::dvec3 mean_rho(0.0);
  for (std::size_t i = 0; i < m; ++i) mean_rho += static_cast<double>(area[i]) * glm::dvec3(reflectance[i]);
  if (total_area > 0.0) mean_rho /= total_area;
  interreflection = Rgb(1.0 / (glm::dvec3(1.0) - mean_rho));
}

void RadiositySystem::patch_means(const std::vector<Rgb>& B, std::vector<Rgb>& patch_B) const {
  std::vector<glm::dvec3> sum(patch_area.size(), glm::dvec3(0.0));
  for (std::size_t i = 0; i < B.size(); ++i) sum[patch[i]] += static_cast<double>(area[i]) * glm::dvec3(B[i]);
  patch_B.resize(patch_area.size());
  for (std::size_t j = 0; j < sum.size(); ++j) patch_B[j] = Rgb(sum[j] / static_cast<double>(patch_area[j]));
}

bool ProgressGate::due(Phase phase, bool force) const {
  if (!fn_) return false;
  // Phase boundaries always get through; within a phase at most one call per 100 ms.
  return force || first_ || phase != phase_ || std::chrono::steady_clock::now() - last_ >= std::chrono::milliseconds(100);
}

bool ProgressGate::report(const Progress& p, bool force) {
  if (!due(p.phase, force)) return true;
  auto now = std::chrono::steady_clock::now();
  first_ = false;
  phase_ = p.phase;
  last_ = now;
  return fn_(p);
}

}  // namespace radiosity::detail
