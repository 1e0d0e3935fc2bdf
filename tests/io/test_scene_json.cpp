// The JSON scene format: every reflection model round-trips to the model make_* builds, every
// Material field is read, the primitives and OBJ includes build the expected polygons, every kind
// of bad input is an Error naming its place in the document, and the JSON Cornell box solves
// like the built-in one.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/geometric.hpp>

#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"
#include "radiosity/solver.hpp"

namespace {

namespace fs = std::filesystem;
namespace rad = radiosity;
using rad::Error;
using rad::ErrorCode;
using rad::Rgb;

const fs::path kData = RADIOSITY_TEST_DATA;
const fs::path kTmp = RADIOSITY_TEST_TMP;
const fs::path kScenes = fs::path(RADIOSITY_TEST_DATA) / ".." / ".." / "examples" / "scenes";
constexpr double kPi = 3.14159265358979323846;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A scene document with the given materials array and one floor quad of the first material.
std::string with_materials(const std::string& materials) {
  return R"({"version": 1, "materials": [)" + materials +
         R"(], "surfaces": [{"type": "quad", "origin": [0,0,0], "edge_u": [0,0,1], "edge_v": [1,0,0], "material": "m0"}]})";
}

/// The model the first material of `doc` carries.
std::shared_ptr<const rad::Brdf> brdf_of(const std::string& doc, const fs::path& base = {}) {
  const rad::Scene scene = rad::parse_scene_json(doc, base);
  REQUIRE(!scene.materials().empty());
  REQUIRE(scene.materials()[0].brdf);
  return scene.materials()[0].brdf;
}

bool close(const Rgb& a, const Rgb& b, float rel = 1e-6f) {
  for (int k = 0; k < 3; ++k)
    if (std::fabs(a[k] - b[k]) > rel * std::max(1.0f, std::max(std::fabs(a[k]), std::fabs(b[k])))) return false;
  return true;
}

/// Compares two models on a fixed set of directions: eval, pdf, sample and albedo must agree to
/// float rounding (the parameters went through JSON text, so they are the same floats).
void check_same_model(const rad::Brdf& a, const rad::Brdf& b) {
  std::vector<glm::vec3> dirs;
  for (double theta : {0.0, 20.0, 45.0, 70.0, 85.0})
    for (double phi : {0.3, 1.9, 4.0}) {
      const double t = theta * kPi / 180.0;
      dirs.push_back(glm::vec3(static_cast<float>(std::sin(t) * std::cos(phi)),
                               static_cast<float>(std::sin(t) * std::sin(phi)), static_cast<float>(std::cos(t))));
    }
  dirs.push_back(glm::normalize(glm::vec3(0.3f, -0.2f, -0.9f)));  // below: the dielectric transmits
  CHECK(a.is_delta() == b.is_delta());
  for (const glm::vec3& wo : dirs) {
    CHECK(close(a.albedo(wo), b.albedo(wo), 1e-5f));
    for (const glm::vec3& wi : dirs) {
      CHECK(close(a.eval(wo, wi), b.eval(wo, wi)));
      CHECK(std::fabs(a.pdf(wo, wi) - b.pdf(wo, wi)) <= 1e-6f * std::max(1.0f, std::fabs(a.pdf(wo, wi))));
    }
    for (glm::vec2 u : {glm::vec2(0.1f, 0.2f), glm::vec2(0.5f, 0.9f), glm::vec2(0.97f, 0.4f)}) {
      const auto sa = a.sample(wo, u), sb = b.sample(wo, u);
      REQUIRE(sa.has_value() == sb.has_value());
      if (!sa) continue;
      CHECK(glm::length(sa->wi - sb->wi) < 1e-6f);
      CHECK(close(sa->weight, sb->weight));
      CHECK(sa->delta == sb->delta);
    }
  }
}

void put_le(std::ofstream& out, std::uint32_t bits, int bytes) {
  for (int i = 0; i < bytes; ++i) out.put(static_cast<char>((bits >> (8 * i)) & 0xff));
}

/// A MERL-layout file (little-endian) whose entry depends on the channel and theta_half index
/// only: a red-tinted glossy lobe over a grey base, in stored (unscaled) units.
fs::path write_merl(const fs::path& path) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  for (std::int32_t d : {90, 90, 180}) put_le(out, static_cast<std::uint32_t>(d), 4);
  const double scale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
  for (int c = 0; c < 3; ++c)
    for (int ih = 0; ih < 90; ++ih) {
      const double f = 0.2 / kPi + (c == 0 ? 0.6 : 0.2) * std::exp(-ih / 8.0);
      std::uint64_t bits = 0;
      const double stored = f / scale[c];
      std::memcpy(&bits, &stored, sizeof bits);
      // One theta_half slab (90 x 180 equal entries), written at once.
      char entry[8];
      for (int b = 0; b < 8; ++b) entry[b] = static_cast<char>((bits >> (8 * b)) & 0xff);
      std::string slab;
      slab.reserve(90 * 180 * 8);
      for (int k = 0; k < 90 * 180; ++k) slab.append(entry, 8);
      out.write(slab.data(), static_cast<std::streamsize>(slab.size()));
    }
  REQUIRE(out.good());
  return path;
}

Error parse_error_of(const std::string& doc, const fs::path& base = {}, bool strict = false) {
  try {
    rad::LoadOptions options;
    options.strict = strict;
    rad::parse_scene_json(doc, base, "scene.json", options);
  } catch (const Error& e) {
    return e;
  }
  FAIL("parse_scene_json did not throw for: " << doc);
  return Error(ErrorCode::internal, "");
}

void check_error(const std::string& doc, ErrorCode code, const std::string& part, const fs::path& base = {},
                 bool strict = false) {
  const Error e = parse_error_of(doc, base, strict);
  INFO("message: " << std::string(e.what()));
  CHECK(e.code() == code);
  CHECK(contains(e.what(), part));
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("JSON brdf objects of every analytic model build the same model as make_*") {
  struct Case {
    const char* json;
    std::shared_ptr<const rad::Brdf> direct;
  };
  const Case cases[] = {
      {R"({"type": "lambertian", "reflectance": [0.7, 0.5, 0.2]})", rad::make_lambertian({0.7f, 0.5f, 0.2f})},
      {R"({"type": "phong", "diffuse": 0.3, "specular": [0.4, 0.5, 0.6], "exponent": 40})",
       rad::make_phong(Rgb(0.3f), {0.4f, 0.5f, 0.6f}, 40.0f)},
      {R"({"type": "blinn_phong", "diffuse": [0.1, 0.2, 0.3], "specular": 0.5, "exponent": 120})",
       rad::make_blinn_phong({0.1f, 0.2f, 0.3f}, Rgb(0.5f), 120.0f)},
      {R"({"type": "ward", "diffuse": 0.2, "specular": 0.3, "alpha_x": 0.05, "alpha_y": 0.3})",
       rad::make_ward(Rgb(0.2f), Rgb(0.3f), 0.05f, 0.3f)},
      {R"({"type": "microfacet", "f0": [0.95, 0.64, 0.54], "roughness": 0.2})",
       rad::make_microfacet({0.95f, 0.64f, 0.54f}, 0.2f, 0.2f)},
      {R"({"type": "microfacet", "f0": 0.04, "roughness_x": 0.1, "roughness_y": 0.4})",
       rad::make_microfacet(Rgb(0.04f), 0.1f, 0.4f)},
      {R"({"type": "mirror", "reflectance": [0.9, 0.8, 0.7]})", rad::make_mirror({0.9f, 0.8f, 0.7f})},
      {R"({"type": "dielectric", "eta": 1.5, "tint": [1, 0.9, 0.8]})", rad::make_dielectric(1.5f, {1.0f, 0.9f, 0.8f})},
      {R"({"type": "dielectric", "eta": 1.33})", rad::make_dielectric(1.33f, Rgb(1.0f))},
      {R"({"type": "mix", "weight": 0.3, "first": {"type": "lambertian", "reflectance": 0.6},
           "second": {"type": "microfacet", "f0": 0.9, "roughness": 0.15}})",
       rad::make_mix(rad::make_lambertian(Rgb(0.6f)), rad::make_microfacet(Rgb(0.9f), 0.15f, 0.15f), 0.3f)},
  };
  for (const Case& c : cases) {
    CAPTURE(c.json);
    const auto parsed = brdf_of(with_materials(std::string(R"({"name": "m0", "brdf": )") + c.json + "}"));
    check_same_model(*parsed, *c.direct);
  }
}

TEST_CASE("JSON measured brdf reads the file relative to the base directory like load_measured") {
  const fs::path file = write_merl(kTmp / "json_scene" / "glossy.binary");
  const auto parsed =
      brdf_of(with_materials(R"({"name": "m0", "brdf": {"type": "measured", "file": "glossy.binary"}})"), file.parent_path());
  const auto direct = rad::load_measured(file);
  check_same_model(*parsed, *direct);
  // Without `reflectance`, the radiosity pass uses the model's albedo at normal incidence.
  const rad::Scene scene = rad::parse_scene_json(
      with_materials(R"({"name": "m0", "brdf": {"type": "measured", "file": "glossy.binary"}})"), file.parent_path());
  CHECK(close(scene.materials()[0].reflectance, direct->albedo({0.0f, 0.0f, 1.0f})));
  fs::remove(file);
}

TEST_CASE("JSON materials read every Material field and derive reflectance from a brdf's diffuse part") {
  const rad::Scene scene = rad::parse_scene_json(with_materials(R"(
    {"name": "m0", "emission": [1, 2, 3], "reflectance": [0.3, 0.2, 0.1], "specular": 0.25,
     "specular_exponent": 30, "transmittance": [0.5, 0.6, 0.7], "ior": 1.33,
     "diffuse_transmittance": 0.1, "two_sided": true},
    {"name": "lamp", "radiance": [17, 12, 4]},
    {"name": "ward", "brdf": {"type": "ward", "diffuse": [0.2, 0.3, 0.4], "specular": 0.2, "alpha_x": 0.1, "alpha_y": 0.2}},
    {"name": "mix", "brdf": {"type": "mix", "weight": 0.25, "first": {"type": "lambertian", "reflectance": 0.8},
                             "second": {"type": "mirror", "reflectance": 0.9}}},
    {"name": "plain"})"));
  REQUIRE(scene.materials().size() == 5);
  const rad::Material& m = scene.materials()[0];
  CHECK(m.name == "m0");
  CHECK(close(m.emission, {1.0f, 2.0f, 3.0f}));
  CHECK(close(m.reflectance, {0.3f, 0.2f, 0.1f}));
  CHECK(close(m.specular, Rgb(0.25f)));
  CHECK(m.specular_exponent == 30.0f);
  CHECK(close(m.transmittance, {0.5f, 0.6f, 0.7f}));
  CHECK(m.ior == doctest::Approx(1.33f));
  CHECK(close(m.diffuse_transmittance, Rgb(0.1f)));
  CHECK(m.two_sided);
  CHECK(!m.brdf);
  // Radiance L of a Lambertian emitter is an exitance of pi L.
  CHECK(close(scene.materials()[1].emission, static_cast<float>(kPi) * Rgb(17.0f, 12.0f, 4.0f)));
  CHECK(close(scene.materials()[2].reflectance, {0.2f, 0.3f, 0.4f}));
  CHECK(close(scene.materials()[3].reflectance, Rgb(0.75f * 0.8f)));  // the mirror has no diffuse part
  const rad::Material defaults;
  CHECK(close(scene.materials()[4].reflectance, defaults.reflectance));
  CHECK(scene.materials()[4].ior == defaults.ior);
}

TEST_CASE("JSON primitives - camera and an OBJ include build the expected polygons") {
  const std::string doc = R"({
    "version": 1,
    "camera": {"eye": [0, 1, -5], "look_at": [0, 1, 0], "fov_deg": 50},
    "materials": [{"name": "grey", "reflectance": 0.5}],
    "surfaces": [
      {"type": "polygon", "vertices": [[0,0,0], [0,0,1], [1,0,1], [1,0,0]], "material": "grey", "group": "tile"},
      {"type": "quad", "origin": [0,0,2], "edge_u": [2,0,0], "edge_v": [0,3,0], "material": "grey", "group": "wall"},
      {"type": "box", "lower": [0,0,0], "upper": [1,2,3], "material": "grey", "group": "box",
       "transform": {"scale": 2, "rotate_deg": [0, 30, 0], "translate": [5, 0, 0]}},
      {"type": "sphere", "centre": [0,3,0], "radius": 0.5, "segments": 8, "material": "grey", "group": "ball"},
      {"type": "obj", "file": "two_quads.obj", "comment": "brings its own materials and groups"}
    ]})";
  const rad::Scene scene = rad::parse_scene_json(doc, kData);
  auto group_area = [&](const char* name) {
    const auto g = scene.find_group(name);
    REQUIRE(g.has_value());
    double a = 0.0;
    for (const rad::Polygon& p : scene.polygons())
      if (p.group == *g) a += p.area;
    return a;
  };
  CHECK(group_area("tile") == doctest::Approx(1.0).epsilon(1e-6));
  CHECK(group_area("floor") == doctest::Approx(1.0).epsilon(1e-6));  // the OBJ's g floor
  CHECK(group_area("wall") == doctest::Approx(6.0).epsilon(1e-6));
  // Scaled by 2: a 2 x 4 x 6 box (rotation and translation keep areas).
  CHECK(group_area("box") == doctest::Approx(2.0 * (8.0 + 24.0 + 12.0)).epsilon(1e-5));
  CHECK(group_area("ball") < 4.0 * kPi * 0.25);
  CHECK(group_area("ball") > 0.85 * 4.0 * kPi * 0.25);
  // The floor polygon faces up (counter-clockwise seen from +y); the quad faces edge_u x edge_v = +z.
  CHECK(scene.polygons()[0].normal.y == doctest::Approx(1.0f));
  CHECK(scene.polygons()[1].normal.z == doctest::Approx(1.0f));
  // The OBJ's groups and its emitter came along (E = pi Ke).
  CHECK(group_area("light") == doctest::Approx(1.0).epsilon(1e-6));
  const rad::Material& lamp = scene.material(scene.polygons().back().material);
  CHECK(close(lamp.emission, static_cast<float>(kPi) * Rgb(17.0f, 12.0f, 4.0f)));
  REQUIRE(scene.has_camera());
  CHECK(scene.camera().fov_deg == 50.0f);
  CHECK(scene.camera().up == glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST_CASE("JSON bad values name the document path of the value") {
  const std::string m0 = R"({"name": "m0"}, {"name": "m1"}, )";
  check_error(with_materials(m0 + R"({"name": "w", "brdf": {"type": "ward", "specular": 0.2, "alpha_x": -0.1, "alpha_y": 0.1}})"),
              ErrorCode::invalid_scene, "scene.json: materials[2].brdf.alpha_x: must be > 0 (got -0.1)");
  check_error(with_materials(R"({"name": "m0", "reflectance": [0.5, 1.0, 0.5]})"), ErrorCode::invalid_scene,
              "materials[0].reflectance: each channel must be in [0, 1)", {}, /*strict=*/true);
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "phong", "diffuse": 0.6, "specular": 0.5, "exponent": 10}})"),
              ErrorCode::invalid_scene, "materials[0].brdf: diffuse + specular must be <= 1");
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "mix", "weight": 1.5,
              "first": {"type": "mirror", "reflectance": 1}, "second": {"type": "dielectric", "eta": 0}}})"),
              ErrorCode::invalid_scene, "materials[0].brdf.second.eta: must be > 0");
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "lambertian", "reflectance": 1}})"),
              ErrorCode::invalid_scene, "materials[0].brdf: its diffuse part");
  check_error(with_materials(R"({"name": "m0", "reflectance": 0.6, "specular": 0.5})"), ErrorCode::invalid_scene,
              "materials[0]: reflectance + specular + diffuse_transmittance must be < 1", {}, /*strict=*/true);
  check_error(with_materials(R"({"name": "m0", "emission": [1, -1, 0]})"), ErrorCode::invalid_scene,
              "materials[0].emission: each channel must be >= 0 (got [1, -1, 0])");
  check_error(with_materials(R"({"name": "m0", "reflectance": 1e300})"), ErrorCode::invalid_scene,
              "materials[0].reflectance: must be a finite number within float range");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "sphere", "centre": [0,0,0], "radius": 1, "segments": 3, "material": "m0"}]})",
              ErrorCode::invalid_scene, "surfaces[0].segments: must be in [4, 1024] (got 3)");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "box", "lower": [0,0,0], "upper": [1,0,1], "material": "m0"}]})",
              ErrorCode::invalid_scene, "surfaces[0].upper: must be above lower");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "polygon", "vertices": [[0,0,0], [1,0,0], [2,0,0]], "material": "m0"}]})",
              ErrorCode::invalid_scene, "surfaces[0]: polygon 0 (group 'default'): degenerate", {}, /*strict=*/true);
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "camera": {"eye": [0,0,0], "look_at": [0,0,0]},
                 "surfaces": [{"type": "quad", "origin": [0,0,0], "edge_u": [1,0,0], "edge_v": [0,1,0], "material": "m0"}]})",
              ErrorCode::invalid_scene, "scene.json: camera: ");
}

TEST_CASE("JSON unknown keys - wrong types - missing fields and unknown names are errors") {
  // A misspelt key must not fall back to a default silently.
  check_error(with_materials(R"({"name": "m0", "reflectence": 0.3})"), ErrorCode::parse_error,
              "scene.json: materials[0].reflectence: unknown key (expected one of: name, emission");
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "ward", "specular": 0.2, "alpah_x": 0.1, "alpha_y": 0.1}})"),
              ErrorCode::parse_error, "materials[0].brdf.alpah_x: unknown key");
  check_error(R"({"version": 1, "surfaces": [], "light": []})", ErrorCode::parse_error, "scene.json: light: unknown key");
  check_error(with_materials(R"({"name": "m0", "reflectance": "red"})"), ErrorCode::parse_error,
              "materials[0].reflectance: expected a number or an array of 3 numbers, got string");
  check_error(with_materials(R"({"name": "m0", "two_sided": 1})"), ErrorCode::parse_error,
              "materials[0].two_sided: expected true or false, got number");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "sphere", "centre": [0,0,0], "radius": 1, "segments": 8.5, "material": "m0"}]})",
              ErrorCode::parse_error, "surfaces[0].segments: expected an integer");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "polygon", "vertices": [[0,0,0], [1,0], [0,1,0]], "material": "m0"}]})",
              ErrorCode::parse_error, "surfaces[0].vertices[1]: expected an array of 3 numbers");
  check_error(R"({"version": 1, "materials": [{"name": "m0"}], "surfaces": [
                 {"type": "sphere", "centre": [0,0,0], "material": "m0"}]})",
              ErrorCode::parse_error, "scene.json: surfaces[0].radius: missing (required)");
  check_error(R"({"surfaces": []})", ErrorCode::parse_error, "scene.json: version: missing");
  check_error(R"({"version": 2, "surfaces": []})", ErrorCode::parse_error, "version: unsupported format version 2");
  check_error(with_materials(R"({"reflectance": 0.3})"), ErrorCode::parse_error, "materials[0].name: missing");
  check_error(with_materials(R"({"name": "m0"}, {"name": "m1", "reflectance": 0.2, "reflectance": 0.3})"),
              ErrorCode::parse_error, "scene.json: materials[1].reflectance: duplicate key");
  check_error(R"({"version": 1, "surfaces": [{"type": "quad"}, {"type": "box", "lower": [0,0,0], "lower": [1,1,1]}]})",
              ErrorCode::parse_error, "scene.json: surfaces[1].lower: duplicate key");
  check_error(with_materials(R"({"name": "m0"}, {"name": "m0"})"), ErrorCode::parse_error,
              "materials[1].name: duplicate material name 'm0'");
  check_error(R"({"version": 1, "materials": [{"name": "white"}, {"name": "red"}], "surfaces": [
                 {"type": "quad", "origin": [0,0,0], "edge_u": [1,0,0], "edge_v": [0,1,0], "material": "white"},
                 {"type": "quad", "origin": [0,0,0], "edge_u": [1,0,0], "edge_v": [0,1,0], "material": "whte"}]})",
              ErrorCode::parse_error, "surfaces[1].material: unknown material 'whte' (defined: white, red)");
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "oren_nayar"}})"), ErrorCode::parse_error,
              "materials[0].brdf.type: unknown model 'oren_nayar'");
  check_error(with_materials(R"({"name": "m0", "brdf": {"reflectance": 0.5}})"), ErrorCode::parse_error,
              "materials[0].brdf.type: missing");
  check_error(R"({"version": 1, "surfaces": [{"type": "cylinder"}]})", ErrorCode::parse_error,
              "surfaces[0].type: unknown surface type 'cylinder'");
  check_error(R"({"version": 1, "surfaces": [{"type": "obj", "file": "no_such.obj"}]})", ErrorCode::file_not_found,
              "scene.json: surfaces[0].file: ", kTmp);
  check_error(with_materials(R"({"name": "m0", "brdf": {"type": "measured", "file": "no_such.binary"}})"),
              ErrorCode::file_not_found, "no_such.binary", kTmp);
  check_error(R"([1, 2])", ErrorCode::parse_error, "scene.json: top level: expected an object, got array");
  check_error(R"({"version": 1, "surfaces": []})", ErrorCode::invalid_scene, "surfaces: the scene has no polygons");
}

TEST_CASE("JSON syntax errors give the line and column of the offending character") {
  const std::string doc = "{\n  \"version\": 1,\n  \"surfaces\": [ ,\n  ]\n}\n";
  // The stray comma: line 3, column 17 (1-based), found independently of the parser.
  const std::size_t comma = doc.find(',', doc.find("surfaces"));
  const std::size_t line_start = doc.rfind('\n', comma) + 1;
  const std::string where = "scene.json:3:" + std::to_string(comma - line_start + 1) + ": JSON syntax error";
  CHECK(where == "scene.json:3:17: JSON syntax error");
  check_error(doc, ErrorCode::parse_error, where);
  check_error("{\"version\": 1,\n \"surfaces\": [\n", ErrorCode::parse_error, "scene.json:3:1: JSON syntax error");
}

TEST_CASE("JSON scenes forgive a reflectance of 1 and degenerate polygons with warnings - errors under strict") {
  const std::string doc = R"({"version": 1,
    "materials": [{"name": "m0", "reflectance": 1}, {"name": "m1", "reflectance": 0.9, "specular": 0.3}],
    "surfaces": [{"type": "quad", "origin": [0,0,0], "edge_u": [0,0,1], "edge_v": [1,0,0], "material": "m0"},
                 {"type": "polygon", "vertices": [[0,1,0], [1,1,0], [2,1,0]], "material": "m1"},
                 {"type": "polygon", "vertices": [[0,2,0], [1,2,0], [1,2,1]], "material": "m1"}]})";
  const rad::Scene scene = rad::parse_scene_json(doc, {}, "scene.json");
  CHECK(scene.polygons().size() == 2);  // the collinear triangle is dropped
  CHECK(scene.materials()[0].reflectance.x == doctest::Approx(0.99f));
  const rad::Material& m1 = scene.materials()[1];
  CHECK((m1.reflectance + m1.specular).x == doctest::Approx(0.99f));
  REQUIRE(scene.warnings().size() == 3);
  CHECK(contains(scene.warnings()[0], "scene.json: materials[0].reflectance: each channel must be in [0, 1)"));
  CHECK(contains(scene.warnings()[0], "clamped"));
  CHECK(contains(scene.warnings()[1], "scene.json: materials[1]: reflectance + specular"));
  CHECK(contains(scene.warnings()[2], "scene.json: surfaces[1]:"));
  CHECK(contains(scene.warnings()[2], "dropped"));
  check_error(doc, ErrorCode::invalid_scene, "materials[0].reflectance", {}, /*strict=*/true);
}

TEST_CASE("a number too large for the JSON library is a radiosity::Error, not the library's exception") {
  check_error(R"({"version": 1, "surfaces": [{"type": "sphere", "centre": [0, 0, 1e999], "radius": 1}]})",
              ErrorCode::parse_error, "scene.json");
}

TEST_CASE("load_scene reads .json files and names the file in errors") {
  fs::create_directories(kTmp);
  const fs::path bad = kTmp / "bad_scene.json";
  std::ofstream(bad) << R"({"version": 1, "materials": [{"name": "m0", "reflectance": -1}], "surfaces": []})";
  try {
    rad::load_scene(bad);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(contains(e.what(), bad.string() + ": materials[0].reflectance: each channel must be in [0, 1)"));
  }
  CHECK_THROWS_WITH_AS(rad::load_scene(kTmp / "missing.json"), doctest::Contains("missing.json"), Error);
  const rad::Scene scene = rad::load_scene(kScenes / "cornell_box.json");
  CHECK(scene.groups().size() == 8);
}

TEST_CASE("the complete example of docs/SCENE_JSON.md loads") {
  std::ifstream in(kData / ".." / ".." / "docs" / "SCENE_JSON.md");
  REQUIRE(in.good());
  std::stringstream md;
  md << in.rdbuf();
  const std::string text = md.str();
  const std::size_t start = text.find("```json\n");
  REQUIRE(start != std::string::npos);
  const std::size_t end = text.find("```\n", start + 8);
  REQUIRE(end != std::string::npos);
  // Its OBJ include, chair.obj, stands for any OBJ next to the file: use a fixture.
  const fs::path dir = kTmp / "scene_json_doc";
  fs::create_directories(dir);
  fs::copy_file(kData / "two_quads.obj", dir / "chair.obj", fs::copy_options::overwrite_existing);
  fs::copy_file(kData / "two_quads.mtl", dir / "two_quads.mtl", fs::copy_options::overwrite_existing);
  const rad::Scene scene = rad::parse_scene_json(text.substr(start + 8, end - start - 8), dir, "SCENE_JSON.md");
  CHECK(scene.materials().size() == 5 + 2);
  for (const char* g : {"floor", "ceiling", "back", "light", "box", "ball", "plate"}) CHECK(scene.find_group(g).has_value());
  CHECK(scene.lights().size() == 1);
  CHECK(scene.warnings().empty());
}

TEST_CASE("the JSON Cornell box solves to the built-in Cornell box's group radiosities within 0.5%") {
  const rad::Scene json = rad::load_scene(kScenes / "cornell_box.json");
  const rad::Scene builtin = rad::cornell_box();
  REQUIRE(json.polygons().size() == builtin.polygons().size());
  CHECK(json.total_area() == doctest::Approx(builtin.total_area()).epsilon(1e-6));
  CHECK(json.warnings().size() == builtin.warnings().size());  // the red wall is triangulated in both
  CHECK(json.camera().fov_deg == builtin.camera().fov_deg);

  rad::SolveOptions o;
  o.mesh.max_patch_area = 12000.0f;
  o.mesh.max_element_area = 6000.0f;
  o.form_factors.method = rad::FormFactorMethod::analytic;  // no visibility rays: fast, deterministic
  o.method = rad::SolverMethod::gauss_seidel;
  o.tolerance = 1e-4;
  const rad::Solution a = rad::solve(json, o), b = rad::solve(builtin, o);
  REQUIRE(a.status() == rad::SolveStatus::converged);
  REQUIRE(b.status() == rad::SolveStatus::converged);
  for (const std::string& g : builtin.groups()) {
    CAPTURE(g);
    const Rgb x = a.group_radiosity(g), y = b.group_radiosity(g);
    for (int k = 0; k < 3; ++k) CHECK(x[k] == doctest::Approx(y[k]).epsilon(5e-3));
  }
}

}  // TEST_SUITE("io")

namespace {

/// A scene document with the given lights array and one floor quad.
std::string with_lights(const std::string& lights) {
  return R"({"version": 1, "materials": [{"name": "m0"}], "lights": [)" + lights +
         R"(], "surfaces": [{"type": "quad", "origin": [0,0,0], "edge_u": [0,0,1], "edge_v": [1,0,0], "material": "m0"}]})";
}

}  // namespace

TEST_CASE("JSON lights of every type are read with their units - and as candela and lux under photometric") {
  const std::string doc = with_lights(R"(
    {"type": "point", "name": "bulb", "position": [1, 2, 3], "intensity": 683, "color": [1, 0.5, 0.25], "light_group": "ceiling"},
    {"type": "spot", "position": [0, 3, 0], "direction": [0, -2, 0], "intensity": 10, "inner_cone_deg": 15, "outer_cone_deg": 30},
    {"type": "directional", "name": "sun", "direction": [1, -1, 0], "intensity": 100000},
    {"type": "sky", "intensity": 20000, "model": "cie_overcast", "zenith": [0, 0, 1], "comment": "z up"},
    {"type": "sky", "intensity": 5})");
  const rad::Scene scene = rad::parse_scene_json(doc, {});
  REQUIRE(scene.lights().size() == 5);
  const rad::Light& bulb = scene.lights()[0];
  CHECK(bulb.type == rad::LightType::point);
  CHECK(bulb.name == "bulb");
  CHECK(bulb.light_group == "ceiling");
  CHECK(bulb.intensity == 683.0f);  // W/sr, as written
  CHECK(bulb.color == Rgb(1.0f, 0.5f, 0.25f));
  CHECK(bulb.position == glm::vec3(1, 2, 3));
  const rad::Light& spot = scene.lights()[1];
  CHECK(spot.type == rad::LightType::spot);
  CHECK(spot.direction == glm::vec3(0, -1, 0));  // normalised
  CHECK(spot.inner_cone_deg == 15.0f);
  CHECK(spot.outer_cone_deg == 30.0f);
  CHECK(scene.lights()[2].type == rad::LightType::directional);
  CHECK(scene.lights()[2].direction.x == doctest::Approx(std::sqrt(0.5)));
  CHECK(scene.lights()[3].sky == rad::SkyModel::cie_overcast);
  CHECK(scene.lights()[3].direction == glm::vec3(0, 0, 1));
  CHECK(scene.lights()[4].sky == rad::SkyModel::uniform);
  CHECK(scene.lights()[4].direction == glm::vec3(0, 1, 0));  // the default zenith

  rad::LoadOptions photometric;
  photometric.photometric = true;
  const rad::Scene lux = rad::parse_scene_json(doc, {}, "scene.json", photometric);
  CHECK(lux.lights()[0].intensity == doctest::Approx(1.0f));            // 683 cd
  CHECK(lux.lights()[2].intensity == doctest::Approx(146.413f));        // 100 klx of sun
  CHECK(lux.lights()[3].intensity == doctest::Approx(20000.0f / 683.0f));
}

TEST_CASE("JSON lights with bad values - keys or types are errors naming their place") {
  check_error(with_lights(R"({"type": "point", "intensity": 1})"), ErrorCode::parse_error,
              "scene.json: lights[0].position: missing (required)");
  check_error(with_lights(R"({"type": "point", "position": [0,1,0], "intensity": -1})"), ErrorCode::invalid_scene,
              "lights[0].intensity: must be >= 0");
  check_error(with_lights(R"({"type": "sky", "intensity": 1}, {"type": "directional", "intensity": 1, "position": [0,1,0], "direction": [0,-1,0]})"),
              ErrorCode::parse_error, "lights[1].position: unknown key (expected one of: type, name, light_group, color, intensity, direction)");
  check_error(with_lights(R"({"type": "area", "intensity": 1})"), ErrorCode::parse_error,
              "lights[0].type: unknown light type 'area' (expected point, spot, directional or sky)");
  check_error(with_lights(R"({"type": "sky", "intensity": 1, "model": "clear"})"), ErrorCode::parse_error,
              "lights[0].model: unknown sky model 'clear'");
  check_error(with_lights(R"({"type": "spot", "position": [0,1,0], "direction": [0,-1,0], "intensity": 1, "inner_cone_deg": 40, "outer_cone_deg": 30})"),
              ErrorCode::invalid_scene, "lights[0].inner_cone_deg: cones must satisfy 0 <= inner_cone_deg <= outer_cone_deg <= 90");
  check_error(with_lights(R"({"type": "directional", "direction": [0,0,0], "intensity": 1})"), ErrorCode::invalid_scene,
              "lights[0].direction: must not be [0, 0, 0]");
  check_error(with_lights(R"({"type": "point", "position": [0,1,0], "intensity": 1, "color": [1, -1, 1]})"),
              ErrorCode::invalid_scene, "lights[0].color: each channel must be >= 0");
  check_error(with_lights(R"({"type": "point", "position": [0,1,0], "intensity": 1e39})"), ErrorCode::invalid_scene,
              "lights[0].intensity: must be a finite number within float range");
  check_error(R"({"version": 1, "lights": {}, "materials": [{"name": "m0"}], "surfaces": [{"type": "quad", "origin": [0,0,0], "edge_u": [0,0,1], "edge_v": [1,0,0], "material": "m0"}]})",
              ErrorCode::parse_error, "scene.json: lights: expected an array");
}

TEST_CASE("JSON lights light the scene they are read with") {
  const rad::Scene scene = rad::parse_scene_json(with_lights(R"({"type": "point", "position": [0.5, 1, 0.5], "intensity": 2})"), {});
  const rad::Solution sol = rad::solve(scene);
  CHECK(sol.report().light_power.x > 0.0f);
  // The unit floor under a point light 1 above its centre subtends 4 asin(a^2 / (a^2 + 4 d^2)) =
  // 4 asin(1/5) sr.
  CHECK(sol.report().light_power.x == doctest::Approx(2.0 * 4.0 * std::asin(0.2)).epsilon(1e-5));
}
