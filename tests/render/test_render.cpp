#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

TEST_SUITE("render") {
  TEST_CASE("inside a furnace every pixel shows B/pi = E/((1-rho) pi)") {
    rad::Material m;
    m.emission = rad::Rgb(1.0f, 2.0f, 3.0f);
    m.reflectance = rad::Rgb(0.5f);
    rad::Scene scene = test::closed_box(m);
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.26f;
    o.mesh.max_element_area = 0.07f;
    o.tolerance = 1e-6;
    rad::Solution sol = rad::solve(scene, o);
    rad::RenderOptions ro;
    ro.width = 24;
    ro.height = 16;
    ro.spp = 4;
    ro.camera = rad::Camera{{0.5f, 0.5f, 0.1f}, {0.5f, 0.6f, 1.0f}, {0, 1, 0}, 90.0f};
    rad::Image img = rad::render(scene, sol, ro);
    REQUIRE(img.width == 24);
    REQUIRE(img.height == 16);
    const float pi = 3.14159265f;
    for (const rad::Rgb& p : img.pixels)
      for (int c = 0; c < 3; ++c) CHECK(p[c] == doctest::Approx(2.0f * m.emission[c] / pi).epsilon(2e-3));
  }

  TEST_CASE("the Cornell box image is identical at 1 and 2 threads and shows the red wall on the left") {
    rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 20000.0f;
    rad::Solution sol = rad::solve(scene, o);
    rad::RenderOptions ro;
    ro.width = 32;
    ro.height = 32;
    ro.threads = 1;
    rad::Image a = rad::render(scene, sol, ro);
    ro.threads = 2;
    rad::Image b = rad::render(scene, sol, ro);
    CHECK(a.pixels == b.pixels);
    // Published camera: +x (the red wall) appears on the left of the picture.
    const rad::Rgb left = a.at(2, 16), right = a.at(29, 16);
    CHECK(left.x > 2.0f * left.y);
    CHECK(right.y > 1.5f * right.x);
  }

  TEST_CASE("bad render options are rejected") {
    rad::Scene scene = test::closed_box(rad::Material{});
    rad::SolveOptions o;
    o.mesh.max_patch_area = 1.0f;
    o.mesh.max_element_area = 1.0f;
    rad::Solution sol = rad::solve(scene, o);
    rad::RenderOptions ro;
    ro.width = 0;
    CHECK_THROWS_AS(rad::render(scene, sol, ro), rad::Error);
    ro.width = 8;
    ro.spp = 0;
    CHECK_THROWS_AS(rad::render(scene, sol, ro), rad::Error);
    // A solution of another scene.
    rad::Scene cornell = rad::cornell_box();
    rad::SolveOptions co;
    co.mesh.max_patch_area = 40000.0f;
    co.mesh.max_element_area = 40000.0f;
    rad::Solution other = rad::solve(cornell, co);
    ro.spp = 1;
    CHECK_THROWS_AS(rad::render(scene, other, ro), rad::Error);
  }
}

TEST_SUITE("render") {
  TEST_CASE("one camera check: Scene::set_camera and the three renderers refuse the same cameras with the same words") {
    const radiosity::Scene scene = radiosity::cornell_box();
    radiosity::Camera ok = scene.camera();
    const struct {
      radiosity::Camera camera;
      const char* words;
    } bad[] = {
        {radiosity::Camera{ok.eye, ok.eye, ok.up, ok.fov_deg}, "camera.look_at must differ from camera.eye"},
        {radiosity::Camera{ok.eye, ok.look_at, ok.look_at - ok.eye, ok.fov_deg}, "camera.up must be non-zero"},
        {radiosity::Camera{ok.eye, ok.look_at, ok.up, 180.0f}, "camera.fov_deg must be in (0, 180)"},
        {radiosity::Camera{glm::vec3(NAN), ok.look_at, ok.up, ok.fov_deg}, "camera: eye, look_at and up must be finite"},
    };
    for (const auto& b : bad) {
      CAPTURE(std::string(b.words));
      radiosity::Scene s = scene;
      CHECK_THROWS_WITH_AS(s.set_camera(b.camera), doctest::Contains(b.words), radiosity::Error);
      radiosity::RenderOptions ro;
      ro.camera = b.camera;
      CHECK_THROWS_WITH_AS(radiosity::validate(ro), doctest::Contains(b.words), radiosity::Error);
      radiosity::PathTraceOptions po;
      po.camera = b.camera;
      CHECK_THROWS_WITH_AS(radiosity::validate(po), doctest::Contains(b.words), radiosity::Error);
      radiosity::TwoPassOptions to;
      to.camera = b.camera;
      CHECK_THROWS_WITH_AS(radiosity::validate(to), doctest::Contains(b.words), radiosity::Error);
    }
    radiosity::RenderOptions ro;
    ro.camera = ok;
    CHECK_NOTHROW(radiosity::validate(ro));
  }
}

TEST_SUITE("render") {
  TEST_CASE("renderers report progress as common.hpp promises: at most every 50 ms and once at the end") {
    const radiosity::Scene scene = radiosity::cornell_box();
    radiosity::SolveOptions so;
    so.mesh.max_patch_area = 40000.0f;
    const radiosity::Solution sol = radiosity::solve(scene, so);
    std::vector<std::chrono::steady_clock::time_point> when;
    std::vector<double> fraction;
    const radiosity::ProgressFn record = [&](const radiosity::Progress& p) {
      when.push_back(std::chrono::steady_clock::now());
      fraction.push_back(p.fraction);
      return true;
    };
    auto check = [&](const char* renderer) {
      CAPTURE(std::string(renderer));
      REQUIRE(!when.empty());
      CHECK(fraction.back() == doctest::Approx(1.0));
      // Between the first report and the forced last one, calls are 50 ms apart at least
      // (the display renders its 32 bands of rows in well under that: ungated, it would call
      // back for each).
      for (std::size_t k = 1; k + 1 < when.size(); ++k)
        CHECK(std::chrono::duration<double>(when[k] - when[k - 1]).count() >= 0.049);
      when.clear();
      fraction.clear();
    };
    radiosity::RenderOptions ro;  // 512 x 512: 32 bands
    ro.on_progress = record;
    radiosity::render(scene, sol, ro);
    check("render");
    radiosity::PathTraceOptions po;
    po.width = 64;
    po.height = 64;
    po.spp = 16;
    po.on_progress = record;
    radiosity::render_path_traced(scene, po);
    check("path");
    radiosity::TwoPassOptions to;
    to.width = 64;
    to.height = 64;
    to.spp = 1;
    to.on_progress = record;
    radiosity::render_two_pass(scene, sol, to);
    check("two-pass");
  }
}
