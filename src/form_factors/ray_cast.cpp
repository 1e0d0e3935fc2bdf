// Ray-cast and analytic element-to-patch form factors.
// Based on: Wallace, Elmquist & Haines, "A ray tracing algorithm for progressive radiosity",
// SIGGRAPH 1989 (sampling the source, visibility by rays); Baum, Rushmeier & Winget, SIGGRAPH 1989
// (the exact point-to-polygon factor for the unoccluded part); Haines & Wallace, "Shaft culling
// for efficient ray-traced radiosity", Eurographics Workshop on Rendering 1991 (rays only where
// an occluder may be); Cohen & Wallace, "Radiosity and Realistic Image Synthesis" (1993), ch. 4;
// Wald, Slusallek, Benthin & Wagner, "Interactive rendering with coherent ray tracing",
// Eurographics 2001 (tracing coherent rays as packets).
//
// F(e -> j) = 1/A_e  integral over e of  F(dx -> j) V(x, j) dx.
// For points x on the element, F(dx -> j) is evaluated exactly by the contour integral (so
// nearness and shared edges cost no accuracy) and integrated by an adaptive Gauss rule. V(x, j),
// the fraction of the patch visible from x, is estimated by occlusion rays between stratified
// points x and y, weighted by the point-to-point kernel cos(theta_x) cos(theta_y) / r^2. Pairs
// that no other polygon can shadow (shaft test) cast no rays, so in an unoccluded configuration
// the estimate is the exact factor up to the quadrature over e. Pairs whose first rays disagree
// (a penumbra) are sampled again with more rays, in proportion to their unoccluded factor.
// The rays of a pass all join one element to one patch and are traced together as packets.
//
// Diffuse transmission (FormFactorOptions::diffuse_transmission): the back of a translucent
// patch is a receiver facing -normal, and an element's back is a source facing -normal
// (backward form factors); both go through the same code with the normal flipped.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/sampling.hpp"
#include "form_factors/shaft.hpp"
#include "form_factors/visibility.hpp"
#include "geometry/ray_scene.hpp"
#include "core/streams.hpp"

namespace radiosity {
inline namespace v1 {
FormFactorEstimator::~FormFactorEstimator() = default;
}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

namespace {

class SampledEstimator final : public BackColumnEstimator {
 public:
  SampledEstimator(const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options,
                   bool with_visibility)
      : BackColumnEstimator(hierarchy),
        hierarchy_(hierarchy),
        options_(options),
        visibility_(with_visibility) {
    // Offsets keep ray end points off the surfaces they start and end on; the same length is
    // the shaft test's "touching" tolerance.
    epsilon_ = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
    const auto& patches = hierarchy.patches();
    if (options.diffuse_transmission) set_translucent_patches(find_back_patches(scene, hierarchy));
    back_target_ = back_targets(patches.size(), translucent_patches());
    corners_.resize(patches.size());
    for (std::size_t j = 0; j < patches.size(); ++j) {
      const Element& root = hierarchy.element(patches[j].root);
      PatchCorners& c = corners_[j];
      c.count = root.corner_count();
      for (int k = 0; k < c.count; ++k) {
        c.p[static_cast<std::size_t>(k)] = hierarchy.vertices()[root.corners[static_cast<std::size_t>(k)]];
        c.radius = std::max(c.radius, glm::length(c.p[static_cast<std::size_t>(k)] - patches[j].centroid));
      }
      c.sampler = CellSampler(c.p.data(), c.count);
    }
    if (visibility_) {
      rays_.emplace(RayScene::from_polygons(scene));
      std::vector<std::vector<glm::vec3>> polygons;
      std::vector<glm::vec3> normals;
      for (const Polygon& p : scene.polygons()) {
        polygons.push_back(p.vertices);
        normals.push_back(p.normal);
      }
      occluders_ = ShaftCuller(polygons, normals);
      // Shaft verdicts per (source patch, receiver patch), shared by the source's elements and
      // filled on first use; only for meshes where n^2 bytes stay small.
      const std::size_t n = patches.size();
      if (n <= kMaxCachedPatches) {
        verdicts_.reset(new std::atomic<std::uint8_t>[n * n]);
        for (std::size_t i = 0; i < n * n; ++i) verdicts_[i].store(kUnknown, std::memory_order_relaxed);
      }
    }
  }

  void element_rows(const std::vector<std::uint32_t>& elements, float* out) const override {
    const std::size_t n = hierarchy_.patches().size();
    parallel_for(options_.threads, elements.size(), 4, [&](std::size_t begin, std::size_t end) {
      Source source;
      RayCastCounters counts;
      for (std::size_t k = begin; k < end; ++k) {
        prepare(elements[k], source);
        for (std::size_t j = 0; j < n; ++j)
          out[k * n + j] = static_cast<float>(factor(source, static_cast<std::uint32_t>(j), counts));
      }
      add(counts);
    });
  }

  void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    column(patch, elements, false, out);
  }

  void back_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    column(patch, elements, true, out);
  }

  RayCastCounters counters() const {
    RayCastCounters c;
    c.factors = factors_.load(std::memory_order_relaxed);
    c.shadowed = shadowed_.load(std::memory_order_relaxed);
    c.rays = rays_cast_.load(std::memory_order_relaxed);
    return c;
  }

 private:
  // With diffuse transmission, rows and columns run over every target (backs after the patches).
  void target_rows(const std::vector<std::uint32_t>& elements, bool back,
                   std::vector<SparseFactors>& out) const override {
    out.assign(elements.size(), SparseFactors{});
    const auto targets = static_cast<std::uint32_t>(target_count());
    parallel_for(options_.threads, elements.size(), 4, [&](std::size_t begin, std::size_t end) {
      Source source;
      RayCastCounters counts;
      for (std::size_t k = begin; k < end; ++k) {
        prepare(elements[k], source, back);
        for (std::uint32_t t = 0; t < targets; ++t) {
          const auto f = static_cast<float>(factor(source, t, counts));
          if (f > 0.0f) {
            out[k].index.push_back(t);
            out[k].value.push_back(f);
          }
        }
      }
      add(counts);
    });
  }

  // F(e -> target) for the elements' fronts, or their backs when `back`.
  void column(std::uint32_t target, const std::vector<std::uint32_t>& elements, bool back, float* out) const {
    parallel_for(options_.threads, elements.size(), 64, [&](std::size_t begin, std::size_t end) {
      Source source;
      RayCastCounters counts;
      for (std::size_t k = begin; k < end; ++k) {
        prepare(elements[k], source, back);
        out[k] = static_cast<float>(factor(source, target, counts));
      }
      add(counts);
    });
  }

  void target_column(std::uint32_t target, const std::vector<std::uint32_t>& elements, float* column) const override {
    const std::size_t m = elements.size();
    parallel_for(options_.threads, m, 64, [&](std::size_t begin, std::size_t end) {
      Source source;
      RayCastCounters counts;
      for (std::size_t k = begin; k < end; ++k) {
        prepare(elements[k], source);
        column[k] = static_cast<float>(factor(source, target, counts));
        if (back_target_[source.patch] == kNone) continue;
        prepare(elements[k], source, true);
        column[m + k] = static_cast<float>(factor(source, target, counts));
      }
      add(counts);
    });
  }

  static constexpr int kMaxDepth = 5;
  // Absolute accuracy goal of each unoccluded factor: rows of a closed enclosure then sum to 1
  // within about 1e-4 even with tens of near neighbours.
  static constexpr double kAbsoluteTolerance = 1e-5;
  static constexpr std::size_t kMaxCachedPatches = 4096;
  static constexpr std::uint8_t kUnknown = 0, kClear = 1, kShadowed = 2;

  struct PatchCorners {
    std::array<glm::vec3, 4> p{};
    int count = 0;
    float radius = 0.0f;  ///< largest distance from the patch centroid to a corner
    CellSampler sampler;
  };

  // What every factor of one source element needs, computed once per element.
  struct Source {
    std::uint32_t element = kNone;
    std::uint32_t patch = kNone;
    PolygonId polygon = 0;
    glm::vec3 normal{0.0f};
    glm::vec3 centroid{0.0f};
    float radius = 0.0f;
    std::array<glm::vec3, 4> corners{};
    int corner_count = 0;
    CellSampler sampler;                    ///< area-uniform points (visibility rays)
    CellMap map;                            ///< polynomial map (quadrature)
    std::array<glm::vec3, 5> quadrature{};  ///< the 2x2 Gauss points, then the midpoint
    std::array<float, 5> density{};         ///< the map's area density at those points
    bool back = false;                      ///< the element's back side (normal flipped)
  };

  // A receiving patch, or the back of a translucent one (facing -normal).
  struct Receiver {
    std::uint32_t patch = 0;   ///< in the hierarchy
    std::uint32_t target = 0;  ///< its index in a row: the patch, or patch count + k for a back
    glm::vec3 normal{0.0f};
  };

  Receiver receiver(std::uint32_t target) const {
    const std::size_t n = patch_count();
    const std::uint32_t j = target < n ? target : translucent_patches()[target - n];
    const glm::vec3 normal = hierarchy_.patches()[j].normal;
    return Receiver{j, target, target < n ? normal : -normal};
  }

  void prepare(std::uint32_t e, Source& s, bool back = false) const {
    const Element& el = hierarchy_.element(e);
    const Patch& patch = hierarchy_.patches()[el.patch];
    s.element = e;
    s.patch = el.patch;
    s.polygon = patch.polygon;
    s.normal = back ? -patch.normal : patch.normal;
    s.back = back;
    s.centroid = el.centroid;
    s.corner_count = el.corner_count();
    s.radius = 0.0f;
    for (int k = 0; k < s.corner_count; ++k) {
      const auto i = static_cast<std::size_t>(k);
      s.corners[i] = hierarchy_.vertices()[el.corners[i]];
      s.radius = std::max(s.radius, glm::length(s.corners[i] - el.centroid));
    }
    s.sampler = CellSampler(s.corners.data(), s.corner_count);
    s.map = CellMap(s.corners.data(), s.corner_count);
    const glm::vec2 nodes[5] = {
        {kGaussLo, kGaussLo}, {kGaussHi, kGaussLo}, {kGaussLo, kGaussHi}, {kGaussHi, kGaussHi}, {0.5f, 0.5f}};
    for (int k = 0; k < 5; ++k) {
      s.quadrature[static_cast<std::size_t>(k)] = s.map.point(nodes[k]);
      s.density[static_cast<std::size_t>(k)] = s.map.density(nodes[k]);
    }
  }

  void add(const RayCastCounters& c) const {
    factors_.fetch_add(c.factors, std::memory_order_relaxed);
    shadowed_.fetch_add(c.shadowed, std::memory_order_relaxed);
    rays_cast_.fetch_add(c.rays, std::memory_order_relaxed);
  }

  // F(source -> target): `target` indexes a row (a patch, or a translucent patch's back).
  double factor(const Source& s, std::uint32_t target_index, RayCastCounters& counts) const {
    ++counts.factors;
    const Receiver r = receiver(target_index);
    const Patch& target = hierarchy_.patches()[r.patch];
    // Patches of one planar polygon cannot see each other.
    if (s.polygon == target.polygon) return 0.0;
    const glm::vec3 nx = s.normal, ny = r.normal;
    const PatchCorners& poly = corners_[r.patch];

    // Whole-pair culling: the receiver entirely below the element's plane, or the element
    // entirely behind the receiver.
    bool any_above = false;
    for (int k = 0; k < poly.count; ++k)
      any_above |= glm::dot(poly.p[static_cast<std::size_t>(k)] - s.centroid, nx) > epsilon_;
    if (!any_above) return 0.0;
    bool any_in_front = false;
    for (int k = 0; k < s.corner_count; ++k)
      any_in_front |= glm::dot(s.corners[static_cast<std::size_t>(k)] - target.centroid, ny) > epsilon_;
    if (!any_in_front) return 0.0;

    const double unoccluded = unoccluded_factor(s, target, ny, poly);
    if (!visibility_ || unoccluded <= 0.0 || !may_be_shadowed(s, r)) return unoccluded;
    ++counts.shadowed;
    return unoccluded * visible_fraction(s, r, unoccluded, counts.rays);
  }

  // Whether any polygon but the pair's own can enter the convex hull of source and receiver.
  // With the cache, the hull of the source's whole patch is tested once for all its elements.
  // The cache holds front-to-front pairs; pairs involving a back are tested each time.
  bool may_be_shadowed(const Source& s, const Receiver& r) const {
    const std::uint32_t j = r.patch;
    const Patch& target = hierarchy_.patches()[j];
    const PatchCorners& poly = corners_[j];
    if (!verdicts_ || s.back || r.target != r.patch)
      return occluders_.may_block(s.corners.data(), s.corner_count, s.normal, poly.p.data(), poly.count, r.normal,
                                  epsilon_, s.polygon, target.polygon);
    std::atomic<std::uint8_t>& slot = verdicts_[static_cast<std::size_t>(s.patch) * corners_.size() + j];
    std::uint8_t v = slot.load(std::memory_order_relaxed);
    if (v == kUnknown) {
      // Concurrent first uses compute the same value, so the race is benign.
      const PatchCorners& own = corners_[s.patch];
      const bool shadowed = occluders_.may_block(own.p.data(), own.count, s.normal, poly.p.data(), poly.count,
                                                 target.normal, epsilon_, s.polygon, target.polygon);
      v = shadowed ? kShadowed : kClear;
      slot.store(v, std::memory_order_relaxed);
    }
    return v == kShadowed;
  }

  // Visible fraction of the pair (visibility.hpp): V = sum_x F(dx -> j) V(x) / sum_x F(dx -> j)
  // over stratified source points x, each with its own stratified points y of the patch (a grid
  // pairing), where F(dx -> j) is the exact point factor and V(x) the kernel-weighted fraction of
  // x's clear rays. The exact F(dx -> j) is at hand here and is the right weight: its integral is
  // the unoccluded factor, and each V(x) lies in [0, 1], so a source point near a shared edge,
  // where the kernel has a 1/r^2 spike, cannot dominate the estimate. The samples have their own
  // stream per pair, so the result does not depend on which thread computes the pair or in which
  // order.
  //
  // The passes have S stratified source points times T rays each, sized in proportion to the
  // unoccluded factor F: max(n, min(256 n F, 1024)) rays first (n = ns nv), and when those
  // disagree (a penumbra) max(4 n, min(1024 n F, 4096)) more. Allocating rays in proportion to F
  // minimises the variance of sums of factors (a row, a group's factor, the gathered radiosity)
  // for a given number of rays: small factors keep ns x nv rays, large ones get up to 64 x 64.
  // (The Monte Carlo estimator's shadow rays have a fixed budget instead: see there.)
  double visible_fraction(const Source& s, const Receiver& to, double unoccluded, std::uint64_t& rays_cast) const {
    const Patch& target = hierarchy_.patches()[to.patch];
    const PatchCorners& poly = corners_[to.patch];
    const glm::vec3 nx = s.normal, ny = to.normal;
    const std::uint32_t ns = options_.source_samples, nv = options_.visibility_rays;
    // A pass of about `budget` rays: S = g^2 stratified source points, T = h^2 rays from each
    // (S <= 256, T <= 64); the smallest budget is exactly ns points x nv rays.
    auto pass = [&](double budget) {
      ShadowPass p{ns, nv};
      if (budget > static_cast<double>(ns * nv)) {
        p.points = static_cast<std::uint32_t>(std::clamp(std::lround(std::sqrt(std::sqrt(budget))), 1l, 16l));
        p.points *= p.points;
        const auto h = static_cast<std::uint32_t>(std::clamp(std::lround(std::sqrt(budget / p.points)), 1l, 8l));
        p.rays_per_point = h * h;
      }
      return p;
    };
    // The first pass grows with F too: a penumbra that blocks a fraction b of the pair escapes N
    // rays with probability (1 - b)^N, which costs at most about F / (e N) of the factor.
    const double base = static_cast<double>(ns * nv);
    auto rays_for = [&](double per_factor, double lo, double hi) {
      return std::max(lo, std::min(per_factor * base * unoccluded, hi));  // lo wins over hi
    };
    const ShadowBudget budget{pass(rays_for(256.0, base, 1024.0)), pass(rays_for(1024.0, 4.0 * base, 4096.0)),
                              ShadowPairing::grid};
    auto point_factor = [&](const glm::vec3& x, double) {
      return glm::dot(x - target.centroid, ny) > 0.0f
                 ? static_cast<double>(point_to_polygon_factor_fast(x, nx, poly.p.data(), poly.count))
                 : 0.0;
    };
    Rng rng(options_.seed, s.element, stream_key(s.back ? Stream::ray_cast_back : Stream::ray_cast_front, to.target));
    const VisibleFraction v =
        detail::visible_fraction(s.sampler, nx, poly.sampler, ny, epsilon_, budget, rng, *rays_, point_factor);
    rays_cast += v.rays;
    return v.value;
  }

  // The unoccluded factor F(e -> patch): the exact point-to-polygon factor integrated over the
  // element. Far pairs have a smooth integrand and one 2x2 Gauss rule suffices; near pairs
  // (shared edges, where the integrand has a logarithmic singularity) are refined adaptively
  // until two levels agree, so closed-enclosure rows sum to 1 and reciprocity holds to ~1e-4.
  double unoccluded_factor(const Source& s, const Patch& target, const glm::vec3& ny, const PatchCorners& poly) const {
    const glm::vec3 nx = s.normal;
    auto at = [&](const glm::vec3& x) -> double {
      if (glm::dot(x - target.centroid, ny) <= 0.0f) return 0.0;  // sees the receiver's back
      return point_to_polygon_factor_fast(x, nx, poly.p.data(), poly.count);
    };
    double coarse = 0.0;
    for (std::size_t k = 0; k < 4; ++k) coarse += 0.25 * s.density[k] * at(s.quadrature[k]);
    // Far from the receiver (distance over four times the two radii) the integrand varies by
    // less than ~1/16 across the element and the Gauss rule's O(h^4) error is far below the goal.
    const float gap = glm::length(target.centroid - s.centroid) - poly.radius;
    if (gap > 4.0f * (s.radius + poly.radius)) return coarse;
    // The 2x2 Gauss rule is O(h^4) accurate and the midpoint rule O(h^2): where they agree to
    // 1e-4, the Gauss value is good to about 1e-5 and no refinement is needed.
    const double midpoint = s.density[4] * at(s.quadrature[4]);
    if (std::fabs(coarse - midpoint) <= 10.0 * kAbsoluteTolerance) return coarse;
    auto g = [&](glm::vec2 st) -> double { return s.map.density(st) * at(s.map.point(st)); };
    // A square at depth d carries 4^-d of the element: its error matters in that proportion.
    return adaptive_gauss_mean(g, glm::vec2(0.0f), 1.0f, coarse, 0, kMaxDepth, kAbsoluteTolerance);
  }

  const PatchHierarchy& hierarchy_;
  FormFactorOptions options_;
  bool visibility_;
  std::optional<RayScene> rays_;
  ShaftCuller occluders_;
  std::unique_ptr<std::atomic<std::uint8_t>[]> verdicts_;
  mutable std::atomic<std::uint64_t> factors_{0}, shadowed_{0}, rays_cast_{0};
  float epsilon_ = 0.0f;
  std::vector<PatchCorners> corners_;
  std::vector<std::uint32_t> back_target_;  // per patch: its back target when translucent, else kNone
};

}  // namespace

bool ray_cast_counters(const FormFactorEstimator& estimator, RayCastCounters& out) {
  const auto* e = dynamic_cast<const SampledEstimator*>(&estimator);
  if (e == nullptr) return false;
  out = e->counters();
  return true;
}

std::unique_ptr<FormFactorEstimator> make_ray_cast_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                             const FormFactorOptions& options) {
  return std::make_unique<SampledEstimator>(scene, hierarchy, options, true);
}

std::unique_ptr<BackColumnEstimator> make_analytic_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                             const FormFactorOptions& options) {
  return std::make_unique<SampledEstimator>(scene, hierarchy, options, false);
}

}  // namespace radiosity::detail
