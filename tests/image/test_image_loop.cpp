// The shared pixel loop of the three renderers (src/image/image_loop.hpp) and the check of the
// options they share (validate(ImageOptions)).
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "image/image_loop.hpp"

namespace rad = radiosity;

namespace {

/// What validate(o) throws, or "" when it does not.
std::string error_of(const rad::ImageOptions& o) {
  try {
    rad::validate(o);
  } catch (const rad::Error& e) {
    CHECK(e.code() == rad::ErrorCode::invalid_argument);
    return e.what();
  }
  return {};
}

}  // namespace

TEST_SUITE("image") {
  TEST_CASE("validate(ImageOptions) names the first bad field") {
    CHECK(error_of(rad::ImageOptions{}) == "");
    rad::ImageOptions o;
    o.width = 0;
    CHECK(error_of(o) == "ImageOptions::width must be > 0, got 0");
    o = {};
    o.height = -3;
    CHECK(error_of(o) == "ImageOptions::height must be > 0, got -3");
    o = {};
    o.spp = 0;
    CHECK(error_of(o) == "ImageOptions::spp must be > 0, got 0");
    // The camera, in camera_problem()'s words (the same as Scene::set_camera's).
    const rad::Camera ok = rad::cornell_box().camera();
    o = {};
    o.camera = ok;
    CHECK(error_of(o) == "");
    o.camera = rad::Camera{ok.eye, ok.look_at, ok.up, 180.0f};
    CHECK(error_of(o).find("ImageOptions::camera.fov_deg must be in (0, 180)") == 0);
    o.camera = rad::Camera{ok.eye, ok.eye, ok.up, ok.fov_deg};
    CHECK(error_of(o) == "ImageOptions::camera.look_at must differ from camera.eye");
    o.camera = rad::Camera{ok.eye, ok.look_at, ok.look_at - ok.eye, ok.fov_deg};
    CHECK(error_of(o).find("ImageOptions::camera.up must be non-zero") == 0);
    o.camera = rad::Camera{glm::vec3(NAN), ok.look_at, ok.up, ok.fov_deg};
    CHECK(error_of(o) == "ImageOptions::camera: eye, look_at and up must be finite");
    // Several bad fields: the first in the order width, height, spp, camera.
    o.width = -1;
    o.height = 0;
    o.spp = 0;
    CHECK(error_of(o).find("ImageOptions::width") == 0);
    o.width = 1;
    CHECK(error_of(o).find("ImageOptions::height") == 0);
    o.height = 1;
    CHECK(error_of(o).find("ImageOptions::spp") == 0);
    o.spp = 1;
    CHECK(error_of(o).find("ImageOptions::camera") == 0);
  }

  TEST_CASE("the renderers' options are ImageOptions with their own spp default") {
    const rad::RenderOptions ro;
    const rad::PathTraceOptions po;
    const rad::TwoPassOptions to;
    CHECK(ro.spp == 4);
    CHECK(po.spp == 64);
    CHECK(to.spp == 16);
    CHECK(rad::ImageOptions{}.spp == 4);
    for (const rad::ImageOptions* o : {static_cast<const rad::ImageOptions*>(&ro),
                                       static_cast<const rad::ImageOptions*>(&po),
                                       static_cast<const rad::ImageOptions*>(&to)}) {
      CHECK(o->width == 512);
      CHECK(o->height == 512);
      CHECK(!o->camera);
      CHECK(o->threads == 0u);
      CHECK(o->seed == 1u);
      CHECK(!o->on_progress);
      CHECK(error_of(*o) == "");
    }
  }

  TEST_CASE("for_each_pixel visits every pixel exactly once at any thread count and size and band") {
    for (const int width : {1, 7, 33})
      for (const int height : {1, 5, 17})
        for (const unsigned threads : {0u, 1u, 2u, 3u})
          for (const int rows : {1, 4, 16, 100})
            for (const std::size_t grain : {std::size_t{1}, std::size_t{5}, std::size_t{64}}) {
              CAPTURE(width);
              CAPTURE(height);
              CAPTURE(threads);
              CAPTURE(rows);
              CAPTURE(grain);
              rad::ImageOptions o;
              o.width = width;
              o.height = height;
              o.threads = threads;
              const std::size_t n = static_cast<std::size_t>(width) * height;
              std::vector<std::atomic<int>> visits(n);
              std::atomic<bool> outside{false};
              const bool done = rad::detail::for_each_pixel(o, {rows, grain}, [&](int x, int y) {
                if (x < 0 || x >= width || y < 0 || y >= height) {
                  outside = true;
                  return;
                }
                ++visits[static_cast<std::size_t>(y) * width + x];
              });
              CHECK(done);
              CHECK(!outside);
              int wrong = 0;
              for (std::size_t k = 0; k < n; ++k) wrong += visits[k] != 1;
              CHECK(wrong == 0);
            }
  }

  TEST_CASE("for_each_pixel reports monotone progress on the calling thread that ends at 1") {
    for (const unsigned threads : {1u, 2u}) {
      CAPTURE(threads);
      rad::ImageOptions o;
      o.width = 3;
      o.height = 9;
      o.threads = threads;
      std::vector<double> fraction;
      const std::thread::id caller = std::this_thread::get_id();
      o.on_progress = [&](const rad::Progress& p) {
        CHECK(p.phase == rad::Phase::rendering);
        CHECK(std::this_thread::get_id() == caller);
        fraction.push_back(p.fraction);
        return true;
      };
      // A band of one row takes about 40 ms: the gate lets some reports through, not all.
      const bool done = rad::detail::for_each_pixel(o, {1, 1}, [&](int x, int) {
        if (x == 0) std::this_thread::sleep_for(std::chrono::milliseconds(40));
      });
      CHECK(done);
      REQUIRE(fraction.size() >= 2);  // the first and the last
      CHECK(fraction.front() == doctest::Approx(1.0 / 9.0));  // the first report always gets through
      for (std::size_t k = 1; k < fraction.size(); ++k) CHECK(fraction[k] > fraction[k - 1]);
      CHECK(fraction.back() == 1.0);
    }
  }

  TEST_CASE("cancel from on_progress stops for_each_pixel after the band it follows") {
    for (const unsigned threads : {1u, 2u})
      for (const int rows : {1, 3}) {
        CAPTURE(threads);
        CAPTURE(rows);
        rad::ImageOptions o;
        o.width = 5;
        o.height = 12;
        o.threads = threads;
        int calls = 0;
        double last = 0.0;
        o.on_progress = [&](const rad::Progress& p) {
          ++calls;
          last = p.fraction;
          return false;  // the first report (always let through) cancels
        };
        std::vector<std::atomic<int>> visits(60);
        const bool done = rad::detail::for_each_pixel(o, {rows, 2}, [&](int x, int y) { ++visits[y * 5 + x]; });
        CHECK(!done);
        CHECK(calls == 1);
        CHECK(last == doctest::Approx(static_cast<double>(rows) / 12.0));
        for (int y = 0; y < 12; ++y)
          for (int x = 0; x < 5; ++x) {
            CAPTURE(y);
            CHECK(visits[y * 5 + x] == (y < rows ? 1 : 0));
          }
      }
    // Cancelling at the last report: every pixel was visited, and the loop says it was cancelled.
    rad::ImageOptions o;
    o.width = 4;
    o.height = 4;
    int calls = 0;
    o.on_progress = [&](const rad::Progress&) { return ++calls < 2; };
    int visited = 0;
    CHECK(!rad::detail::for_each_pixel(o, {2, 16}, [&](int, int) { ++visited; }));
    CHECK(calls == 2);
    CHECK(visited == 16);
  }

  TEST_CASE("an exception from on_progress propagates out of for_each_pixel") {
    rad::ImageOptions o;
    o.width = 4;
    o.height = 8;
    o.threads = 2;
    o.on_progress = [](const rad::Progress&) -> bool { throw std::runtime_error("stop"); };
    std::atomic<int> visited{0};
    CHECK_THROWS_WITH_AS(rad::detail::for_each_pixel(o, {2, 1}, [&](int, int) { ++visited; }), "stop",
                         std::runtime_error);
    CHECK(visited == 8);  // the first band only
  }
}
