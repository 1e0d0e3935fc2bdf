// The cluster hierarchy and its directional moments (cluster_tree.hpp, docs/HIERARCHICAL.md).
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991; B. Smits, J. Arvo & D. Greenberg, "A clustering algorithm for radiosity in
// complex environments", SIGGRAPH 1994; F. Sillion, "A unified hierarchical algorithm for global
// illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995; A. Willmott,
// P. Heckbert & M. Garland, "Face cluster radiosity", EGWR 1999.
#include "solver/hierarchical/cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/assert.hpp"
#include "core/constants.hpp"
#include "core/parallel.hpp"

namespace radiosity::detail {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Recursive median-split build over the permutation array (ClusterTree's constructor).
struct Builder {
  const PatchHierarchy& hierarchy;
  std::vector<ClusterNode>& nodes;
  std::vector<std::uint32_t>& order;
  std::vector<std::uint32_t>& leaf_of;
  int depth = 0;

  ClusterNode leaf(std::uint32_t first) const {
    const std::uint32_t p = order[first];
    const Patch& patch = hierarchy.patches()[p];
    const Element& root = hierarchy.element(patch.root);
    ClusterNode n;
    n.bounds.lower = glm::vec3(kInf);
    n.bounds.upper = glm::vec3(-kInf);
    for (int c = 0; c < root.corner_count(); ++c) {
      const glm::vec3& v = hierarchy.vertices()[root.corners[c]];
      n.bounds.lower = glm::min(n.bounds.lower, v);
      n.bounds.upper = glm::max(n.bounds.upper, v);
    }
    n.centre = 0.5f * (n.bounds.lower + n.bounds.upper);
    for (int c = 0; c < root.corner_count(); ++c)
      n.radius = std::max(n.radius, glm::length(hierarchy.vertices()[root.corners[c]] - n.centre));
    n.area = patch.area;
    n.first = first;
    n.count = 1;
    return n;
  }

  std::uint32_t build(std::uint32_t first, std::uint32_t count, int level) {
    const auto id = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    depth = std::max(depth, level);
    if (count == 1) {
      nodes[id] = leaf(first);
      leaf_of[order[first]] = id;
      return id;
    }

    // Split at the median centroid along the longest axis of the centroids' bounds; ties go by
    // patch id, a strict total order, so nth_element's result does not depend on its algorithm.
    const std::vector<Patch>& patches = hierarchy.patches();
    glm::vec3 lower(kInf), upper(-kInf);
    for (std::uint32_t i = first; i < first + count; ++i) {
      lower = glm::min(lower, patches[order[i]].centroid);
      upper = glm::max(upper, patches[order[i]].centroid);
    }
    const glm::vec3 extent = upper - lower;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::uint32_t half = count / 2;
    const auto begin = order.begin() + first;
    std::nth_element(begin, begin + half, begin + count, [&](std::uint32_t a, std::uint32_t b) {
      const float ca = patches[a].centroid[axis], cb = patches[b].centroid[axis];
      return ca < cb || (ca == cb && a < b);
    });
    const std::uint32_t left = build(first, half, level + 1);
    const std::uint32_t right = build(first + half, count - half, level + 1);

    // Bounds, sphere and area from the children: the sphere is centred on the box and is the
    // smaller of the box's circumsphere and the sphere around the children's spheres.
    const ClusterNode& l = nodes[left];
    const ClusterNode& r = nodes[right];
    ClusterNode n;
    n.bounds.lower = glm::min(l.bounds.lower, r.bounds.lower);
    n.bounds.upper = glm::max(l.bounds.upper, r.bounds.upper);
    n.centre = 0.5f * (n.bounds.lower + n.bounds.upper);
    const float around_children = std::max(glm::length(l.centre - n.centre) + l.radius,
                                           glm::length(r.centre - n.centre) + r.radius);
    n.radius = std::min(0.5f * glm::length(n.bounds.upper - n.bounds.lower), around_children);
    n.area = l.area + r.area;
    n.first = first;
    n.count = count;
    n.children = {left, right};
    nodes[id] = n;
    return id;
  }
};

}  // namespace

ClusterTree::ClusterTree(const PatchHierarchy& hierarchy) {
  const auto n = static_cast<std::uint32_t>(hierarchy.patches().size());
  if (n == 0) return;
  order_.resize(n);
  for (std::uint32_t p = 0; p < n; ++p) order_[p] = p;
  leaf_of_.assign(n, kNone);
  nodes_.reserve(2 * static_cast<std::size_t>(n) - 1);
  Builder builder{hierarchy, nodes_, order_, leaf_of_};
  builder.build(0, n, 0);
  depth_ = builder.depth;
  RADIOSITY_ASSERT(nodes_.size() == 2 * static_cast<std::size_t>(n) - 1);
}

void add_surface(Moments& P, const glm::vec3& n, const Rgb& power) {
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  RADIOSITY_ASSERT(l1 > 0.0f);
  for (int a = 0; a < 3; ++a) {
    const float share = n[a] / l1;
    if (share > 0.0f) P[2 * a] += power * share;
    if (share < 0.0f) P[2 * a + 1] -= power * share;
  }
}

Rgb intensity(const Moments& P, const glm::vec3& w) {
  // I(w) = (1/pi) sum_a |w_a| P[sign(w_a) a] (docs/HIERARCHICAL.md, "Transport through a cluster").
  return kInvPi * directional_sum(P, w);
}

void sending_moments(const ClusterTree& tree, const PatchHierarchy& hierarchy, const std::vector<Rgb>& front,
                     const std::vector<Rgb>& back, unsigned threads, std::vector<Moments>& out) {
  const std::vector<Patch>& patches = hierarchy.patches();
  RADIOSITY_ASSERT(front.size() == patches.size());
  RADIOSITY_ASSERT(back.empty() || back.size() == patches.size());
  out.assign(tree.nodes().size(), Moments{});
  // Leaves: each patch's B A split by its normal, every leaf written by one index alone.
  parallel_for(threads, patches.size(), 1024, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      Moments& leaf = out[tree.leaf_of(static_cast<std::uint32_t>(p))];
      add_surface(leaf, patches[p].normal, front[p] * patches[p].area);
      if (!back.empty()) add_surface(leaf, -patches[p].normal, back[p] * patches[p].area);
    }
  });
  // Inner nodes: children before parents (depth-first ids), left child then right, so every sum
  // runs in one fixed order.
  for (std::size_t i = tree.nodes().size(); i-- > 0;) {
    const ClusterNode& node = tree.node(static_cast<std::uint32_t>(i));
    if (node.is_leaf()) continue;
    for (int k = 0; k < 6; ++k) out[i][k] = out[node.children[0]][k] + out[node.children[1]][k];
  }
}

void add_irradiance(Moments& E, const glm::vec3& d, const Rgb& flux) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0.0f) E[2 * a] += flux * d[a];
    if (d[a] < 0.0f) E[2 * a + 1] -= flux * d[a];
  }
}

Rgb element_irradiance(const Moments& E, const glm::vec3& n) {
  Rgb sum(0.0f);
  for (int a = 0; a < 3; ++a) sum += n[a] >= 0.0f ? n[a] * E[2 * a] : -n[a] * E[2 * a + 1];
  return sum;
}

}  // namespace radiosity::detail
