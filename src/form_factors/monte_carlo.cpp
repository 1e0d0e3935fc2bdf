// Monte Carlo ray-shooting form factors: sparse rows in O(rays) per element.
// Based on: F. Sillion & C. Puech, "A general two-pass method integrating specular and diffuse
// reflection", SIGGRAPH 1989, and P. Shirley, "Radiosity via ray tracing", Graphics Gems II
// (1991) (form factors as the fraction of cosine-distributed rays that land on a patch);
// P. Shirley & K. Chiu, "A low distortion map between disk and square", JGT 2(3), 1997
// (cosine directions that keep the square's spread); M. Cohen & J. Wallace, "Radiosity and
// Realistic Image Synthesis" (1993), sec. 4.9; J. H. Halton (1960) randomised by Cranley &
// Patterson (1976): the rays' points and directions (core/halton.hpp).
//
// F(e -> j) = 1/A_e integral over e integral over the hemisphere of V_j(x, w) cos(w)/pi dw dx,
// where V_j(x, w) is 1 when the ray from x in direction w first hits the front of patch j. Rays
// leave points of the element in cosine-distributed directions, both from one randomised 4D
// Halton set, so each entry is a hit count over the ray count: unbiased, and a
// closed enclosure's rows sum to 1 exactly. A patch hit by no ray has no entry, so a row has at
// most `hemisphere_rays` entries and costs O(rays), not O(patches).
//
// Small factors to bright patches are where this noise shows (a light seen from the floor is hit
// by a handful of rays). Factors to emitting patches are therefore computed apart, and rays that
// land on an emitting patch are not counted (a split like the next-event estimation of path
// tracing): F(e -> j) = F_unoccluded(e -> j) x V(e, P), the exact contour-integral factor of the
// analytic estimator times the visible fraction of j's whole polygon P, estimated by shadow rays
// between stratified points of e and P weighted by the point-to-point kernel (none when a shaft
// test shows that nothing can come between). One visibility per (element, emitting polygon)
// instead of per (element, emitting patch) is what keeps this cheap on fine meshes; an emitting
// polygon's patches have nearly equal radiosity, so sharing its visible fraction costs little.
//
// A column F(. -> i) (progressive refinement) is shot from patch i instead: with the same
// reasoning F(i -> e) is a hit fraction, and reciprocity gives F(e -> i) = F(i -> e) A_i / A_e.
// The patch shoots hemisphere_rays rays per element it holds, so each of its entries has the
// noise of the corresponding row entry.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "core/assert.hpp"
#include "core/frame.hpp"
#include "core/halton.hpp"
#include "core/sampling.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "form_factors/estimators.hpp"
#include "radiosity/brdf.hpp"
#include "form_factors/sampling.hpp"
#include "form_factors/shaft.hpp"
#include "form_factors/visibility.hpp"
#include "geometry/burial.hpp"
#include "geometry/polygon_fan.hpp"
#include "geometry/ray_scene.hpp"
#include "form_factors/pass1_material.hpp"
#include "core/streams.hpp"
#include "core/color.hpp"

namespace radiosity::detail {

namespace {

/// Area-uniform points over a set of patches taken as one surface, from [0,1)^2 with strata
/// kept: u picks the patch by its share of the total area and is rescaled within it, v is kept;
/// each patch's points come from its root element's CellSampler.
class PatchSetSampler {
 public:
  PatchSetSampler(const PatchHierarchy& hierarchy, const std::vector<std::uint32_t>& patches) {
    cells_.reserve(patches.size());
    cumulative_.reserve(patches.size() + 1);
    cumulative_.push_back(0.0f);
    for (const std::uint32_t j : patches) {
      const Element& root = hierarchy.element(hierarchy.patches()[j].root);
      std::array<glm::vec3, 4> corners{};
      for (int k = 0; k < root.corner_count(); ++k)
        corners[static_cast<std::size_t>(k)] = hierarchy.vertices()[root.corners[static_cast<std::size_t>(k)]];
      cells_.emplace_back(corners.data(), root.corner_count());
      cumulative_.push_back(cumulative_.back() + hierarchy.patches()[j].area);
    }
  }
  glm::vec3 operator()(glm::vec2 uv) const {
    RADIOSITY_ASSERT(!cells_.empty());
    const float target = uv.x * cumulative_.back();
    // The last patch whose share starts at or before the target (a few patches: a linear walk).
    std::size_t k = 0;
    while (k + 1 < cells_.size() && cumulative_[k + 1] <= target) ++k;
    const float share = cumulative_[k + 1] - cumulative_[k];
    const float u = share > 0.0f ? std::clamp((target - cumulative_[k]) / share, 0.0f, 0.99999994f) : 0.5f;
    return cells_[k](glm::vec2(u, uv.y));
  }

 private:
  std::vector<CellSampler> cells_;
  std::vector<float> cumulative_;
};

/// Hit weights per target, with the touched targets listed so that clearing costs O(hits).
/// Weights are > 0 (1 for a plain hit, less after mirrors and windows).
class HitCounter {
 public:
  explicit HitCounter(std::size_t targets) : sum_(targets, 0.0f) {}
  void add(std::uint32_t target, float weight) {
    if (sum_[target] == 0.0f) touched_.push_back(target);
    sum_[target] += weight;
  }
  /// Appends (target, scale(target, sum)) in increasing target order and clears.
  template <typename Scale>
  void drain(std::vector<std::uint32_t>& index, std::vector<float>& value, const Scale& scale) {
    // Many distinct targets: walking the sums in order is cheaper than sorting.
    if (touched_.size() * 64 > sum_.size()) {
      for (std::uint32_t t = 0; t < sum_.size(); ++t)
        if (sum_[t] != 0.0f) {
          index.push_back(t);
          value.push_back(scale(t, sum_[t]));
          sum_[t] = 0.0f;
        }
    } else {
      std::sort(touched_.begin(), touched_.end());
      for (std::uint32_t t : touched_) {
        index.push_back(t);
        value.push_back(scale(t, sum_[t]));
        sum_[t] = 0.0f;
      }
    }
    touched_.clear();
  }

 private:
  std::vector<float> sum_;
  std::vector<std::uint32_t> touched_;
};

class MonteCarloEstimator final : public FormFactorEstimator {
 public:
  MonteCarloEstimator(const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options)
      : FormFactorEstimator(hierarchy.patches().size()),
        hierarchy_(hierarchy),
        options_(options),
        analytic_(make_analytic_estimator(scene, hierarchy, options)) {
    epsilon_ = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
    backs_inside_ = RayScene::backs_inside(scene, hierarchy);
    const auto& patches = hierarchy.patches();
    const auto& polygons = scene.polygons();
    specular_depth_ = options.specular_depth;
    specular_.resize(polygons.size());
    for (std::size_t p = 0; p < polygons.size(); ++p) {
      const Material& m = scene.material(polygons[p].material);
      specular_[p].mirror = pass1_mirror(m);
      specular_[p].window = pass1_window(m);
      specular_[p].glass = pass1_glass(m);
      specular_[p].ior = m.ior;
    }
    if (options.diffuse_transmission) set_translucent_patches(find_back_patches(scene, hierarchy));
    back_target_ = back_targets(patches.size(), translucent_patches());
    // Backs are never exact: those of two-sided emitters are counted by the rays that reach them.
    exact_.assign(target_count(), 0);
    emitter_of_.assign(patches.size(), kNone);
    emitter_power_.assign(patches.size(), 0.0f);
    std::vector<std::uint32_t> polygon_slot(polygons.size(), kNone);
    for (std::uint32_t j = 0; j < patches.size(); ++j) {
      const PolygonId pid = patches[j].polygon;
      const Rgb e = scene.material(polygons[pid].material).emission;
      if (max_channel(e) <= 0.0f) continue;
      exact_[j] = 1;
      emitters_.push_back(j);
      emitter_power_[j] = e.x + e.y + e.z;
      if (polygon_slot[pid] == kNone) {
        polygon_slot[pid] = static_cast<std::uint32_t>(lights_.size());
        lights_.emplace_back(pid, polygons[pid]);
      }
      emitter_of_[j] = polygon_slot[pid];
      ++lights_[polygon_slot[pid]].patches;
    }
    if (!lights_.empty()) {
      shadow_rays_.emplace(RayScene::from_polygons(scene));
      std::vector<std::vector<glm::vec3>> corners;
      std::vector<glm::vec3> normals;
      for (const Polygon& p : polygons) {
        corners.push_back(p.vertices);
        normals.push_back(p.normal);
      }
      occluders_ = ShaftCuller(corners, normals);
      visible_.resize(lights_.size());
      visible_back_.resize(lights_.size());
    }
  }

  bool sparse() const override { return true; }

  std::size_t max_row_entries() const override {
    return std::min<std::size_t>(target_count(), options_.hemisphere_rays + emitters_.size());
  }

  void sparse_element_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const override {
    rows(elements, false, out);
  }

  void sparse_back_rows(const std::vector<std::uint32_t>& elements, std::vector<SparseFactors>& out) const override {
    check_back_rows(*this, hierarchy_, elements);
    rows(elements, true, out);
  }

  /// Dense rows keep to the fronts of patches (FormFactorOptions::diffuse_transmission).
  void element_rows(const std::vector<std::uint32_t>& elements, float* out) const override {
    const std::size_t n = hierarchy_.patches().size();
    std::fill(out, out + elements.size() * n, 0.0f);
    std::vector<SparseFactors> rows;
    sparse_element_rows(elements, rows);
    for (std::size_t k = 0; k < rows.size(); ++k)
      for (std::size_t i = 0; i < rows[k].index.size() && rows[k].index[i] < n; ++i)
        out[k * n + rows[k].index[i]] = rows[k].value[i];
  }

  void sparse_patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements,
                           SparseFactors& out) const override {
    out.index.clear();
    out.value.clear();
    check_target(*this, patch);
    if (exact_[patch]) {
      std::vector<float> column(elements.size());
      SparseFactors backs;
      emitter_column(patch, elements, column.data(), &backs);
      compress(column.data(), column.size(), out);
      // Arrivals at backs: indices past the fronts, already increasing.
      out.index.insert(out.index.end(), backs.index.begin(), backs.index.end());
      out.value.insert(out.value.end(), backs.value.begin(), backs.value.end());
      return;
    }
    const std::shared_ptr<const LeafRays> rays = leaf_scene();
    shot_column(patch, elements, positions(elements), *rays, options_.threads, false, out);
  }

  void sparse_patch_columns(const std::vector<std::uint32_t>& patches, const std::vector<std::uint32_t>& elements,
                            std::vector<SparseFactors>& out) const override {
    out.assign(patches.size(), SparseFactors{});
    std::vector<std::size_t> shot;
    for (std::size_t k = 0; k < patches.size(); ++k) {
      if (patches[k] >= target_count() || exact_[patches[k]])
        sparse_patch_column(patches[k], elements, out[k]);  // parallel inside
      else
        shot.push_back(k);
    }
    if (shot.empty()) return;
    // One column per task: small columns cannot use two threads each, several at once can.
    const std::shared_ptr<const LeafRays> rays = leaf_scene();
    const std::vector<std::uint32_t> position = positions(elements);
    parallel_for(options_.threads, shot.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        shot_column(patches[shot[i]], elements, position, *rays, 1, false, out[shot[i]]);
    });
  }

  /// Dense columns keep to patches and to the fronts of elements.
  void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    if (exact_[patch]) {
      emitter_column(patch, elements, out, nullptr);
      return;
    }
    SparseFactors column;
    sparse_patch_column(patch, elements, column);
    std::fill(out, out + elements.size(), 0.0f);
    for (std::size_t i = 0; i < column.index.size() && column.index[i] < elements.size(); ++i)
      out[column.index[i]] = column.value[i];
  }

 private:
  /// The current leaves as an Embree scene (ids: element ids), with each triangle's patch and
  /// polygon in compact arrays.
  struct LeafRays {
    RayScene scene;
    std::vector<std::uint32_t> patch, polygon;  ///< per triangle
    std::vector<std::uint32_t> back;            ///< per triangle: its patch's back target, or kNone
  };

  /// An emitting polygon, as a target of shadow rays.
  struct Light {
    Light(PolygonId polygon_id, const Polygon& source)
        : polygon(polygon_id), vertices(source.vertices), normal(source.normal), fan(source.vertices) {}
    PolygonId polygon;
    std::vector<glm::vec3> vertices;
    glm::vec3 normal;
    PolygonFan fan;  ///< area-uniform points, strata kept
    std::uint32_t patches = 0;  ///< how many patches the polygon is meshed into
  };

  /// The rows of the elements' fronts, or of their backs when `back` (backward form factors).
  void rows(const std::vector<std::uint32_t>& elements, bool back, std::vector<SparseFactors>& out) const {
    const std::size_t m = elements.size();
    out.assign(m, SparseFactors{});
    const std::shared_ptr<const LeafRays> rays = leaf_scene();
    const std::uint32_t N = options_.hemisphere_rays;
    const float per_ray = 1.0f / static_cast<float>(N);
    // One parallel loop does everything for a run of elements. The analytic estimator's loops
    // inside it are nested parallel_for calls, which core/parallel.hpp runs isolated (a waiting
    // thread takes no outer task), and a run's few elements make each of them one chunk.
    const bool limited = options_.exact_emitters > 0 && emitters_.size() > options_.exact_emitters;
    parallel_for(options_.threads, m, 8, [&](std::size_t begin, std::size_t end) {
      HitCounter counter(target_count());
      Scratch scratch(N);
      std::vector<std::uint32_t> index, run(elements.begin() + static_cast<std::ptrdiff_t>(begin),
                                             elements.begin() + static_cast<std::ptrdiff_t>(end));
      std::vector<float> value, column(run.size()), fraction(lights_.size());
      std::vector<std::uint32_t> subset;  // one light's exact patches for the element at hand
      std::vector<std::vector<std::pair<std::uint32_t, float>>> exact(run.size());
      // Emitting patches left to the rays for the element at hand (only when some are).
      std::vector<std::uint8_t> by_rays;
      if (limited) by_rays.assign(target_count(), 0);
      if (!limited) {
        // Every emitting patch exact: unoccluded factors, column by column over the run...
        for (std::uint32_t j : emitters_) {
          if (back)
            analytic_->back_column(j, run, column.data());
          else
            analytic_->patch_column(j, run, column.data());
          for (std::size_t k = 0; k < run.size(); ++k)
            if (column[k] > 0.0f) exact[k].emplace_back(j, column[k]);
        }
      }
      std::vector<std::pair<float, std::uint32_t>> ranked;
      for (std::size_t k = begin; k < end; ++k) {
        auto& own = exact[k - begin];
        if (limited) {
          // ... or the exact_emitters patches that send the element the most (a centroid
          // estimate ranks them), the rest counted by the rays below.
          ranked.clear();
          const Element& el = hierarchy_.element(elements[k]);
          const glm::vec3 n = back ? -hierarchy_.patches()[el.patch].normal : hierarchy_.patches()[el.patch].normal;
          for (std::uint32_t j : emitters_) {
            const Patch& p = hierarchy_.patches()[j];
            const glm::vec3 d = p.centroid - el.centroid;
            const float r2 = glm::dot(d, d);
            const float c = std::max(0.0f, glm::dot(d, n)) * std::max(0.0f, -glm::dot(d, p.normal));
            if (!(c > 0.0f) || !(r2 > 0.0f)) continue;
            ranked.emplace_back(emitter_power_[j] * p.area * c / (r2 * r2), j);
          }
          const std::size_t keep = std::min<std::size_t>(ranked.size(), options_.exact_emitters);
          // Strongest first; ties by patch id, so the choice does not depend on the sort.
          auto stronger = [](const auto& a, const auto& b) {
            return a.first > b.first || (a.first == b.first && a.second < b.second);
          };
          std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end(), stronger);
          for (std::uint32_t j : emitters_) by_rays[j] = 1;
          const std::vector<std::uint32_t> one{elements[k]};
          for (std::size_t i = 0; i < keep; ++i) {
            const std::uint32_t j = ranked[i].second;
            by_rays[j] = 0;
            float f = 0.0f;
            if (back)
              analytic_->back_column(j, one, &f);
            else
              analytic_->patch_column(j, one, &f);
            if (f > 0.0f) own.emplace_back(j, f);
          }
          std::sort(own.begin(), own.end());
        }
        // ... times the element's visible fraction of each emitting polygon it faces: of the
        // whole polygon where all its patches are exact here, else of the exact ones only (the
        // others' light comes by the rays), whose factors it multiplies. (Until session 20 the
        // whole polygon's always: where the element saw the polygon's near, exact patches
        // hidden and its far ones clear, or the reverse, their light came out by the whole
        // polygon's share; the Cornell box at 4000 elements, whose lamp is 28 patches, lost
        // 2.5 % of the floor's direct light, 15-33 % on elements in the blocks' penumbrae.)
        std::fill(fraction.begin(), fraction.end(), -1.0f);
        for (auto& [j, f] : own) {
          float& v = fraction[emitter_of_[j]];
          if (v < 0.0f) {
            const std::uint32_t light = emitter_of_[j];
            subset.clear();
            if (limited)
              for (const auto& [i, g] : own)
                if (emitter_of_[i] == light) subset.push_back(i);
            v = static_cast<float>(!limited || subset.size() == lights_[light].patches
                                       ? visibility(elements[k], light, back)
                                       : visibility(elements[k], light, back, &subset));
          }
          f *= v;
        }
        own.erase(std::remove_if(own.begin(), own.end(), [](const auto& x) { return !(x.second > 0.0f); }),
                  own.end());
        // Everything else: the hit fractions of the rays.
        const std::uint32_t e = elements[k];
        const Patch& source = hierarchy_.patches()[hierarchy_.element(e).patch];
        Rng rng(options_.seed, e, stream_key(back ? Stream::monte_carlo_back_row : Stream::monte_carlo_row));
        std::uint32_t buried_rays = 0;
        shoot(
            *rays, e, source, back, N, rng, scratch,
            [&](std::uint32_t, std::uint32_t j, float w, Path path) {
              // Emitting patches reached directly are in the exact part (unless left to the rays for
              // this element), through glass in the photon map (unless emitted_through_glass).
              if (!exact_[j] || (limited && by_rays[j]) || carried_from_emitter(path)) counter.add(j, w);
            },
            &buried_rays);
        index.clear();
        value.clear();
        counter.drain(index, value, [&](std::uint32_t, float c) { return c * per_ray; });
        merge(index, value, own, out[k]);
        out[k].exposed = static_cast<float>(N - buried_rays) * per_ray;
      }
    });
  }

  /// F(e -> emitting patch) for each element: unoccluded factor times the element's visible
  /// fraction of the patch's polygon, the latter kept per element for later columns. With
  /// `backs`, the arrivals at the backs of translucent elements (the same from their backs) are
  /// appended to it as sparse entries (indices elements.size() + k, increasing).
  void emitter_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out,
                      SparseFactors* backs) const {
    analytic_->patch_column(patch, elements, out);
    const std::uint32_t light = emitter_of_[patch];
    times_visibility(light, false, elements, out);
    // Arrivals at the backs of translucent elements: exact as well (backward factors).
    std::vector<float> back;
    if (backs && !translucent_patches().empty()) {
      std::vector<std::uint32_t> translucent, where;
      for (std::size_t k = 0; k < elements.size(); ++k)
        if (back_target_[hierarchy_.element(elements[k]).patch] != kNone) {
          translucent.push_back(elements[k]);
          where.push_back(static_cast<std::uint32_t>(k));
        }
      std::vector<float> column(translucent.size());
      analytic_->back_column(patch, translucent, column.data());
      times_visibility(light, true, translucent, column.data());
      back.assign(elements.size(), 0.0f);
      for (std::size_t k = 0; k < translucent.size(); ++k) back[where[k]] = column[k];
    }
    if (specular_depth_ > 0) {
      // What the patch sends through mirrors and windows is shot like any other patch's.
      SparseFactors extra;
      const std::shared_ptr<const LeafRays> rays = leaf_scene();
      shot_column(patch, elements, positions(elements), *rays, options_.threads, true, extra);
      for (std::size_t i = 0; i < extra.index.size(); ++i) {
        if (extra.index[i] < elements.size())
          out[extra.index[i]] += extra.value[i];
        else if (!back.empty())
          back[extra.index[i] - elements.size()] += extra.value[i];
      }
    }
    for (std::size_t k = 0; k < back.size(); ++k)
      if (back[k] > 0.0f) {
        backs->index.push_back(static_cast<std::uint32_t>(elements.size() + k));
        backs->value.push_back(back[k]);
      }
  }

  /// Multiplies each factor column[k] > 0 of elements[k] by the element's visible fraction of
  /// light polygon `light` (from its back when `back`), kept per element for later columns.
  /// The lock guards the cache only: the missing fractions are computed in parallel without it
  /// and published after. Each is a function of its (element, light) stream alone, so a value
  /// computed twice by concurrent calls is the same, and no result depends on the order of the
  /// calls or the thread count.
  void times_visibility(std::uint32_t light, bool back, const std::vector<std::uint32_t>& elements,
                        float* column) const {
    std::vector<float> v(elements.size(), -1.0f);
    std::vector<std::uint32_t> missing;  // positions k whose fraction is not cached yet
    {
      std::lock_guard<std::mutex> lock(visible_mutex_);
      std::vector<float>& cache = (back ? visible_back_ : visible_)[light];
      if (cache.size() < hierarchy_.elements().size()) cache.resize(hierarchy_.elements().size(), -1.0f);
      for (std::size_t k = 0; k < elements.size(); ++k) {
        if (!(column[k] > 0.0f)) continue;
        v[k] = cache[elements[k]];
        if (v[k] < 0.0f) missing.push_back(static_cast<std::uint32_t>(k));
      }
    }
    parallel_for(options_.threads, missing.size(), 64, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        v[missing[i]] = static_cast<float>(visibility(elements[missing[i]], light, back));
    });
    if (!missing.empty()) {
      std::lock_guard<std::mutex> lock(visible_mutex_);
      std::vector<float>& cache = (back ? visible_back_ : visible_)[light];
      for (std::uint32_t k : missing) cache[elements[k]] = v[k];
    }
    for (std::size_t k = 0; k < elements.size(); ++k)
      if (column[k] > 0.0f) column[k] *= v[k];
  }

  /// The visible fraction of light polygon `light` from element e (from its back side when
  /// `back`), by the shared shadow-ray estimator (visibility.hpp): 1 without rays when a shaft
  /// test shows nothing can come between. Its own random stream per pair, so the value does not
  /// depend on the caller.
  ///
  /// The budget differs from ray_cast's, which sizes its passes by the pair's unoccluded factor:
  /// this visibility multiplies the exact factors of all the polygon's patches (and is kept for
  /// later columns), so no one factor sizes it. 64 rays settle unshadowed and fully shadowed
  /// pairs, 256 more resolve a penumbra. The rays pair shuffled point strata one to one and are
  /// weighted by their kernel (one kernel-weighted ratio over all rays), as this estimator has
  /// always done: ray_cast's grid with exact point-factor weights would have lower variance near
  /// shared edges, but would change every result.
  ///
  /// With `subset` (some of the light's patches): the visible fraction of those patches, taken as
  /// one surface (points by area over them), for the factors of those patches alone.
  double visibility(std::uint32_t e, std::uint32_t light, bool back = false,
                    const std::vector<std::uint32_t>* subset = nullptr) const {
    const Light& L = lights_[light];
    const Element& el = hierarchy_.element(e);
    const Patch& patch = hierarchy_.patches()[el.patch];
    const glm::vec3 normal = back ? -patch.normal : patch.normal;
    std::array<glm::vec3, 4> corners{};
    for (int k = 0; k < el.corner_count(); ++k)
      corners[static_cast<std::size_t>(k)] = hierarchy_.vertices()[el.corners[static_cast<std::size_t>(k)]];
    // Shafts take receivers of up to 4 corners; larger lights always cast rays.
    if (L.vertices.size() <= 4 &&
        !occluders_.may_block(corners.data(), el.corner_count(), normal, L.vertices.data(),
                              static_cast<int>(L.vertices.size()), L.normal, epsilon_, patch.polygon, L.polygon))
      return 1.0;
    static constexpr ShadowBudget kBudget{{64, 1}, {256, 1}, ShadowPairing::shuffled};
    const CellSampler sampler(corners.data(), el.corner_count());
    auto ray_kernel = [](const glm::vec3&, double kernel) { return kernel; };
    Rng rng(options_.seed, e, stream_key(back ? Stream::monte_carlo_back_light : Stream::monte_carlo_light, light));
    if (subset == nullptr) {
      auto light_point = [&L](glm::vec2 uv) { return L.fan.sample(uv); };
      return visible_fraction(sampler, normal, light_point, L.normal, epsilon_, kBudget, rng, *shadow_rays_, ray_kernel)
          .value;
    }
    const PatchSetSampler patches(hierarchy_, *subset);
    return visible_fraction(sampler, normal, patches, L.normal, epsilon_, kBudget, rng, *shadow_rays_, ray_kernel).value;
  }

  /// Element id -> position in `elements` (kNone elsewhere), so hits on leaves map to indices.
  std::vector<std::uint32_t> positions(const std::vector<std::uint32_t>& elements) const {
    std::vector<std::uint32_t> position(hierarchy_.elements().size(), kNone);
    for (std::size_t k = 0; k < elements.size(); ++k) position[elements[k]] = static_cast<std::uint32_t>(k);
    return position;
  }

  /// The column of a non-emitting target, shot from it (from the back of a translucent patch
  /// for a back target): as many rays as its elements would shoot for their rows, in chunks with
  /// their own random streams (on up to `threads` threads); the sums do not depend on the thread
  /// count. Arrivals at the back of elements[k] are entry elements.size() + k.
  /// `emitter`: arrivals count only through mirrors and windows (an emitting patch's direct
  /// factors, to fronts and backs, are computed exactly; its light through glass is the photon
  /// map's).
  void shot_column(std::uint32_t target, const std::vector<std::uint32_t>& elements,
                   const std::vector<std::uint32_t>& position, const LeafRays& rays, unsigned threads,
                   bool emitter, SparseFactors& out) const {
    out.index.clear();
    out.value.clear();
    const std::size_t n = hierarchy_.patches().size();
    const bool back = target >= n;
    const std::uint32_t patch = back ? translucent_patches()[target - n] : target;
    const Patch& source = hierarchy_.patches()[patch];
    const std::uint32_t root = source.root;
    const std::uint64_t total = std::uint64_t{options_.hemisphere_rays} * leaves_under(root);
    constexpr std::uint32_t kChunk = 1024;
    const auto chunks = static_cast<std::size_t>((total + kChunk - 1) / kChunk);
    std::vector<std::vector<std::pair<std::uint32_t, float>>> hits(chunks);
    parallel_for(threads, chunks, 1, [&](std::size_t begin, std::size_t end) {
      Scratch scratch(kChunk);
      for (std::size_t c = begin; c < end; ++c) {
        const auto count = static_cast<std::uint32_t>(std::min<std::uint64_t>(kChunk, total - c * kChunk));
        Rng rng(options_.seed, target, stream_key(Stream::monte_carlo_column, c));
        shoot(rays, root, source, back, count, rng, scratch,
              [&](std::uint32_t leaf, std::uint32_t j, float w, Path path) {
                if (position[leaf] == kNone) return;
                const bool at_back = j >= n;
                if (emitter && !carried_from_emitter(path)) return;
                hits[c].emplace_back(static_cast<std::uint32_t>(position[leaf] + (at_back ? elements.size() : 0)), w);
              });
      }
    });
    const std::size_t m = elements.size();
    HitCounter counter(translucent_patches().empty() ? m : 2 * m);
    for (const auto& h : hits)
      for (const auto& [k, w] : h) counter.add(k, w);
    const double scale = static_cast<double>(source.area) / static_cast<double>(total);
    counter.drain(out.index, out.value, [&](std::uint32_t k, float c) {
      return static_cast<float>(scale * c / static_cast<double>(hierarchy_.element(elements[k % m]).area));
    });
  }

  /// shoot(): sealed first hits whose points are tested for burial before an element's later
  /// ones are taken as buried, when all of these were.
  static constexpr std::uint32_t kBurialProbes = 32;

  /// How a ray reached the surface it reports: straight, through mirrors and windows only, or
  /// through refracting glass (and maybe mirrors and windows too).
  enum class Path : std::uint8_t { direct, specular, glass };

  /// Whether light an emitting patch sends along `path` is counted by the rays (the direct path
  /// is the exact part's; through glass it is the photon map's, unless emitted_through_glass).
  bool carried_from_emitter(Path path) const {
    return path == Path::specular || (path == Path::glass && options_.emitted_through_glass);
  }

  /// Per-thread sample buffers.
  struct Scratch {
    explicit Scratch(std::uint32_t n) : points(n), directions(n), origin(n), dir(n), hits(n), found(n) {}
    std::vector<glm::vec2> points, directions;
    std::vector<glm::vec3> origin, dir;
    std::vector<RayScene::Hit> hits;
    std::vector<std::uint8_t> found;
  };

  /// Casts `count` cosine-distributed rays from points of element `from` (of patch
  /// `source`; from its back side when `back`) and calls hit(leaf, target, weight, path) for
  /// each diffuse arrival: a ray that hits the front of another polygon's element arrives at its
  /// patch with weight 1 by Path::direct; one that hits the back of a translucent polygon's
  /// element arrives at that patch's back target (>= the patch count).
  /// With FormFactorOptions::specular_depth > 0 (extended form factors) a ray also goes on
  /// after a surface's diffuse part has counted it: reflected by an ideal mirror (times the
  /// mirror's mean specular reflectance, at most specular_depth reflections), straight through
  /// a window (ior 1, times its mean transmittance) or through refracting glass (times its
  /// transmittance: reflected with the interface's Fresnel reflectance, a reflection of the
  /// depth, else straight on; Path::glass). These are
  /// Wallace, Cohen & Greenberg's mirror and window form factors, traced instead of built from
  /// virtual mirror worlds (for a planar mirror the reflected ray is the ray to the virtual image).
  ///
  /// With `buried_rays`, counts there the rays that start at buried points (geometry/
  /// burial.hpp: under a block standing on the element, inside a prop sunk into it): a ray that
  /// first meets the back of a one-sided polygon is tested with the burial test's four rays
  /// from its point, and after kBurialProbes such rays all found buried, the element's later
  /// ones are taken as buried without the test (an element wholly under a block, or a room
  /// seen from outside, costs at most 4 x kBurialProbes more rays).
  template <typename Hit>
  void shoot(const LeafRays& rays, std::uint32_t from, const Patch& source, bool back, std::uint32_t count, Rng& rng,
             Scratch& scratch, const Hit& hit, std::uint32_t* buried_rays = nullptr) const {
    if (scratch.points.size() < count) scratch = Scratch(count);
    // Points and directions from one randomised 4D Halton set (core/halton.hpp): spread in the
    // four dimensions jointly, where two stratified 2D sets paired by a random permutation are
    // stratified in each pair only. On issue #15's 22k city, 256 rays per element: the rows'
    // own element error 0.48 % -> 0.35 % (docs/FORM_FACTORS.md).
    const ShiftedHalton4 halton(rng);
    for (std::uint32_t r = 0; r < count; ++r) halton.point(r, scratch.directions[r], scratch.points[r]);
    const glm::vec3 n = back ? -source.normal : source.normal;
    const Frame frame(n);
    const Element& el = hierarchy_.element(from);
    std::array<glm::vec3, 4> corners{};
    for (int k = 0; k < el.corner_count(); ++k)
      corners[static_cast<std::size_t>(k)] = hierarchy_.vertices()[el.corners[static_cast<std::size_t>(k)]];
    const CellSampler sampler(corners.data(), el.corner_count());  // as sample_point, constants hoisted
    constexpr float kInfinity = std::numeric_limits<float>::infinity();
    // The first segments of all rays, traced as packets (they share an origin region).
    for (std::uint32_t r = 0; r < count; ++r) {
      scratch.origin[r] = sampler(scratch.points[r]) + epsilon_ * n;
      scratch.dir[r] = frame.to_world(cosine_hemisphere(scratch.directions[r]));
    }
    rays.scene.intersect(count, scratch.origin.data(), scratch.dir.data(), 0.0f, kInfinity, scratch.hits.data(),
                         scratch.found.data());
    // The burial test's rays and what they count as sealed: the back of a one-sided polygon
    // other than the source's own (which a ray meets only by rounding), and with extended form
    // factors not a window or glass (which rays pass through either way).
    std::array<glm::vec3, 4> burial{};
    if (buried_rays) burial = burial_directions(n);
    auto sealed = [&](const RayScene::Hit& h, const glm::vec3& d) {
      const std::uint32_t polygon = rays.polygon[h.triangle];
      return glm::dot(d, h.geometric_normal) >= 0.0f && rays.back[h.triangle] == kNone && polygon != source.polygon &&
             (specular_depth_ == 0 || (specular_[polygon].window == 0.0f && specular_[polygon].glass == 0.0f));
    };
    std::uint32_t probed = 0;  // sealed first hits tested, all found buried so far
    bool assume_buried = false;
    auto count_buried = [&](std::uint32_t r) {
      if (!assume_buried) {
        if (!buried(rays.scene, scratch.origin[r], burial, sealed)) {
          probed = kBurialProbes + 1;  // an open point among them: keep testing
          return false;
        }
        assume_buried = ++probed == kBurialProbes;
      }
      ++*buried_rays;
      return true;
    };
    for (std::uint32_t r = 0; r < count; ++r) {
      if (!scratch.found[r]) continue;  // escaped (an open scene)
      glm::vec3 x = scratch.origin[r], w = scratch.dir[r];
      std::optional<RayScene::Hit> h = scratch.hits[r];
      if (buried_rays && sealed(*h, w) && count_buried(r)) continue;
      // The common case, fast: one-sided surfaces absorb at their back, and a hit on the
      // source's own plane is rounding. (Per-triangle arrays and Embree's normal, because the
      // hierarchy's structs would be cache misses.)
      if (specular_depth_ == 0) {
        if (rays.polygon[h->triangle] == source.polygon) continue;
        if (glm::dot(w, h->geometric_normal) < 0.0f)
          hit(h->id, rays.patch[h->triangle], 1.0f, Path::direct);
        else if (rays.back[h->triangle] != kNone)
          hit(h->id, rays.back[h->triangle], 1.0f, Path::direct);
        continue;
      }
      float weight = 1.0f;
      std::uint32_t mirrors = 0, last = source.polygon;
      Path path = Path::direct;
      for (;;) {
        const std::uint32_t polygon = rays.polygon[h->triangle];
        const glm::vec3 ng = glm::normalize(h->geometric_normal);
        const float cos_in = glm::dot(w, ng);
        const bool front = cos_in < 0.0f;
        const SpecularSurface& surface = specular_[polygon];
        // A ray cannot meet the plane it left (the source's, or the mirror's or pane's it just
        // passed): such a hit is rounding.
        if (polygon == last) break;
        if (front)
          hit(h->id, rays.patch[h->triangle], weight, path);
        else if (rays.back[h->triangle] != kNone)
          hit(h->id, rays.back[h->triangle], weight, path);
        const glm::vec3 p = x + h->t * w;
        if (front && surface.mirror > 0.0f && mirrors < specular_depth_) {
          w = w - 2.0f * cos_in * ng;
          weight *= surface.mirror;
          x = p + epsilon_ * ng;
          ++mirrors;
          if (path == Path::direct) path = Path::specular;
        } else if (surface.window > 0.0f) {
          weight *= surface.window;
          x = p + epsilon_ * w;  // straight on, through either face
          if (path == Path::direct) path = Path::specular;
        } else if (surface.glass > 0.0f) {
          // The interface reflects its Fresnel reflectance F and transmits the rest: with
          // probability F the ray is reflected as by a mirror (a reflection of the specular
          // depth), else it goes straight on (the bending and the block's displacement of the
          // ray ignored); each weighted by the glass's transmittance, so neither part is lost
          // (Russian roulette). Only transmitting (weight 1 - F) lost the reflected part: a
          // glass pane in a closed room with walls of 0.99 lost 19 % of the lamp's power over
          // the bounces, reported as escaped (session 31).
          // F is taken at the ray's angle as if it met the interface from outside, whichever
          // face it meets: the ray is not bent, so its direction is the one outside the glass,
          // and the bent ray meets a slab's far face at its refracted angle, where F is the
          // same as at the near face (Stokes). F from inside at the unbent angle is total
          // internal reflection beyond 42 degrees for n = 1.5: a glass table top (a closed
          // slab) trapped and lost the light, 45 % of a closed room's power (session 32).
          const float reflectance = fresnel_dielectric(std::fabs(cos_in), surface.ior);
          weight *= surface.glass;
          if (!(weight > 0.0f)) break;
          // Beyond the depth the reflected part goes on with the transmitted one rather than
          // being lost.
          const bool reflected = rng.uniform() < reflectance;
          if (reflected && mirrors < specular_depth_) {
            w = w - 2.0f * cos_in * ng;
            x = p + epsilon_ * (front ? ng : -ng);
            ++mirrors;
          } else {
            x = p + epsilon_ * w;
          }
          path = Path::glass;
        } else {
          break;  // absorbed (the diffuse part was counted above)
        }
        last = polygon;
        h = rays.scene.intersect(x, w, 0.0f, kInfinity);
        if (!h) break;
      }
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
  /// refined: a column must land on the leaves that exist now. Built without the lock (Embree
  /// builds in parallel); concurrent first calls may each build the same scene, and one is kept.
  std::shared_ptr<const LeafRays> leaf_scene() const {
    const std::size_t leaves = hierarchy_.leaves().size();
    {
      std::lock_guard<std::mutex> lock(leaf_mutex_);
      if (leaf_rays_ && leaf_count_ == leaves) return leaf_rays_;
    }
    RayScene scene = RayScene::from_leaves(hierarchy_, backs_inside_);
    std::vector<std::uint32_t> patch, polygon, back;
    for (std::uint32_t e : scene.triangle_ids()) {
      patch.push_back(hierarchy_.element(e).patch);
      polygon.push_back(hierarchy_.patches()[patch.back()].polygon);
      back.push_back(back_target_[patch.back()]);
    }
    auto built = std::make_shared<const LeafRays>(
        LeafRays{std::move(scene), std::move(patch), std::move(polygon), std::move(back)});
    std::lock_guard<std::mutex> lock(leaf_mutex_);
    if (!leaf_rays_ || leaf_count_ != leaves) {
      leaf_rays_ = std::move(built);
      leaf_count_ = leaves;
    }
    return leaf_rays_;
  }

  const PatchHierarchy& hierarchy_;
  /// Per patch: its back is no surface (RayScene::backs_inside()), for the leaves' ray scene.
  /// Patches added by adaptive subdivision are none: only leaves are, under existing patches.
  std::vector<std::uint8_t> backs_inside_;
  FormFactorOptions options_;
  std::unique_ptr<BackColumnEstimator> analytic_;  ///< unoccluded factors to emitting patches
  /// Per polygon, for extended form factors: mean reflectance of an ideal mirror, mean
  /// transmittance of a window (0 = neither).
  struct SpecularSurface {
    float mirror = 0.0f, window = 0.0f, glass = 0.0f;
    float ior = 1.0f;
  };
  std::vector<SpecularSurface> specular_;
  std::uint32_t specular_depth_ = 0;
  std::vector<std::uint8_t> exact_;                ///< per target: 1 when it emits (no ray counts)
  std::vector<std::uint32_t> back_target_;         ///< per patch: target of its back, or kNone (opaque)
  std::vector<std::uint32_t> emitters_;            ///< the patches with exact_ set, increasing
  std::vector<std::uint32_t> emitter_of_;          ///< per patch: index into lights_, or kNone
  std::vector<float> emitter_power_;               ///< per patch: E summed over channels (0: not emitting)
  std::vector<Light> lights_;                      ///< the emitting polygons
  std::optional<RayScene> shadow_rays_;            ///< the scene's polygons, for shadow rays
  ShaftCuller occluders_;
  mutable std::mutex visible_mutex_;
  mutable std::vector<std::vector<float>> visible_;  ///< per light, per element id: V, or -1 = not yet
  mutable std::vector<std::vector<float>> visible_back_;  ///< the same for the elements' backs
  float epsilon_ = 0.0f;
  mutable std::mutex leaf_mutex_;
  mutable std::shared_ptr<const LeafRays> leaf_rays_;
  mutable std::size_t leaf_count_ = 0;
};

}  // namespace

std::unique_ptr<FormFactorEstimator> make_monte_carlo_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                                const FormFactorOptions& options) {
  return std::make_unique<MonteCarloEstimator>(scene, hierarchy, options);
}

}  // namespace radiosity::detail
