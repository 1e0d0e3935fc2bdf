// Loading a scene file in a test: strict or not, the Error it throws, and a vector comparison.
#pragma once

#include <cmath>
#include <filesystem>

#include <doctest/doctest.h>
#include <glm/vec3.hpp>

#include "radiosity/io.hpp"

namespace test {

inline bool near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  return std::fabs(a.x - b.x) <= eps && std::fabs(a.y - b.y) <= eps && std::fabs(a.z - b.z) <= eps;
}

/// load_scene() with LoadOptions::strict as given.
inline radiosity::Scene load(const std::filesystem::path& path, bool strict = false) {
  radiosity::LoadOptions options;
  options.strict = strict;
  return radiosity::load_scene(path, options);
}

/// The Error that loading `path` throws (failing the test when it loads).
inline radiosity::Error load_error(const std::filesystem::path& path, bool strict = false) {
  try {
    load(path, strict);
  } catch (const radiosity::Error& e) {
    return e;
  }
  FAIL("load_scene(" << path.string() << ") did not throw");
  return radiosity::Error(radiosity::ErrorCode::internal, "");
}

}  // namespace test
