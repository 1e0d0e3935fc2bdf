// The path tracer with the scene's lights (point, spot, directional, sky), against closed forms
// and against radiosity's display of the same scene: the lights are the same in all three
// renderers, so their images agree group by group within the path tracer's noise.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "image/camera.hpp"
#include "support/path_tracer_reference.hpp"
#include "support/pixel_groups.hpp"
#include "support/scenes.hpp"
#include "support/build.hpp"

namespace rad = radiosity;

namespace {

constexpr double kPi = 3.14159265358979323846;

rad::Light sun() {
  rad::Light l;
  l.type = rad::LightType::directional;
  l.name = "sun";
  l.intensity = 10.0f;
  l.direction = {0.2f, -1.0f, 0.3f};
  return l;
}

}  // namespace

TEST_SUITE("path_tracer") {
  TEST_CASE("lights: sunlight through a window into a room matches the radiosity display group by group"
            * test::release_only) {
    // A directional light (10 W/m^2 travelling along (0.2, -1, 0.3)) through a hole in the
    // ceiling of a closed room: the sun patch on the floor lights the walls.
    rad::Scene scene = test::window_room();
    scene.add_light(sun());
    constexpr int kSize = 32;
    rad::SolveOptions so;
    so.mesh.max_patch_area = 1.0f / 1024.0f;  // fine patches: the sun patch's edges near the walls
    so.mesh.max_element_area = 1.0f / 1024.0f;
    so.tolerance = 1e-4;
    const rad::Solution sol = rad::solve(scene, so);
    // All of the sun that passes the window lands on the floor: 0.16 m^2 x 10 W/m^2 x cos.
    double floor_power = 0.0;
    const rad::PatchHierarchy& h = sol.hierarchy();
    for (std::uint32_t e : h.leaves())
      if (h.patches()[h.element(e).patch].group == *scene.find_group("floor"))
        floor_power += h.element(e).area * sol.direct_irradiance()[e].x;
    CHECK(floor_power == doctest::Approx(1.6 / std::sqrt(1.13)).epsilon(1e-3));
    rad::RenderOptions ro;
    ro.width = ro.height = kSize;
    ro.spp = 16;
    const rad::Image display = rad::render(scene, sol, ro);

    // Group means over the pixels that show one group only. The path tracer's noise is
    // estimated from the two seeds (sigma of their mean = |a - b| / 2); on top of 4 sigma the
    // radiosity display may differ by 2 %, its own discretisation (patches and elements of
    // 1/1024 m^2, the display's interpolation of the sun patch's edges). Measured: floor +0.34
    // to +0.40 % (the seeds differ by 0.05 to 0.07 %), walls -1.5 to +0.8 % (0.24 to 1.3 %).
    const int compared =
        test::check_against_path_tracer(scene, kSize, {{"radiosity", &display}}, test::path_traced_twice(scene, kSize), 0.02);
    CHECK(compared == 4);  // floor, right, left and back walls
  }

  TEST_CASE("lights: a point light over a plane shows rho I cos / (pi r^2) with no noise") {
    // Delta light sampling is exact and the bounces escape into a black sky: every path through
    // a point gives the same value, so a pixel is the mean over the points its jittered rays
    // hit; a narrow view (2 degrees) makes that the centre's within 0.1 %.
    rad::Scene scene;
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.6f, 0.4f, 0.2f);
    rad::add_quad(scene, {-5, 0, -5}, {0, 0, 10}, {10, 0, 0}, scene.add_material(grey), "floor");
    rad::Light lamp;
    lamp.intensity = 3.0f;
    lamp.position = {0.4f, 1.0f, 0.2f};
    scene.add_light(lamp);
    rad::PathTraceOptions po;
    po.width = po.height = 8;
    po.spp = 4;
    po.camera = rad::Camera{{0.3f, 2.0f, 0.1f}, {0.3f, 0.0f, 0.1f}, {0, 0, 1}, 2.0f};
    const rad::Image img = rad::render_path_traced(scene, po);
    const rad::detail::PinholeCamera cam(*po.camera, 8, 8);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const glm::vec3 d = cam.direction((x + 0.5f) / 8.0f, (y + 0.5f) / 8.0f);
        const glm::vec3 p = cam.eye + (-cam.eye.y / d.y) * d;
        const glm::vec3 to = lamp.position - p;
        const double E = lamp.intensity * to.y / std::pow(glm::dot(to, to), 1.5);
        for (int c = 0; c < 3; ++c) {
          const double want = grey.reflectance[c] * E / kPi;
          CHECK(std::fabs(img.at(x, y)[c] - want) <= 1e-3 * want);
        }
      }
  }

  TEST_CASE("lights: a plane under a uniform sky shows rho E / pi and the sky itself shows E / pi") {
    rad::Scene scene;
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.5f);
    rad::add_quad(scene, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, scene.add_material(grey), "floor");
    rad::Light sky;
    sky.type = rad::LightType::sky;
    sky.intensity = 2.0f;
    sky.color = rad::Rgb(1.0f, 0.8f, 0.6f);
    scene.add_light(sky);
    rad::PathTraceOptions po;
    po.width = po.height = 8;
    po.spp = 4;
    // Looking down at the floor (every bounce escapes into the sky: L = rho E / pi exactly)...
    po.camera = rad::Camera{{0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0, 0, 1}, 30.0f};
    const rad::Image down = rad::render_path_traced(scene, po);
    for (const rad::Rgb& px : down.pixels)
      for (int c = 0; c < 3; ++c) CHECK(px[c] == doctest::Approx(0.5 * 2.0 * sky.color[c] / kPi).epsilon(1e-5));
    // ...and up at the sky, whose radiance is E / pi.
    po.camera = rad::Camera{{0.0f, 1.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, {0, 0, 1}, 30.0f};
    const rad::Image up = rad::render_path_traced(scene, po);
    for (const rad::Rgb& px : up.pixels)
      for (int c = 0; c < 3; ++c) CHECK(px[c] == doctest::Approx(2.0 * sky.color[c] / kPi).epsilon(1e-5));
  }
}
