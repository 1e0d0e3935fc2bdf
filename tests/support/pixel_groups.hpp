// Which group each pixel of an image shows, for comparing renderers group by group: a pixel
// counts for a group when the rays through its centre and four points near its corners all hit
// the front of that group's polygons (edge pixels, which mix surfaces, count for none).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

#include "geometry/ray_scene.hpp"
#include "image/camera.hpp"

namespace test {

namespace rad = radiosity;

/// Per pixel (row-major): the group it shows, or -1.
inline std::vector<int> pixel_groups(const rad::Scene& scene, const rad::Camera& camera, int width, int height) {
  const rad::detail::RayScene rays = rad::detail::RayScene::from_polygons(scene);
  const rad::detail::PinholeCamera cam(camera, width, height);
  std::vector<int> out(static_cast<std::size_t>(width) * height, -1);
  const float inset[5][2] = {{0.5f, 0.5f}, {0.05f, 0.05f}, {0.95f, 0.05f}, {0.05f, 0.95f}, {0.95f, 0.95f}};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int group = -2;
      for (const auto& p : inset) {
        const glm::vec3 d = cam.direction((x + p[0]) / width, (y + p[1]) / height);
        const auto hit = rays.intersect(cam.eye, d, 0.0f, std::numeric_limits<float>::infinity());
        int g = -1;
        if (hit && glm::dot(scene.polygons()[hit->id].normal, d) < 0.0f)
          g = static_cast<int>(scene.polygons()[hit->id].group);
        group = group == -2 || group == g ? g : -1;
      }
      out[static_cast<std::size_t>(y) * width + x] = group;
    }
  return out;
}

/// The mean pixel value of each group (index = GroupId) over the pixels pixel_groups() gives
/// it; `counts` receives how many pixels each mean has.
inline std::vector<rad::Rgb> group_means(const rad::Image& image, const std::vector<int>& groups, std::size_t group_count,
                                         std::vector<int>* counts = nullptr) {
  std::vector<glm::dvec3> sum(group_count, glm::dvec3(0.0));
  std::vector<int> n(group_count, 0);
  for (std::size_t i = 0; i < groups.size(); ++i)
    if (groups[i] >= 0) {
      sum[static_cast<std::size_t>(groups[i])] += glm::dvec3(image.pixels[i]);
      ++n[static_cast<std::size_t>(groups[i])];
    }
  std::vector<rad::Rgb> out(group_count, rad::Rgb(0.0f));
  for (std::size_t g = 0; g < group_count; ++g)
    if (n[g] > 0) out[g] = rad::Rgb(sum[g] / static_cast<double>(n[g]));
  if (counts) *counts = n;
  return out;
}

}  // namespace test
