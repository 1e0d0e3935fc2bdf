// A brute-force, unbiased path tracer: the ground truth that radiosity images are checked against.
#pragma once

#include "radiosity/common.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

/// How render_path_traced() samples the image: ImageOptions (spp = paths per pixel, 64 by
/// default; noise falls as 1/sqrt(spp)) plus the path length. Every field has a default.
/// Thread safety: a plain value; render_path_traced() only reads it.
struct PathTraceOptions : ImageOptions {
  PathTraceOptions() : ImageOptions(64) {}
  /// Most scattering events (reflections and refractions, delta ones included) a path may have,
  /// >= 0: 1 = direct lighting only, 2 = one indirect bounce, ... 0 = unlimited, ended only by
  /// Russian roulette (unbiased).
  int max_depth = 0;
};

/// Checks options; throws Error{invalid_argument} naming the first bad field: those of
/// validate(ImageOptions) first (width, height, spp, the camera), then max_depth.
/// Thread safety: may be called concurrently.
RADIOSITY_API void validate(const PathTraceOptions& options);

/// Renders `scene` by Monte Carlo path tracing (Kajiya's rendering equation): radiance in
/// W/(m^2 sr), the same units and camera model as render(), so the two images compare pixel by
/// pixel. A diffuse surface of radiosity B shows B/pi; an emitter of exitance E shows E/pi plus
/// the light it reflects.
///
/// Materials: each material's reflection model is make_brdf(material) (brdf.hpp), built once
/// per render: Lambertian, Phong, mirror, glass (dielectric) or mixtures of them from the
/// fields, or Material::brdf when set. Emission is Lambertian, from the front only.
/// - One-sided (the default): a ray that reaches the back of a polygon sees black and the path
///   ends, as in the radiosity solver. Material::two_sided flips the shading frame to the side
///   hit, so the back reflects like the front (ignored for materials with transmittance > 0).
/// - Glass (transmittance > 0): the front faces the outside (index 1), the back the inside
///   (Material::ior); closed objects are polygons facing outwards. Across a refraction the
///   radiance is scaled by (n_from / n_to)^2, which the models leave out; it cancels on every
///   path that enters and leaves the glass, and makes an emitter inside glass appear at its
///   physical radiance (T / n^2 of it at normal incidence). A Material::brdf that refracts
///   must have Material::ior set to its index.
/// - Material::diffuse_transmittance tau adds a Lambertian transmission lobe f = tau/pi on the
///   side away from the viewer, from either side (the back of a one-sided surface then
///   transmits but does not reflect).
/// A scene of one-sided Lambertian materials (no specular, transmission, translucency or own
/// BRDF) takes the original diffuse code path and renders bit-identically to earlier versions.
///
/// The estimator is unbiased for max_depth == 0: next-event estimation (emitters chosen by power
/// E*A summed over channels, a uniform point on the polygon) for every non-delta part, combined
/// with BSDF sampling by multiple importance sampling (power heuristic); delta events (mirror,
/// refraction, Fresnel reflection) continue the path without a light sample, and an emitter
/// reached right after one counts in full. Delta surfaces block shadow rays. Light reflected
/// once by a plain planar mirror (a material with only `specular`, exponent 0, one-sided) is
/// also sampled through the emitters' mirror images and MIS-weighted against BSDF sampling;
/// other caustics (through glass, off several mirrors) are found by BSDF sampling alone and
/// converge more slowly.
/// The scene's lights (Scene::lights(), docs/LIGHTS.md): every non-delta vertex takes the direct
/// light of each point, spot and directional light with one shadow ray apiece (delta lights:
/// no MIS; their light reaching a diffuse surface only through mirrors or glass is not found),
/// and a ray that leaves the scene sees the sky's radiance (found by BSDF sampling alone).
/// Russian roulette after three scattering events, on the throughput with the refraction
/// scales divided out. Pixels use counter-based random streams keyed by (seed, pixel), so the
/// image is bit-identical at any thread count. A scene without emitters and lights renders black.
///
/// Cost: about two rays per scattering event (timings in docs/PATH_TRACER.md). Noise falls as
/// 1/sqrt(spp): the 64 x 64 Cornell box has
/// about 2.5 % relative RMSE at 1024 spp and 0.25 % at 65536; the mirror and glass Cornell boxes
/// (cornell_box_specular()) have about 2.6 % and 6 % at 1024 spp (the glass box's caustics).
///
/// Throws Error{invalid_argument} as validate() does, Error{internal} if Embree fails; an
/// exception thrown by on_progress propagates after the workers have stopped.
/// Thread safety: concurrent calls are safe (the scene is only read).
RADIOSITY_API Image render_path_traced(const Scene& scene, const PathTraceOptions& options = {});

}  // namespace v1
}  // namespace radiosity
