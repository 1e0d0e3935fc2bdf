// Images of a solution seen through a camera.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace radiosity {
inline namespace v1 {

/// Linear float RGB image, row-major from the top-left pixel, radiance in W/(m^2 sr).
/// Optional named layers of the same size (e.g. "direct", "indirect") go to EXR layers.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<Rgb> pixels;
  std::vector<std::pair<std::string, std::vector<Rgb>>> layers;

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h, Rgb(0.0f)) {}
  Rgb& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  const Rgb& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

/// What the three renderers (render(), render_path_traced(), render_two_pass()) share: the image
/// size, the sampling, the camera, threads, seed and progress. Each renderer's options derive
/// from it, so `RenderOptions o; o.width = 64;` sets this struct's field. Every field has a
/// default; only spp's default differs between the renderers (see spp).
/// Thread safety: a plain value; the renderers only read it.
struct ImageOptions {
  int width = 512;   ///< pixels, > 0
  int height = 512;  ///< pixels, > 0
  /// Samples (camera rays or paths) per pixel, > 0, on a stratified jittered g x g grid with a
  /// box filter; rounded up to a square (g = ceil(sqrt(spp))). Default 4 here and in
  /// RenderOptions, 64 in PathTraceOptions, 16 in TwoPassOptions.
  int spp = 4;
  std::optional<Camera> camera;  ///< default: choose_camera(scene) (the scene's camera if it has one)
  unsigned threads = 0;          ///< 0 = all hardware threads; 1 = the calling thread only
  /// The image is a function of the inputs and the seed only: bit-identical at any thread count
  /// (each pixel draws from its own random stream keyed by (seed, pixel)).
  std::uint64_t seed = 1;
  /// Called on the calling thread, one call at a time, after bands of rows (Phase::rendering,
  /// fraction = rows done / height): at most about every 50 ms, and always after the last
  /// row (fraction 1). Return false to cancel: the rows not yet rendered stay black, and the
  /// renderer returns the image as it is.
  ProgressFn on_progress;

  ImageOptions() = default;
  /// The defaults above with another spp: each renderer's options keep their own default.
  explicit ImageOptions(int default_spp) : spp(default_spp) {}
};

/// Checks the shared options; throws Error{invalid_argument} naming the first bad field (width,
/// height, spp, then the camera: camera.fov_deg outside (0, 180), camera.look_at equal to
/// camera.eye, camera.up zero or parallel to the view direction, a non-finite camera value).
/// The renderers' validate() overloads call it first. Thread safety: pure function.
RADIOSITY_API void validate(const ImageOptions& options);

/// How render() samples the image: ImageOptions (spp 4 by default) plus the display settings.
/// Thread safety: a plain value; render() only reads it.
struct RenderOptions : ImageOptions {
  RenderOptions() : ImageOptions(4) {}
  /// Show radiosity plus reflectance x ambient (Solution::radiosity_with_ambient): the usual
  /// display of an unfinished progressive solution.
  bool ambient = false;
  /// Draw the edges of the leaf elements in black over the image (to see the mesh and the
  /// adaptive subdivision).
  bool wireframe = false;
};

/// Checks options; throws Error{invalid_argument} naming the first bad field (width, height,
/// spp, or the camera, as validate(ImageOptions) checks them). Thread safety: pure function.
RADIOSITY_API void validate(const RenderOptions& options);

/// Ray-casts the solution: each camera ray shows the interpolated vertex radiosity / pi of the
/// element it hits (Gouraud-style, continuous across elements); a ray that hits nothing shows
/// the scene's sky (a LightType::sky light; black without one; in a relit solution at its light
/// group's weight, so the images of one-group relights add up to the whole). Deterministic for a
/// seed at any thread count. Throws Error{invalid_argument} for a non-positive size or spp, a
/// solution that was not made from this scene, or a relit one whose light groups are not the
/// scene's materials' and lights'.
RADIOSITY_API Image render(const Scene& scene, const Solution& solution, const RenderOptions& options = {});

/// The camera the renderers take when ImageOptions::camera is not set, and why.
struct CameraChoice {
  Camera camera;
  /// e.g. "the scene's camera", "the scene has none: framing its bounds from -z (y up: as OBJ
  /// and glTF have it)", "the scene has none: framing what stands on its ground from -y, 30
  /// degrees above (z up: the sky's zenith)", or "the scene has none, and from outside 44 % of the view is surfaces no
  /// light reaches (a closed model): inside, at (2, 1.5, 0.2) looking +z, 60 degrees (100 % of
  /// the view lit surfaces; y up: the emitters face down -y)", "the scene has none, and from -z
  /// 44 % of the view is surfaces no light reaches: framing its bounds from +z (30 % of the view
  /// lit surfaces; y up: the emitters face down -y)".
  std::string reason;
};

/// The scene's camera when it has one (Scene::has_camera()). Otherwise, on a ground open to the
/// sky (level polygons at the lowest end along the up cover most of the bounds' section, and
/// roofs or a ceiling above cover less than half of them: a site, a city), a view from 30
/// degrees above framing what stands on the ground; else a view framing the bounds from the
/// side: Scene::camera()'s view from -z when y is up, from -y when z is up. The up is a sky's zenith, else the directional lights' (they shine down),
/// else the axis (y or z) along which polygons at the bounds' lowest end cover the bounds (the
/// ground), else the one the emitting polygons face down along (ceiling lamps), else y (OBJ's
/// and glTF's custom); CameraChoice::reason says which. That view is kept unless most of the
/// surfaces it meets (and a quarter of the view at least) show no light: the
/// backs of one-sided polygons, or sides that no emitter (the centroids of the 16 strongest
/// emitting polygons) or light reaches directly, as a closed room seen from outside (whose
/// image would be black). Then the bounds framed from the other sides across the up (from +z,
/// -x, +x when y is up; a box open on one side is seen through its opening), the one that shows
/// the most lit surfaces among those not mostly unlit; when none is, a view from inside, at mid height 5 % in from a side of the
/// bounds looking across (along the two axes across the up) with a 60 degree field of view: the one whose
/// image shows the most lit surfaces, judged by 24 x 24 rays per candidate and a shadow ray to
/// each emitter and light from what they meet. Builds a ray scene of the polygons (Embree) when
/// the scene has no camera: about 1 s a million polygons, not cancellable (the renderers judge
/// on the ray scene they build anyway). Thread safety: may be called concurrently (reads
/// `scene` only).
RADIOSITY_API CameraChoice choose_camera(const Scene& scene);

/// Which pipeline turns a scene into an image (`radiosity render --mode`).
enum class RenderMode {
  automatic,  ///< let choose_render_mode() decide
  radiosity,  ///< solve(), then render(): every surface is shown as diffuse
  two_pass,   ///< solve() (see prepare_two_pass()), then render_two_pass(): mirrors, glass, glossy lobes, caustics
  path,       ///< render_path_traced(): the unbiased reference, no solve
};

/// The CLI's spelling of a mode: "auto", "radiosity", "two-pass" or "path".
/// Thread safety: pure function.
RADIOSITY_API const char* to_string(RenderMode mode);

/// The cheapest mode that shows `scene` right: RenderMode::two_pass when some polygon's material
/// is not purely diffuse, else RenderMode::radiosity (never automatic or path). A material is not
/// purely diffuse when a channel of `specular` or `transmittance` is > 0, or when it has its own
/// `brdf` that is not Lambertian: one that is_delta(), or whose eval() is not the same constant
/// f with pi * f = albedo() at a few fixed pairs of directions (so a mix of a Lambertian and a
/// mirror counts as specular). Emission and diffuse transmittance do not count (pass 1 carries
/// them), nor do materials that no polygon uses.
/// Thread safety: may be called concurrently (reads `scene` only).
RADIOSITY_API RenderMode choose_render_mode(const Scene& scene);

/// Whether the first pass of render_two_pass() over `scene` should be the extended one: some
/// polygon's material is an ideal mirror (specular > 0 with specular_exponent 0), a window or
/// glass (transmittance > 0), which FormFactorOptions::specular_depth > 0 carries between
/// diffuse surfaces. Glossy lobes and a material's own `brdf` do not count (pass 1 ignores them).
/// Thread safety: may be called concurrently.
RADIOSITY_API bool needs_extended_first_pass(const Scene& scene);

/// Sets up `options` for the first pass of the two-pass view of `scene`: when
/// needs_extended_first_pass(scene), form_factors.method = FormFactorMethod::monte_carlo (the only
/// estimator that carries specular events) and form_factors.specular_depth = at least 1 (a larger
/// value is kept); otherwise `options` is left unchanged. Every other field is left as it is.
/// Typical use: `SolveOptions o; prepare_two_pass(scene, o); render_two_pass(scene, solve(scene, o))`.
/// Thread safety: may be called concurrently for different `options`.
RADIOSITY_API void prepare_two_pass(const Scene& scene, SolveOptions& options);

}  // namespace v1
}  // namespace radiosity
