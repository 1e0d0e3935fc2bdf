// Scene::add_light(): lights enter checked, with the field named in every refusal, their
// direction normalised and defaulted; the photometric conversion.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// The message of the Error that add_light(light) throws (empty when it does not throw).
std::string refusal(const rad::Light& light) {
  rad::Scene scene;
  try {
    scene.add_light(light);
  } catch (const rad::Error& e) {
    CHECK(e.code() == rad::ErrorCode::invalid_scene);
    CHECK(scene.lights().empty());
    return e.what();
  }
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("add_light keeps the light with its direction normalised and defaulted per type") {
    rad::Scene scene;
    rad::Light sun;
    sun.type = rad::LightType::directional;
    sun.name = "sun";
    sun.intensity = 800.0f;
    sun.direction = {1.0f, -2.0f, 2.0f};
    CHECK(scene.add_light(sun) == 0);
    rad::Light sky;
    sky.type = rad::LightType::sky;
    CHECK(scene.add_light(sky) == 1);
    rad::Light spot;
    spot.type = rad::LightType::spot;
    CHECK(scene.add_light(spot) == 2);
    REQUIRE(scene.lights().size() == 3);
    CHECK(scene.lights()[0].name == "sun");
    CHECK(scene.lights()[0].direction.x == doctest::Approx(1.0 / 3.0));
    CHECK(scene.lights()[0].direction.y == doctest::Approx(-2.0 / 3.0));
    CHECK(scene.lights()[1].direction == glm::vec3(0.0f, 1.0f, 0.0f));   // a sky's zenith: up
    CHECK(scene.lights()[2].direction == glm::vec3(0.0f, -1.0f, 0.0f));  // a spot: straight down
    CHECK(scene.lights()[1].light_group.empty());
  }

  TEST_CASE("add_light refuses bad values naming the light and the field") {
    rad::Light l;
    l.name = "lamp";
    l.intensity = -1.0f;
    std::string m = refusal(l);
    CHECK(contains(m, "light 'lamp' (light 0, point)"));
    CHECK(contains(m, "intensity"));
    l.intensity = std::numeric_limits<float>::quiet_NaN();
    CHECK(contains(refusal(l), "intensity"));
    l.intensity = 1.0f;
    l.color = rad::Rgb(1.0f, -0.5f, 1.0f);
    CHECK(contains(refusal(l), "color"));
    l.color = rad::Rgb(1.0f);
    l.position.x = std::numeric_limits<float>::infinity();
    CHECK(contains(refusal(l), "position"));
    l.position = glm::vec3(0.0f);
    l.type = rad::LightType::spot;
    l.inner_cone_deg = 50.0f;
    l.outer_cone_deg = 40.0f;
    CHECK(contains(refusal(l), "inner_cone_deg/outer_cone_deg"));
    l.inner_cone_deg = 10.0f;
    l.outer_cone_deg = 95.0f;
    CHECK(contains(refusal(l), "inner_cone_deg/outer_cone_deg"));
    l.inner_cone_deg = -1.0f;
    l.outer_cone_deg = 40.0f;
    CHECK(contains(refusal(l), "inner_cone_deg/outer_cone_deg"));
    l.inner_cone_deg = 10.0f;
    l.type = rad::LightType::directional;
    l.direction = {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f};
    CHECK(contains(refusal(l), "direction"));
    l.direction = {1e-30f, 0.0f, 0.0f};  // tiny but valid: normalised in double
    CHECK(refusal(l).empty());
    l.type = static_cast<rad::LightType>(17);
    CHECK(contains(refusal(l), "type"));
  }

  TEST_CASE("photometric_to_radiometric divides candela and lux by 683 lm/W") {
    CHECK(rad::photometric_to_radiometric(683.0f) == doctest::Approx(1.0f));
    CHECK(rad::photometric_to_radiometric(100000.0f) == doctest::Approx(146.41f).epsilon(1e-4));
    static_assert(rad::kLumensPerWatt == 683.0f, "the definition of the candela");
  }
}
