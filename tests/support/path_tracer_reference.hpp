// Images checked against the reference path tracer group by group (the pixels that show one
// group only, pixel_groups.hpp), its noise estimated from two seeds.
#pragma once

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/pixel_groups.hpp"

namespace test {

/// `scene` path traced at seeds 1 and 2, size x size pixels, `spp` samples each.
inline std::pair<rad::Image, rad::Image> path_traced_twice(const rad::Scene& scene, int size, int spp = 1024) {
  rad::PathTraceOptions po;
  po.width = po.height = size;
  po.spp = spp;
  rad::Image a = rad::render_path_traced(scene, po);
  po.seed = 2;
  return {std::move(a), rad::render_path_traced(scene, po)};
}

/// Checks the group means of each of `images` (name, image; size x size pixels of the scene's
/// camera) against the path tracer's, the mean of the two seeds in `path`, per channel: within
/// `share` of it plus 4 sigma (sigma = |a - b| / 2, the noise of their mean), each figure
/// reported. Only the groups that at least 50 pixels show count; returns how many did.
inline int check_against_path_tracer(const rad::Scene& scene, int size,
                                     const std::vector<std::pair<std::string, const rad::Image*>>& images,
                                     const std::pair<rad::Image, rad::Image>& path, double share) {
  const std::vector<int> groups = pixel_groups(scene, scene.camera(), size, size);
  const std::size_t n = scene.groups().size();
  std::vector<int> counts;
  const std::vector<rad::Rgb> ma = group_means(path.first, groups, n, &counts);
  const std::vector<rad::Rgb> mb = group_means(path.second, groups, n);
  std::vector<std::vector<rad::Rgb>> means;
  for (const auto& image : images) means.push_back(group_means(*image.second, groups, n));
  int compared = 0;
  for (std::size_t g = 0; g < n; ++g) {
    if (counts[g] < 50) continue;
    ++compared;
    for (int c = 0; c < 3; ++c) {
      const double reference = 0.5 * (ma[g][c] + mb[g][c]), sigma = std::fabs(ma[g][c] - mb[g][c]) / 2.0;
      CAPTURE(scene.groups()[g]);
      CAPTURE(c);
      std::string line = scene.groups()[g] + " channel " + std::to_string(c) + " (" + std::to_string(counts[g]) + " pixels):";
      for (std::size_t k = 0; k < images.size(); ++k)
        line += " " + images[k].first + " " + std::to_string((means[k][g][c] / reference - 1.0) * 100) + " %,";
      MESSAGE(line << " seeds differ by " << std::fabs(ma[g][c] - mb[g][c]) / reference * 100 << " %");
      for (std::size_t k = 0; k < images.size(); ++k) {
        CAPTURE(images[k].first);
        CHECK(std::fabs(means[k][g][c] - reference) <= share * reference + 4.0 * sigma);
      }
    }
  }
  return compared;
}

}  // namespace test
