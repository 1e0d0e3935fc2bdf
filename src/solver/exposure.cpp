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

/// The burial test at points of leaf side (e, back), by their (u, v) in the leaf.
class SidePoints {
 public:
  SidePoints(const PatchHierarchy& h, const RayScene& occluders, float epsilon,
             const std::vector<std::uint8_t>& back_surface, std::uint32_t e, bool back)
      : h_(h), occluders_(occluders), back_surface_(back_surface), e_(e),
        lift_(epsilon * (back ? -h.normal(e) : h.normal(e))),
        directions_(burial_directions(back ? -h.normal(e) : h.normal(e))) {}

  bool open(glm::vec2 uv) const {
    auto sealed = [&](const RayScene::Hit& hit, const glm::vec3& d) {
      return glm::dot(d, hit.geometric_normal) > 0.0f && !back_surface_[hit.id];
    };
    return !buried(occluders_, h_.sample_point(e_, uv) + lift_, directions_, sealed);
  }
  /// The share of `cells` x `cells` cell centres that are open.
  float share(int cells) const {
    int count = 0;
    for (int i = 0; i < cells; ++i)
      for (int k = 0; k < cells; ++k)
        count += open(glm::vec2((static_cast<float>(i) + 0.5f) / static_cast<float>(cells),
                                (static_cast<float>(k) + 0.5f) / static_cast<float>(cells)))
                     ? 1
                     : 0;
    return static_cast<float>(count) / static_cast<float>(cells * cells);
  }
  /// Whether the leaf's four corners (a hair inside it) are all `open`, or all buried.
  bool corners_are(bool want_open) const {
    constexpr float kIn = 0.01f;
    for (const glm::vec2 uv : {glm::vec2(kIn, kIn), glm::vec2(1.0f - kIn, kIn), glm::vec2(kIn, 1.0f - kIn),
                               glm::vec2(1.0f - kIn, 1.0f - kIn)})
      if (open(uv) != want_open) return false;
    return true;
  }

 private:
  const PatchHierarchy& h_;
  const RayScene& occluders_;
  const std::vector<std::uint8_t>& back_surface_;
  std::uint32_t e_;
  glm::vec3 lift_;
  std::array<glm::vec3, 4> directions_;
};

}  // namespace

void measure_exposure(const PatchHierarchy& h, const RayScene& occluders, float epsilon,
                      const std::vector<std::uint8_t>& back_surface, const std::vector<std::uint8_t>& has_back,
                      const std::vector<std::uint32_t>& leaves, unsigned threads, std::vector<float>& exposure) {
  RADIOSITY_ASSERT(exposure.size() >= 2 * h.elements().size());
  const std::vector<Patch>& patches = h.patches();
  auto sides = [&](std::uint32_t e) { return has_back[h.element(e).patch] ? 2u : 1u; };
  // `fine`: the coarse share stands where the leaf's corners agree with it (all open, or all
  // buried: a block's footprint is convex), else the fine one is taken.
  auto measure = [&](const std::vector<std::uint32_t>& todo, bool fine, std::size_t grain) {
    parallel_for(threads, todo.size(), grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t e = todo[i];
        for (unsigned side = 0; side < sides(e); ++side) {
          const SidePoints points(h, occluders, epsilon, back_surface, e, side == 1);
          float& x = exposure[2 * std::size_t{e} + side];
          if (!fine)
            x = points.share(kCoarseCells);
          else if (!((x == 0.0f || x == 1.0f) && points.corners_are(x == 1.0f)))
            x = points.share(kFineCells);
        }
      }
    });
  };
  for (const std::uint32_t e : leaves) exposure[2 * std::size_t{e} + 1] = 1.0f;
  measure(leaves, false, 256);
  std::vector<std::uint8_t> touched(back_surface.size(), 0);
  for (const std::uint32_t e : leaves)
    if (exposure[2 * std::size_t{e}] < 1.0f || exposure[2 * std::size_t{e} + 1] < 1.0f)
      touched[patches[h.element(e).patch].polygon] = 1;
  std::vector<std::uint32_t> fine;
  for (const std::uint32_t e : leaves)
    if (touched[patches[h.element(e).patch].polygon]) fine.push_back(e);
  measure(fine, true, 16);
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
