#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

bool message_contains(const rad::Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

template <typename F>
rad::Error capture(F&& f) {
  try {
    f();
  } catch (const rad::Error& e) {
    return e;
  }
  FAIL("expected radiosity::Error");
  return rad::Error(rad::ErrorCode::internal, "unreachable");
}

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("a quad keeps its vertices - right-hand normal and area") {
    rad::Scene s;
    auto m = s.add_material({});
    auto r = s.add_polygon({{0, 0, 0}, {2, 0, 0}, {2, 3, 0}, {0, 3, 0}}, m, "wall");
    REQUIRE(r.count == 1);
    const rad::Polygon& p = s.polygons()[r.first];
    CHECK(p.vertices.size() == 4);
    CHECK(p.area == doctest::Approx(6.0).epsilon(1e-6));
    CHECK(p.normal.z == doctest::Approx(1.0));
    CHECK(s.groups()[p.group] == "wall");
    CHECK(s.warnings().empty());
  }

  TEST_CASE("duplicate and collinear vertices are dropped") {
    rad::Scene s;
    auto m = s.add_material({});
    auto r = s.add_polygon({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}}, m, "g");
    CHECK(s.polygons()[r.first].vertices.size() == 4);
    CHECK(s.polygons()[r.first].area == doctest::Approx(4.0));
  }

  TEST_CASE("a non-convex polygon is triangulated with a warning and keeps its area") {
    rad::Scene s;
    auto m = s.add_material({});
    // An L shape of area 3.
    auto r = s.add_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}}, m, "L");
    CHECK(r.count == 4);
    double area = 0;
    for (std::uint32_t i = 0; i < r.count; ++i) {
      area += s.polygons()[r.first + i].area;
      CHECK(s.polygons()[r.first + i].normal.z == doctest::Approx(1.0));
    }
    CHECK(area == doctest::Approx(3.0));
    REQUIRE(s.warnings().size() == 1);
    CHECK(s.warnings()[0].find("non-convex") != std::string::npos);
  }

  TEST_CASE("a non-planar quad is split into two triangles with a warning") {
    rad::Scene s;
    auto m = s.add_material({});
    auto r = s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.2f}, {0, 1, 0}}, m, "bent");
    CHECK(r.count == 2);
    CHECK(s.warnings().size() == 1);
    CHECK(s.warnings()[0].find("non-planar") != std::string::npos);
  }

  TEST_CASE("NaN - infinite and degenerate polygons are rejected with a message naming the problem") {
    rad::Scene s;
    auto m = s.add_material({});
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    auto e1 = capture([&] { s.add_polygon({{0, 0, 0}, {nan, 0, 0}, {0, 1, 0}}, m, "g"); });
    CHECK(e1.code() == rad::ErrorCode::invalid_scene);
    CHECK(message_contains(e1, "NaN or infinite"));
    auto e2 = capture([&] { s.add_polygon({{0, 0, 0}, {inf, 0, 0}, {0, 1, 0}}, m, "g"); });
    CHECK(message_contains(e2, "vertex 1"));
    auto e3 = capture([&] { s.add_polygon({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, m, "line"); });
    CHECK(message_contains(e3, "degenerate"));
    CHECK(message_contains(e3, "line"));
    auto e4 = capture([&] { s.add_polygon({{0, 0, 0}, {1, 0, 0}}, m, "g"); });
    CHECK(message_contains(e4, "degenerate"));
    auto e5 = capture([&] { s.add_polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 7, "g"); });
    CHECK(e5.code() == rad::ErrorCode::invalid_argument);
    // Finite but so large that the area overflows float: refused, not an infinite area (a
    // fuzzed STL file found it, at 1e30); 1e9 is the largest accepted.
    auto e6 = capture([&] { s.add_polygon({{0, 0, 0}, {2e9f, 0, 0}, {0, 1, 0}}, m, "huge"); });
    CHECK(e6.code() == rad::ErrorCode::invalid_scene);
    CHECK(message_contains(e6, "vertex 1 has a coordinate beyond +-1e9"));
    CHECK(s.polygons().empty());
    s.add_polygon({{0, 0, 0}, {1e9f, 0, 0}, {0, 1e9f, 0}}, m, "large");
    REQUIRE(s.polygons().size() == 1);
    CHECK(std::isfinite(s.polygons()[0].area));
  }

  TEST_CASE("reflectance of 1 or more - negative emission and NaN are rejected naming the material") {
    rad::Scene s;
    rad::Material m;
    m.name = "bright";
    m.reflectance = rad::Rgb(0.5f, 1.0f, 0.5f);
    auto e1 = capture([&] { s.add_material(m); });
    CHECK(e1.code() == rad::ErrorCode::invalid_scene);
    CHECK(message_contains(e1, "bright"));
    CHECK(message_contains(e1, "reflectance"));
    m.reflectance = rad::Rgb(-0.1f);
    CHECK_THROWS_AS(s.add_material(m), rad::Error);
    m.reflectance = rad::Rgb(0.5f);
    m.emission = rad::Rgb(-1.0f);
    CHECK_THROWS_AS(s.add_material(m), rad::Error);
    m.emission = rad::Rgb(std::numeric_limits<float>::quiet_NaN());
    CHECK_THROWS_AS(s.add_material(m), rad::Error);
    m.emission = rad::Rgb(0.0f);
    m.specular = rad::Rgb(0.6f);  // 0.5 diffuse + 0.6 specular would create energy
    auto e2 = capture([&] { s.add_material(m); });
    CHECK(message_contains(e2, "reflectance + specular"));
    CHECK(s.materials().empty());
  }

  TEST_CASE("the built-in Cornell box has the published camera - groups and materials") {
    rad::Scene s = rad::cornell_box();
    rad::Camera c = s.camera();
    CHECK(c.eye.x == doctest::Approx(278));
    CHECK(c.eye.z == doctest::Approx(-800));
    CHECK(c.fov_deg == doctest::Approx(39.3077));
    for (const char* g : {"floor", "ceiling", "back_wall", "red_wall", "green_wall", "light", "short_block",
                          "tall_block"})
      CHECK_MESSAGE(s.find_group(g).has_value(), g);
    // Every wall faces the inside of the room, every block face faces out of its block.
    const glm::vec3 inside(278, 274, 280);
    for (const rad::Polygon& p : s.polygons()) {
      const std::string& g = s.groups()[p.group];
      glm::vec3 centre(0.0f);
      for (auto& v : p.vertices) centre += v;
      centre /= static_cast<float>(p.vertices.size());
      if (g.find("block") == std::string::npos) CHECK_MESSAGE(glm::dot(p.normal, inside - centre) > 0.0f, g);
    }
    // Light: radiance (17,12,4) -> exitance pi * L.
    bool found = false;
    for (const rad::Material& m : s.materials())
      if (m.name == "light") {
        CHECK(m.emission.x == doctest::Approx(17 * 3.14159265));
        CHECK(m.reflectance.x == doctest::Approx(0.78));
        found = true;
      }
    CHECK(found);
    // Total area: 5 walls (the ceiling includes the light) and two blocks, in mm^2.
    CHECK(s.total_area() == doctest::Approx(5.0 * 556 * 556).epsilon(0.35));
  }

  TEST_CASE("a scene without a camera frames its bounds") {
    rad::Scene s;
    auto m = s.add_material({});
    s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "q");
    rad::Camera c = s.camera();
    CHECK(c.look_at.x == doctest::Approx(0.5));
    CHECK(c.eye.z < 0.0f);
    CHECK_THROWS_AS(s.set_camera(rad::Camera{{0, 0, 0}, {0, 0, 0}, {0, 1, 0}, 45}), rad::Error);
  }

  TEST_CASE("version() matches the generated header") { CHECK(std::string(rad::version()) == RADIOSITY_VERSION_STRING); }
}
