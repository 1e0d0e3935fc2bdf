// The shape helpers add_quad, add_box and add_sphere: closed surfaces (the area-weighted normals
// sum to zero), outward normals (the divergence-theorem volume is positive and right), areas
// against closed forms, and argument validation.
#include <cmath>
#include <limits>
#include <string>

#include <doctest/doctest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "radiosity/scene.hpp"

namespace {

namespace rad = radiosity;
constexpr double kPi = 3.14159265358979323846;

struct Totals {
  double area = 0.0;
  glm::dvec3 weighted_normal{0.0};  ///< sum of A n: zero for a closed surface
  double volume = 0.0;              ///< (1/3) sum A (n . c): the enclosed volume when normals point out
  bool all_outward = true;          ///< every polygon faces away from `inside`
};

Totals totals(const rad::Scene& scene, rad::PolygonRange range, glm::vec3 inside) {
  Totals t;
  for (rad::PolygonId i = range.first; i < range.first + range.count; ++i) {
    const rad::Polygon& p = scene.polygons()[i];
    glm::vec3 c(0.0f);
    for (const glm::vec3& v : p.vertices) c += v;
    c /= static_cast<float>(p.vertices.size());
    t.area += p.area;
    t.weighted_normal += glm::dvec3(p.normal) * static_cast<double>(p.area);
    t.volume += p.area * glm::dot(glm::dvec3(p.normal), glm::dvec3(c - inside)) / 3.0;
    t.all_outward = t.all_outward && glm::dot(p.normal, c - inside) > 0.0f;
  }
  return t;
}

/// Closed-form area of the UV sphere add_sphere builds: each slice of each band is an isosceles
/// trapezoid (a triangle at the poles) with parallel sides 2 a_i = 2 r sin(theta_i) sin(pi/n)
/// and height the distance between their midpoints.
double uv_sphere_area(double r, int n) {
  const int rings = (n + 1) / 2;
  double sum = 0.0;
  for (int i = 0; i < rings; ++i) {
    const double t0 = kPi * i / rings, t1 = kPi * (i + 1) / rings;
    const double a0 = r * std::sin(t0) * std::sin(kPi / n), a1 = r * std::sin(t1) * std::sin(kPi / n);
    const double dm = r * (std::sin(t0) - std::sin(t1)) * std::cos(kPi / n), dy = r * (std::cos(t0) - std::cos(t1));
    sum += (a0 + a1) * std::sqrt(dm * dm + dy * dy);
  }
  return n * sum;
}

}  // namespace

TEST_SUITE("scene") {

TEST_CASE("add_quad faces edge_u x edge_v with the area of that cross product") {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  const rad::PolygonRange r = rad::add_quad(scene, {1, 2, 3}, {2, 0, 0}, {0.5f, 0, -3}, m, "q");
  REQUIRE(r.count == 1);
  const rad::Polygon& p = scene.polygons()[r.first];
  const glm::vec3 n = glm::cross(glm::vec3(2, 0, 0), glm::vec3(0.5f, 0, -3));
  CHECK(p.area == doctest::Approx(glm::length(n)).epsilon(1e-6));
  CHECK(glm::dot(p.normal, glm::normalize(n)) == doctest::Approx(1.0).epsilon(1e-6));
  CHECK_THROWS_AS(rad::add_quad(scene, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}, m), rad::Error);
}

TEST_CASE("add_box makes six outward quads enclosing the box volume - also under a mirroring transform") {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  const glm::vec3 lo(-1, 0, 2), hi(1, 3, 2.5f);
  const rad::PolygonRange r = rad::add_box(scene, lo, hi, m, "box");
  REQUIRE(r.count == 6);
  CHECK(scene.warnings().empty());
  Totals t = totals(scene, r, 0.5f * (lo + hi));
  // 2 (xy + yz + zx) and xyz for a 2 x 3 x 0.5 box; float rounding of 1e-6 relative.
  CHECK(t.area == doctest::Approx(2.0 * (6.0 + 1.5 + 1.0)).epsilon(1e-6));
  CHECK(t.volume == doctest::Approx(3.0).epsilon(1e-6));
  CHECK(glm::length(t.weighted_normal) < 1e-5 * t.area);
  CHECK(t.all_outward);

  // Rotate 30 degrees about (1, 1, 0), scale by (2, -1, 0.5) (a mirror: det < 0), translate.
  glm::mat4 x = glm::translate(glm::mat4(1.0f), glm::vec3(5, -2, 1));
  x = glm::rotate(x, glm::radians(30.0f), glm::normalize(glm::vec3(1, 1, 0)));
  x = glm::scale(x, glm::vec3(2, -1, 0.5f));
  const rad::PolygonRange rx = rad::add_box(scene, lo, hi, m, "turned", x);
  REQUIRE(rx.count == 6);
  CHECK(rx.first == 6);
  t = totals(scene, rx, glm::vec3(x * glm::vec4(0.5f * (lo + hi), 1.0f)));
  CHECK(t.all_outward);
  CHECK(t.volume == doctest::Approx(3.0 * 2.0 * 1.0 * 0.5).epsilon(1e-5));  // |det| x volume
  CHECK(glm::length(t.weighted_normal) < 1e-5 * t.area);
}

TEST_CASE("add_box rejects empty bounds and singular - non-affine or non-finite transforms") {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  CHECK_THROWS_WITH_AS(rad::add_box(scene, {0, 0, 0}, {1, 0, 1}, m), doctest::Contains("lower must be below upper"),
                       rad::Error);
  CHECK_THROWS_WITH_AS(rad::add_box(scene, {0, 0, 0}, {1, 1, 1}, m, "b", glm::scale(glm::mat4(1.0f), {1, 0, 1})),
                       doctest::Contains("singular"), rad::Error);
  glm::mat4 projective(1.0f);
  projective[0][3] = 0.5f;
  CHECK_THROWS_WITH_AS(rad::add_box(scene, {0, 0, 0}, {1, 1, 1}, m, "b", projective), doctest::Contains("affine"),
                       rad::Error);
  glm::mat4 nan(1.0f);
  nan[3][0] = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH_AS(rad::add_box(scene, {0, 0, 0}, {1, 1, 1}, m, "b", nan), doctest::Contains("finite"), rad::Error);
  CHECK(scene.polygons().empty());
}

TEST_CASE("add_sphere is closed with outward convex faces and its area matches the inscribed polyhedron") {
  const glm::vec3 centre(0.3f, -1.0f, 2.0f);
  const float radius = 1.5f;
  for (int n : {4, 7, 16, 32}) {
    CAPTURE(n);
    rad::Scene scene;
    const rad::MaterialId m = scene.add_material(rad::Material{});
    const rad::PolygonRange r = rad::add_sphere(scene, centre, radius, m, "ball", n);
    const int rings = (n + 1) / 2;
    CHECK(r.count == static_cast<std::uint32_t>(n * rings));  // no face was triangulated or dropped
    CHECK(scene.warnings().empty());                         // every face planar and convex
    const Totals t = totals(scene, r, centre);
    CHECK(t.all_outward);
    CHECK(glm::length(t.weighted_normal) < 1e-5 * t.area);
    CHECK(t.area == doctest::Approx(uv_sphere_area(radius, n)).epsilon(1e-5));
    // An inscribed convex polyhedron encloses less than the ball.
    CHECK(t.volume > 0.0);
    CHECK(t.volume < 4.0 / 3.0 * kPi * radius * radius * radius);
  }
}

TEST_CASE("add_sphere area converges to 4 pi r^2 from below as 1 over segments squared") {
  const float radius = 2.0f;
  const double exact = 4.0 * kPi * radius * radius;
  double previous = 0.0;
  for (int n : {16, 32, 64, 128}) {
    CAPTURE(n);
    rad::Scene scene;
    const rad::MaterialId m = scene.add_material(rad::Material{});
    const Totals t = totals(scene, rad::add_sphere(scene, glm::vec3(0.0f), radius, m, "s", n), glm::vec3(0.0f));
    const double error = (exact - t.area) / exact;
    CHECK(error > 0.0);
    // With d = 2 pi / n in both directions, a face loses d^2 / 24 to its chords along the ring,
    // d^2 / 24 to its chords along the meridian, and d^2 / 8 because its mean width is taken at
    // the rings (the mean of sin(theta) at the ends is sin(theta_mid) cos(d / 2)): in all
    // 5 d^2 / 24 = 5 pi^2 / (6 n^2), 0.80 % at n = 32. Allow 10 % for the higher-order terms.
    const double predicted = 5.0 * kPi * kPi / (6.0 * n * n);
    CHECK(error < 1.1 * predicted);
    CHECK(error > 0.9 * predicted);
    if (previous > 0.0) CHECK(previous / error == doctest::Approx(4.0).epsilon(0.05));
    previous = error;
  }
}

TEST_CASE("add_sphere validates segments - radius and centre naming the argument") {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  CHECK_THROWS_WITH_AS(rad::add_sphere(scene, {0, 0, 0}, 1.0f, m, "s", 3), doctest::Contains("segments"), rad::Error);
  CHECK_THROWS_WITH_AS(rad::add_sphere(scene, {0, 0, 0}, 1.0f, m, "s", 1025), doctest::Contains("segments"), rad::Error);
  CHECK_THROWS_WITH_AS(rad::add_sphere(scene, {0, 0, 0}, 0.0f, m, "s", 8), doctest::Contains("radius"), rad::Error);
  CHECK_THROWS_WITH_AS(rad::add_sphere(scene, {0, 0, 0}, std::numeric_limits<float>::quiet_NaN(), m, "s", 8),
                       doctest::Contains("radius"), rad::Error);
  CHECK_THROWS_WITH_AS(rad::add_sphere(scene, {0, std::numeric_limits<float>::infinity(), 0}, 1.0f, m, "s", 8),
                       doctest::Contains("centre"), rad::Error);
  CHECK(scene.polygons().empty());
}

}  // TEST_SUITE("scene")
