// The shared core's warps and frame (src/core/): each warp against its density, the frame
// orthonormal and right-handed everywhere, the seam at n.z = 0 included.
#include <doctest/doctest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "core/rng.hpp"

namespace core = radiosity::detail;

namespace {

/// Calls f(u) over the centres of an n x n grid of [0,1)^2.
template <class F>
void grid(int n, F f) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) f(glm::vec2((i + 0.5f) / n, (k + 0.5f) / n));
}

}  // namespace

TEST_SUITE("core") {
  TEST_CASE("the concentric map is area-preserving onto the unit disk") {
    constexpr int n = 256;
    double r2_sum = 0.0, inner = 0.0, right = 0.0;
    grid(n, [&](glm::vec2 u) {
      const glm::vec2 d = core::concentric_disk(u);
      const double r2 = glm::dot(d, d);
      CHECK(r2 <= 1.0 + 1e-6);
      r2_sum += r2;
      inner += r2 < 0.25 ? 1.0 : 0.0;   // the disk of radius 1/2 holds a quarter of the area
      right += d.x > 0.0f ? 1.0 : 0.0;  // each half-plane half of it
    });
    const double count = static_cast<double>(n) * n;
    CHECK(r2_sum / count == doctest::Approx(0.5).epsilon(1e-3));  // E[r^2] = 1/2 for a uniform disk
    CHECK(inner / count == doctest::Approx(0.25).epsilon(2e-3));
    CHECK(right / count == doctest::Approx(0.5).epsilon(2e-3));
  }

  TEST_CASE("both cosine warps give unit directions of density cos(theta)/pi") {
    constexpr int n = 256;
    for (int warp = 0; warp < 2; ++warp) {
      CAPTURE(warp);
      double z_sum = 0.0, below = 0.0;
      grid(n, [&](glm::vec2 u) {
        const glm::vec3 w = warp == 0 ? core::cosine_hemisphere(u) : core::cosine_hemisphere_polar(u);
        CHECK(std::fabs(glm::length(w) - 1.0f) < 1e-5f);
        CHECK(w.z >= 0.0f);
        z_sum += w.z;
        below += w.z * w.z < 0.3f ? 1.0 : 0.0;  // under cos/pi, z^2 is uniform on [0, 1]
      });
      const double count = static_cast<double>(n) * n;
      CHECK(z_sum / count == doctest::Approx(2.0 / 3.0).epsilon(1e-3));  // E[cos] = 2/3
      CHECK(below / count == doctest::Approx(0.3).epsilon(3e-3));
    }
    // The pdf integrates to 1 over the sphere (midpoint rule in theta and phi) and is 0 below.
    const int nt = 2000, np = 64;
    double integral = 0.0;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < nt; ++i) {
      const double theta = pi * (i + 0.5) / nt;
      for (int k = 0; k < np; ++k) {
        const double phi = 2.0 * pi * (k + 0.5) / np;
        const glm::vec3 w(static_cast<float>(std::sin(theta) * std::cos(phi)),
                          static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)));
        integral += core::cosine_hemisphere_pdf(w) * std::sin(theta) * (pi / nt) * (2.0 * pi / np);
      }
    }
    CHECK(integral == doctest::Approx(1.0).epsilon(1e-4));
    CHECK(core::cosine_hemisphere_pdf(glm::vec3(0.0f, 0.6f, -0.8f)) == 0.0f);
  }

  TEST_CASE("the tangent frame is orthonormal and right-handed for every normal") {
    radiosity::detail::Rng rng(7, 0, 0);
    auto check = [](const glm::vec3& n) {
      glm::vec3 t, b;
      core::tangent_frame(n, t, b);
      CHECK(std::fabs(glm::length(t) - 1.0f) < 1e-5f);
      CHECK(std::fabs(glm::length(b) - 1.0f) < 1e-5f);
      CHECK(std::fabs(glm::dot(t, b)) < 1e-5f);
      CHECK(std::fabs(glm::dot(t, n)) < 1e-5f);
      CHECK(std::fabs(glm::dot(b, n)) < 1e-5f);
      CHECK(glm::length(glm::cross(t, b) - n) < 1e-5f);
    };
    for (const glm::vec3& n : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0),
                               glm::normalize(glm::vec3(1, 1, 1e-7f)), glm::normalize(glm::vec3(1, 1, -1e-7f))})
      check(n);
    for (int i = 0; i < 1000; ++i) {
      const glm::vec2 u = rng.uniform2();
      const float z = 1.0f - 2.0f * u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 6.2831853f * u.y;
      check(glm::vec3(r * std::cos(phi), r * std::sin(phi), z));
    }
  }
}
