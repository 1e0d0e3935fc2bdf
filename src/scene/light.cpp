// Scene::add_light(): the lights that are not polygons enter the scene checked, so the first
// shot and the renderers can trust them (docs/LIGHTS.md).
#include <cmath>
#include <sstream>
#include <string>

#include <glm/geometric.hpp>

#include "radiosity/scene.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

const char* type_name(LightType type) {
  switch (type) {
    case LightType::point: return "point";
    case LightType::spot: return "spot";
    case LightType::directional: return "directional";
    case LightType::sky: return "sky";
  }
  return "unknown";
}

std::string text(const glm::vec3& v) {
  std::ostringstream s;
  s << '(' << v.x << ", " << v.y << ", " << v.z << ')';
  return s.str();
}

}  // namespace

LightId Scene::add_light(const Light& given) {
  const auto id = static_cast<LightId>(lights_.size());
  const std::string who = "light '" + given.name + "' (light " + std::to_string(id) + ", " + type_name(given.type) + ")";
  auto fail = [&](const std::string& field, const std::string& problem) {
    throw Error(ErrorCode::invalid_scene, who + ": " + field + " " + problem);
  };
  if (given.type != LightType::point && given.type != LightType::spot && given.type != LightType::directional &&
      given.type != LightType::sky)
    fail("type", "is not a LightType");
  if (given.sky != SkyModel::uniform && given.sky != SkyModel::cie_overcast) fail("sky", "is not a SkyModel");
  if (!std::isfinite(given.intensity) || given.intensity < 0.0f)
    fail("intensity", "must be finite and >= 0, got " + std::to_string(given.intensity));
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(given.color[c]) || given.color[c] < 0.0f)
      fail("color", text(given.color) + " must be finite and >= 0 per channel");
  if (!detail::finite(given.position)) fail("position", text(given.position) + " must be finite");
  if (!detail::finite(given.direction)) fail("direction", text(given.direction) + " must be finite");
  if (!std::isfinite(given.inner_cone_deg) || !std::isfinite(given.outer_cone_deg) || given.inner_cone_deg < 0.0f ||
      given.inner_cone_deg > given.outer_cone_deg || given.outer_cone_deg > 90.0f)
    fail("inner_cone_deg/outer_cone_deg",
         "must satisfy 0 <= inner <= outer <= 90, got " + std::to_string(given.inner_cone_deg) + " and " +
             std::to_string(given.outer_cone_deg));

  Light light = given;
  if (light.direction == glm::vec3(0.0f))
    light.direction = light.type == LightType::sky ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(0.0f, -1.0f, 0.0f);
  // Normalised in double: a tiny but valid vector must not underflow to a NaN.
  const glm::dvec3 d(light.direction);
  const double length = glm::length(d);
  if (!(length > 0.0) || !std::isfinite(length)) fail("direction", text(given.direction) + " cannot be normalised");
  light.direction = glm::vec3(d / length);
  lights_.push_back(std::move(light));
  return id;
}

}  // namespace v1
}  // namespace radiosity
