// Baking a solution into the lightmap texels of a host's meshes: conservative rasterisation of
// each triangle in UV1 space, the value at each covered texel's surface point (the solution's
// interpolated field, or a final gather), and dilation into the gutter.
// Based on:
//   J. Hasselgren, T. Akenine-Moller & L. Ohlsson, "Conservative rasterization", GPU Gems 2,
//     ch. 42 (2005): a texel is covered when its square overlaps the triangle (separating axes).
//   C. Ericson, "Real-Time Collision Detection", Morgan Kaufmann 2005, sec. 5.1.5 (the point of
//     a triangle nearest to a point, by Voronoi regions): a border texel reads the chart's edge.
//   M. Reichert, "A two-pass radiosity method driven by lights and viewer position", MSc thesis,
//     Cornell 1992, and H. Rushmeier, C. Patterson & A. Veerasamy, "Geometric simplification for
//     indirect illumination calculations", Graphics Interface 1993 (a final gather: direct light
//     per point, indirect light read from a coarser radiosity solution where gather rays land).
//   Dilation of the gutter is common practice in lightmap bakers: bilinear filtering reads the
//   texels next to a chart, which must hold the chart's light, not black.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "core/streams.hpp"
#include "form_factors/visibility.hpp"
#include "geometry/polygon_fan.hpp"
#include "geometry/ray_scene.hpp"
#include "scene/lights.hpp"
#include "solver/light_groups.hpp"
#include "image/image_loop.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/lightmap.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

constexpr std::uint64_t kMaxTexels = std::uint64_t{1} << 28;  // 16384^2: about 10 GB of working memory

void bad_lightmap_option(const std::string& problem) { throw Error(ErrorCode::invalid_argument, "LightmapOptions: " + problem); }

/// Where a covered texel reads the surface: a triangle of one of the baked meshes and the
/// barycentric coordinates of the point nearest to the texel centre.
struct TexelSample {
  std::uint32_t slot = kNone;      ///< index into the meshes being baked; kNone: not covered
  std::uint32_t triangle = kNone;
  glm::vec3 bary{0.0f};
  float distance2 = std::numeric_limits<float>::infinity();  ///< texel units^2 from the centre
};

/// The point of triangle abc nearest to p and its barycentric coordinates (Ericson 5.1.5).
/// Works for degenerate triangles too (it then lands on an edge or a corner).
glm::vec3 closest_barycentric(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b, const glm::vec2& c) {
  const glm::vec2 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return {1.0f, 0.0f, 0.0f};
  const glm::vec2 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return {0.0f, 1.0f, 0.0f};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
    const float v = d1 / (d1 - d3);
    return {1.0f - v, v, 0.0f};
  }
  const glm::vec2 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return {0.0f, 0.0f, 1.0f};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
    const float w = d2 / (d2 - d6);
    return {1.0f - w, 0.0f, w};
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0f, 1.0f - w, w};
  }
  const float denom = va + vb + vc;
  if (!(denom > 0.0f)) return {1.0f, 0.0f, 0.0f};  // unreachable for finite input; keeps NaN out
  const float v = vb / denom, w = vc / denom;
  return {1.0f - v - w, v, w};
}

/// Whether the texel square [x, x+1] x [y, y+1] and triangle abc (texel units) overlap, by
/// separating axes: the bounding box was checked by the caller, so the triangle's three edge
/// normals remain. Touching counts as overlapping (conservative).
bool texel_overlaps(int x, int y, const glm::vec2 t[3]) {
  const glm::vec2 corners[4] = {{float(x), float(y)}, {float(x + 1), float(y)}, {float(x), float(y + 1)},
                                {float(x + 1), float(y + 1)}};
  for (int k = 0; k < 3; ++k) {
    const glm::vec2 e = t[(k + 1) % 3] - t[k];
    const glm::vec2 axis(-e.y, e.x);
    if (axis == glm::vec2(0.0f)) continue;
    float tri_lo = std::numeric_limits<float>::infinity(), tri_hi = -tri_lo;
    for (int i = 0; i < 3; ++i) {
      const float d = glm::dot(axis, t[i]);
      tri_lo = std::min(tri_lo, d);
      tri_hi = std::max(tri_hi, d);
    }
    float box_lo = std::numeric_limits<float>::infinity(), box_hi = -box_lo;
    for (const glm::vec2& c : corners) {
      const float d = glm::dot(axis, c);
      box_lo = std::min(box_lo, d);
      box_hi = std::max(box_hi, d);
    }
    if (box_hi < tri_lo || tri_hi < box_lo) return false;
  }
  return true;
}

/// Barycentric coordinates of x (in the triangle's plane) with respect to triangle abc.
glm::vec3 barycentric(const glm::vec3& x, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 n = glm::cross(b - a, c - a);
  const float d = glm::dot(n, n);
  if (!(d > 0.0f)) return {1.0f, 0.0f, 0.0f};
  const float wa = glm::dot(glm::cross(c - b, x - b), n) / d;
  const float wb = glm::dot(glm::cross(a - c, x - c), n) / d;
  return {wa, wb, 1.0f - wa - wb};
}

/// A leaf triangle of the hierarchy (a quad leaf is two, split as render() splits it) and the
/// weights of its three vertices at a point.
struct FieldPoint {
  std::uint32_t vertex[3] = {0, 0, 0};
  glm::vec3 weight{1.0f, 0.0f, 0.0f};
};

/// Finds, for a point on a polygon, the leaf element under it and its interpolation weights.
/// A short ray straight down onto the surface finds the leaf through the BVH; where that fails
/// (the point on an element's edge, or another surface in contact within the ray's reach) the
/// polygon's quadtrees are descended, each level taking the child that contains the point.
class ElementLocator {
 public:
  ElementLocator(const PatchHierarchy& hierarchy, const detail::RayScene& leaves, float epsilon)
      : h_(hierarchy), leaves_(leaves), epsilon_(epsilon) {
    // PatchHierarchy meshes the polygons in order, so each polygon's patches are consecutive.
    for (std::uint32_t j = 0; j < h_.patches().size(); ++j) {
      const PolygonId p = h_.patches()[j].polygon;
      if (p >= patches_.size()) patches_.resize(p + std::size_t{1}, {kNone, 0});
      if (patches_[p].first == kNone) patches_[p].first = j;
      ++patches_[p].second;
    }
  }

  FieldPoint locate(PolygonId polygon, const glm::vec3& x, const glm::vec3& n) const {
    if (auto hit = leaves_.intersect(x + epsilon_ * n, -n, 0.0f, 2.0f * epsilon_);
        hit && h_.patches()[h_.element(hit->id).patch].polygon == polygon) {
      FieldPoint f;
      const std::uint32_t* tri = leaves_.triangle(hit->triangle);
      f.vertex[0] = tri[0];
      f.vertex[1] = tri[1];
      f.vertex[2] = tri[2];
      f.weight = glm::vec3(1.0f - hit->u - hit->v, hit->u, hit->v);
      return f;
    }
    return descend(polygon, x);
  }

 private:
  /// How far inside element `e` the point lies: the best over its triangles of the smallest
  /// barycentric coordinate (>= 0 inside); `f` gets that triangle's weights.
  float containment(std::uint32_t e, const glm::vec3& x, FieldPoint& f) const {
    const Element& el = h_.element(e);
    const glm::vec3* v = h_.vertices().data();
    const int triangles = el.corner_count() == 4 ? 2 : 1;
    float best = -std::numeric_limits<float>::infinity();
    for (int k = 0; k < triangles; ++k) {
      const std::uint32_t ids[3] = {el.corners[0], el.corners[k == 0 ? 1u : 2u], el.corners[k == 0 ? 2u : 3u]};
      const glm::vec3 w = barycentric(x, v[ids[0]], v[ids[1]], v[ids[2]]);
      const float inside = std::min({w.x, w.y, w.z});
      if (inside > best) {
        best = inside;
        f.vertex[0] = ids[0];
        f.vertex[1] = ids[1];
        f.vertex[2] = ids[2];
        f.weight = w;
      }
    }
    return best;
  }

  FieldPoint descend(PolygonId polygon, const glm::vec3& x) const {
    FieldPoint f;
    if (polygon >= patches_.size() || patches_[polygon].first == kNone) return f;
    const auto [first, count] = patches_[polygon];
    std::uint32_t e = kNone;
    float best = -std::numeric_limits<float>::infinity();
    for (std::uint32_t j = first; j < first + count; ++j) {
      FieldPoint g;
      const float inside = containment(h_.patches()[j].root, x, g);
      if (inside > best) {
        best = inside;
        e = h_.patches()[j].root;
      }
    }
    while (!h_.element(e).is_leaf()) {
      const std::uint32_t child = h_.element(e).first_child;
      std::uint32_t next = child;
      best = -std::numeric_limits<float>::infinity();
      for (std::uint32_t k = 0; k < 4; ++k) {
        FieldPoint g;
        const float inside = containment(child + k, x, g);
        if (inside > best) {
          best = inside;
          next = child + k;
        }
      }
      e = next;
    }
    containment(e, x, f);
    // A point a hair outside (rounding, or the polygon's own clean-up) reads the nearest edge.
    f.weight = glm::max(f.weight, glm::vec3(0.0f));
    const float sum = f.weight.x + f.weight.y + f.weight.z;
    f.weight = sum > 0.0f ? f.weight / sum : glm::vec3(1.0f, 0.0f, 0.0f);
    return f;
  }

  const PatchHierarchy& h_;
  const detail::RayScene& leaves_;
  float epsilon_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> patches_;  ///< per polygon: first patch, count
};

Rgb interpolate(const std::vector<Rgb>& field, const FieldPoint& f) {
  return f.weight.x * field[f.vertex[0]] + f.weight.y * field[f.vertex[1]] + f.weight.z * field[f.vertex[2]];
}

/// An emitting polygon of the scene, as the final gather sees it.
struct LightmapEmitter {
  PolygonId polygon = 0;
  Rgb emission{0.0f};
  bool two_sided = false;
  detail::PolygonFan fan;
};

/// The final gather at one surface point: the direct light of the strongest emitters exactly
/// (point-to-polygon factor times a visible fraction), the rest of the light by hemisphere rays
/// that read pass 1's radiosity where they land. Each emitting polygon and light counts at its
/// weight (detail::emitter_weights(): 0 outside the light group baked), and pass 1's radiosity is
/// the baked light group's.
class FinalGather {
 public:
  FinalGather(const Scene& scene, const Solution& solution, const detail::RayScene& leaves,
              const LightmapOptions& options, float epsilon)
      : scene_(scene),
        h_(solution.hierarchy()),
        leaves_(leaves),
        options_(options),
        epsilon_(epsilon) {
    const detail::EmitterWeights weights =
        detail::emitter_weights(scene, solution, options.light_group, "bake_lightmap");
    lights_ = detail::SceneLights(scene.lights(), &weights.light);
    // The delta lights and the gather rays through windows and glass, as pass 1 took them
    // (the extended pass).
    if (solution.report().specular_depth > 0) through_ = detail::PassThrough::if_any(scene, true, h_);
    if (options.light_group < 0) {
      front_ = solution.vertex_radiosity();
      back_ = solution.vertex_back_radiosity();
    } else {
      const auto k = static_cast<std::size_t>(options.light_group);
      front_ = h_.vertex_values(solution.light_group_values(k, Quantity::radiosity), solution.exposure());
      std::vector<Rgb> back = solution.light_groups()[k].back_radiosity;
      for (Rgb& b : back) b *= solution.light_group_weights()[k];
      if (!back.empty()) back_ = h_.vertex_values(back);
    }
    const std::vector<Polygon>& polygons = scene.polygons();
    emission_.resize(polygons.size());
    for (PolygonId p = 0; p < polygons.size(); ++p) {
      const Material& m = scene.material(polygons[p].material);
      emission_[p] = m.emission * weights.polygon[p];
      if (detail::max_channel(emission_[p]) <= 0.0f) continue;
      emitters_.push_back({p, emission_[p], m.two_sided, detail::PolygonFan(polygons[p].vertices)});
    }
  }

  struct Light {
    Rgb direct{0.0f};
    Rgb indirect{0.0f};
  };

  Light at(const glm::vec3& x, const glm::vec3& n, std::uint64_t texel) const {
    Light out;
    const std::vector<PolygonId> exact = direct_exact(x, n, texel, out.direct);
    // Point, spot and directional lights (Scene::lights()) exactly, a shadow ray each.
    if (!lights_.delta().empty())
      out.direct += detail::delta_irradiance_at(lights_, leaves_, x, n, epsilon_, through_ ? &*through_ : nullptr);

    // Hemisphere rays, cosine-distributed: H = pi * mean(L) = mean(B) over the hits.
    const auto rays = static_cast<std::uint32_t>(options_.gather_rays);
    thread_local std::vector<glm::vec2> u;
    thread_local std::vector<glm::vec3> origin, direction;
    thread_local std::vector<detail::RayScene::Hit> hits;
    thread_local std::vector<std::uint8_t> found;
    u.resize(rays);
    origin.assign(rays, x + epsilon_ * n);
    direction.resize(rays);
    hits.resize(rays);
    found.resize(rays);
    detail::Rng rng(options_.seed, texel, detail::stream_key(detail::Stream::lightmap_gather));
    detail::stratified(rays, rng, true, u.data());
    const detail::Frame frame(n);
    for (std::uint32_t r = 0; r < rays; ++r) direction[r] = frame.to_world(detail::cosine_hemisphere(u[r]));
    leaves_.intersect(rays, origin.data(), direction.data(), 0.0f, std::numeric_limits<float>::infinity(),
                      hits.data(), found.data());
    Rgb direct(0.0f), indirect(0.0f);
    constexpr int kMaxCrossings = detail::PassThrough::kMaxCrossings;
    for (std::uint32_t r = 0; r < rays; ++r) {
      // A ray goes on through windows and glass (through_: the extended pass), each pane's
      // own radiosity counted first, what lies beyond times what the panes passed (T).
      Rgb T(1.0f);
      bool crossed = false;
      std::optional<detail::RayScene::Hit> at;
      if (found[r]) at = hits[r];
      for (int crossing = 0;; ++crossing) {
        if (!at) {
          // Into the sky: its light is direct, pi L per cosine-weighted ray.
          if (lights_.has_sky()) direct += T * detail::kPi * lights_.sky_radiance(glm::normalize(direction[r]));
          break;
        }
        const detail::RayScene::Hit& hit = *at;
        const bool front = glm::dot(h_.normal(hit.id), direction[r]) < 0.0f;
        if (front || !back_.empty()) {
          const std::uint32_t* tri = leaves_.triangle(hit.triangle);
          const std::vector<Rgb>& field = front ? front_ : back_;
          const Rgb B = (1.0f - hit.u - hit.v) * field[tri[0]] + hit.u * field[tri[1]] + hit.v * field[tri[2]];
          const PolygonId q = h_.patches()[h_.element(hit.id).patch].polygon;
          const Rgb E =
              (front || scene_.material(scene_.polygons()[q].material).two_sided) ? emission_[q] : Rgb(0.0f);
          // An exact emitter's own light was counted above (unless seen through a pane, which
          // its shadow rays do not pass); what it reflects is indirect light.
          if (crossed || std::find(exact.begin(), exact.end(), q) == exact.end()) direct += T * E;
          indirect += T * glm::max(B - E, Rgb(0.0f));
        }
        const Rgb pass = through_ && crossing < kMaxCrossings ? through_->crossing(hit.id, direction[r], hit.geometric_normal)
                                                             : Rgb(0.0f);
        if (!(detail::max_channel(pass) > 0.0f)) break;
        T *= pass;
        crossed = true;
        at = leaves_.intersect(origin[r], direction[r], hit.t + epsilon_, std::numeric_limits<float>::infinity());
      }
    }
    out.direct += direct / static_cast<float>(rays);
    out.indirect = indirect / static_cast<float>(rays);
    return out;
  }

 private:
  /// Adds the direct light of up to exact_emitters emitters (the largest unoccluded
  /// contributions at x) to `direct`; returns their polygons.
  std::vector<PolygonId> direct_exact(const glm::vec3& x, const glm::vec3& n, std::uint64_t texel, Rgb& direct) const {
    struct Candidate {
      std::uint32_t emitter;
      float weight;  // max channel of E F
      double factor;
      glm::vec3 normal;  // of the emitting side facing x
    };
    std::vector<Candidate> candidates;
    for (std::uint32_t k = 0; k < emitters_.size(); ++k) {
      const LightmapEmitter& L = emitters_[k];
      const Polygon& poly = scene_.polygons()[L.polygon];
      // The side of the emitter's plane that x is on must emit.
      const float side = glm::dot(poly.normal, x - poly.vertices[0]);
      if (side == 0.0f || (side < 0.0f && !L.two_sided)) continue;
      const double F = point_to_polygon_factor(x, n, poly.vertices.data(), static_cast<int>(poly.vertices.size()));
      if (!(F > 0.0)) continue;
      candidates.push_back({k, static_cast<float>(F) * detail::max_channel(L.emission), F, side > 0.0f ? poly.normal : -poly.normal});
    }
    const std::size_t keep = std::min(candidates.size(), static_cast<std::size_t>(options_.exact_emitters));
    // Strongest first; ties by emitter order, so the choice is deterministic.
    std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(keep), candidates.end(),
                      [](const Candidate& a, const Candidate& b) {
                        return a.weight != b.weight ? a.weight > b.weight : a.emitter < b.emitter;
                      });
    std::vector<PolygonId> exact;
    const auto rays = static_cast<std::uint32_t>(options_.shadow_rays);
    // Unshadowed and fully shadowed texels are settled by the first pass; a penumbra gets four
    // times as many rays again.
    const detail::ShadowBudget budget{{rays, 1}, {4 * rays, 1}, detail::ShadowPairing::shuffled};
    for (std::size_t i = 0; i < keep; ++i) {
      const Candidate& c = candidates[i];
      const LightmapEmitter& L = emitters_[c.emitter];
      exact.push_back(L.polygon);
      auto from = [&x](glm::vec2) { return x; };
      auto to = [&L](glm::vec2 uv) { return L.fan.sample(uv); };
      auto ray_kernel = [](const glm::vec3&, double kernel) { return kernel; };
      detail::Rng rng(options_.seed, texel, detail::stream_key(detail::Stream::lightmap_light, L.polygon));
      const double V =
          detail::visible_fraction(from, n, to, c.normal, epsilon_, budget, rng, leaves_, ray_kernel).value;
      direct += L.emission * static_cast<float>(c.factor * V);
    }
    return exact;
  }

  const Scene& scene_;
  const PatchHierarchy& h_;
  const detail::RayScene& leaves_;
  std::optional<detail::PassThrough> through_;
  const LightmapOptions& options_;
  float epsilon_;
  std::vector<Rgb> front_, back_;  ///< pass 1's radiosity per hierarchy vertex
  std::vector<Rgb> emission_;      ///< per polygon: its emission at its weight
  std::vector<LightmapEmitter> emitters_;
  detail::SceneLights lights_;
};

/// Fills `rings` rings of empty texels around the covered ones, each with the mean of its
/// filled 8-neighbours of the ring before.
void dilate(Lightmap& map, int rings) {
  const int W = map.image.width, H = map.image.height;
  std::vector<std::pair<std::size_t, Rgb>> ring;
  for (int r = 0; r < rings; ++r) {
    ring.clear();
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t at = static_cast<std::size_t>(y) * W + x;
        if (map.state[at] != TexelState::empty) continue;
        Rgb sum(0.0f);
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
            const std::size_t n = static_cast<std::size_t>(ny) * W + nx;
            if (map.state[n] == TexelState::empty) continue;
            sum += map.image.pixels[n];
            ++count;
          }
        if (count > 0) ring.emplace_back(at, sum / static_cast<float>(count));
      }
    if (ring.empty()) break;
    // Written after the whole ring is found, so a ring reads only the rings before it.
    for (const auto& [at, value] : ring) {
      map.image.pixels[at] = value;
      map.state[at] = TexelState::dilated;
    }
    map.dilated += ring.size();
  }
}

}  // namespace

void validate(const LightmapOptions& options) {
  if (options.width <= 0 || options.height <= 0)
    bad_lightmap_option("width and height must be > 0, got " + std::to_string(options.width) + "x" +
               std::to_string(options.height));
  const std::uint64_t texels = static_cast<std::uint64_t>(options.width) * static_cast<std::uint64_t>(options.height);
  if (texels > kMaxTexels)
    bad_lightmap_option(std::to_string(options.width) + "x" + std::to_string(options.height) + " texels would need about " +
               std::to_string(texels * (sizeof(TexelSample) + sizeof(Rgb) + 1) >> 20) +
               " MiB of working memory; at most 16384x16384 texels are baked at once");
  if (options.gather_rays < 1) bad_lightmap_option("gather_rays must be >= 1, got " + std::to_string(options.gather_rays));
  if (options.shadow_rays < 1) bad_lightmap_option("shadow_rays must be >= 1, got " + std::to_string(options.shadow_rays));
  if (options.exact_emitters < 0)
    bad_lightmap_option("exact_emitters must be >= 0, got " + std::to_string(options.exact_emitters));
  if (options.dilation < 0) bad_lightmap_option("dilation must be >= 0, got " + std::to_string(options.dilation));
  if (options.light_group < -1)
    bad_lightmap_option("light_group must be >= -1 (-1 = all), got " + std::to_string(options.light_group));
  switch (options.quantity) {
    case Quantity::radiosity:
    case Quantity::irradiance:
    case Quantity::direct_irradiance:
    case Quantity::indirect_irradiance: return;
  }
  bad_lightmap_option("quantity is not a Quantity");
}

Lightmap bake_lightmap(const Scene& scene, const Solution& solution, MeshId mesh, const LightmapOptions& options) {
  return bake_lightmap(scene, solution, std::vector<MeshId>{mesh}, options);
}

Lightmap bake_lightmap(const Scene& scene, const Solution& solution, const std::vector<MeshId>& meshes,
                       const LightmapOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  validate(options);
  auto fail = [](const std::string& problem) { throw Error(ErrorCode::invalid_argument, "bake_lightmap: " + problem); };
  const PatchHierarchy& h = solution.hierarchy();
  for (const Patch& p : h.patches())
    if (p.polygon >= scene.polygons().size()) fail("the solution was not made from this scene");
  if (meshes.empty()) fail("no mesh to bake");
  for (const MeshId id : meshes) {
    if (id >= scene.meshes().size())
      fail("mesh " + std::to_string(id) + " does not exist (the scene has " + std::to_string(scene.meshes().size()) +
           " meshes)");
    const Mesh& m = scene.meshes()[id];
    if (m.uv1.size() != m.positions.size())
      fail("mesh " + std::to_string(id) + " has no UV1 (lightmap coordinates); give MeshDesc::uv1 or call "
           "generate_lightmap_uvs()");
    if (id >= solution.meshes().size() || solution.meshes()[id].triangle_polygon != m.triangle_polygon)
      fail("mesh " + std::to_string(id) + " of the scene is not the mesh the solution was solved with");
  }
  // The values to interpolate (the whole solution's, or one light group's), or (final gather) a
  // check that the solution holds what is asked.
  detail::check_light_group(solution, options.light_group, "bake_lightmap");
  const std::vector<Rgb> field = h.vertex_values(
      options.light_group < 0 ? solution.element_values(options.quantity)
                              : solution.light_group_values(static_cast<std::size_t>(options.light_group),
                                                            options.quantity),
      solution.exposure());

  const int W = options.width, H = options.height;
  Lightmap map;
  map.image = Image(W, H);
  map.state.assign(static_cast<std::size_t>(W) * H, TexelState::empty);

  // Rasterise every triangle conservatively; a texel that several triangles touch reads the one
  // nearest to its centre (the one containing it, when there is one). Serial and in mesh and
  // triangle order, so ties are resolved the same way every time.
  std::vector<TexelSample> samples(static_cast<std::size_t>(W) * H);
  for (std::uint32_t slot = 0; slot < meshes.size(); ++slot) {
    const Mesh& m = scene.meshes()[meshes[slot]];
    for (std::uint32_t t = 0; t < m.triangle_polygon.size(); ++t) {
      if (m.triangle_polygon[t] == kNone) continue;
      glm::vec2 uv[3];
      for (int k = 0; k < 3; ++k) {
        const glm::vec2 c = m.uv1[m.indices[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)]];
        uv[k] = glm::vec2(c.x * static_cast<float>(W), c.y * static_cast<float>(H));
      }
      const glm::vec2 lo = glm::min(uv[0], glm::min(uv[1], uv[2])), hi = glm::max(uv[0], glm::max(uv[1], uv[2]));
      // UVs outside [0, 1] (a host's tiling, or garbage) are clipped to the map before any
      // conversion to int, which would overflow for huge values.
      const glm::vec2 size(static_cast<float>(W), static_cast<float>(H));
      const glm::vec2 first = glm::clamp(glm::floor(lo) - 1.0f, glm::vec2(0.0f), size - 1.0f);
      const glm::vec2 last = glm::clamp(glm::floor(hi), glm::vec2(-1.0f), size - 1.0f);
      const int x0 = static_cast<int>(first.x), y0 = static_cast<int>(first.y);
      const int x1 = static_cast<int>(last.x), y1 = static_cast<int>(last.y);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          if (float(x + 1) < lo.x || float(x) > hi.x || float(y + 1) < lo.y || float(y) > hi.y) continue;
          if (!texel_overlaps(x, y, uv)) continue;
          const glm::vec2 centre(float(x) + 0.5f, float(y) + 0.5f);
          const glm::vec3 b = closest_barycentric(centre, uv[0], uv[1], uv[2]);
          const glm::vec2 q = b.x * uv[0] + b.y * uv[1] + b.z * uv[2];
          const float d2 = glm::dot(q - centre, q - centre);
          TexelSample& s = samples[static_cast<std::size_t>(y) * W + x];
          if (d2 < s.distance2) s = {slot, t, b, d2};
        }
    }
  }

  const float epsilon = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
  const detail::RayScene leaves = detail::RayScene::from_leaves(h);
  const ElementLocator locator(h, leaves, epsilon);
  const bool gather = options.final_gather && options.quantity != Quantity::radiosity;
  std::unique_ptr<FinalGather> gatherer;
  if (gather) gatherer = std::make_unique<FinalGather>(scene, solution, leaves, options, epsilon);

  ImageOptions loop;
  loop.width = W;
  loop.height = H;
  loop.threads = options.threads;
  loop.on_progress = options.on_progress;
  const bool finished = detail::for_each_pixel(loop, detail::ImageBands{gather ? 2 : 64, gather ? 4u : 256u}, [&](int x, int y) {
    const std::size_t at = static_cast<std::size_t>(y) * W + x;
    const TexelSample& s = samples[at];
    if (s.slot == kNone) return;
    const Mesh& m = scene.meshes()[meshes[s.slot]];
    const std::uint32_t* tri = &m.indices[3 * static_cast<std::size_t>(s.triangle)];
    glm::vec3 point = s.bary.x * m.positions[tri[0]] + s.bary.y * m.positions[tri[1]] + s.bary.z * m.positions[tri[2]];
    // A texel on a chart border reads the triangle's edge, where another surface may meet it (a
    // wall on a floor): gather rays from there would start behind that surface. A step of a few
    // ray offsets towards the centroid keeps the point inside.
    const glm::vec3 centroid = (m.positions[tri[0]] + m.positions[tri[1]] + m.positions[tri[2]]) / 3.0f;
    const float to_centroid = glm::length(centroid - point);
    if (to_centroid > 0.0f) point += (centroid - point) * std::min(1.0f, 4.0f * epsilon / to_centroid);
    const PolygonId polygon = m.triangle_polygon[s.triangle];
    const glm::vec3& n = scene.polygons()[polygon].normal;
    if (gather) {
      const FinalGather::Light light = gatherer->at(point, n, at);
      map.image.pixels[at] = options.quantity == Quantity::direct_irradiance     ? light.direct
                             : options.quantity == Quantity::indirect_irradiance ? light.indirect
                                                                                 : light.direct + light.indirect;
    } else {
      map.image.pixels[at] = interpolate(field, locator.locate(polygon, point, n));
    }
    map.state[at] = TexelState::covered;
  });
  for (const TexelState s : map.state) map.covered += s == TexelState::covered ? 1u : 0u;
  map.cancelled = !finished;
  if (finished) dilate(map, options.dilation);
  map.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return map;
}

}  // namespace v1
}  // namespace radiosity
