// Monte Carlo ray-shooting form factors: sparse rows in O(rays) per element.
// Based on: F. Sillion & C. Puech, "A general two-pass method integrating specular and diffuse
// reflection", SIGGRAPH 1989, and P. Shirley, "Radiosity via ray tracing", Graphics Gems II
// (1991) (form factors as the fraction of cosine-distributed rays that land on a patch);
// P. Shirley & K. Chiu, "A low distortion map between disk and square", JGT 2(3), 1997
// (stratified cosine directions); M. Cohen & J. Wallace, "Radiosity and Realistic Image
// Synthesis" (1993), sec. 4.9.
//
// F(e -> j) = 1/A_e integral over e integral over the hemisphere of V_j(x, w) cos(w)/pi dw dx,
// where V_j(x, w) is 1 when the ray from x in direction w first hits the front of patch j. Rays
// leave stratified points of the element in cosine-distributed directions from a second,
// shuffled stratification, so each entry is a hit count over the ray count: unbiased, and a
// closed enclosure's rows sum to 1 exactly. A patch hit by no ray has no entry, so a row has at
// most `hemisphere_rays` entries and costs O(rays), not O(patches).
//
// Small factors to bright patches are where this noise shows (a light seen from the floor is hit
// by a handful of rays). Factors to emitting patches are therefore taken from the accurate
// ray-cast estimator, and rays that land on an emitting patch are not counted (a split like the
// next-event estimation of path tracing): the row stays unbiased and the direct light is smooth.
//
// A column F(. -> i) (progressive refinement) is shot from patch i instead: with the same
// reasoning F(i -> e) is a hit fraction, and reciprocity gives F(e -> i) = F(i -> e) A_i / A_e.
// The patch shoots hemisphere_rays rays per element it holds, so each of its entries has the
// noise of the corresponding row entry.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <mutex>
#include <limits>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "detail/parallel.hpp"
#include "detail/rng.hpp"
#include "formfactor/estimators.hpp"
#include "formfactor/sampling.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity::detail {

namespace {

/// Cosine-distributed direction around +z from a point of [0,1)^2, by Shirley & Chiu's concentric
/// map to the disk and Malley's projection up to the hemisphere (strata stay compact).
glm::vec3 cosine_direction(glm::vec2 u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f, 1.0f};
  constexpr float kQuarterPi = 0.25f * glm::pi<float>();
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = kQuarterPi * (b / a);
  } else {
    r = b;
    phi = 2.0f * kQuarterPi - kQuarterPi * (a / b);
  }
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y))};
}

/// Tangents completing a unit normal to a right-handed frame (Duff et al., JCGT 2017).
void tangents(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

/// Hit counts per target, with the touched targets listed so that clearing costs O(hits).
class HitCounter {
 public:
  explicit HitCounter(std::size_t targets) : count_(targets, 0) {}
  void add(std::uint32_t target) {
    if (count_[target]++ == 0) touched_.push_back(target);
  }
  /// Appends (target, scale x count) in increasing target order and clears.
  template <typename Scale>
  void drain(std::vector<std::uint32_t>& index, std::vector<float>& value, const Scale& scale) {
    std::sort(touched_.begin(), touched_.end());
    for (std::uint32_t t : touched_) {
      index.push_back(t);
      value.push_back(scale(t, count_[t]));
      count_[t] = 0;
    }
    touched_.clear();
  }

 private:
  std::vector<std::uint32_t> count_;
  std::vector<std::uint32_t> touched_;
};

class MonteCarloEstimator final : public FormFactorEstimator {
 public:
  MonteCarloEstimator(const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options)
      : FormFactorEstimator(hierarchy.patches().size()),
        hierarchy_(hierarchy),
        options_(options),
        accurate_(make_ray_cast_estimator(scene, hierarchy, options)) {
    epsilon_ = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
    const auto& patches = hierarchy.patches();
    exact_.assign(patches.size(), 0);
    for (std::uint32_t j = 0; j < patches.size(); ++j) {
      const Rgb e = scene.material(scene.polygons()[patches[j].polygon].material).emission;
      if (std::max(e.x, std::max(e.y, e.z)) > 0.0f) {
        exact_[j] = 1;
        emitters_.push_back(j);
      }
    }
  }

  bool sparse() const override { return true; }

  std::size_t max_row_entries() const override {
    return std::min<std::size_t>(hierarchy_.patches().size(), options_.hemisphere_rays + emitters_.size());
  }

  void sparse_element_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const override {
    const std::size_t m = elements.size();
    out.assign(m, SparseFactors{});
    // The accurate part: one ray-cast column per emitting patch (parallel inside).
    std::vector<std::vector<std::pair<std::uint32_t, float>>> exact(m);
    if (!emitters_.empty()) {
      std::vector<float> column(m);
      for (std::uint32_t j : emitters_) {
        accurate_->patch_column(j, elements, column.data());
        for (std::size_t k = 0; k < m; ++k)
          if (column[k] > 0.0f) exact[k].emplace_back(j, column[k]);
      }
    }
    const std::shared_ptr<const RayScene> rays = leaf_scene();
    const std::uint32_t N = options_.hemisphere_rays;
    const float per_ray = 1.0f / static_cast<float>(N);
    parallel_for(options_.threads, m, 16, [&](std::size_t begin, std::size_t end) {
      HitCounter counter(hierarchy_.patches().size());
      Scratch scratch(N);
      std::vector<std::uint32_t> index;
      std::vector<float> value;
      for (std::size_t k = begin; k < end; ++k) {
        const std::uint32_t e = elements[k];
        const Element& el = hierarchy_.element(e);
        const Patch& source = hierarchy_.patches()[el.patch];
        Rng rng(options_.seed, e, 0x300000000ull);
        shoot(*rays, e, source, N, rng, scratch, [&](std::uint32_t leaf) {
          const std::uint32_t j = hierarchy_.element(leaf).patch;
          if (!exact_[j]) counter.add(j);
        });
        index.clear();
        value.clear();
        counter.drain(index, value, [&](std::uint32_t, std::uint32_t c) { return static_cast<float>(c) * per_ray; });
        merge(index, value, exact[k], out[k]);
      }
    });
  }

  void element_rows(const std::vector<std::uint32_t>& elements, float* out) const override {
    const std::size_t n = hierarchy_.patches().size();
    std::fill(out, out + elements.size() * n, 0.0f);
    std::vector<SparseFactors> rows;
    sparse_element_rows(elements, rows);
    for (std::size_t k = 0; k < rows.size(); ++k)
      for (std::size_t i = 0; i < rows[k].index.size(); ++i) out[k * n + rows[k].index[i]] = rows[k].value[i];
  }

  void sparse_patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                           SparseFactors& out) const override {
    out.index.clear();
    out.value.clear();
    if (exact_[patch]) {
      FormFactorEstimator::sparse_patch_column(patch, elements, out);
      return;
    }
    const std::shared_ptr<const RayScene> rays = leaf_scene();
    // Position of each element in `elements`, so hits on leaves map to output indices.
    std::vector<std::uint32_t> position(hierarchy_.elements().size(), kNone);
    for (std::size_t k = 0; k < elements.size(); ++k) position[elements[k]] = static_cast<std::uint32_t>(k);

    const Patch& source = hierarchy_.patches()[patch];
    const std::uint32_t root = source.root;
    // As many rays as the patch's elements would shoot for their rows, in chunks that run in
    // parallel with their own random streams; the counts are integers, so the sum does not
    // depend on the order.
    const std::uint64_t total = std::uint64_t{options_.hemisphere_rays} * leaves_under(root);
    constexpr std::uint32_t kChunk = 4096;
    const auto chunks = static_cast<std::size_t>((total + kChunk - 1) / kChunk);
    std::vector<std::vector<std::uint32_t>> hits(chunks);
    parallel_for(options_.threads, chunks, 1, [&](std::size_t begin, std::size_t end) {
      Scratch scratch(kChunk);
      for (std::size_t c = begin; c < end; ++c) {
        const auto count = static_cast<std::uint32_t>(std::min<std::uint64_t>(kChunk, total - c * kChunk));
        Rng rng(options_.seed, patch, 0x400000000ull + c);
        shoot(*rays, root, source, count, rng, scratch, [&](std::uint32_t leaf) {
          if (position[leaf] != kNone) hits[c].push_back(position[leaf]);
        });
      }
    });
    HitCounter counter(elements.size());
    for (const auto& h : hits)
      for (std::uint32_t k : h) counter.add(k);
    const double scale = static_cast<double>(source.area) / static_cast<double>(total);
    counter.drain(out.index, out.value, [&](std::uint32_t k, std::uint32_t c) {
      return static_cast<float>(scale * c / static_cast<double>(hierarchy_.element(elements[k]).area));
    });
  }

  void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    if (exact_[patch]) {
      accurate_->patch_column(patch, elements, out);
      return;
    }
    SparseFactors column;
    sparse_patch_column(patch, elements, column);
    std::fill(out, out + elements.size(), 0.0f);
    for (std::size_t i = 0; i < column.index.size(); ++i) out[column.index[i]] = column.value[i];
  }

 private:
  /// Per-thread sample buffers.
  struct Scratch {
    explicit Scratch(std::uint32_t n) : points(n), directions(n) {}
    std::vector<glm::vec2> points, directions;
  };

  /// Casts `count` cosine-distributed rays from stratified points of element `from` (of patch
  /// `source`) and calls hit(leaf) for each ray that first hits the front of another
  /// polygon's element.
  template <typename Hit>
  void shoot(const RayScene& rays, std::uint32_t from, const Patch& source, std::uint32_t count, Rng& rng,
             Scratch& scratch, const Hit& hit) const {
    if (scratch.points.size() < count) scratch = Scratch(count);
    stratified(count, rng, true, scratch.points.data());
    stratified(count, rng, true, scratch.directions.data());
    // Pair point strata with direction strata at random, so the 4D samples are stratified in
    // each 2D projection (a Latin-hypercube-like padding).
    for (std::uint32_t i = count; i > 1; --i) std::swap(scratch.directions[i - 1], scratch.directions[rng.next() % i]);
    const glm::vec3 n = source.normal;
    glm::vec3 t, b;
    tangents(n, t, b);
    const Element& el = hierarchy_.element(from);
    std::array<glm::vec3, 4> corners{};
    for (int k = 0; k < el.corner_count(); ++k)
      corners[static_cast<std::size_t>(k)] = hierarchy_.vertices()[el.corners[static_cast<std::size_t>(k)]];
    const CellSampler sampler(corners.data(), el.corner_count());  // as sample_point, constants hoisted
    for (std::uint32_t r = 0; r < count; ++r) {
      const glm::vec3 x = sampler(scratch.points[r]) + epsilon_ * n;
      const glm::vec3 local = cosine_direction(scratch.directions[r]);
      const glm::vec3 w = local.x * t + local.y * b + local.z * n;
      const std::optional<RayScene::Hit> h = rays.intersect(x, w, 0.0f, std::numeric_limits<float>::infinity());
      if (!h) continue;  // escaped (an open scene)
      const Element& target = hierarchy_.element(h->id);
      const Patch& receiver = hierarchy_.patches()[target.patch];
      // The back of a one-sided surface absorbs; a hit on the source's own plane is rounding.
      if (glm::dot(w, receiver.normal) >= 0.0f || receiver.polygon == source.polygon) continue;
      hit(h->id);
    }
  }

  /// Merges two index-sorted entry lists into `out`.
  static void merge(const std::vector<std::uint32_t>& index, const std::vector<float>& value,
                    const std::vector<std::pair<std::uint32_t, float>>& exact, SparseFactors& out) {
    out.index.reserve(index.size() + exact.size());
    out.value.reserve(index.size() + exact.size());
    std::size_t a = 0, b = 0;
    while (a < index.size() || b < exact.size()) {
      if (b == exact.size() || (a < index.size() && index[a] < exact[b].first)) {
        out.index.push_back(index[a]);
        out.value.push_back(value[a++]);
      } else {
        out.index.push_back(exact[b].first);
        out.value.push_back(exact[b++].second);
      }
    }
  }

  std::uint32_t leaves_under(std::uint32_t element) const {
    const Element& el = hierarchy_.element(element);
    if (el.is_leaf()) return 1;
    std::uint32_t sum = 0;
    for (std::uint32_t c = 0; c < 4; ++c) sum += leaves_under(el.first_child + c);
    return sum;
  }

  /// The Embree scene of the current leaves (element ids), rebuilt after the hierarchy was
  /// refined: a column must land on the leaves that exist now.
  std::shared_ptr<const RayScene> leaf_scene() const {
    std::lock_guard<std::mutex> lock(leaf_mutex_);
    if (!leaf_rays_ || leaf_count_ != hierarchy_.leaves().size()) {
      leaf_rays_ = std::make_shared<const RayScene>(RayScene::from_leaves(hierarchy_));
      leaf_count_ = hierarchy_.leaves().size();
    }
    return leaf_rays_;
  }

  const PatchHierarchy& hierarchy_;
  FormFactorOptions options_;
  std::unique_ptr<FormFactorEstimator> accurate_;
  std::vector<std::uint8_t> exact_;     ///< per patch: 1 when its factors come from accurate_
  std::vector<std::uint32_t> emitters_;  ///< the patches with exact_ set, increasing
  float epsilon_ = 0.0f;
  mutable std::mutex leaf_mutex_;
  mutable std::shared_ptr<const RayScene> leaf_rays_;
  mutable std::size_t leaf_count_ = 0;
};

}  // namespace

std::unique_ptr<FormFactorEstimator> make_monte_carlo_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                                const FormFactorOptions& options) {
  return std::make_unique<MonteCarloEstimator>(scene, hierarchy, options);
}

}  // namespace radiosity::detail
