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

/// How render() samples the image.
struct RenderOptions {
  int width = 512;
  int height = 512;
  /// Samples per pixel, stratified on a jittered grid and box-filtered. Rounded up to a square.
  int spp = 4;
  std::optional<Camera> camera;  ///< default: the scene's camera
  unsigned threads = 0;          ///< 0 = all hardware threads
  std::uint64_t seed = 1;
  /// Show radiosity plus reflectance x ambient (Solution::radiosity_with_ambient): the usual
  /// display of an unfinished progressive solution.
  bool ambient = false;
  /// Draw the edges of the leaf elements in black over the image (to see the mesh and the
  /// adaptive subdivision).
  bool wireframe = false;
  ProgressFn on_progress;
};

/// Ray-casts the solution: each camera ray shows the interpolated vertex radiosity / pi of the
/// element it hits (Gouraud-style, continuous across elements). Deterministic for a seed at any
/// thread count. Throws Error{invalid_argument} for a non-positive size or spp, or a solution
/// that was not made from this scene.
RADIOSITY_API Image render(const Scene& scene, const Solution& solution, const RenderOptions& options = {});

}  // namespace v1
}  // namespace radiosity
