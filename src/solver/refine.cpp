// Choosing elements for adaptive subdivision.
// Based on: Cohen, Greenberg, Immel & Brock, "An efficient radiosity approach for realistic
// image synthesis", IEEE CG&A 6(3), 1986 (adaptive element subdivision where radiosity
// gradients are high); Cohen & Wallace 1993, ch. 6 (discontinuities, shadow boundaries).
#include <algorithm>
#include <cmath>
#include <utility>

#include "solver/system.hpp"

namespace radiosity::detail {

namespace {

float luminance(const Rgb& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

std::vector<std::uint32_t> leaves_to_refine(const PatchHierarchy& hierarchy, const std::vector<Rgb>& B_elements,
                                            const std::vector<float>& exposure, const AdaptiveOptions& options,
                                            std::uint8_t max_depth, std::size_t element_budget) {
  const std::vector<std::uint32_t>& leaves = hierarchy.leaves();
  if (leaves.size() >= element_budget) return {};
  // The corner values average the neighbouring leaves, so a leaf that differs from a corner
  // differs from the neighbours there: a gradient or a discontinuity (shadow edge) crosses it.
  const std::vector<Rgb> vertex_B = hierarchy.vertex_values(B_elements, exposure);

  double area = 0.0, sum = 0.0;
  for (std::uint32_t e : leaves) {
    area += hierarchy.element(e).area;
    sum += static_cast<double>(hierarchy.element(e).area) * luminance(B_elements[e]);
  }
  // Relative differences in the dark are noise to the eye; below this floor they count
  // absolutely.
  const float floor = static_cast<float>(0.1 * sum / std::max(area, 1e-30));

  std::vector<std::pair<float, std::uint32_t>> candidates;
  for (std::uint32_t e : leaves) {
    const Element& el = hierarchy.element(e);
    if (el.depth >= max_depth || (!exposure.empty() && exposure[e] == 0.0f)) continue;
    const float Le = luminance(B_elements[e]);
    float score = 0.0f;
    for (int k = 0; k < el.corner_count(); ++k) {
      const float Lv = luminance(vertex_B[el.corners[k]]);
      const float scale = std::max(0.5f * (Lv + Le), floor);
      if (scale > 0.0f) score = std::max(score, std::fabs(Lv - Le) / scale);
    }
    if (score > options.threshold) candidates.emplace_back(score, e);
  }
  // Largest contrast first, within the budget (a split adds three leaves).
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
  const std::size_t room = (element_budget - leaves.size()) / 3;
  if (candidates.size() > room) candidates.resize(room);
  std::vector<std::uint32_t> out;
  out.reserve(candidates.size());
  for (const auto& c : candidates) out.push_back(c.second);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace radiosity::detail
