// load_scene() on glTF 2.0 files made by the tests (tests/support/gltf_builder.hpp) and on the
// checked-in room of tests/data/gltf: groups from node and mesh names, node transforms (a
// mirroring node keeps its box facing out), the material mapping of docs/SCENE_GLTF.md,
// cameras, a furnace solved end to end; and broken files (truncated or corrupted GLBs,
// references and accessors out of range, missing buffers, NaN values, unsupported required
// extensions), each an Error naming the file and the place, never a crash.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"
#include "radiosity/render.hpp"
#include "radiosity/solver.hpp"
#include "support/gltf_builder.hpp"
#include "support/loading.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using radiosity::Error;
using radiosity::ErrorCode;
using radiosity::Rgb;

const fs::path kData = RADIOSITY_TEST_DATA;
const fs::path kTmp = fs::path(RADIOSITY_TEST_TMP) / "gltf";
constexpr float kPi = 3.14159265358979323846f;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

using test::load;
using test::load_error;
using test::near;

/// Checks the code, and that the message names the file and contains each of `parts`.
void check_error(const fs::path& path, ErrorCode code, const std::vector<std::string>& parts, bool strict = false) {
  const Error e = load_error(path, strict);
  const std::string message = e.what();
  INFO("message: " << message);
  CHECK(e.code() == code);
  CHECK(contains(e.what(), path.string() + (e.code() == ErrorCode::file_not_found ? "" : ":")));
  for (const std::string& part : parts) CHECK(contains(e.what(), part));
}

fs::path write_gltf(const test::GltfBuilder& b, const std::string& name) { return test::write_file(kTmp / name, b.gltf()); }
fs::path write_glb(const test::GltfBuilder& b, const std::string& name) { return test::write_file(kTmp / name, b.glb()); }

/// A material of glTF's metallic-roughness model, non-metallic unless `extra` says otherwise.
json diffuse(Rgb base, json extra = json::object()) {
  json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {base.x, base.y, base.z, 1.0}}, {"metallicFactor", 0.0}}}};
  for (auto& [k, v] : extra.items()) m[k] = v;
  return m;
}

/// The polygons of group `name`.
std::vector<radiosity::Polygon> group_polygons(const radiosity::Scene& s, const std::string& name) {
  std::vector<radiosity::Polygon> out;
  const auto g = s.find_group(name);
  if (!g) return out;
  for (const radiosity::Polygon& p : s.polygons())
    if (p.group == *g) out.push_back(p);
  return out;
}

glm::vec3 centroid(const radiosity::Polygon& p) {
  glm::vec3 c(0.0f);
  for (const glm::vec3& v : p.vertices) c += v;
  return c / static_cast<float>(p.vertices.size());
}

/// PNG bytes of a w x h image of linear colours (write_png encodes them as sRGB).
std::string png_bytes(const std::vector<Rgb>& texels, int w, int h) {
  radiosity::Image image(w, h);
  image.pixels = texels;
  const fs::path path = kTmp / "texture.png";
  fs::create_directories(kTmp);
  radiosity::write_png(image, path);
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A room of test::GltfBuilder: the checked-in tests/data/gltf/room.gltf and room.glb. Walls
/// facing in (floor, ceiling, back, red left and green right wall; the front is open), a light
/// quad under the ceiling (L = 17 x emissiveFactor, KHR_materials_emissive_strength), a block
/// on the floor turned by its node, and a camera in front looking in (down its -Z).
test::GltfBuilder make_room() {
  test::GltfBuilder b;
  auto material = [&](const char* name, Rgb base, json extra = json::object()) {
    json m = diffuse(base, extra);
    m["name"] = name;
    m["pbrMetallicRoughness"]["roughnessFactor"] = 1.0;
    return b.material(m);
  };
  const int white = material("white", Rgb(0.73f, 0.73f, 0.73f));
  const int red = material("red", Rgb(0.63f, 0.065f, 0.05f));
  const int green = material("green", Rgb(0.14f, 0.45f, 0.091f));
  const int light = material("light", Rgb(0.78f, 0.78f, 0.78f),
                             {{"emissiveFactor", {1.0, 0.706, 0.235}},
                              {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 17.0}}}}}});
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  const float W = 4.0f, H = 3.0f, D = 4.0f;
  std::vector<int> roots;
  auto wall = [&](const char* name, glm::vec3 a, glm::vec3 c, glm::vec3 d, glm::vec3 e, int m) {
    roots.push_back(b.node({{"name", name}, {"mesh", b.mesh(b.quad(a, c, d, e, m), name)}}));
  };
  // The floor has lightmap coordinates (TEXCOORD_1) of its own, the rest get them made.
  json floor = b.quad({0, 0, 0}, {0, 0, D}, {W, 0, D}, {W, 0, 0}, white);
  floor["attributes"]["TEXCOORD_1"] = b.vec2s({{0.05f, 0.05f}, {0.05f, 0.95f}, {0.95f, 0.95f}, {0.95f, 0.05f}});
  roots.push_back(b.node({{"name", "floor"}, {"mesh", b.mesh(floor, "floor")}}));
  wall("ceiling", {0, H, 0}, {W, H, 0}, {W, H, D}, {0, H, D}, white);
  wall("back_wall", {0, 0, 0}, {W, 0, 0}, {W, H, 0}, {0, H, 0}, white);
  wall("red_wall", {0, 0, 0}, {0, H, 0}, {0, H, D}, {0, 0, D}, red);
  wall("green_wall", {W, 0, 0}, {W, 0, D}, {W, H, D}, {W, H, 0}, green);
  wall("light", {1.5f, H - 0.01f, 1.5f}, {2.5f, H - 0.01f, 1.5f}, {2.5f, H - 0.01f, 2.5f}, {1.5f, H - 0.01f, 2.5f}, light);
  const float s = std::sin(0.3f), c = std::cos(0.3f);  // 0.6 rad about +Y
  roots.push_back(b.node({{"name", "block"},
                          {"mesh", b.mesh(b.box({-0.6f, 0.0f, -0.6f}, {0.6f, 1.2f, 0.6f}, white), "block")},
                          {"translation", {1.3, 0.0, 1.4}},
                          {"rotation", {0.0, s, 0.0, c}}}));
  b.doc["cameras"] = json::array({{{"type", "perspective"}, {"name", "front"},
                                   {"perspective", {{"yfov", 0.6}, {"znear", 0.1}, {"aspectRatio", 1.0}}}}});
  roots.push_back(b.node({{"name", "camera"}, {"camera", 0}, {"translation", {W / 2, H / 2, D + 5.0f}}}));
  b.scene(roots);
  return b;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("glTF groups are node names - else mesh names - else mesh and its index") {
  test::GltfBuilder b;
  const int quad = b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}), "panel");
  const int unnamed = b.mesh(b.quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}));
  b.scene({b.node({{"name", "floor"}, {"mesh", quad}}), b.node({{"mesh", quad}, {"translation", {0, 0, 5}}}),
           b.node({{"mesh", unnamed}})});
  for (const fs::path& path : {write_gltf(b, "groups.gltf"), write_glb(b, "groups.glb")}) {
    CAPTURE(path);
    const radiosity::Scene s = load(path);
    CHECK(s.warnings().empty());
    REQUIRE(s.groups().size() == 3);
    CHECK(s.groups()[0] == "floor");
    CHECK(s.groups()[1] == "panel");
    CHECK(s.groups()[2] == "mesh1");
    // One scene mesh per placed primitive, two triangles each, and the material-less grey.
    REQUIRE(s.meshes().size() == 3);
    CHECK(s.polygons().size() == 6);
    // Mesh::source: the node that places it and the primitive (what write_baked_gltf() reads).
    CHECK(s.meshes()[0].source == "nodes[0]: meshes[0].primitives[0]");
    CHECK(s.meshes()[1].source == "nodes[1]: meshes[0].primitives[0]");
    CHECK(s.meshes()[2].source == "nodes[2]: meshes[1].primitives[0]");
    CHECK(s.material(s.polygons()[0].material).name == "default");
    CHECK(s.material(s.polygons()[0].material).reflectance == Rgb(0.5f));
  }
}

TEST_CASE("glTF node transforms: a child's translation rotation and scale under its parent's matrix") {
  test::GltfBuilder b;
  const int quad = b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}));
  const float h = std::sqrt(0.5f);  // 90 degrees about +Z
  const int child = b.node({{"name", "moved"}, {"mesh", quad}, {"translation", {0, 2, 0}}, {"rotation", {0, 0, h, h}}, {"scale", {2, 2, 2}}});
  b.scene({b.node({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1}}, {"children", {child}}})});
  const radiosity::Scene s = load(write_gltf(b, "transforms.gltf"));
  REQUIRE(s.meshes().size() == 1);
  const radiosity::Mesh& m = s.meshes()[0];
  // p -> parent (translate 10 x) of child (translate 2 y, turn 90 degrees, scale 2).
  const glm::vec3 expected[] = {{10, 2, 0}, {10, 4, 0}, {8, 4, 0}, {8, 2, 0}};
  for (int v = 0; v < 4; ++v) CHECK(near(m.positions[static_cast<std::size_t>(v)], expected[v], 1e-5f));
  for (const glm::vec3& n : m.normals) CHECK(near(n, {0, 0, 1}));
  REQUIRE(s.polygons().size() == 2);
  CHECK(s.polygons()[0].area + s.polygons()[1].area == doctest::Approx(4.0));
  CHECK(near(s.polygons()[0].normal, {0, 0, 1}));
  CHECK(s.groups()[0] == "moved");
}

TEST_CASE("glTF a mirroring node flips the winding so a box keeps facing out and normals agree") {
  test::GltfBuilder b;
  const int box = b.mesh(b.box({0, 0, 0}, {1, 1, 1}));
  const int quad = b.mesh(b.quad({0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}));  // faces +x
  b.scene({b.node({{"name", "mirrored"}, {"mesh", box}, {"scale", {-1, 1, 1}}, {"translation", {5, 0, 0}}}),
           b.node({{"name", "card"}, {"mesh", quad}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}})});
  const radiosity::Scene s = load(write_gltf(b, "mirror.gltf"));
  const std::vector<radiosity::Polygon> faces = group_polygons(s, "mirrored");
  REQUIRE(faces.size() == 12);
  const glm::vec3 centre(4.5f, 0.5f, 0.5f);
  for (const radiosity::Polygon& f : faces) CHECK(glm::dot(f.normal, centroid(f) - centre) > 0.0f);
  // The card faced +x; mirrored in x it faces -x, by its triangles and by its normals.
  const std::vector<radiosity::Polygon> card = group_polygons(s, "card");
  REQUIRE(card.size() == 2);
  CHECK(near(card[0].normal, {-1, 0, 0}));
  for (const glm::vec3& n : s.meshes()[1].normals) CHECK(near(n, {-1, 0, 0}));
}

TEST_CASE("glTF materials: base colour - metallic-roughness - emission with its strength - two-sided - transmission") {
  test::GltfBuilder b;
  const int paint = b.material(diffuse(Rgb(0.8f, 0.4f, 0.2f), {{"name", "paint"}}));
  const int lamp = b.material(diffuse(Rgb(0.5f), {{"name", "lamp"}, {"emissiveFactor", {1.0, 0.5, 0.25}},
                                                  {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}}));
  const int card = b.material(diffuse(Rgb(0.6f), {{"name", "card"}, {"doubleSided", true}}));
  const int glass = b.material(diffuse(Rgb(0.9f), {{"name", "glass"},
                                                   {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                                                   {"KHR_materials_ior", {{"ior", 1.33}}}}}}));
  json gold_material = {{"name", "gold"},
                        {"pbrMetallicRoughness", {{"baseColorFactor", {0.95, 0.8, 0.3, 1}}, {"metallicFactor", 1.0}, {"roughnessFactor", 0.3}}}};
  const int gold = b.material(gold_material);
  std::vector<int> roots;
  float z = 0.0f;
  for (int m : {paint, lamp, card, glass, gold}) {
    roots.push_back(b.node({{"mesh", b.mesh(b.quad({0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}, m))}}));
    z += 1.0f;
  }
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior"};
  b.scene(roots);
  const fs::path path = write_gltf(b, "materials.gltf");
  const radiosity::Scene s = load(path);
  // The gold is a metal on purpose: a note, not a problem (below).
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], path.string() + ": materials[4] 'gold': metallic 1"));
  auto by_name = [&](const std::string& name) -> const radiosity::Material& {
    for (const radiosity::Material& m : s.materials())
      if (m.name == name) return m;
    FAIL("no material " << name);
    return s.materials()[0];
  };
  const glm::vec3 wo = glm::normalize(glm::vec3(0.3f, 0.1f, 0.9f)), wi = glm::normalize(glm::vec3(-0.5f, 0.2f, 0.7f));

  // A dielectric base: the diffuse part is the base colour, the view pass adds the GGX coat.
  const radiosity::Material& p = by_name("paint");
  CHECK(near(p.reflectance, Rgb(0.8f, 0.4f, 0.2f)));
  CHECK(p.emission == Rgb(0.0f));
  CHECK_FALSE(p.two_sided);
  REQUIRE(p.brdf);
  CHECK(p.brdf->eval(wo, wo).x != doctest::Approx(p.brdf->eval(wo, wi).x));  // not Lambertian

  CHECK(near(by_name("lamp").emission, kPi * 4.0f * Rgb(1.0f, 0.5f, 0.25f), 1e-4f));
  CHECK(by_name("card").two_sided);

  const radiosity::Material& g = by_name("glass");
  CHECK(near(g.transmittance, Rgb(0.9f)));
  CHECK(near(g.reflectance, Rgb(0.0f)));
  CHECK(g.ior == doctest::Approx(1.33f));
  const auto glass_brdf = radiosity::make_brdf(g);
  CHECK(glass_brdf->is_delta());

  // A pure metal is the GGX microfacet model itself: F0 the base colour, alpha = roughness^2.
  const radiosity::Material& au = by_name("gold");
  CHECK(au.reflectance == Rgb(0.0f));
  REQUIRE(au.brdf);
  const auto ggx = radiosity::make_microfacet(Rgb(0.95f, 0.8f, 0.3f), 0.09f, 0.09f);
  for (int c = 0; c < 3; ++c) CHECK(au.brdf->eval(wo, wi)[c] == doctest::Approx(ggx->eval(wo, wi)[c]));
}

TEST_CASE("glTF a material that is all metal (metallicFactor absent) gets one note naming it - kept under strict") {
  test::GltfBuilder b;
  // The spec's defaults: metallicFactor 1, so base colour alone is a rough metal.
  const int wall = b.material({{"name", "Wall"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}}}}});
  const int floor = b.material({{"name", "Floor"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.4, 0.3, 1.0}}}}});
  const int paint = b.material(diffuse(Rgb(0.8f, 0.8f, 0.8f), {{"name", "Paint"}}));
  b.material({{"name", "Unused"}});  // a metal that no mesh uses: no note
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, wall))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, floor))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}, wall))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 3}, {1, 0, 3}, {1, 1, 3}, {0, 1, 3}, paint))}})});
  const fs::path path = write_gltf(b, "metal.gltf");
  for (const bool strict : {false, true}) {
    CAPTURE(strict);
    const radiosity::Scene s = load(path, strict);
    REQUIRE(s.warnings().size() == 1);
    const std::string& w = s.warnings()[0];
    INFO(w);
    CHECK(w == path.string() + ": materials[0] 'Wall': metallic 1 (glTF's default when metallicFactor is absent): a metal has "
                               "no diffuse reflectance, so radiosity passes no light on from it; set metallicFactor 0 for a "
                               "diffuse surface (2 in all; also at " + path.string() + ": materials[1] 'Floor')");
    for (const radiosity::Material& m : s.materials())
      CHECK(m.reflectance == (m.name == "Paint" ? Rgb(0.8f) : Rgb(0.0f)));
  }
}

TEST_CASE("glTF metallicFactor 0 or 0.5 leaves a diffuse part and no note") {
  test::GltfBuilder b;
  const int dielectric = b.material(diffuse(Rgb(0.5f), {{"name", "plastic"}}));
  const int half_metal = b.material({{"name", "half"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}, {"metallicFactor", 0.5}}}});
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, dielectric))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, half_metal))}})});
  const radiosity::Scene s = load(write_gltf(b, "not_metal.gltf"), true);
  CHECK(s.warnings().empty());
  for (const radiosity::Material& m : s.materials()) CHECK(m.reflectance.x > 0.0f);
}

TEST_CASE("glTF a base colour of 1 is clamped with one warning - and is an error under strict") {
  test::GltfBuilder b;
  const int white = b.material({{"name", "white"}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});  // base colour 1 by default
  const int brighter = b.material(diffuse(Rgb(1.2f, 0.5f, 0.5f), {{"name", "brighter"}}));
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, white))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, brighter))}})});
  const fs::path path = write_gltf(b, "clamp.gltf");
  const radiosity::Scene s = load(path);
  REQUIRE(s.warnings().size() == 1);
  const std::string& w = s.warnings()[0];
  INFO(w);
  CHECK(contains(w, path.string() + ": materials[0]: base colour (1, 1, 1) is a diffuse reflectance"));
  CHECK(contains(w, "clamped to (0.99, 0.99, 0.99)"));
  CHECK(contains(w, "(2 in all; also at " + path.string() + ": materials[1])"));
  for (const radiosity::Material& m : s.materials()) CHECK(std::max({m.reflectance.x, m.reflectance.y, m.reflectance.z}) < 0.99f);
  check_error(path, ErrorCode::invalid_scene, {"materials[0]: base colour (1, 1, 1)"}, true);
}

TEST_CASE("glTF a base colour texture multiplies the factor by its mean - an unreadable one warns") {
  test::GltfBuilder b;
  const std::vector<Rgb> texels = {Rgb(0.2f, 0.4f, 0.6f), Rgb(0.6f, 0.4f, 0.2f), Rgb(0.1f, 0.1f, 0.1f), Rgb(0.5f, 0.7f, 0.9f)};
  const std::string png = png_bytes(texels, 2, 2);
  const std::string garbage = "not an image at all";
  b.doc["images"] = json::array({{{"bufferView", b.view(png.data(), png.size())}, {"mimeType", "image/png"}},
                                 {{"bufferView", b.view(garbage.data(), garbage.size())}, {"mimeType", "image/png"}},
                                 {{"uri", "missing.png"}}});
  b.doc["textures"] = json::array({{{"source", 0}}, {{"source", 1}}, {{"source", 2}}});
  auto textured = [&](const char* name, int texture) {
    json m = diffuse(Rgb(0.5f, 1.0f, 0.5f), {{"name", name}});
    m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", texture}};
    return b.material(m);
  };
  const int good = textured("good", 0), broken = textured("broken", 1), missing = textured("missing", 2);
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, good))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, broken))}}),
           b.node({{"mesh", b.mesh(b.quad({0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}, missing))}})});
  for (const fs::path& path : {write_gltf(b, "texture.gltf"), write_glb(b, "texture.glb")}) {
    CAPTURE(path);
    const radiosity::Scene s = load(path);
    const Rgb mean = (texels[0] + texels[1] + texels[2] + texels[3]) / 4.0f;
    const Rgb expected = Rgb(0.5f, 1.0f, 0.5f) * mean;
    const radiosity::Material& m = s.material(s.polygons()[0].material);
    CHECK(m.name == "good");
    for (int c = 0; c < 3; ++c) CHECK(m.reflectance[c] == doctest::Approx(expected[c]).epsilon(0.02));
    // The two others keep their factor (then clamped below 1, which warns too).
    REQUIRE(s.warnings().size() == 2);
    INFO(s.warnings()[0]);
    CHECK(contains(s.warnings()[0], path.string() + ": materials[1].pbrMetallicRoughness.baseColorTexture: texture 1: image 1"));
    CHECK(contains(s.warnings()[0], "cannot decode"));
    CHECK(contains(s.warnings()[0], "its factor alone is used (2 in all; also at " + path.string() + ": materials[2]"));
    check_error(path, ErrorCode::file_not_found, {"materials[1].pbrMetallicRoughness.baseColorTexture: texture 1"}, true);
  }
}

TEST_CASE("glTF cameras: the scene's first perspective camera is the scene camera - others are ignored with a warning") {
  test::GltfBuilder b;
  b.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}},
                                  {{"type", "perspective"}, {"name", "spare"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}},
                                  {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}});
  const float h = std::sqrt(0.5f);  // 90 degrees about +Y: -Z turns to -X
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}}),
           b.node({{"camera", 0}, {"translation", {0, 1, 5}}, {"rotation", {0, h, 0, h}}}),
           b.node({{"camera", 1}}), b.node({{"camera", 2}})});
  const fs::path path = write_gltf(b, "cameras.gltf");
  const radiosity::Scene s = load(path);
  REQUIRE(s.has_camera());
  const radiosity::Camera c = s.camera();
  CHECK(near(c.eye, {0, 1, 5}));
  CHECK(near(glm::normalize(c.look_at - c.eye), {-1, 0, 0}));
  CHECK(near(c.up, {0, 1, 0}));
  CHECK(c.fov_deg == doctest::Approx(0.8 * 180.0 / 3.14159265358979));
  REQUIRE(s.warnings().size() == 2);
  CHECK(contains(s.warnings()[0], path.string() + ": nodes[2]: camera 1 'spare': only the scene's first perspective camera is used; ignored"));
  CHECK(contains(s.warnings()[1], path.string() + ": nodes[3]: camera 2 is orthographic"));
  check_error(path, ErrorCode::invalid_scene, {"nodes[2]: camera 1 'spare'"}, true);
}

TEST_CASE("glTF KHR_lights_punctual: point - spot and directional lights at their nodes - photometric - range and unknown types warn") {
  test::GltfBuilder b;
  b.doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
  b.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights", json::array({{{"type", "point"}, {"name", "bulb"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 683.0}},
                                                   {{"type", "spot"}, {"intensity", 10.0}, {"range", 5.0},
                                                    {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}},
                                                   {{"type", "directional"}, {"intensity", 3.0}},
                                                   {{"type", "area"}, {"intensity", 1.0}}})}}}};
  const float h = std::sqrt(0.5f);  // -90 degrees about X: -Z turns to -Y (down)
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}}),
           b.node({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}),
           b.node({{"translation", {0, 4, 0}}, {"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}),
           b.node({{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}}),
           b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 3}}}}}})});
  const fs::path path = write_gltf(b, "lights.gltf");
  const radiosity::Scene s = load(path);
  REQUIRE(s.lights().size() == 3);
  using radiosity::LightType;
  // Radiometric: W/sr as written.
  test::check_light(s.lights()[0], test::light_of(LightType::point, "bulb", {1, 2, 3}, {}, Rgb(1.0f, 0.5f, 0.25f), 683.0f));
  test::check_light(s.lights()[1], test::light_of(LightType::spot, "light 1", {0, 4, 0}, {0, -1, 0}, Rgb(1.0f), 10.0f,
                                                  0.1f * 180.0f / kPi, 0.5f * 180.0f / kPi));
  test::check_light(s.lights()[2], test::light_of(LightType::directional, "light 2", {}, {0, -1, 0}, Rgb(1.0f), 3.0f));
  REQUIRE(s.warnings().size() == 2);
  CHECK(contains(s.warnings()[0], "extensions.KHR_lights_punctual.lights[1]: range 5"));
  CHECK(contains(s.warnings()[1], "lights[3]: type 'area' is not point, spot or directional; skipped"));
  check_error(path, ErrorCode::invalid_scene, {"lights[1]: range"}, true);

  // Photometric: candela and lux at 683 lm/W.
  radiosity::LoadOptions photometric;
  photometric.photometric = true;
  const radiosity::Scene p = radiosity::load_scene(path, photometric);
  CHECK(p.lights()[0].intensity == doctest::Approx(1.0));

  // A light index out of range names the node.
  b.doc["nodes"][1]["extensions"]["KHR_lights_punctual"]["light"] = 9;
  check_error(write_gltf(b, "lights_bad.gltf"), ErrorCode::parse_error, {"nodes[1].extensions.KHR_lights_punctual.light", "not an index"});
}

TEST_CASE("glTF a file that requires KHR_lights_punctual loads with its lights") {
  test::GltfBuilder b;
  b.doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
  b.doc["extensionsRequired"] = json::array({"KHR_lights_punctual"});
  b.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({{{"type", "point"}, {"intensity", 2.0}}})}}}};
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, b.material(diffuse(Rgb(0.5f)))))}}),
           b.node({{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
  const radiosity::Scene s = load(write_glb(b, "lights_required.glb"), true);
  CHECK(s.warnings().empty());
  REQUIRE(s.lights().size() == 1);
  CHECK(s.lights()[0].name == "light 0");
  CHECK(near(s.lights()[0].position, {0, 0, 2}));
  CHECK(s.lights()[0].intensity == doctest::Approx(2.0));
}

TEST_CASE("glTF furnace: a closed inward box of emission E and reflectance rho solves to B = E/(1-rho) within 0.5 %") {
  test::GltfBuilder b;
  const Rgb base(0.5f, 0.6f, 0.3f), emissive(0.2f, 0.4f, 0.1f);
  const float strength = 2.0f;
  const int furnace = b.material(diffuse(base, {{"name", "furnace"}, {"emissiveFactor", {emissive.x, emissive.y, emissive.z}},
                                                {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", strength}}}}}}));
  // Placed by a scaling, turning and moving node, so that the node path is part of the test.
  b.scene({b.node({{"name", "furnace"}, {"mesh", b.mesh(b.box({0, 0, 0}, {1, 1, 1}, furnace, true))},
                   {"translation", {3, -1, 2}}, {"rotation", {0.2, 0.3, 0.1, 0.927}}, {"scale", {2, 2, 2}}})});
  const radiosity::Scene scene = load(write_glb(b, "furnace.glb"));
  CHECK(scene.warnings().empty());
  const radiosity::Material& m = scene.material(scene.polygons()[0].material);
  CHECK(near(m.reflectance, base));
  const Rgb E = kPi * strength * emissive;
  CHECK(near(m.emission, E, 1e-5f));
  radiosity::SolveOptions o;
  o.form_factors.method = radiosity::FormFactorMethod::ray_cast;
  o.mesh.max_patch_area = 0.25f;
  o.tolerance = 1e-6;
  const radiosity::Solution sol = radiosity::solve(scene, o);
  const Rgb B = E / (Rgb(1.0f) - base);
  for (std::uint32_t e : sol.hierarchy().leaves())
    for (int c = 0; c < 3; ++c) CHECK(sol.radiosity()[e][c] == doctest::Approx(B[c]).epsilon(5e-3));
}

TEST_CASE("glTF external buffers - data URIs and GLB read the same scene") {
  test::GltfBuilder b = make_room();
  const fs::path embedded = write_gltf(b, "same.gltf"), binary = write_glb(b, "same.glb");
  test::write_file(kTmp / "external" / "room data.bin", b.bin);
  const fs::path external = test::write_file(kTmp / "external" / "same.gltf", b.gltf("room%20data.bin"));
  const radiosity::Scene a = load(embedded), c = load(binary), d = load(external);
  REQUIRE(a.polygons().size() == c.polygons().size());
  REQUIRE(a.polygons().size() == d.polygons().size());
  for (std::size_t i = 0; i < a.polygons().size(); ++i) {
    CHECK(a.polygons()[i].vertices == c.polygons()[i].vertices);
    CHECK(a.polygons()[i].vertices == d.polygons()[i].vertices);
  }
  CHECK(a.groups() == d.groups());
}

TEST_CASE("glTF strips and fans become triangles - points and lines are skipped with one warning") {
  test::GltfBuilder b;
  const int strip_positions = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
  const int fan_positions = b.positions({{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}});
  const int strip = b.mesh(json{{"attributes", {{"POSITION", strip_positions}}}, {"mode", 5}}, "strip");
  const int fan = b.mesh(json{{"attributes", {{"POSITION", fan_positions}}}, {"mode", 6}, {"indices", b.indices({0, 1, 2, 3})}}, "fan");
  const int points = b.mesh(json{{"attributes", {{"POSITION", fan_positions}}}, {"mode", 0}}, "points");
  const int lines = b.mesh(json{{"attributes", {{"POSITION", fan_positions}}}, {"mode", 1}}, "lines");
  b.scene({b.node({{"mesh", strip}}), b.node({{"mesh", fan}}), b.node({{"mesh", points}}), b.node({{"mesh", lines}})});
  const fs::path path = write_gltf(b, "modes.gltf");
  const radiosity::Scene s = load(path);
  REQUIRE(s.polygons().size() == 4);
  for (const radiosity::Polygon& p : s.polygons()) CHECK(near(p.normal, {0, 0, 1}));
  CHECK(s.polygons()[0].area + s.polygons()[1].area == doctest::Approx(1.0));
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], path.string() + ": meshes[2].primitives[0]: mode POINTS has no area; skipped (2 in all; also at " +
                                      path.string() + ": meshes[3].primitives[0])"));
  check_error(path, ErrorCode::parse_error, {"meshes[2].primitives[0]: mode POINTS"}, true);
}

TEST_CASE("glTF sparse accessors - quantized positions and interleaved attributes are read") {
  test::GltfBuilder b;
  // A quad whose third corner is stored as zero and replaced by sparse storage.
  const std::vector<glm::vec3> stored = {{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}};
  const glm::vec3 replaced(1, 1, 0);
  const std::uint32_t sparse_index = 2;
  const int sparse_positions = b.accessor(b.view(stored.data(), sizeof(glm::vec3) * 4), 5126, 4, "VEC3",
                                          {{"sparse", {{"count", 1},
                                                       {"indices", {{"bufferView", b.view(&sparse_index, 4)}, {"componentType", 5125}}},
                                                       {"values", {{"bufferView", b.view(&replaced, 12)}}}}}});
  const int sparse = b.mesh(json{{"attributes", {{"POSITION", sparse_positions}}}, {"indices", b.indices({0, 1, 2, 0, 2, 3})}});
  // KHR_mesh_quantization: positions as normalized shorts (32767 is 1), interleaved with
  // TEXCOORD_0 as normalized unsigned bytes in one bufferView of stride 12.
  struct Vertex {
    std::int16_t p[3];
    std::uint16_t pad;
    std::uint8_t uv[2];
    std::uint8_t pad2[2];
  };
  const Vertex vertices[4] = {{{0, 0, 0}, 0, {0, 0}, {0, 0}}, {{32767, 0, 0}, 0, {255, 0}, {0, 0}},
                              {{32767, 32767, 0}, 0, {255, 255}, {0, 0}}, {{0, 32767, 0}, 0, {0, 255}, {0, 0}}};
  const int interleaved = b.view(vertices, sizeof vertices, sizeof(Vertex));
  const int quantized_positions = b.accessor(interleaved, 5122, 4, "VEC3", {{"normalized", true}});
  const int quantized_uv = b.accessor(interleaved, 5121, 4, "VEC2", {{"normalized", true}, {"byteOffset", 8}});
  const int quantized = b.mesh(json{{"attributes", {{"POSITION", quantized_positions}, {"TEXCOORD_0", quantized_uv}}},
                                    {"indices", b.indices({0, 1, 2, 0, 2, 3})}});
  b.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  b.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  b.scene({b.node({{"name", "sparse"}, {"mesh", sparse}}), b.node({{"name", "quantized"}, {"mesh", quantized}, {"translation", {0, 0, 1}}})});
  const radiosity::Scene s = load(write_glb(b, "sparse.glb"));
  CHECK(s.warnings().empty());
  REQUIRE(s.meshes().size() == 2);
  CHECK(near(s.meshes()[0].positions[2], replaced));
  CHECK(group_polygons(s, "sparse").size() == 2);
  CHECK(near(s.meshes()[1].positions[2], {1, 1, 1}));
  REQUIRE(s.meshes()[1].uv0.size() == 4);
  CHECK(s.meshes()[1].uv0[2] == glm::vec2(1.0f, 1.0f));
  CHECK(group_polygons(s, "quantized").size() == 2);
}

TEST_CASE("glTF the checked-in room is what the generator makes and reads as a Cornell-like room") {
  const test::GltfBuilder b = make_room();
  const fs::path gltf = kData / "gltf" / "room.gltf", glb = kData / "gltf" / "room.glb", broken = kData / "gltf" / "broken.glb";
  const std::string glb_bytes = b.glb();
  const std::string broken_bytes = glb_bytes.substr(0, glb_bytes.size() / 2);
  // RADIOSITY_REGENERATE=1 rewrites the files (after a deliberate change of make_room()).
  if (const char* regenerate = std::getenv("RADIOSITY_REGENERATE"); regenerate && std::string(regenerate) == "1") {
    test::write_file(gltf, b.gltf());
    test::write_file(glb, glb_bytes);
    test::write_file(broken, broken_bytes);
  }
  CHECK(read_bytes(gltf) == b.gltf());
  CHECK(read_bytes(glb) == glb_bytes);
  CHECK(read_bytes(broken) == broken_bytes);

  const radiosity::Scene s = load(gltf, true);
  CHECK(s.warnings().empty());
  CHECK(s.groups() == std::vector<std::string>{"floor", "ceiling", "back_wall", "red_wall", "green_wall", "light", "block"});
  const std::vector<radiosity::Polygon> light = group_polygons(s, "light");
  REQUIRE(light.size() == 2);
  CHECK(near(light[0].normal, {0, -1, 0}));
  CHECK(near(s.material(light[0].material).emission, kPi * 17.0f * Rgb(1.0f, 0.706f, 0.235f), 1e-3f));
  CHECK(near(group_polygons(s, "floor")[0].normal, {0, 1, 0}));
  CHECK(near(group_polygons(s, "red_wall")[0].normal, {1, 0, 0}));
  CHECK(s.has_camera());
  CHECK(near(s.camera().eye, {2, 1.5f, 9}));
  REQUIRE(s.meshes()[0].uv1.size() == 4);
  CHECK(s.meshes()[0].uv1[2] == glm::vec2(0.95f, 0.95f));
  CHECK(s.meshes()[0].uv0.empty());
  CHECK(s.meshes()[1].uv1.empty());
  check_error(broken, ErrorCode::parse_error, {"truncated GLB: its header gives " + std::to_string(glb_bytes.size()) + " bytes"});
}

// --- broken files ---------------------------------------------------------------------------

TEST_CASE("glTF broken: every truncation of a GLB or a .gltf is an Error naming the file - never a crash") {
  const test::GltfBuilder b = make_room();
  const std::string glb = b.glb(), text = b.gltf();
  const fs::path path = kTmp / "truncated.glb", text_path = kTmp / "truncated.gltf";
  std::size_t errors = 0;
  for (std::size_t n = 0; n < glb.size(); n += (n < 64 ? 1 : 7)) {
    test::write_file(path, glb.substr(0, n));
    const Error e = load_error(path);
    errors += e.code() == ErrorCode::parse_error && contains(e.what(), path.string() + ": truncated GLB");
  }
  CHECK(errors == (64 + (glb.size() - 64 + 6) / 7));
  // A writer that stopped early but kept its header consistent: the header's and the BIN
  // chunk's lengths fixed to what is left, so the bufferViews reach beyond their buffer.
  for (std::size_t n = glb.size() - 1; n > glb.size() - 400; n -= 13) {
    std::string cut = glb.substr(0, n);
    const std::size_t json_length = static_cast<std::uint8_t>(glb[12]) | static_cast<std::uint8_t>(glb[13]) << 8;
    const std::size_t bin_start = 20 + json_length + 8;
    if (n <= bin_start) break;
    auto put = [&cut](std::size_t at, std::size_t v) {
      for (int k = 0; k < 4; ++k) cut[at + static_cast<std::size_t>(k)] = static_cast<char>((v >> (8 * k)) & 0xFF);
    };
    put(8, n);
    put(bin_start - 8, n - bin_start);
    test::write_file(path, cut);
    const Error e = load_error(path);
    const std::string message = e.what();
    INFO(message);
    CHECK(e.code() == ErrorCode::parse_error);
    CHECK(contains(e.what(), path.string() + ": buffers[0].byteLength"));
  }
  for (std::size_t n = 0; n < text.size(); n += 97) {
    test::write_file(text_path, text.substr(0, n));
    const Error e = load_error(text_path);
    CHECK(e.code() == ErrorCode::parse_error);
    CHECK(contains(e.what(), text_path.string() + ":"));
  }
}

TEST_CASE("glTF broken: a bad magic - another GLB version - a first chunk that is not JSON") {
  const std::string glb = make_room().glb();
  std::string bad = glb;
  bad[0] = 'x';
  check_error(test::write_file(kTmp / "magic.glb", bad), ErrorCode::parse_error,
              {"not a binary glTF (GLB) file: its first 4 bytes are not the magic 'glTF'"});
  bad = glb;
  bad[4] = 1;
  check_error(test::write_file(kTmp / "version.glb", bad), ErrorCode::parse_error, {"GLB version 1 (only version 2"});
  bad = glb;
  bad[16] = 'X';
  check_error(test::write_file(kTmp / "chunk.glb", bad), ErrorCode::parse_error, {"the first GLB chunk is not the JSON chunk"});
}

TEST_CASE("glTF broken: references out of range name their place") {
  auto broken = [](const std::string& name, auto&& edit) {
    test::GltfBuilder b;
    b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}})});
    edit(b.doc);
    return write_gltf(b, name);
  };
  check_error(broken("ref_position.gltf", [](json& d) { d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 7; }),
              ErrorCode::parse_error, {"meshes[0].primitives[0].attributes.POSITION: accessor 7 does not exist (the file has 3 accessors)"});
  check_error(broken("ref_indices.gltf", [](json& d) { d["meshes"][0]["primitives"][0]["indices"] = 9; }),
              ErrorCode::parse_error, {"meshes[0].primitives[0].indices: accessor 9 does not exist"});
  check_error(broken("ref_view.gltf", [](json& d) { d["accessors"][1]["bufferView"] = 12; }), ErrorCode::parse_error,
              {"accessors[1].bufferView: bufferView 12 does not exist (the file has 3 bufferViews)"});
  check_error(broken("ref_mesh.gltf", [](json& d) { d["nodes"][0]["mesh"] = 3; }), ErrorCode::parse_error,
              {"nodes[0].mesh: mesh 3 does not exist"});
  check_error(broken("ref_negative.gltf", [](json& d) { d["scenes"][0]["nodes"][0] = -1; }), ErrorCode::parse_error,
              {"scenes[0].nodes[0]: index -1 is negative"});
  check_error(broken("ref_type.gltf", [](json& d) { d["meshes"][0]["primitives"][0]["material"] = "white"; }),
              ErrorCode::parse_error, {"meshes[0].primitives[0].material: must be an index into materials (got \"white\")"});
}

TEST_CASE("glTF broken: accessors and bufferViews that reach beyond their data") {
  auto broken = [](const std::string& name, auto&& edit) {
    test::GltfBuilder b;
    b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}})});
    edit(b);
    return write_glb(b, name);
  };
  check_error(broken("count.glb", [](test::GltfBuilder& b) { b.doc["accessors"][0]["count"] = 100; }), ErrorCode::parse_error,
              {"meshes[0].primitives[0]: accessor 0 (POSITION): 100 elements of 12 bytes", "reach beyond bufferView 0 (48 bytes)"});
  check_error(broken("offset.glb", [](test::GltfBuilder& b) { b.doc["bufferViews"][0]["byteOffset"] = 100000; }),
              ErrorCode::parse_error, {"bufferViews[0]: bytes 100000 + 48 lie beyond buffer 0"});
  check_error(broken("huge_offset.glb", [](test::GltfBuilder& b) { b.doc["accessors"][1]["byteOffset"] = 4611686018427387904ull; }),
              ErrorCode::parse_error, {"accessor 1 (indices)", "from byte 4611686018427387904, reach beyond bufferView 1"});
  check_error(broken("stride.glb", [](test::GltfBuilder& b) { b.doc["bufferViews"][0]["byteStride"] = 8; }),
              ErrorCode::parse_error, {"accessor 0 (POSITION): bufferView 0's byteStride 8 is smaller than an element (12 bytes)"});
  check_error(broken("type.glb", [](test::GltfBuilder& b) { b.doc["accessors"][0]["type"] = "VEC2"; }), ErrorCode::parse_error,
              {"accessor 0 (POSITION): type VEC2, VEC3 expected"});
  check_error(broken("normals.glb", [](test::GltfBuilder& b) { b.doc["accessors"][2]["count"] = 3; }), ErrorCode::parse_error,
              {"accessor 2 (NORMAL) has 3 elements, POSITION has 4"});
  check_error(broken("sparse.glb",
                     [](test::GltfBuilder& b) {
                       const std::uint32_t index = 99;
                       const glm::vec3 value(0.0f);
                       b.doc["accessors"][0]["sparse"] = {{"count", 1},
                                                          {"indices", {{"bufferView", b.view(&index, 4)}, {"componentType", 5125}}},
                                                          {"values", {{"bufferView", b.view(&value, 12)}}}};
                     }),
              ErrorCode::parse_error, {"accessor 0 (POSITION): sparse index 99 (entry 0) is out of range (4 elements)"});
  check_error(broken("mode.glb", [](test::GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["mode"] = 9; }),
              ErrorCode::parse_error, {"meshes[0].primitives[0].mode: 9 is not a primitive mode"});
}

TEST_CASE("glTF broken: a missing external buffer is file_not_found naming the buffer") {
  test::GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}})});
  const fs::path path = test::write_file(kTmp / "missing_buffer.gltf", b.gltf("missing.bin"));
  check_error(path, ErrorCode::file_not_found, {"buffers[0].uri: external buffer file 'missing.bin' not found (looked for '"});
  check_error(kTmp / "no_such_scene.glb", ErrorCode::file_not_found, {"cannot open glTF file"});
  const fs::path remote = test::write_file(kTmp / "remote_buffer.gltf", b.gltf("https://example.com/scene.bin"));
  check_error(remote, ErrorCode::parse_error, {"buffers[0].uri: 'https://example.com/scene.bin' is not a relative file name"});
}

TEST_CASE("glTF broken: NaN and infinite positions - indices out of range") {
  for (float bad : {std::nanf(""), INFINITY}) {
    test::GltfBuilder b;
    b.scene({b.node({{"mesh", b.mesh(b.triangles({{0, 0, 0}, {1, 0, 0}, {1, bad, 0}}, {0, 1, 2}))}})});
    check_error(write_glb(b, "nan.glb"), ErrorCode::parse_error,
                {"meshes[0].primitives[0]: accessor 0 (POSITION): element 2 is NaN or infinite"});
  }
  test::GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh(b.triangles({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 9, 3}))}})});
  check_error(write_glb(b, "index.glb"), ErrorCode::parse_error,
              {"meshes[0].primitives[0]: accessor 1 (indices): element 4 is vertex 9, out of range (4 vertices)"});
}

TEST_CASE("glTF broken: an unsupported required extension - glTF 1.0 - a node cycle - a syntax error") {
  auto broken = [](const std::string& name, auto&& edit) {
    test::GltfBuilder b;
    const int child = b.node({{"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}});
    b.scene({b.node({{"children", {child}}})});
    edit(b.doc);
    return write_gltf(b, name);
  };
  check_error(broken("draco.gltf", [](json& d) { d["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }),
              ErrorCode::parse_error, {"extensionsRequired[0]: 'KHR_draco_mesh_compression' is not supported (decompress"});
  check_error(broken("version.gltf", [](json& d) { d["asset"]["version"] = "1.0"; }), ErrorCode::parse_error,
              {"asset.version: '1.0': only glTF 2.0 is read"});
  check_error(broken("cycle.gltf", [](json& d) { d["nodes"][0]["children"] = {1}; }), ErrorCode::parse_error,
              {"nodes[1]: reached twice from the scene's roots"});
  const fs::path syntax = test::write_file(kTmp / "syntax.gltf", "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}\n");
  check_error(syntax, ErrorCode::parse_error, {syntax.string() + ":3:13: JSON syntax error: "});
  check_error(broken("no_triangles.gltf", [](json& d) { d["nodes"][1].erase("children"); }), ErrorCode::parse_error,
              {"has no triangles in its scene"});
}

TEST_CASE("glTF broken: corrupted bytes of a GLB give an Error or a scene - never a crash") {
  const std::string glb = make_room().glb();
  const fs::path path = kTmp / "corrupted.glb";
  std::size_t loaded = 0, refused = 0;
  for (std::size_t at = 0; at < glb.size(); at += 11)
    for (char value : {'\0', '\xff', '9', '"'}) {
      std::string bad = glb;
      if (bad[at] == value) continue;
      bad[at] = value;
      test::write_file(path, bad);
      try {
        load(path);
        ++loaded;
      } catch (const Error& e) {
        ++refused;
        const std::string message = e.what();
        INFO(message);
        CHECK(contains(e.what(), path.string()));
      }
    }
  MESSAGE("corrupted GLBs: " << loaded << " loaded, " << refused << " refused");
  CHECK(refused > 0);
}

}  // TEST_SUITE
