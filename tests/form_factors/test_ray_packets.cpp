// RayScene's batched occlusion query (coherent Embree packets, used by the ray-cast estimator)
// against one ray at a time.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "core/rng.hpp"
#include "geometry/ray_scene.hpp"

namespace rad = radiosity;

TEST_SUITE("form_factors") {
  TEST_CASE("batched occlusion rays answer exactly as single rays - including a partial last packet") {
    const rad::Scene scene = rad::cornell_box();
    const rad::detail::RayScene rays = rad::detail::RayScene::from_polygons(scene);
    const rad::Bounds b = scene.bounds();
    rad::detail::Rng rng(3);
    auto inside = [&] {
      const glm::vec2 u = rng.uniform2(), v = rng.uniform2();
      return b.lower + glm::vec3(u.x, u.y, v.x) * (b.upper - b.lower);
    };
    // Bundles of 1 to 37 segments from one point (never a multiple of the packet width only),
    // between random points of the box: some pass the blocks, some do not.
    std::vector<glm::vec3> origin, dir;
    while (origin.size() < 20000) {
      const glm::vec3 x = inside();
      const auto n = static_cast<int>(1 + rng.next() % 37);
      for (int k = 0; k < n; ++k) {
        origin.push_back(x);
        dir.push_back(inside() - x);
      }
    }
    std::vector<std::uint8_t> batched(origin.size(), 7);
    // In uneven chunks, so that packets start anywhere.
    for (std::size_t i = 0; i < origin.size();) {
      const std::size_t n = std::min<std::size_t>(origin.size() - i, 1 + rng.next() % 53);
      rays.occluded(n, origin.data() + i, dir.data() + i, 0.0f, 1.0f - 1e-4f, batched.data() + i);
      i += n;
    }
    std::size_t blocked = 0, differ = 0;
    for (std::size_t i = 0; i < origin.size(); ++i) {
      const bool single = rays.occluded(origin[i], dir[i], 0.0f, 1.0f - 1e-4f);
      blocked += single ? 1 : 0;
      differ += (batched[i] == 1) != single || batched[i] > 1 ? 1 : 0;
    }
    CHECK(differ == 0);
    // Both answers occur often enough for the comparison to mean something.
    CHECK(blocked > origin.size() / 10);
    CHECK(blocked < origin.size() * 9 / 10);
  }
}
