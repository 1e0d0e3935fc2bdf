// Brute-force path tracing with each material's reflection model: the reference that radiosity
// and two-pass images are checked against.
// Based on:
//   J. T. Kajiya, "The rendering equation", SIGGRAPH 1986 (the path integral estimated here).
//   E. Veach, "Robust Monte Carlo Methods for Light Transport Simulation", PhD thesis, Stanford
//     1997: next-event estimation and multiple importance sampling with the power heuristic
//     (ch. 9, eq. 9.13), the area-to-solid-angle pdf conversion (eq. 8.10).
//   J. Arvo & D. Kirk, "Particle transport and image synthesis", SIGGRAPH 1990 (Russian roulette).
//   T. Duff et al., "Building an orthonormal basis, revisited", JCGT 6(1), 2017.
//   E. Veach, ibid., ch. 5: radiance is not symmetric under refraction; it scales by
//     (eta_o / eta_i)^2 across an interface, which is applied here for a camera path.
//   J. R. Wallace, M. F. Cohen & D. P. Greenberg, "A two-pass solution to the rendering
//     equation: a synthesis of ray tracing and radiosity methods", SIGGRAPH 1987 (mirror images
//     of the scene as virtual sources; here used to sample light through planar mirrors).
//   M. Pharr, W. Jakob & G. Humphreys, "Physically Based Rendering", 3rd ed. 2016, sec. 13.6
//     (cosine-weighted hemisphere sampling, Malley's method) and sec. 14.5 (path loop layout;
//     Russian roulette on the throughput with the refraction scale taken out, "etaScale").
#include "radiosity/path_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "core/rng.hpp"
#include "geometry/polygon_fan.hpp"
#include "geometry/ray_scene.hpp"
#include "radiosity/brdf.hpp"
#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "core/streams.hpp"
#include "image/camera.hpp"
#include "image/image_loop.hpp"
#include "image/image_options.hpp"
#include "render/camera_choice.hpp"
#include "scene/lights.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

/// Reflections a path has before Russian roulette may end it.
constexpr int kRouletteStart = 3;
/// Russian roulette never keeps a path with probability above this, so every path ends (a
/// ray caught by total internal reflection in glass keeps its throughput). Past this cap a
/// path's weight grows by rho / kMaxSurvival a bounce, and the estimator's variance is infinite
/// where rho^2 > kMaxSurvival: at 0.95 (until session 26) a closed room of reflectance 0.99
/// (an exporter's Kd 1, clamped) rendered 25 % dark at 256 paths a pixel. The readers clamp
/// reflectance to 0.99 at most, whose weight this cap keeps at 1.
constexpr float kMaxSurvival = 0.99f;
/// Roughly how many paths a band of rows holds, so progress is reported every ~50 ms.
constexpr std::size_t kPathsPerBand = std::size_t{1} << 17;

[[noreturn]] void bad_option(const std::string& what) {
  throw Error(ErrorCode::invalid_argument, "PathTraceOptions::" + what);
}

using detail::kInvPi;
using detail::kPi;
float max_component(const Rgb& c) { return detail::max_channel(c); }

/// Power heuristic with exponent 2 (Veach 1997, eq. 9.13) for one sample of each strategy.
float power_heuristic(float pdf_this, float pdf_other) {
  const float a = pdf_this * pdf_this, b = pdf_other * pdf_other;
  return a / (a + b);
}

/// The surfaces as the tracer needs them, indexed by polygon id (= RayScene hit id).
struct Surface {
  glm::vec3 normal{0.0f};
  glm::vec3 origin{0.0f};  ///< a vertex, to snap hit points onto the plane
  Rgb emission{0.0f};      ///< exitance E, W/m^2, from the front (and the back when emits_back)
  bool emits_back = false; ///< a two-sided material emits on both sides, as in pass 1
  std::uint32_t material = 0;
  std::int32_t mirror = -1;  ///< index into mirrors_ for a plain planar mirror, else -1
  /// Probability density per unit area with which next-event estimation picks a point here:
  /// P(choose this polygon) / area; 0 for non-emitters.
  float light_pdf_area = 0.0f;
};

/// How a material scatters, built once per render.
struct Shading {
  /// A plain Lambertian reflector (no specular, transmission, translucency or own BRDF): the
  /// original diffuse code path, with no virtual calls, so diffuse scenes render exactly as
  /// they did before materials had models.
  bool lambertian = true;
  Rgb reflectance{0.0f};  ///< the Lambertian albedo (lambertian only)
  bool two_sided = false;  ///< hit from the back, flip the frame (never for refracting materials)
  /// make_brdf(material) (not lambertian only), evaluated in the frame of the side hit.
  std::shared_ptr<const Brdf> model;
  bool model_delta = false;  ///< the model has no non-delta part: no light sampling for it
  /// The model is known to be one-sided (derived from the fields, no specular transmission),
  /// so calling it from the unflipped back is pointless.
  bool model_one_sided = true;
  float ior = 1.0f;  ///< index of the back side, for the radiance scale across a refraction
  Rgb translucency{0.0f};  ///< Material::diffuse_transmittance: f = tau / pi on the far side
  /// Probability of sampling the translucent lobe where the model also scatters, in proportion
  /// to the two parts' largest albedos at normal incidence.
  float translucent_share = 0.0f;
  /// Seen from the back the surface is black and ends the path (as in the radiosity solver).
  bool back_black = true;
};

/// An emitting polygon, fan-triangulated for uniform area sampling.
struct Emitter {
  std::uint32_t polygon = 0;
  detail::PolygonFan fan;
};

/// A polygon whose material is a plain one-sided ideal mirror (specular only, exponent 0), for
/// light sampling through its mirror image.
struct MirrorFace {
  glm::vec3 normal{0.0f};
  glm::vec3 origin{0.0f};
  Rgb reflectance{0.0f};
  std::vector<glm::vec3> vertices;  ///< counter-clockwise seen from the front
};

/// What the MIS weight of an emitter hit needs when the path reached it by one mirror
/// reflection from a vertex that also sampled light through the mirrors.
struct MirrorPath {
  bool valid = false;
  glm::vec3 x{0.0f};     ///< the non-delta vertex
  float pdf_bsdf = 0.0f;  ///< solid-angle pdf of its bounce towards the mirror
};

class PathTracer {
 public:
  PathTracer(const Scene& scene, const PathTraceOptions& options)
      : options_(options),
        rays_(detail::RayScene::from_polygons(scene)),
        camera_(options.camera ? *options.camera
                               : detail::choose_camera(scene, rays_, [](std::uint32_t id) { return PolygonId{id}; }).camera,
                options.width, options.height),
        lights_(scene.lights()),
        through_(scene, false),
        g_(static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options.spp)) - 1e-9))) {
    // Each material's model is built once here; the render only reads it.
    for (const Material& m : scene.materials()) shading_.push_back(make_shading(m));
    const auto& polygons = scene.polygons();
    surfaces_.resize(polygons.size());
    std::vector<double> emitter_power;
    for (std::size_t p = 0; p < polygons.size(); ++p) {
      const Polygon& poly = polygons[p];
      const Material& m = scene.material(poly.material);
      Surface& s = surfaces_[p];
      s.normal = poly.normal;
      s.origin = poly.vertices[0];
      s.emission = m.emission;
      s.emits_back = m.two_sided;
      s.material = poly.material;
      if (is_plain_mirror(m)) {
        s.mirror = static_cast<std::int32_t>(mirrors_.size());
        mirrors_.push_back(MirrorFace{poly.normal, poly.vertices[0], m.specular, poly.vertices});
      }
      const double power = static_cast<double>(m.emission.x + m.emission.y + m.emission.z) * poly.area;
      if (!(power > 0.0)) continue;
      emitters_.push_back(Emitter{static_cast<std::uint32_t>(p), detail::PolygonFan(poly.vertices)});
      emitter_power.push_back(power);
    }
    // Emitters are chosen in proportion to their power summed over channels.
    emitter_choice_ = detail::DiscreteDistribution(emitter_power);
    for (std::size_t i = 0; i < emitters_.size(); ++i) {
      const std::uint32_t p = emitters_[i].polygon;
      surfaces_[p].light_pdf_area = static_cast<float>(emitter_choice_.probability(i) / polygons[p].area);
    }
    // Ray offsets: far above float rounding at the scene's scale, far below any feature.
    epsilon_ = std::max(1e-5f * scene.bounds().diagonal(), 1e-6f);
  }

  Image render() const {
    Image image(options_.width, options_.height);
    const std::size_t paths_per_row = static_cast<std::size_t>(options_.width) * g_ * g_;
    detail::ImageBands bands;
    bands.rows = static_cast<int>(std::max<std::size_t>(1, kPathsPerBand / paths_per_row));
    bands.grain = std::max<std::size_t>(1, 1024 / (static_cast<std::size_t>(g_) * g_));
    detail::for_each_pixel(options_, bands, [&](int x, int y) { image.at(x, y) = pixel(x, y); });
    return image;
  }

 private:
  /// Exactly the materials for which make_brdf() returns make_mirror(specular).
  static bool is_plain_mirror(const Material& m) {
    return !m.brdf && !m.two_sided && max_component(m.specular) > 0.0f && m.specular_exponent <= 0.0f &&
           !(max_component(m.reflectance) > 0.0f) && !(max_component(m.transmittance) > 0.0f) &&
           !(max_component(m.diffuse_transmittance) > 0.0f);
  }

  static Shading make_shading(const Material& m) {
    Shading sh;
    sh.two_sided = m.two_sided && !(max_component(m.transmittance) > 0.0f);
    sh.translucency = m.diffuse_transmittance;
    sh.lambertian = !m.brdf && !(max_component(m.specular) > 0.0f) && !(max_component(m.transmittance) > 0.0f) &&
                    !(max_component(m.diffuse_transmittance) > 0.0f);
    if (sh.lambertian) {
      sh.reflectance = m.reflectance;
      sh.back_black = !sh.two_sided;
      return sh;
    }
    sh.model = make_brdf(m);
    sh.model_delta = sh.model->is_delta();
    sh.model_one_sided = !m.brdf && !(max_component(m.transmittance) > 0.0f);
    sh.ior = m.ior;
    const float a_model = max_component(sh.model->albedo(glm::vec3(0.0f, 0.0f, 1.0f)));
    const float a_translucent = max_component(m.diffuse_transmittance);
    if (a_translucent > 0.0f) sh.translucent_share = a_translucent / (a_translucent + a_model);
    sh.back_black = !sh.two_sided && sh.model_one_sided && !(a_translucent > 0.0f);
    return sh;
  }

  /// Box-filtered mean of g x g jittered paths through the pixel, from the pixel's own stream.
  Rgb pixel(int x, int y) const {
    const std::uint64_t index = static_cast<std::uint64_t>(y) * options_.width + x;
    detail::Rng rng(options_.seed, index, detail::stream_key(detail::Stream::path));
    double sum[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < g_; ++j)
      for (int i = 0; i < g_; ++i) {
        const glm::vec2 u = rng.uniform2();
        const float sx = (static_cast<float>(x) + (static_cast<float>(i) + u.x) / g_) / options_.width;
        const float sy = (static_cast<float>(y) + (static_cast<float>(j) + u.y) / g_) / options_.height;
        const Rgb L = trace(camera_.eye, camera_.direction(sx, sy), rng);
        for (int c = 0; c < 3; ++c) sum[c] += L[c];
      }
    const double n = static_cast<double>(g_) * g_;
    return Rgb(static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n));
  }

  /// Radiance arriving at `origin` from direction -`dir` (one path sample).
  Rgb trace(glm::vec3 origin, glm::vec3 dir, detail::Rng& rng) const {
    Rgb L(0.0f);
    Rgb beta(1.0f);            // path throughput: product of f cos / pdf so far
    glm::vec3 prev_x = origin;  // the previous vertex (for the MIS weight of an emitter hit)
    float prev_pdf = 0.0f;     // solid-angle pdf of the bounce that produced `dir`
    bool prev_delta = false;   // that bounce was a delta event, which light sampling cannot make
    // The previous vertex also sampled light through the mirrors, and `dir` left it by a
    // non-delta bounce; and, when `dir` leaves a mirror reached that way, that vertex's data.
    bool mirror_sampled = false;
    MirrorPath via_mirror;
    // Product of the (eta_i / eta_o)^2 radiance scales applied so far, divided out again for
    // Russian roulette so that a path inside glass is not killed for its lower radiance.
    float eta_scale = 1.0f;
    float tnear = 0.0f;
    for (int depth = 0;; ++depth) {
      const auto hit = rays_.intersect(origin, dir, tnear, std::numeric_limits<float>::infinity());
      if (!hit) {
        // Escaped: the sky's radiance in full. It is not light-sampled, so no MIS weight.
        if (lights_.has_sky()) L += beta * lights_.sky_radiance(dir);
        break;
      }
      const Surface& s = surfaces_[hit->id];
      const Shading& sh = shading_[s.material];
      // One-sided surfaces: the back of a polygon absorbs, as in the radiosity solver.
      const float cos_in = -glm::dot(s.normal, dir);
      const bool front = cos_in > 0.0f;
      if (!front && (sh.back_black || !(cos_in < 0.0f))) break;
      glm::vec3 x = origin + hit->t * dir;
      x -= s.normal * glm::dot(x - s.origin, s.normal);  // snap onto the polygon's plane

      // Emission (the front's, and a two-sided emitter's back) seen along the path: in full
      // from the camera or after a delta event (no light sample can produce those paths);
      // after any other bounce weighted against next-event estimation, which samples the same
      // paths (Veach eq. 9.13).
      if ((front || s.emits_back) && s.light_pdf_area > 0.0f) {
        const float cos_light = std::abs(cos_in);
        if (depth == 0 || (prev_delta && !via_mirror.valid)) {
          L += beta * s.emission * kInvPi;
        } else if (prev_delta) {
          // Reached by one mirror reflection: mirror_light() samples this path too, with the
          // pdf of the emitter's image (path length through the mirror, 1/K for the face).
          const float D = glm::length(prev_x - via_mirror.x) + glm::length(x - prev_x);
          const float pdf_mirror = s.light_pdf_area * D * D / cos_light / static_cast<float>(mirrors_.size());
          L += beta * s.emission * (kInvPi * power_heuristic(via_mirror.pdf_bsdf, pdf_mirror));
        } else {
          const glm::vec3 w = x - prev_x;
          const float pdf_light = s.light_pdf_area * glm::dot(w, w) / cos_light;
          L += beta * s.emission * (kInvPi * power_heuristic(prev_pdf, pdf_light));
        }
      }
      if (options_.max_depth > 0 && depth >= options_.max_depth) break;
      // This vertex is a mirror reached by a non-delta bounce from a vertex that sampled light
      // through the mirrors: remember that vertex for the MIS weight of an emitter hit next.
      MirrorPath next_via_mirror;
      if (s.mirror >= 0 && front && mirror_sampled) next_via_mirror = MirrorPath{true, prev_x, prev_pdf};
      // Light through a mirror makes a path two events longer than this vertex.
      const bool sample_mirrors = !mirrors_.empty() && !emitters_.empty() &&
                                  (options_.max_depth == 0 || depth + 2 <= options_.max_depth);
      mirror_sampled = false;

      if (sh.lambertian) {
        if (max_component(sh.reflectance) <= 0.0f) break;
        const glm::vec3 n = front ? s.normal : -s.normal;  // a two-sided back reflects like a front
        const glm::vec3 offset_origin = x + epsilon_ * n;
        if (!emitters_.empty()) L += beta * direct_light(x, offset_origin, n, sh.reflectance, rng);
        if (!lights_.delta().empty()) L += beta * sh.reflectance * (kInvPi * delta_irradiance(x, offset_origin, n));
        if (sample_mirrors) {
          const Rgb f = sh.reflectance * kInvPi;
          L += beta * mirror_light(x, n, rng, [&](const glm::vec3& wi, float& pdf, float& cos_x) {
                 cos_x = glm::dot(n, wi);
                 pdf = std::max(cos_x, 0.0f) * kInvPi;
                 return cos_x > 0.0f ? f : Rgb(0.0f);
               });
          mirror_sampled = true;
        }

        // Cosine-weighted bounce: f cos / pdf = (rho/pi) cos / (cos/pi) = rho.
        const glm::vec3 l = detail::cosine_hemisphere_polar(rng.uniform2());
        dir = glm::normalize(detail::Frame(n).to_world(l));
        prev_pdf = std::max(glm::dot(n, dir), 0.0f) * kInvPi;
        prev_delta = false;
        beta *= sh.reflectance;
        origin = offset_origin;
      } else if (!scatter(s, sh, front, x, sample_mirrors, dir, rng, L, beta, prev_pdf, prev_delta, mirror_sampled,
                          eta_scale, origin)) {
        break;
      }
      via_mirror = next_via_mirror;

      // Russian roulette (Arvo & Kirk 1990): survive with q = min(max beta, kMaxSurvival), reweight 1/q.
      if (depth + 1 >= kRouletteStart) {
        const float q = std::min(max_component(beta * eta_scale), kMaxSurvival);
        if (!(rng.uniform() < q)) break;
        beta /= q;
      }
      prev_x = x;
      tnear = 0.0f;
    }
    return L;
  }

  /// A vertex on a surface with a reflection model (and possibly translucency): adds the light
  /// sample to L, draws the next direction into `dir`, updates the throughput and the MIS state,
  /// and sets the next ray's `origin`. Returns false when the path ends here.
  bool scatter(const Surface& s, const Shading& sh, bool front, const glm::vec3& x, bool sample_mirrors,
               glm::vec3& dir, detail::Rng& rng, Rgb& L, Rgb& beta, float& prev_pdf, bool& prev_delta,
               bool& mirror_sampled, float& eta_scale, glm::vec3& origin) const {
    // The shading frame: the geometric normal, flipped to the viewer's side for a two-sided
    // surface. Unflipped, z > 0 is the front, whose medium has index 1 (the dielectric's "above").
    ShadingFrame frame;
    frame.normal = (!front && sh.two_sided) ? -s.normal : s.normal;
    detail::tangent_frame(frame.normal, frame.tangent, frame.bitangent);
    const glm::vec3 wo = frame.to_local(-dir);
    const bool model_on = wo.z > 0.0f || !sh.model_one_sided;
    const float p_translucent = sh.translucent_share > 0.0f ? (model_on ? sh.translucent_share : 1.0f) : 0.0f;
    if (!model_on && !(p_translucent > 0.0f)) return false;

    // The BSDF for light sampling: the model (where it is on) plus the translucent lobe on the
    // far side, with the pdf of the sampling below; delta parts are 0 here.
    const auto bsdf = [&](const glm::vec3& wi_world, float& pdf, float& cos_x) {
      const glm::vec3 wi = frame.to_local(wi_world);
      Rgb f(0.0f);
      pdf = 0.0f;
      if (model_on) {
        f = sh.model->eval(wo, wi);
        pdf = (1.0f - p_translucent) * sh.model->pdf(wo, wi);
      }
      if (p_translucent > 0.0f && wi.z * wo.z < 0.0f) {
        f += sh.translucency * kInvPi;
        pdf += p_translucent * std::abs(wi.z) * kInvPi;
      }
      cos_x = std::abs(wi.z);
      return f;
    };
    const bool has_lobe = p_translucent > 0.0f || !sh.model_delta;
    if (!emitters_.empty() && has_lobe) L += beta * direct_light(x, s.normal, rng, bsdf);
    if (!lights_.delta().empty() && has_lobe) L += beta * delta_light(x, s.normal, bsdf);
    const bool mirrors_sampled_here = sample_mirrors && has_lobe;
    if (mirrors_sampled_here) L += beta * mirror_light(x, s.normal, rng, bsdf);

    // Draw the next direction from the model or, with probability p_translucent, from the
    // cosine lobe on the far side. The weight of a non-delta direction uses the whole BSDF and
    // the whole pdf (one-sample MIS over the two parts), like Brdf mixtures do.
    glm::vec3 wi;
    Rgb weight(0.0f);
    float pdf = 0.0f;
    bool delta = false;
    const bool pick_translucent =
        p_translucent >= 1.0f || (p_translucent > 0.0f && rng.uniform() < p_translucent);
    if (pick_translucent) {
      const glm::vec3 l = detail::cosine_hemisphere_polar(rng.uniform2());
      const float cz = l.z;
      wi = glm::vec3(l.x, l.y, wo.z > 0.0f ? -cz : cz);
      const Rgb f = sh.translucency * kInvPi + (model_on ? sh.model->eval(wo, wi) : Rgb(0.0f));
      pdf = p_translucent * cz * kInvPi + (model_on ? (1.0f - p_translucent) * sh.model->pdf(wo, wi) : 0.0f);
      if (!(pdf > 0.0f)) return false;
      weight = f * (cz / pdf);
    } else {
      const std::optional<BrdfSample> b = sh.model->sample(wo, rng.uniform2());
      if (!b) return false;
      wi = b->wi;
      if (b->delta) {
        weight = b->weight / (1.0f - p_translucent);
        delta = true;
      } else if (!(p_translucent > 0.0f)) {
        weight = b->weight;
        pdf = b->pdf;
      } else {
        const bool across = wi.z * wo.z < 0.0f;
        const Rgb f = sh.model->eval(wo, wi) + (across ? sh.translucency * kInvPi : Rgb(0.0f));
        pdf = (1.0f - p_translucent) * b->pdf + (across ? p_translucent * std::abs(wi.z) * kInvPi : 0.0f);
        weight = f * (std::abs(wi.z) / pdf);
      }
      if (!delta && !(pdf > 0.0f)) return false;
    }
    // A refraction carries radiance from the index of wi's side n_i into wo's side n_o, scaled
    // by (n_o / n_i)^2 (Veach 1997, ch. 5). The models leave it out (brdf.hpp); a camera path
    // applies it, so that an emitter inside glass is seen at its true radiance. On a path that
    // enters and leaves glass the factors cancel.
    if (delta && wi.z * wo.z < 0.0f) {
      const float n_o = wo.z > 0.0f ? 1.0f : sh.ior, n_i = wi.z > 0.0f ? 1.0f : sh.ior;
      const float scale = (n_o * n_o) / (n_i * n_i);
      weight *= scale;
      eta_scale /= scale;
    }
    if (!(max_component(weight) > 0.0f) || !std::isfinite(max_component(weight))) return false;

    dir = glm::normalize(frame.to_world(wi));
    beta *= weight;
    prev_pdf = pdf;
    prev_delta = delta;
    mirror_sampled = mirrors_sampled_here && !delta;
    origin = offset_towards(x, s.normal, dir);
    return true;
  }

  /// A path from a surface point to a point on an emitter, before its shadow rays.
  struct Connection {
    glm::vec3 lit_side{0.0f};  ///< normal of the emitter's side that the light leaves
    float cos_y = 0.0f;        ///< cosine at the emitter
    Rgb f{0.0f};               ///< the BSDF at the surface point for the arriving direction
    float pdf_bounce = 0.0f;   ///< the BSDF's pdf of sampling that direction (for MIS)
    float cos_x = 0.0f;        ///< cosine at the surface point
  };

  /// Fills `c` for light that arrives at `light` along `at_light` (the last leg's direction,
  /// towards the emitter) and leaves the surface point along `wi`; false when that side of the
  /// emitter does not emit or the BSDF is 0 (nothing to trace).
  template <class Bsdf>
  static bool connect(const Surface& light, const glm::vec3& at_light, const glm::vec3& wi, const Bsdf& bsdf,
                      Connection& c) {
    c.cos_y = emitter_cosine(light, at_light, c.lit_side);
    if (c.cos_y <= 0.0f) return false;
    c.f = bsdf(wi, c.pdf_bounce, c.cos_x);
    return max_component(c.f) > 0.0f;
  }

  /// x moved off its surface (unit normal `normal`) to the side that direction `w` leaves
  /// from, so that a ray from there does not hit the surface itself.
  glm::vec3 offset_towards(const glm::vec3& x, const glm::vec3& normal, const glm::vec3& w) const {
    return x + (glm::dot(w, normal) > 0.0f ? epsilon_ : -epsilon_) * normal;
  }

  /// The cosine at an emitter of light leaving it against `wi` (the direction from the lit
  /// point towards the emitter), or <= 0 when that side does not emit; `lit_side` is the
  /// normal of the side it leaves.
  static float emitter_cosine(const Surface& light, const glm::vec3& wi, glm::vec3& lit_side) {
    const float c = -glm::dot(light.normal, wi);
    lit_side = c < 0.0f && light.emits_back ? -light.normal : light.normal;
    return light.emits_back ? std::abs(c) : c;
  }

  /// A uniform point on an emitter chosen by power, and that emitter.
  const Surface& sample_light(detail::Rng& rng, glm::vec3& y) const {
    const Emitter& e = emitters_[emitter_choice_.sample(rng.uniform())];
    const std::size_t tri = e.fan.triangle(rng.uniform());
    y = e.fan.point(tri, rng.uniform2());
    return surfaces_[e.polygon];
  }

  /// A point on an emitter seen from a surface point x.
  struct LightSample {
    const Surface* light = nullptr;
    glm::vec3 y{0.0f};   ///< the point on the emitter
    glm::vec3 wi{0.0f};  ///< unit direction from x to y
    float d2 = 0.0f;     ///< squared distance from x to y
  };

  /// A point on an emitter chosen by power (sample_light()) and where it lies from x; false
  /// when it coincides with x.
  bool sample_towards_light(const glm::vec3& x, detail::Rng& rng, LightSample& s) const {
    s.light = &sample_light(rng, s.y);
    const glm::vec3 w = s.y - x;
    s.d2 = glm::dot(w, w);
    if (!(s.d2 > 0.0f)) return false;
    s.wi = w / std::sqrt(s.d2);
    return true;
  }

  /// Next-event estimate of the light reflected at x towards the previous vertex, divided by
  /// the throughput: one point on one emitter, MIS-weighted against the cosine bounce.
  Rgb direct_light(const glm::vec3& x, const glm::vec3& offset_origin, const glm::vec3& n, const Rgb& rho,
                   detail::Rng& rng) const {
    LightSample ls;
    if (!sample_towards_light(x, rng, ls)) return Rgb(0.0f);
    const Surface& light = *ls.light;
    const glm::vec3 &y = ls.y, &wi = ls.wi;
    const float d2 = ls.d2;
    glm::vec3 lit_side;
    const float cos_x = glm::dot(n, wi), cos_y = emitter_cosine(light, wi, lit_side);
    if (cos_x <= 0.0f || cos_y <= 0.0f) return Rgb(0.0f);

    // Shadow ray between the two offset points (both on the lit sides of their planes).
    const glm::vec3 target = y + epsilon_ * lit_side;
    const glm::vec3 sw = target - offset_origin;
    const float dist = glm::length(sw);
    if (rays_.occluded(offset_origin, sw / dist, 0.0f, dist)) return Rgb(0.0f);

    // Area pdf to solid angle: p_w = p_A r^2 / cos_y (Veach eq. 8.10).
    const float pdf_light = light.light_pdf_area * d2 / cos_y;
    const float pdf_bounce = cos_x * kInvPi;
    // f L_e cos_x / p_w, with f = rho/pi and L_e = E/pi.
    return rho * light.emission * (kInvPi * kInvPi * cos_x / pdf_light * power_heuristic(pdf_light, pdf_bounce));
  }

  /// The same for a surface with a model: `bsdf(wi, pdf, cos_x)` returns f (model plus
  /// translucency) for the world direction wi and sets scatter()'s pdf of wi and |cos|. Delta
  /// parts contribute nothing here (a light sample never hits a delta direction) and block
  /// shadow rays.
  template <class Bsdf>
  Rgb direct_light(const glm::vec3& x, const glm::vec3& normal, detail::Rng& rng, const Bsdf& bsdf) const {
    LightSample ls;
    if (!sample_towards_light(x, rng, ls)) return Rgb(0.0f);
    const Surface& light = *ls.light;
    const glm::vec3 &y = ls.y, &wi = ls.wi;
    const float d2 = ls.d2;
    Connection c;
    if (!connect(light, wi, wi, bsdf, c)) return Rgb(0.0f);
    const glm::vec3& lit_side = c.lit_side;

    // Shadow ray from the side of x that wi leaves from to the lit side of the emitter.
    const glm::vec3 start = offset_towards(x, normal, wi);
    const glm::vec3 sw = y + epsilon_ * lit_side - start;
    const float dist = glm::length(sw);
    if (rays_.occluded(start, sw / dist, 0.0f, dist)) return Rgb(0.0f);

    const float pdf_light = light.light_pdf_area * d2 / c.cos_y;
    return c.f * light.emission * (kInvPi * c.cos_x / pdf_light * power_heuristic(pdf_light, c.pdf_bounce));
  }

  /// The irradiance at x (offset to `offset_origin` along the unit normal n) from the point,
  /// spot and directional lights, each with a shadow ray. Delta lights cannot be hit by a
  /// bounce, so this is their whole contribution: no MIS.
  Rgb delta_irradiance(const glm::vec3& x, const glm::vec3& offset_origin, const glm::vec3& n) const {
    Rgb E(0.0f);
    for (const detail::PreparedLight& l : lights_.delta()) {
      detail::Incidence in;
      if (!detail::incidence(l, x, in)) continue;
      const float cos_x = glm::dot(n, in.wi);
      if (cos_x > 0.0f) E += in.irradiance * cos_x * detail::light_transmittance(rays_, through(), offset_origin, l.position, in, epsilon_);
    }
    return E;
  }

  /// The same for a surface with a model: f(wi) E_l cos_x for each delta light, the shadow ray
  /// from the side of x that wi leaves from (a translucent surface is lit from behind too).
  template <class Bsdf>
  Rgb delta_light(const glm::vec3& x, const glm::vec3& normal, const Bsdf& bsdf) const {
    Rgb out(0.0f);
    for (const detail::PreparedLight& l : lights_.delta()) {
      detail::Incidence in;
      if (!detail::incidence(l, x, in)) continue;
      float pdf = 0.0f, cos_x = 0.0f;
      const Rgb f = bsdf(in.wi, pdf, cos_x);
      if (!(max_component(f) > 0.0f)) continue;
      out += f * in.irradiance * cos_x *
             detail::light_transmittance(rays_, through(), offset_towards(x, normal, in.wi), l.position, in, epsilon_);
    }
    return out;
  }

  /// Light that reaches x by one reflection in a plain planar mirror, sampled through the
  /// emitters' mirror images (the virtual sources of Wallace, Cohen & Greenberg 1987): a mirror
  /// face chosen uniformly, a point y on an emitter as in direct_light(), and the direction to
  /// y's image y' behind the mirror's plane. The path x -> p -> y exists when x and y are in
  /// front of the mirror and the segment x y' crosses the mirror polygon at p; its length is
  /// |x - y'|. MIS-weighted against BSDF sampling, which finds the same path when a bounce from
  /// x hits the mirror and then the emitter (see trace()). Without it the light a mirror throws
  /// onto diffuse surfaces is found only by BSDF sampling, which is far noisier.
  template <class Bsdf>
  Rgb mirror_light(const glm::vec3& x, const glm::vec3& normal, detail::Rng& rng, const Bsdf& bsdf) const {
    const std::size_t k = static_cast<std::size_t>(rng.uniform() * static_cast<float>(mirrors_.size()));
    const MirrorFace& m = mirrors_[std::min(k, mirrors_.size() - 1)];
    glm::vec3 y;
    const Surface& light = sample_light(rng, y);
    const float hx = glm::dot(x - m.origin, m.normal), hy = glm::dot(y - m.origin, m.normal);
    if (!(hx > 0.0f) || !(hy > 0.0f)) return Rgb(0.0f);

    const glm::vec3 w = y - 2.0f * hy * m.normal - x;  // towards the image y'
    const float d2 = glm::dot(w, w);
    if (!(d2 > 0.0f)) return Rgb(0.0f);
    const float D = std::sqrt(d2);
    const glm::vec3 wi = w / D;
    // The segment crosses the plane where it has descended hx of its hx + hy.
    const glm::vec3 p = x + (D * hx / (hx + hy)) * wi;
    const std::size_t n = m.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
      const glm::vec3& a = m.vertices[i];
      if (glm::dot(glm::cross(m.vertices[(i + 1) % n] - a, p - a), m.normal) < 0.0f) return Rgb(0.0f);
    }
    const glm::vec3 wr = wi - 2.0f * glm::dot(wi, m.normal) * m.normal;  // from p towards y
    Connection c;
    if (!connect(light, wr, wi, bsdf, c)) return Rgb(0.0f);
    const glm::vec3& lit_side = c.lit_side;

    // Both legs unoccluded: x to just in front of p, and from there to the emitter.
    const glm::vec3 start = offset_towards(x, normal, wi);
    const glm::vec3 at_mirror = p + epsilon_ * m.normal;
    const glm::vec3 leg1 = at_mirror - start, leg2 = y + epsilon_ * lit_side - at_mirror;
    const float l1 = glm::length(leg1), l2 = glm::length(leg2);
    if (!(l1 > 0.0f) || !(l2 > 0.0f)) return Rgb(0.0f);
    if (rays_.occluded(start, leg1 / l1, 0.0f, l1) || rays_.occluded(at_mirror, leg2 / l2, 0.0f, l2))
      return Rgb(0.0f);

    const float pdf_light = light.light_pdf_area * d2 / c.cos_y / static_cast<float>(mirrors_.size());
    return c.f * m.reflectance * light.emission *
           (kInvPi * c.cos_x / pdf_light * power_heuristic(pdf_light, c.pdf_bounce));
  }

  const PathTraceOptions& options_;
  detail::RayScene rays_;  // before camera_: choose_camera() looks through it
  detail::PinholeCamera camera_;
  detail::SceneLights lights_;  ///< Scene::lights(): delta lights sampled at every vertex, the sky seen by escaping rays
  /// The delta lights' shadow rays pass windows (ior 1: straight through, times their
  /// transmittance, which is what the window's own model does to a ray), so a lamp or the sun
  /// behind a pane is found; glass is left as the refracting interface it is (a delta light
  /// beyond it has no sampling strategy).
  detail::PassThrough through_;
  const detail::PassThrough* through() const { return through_.any() ? &through_ : nullptr; }
  int g_;
  float epsilon_ = 0.0f;
  std::vector<Surface> surfaces_;
  std::vector<Shading> shading_;  ///< by material id
  std::vector<Emitter> emitters_;
  std::vector<MirrorFace> mirrors_;
  detail::DiscreteDistribution emitter_choice_;  ///< over emitters_, by power
};

}  // namespace

void validate(const PathTraceOptions& options) {
  const std::string problem = detail::image_options_problem(options);
  if (!problem.empty()) bad_option(problem);
  if (options.max_depth < 0)
    bad_option("max_depth must be >= 0 (0 = unlimited), got " + std::to_string(options.max_depth));
}

Image render_path_traced(const Scene& scene, const PathTraceOptions& options) {
  validate(options);
  const PathTracer tracer(scene, options);
  return tracer.render();
}

}  // namespace v1
}  // namespace radiosity
