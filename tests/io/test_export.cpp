// PLY export of a solution's leaves and the --stats JSON, on a hand-made Solution (a quad and a
// triangle meshed into a few patches, one leaf subdivided so the mesh has hanging vertices).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include "io/writers/srgb.hpp"
#include "radiosity/io.hpp"
#include "radiosity/radiosity.hpp"
#include "support/scenes.hpp"

namespace {

namespace fs = std::filesystem;
using radiosity::Error;
using radiosity::ErrorCode;
using radiosity::Rgb;

const fs::path kTmp = RADIOSITY_TEST_TMP;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A solution whose radiosity is a smooth function of position, with a hand-written report.
radiosity::Solution small_solution() {
  radiosity::Scene scene;
  radiosity::Material white;
  white.name = "white";
  white.reflectance = Rgb(0.7f);
  radiosity::Material lamp;
  lamp.name = "lamp";
  lamp.emission = Rgb(10.0f, 8.0f, 6.0f);
  const radiosity::MaterialId w = scene.add_material(white);
  const radiosity::MaterialId l = scene.add_material(lamp);
  scene.add_polygon({{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, w, "floor");
  scene.add_polygon({{0, 1, 0}, {1, 1, 0}, {0, 1, 1}}, l, "light");

  radiosity::MeshOptions mesh;
  mesh.max_patch_area = 0.25f;
  mesh.max_element_area = 0.25f;
  radiosity::PatchHierarchy h(scene, mesh);
  h.subdivide(h.leaves().front());

  std::vector<Rgb> B(h.elements().size());
  for (std::uint32_t leaf : h.leaves()) {
    const glm::vec3 c = h.element(leaf).centroid;
    B[leaf] = Rgb(1.0f + c.x, 2.0f + c.z, 3.0f + c.y);
  }
  h.aggregate(B);

  radiosity::SolveReport report;
  report.iterations = 3;
  report.residual = 5e-4;
  report.residual_history = {0.5, 0.01, 5e-4};
  report.time_history = {0.1, 0.2, 0.3};
  report.patch_count = h.patches().size();
  report.element_count = h.leaves().size();
  report.form_factor_bytes = 1234;
  report.emitted_power = Rgb(5.0f, 4.0f, 3.0f);
  report.absorbed_power = Rgb(4.5f, 3.5f, 2.5f);
  report.escaped_power = Rgb(0.5f, 0.5f, 0.5f);
  report.seconds_meshing = 0.001;
  report.seconds_form_factors = 0.25;
  report.seconds_solving = 0.125;
  report.warnings = {"first warning", "second warning"};
  std::vector<std::string> groups = scene.groups();
  return radiosity::Solution(std::move(h), std::move(B), std::move(groups), radiosity::SolveStatus::iteration_cap,
                             std::move(report));
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

template <typename T>
T get_le(const std::string& bytes, std::size_t offset) {
  std::uint8_t b[sizeof(T)];
  for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<std::uint8_t>(bytes[offset + i]);
  std::uint32_t u = 0;
  for (std::size_t i = sizeof(T); i-- > 0;) u = (u << 8) | b[i];
  T v;
  std::memcpy(&v, &u, sizeof(T));
  return v;
}

float triangle_area(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 u = b - a, v = c - a;
  const glm::vec3 n(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x);
  return 0.5f * std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("write_ply writes the leaves as triangles over the vertices they use - with radiosity and sRGB colour") {
  const radiosity::Solution sol = small_solution();
  const radiosity::PatchHierarchy& h = sol.hierarchy();
  std::set<std::uint32_t> used;
  std::size_t triangles = 0;
  double leaf_area = 0.0;
  for (std::uint32_t leaf : h.leaves()) {
    const radiosity::Element& e = h.element(leaf);
    for (int c = 0; c < e.corner_count(); ++c) used.insert(e.corners[static_cast<std::size_t>(c)]);
    triangles += static_cast<std::size_t>(e.corner_count() - 2);
    leaf_area += e.area;
  }

  fs::create_directories(kTmp);
  const fs::path path = kTmp / "solution.ply";
  radiosity::write_ply(sol, path, radiosity::PngOptions{0.5f});
  const std::string bytes = read_all(path);

  const std::size_t end = bytes.find("end_header\n");
  REQUIRE(end != std::string::npos);
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  std::getline(header, line);
  CHECK(line == "ply");
  std::getline(header, line);
  CHECK(line == "format binary_little_endian 1.0");
  std::size_t vertices = 0, faces = 0;
  std::vector<std::string> properties;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string a, b, c;
    words >> a >> b >> c;
    if (a == "element" && b == "vertex") vertices = std::stoul(c);
    if (a == "element" && b == "face") faces = std::stoul(c);
    if (a == "property") properties.push_back(line);
  }
  CHECK(vertices == used.size());
  CHECK(faces == triangles);
  CHECK(vertices < h.vertices().size() + 1);
  REQUIRE(properties.size() == 10);
  CHECK(properties[0] == "property float x");
  CHECK(properties[3] == "property float radiosity_r");
  CHECK(properties[6] == "property uchar red");
  CHECK(properties[9] == "property list uchar int vertex_indices");

  // Body: 27 bytes a vertex, 13 a triangle, nothing else.
  const std::size_t body = end + std::string("end_header\n").size();
  REQUIRE(bytes.size() == body + 27 * vertices + 13 * faces);
  const std::vector<Rgb> B = sol.vertex_radiosity();
  std::vector<glm::vec3> positions(vertices);
  for (std::size_t i = 0; i < vertices; ++i) {
    const std::size_t o = body + 27 * i;
    positions[i] = glm::vec3(get_le<float>(bytes, o), get_le<float>(bytes, o + 4), get_le<float>(bytes, o + 8));
    const Rgb b(get_le<float>(bytes, o + 12), get_le<float>(bytes, o + 16), get_le<float>(bytes, o + 20));
    // Find the hierarchy vertex at this position and compare its radiosity.
    bool found = false;
    for (std::uint32_t v : used)
      if (h.vertices()[v] == positions[i]) {
        found = true;
        CHECK(b == B[v]);
        // Display colour: sRGB of exposure x B / pi.
        for (int c = 0; c < 3; ++c)
          CHECK(static_cast<std::uint8_t>(bytes[o + 24 + static_cast<std::size_t>(c)]) ==
                radiosity::detail::srgb8(0.5f * b[c] / 3.14159265358979323846f));
      }
    CHECK(found);
  }
  double area = 0.0;
  for (std::size_t t = 0; t < faces; ++t) {
    const std::size_t o = body + 27 * vertices + 13 * t;
    CHECK(static_cast<std::uint8_t>(bytes[o]) == 3);
    std::uint32_t idx[3];
    for (int k = 0; k < 3; ++k) {
      idx[k] = get_le<std::uint32_t>(bytes, o + 1 + 4 * static_cast<std::size_t>(k));
      REQUIRE(idx[k] < vertices);
    }
    area += triangle_area(positions[idx[0]], positions[idx[1]], positions[idx[2]]);
  }
  CHECK(area == doctest::Approx(leaf_area).epsilon(1e-5));
  CHECK(area == doctest::Approx(1.5).epsilon(1e-5));  // unit quad + half-unit triangle
}

TEST_CASE("write_ply gives translucent elements a reversed back face carrying their back radiosity") {
  // A lamp above a translucent panel facing it (one element each): the panel's back sends
  // tau H_front, so the PLY holds the lamp's and the panel's fronts plus the panel's back.
  radiosity::Scene scene;
  radiosity::Material lamp, paper;
  lamp.emission = Rgb(10.0f);
  paper.reflectance = Rgb(0.0f);
  paper.diffuse_transmittance = Rgb(0.5f);
  const radiosity::MaterialId l = scene.add_material(lamp), p = scene.add_material(paper);
  radiosity::add_quad(scene, {0, 1, 2}, {1, 0, 0}, {0, -1, 0}, l, "lamp");  // faces down
  radiosity::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, p, "paper");  // faces up
  radiosity::SolveOptions so;
  so.form_factors.method = radiosity::FormFactorMethod::monte_carlo;
  so.mesh.max_patch_area = so.mesh.max_element_area = 10.0f;
  const radiosity::Solution sol = radiosity::solve(scene, so);
  const Rgb back = sol.back_radiosity()[sol.hierarchy().patches()[1].root];
  REQUIRE(back.x > 0.0f);

  fs::create_directories(kTmp);
  const fs::path path = kTmp / "translucent.ply";
  radiosity::write_ply(sol, path);
  const std::string bytes = read_all(path);
  const std::size_t end = bytes.find("end_header\n");
  REQUIRE(end != std::string::npos);
  CHECK(bytes.find("element vertex 12\n") < end);  // 4 + 4 fronts, 4 back copies
  CHECK(bytes.find("element face 6\n") < end);     // 2 + 2 fronts, 2 backs
  const std::size_t body = end + std::string("end_header\n").size();
  REQUIRE(bytes.size() == body + 27 * 12 + 13 * 6);
  auto position = [&](std::uint32_t i) {
    const std::size_t o = body + 27 * i;
    return glm::vec3(get_le<float>(bytes, o), get_le<float>(bytes, o + 4), get_le<float>(bytes, o + 8));
  };
  // The last two faces are the back: over vertices 8..11, radiosity = the back's, facing -z.
  for (std::size_t t = 4; t < 6; ++t) {
    const std::size_t o = body + 27 * 12 + 13 * t;
    std::uint32_t idx[3];
    for (int k = 0; k < 3; ++k) {
      idx[k] = get_le<std::uint32_t>(bytes, o + 1 + 4 * static_cast<std::size_t>(k));
      REQUIRE(idx[k] >= 8);
      REQUIRE(idx[k] < 12);
      CHECK(get_le<float>(bytes, body + 27 * idx[k] + 12) == doctest::Approx(back.x));
      CHECK(position(idx[k]).z == 1.0f);
    }
    const glm::vec3 a = position(idx[0]), b = position(idx[1]), c = position(idx[2]);
    CHECK(glm::cross(b - a, c - a).z < 0.0f);  // the panel faces +z, its back -z
  }
}

TEST_CASE("write_ply errors name the path") {
  const radiosity::Solution sol = small_solution();
  const fs::path bad = kTmp / "no_such_dir" / "out.ply";
  try {
    radiosity::write_ply(sol, bad);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.code() == ErrorCode::io_error);
    CHECK(contains(e.what(), bad.string()));
  }
}

TEST_CASE("write_stats_json records status - sizes - power - per-group radiosity - timings and warnings") {
  const radiosity::Solution sol = small_solution();
  fs::create_directories(kTmp);
  const fs::path path = kTmp / "stats.json";
  radiosity::write_stats_json(sol, path);
  const nlohmann::json j = nlohmann::json::parse(read_all(path));

  CHECK(j.at("version") == radiosity::version());
  CHECK(!j.contains("method"));
  CHECK(j.at("status") == "iteration_cap");
  CHECK(j.at("iterations") == 3);
  CHECK(j.at("residual").get<double>() == 5e-4);
  CHECK(j.at("patches") == sol.hierarchy().patches().size());
  CHECK(j.at("elements") == sol.hierarchy().leaves().size());
  CHECK(j.at("form_factor_bytes") == 1234);
  CHECK(j.at("emitted_power") == nlohmann::json::array({5.0, 4.0, 3.0}));
  CHECK(j.at("absorbed_power") == nlohmann::json::array({4.5, 3.5, 2.5}));
  CHECK(j.at("escaped_power") == nlohmann::json::array({0.5, 0.5, 0.5}));
  CHECK(j.at("mesh").at("max_patch_area").get<double>() == doctest::Approx(0.25));
  for (const char* g : {"floor", "light"}) {
    const nlohmann::json& group = j.at("groups").at(g);
    const Rgb B = sol.group_radiosity(g);
    for (int c = 0; c < 3; ++c) CHECK(group.at("radiosity")[static_cast<std::size_t>(c)].get<float>() == B[c]);
    CHECK(group.at("area").get<double>() == doctest::Approx(sol.group_area(g)));
  }
  CHECK(j.at("groups").at("floor").at("area").get<double>() == doctest::Approx(1.0));
  CHECK(j.at("timings").at("meshing").get<double>() == 0.001);
  CHECK(j.at("timings").at("form_factors").get<double>() == 0.25);
  CHECK(j.at("timings").at("solving").get<double>() == 0.125);
  CHECK(j.at("residual_history") == nlohmann::json::array({0.5, 0.01, 5e-4}));
  CHECK(j.at("time_history").size() == 3);
  CHECK(j.at("warnings") == nlohmann::json::array({"first warning", "second warning"}));
}

TEST_CASE("write_mesh_ply writes the host's vertices and triangles with UV1 and the solution on each vertex") {
  // A furnace cube as one mesh with UV1: every vertex has H = B = E / (1 - rho).
  radiosity::Scene scene;
  radiosity::Material m;
  m.emission = Rgb(1.0f);
  m.reflectance = Rgb(0.5f);
  const test::InwardCube cube;
  std::vector<glm::vec2> uv1;
  for (const glm::vec3& c : cube.corners) uv1.emplace_back(0.1f + 0.8f * c.x, 0.1f + 0.4f * c.y + 0.4f * c.z);
  radiosity::MeshDesc d = cube.desc(scene.add_material(m));
  d.uv1 = uv1.data();
  const radiosity::MeshId id = scene.add_mesh(d);
  radiosity::SolveOptions o;
  o.form_factors.method = radiosity::FormFactorMethod::ray_cast;
  o.mesh.max_patch_area = 0.1f;
  o.tolerance = 1e-6;
  const radiosity::Solution sol = radiosity::solve(scene, o);
  const fs::path path = kTmp / "mesh.ply";
  radiosity::write_mesh_ply(scene, sol, id, path, radiosity::PngOptions{0.5f});
  const std::string bytes = read_all(path);
  const std::size_t end = bytes.find("end_header\n");
  REQUIRE(end != std::string::npos);
  const std::string header = bytes.substr(0, end);
  CHECK(contains(header, "element vertex 8\n"));
  CHECK(contains(header, "element face 12\n"));
  CHECK(contains(header, "property float s\nproperty float t\nproperty float irradiance_r\n"));
  CHECK(contains(header, "property float radiosity_b\nproperty uchar red\n"));
  // 11 floats and 3 bytes a vertex, 13 bytes a triangle.
  const std::size_t body = end + std::string("end_header\n").size();
  REQUIRE(bytes.size() == body + 47 * 8 + 13 * 12);
  for (std::size_t v = 0; v < 8; ++v) {
    const std::size_t at = body + 47 * v;
    CHECK(get_le<float>(bytes, at) == cube.corners[v].x);
    CHECK(get_le<float>(bytes, at + 12) == uv1[v].x);
    CHECK(get_le<float>(bytes, at + 16) == uv1[v].y);
    CHECK(get_le<float>(bytes, at + 20) == doctest::Approx(2.0).epsilon(2e-3));  // H
    CHECK(get_le<float>(bytes, at + 32) == doctest::Approx(2.0).epsilon(2e-3));  // B
    CHECK(static_cast<std::uint8_t>(bytes[at + 44]) ==
          radiosity::detail::srgb8(0.5f * get_le<float>(bytes, at + 32) / 3.14159265358979323846f));
  }
  for (std::size_t t = 0; t < 12; ++t)
    for (std::size_t k = 0; k < 3; ++k)
      CHECK(get_le<std::uint32_t>(bytes, body + 47 * 8 + 13 * t + 1 + 4 * k) == cube.indices[3 * t + k]);

  radiosity::Scene other;
  other.add_mesh(cube.desc(other.add_material(m)));
  try {
    radiosity::write_mesh_ply(scene, sol, 3, path);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.code() == ErrorCode::invalid_argument);
    CHECK(contains(e.what(), "mesh 3 does not exist"));
  }
}

TEST_CASE("write_stats_json names the estimator that ran, and none for the hierarchical solver") {
  // The hierarchical solver's links are its own transport: until session 28 the file said
  // "monte_carlo" there, an estimator that never ran.
  const radiosity::Scene scene = radiosity::cornell_box();
  for (const radiosity::SolverMethod method : {radiosity::SolverMethod::gauss_seidel, radiosity::SolverMethod::hierarchical}) {
    radiosity::SolveOptions opt;
    opt.method = method;
    opt.mesh.max_patch_area = 40000.0f;
    const radiosity::Solution sol = radiosity::solve(scene, opt);
    const fs::path path = kTmp / "stats_estimator.json";
    radiosity::write_stats_json(sol, path, opt, "cornell");
    const nlohmann::json j = nlohmann::json::parse(read_all(path));
    if (method == radiosity::SolverMethod::hierarchical) {
      CHECK(j.at("method_used") == "hierarchical");
      CHECK(j.at("form_factor_method_used").is_null());
      CHECK(j.at("link_count").get<std::uint64_t>() > 0);
      CHECK_FALSE(sol.report().estimator_ran());
    } else {
      CHECK(sol.report().estimator_ran());
      CHECK(j.at("method_used") == "gauss_seidel");
      CHECK(j.at("form_factor_method_used") == "monte_carlo");  // automatic, on a mesh this small
    }
  }
}

TEST_CASE("write_stats_json records the specular depth solve() chose for a scene with glass, and why") {
  const radiosity::Scene scene = radiosity::cornell_box_specular(radiosity::CornellSpecular::glass);
  radiosity::SolveOptions opt;
  opt.mesh.max_patch_area = 40000.0f;
  const fs::path path = kTmp / "stats_specular.json";
  radiosity::write_stats_json(radiosity::solve(scene, opt), path, opt, "cornell-glass");
  const nlohmann::json j = nlohmann::json::parse(read_all(path));
  CHECK(j.at("specular_depth_used") == 1);
  CHECK(j.at("specular_depth_choice") == "1 (automatic: the scene has mirror or glass materials)");
  CHECK(j.at("emitted_through_glass") == true);
  // Without glass or mirrors: depth 0, no choice.
  radiosity::write_stats_json(radiosity::solve(radiosity::cornell_box(), opt), path, opt, "cornell");
  const nlohmann::json plain = nlohmann::json::parse(read_all(path));
  CHECK(plain.at("specular_depth_used") == 0);
  CHECK(plain.at("specular_depth_choice") == "");
  CHECK(plain.at("emitted_through_glass") == false);
}

TEST_CASE("write_stats_json with options records the scene and the solve's method") {
  const radiosity::Solution sol = small_solution();
  radiosity::SolveOptions opt;
  opt.method = radiosity::SolverMethod::progressive;
  opt.form_factors.method = radiosity::FormFactorMethod::analytic;
  opt.tolerance = 1e-4;
  const fs::path path = kTmp / "stats_options.json";
  radiosity::write_stats_json(sol, path, opt, "room.obj");
  const nlohmann::json j = nlohmann::json::parse(read_all(path));
  CHECK(j.at("scene") == "room.obj");
  CHECK(j.at("method") == "progressive");
  CHECK(j.at("form_factor_method") == "analytic");
  CHECK(j.at("tolerance").get<double>() == 1e-4);
  CHECK(j.at("status") == "iteration_cap");

  const fs::path bad = kTmp / "no_such_dir" / "stats.json";
  try {
    radiosity::write_stats_json(sol, bad);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.code() == ErrorCode::io_error);
    CHECK(contains(e.what(), bad.string()));
  }
}

}  // TEST_SUITE("io")
