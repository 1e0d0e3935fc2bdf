#include "solver/exposure.hpp"

#include <algorithm>
#include <array>

#include <glm/geometric.hpp>

#include "core/assert.hpp"
#include "core/parallel.hpp"
#include "geometry/burial.hpp"

namespace radiosity::detail {
namespace {

constexpr int kCoarseCells = 2;
constexpr int kFineCells = 8;

/// The share of `cells` x `cells` cell centres of leaf side (e, back) that are not buried.
float open_share(const PatchHierarchy& h, const RayScene& occluders, float epsilon,
                 const std::vector<std::uint8_t>& back_surface, std::uint32_t e, bool back, int cells) {
  const glm::vec3 n = back ? -h.normal(e) : h.normal(e);
  const std::array<glm::vec3, 4> directions = burial_directions(n);
  auto sealed = [&](const RayScene::Hit& hit, const glm::vec3& d) {
    return glm::dot(d, hit.geometric_normal) > 0.0f && !back_surface[hit.id];
  };
  int open = 0;
  for (int i = 0; i < cells; ++i)
    for (int k = 0; k < cells; ++k) {
      const glm::vec2 uv((static_cast<float>(i) + 0.5f) / static_cast<float>(cells),
                         (static_cast<float>(k) + 0.5f) / static_cast<float>(cells));
      open += buried(occluders, h.sample_point(e, uv) + epsilon * n, directions, sealed) ? 0 : 1;
    }
  return static_cast<float>(open) / static_cast<float>(cells * cells);
}

}  // namespace

void measure_exposure(const PatchHierarchy& h, const RayScene& occluders, float epsilon,
                      const std::vector<std::uint8_t>& back_surface, const std::vector<std::uint8_t>& has_back,
                      const std::vector<std::uint32_t>& leaves, unsigned threads, std::vector<float>& exposure) {
  RADIOSITY_ASSERT(exposure.size() >= 2 * h.elements().size());
  const std::vector<Patch>& patches = h.patches();
  auto sides = [&](std::uint32_t e) { return has_back[h.element(e).patch] ? 2u : 1u; };
  auto measure = [&](const std::vector<std::uint32_t>& todo, int cells, std::size_t grain) {
    parallel_for(threads, todo.size(), grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t e = todo[i];
        for (unsigned side = 0; side < sides(e); ++side)
          exposure[2 * std::size_t{e} + side] = open_share(h, occluders, epsilon, back_surface, e, side == 1, cells);
      }
    });
  };
  for (const std::uint32_t e : leaves) exposure[2 * std::size_t{e} + 1] = 1.0f;
  measure(leaves, kCoarseCells, 256);
  std::vector<std::uint8_t> touched(back_surface.size(), 0);
  for (const std::uint32_t e : leaves)
    if (exposure[2 * std::size_t{e}] < 1.0f || exposure[2 * std::size_t{e} + 1] < 1.0f)
      touched[patches[h.element(e).patch].polygon] = 1;
  std::vector<std::uint32_t> fine;
  for (const std::uint32_t e : leaves)
    if (touched[patches[h.element(e).patch].polygon]) fine.push_back(e);
  measure(fine, kFineCells, 16);
}

std::vector<float> unknown_exposure(const Scene& scene, const PatchHierarchy& h, const RadiositySystem& system,
                                    unsigned threads) {
  const RayScene occluders = RayScene::from_polygons(scene);
  const float epsilon = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
  std::vector<std::uint8_t> has_back(h.patches().size(), 0), back_surface(scene.polygons().size(), 0);
  for (std::size_t u = system.fronts(); u < system.unknowns(); ++u) {
    const std::uint32_t p = h.element(system.element(u)).patch;
    has_back[p] = 1;
    back_surface[h.patches()[p].polygon] = 1;
  }
  std::vector<float> exposure(2 * h.elements().size(), 1.0f);
  measure_exposure(h, occluders, epsilon, back_surface, has_back, system.leaves, threads, exposure);
  std::vector<float> out(system.unknowns());
  bool buried = false;
  for (std::size_t u = 0; u < out.size(); ++u) {
    out[u] = effective_exposure(exposure[2 * std::size_t{system.element(u)} + (u >= system.fronts() ? 1 : 0)]);
    buried = buried || out[u] < 1.0f;
  }
  if (!buried) out.clear();
  return out;
}

}  // namespace radiosity::detail
