// The view-dependent second pass of the two-pass method: camera rays read the radiosity of the
// first pass where they land on diffuse surfaces, follow specular chains recursively, integrate
// glossy lobes against the first pass's radiosity, and add a photon-mapped caustic term.
// Based on:
//   J. R. Wallace, M. F. Cohen & D. P. Greenberg, "A two-pass solution to the rendering
//     equation: a synthesis of ray tracing and radiosity methods", SIGGRAPH 1987 (pass 1 the
//     diffuse solution, pass 2 the view-dependent specular one; diffuse-to-specular light
//     integrated over the specular lobe, read from pass 1; figure 10).
//   T. Whitted, "An improved illumination model for shaded display", CACM 23(6), 1980
//     (recursive specular reflection and refraction).
//   H. W. Jensen, "Global illumination using photon maps", Rendering Techniques '96, 1996 (the
//     caustic map; see photon_map.cpp).
//   R. L. Cook, T. Porter & L. Carpenter, "Distributed ray tracing", SIGGRAPH 1984 (sampling a
//     glossy lobe, stratified per pixel); Cranley & Patterson, "Randomization of number
//     theoretic methods for multiple integration", SIAM J. Numer. Anal. 13(6), 1976 (the random
//     rotation of the per-pixel strata).
#include "radiosity/two_pass.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/streams.hpp"
#include "image/camera.hpp"
#include "image/image_loop.hpp"
#include "image/image_options.hpp"
#include "render/camera_choice.hpp"
#include "two_pass/photon_map.hpp"
#include "two_pass/specular_scene.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using detail::kInvPi;
using detail::max_channel;
/// Rows per band: progress and cancel are checked between bands.
constexpr int kBandRows = 16;
/// Delta events with two branches (glass) are split into both for the first this many events of
/// a camera path: at most 2^kSplitDepth paths per camera ray, only where it meets glass.
constexpr int kSplitDepth = 3;
/// The layers, in the order they appear in Image::layers.
enum Layer { kDirect = 0, kIndirect, kSpecular, kCaustic, kLayers };
const char* const kLayerNames[kLayers] = {"direct", "indirect", "specular", "caustic"};

[[noreturn]] void bad_option(const std::string& what) {
  throw Error(ErrorCode::invalid_argument, "TwoPassOptions::" + what);
}

using detail::seconds_since;

/// The scene as pass 2 traces it, its emitters and lights at the weights of pass 1's light
/// groups (all 1 unless pass 1 was relit).
detail::SpecularScene traced_scene(const Scene& scene, const Solution& pass1) {
  const detail::EmitterWeights weights = detail::emitter_weights(scene, pass1, -1, "render_two_pass");
  return detail::SpecularScene(scene, pass1.hierarchy(), &weights, pass1.report().specular_depth > 0);
}

/// The four layers of one camera ray.
struct Radiance {
  Rgb layer[kLayers] = {Rgb(0.0f), Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)};
};

class TwoPassRenderer {
 public:
  TwoPassRenderer(const Scene& scene, const Solution& pass1, const TwoPassOptions& options, TwoPassReport& report)
      : options_(options),
        scene_(traced_scene(scene, pass1)),
        camera_(options.camera ? *options.camera
                               : detail::choose_camera(scene, scene_.rays(),
                                                       [this](std::uint32_t element) {
                                                         return scene_.polygon_of_element(element);
                                                       })
                                     .camera,
                options.width, options.height),
        g_(static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options.spp)) - 1e-9))) {
    auto start = std::chrono::steady_clock::now();
    vertex_B_ = pass1.vertex_radiosity(options.ambient);
    vertex_back_ = pass1.vertex_back_radiosity();
    vertex_direct_ = direct_part_of_pass1(pass1.exposure());
    caustics_ = options.content == TwoPassContent::full && options.caustics.photons > 0;
    specular_ = options.content == TwoPassContent::full && options.max_specular_depth > 0 && scene_.has_specular();
    max_radius_ = options.caustics.max_radius > 0.0f ? options.caustics.max_radius : 0.02f * scene.bounds().diagonal();
    report.emitted_power = scene_.emitted_power();
    report.seconds_setup = seconds_since(start);

    start = std::chrono::steady_clock::now();
    if (caustics_) {
      detail::PhotonShoot shot = detail::shoot_caustic_photons(
          scene_, options.caustics, static_cast<int>(pass1.report().specular_depth), options.threads, options.seed,
          pass1.report().emitted_through_glass);
      report.photons_emitted = shot.emitted;
      report.photons_stored = shot.photons.size();
      for (const detail::Photon& p : shot.photons) report.caustic_power += p.power;
      photon_map_ = detail::PhotonMap(std::move(shot.photons));
      caustics_ = !photon_map_.empty();
    }
    report.seconds_photons = seconds_since(start);
  }

  Image render() const {
    Image image(options_.width, options_.height);
    std::vector<Rgb> layers[kLayers];
    for (auto& l : layers) l.assign(image.pixels.size(), Rgb(0.0f));
    detail::for_each_pixel(options_, detail::ImageBands{kBandRows, 16}, [&](int x, int y) {
      const Radiance r = pixel(x, y);
      const std::size_t at = static_cast<std::size_t>(y) * options_.width + x;
      for (int l = 0; l < kLayers; ++l) layers[l][at] = r.layer[l];
      image.pixels[at] = r.layer[kDirect] + r.layer[kIndirect] + r.layer[kSpecular] + r.layer[kCaustic];
    });
    for (int l = 0; l < kLayers; ++l) image.layers.emplace_back(kLayerNames[l], std::move(layers[l]));
    return image;
  }

 private:
  /// Per vertex, the part of pass 1's radiosity that is emission plus directly reflected light:
  /// per leaf element E + rho * (mean direct irradiance over the element from the emitters and
  /// the lights, by stratified shadow rays; the sky's directions stratified too and paired with
  /// the points by a random permutation), interpolated to the vertices like the radiosity, and
  /// capped at the radiosity so the indirect remainder is never negative (the two estimates
  /// differ by the solver's error). Where pass 1 found a leaf partly buried (`exposure`,
  /// Solution::exposure()), its points under the solid see nothing: the mean is over its
  /// open part, as pass 1's values are.
  std::vector<Rgb> direct_part_of_pass1(const std::vector<float>& exposure) const {
    const PatchHierarchy& h = scene_.hierarchy();
    std::vector<Rgb> element_direct(h.elements().size(), Rgb(0.0f));
    const auto& leaves = h.leaves();
    const int n = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options_.direct_samples)) - 1e-9));
    detail::parallel_for(options_.threads, leaves.size(), 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t e = leaves[i];
        const detail::SplitSurface& s = scene_.surface(scene_.polygon_of_element(e));
        Rgb H(0.0f);
        if (max_channel(s.diffuse) > 0.0f && (scene_.has_emitters() || scene_.has_lights())) {
          detail::Rng rng(options_.seed, e, detail::stream_key(detail::Stream::two_pass_direct));
          auto uniform = [&rng] { return rng.uniform(); };
          thread_local std::vector<glm::vec2> sky_u;
          const bool sky = scene_.lights().has_sky();
          if (sky) {
            detail::Rng sky_rng(options_.seed, e, detail::stream_key(detail::Stream::two_pass_sky));
            sky_u.resize(static_cast<std::size_t>(n) * n);
            detail::stratified(static_cast<std::uint32_t>(n * n), sky_rng, true, sky_u.data());
            detail::shuffle(sky_u.data(), sky_u.size(), sky_rng);
          }
          for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
              const glm::vec2 u = rng.uniform2();
              const glm::vec2 uv((static_cast<float>(a) + u.x) / n, (static_cast<float>(b) + u.y) / n);
              const glm::vec3 x = h.sample_point(e, uv);
              H += scene_.direct_irradiance(x, s.normal, 1, uniform);
              if (scene_.has_lights()) {
                H += scene_.delta_light_irradiance(x, s.normal);
                if (sky) H += scene_.sky_light_irradiance(x, s.normal, sky_u[static_cast<std::size_t>(a) * n + b]);
              }
            }
          H /= static_cast<float>(n * n);
          if (!exposure.empty() && exposure[e] > 0.0f) H /= exposure[e];
        }
        element_direct[e] = s.emission + s.diffuse * H;
      }
    });
    std::vector<Rgb> direct = h.vertex_values(element_direct, exposure);
    for (std::size_t v = 0; v < direct.size(); ++v) direct[v] = glm::min(direct[v], vertex_B_[v]);
    return direct;
  }

  /// Final gather of the lights at x: the delta lights exactly, the sky by gather_samples
  /// cosine-weighted rays.
  Rgb gathered_light(const glm::vec3& x, const glm::vec3& n, detail::Rng& rng) const {
    Rgb H = scene_.delta_light_irradiance(x, n);
    if (scene_.lights().has_sky()) {
      Rgb sky(0.0f);
      for (int k = 0; k < options_.gather_samples; ++k) sky += scene_.sky_light_irradiance(x, n, rng.uniform2());
      H += sky / static_cast<float>(options_.gather_samples);
    }
    return H;
  }

  /// A ray's hit with what shading needs.
  struct SurfaceHit {
    glm::vec3 x{0.0f};
    const detail::SplitSurface* surface = nullptr;
    bool front = false;
    const std::uint32_t* triangle = nullptr;  ///< vertex ids of the hit triangle
    float b0 = 0.0f, b1 = 0.0f, b2 = 0.0f;    ///< barycentric coordinates
  };

  bool intersect(const glm::vec3& origin, const glm::vec3& dir, SurfaceHit& out) const {
    const auto hit = scene_.rays().intersect(origin, dir, 0.0f, std::numeric_limits<float>::infinity());
    if (!hit) return false;
    const detail::SplitSurface& s = scene_.surface(scene_.polygon_of_element(hit->id));
    out.surface = &s;
    out.front = glm::dot(s.normal, dir) < 0.0f;
    out.x = origin + hit->t * dir;
    out.x -= s.normal * glm::dot(out.x - s.origin, s.normal);  // snap onto the polygon's plane
    out.triangle = scene_.rays().triangle(hit->triangle);
    out.b1 = hit->u;
    out.b2 = hit->v;
    out.b0 = 1.0f - hit->u - hit->v;
    return true;
  }

  Rgb interpolate(const std::vector<Rgb>& values, const SurfaceHit& h) const {
    return h.b0 * values[h.triangle[0]] + h.b1 * values[h.triangle[1]] + h.b2 * values[h.triangle[2]];
  }

  /// Diffuse reflection of the photon map's irradiance at `h`, times `weight` (0 skips the
  /// lookup: only some camera rays of a pixel look photons up; see Strata::caustic_weight).
  Rgb caustic_radiance(const SurfaceHit& h, float weight) const {
    if (!caustics_ || weight == 0.0f || max_channel(h.surface->diffuse) <= 0.0f) return Rgb(0.0f);
    const PhotonOptions& c = options_.caustics;
    return h.surface->diffuse * (weight * kInvPi) *
           photon_map_.irradiance(h.x, h.surface->normal, c.nearest, max_radius_, c.filter);
  }

  /// Stratification of the first scattering event of a pixel's camera rays: sample `index` of
  /// `count` gets the stratum index/count of [0,1) in its first dimension, rotated by `shift`.
  /// `caustic_weight` is count / lookups for the camera rays that look photons up and 0 for the
  /// others: a k-NN search costs more than the rest of a ray, and the estimate is smooth over a
  /// pixel, so a few lookups per pixel, reweighted, give the same expected value.
  struct Strata {
    int index = 0;
    int count = 1;
    float shift = 0.0f;
    float caustic_weight = 1.0f;
  };

  /// Scatters a ray that arrived along `dir` at `h` through the surface's specular part: `samples`
  /// directions, each traced on with throughput beta * weight / samples. A delta model with two
  /// events (a glass interface: reflection with probability R, refraction with 1 - R) is split
  /// instead, for the first kSplitDepth events of a camera path: both branches are traced, with
  /// throughput beta * weight * probability each. That removes the variance of the random
  /// choice, which is most of the grain seen through glass.
  void scatter(const SurfaceHit& h, const glm::vec3& dir, const Rgb& beta, int depth, int samples,
               const Strata& strata, detail::Rng& rng, Radiance& out) const {
    const detail::SplitSurface& s = *h.surface;
    const glm::vec3 n = (!h.front && s.two_sided) ? -s.normal : s.normal;
    const ShadingFrame frame = ShadingFrame::from_normal(n);
    const glm::vec3 wo = frame.to_local(-dir);
    // Traces one sampled event on with throughput beta * weight * scale.
    auto follow = [&](const BrdfSample& sample, float scale) {
      Rgb throughput = beta * sample.weight * scale;
      // A refraction carries radiance from the index of wi's side n_i into wo's side n_o, scaled
      // by (n_o / n_i)^2 (Veach 1997, ch. 5), which the models leave out (brdf.hpp). It cancels on
      // a path that enters and leaves glass, but not on one that ends on a diffuse surface inside
      // it (the floor under a glass block), whose light mostly stays trapped by total internal
      // reflection. The same rule as the reference path tracer.
      if (sample.delta && sample.wi.z * wo.z < 0.0f) {
        const float n_o = wo.z > 0.0f ? 1.0f : s.ior, n_i = sample.wi.z > 0.0f ? 1.0f : s.ior;
        throughput *= (n_o * n_o) / (n_i * n_i);
      }
      if (!(max_channel(throughput) > 0.0f)) return;
      const glm::vec3 wi = glm::normalize(frame.to_world(sample.wi));
      const glm::vec3 origin = h.x + scene_.epsilon() * (glm::dot(wi, s.normal) > 0.0f ? s.normal : -s.normal);
      trace_specular(origin, wi, throughput, depth + 1, strata.caustic_weight, rng, out);
    };
    if (s.specular_is_delta && depth < kSplitDepth) {
      // The model's first and last events in its choice dimension; exactly two delta events
      // whose probabilities add up to 1 are a split.
      const auto first = s.specular->sample(wo, glm::vec2(0.0f, 0.5f));
      const auto last = s.specular->sample(wo, glm::vec2(std::nextafter(1.0f, 0.0f), 0.5f));
      if (first && last && first->delta && last->delta && first->pdf < 1.0f && last->pdf < 1.0f &&
          std::fabs(first->pdf + last->pdf - 1.0f) < 1e-5f) {
        follow(*first, first->pdf);
        follow(*last, last->pdf);
        return;
      }
    }
    for (int j = 0; j < samples; ++j) {
      glm::vec2 u = rng.uniform2();
      const float total = static_cast<float>(strata.count) * samples;
      u.x = (static_cast<float>(strata.index * samples + j) + u.x) / total + strata.shift;
      if (u.x >= 1.0f) u.x -= 1.0f;
      const auto sample = s.specular->sample(wo, u);
      if (sample) follow(*sample, 1.0f / static_cast<float>(samples));
    }
  }

  /// Light reached after `depth` >= 1 specular events with throughput beta: pass 1's radiosity
  /// (emission included) and the caustic term where the ray lands, then its specular part.
  void trace_specular(const glm::vec3& origin, const glm::vec3& dir, const Rgb& beta, int depth, float caustic_weight,
                      detail::Rng& rng, Radiance& out) const {
    SurfaceHit h;
    if (!intersect(origin, dir, h)) {
      out.layer[kSpecular] += beta * scene_.lights().sky_radiance(dir);  // the sky, seen in a mirror
      return;
    }
    const detail::SplitSurface& s = *h.surface;
    if (h.front) {
      if (s.uses_pass1) {
        out.layer[kSpecular] += beta * interpolate(vertex_B_, h) * kInvPi;
        out.layer[kCaustic] += beta * caustic_radiance(h, caustic_weight);
      } else {
        out.layer[kSpecular] += beta * s.emission * kInvPi;
      }
    } else if (s.uses_pass1 && !vertex_back_.empty()) {
      out.layer[kSpecular] += beta * interpolate(vertex_back_, h) * kInvPi;  // a translucent back
    }
    if (!s.specular || depth >= options_.max_specular_depth) return;
    scatter(h, dir, beta, depth, 1, Strata{0, 1, 0.0f, caustic_weight}, rng, out);
  }

  /// One camera ray: its four layers.
  Radiance camera_ray(const glm::vec3& dir, const Strata& strata, detail::Rng& rng) const {
    Radiance out;
    SurfaceHit h;
    if (!intersect(camera_.eye, dir, h)) {
      out.layer[kDirect] = scene_.lights().sky_radiance(dir);  // the sky, as render() shows it
      return out;
    }
    const detail::SplitSurface& s = *h.surface;
    if (h.front) {
      if (s.uses_pass1) {
        const Rgb direct_part = interpolate(vertex_direct_, h);
        if (options_.diffuse == DiffuseShading::final_gather) {
          auto uniform = [&rng] { return rng.uniform(); };
          Rgb H(0.0f);
          if (max_channel(s.diffuse) > 0.0f) {
            H = scene_.direct_irradiance(h.x, s.normal, options_.gather_samples, uniform);
            if (scene_.has_lights()) H += gathered_light(h.x, s.normal, rng);
          }
          out.layer[kDirect] = (s.emission + s.diffuse * H) * kInvPi;
        } else {
          out.layer[kDirect] = direct_part * kInvPi;
        }
        if (options_.content != TwoPassContent::direct_only)
          out.layer[kIndirect] = (interpolate(vertex_B_, h) - direct_part) * kInvPi;
        out.layer[kCaustic] = caustic_radiance(h, strata.caustic_weight);
      } else {
        out.layer[kDirect] = s.emission * kInvPi;
      }
    } else if (s.uses_pass1 && !vertex_back_.empty() && options_.content != TwoPassContent::direct_only) {
      // The back of a translucent sheet shows what pass 1 transmitted through it: all indirect.
      out.layer[kIndirect] = interpolate(vertex_back_, h) * kInvPi;
    }
    if (specular_ && s.specular) {
      const int samples = s.specular_is_delta ? 1 : options_.glossy_samples;
      scatter(h, dir, Rgb(1.0f), 0, samples, strata, rng, out);
    }
    return out;
  }

  /// Box-filtered mean over g x g jittered camera rays. The jitter comes from the same stream
  /// and in the same order as render(), so a scene without specular parts gives its pixels.
  Radiance pixel(int x, int y) const {
    const std::uint64_t index = static_cast<std::uint64_t>(y) * options_.width + x;
    detail::Rng rng(options_.seed, index, detail::stream_key(detail::Stream::pixel_jitter));
    detail::Rng path_rng(options_.seed, index, detail::stream_key(detail::Stream::two_pass_path));
    const int count = g_ * g_;
    const int lookups = std::min(count, options_.caustics.lookups_per_pixel);
    Strata strata{0, count, path_rng.uniform(), 0.0f};
    Radiance sum;
    for (int i = 0; i < g_; ++i)
      for (int j = 0; j < g_; ++j) {
        // Exactly `lookups` of the count rays, spread evenly over the pixel's strata.
        const bool lookup = (strata.index + 1) * lookups / count > strata.index * lookups / count;
        strata.caustic_weight = lookup ? static_cast<float>(count) / static_cast<float>(lookups) : 0.0f;
        const glm::vec2 u = rng.uniform2();
        const float sx = (static_cast<float>(x) + (static_cast<float>(i) + u.x) / g_) / options_.width;
        const float sy = (static_cast<float>(y) + (static_cast<float>(j) + u.y) / g_) / options_.height;
        const Radiance r = camera_ray(camera_.direction(sx, sy), strata, path_rng);
        for (int l = 0; l < kLayers; ++l) sum.layer[l] += r.layer[l];
        ++strata.index;
      }
    const float inv = 1.0f / static_cast<float>(g_ * g_);
    for (auto& l : sum.layer) l *= inv;
    return sum;
  }

  const TwoPassOptions& options_;
  detail::SpecularScene scene_;  // before camera_: choose_camera() looks through its rays
  detail::PinholeCamera camera_;
  int g_;
  std::vector<Rgb> vertex_B_;
  std::vector<Rgb> vertex_back_;  ///< pass 1's radiosity of translucent backs, or empty (black backs)
  std::vector<Rgb> vertex_direct_;
  detail::PhotonMap photon_map_;
  float max_radius_ = 0.0f;
  bool caustics_ = false;
  bool specular_ = false;
};

}  // namespace

void validate(const TwoPassOptions& options) {
  const std::string problem = detail::image_options_problem(options);
  if (!problem.empty()) bad_option(problem);
  if (options.gather_samples < 1) bad_option("gather_samples must be >= 1, got " + std::to_string(options.gather_samples));
  if (options.max_specular_depth < 0)
    bad_option("max_specular_depth must be >= 0, got " + std::to_string(options.max_specular_depth));
  if (options.glossy_samples < 1) bad_option("glossy_samples must be >= 1, got " + std::to_string(options.glossy_samples));
  if (options.direct_samples < 1) bad_option("direct_samples must be >= 1, got " + std::to_string(options.direct_samples));
  const PhotonOptions& c = options.caustics;
  if (c.max_bounces < 1) bad_option("caustics.max_bounces must be >= 1, got " + std::to_string(c.max_bounces));
  if (c.nearest < 1) bad_option("caustics.nearest must be >= 1, got " + std::to_string(c.nearest));
  if (c.lookups_per_pixel < 1)
    bad_option("caustics.lookups_per_pixel must be >= 1, got " + std::to_string(c.lookups_per_pixel));
  if (!std::isfinite(c.max_radius) || c.max_radius < 0.0f)
    bad_option("caustics.max_radius must be finite and >= 0, got " + std::to_string(c.max_radius));
}

Image render_two_pass(const Scene& scene, const Solution& pass1, const TwoPassOptions& options, TwoPassReport& report) {
  validate(options);
  report = TwoPassReport{};
  const TwoPassRenderer renderer(scene, pass1, options, report);
  const auto start = std::chrono::steady_clock::now();
  Image image = renderer.render();
  report.seconds_render = seconds_since(start);
  return image;
}

Image render_two_pass(const Scene& scene, const Solution& pass1, const TwoPassOptions& options) {
  TwoPassReport report;
  return render_two_pass(scene, pass1, options, report);
}

}  // namespace v1
}  // namespace radiosity
