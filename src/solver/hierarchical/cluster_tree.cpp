// The cluster hierarchy and its directional moments (cluster_tree.hpp, docs/HIERARCHICAL.md).
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991; B. Smits, J. Arvo & D. Greenberg, "A clustering algorithm for radiosity in
// complex environments", SIGGRAPH 1994; F. Sillion, "A unified hierarchical algorithm for global
// illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995; A. Willmott,
// P. Heckbert & M. Garland, "Face cluster radiosity", EGWR 1999.
#include "solver/hierarchical/cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/assert.hpp"
#include "core/constants.hpp"
#include "core/parallel.hpp"
#include "scene/polygon_math.hpp"

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

ClusterTree::ClusterTree(const PatchHierarchy& hierarchy, const std::vector<std::uint8_t>& include) {
  const auto patches = static_cast<std::uint32_t>(hierarchy.patches().size());
  RADIOSITY_ASSERT(include.empty() || include.size() == patches);
  leaf_of_.assign(patches, kNone);
  for (std::uint32_t p = 0; p < patches; ++p)
    if (include.empty() || include[p] != 0) order_.push_back(p);
  const auto n = static_cast<std::uint32_t>(order_.size());
  if (n == 0) return;
  nodes_.reserve(2 * static_cast<std::size_t>(n) - 1);
  Builder builder{hierarchy, nodes_, order_, leaf_of_};
  builder.build(0, n, 0);
  depth_ = builder.depth;
  RADIOSITY_ASSERT(nodes_.size() == 2 * static_cast<std::size_t>(n) - 1);
}

std::uint32_t MomentBases::axis_id(const glm::vec3& n) {
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    if (n[b] != 0.0f || n[c] != 0.0f) continue;
    if (n[a] == 1.0f) return static_cast<std::uint32_t>(2 * a);
    if (n[a] == -1.0f) return static_cast<std::uint32_t>(2 * a + 1);
  }
  return kNone;
}

MomentBases::MomentBases(const ClusterTree& tree, const PatchHierarchy& hierarchy,
                         const std::vector<std::uint8_t>& has_back) {
  const std::vector<Patch>& patches = hierarchy.patches();
  RADIOSITY_ASSERT(has_back.size() == patches.size());
  // Direction ids, in patch order (so the same on every run): the axes' own, else one per
  // direction_key() (the normal quantised to 2^-12), a quantised axis taking the axis' id. The
  // facets of one turned face (a block's side cut into facets as an exporter writes them) have
  // normals that differ in their last bits: quantised to 2^-20, the tall Cornell block's four
  // turned sides in 6 x 6 facets made 18 ids, its clusters passed six and fell back to the
  // axes, whose moments send a turned side's light partly backwards.
  std::map<std::array<std::int64_t, 3>, std::uint32_t> ids;
  std::uint32_t next = 6;
  auto id_of = [&](const glm::vec3& n) {
    const std::uint32_t axis = axis_id(n);
    if (axis != kNone) return axis;
    const std::array<std::int64_t, 3> key = direction_key(n);
    for (std::size_t a = 0; a < 3; ++a) {
      if (key[(a + 1) % 3] != 0 || key[(a + 2) % 3] != 0) continue;
      if (key[a] == kDirectionKeyUnit) return static_cast<std::uint32_t>(2 * a);
      if (key[a] == -kDirectionKeyUnit) return static_cast<std::uint32_t>(2 * a + 1);
    }
    const auto [at, inserted] = ids.emplace(key, next);
    if (inserted) ++next;
    return at->second;
  };
  front_.resize(patches.size());
  back_.assign(patches.size(), kNone);
  for (std::size_t p = 0; p < patches.size(); ++p) {
    front_[p] = id_of(patches[p].normal);
    if (has_back[p]) back_[p] = id_of(-patches[p].normal);
  }
  // Bases bottom-up (children have larger ids than their parent). A cluster's set is its
  // children's union while that has at most six directions; kOverflow marks a cluster beyond,
  // and every cluster above it.
  constexpr std::uint32_t kOverflow = 0;
  const std::size_t C = tree.nodes().size();
  of_cluster_.assign(C, kOverflow);
  std::map<std::vector<std::uint32_t>, std::uint32_t> index;
  // The direction sets themselves, per basis (the axes' flag alone does not say which axes).
  std::vector<std::vector<std::uint32_t>> sets(1);
  std::vector<std::uint32_t> set;
  for (std::size_t i = C; i-- > 0;) {
    const ClusterNode& node = tree.node(static_cast<std::uint32_t>(i));
    set.clear();
    if (node.is_leaf()) {
      const std::uint32_t p = tree.order()[node.first];
      set.push_back(front_[p]);
      if (back_[p] != kNone) set.push_back(back_[p]);
    } else {
      const std::uint32_t l = of_cluster_[node.children[0]], r = of_cluster_[node.children[1]];
      if (l == kOverflow || r == kOverflow) continue;
      std::set_union(sets[l].begin(), sets[l].end(), sets[r].begin(), sets[r].end(), std::back_inserter(set));
    }
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    if (set.size() > 6) continue;
    auto found = index.find(set);
    if (found == index.end()) {
      if (bases_.size() >= kMaxBases) continue;
      MomentBasis b;
      b.axes = set.back() < 6;  // every direction along an axis: the axis moments are exact
      b.count = static_cast<std::uint8_t>(set.size());
      for (std::size_t k = 0; k < set.size(); ++k) b.ids[k] = set[k];
      found = index.emplace(set, static_cast<std::uint32_t>(bases_.size())).first;
      bases_.push_back(b);
      sets.push_back(set);
    }
    of_cluster_[i] = found->second;
  }
  // The explicit bases' directions: each id's first patch side's normal.
  std::vector<glm::vec3> direction(next, glm::vec3(0.0f));
  for (int a = 0; a < 6; ++a) direction[static_cast<std::size_t>(a)] = axis_direction(a);
  for (std::size_t p = patches.size(); p-- > 0;) {  // the first patch's normal last, so it stays
    direction[front_[p]] = patches[p].normal;
    if (back_[p] != kNone) direction[back_[p]] = -patches[p].normal;
  }
  for (std::size_t k = 1; k < bases_.size(); ++k) {
    MomentBasis& b = bases_[k];
    for (int j = 0; j < b.count; ++j) b.directions[static_cast<std::size_t>(j)] = direction[b.ids[static_cast<std::size_t>(j)]];
  }
  for (std::size_t i = 0; i < C; ++i) explicit_clusters_ += bases_[of_cluster_[i]].axes ? 0 : 1;
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

Rgb intensity(const Moments& P, const MomentBasis& b, const glm::vec3& w) {
  // I(w) = (1/pi) sum_k P_k max(0, u_k . w) (docs/HIERARCHICAL.md, "Transport through a cluster").
  return kInvPi * directional_sum(P, b, w);
}

Rgb intensity(const Moments& P, const glm::vec3& w) {
  // I(w) = (1/pi) sum_a |w_a| P[sign(w_a) a] (docs/HIERARCHICAL.md, "Transport through a cluster").
  return kInvPi * directional_sum(P, w);
}

void sending_moments(const ClusterTree& tree, const PatchHierarchy& hierarchy, const MomentBases& bases,
                     const std::vector<Rgb>& front, const std::vector<Rgb>& back, unsigned threads,
                     std::vector<Moments>& out) {
  const std::vector<Patch>& patches = hierarchy.patches();
  RADIOSITY_ASSERT(front.size() == patches.size());
  RADIOSITY_ASSERT(back.empty() || back.size() == patches.size());
  out.assign(tree.nodes().size(), Moments{});
  // Leaves: each patch's B A split by its normal, every leaf written by one index alone.
  parallel_for(threads, patches.size(), 1024, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      const std::uint32_t c = tree.leaf_of(static_cast<std::uint32_t>(p));
      if (c == kNone) continue;  // left out of the tree
      const auto patch = static_cast<std::uint32_t>(p);
      const glm::vec3& n = patches[p].normal;
      add_surface(out[c], bases.of(c), bases.front(patch, n), front[p] * patches[p].area);
      // A patch without a back side sends 0 there (and may lack the direction).
      if (!back.empty() && back[p] != Rgb(0.0f))
        add_surface(out[c], bases.of(c), bases.back(patch, n), back[p] * patches[p].area);
    }
  });
  // Inner nodes: children before parents (depth-first ids), left child then right, so every sum
  // runs in one fixed order.
  for (std::size_t i = tree.nodes().size(); i-- > 0;) {
    const ClusterNode& node = tree.node(static_cast<std::uint32_t>(i));
    if (node.is_leaf()) continue;
    for (const std::uint32_t child : node.children)
      pull_moments(out[child], bases.of(child), out[i], bases.of(static_cast<std::uint32_t>(i)));
  }
}

void add_irradiance(Moments& E, const glm::vec3& d, const Rgb& flux) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0.0f) E[2 * a] += flux * d[a];
    if (d[a] < 0.0f) E[2 * a + 1] -= flux * d[a];
  }
}

void add_irradiance(Moments& E, const MomentBasis& b, const glm::vec3& d, const Rgb& flux) {
  if (b.axes) {
    add_irradiance(E, d, flux);
    return;
  }
  for (int k = 0; k < b.count; ++k) {
    const float c = glm::dot(b.directions[static_cast<std::size_t>(k)], d);
    if (c > 0.0f) E[static_cast<std::size_t>(k)] += flux * c;
  }
}

Rgb element_irradiance(const Moments& E, const glm::vec3& n) {
  Rgb sum(0.0f);
  for (int a = 0; a < 3; ++a) sum += n[a] >= 0.0f ? n[a] * E[2 * a] : -n[a] * E[2 * a + 1];
  return sum;
}

}  // namespace radiosity::detail
