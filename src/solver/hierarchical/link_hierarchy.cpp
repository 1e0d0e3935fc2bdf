// Hierarchical radiosity's links: refinement and the sweeps (link_hierarchy.hpp,
// docs/HIERARCHICAL.md).
// Based on: P. Hanrahan, D. Salzman & L. Aupperle, "A rapid hierarchical radiosity algorithm",
// SIGGRAPH 1991; B. Smits, J. Arvo & D. Greenberg, "A clustering algorithm for radiosity in
// complex environments", SIGGRAPH 1994; F. Sillion, "A unified hierarchical algorithm for global
// illumination with scattering volumes and object clusters", IEEE TVCG 1(3), 1995.
#include "solver/hierarchical/link_hierarchy.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/assert.hpp"
#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/halton.hpp"
#include "core/sampling.hpp"
#include "core/growable_array.hpp"
#include "core/memory_budget.hpp"
#include "core/parallel.hpp"
#include "core/quadrature.hpp"
#include "core/rng.hpp"
#include "core/streams.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/sampling.hpp"
#include "solver/exposure.hpp"

namespace radiosity::detail {
namespace {

/// Visibility rays per link: a pilot that decides (mixed: a penumbra, refined when the link
/// carries enough), then fresh rays that estimate (process(): why the estimate must not reuse
/// the pilot): n = (bound / threshold)^2 / 4, so that the visible fraction's standard error (at
/// most 1 / (2 sqrt(n))) times what the link may bring stays about the threshold, within
/// [kFirstRays, kMaxPureRays] after a pure pilot and [kPenumbraRays, kMaxPenumbraRays] after a
/// mixed one whose pair cannot be split. Measured on the Cornell box at epsilon 0.005 (100 mm
/// elements, which refinement may not split): the red wall's direct light -0.8 % against the
/// Gauss-Seidel reference with 4 / 12 rays (noise: a few strong links whose 4 rays all missed),
/// +0.07 % with these bounds; on the 22k city the link rays grow by 12 %.
constexpr int kFirstRays = 4;
constexpr int kPenumbraRays = 12;
constexpr int kMaxPureRays = 64;
constexpr int kMaxPenumbraRays = 256;
/// A link into a cluster casts a larger pilot when it carries more: kFirstRays x sqrt(bound /
/// threshold) rays, at most this many. A pure pilot misses a shadow over a share f of the
/// receiving members with probability (1 - f)^n, and then the link's light reaches the shadow
/// too (the Cornell box's floor in the blocks' shadows: +30 % of its small direct light at
/// 4 000 elements). Measured on the Cornell box at 16 679 elements, epsilon 0.05, seeds 1-4:
/// the floor +0.51/+0.74/+0.32/+0.41 % -> +0.39/+0.54/+0.29/+0.22 %, the other groups within
/// 0.05 % of before; the 22k city's link rays and element RMS unchanged (its links into
/// clusters carry little).
constexpr int kMaxClusterPilotRays = 16;
/// Tries per wanted ray to find a pair of points that face each other (cluster surfaces face
/// many ways); a link with no such pair in all its tries carries nothing.
constexpr int kTriesPerRay = 8;
/// A visibility ray's weight is the point-to-point kernel cos cos / d^2 of its ends (the visible
/// fraction is the kernel-weighted mean, as the link's transport is the kernel's integral: where
/// the near parts of a pair are the seen ones, the plain fraction underestimates), with d taken
/// as at least this fraction of the two nodes' radii added up (the kernel is singular where they
/// touch). Measured: the Cornell box's red wall, lit past the tall block, -0.75 % -> -0.12 % in
/// its direct light; the 22k city's walls -0.55 % -> -0.41 % against its reference.
constexpr float kWeightFloor = 0.1f;
/// Pairs per block of a refinement round: blocks are the unit of parallel work and of output
/// order, so results do not depend on the thread count.
constexpr std::size_t kBlock = 1024;
/// Links with a cluster end are taken only when the two nodes' radii add up to at most this
/// fraction of their distance (unless they carry less than kSeparationFloor x the threshold):
/// a cluster's transport is taken from its centroid, corrected by its geometry levels down
/// (refined_transport()), which holds only for nodes small for their distance. Measured on the
/// benchmark city (walls' mean radiosity against the Monte Carlo path / links at 22k): 0.3:
/// -0.74 % / 1.30 M; 0.4: -0.93 % / 0.75 M; 0.5: -0.97 % / 0.52 M (without the correction: -1.1 %
/// at 0.3, -2.4 % at 0.5).
constexpr float kSeparation = 0.4f;
constexpr float kSeparationFloor = 0.1f;
/// A link's *power share*: the power it may bring (its bound times the receiver's area) over
/// the threshold times the scene's area (about epsilon times the power all surfaces send;
/// power_share()). Group means are area integrals, so a link's error counts in a group by its
/// power, which the per-link threshold (irradiance) does not bound: in a scene of few patches
/// one link can carry a large share of a group's light; in a large scene none does, and the two
/// rules below leave it alone. Hanrahan, Salzman & Aupperle 1991's brightness-weighted ("BF")
/// oracle weighted by area, the power ("BFA") criterion of later hierarchical systems:
/// - a link with a cluster end is refined, whatever the separation, while its share exceeds
///   kLinkPowerShare: the corrected centroid transport's small relative error has one sign over
///   the many cluster links into a group;
/// - a link's estimate casts at least (share / kLinkPowerShare)^2 / 4 rays (within the bounds
///   above), so that its visibility noise in power stays about kLinkPowerShare times the unit:
///   a few strong links of the lamp into floor elements half in a block's shadow, 12 rays each,
///   moved the floor's mean by up to 2.6 % from one seed to the next.
/// Measured (worst group mean against Gauss-Seidel over element-to-element factors, epsilon
/// 0.05, seeds averaged), without the rules / at a share of 0.001 / at 0.0002 (kept):
/// - the Cornell box at 100 mm elements (248), 8 seeds: 0.60 / 0.35 / 0.35 % (the ceiling); the
///   floor on single seeds -1.5..+2.6 % without the rays rule, within 0.7 % with it;
/// - at 50 mm (about 1 000), 8 seeds: 0.70 / 0.65 / 0.29 % (0.41 % at 0.0003, 0.20 % at
///   0.0001): the smaller the elements, the smaller each cluster link's share, while their sum
///   stays, so a share that holds at 100 mm did not at 50;
/// - at 16 679 elements, 4 seeds: 0.48 / 0.33 / 0.34 %;
/// - the 22k city: links 0.94 / 0.94 / 1.00 M (1.10 M at 0.0001), link rays 11.5 / 11.5 /
///   12.8 M, element RMS against its reference 1.36 / 1.36 / 1.35 %; the 246k city at 0.0001:
///   links +1.2 %, link rays +4 %;
/// - closed rooms of reflectance 0.99 (tests/data/exported_room.obj, room_lamp_under_ceiling.obj,
///   made two-sided), balanced, the inside against Gauss-Seidel: -0.8 / -0.1 / -1.4 % and
///   -3.0 / -1.1 / -0.3 %, at up to 2.5 times the solve time (a third refinement pass, more
///   sweeps); the balancing's result moves by shares there (-3.3 % at 0.0003, +0.1 % at 0.0001).
///   Without the balancing the links' loss grows with their number (the exported room -1.1 /
///   -3.1 / -6.4 %: at reflectance 0.99 a loss of 0.06 % of a bounce).
/// kSeparation 0.3 instead gives 0.38 % on the small box, at 1.7 times the city's links.
constexpr float kLinkPowerShare = 0.0002f;
/// A partly hidden link into a cluster is refined while it may bring more than this fraction of
/// the threshold (other partly hidden links: more than the threshold). A cluster spreads what it
/// receives over its members alike, so light that only some of them see reaches the hidden ones
/// (the ground under a building) and is missing from those that see it. Measured on the 22k
/// benchmark city against its reference (bench_city --reference): walls' mean -0.84 % -> -0.55 %,
/// under_buildings 0.15 -> 0.09 W/m^2 (0 in the reference), element RMS 2.45 % -> 2.22 %, links
/// +12 %.
constexpr float kHiddenClusterFloor = 0.03f;
/// A link into a cluster with a buried part (a floor or ground under a block or a building
/// standing on it) is refined while it may bring more than this fraction of the threshold. The
/// open parts of the members cut by the contact lie at the occluder's foot, which hides much of
/// what the cluster as a whole sees, and a cluster spreads what it receives over its members
/// alike: the Cornell box's floor elements partly under a block got 10 % too much indirect light
/// (4 000 elements). A 4-ray pilot rarely sees it (the members are a small part of the
/// cluster). Measured on the 22k city against its reference (element RMS, link rays): without
/// the rule 1.48 %, 10.8 M; 1: unchanged; 0.3: 1.36 % (ground 2.35 -> 2.03 %), 11.3 M; 0.1:
/// 1.27 %, 13.5 M; 0.03: 1.24 %, 18.9 M. The 246k city's links at 0.3: 20.8 -> 22.5-24.1 s; at
/// 0.1: 31.5 s and 98 MiB more (the Cornell box's floor +0.50 -> +0.36 % there).
constexpr float kBuriedClusterFloor = 0.3f;
/// How an element pair's closed form is averaged over the receiver: at n x n Gauss-Legendre
/// points, or (`adaptive`) by the 2 x 2 Gauss rule refined by quarters where two levels differ
/// by more than kTouchingTolerance, down to kTouchingDepth (adaptive_gauss_mean()).
struct ReceiverRule {
  int n;
  bool adaptive;
};
constexpr double kTouchingTolerance = 1e-4;
constexpr int kTouchingDepth = 3;
/// The rule for an element pair whose radii add up to R at distance d: Gauss-Legendre 2 x 2
/// beyond 3 R (and where the link carries little), 3 x 3 beyond R; touching or nearly,
/// adaptive. Gauss-Legendre for pairs apart (session 42; from 1 / 2 / 4 cell midpoints beyond
/// 6 R / 3 R / R, the single point corrected for curvature): next to the source's plane the
/// factor vanishes and is concave over the receiver, which midpoints overestimate (the 1 x 2 x 3
/// box's element view factors over 0.01 within 0.22 % of the exact mode's with 4 x 4 points for
/// touching pairs, 0.51 % before; docs/HIERARCHICAL.md, "One bounce through the links at the
/// walls' feet"). Adaptive for pairs that touch (session 43): the factor has a logarithmic edge
/// there and, along a sliver of floor at a block's foot, a step where two of the block's facets
/// meet, which a fixed rule puts in the wrong place: the closed Cornell box's link view factors
/// (bench_view_factors --cornell 23) worst 0.069 against the exact mode's at 4 x 4 Gauss points,
/// 0.046 at 8 x 8, 0.036 at the midpoints of 8 x 8 cells (before session 42), 0.046 adaptive
/// (where the rest is a row's excess from cluster links, not quadrature: docs/HIERARCHICAL.md,
/// "Pairs that touch"); the 1 x 2 x 3 box's factors over 0.01 within 0.063 % adaptive.
ReceiverRule receiver_rule(float d, float R) {
  if (d >= 3.0f * R) return {2, false};
  if (d > R) return {3, false};
  return {0, true};
}
/// An element pair's closed form is integrated over the source instead of the receiver when the
/// receiver is more than this many times larger (process(), at the link).
constexpr float kReciprocalAreaRatio = 4.0f;
/// Levels below a link's nodes at which its geometry is integrated to correct the transport
/// between the nodes' centroids (refined_transport()): each level multiplies the point
/// transports by the children's pairs (at most 4 x 4 per level for elements, 2 x 2 for clusters).
/// Three levels rather than two: walls' mean on the 22k city -0.87 % -> -0.78 % against the
/// reference, at no measurable cost.
constexpr int kCorrectionLevels = 3;
/// The final gather's kernel push takes an element source as a point beyond this many of its
/// radii (point_kernel()). At 4 radii the plates of the closed-form test, 16 x 16 leaves
/// under one element quadtree each, took 5 to 16 times the leaf error of the closed form
/// (0.04 % instead of 0.008 % at epsilon 0.5); at 16, 1.3 times at epsilon 0.004 and the
/// same elsewhere.
constexpr float kFarKernel = 16.0f;
/// The kernel push gives no leaf more than this many times the irradiance the link brings the
/// receiver's most facing side by the linear push; a link that would is pushed linearly
/// (kernel_weight()).
constexpr double kKernelPeak = 4.0;
/// Leaf sides per parallel block of one link's final gather (kernel_weight()).
constexpr std::size_t kLeafBlock = 4096;
/// The final gather's visibility rays (kernel_weight(), ShadowSampler::leaf_visibility()): a
/// link that brings its receiver an irradiance E casts n = (E / (kLeafRayShare x the scene's
/// radiosity scale))^2 rays to each leaf it lights, at least 1 and at most kMaxLeafRays, from
/// max(n, kLeafRaySources) points of its source drawn by power, so that the noise of a leaf's
/// visible fraction costs it at most about half that share of the scale (a binary ray's
/// standard error is at most 1 / (2 sqrt(n))), whatever the link. The scale is the oracle's
/// (its threshold over epsilon).
///
/// Why a ray per leaf for every link: a link into a cluster has one visible fraction, and the
/// weakest links, far sources seen past other buildings, are most of the links and share their
/// fraction over leaves of which some see the source and some do not, wrong the same way on many
/// of them. On the 22k city the transport's own error on the walls went 0.46 -> 0.34 % of the
/// radiosity (the Monte Carlo rows' is 0.18 %), the element RMS 0.90 -> 0.87 %; with rays only
/// for links of at least 0.03 of the threshold, nothing gained. Why n grows as E^2: one binary
/// ray per leaf is noise where one link is much of a leaf's light; on plates with a strip
/// between them (the tests) a ray for every link took the leaf RMS at epsilon 0.5 from 3.4 % to
/// 8.5 %, and with this rule it is 1.9 %.
constexpr float kLeafRayShare = 0.005f;
constexpr int kMaxLeafRays = 64;
/// Source points a link's leaf rays leave from at least: neighbouring leaves take different
/// ones, so that one point's shadow does not fall on all of them.
constexpr int kLeafRaySources = 4;
/// Rays per element side that decide whether it is enclosed (enclosed_power_share()), cast
/// kEnclosureBatch at a time until one escapes. A side open over a fraction O of its
/// (cosine-weighted) hemisphere passes for enclosed with probability (1 - O)^32: 19 % at O =
/// 0.05, 3e-4 at O = 0.22.
constexpr std::uint32_t kEnclosureRays = 32;
constexpr std::uint32_t kEnclosureBatch = 8;
/// Rays per side that is not enclosed, for the share that meets receivers (update_scales();
/// pooled over a polygon side's leaves). Measured on a closed room with a lamp 50 cm under its
/// ceiling: 32 left the ceiling's share too noisy to use, 128 and 512 gave the same room.
constexpr std::uint32_t kReachRays = 128;
/// Sides enclosed_power_share() tests at most, drawn by the power they send.
constexpr std::size_t kEnclosureSamples = 1024;
/// The centroid rule underestimates a convex kernel at every level, by about the square of the
/// nodes' size for their distance; one level down a cluster (two children) halves the area of
/// flat parts, so the error about halves, and T3 + (T3 - T2) (Richardson's extrapolation of
/// the last two levels) removes most of what is left. Measured on the 22k city against its
/// reference: mean -0.17 % -> -0.12 %, walls -0.37 % -> -0.29 %, element RMS 1.72 % -> 1.71 %
/// (half the step: -0.15 %, walls -0.33 %).
constexpr float kExtrapolate = 1.0f;
/// Rounds of the row and column balancing of closed regions (update_scales()), and the most a
/// side's scale may raise its transport (lowering it is not bounded: a side that delivers more
/// than it sends, as coincident surfaces seen twice do, must be brought down all the way, or a
/// region of reflectance 0.99 gains energy on every sweep).
constexpr int kBalanceRounds = 8;
constexpr int kWarmBalanceRounds = 3;  ///< from the last refinement pass's scales
constexpr float kMaxBalance = 4.0f;
/// The smallest share of the sides' area that must be enclosed for the balancing to run.
constexpr double kBalanceMinShare = 0.01;
/// The share of a polygon side's area whose leaves must be enclosed for them to be balanced.
/// In an open box (the Cornell box) a deep side's 32 rays all meet surfaces by chance; balanced
/// alone, such sides raised every group by about 0.3 %.
constexpr double kBalancePolygonShare = 0.9;
/// The linear pull's factor on a link's transport (gather_sides()) stays within these bounds,
/// and is not computed for a source whose power centroid lies within this fraction of its
/// radius from its centroid (the factor would be within that fraction of 1). Measured on the
/// 22k city (one thread): the sweeps 0.45 s without the pull, 0.66 s with it everywhere, 0.61 s
/// with this floor, the Cornell box's groups unchanged (0.03: 0.55 s, groups 0.03-0.08 % lower).
constexpr float kPullLow = 0.5f, kPullHigh = 1.5f;
constexpr float kPullMinOffset = 0.01f;

float mean(const Rgb& c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

struct Pair {
  NodeHandle receiver, source;
};

struct LinkRecord {
  NodeHandle receiver, source;
  float coefficient;
};
/// Links as refinement makes them: a chunk per block of a round, in the round's order (or the
/// links a later pass keeps).
using LinkChunks = std::vector<std::vector<LinkRecord>>;
/// Node pairs to examine, in order: the segments one after the other. A round's pairs for the
/// next are its blocks' outputs, kept as they were made: copied into one array, they were held
/// twice for a moment, the largest round's pairs at the 246k city's peak.
using PairSegments = std::vector<std::vector<Pair>>;

/// One block's output of a refinement round, in the order it was made.
struct BlockOutput {
  std::vector<LinkRecord> links;
  std::vector<Pair> next;                   ///< children's pairs, and pairs waiting for a split
  std::vector<std::uint32_t> subdivide;     ///< element leaves to split before the next round
  std::size_t examined = 0, refined = 0;
  std::uint64_t rays = 0;
};

}  // namespace

struct LinkHierarchy::Impl {
  const Scene& scene;
  ClusterTree tree;        ///< over the patches not wholly buried (build_tree())
  bool tree_built = false;
  std::unique_ptr<RayScene> own_occluders;  ///< when none was shared
  const RayScene& occluders;
  std::uint64_t seed;
  unsigned threads;
  /// Bytes the refinement's link arrays may reach (LinkHierarchy::set_memory_budget()).
  std::size_t memory_budget = kDefaultMemoryBudget;
  const char* memory_budget_field = "SolveOptions::memory_budget_bytes";
  bool balancing = true;  ///< LinkHierarchy::set_balancing()
  float ray_epsilon;
  /// The final gather's visibility rays per leaf (ShadowSampler::leaf_visibility()), counted
  /// by final_gather().
  mutable std::atomic<std::uint64_t> leaf_rays{0};
  /// Per position of tree.order(): the area of the patches before it, for sampling a
  /// cluster's surface by area.
  std::vector<double> cumulative_area;
  std::vector<glm::vec3> cluster_centroid;  ///< per cluster: the area centroid of its patches
  /// Per position of tree.order(): the power (mean channel of B A, both sides) of the patches
  /// before it, from the radiosity of the current refine() pass.
  std::vector<double> cumulative_power;

  /// Per patch: 1 when it has a back side (refresh_patch_data(), at every refine()).
  std::vector<std::uint8_t> has_back;
  /// Per position of tree.order(): what sampling a point of that patch needs, in one cache
  /// line, so that a cluster's points (a contiguous range) are drawn without chasing the
  /// patch, its root element and its vertices through memory (refresh_patch_data()).
  struct SamplePatch {
    std::array<glm::vec3, 4> corners;  ///< the root element's, counter-clockwise
    glm::vec3 normal;
    std::uint8_t corner_count, has_back;
  };
  std::vector<SamplePatch> sample_patches;
  /// Per cluster: the directions its moments are kept along (refresh_patch_data()).
  MomentBases bases;
  /// Per cluster: its sides' area in its basis, as add_surface() adds power
  /// (refresh_patch_data()): what it shows toward a direction (projected_area()).
  std::vector<std::array<float, 6>> area_moments;

  // The links, by receiver: receiver index r (receiver_index()) has the links
  // [offsets[r], offsets[r + 1]) of sources[] and coefficients[].
  std::vector<std::uint64_t> offsets;
  GrowableArray<NodeHandle> sources;
  GrowableArray<float> coefficients;  ///< negative for a partly hidden link (the factor is the magnitude)
  std::uint32_t linked_elements = 0;  ///< the element count the receiver indices were made for
  bool linked = false;
  /// Per element side (2 e + 1 for its back): what its radiosity is multiplied by before the
  /// sweeps' gather, so that an enclosed side delivers the power it sends (update_scales());
  /// empty when no side is enclosed.
  std::vector<float> send_scale;
  /// Per element side: what the irradiance the links bring it is multiplied by (a closed
  /// region's rows; update_scales()); empty when no side is in one.
  std::vector<float> receive_scale;
  /// Per element side: whether update_scales() found it enclosed (0 not yet tested, 1 open, 2
  /// enclosed).
  std::vector<std::uint8_t> side_enclosure;
  /// Per element side that update_scales() found not enclosed: the share of its kReachRays rays
  /// that meet receiving surfaces (-1 not yet cast), and whether any met no surface at all.
  /// Kept across passes, as side_enclosure.
  std::vector<float> side_reach;
  std::vector<std::uint8_t> side_escapes;
  /// The linear pull's power keeping in closed regions (update_pull_means()): per source node
  /// (a cluster c at c, an element side at cluster_count() + 2 e + side), its links' mean pull
  /// gradient weighted by the power each delivers, times the share of its area the balancing
  /// treats as enclosed; empty when nothing is balanced.
  std::vector<glm::vec3> pull_mean;
  /// Per element side (2 e + 1 for its back): the share of its area that is not buried (inside
  /// a block standing on it: update_exposure()), leaves sampled once, inner elements the
  /// area-weighted mean of their children (empty until refine()). What a receiving node gathers
  /// is pushed to each part below it in proportion, so that a floor element half under a block
  /// gets nothing for its buried half.
  std::vector<float> exposure;
  bool any_buried = false;  ///< some leaf side has leaf_exposure() < 1
  /// Per cluster with a buried part: an index into open_moments, its sides' exposed area in its
  /// basis (as area_moments holds their area); kNone for a cluster wholly exposed. A cluster's
  /// exposure toward a direction is the one over the other (cluster_exposure_toward()).
  std::vector<std::uint32_t> open_index;
  std::vector<std::array<float, 6>> open_moments;

  /// Node radiosity for the oracle and the sweeps.
  /// The linear push's shares in one gather (gather_sides()): per cluster and slot of its
  /// moment basis, of its parent's irradiance (cluster_shares()); per element side (2 e + side),
  /// of its parent element's. 1 where not recorded.
  struct PushShares {
    std::vector<std::array<float, 6>> cluster;
    std::vector<float> side;
    double of_cluster(std::uint32_t c, std::size_t slot) const { return c < cluster.size() ? cluster[c][slot] : 1.0; }
    double of_side(std::size_t k) const { return k < side.size() ? side[k] : 1.0; }
  };

  struct Values {
    std::vector<Rgb> front, back;   ///< per element id (inner nodes: area-weighted means)
    std::vector<Moments> sending;   ///< per cluster
    /// Per cluster, per channel: the largest radiosity its patches send (either side), the
    /// bound of gather()'s maximum principle.
    std::vector<Rgb> cluster_max;
    /// The linear pull (gather_sides()): per cluster and per element side (empty where no
    /// element has children), the offset of its power centroid (its parts weighted by their
    /// mean-channel radiosity times open area) from its area centroid; 0 for a leaf element.
    std::vector<glm::vec3> pull_cluster, pull_front, pull_back;
    /// Refinement only (node_variation()): how far the radiosity below a node strays from the
    /// node's mean, relative to that mean (mean channel; per element side and per cluster).
    std::vector<float> variation_front, variation_back, variation_cluster;
  };

  /// Values::variation_*: for each node the largest |B(leaf) - B(node)| over the leaves below
  /// it (bounded by summing the steps down the tree), over B(node). A link from a node whose
  /// radiosity is far from uniform (a floor patch half hidden under a block) misplaces light
  /// when its receiver sees only part of it, so the oracle counts it.
  void node_variation(const PatchHierarchy& hierarchy, Values& v) const {
    const std::size_t count = hierarchy.elements().size();
    std::vector<float> front(count, 0.0f), back(v.back.empty() ? 0 : count, 0.0f);
    for (std::size_t id = count; id-- > 0;) {
      const Element& e = hierarchy.element(static_cast<std::uint32_t>(id));
      if (e.is_leaf()) continue;
      for (std::uint32_t k = 0; k < 4; ++k) {
        const std::uint32_t c = e.first_child + k;
        front[id] = std::max(front[id], std::abs(mean(v.front[c]) - mean(v.front[id])) + front[c]);
        if (!back.empty()) back[id] = std::max(back[id], std::abs(mean(v.back[c]) - mean(v.back[id])) + back[c]);
      }
    }
    const std::uint32_t C = cluster_count();
    std::vector<float> cluster(C, 0.0f), cluster_mean(C, 0.0f);
    for (std::uint32_t i = C; i-- > 0;) {
      const ClusterNode& c = tree.node(i);
      float power = 0.0f;
      for (const Rgb& m : v.sending[i]) power += mean(m);
      cluster_mean[i] = c.area > 0.0f ? power / c.area : 0.0f;
      if (c.is_leaf()) {
        const std::uint32_t p = tree.order()[c.first];
        const std::uint32_t root = hierarchy.patches()[p].root;
        cluster[i] = std::abs(mean(v.front[root]) - cluster_mean[i]) + front[root];
        if (!back.empty() && has_back[p])
          cluster[i] = std::max(cluster[i], std::abs(mean(v.back[root]) - cluster_mean[i]) + back[root]);
      } else {
        for (std::uint32_t child : c.children)
          cluster[i] = std::max(cluster[i], std::abs(cluster_mean[child] - cluster_mean[i]) + cluster[child]);
      }
    }
    auto relative = [](std::vector<float>& var, auto mean_of) {
      for (std::size_t k = 0; k < var.size(); ++k) {
        const float m = mean_of(k);
        var[k] = m > 0.0f ? var[k] / m : 0.0f;
      }
    };
    relative(front, [&](std::size_t k) { return mean(v.front[k]); });
    if (!back.empty()) relative(back, [&](std::size_t k) { return mean(v.back[k]); });
    relative(cluster, [&](std::size_t k) { return cluster_mean[k]; });
    v.variation_front = std::move(front);
    v.variation_back = std::move(back);
    v.variation_cluster = std::move(cluster);
  }

  Impl(const Scene& s, std::uint64_t seed_, unsigned threads_, const RayScene* shared)
      : scene(s),
        own_occluders(shared ? nullptr : std::make_unique<RayScene>(RayScene::from_polygons(s))),
        occluders(shared ? *shared : *own_occluders),
        seed(seed_),
        threads(threads_),
        ray_epsilon(1e-5f * std::max(s.bounds().diagonal(), 1e-6f)) {}

  /// The cluster tree, once (at the first refresh_patch_data(), which has set has_back), over
  /// the patches not wholly buried. A patch wholly under a solid (the ground under a building,
  /// once the mesher has cut it at the walls' feet) exchanges no light: in the tree it only
  /// diluted the clusters it shared with open patches, whose pushes then multiplied a mostly
  /// buried cluster's estimate by its exposure ratio (a sliver of ground beside a wall, in a
  /// leaf cluster with the buried piece of its triangle, took 2.5 times its indirect light;
  /// docs/HIERARCHICAL.md, "Buried parts"), and links into such clusters are refined further
  /// (kBuriedClusterFloor). So the exposure is measured first, and the tree leaves those out:
  /// they get no links and receive nothing, as their exposure 0 says.
  void build_tree(const PatchHierarchy& hierarchy) {
    measure_leaf_exposure(hierarchy);
    const std::vector<Patch>& patches = hierarchy.patches();
    std::vector<std::uint8_t> include(patches.size(), 1);
    for (std::size_t p = 0; p < patches.size(); ++p) {
      const std::uint32_t root = patches[p].root;
      include[p] = element_exposure(root, false) != 0.0f || (has_back[p] && element_exposure(root, true) != 0.0f);
    }
    tree = ClusterTree(hierarchy, include);
    tree_built = true;
    const std::vector<std::uint32_t>& order = tree.order();
    cumulative_area.resize(order.size() + 1, 0.0);
    for (std::size_t k = 0; k < order.size(); ++k)
      cumulative_area[k + 1] = cumulative_area[k] + hierarchy.patches()[order[k]].area;
    // Centroids bottom-up (children have larger ids), area-weighted in double.
    std::vector<glm::dvec3> moment(tree.nodes().size(), glm::dvec3(0.0));
    std::vector<double> area(tree.nodes().size(), 0.0);
    for (std::size_t i = tree.nodes().size(); i-- > 0;) {
      const ClusterNode& c = tree.node(static_cast<std::uint32_t>(i));
      if (c.is_leaf()) {
        const Patch& p = hierarchy.patches()[order[c.first]];
        area[i] = p.area;
        moment[i] = static_cast<double>(p.area) * glm::dvec3(p.centroid);
      } else {
        area[i] = area[c.children[0]] + area[c.children[1]];
        moment[i] = moment[c.children[0]] + moment[c.children[1]];
      }
    }
    cluster_centroid.resize(tree.nodes().size());
    for (std::size_t i = 0; i < tree.nodes().size(); ++i)
      cluster_centroid[i] = area[i] > 0.0 ? glm::vec3(moment[i] / area[i]) : tree.node(static_cast<std::uint32_t>(i)).centre;
  }

  std::uint32_t cluster_count() const { return static_cast<std::uint32_t>(tree.nodes().size()); }

  /// Dense receiver index: clusters, then element fronts, then element backs.
  std::uint64_t receiver_index(NodeHandle h, std::uint32_t elements) const {
    if (is_cluster(h)) return handle_index(h);
    return std::uint64_t{cluster_count()} + (is_back(h) ? elements : 0u) + element_of(h);
  }
  NodeHandle receiver_handle(std::uint64_t index, std::uint32_t elements) const {
    if (index < cluster_count()) return cluster_handle(static_cast<std::uint32_t>(index));
    index -= cluster_count();
    return index < elements ? side_handle(static_cast<std::uint32_t>(index), false)
                            : side_handle(static_cast<std::uint32_t>(index - elements), true);
  }

  /// What only refinement's shadow rays read (sample()), rebuilt by every refine(): released
  /// after it, so that the sweeps' gathers, where the peak memory is, do not hold it (72 MB at
  /// a million patches).
  void release_sampling() {
    std::vector<SamplePatch>().swap(sample_patches);
    std::vector<double>().swap(cumulative_power);
  }
  /// What sample() reads, from the patches (after refresh_patch_data()) and the power their
  /// radiosity `v` sends: built by every refine() and by the final gather, released after each.
  void prepare_sampling(const PatchHierarchy& hierarchy, const Values& v) {
    const std::vector<std::uint32_t>& order = tree.order();
    sample_patches.resize(order.size());
    cumulative_power.assign(order.size() + 1, 0.0);
    for (std::size_t k = 0; k < order.size(); ++k) {
      const Patch& patch = hierarchy.patches()[order[k]];
      const Element& root = hierarchy.element(patch.root);
      SamplePatch& sp = sample_patches[k];
      sp.corner_count = static_cast<std::uint8_t>(root.corner_count());
      for (int c = 0; c < 4; ++c) sp.corners[static_cast<std::size_t>(c)] = hierarchy.vertices()[root.corners[std::min(c, root.corner_count() - 1)]];
      sp.normal = patch.normal;
      sp.has_back = has_back[order[k]];
      double power = mean(v.front[patch.root]);
      if (!v.back.empty()) power += mean(v.back[patch.root]);
      cumulative_power[k + 1] = cumulative_power[k] + power * patch.area;
    }
  }

  void refresh_patch_data(const PatchHierarchy& hierarchy, const RadiositySystem& sys) {
    has_back.assign(hierarchy.patches().size(), 0);
    for (std::size_t u = sys.fronts(); u < sys.unknowns(); ++u) has_back[hierarchy.element(sys.element(u)).patch] = 1;
    const bool first = !tree_built;
    if (first) build_tree(hierarchy);
    bases = MomentBases(tree, hierarchy, has_back);
    const std::uint32_t C = cluster_count();
    area_moments.assign(C, std::array<float, 6>{});
    for (std::uint32_t i = C; i-- > 0;) {
      const ClusterNode& c = tree.node(i);
      std::array<float, 6>& m = area_moments[i];
      if (!c.is_leaf()) {
        for (const std::uint32_t child : c.children) pull_moments(area_moments[child], bases.of(child), m, bases.of(i));
        continue;
      }
      const std::uint32_t p = tree.order()[c.first];
      const Patch& patch = hierarchy.patches()[p];
      add_surface(m, bases.of(i), bases.front(p, patch.normal), patch.area);
      if (has_back[p]) add_surface(m, bases.of(i), bases.back(p, patch.normal), patch.area);
    }
    // The exposure measured with the tree: the first pass pushes by it too.
    if (first) update_open_moments(hierarchy);
  }

  /// The area a node shows toward the unit direction `v`: sum over its sides of
  /// A max(0, n . v) (exact for axis-aligned sides of a cluster, as the moments are).
  float projected_area(const PatchHierarchy& h, NodeHandle n, const glm::vec3& v) const {
    if (!is_cluster(n)) return h.element(element_of(n)).area * std::max(0.0f, glm::dot(side_normal(h, n), v));
    return directional_sum(area_moments[handle_index(n)], bases.of(handle_index(n)), v);
  }

  /// The unoccluded transport (pi x power, for B = 1 on every side) from `s` to `r` taken
  /// between their centroids, as a link takes it: geometry only, so that refined_transport()
  /// can judge the link's geometry whatever the radiosity.
  float point_transport(const PatchHierarchy& h, NodeHandle r, NodeHandle s) const {
    const glm::vec3 d = centroid(h, r) - centroid(h, s);
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0.0f)) return 0.0f;
    const glm::vec3 w = d / std::sqrt(d2);
    return projected_area(h, s, w) * projected_area(h, r, -w) / d2;
  }

  /// The descendants of a node some levels down, as point_transport() needs them: where each
  /// is and the area it shows toward a unit direction v, max(0, sum_a |v_a| (v_a > 0 ? pos_a :
  /// neg_a)). A cluster's pos / neg are its area moments on +a / -a (the sum is then
  /// directional_sum()); an element side's are A n_a and -A n_a (the sum is then A n . v).
  /// Stored by component, so that refined_transport()'s loop over pairs is vectorised.
  struct TransportEnds {
    /// 4^3, an element's third level; a cluster's third level is at most 8 clusters of up to
    /// 6 ends (an explicit basis) or 16 elements.
    static constexpr std::size_t kMax = 64;
    alignas(16) std::array<float, kMax> x, y, z, pos_x, pos_y, pos_z, neg_x, neg_y, neg_z;
    std::size_t count = 0;
    void add(const glm::vec3& at, const glm::vec3& pos, const glm::vec3& neg) {
      RADIOSITY_ASSERT(count < kMax);
      x[count] = at.x, y[count] = at.y, z[count] = at.z;
      pos_x[count] = pos.x, pos_y[count] = pos.y, pos_z[count] = pos.z;
      neg_x[count] = neg.x, neg_y[count] = neg.y, neg_z[count] = neg.z;
      ++count;
    }
  };
  /// Appends the descendants of `n` `levels` down to `out` (a node without children stands for
  /// itself), and with `upper` those `levels` - 1 down to it: one walk for both, each in the
  /// order of its own walk.
  void transport_ends(const PatchHierarchy& h, NodeHandle n, int levels, TransportEnds& out,
                      TransportEnds* upper = nullptr) const {
    std::array<NodeHandle, 4> kids{};
    const int k = levels > 0 ? children(h, n, kids) : 0;
    if (k == 0) {
      add_transport_end(h, n, out);
      if (upper) add_transport_end(h, n, *upper);
      return;
    }
    if (upper && levels == 1) {
      add_transport_end(h, n, *upper);
      upper = nullptr;
    }
    for (int i = 0; i < k; ++i) transport_ends(h, kids[static_cast<std::size_t>(i)], levels - 1, out, upper);
  }
  /// Appends node `n` itself to `out`.
  void add_transport_end(const PatchHierarchy& h, NodeHandle n, TransportEnds& out) const {
    if (!is_cluster(n)) {
      const Element& e = h.element(element_of(n));
      const glm::vec3 an = e.area * side_normal(h, n);
      out.add(e.centroid, an, -an);
      return;
    }
    const std::uint32_t c = handle_index(n);
    const std::array<float, 6>& m = area_moments[c];
    const MomentBasis& b = bases.of(c);
    if (b.axes) {
      out.add(cluster_centroid[c], glm::vec3(m[0], m[2], m[4]), glm::vec3(m[1], m[3], m[5]));
      return;
    }
    // An explicit basis: one end per direction, as an element of that normal and area at the
    // centroid (the pairs' products then sum to the product of the sums).
    for (int j = 0; j < b.count; ++j) {
      const glm::vec3 an = m[static_cast<std::size_t>(j)] * b.directions[static_cast<std::size_t>(j)];
      out.add(cluster_centroid[c], an, -an);
    }
  }

  /// point_transport() summed over the pairs of the nodes' descendants `levels` down (a node
  /// without children stands for itself): a quadrature of the link's geometry. The kernel
  /// cos cos / r^2 is convex over nodes that are large for their distance (a wall seeing the
  /// ground near grazing), so the centroids' value alone underestimates it: by 1.1 % of the
  /// power in a room with a window (measured against ray-cast rows), by 0.3 % corrected. Each
  /// side's descendants are gathered once and then paired in a vectorised loop: a recursion
  /// over the pairs, looking each one up again for every partner, took 12 % of the 246k
  /// city's run.
  /// With `coarser`, also the same `levels` - 1 down, from the same walks.
  float refined_transport(const PatchHierarchy& h, NodeHandle r, NodeHandle s, int levels,
                          float* coarser = nullptr) const {
    TransportEnds re, se, re_upper, se_upper;
    transport_ends(h, r, levels, re, coarser ? &re_upper : nullptr);
    transport_ends(h, s, levels, se, coarser ? &se_upper : nullptr);
    if (coarser) *coarser = transport_sum(re_upper, se_upper);
    return transport_sum(re, se);
  }
  /// point_transport() summed over the pairs of `re` and `se`.
  static float transport_sum(const TransportEnds& re, const TransportEnds& se) {
    // Per source end, summed over the receiver ends; the sources' sums are added at the end
    // (a fixed order, so the result does not depend on the vector width).
    alignas(16) std::array<float, TransportEnds::kMax> acc{};
    const std::size_t ns = se.count;
    for (std::size_t i = 0; i < re.count; ++i) {
      const float rx = re.x[i], ry = re.y[i], rz = re.z[i];
      const float rpx = re.pos_x[i], rpy = re.pos_y[i], rpz = re.pos_z[i];
      const float rnx = re.neg_x[i], rny = re.neg_y[i], rnz = re.neg_z[i];
      for (std::size_t j = 0; j < ns; ++j) {
        const float dx = rx - se.x[j], dy = ry - se.y[j], dz = rz - se.z[j];
        const float d2 = dx * dx + dy * dy + dz * dz;
        // Coincident centroids (d2 = 0) give w = 0 and so no term, as point_transport() does.
        const float safe = d2 > 0.0f ? d2 : 1.0f;
        const float inv = 1.0f / std::sqrt(safe);
        const float wx = dx * inv, wy = dy * inv, wz = dz * inv;
        // The source shows toward w, the receiver toward -w: |w_a| (w_a > 0 ? pos_a : neg_a)
        // written without selects, so that the loop has no branches.
        const float px = wx > 0.0f ? wx : 0.0f, py = wy > 0.0f ? wy : 0.0f, pz = wz > 0.0f ? wz : 0.0f;
        const float mx = px - wx, my = py - wy, mz = pz - wz;  // max(-w_a, 0)
        const float shown = px * se.pos_x[j] + mx * se.neg_x[j] + py * se.pos_y[j] + my * se.neg_y[j] +
                            pz * se.pos_z[j] + mz * se.neg_z[j];
        const float seen = px * rnx + mx * rpx + py * rny + my * rpy + pz * rnz + mz * rpz;
        const float s_pos = shown > 0.0f ? shown : 0.0f, r_pos = seen > 0.0f ? seen : 0.0f;
        acc[j] += s_pos * r_pos / safe;
      }
    }
    float sum = 0.0f;
    for (std::size_t j = 0; j < ns; ++j) sum += acc[j];
    return sum;
  }

  /// Element values from side values per unknown, then the clusters' sending moments.
  void node_values(const PatchHierarchy& hierarchy, const RadiositySystem& sys, const std::vector<Rgb>& B,
                   Values& v, bool with_max = false) const {
    const std::size_t count = hierarchy.elements().size();
    v.front.assign(count, Rgb(0.0f));
    v.back.assign(sys.has_backs() ? count : 0, Rgb(0.0f));
    for (std::size_t u = 0; u < sys.unknowns(); ++u) (u < sys.fronts() ? v.front : v.back)[sys.element(u)] = B[u];
    leaf_values(hierarchy, v, with_max);
  }
  /// The rest of node_values() from the leaves' values already in v.front and v.back: the
  /// leaves' values are their open parts' (side_exposures()) and each inner element takes its
  /// children's mean weighted by their open area: the links' factors see a source's buried part
  /// as hidden, so a source sends its open part's radiosity. The balancing's unit values are
  /// aggregated the same way (update_scales(); its adjoint transposes this).
  /// With `with_max`, also Values::cluster_max (only gather()'s hold reads it: 12 bytes a
  /// cluster not held through the sweeps otherwise).
  void leaf_values(const PatchHierarchy& hierarchy, Values& v, bool with_max = false) const {
    if (any_buried) {
      aggregate_open(hierarchy, v.front, [&](std::uint32_t e) { return leaf_exposure(e, false); });
      if (!v.back.empty()) aggregate_open(hierarchy, v.back, [&](std::uint32_t e) { return leaf_exposure(e, true); });
    } else {
      hierarchy.aggregate(v.front);
      if (!v.back.empty()) hierarchy.aggregate(v.back);
    }
    const std::vector<Patch>& patches = hierarchy.patches();
    std::vector<Rgb> patch_front(patches.size()), patch_back(v.back.empty() ? 0 : patches.size());
    for (std::size_t p = 0; p < patches.size(); ++p) {
      patch_front[p] = v.front[patches[p].root];
      if (!v.back.empty()) patch_back[p] = v.back[patches[p].root];
    }
    sending_moments(tree, hierarchy, bases, patch_front, patch_back, threads, v.sending);
    pull_offsets(hierarchy, v);
    if (!with_max) {
      std::vector<Rgb>().swap(v.cluster_max);
      return;
    }
    v.cluster_max.assign(tree.nodes().size(), Rgb(0.0f));
    for (std::uint32_t c = cluster_count(); c-- > 0;) {  // children after parents
      const ClusterNode& node = tree.node(c);
      if (!node.is_leaf()) {
        v.cluster_max[c] = glm::max(v.cluster_max[node.children[0]], v.cluster_max[node.children[1]]);
        continue;
      }
      const std::uint32_t p = tree.order()[node.first];
      v.cluster_max[c] = v.back.empty() ? patch_front[p] : glm::max(patch_front[p], patch_back[p]);
    }
  }

  /// Values::pull_*: each node's power centroid's offset from its area centroid, from the
  /// leaves up (children have larger ids than their parents, in both trees).
  void pull_offsets(const PatchHierarchy& h, Values& v) const {
    const std::size_t count = h.elements().size();
    const bool inner = h.leaves().size() < count;
    auto side_offsets = [&](const std::vector<Rgb>& value, bool back, std::vector<glm::vec3>& offset) {
      offset.assign(inner && !value.empty() ? count : 0, glm::vec3(0.0f));
      if (offset.empty()) return;
      for (std::size_t e = count; e-- > 0;) {
        const Element& el = h.element(static_cast<std::uint32_t>(e));
        if (el.is_leaf()) continue;
        float power = 0.0f;
        glm::vec3 moment(0.0f);
        for (std::uint32_t k = 0; k < 4; ++k) {
          const std::uint32_t c = el.first_child + k;
          const Element& child = h.element(c);
          const float p = std::max(0.0f, mean(value[c])) * child.area * element_exposure(c, back);
          power += p;
          moment += p * (child.centroid + offset[c] - el.centroid);
        }
        if (power > 0.0f) offset[e] = moment / power;
      }
    };
    side_offsets(v.front, false, v.pull_front);
    side_offsets(v.back, true, v.pull_back);
    const std::uint32_t C = cluster_count();
    v.pull_cluster.assign(C, glm::vec3(0.0f));
    std::vector<float> power(C, 0.0f);
    for (std::uint32_t c = C; c-- > 0;) {
      const ClusterNode& node = tree.node(c);
      if (node.is_leaf()) {
        // A one-patch cluster: its patch's root element, both sides by their power.
        const std::uint32_t p = tree.order()[node.first];
        const Patch& patch = h.patches()[p];
        const float front = std::max(0.0f, mean(v.front[patch.root])) * element_exposure(patch.root, false);
        const float back =
            v.back.empty() || !has_back[p] ? 0.0f : std::max(0.0f, mean(v.back[patch.root])) * element_exposure(patch.root, true);
        power[c] = (front + back) * patch.area;
        glm::vec3 offset(0.0f);
        if (!v.pull_front.empty() && front + back > 0.0f)
          offset = (front * v.pull_front[patch.root] + (back > 0.0f ? back * v.pull_back[patch.root] : glm::vec3(0.0f))) /
                   (front + back);
        v.pull_cluster[c] = offset + h.element(patch.root).centroid - cluster_centroid[c];
        continue;
      }
      glm::vec3 moment(0.0f);
      for (const std::uint32_t child : node.children) {
        power[c] += power[child];
        moment += power[child] * (cluster_centroid[child] + v.pull_cluster[child] - cluster_centroid[c]);
      }
      if (power[c] > 0.0f) v.pull_cluster[c] = moment / power[c];
    }
  }
  const glm::vec3& pull_offset(const Values& v, NodeHandle n) const {
    static const glm::vec3 zero(0.0f);
    if (is_cluster(n)) return v.pull_cluster[handle_index(n)];
    const std::vector<glm::vec3>& side = is_back(n) ? v.pull_back : v.pull_front;
    return side.empty() ? zero : side[element_of(n)];
  }

  // ---- Node geometry ------------------------------------------------------------------------

  static float element_radius(const PatchHierarchy& h, std::uint32_t e) {
    const Element& el = h.element(e);
    float r = 0.0f;
    for (int k = 0; k < el.corner_count(); ++k) r = std::max(r, glm::length(h.vertices()[el.corners[k]] - el.centroid));
    return r;
  }
  /// Where a node's transport is taken from and to: its area centroid (a cluster's bounding
  /// sphere is centred on its box, which can lie far from where its surfaces are).
  glm::vec3 centroid(const PatchHierarchy& h, NodeHandle n) const {
    return is_cluster(n) ? cluster_centroid[handle_index(n)] : h.element(element_of(n)).centroid;
  }
  /// The centre of a node's bounding sphere (the oracle's bounds).
  glm::vec3 centre(const PatchHierarchy& h, NodeHandle n) const {
    return is_cluster(n) ? tree.node(handle_index(n)).centre : h.element(element_of(n)).centroid;
  }
  /// A node's area (a cluster's: its patches', each counted once).
  float area(const PatchHierarchy& h, NodeHandle n) const {
    return is_cluster(n) ? tree.node(handle_index(n)).area : h.element(element_of(n)).area;
  }
  float radius(const PatchHierarchy& h, NodeHandle n) const {
    return is_cluster(n) ? tree.node(handle_index(n)).radius : element_radius(h, element_of(n));
  }
  static glm::vec3 side_normal(const PatchHierarchy& h, NodeHandle n) {
    const glm::vec3& normal = h.normal(element_of(n));
    return is_back(n) ? -normal : normal;
  }
  /// Largest of dot(n, x - p) over the points x of node `h`.
  float support(const PatchHierarchy& hierarchy, NodeHandle h, const glm::vec3& n, const glm::vec3& p) const {
    if (is_cluster(h)) {
      const Bounds& b = tree.node(handle_index(h)).bounds;
      const glm::vec3 mid = 0.5f * (b.lower + b.upper), half = 0.5f * (b.upper - b.lower);
      return glm::dot(n, mid - p) + std::abs(n.x) * half.x + std::abs(n.y) * half.y + std::abs(n.z) * half.z;
    }
    const Element& e = hierarchy.element(element_of(h));
    float s = -std::numeric_limits<float>::infinity();
    for (int k = 0; k < e.corner_count(); ++k) s = std::max(s, glm::dot(n, hierarchy.vertices()[e.corners[k]] - p));
    return s;
  }

  /// Radiant intensity (W/sr) of node `h` toward the unit direction `w`.
  Rgb source_intensity(const PatchHierarchy& hierarchy, const Values& v, NodeHandle h, const glm::vec3& w) const {
    if (is_cluster(h)) return intensity(v.sending[handle_index(h)], bases.of(handle_index(h)), w);
    const std::uint32_t e = element_of(h);
    const float cosine = std::max(0.0f, glm::dot(side_normal(hierarchy, h), w));
    const Rgb& B = (is_back(h) ? v.back : v.front)[e];
    return B * (hierarchy.element(e).area * cosine * kInvPi);
  }
  /// The most node `h`'s intensity (W/sr, mean channel) can be toward any unit direction w'
  /// with |w' - w| <= `turn`: its intensity toward w plus what turning can add. An element
  /// side's cosine grows by at most `turn`; a cluster's directional sum by at most `turn` times
  /// the length of its moments' largest per axis (sum_a |w'_a - w_a| max(P+a, P-a), bounded by
  /// Cauchy-Schwarz), or with an explicit basis `turn` times their sum.
  float intensity_bound(const PatchHierarchy& hierarchy, const Values& v, NodeHandle h, const glm::vec3& w,
                        float turn) const {
    if (!is_cluster(h)) {
      const std::uint32_t e = element_of(h);
      const float cosine = std::min(1.0f, std::max(0.0f, glm::dot(side_normal(hierarchy, h), w)) + turn);
      return mean((is_back(h) ? v.back : v.front)[e]) * (hierarchy.element(e).area * cosine * kInvPi);
    }
    const std::uint32_t c = handle_index(h);
    const Moments& P = v.sending[c];
    const MomentBasis& b = bases.of(c);
    float spread = 0.0f;
    if (b.axes) {
      for (int a = 0; a < 3; ++a) {
        const float largest = mean(glm::max(P[static_cast<std::size_t>(2 * a)], P[static_cast<std::size_t>(2 * a + 1)]));
        spread += largest * largest;
      }
      spread = std::sqrt(spread);
    } else {
      for (int k = 0; k < b.count; ++k) spread += mean(P[static_cast<std::size_t>(k)]);
    }
    return mean(intensity(P, b, w)) + turn * kInvPi * spread;
  }
  /// The children of a node in the link hierarchy: a cluster's two, a one-patch cluster's root
  /// element (both sides when the patch has a back), an element's four (same side). Returns
  /// the count (0 for a leaf element).
  int children(const PatchHierarchy& hierarchy, NodeHandle h, std::array<NodeHandle, 4>& out) const {
    if (is_cluster(h)) {
      const ClusterNode& c = tree.node(handle_index(h));
      if (!c.is_leaf()) {
        out[0] = cluster_handle(c.children[0]);
        out[1] = cluster_handle(c.children[1]);
        return 2;
      }
      const std::uint32_t p = tree.order()[c.first];
      const std::uint32_t root = hierarchy.patches()[p].root;
      out[0] = side_handle(root, false);
      if (!has_back[p]) return 1;
      out[1] = side_handle(root, true);
      return 2;
    }
    const Element& e = hierarchy.element(element_of(h));
    if (e.is_leaf()) return 0;
    for (std::uint32_t k = 0; k < 4; ++k) out[k] = side_handle(e.first_child + k, is_back(h));
    return 4;
  }

  bool is_leaf_cluster(NodeHandle h) const { return is_cluster(h) && tree.node(handle_index(h)).is_leaf(); }
  /// Whether a receiver has parts below it to push its light to: an element with children, an
  /// inner cluster, or a one-patch cluster whose root element has children.
  bool node_has_children(const PatchHierarchy& hierarchy, NodeHandle h) const {
    if (!is_cluster(h)) return !hierarchy.element(element_of(h)).is_leaf();
    const ClusterNode& node = tree.node(handle_index(h));
    return !node.is_leaf() || !hierarchy.element(hierarchy.patches()[tree.order()[node.first]].root).is_leaf();
  }

  // ---- Visibility ---------------------------------------------------------------------------

  /// A point of an element for (u, v) in [0,1)^2: the bilinear map of a quad, the folded
  /// barycentric map of a triangle. Not area-uniform on a non-parallelogram quad (the
  /// estimators' CellSampler is, at several times the cost): visibility rays only need points
  /// spread over the element.
  static glm::vec3 polygon_point(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
                                 int count, glm::vec2 uv) {
    if (count == 3) {
      if (uv.x + uv.y > 1.0f) uv = glm::vec2(1.0f) - uv;
      return a + uv.x * (b - a) + uv.y * (c - a);
    }
    const glm::vec3 ab = a + uv.x * (b - a), dc = d + uv.x * (c - d);
    return ab + uv.y * (dc - ab);
  }
  static glm::vec3 element_point(const PatchHierarchy& h, std::uint32_t element, glm::vec2 uv) {
    const Element& e = h.element(element);
    const std::vector<glm::vec3>& v = h.vertices();
    const int count = e.corner_count();
    return polygon_point(v[e.corners[0]], v[e.corners[1]], v[e.corners[2]], v[e.corners[count == 3 ? 2 : 3]], count, uv);
  }

  /// A point of node `h`, area-uniform, with the normal of the side it lies on (a cluster's
  /// patch with a back takes the side facing `toward`; with toward == point, the front).
  void sample(const PatchHierarchy& hierarchy, NodeHandle h, bool by_power, Rng& rng, glm::vec3& point,
              glm::vec3& normal, bool& two_sided) const {
    if (!is_cluster(h)) {
      point = element_point(hierarchy, element_of(h), rng.uniform2());
      normal = side_normal(hierarchy, h);
      two_sided = false;
      return;
    }
    const ClusterNode& c = tree.node(handle_index(h));
    // A source's points by the power its patches send (dark patches, such as ground hidden
    // under a building, send nothing and must not count in its visibility), a receiver's by
    // area; by area too where the cluster sends nothing yet.
    const std::vector<double>* cumulative = &cumulative_area;
    if (by_power && cumulative_power[c.first + c.count] > cumulative_power[c.first]) cumulative = &cumulative_power;
    const double lo = (*cumulative)[c.first], hi = (*cumulative)[c.first + c.count];
    const double target = lo + static_cast<double>(rng.uniform()) * (hi - lo);
    // The last patch k of the cluster with cumulative[k] <= target: a binary search without
    // branches (the compiler's conditional moves), since the targets are random and a
    // branching search mispredicts at every step.
    const double* base = cumulative->data() + c.first;
    for (std::uint32_t n = c.count; n > 1;) {
      const std::uint32_t half = n / 2;
      base = base[half] <= target ? base + half : base;
      n -= half;
    }
    const SamplePatch& sp = sample_patches[static_cast<std::size_t>(base - cumulative->data())];
    point = polygon_point(sp.corners[0], sp.corners[1], sp.corners[2], sp.corners[3], sp.corner_count, rng.uniform2());
    normal = sp.normal;
    two_sided = sp.has_back != 0;
  }

  /// A leaf element side below a receiving node, as the kernel push sees it.
  struct LeafSide {
    glm::vec3 centroid, normal;
    float area;
    std::uint32_t element;
    bool back;
  };

  /// Shadow rays between facing points of two nodes, drawn from the link's own stream: its
  /// visibility rays (`stream` hierarchical_link) or the final gather's
  /// (hierarchical_leaf_visibility, leaf_visibility()).
  class ShadowSampler {
   public:
    ShadowSampler(const Impl& m, const PatchHierarchy& h, NodeHandle r, NodeHandle s,
                  Stream stream = Stream::hierarchical_link)
        : m_(m),
          h_(h),
          r_(r),
          s_(s),
          rng_(m.seed, (std::uint64_t{r} << 32) | s, stream_key(stream)),
          receiver_centre_(m.centre(h, r)),
          receiver_radius_(m.radius(h, r)) {
      const float floor = kWeightFloor * (receiver_radius_ + m.radius(h, s));
      weight_floor2_ = floor * floor;
    }
    /// Casts up to `wanted` rays (as many facing pairs as `wanted` x kTriesPerRay tries find):
    /// how many were cast and clear, and their kernel weights.
    struct Result {
      int clear = 0, cast = 0;
      double weight_clear = 0.0, weight = 0.0;  ///< the rays' kernel weights: all, and the clear ones'
      /// The visible fraction, each ray weighted by the point-to-point kernel of its ends.
      float visible() const {
        return weight > 0.0 ? static_cast<float>(weight_clear / weight)
                            : static_cast<float>(clear) / static_cast<float>(std::max(cast, 1));
      }
    };
    /// Draws the source's points by area from now on (by the power its patches send until then).
    void source_by_area() { source_by_power_ = false; }
    Result draw(int wanted, std::uint64_t& rays) {
      Batch& b = batch();
      for (int tries = 0; tries < kTriesPerRay * wanted && static_cast<int>(b.origin.size()) < wanted; ++tries) {
        glm::vec3 x, nx, y, ny;
        bool two_x, two_y;
        m_.sample(h_, s_, source_by_power_, rng_, x, nx, two_x);
        // A one-sided source point facing away from the receiver's whole bounding sphere has
        // no partner there: the try ends before the receiver point is drawn.
        if (!two_x && !(glm::dot(nx, receiver_centre_ - x) + receiver_radius_ > 0.0f)) continue;
        m_.sample(h_, r_, false, rng_, y, ny, two_y);
        add_ray(b, x, nx, two_x, y, ny, two_y);
      }
      cast(b, rays);
      Result out;
      out.cast = static_cast<int>(b.origin.size());
      for (std::size_t k = 0; k < b.blocked.size(); ++k) {
        out.weight += b.weight[k];
        if (b.blocked[k] != 0) continue;
        ++out.clear;
        out.weight_clear += b.weight[k];
      }
      return out;
    }
    /// Points of the source for the final gather's visibility rays (leaf_visibility()).
    struct SourcePoints {
      std::array<glm::vec3, kMaxLeafRays> point, normal;
      std::array<bool, kMaxLeafRays> two_sided{};
      int count = 0;
      int rays_per_leaf = 1;
    };
    /// Up to max(rays_per_leaf, kLeafRaySources) points of the source, drawn by power, that may
    /// face the receiver.
    SourcePoints source_points(int rays_per_leaf) {
      SourcePoints out;
      out.rays_per_leaf = rays_per_leaf;
      const int wanted = std::max(rays_per_leaf, kLeafRaySources);
      RADIOSITY_ASSERT(wanted <= kMaxLeafRays);
      for (int tries = 0; tries < kTriesPerRay * wanted && out.count < wanted; ++tries) {
        const auto k = static_cast<std::size_t>(out.count);
        m_.sample(h_, s_, true, rng_, out.point[k], out.normal[k], out.two_sided[k]);
        if (out.two_sided[k] || glm::dot(out.normal[k], receiver_centre_ - out.point[k]) + receiver_radius_ > 0.0f)
          ++out.count;
      }
      return out;
    }
    /// The final gather's visibility per leaf side (kernel_weight()): for each side k in
    /// [begin, end) of `leaves` (below the receiver) with lit[k] > 0, points.rays_per_leaf rays
    /// to its centroid from the source's `points` (the first that face it from the k-th on);
    /// lit[k] is scaled by the fraction of them that is clear (kept where no point faces it).
    /// A few points shared by all the leaves rather than drawn per leaf: the rays leave from the
    /// same few origins, so Embree's packets stay coherent, and no cluster is searched per
    /// leaf. Each side's rays depend on k alone, not on the range.
    void leaf_visibility(const SourcePoints& points, const std::vector<LeafSide>& leaves, std::vector<Rgb>& lit,
                         std::size_t begin, std::size_t end) const {
      if (points.count == 0) return;
      Batch& b = batch();
      thread_local std::vector<std::uint32_t> leaf_of_ray;
      leaf_of_ray.clear();
      for (std::size_t k = begin; k < end; ++k) {
        if (!(mean(lit[k]) > 0.0f)) continue;
        const auto first = static_cast<int>(k % static_cast<std::size_t>(points.count));
        for (int j = 0, added = 0; j < points.count && added < points.rays_per_leaf; ++j) {
          const auto p = static_cast<std::size_t>((first + j) % points.count);
          if (!add_ray(b, points.point[p], points.normal[p], points.two_sided[p], leaves[k].centroid, leaves[k].normal,
                       false))
            continue;
          leaf_of_ray.push_back(static_cast<std::uint32_t>(k));
          ++added;
        }
      }
      std::uint64_t rays = 0;
      cast(b, rays);
      m_.leaf_rays.fetch_add(rays, std::memory_order_relaxed);
      // Rays per leaf, clear and cast: leaf_of_ray holds each leaf's rays together.
      for (std::size_t first = 0; first < leaf_of_ray.size();) {
        std::size_t last = first;
        int clear = 0;
        for (; last < leaf_of_ray.size() && leaf_of_ray[last] == leaf_of_ray[first]; ++last) clear += b.blocked[last] == 0;
        lit[leaf_of_ray[first]] *= static_cast<float>(clear) / static_cast<float>(last - first);
        first = last;
      }
    }

   private:
    /// One thread's rays before they are cast (reused: a link casts a few dozen).
    struct Batch {
      std::vector<glm::vec3> origin, direction;
      std::vector<float> weight;
      std::vector<std::uint8_t> blocked;
    };
    static Batch& batch() {
      thread_local Batch b;
      b.origin.clear();
      b.direction.clear();
      b.weight.clear();
      b.blocked.clear();
      return b;
    }
    /// Adds the ray between x (normal nx) and y (normal ny) to `b` when the two face each
    /// other (a two-sided point's normal turned toward the other end first), with its kernel
    /// weight: whether it was added.
    bool add_ray(Batch& b, const glm::vec3& x, glm::vec3 nx, bool two_x, const glm::vec3& y, glm::vec3 ny,
                 bool two_y) const {
      const glm::vec3 d = y - x;
      if (two_x && glm::dot(nx, d) < 0.0f) nx = -nx;
      if (two_y && glm::dot(ny, d) > 0.0f) ny = -ny;
      if (!(glm::dot(nx, d) > 0.0f) || !(glm::dot(ny, d) < 0.0f)) return false;
      const glm::vec3 o = x + m_.ray_epsilon * nx;
      b.origin.push_back(o);
      b.direction.push_back((y + m_.ray_epsilon * ny) - o);
      const float d2 = glm::dot(d, d);
      b.weight.push_back(glm::dot(nx, d) * -glm::dot(ny, d) / (d2 * std::max(d2, weight_floor2_)));
      return true;
    }
    /// Casts `b`'s rays, filling b.blocked. As coherent packets: a link's rays join two nodes,
    /// a bundle. The same answers as one ray at a time; the 246k city's links 17.7 s ->
    /// 16.6-17.2 s (Embree's traversal is a quarter of their time; drawing the points is most
    /// of the rest).
    void cast(Batch& b, std::uint64_t& rays) const {
      b.blocked.resize(b.origin.size());
      m_.occluders.occluded(b.origin.size(), b.origin.data(), b.direction.data(), 0.0f, 1.0f - 1e-4f, b.blocked.data());
      rays += b.origin.size();
    }

    const Impl& m_;
    const PatchHierarchy& h_;
    NodeHandle r_, s_;
    Rng rng_;
    glm::vec3 receiver_centre_;
    float receiver_radius_;
    float weight_floor2_ = 0.0f;  ///< the kernel's distance squared is taken as at least this
    bool source_by_power_ = true;
  };

  /// An element's corners (the fourth unused for a triangle): the polygon the closed forms take.
  static std::array<glm::vec3, 4> corner_points(const PatchHierarchy& h, const Element& e) {
    std::array<glm::vec3, 4> out{};
    for (int k = 0; k < e.corner_count(); ++k) out[static_cast<std::size_t>(k)] = h.vertices()[e.corners[k]];
    return out;
  }
  /// Element-to-element factor: the point-to-polygon closed form (Lambert's contour integral,
  /// point_to_polygon_factor_fast()) from receiver points to the source element, 0 at points
  /// behind the source's side, averaged over the receiver by `rule` (receiver_rule(): n x n
  /// Gauss-Legendre points, polygon_gauss_mean() in core/quadrature.hpp, or adaptive for pairs
  /// that touch). Until session 42 the points were always the
  /// midpoints of n x n cells (twice as many per side), and one point with a curvature
  /// correction where the link carried little or the pair was far apart; next to the source's
  /// plane, where the factor vanishes and is concave over the receiver, both overestimated
  /// (a ground square at a wall's foot, from the wall's second row of squares: 4 x 4 midpoints
  /// +1.24 %, the corrected centroid +6.7 %; Gauss-Legendre 3 x 3 within 0.01 %).
  static float element_factor(const PatchHierarchy& h, NodeHandle r, NodeHandle s, ReceiverRule rule) {
    const std::uint32_t re = element_of(r);
    const Element& es = h.element(element_of(s));
    const glm::vec3 ns = side_normal(h, s), nr = side_normal(h, r);
    const std::array<glm::vec3, 4> polygon = corner_points(h, es);
    auto at = [&](const glm::vec3& x) {
      if (!(glm::dot(ns, x - es.centroid) > 0.0f)) return 0.0f;
      return point_to_polygon_factor_fast(x, nr, polygon.data(), es.corner_count());
    };
    const Element& er = h.element(re);
    const std::array<glm::vec3, 4> receiver = corner_points(h, er);
    if (rule.adaptive) {
      const CellMap map(receiver.data(), er.corner_count());
      auto g = [&](glm::vec2 st) -> double { return map.density(st) * at(map.point(st)); };
      const double coarse = 0.25 * (g(glm::vec2(kGaussLo, kGaussLo)) + g(glm::vec2(kGaussHi, kGaussLo)) +
                                    g(glm::vec2(kGaussLo, kGaussHi)) + g(glm::vec2(kGaussHi, kGaussHi)));
      return static_cast<float>(
          adaptive_gauss_mean(g, glm::vec2(0.0f), 1.0f, coarse, 0, kTouchingDepth, kTouchingTolerance));
    }
    const int n = rule.n;
    // A receiver that straddles the source's plane has a kink there (0 behind it), which no
    // Gauss rule integrates well: its front part alone (a convex polygon of up to 5 corners) is
    // integrated, triangle by triangle of a fan, over the whole receiver's area.
    const float scale = std::max(1e-6f, element_radius(h, re));
    std::array<float, 4> side{};
    bool behind = false;
    for (int k = 0; k < er.corner_count(); ++k) {
      side[static_cast<std::size_t>(k)] = glm::dot(ns, receiver[static_cast<std::size_t>(k)] - es.centroid);
      behind |= side[static_cast<std::size_t>(k)] < -1e-5f * scale;
    }
    if (!behind) return polygon_gauss_mean(receiver.data(), er.corner_count(), n, at);
    std::array<glm::vec3, 5> front{};
    int count = 0;
    for (int k = 0; k < er.corner_count(); ++k) {
      const int next = (k + 1) % er.corner_count();
      const float a = side[static_cast<std::size_t>(k)], b = side[static_cast<std::size_t>(next)];
      const glm::vec3 &p = receiver[static_cast<std::size_t>(k)], &q = receiver[static_cast<std::size_t>(next)];
      if (a >= 0.0f) front[static_cast<std::size_t>(count++)] = p;
      if ((a >= 0.0f) != (b >= 0.0f)) front[static_cast<std::size_t>(count++)] = p + (a / (a - b)) * (q - p);
    }
    if (count < 3 || !(er.area > 0.0f)) return 0.0f;
    double sum = 0.0;
    for (int k = 1; k + 1 < count; ++k) {
      const std::array<glm::vec3, 3> t{front[0], front[static_cast<std::size_t>(k)],
                                       front[static_cast<std::size_t>(k + 1)]};
      const float area = 0.5f * glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
      sum += static_cast<double>(area) * polygon_gauss_mean(t.data(), 3, n, at);
    }
    return static_cast<float>(sum / er.area);
  }

  // ---- Refinement ---------------------------------------------------------------------------

  struct RoundContext {
    const PatchHierarchy& hierarchy;
    const Values& values;
    float threshold;
    const SubdivisionLimits& limits;
    bool subdivision_closed;
  };

  bool can_split(const RoundContext& rc, NodeHandle h) const {
    if (is_cluster(h)) return true;
    const Element& e = rc.hierarchy.element(element_of(h));
    if (!e.is_leaf()) return true;
    return !rc.subdivision_closed && e.depth < rc.limits.max_depth && e.area > 0.0f;
  }

  /// The oracle's two estimates for link (r <- s), irradiance at the receiver (mean channel,
  /// W/m^2): `bound`, what the link may bring (the source's intensity toward r's centre over
  /// the nearest distance squared), and `spread`, how much that varies over the pair (between the
  /// nearest and the farthest distance): the error of taking the transport as uniform over the
  /// nodes. Both infinite when the nodes' spheres overlap. Irradiance rather than the
  /// radiosity it makes (Hanrahan et al.'s rho B F): lightmaps store irradiance, which a black
  /// receiver has too.
  /// The spread takes the source's largest intensity toward any point of the pair
  /// (intensity_bound(), the direction turned by up to the nodes' reach over their distance),
  /// not its intensity toward the centre: seen near grazing, a source shows the centre of a
  /// receiver far less than its nearer parts. A lamp set in a ceiling shows the top of a wall
  /// beside it almost nothing toward the wall cluster's centre, and the link was kept at a level
  /// where its transport came out 10 % low (the Cornell box with its blocks raised 50 mm, the
  /// lamp's direct light on the green wall's upper third, 4 000 elements: -12 %, the wall's mean
  /// -2 %, at epsilon 0.005; now within 0.2 %). Only the spread: the same in `bound` (which
  /// sets the rays, the separation rule and the penumbra refinement) made 18 % more links on the
  /// 22k city for about the same accuracy, this 6 % (docs/HIERARCHICAL.md, "The oracle near
  /// grazing").
  struct LinkError {
    float bound, spread;
  };
  LinkError link_error(const RoundContext& rc, NodeHandle r, NodeHandle s) const {
    constexpr float infinite = std::numeric_limits<float>::infinity();
    const glm::vec3 cr = centre(rc.hierarchy, r), cs = centre(rc.hierarchy, s);
    const float d = glm::length(cr - cs);
    const float reach = radius(rc.hierarchy, r) + radius(rc.hierarchy, s);
    const float gap = d - reach;
    if (!(gap > 0.0f)) return {infinite, infinite};
    const glm::vec3 w = (cr - cs) / d;
    const float transport = mean(source_intensity(rc.hierarchy, rc.values, s, w));
    const float widest = intensity_bound(rc.hierarchy, rc.values, s, w, std::min(1.0f, reach / d));
    const float far = d + reach;
    const float bound = transport / (gap * gap);
    const Values& v = rc.values;
    const float variation = is_cluster(s) ? v.variation_cluster[handle_index(s)]
                            : is_back(s)  ? v.variation_back[element_of(s)]
                                          : v.variation_front[element_of(s)];
    return {bound, widest * (1.0f / (gap * gap) - 1.0f / (far * far)) + bound * variation};
  }

  /// A link's power share (kLinkPowerShare): the power it may bring over the threshold times
  /// the scene's area.
  float power_share(const RoundContext& rc, NodeHandle r, const LinkError& error) const {
    return error.bound * area(rc.hierarchy, r) / (rc.threshold * tree.node(ClusterTree::root()).area);
  }

  /// How far the rule for receivers with a buried part lowers its floor for receiver `r`
  /// (kBuriedClusterFloor x the threshold, times this): infinite for a receiver with nothing
  /// buried (the rule does not apply) or everything (it receives nothing), 1 for a cluster
  /// whose exposure is kMinExposure or more (its least per direction), and below that, for
  /// clusters and inner elements, the exposure over kMinExposure. What a link brings to a
  /// receiver with exposure x is pushed to its open parts times 1 / x, and its estimate, from
  /// rays at points over the whole receiver, is noisy by about the light of one ray's point in
  /// a share x of them: a link into a cluster of ground mostly under a building, beside a
  /// sliver left open, gave the sliver 4 times the irradiance of the open sky (an exported
  /// block with its buildings turned, benchmarks/exported_block.py --turn: 402 W/m^2 under a
  /// sky of 100, Gauss-Seidel 62). Down to receivers mostly open or wholly buried, the push
  /// cannot amplify the noise much (docs/HIERARCHICAL.md, "Buried parts").
  float buried_scale(const PatchHierarchy& h, NodeHandle r) const {
    constexpr float kNotBuried = std::numeric_limits<float>::infinity();
    float x = 1.0f;
    if (is_cluster(r)) {
      if (wholly_exposed(handle_index(r))) return kNotBuried;
      x = least_cluster_exposure(handle_index(r));
      if (x >= kMinExposure) return 1.0f;
    } else {
      if (h.element(element_of(r)).is_leaf()) return kNotBuried;
      x = element_exposure(element_of(r), is_back(r));
      if (x >= kMinExposure) return kNotBuried;
    }
    return x > 0.0f ? x / kMinExposure : kNotBuried;
  }

  /// The oracle (docs/HIERARCHICAL.md, "Refinement (the oracle)"): refine a link when its
  /// transport varies over its nodes by more than the threshold; when it has a cluster end
  /// and its nodes are large for their distance (a cluster's transport is taken from its
  /// centre, accurate only when the nodes are small for their distance, as in Barnes & Hut's
  /// multipole acceptance), unless it carries little, or may bring a share of the scene's
  /// power (kLinkPowerShare); when it is partly hidden (a shadow
  /// boundary somewhere in its nodes) and may bring more than the threshold (kHiddenClusterFloor
  /// x the threshold into a cluster). A fully visible or fully hidden link is never refined for
  /// visibility.
  bool needs_refinement(const RoundContext& rc, NodeHandle r, NodeHandle s, bool partly_hidden) const {
    return needs_refinement(rc, r, s, link_error(rc, r, s), partly_hidden);
  }
  bool needs_refinement(const RoundContext& rc, NodeHandle r, NodeHandle s, const LinkError& error,
                        bool partly_hidden) const {
    if (error.spread > rc.threshold) return true;
    if (partly_hidden && error.bound > (is_cluster(r) ? kHiddenClusterFloor : 1.0f) * rc.threshold) return true;
    if (error.bound > kBuriedClusterFloor * rc.threshold * buried_scale(rc.hierarchy, r)) return true;
    if (!is_cluster(r) && !is_cluster(s)) return false;
    if (power_share(rc, r, error) > kLinkPowerShare) return true;
    const float reach = radius(rc.hierarchy, r) + radius(rc.hierarchy, s);
    return reach > kSeparation * glm::length(centre(rc.hierarchy, r) - centre(rc.hierarchy, s)) &&
           error.bound > kSeparationFloor * rc.threshold;
  }

  /// The axis-aligned box of a node: a cluster's bounds, an element's corners.
  Bounds node_bounds(const PatchHierarchy& h, NodeHandle n) const {
    if (is_cluster(n)) return tree.node(handle_index(n)).bounds;
    const Element& e = h.element(element_of(n));
    Bounds b{h.vertices()[e.corners[0]], h.vertices()[e.corners[0]]};
    for (int k = 1; k < e.corner_count(); ++k) {
      b.lower = glm::min(b.lower, h.vertices()[e.corners[k]]);
      b.upper = glm::max(b.upper, h.vertices()[e.corners[k]]);
    }
    return b;
  }
  /// False when no side of cluster `c` faces any point of the box `to`. A side of normal n at
  /// x faces y when n . (y - x) > 0, which needs an axis a along which n and y - x have the same
  /// sign: n's share on +a (or -a) is in the cluster's area moments, and y - x can be positive
  /// along a only if the box reaches above the cluster's lowest a (with an explicit basis, the
  /// largest u . (y - x) per direction u). A necessary condition, so never a wrong refusal; it
  /// drops a roof cluster seen from the ground below in one step.
  bool cluster_faces(std::uint32_t c, const Bounds& to, float tolerance) const {
    const std::array<float, 6>& m = area_moments[c];
    const Bounds& from = tree.node(c).bounds;
    const MomentBasis& b = bases.of(c);
    if (!b.axes) {
      // Each direction u it has area along: the largest u . (y - x) over the two boxes.
      for (int k = 0; k < b.count; ++k) {
        if (!(m[static_cast<std::size_t>(k)] > 0.0f)) continue;
        const glm::vec3& u = b.directions[static_cast<std::size_t>(k)];
        float reach = 0.0f;
        for (int a = 0; a < 3; ++a) reach += u[a] >= 0.0f ? u[a] * (to.upper[a] - from.lower[a]) : u[a] * (to.lower[a] - from.upper[a]);
        if (reach > tolerance) return true;
      }
      return false;
    }
    for (int a = 0; a < 3; ++a) {
      if (m[static_cast<std::size_t>(2 * a)] > 0.0f && to.upper[a] > from.lower[a] + tolerance) return true;
      if (m[static_cast<std::size_t>(2 * a + 1)] > 0.0f && to.lower[a] < from.upper[a] - tolerance) return true;
    }
    return false;
  }

  /// True when nothing can pass between the two nodes: one is an element side wholly in front
  /// of which the other does not reach, or a cluster none of whose sides faces the other's
  /// box (cluster_faces()), or both are elements of one patch.
  bool cannot_exchange(const PatchHierarchy& h, NodeHandle r, NodeHandle s, float scale) const {
    const float tolerance = 1e-5f * scale;
    if (!is_cluster(r) && !is_cluster(s) && h.element(element_of(r)).patch == h.element(element_of(s)).patch)
      return true;
    if (!is_cluster(s) && support(h, r, side_normal(h, s), h.element(element_of(s)).centroid) <= tolerance)
      return true;
    if (!is_cluster(r) && support(h, s, side_normal(h, r), h.element(element_of(r)).centroid) <= tolerance)
      return true;
    if (is_cluster(s) && !cluster_faces(handle_index(s), node_bounds(h, r), tolerance)) return true;
    if (is_cluster(r) && !cluster_faces(handle_index(r), node_bounds(h, s), tolerance)) return true;
    return false;
  }

  void process(const RoundContext& rc, const Pair& pair, BlockOutput& out) const {
    const PatchHierarchy& h = rc.hierarchy;
    const NodeHandle r = pair.receiver, s = pair.source;
    std::array<NodeHandle, 4> kids{};
    ++out.examined;
    if (r == s) {
      // A cluster's light to itself: between its children, each to itself too; a single patch
      // (planar) sends nothing to itself.
      if (is_leaf_cluster(r)) return;
      const int n = children(h, r, kids);
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) out.next.push_back({kids[static_cast<std::size_t>(a)], kids[static_cast<std::size_t>(b)]});
      ++out.refined;
      return;
    }
    // A one-patch cluster stands for its patch's element(s): links to clusters are for groups.
    for (const NodeHandle leaf : {r, s}) {
      if (!is_leaf_cluster(leaf)) continue;
      const int n = children(h, leaf, kids);
      for (int k = 0; k < n; ++k)
        out.next.push_back(leaf == r ? Pair{kids[static_cast<std::size_t>(k)], s} : Pair{r, kids[static_cast<std::size_t>(k)]});
      return;
    }
    const float rr = radius(h, r), rs = radius(h, s);
    if (cannot_exchange(h, r, s, rr + rs)) return;

    const bool split_r = can_split(rc, r), split_s = can_split(rc, s);
    // Splits the larger node (by radius) that can be split; false when neither can.
    auto refine = [&] {
      if (!split_r && !split_s) return false;
      const NodeHandle split = split_r && (!split_s || rr >= rs) ? r : s;
      const int n = children(h, split, kids);
      if (n == 0) {
        // An element leaf that may be subdivided: split it, then look at this pair again.
        out.subdivide.push_back(element_of(split));
        out.next.push_back(pair);
        return true;
      }
      for (int k = 0; k < n; ++k)
        out.next.push_back(split == r ? Pair{kids[static_cast<std::size_t>(k)], s} : Pair{r, kids[static_cast<std::size_t>(k)]});
      ++out.refined;
      return true;
    };
    const LinkError error = link_error(rc, r, s);
    if (needs_refinement(rc, r, s, error, false) && refine()) return;

    // Link. Element pairs take the closed form (averaged over the receiver when close), the
    // rest the point-to-point transport between the nodes' centroids, corrected below.
    const float d = glm::length(centroid(h, r) - centroid(h, s));
    float coefficient = 0.0f;
    if (!is_cluster(r) && !is_cluster(s)) {
      // Receiver points by how close the pair is for its size (the closed form's variation
      // over the receiver), the fewest where the link carries little. A receiver much larger than its
      // source takes the source's points and reciprocity (A_r F_rs = A_s F_sr): its own points
      // miss where a small source beside it shows (a wall's 64 points gave it 1/17 of its
      // factor to a sliver of ground at its foot, and the view factors, the mean of both
      // directions, half the sliver's factor to the wall; session 40). Between elements of
      // about one size each direction keeps its own points: the two directions' quadratures
      // then differ, and the view factors' mean of them is closer to the exact factors (the
      // 1 x 2 x 3 box's factors over 0.01 within 0.51 %, 1.1 % with the smaller's points, at
      // the midpoint grids of session 40).
      const ReceiverRule rule =
          error.bound < kSeparationFloor * rc.threshold ? ReceiverRule{2, false} : receiver_rule(d, rr + rs);
      const float ar = area(h, r), as = area(h, s);
      coefficient =
          ar > kReciprocalAreaRatio * as ? element_factor(h, s, r, rule) * (as / ar) : element_factor(h, r, s, rule);
    } else {
      coefficient = d > 0.0f ? 1.0f / (d * d) : 0.0f;
      // Corrected by the link's geometry integrated further down (refined_transport()); the
      // clamp keeps a grazing pair, whose centroids see each other edge-on, from an outlier.
      const float coarse = point_transport(h, r, s);
      if (!(coarse > 0.0f)) {
        // Between the centroids the nodes show each other nothing (no member of a roof
        // cluster faces down toward the ground), and gather() takes the same directional
        // moments: a link here would carry nothing, so no rays are spent on it. Where members
        // further down do face each other (clusters of mixed orientation seen near grazing:
        // refined_transport() > 0) the pair is refined instead, so their light is not lost.
        // Measured on the 246k-facet city: 4.5 M such pairs reached this point; 4.1 M of them
        // spent a whole pilot's tries (32 point pairs) finding no facing pair, 0.2 M had
        // transport further down.
        if (refined_transport(h, r, s, kCorrectionLevels) > 0.0f) refine();
        return;
      }
      // Extrapolated from the last two levels (kExtrapolate).
      float coarser = 0.0f;
      const float fine = refined_transport(h, r, s, kCorrectionLevels, &coarser);
      const float extrapolated = fine + kExtrapolate * (fine - coarser);
      coefficient *= std::clamp(extrapolated / coarse, 0.25f, 4.0f);
    }
    if (!(coefficient > 0.0f)) return;
    // Visibility: a pilot pass decides, fresh rays estimate. A partly hidden pilot (a shadow
    // boundary somewhere in the nodes) refines the link while it may bring more than the
    // threshold, and a kept one gets the larger second pass; a fully visible or fully hidden
    // pilot is never refined for visibility. The estimate comes from rays drawn after the
    // decision, so it is unbiased: deciding and estimating with the same rays would favour the
    // extremes (a pilot all clear or all blocked happens with probability V^n or (1 - V)^n).
    ShadowSampler shadows(*this, h, r, s);
    // Into a cluster, a pilot that misses a shadow over part of its members spreads the link's
    // light over them alike (kMaxClusterPilotRays).
    const int pilot_rays =
        is_cluster(r) ? static_cast<int>(std::clamp(kFirstRays * std::sqrt(error.bound / rc.threshold), float{kFirstRays},
                                                    float{kMaxClusterPilotRays}))
                      : kFirstRays;
    ShadowSampler::Result pilot = shadows.draw(pilot_rays, out.rays);
    if (pilot.cast == 0 && is_cluster(s)) {
      // A cluster's points are drawn by the power its patches send now. When none of those can
      // face the receiver, its other patches still may, and send later: a reflector is dark in
      // the first pass, and a pair dropped here is never looked at again (multigridding
      // revisits links, not dropped pairs). So the pair is judged by its geometry, the points
      // drawn by area. Measured on two parallel 1 m plates 5 cm apart, reflectance 0.9, one
      // emitting: against Gauss-Seidel the plates were 15 % dark, every cluster holding parts
      // of both having lost its link to the emitter's plate; now 1.7 %.
      shadows.source_by_area();
      pilot = shadows.draw(pilot_rays, out.rays);
    }
    if (pilot.cast == 0) return;  // no facing pair found: nothing passes
    const bool partly_hidden = pilot.clear > 0 && pilot.clear < pilot.cast;
    // The estimate's rays: as many as make the visible fraction's standard error (at most
    // 1 / (2 sqrt(n))) times what the link may bring about the threshold, and times its power
    // about kLinkPowerShare of the unit, within bounds: a pure pilot's link has no shadow
    // boundary in sight, a mixed one that cannot be split has.
    const float ratio = std::max(error.bound / rc.threshold, power_share(rc, r, error) / kLinkPowerShare);
    const float wanted = 0.25f * ratio * ratio;
    int rays = static_cast<int>(std::clamp(wanted, static_cast<float>(kFirstRays), static_cast<float>(kMaxPureRays)));
    if (partly_hidden) {
      if (needs_refinement(rc, r, s, error, true) && refine()) return;
      rays = static_cast<int>(std::clamp(wanted, static_cast<float>(kPenumbraRays), static_cast<float>(kMaxPenumbraRays)));
    }
    const ShadowSampler::Result estimate = shadows.draw(rays, out.rays);
    // No ray cast (the pilot found facing pairs, these draws none) or none clear: a zero link.
    if (estimate.cast == 0 || estimate.clear == 0) {
      // Kept as a zero link until the next pass looks at it (refine()): dropped, it could not be
      // refined there, while the pairs whose few rays did see through are, and refinement
      // replaces their estimates (on average above V, since they are the ones that saw
      // through) by their children's unbiased ones. So light went missing wherever a pass
      // refines links that the first judged weak: every link from a reflector, whose radiosity
      // is 0 in the first pass. Measured on the Cornell box, 4 000 elements, epsilon 0.05: the
      // groups 0.3-0.5 % darker; with the blocks black and raised, the ceiling 1.05 % low
      // instead of 0.54 % (docs/HIERARCHICAL.md, "Zero links").
      out.links.push_back({r, s, partly_hidden ? -0.0f : 0.0f});
      return;
    }
    const float v = estimate.visible();
    // The sign records a partly hidden link, for the next pass's look at it.
    out.links.push_back({r, s, partly_hidden ? -coefficient * v : coefficient * v});
  }

  /// Runs refinement rounds from `frontier` until it is empty; each round's links become
  /// chunks of `chunks`, one per block. False when `gate` cancels.
  bool run_rounds(PatchHierarchy& hierarchy, Values& values, PairSegments frontier, float threshold,
                  const SubdivisionLimits& limits, ProgressGate& gate, LinkChunks& chunks,
                  std::vector<std::uint32_t>& split, RefineStats& stats, bool merge_each_round) {
    bool subdivision_closed = limits.max_depth == 0;
    std::size_t done = 0, rounds = 0;
    double reported = 0.0;  // the largest fraction reported
    std::vector<BlockOutput> blocks;
    struct Block {
      std::size_t segment, first, last;  ///< frontier[segment][first, last)
    };
    std::vector<Block> work;
    const std::size_t workers = static_cast<std::size_t>(thread_count(threads));
    BlockSizer slices(workers, workers, std::numeric_limits<std::size_t>::max());
    auto pairs_in = [](const PairSegments& segments) {
      std::size_t count = 0;
      for (const std::vector<Pair>& segment : segments) count += segment.size();
      return count;
    };
    for (std::size_t pairs = pairs_in(frontier); pairs > 0; pairs = pairs_in(frontier)) {
      ++rounds;
      const RoundContext rc{hierarchy, values, threshold, limits, subdivision_closed};
      // Blocks of at most kBlock pairs, none across segments: each pair's output depends on the
      // pair alone, and the outputs are taken in block order, so the blocks' bounds change
      // nothing.
      work.clear();
      for (std::size_t g = 0; g < frontier.size(); ++g)
        for (std::size_t first = 0; first < frontier[g].size(); first += kBlock)
          work.push_back({g, first, std::min(frontier[g].size(), first + kBlock)});
      const std::size_t block_count = work.size();
      blocks.assign(block_count, BlockOutput{});
      // A round can hold millions of pairs: its blocks go in slices of about 15 ms with a
      // progress report between them, so a cancel is seen within a round too (refine() then
      // drops the pass's new links, as after a cancel between rounds); each block's output
      // does not depend on the slices.
      std::size_t pairs_done = 0;
      for (std::size_t slice = 0, slice_end = 0; slice < block_count; slice = slice_end) {
        slice_end = std::min(block_count, slice + slices.size());
        parallel_for(threads, slice_end - slice, 1, [&](std::size_t begin, std::size_t end) {
          for (std::size_t b = slice + begin; b < slice + end; ++b) {
            const Block& block = work[b];
            for (std::size_t k = block.first; k < block.last; ++k) process(rc, frontier[block.segment][k], blocks[b]);
            // Kept as the next round's segment and a chunk of links: without the slack their
            // doubling growth left.
            blocks[b].next.shrink_to_fit();
            blocks[b].links.shrink_to_fit();
          }
        });
        slices.done(slice_end - slice);
        for (std::size_t b = slice; b < slice_end; ++b) pairs_done += work[b].last - work[b].first;
        if (slice_end == block_count) break;
        // The pairs of the rounds to come are not known yet, so this estimate can fall when a
        // round turns out larger than the last; reported, it only goes forward.
        Progress p;
        p.phase = Phase::form_factors;
        reported = std::max(reported, static_cast<double>(done + pairs_done) / static_cast<double>(done + pairs));
        p.fraction = reported;
        if (!gate.report(p, false)) return false;
      }
      done += pairs;
      frontier = {};  // read; its memory goes before the next round's is held
      std::size_t link_count = 0, next_count = 0;
      for (const BlockOutput& b : blocks) {
        link_count += b.links.size();
        next_count += b.next.size();
      }
      stats.links_added += link_count;
      // The links so far and the round's pairs, before merging makes the link arrays grow:
      // refuse here, with the figure, if they pass the budget.
      {
        std::size_t held = 0, links_held = link_count;
        for (const std::vector<LinkRecord>& c : chunks) {
          held += c.capacity() * sizeof(LinkRecord);
          links_held += c.size();
        }
        for (const BlockOutput& b : blocks)
          held += b.links.capacity() * sizeof(LinkRecord) + b.next.capacity() * sizeof(Pair);
        if (static_cast<double>(held) > static_cast<double>(memory_budget))
          refuse_memory("hierarchical radiosity's link refinement (" + std::to_string(links_held) + " links and " +
                            std::to_string(next_count) + " node pairs to examine after round " +
                            std::to_string(rounds) + ")",
                        static_cast<double>(held), memory_budget, memory_budget_field,
                        "; raise HierarchicalOptions::epsilon, coarsen the mesh or raise the budget");
      }
      std::vector<std::uint32_t> subdivide;
      for (BlockOutput& b : blocks) {
        if (!b.links.empty()) chunks.push_back(std::move(b.links));
        if (!b.next.empty()) frontier.push_back(std::move(b.next));
        subdivide.insert(subdivide.end(), b.subdivide.begin(), b.subdivide.end());
        stats.examined += b.examined;
        stats.refined += b.refined;
        stats.rays += b.rays;
        b = BlockOutput{};
      }
      blocks.clear();
      if (!subdivide.empty()) {
        // Split in increasing id order (deterministic ids).
        std::sort(subdivide.begin(), subdivide.end());
        subdivide.erase(std::unique(subdivide.begin(), subdivide.end()), subdivide.end());
        for (std::uint32_t e : subdivide) {
          if (hierarchy.leaves().size() + 3 > limits.max_leaves) {
            subdivision_closed = true;
            break;
          }
          const std::uint32_t first = hierarchy.subdivide(e);
          split.push_back(e);
          // The children take their parent's radiosity (so no variation below them) until
          // the next solve.
          const std::size_t count = hierarchy.elements().size();
          values.front.resize(count);
          values.variation_front.resize(count, 0.0f);
          for (std::uint32_t c = first; c < first + 4; ++c) values.front[c] = values.front[e];
          if (!values.back.empty()) {
            values.back.resize(count);
            values.variation_back.resize(count, 0.0f);
            for (std::uint32_t c = first; c < first + 4; ++c) values.back[c] = values.back[e];
          }
        }
      }
      if (merge_each_round) merge(chunks, static_cast<std::uint32_t>(hierarchy.elements().size()));
      release_free_heap();
      Progress p;
      p.phase = Phase::form_factors;
      const std::size_t next = pairs_in(frontier);
      reported = std::max(reported, static_cast<double>(done) / static_cast<double>(done + next));
      p.fraction = reported;
      if (!gate.report(p, next == 0)) return false;
    }
    return true;
  }

  /// Drops every link (a cancelled first pass).
  void unlink() {
    offsets = {};
    sources.clear();
    coefficients.clear();
    linked_elements = 0;
    linked = false;
    send_scale = {};
    receive_scale = {};
  }

  /// Adds the links in `chunks` to the receiver-ordered arrays, after each receiver's links
  /// already there and in chunk order (so the order, and every sum over it, is the one a
  /// single pass would make), for `elements` elements (at least linked_elements: adaptive
  /// subdivision only adds elements). The new links are sorted by receiver first (a stable
  /// counting sort, each chunk freed once placed), then the arrays grow and every receiver's
  /// links move up to their new place, from the last receiver down (the arrays grow in place,
  /// GrowableArray), so the old links are never copied elsewhere: the peak is the arrays (8
  /// bytes a link) plus the new links twice (20 bytes each). The first pass merges after every
  /// round, a later one at its end; before, all links were kept as 12-byte records beside the
  /// arrays (246k-facet city: peak RSS 576 -> 471 MiB; 1M: 2163 -> 1801 MiB).
  void merge(LinkChunks& chunks, std::uint32_t elements) {
    const std::uint32_t old_elements = linked ? linked_elements : 0;
    RADIOSITY_ASSERT(elements >= old_elements);
    const std::uint64_t C = cluster_count();
    const std::uint64_t receivers = C + 2ull * elements;
    // extra_at[r]: first of receiver r's new links in extra_*; after the fill, its end.
    std::vector<std::uint64_t> extra_at(receivers + 1, 0);
    std::size_t count = 0;
    for (const std::vector<LinkRecord>& chunk : chunks) {
      count += chunk.size();
      for (const LinkRecord& l : chunk) ++extra_at[receiver_index(l.receiver, elements) + 1];
    }
    if (count == 0 && linked && elements == linked_elements) {
      chunks.clear();  // nothing new (only empty chunks)
      return;
    }
    for (std::uint64_t r = 0; r < receivers; ++r) extra_at[r + 1] += extra_at[r];
    std::vector<NodeHandle> extra_sources(count);
    std::vector<float> extra_coefficients(count);
    for (std::vector<LinkRecord>& chunk : chunks) {
      for (const LinkRecord& l : chunk) {
        const std::uint64_t k = extra_at[receiver_index(l.receiver, elements)]++;
        extra_sources[k] = l.source;
        extra_coefficients[k] = l.coefficient;
      }
      chunk = {};
    }
    chunks.clear();
    // The old index of new receiver r (elements keep their ids; the backs move up), or none.
    constexpr std::uint64_t kNone = ~std::uint64_t{0};
    auto old_index = [&](std::uint64_t r) -> std::uint64_t {
      if (!linked) return kNone;
      if (r < C) return r;
      std::uint64_t e = r - C;
      const bool back = e >= elements;
      if (back) e -= elements;
      if (e >= old_elements) return kNone;
      return C + (back ? old_elements : 0u) + e;
    };
    std::vector<std::uint64_t> at(receivers + 1, 0);
    for (std::uint64_t r = 0; r < receivers; ++r) {
      const std::uint64_t o = old_index(r);
      const std::uint64_t kept = o == kNone ? 0 : offsets[o + 1] - offsets[o];
      const std::uint64_t added = extra_at[r] - (r == 0 ? 0 : extra_at[r - 1]);
      at[r + 1] = at[r] + kept + added;
    }
    RADIOSITY_ASSERT(at[receivers] == sources.size() + count);
    sources.resize(at[receivers]);
    coefficients.resize(at[receivers]);
    for (std::uint64_t r = receivers; r-- > 0;) {
      const std::uint64_t o = old_index(r), to = at[r];
      std::uint64_t kept = 0;
      if (o != kNone) {
        // Up (to >= offsets[o]: every receiver before o is before r too), from the top down.
        const std::uint64_t from = offsets[o];
        kept = offsets[o + 1] - from;
        if (to != from) {
          std::copy_backward(sources.begin() + from, sources.begin() + from + kept, sources.begin() + to + kept);
          std::copy_backward(coefficients.begin() + from, coefficients.begin() + from + kept,
                             coefficients.begin() + to + kept);
        }
      }
      const std::uint64_t first = r == 0 ? 0 : extra_at[r - 1];
      std::copy(extra_sources.begin() + static_cast<std::ptrdiff_t>(first),
                extra_sources.begin() + static_cast<std::ptrdiff_t>(extra_at[r]),
                sources.begin() + to + kept);
      std::copy(extra_coefficients.begin() + static_cast<std::ptrdiff_t>(first),
                extra_coefficients.begin() + static_cast<std::ptrdiff_t>(extra_at[r]),
                coefficients.begin() + to + kept);
    }
    offsets = std::move(at);
    linked_elements = elements;
    linked = true;
  }

  // ---- Buried parts ------------------------------------------------------------------------

  /// exposure, open_index and open_moments for the elements as they stand: new leaves sampled, inner
  /// elements and clusters aggregated. After refinement, which may split elements.
  void update_exposure(const PatchHierarchy& h) {
    measure_leaf_exposure(h);
    update_open_moments(h);
  }
  /// exposure and any_buried: leaves not measured yet sampled, inner elements aggregated.
  void measure_leaf_exposure(const PatchHierarchy& h) {
    const std::size_t count = h.elements().size();
    const std::vector<Patch>& patches = h.patches();
    exposure.resize(2 * count, -1.0f);
    std::vector<std::uint8_t> back_surface(scene.polygons().size(), 0);
    for (std::size_t p = 0; p < patches.size(); ++p)
      if (has_back[p]) back_surface[patches[p].polygon] = 1;
    // New leaves measured (solver/exposure.hpp). Rays and hemicubes find buried points by
    // themselves (docs/FORM_FACTORS.md, "Touching ... geometry"), as do the links' shadow rays
    // from a receiver's points; light pushed down from a receiving cluster or a larger element
    // does not, and the exposure is what the push gives each part. A leaf's own values are its
    // open part's (side_exposures()).
    std::vector<std::uint32_t> todo;
    for (std::uint32_t e = 0; e < count; ++e)
      if (h.element(e).is_leaf() && exposure[2 * std::size_t{e}] < 0.0f) todo.push_back(e);
    measure_exposure(h, occluders, ray_epsilon, back_surface, has_back, todo, threads, exposure);
    for (std::uint32_t e = static_cast<std::uint32_t>(count); e-- > 0;) {  // children before parents
      const Element& el = h.element(e);
      if (el.is_leaf()) continue;
      for (std::size_t side = 0; side < 2; ++side) {
        double area = 0.0, open = 0.0;
        for (std::uint32_t k = 0; k < 4; ++k) {
          const double a = h.element(el.first_child + k).area;
          area += a;
          open += a * exposure[2 * std::size_t{el.first_child + k} + side];
        }
        exposure[2 * std::size_t{e} + side] = area > 0.0 ? static_cast<float>(open / area) : 1.0f;
      }
    }
    any_buried = false;
    for (std::uint32_t e = 0; e < count && !any_buried; ++e)
      if (h.element(e).is_leaf())
        any_buried = leaf_exposure(e, false) < 1.0f || (has_back[h.element(e).patch] && leaf_exposure(e, true) < 1.0f);
  }
  /// open_index and open_moments: the clusters' exposed area moments, only where something
  /// below is buried.
  void update_open_moments(const PatchHierarchy& h) {
    const std::vector<Patch>& patches = h.patches();
    const std::uint32_t C = cluster_count();
    open_index.assign(C, kNone);
    open_moments.clear();
    for (std::uint32_t i = C; i-- > 0;) {
      const ClusterNode& c = tree.node(i);
      std::array<float, 6> open{};
      if (c.is_leaf()) {
        const std::uint32_t p = tree.order()[c.first];
        const std::uint32_t root = patches[p].root;
        const float front = exposure[2 * std::size_t{root}], back = exposure[2 * std::size_t{root} + 1];
        if (front == 1.0f && (!has_back[p] || back == 1.0f)) continue;
        add_surface(open, bases.of(i), bases.front(p, patches[p].normal), patches[p].area * front);
        if (has_back[p]) add_surface(open, bases.of(i), bases.back(p, patches[p].normal), patches[p].area * back);
      } else {
        if (open_index[c.children[0]] == kNone && open_index[c.children[1]] == kNone) continue;
        for (const std::uint32_t child : c.children)
          pull_moments(open_index[child] == kNone ? area_moments[child] : open_moments[open_index[child]],
                       bases.of(child), open, bases.of(i));
      }
      open_index[i] = static_cast<std::uint32_t>(open_moments.size());
      open_moments.push_back(open);
    }
  }
  /// The exposure by which a leaf side's irradiance is divided for its open part's
  /// (effective_exposure(): a sliver is left as it is, a wholly buried side at 0).
  float leaf_exposure(std::uint32_t e, bool back) const { return effective_exposure(element_exposure(e, back)); }
  /// Per unknown, leaf_exposure() of its side; empty when every side is open.
  std::vector<float> side_exposures(const RadiositySystem& sys) const {
    if (!any_buried) return {};
    std::vector<float> x(sys.unknowns());
    for (std::size_t u = 0; u < x.size(); ++u) x[u] = leaf_exposure(sys.element(u), u >= sys.fronts());
    return x;
  }
  /// H per unknown (a mean over the side's whole area, its buried part receiving nothing) to
  /// its open part's.
  static void to_open(std::vector<Rgb>& H, const std::vector<float>& x) {
    for (std::size_t u = 0; u < x.size(); ++u)
      if (x[u] > 0.0f && x[u] < 1.0f) H[u] /= x[u];
  }
  /// What a node's irradiance is multiplied by as it is pushed to a part below it: the part's
  /// exposure over the node's (power kept: the node's is the parts' area-weighted mean).
  static float exposure_ratio(float part, float node) { return node > 0.0f ? part / node : 0.0f; }
  float element_exposure(std::uint32_t e, bool back) const {
    const std::size_t k = 2 * std::size_t{e} + (back ? 1 : 0);
    return k < exposure.size() ? exposure[k] : 1.0f;
  }
  /// The exposure of cluster `c`'s sides of direction `d`: their exposed area over their area
  /// (on the axes, of the sides its moments for `d` stand for).
  float cluster_exposure_toward(std::uint32_t c, const SideDirection& d) const {
    const std::uint32_t k = c < open_index.size() ? open_index[c] : kNone;
    if (k == kNone) return 1.0f;
    const float area = element_irradiance(area_moments[c], bases.of(c), d);
    return area > 0.0f ? element_irradiance(open_moments[k], bases.of(c), d) / area : 1.0f;
  }
  bool wholly_exposed(std::uint32_t c) const { return c >= open_index.size() || open_index[c] == kNone; }
  /// The least exposure of cluster `c`'s sides of one direction (a moment of its basis), over
  /// the directions whose sides are not wholly buried (1 when nothing below is buried; 0 when
  /// everything is). A cluster of walls and of the ground at their feet mostly under a building
  /// is mostly exposed, but its ground, which the links toward up bring light to, is not.
  float least_cluster_exposure(std::uint32_t c) const {
    const std::uint32_t k = c < open_index.size() ? open_index[c] : kNone;
    if (k == kNone) return 1.0f;
    float least = 0.0f;
    for (std::size_t q = 0; q < 6; ++q) {
      const float open = open_moments[k][q], area = area_moments[c][q];
      if (open > 0.0f && area > 0.0f) least = least > 0.0f ? std::min(least, open / area) : open / area;
    }
    return least;
  }
  /// push_moments() from cluster `pc` to its child `cc`, each direction of the child's in
  /// proportion to its exposure over the parent's.
  template <typename T>
  void push_exposed(const std::array<T, 6>& parent, std::uint32_t pc, std::array<T, 6>& child, std::uint32_t cc) const {
    const MomentBasis& pb = bases.of(pc);
    const MomentBasis& cb = bases.of(cc);
    if (wholly_exposed(pc) && wholly_exposed(cc)) {
      push_moments(parent, pb, child, cb);
      return;
    }
    for (int j = 0; j < cb.slots(); ++j) {
      const SideDirection d = cb.direction(j);
      child[static_cast<std::size_t>(j)] +=
          element_irradiance(parent, pb, d) * exposure_ratio(cluster_exposure_toward(cc, d), cluster_exposure_toward(pc, d));
    }
  }
  /// push_exposed()'s transpose (the balancing's adjoint).
  template <typename T>
  void push_exposed_transpose(const std::array<T, 6>& Qc, std::uint32_t cc, std::array<T, 6>& Qp, std::uint32_t pc) const {
    const MomentBasis& pb = bases.of(pc);
    const MomentBasis& cb = bases.of(cc);
    if (wholly_exposed(pc) && wholly_exposed(cc)) {
      push_transpose(Qc, cb, Qp, pb);
      return;
    }
    for (int j = 0; j < cb.slots(); ++j) {
      const SideDirection d = cb.direction(j);
      add_element_weight(Qp, pb, d,
                         Qc[static_cast<std::size_t>(j)] *
                             exposure_ratio(cluster_exposure_toward(cc, d), cluster_exposure_toward(pc, d)));
    }
  }

  // ---- View factors from the links ------------------------------------------------------------

  /// What view_factor_rows() reads besides the links: the push's shares at unit radiosity on
  /// every front, and each cluster's parent.
  struct RowContext {
    PushShares shares;
    std::vector<std::uint32_t> parent;
  };
  std::unique_ptr<RowContext> row_context;

  /// Per thread: transport_row()'s sums, zero between rows.
  struct RowWorkspace {
    std::vector<std::array<double, 6>> R;  ///< per cluster: per unit of its sending moments
    std::vector<std::uint8_t> queued;      ///< per cluster: in `touched`
    std::vector<std::uint32_t> touched;    ///< source clusters with a share, to push down
    std::vector<double> by_patch;          ///< per patch: transport from the row's element
    std::vector<std::uint32_t> patches;    ///< patches with a non-zero by_patch
    bool clean = true;                     ///< all zero (false while a row is being made)
  };

  /// One row of the links' view factors: F(e -> p) for the front of leaf element `e` to the
  /// front of every patch p, into `row` (patches increasing). It is adjoint_delivery() for a
  /// weight of 1 on e alone: the push's transpose only along e's ancestors (its parent elements,
  /// its patch's leaf cluster and that cluster's parents), the links into those, and each
  /// source cluster's sending moments down to its patches. So a row costs its ancestors' links
  /// plus the source clusters' subtrees it reaches: as dense as the links make it.
  void transport_row(const PatchHierarchy& h, std::uint32_t e, RowWorkspace& ws, SparseFactors& row) const {
    row.index.clear();
    row.value.clear();
    row.exposed = 1.0f;
    const double area = h.element(e).area;
    // A wholly buried element (every point the burial test tried is inside a solid: the floor
    // under a block) sends nothing (its radiosity is 0 here, as in refinement:
    // view_factor_links()) and receives nothing, whatever the few rays of its element links that
    // graze the solid's edge found (up to 8e-5 of a row on the 3 708-facet room around a block).
    if (!(area > 0.0) || element_exposure(e, false) == 0.0f) return;
    ws.clean = false;
    const RowContext& context = *row_context;
    const std::uint32_t elements = linked_elements;
    const std::vector<Patch>& patches = h.patches();
    auto add_patch = [&](std::uint32_t p, double t) {
      if (!(t > 0.0)) return;
      if (ws.by_patch[p] == 0.0) ws.patches.push_back(p);
      ws.by_patch[p] += t;
    };
    auto queue = [&](std::uint32_t c) {
      if (ws.queued[c]) return;
      ws.queued[c] = 1;
      ws.touched.push_back(c);
    };
    // As adjoint_delivery()'s from_source(): kappa per unit of I_s(w); fronts only (the view
    // factors' radiosity is 1 on every front but wholly buried ones, 0 on every back).
    auto from_source = [&](NodeHandle s, const glm::vec3& w, double kappa) {
      if (is_cluster(s)) {
        add_intensity_weight(ws.R[handle_index(s)], bases.of(handle_index(s)), w, kappa);
        queue(handle_index(s));
        return;
      }
      const std::uint32_t se = element_of(s);
      if (is_back(s) || element_exposure(se, false) == 0.0f) return;
      add_patch(h.element(se).patch, kappa * h.element(se).area * std::max(0.0f, glm::dot(side_normal(h, s), w)) * kInvPi);
    };
    // Up the element chain: W, what unit irradiance on each ancestor side delivers into e (the
    // push's shares and exposure ratios), and the links into each.
    double W = area;
    std::uint32_t x = e;
    for (;;) {
      const NodeHandle r = side_handle(x, false);
      const std::uint64_t i = receiver_index(r, elements);
      const glm::vec3 cr = centroid(h, r), nr = side_normal(h, r);
      for (std::uint64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
        const NodeHandle s = sources[k];
        if (!is_cluster(s)) {
          if (!is_back(s) && element_exposure(element_of(s), false) != 0.0f)
            add_patch(h.element(element_of(s)).patch, std::abs(coefficients[k]) * W);
          continue;
        }
        const glm::vec3 w = glm::normalize(cr - centroid(h, s));
        from_source(s, w, std::abs(coefficients[k]) * std::max(0.0f, -glm::dot(nr, w)) * W);
      }
      const std::uint32_t parent = h.element(x).parent;
      if (parent == kNone) break;
      W *= context.shares.of_side(2 * std::size_t{x}) * exposure_ratio(element_exposure(x, false), element_exposure(parent, false));
      x = parent;
    }
    // Up the cluster chain: Q, what unit irradiance moments on each cluster deliver into e.
    const std::uint32_t p = h.element(e).patch;
    std::uint32_t c = tree.leaf_of(p);
    RADIOSITY_ASSERT(c != kNone);  // a patch left out of the tree is wholly buried: returned above
    std::array<double, 6> Q{};
    const SideDirection front = bases.front(p, patches[p].normal);
    add_element_weight(Q, bases.of(c), front, W * exposure_ratio(element_exposure(x, false), cluster_exposure_toward(c, front)));
    for (;;) {
      const glm::vec3 cr = cluster_centroid[c];
      const MomentBasis& b = bases.of(c);
      for (std::uint64_t k = offsets[c]; k < offsets[c + 1]; ++k) {
        const NodeHandle s = sources[k];
        const glm::vec3 w = glm::normalize(cr - centroid(h, s));
        from_source(s, w, std::abs(coefficients[k]) * irradiance_weight(Q, b, w));
      }
      const std::uint32_t parent = context.parent[c];
      if (parent == kNone) break;
      std::array<double, 6> shared = Q;
      for (std::size_t q = 0; q < shared.size(); ++q) shared[q] *= context.shares.of_cluster(c, q);
      Q = {};
      push_exposed_transpose(shared, c, Q, parent);
      c = parent;
    }
    // Down each source cluster to its patches. The tree is in depth-first order, so a cluster's
    // subtree is the ids [c, c + 2 count - 1): one scan in increasing id over the union of the
    // touched clusters' subtrees visits every parent before its children, a nested touched
    // cluster's own share already in place (a heap of the touched clusters instead made the 22k
    // city's rows take 28 s).
    std::sort(ws.touched.begin(), ws.touched.end());
    std::uint32_t covered = 0;  // ids below this were scanned
    for (const std::uint32_t t : ws.touched) {
      ws.queued[t] = 0;
      const std::uint32_t end = t + 2 * tree.node(t).count - 1;
      for (std::uint32_t i = std::max(t, covered); i < end; ++i) {
        std::array<double, 6>& Ri = ws.R[i];
        const ClusterNode& node = tree.node(i);
        if (node.is_leaf()) {
          const std::uint32_t q = tree.order()[node.first];
          if (element_exposure(patches[q].root, false) > 0.0f)
            add_patch(q, surface_share(Ri, bases.of(i), bases.front(q, patches[q].normal)) * patches[q].area);
          Ri = {};
          continue;
        }
        for (const std::uint32_t child : node.children) pull_moments_transpose(Ri, i, ws.R[child], child);
        Ri = {};
      }
      covered = std::max(covered, end);
    }
    ws.touched.clear();
    std::sort(ws.patches.begin(), ws.patches.end());
    for (const std::uint32_t q : ws.patches) {
      const auto f = static_cast<float>(ws.by_patch[q] / area);
      ws.by_patch[q] = 0.0;
      if (!(f > 0.0f)) continue;
      row.index.push_back(q);
      row.value.push_back(f);
    }
    ws.patches.clear();
    ws.clean = true;
  }

  // ---- Enclosure ----------------------------------------------------------------------------

  /// Casts an element side's `count` (a multiple of kEnclosureBatch) cosine-distributed rays
  /// (points and directions from one randomised Halton set, the side's own stream; a longer
  /// cast begins with the same rays), kEnclosureBatch at a time, calling `visit(found, hit,
  /// front)` for each until it returns false; returns whether all were visited.
  template <typename Visit>
  bool enclosure_rays(const PatchHierarchy& h, std::uint32_t e, bool back, Visit&& visit,
                      std::uint32_t count = kEnclosureRays) const {
    RADIOSITY_ASSERT(count % kEnclosureBatch == 0);
    const glm::vec3 n = back ? -h.normal(e) : h.normal(e);
    const Frame frame(n);
    Rng rng(seed, 2ull * e + (back ? 1u : 0u), stream_key(Stream::hierarchical_enclosure));
    const ShiftedHalton4 halton(rng);
    std::array<glm::vec3, kEnclosureBatch> origin, direction;
    std::array<RayScene::Hit, kEnclosureBatch> hits;
    std::array<std::uint8_t, kEnclosureBatch> found{};
    for (std::uint32_t first = 0; first < count; first += kEnclosureBatch) {
      for (std::uint32_t k = 0; k < kEnclosureBatch; ++k) {
        glm::vec2 dir2, point2;
        halton.point(first + k, dir2, point2);
        origin[k] = h.sample_point(e, point2) + ray_epsilon * n;
        direction[k] = frame.to_world(cosine_hemisphere(dir2));
      }
      occluders.intersect(kEnclosureBatch, origin.data(), direction.data(), 0.0f, std::numeric_limits<float>::infinity(),
                          hits.data(), found.data());
      for (std::uint32_t k = 0; k < kEnclosureBatch; ++k)
        if (!visit(found[k] != 0, hits[k], glm::dot(direction[k], hits[k].geometric_normal) < 0.0f)) return false;
    }
    return true;
  }

  /// The share of the power `B` sends (A B per side, channel means) that leaves sides in
  /// enclosed places, estimated from up to kEnclosureSamples sides drawn by that power (at
  /// stratified, fixed points of its cumulative sum): a side is enclosed when all its rays meet
  /// a surface that receives light there, a polygon's front or the back of one that has backs
  /// (a one-sided back absorbs, so light that meets one is rightly lost), not an
  /// obstruction-only polygon.
  double enclosed_power_share(const PatchHierarchy& h, const RadiositySystem& sys, const std::vector<Rgb>& B) const {
    std::vector<std::uint8_t> receives(2 * scene.polygons().size(), 0);
    for (std::size_t u = 0; u < sys.unknowns(); ++u)
      receives[2 * std::size_t{h.patches()[h.element(sys.element(u)).patch].polygon} + (u >= sys.fronts() ? 1 : 0)] = 1;
    std::vector<double> cumulative(sys.unknowns() + 1, 0.0);
    for (std::size_t u = 0; u < sys.unknowns(); ++u)
      cumulative[u + 1] = cumulative[u] + std::max(0.0, static_cast<double>(sys.area[u]) * channel_mean(B[u]));
    const double total = cumulative.back();
    if (!(total > 0.0)) return 0.0;
    const std::size_t samples = std::min(kEnclosureSamples, sys.unknowns());
    std::vector<std::uint8_t> enclosed(samples, 0);
    parallel_for(threads, samples, 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        const double target = (static_cast<double>(k) + 0.5) / static_cast<double>(samples) * total;
        const auto u = static_cast<std::size_t>(std::upper_bound(cumulative.begin() + 1, cumulative.end(), target) -
                                                (cumulative.begin() + 1));
        if (u >= sys.unknowns()) continue;
        enclosed[k] = enclosure_rays(h, sys.element(u), u >= sys.fronts(), [&](bool found, const RayScene::Hit& hit, bool front) {
          return found && !scene.polygons()[hit.id].obstruction_only && receives[2 * std::size_t{hit.id} + (front ? 0 : 1)];
        });
      }
    });
    std::size_t count = 0;
    for (const std::uint8_t e : enclosed) count += e;
    return static_cast<double>(count) / static_cast<double>(samples);
  }

  // ---- Delivery in closed regions ----------------------------------------------------------

  /// Sets send_scale and receive_scale from the links as they stand. In a closed region the
  /// true transport is balanced both ways: each side delivers all the power A B it sends to
  /// sides that take it in (its column), and each side gathers from uniform radiosity 1 an
  /// irradiance of 1 (its row). The links' estimates miss both by a few per cent per side
  /// (cluster moments, corrected centroid transport, a few visibility rays: a lamp under a
  /// ceiling delivers 0.93 of its power and gathers 0.90), and a region of reflectance near 1
  /// multiplies the error up to 1 / (1 - rho) times. The transport is therefore scaled, H_u =
  /// r_u G(g B)_u, with g and r found by kBalanceRounds rounds of iterative proportional
  /// fitting (Sinkhorn's balancing, as View3D's enclosure adjustment balances a factor matrix),
  /// g at most kMaxBalance and r within [1/2, kMaxBalance]:
  /// - g_v for an enclosed side v (its kEnclosureRays rays all meet receiving surfaces, as in
  ///   enclosed_power_share()): 1 / the power the scaled links deliver per unit of its A B,
  ///   from the adjoint of gather() (adjoint_delivery());
  /// - r_u for a side whose rays all meet wholly enclosed polygon sides (a closed room's
  ///   inside): 1 / what it gathers from radiosity g on the enclosed sides. Such a closed
  ///   side's g counts only what the links take to closed sides (a second adjoint pass).
  /// - g for the other sides: on a mostly enclosed polygon side, or one none of whose rays leave
  ///   the scene, what makes its open leaves together deliver what their rays measure
  ///   (side_reach, pooled); elsewhere 1, or less where a polygon side's open leaves together
  ///   would deliver more than the power they send (a bound the true transport always meets).
  /// Sides of open scenes are otherwise left alone: what they send partly leaves the scene, and
  /// the rays of a side cannot say how much. Deterministic: fixed rays per side, the adjoint in
  /// serial passes.
  /// The rows cannot always be met: a receiving cluster that spreads light over members the
  /// source sees unlike (a ceiling above a lamp 1 cm under it, fine-meshed, gathers 1.76 from
  /// uniform radiosity) asks for more than any scaling can give, and its r and the lamp's g
  /// would run to the bounds; r >= 1/2 stops that. Measured against Gauss-Seidel on exported
  /// rooms (docs/HIERARCHICAL.md, "Balancing closed regions").
  void update_scales(const PatchHierarchy& h, const Values& values) {
    // A later pass starts from the last pass's scales (most links are the same): fewer rounds.
    std::vector<float> last_send = std::move(send_scale), last_receive = std::move(receive_scale);
    send_scale = {};
    receive_scale = {};
    pull_mean = {};
    const std::uint32_t elements = linked_elements;
    if (!balancing || !linked || elements != h.elements().size()) return;
    const std::vector<Patch>& patches = h.patches();
    bool backs = false;
    for (const std::uint8_t b : has_back) backs = backs || b != 0;
    const std::size_t sides = 2 * std::size_t{elements};
    // Which leaf sides are enclosed.
    std::vector<std::uint8_t> receives(2 * scene.polygons().size(), 0);
    for (std::size_t p = 0; p < patches.size(); ++p) {
      receives[2 * std::size_t{patches[p].polygon}] = 1;
      if (has_back[p]) receives[2 * std::size_t{patches[p].polygon} + 1] = 1;
    }
    auto each_leaf_side = [&](auto&& f) {
      parallel_for(threads, elements, 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t e = begin; e < end; ++e) {
          const Element& el = h.element(static_cast<std::uint32_t>(e));
          if (!el.is_leaf() || !(el.area > 0.0f)) continue;
          for (std::size_t side = 0; side < (has_back[el.patch] ? 2u : 1u); ++side) f(e, side);
        }
      });
    };
    // Kept across passes (the geometry does not change; split elements add sides): 0 not yet
    // tested, 1 open, 2 enclosed.
    side_enclosure.resize(sides, 0);
    each_leaf_side([&](std::size_t e, std::size_t side) {
      std::uint8_t& known = side_enclosure[2 * e + side];
      if (known != 0) return;
      known = enclosure_rays(h, static_cast<std::uint32_t>(e), side == 1,
                             [&](bool found, const RayScene::Hit& hit, bool front) {
                               return found && !scene.polygons()[hit.id].obstruction_only &&
                                      receives[2 * std::size_t{hit.id} + (front ? 0 : 1)];
                             })
                  ? 2
                  : 1;
    });
    std::vector<std::uint8_t> enclosed(sides, 0);
    for (std::size_t k = 0; k < sides; ++k) enclosed[k] = side_enclosure[k] == 2 ? 1 : 0;
    // The polygon side (2 polygon + 1 for its back) that element side k lies on.
    auto polygon_side = [&](std::size_t k) {
      return 2 * std::size_t{patches[h.element(static_cast<std::uint32_t>(k / 2)).patch].polygon} + k % 2;
    };
    // Per polygon side: at least kBalancePolygonShare of its leaves' area is enclosed.
    std::vector<std::uint8_t> mostly_enclosed(2 * scene.polygons().size(), 0);
    {
      // Only the leaves of polygon sides mostly enclosed (kBalancePolygonShare).
      std::vector<double> polygon_area(2 * scene.polygons().size(), 0.0), polygon_enclosed(polygon_area.size(), 0.0);
      for (std::size_t k = 0; k < sides; ++k) {
        const Element& el = h.element(static_cast<std::uint32_t>(k / 2));
        if (!el.is_leaf() || (k % 2 == 1 && !has_back[el.patch])) continue;
        const std::size_t ps = polygon_side(k);
        polygon_area[ps] += el.area;
        if (enclosed[k]) polygon_enclosed[ps] += el.area;
      }
      for (std::size_t ps = 0; ps < mostly_enclosed.size(); ++ps)
        mostly_enclosed[ps] = polygon_area[ps] > 0.0 && polygon_enclosed[ps] >= kBalancePolygonShare * polygon_area[ps];
      for (std::size_t k = 0; k < sides; ++k)
        if (enclosed[k] && !mostly_enclosed[polygon_side(k)]) enclosed[k] = 0;
    }
    double enclosed_area = 0.0, total_area = 0.0;
    for (std::size_t k = 0; k < sides; ++k) {
      const Element& el = h.element(static_cast<std::uint32_t>(k / 2));
      if (!el.is_leaf() || (k % 2 == 1 && !has_back[el.patch])) continue;
      total_area += el.area;
      enclosed_area += enclosed[k] ? el.area : 0.0;
    }
    // The balancing's rounds each cost a gather and a pass over the links: not for a few
    // enclosed corners of an open scene (16 of the 22k city's sides).
    if (!(enclosed_area >= kBalanceMinShare * total_area)) return;
    update_pull_means(h, values, enclosed);
    // The sides that are not enclosed: what share of their rays meets receivers, and whether
    // any leaves the scene. Per polygon side: whether its open leaves' delivery is taken from
    // that share (update_scales()'s rounds), on a mostly enclosed one or where none of their
    // rays left the scene (a closed room's ceiling that sees a lamp's back).
    side_reach.resize(sides, -1.0f);
    side_escapes.resize(sides, 0);
    // A side off a mostly enclosed polygon side stops at its first ray that leaves the scene
    // (its share is then not used; kNotMeasured): a two-sided room's outer faces cost a ray.
    constexpr float kNotMeasured = -2.0f;
    each_leaf_side([&](std::size_t e, std::size_t side) {
      const std::size_t k = 2 * e + side;
      const bool mostly = mostly_enclosed[polygon_side(k)] != 0;
      if (enclosed[k] || side_reach[k] >= 0.0f || (side_reach[k] == kNotMeasured && !mostly)) return;
      std::uint32_t met = 0;
      const bool all = enclosure_rays(
          h, static_cast<std::uint32_t>(e), side == 1,
          [&](bool found, const RayScene::Hit& hit, bool front) {
            met += found && !scene.polygons()[hit.id].obstruction_only && receives[2 * std::size_t{hit.id} + (front ? 0 : 1)];
            side_escapes[k] = side_escapes[k] || !found;
            return found || mostly;
          },
          kReachRays);
      side_reach[k] = all ? static_cast<float>(met) / static_cast<float>(kReachRays) : kNotMeasured;
    });
    std::vector<std::uint8_t> measured = mostly_enclosed, escaped(mostly_enclosed.size(), 0);
    for (std::size_t k = 0; k < sides; ++k) {
      const Element& el = h.element(static_cast<std::uint32_t>(k / 2));
      if (!enclosed[k] && el.is_leaf() && (k % 2 == 0 || has_back[el.patch]) && side_escapes[k]) escaped[polygon_side(k)] = 1;
    }
    for (std::size_t ps = 0; ps < measured.size(); ++ps) measured[ps] = measured[ps] || !escaped[ps];
    // Per polygon side, the power its open leaves should deliver (update_scales()'s rounds):
    // what their rays measure where `measured`, else at most the open power they send.
    std::vector<double> open_target(measured.size(), 0.0);
    for (std::size_t k = 0; k < sides; ++k) {
      const Element& el = h.element(static_cast<std::uint32_t>(k / 2));
      if (enclosed[k] || !el.is_leaf() || (k % 2 == 1 && !has_back[el.patch])) continue;
      const std::size_t ps = polygon_side(k);
      const double b = (k % 2 == 0 ? values.front : values.back)[k / 2].x;
      const double share = measured[ps] ? double{side_reach[k]}
                                         : double{leaf_exposure(static_cast<std::uint32_t>(k / 2), k % 2 == 1)};
      open_target[ps] += b * double{el.area} * share;
    }
    // Polygon sides all of whose leaves are enclosed, and the sides that see only those.
    std::vector<std::uint8_t> closed_polygon = receives;
    for (std::uint32_t e = 0; e < elements; ++e) {
      const Element& el = h.element(e);
      if (!el.is_leaf() || !(el.area > 0.0f)) continue;
      const std::size_t polygon = patches[el.patch].polygon;
      for (std::size_t side = 0; side < (has_back[el.patch] ? 2u : 1u); ++side)
        if (!enclosed[2 * std::size_t{e} + side]) closed_polygon[2 * polygon + side] = 0;
    }
    std::vector<std::uint8_t> closed(sides, 0);
    each_leaf_side([&](std::size_t e, std::size_t side) {
      if (!enclosed[2 * e + side]) return;
      closed[2 * e + side] = enclosure_rays(h, static_cast<std::uint32_t>(e), side == 1,
                                            [&](bool found, const RayScene::Hit& hit, bool front) {
                                              return found && closed_polygon[2 * std::size_t{hit.id} + (front ? 0 : 1)];
                                            });
    });
    const bool rows = std::find(closed.begin(), closed.end(), std::uint8_t{1}) != closed.end();

    std::vector<float> g(sides, 1.0f), r(sides, 1.0f);
    std::copy_n(last_send.begin(), std::min(sides, last_send.size()), g.begin());
    std::copy_n(last_receive.begin(), std::min(sides, last_receive.size()), r.begin());
    const int rounds = last_send.empty() ? kBalanceRounds : kWarmBalanceRounds;
    std::vector<double> delivered, delivered_closed;
    std::vector<float> r_closed(rows ? sides : 0, 0.0f);
    Values v;
    std::vector<Rgb> front, back, unused_front, unused_back;
    PushShares shares;
    for (int round = 0; round < rounds; ++round) {
      // The gather from radiosity g on the enclosed sides: the rows, and the linear push's
      // shares, which the adjoint pushes back by.
      v.front.assign(elements, Rgb(0.0f));
      v.back.assign(backs ? elements : 0, Rgb(0.0f));
      for (std::size_t k = 0; k < sides; ++k)
        if (enclosed[k]) (k % 2 == 0 ? v.front : v.back)[k / 2] = Rgb(g[k]);
      leaf_values(h, v);
      gather_sides(h, v, backs, false, front, back, unused_front, unused_back, &shares);
      if (rows) {
        for (std::size_t k = 0; k < sides; ++k) {
          if (!closed[k]) continue;
          const float gathered = (k % 2 == 0 ? front : back)[k / 2].x;
          if (gathered > 0.0f) r[k] = std::clamp(1.0f / gathered, 0.5f, kMaxBalance);
        }
      }
      adjoint_delivery(h, backs, r, shares, delivered);
      if (rows) {
        // A closed side's light lands only on sides of wholly enclosed polygon sides (what its
        // rays met), closed themselves or not: what the links take to other sides (through the
        // walls, to a two-sided room's outer faces, through receiving clusters that hold both)
        // is their error, and counting it as delivered would leave it lost. (Counting only what
        // reached closed sides was wrong the other way: a lamp facing a ceiling 5 cm away is
        // closed, the ceiling, which also sees the rest of the room, is not; the lamp's delivery
        // came to 0.15 of its power, its scale to the bound, and the ceiling received 3.1 times
        // what the lamp emits.)
        for (std::size_t k = 0; k < sides; ++k) r_closed[k] = closed_polygon[polygon_side(k)] ? r[k] : 0.0f;
        adjoint_delivery(h, backs, r_closed, shares, delivered_closed);
      }
      // The sides that are not enclosed, per polygon side (their rays meet surfaces that take
      // no light in, or none). Where `measured` (a mostly enclosed polygon side, or one none of
      // whose rays left the scene: a closed room's wall or ceiling that sees a one-sided lamp's
      // back) they deliver together what their rays measure, pooled: enough rays to say how
      // much, as one leaf's are not. The enclosed leaves' target of 1 takes a polygon side's
      // loss to be in the rest: the walls of a room with a lamp 2 cm under its ceiling send
      // 0.999 of their power to receivers and were left delivering 1.000, the ceiling of one
      // with the lamp 50 cm under it 0.9526 where its rays say 0.9492, and the rooms came out
      // 1.4 % and 0.5-1.7 % bright against Gauss-Seidel (now 0.6 % and 0.0-0.4 %). In open
      // scenes the pooled share is too noisy for this (the Cornell box's walls, shares near
      // 0.7: scaled to it, its groups moved by 2 %): there they keep the links' own estimate,
      // but never deliver more than the open power they send. The burial test takes the pocket
      // between a ceiling and a one-sided lamp 2 cm under it for buried, the links see into it
      // from the side, and the ceiling's leaves straddling the lamp's edge sent 2-3 times their
      // open power (a furnished room gained energy; docs/HIERARCHICAL.md, "Balancing closed
      // regions").
      {
        std::vector<double> arrived(open_target.size(), 0.0);
        for (std::size_t k = 0; k < sides; ++k) {
          const Element& el = h.element(static_cast<std::uint32_t>(k / 2));
          if (enclosed[k] || !el.is_leaf() || (k % 2 == 1 && !has_back[el.patch])) continue;
          arrived[polygon_side(k)] += (k % 2 == 0 ? values.front : values.back)[k / 2].x * delivered[k];
        }
        for (std::size_t k = 0; k < sides; ++k) {
          if (enclosed[k]) continue;
          const std::size_t ps = polygon_side(k);
          if (measured[ps])
            g[k] = arrived[ps] > 0.0 ? static_cast<float>(std::min(open_target[ps] / arrived[ps], double{kMaxBalance})) : 1.0f;
          else
            g[k] = arrived[ps] > open_target[ps] ? static_cast<float>(open_target[ps] / arrived[ps]) : 1.0f;
        }
      }
      for (std::size_t k = 0; k < sides; ++k) {
        if (!enclosed[k]) continue;
        const double per_unit = (closed[k] ? delivered_closed : delivered)[k] / h.element(static_cast<std::uint32_t>(k / 2)).area;
        if (per_unit > 0.0) g[k] = static_cast<float>(std::min(1.0 / per_unit, double{kMaxBalance}));
      }
    }
    send_scale = std::move(g);
    if (rows) receive_scale = std::move(r);
  }

  /// Per element side (2 e + 1 for its back), the power the links deliver to every leaf side
  /// (each weighted by `weight`, per element side: receive_scale's part) per unit of that
  /// side's value: the adjoint of leaf_values() and gather_sides() (the push's transpose, by
  /// the linear push's `shares` of the round's gather, which depend on the values gathered;
  /// the link sums' transpose, the cluster moments' transpose, the pull's transpose). For a leaf,
  /// delivered / area is the fraction of the power it sends that arrives. One serial pass over
  /// the links: the same sums in the same order at any thread count.
  // The transposes of the gather's steps through a cluster's moments, which the balancing's
  // adjoint (adjoint_delivery()) and the view factors' rows (transport_row()) both take.
  /// intensity()'s transpose: adds kappa per unit of I(w) to the weights R of the sending
  /// moments in basis `b`.
  static void add_intensity_weight(std::array<double, 6>& R, const MomentBasis& b, const glm::vec3& w, double kappa) {
    if (b.axes) {
      for (int a = 0; a < 3; ++a) R[w[a] >= 0.0f ? 2 * a : 2 * a + 1] += kappa * kInvPi * std::abs(w[a]);
      return;
    }
    for (int k = 0; k < b.count; ++k)
      R[static_cast<std::size_t>(k)] += kappa * kInvPi * std::max(0.0f, glm::dot(b.directions[static_cast<std::size_t>(k)], w));
  }
  /// add_irradiance()'s transpose: sum_k Q_k max(0, u_k . d) for d = -w, what flux arriving
  /// along w at a cluster of basis `b` delivers per unit, given the weights Q of its moments.
  static double irradiance_weight(const std::array<double, 6>& Q, const MomentBasis& b, const glm::vec3& w) {
    double taken = 0.0;
    if (b.axes) {
      for (int a = 0; a < 3; ++a) taken += w[a] <= 0.0f ? -w[a] * Q[2 * a] : w[a] * Q[2 * a + 1];
      return taken;
    }
    for (int j = 0; j < b.count; ++j)
      taken += std::max(0.0f, -glm::dot(b.directions[static_cast<std::size_t>(j)], w)) * Q[static_cast<std::size_t>(j)];
    return taken;
  }
  /// pull_moments()'s transpose: the weights R of cluster `parent`'s sending moments passed on
  /// to those of its child `child` (added to Rc).
  void pull_moments_transpose(const std::array<double, 6>& R, std::uint32_t parent, std::array<double, 6>& Rc,
                              std::uint32_t child) const {
    const MomentBasis& cb = bases.of(child);
    const MomentBasis& pb = bases.of(parent);
    if (cb.axes && pb.axes) {
      for (std::size_t a = 0; a < 6; ++a) Rc[a] += R[a];
      return;
    }
    for (int k = 0; k < cb.slots(); ++k) {
      const SideDirection d = cb.direction(k);
      if (pb.axes || pb.slot(d.id) >= 0) Rc[static_cast<std::size_t>(k)] += surface_share(R, pb, d);
    }
  }

  void adjoint_delivery(const PatchHierarchy& h, bool backs, const std::vector<float>& weight,
                        const PushShares& shares, std::vector<double>& delivered) const {
    const std::uint32_t elements = linked_elements;
    const std::vector<Patch>& patches = h.patches();
    // W per element side: the weighted area of its leaves (what unit irradiance on it delivers).
    std::vector<double> W(2 * std::size_t{elements}, 0.0);
    for (std::uint32_t e = elements; e-- > 0;) {
      const Element& el = h.element(e);
      for (std::size_t side = 0; side < 2; ++side) {
        double& w = W[2 * std::size_t{e} + side];
        if (el.is_leaf()) {
          w = static_cast<double>(el.area) * weight[2 * std::size_t{e} + side];
          continue;
        }
        for (std::uint32_t k = 0; k < 4; ++k)  // the push's transpose, its shares and exposure ratios too
          w += W[2 * std::size_t{el.first_child + k} + side] * shares.of_side(2 * std::size_t{el.first_child + k} + side) *
               exposure_ratio(element_exposure(el.first_child + k, side == 1), element_exposure(e, side == 1));
      }
    }
    // Q per cluster: the power its patches take in from unit irradiance moments (the push's
    // element_irradiance() on each patch side).
    const std::uint32_t C = cluster_count();
    std::vector<std::array<double, 6>> Q(C, std::array<double, 6>{});
    for (std::uint32_t i = C; i-- > 0;) {
      const ClusterNode& c = tree.node(i);
      if (!c.is_leaf()) {
        for (const std::uint32_t child : c.children) {
          std::array<double, 6> shared = Q[child];
          for (std::size_t q = 0; q < shared.size(); ++q) shared[q] *= shares.of_cluster(child, q);
          push_exposed_transpose(shared, child, Q[i], i);
        }
        continue;
      }
      const std::uint32_t p = tree.order()[c.first];
      const glm::vec3& n = patches[p].normal;
      const std::uint32_t root = patches[p].root;
      const SideDirection front = bases.front(p, n), back = bases.back(p, n);
      add_element_weight(Q[i], bases.of(i), front,
                         W[2 * std::size_t{root}] *
                             exposure_ratio(element_exposure(root, false), cluster_exposure_toward(i, front)));
      if (backs && has_back[p])
        add_element_weight(Q[i], bases.of(i), back,
                           W[2 * std::size_t{root} + 1] *
                               exposure_ratio(element_exposure(root, true), cluster_exposure_toward(i, back)));
    }
    // The links, receiver by receiver: what each source's value delivers. R per cluster: per
    // unit of its six sending moments.
    delivered.assign(2 * std::size_t{elements}, 0.0);
    std::vector<std::array<double, 6>> R(C, std::array<double, 6>{});
    auto from_source = [&](NodeHandle s, const glm::vec3& w, double kappa) {  // kappa per unit I_s(w)
      if (is_cluster(s)) {
        add_intensity_weight(R[handle_index(s)], bases.of(handle_index(s)), w, kappa);
        return;
      }
      const std::uint32_t e = element_of(s);
      delivered[2 * std::size_t{e} + (is_back(s) ? 1 : 0)] +=
          kappa * h.element(e).area * std::max(0.0f, glm::dot(side_normal(h, s), w)) * kInvPi;
    };
    const std::uint64_t receivers = offsets.size() - 1;
    for (std::uint64_t i = 0; i < receivers; ++i) {
      const std::uint64_t first = offsets[i], last = offsets[i + 1];
      if (first == last) continue;
      const NodeHandle r = receiver_handle(i, elements);
      const glm::vec3 cr = centroid(h, r);
      if (is_cluster(r)) {
        const std::array<double, 6>& q = Q[handle_index(r)];
        const MomentBasis& b = bases.of(handle_index(r));
        for (std::uint64_t k = first; k < last; ++k) {
          const NodeHandle s = sources[k];
          const glm::vec3 w = glm::normalize(cr - centroid(h, s));
          from_source(s, w, std::abs(coefficients[k]) * irradiance_weight(q, b, w));
        }
        continue;
      }
      const double taken = W[2 * std::size_t{element_of(r)} + (is_back(r) ? 1 : 0)];
      const glm::vec3 nr = side_normal(h, r);
      for (std::uint64_t k = first; k < last; ++k) {
        const NodeHandle s = sources[k];
        if (!is_cluster(s)) {
          delivered[2 * std::size_t{element_of(s)} + (is_back(s) ? 1 : 0)] += std::abs(coefficients[k]) * taken;
          continue;
        }
        const glm::vec3 w = glm::normalize(cr - centroid(h, s));
        from_source(s, w, std::abs(coefficients[k]) * std::max(0.0f, -glm::dot(nr, w)) * taken);
      }
    }
    // Down the cluster tree (parents have smaller ids), then into each patch's root element by
    // add_surface()'s split of its normal.
    for (std::uint32_t i = 0; i < C; ++i) {
      const ClusterNode& c = tree.node(i);
      if (!c.is_leaf()) {
        for (const std::uint32_t child : c.children) pull_moments_transpose(R[i], i, R[child], child);
        continue;
      }
      const std::uint32_t p = tree.order()[c.first];
      const glm::vec3& n = patches[p].normal;
      delivered[2 * std::size_t{patches[p].root}] += surface_share(R[i], bases.of(i), bases.front(p, n)) * patches[p].area;
      if (backs && has_back[p])
        delivered[2 * std::size_t{patches[p].root} + 1] += surface_share(R[i], bases.of(i), bases.back(p, n)) * patches[p].area;
    }
    // leaf_values()'s transpose: an inner element's value is its children's mean weighted by
    // their open area (aggregate_open()'s open_areas(), as the sweeps take it), or by area where
    // it has none.
    std::array<std::vector<double>, 2> open;  // per side, when any leaf is buried
    for (std::size_t side = 0; side < 2 && any_buried; ++side)
      open[side] = open_areas(h, elements, [&](std::uint32_t e) { return leaf_exposure(e, side == 1); });
    for (std::uint32_t e = 0; e < elements; ++e) {
      const Element& el = h.element(e);
      if (el.is_leaf()) continue;
      for (std::size_t side = 0; side < 2; ++side) {
        const bool by_open = any_buried && open[side][e] > 0.0;
        double sum = 0.0;
        for (std::uint32_t k = 0; k < 4; ++k)
          sum += by_open ? open[side][el.first_child + k] : double{h.element(el.first_child + k).area};
        if (!(sum > 0.0)) continue;
        for (std::uint32_t k = 0; k < 4; ++k) {
          const double part = by_open ? open[side][el.first_child + k] : double{h.element(el.first_child + k).area};
          delivered[2 * std::size_t{el.first_child + k} + side] += delivered[2 * std::size_t{e} + side] * part / sum;
        }
      }
    }
  }

  /// `B` (per unknown) as the sweeps send it: times send_scale.
  const std::vector<Rgb>& sent(const RadiositySystem& sys, const std::vector<Rgb>& B, std::vector<Rgb>& out) const {
    if (send_scale.empty()) return B;
    out.resize(B.size());
    for (std::size_t u = 0; u < B.size(); ++u) {
      const std::size_t k = 2 * std::size_t{sys.element(u)} + (u >= sys.fronts() ? 1 : 0);
      out[u] = k < send_scale.size() ? B[u] * send_scale[k] : B[u];
    }
    return out;
  }

  // ---- Sweeps -------------------------------------------------------------------------------

  /// The relative gradient (1/m) of a link's irradiance over its receiver, at the receiver's
  /// centroid x from a source at y: the gradient of ln(f_s(w) f_r(-w) / d^2), w = (x - y) / d,
  /// where f_s is what the source shows toward w (an element side: A cos_s; a cluster: its
  /// sending moments' directional sum) and f_r what the receiver shows toward the source. Each
  /// end is given by `q` = grad f / f at its direction (directional_q(); zero: taken as
  /// uniform), which, f being homogeneous of degree one, gives grad_x ln f_s = (q_s - w) / d and
  /// grad_x ln f_r = -(q_r + w) / d. An element receiver (normal `nr`, non-zero) keeps the
  /// part in its plane, where its children lie. Near grazing (cos_s -> 0) the gradient is
  /// unbounded: with `radius` > 0 it is at most 1 / `radius` long (the pull's use, over its
  /// source); the push clamps it by the receiver's box instead (clamp_to_box()).
  static glm::vec3 irradiance_slope(const glm::vec3& x, const glm::vec3& nr, const glm::vec3& q_r, const glm::vec3& y,
                                    const glm::vec3& q_s, float radius) {
    const glm::vec3 u = x - y;
    const float d2 = glm::dot(u, u);
    if (!(d2 > 0.0f)) return glm::vec3(0.0f);
    const float d = std::sqrt(d2);
    const glm::vec3 w = u / d;
    glm::vec3 g = -2.0f * w / d;  // 1 / d^2
    if (q_s != glm::vec3(0.0f)) g += (q_s - w) / d;
    if (nr != glm::vec3(0.0f)) {
      g -= w / d;  // cos_r, whose other term lies along nr
      g -= nr * glm::dot(nr, g);
    } else if (q_r != glm::vec3(0.0f)) {
      g -= (q_r + w) / d;
    }
    const float length = glm::length(g);
    if (radius > 0.0f && length * radius > 1.0f) g *= 1.0f / (length * radius);
    return g;
  }
  /// `g` (a relative gradient at `x`) with each component shortened so that 1 + g_a (p_a - x_a)
  /// >= 0 along axis a across the box `to`: the push's clamp for a receiving node (a cluster, an
  /// element with children) instead of irradiance_slope()'s sphere, which is much larger than
  /// the node's extent along any one axis. A wall cluster from its foot to 8 m high, lit by
  /// ground far away at grazing, has an irradiance about linear in height and 0 at the foot:
  /// its relative gradient is 1 / (the centroid's height), which the sphere of that 4.4 x 8 m
  /// cluster (radius 4.6 m against a height of 3.6 m) cut to 0.8 times, so the linear push gave
  /// the wall's lowest elements that far light 1.5 times over (docs/HIERARCHICAL.md, "The push
  /// at a wall's foot"). Per axis rather than over the whole box: the box's corners take a
  /// gradient across the wall as well, which cut the height's again (the lowest row's view
  /// factor to far ground +28 % instead of +8 %); push_factor() keeps every share within [0, 2]
  /// anyway. Across a cluster of mixed orientation this needs cluster_shares(): with one share
  /// per child over all its sides, a wall's lowest elements took 1.9 times their light. A wall
  /// of one polygon meshed into elements takes that light through its element quadtree: with the
  /// sphere its lowest row +4.0 % and the next -2.9 %, with this within 0.2 %.
  static glm::vec3 clamp_to_box(glm::vec3 g, const glm::vec3& x, const Bounds& to) {
    for (int a = 0; a < 3; ++a) {
      const float lowest = std::min(g[a] * (to.lower[a] - x[a]), g[a] * (to.upper[a] - x[a]));
      if (lowest < -1.0f) g[a] *= -1.0f / lowest;
    }
    return g;
  }
  /// grad f / f of what node `n` shows toward the unit direction `w` (irradiance_slope()'s q):
  /// its sending moments' (`sending`) or, for a receiver, its area moments' directional sum
  /// for a cluster; n / (n . w) for an element side. Zero where it shows nothing that way (or
  /// next to nothing: an element seen within 0.06 degrees of its plane).
  glm::vec3 directional_q(const PatchHierarchy& h, const Values* sending, NodeHandle n, const glm::vec3& w) const {
    if (!is_cluster(n)) {
      const glm::vec3 normal = side_normal(h, n);
      const float cosine = glm::dot(normal, w);
      return cosine > 1e-3f ? normal / cosine : glm::vec3(0.0f);
    }
    const std::uint32_t c = handle_index(n);
    std::array<float, 6> m{};
    if (sending) {
      for (std::size_t k = 0; k < 6; ++k) m[k] = mean(sending->sending[c][k]);
    } else {
      m = area_moments[c];
    }
    const MomentBasis& b = bases.of(c);
    const float sum = directional_sum(m, b, w);
    return sum > 0.0f ? directional_gradient(m, b, w) / sum : glm::vec3(0.0f);
  }
  /// The linear pull: a link takes its source's light from the source node's centroid `cs`, as
  /// if the source's radiosity were uniform over it; where it is not (a floor brightest under
  /// the lamp), the light comes from about its power centroid instead. The link's transport K
  /// (towards `cr`, w the unit direction from `cs`) is taken to first order at the power
  /// centroid, cs + offset: times 1 + grad_y ln K . offset, where grad_y ln K is minus
  /// irradiance_slope()'s gradient over the receiver (K depends on x - y, and on w through both
  /// ends' directional factors), within [kPullLow, kPullHigh]. Measured on the empty Cornell box
  /// (4 000 elements, epsilon 0.05, against ray-cast rows): its indirect light per group from
  /// -0.5..-1.1 % to within 0.75 %.
  float pull_factor(const PatchHierarchy& h, const Values& v, NodeHandle r, const glm::vec3& cr, NodeHandle s,
                    const glm::vec3& cs, const glm::vec3& w) const {
    const glm::vec3& offset = pull_offset(v, s);
    // |gradient| <= 1 / radius (irradiance_slope()'s clamp): a smaller offset moves the
    // factor by less than kPullMinOffset.
    const float r_s = radius(h, s);
    if (!(glm::dot(offset, offset) >= kPullMinOffset * kPullMinOffset * r_s * r_s)) return 1.0f;
    glm::vec3 gradient = pull_gradient(h, &v, r, cr, s, cs, w, r_s);
    if (!pull_mean.empty()) gradient -= pull_mean[source_slot(s)];
    return std::clamp(1.0f + glm::dot(gradient, offset), kPullLow, kPullHigh);
  }
  /// grad_y ln K of the link (r <- s) at the source's centroid `cs` (pull_factor()), at most
  /// 1 / `radius_s` long; the source's directional factor from `sending` moments (its area
  /// moments when null).
  glm::vec3 pull_gradient(const PatchHierarchy& h, const Values* sending, NodeHandle r, const glm::vec3& cr,
                          NodeHandle s, const glm::vec3& cs, const glm::vec3& w, float radius_s) const {
    return -irradiance_slope(cr, glm::vec3(0.0f), directional_q(h, nullptr, r, -w), cs, directional_q(h, sending, s, w),
                             radius_s);
  }
  std::size_t source_slot(NodeHandle s) const {
    return is_cluster(s) ? handle_index(s) : cluster_count() + 2 * std::size_t{element_of(s)} + (is_back(s) ? 1 : 0);
  }
  /// pull_mean from the links as they stand and the balanced sides (`enclosed`, per element
  /// side). In a closed region every source delivers all the power it sends, wherever its
  /// power centroid lies, so there the pull must only move a source's light among its
  /// receivers: each link's gradient less the source's mean over its links (weighted by what
  /// each delivers from unit radiosity) keeps the source's delivered power, to first order,
  /// and with it what the balancing fitted. In an open scene part of what the pull changes is
  /// real (a bright spot nearer an opening sends more out of it), so a source's mean is taken
  /// off in proportion to the share of its power that leaves enclosed sides (of its area where
  /// it sends nothing yet). Without this, the furnace of reflectance 0.99 came
  /// out at 99.57 instead of 100 (the balancing's scales no longer held). One serial pass over
  /// the links (the same sums at any thread count); the weights and the sources' directional
  /// factors are taken from area, not from the radiosity.
  void update_pull_means(const PatchHierarchy& h, const Values& values, const std::vector<std::uint8_t>& enclosed) {
    pull_mean = {};
    const std::uint32_t elements = linked_elements;
    const std::uint32_t C = cluster_count();
    // The enclosed share of each node, from the leaves up: of an element side's area; of a
    // cluster's power (`values`, both sides of its patches), or of its area where it sends
    // nothing yet. By power, because a closed room's two-sided walls send only from their
    // inner sides: by area their clusters were half open, and the room (Kd 0.99) came out 1 %
    // too bright.
    std::vector<float> share(C + 2 * std::size_t{elements}, 0.0f);
    std::vector<double> enclosed_area(C, 0.0), area(C, 0.0), enclosed_power(C, 0.0), power(C, 0.0);
    for (std::uint32_t e = elements; e-- > 0;) {
      const Element& el = h.element(e);
      for (std::size_t side = 0; side < 2; ++side) {
        float& q = share[C + 2 * std::size_t{e} + side];
        if (el.is_leaf()) {
          q = enclosed[2 * std::size_t{e} + side] ? 1.0f : 0.0f;
          continue;
        }
        float sum = 0.0f;
        for (std::uint32_t k = 0; k < 4; ++k)
          sum += h.element(el.first_child + k).area * share[C + 2 * std::size_t{el.first_child + k} + side];
        q = el.area > 0.0f ? sum / el.area : 0.0f;
      }
    }
    for (std::uint32_t c = C; c-- > 0;) {
      const ClusterNode& node = tree.node(c);
      if (node.is_leaf()) {
        const std::uint32_t p = tree.order()[node.first];
        const Patch& patch = h.patches()[p];
        const int sides = has_back[p] ? 2 : 1;
        area[c] = static_cast<double>(patch.area) * sides;
        for (int side = 0; side < sides; ++side) {
          const float q = share[C + 2 * std::size_t{patch.root} + static_cast<std::size_t>(side)];
          const std::vector<Rgb>& value = side == 0 ? values.front : values.back;
          const double p_side = value.empty() ? 0.0 : static_cast<double>(patch.area) * std::max(0.0f, mean(value[patch.root]));
          enclosed_area[c] += static_cast<double>(patch.area) * q;
          power[c] += p_side;
          enclosed_power[c] += p_side * q;
        }
      } else {
        for (const std::uint32_t child : node.children) {
          area[c] += area[child];
          enclosed_area[c] += enclosed_area[child];
          power[c] += power[child];
          enclosed_power[c] += enclosed_power[child];
        }
      }
      share[c] = power[c] > 0.0   ? static_cast<float>(enclosed_power[c] / power[c])
                 : area[c] > 0.0 ? static_cast<float>(enclosed_area[c] / area[c])
                                 : 0.0f;
    }
    if (std::find_if(share.begin(), share.end(), [](float q) { return q > 0.0f; }) == share.end()) return;
    std::vector<glm::dvec3> sum_gradient(share.size(), glm::dvec3(0.0));
    std::vector<double> sum_weight(share.size(), 0.0);
    auto unit_intensity = [&](NodeHandle n, const glm::vec3& w) {
      if (is_cluster(n)) return kInvPi * directional_sum(area_moments[handle_index(n)], bases.of(handle_index(n)), w);
      return kInvPi * h.element(element_of(n)).area * std::max(0.0f, glm::dot(side_normal(h, n), w));
    };
    const std::uint64_t receivers = offsets.size() - 1;
    for (std::uint64_t i = 0; i < receivers; ++i) {
      const NodeHandle r = receiver_handle(i, elements);
      const glm::vec3 cr = centroid(h, r);
      for (std::uint64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
        const NodeHandle s = sources[k];
        const std::size_t slot = source_slot(s);
        if (!(share[slot] > 0.0f)) continue;
        const glm::vec3 cs = centroid(h, s);
        const glm::vec3 w = glm::normalize(cr - cs);
        // What the link delivers from unit radiosity on its source (gather_sides()'s terms).
        double weight = std::abs(coefficients[k]);
        if (is_cluster(r)) {
          weight *= unit_intensity(s, w) * directional_sum(area_moments[handle_index(r)], bases.of(handle_index(r)), -w);
        } else if (is_cluster(s)) {
          weight *= h.element(element_of(r)).area * std::max(0.0f, -glm::dot(side_normal(h, r), w)) * unit_intensity(s, w);
        } else {
          weight *= h.element(element_of(r)).area;
        }
        if (!(weight > 0.0)) continue;
        sum_gradient[slot] += weight * glm::dvec3(pull_gradient(h, nullptr, r, cr, s, cs, w, radius(h, s)));
        sum_weight[slot] += weight;
      }
    }
    pull_mean.assign(share.size(), glm::vec3(0.0f));
    for (std::size_t k = 0; k < share.size(); ++k)
      if (sum_weight[k] > 0.0) pull_mean[k] = glm::vec3(sum_gradient[k] / sum_weight[k]) * share[k];
  }
  /// The share of a node's irradiance a child at `offset` from the node's centroid takes: 1 plus
  /// the node's irradiance-weighted mean relative gradient along the offset (`slope` as
  /// gather_sides() sums it), within [0, 2]. A node's children's area-weighted centroids are
  /// its centroid, so the shares keep its power (clamping aside).
  static float push_factor(const glm::vec4& slope, const glm::vec3& offset) {
    if (!(slope.w > 0.0f)) return 1.0f;
    return std::clamp(1.0f + glm::dot(glm::vec3(slope) / slope.w, offset), 0.0f, 2.0f);
  }
  /// What a child at share `f` of its parent's irradiance carries of the parent's `slope`
  /// (xyz: the sum of its links' irradiance times their relative gradients, i.e. the
  /// irradiance's gradient; w: the irradiance): the same gradient, a linear field's gradient
  /// being the same everywhere, over f times the irradiance. Until session 44 both were scaled
  /// by f, which kept the parent's relative gradient: where the child is darker (f < 1) its
  /// relative gradient is steeper, and the grandchildren's shares came out too even (a wall's
  /// lowest elements, lit about in proportion to their height by far ground, too bright).
  static glm::vec4 carried_slope(const glm::vec4& slope, float f) { return glm::vec4(glm::vec3(slope), f * slope.w); }

  /// Scales the `n` children's shares so that their area-weighted mean is 1: the linear push
  /// then moves a node's irradiance among its children and keeps its power (clamped shares
  /// would not).
  static void keep_power(float* share, const float* area, int n) {
    float weighted = 0.0f, total = 0.0f;
    for (int k = 0; k < n; ++k) {
      weighted += area[k] * share[k];
      total += area[k];
    }
    if (!(weighted > 0.0f)) {
      for (int k = 0; k < n; ++k) share[k] = 1.0f;
      return;
    }
    for (int k = 0; k < n; ++k) share[k] *= total / weighted;
  }
  /// The push's `share` of cluster `c`'s irradiance for each of its two children, per slot of
  /// the child's moment basis: normalised per direction, so that the sides facing a direction
  /// (the children's area moments in it) take, on their area-weighted mean, what the cluster
  /// received from it (keep_power() holds the mean over all sides). A link's light into a
  /// cluster is its mean over the sides that face the light (the link's factor is corrected by
  /// the transport to its descendants), so in a cluster of a wall's foot with the ground before
  /// it, light that only the wall faces went to the wall child times the wall's share over the
  /// whole area: with the box clamp the wall's lowest elements 1.9 times too much, and a clamp
  /// by the sphere had to keep those shares near 1 (docs/HIERARCHICAL.md, "The push at a wall's
  /// foot"). A direction only one child faces goes to it whole. A tilted direction that a
  /// sibling on the axes holds only in its axis moments keeps the child's one share.
  std::array<std::array<float, 6>, 2> cluster_shares(std::uint32_t c, const std::array<float, 2>& share) const {
    const ClusterNode& node = tree.node(c);
    std::array<std::array<float, 6>, 2> out{};
    for (std::size_t k = 0; k < 2; ++k) {
      const std::uint32_t child = node.children[k], other = node.children[1 - k];
      const MomentBasis& cb = bases.of(child);
      const MomentBasis& ob = bases.of(other);
      out[k].fill(share[k]);
      for (int j = 0; j < cb.slots(); ++j) {
        const int o = ob.slot(cb.direction(j).id);
        if (o < 0 && ob.axes) continue;
        const float mine = area_moments[child][static_cast<std::size_t>(j)];
        const float theirs = o < 0 ? 0.0f : area_moments[other][static_cast<std::size_t>(o)];
        const float weighted = mine * share[k] + theirs * share[1 - k];
        if (weighted > 0.0f) out[k][static_cast<std::size_t>(j)] = share[k] * (mine + theirs) / weighted;
      }
    }
    return out;
  }

  /// Gather and push: the irradiance per unknown from the links with node values `v`.
  /// With `hold`, each unknown's irradiance is then held to the discrete maximum principle: at
  /// most, per channel, the largest radiosity among the sources of the links that reach it (its
  /// own, its ancestors' in the element quadtree and the clusters above it). The true irradiance
  /// is a mean of what a surface sees, weighted by view factors that sum to at most 1, so it
  /// cannot exceed that. The links' estimates can: a receiver that sees two coincident surfaces
  /// (a box resting on a floor, its bottom face on the floor) counts both, and a closed box of
  /// reflectance 0.99 around it then gains energy on every sweep until the sweeps diverge (an
  /// exported room made two-sided did, after 619 sweeps). Held so, the largest radiosity after a
  /// sweep is at most the largest emission plus rho_max times the largest before it: bounded
  /// for any rho < 1. Not by default: the estimates err both ways by a few per cent per leaf, so
  /// holding the high ones alone biases the irradiance low (a furnace's mean by -2.4 %).
  /// `kernel_scale`: as gather_sides()'s.
  void gather(const PatchHierarchy& hierarchy, const RadiositySystem& sys, const Values& v,
              std::vector<Rgb>& H, bool hold = false, float kernel_scale = 0.0f) const {
    std::vector<Rgb> front, back, bound_front, bound_back;
    gather_sides(hierarchy, v, sys.has_backs(), hold, front, back, bound_front, bound_back, nullptr, kernel_scale);
    H.resize(sys.unknowns());
    for (std::size_t u = 0; u < sys.unknowns(); ++u) {
      const bool is_front = u < sys.fronts();
      const std::uint32_t e = sys.element(u);
      H[u] = (is_front ? front : back)[e];
      if (hold) H[u] = glm::min(H[u], (is_front ? bound_front : bound_back)[e]);
      const std::size_t k = 2 * std::size_t{e} + (is_front ? 0 : 1);
      if (k < receive_scale.size()) H[u] *= receive_scale[k];
    }
  }
  // ---- The kernel push ----------------------------------------------------------------------

  /// The leaf sides below node `r`: a cluster's, each leaf of its patches on both sides where
  /// the patch has a back; an element's, its leaves on its side. False (and `out` partly
  /// filled) when one of them is in a balanced closed region (side_enclosure): there the
  /// balancing fitted its scales to the linear push, which delivers to each side what it
  /// sends, and the kernel push would not (a furnace of reflectance 0.99 off by 0.4 %).
  bool leaf_sides(const PatchHierarchy& h, NodeHandle r, std::vector<LeafSide>& out) const {
    out.clear();
    bool open = true;
    auto enclosed = [&](std::uint32_t e, bool back) {
      const std::size_t k = 2 * std::size_t{e} + (back ? 1 : 0);
      return k < side_enclosure.size() && side_enclosure[k] == 2;
    };
    auto add_leaves = [&](std::uint32_t top, bool front, bool back) {
      thread_local std::vector<std::uint32_t> stack;
      stack.assign(1, top);
      while (!stack.empty()) {
        const std::uint32_t e = stack.back();
        stack.pop_back();
        const Element& el = h.element(e);
        if (!el.is_leaf()) {
          for (std::uint32_t k = 0; k < 4; ++k) stack.push_back(el.first_child + k);
          continue;
        }
        const glm::vec3& n = h.normal(e);
        if (front) out.push_back({el.centroid, n, el.area, e, false});
        if (back) out.push_back({el.centroid, -n, el.area, e, true});
        open = open && !(front && enclosed(e, false)) && !(back && enclosed(e, true));
      }
    };
    if (!is_cluster(r)) {
      add_leaves(element_of(r), !is_back(r), is_back(r));
      return open;
    }
    const ClusterNode& node = tree.node(handle_index(r));
    for (std::uint32_t k = node.first; k < node.first + node.count && open; ++k) {
      const std::uint32_t p = tree.order()[k];
      add_leaves(h.patches()[p].root, true, has_back[p] != 0);
    }
    return open;
  }
  /// The irradiance (W/m^2) that source `s` of radiosity `v` brings a point `x` of normal `n`,
  /// unoccluded: a cluster's directional intensity from its centroid, cos / d^2; an element's
  /// radiosity times the point-to-polygon factor (0 behind its side), or beyond kFarKernel of
  /// its radii the point-to-point one.
  Rgb point_kernel(const PatchHierarchy& h, const Values& v, NodeHandle s, const glm::vec3& x, const glm::vec3& n) const {
    if (is_cluster(s)) {
      const glm::vec3 d = x - cluster_centroid[handle_index(s)];
      const float d2 = glm::dot(d, d);
      if (!(d2 > 0.0f)) return Rgb(0.0f);
      const glm::vec3 w = d / std::sqrt(d2);
      const float cosine = -glm::dot(n, w);
      if (!(cosine > 0.0f)) return Rgb(0.0f);
      return source_intensity(h, v, s, w) * (cosine / d2);
    }
    const Element& es = h.element(element_of(s));
    const glm::vec3 ns = side_normal(h, s), d = x - es.centroid;
    const float ahead = glm::dot(ns, d);
    if (!(ahead > 0.0f)) return Rgb(0.0f);
    const Rgb& B = (is_back(s) ? v.back : v.front)[element_of(s)];
    const float d2 = glm::dot(d, d), reach = element_radius(h, element_of(s));
    if (d2 > kFarKernel * kFarKernel * reach * reach) {
      // Far from the source (kFarKernel radii): the point-to-point kernel, within about
      // (radius / distance)^2 of the closed form, at a tenth of its cost.
      const float cosine = -glm::dot(n, d);
      if (!(cosine > 0.0f)) return Rgb(0.0f);
      return B * (es.area * kInvPi * ahead * cosine / (d2 * d2));
    }
    return B * point_to_polygon_factor_fast(x, n, corner_points(h, es).data(), es.corner_count());
  }
  /// The kernel push's weight of a link from `s` into node `r` of centroid `cr` whose leaf
  /// sides are `leaves`, which brings it `irradiance` (W/m^2, mean channel) as the linear push
  /// has it: on a side facing the source for an element (`facing` false), times each side's
  /// max(0, -n . w) toward the centroids' direction w for a cluster. Each leaf side is lit by
  /// point_kernel() times its visible fraction from the source (by the final gather's rays,
  /// kLeafRayShare, ShadowSampler::leaf_visibility()); the weight is the power the link
  /// delivers over the sum of the leaves' area times that light (mean channel), so that leaf
  /// side l takes weight x its light and the leaves together the link's power.
  /// 0 (the link is then pushed linearly) where no leaf is lit, or where a leaf would take
  /// more than kKernelPeak times the irradiance on the receiver's most facing side: near
  /// grazing the centroids' direction can show the source to sides that their own directions
  /// do not (a cluster of a turned building's walls and a sliver of ground at their foot, 40 m
  /// from a wall it saw edge-on: the sliver, the one side the kernel found lit, took the link's
  /// whole power, 757 W/m^2 under a sky of 100). A check of the totals instead (the kernel
  /// at the leaves against the point kernel at the centroid, within a factor of 2) also
  /// turned away the ground beside a wall lit by the wall above it, where the two
  /// legitimately differ (the 22k city's ground within 1.2 m of a wall +0.43 -> +0.50 %).
  /// `lit_by_leaf` receives each leaf side's light (point_kernel() times its visible fraction);
  /// `scale` is the scene's radiosity scale (W/m^2) the rays are counted by.
  float kernel_weight(const PatchHierarchy& h, const Values& v, NodeHandle r, NodeHandle s, const glm::vec3& cr,
                      const std::vector<LeafSide>& leaves, std::vector<Rgb>& lit_by_leaf, float irradiance,
                      bool facing, float scale) const {
    if (!(irradiance > 0.0f)) return 0.0f;
    const glm::vec3 u = cr - centroid(h, s);
    const float d2 = glm::dot(u, u);
    if (!(d2 > 0.0f)) return 0.0f;
    const glm::vec3 w = u / std::sqrt(d2);
    lit_by_leaf.resize(leaves.size());
    // The visibility per leaf, by rays as many as the link's strength asks (kLeafRayShare).
    ShadowSampler shadows(*this, h, r, s, Stream::hierarchical_leaf_visibility);
    const float strength = irradiance / (kLeafRayShare * scale);
    const int rays_per_leaf = static_cast<int>(std::clamp(std::ceil(strength * strength), 1.0f, float{kMaxLeafRays}));
    const ShadowSampler::SourcePoints points = shadows.source_points(rays_per_leaf);
    // In parallel over the leaves where they are many: the top levels of the pass by levels
    // hold one or two receivers, each over a large part of the scene's leaves.
    parallel_for(threads, leaves.size(), kLeafBlock, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) lit_by_leaf[k] = point_kernel(h, v, s, leaves[k].centroid, leaves[k].normal);
      shadows.leaf_visibility(points, leaves, lit_by_leaf, begin, end);
    });
    double lit = 0.0, area = 0.0, far = 0.0;
    float brightest = 0.0f, most_facing = facing ? 0.0f : 1.0f;
    for (std::size_t k = 0; k < leaves.size(); ++k) {
      const LeafSide& l = leaves[k];
      const float kernel = mean(lit_by_leaf[k]);
      const float cosine = std::max(0.0f, -glm::dot(l.normal, w));
      lit += static_cast<double>(l.area) * kernel;
      area += static_cast<double>(l.area);
      far += static_cast<double>(l.area) * cosine;
      brightest = std::max(brightest, kernel);
      if (facing) most_facing = std::max(most_facing, cosine);
    }
    if (!(lit > 0.0)) return 0.0f;
    const double weight = irradiance * (facing ? far : area) / lit;
    if (!(weight * brightest <= kKernelPeak * irradiance * most_facing)) return 0.0f;
    return static_cast<float>(weight);
  }
  /// The kernel push's pass (gather_sides() with a `kernel_scale`): `receive(i, true, leaves,
  /// lit)` for every receiver `i` with links that `candidate` takes, level by level (clusters by depth,
  /// then elements with children by depth), each level in parallel. The nodes of one level
  /// hold disjoint leaves, so each leaf side takes its ancestors' links in one order, from the
  /// root down, at any thread count, and each link's kernel is evaluated once per leaf. The
  /// linear push spreads a link's light over its receiver by a gradient at the receiver's
  /// centroid, and each node's links alike: between clusters cut where the tree's median
  /// splits fall, the leaves took an error that changes from one element to the next (on the
  /// 22k city 0.73 % of the walls' radiosity, where the Monte Carlo rows err by 0.18 %; with
  /// every link refined down to the leaves 0.22 %).
  template <typename Candidate, typename Receive>
  void kernel_push(const PatchHierarchy& h, const Candidate& candidate, const Receive& receive) const {
    const std::uint32_t elements = linked_elements;
    const std::uint32_t C = cluster_count();
    std::vector<std::vector<std::uint64_t>> levels;
    auto add = [&](std::size_t level, std::uint64_t i) {
      if (offsets[i] == offsets[i + 1] || !candidate(receiver_handle(i, elements))) return;
      if (levels.size() <= level) levels.resize(level + 1);
      levels[level].push_back(i);
    };
    std::vector<std::uint32_t> depth(C, 0);
    for (std::uint32_t c = 0; c < C; ++c) {
      const ClusterNode& node = tree.node(c);
      if (!node.is_leaf())
        for (const std::uint32_t child : node.children) depth[child] = depth[c] + 1;
      add(depth[c], c);
    }
    const std::size_t cluster_levels = levels.size();
    for (std::uint64_t i = C; i + 1 < offsets.size(); ++i) {
      const NodeHandle r = receiver_handle(i, elements);
      add(cluster_levels + h.element(element_of(r)).depth, i);
    }
    for (const std::vector<std::uint64_t>& level : levels)
      parallel_for(threads, level.size(), 1, [&](std::size_t begin, std::size_t end) {
        std::vector<LeafSide> leaves;
        std::vector<Rgb> lit;
        for (std::size_t k = begin; k < end; ++k) receive(level[k], true, leaves, lit);
      });
  }

  /// gather()'s work: the irradiance per element side (`back` empty without `backs`), pushed
  /// down to every leaf, and with `hold` the maximum principle's bound per element side.
  /// With `shares`, also the linear push's shares (the balancing's adjoint pushes back by them).
  /// With `kernel_scale` > 0 (the final gather: the scene's radiosity scale, W/m^2, for
  /// kLeafRayShare; it needs prepare_sampling()), the links into wholly open nodes with
  /// children are pushed by the kernel and the leaves' visibility instead (kernel_weight(),
  /// kernel_push()); not with `shares`.
  void gather_sides(const PatchHierarchy& hierarchy, const Values& v, bool backs, bool hold, std::vector<Rgb>& front,
                    std::vector<Rgb>& back, std::vector<Rgb>& bound_front, std::vector<Rgb>& bound_back,
                    PushShares* shares = nullptr, float kernel_scale = 0.0f) const {
    const bool kernel = kernel_scale > 0.0f;
    const std::uint32_t elements = linked_elements;
    RADIOSITY_ASSERT(hierarchy.elements().size() == elements);
    const std::uint32_t C = cluster_count();
    RADIOSITY_ASSERT(!hold || v.cluster_max.size() == C);
    RADIOSITY_ASSERT(!(kernel && shares));
    std::vector<Moments> received(C, Moments{});
    front.assign(elements, Rgb(0.0f));
    back.assign(backs ? elements : 0, Rgb(0.0f));
    // The maximum principle's bound per node: the largest radiosity its own links bring.
    std::vector<Rgb> bound_cluster(hold ? C : 0, Rgb(0.0f));
    bound_front.assign(hold ? elements : 0, Rgb(0.0f));
    bound_back.assign(hold ? back.size() : 0, Rgb(0.0f));
    auto source_max = [&](NodeHandle s) -> const Rgb& {
      return is_cluster(s) ? v.cluster_max[handle_index(s)] : (is_back(s) ? v.back : v.front)[element_of(s)];
    };
    // The linear push: per node, the sum over the links into it of each link's irradiance (mean
    // channel) times its relative gradient (xyz), and the sum of those irradiances (w). Only
    // nodes with children use theirs: where no element has children (one element per patch, as
    // the benchmark city) the elements keep none, 16 bytes an element less while the gather runs
    // (the 1M city's peak memory is its first gather's).
    const bool inner_elements = hierarchy.leaves().size() < elements;
    std::vector<glm::vec4> slope_cluster(C, glm::vec4(0.0f)), slope_front(inner_elements ? elements : 0, glm::vec4(0.0f)),
        slope_back(inner_elements && backs ? elements : 0, glm::vec4(0.0f));
    if (shares) {
      shares->cluster.assign(C, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f});
      shares->side.assign(2 * std::size_t{elements}, 1.0f);
    }
    const std::uint64_t receivers = offsets.size() - 1;
    // A receiver the kernel push may take (with children and wholly open) is left to the pass by
    // levels below; there `leaves` holds its leaf sides and `lit` each one's point_kernel() of
    // the link at hand.
    auto kernel_candidate = [&](NodeHandle r) {
      return kernel && node_has_children(hierarchy, r) &&
             (is_cluster(r) ? wholly_exposed(handle_index(r)) : element_exposure(element_of(r), is_back(r)) == 1.0f);
    };
    auto receive = [&](std::size_t i, bool by_levels, std::vector<LeafSide>& leaves, std::vector<Rgb>& lit) {
      const std::uint64_t first = offsets[i], last = offsets[i + 1];
      if (first == last) return;
      const NodeHandle r = receiver_handle(i, elements);
      if (!by_levels && kernel_candidate(r)) return;
      // By levels, the links whose kernel weight is positive go to the leaves; the rest below.
      const bool by_kernel = by_levels && leaf_sides(hierarchy, r, leaves);
      auto to_leaves = [&](NodeHandle s, const glm::vec3& cr, float irradiance, bool facing) {
        if (!by_kernel) return false;
        const float weight = kernel_weight(hierarchy, v, r, s, cr, leaves, lit, irradiance, facing, kernel_scale);
        if (!(weight > 0.0f)) return false;
        for (std::size_t l = 0; l < leaves.size(); ++l)
          (leaves[l].back ? back : front)[leaves[l].element] += weight * lit[l];
        return true;
      };
      const glm::vec3 cr = centroid(hierarchy, r);
      Rgb bound(0.0f);
      if (hold)
        for (std::uint64_t k = first; k < last; ++k) bound = glm::max(bound, source_max(sources[k]));
      if (is_cluster(r)) {
        if (hold) bound_cluster[handle_index(r)] = bound;
        Moments& E = received[handle_index(r)];
        glm::vec4& slope = slope_cluster[handle_index(r)];
        const ClusterNode& node = tree.node(handle_index(r));
        // A one-patch cluster's slope goes to its patch's root element: used if that has children.
        const bool has_children = node_has_children(hierarchy, r);
        // A cluster clamps its links' gradients by its box (clamp_to_box()).
        for (std::uint64_t k = first; k < last; ++k) {
          const NodeHandle s = sources[k];
          const glm::vec3 cs = centroid(hierarchy, s);
          const glm::vec3 w = glm::normalize(cr - cs);
          const Rgb flux = std::abs(coefficients[k]) * pull_factor(hierarchy, v, r, cr, s, cs, w) *
                           source_intensity(hierarchy, v, s, w);
          if (to_leaves(s, cr, mean(flux), true)) continue;
          add_irradiance(E, bases.of(handle_index(r)), -w, flux);
          if (!has_children) continue;
          const glm::vec3 g = clamp_to_box(irradiance_slope(cr, glm::vec3(0.0f), directional_q(hierarchy, nullptr, r, -w),
                                                            cs, directional_q(hierarchy, &v, s, w), 0.0f),
                                           cr, node.bounds);
          slope += mean(flux) * glm::vec4(g, 1.0f);
        }
        return;
      }
      const glm::vec3 nr = side_normal(hierarchy, r);
      Rgb sum(0.0f);
      glm::vec4 slope(0.0f);
      const bool has_children = node_has_children(hierarchy, r);
      const Bounds box = has_children ? node_bounds(hierarchy, r) : Bounds{};
      for (std::uint64_t k = first; k < last; ++k) {
        const NodeHandle s = sources[k];
        Rgb brought;
        if (!is_cluster(s)) {
          brought = std::abs(coefficients[k]) * (is_back(s) ? v.back : v.front)[element_of(s)];
          const glm::vec3& offset = pull_offset(v, s);
          if (offset != glm::vec3(0.0f)) {
            const glm::vec3 cs = centroid(hierarchy, s);
            brought *= pull_factor(hierarchy, v, r, cr, s, cs, glm::normalize(cr - cs));
          }
        } else {
          const glm::vec3 cs = centroid(hierarchy, s);
          const glm::vec3 w = glm::normalize(cr - cs);
          brought = (std::abs(coefficients[k]) * std::max(0.0f, -glm::dot(nr, w)) * pull_factor(hierarchy, v, r, cr, s, cs, w)) *
                    source_intensity(hierarchy, v, s, w);
        }
        if (to_leaves(s, cr, mean(brought), false)) continue;
        sum += brought;
        // Leaves (most receivers) push nothing: no slope, and no look-up of an element
        // source's centroid and normal, which the sum alone does not need.
        if (!has_children) continue;
        const glm::vec3 cs = centroid(hierarchy, s);
        const glm::vec3 g = clamp_to_box(
            irradiance_slope(cr, nr, glm::vec3(0.0f), cs, directional_q(hierarchy, &v, s, glm::normalize(cr - cs)), 0.0f), cr,
            box);
        slope += mean(brought) * glm::vec4(g, 1.0f);
      }
      (is_back(r) ? back : front)[element_of(r)] = sum;
      if (has_children) (is_back(r) ? slope_back : slope_front)[element_of(r)] = slope;
      if (hold) (is_back(r) ? bound_back : bound_front)[element_of(r)] = bound;
    };
    parallel_for(threads, receivers, 2048, [&](std::size_t begin, std::size_t end) {
      std::vector<LeafSide> leaves;
      std::vector<Rgb> lit;
      for (std::size_t i = begin; i < end; ++i) receive(i, false, leaves, lit);
    });
    if (kernel) kernel_push(hierarchy, kernel_candidate, receive);
    // Push: clusters to their children (ids increase downward), one-patch clusters to their
    // patch's root element by its normal, elements to their children; the bounds alike.
    for (std::uint32_t c = 0; c < C; ++c) {
      const ClusterNode& node = tree.node(c);
      if (!node.is_leaf()) {
        std::array<float, 2> share{}, area{};
        for (std::size_t k = 0; k < 2; ++k) {
          const std::uint32_t child = node.children[k];
          share[k] = push_factor(slope_cluster[c], cluster_centroid[child] - cluster_centroid[c]);
          const ClusterNode& cn = tree.node(child);
          area[k] = static_cast<float>(cumulative_area[cn.first + cn.count] - cumulative_area[cn.first]);
        }
        keep_power(share.data(), area.data(), 2);
        const std::array<std::array<float, 6>, 2> by_slot = cluster_shares(c, share);
        for (std::size_t k = 0; k < 2; ++k) {
          const std::uint32_t child = node.children[k];
          const float f = share[k];
          if (shares) shares->cluster[child] = by_slot[k];
          Moments pushed{};
          push_exposed(received[c], c, pushed, child);
          for (std::size_t q = 0; q < pushed.size(); ++q) received[child][q] += by_slot[k][q] * pushed[q];
          slope_cluster[child] += carried_slope(slope_cluster[c], f);
          if (hold) bound_cluster[child] = glm::max(bound_cluster[child], bound_cluster[c]);
        }
        continue;
      }
      const std::uint32_t p = tree.order()[node.first];
      const Patch& patch = hierarchy.patches()[p];
      const SideDirection front_side = bases.front(p, patch.normal), back_side = bases.back(p, patch.normal);
      front[patch.root] += element_irradiance(received[c], bases.of(c), front_side) *
                           exposure_ratio(element_exposure(patch.root, false), cluster_exposure_toward(c, front_side));
      // A one-patch cluster's centroid is its patch's: the root element takes the slope whole.
      if (!hierarchy.element(patch.root).is_leaf()) {
        slope_front[patch.root] += slope_cluster[c];
        if (!back.empty() && has_back[p]) slope_back[patch.root] += slope_cluster[c];
      }
      if (hold) bound_front[patch.root] = glm::max(bound_front[patch.root], bound_cluster[c]);
      if (!back.empty() && has_back[p]) {
        back[patch.root] += element_irradiance(received[c], bases.of(c), back_side) *
                            exposure_ratio(element_exposure(patch.root, true), cluster_exposure_toward(c, back_side));
        if (hold) bound_back[patch.root] = glm::max(bound_back[patch.root], bound_cluster[c]);
      }
    }
    for (std::uint32_t e = 0; e < elements; ++e) {
      const Element& el = hierarchy.element(e);
      if (el.is_leaf()) continue;
      std::array<float, 4> share_front{}, share_back{}, area{};
      for (std::uint32_t k = 0; k < 4; ++k) {
        const Element& child = hierarchy.element(el.first_child + k);
        area[k] = child.area;
        share_front[k] = push_factor(slope_front[e], child.centroid - el.centroid);
        share_back[k] = back.empty() ? 1.0f : push_factor(slope_back[e], child.centroid - el.centroid);
      }
      keep_power(share_front.data(), area.data(), 4);
      keep_power(share_back.data(), area.data(), 4);
      for (std::uint32_t k = 0; k < 4; ++k) {
        const std::uint32_t child = el.first_child + k;
        const float ff = share_front[k];
        if (shares) shares->side[2 * std::size_t{child}] = ff;
        slope_front[child] += carried_slope(slope_front[e], ff);
        front[child] += ff * front[e] * exposure_ratio(element_exposure(child, false), element_exposure(e, false));
        if (!back.empty()) {
          const float fb = share_back[k];
          if (shares) shares->side[2 * std::size_t{child} + 1] = fb;
          slope_back[child] += carried_slope(slope_back[e], fb);
          back[child] += fb * back[e] * exposure_ratio(element_exposure(child, true), element_exposure(e, true));
        }
        if (!hold) continue;
        bound_front[el.first_child + k] = glm::max(bound_front[el.first_child + k], bound_front[e]);
        if (!back.empty())
          bound_back[el.first_child + k] = glm::max(bound_back[el.first_child + k], bound_back[e]);
      }
    }
  }

  /// Scales the irradiance `H` (per unknown) that radiosity `B` (per unknown) sent along the
  /// links so that, per channel, the power they deliver (sum A_u H_u over every unknown side)
  /// is at most the power the surfaces send (sum A_u B_u). The true transport cannot deliver
  /// more, but the links' estimates err both ways by several per cent per source (cluster
  /// moments, the corrected centroid transport, a few visibility rays) and only cancel out on
  /// the whole: in a closed room of reflectance 0.99 a net gain of 1 % made the sweeps diverge
  /// (an exported room made two-sided, after 619 sweeps). Capped so, each sweep's power is at
  /// most the emitted power plus rho_max times the last sweep's: bounded for any rho < 1. In an
  /// open scene, or where the links lose light, nothing changes. Applied only together with
  /// gather()'s hold: where the links do not gain energy overall, capping the sweeps that happen
  /// to would bias them low for nothing.
  static void cap_delivered_power(const RadiositySystem& sys, const std::vector<Rgb>& B, std::vector<Rgb>& H) {
    glm::dvec3 sent(0.0), delivered(0.0);
    for (std::size_t u = 0; u < sys.unknowns(); ++u) {
      sent += static_cast<double>(sys.area[u]) * glm::dvec3(B[u]);
      delivered += static_cast<double>(sys.area[u]) * glm::dvec3(H[u]);
    }
    Rgb scale(1.0f);
    for (int c = 0; c < 3; ++c)
      if (delivered[c] > sent[c] && delivered[c] > 0.0) scale[c] = static_cast<float>(sent[c] / delivered[c]);
    if (scale != Rgb(1.0f))
      for (Rgb& h : H) h *= scale;
  }
};

LinkHierarchy::LinkHierarchy(const Scene& scene, std::uint64_t seed, unsigned threads, const RayScene* occluders)
    : impl_(std::make_unique<Impl>(scene, seed, threads, occluders)) {}
LinkHierarchy::~LinkHierarchy() = default;

bool LinkHierarchy::refine(PatchHierarchy& hierarchy, const RadiositySystem& system, const std::vector<Rgb>& B,
                           float threshold, const SubdivisionLimits& limits, ProgressGate& gate,
                           std::vector<std::uint32_t>& split, RefineStats& stats) {
  Impl& m = *impl_;
  m.refresh_patch_data(hierarchy, system);
  if (m.tree.empty()) return true;
  Impl::Values values;
  m.node_values(hierarchy, system, B, values);
  m.node_variation(hierarchy, values);
  m.prepare_sampling(hierarchy, values);

  LinkChunks chunks;
  std::vector<Pair> frontier;  // the first round's pairs: run_rounds() takes them as one segment
  std::vector<LinkRecord> replaced;  // multigridding: the links being refined
  if (!m.linked) {
    frontier.push_back({cluster_handle(ClusterTree::root()), cluster_handle(ClusterTree::root())});
  } else {
    // Multigridding: every link looked at again with the radiosity solved so far; those that
    // now carry too much are refined, in receiver order (deterministic). A flag per link
    // first, then the kept links and the pairs to refine at their final sizes.
    const Impl::RoundContext rc{hierarchy, values, threshold, limits, limits.max_depth == 0};
    const std::uint64_t receivers = m.offsets.size() - 1;
    std::vector<std::uint8_t> refine(m.sources.size(), 0);
    parallel_for(m.threads, receivers, kBlock, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const NodeHandle r = m.receiver_handle(i, m.linked_elements);
        for (std::uint64_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k) {
          const NodeHandle s = m.sources[k];
          const bool partly_hidden = std::signbit(m.coefficients[k]);
          refine[k] = m.needs_refinement(rc, r, s, partly_hidden) && (m.can_split(rc, r) || m.can_split(rc, s));
          // A zero link (no estimate ray saw through) is looked at once more, here: refined,
          // or else dropped (it carries nothing).
          if (!refine[k] && m.coefficients[k] == 0.0f) refine[k] = 2;
        }
      }
    });
    // refine[k]: 1 to refine, 2 to drop (a zero link not refined).
    std::size_t refined = 0;
    for (std::uint8_t f : refine) refined += f == 1;
    // The links to refine or drop leave the arrays, which close up in place (kept links keep
    // their order); those refined are kept aside to be put back if this pass is cancelled (the
    // dropped zero links are not: at 12 bytes each they would raise the 1M city's peak, and a
    // cancelled pass losing them costs only their next look).
    replaced.reserve(refined);
    frontier.reserve(refined);
    std::uint64_t write = 0, first = m.offsets[0];
    for (std::uint64_t i = 0; i < receivers; ++i) {
      const NodeHandle r = m.receiver_handle(i, m.linked_elements);
      const std::uint64_t last = m.offsets[i + 1];
      m.offsets[i] = write;
      for (std::uint64_t k = first; k < last; ++k) {
        if (refine[k] == 1) {
          frontier.push_back({r, m.sources[k]});
          replaced.push_back({r, m.sources[k], m.coefficients[k]});
        } else if (refine[k] == 0) {
          m.sources[write] = m.sources[k];
          m.coefficients[write] = m.coefficients[k];
          ++write;
        }
      }
      first = last;
    }
    m.offsets[receivers] = write;
    m.sources.resize(write);
    m.coefficients.resize(write);
    stats.links_replaced += frontier.size();
    if (frontier.empty()) {
      m.release_sampling();
      return true;
    }
  }
  // The first pass merges its links round by round (nothing to put back if it is cancelled:
  // the links are then dropped, and the next solve starts again); a later pass at its end.
  const bool first_pass = !m.linked;
  const bool completed =
      m.run_rounds(hierarchy, values, PairSegments{std::move(frontier)}, threshold, limits, gate, chunks, split, stats,
                   first_pass);
  // After the rounds: they may have split elements (adaptive subdivision).
  const auto elements = static_cast<std::uint32_t>(hierarchy.elements().size());
  if (!completed) {
    if (first_pass) {
      m.unlink();
    } else if (!replaced.empty()) {
      // The links this pass took out go back (after the kept ones of their receiver), so the
      // links stand as before it; its new links are dropped.
      chunks.clear();
      chunks.push_back(std::move(replaced));
      m.merge(chunks, elements);
    }
    m.release_sampling();
    return false;
  }
  replaced = {};
  m.merge(chunks, elements);
  release_free_heap();
  m.update_exposure(hierarchy);
  m.update_scales(hierarchy, values);
  m.release_sampling();
  return true;
}

SolverResult LinkHierarchy::solve(const SolverContext& ctx, const std::vector<Rgb>& B0, bool hold,
                                  bool with_irradiance) const {
  const Impl& m = *impl_;
  const RadiositySystem& sys = ctx.system;
  const std::size_t n = sys.unknowns();
  SolverResult result;
  // Leaves partly buried: their values are their open parts' (SolverResult::exposure).
  result.exposure = m.side_exposures(sys);
  const std::vector<Rgb> source = sys.exposed_source(result.exposure);
  const std::vector<Rgb>& start = B0.empty() ? source : B0;
  result.B = start;
  result.H.assign(n, Rgb(0.0f));
  result.form_factor_bytes = bytes();
  if (!m.linked) return result;
  auto t0 = std::chrono::steady_clock::now();
  Impl::Values values;
  std::vector<Rgb> next(n);
  const int max_iterations = ctx.options.max_iterations;
  result.status = SolveStatus::iteration_cap;
  // Jacobi sweeps contract when the links pass on less light than they receive. When the change
  // grows for kGrowingSweeps sweeps in a row they do not (the links gain energy somewhere: a
  // closed region of reflectance near 1, coincident surfaces seen twice); the sweeps then start
  // again from `start` with gather()'s hold, which bounds them (result.held says so). A gain
  // near rho = 1 makes the change grow by a fraction of a per cent per sweep, so any growth
  // counts; rounding alone does not grow it for 16 sweeps in a row.
  constexpr int kGrowingSweeps = 16;
  result.held = hold;
  int growing = 0;
  double last_change = std::numeric_limits<double>::infinity();
  std::vector<Rgb> scaled;  // result.B as sent (Impl::sent())
  for (int it = 1; it <= max_iterations; ++it) {
    const std::vector<Rgb>& B_sent = m.sent(sys, result.B, scaled);
    m.node_values(ctx.hierarchy, sys, B_sent, values, hold);
    m.gather(ctx.hierarchy, sys, values, result.H, hold);
    if (hold) Impl::cap_delivered_power(sys, result.B, result.H);
    Impl::to_open(result.H, result.exposure);
    // B_u = E_u + rho_u H_u + tau_u H_twin (system.hpp), from the previous sweep's values.
    double change = 0.0;
    for (std::size_t u = 0; u < n; ++u) {
      const Rgb b = sys.radiosity_of(u, source[u], result.H);
      next[u] = b;
      change += sys.area[u] * channel_l1(b - result.B[u]);
    }
    growing = change > last_change ? growing + 1 : 0;
    last_change = change;
    if (!hold && (growing >= kGrowingSweeps || !std::isfinite(change))) {
      hold = true;
      result.held = true;
      growing = 0;
      last_change = std::numeric_limits<double>::infinity();
      result.B = start;
      continue;
    }
    result.B.swap(next);
    if (end_sweep(ctx, result, it, change, seconds_since(t0))) break;
  }
  // Irradiance for the energy balance, from the final radiosity.
  if (with_irradiance) result.H = irradiance(ctx.hierarchy, sys, result.B, hold);
  return result;
}

std::vector<Rgb> LinkHierarchy::irradiance(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                                           const std::vector<Rgb>& B, bool hold) const {
  std::vector<Rgb> H(system.unknowns(), Rgb(0.0f));
  if (!impl_->linked) return H;
  Impl::Values values;
  std::vector<Rgb> scaled;
  impl_->node_values(hierarchy, system, impl_->sent(system, B, scaled), values, hold);
  impl_->gather(hierarchy, system, values, H, hold);
  if (hold) Impl::cap_delivered_power(system, B, H);
  Impl::to_open(H, impl_->side_exposures(system));
  return H;
}

std::vector<Rgb> LinkHierarchy::final_gather(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                                             const std::vector<Rgb>& B, float scale, bool hold,
                                             std::uint64_t* rays) {
  Impl& m = *impl_;
  std::vector<Rgb> H(system.unknowns(), Rgb(0.0f));
  m.leaf_rays = 0;
  if (rays) *rays = 0;
  if (!m.linked) return H;
  Impl::Values values;
  std::vector<Rgb> scaled;
  m.node_values(hierarchy, system, m.sent(system, B, scaled), values, hold);
  // The leaves' visibility rays draw source points by the power sent now.
  m.prepare_sampling(hierarchy, values);
  m.gather(hierarchy, system, values, H, hold, scale);
  m.release_sampling();
  if (rays) *rays = m.leaf_rays.load();
  if (hold) Impl::cap_delivered_power(system, B, H);
  Impl::to_open(H, m.side_exposures(system));
  return H;
}

double LinkHierarchy::enclosed_power_share(const PatchHierarchy& hierarchy, const RadiositySystem& system,
                                           const std::vector<Rgb>& B) const {
  return impl_->enclosed_power_share(hierarchy, system, B);
}

void LinkHierarchy::prepare_view_factor_rows(const PatchHierarchy& hierarchy, const RadiositySystem& system) {
  Impl& m = *impl_;
  auto context = std::make_unique<Impl::RowContext>();
  if (!m.linked) {  // no patches: no links, and rows of nothing
    m.row_context = std::move(context);
    return;
  }
  // The push's shares at the view factors' radiosity: 1 on every front but wholly buried ones.
  std::vector<Rgb> B(system.unknowns(), Rgb(0.0f));
  for (std::size_t u = 0; u < system.fronts(); ++u)
    if (m.element_exposure(system.element(u), false) != 0.0f) B[u] = Rgb(1.0f);
  Impl::Values values;
  m.node_values(hierarchy, system, B, values);
  std::vector<Rgb> front, back, bound_front, bound_back;
  m.gather_sides(hierarchy, values, system.has_backs(), false, front, back, bound_front, bound_back, &context->shares);
  context->parent.assign(m.tree.nodes().size(), kNone);
  for (std::uint32_t c = 0; c < m.tree.nodes().size(); ++c)
    if (!m.tree.node(c).is_leaf())
      for (const std::uint32_t child : m.tree.node(c).children) context->parent[child] = c;
  m.row_context = std::move(context);
}

void LinkHierarchy::view_factor_rows(const PatchHierarchy& hierarchy, const std::vector<std::uint32_t>& elements,
                                     std::vector<SparseFactors>& rows) const {
  const Impl& m = *impl_;
  RADIOSITY_ASSERT(m.row_context != nullptr);
  rows.resize(elements.size());
  if (!m.linked) {
    for (SparseFactors& r : rows) r = SparseFactors{};
    return;
  }
  parallel_for(m.threads, elements.size(), 16, [&](std::size_t begin, std::size_t end) {
    // Per thread, kept between blocks and calls: every row leaves it zero, so only a new size
    // (another scene) or a row that did not finish (an exception) fills it again (filling it
    // per block of 16 rows was megabytes each).
    thread_local Impl::RowWorkspace ws;
    if (!ws.clean || ws.R.size() != m.tree.nodes().size() || ws.by_patch.size() != hierarchy.patches().size()) {
      ws = Impl::RowWorkspace{};
      ws.R.assign(m.tree.nodes().size(), std::array<double, 6>{});
      ws.queued.assign(m.tree.nodes().size(), 0);
      ws.by_patch.assign(hierarchy.patches().size(), 0.0);
    }
    for (std::size_t k = begin; k < end; ++k) m.transport_row(hierarchy, elements[k], ws, rows[k]);
  });
}

void LinkHierarchy::measure_buried_parts(const PatchHierarchy& hierarchy, const RadiositySystem& system) {
  impl_->refresh_patch_data(hierarchy, system);
  impl_->update_exposure(hierarchy);
}

float LinkHierarchy::exposure(std::uint32_t element, bool back) const { return impl_->element_exposure(element, back); }

std::size_t LinkHierarchy::link_count() const { return impl_->sources.size(); }

void LinkHierarchy::set_balancing(bool on) { impl_->balancing = on; }

void LinkHierarchy::set_memory_budget(std::size_t bytes, const char* field) {
  impl_->memory_budget = resolve_memory_budget(bytes);
  impl_->memory_budget_field = field;
}

std::size_t LinkHierarchy::bytes() const {
  const Impl& m = *impl_;
  const std::size_t clusters = m.tree.nodes().size();
  return m.sources.size() * sizeof(NodeHandle) + m.coefficients.size() * sizeof(float) +
         m.offsets.capacity() * sizeof(std::uint64_t) + clusters * (sizeof(ClusterNode) + 2 * sizeof(Moments)) +
         m.cumulative_area.capacity() * sizeof(double) + m.sample_patches.capacity() * sizeof(Impl::SamplePatch) +
         (m.send_scale.capacity() + m.receive_scale.capacity() + m.side_reach.capacity()) * sizeof(float) +
         m.side_enclosure.capacity() + m.side_escapes.capacity() + m.bases.memory_bytes();
}

const ClusterTree& LinkHierarchy::tree() const { return impl_->tree; }

}  // namespace radiosity::detail
