// A brute-force, unbiased path tracer: the ground truth that radiosity images are checked against.
#pragma once

#include <cstdint>
#include <optional>

#include "radiosity/common.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

/// How render_path_traced() samples the image. Every field has a default.
struct PathTraceOptions {
  int width = 512;   ///< pixels, > 0
  int height = 512;  ///< pixels, > 0
  /// Paths per pixel, > 0, on a stratified jittered g x g grid with a box filter; rounded up to
  /// a square (g = ceil(sqrt(spp))). Noise falls as 1/sqrt(spp).
  int spp = 64;
  /// Most reflections a path may have, >= 0: 1 = direct lighting only, 2 = one indirect bounce,
  /// ... 0 = unlimited, ended only by Russian roulette (unbiased).
  int max_depth = 0;
  std::optional<Camera> camera;  ///< default: the scene's camera
  unsigned threads = 0;          ///< 0 = all hardware threads; 1 = the calling thread only
  std::uint64_t seed = 1;        ///< the image is a function of (scene, options, seed) only
  /// Called on the calling thread after each band of rows (Phase::rendering, fraction = rows
  /// done / height). Return false to cancel: rows not yet rendered stay black.
  ProgressFn on_progress;
};

/// Checks options; throws Error{invalid_argument} naming the first bad field (width, height,
/// spp, max_depth, camera.fov_deg outside (0, 180), camera.eye == camera.look_at or camera.up
/// parallel to the view direction, a non-finite camera value).
/// Thread safety: may be called concurrently.
RADIOSITY_API void validate(const PathTraceOptions& options);

/// Renders `scene` by Monte Carlo path tracing (Kajiya's rendering equation): radiance in
/// W/(m^2 sr), the same units and camera model as render(), so the two images compare pixel by
/// pixel. A diffuse surface of radiosity B shows B/pi; an emitter of exitance E shows E/pi plus
/// the light it reflects.
///
/// Light transport is the radiosity method's: every surface is a one-sided Lambertian reflector
/// with albedo Material::reflectance and a Lambertian emitter of exitance Material::emission.
/// A ray that reaches the back of a polygon sees black and ends (the back absorbs), as in the
/// radiosity solver; Material::two_sided, the specular, transmission and translucency fields and
/// Material::brdf are ignored for now (issue #5 / the two-pass issue will extend this).
///
/// The estimator is unbiased for max_depth == 0: next-event estimation (emitters chosen by power
/// E*A summed over channels, a uniform point on the polygon) and cosine-weighted bounces,
/// combined by multiple importance sampling (power heuristic), and Russian roulette after three
/// reflections. Pixels use counter-based random streams keyed by (seed, pixel), so the image is
/// bit-identical at any thread count. A scene without emitters renders black.
///
/// Cost: two rays per reflection; the 64 x 64 Cornell box at 1024 spp (4 M paths) takes about
/// 4 s on 2 cores (Release). Noise falls as 1/sqrt(spp): the same image has about 2.5 % relative
/// RMSE at 1024 spp and 0.25 % at 65536.
///
/// Throws Error{invalid_argument} as validate() does, Error{internal} if Embree fails; an
/// exception thrown by on_progress propagates after the workers have stopped.
/// Thread safety: concurrent calls are safe (the scene is only read).
RADIOSITY_API Image render_path_traced(const Scene& scene, const PathTraceOptions& options = {});

}  // namespace v1
}  // namespace radiosity
