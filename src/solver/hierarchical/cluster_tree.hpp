// The cluster hierarchy of hierarchical radiosity (docs/HIERARCHICAL.md, issue #15): a binary
// volume hierarchy over the patches of a PatchHierarchy, node handles that put clusters and
// elements in one id space, and the six directional moments by which a cluster sends and
// receives. Private to the library.
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991; B. Smits, J. Arvo & D. Greenberg, "A clustering algorithm for radiosity in
// complex environments", SIGGRAPH 1994; F. Sillion, "A unified hierarchical algorithm for global
// illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995; A. Willmott,
// P. Heckbert & M. Garland, "Face cluster radiosity", EGWR 1999 (the directional moments here
// replace its vector radiosity, which cancels the opposite faces of a box).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/assert.hpp"
#include "radiosity/common.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

// ---- Node handles -------------------------------------------------------------------------

/// A node of the link hierarchy: a cluster (ClusterTree node id with kClusterTag set) or an
/// element (PatchHierarchy element id, tag clear), so a link is two handles and a float. kNone
/// is no valid handle.
using NodeHandle = std::uint32_t;
inline constexpr NodeHandle kClusterTag = 0x80000000u;

/// Handles of cluster and element ids below 2^31 (a billion elements; the tag bit is the 32nd).
inline NodeHandle cluster_handle(std::uint32_t cluster) {
  RADIOSITY_ASSERT(cluster < kClusterTag);
  return cluster | kClusterTag;
}
inline NodeHandle element_handle(std::uint32_t element) {
  RADIOSITY_ASSERT(element < kClusterTag);
  return element;
}
inline bool is_cluster(NodeHandle h) { return (h & kClusterTag) != 0; }
/// The cluster or element id a handle names.
inline std::uint32_t handle_index(NodeHandle h) { return h & ~kClusterTag; }

// ---- The tree -----------------------------------------------------------------------------

/// A cluster: 60 bytes (bounds 24, sphere 16, area 4, patch range 8, children 8); a tree over
/// n patches has 2n - 1 of them, plus the 4-byte permutation and leaf entry per patch, so about
/// 128 bytes per patch in all.
struct ClusterNode {
  Bounds bounds;                 ///< of its patches' corner vertices
  glm::vec3 centre{0.0f};        ///< bounding sphere: centre of `bounds`
  float radius = 0.0f;           ///< bounding sphere: contains every corner of its patches
  float area = 0.0f;             ///< total area of its patches
  std::uint32_t first = 0;       ///< its patches are ClusterTree::order()[first .. first + count)
  std::uint32_t count = 0;
  std::array<std::uint32_t, 2> children{kNone, kNone};  ///< kNone for a leaf (one patch)

  bool is_leaf() const { return children[0] == kNone; }
};
static_assert(sizeof(ClusterNode) == 60, "the memory per node stated above");

/// Binary volume hierarchy over the patches of a PatchHierarchy, built once: each inner node
/// splits its patches at the median centroid along the longest axis of their centroids' bounds
/// (ties broken by patch id, so the tree is the same on every run and platform); a leaf holds
/// exactly one patch. Nodes are in depth-first order (the root is 0, a child's id exceeds its
/// parent's), so a reverse sweep visits children before parents. Build: O(n log n) time
/// (nth_element per level), recursion depth ceil(log2 n).
/// Thread safety: immutable after construction; const members may be called concurrently.
class ClusterTree {
 public:
  /// Builds the tree over every patch of `hierarchy` (empty when it has none). Reads only the
  /// patches and their root elements' corners, so it stays valid as elements are subdivided.
  explicit ClusterTree(const PatchHierarchy& hierarchy);

  const std::vector<ClusterNode>& nodes() const { return nodes_; }
  const ClusterNode& node(std::uint32_t id) const { return nodes_[id]; }
  bool empty() const { return nodes_.empty(); }
  static constexpr std::uint32_t root() { return 0; }
  /// Patch ids, permuted so that every node's patches are contiguous.
  const std::vector<std::uint32_t>& order() const { return order_; }
  /// The leaf cluster that holds `patch`.
  std::uint32_t leaf_of(std::uint32_t patch) const { return leaf_of_[patch]; }
  /// Levels below the root of the deepest leaf (0 for a single patch).
  int depth() const { return depth_; }

 private:
  std::vector<ClusterNode> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<std::uint32_t> leaf_of_;
  int depth_ = 0;
};

// ---- Directional moments (docs/HIERARCHICAL.md, "Transport through a cluster") -------------

/// Six directional moments, indexed by kPosX .. kNegZ: what a cluster sends (power, W) or the
/// irradiance its links bring (W/m^2).
using Moments = std::array<Rgb, 6>;
enum MomentAxis : int { kPosX = 0, kNegX = 1, kPosY = 2, kNegY = 3, kPosZ = 4, kNegZ = 5 };

/// Adds a surface of normal `n` (any length, not zero) sending `power` (B A, W) to sending
/// moments: P[+a] += power max(0, n_a) / |n|_1, P[-a] += power max(0, -n_a) / |n|_1, so the six
/// parts sum to `power`.
void add_surface(Moments& P, const glm::vec3& n, const Rgb& power);

/// sum_a |w_a| m[sign(w_a) a] over six directional moments `m` (kPosX .. kNegZ) of any
/// quantity: what they show toward the unit direction `w`. intensity() is this over pi; the
/// link hierarchy's projected areas are this of the area moments.
template <typename T>
T directional_sum(const std::array<T, 6>& m, const glm::vec3& w) {
  T sum = m[0] * 0.0f;
  for (int a = 0; a < 3; ++a) sum += std::abs(w[a]) * m[w[a] >= 0.0f ? 2 * a : 2 * a + 1];
  return sum;
}

/// Radiant intensity (W/sr) of sending moments toward the unit direction `w`:
/// I(w) = (1/pi) sum_a |w_a| P[sign(w_a) a]. Its integral over the sphere is the sum of the six
/// moments, and it is exact for surfaces whose normals lie along the axes.
Rgb intensity(const Moments& P, const glm::vec3& w);

/// Sending moments of every cluster of `tree` from per-patch radiosities (indexed by patch id,
/// W/m^2): leaves from their patch (front B A split by its normal, and back B A by the reversed
/// normal), inner nodes the sum of their two children. `back` is empty when no patch has a back
/// side (else one value per patch, 0 where a patch has none). Deterministic at any thread count
/// (leaves in parallel, then inner nodes in a fixed order). `out` is resized to the node count.
/// Thread safety: pure; `out` is the caller's.
void sending_moments(const ClusterTree& tree, const PatchHierarchy& hierarchy, const std::vector<Rgb>& front,
                     const std::vector<Rgb>& back, unsigned threads, std::vector<Moments>& out);

/// Adds to irradiance moments `E` a link's irradiance `flux` (W/m^2, as received by a surface
/// facing the source) arriving from the unit direction `d` (from the receiver toward the
/// source): E[+a] += flux max(0, d_a), E[-a] += flux max(0, -d_a).
void add_irradiance(Moments& E, const glm::vec3& d, const Rgb& flux);

/// Irradiance (W/m^2) that irradiance moments `E` bring to an element of unit normal `n`:
/// sum_a max(0, n_a) E[+a] + max(0, -n_a) E[-a]; exact (flux x cos) for axis-aligned elements.
Rgb element_irradiance(const Moments& E, const glm::vec3& n);

}  // namespace radiosity::detail
