// The shared core's warps and frame (src/core/): each warp against its density, the frame
// orthonormal and right-handed everywhere, the seam at n.z = 0 included.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "core/frame.hpp"
#include "core/halton.hpp"
#include "core/quadrature.hpp"
#include "core/sampling.hpp"
#include "core/rng.hpp"

namespace core = radiosity::detail;

namespace {

/// Area of a polygon in the z = 0 plane (shoelace).
double area_xy(const std::vector<glm::dvec2>& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const glm::dvec2 &q = p[i], &r = p[(i + 1) % p.size()];
    a += q.x * r.y - r.x * q.y;
  }
  return 0.5 * std::fabs(a);
}

/// The part of convex polygon p with x_or_y (0: x, 1: y) on the `keep_below` side of `cut`
/// (one Sutherland-Hodgman step).
std::vector<glm::dvec2> clip(const std::vector<glm::dvec2>& p, int axis, double cut, bool keep_below) {
  std::vector<glm::dvec2> out;
  auto in = [&](const glm::dvec2& q) { return keep_below ? q[axis] <= cut : q[axis] >= cut; };
  for (std::size_t i = 0; i < p.size(); ++i) {
    const glm::dvec2 &a = p[i], &b = p[(i + 1) % p.size()];
    if (in(a)) out.push_back(a);
    if (in(a) != in(b)) out.push_back(a + (b - a) * ((cut - a[axis]) / (b[axis] - a[axis])));
  }
  return out;
}

/// Cells of the z = 0 plane to test warps on: a trapezoid, a general convex quad, a triangle.
std::vector<std::vector<glm::vec3>> test_cells() {
  return {{{0, 0, 0}, {4, 0, 0}, {3, 1, 0}, {1, 1, 0}},
          {{0, 0, 0}, {3, 0.5f, 0}, {2.5f, 2, 0}, {-0.5f, 1.5f, 0}},
          {{0, 0, 0}, {2, 0.5f, 0}, {0.5f, 1.5f, 0}}};
}

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
      // Frame::to_world takes the local axes to t, b, n.
      const core::Frame frame(n);
      CHECK(glm::length(frame.to_world(glm::vec3(1, 0, 0)) - t) == 0.0f);
      CHECK(glm::length(frame.to_world(glm::vec3(0, 1, 0)) - b) == 0.0f);
      CHECK(glm::length(frame.to_world(glm::vec3(0, 0, 1)) - n) == 0.0f);
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

  TEST_CASE("the cell warp is area-uniform: chi-square over exact sub-region areas, pdf 1 / area") {
    // Counts of random points in a k x k grid of the bounding box against the exact areas of the
    // grid cells clipped to the polygon; 99.99th percentile of chi-square with <= 63 degrees of
    // freedom is about 113.
    constexpr int k = 8, n = 200000;
    for (const auto& corners : test_cells()) {
      CAPTURE(corners.size());
      const core::CellSampler warp(corners.data(), static_cast<int>(corners.size()));
      std::vector<glm::dvec2> polygon;
      glm::dvec2 lo(1e9), hi(-1e9);
      for (const glm::vec3& c : corners) {
        polygon.emplace_back(c.x, c.y);
        lo = glm::min(lo, polygon.back());
        hi = glm::max(hi, polygon.back());
      }
      const double area = area_xy(polygon);
      CHECK(warp.pdf() == doctest::Approx(1.0 / area).epsilon(1e-6));
      const glm::dvec2 cell = (hi - lo) / double(k);
      std::array<int, k * k> count{};
      core::Rng rng(11, corners.size(), 0);
      for (int i = 0; i < n; ++i) {
        const glm::vec3 x = warp(rng.uniform2());
        CHECK(x.z == 0.0f);
        const int a = std::min(k - 1, static_cast<int>((x.x - lo.x) / cell.x));
        const int b = std::min(k - 1, static_cast<int>((x.y - lo.y) / cell.y));
        ++count[static_cast<std::size_t>(a * k + b)];
      }
      double chi2 = 0.0, covered = 0.0;
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          std::vector<glm::dvec2> part = clip(polygon, 0, lo.x + a * cell.x, false);
          part = clip(part, 0, lo.x + (a + 1) * cell.x, true);
          part = clip(part, 1, lo.y + b * cell.y, false);
          part = clip(part, 1, lo.y + (b + 1) * cell.y, true);
          const double q = part.size() >= 3 ? area_xy(part) / area : 0.0;
          covered += q;
          const int c = count[static_cast<std::size_t>(a * k + b)];
          if (q > 0.0) {
            chi2 += (c - n * q) * (c - n * q) / (n * q);
          } else {
            CHECK(c == 0);
          }
        }
      CHECK(covered == doctest::Approx(1.0).epsilon(1e-9));
      CHECK(chi2 < 113.0);
    }
  }

  TEST_CASE("the cell warp keeps strata: each (u,v) stratum maps to 1/g^2 of the area") {
    // The image of a stratum, measured as the sum of the areas of the images of an m x m
    // sub-grid (chords for the curved edges: error O(1/m^2)). The plain bilinear map would miss
    // by a third on the trapezoid, whose Jacobian doubles from its short side to its long one.
    constexpr int g = 6, m = 16;
    for (const auto& corners : test_cells()) {
      CAPTURE(corners.size());
      const core::CellSampler warp(corners.data(), static_cast<int>(corners.size()));
      auto image = [&](double u, double v) {
        const glm::vec3 x = warp(glm::vec2(static_cast<float>(u), static_cast<float>(v)));
        return glm::dvec2(x.x, x.y);
      };
      const double area = 1.0 / warp.pdf();
      double worst = 0.0;
      for (int i = 0; i < g; ++i)
        for (int j = 0; j < g; ++j) {
          double a = 0.0;
          for (int p = 0; p < m; ++p)
            for (int q = 0; q < m; ++q) {
              const double u0 = (i + double(p) / m) / g, u1 = (i + double(p + 1) / m) / g;
              const double v0 = (j + double(q) / m) / g, v1 = (j + double(q + 1) / m) / g;
              a += area_xy({image(u0, v0), image(u1, v0), image(u1, v1), image(u0, v1)});
            }
          worst = std::max(worst, std::fabs(a / area * g * g - 1.0));
        }
      CHECK(worst < 1e-4);
    }
  }

  TEST_CASE("the cell warp of a parallelogram is the plain affine map") {
    const std::array<glm::vec3, 4> p{glm::vec3(1, 2, 3), glm::vec3(4, 2.5f, 3), glm::vec3(5, 4.5f, 4),
                                     glm::vec3(2, 4, 4)};
    const core::CellSampler warp(p.data(), 4);
    // A quad just beyond the parallelogram test takes the general bilinear warp: it agrees to
    // the size of the change.
    std::array<glm::vec3, 4> q = p;
    q[2] += glm::vec3(1e-3f, 0, 0);
    const core::CellSampler near(q.data(), 4);
    grid(16, [&](glm::vec2 u) {
      const glm::vec3 affine = p[0] + u.x * (p[1] - p[0]) + u.y * (p[3] - p[0]);
      CHECK(warp(u) == affine);
      CHECK(glm::length(near(u) - affine) < 2e-3f);
    });
  }

  TEST_CASE("stratified points: one per cell of the closest-to-square grid, or a Latin hypercube") {
    // (rows, columns) the grid must have, or 0 rows for a Latin hypercube: squares, the
    // sky's 640 = 20 x 32 and 160 = 10 x 16, a prime, and 2 x 97 (too elongated for a grid).
    const std::array<std::array<unsigned, 3>, 6> cases{{{256, 16, 16}, {640, 20, 32}, {160, 10, 16}, {12, 3, 4},
                                                         {97, 0, 0}, {194, 0, 0}}};
    for (const auto& c : cases) {
      const unsigned count = c[0], rows = c[1], columns = c[2];
      core::Rng rng(7, count, 0);
      std::vector<glm::vec2> p(count);
      core::stratified(count, rng, true, p.data());
      std::vector<int> cell(count, 0), u_strata(count, 0), v_strata(count, 0);
      for (const glm::vec2& q : p) {
        REQUIRE(q.x >= 0.0f);
        REQUIRE(q.x < 1.0f);
        REQUIRE(q.y >= 0.0f);
        REQUIRE(q.y < 1.0f);
        if (rows > 0)
          ++cell[static_cast<unsigned>(q.x * rows) * columns + static_cast<unsigned>(q.y * columns)];
        ++u_strata[static_cast<unsigned>(q.x * count)];
        ++v_strata[static_cast<unsigned>(q.y * count)];
      }
      INFO("count " << count);
      if (rows > 0) {
        for (int n : cell) CHECK(n == 1);
      } else {
        for (unsigned k = 0; k < count; ++k) {
          CHECK(u_strata[k] == 1);
          CHECK(v_strata[k] == 1);
        }
      }
    }
  }

  TEST_CASE("shifted Halton points: the sequence plus the shift modulo 1, below 1, stratified in 4D") {
    radiosity::detail::Rng rng(11, 3, 0);
    const core::ShiftedHalton4 halton(rng);
    // Point k - point 0 (mod 1) is the sequence's point k + 1 - its point 1, whatever the shift,
    // in the table and past it (k >= kHaltonTable is computed, not looked up).
    glm::vec2 a0, b0;
    halton.point(0, a0, b0);
    const std::array<double, 4> p0 = {a0.x, a0.y, b0.x, b0.y};
    const std::array<std::uint32_t, 4> bases = {2, 3, 5, 7};
    for (const std::uint32_t k : {1u, 2u, 17u, 4095u, core::kHaltonTable - 1, core::kHaltonTable, 100000u}) {
      glm::vec2 a, b;
      halton.point(k, a, b);
      const std::array<double, 4> p = {a.x, a.y, b.x, b.y};
      for (std::size_t d = 0; d < 4; ++d) {
        CHECK(p[d] >= 0.0);
        CHECK(p[d] < 1.0);
        double diff = p[d] - p0[d] - (core::radical_inverse(k + 1, bases[d]) - core::radical_inverse(1, bases[d]));
        diff -= std::round(diff);
        CHECK(std::fabs(diff) < 1e-6);  // the 24-bit floats' rounding, twice
      }
    }
    // Stratified: per dimension, the first b^2 points of base b put exactly b points in each
    // interval [j / b, (j + 1) / b), counted from point 0 modulo 1 (the shift moves them all).
    for (std::size_t d = 0; d < 4; ++d) {
      const std::uint32_t base = bases[d];
      std::vector<int> count(base, 0);
      for (std::uint32_t k = 0; k < base * base; ++k) {
        glm::vec2 a, b;
        halton.point(k, a, b);
        const double x = std::array<double, 4>{a.x, a.y, b.x, b.y}[d] - p0[d];
        double unit = x - std::floor(x);
        if (unit > 1.0 - 1e-6) unit = 0.0;  // just below a wrap by rounding: 0
        ++count[std::min<std::size_t>(base - 1, static_cast<std::size_t>(unit * base + 1e-5))];
      }
      for (const int c : count) CHECK(c == static_cast<int>(base));
    }
  }

  TEST_CASE("Gauss-Legendre rules integrate polynomials of degree 2n - 1 exactly, over [0,1], a triangle and a "
            "trapezoid") {
    for (int n = 1; n <= core::kMaxGaussOrder; ++n) {
      const core::GaussRule& rule = core::gauss_rule(n);
      double weights = 0.0, moment = 0.0;
      for (int i = 0; i < n; ++i) {
        weights += rule.weight[static_cast<std::size_t>(i)];
        moment += rule.weight[static_cast<std::size_t>(i)] * std::pow(rule.node[static_cast<std::size_t>(i)], 2 * n - 1);
      }
      CHECK(weights == doctest::Approx(1.0).epsilon(1e-6));
      CHECK(moment == doctest::Approx(1.0 / (2 * n)).epsilon(1e-5));  // the integral of t^(2n-1) over [0,1]
    }
    // Means of x^2 and y^2 (degree 2: exact with 2 x 2 points) against their integrals.
    const glm::vec3 triangle[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // mean of x^2: (1/12) / (1/2)
    CHECK(core::polygon_gauss_mean(triangle, 3, 2, [](const glm::vec3& p) { return p.x * p.x; }) ==
          doctest::Approx(1.0 / 6.0).epsilon(1e-5));
    // A trapezoid (no parallelogram: the bilinear map's Jacobian varies), width 2 - y, area 1.5:
    // the mean of y is (1 - 1/3) / 1.5 = 4/9, of y^2 (2/3 - 1/4) / 1.5 = 5/18.
    const glm::vec3 trapezoid[4] = {{0, 0, 0}, {2, 0, 0}, {1.5f, 1, 0}, {0.5f, 1, 0}};
    CHECK(core::polygon_gauss_mean(trapezoid, 4, 2, [](const glm::vec3& p) { return p.y; }) ==
          doctest::Approx(4.0 / 9.0).epsilon(1e-5));
    CHECK(core::polygon_gauss_mean(trapezoid, 4, 2, [](const glm::vec3& p) { return p.y * p.y; }) ==
          doctest::Approx(5.0 / 18.0).epsilon(1e-5));
    const glm::vec3 degenerate[3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    CHECK(core::polygon_gauss_mean(degenerate, 3, 2, [](const glm::vec3&) { return 1.0f; }) == 0.0f);
  }
}
