// The visible fraction of a pair of surfaces by shadow rays: the one estimator behind the
// ray-cast estimator's V(element, patch) and the Monte Carlo estimator's V(element, emitting
// polygon).
// Based on: J. Wallace, K. Elmquist & E. Haines, "A ray tracing algorithm for progressive
// radiosity", SIGGRAPH 1989 (visibility as the fraction of clear rays between sampled points);
// M. Cohen & J. Wallace, "Radiosity and Realistic Image Synthesis" (1993), sec. 4.10 (weighting
// the rays by the point-to-point kernel); I. Wald, P. Slusallek, C. Benthin & M. Wagner,
// "Interactive rendering with coherent ray tracing", Eurographics 2001 (tracing the rays of a
// pair together as packets).
//
// V = integral over x, y of K(x, y) vis(x, y) / integral of K(x, y), with the kernel
// K = cos(theta_x) cos(theta_y) / r^2. The rays join stratified points x of the source to
// stratified points y of the receiver. Per source point x the kernel-weighted fraction of its
// clear rays, V(x), lies in [0, 1]; the points are then averaged with weights W(x) that the
// caller chooses: the exact point factor F(dx -> receiver) (whose integral is the unoccluded
// factor, so V(x) cannot let a 1/r^2 spike near a shared edge decide the estimate) or, with one
// ray per point, the kernel of that ray (one kernel-weighted ratio over all rays). A first pass
// that is all clear gives V = 1 and all blocked V = 0, whatever the weights; only a mixed one
// (a penumbra) is sampled again, by a second, larger pass, and both passes make the estimate.
// Shaft tests that clear a pair without rays are the caller's (each caches them its own way).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "form_factors/estimators.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity::detail {

/// How the source and receiver points of a pass are joined.
enum class ShadowPairing : std::uint8_t {
  /// `points` stratified source points, each with its own `rays_per_point` stratified receiver
  /// points (the random numbers of one source point after the other).
  grid,
  /// `points` source strata and as many receiver strata, paired by a random permutation (so the
  /// 4D samples are stratified in each 2D projection, a Latin-hypercube-like padding); one ray
  /// per source point, `rays_per_point` is ignored.
  shuffled,
};

/// The rays of one pass: points x rays_per_point.
struct ShadowPass {
  std::uint32_t points = 0;
  std::uint32_t rays_per_point = 1;
  std::uint32_t rays() const { return points * rays_per_point; }
};

/// The caller's ray budget: its constants, documented where it sets them.
struct ShadowBudget {
  ShadowPass first;     ///< always cast
  ShadowPass penumbra;  ///< cast as well when the first pass has clear and blocked rays
  ShadowPairing pairing = ShadowPairing::grid;
};

struct VisibleFraction {
  double value = 1.0;      ///< in [0, 1]
  std::uint64_t rays = 0;  ///< occlusion rays cast
};

/// The rays of one pass, one buffer per thread, reused (a pass has up to 256 x 64 rays).
struct ShadowRays {
  std::vector<glm::vec2> source_uv, target_uv;
  std::vector<glm::vec3> source, origin, direction;
  std::vector<std::uint8_t> blocked;

  static ShadowRays& for_this_thread() {
    thread_local ShadowRays rays;
    return rays;
  }
};

/// The visible fraction of a source (area-uniform points `from(uv)`, facing `from_normal`) seen
/// from a receiver (`to(uv)`, facing `to_normal`), both maps from [0,1)^2 that keep strata.
/// Ray ends are lifted by `epsilon` along their normals; a ray is blocked when `occluders` has a
/// hit strictly between them, and a zero-length one counts as blocked. `point_weight(x, kernel)`
/// is the weight W(x) of source point x (not lifted), given the summed kernel of its rays. All
/// random numbers come from `rng` in a fixed order, so the value depends only on its stream.
/// Thread safety: concurrent calls are safe (each thread has its own ray buffer).
template <typename From, typename To, typename PointWeight>
VisibleFraction visible_fraction(const From& from, const glm::vec3& from_normal, const To& to,
                                 const glm::vec3& to_normal, float epsilon, const ShadowBudget& budget, Rng& rng,
                                 const RayScene& occluders, const PointWeight& point_weight) {
  ShadowRays& b = ShadowRays::for_this_thread();
  const glm::vec3 nx = from_normal, ny = to_normal;
  VisibleFraction out;
  std::uint32_t S = 0, T = 0;  // the last pass's source points and rays per point
  // Generates and traces one pass; returns its clear rays.
  auto pass = [&](const ShadowPass& p) {
    S = p.points;
    T = budget.pairing == ShadowPairing::grid ? p.rays_per_point : 1;
    const std::size_t count = static_cast<std::size_t>(S) * T;
    b.source_uv.resize(std::max<std::size_t>(b.source_uv.size(), S));
    b.target_uv.resize(std::max<std::size_t>(b.target_uv.size(), budget.pairing == ShadowPairing::grid ? T : S));
    b.source.resize(std::max<std::size_t>(b.source.size(), S));
    b.origin.resize(std::max(b.origin.size(), count));
    b.direction.resize(std::max(b.direction.size(), count));
    b.blocked.resize(std::max(b.blocked.size(), count));
    stratified(S, rng, true, b.source_uv.data());
    if (budget.pairing == ShadowPairing::shuffled) {
      stratified(S, rng, true, b.target_uv.data());
      shuffle(b.target_uv.data(), S, rng);
    }
    for (std::uint32_t k = 0; k < S; ++k) {
      const glm::vec3 x = from(b.source_uv[k]);
      b.source[k] = x;
      const glm::vec3 origin = x + epsilon * nx;
      if (budget.pairing == ShadowPairing::shuffled) {
        b.origin[k] = origin;
        b.direction[k] = (to(b.target_uv[k]) + epsilon * ny) - origin;
        continue;
      }
      stratified(T, rng, true, b.target_uv.data());
      for (std::uint32_t t = 0; t < T; ++t) {
        const std::size_t r = static_cast<std::size_t>(k) * T + t;
        b.origin[r] = origin;
        b.direction[r] = (to(b.target_uv[t]) + epsilon * ny) - origin;
      }
    }
    // All rays of a pass join the same two surfaces: Embree traces them as coherent packets.
    occluders.occluded(count, b.origin.data(), b.direction.data(), 0.0f, 1.0f - 1e-4f, b.blocked.data());
    out.rays += count;
    std::uint32_t clear = 0;
    for (std::size_t r = 0; r < count; ++r) {
      const glm::vec3& d = b.direction[r];
      if (!(glm::dot(d, d) > 0.0f)) b.blocked[r] = 1;
      clear += b.blocked[r] == 0 ? 1u : 0u;
    }
    return clear;
  };
  // The weighted sums over the source points of the passes so far.
  double weight_sum = 0.0, visible_sum = 0.0, fraction_sum = 0.0;
  std::uint32_t points = 0;
  auto weigh = [&] {
    for (std::uint32_t k = 0; k < S; ++k) {
      double kernel = 0.0, visible_kernel = 0.0;
      std::uint32_t visible_count = 0;
      for (std::uint32_t t = 0; t < T; ++t) {
        const std::size_t r = static_cast<std::size_t>(k) * T + t;
        const glm::vec3 d = b.direction[r];
        const float r2 = glm::dot(d, d);
        if (!(r2 > 0.0f)) continue;
        const float w = std::max(0.0f, glm::dot(d, nx)) * std::max(0.0f, -glm::dot(d, ny)) / (r2 * r2);
        const bool visible = b.blocked[r] == 0;
        visible_count += visible ? 1u : 0u;
        kernel += w;
        visible_kernel += visible ? w : 0.0f;
      }
      // All segments grazing (kernel 0): the plain fraction of clear rays.
      const double v = kernel > 0.0 ? visible_kernel / kernel : static_cast<double>(visible_count) / T;
      const double f = point_weight(b.source[k], kernel);
      weight_sum += f;
      visible_sum += f * v;
      fraction_sum += v;
      ++points;
    }
  };
  const std::uint32_t clear = pass(budget.first);
  if (clear == 0) {
    out.value = 0.0;
    return out;
  }
  if (clear == S * T) return out;
  weigh();
  pass(budget.penumbra);
  weigh();
  // No point with weight (a grazing pair): the plain mean of V(x).
  out.value = weight_sum > 0.0 ? visible_sum / weight_sum : fraction_sum / points;
  return out;
}

}  // namespace radiosity::detail
