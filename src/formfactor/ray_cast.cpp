// Ray-cast and analytic element-to-patch form factors.
// Based on: Wallace, Elmquist & Haines, "A ray tracing algorithm for progressive radiosity",
// SIGGRAPH 1989 (sampling the source, visibility by rays); Baum, Rushmeier & Winget, SIGGRAPH 1989
// (the exact point-to-polygon factor for the unoccluded part); Cohen & Wallace 1993, ch. 4.
//
// F(e -> j) = 1/A_e  integral over e of  F(dx -> j) V(x, j) dx.
// For each stratified point x on the element, F(dx -> j) is evaluated exactly by the contour
// integral (so nearness and shared edges cost no accuracy), and V(x, j) is the fraction of the
// patch visible from x, estimated by occlusion rays to stratified points y on the patch and
// weighted by the point-to-point kernel cos(theta_x) cos(theta_y) / r^2. In an unoccluded
// configuration the estimate is therefore the exact factor up to the quadrature over e.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>

#include "detail/parallel.hpp"
#include "detail/rng.hpp"
#include "formfactor/estimators.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity {
inline namespace v1 {
FormFactorEstimator::~FormFactorEstimator() = default;
}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

namespace {

// Stratified points on [0,1]^2: a jittered g x g grid when count is a square, otherwise
// stratified along u with random v.
void stratified(std::uint32_t count, Rng& rng, bool jitter, glm::vec2* out) {
  auto g = static_cast<std::uint32_t>(std::lround(std::sqrt(static_cast<double>(count))));
  if (g * g == count) {
    for (std::uint32_t i = 0; i < g; ++i)
      for (std::uint32_t k = 0; k < g; ++k) {
        glm::vec2 u = jitter ? rng.uniform2() : glm::vec2(0.5f);
        out[i * g + k] = glm::vec2((static_cast<float>(i) + u.x) / static_cast<float>(g),
                                   (static_cast<float>(k) + u.y) / static_cast<float>(g));
      }
  } else {
    for (std::uint32_t i = 0; i < count; ++i) {
      glm::vec2 u = jitter ? rng.uniform2() : glm::vec2(0.5f);
      out[i] = glm::vec2((static_cast<float>(i) + u.x) / static_cast<float>(count), u.y);
    }
  }
}

class SampledEstimator final : public FormFactorEstimator {
 public:
  SampledEstimator(const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options,
                   bool with_visibility)
      : hierarchy_(hierarchy), options_(options), visibility_(with_visibility) {
    if (visibility_) rays_.emplace(RayScene::from_polygons(scene));
    // Offsets keep ray end points off the surfaces they start and end on.
    epsilon_ = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
    const auto& patches = hierarchy.patches();
    corners_.resize(patches.size());
    for (std::size_t j = 0; j < patches.size(); ++j) {
      const Element& root = hierarchy.element(patches[j].root);
      PatchCorners& c = corners_[j];
      c.count = root.corner_count();
      for (int k = 0; k < c.count; ++k) {
        c.p[k] = hierarchy.vertices()[root.corners[k]];
        c.radius = std::max(c.radius, glm::length(c.p[k] - patches[j].centroid));
      }
    }
  }

  void element_rows(const std::vector<std::uint32_t>& elements, float* out) const override {
    const std::size_t n = hierarchy_.patches().size();
    parallel_for(options_.threads, elements.size(), 4, [&](std::size_t begin, std::size_t end) {
      std::array<glm::vec3, 64> points;
      for (std::size_t k = begin; k < end; ++k) {
        source_points(elements[k], points.data());
        for (std::size_t j = 0; j < n; ++j)
          out[k * n + j] = static_cast<float>(factor(elements[k], static_cast<std::uint32_t>(j), points.data()));
      }
    });
  }

  void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    parallel_for(options_.threads, elements.size(), 64, [&](std::size_t begin, std::size_t end) {
      std::array<glm::vec3, 64> points;
      for (std::size_t k = begin; k < end; ++k) {
        source_points(elements[k], points.data());
        out[k] = static_cast<float>(factor(elements[k], patch, points.data()));
      }
    });
  }

 private:
  static constexpr int kMaxDepth = 5;
  // Absolute accuracy goal of each unoccluded factor: rows of a closed enclosure then sum to 1
  // within about 1e-4 even with tens of near neighbours.
  static constexpr double kAbsoluteTolerance = 1e-5;

  struct PatchCorners {
    std::array<glm::vec3, 4> p{};
    int count = 0;
    float radius = 0.0f;  ///< largest distance from the patch centroid to a corner
  };

  // The points on element e at which F(dx -> j) is evaluated. They depend on e only, not on the
  // receiver, so in an unoccluded closed scene each row sums to exactly 1 whatever the
  // quadrature error of the individual factors.
  void source_points(std::uint32_t e, glm::vec3* out) const {
    std::array<glm::vec2, 64> uv;
    Rng rng(options_.seed, e, 0x5eed5eedull);
    stratified(options_.source_samples, rng, visibility_, uv.data());
    for (std::uint32_t s = 0; s < options_.source_samples; ++s) out[s] = hierarchy_.sample_point(e, uv[s]);
  }

  double factor(std::uint32_t e, std::uint32_t j, const glm::vec3* points) const {
    const Element& el = hierarchy_.element(e);
    const Patch& source_patch = hierarchy_.patches()[el.patch];
    const Patch& target = hierarchy_.patches()[j];
    // Patches of one planar polygon cannot see each other.
    if (source_patch.polygon == target.polygon) return 0.0;
    const glm::vec3 nx = source_patch.normal, ny = target.normal;
    const PatchCorners& poly = corners_[j];

    // Whole-pair culling: the receiver entirely below the element's plane, or the element
    // entirely behind the receiver.
    bool any_above = false;
    for (int k = 0; k < poly.count; ++k) any_above |= glm::dot(poly.p[k] - el.centroid, nx) > epsilon_;
    if (!any_above) return 0.0;
    bool any_in_front = false;
    for (int k = 0; k < el.corner_count(); ++k)
      any_in_front |= glm::dot(hierarchy_.vertices()[el.corners[k]] - target.centroid, ny) > epsilon_;
    if (!any_in_front) return 0.0;

    const double unoccluded = unoccluded_factor(el, target, poly);
    if (!visibility_ || unoccluded <= 0.0) return unoccluded;

    // Visible fraction of the pair: occlusion rays between stratified points, each weighted by
    // the point-to-point kernel cos(theta_x) cos(theta_y) / r^2 so that the fraction measures
    // transport, not solid angle. Visibility samples have their own stream per pair, so the
    // result does not depend on which thread computes the pair or in which order.
    const std::uint32_t ns = options_.source_samples, nv = options_.visibility_rays;
    Rng rng(options_.seed, e, 0x100000000ull + j);
    std::array<glm::vec2, 64> target_uv;
    double weight_sum = 0.0, visible_weight = 0.0;
    std::uint32_t tested = 0, visible_count = 0;
    for (std::uint32_t s = 0; s < ns; ++s) {
      const glm::vec3& x = points[s];
      stratified(nv, rng, true, target_uv.data());
      const glm::vec3 origin = x + epsilon_ * nx;
      for (std::uint32_t t = 0; t < nv; ++t) {
        const glm::vec3 y = hierarchy_.sample_point(target.root, target_uv[t]);
        const glm::vec3 d = (y + epsilon_ * ny) - origin;
        const float r2 = glm::dot(d, d);
        if (!(r2 > 0.0f)) continue;
        const float w = std::max(0.0f, glm::dot(d, nx)) * std::max(0.0f, -glm::dot(d, ny)) / (r2 * r2);
        const bool visible = !rays_->occluded(origin, d, 0.0f, 1.0f - 1e-4f);
        ++tested;
        visible_count += visible ? 1u : 0u;
        weight_sum += w;
        visible_weight += visible ? w : 0.0f;
      }
    }
    // All sampled segments grazing (weight 0): fall back to the plain fraction of clear rays.
    const double v = weight_sum > 0.0 ? visible_weight / weight_sum
                                      : (tested > 0 ? static_cast<double>(visible_count) / tested : 1.0);
    return unoccluded * v;
  }

  // Gauss-Legendre 2x2 on the square [lo, lo + size]^2 of the element's (u,v) domain, which
  // sample_point() maps area-uniformly onto the element: the mean of F(dx -> patch) over it.
  template <typename G>
  static double gauss_2x2(const G& g, glm::vec2 lo, float size) {
    constexpr float a = 0.5f - 0.28867513459481287f, b = 0.5f + 0.28867513459481287f;
    return 0.25 * (g(lo + size * glm::vec2(a, a)) + g(lo + size * glm::vec2(b, a)) + g(lo + size * glm::vec2(a, b)) +
                   g(lo + size * glm::vec2(b, b)));
  }

  template <typename G>
  static double adaptive(const G& g, glm::vec2 lo, float size, double coarse, int depth) {
    const float h = 0.5f * size;
    const glm::vec2 corner[4] = {lo, lo + glm::vec2(h, 0.0f), lo + glm::vec2(0.0f, h), lo + glm::vec2(h, h)};
    double q[4], fine = 0.0;
    for (int k = 0; k < 4; ++k) fine += 0.25 * (q[k] = gauss_2x2(g, corner[k], h));
    // A square at depth d carries 4^-d of the element: its error matters in that proportion.
    if (depth >= kMaxDepth || std::ldexp(std::fabs(fine - coarse), -2 * depth) <= kAbsoluteTolerance) return fine;
    double sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += 0.25 * adaptive(g, corner[k], h, q[k], depth + 1);
    return sum;
  }

  // The unoccluded factor F(e -> patch): the exact point-to-polygon factor integrated over the
  // element. Far pairs have a smooth integrand and one 2x2 Gauss rule suffices; near pairs
  // (shared edges, where the integrand has a logarithmic singularity) are refined adaptively
  // until two levels agree, so closed-enclosure rows sum to 1 and reciprocity holds to ~1e-4.
  double unoccluded_factor(const Element& el, const Patch& target, const PatchCorners& poly) const {
    const glm::vec3 nx = hierarchy_.patches()[el.patch].normal, ny = target.normal;
    const std::uint32_t e = static_cast<std::uint32_t>(&el - hierarchy_.elements().data());
    auto g = [&](glm::vec2 uv) -> double {
      const glm::vec3 x = hierarchy_.sample_point(e, uv);
      if (glm::dot(x - target.centroid, ny) <= 0.0f) return 0.0;  // sees the receiver's back
      return point_to_polygon_factor(x, nx, poly.p.data(), poly.count);
    };
    // The 2x2 Gauss rule is O(h^4) accurate and the midpoint rule O(h^2): where they agree to
    // 1 %, the Gauss value is good to about 1e-4 and no refinement is needed.
    const double coarse = gauss_2x2(g, glm::vec2(0.0f), 1.0f);
    const double midpoint = g(glm::vec2(0.5f));
    if (std::fabs(coarse - midpoint) <= 10.0 * kAbsoluteTolerance) return coarse;
    return adaptive(g, glm::vec2(0.0f), 1.0f, coarse, 0);
  }

  const PatchHierarchy& hierarchy_;
  FormFactorOptions options_;
  bool visibility_;
  std::optional<RayScene> rays_;
  float epsilon_ = 0.0f;
  std::vector<PatchCorners> corners_;
};

}  // namespace

std::unique_ptr<FormFactorEstimator> make_ray_cast_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                             const FormFactorOptions& options) {
  return std::make_unique<SampledEstimator>(scene, hierarchy, options, true);
}

std::unique_ptr<FormFactorEstimator> make_analytic_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                             const FormFactorOptions& options) {
  return std::make_unique<SampledEstimator>(scene, hierarchy, options, false);
}

}  // namespace radiosity::detail
