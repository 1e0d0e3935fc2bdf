// The lights' first shot: the mean direct irradiance over each element side from each Light.
// Based on:
//   J. Wallace, K. Elmquist & E. Haines, "A ray tracing algorithm for progressive radiosity",
//     SIGGRAPH 1989 (direct light onto elements by shadow rays from sample points).
//   J. H. Halton, Numerische Mathematik 2, 1960, randomised by R. Cranley & T. Patterson, SIAM
//     J. Numer. Anal. 13(6), 1976 (the sky's points and directions; core/halton.hpp).
//   M. Cohen & J. Wallace, "Radiosity and Realistic Image Synthesis" (1993), sec. 4.10 (the
//     unoccluded factor times a visible fraction; here exact unoccluded irradiance, so an
//     element that sees all of a light gets it without noise).
//   A. van Oosterom & J. Strackee, "The solid angle of a plane triangle", IEEE Trans. Biomed.
//     Eng. 30(2), 1983 (tan(Omega / 2) in closed form).
//   The Khronos Group, "KHR_lights_punctual" (2018) and CIE S 011/E:2003 (the lights' units and
//     distributions; see scene/lights.hpp).
//
// Each element side e and light l gives H(e, l) = H_unoccluded(e, l) x V(e, l):
// - H_unoccluded, the element mean of what l sends onto the side without occlusion, is exact:
//   I Omega_e / A_e for a point light (the integral of I cos / r^2 over the element is I times
//   the solid angle it subtends), the spot's falloff integrated over that solid angle, E cos for
//   a directional light, the closed-form sky irradiance of a plane for a sky (scene/lights.cpp).
// - V, the visible part, is a weighted fraction of shadow rays from points of the element: from
//   stratified points to the light (point, spot) or along -direction (directional); for a sky,
//   points and cosine-weighted directions from one randomised 4D Halton set (core/halton.hpp:
//   half the rays of a stratified point set shuffled against a stratified direction set, for
//   the same error; docs/LIGHTS.md). Each ray weighs what its point would
//   receive unoccluded (I t cos / r^2; the sky's radiance in its direction), so V is the
//   irradiance-weighted visible fraction. A first pass whose rays all agree gives V = 1 or 0;
//   otherwise a second, larger pass is cast and both make the estimate (visibility.hpp's idea).
#include "solver/light_shot.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/geometric.hpp>

#include "core/color.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/halton.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "core/streams.hpp"
#include "form_factors/pass1_material.hpp"

namespace radiosity::detail {

namespace {

/// Shadow rays to a point light stop this fraction of the segment short of it (lights.cpp).
constexpr float kShadowEnd = 1.0f - 1e-4f;
/// Elements per progress report and cancel check: the first block's, then BlockSizer's choice
/// (a sky costs SolveOptions::sky_rays rays per element, a point light one) within these.
constexpr std::size_t kFirstBlock = 32, kSmallestBlock = 8, kLargestBlock = 16384;
/// Spot integration: cells are split until they are this small (radians of angular diameter)
/// where the falloff is smooth, or this deep where a cone's edge crosses them.
constexpr double kSmoothDiameter = 0.02;
constexpr int kMaxSpotDepth = 8;

/// The solid angle of the triangle (a, b, c) given as vectors from the viewpoint (van Oosterom
/// & Strackee), in [0, 2 pi), whichever side is seen.
double solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = std::fabs(glm::dot(a, glm::cross(b, c)));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

double angle_between(const glm::dvec3& u, const glm::dvec3& v) {
  return std::acos(std::clamp(glm::dot(u, v), -1.0, 1.0));
}

/// The integral over the solid angle of triangle (a, b, c) (vectors from the light) of the
/// spot's falloff. Cells wholly outside the outer cone or inside the inner one are exact; the
/// others are split into four until the falloff is smooth over them (then the midpoint rule)
/// or the depth limit is reached.
double spot_integral(const PreparedLight& light, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                     double inner, double outer, int depth) {
  const double omega = solid_angle(a, b, c);
  if (!(omega > 0.0)) return 0.0;
  const glm::dvec3 axis(light.direction);
  const glm::dvec3 da = glm::normalize(a), db = glm::normalize(b), dc = glm::normalize(c);
  const double ta = angle_between(da, axis), tb = angle_between(db, axis), tc = angle_between(dc, axis);
  // Every direction of the cell lies within its angular diameter of each corner.
  const double diameter = std::max({angle_between(da, db), angle_between(db, dc), angle_between(dc, da)});
  const double lo = std::min({ta, tb, tc}) - diameter, hi = std::max({ta, tb, tc}) + diameter;
  if (lo >= outer) return 0.0;
  if (hi <= inner) return omega;
  const bool smooth = lo >= inner && hi <= outer;  // no cone edge (a kink of the falloff) inside
  if (depth >= kMaxSpotDepth || (smooth && diameter < kSmoothDiameter))
    return omega * light.falloff(glm::vec3(glm::normalize(a + b + c)));
  const glm::dvec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  return spot_integral(light, a, ab, ca, inner, outer, depth + 1) + spot_integral(light, ab, b, bc, inner, outer, depth + 1) +
         spot_integral(light, ca, bc, c, inner, outer, depth + 1) + spot_integral(light, ab, bc, ca, inner, outer, depth + 1);
}

/// The rays of one pass over one element side, one buffer per thread.
struct LightRays {
  std::vector<glm::vec2> point_uv, direction_uv;
  std::vector<glm::vec3> origin, direction;
  std::vector<float> weight;
  std::vector<std::uint8_t> blocked;

  static LightRays& for_this_thread() {
    thread_local LightRays rays;
    return rays;
  }
};

}  // namespace

Rgb unoccluded_cell_irradiance(const PreparedLight& light, const glm::vec3* corners, int count, float area,
                               const glm::vec3& n) {
  RADIOSITY_ASSERT(count == 3 || count == 4);
  if (!(area > 0.0f)) return Rgb(0.0f);
  if (light.type == LightType::directional) return light.power * std::max(0.0f, -glm::dot(n, light.direction));
  if (light.type == LightType::sky) return light.sky_irradiance(n);
  // Point and spot: only the side that faces the light receives it.
  const glm::dvec3 L(light.position);
  if (!(glm::dot(glm::dvec3(corners[0]) - L, glm::dvec3(n)) < 0.0)) return Rgb(0.0f);
  double omega = 0.0;
  const double inner = std::acos(static_cast<double>(light.cos_inner)),
               outer = std::acos(static_cast<double>(light.cos_outer));
  for (int k = 1; k + 1 < count; ++k) {
    const glm::dvec3 a = glm::dvec3(corners[0]) - L, b = glm::dvec3(corners[k]) - L, c = glm::dvec3(corners[k + 1]) - L;
    omega += light.type == LightType::spot ? spot_integral(light, a, b, c, inner, outer, 0) : solid_angle(a, b, c);
  }
  return light.power * static_cast<float>(omega / static_cast<double>(area));
}

LightShooter::LightShooter(const Scene& scene, const PatchHierarchy& hierarchy, std::uint64_t seed, unsigned threads,
                           std::uint32_t sky_rays, bool through_windows)
    : hierarchy_(hierarchy),
      lights_(scene.lights()),
      occluders_(RayScene::from_polygons(scene)),
      sky_budget_(sky_ray_budget(sky_rays)),
      seed_(seed),
      threads_(threads) {
  // The estimators' ray offset: far above float rounding at the scene's scale, far below any feature.
  epsilon_ = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
  patch_has_back_.resize(hierarchy.patches().size());
  for (std::size_t p = 0; p < patch_has_back_.size(); ++p)
    patch_has_back_[p] = pass1_has_back(scene.material(hierarchy.patches()[p].material)) ? 1 : 0;
  if (through_windows) through_ = PassThrough::if_any(scene, true);
}

Rgb LightShooter::element_irradiance(std::uint32_t e, bool back_side, std::uint64_t& rays,
                                     const std::vector<char>* only) const {
  const Element& el = hierarchy_.element(e);
  const int count = el.corner_count();
  glm::vec3 corners[4];
  for (int k = 0; k < count; ++k) corners[k] = hierarchy_.vertices()[el.corners[static_cast<std::size_t>(k)]];
  const glm::vec3 n = back_side ? -hierarchy_.normal(e) : hierarchy_.normal(e);
  const CellSampler sampler(corners, count);
  const Frame frame(n);
  LightRays& r = LightRays::for_this_thread();

  Rgb H(0.0f);
  for (const PreparedLight& light : lights_.all()) {
    if (only && !(*only)[light.id]) continue;
    const Rgb unoccluded = unoccluded_cell_irradiance(light, corners, count, el.area, n);
    if (!(unoccluded.x > 0.0f || unoccluded.y > 0.0f || unoccluded.z > 0.0f)) continue;
    Rng rng(seed_, e, stream_key(back_side ? Stream::light_back : Stream::light_front, light.id));
    const bool sky = light.type == LightType::sky;
    const bool to_point = light.type == LightType::point || light.type == LightType::spot;
    const LightRayBudget budget = sky ? sky_budget_ : kDeltaLightRays;
    // Generates and traces one pass of `points` rays; returns how many were traced and how many
    // of those were clear, adding their weights to the sums. A ray's transmittance T is 1 when
    // clear, 0 when blocked, and between through windows and glass (through_).
    double weight_sum = 0.0;
    glm::dvec3 visible_sum(0.0);
    std::uint32_t traced_total = 0, clear_total = 0, drawn = 0;
    bool agree = true;  // every ray's T so far the same (first_T)
    Rgb first_T(0.0f);
    // A sky's rays: points and directions from one randomised Halton set in four dimensions,
    // the second pass continuing the first's points (core/halton.hpp).
    const std::optional<ShiftedHalton4> halton = sky ? std::optional<ShiftedHalton4>(rng) : std::nullopt;
    auto pass = [&](std::uint32_t points, std::uint32_t& traced, std::uint32_t& clear) {
      r.point_uv.resize(points);
      r.origin.resize(points);
      r.direction.resize(points);
      r.weight.resize(points);
      r.blocked.resize(points);
      if (sky) {
        r.direction_uv.resize(points);
        for (std::uint32_t k = 0; k < points; ++k) halton->point(drawn + k, r.direction_uv[k], r.point_uv[k]);
      } else {
        stratified(points, rng, true, r.point_uv.data());
      }
      drawn += points;
      traced = 0;
      for (std::uint32_t k = 0; k < points; ++k) {
        const glm::vec3 x = sampler(r.point_uv[k]);
        const glm::vec3 origin = x + epsilon_ * n;
        glm::vec3 dir;
        float w = 1.0f;
        if (to_point) {
          dir = light.position - origin;
          Incidence in;
          w = incidence(light, x, in) ? std::max(0.0f, glm::dot(n, in.wi)) * channel_mean(in.irradiance) : 0.0f;
        } else if (sky) {
          const glm::vec3 l = cosine_hemisphere(r.direction_uv[k]);
          dir = frame.to_world(l);  // unit: the frame is orthonormal
          w = channel_mean(light.sky_radiance(dir));
          if (!(w > 0.0f)) continue;  // below the horizon: no sky there to hide
        } else {
          dir = -light.direction;
        }
        r.origin[traced] = origin;
        r.direction[traced] = dir;
        r.weight[traced] = w;
        ++traced;
      }
      // Rays to a point or along a direction travel together; sky rays spread over the
      // hemisphere, where packets only slow Embree down.
      if (sky)
        occluders_.occluded_incoherent(traced, r.origin.data(), r.direction.data(), 0.0f,
                                       std::numeric_limits<float>::infinity(), r.blocked.data());
      else
        occluders_.occluded(traced, r.origin.data(), r.direction.data(), 0.0f,
                            to_point ? kShadowEnd : std::numeric_limits<float>::infinity(), r.blocked.data());
      rays += traced;
      clear = 0;
      const float tfar = to_point ? kShadowEnd : std::numeric_limits<float>::infinity();
      for (std::uint32_t k = 0; k < traced; ++k) {
        Rgb T(r.blocked[k] == 0 ? 1.0f : 0.0f);
        if (r.blocked[k] != 0 && through_) {
          const float step = to_point ? epsilon_ / glm::length(r.direction[k]) : epsilon_;
          T = through_->transmittance(occluders_, r.origin[k], r.direction[k], 0.0f, tfar, step);
        }
        if (traced_total + k == 0) first_T = T;
        agree = agree && T == first_T;
        clear += r.blocked[k] == 0 ? 1u : 0u;
        weight_sum += r.weight[k];
        visible_sum += static_cast<double>(r.weight[k]) * glm::dvec3(T);
      }
      traced_total += traced;
      clear_total += clear;
    };
    std::uint32_t traced = 0, clear = 0;
    pass(budget.first, traced, clear);
    Rgb V(1.0f);
    if (traced > 0 && agree) {
      V = first_T;  // all clear, all blocked, or all through the same panes alike
    } else {
      // A penumbra (or, for a sky seen nearly edge-on, no direction above the horizon yet).
      pass(budget.penumbra, traced, clear);
      if (traced_total == 0)
        V = Rgb(1.0f);  // the lune of sky this side sees is too thin to sample: taken as unoccluded
      else if (weight_sum > 0.0)
        V = Rgb(visible_sum / weight_sum);
      else
        V = Rgb(static_cast<float>(clear_total) / static_cast<float>(traced_total));
    }
    H += unoccluded * V;
  }
  return H;
}

bool LightShooter::shoot(const std::vector<std::uint32_t>& elements, LightShot& shot, ProgressGate& gate,
                         const std::vector<char>* only) const {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<std::uint32_t> todo = shot.pending(elements, hierarchy_.elements().size());
  if (todo.empty()) return true;  // kept from an earlier solve: no time spent
  bool completed = true;
  if (!lights_.empty()) {
    std::vector<std::uint64_t> rays(todo.size(), 0);
    BlockSizer blocks(kFirstBlock, kSmallestBlock, kLargestBlock);
    for (std::size_t begin = 0, end = 0; begin < todo.size(); begin = end) {
      end = std::min(todo.size(), begin + blocks.size());
      parallel_for(threads_, end - begin, 8, [&](std::size_t lo, std::size_t hi) {
        for (std::size_t i = begin + lo; i < begin + hi; ++i) {
          const std::uint32_t e = todo[i];
          shot.front[e] = element_irradiance(e, false, rays[i], only);
          if (patch_has_back_[hierarchy_.element(e).patch]) shot.back[e] = element_irradiance(e, true, rays[i], only);
          shot.done[e] = 1;
        }
      });
      blocks.done(end - begin);
      Progress p;
      p.phase = Phase::lights;
      p.fraction = static_cast<double>(end) / static_cast<double>(todo.size());
      if (!gate.report(p, end == todo.size())) {
        completed = false;
        break;
      }
    }
    for (std::uint64_t n : rays) shot.rays += n;
  } else {
    for (std::uint32_t e : todo) shot.done[e] = 1;
  }
  shot.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return completed;
}

}  // namespace radiosity::detail
