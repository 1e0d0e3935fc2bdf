// The cluster hierarchy of hierarchical radiosity (docs/HIERARCHICAL.md, issue #15): a binary
// volume hierarchy over the patches of a PatchHierarchy, node handles that put clusters and
// elements in one id space, and the six directional moments by which a cluster sends and
// receives, each cluster's in its own basis (MomentBases). Private to the library.
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991; B. Smits, J. Arvo & D. Greenberg, "A clustering algorithm for radiosity in
// complex environments", SIGGRAPH 1994; F. Sillion, "A unified hierarchical algorithm for global
// illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995; A. Willmott,
// P. Heckbert & M. Garland, "Face cluster radiosity", EGWR 1999 (the directional moments here
// replace its vector radiosity, which cancels the opposite faces of a box).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
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
  /// An empty tree.
  ClusterTree() = default;
  /// Builds the tree over the patches of `hierarchy` with `include[p] != 0`, or over every
  /// patch when `include` is empty (empty when none is taken). Patches left out have no leaf
  /// (leaf_of() is kNone) and take no part in the links: the link hierarchy leaves out patches
  /// wholly buried under a solid, which exchange no light. Reads only the patches and their
  /// root elements' corners, so it stays valid as elements are subdivided.
  explicit ClusterTree(const PatchHierarchy& hierarchy, const std::vector<std::uint8_t>& include = {});

  const std::vector<ClusterNode>& nodes() const { return nodes_; }
  const ClusterNode& node(std::uint32_t id) const { return nodes_[id]; }
  bool empty() const { return nodes_.empty(); }
  static constexpr std::uint32_t root() { return 0; }
  /// Ids of the patches in the tree, permuted so that every node's patches are contiguous.
  const std::vector<std::uint32_t>& order() const { return order_; }
  /// The leaf cluster that holds `patch`; kNone for a patch left out.
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

/// Six directional moments: what a cluster sends (power, W) or the irradiance its links bring
/// (W/m^2), one per direction of the cluster's MomentBasis (kPosX .. kNegZ on the axes).
using Moments = std::array<Rgb, 6>;
enum MomentAxis : int { kPosX = 0, kNegX = 1, kPosY = 2, kNegY = 3, kPosZ = 4, kNegZ = 5 };

/// A side's direction: its id in MomentBases (0 .. 5 are the axes in MomentAxis order) and its
/// unit normal.
struct SideDirection {
  std::uint32_t id = 0;
  glm::vec3 normal{0.0f};
};

/// The axis direction with id `a` (MomentAxis order).
inline glm::vec3 axis_direction(int a) {
  glm::vec3 u(0.0f);
  u[a / 2] = a % 2 == 0 ? 1.0f : -1.0f;
  return u;
}

/// The directions along which one cluster keeps its moments. Explicit (`axes` false): one
/// moment per distinct direction its sides face, at most six: a side of direction u_k adds to
/// moment k alone, so what the cluster sends toward w, sum_k P_k max(0, u_k . w), and what an
/// element of direction u_k receives, E_k, are exact in every orientation. On the axes: the
/// six axes, a side tilted off them split among them by add_surface() (exact only for sides
/// along the axes: a tilted side sends part of its light backwards and receives some from
/// behind). A cluster is on the axes when all its sides lie along them (the same moments,
/// exact) or when it faces more than six directions.
struct MomentBasis {
  bool axes = true;
  std::uint8_t count = 0;                   ///< explicit: directions in use
  std::array<std::uint32_t, 6> ids{};       ///< explicit: direction ids, ascending
  std::array<glm::vec3, 6> directions{};   ///< explicit: unit normals
  /// The moment that holds direction `id` exactly, or -1 (a tilted side of a cluster on the
  /// axes, or a direction none of an explicit cluster's sides faces).
  int slot(std::uint32_t id) const {
    if (axes) return id < 6 ? static_cast<int>(id) : -1;
    for (int k = 0; k < count; ++k)
      if (ids[static_cast<std::size_t>(k)] == id) return k;
    return -1;
  }
  int slots() const { return axes ? 6 : count; }
  SideDirection direction(int k) const {
    if (axes) return {static_cast<std::uint32_t>(k), axis_direction(k)};
    return {ids[static_cast<std::size_t>(k)], directions[static_cast<std::size_t>(k)]};
  }
};

/// Every cluster's MomentBasis and every patch side's direction, made bottom-up over a
/// ClusterTree (the union of the children's directions while it has at most six). Patch
/// normals along an axis (exactly +-1 in one component) take the axis ids; other normals are
/// told apart by their components quantised to 2^-12, so the patches of one polygon, and the
/// facets of one face whose normals differ by rounding, share an id (a quantised axis is the
/// axis' id). Memory: 8 bytes per patch and 4 per cluster, plus one 104-byte basis per distinct
/// direction set, at most kMaxBases (clusters beyond fall back to the axes).
/// Thread safety: immutable after construction.
class MomentBases {
 public:
  static constexpr std::size_t kMaxBases = std::size_t{1} << 16;
  /// Every cluster on the axes (what tests of the axis moments use).
  MomentBases() = default;
  /// `has_back` per patch id: 1 when the patch has a back side (direction -normal).
  MomentBases(const ClusterTree& tree, const PatchHierarchy& hierarchy, const std::vector<std::uint8_t>& has_back);

  const MomentBasis& of(std::uint32_t cluster) const {
    return cluster < of_cluster_.size() ? bases_[of_cluster_[cluster]] : bases_[0];
  }
  /// A patch's front and back directions (the back's normal is -normal).
  SideDirection front(std::uint32_t patch, const glm::vec3& normal) const {
    return {patch < front_.size() ? front_[patch] : axis_id(normal), normal};
  }
  SideDirection back(std::uint32_t patch, const glm::vec3& normal) const {
    return {patch < back_.size() ? back_[patch] : axis_id(-normal), -normal};
  }
  /// Clusters whose basis is explicit.
  std::size_t explicit_clusters() const { return explicit_clusters_; }
  std::size_t memory_bytes() const {
    return (front_.capacity() + back_.capacity() + of_cluster_.capacity()) * sizeof(std::uint32_t) +
           bases_.capacity() * sizeof(MomentBasis);
  }
  /// The axis id of a normal along an axis, else kNone.
  static std::uint32_t axis_id(const glm::vec3& n);

 private:
  std::vector<std::uint32_t> front_, back_, of_cluster_;
  std::vector<MomentBasis> bases_{MomentBasis{}};  ///< 0: the axes, for clusters of more than six
  std::size_t explicit_clusters_ = 0;
};

/// Adds a surface of normal `n` (any length, not zero) sending `power` (B A, W) to sending
/// moments on the axes: P[+a] += power max(0, n_a) / |n|_1, P[-a] += power max(0, -n_a) / |n|_1,
/// so the six parts sum to `power`.
void add_surface(Moments& P, const glm::vec3& n, const Rgb& power);

/// Adds a side of direction `s` sending `power` (B A, W; or its area, for area moments) to the
/// moments `P` of basis `b`: to its own moment, or split over the axes as above.
template <typename T>
void add_surface(std::array<T, 6>& P, const MomentBasis& b, const SideDirection& s, const T& power) {
  const int k = b.slot(s.id);
  if (k >= 0) {
    P[static_cast<std::size_t>(k)] += power;
    return;
  }
  RADIOSITY_ASSERT(b.axes);
  const glm::vec3& n = s.normal;
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  RADIOSITY_ASSERT(l1 > 0.0f);
  for (int a = 0; a < 3; ++a) {
    const float share = n[a] / l1;
    if (share > 0.0f) P[static_cast<std::size_t>(2 * a)] += power * share;
    if (share < 0.0f) P[static_cast<std::size_t>(2 * a + 1)] -= power * share;
  }
}
/// The transpose of add_surface(): what a unit of a side's power adds to moments, weighted
/// per moment by `R` (the balancing's adjoint).
template <typename T>
T surface_share(const std::array<T, 6>& R, const MomentBasis& b, const SideDirection& s) {
  const int k = b.slot(s.id);
  if (k >= 0) return R[static_cast<std::size_t>(k)];
  RADIOSITY_ASSERT(b.axes);
  const glm::vec3& n = s.normal;
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  T sum = R[0] * 0.0f;
  for (int a = 0; a < 3; ++a) sum += R[static_cast<std::size_t>(n[a] >= 0.0f ? 2 * a : 2 * a + 1)] * (std::abs(n[a]) / l1);
  return sum;
}

/// sum_a |w_a| m[sign(w_a) a] over six directional moments `m` on the axes of any quantity:
/// what they show toward the unit direction `w`.
template <typename T>
T directional_sum(const std::array<T, 6>& m, const glm::vec3& w) {
  T sum = m[0] * 0.0f;
  for (int a = 0; a < 3; ++a) sum += std::abs(w[a]) * m[w[a] >= 0.0f ? 2 * a : 2 * a + 1];
  return sum;
}
/// sum_k m_k max(0, u_k . w) over the moments of basis `b` (on the axes: the above):
/// intensity() is this over pi; the link hierarchy's projected areas are this of the area
/// moments.
template <typename T>
T directional_sum(const std::array<T, 6>& m, const MomentBasis& b, const glm::vec3& w) {
  if (b.axes) return directional_sum(m, w);
  T sum = m[0] * 0.0f;
  for (int k = 0; k < b.count; ++k)
    sum += std::max(0.0f, glm::dot(b.directions[static_cast<std::size_t>(k)], w)) * m[static_cast<std::size_t>(k)];
  return sum;
}

/// The gradient of directional_sum() with respect to the direction `w` (of one-channel
/// moments): sum_a sign(w_a) m[sign(w_a) a] e_a on the axes, sum_k m_k u_k over the moments that
/// face w otherwise. The sum is homogeneous of degree one in w, so w . gradient = the sum
/// (Euler): gradient / sum is the moments' counterpart of an element's n / (n . w).
inline glm::vec3 directional_gradient(const std::array<float, 6>& m, const MomentBasis& b, const glm::vec3& w) {
  glm::vec3 g(0.0f);
  if (b.axes) {
    for (int a = 0; a < 3; ++a)
      g[a] = w[a] >= 0.0f ? m[static_cast<std::size_t>(2 * a)] : -m[static_cast<std::size_t>(2 * a + 1)];
    return g;
  }
  for (int k = 0; k < b.count; ++k)
    if (glm::dot(b.directions[static_cast<std::size_t>(k)], w) > 0.0f)
      g += m[static_cast<std::size_t>(k)] * b.directions[static_cast<std::size_t>(k)];
  return g;
}

/// Radiant intensity (W/sr) of sending moments toward the unit direction `w`:
/// I(w) = (1/pi) sum_k P_k max(0, u_k . w). Its integral over the sphere is the sum of the six
/// moments, and it is exact for an explicit basis and for sides along the axes.
Rgb intensity(const Moments& P, const MomentBasis& b, const glm::vec3& w);
/// The same on the axes.
Rgb intensity(const Moments& P, const glm::vec3& w);

/// Sending moments of every cluster of `tree` from per-patch radiosities (indexed by patch id,
/// W/m^2): leaves from their patch (front B A, and back B A by the reversed normal), inner
/// nodes from their two children, each in its basis (`bases`). `back` is empty when no patch
/// has a back side (else one value per patch, 0 where a patch has none). Deterministic at any
/// thread count (leaves in parallel, then inner nodes in a fixed order). `out` is resized to
/// the node count. Thread safety: pure; `out` is the caller's.
void sending_moments(const ClusterTree& tree, const PatchHierarchy& hierarchy, const MomentBases& bases,
                     const std::vector<Rgb>& front, const std::vector<Rgb>& back, unsigned threads,
                     std::vector<Moments>& out);

/// Adds moments `child` (basis `cb`) to their parent's `parent` (basis `pb`): the pull up the
/// tree of sending moments or area moments, the same sums as adding the child's sides one by one.
template <typename T>
void pull_moments(const std::array<T, 6>& child, const MomentBasis& cb, std::array<T, 6>& parent, const MomentBasis& pb) {
  if (cb.axes && pb.axes) {
    for (std::size_t k = 0; k < 6; ++k) parent[k] += child[k];
    return;
  }
  const T zero = child[0] * 0.0f;
  for (int k = 0; k < cb.slots(); ++k) {
    // An axis moment of a child whose sides all lie along the axes is 0 where it has no side,
    // and an explicit parent need not have that direction.
    if (child[static_cast<std::size_t>(k)] == zero) continue;
    add_surface(parent, pb, cb.direction(k), child[static_cast<std::size_t>(k)]);
  }
}

/// Adds to irradiance moments `E` on the axes a link's irradiance `flux` (W/m^2, as received
/// by a surface facing the source) arriving from the unit direction `d` (from the receiver
/// toward the source): E[+a] += flux max(0, d_a), E[-a] += flux max(0, -d_a).
void add_irradiance(Moments& E, const glm::vec3& d, const Rgb& flux);
/// The same in basis `b`: E_k += flux max(0, u_k . d), the irradiance of a surface facing u_k.
void add_irradiance(Moments& E, const MomentBasis& b, const glm::vec3& d, const Rgb& flux);

/// Irradiance (W/m^2) that irradiance moments `E` on the axes bring to an element of unit
/// normal `n`: sum_a max(0, n_a) E[+a] + max(0, -n_a) E[-a]; exact (flux x cos) for
/// axis-aligned elements, too high for tilted ones (light from behind counts).
Rgb element_irradiance(const Moments& E, const glm::vec3& n);
/// The same in basis `b` for a side of direction `s`: its own moment when the basis has it
/// (exact), else on the axes the above; 0 for a direction an explicit basis lacks (no side of
/// the cluster faces it, so nothing asks).
template <typename T>
T element_irradiance(const std::array<T, 6>& E, const MomentBasis& b, const SideDirection& s) {
  const int k = b.slot(s.id);
  if (k >= 0) return E[static_cast<std::size_t>(k)];
  T sum = E[0] * 0.0f;
  if (!b.axes) return sum;
  const glm::vec3& n = s.normal;
  for (int a = 0; a < 3; ++a) sum += n[a] >= 0.0f ? n[a] * E[static_cast<std::size_t>(2 * a)] : -n[a] * E[static_cast<std::size_t>(2 * a + 1)];
  return sum;
}
/// The transpose of element_irradiance(): adds `weight` times its coefficients to `Q`.
template <typename T>
void add_element_weight(std::array<T, 6>& Q, const MomentBasis& b, const SideDirection& s, const T& weight) {
  const int k = b.slot(s.id);
  if (k >= 0) {
    Q[static_cast<std::size_t>(k)] += weight;
    return;
  }
  if (!b.axes) return;
  const glm::vec3& n = s.normal;
  for (int a = 0; a < 3; ++a) {
    Q[static_cast<std::size_t>(2 * a)] += weight * std::max(0.0f, n[a]);
    Q[static_cast<std::size_t>(2 * a + 1)] += weight * std::max(0.0f, -n[a]);
  }
}

/// Pushes irradiance moments `parent` (basis `pb`) down into `child`'s (basis `cb`): each of
/// the child's directions gets the parent's irradiance for it.
template <typename T>
void push_moments(const std::array<T, 6>& parent, const MomentBasis& pb, std::array<T, 6>& child, const MomentBasis& cb) {
  if (cb.axes && pb.axes) {
    for (std::size_t k = 0; k < 6; ++k) child[k] += parent[k];
    return;
  }
  for (int k = 0; k < cb.slots(); ++k)
    child[static_cast<std::size_t>(k)] += element_irradiance(parent, pb, cb.direction(k));
}
/// The transpose of push_moments(): the child's weights `Qc` added into the parent's `Qp`.
template <typename T>
void push_transpose(const std::array<T, 6>& Qc, const MomentBasis& cb, std::array<T, 6>& Qp, const MomentBasis& pb) {
  if (cb.axes && pb.axes) {
    for (std::size_t k = 0; k < 6; ++k) Qp[k] += Qc[k];
    return;
  }
  for (int k = 0; k < cb.slots(); ++k) add_element_weight(Qp, pb, cb.direction(k), Qc[static_cast<std::size_t>(k)]);
}

}  // namespace radiosity::detail
