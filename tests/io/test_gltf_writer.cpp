// write_baked_gltf(): the solution baked into glTF 2.0. The output is read back twice: by
// tinygltf on its own (what a viewer gets: attributes, materials, the decoded lightmap PNG) and
// by load_scene() (the geometry, transforms and winding are the input's).
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/geometric.hpp>

#include "io/writers/srgb.hpp"
#include "radiosity/io.hpp"
#include "radiosity/lightmap.hpp"
#include "radiosity/radiosity.hpp"
#include "support/gltf_builder.hpp"
#include "support/loading.hpp"

namespace {

namespace fs = std::filesystem;
namespace rad = radiosity;
using rad::Rgb;

const fs::path kData = RADIOSITY_TEST_DATA;
const fs::path kTmp = fs::path(RADIOSITY_TEST_TMP) / "gltf_writer";

/// The output as a viewer reads it (tinygltf, images decoded).
tinygltf::Model read_model(const fs::path& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, path.string())
                                             : loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
  INFO("tinygltf: " << err);
  REQUIRE(ok);
  return model;
}

/// Accessor `index` of float VEC2/VEC3 data (as the writer makes them: packed floats).
std::vector<float> floats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(static_cast<std::size_t>(index));
  REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  const std::size_t n = a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type)));
  std::vector<float> out(n);
  std::memcpy(out.data(), m.buffers[static_cast<std::size_t>(v.buffer)].data.data() + v.byteOffset + a.byteOffset,
              n * sizeof(float));
  return out;
}

const tinygltf::Node* node_named(const tinygltf::Model& m, const std::string& name) {
  for (const tinygltf::Node& n : m.nodes)
    if (n.name == name) return &n;
  return nullptr;
}

/// The scene's mesh of group `name`.
rad::MeshId mesh_of(const rad::Scene& s, const std::string& name) {
  for (rad::MeshId id = 0; id < s.meshes().size(); ++id)
    if (s.groups()[s.meshes()[id].group] == name) return id;
  FAIL("no mesh of group " << name);
  return 0;
}

/// Area-weighted normal and area per group: what geometry and winding come to.
std::map<std::string, std::pair<glm::vec3, double>> group_geometry(const rad::Scene& s) {
  std::map<std::string, std::pair<glm::vec3, double>> out;
  for (const rad::Polygon& p : s.polygons()) {
    double area = 0.0;  // a fan: the polygons are planar and convex
    for (std::size_t k = 1; k + 1 < p.vertices.size(); ++k)
      area += 0.5 * glm::length(glm::cross(p.vertices[k] - p.vertices[0], p.vertices[k + 1] - p.vertices[0]));
    auto& g = out[s.groups()[p.group]];
    g.first += static_cast<float>(area) * p.normal;
    g.second += area;
  }
  return out;
}

void check_same_geometry(const rad::Scene& a, const rad::Scene& b) {
  const auto ga = group_geometry(a), gb = group_geometry(b);
  REQUIRE(ga.size() == gb.size());
  for (const auto& entry : ga) {
    const std::string& name = entry.first;  // not a structured binding: INFO takes it in a lambda
    const auto& g = entry.second;
    INFO("group " << name);
    REQUIRE(gb.count(name) == 1);
    CHECK(gb.at(name).second == doctest::Approx(g.second).epsilon(1e-5));
    CHECK(test::near(gb.at(name).first, g.first, 1e-4f * static_cast<float>(g.second) + 1e-6f));
  }
}

rad::SolveOptions quick_solve() {
  rad::SolveOptions o;
  o.mesh.max_patch_area = 0.25f;
  return o;
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("glTF bake: the room written back shows its light per vertex or per lightmap texel - geometry and winding kept") {
  rad::Scene scene = test::load(kData / "gltf" / "room.glb");
  const rad::MeshId floor = mesh_of(scene, "floor"), block = mesh_of(scene, "block"), wall = mesh_of(scene, "red_wall"),
                    light = mesh_of(scene, "light");
  REQUIRE(scene.meshes()[floor].uv1.size() == 4);  // the file's own lightmap UVs
  rad::LightmapUvOptions uo;
  uo.resolution = 64;
  uo.padding = 2;
  rad::generate_lightmap_uvs(scene, block, uo);  // splits the box's corners between its faces
  const std::size_t block_vertices = scene.meshes()[block].positions.size();
  CHECK(block_vertices > 8);
  REQUIRE(scene.meshes()[block].vertex_origin.size() == block_vertices);
  const rad::Solution sol = rad::solve(scene, quick_solve());

  rad::GltfBakeOptions go;
  go.exposure = 0.02f;
  go.lightmaps.resize(scene.meshes().size());
  rad::LightmapOptions lo;
  lo.width = lo.height = 64;
  lo.dilation = 2;
  for (rad::MeshId id : {floor, block}) go.lightmaps[id] = rad::bake_lightmap(scene, sol, id, lo).image;
  const fs::path out = kTmp / "room_lit.glb";
  fs::create_directories(kTmp);
  rad::write_baked_gltf(kData / "gltf" / "room.glb", scene, sol, out, go);

  const tinygltf::Model lit = read_model(out);
  const tinygltf::Model original = read_model(kData / "gltf" / "room.glb");
  CHECK(lit.nodes.size() == original.nodes.size());
  CHECK(lit.cameras.size() == 1);
  CHECK(std::count(lit.extensionsUsed.begin(), lit.extensionsUsed.end(), "KHR_materials_unlit") == 1);
  for (const tinygltf::Material& m : lit.materials) CHECK(m.extensions.count("KHR_materials_unlit") == 1);

  SUBCASE("vertex colours: exposure x the vertex irradiance, times the reflectance as base colour") {
    const tinygltf::Primitive& p = lit.meshes.at(static_cast<std::size_t>(node_named(lit, "red_wall")->mesh)).primitives.at(0);
    REQUIRE(p.attributes.count("COLOR_0") == 1);
    CHECK(p.attributes.count("TEXCOORD_1") == 0);
    const std::vector<float> colour = floats(lit, p.attributes.at("COLOR_0"));
    const std::vector<float> irradiance = floats(lit, p.attributes.at("_IRRADIANCE"));
    const std::vector<Rgb> H = sol.mesh_vertex_values(wall, rad::Quantity::irradiance);
    REQUIRE(colour.size() == 3 * H.size());
    for (std::size_t v = 0; v < H.size(); ++v)
      for (int c = 0; c < 3; ++c) {
        CHECK(irradiance[3 * v + c] == doctest::Approx(H[v][c]).epsilon(1e-6));
        CHECK(colour[3 * v + c] == doctest::Approx(std::min(1.0f, go.exposure * H[v][c])).epsilon(1e-6));
      }
    CHECK(H[0].x > 0.0f);
    const tinygltf::Material& m = lit.materials.at(static_cast<std::size_t>(p.material));
    const Rgb rho = scene.material(scene.polygons()[scene.meshes()[wall].polygons.first].material).reflectance;
    for (int c = 0; c < 3; ++c) CHECK(m.pbrMetallicRoughness.baseColorFactor[static_cast<std::size_t>(c)] == doctest::Approx(rho[c]));
    CHECK(m.pbrMetallicRoughness.baseColorTexture.index == -1);
  }
  SUBCASE("the emitter shows its emission x exposure, flat, without vertex colours") {
    const tinygltf::Primitive& p = lit.meshes.at(static_cast<std::size_t>(node_named(lit, "light")->mesh)).primitives.at(0);
    CHECK(p.attributes.count("COLOR_0") == 0);
    const Rgb E = scene.material(scene.polygons()[scene.meshes()[light].polygons.first].material).emission;
    const std::vector<double>& f = lit.materials.at(static_cast<std::size_t>(p.material)).pbrMetallicRoughness.baseColorFactor;
    for (int c = 0; c < 3; ++c) CHECK(f[static_cast<std::size_t>(c)] == doctest::Approx(std::min(1.0f, go.exposure * E[c])));
  }
  SUBCASE("a lightmap: TEXCOORD_1 and the PNG as base colour texture, texel for texel the baked one") {
    const tinygltf::Primitive& p = lit.meshes.at(static_cast<std::size_t>(node_named(lit, "floor")->mesh)).primitives.at(0);
    CHECK(p.attributes.count("COLOR_0") == 0);
    REQUIRE(p.attributes.count("TEXCOORD_1") == 1);
    const std::vector<float> uv1 = floats(lit, p.attributes.at("TEXCOORD_1"));
    for (std::size_t v = 0; v < 4; ++v) {
      CHECK(uv1[2 * v] == scene.meshes()[floor].uv1[v].x);
      CHECK(uv1[2 * v + 1] == scene.meshes()[floor].uv1[v].y);
    }
    const tinygltf::Material& m = lit.materials.at(static_cast<std::size_t>(p.material));
    REQUIRE(m.pbrMetallicRoughness.baseColorTexture.index >= 0);
    CHECK(m.pbrMetallicRoughness.baseColorTexture.texCoord == 1);
    const tinygltf::Image& image =
        lit.images.at(static_cast<std::size_t>(lit.textures.at(static_cast<std::size_t>(m.pbrMetallicRoughness.baseColorTexture.index)).source));
    REQUIRE(image.width == 64);
    REQUIRE(image.height == 64);
    REQUIRE(image.component >= 3);
    const rad::Image& baked = go.lightmaps[floor];
    std::size_t compared = 0;
    for (std::size_t i = 0; i < baked.pixels.size(); i += 37) {
      for (int c = 0; c < 3; ++c)
        CHECK(image.image[i * static_cast<std::size_t>(image.component) + static_cast<std::size_t>(c)] ==
              rad::detail::srgb8(go.exposure * baked.pixels[i][c]));
      ++compared;
    }
    CHECK(compared > 100);
  }
  SUBCASE("split vertices carry the file's own attributes: each new vertex is at its origin's place") {
    const tinygltf::Node* node = node_named(lit, "block");
    const tinygltf::Primitive& p = lit.meshes.at(static_cast<std::size_t>(node->mesh)).primitives.at(0);
    const std::vector<float> positions = floats(lit, p.attributes.at("POSITION"));
    REQUIRE(positions.size() == 3 * block_vertices);
    const tinygltf::Primitive& q =
        original.meshes.at(static_cast<std::size_t>(node_named(original, "block")->mesh)).primitives.at(0);
    const std::vector<float> file = floats(original, q.attributes.at("POSITION"));
    const std::vector<std::uint32_t>& origin = scene.meshes()[block].vertex_origin;
    for (std::size_t v = 0; v < block_vertices; ++v)
      for (int c = 0; c < 3; ++c) CHECK(positions[3 * v + static_cast<std::size_t>(c)] == file[3 * origin[v] + static_cast<std::size_t>(c)]);
    const tinygltf::Accessor& a = lit.accessors.at(static_cast<std::size_t>(p.attributes.at("POSITION")));
    REQUIRE(a.minValues.size() == 3);
    CHECK(a.minValues[0] == doctest::Approx(-0.6));
    CHECK(a.maxValues[1] == doctest::Approx(1.2));
  }
  SUBCASE("read back: the same groups, areas and facing; the unlit base colour reads as the reflectance") {
    const rad::Scene back = test::load(out);
    check_same_geometry(scene, back);
    const rad::MeshId w = mesh_of(back, "red_wall");
    const Rgb rho = scene.material(scene.polygons()[scene.meshes()[wall].polygons.first].material).reflectance;
    CHECK(test::near(back.material(back.polygons()[back.meshes()[w].polygons.first].material).reflectance, rho, 1e-6f));
  }
}

TEST_CASE("glTF bake: a mesh placed by a mirroring node and by a plain one gets a copy each, wound as in the file") {
  test::GltfBuilder b;
  const int white = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}, {"metallicFactor", 0.0}}}});
  const int light = b.material({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}, {"emissiveFactor", {1.0, 1.0, 1.0}}});
  const int box = b.mesh(b.box({0, 0, 0}, {1, 1, 1}, white));
  const int floor = b.mesh(b.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, white));
  const int lamp = b.mesh(b.quad({-1, 3, -1}, {1, 3, -1}, {1, 3, 1}, {-1, 3, 1}, light));
  b.scene({b.node({{"name", "plain"}, {"mesh", box}, {"translation", {1.5, 0, 0}}}),
           b.node({{"name", "mirrored"}, {"mesh", box}, {"scale", {-1, 1, 1}}, {"translation", {-1.5, 0, 0}}}),
           b.node({{"name", "floor"}, {"mesh", floor}}), b.node({{"name", "lamp"}, {"mesh", lamp}})});
  fs::create_directories(kTmp);
  const fs::path source = test::write_file(kTmp / "instanced.gltf", b.gltf());
  rad::Scene scene = test::load(source);
  REQUIRE(scene.meshes().size() == 4);
  rad::LightmapUvOptions uo;
  uo.resolution = 32;
  uo.padding = 1;
  for (const char* name : {"plain", "mirrored"}) rad::generate_lightmap_uvs(scene, mesh_of(scene, name), uo);
  const rad::Solution sol = rad::solve(scene, quick_solve());
  rad::GltfBakeOptions go;
  go.exposure = 0.5f;
  const fs::path out = kTmp / "instanced_lit.gltf";
  rad::write_baked_gltf(source, scene, sol, out, go);
  CHECK(fs::exists(kTmp / "instanced_lit.bin"));

  const tinygltf::Model lit = read_model(out);
  CHECK(node_named(lit, "plain")->mesh != node_named(lit, "mirrored")->mesh);
  const rad::Scene back = test::load(out);
  check_same_geometry(scene, back);
  // Split and re-indexed under a mirroring node, the box still faces out.
  std::size_t faces = 0;
  for (const rad::Polygon& p : back.polygons()) {
    if (back.groups()[p.group] != "mirrored") continue;
    const glm::vec3 centroid = (p.vertices[0] + p.vertices[1] + p.vertices[2]) / 3.0f;
    CHECK(glm::dot(p.normal, centroid - glm::vec3(-2.0f, 0.5f, 0.5f)) > 0.0f);
    ++faces;
  }
  CHECK(faces == 12);
  // The two boxes are lit alike (the lamp is symmetric), and their colours say so.
  const auto mean_colour = [&](const char* name) {
    const tinygltf::Primitive& p = lit.meshes.at(static_cast<std::size_t>(node_named(lit, name)->mesh)).primitives.at(0);
    const std::vector<float> c = floats(lit, p.attributes.at("COLOR_0"));
    double sum = 0.0;
    for (float x : c) sum += x;
    return sum / static_cast<double>(c.size());
  };
  CHECK(mean_colour("plain") > 0.01);
  CHECK(mean_colour("mirrored") == doctest::Approx(mean_colour("plain")).epsilon(0.05));
}

TEST_CASE("glTF bake: split vertices carry morph targets (with their bounds) - material variants are dropped with the materials") {
  test::GltfBuilder b;
  const int white = b.material({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}, {"emissiveFactor", {1.0, 1.0, 1.0}}});
  nlohmann::json box = b.box({0, 0, 0}, {1, 1, 1}, white);
  std::vector<glm::vec3> delta(8);
  for (std::size_t k = 0; k < 8; ++k) delta[k] = glm::vec3(0.0f, 0.1f * static_cast<float>(k), 0.0f);
  box["targets"] = nlohmann::json::array({{{"POSITION", b.positions(delta)}}});
  box["extensions"] = {{"KHR_materials_variants", {{"mappings", nlohmann::json::array({{{"material", 0}, {"variants", {0}}}})}}}};
  b.doc["extensions"] = {{"KHR_materials_variants", {{"variants", nlohmann::json::array({{{"name", "v"}}})}}}};
  b.doc["extensionsUsed"] = {"KHR_materials_variants"};
  b.scene({b.node({{"name", "box"}, {"mesh", b.mesh(box)}})});
  fs::create_directories(kTmp);
  const fs::path source = test::write_file(kTmp / "morph.glb", b.glb());
  rad::Scene scene = test::load(source);
  rad::LightmapUvOptions uo;
  uo.resolution = 32;
  uo.padding = 1;
  rad::generate_lightmap_uvs(scene, 0, uo);
  const std::vector<std::uint32_t> origin = scene.meshes()[0].vertex_origin;
  REQUIRE(origin.size() > 8);
  const rad::Solution sol = rad::solve(scene, quick_solve());
  const fs::path out = kTmp / "morph_lit.glb";
  rad::write_baked_gltf(source, scene, sol, out);
  const tinygltf::Model lit = read_model(out);
  CHECK(lit.extensionsUsed == std::vector<std::string>{"KHR_materials_unlit"});
  CHECK(lit.extensions.count("KHR_materials_variants") == 0);
  const tinygltf::Primitive& p = lit.meshes.at(0).primitives.at(0);
  CHECK(p.extensions.count("KHR_materials_variants") == 0);
  REQUIRE(p.targets.size() == 1);
  const int target = p.targets[0].at("POSITION");
  const std::vector<float> moved = floats(lit, target);
  REQUIRE(moved.size() == 3 * origin.size());
  for (std::size_t v = 0; v < origin.size(); ++v) CHECK(moved[3 * v + 1] == doctest::Approx(0.1f * static_cast<float>(origin[v])));
  const tinygltf::Accessor& a = lit.accessors.at(static_cast<std::size_t>(target));
  REQUIRE(a.maxValues.size() == 3);
  CHECK(a.maxValues[1] == doctest::Approx(0.7));
}

TEST_CASE("glTF bake: a scene from elsewhere (the Cornell box) becomes a new file of a node per group") {
  rad::Scene scene = rad::cornell_box();
  scene.add_group_meshes();
  const rad::Solution sol = rad::solve(scene);
  fs::create_directories(kTmp);
  const fs::path out = kTmp / "cornell_lit.glb";
  rad::write_baked_gltf({}, scene, sol, out);
  const rad::Scene back = test::load(out);
  check_same_geometry(scene, back);
  const tinygltf::Model lit = read_model(out);
  CHECK(lit.nodes.size() == scene.meshes().size());
  // One primitive per material, each with the vertices it uses.
  for (const tinygltf::Mesh& m : lit.meshes)
    for (const tinygltf::Primitive& p : m.primitives)
      CHECK(lit.accessors.at(static_cast<std::size_t>(p.attributes.at("_IRRADIANCE"))).count ==
            lit.accessors.at(static_cast<std::size_t>(p.attributes.at("POSITION"))).count);
}

TEST_CASE("glTF bake: wrong inputs are errors that say what is wrong") {
  const rad::Scene room = test::load(kData / "gltf" / "room.glb");
  const rad::Solution sol = rad::solve(room, quick_solve());
  fs::create_directories(kTmp);
  auto error = [&](const fs::path& source, const fs::path& out, const rad::GltfBakeOptions& o) -> std::string {
    try {
      rad::write_baked_gltf(source, room, sol, out, o);
    } catch (const rad::Error& e) {
      CHECK(e.code() == rad::ErrorCode::invalid_argument);
      return e.what();
    }
    FAIL("no error");
    return "";
  };
  rad::GltfBakeOptions o;
  CHECK(error(kData / "gltf" / "room.glb", kTmp / "x.obj", o).find(".glb or .gltf") != std::string::npos);
  o.exposure = -1.0f;
  CHECK(error(kData / "gltf" / "room.glb", kTmp / "x.glb", o).find("exposure") != std::string::npos);
  o = {};
  o.lightmaps.resize(room.meshes().size() + 1);
  CHECK(error(kData / "gltf" / "room.glb", kTmp / "x.glb", o).find("lightmaps for") != std::string::npos);
  // The room's meshes are not primitives of another file.
  test::GltfBuilder b;
  b.scene({b.node({{"name", "q"}, {"mesh", b.mesh(b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}))}})});
  const fs::path other = test::write_file(kTmp / "other.gltf", b.gltf());
  CHECK(error(other, kTmp / "x.glb", {}).find("was the scene loaded from") != std::string::npos);
}

}  // TEST_SUITE
