// Exposure: the share of each leaf element side that is not buried, i.e. not inside a solid
// standing on it (the floor under a block resting on it, the part of a prop sunk into the floor;
// geometry/burial.hpp). The solvers take a partly buried element's values as its open part's and
// weight its targets by open area (RadiositySystem::Weights, docs/ARCHITECTURE.md, "Contact and
// light leaks"). The Monte Carlo rows measure it with their own rays (SparseFactors::exposed);
// this measures it by points for the solvers that have no rows: hierarchical and progressive.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "geometry/ray_scene.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "solver/system.hpp"

namespace radiosity::detail {

/// Measures exposure[2 e] (front) and exposure[2 e + 1] (back) of the leaves `leaves` of `h`:
/// the share of 2 x 2 cell centres that the burial test finds open, then of 8 x 8 for the
/// leaves of a polygon where one was found buried, partly or wholly: those found partly
/// buried, and those whose four corners do not all agree with their centres (a block's edge
/// may cross a leaf between its four centres; the values of a partly buried leaf are divided
/// by its exposure, which a quarter's resolution would make up to twice too bright or too dark).
/// `occluders`: the scene's polygons (ids are polygon ids); `back_surface[polygon]`: its back
/// is a surface (two-sided or translucent), so a ray that meets it is not sealed;
/// `has_back[patch]`: the patch has a back side of its own (else its back exposure is 1);
/// `epsilon`: how far the points are lifted off their surface. `exposure` must hold 2 values
/// per element; others are not touched. Cost: one ray per open point, four per buried one.
/// Deterministic; runs on `threads` threads.
void measure_exposure(const PatchHierarchy& h, const RayScene& occluders, float epsilon,
                      const std::vector<std::uint8_t>& back_surface, const std::vector<std::uint8_t>& has_back,
                      const std::vector<std::uint32_t>& leaves, unsigned threads, std::vector<float>& exposure);

/// Per element id of `h` (the first `count`), its open area: a leaf's area x
/// `leaf_exposure(e)`, an inner node's its children's sum. The weights of aggregate_open().
template <typename LeafExposure>
std::vector<double> open_areas(const PatchHierarchy& h, std::size_t count, const LeafExposure& leaf_exposure) {
  std::vector<double> open(count, 0.0);
  for (std::size_t e = count; e-- > 0;) {  // children have larger ids than their parent
    const Element& el = h.element(static_cast<std::uint32_t>(e));
    if (el.is_leaf()) {
      open[e] = static_cast<double>(el.area) * static_cast<double>(leaf_exposure(static_cast<std::uint32_t>(e)));
      continue;
    }
    for (std::uint32_t k = 0; k < 4; ++k) open[e] += open[el.first_child + k];
  }
  return open;
}

/// Fills the inner nodes of `values` (per element id; leaves are read) with the mean of their
/// children weighted by open area (open_areas()): the leaves' values are their open parts', and
/// so are the inner nodes'. A node with no open area takes the plain area mean.
template <typename LeafExposure>
void aggregate_open(const PatchHierarchy& h, std::vector<Rgb>& values, const LeafExposure& leaf_exposure) {
  const std::vector<double> weight = open_areas(h, values.size(), leaf_exposure);
  for (std::size_t e = values.size(); e-- > 0;) {
    const Element& el = h.element(static_cast<std::uint32_t>(e));
    if (el.is_leaf()) continue;
    glm::dvec3 sum(0.0), open_sum(0.0);
    double area = 0.0;
    for (std::uint32_t k = 0; k < 4; ++k) {
      const std::uint32_t c = el.first_child + k;
      const double a = h.element(c).area;
      sum += a * glm::dvec3(values[c]);
      open_sum += weight[c] * glm::dvec3(values[c]);
      area += a;
    }
    values[e] = weight[e] > 0.0 ? Rgb(open_sum / weight[e]) : area > 0.0 ? Rgb(sum / area) : Rgb(0.0f);
  }
}

/// Per unknown of `system` (meshed as `h` from `scene`): effective_exposure() of its side, by
/// measure_exposure() over every leaf (backs where the system has them); empty when every side
/// is open. Builds a BVH of the scene's polygons for it.
std::vector<float> unknown_exposure(const Scene& scene, const PatchHierarchy& h, const RadiositySystem& system,
                                    unsigned threads);

}  // namespace radiosity::detail
