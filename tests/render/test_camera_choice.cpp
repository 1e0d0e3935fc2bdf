// choose_camera(): the camera the renderers take for a scene without one.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

bool inside(const rad::Bounds& b, const glm::vec3& p) {
  return p.x > b.lower.x && p.x < b.upper.x && p.y > b.lower.y && p.y < b.upper.y && p.z > b.lower.z &&
         p.z < b.upper.z;
}

}  // namespace

TEST_SUITE("render") {
  TEST_CASE("choose_camera: the scene's own, the view from outside for an object, a view from inside for a closed "
            "room - whose render is then its radiosity and not black") {
    // A closed box whose walls face its centre, emitting E and reflecting rho: a furnace, whose
    // every wall has B = E / (1 - rho), so every pixel seen from inside shows B / pi. From
    // outside (Scene::camera()'s default view) a camera sees only the walls' backs: black.
    const float E = 1.0f, rho = 0.5f;
    rad::Material wall;
    wall.emission = rad::Rgb(E);
    wall.reflectance = rad::Rgb(rho);
    const rad::Scene room = test::closed_box(wall, glm::vec3(4.0f, 3.0f, 5.0f));
    const rad::CameraChoice chosen = rad::choose_camera(room);
    MESSAGE(chosen.reason);
    CHECK(inside(room.bounds(), chosen.camera.eye));
    CHECK(chosen.reason.find("the scene has none, and from outside") == 0);
    CHECK(chosen.reason.find("inside, at") != std::string::npos);
    CHECK(chosen.reason.find("(100 % of the view lit surfaces)") != std::string::npos);

    rad::SolveOptions so;
    so.mesh.max_patch_area = 1.0f;
    so.tolerance = 1e-6;
    const rad::Solution sol = rad::solve(room, so);
    rad::RenderOptions ro;
    ro.width = ro.height = 16;
    const rad::Image image = rad::render(room, sol, ro);
    const double expected = E / (1.0 - rho) / 3.14159265358979;
    double worst = 0.0;
    for (const rad::Rgb& p : image.pixels) worst = std::max(worst, std::fabs(p.y - expected) / expected);
    MESSAGE("render from the chosen camera: worst pixel " << worst << " off B / pi");
    // A furnace is uniform: what is left is the form factors' row sums (measured 0.33 %).
    CHECK(worst < 0.01);
    // The two-pass view (nothing specular: the display's image) and the path tracer look from
    // the same chosen camera.
    rad::TwoPassOptions to;
    to.width = to.height = 16;
    to.spp = 4;
    const rad::Image two_pass = rad::render_two_pass(room, sol, to);
    double display_sum = 0.0, two_pass_sum = 0.0;
    for (std::size_t k = 0; k < image.pixels.size(); ++k) {
      display_sum += image.pixels[k].y;
      two_pass_sum += two_pass.pixels[k].y;
    }
    CHECK(two_pass_sum == doctest::Approx(display_sum).epsilon(1e-4));
    rad::PathTraceOptions po;
    po.width = po.height = 16;
    po.spp = 64;
    double traced = 0.0;
    for (const rad::Rgb& p : rad::render_path_traced(room, po).pixels) traced += p.y;
    traced /= 256.0;
    MESSAGE("path traced from the chosen camera: mean pixel " << traced << ", B / pi = " << expected);
    // 16 384 paths of a furnace with rho 0.5: the mean's noise is well under 2 %.
    CHECK(traced == doctest::Approx(expected).epsilon(0.02));

    // The view from outside, which renders used before: black.
    ro.camera = room.camera();
    double outside = 0.0;
    for (const rad::Rgb& p : rad::render(room, sol, ro).pixels) outside += p.y;
    CHECK(outside == 0.0);

    // An object seen from outside (a box whose faces face out): the default view is kept.
    rad::Scene object;
    rad::add_box(object, {0, 0, 0}, {1, 1, 1}, object.add_material(rad::Material{}), "box");
    const rad::CameraChoice framed = rad::choose_camera(object);
    CHECK(framed.reason == "the scene has none: framing its bounds from -z");
    CHECK(framed.camera.eye == object.camera().eye);

    // Blocks on a ground under a sky (no emitter): their walls see the sky too, so the view
    // from outside is kept.
    rad::Scene blocks;
    const rad::MaterialId grey = blocks.add_material(rad::Material{});
    blocks.add_polygon({{-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}}, grey, "ground");
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j)
        rad::add_box(blocks, {i * 12.0f - 4, 0, j * 12.0f - 4}, {i * 12.0f + 4, 10.0f + 3.0f * ((i + j) & 3), j * 12.0f + 4},
                     grey, "building");
    rad::Light sky;
    sky.type = rad::LightType::sky;
    blocks.add_light(sky);
    CHECK(rad::choose_camera(blocks).reason == "the scene has none: framing its bounds from -z");

    // A scene with its own camera keeps it.
    rad::Scene with_camera = room;
    rad::Camera own;
    own.eye = {1, 1, 1};
    own.look_at = {2, 1, 3};
    with_camera.set_camera(own);
    const rad::CameraChoice kept = rad::choose_camera(with_camera);
    CHECK(kept.reason == "the scene's camera");
    CHECK(kept.camera.eye == own.eye);
    CHECK(kept.camera.look_at == own.look_at);
  }
}
