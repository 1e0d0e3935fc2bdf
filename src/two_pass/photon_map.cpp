// Caustic photon map: shooting photons through specular surfaces and estimating the irradiance
// they deposit on diffuse ones.
// Based on:
//   H. W. Jensen, "Global illumination using photon maps", Rendering Techniques '96
//     (Eurographics Workshop on Rendering), 1996: the caustic map of L S+ D paths, the
//     k-nearest-neighbour radiance estimate and the cone filter (sec. 3 and 4).
//   H. W. Jensen, "Realistic Image Synthesis Using Photon Mapping", A K Peters 2001, sec. 7.2
//     (photon power = emitted power / photons emitted) and 7.4 (the Epanechnikov kernel).
//   J. Arvo & D. Kirk, "Particle transport and image synthesis", SIGGRAPH 1990 (Russian roulette).
//   J. L. Blanco & P. K. Rai, nanoflann: a C++ header-only library for nearest neighbour
//     search with KD-trees, 2014 (the kd-tree).
#include "two_pass/photon_map.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <nanoflann.hpp>

#include "core/memory_budget.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/sampling.hpp"
#include "core/streams.hpp"

namespace radiosity::detail {

namespace {

/// Photons traced per parallel work item; the blocks (not the threads) fix the storage order.
constexpr std::size_t kPhotonBlock = 2048;
/// Photons count for an estimate only on surfaces within about 25 degrees of the query's normal.
constexpr float kMinNormalCosine = 0.9f;

/// Cosine-weighted direction about the unit normal n (Malley's method).
glm::vec3 cosine_direction(const glm::vec3& n, const glm::vec2& u) {
  const ShadingFrame frame = ShadingFrame::from_normal(n);
  return glm::normalize(frame.to_world(cosine_hemisphere_polar(u)));
}

/// Traces photon `index` and appends its landings to `out`.
void trace_photon(const SpecularScene& scene, const PhotonOptions& options, int pass1_depth, bool pass1_glass,
                  std::uint64_t seed, std::size_t index, std::vector<Photon>& out) {
  Rng rng(seed, index, stream_key(Stream::photon));
  const float u_emitter = rng.uniform();
  const glm::vec2 u_point = rng.uniform2();
  const EmitterSample y = scene.sample_emitter(u_emitter, u_point);
  // A Lambertian emitter sampled by area (density pdf_area) and cosine-weighted direction
  // carries E / pdf_area in total; each of the N photons a 1/N share (Jensen 2001, sec. 7.2).
  Rgb power = y.emission / (y.pdf_area * static_cast<float>(options.photons));
  glm::vec3 dir = cosine_direction(y.normal, rng.uniform2());
  glm::vec3 origin = y.position + scene.epsilon() * y.normal;
  const RayScene& rays = scene.rays();
  // Whether every specular event so far is one that pass 1 carries (mirror reflection, window
  // passage, and with `pass1_glass` glass either way); with at most `pass1_depth` reflections,
  // pass 1 already has this landing.
  bool pass1_kind = true;
  int mirrors = 0;
  for (int specular = 0;;) {
    const auto hit = rays.intersect(origin, dir, 0.0f, std::numeric_limits<float>::infinity());
    if (!hit) return;
    const PolygonId polygon = scene.polygon_of_element(hit->id);
    const SplitSurface& s = scene.surface(polygon);
    glm::vec3 x = origin + hit->t * dir;
    x -= s.normal * glm::dot(x - s.origin, s.normal);
    const bool front = glm::dot(s.normal, dir) < 0.0f;

    // An L S+ D landing: the caustic map's business, unless the extended pass 1 carries it.
    const bool counted_by_pass1 = pass1_depth > 0 && pass1_kind && mirrors <= pass1_depth;
    if (specular >= 1 && front && s.uses_pass1 && max_channel(s.diffuse) > 0.0f && !counted_by_pass1)
      out.push_back(Photon{x, s.normal, power, polygon, static_cast<std::uint16_t>(specular)});

    // Diffuse reflection from here is pass 1's; only the specular part carries the photon on.
    if (!s.specular || specular >= options.max_bounces) return;
    const glm::vec3 n = (!front && s.two_sided) ? -s.normal : s.normal;
    const ShadingFrame frame = ShadingFrame::from_normal(n);
    const glm::vec3 wo = frame.to_local(-dir);
    const auto sample = s.specular->sample(wo, rng.uniform2());
    if (!sample) return;
    // Russian roulette by the event's weight keeps the photon's power about constant.
    const float q = std::min(1.0f, max_channel(sample->weight));
    if (!(q > 0.0f) || !(rng.uniform() < q)) return;
    power *= sample->weight / q;
    // Reflected: back to the side it came from (a photon inside a one-sided slab meets its faces
    // from behind, wo.z < 0).
    const bool reflected = (sample->wi.z > 0.0f) == (wo.z > 0.0f);
    const bool glass = pass1_glass && s.pass1_glass;
    pass1_kind = pass1_kind && sample->delta && (glass || (reflected ? s.pass1_mirror : s.pass1_window));
    // Pass 1 carries glass either way: a reflection beyond its depth goes on straight there
    // (monte_carlo.cpp), so with `pass1_glass` only mirrors count toward the depth.
    mirrors += reflected && !glass ? 1 : 0;
    dir = glm::normalize(frame.to_world(sample->wi));
    origin = x + scene.epsilon() * (glm::dot(dir, s.normal) > 0.0f ? s.normal : -s.normal);
    ++specular;
  }
}

}  // namespace

PhotonShoot shoot_caustic_photons(const SpecularScene& scene, const PhotonOptions& options, int pass1_depth,
                                  unsigned threads, std::uint64_t seed, bool pass1_glass) {
  PhotonShoot result;
  result.emitted_power = scene.emitted_power();
  if (options.photons == 0 || !scene.has_emitters() || !scene.has_specular()) return result;
  result.emitted = options.photons;
  const std::size_t blocks = (options.photons + kPhotonBlock - 1) / kPhotonBlock;
  std::vector<std::vector<Photon>> stored(blocks);
  // The stored photons are held twice at the end (the blocks and the merged array): the count
  // that fits the budget so, checked as each block grows.
  const std::size_t budget = resolve_memory_budget(options.memory_budget_bytes);
  const std::size_t most = budget / (2 * sizeof(Photon));
  std::atomic<std::size_t> held{0};
  parallel_for(threads, blocks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      const std::size_t last = std::min(options.photons, (b + 1) * kPhotonBlock);
      for (std::size_t k = b * kPhotonBlock; k < last; ++k)
        trace_photon(scene, options, pass1_depth, pass1_glass, seed, k, stored[b]);
      const std::size_t now = held.fetch_add(stored[b].size()) + stored[b].size();
      if (now > most)
        refuse_memory("the caustic photon map (" + std::to_string(now) + " photons stored after " +
                          std::to_string(last) + " of " + std::to_string(options.photons) + " shot, more to come)",
                      2.0 * static_cast<double>(now) * sizeof(Photon), budget, "PhotonOptions::memory_budget_bytes",
                      "; shoot fewer photons or raise the budget");
    }
  });
  std::size_t total = 0;
  for (const auto& block : stored) total += block.size();
  result.photons.reserve(total);
  for (const auto& block : stored) result.photons.insert(result.photons.end(), block.begin(), block.end());
  return result;
}

/// nanoflann's dataset adaptor over the photons' positions. Points at the vector's buffer, which
/// stays put when the PhotonMap (and its vector) is moved.
struct PhotonMap::Tree {
  struct Cloud {
    const Photon* data = nullptr;
    std::size_t count = 0;
    std::size_t kdtree_get_point_count() const { return count; }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return data[i].position[static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Index =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, std::uint32_t>;

  explicit Tree(const std::vector<Photon>& photons)
      : cloud{photons.data(), photons.size()}, index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}

  Cloud cloud;
  Index index;
};

PhotonMap::PhotonMap() = default;
PhotonMap::PhotonMap(std::vector<Photon> photons) : photons_(std::move(photons)) {
  if (!photons_.empty()) tree_ = std::make_unique<Tree>(photons_);
}
PhotonMap::PhotonMap(PhotonMap&&) noexcept = default;
PhotonMap& PhotonMap::operator=(PhotonMap&&) noexcept = default;
PhotonMap::~PhotonMap() = default;

Rgb PhotonMap::irradiance(const glm::vec3& x, const glm::vec3& n, int k, float max_radius, PhotonFilter filter) const {
  if (!tree_ || k <= 0 || !(max_radius > 0.0f)) return Rgb(0.0f);
  const std::size_t want = std::min<std::size_t>(static_cast<std::size_t>(k), photons_.size());
  // Small fixed buffers for the usual k; larger k falls back to the heap.
  constexpr std::size_t kStack = 256;
  std::uint32_t stack_index[kStack];
  float stack_d2[kStack];
  std::vector<std::uint32_t> heap_index;
  std::vector<float> heap_d2;
  std::uint32_t* index = stack_index;
  float* d2 = stack_d2;
  if (want > kStack) {
    heap_index.resize(want);
    heap_d2.resize(want);
    index = heap_index.data();
    d2 = heap_d2.data();
  }
  // k nearest within max_radius: nanoflann's k-NN result set prunes against its last slot, so
  // seeding that slot with max_radius^2 stops the search from visiting farther photons (most
  // queries land where photons are sparse, and an unbounded k-NN search there is slow).
  const float r2_max = max_radius * max_radius;
  nanoflann::KNNResultSet<float, std::uint32_t> result(want);
  result.init(index, d2);
  d2[want - 1] = r2_max;
  const float query[3] = {x.x, x.y, x.z};
  tree_->index.findNeighbors(result, query, nanoflann::SearchParams());
  const std::size_t found = result.size();
  if (found == 0) return Rgb(0.0f);

  // The disc holding the photons: out to the k-th, or max_radius when fewer lie within it (then
  // it is a fixed-radius estimate over the photons inside).
  const float r2 = found == static_cast<std::size_t>(k) ? d2[found - 1] : r2_max;
  if (!(r2 > 0.0f)) return Rgb(0.0f);
  Rgb sum(0.0f);
  for (std::size_t i = 0; i < found; ++i) {
    if (d2[i] > r2) break;  // sorted by distance
    const Photon& p = photons_[index[i]];
    if (glm::dot(p.normal, n) < kMinNormalCosine) continue;
    // Cone filter with k = 1: w = 1 - d/r, whose integral over the disc is pi r^2 / 3 (Jensen
    // 1996, eq. 7 with k = 1). Epanechnikov: w = 1 - d^2/r^2, integral pi r^2 / 2.
    const float w = filter == PhotonFilter::cone ? 1.0f - std::sqrt(d2[i] / r2) : 1.0f - d2[i] / r2;
    sum += w * p.power;
  }
  const float normalisation = filter == PhotonFilter::cone ? 3.0f : 2.0f;
  return sum * (normalisation / (kPi * r2));
}

}  // namespace radiosity::detail
