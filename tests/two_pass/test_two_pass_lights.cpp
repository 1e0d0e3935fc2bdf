// The two-pass view with the scene's lights: on a diffuse scene lit by a point light and a sky
// through a window, the two-pass image (pass 1's direct part and its final gather) agrees with
// the radiosity display and with the path tracer group by group.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/pixel_groups.hpp"
#include "support/scenes.hpp"

namespace rad = radiosity;

TEST_SUITE("two_pass") {
  TEST_CASE("lights: the two-pass view and the path tracer agree with the radiosity display under a point light and a sky") {
    rad::Scene scene = test::window_room();
    rad::Light lamp, sky;
    lamp.intensity = 0.3f;
    lamp.position = {0.45f, 0.7f, 0.6f};
    sky.type = rad::LightType::sky;
    sky.intensity = 2.0f;
    scene.add_light(lamp);
    scene.add_light(sky);
    constexpr int kSize = 32;
    rad::SolveOptions so;
    so.mesh.max_patch_area = 1.0f / 256.0f;
    so.mesh.max_element_area = 1.0f / 1024.0f;
    so.tolerance = 1e-4;
    const rad::Solution sol = rad::solve(scene, so);

    rad::RenderOptions ro;
    ro.width = ro.height = kSize;
    ro.spp = 16;
    const rad::Image display = rad::render(scene, sol, ro);
    rad::TwoPassOptions to;
    to.width = to.height = kSize;
    to.spp = 16;
    const rad::Image two_pass = rad::render_two_pass(scene, sol, to);
    // Without specular parts the two-pass image is the display, sky and lights included.
    for (std::size_t i = 0; i < display.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        CHECK(two_pass.pixels[i][c] == doctest::Approx(display.pixels[i][c]).epsilon(1e-5).scale(1e-6));
    to.diffuse = rad::DiffuseShading::final_gather;
    to.gather_samples = 4;
    const rad::Image gathered = rad::render_two_pass(scene, sol, to);

    rad::PathTraceOptions po;
    po.width = po.height = kSize;
    po.spp = 1024;
    const rad::Image a = rad::render_path_traced(scene, po);
    po.seed = 2;
    const rad::Image b = rad::render_path_traced(scene, po);

    // Group means over the pixels that show one group; the path tracer's noise from the two
    // seeds (sigma of their mean = |a - b| / 2). The display and the final gather may differ by
    // 2 % on top of 4 sigma: pass 1's discretisation (1/1024 m^2 elements) and the
    // interpolation of the point light's falloff and the window's sky patch. Measured: display
    // -0.3 to -0.07 %, final gather -0.5 to +0.1 %, the seeds differing by 0.03 to 0.35 %.
    const std::vector<int> groups = test::pixel_groups(scene, scene.camera(), kSize, kSize);
    std::vector<int> counts;
    const std::size_t n = scene.groups().size();
    const std::vector<rad::Rgb> md = test::group_means(display, groups, n, &counts);
    const std::vector<rad::Rgb> mg = test::group_means(gathered, groups, n);
    const std::vector<rad::Rgb> ma = test::group_means(a, groups, n);
    const std::vector<rad::Rgb> mb = test::group_means(b, groups, n);
    int compared = 0;
    for (std::size_t g = 0; g < n; ++g) {
      if (counts[g] < 50) continue;
      ++compared;
      for (int c = 0; c < 3; ++c) {
        const double path = 0.5 * (ma[g][c] + mb[g][c]), sigma = std::fabs(ma[g][c] - mb[g][c]) / 2.0;
        CAPTURE(scene.groups()[g]);
        CAPTURE(c);
        MESSAGE(scene.groups()[g] << " channel " << c << ": display " << (md[g][c] / path - 1.0) * 100
                                  << " %, final gather " << (mg[g][c] / path - 1.0) * 100 << " %, seeds differ by "
                                  << std::fabs(ma[g][c] - mb[g][c]) / path * 100 << " %");
        CHECK(std::fabs(md[g][c] - path) <= 0.02 * path + 4.0 * sigma);
        CHECK(std::fabs(mg[g][c] - path) <= 0.02 * path + 4.0 * sigma);
      }
    }
    CHECK(compared == 4);
  }
}
