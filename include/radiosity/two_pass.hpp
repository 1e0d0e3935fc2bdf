// The second pass of the two-pass method: a view-dependent ray tracer over a radiosity solution,
// with photon-mapped caustics, producing an image with the layers direct, indirect, specular and
// caustic. The design, the layers and the approximations are described in docs/TWO_PASS.md.
#pragma once

#include <cstddef>

#include "radiosity/common.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace radiosity {
inline namespace v1 {

/// Which terms render_two_pass() computes: the three images of Wallace, Cohen & Greenberg's
/// figure 10. Layers that are not computed are present and zero.
enum class TwoPassContent {
  direct_only,  ///< (a) the `direct` layer only: emission and direct light on what the camera sees
  pass1_only,   ///< (b) `direct` + `indirect`: the diffuse solution, no specular or caustic term
  full,         ///< (c) every layer
};

/// How the diffuse surfaces that the camera sees directly are shaded.
enum class DiffuseShading {
  /// Pass 1's interpolated vertex radiosity / pi, split into its direct and indirect parts (the
  /// same pixels as render()).
  pass1,
  /// Direct light by shadow rays to the emitters at each hit (sharp shadows, no mesh artefacts),
  /// plus pass 1's indirect part. A final gather of direct light.
  final_gather,
};

/// Kernel of the photon density estimate.
enum class PhotonFilter {
  cone,          ///< w = 1 - d / r (Jensen 1996, with k = 1), normalised by 1 / (1 - 2/3)
  epanechnikov,  ///< w = 1 - d^2 / r^2, normalised by 2
};

/// The caustic photon map (Jensen 1996). Every field has a default.
/// Thread safety: a plain value.
struct PhotonOptions {
  /// Photons emitted from the emitters (chosen by power), >= 0; 0 turns caustics off. Only the
  /// photons whose first hit is specular cost more than one ray.
  std::size_t photons = 200000;
  /// The most bytes the stored photons may take while they are shot and gathered, 0 = 4 GiB
  /// (44 bytes a photon, held twice while the blocks are merged: about 48 million stored
  /// photons): shooting that passes it stops with Error{memory_budget}, naming the figure.
  std::size_t memory_budget_bytes = 0;
  /// Specular events a photon may go through, >= 1.
  int max_bounces = 8;
  /// Nearest photons per density estimate, >= 1 (more: smoother, blurrier caustics).
  int nearest = 64;
  /// Largest gather radius in scene units, >= 0; 0 = 2 % of the scene's bounding-box diagonal.
  float max_radius = 0.0f;
  PhotonFilter filter = PhotonFilter::cone;
  /// Camera rays per pixel that look the photon map up, >= 1 (capped at the rays per pixel);
  /// their caustic term is weighted by rays / lookups. A lookup (a k-NN search) costs more than
  /// the rest of a ray, and the estimate varies little within a pixel.
  int lookups_per_pixel = 2;
};

/// How render_two_pass() samples the image: ImageOptions (spp = camera rays per pixel, 16 by
/// default, rounded up to a square as render() does) plus the two-pass settings. Every field
/// has a default. Thread safety: a plain value; render_two_pass() only reads it.
struct TwoPassOptions : ImageOptions {
  TwoPassOptions() : ImageOptions(16) {}
  TwoPassContent content = TwoPassContent::full;
  DiffuseShading diffuse = DiffuseShading::pass1;
  /// Shadow rays per camera ray for DiffuseShading::final_gather, >= 1.
  int gather_samples = 2;
  /// Show pass 1's radiosity plus reflectance x ambient, as RenderOptions::ambient does.
  bool ambient = false;
  /// Specular and glossy events followed from the camera, >= 0 (0: no specular term).
  int max_specular_depth = 8;
  /// Directions sampled from a glossy lobe where a camera ray first meets it, >= 1 (one at
  /// later events). Each reads pass 1's radiosity where it lands (Wallace et al. 1987).
  int glossy_samples = 4;
  /// Shadow rays per leaf element (on a stratified grid, rounded up to a square) for splitting
  /// pass 1 into its direct and indirect parts, >= 1.
  int direct_samples = 64;
  PhotonOptions caustics;
};

/// Times and counts of one render_two_pass() call. Thread safety: a plain value.
struct TwoPassReport {
  std::size_t photons_emitted = 0;
  std::size_t photons_stored = 0;
  Rgb emitted_power{0.0f};      ///< sum of E * A over emitters, W per channel
  Rgb caustic_power{0.0f};      ///< sum of the stored photons' power, W per channel
  double seconds_setup = 0.0;   ///< BVH, materials, the direct part of pass 1
  double seconds_photons = 0.0; ///< shooting photons and building the kd-tree
  double seconds_render = 0.0;  ///< camera rays
};

/// Checks options; throws Error{invalid_argument} naming the first bad field: those of
/// validate(ImageOptions) first (width, height, spp, the camera), then the two-pass settings.
/// Thread safety: may be called concurrently.
RADIOSITY_API void validate(const TwoPassOptions& options);

/// Renders `scene` by the second pass of the two-pass method over `pass1`, a radiosity solution
/// of the same scene: camera rays read pass 1's diffuse radiosity where they land, follow
/// specular and glossy reflection and transmission (the make_brdf() model of each material
/// minus its Lambertian part) to max_specular_depth, and add photon-mapped caustics.
///
/// The image is radiance in W/(m^2 sr), same camera model as render(). Its layers (in this
/// order; each is a sum over camera rays, weighted by the path throughput, box-filtered):
/// - "direct": at the first surface a camera ray hits, its emission E/pi plus the light it
///   reflects diffusely that came straight from the emitters and the scene's lights
///   (Scene::lights(); a camera ray that hits nothing shows the sky here) (DiffuseShading::pass1: the direct
///   part of pass 1's radiosity, estimated per element with shadow rays and interpolated like
///   the radiosity, capped at pass 1's value; final_gather: shadow rays at the hit point);
/// - "indirect": at that first surface, pass 1's radiosity minus its direct part, over pi:
///   diffuse interreflection;
/// - "specular": all light reached through one or more specular or glossy events from the
///   camera, except the photon term: pass 1's radiosity / pi (emission included) at each
///   surface a specular chain lands on;
/// - "caustic": diffuse reflectance / pi times the photon-map irradiance at every diffuse
///   surface the camera reaches, directly or through specular chains.
/// The four layers sum to the RGB image (up to float rounding). With no specular material and
/// DiffuseShading::pass1, the image equals render() with the same size, spp, camera, seed and
/// ambient setting. A material with its own Material::brdf cannot be split into a diffuse and a
/// specular part: pass 2 samples all of it. A relit `pass1` (Solution::relight()) is rendered
/// with every emitting polygon and light at its light group's weight (emission seen, direct
/// light, caustic photons, the sky), so the renders of one-group relights add up to the whole,
/// statistically (each draws its own emitter samples and photons). The approximations (pass 1 carries no diffuse ->
/// specular -> diffuse light, glass is opaque to pass 1, no caustic photons from Light
/// sources, ...) are listed in docs/TWO_PASS.md and docs/LIGHTS.md.
///
/// Throws Error{invalid_argument} as validate() does, when `pass1` was not solved from `scene`,
/// or when a relit pass 1's light groups are not the scene's materials' and lights',
/// Error{internal} if Embree fails; an exception thrown by on_progress propagates.
/// Thread safety: concurrent calls are safe; the image is bit-identical at any thread count.
RADIOSITY_API Image render_two_pass(const Scene& scene, const Solution& pass1, const TwoPassOptions& options = {});

/// As above, and fills `report` with timings and photon counts.
RADIOSITY_API Image render_two_pass(const Scene& scene, const Solution& pass1, const TwoPassOptions& options,
                                    TwoPassReport& report);

}  // namespace v1
}  // namespace radiosity
