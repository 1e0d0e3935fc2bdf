// Loading a scene file in a test: strict or not, the Error it throws, a vector comparison, and
// the check of a light a reader made.
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <doctest/doctest.h>
#include <glm/vec3.hpp>

#include "radiosity/io.hpp"

namespace test {

/// A copy of the OBJ `source` in `dir` named `name`, every `v` moved by `offset` and written
/// with 6 decimals (as a GIS or BIM export writes a model at its site's coordinates), with the
/// MTL of the same stem beside it; returns its path.
inline std::filesystem::path moved_obj(const std::filesystem::path& source, const std::filesystem::path& dir,
                                       const std::string& name, const glm::dvec3& offset) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  fs::path mtl = source;
  mtl.replace_extension(".mtl");
  if (fs::exists(mtl)) fs::copy_file(mtl, dir / mtl.filename(), fs::copy_options::overwrite_existing);
  std::ifstream in(source);
  std::ofstream out(dir / name);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string tag;
    double x = 0, y = 0, z = 0;
    if ((words >> tag) && tag == "v" && (words >> x >> y >> z)) {
      char moved[128];
      std::snprintf(moved, sizeof moved, "v %.6f %.6f %.6f", x + offset.x, y + offset.y, z + offset.z);
      line = moved;
    }
    out << line << "\n";
  }
  return dir / name;
}

inline bool near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  return std::fabs(a.x - b.x) <= eps && std::fabs(a.y - b.y) <= eps && std::fabs(a.z - b.z) <= eps;
}

/// A Light of the given fields, what a reader is expected to make (cones in degrees).
inline radiosity::Light light_of(radiosity::LightType type, const std::string& name, glm::vec3 position, glm::vec3 direction,
                                 radiosity::Rgb color, float intensity, float inner_cone_deg = 0.0f, float outer_cone_deg = 45.0f) {
  radiosity::Light l;
  l.type = type;
  l.name = name;
  l.position = position;
  l.direction = direction;
  l.color = color;
  l.intensity = intensity;
  l.inner_cone_deg = inner_cone_deg;
  l.outer_cone_deg = outer_cone_deg;
  return l;
}

/// Checks that `got` is `want` in what its type uses: name, colour, intensity; the position of
/// a point or spot, the direction of a spot or directional light, a spot's cones.
inline void check_light(const radiosity::Light& got, const radiosity::Light& want) {
  INFO("light '" << want.name << "'");
  CHECK(got.type == want.type);
  CHECK(got.name == want.name);
  CHECK(near(got.color, want.color));
  CHECK(got.intensity == doctest::Approx(want.intensity));
  if (want.type != radiosity::LightType::directional) CHECK(near(got.position, want.position));
  if (want.type != radiosity::LightType::point) CHECK(near(got.direction, want.direction));
  if (want.type == radiosity::LightType::spot) {
    CHECK(got.inner_cone_deg == doctest::Approx(want.inner_cone_deg));
    CHECK(got.outer_cone_deg == doctest::Approx(want.outer_cone_deg));
  }
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
