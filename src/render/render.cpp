// Ray-cast display of a radiosity solution: the view pass of the method in its simplest form.
// Each pixel averages stratified camera rays; a ray that hits a leaf element shows the
// element's vertex radiosity interpolated at the hit point, divided by pi (a Lambertian
// surface's radiance); a ray that hits nothing sees the sky (a LightType::sky light), as in the
// other two renderers.
#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>
#include <limits>

#include "core/rng.hpp"
#include "core/streams.hpp"
#include "geometry/ray_scene.hpp"
#include "image/camera.hpp"
#include "image/image_loop.hpp"
#include "image/image_options.hpp"
#include "radiosity/render.hpp"
#include "render/camera_choice.hpp"
#include "scene/lights.hpp"
#include "solver/light_groups.hpp"

namespace radiosity {
inline namespace v1 {

void validate(const RenderOptions& options) {
  const std::string problem = detail::image_options_problem(options);
  if (problem.empty()) return;
  // render() names the size as one field, as it always has.
  if (options.width <= 0 || options.height <= 0)
    throw Error(ErrorCode::invalid_argument, "render: width and height must be > 0, got " +
                                                 std::to_string(options.width) + "x" + std::to_string(options.height));
  throw Error(ErrorCode::invalid_argument, "render: " + problem);
}

Image render(const Scene& scene, const Solution& solution, const RenderOptions& options) {
  validate(options);
  const PatchHierarchy& hierarchy = solution.hierarchy();
  for (const Patch& p : hierarchy.patches())
    if (p.polygon >= scene.polygons().size())
      throw Error(ErrorCode::invalid_argument, "render: the solution was not made from this scene");

  const detail::RayScene rays =
      detail::RayScene::from_leaves(hierarchy, detail::RayScene::backs_inside(scene, hierarchy));
  const Camera camera_settings =
      options.camera ? *options.camera
                     : detail::choose_camera(scene, rays, [&](std::uint32_t element) {
                         return hierarchy.patches()[hierarchy.element(element).patch].polygon;
                       }).camera;
  const detail::PinholeCamera camera(camera_settings, options.width, options.height);
  const std::vector<Rgb> vertex_B = solution.vertex_radiosity(options.ambient);
  const std::vector<Rgb> vertex_back = solution.vertex_back_radiosity();  // empty: every back is black
  // A ray that hits nothing sees the sky, at its light group's weight in a relit solution.
  const detail::EmitterWeights weights = detail::emitter_weights(scene, solution, -1, "render");
  const detail::SceneLights lights(scene.lights(), &weights.light);

  // spp rounded up to a square for a jittered g x g grid per pixel.
  const int g = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options.spp)) - 1e-9));
  const float inv_pi = 1.0f / glm::pi<float>();
  Image image(options.width, options.height);

  // Wireframe overlay: is the hit within about a pixel of an edge of its element? Quads are
  // drawn as two triangles; their shared diagonal (corner 0 to corner 2) is not an edge.
  const float pixel_angle = 2.0f * camera.tan_half_fov / static_cast<float>(options.height);
  auto near_element_edge = [&](std::uint32_t element, const std::uint32_t* tri, float w, float u, float v, float t) {
    const Element& el = hierarchy.element(element);
    const glm::vec3 &p0 = hierarchy.vertices()[tri[0]], &p1 = hierarchy.vertices()[tri[1]],
                    &p2 = hierarchy.vertices()[tri[2]];
    const float twice_area = glm::length(glm::cross(p1 - p0, p2 - p0));
    const float width = 0.75f * pixel_angle * t;
    // Distance to an edge = barycentric coordinate of the opposite vertex x its altitude.
    const float d01 = v * twice_area / glm::length(p1 - p0), d12 = w * twice_area / glm::length(p2 - p1),
                d20 = u * twice_area / glm::length(p0 - p2);
    if (el.corner_count() == 3) return std::min({d01, d12, d20}) < width;
    const bool first_half = tri[1] == el.corners[1];  // (c0, c1, c2) or (c0, c2, c3)
    return first_half ? std::min(d01, d12) < width : std::min(d12, d20) < width;
  };

  auto shade = [&](const glm::vec3& dir) -> Rgb {
    auto hit = rays.intersect(camera.eye, dir, 0.0f, std::numeric_limits<float>::infinity());
    if (!hit) return lights.sky_radiance(dir);
    // One-sided surfaces: the back of a polygon sends nothing, unless it is translucent.
    const bool front = glm::dot(hierarchy.normal(hit->id), dir) < 0.0f;
    if (!front && vertex_back.empty()) return Rgb(0.0f);
    const std::vector<Rgb>& values = front ? vertex_B : vertex_back;
    const std::uint32_t* tri = rays.triangle(hit->triangle);
    const float w = 1.0f - hit->u - hit->v;
    Rgb b = w * values[tri[0]] + hit->u * values[tri[1]] + hit->v * values[tri[2]];
    if (options.wireframe && near_element_edge(hit->id, tri, w, hit->u, hit->v, hit->t)) return Rgb(0.0f);
    return b * inv_pi;
  };

  // Each pixel has its own random stream: thread count does not matter.
  detail::for_each_pixel(options, detail::ImageBands{16, 64}, [&](int x, int y) {
    detail::Rng rng(options.seed, static_cast<std::uint64_t>(y) * options.width + x,
                    detail::stream_key(detail::Stream::pixel_jitter));
    Rgb sum(0.0f);
    for (int i = 0; i < g; ++i)
      for (int j = 0; j < g; ++j) {
        glm::vec2 u = rng.uniform2();
        float sx = (static_cast<float>(x) + (static_cast<float>(i) + u.x) / g) / options.width;
        float sy = (static_cast<float>(y) + (static_cast<float>(j) + u.y) / g) / options.height;
        sum += shade(camera.direction(sx, sy));
      }
    image.at(x, y) = sum / static_cast<float>(g * g);
  });
  return image;
}

}  // namespace v1
}  // namespace radiosity
