// Models far from the origin for their size (georeferenced: a city in UTM, a building at its
// national-grid position): the OBJ and View3D readers move them to a local origin
// (LoadOptions::local_origin, Scene::origin()), the solve and the view factors are those of the
// model at home, and the writers put the results back where the file had them.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <radiosity/radiosity.hpp>

#include "support/loading.hpp"

namespace rad = radiosity;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(RADIOSITY_TEST_DATA);

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// McGuire's Cornell box (tests/data/mcguire) with every vertex moved by `offset`.
fs::path moved_mcguire_box(const fs::path& dir, const glm::dvec3& offset) {
  return test::moved_obj(kData / "mcguire" / "CornellBox-Original.obj", dir, "moved.obj", offset);
}

/// Every group's radiosity of `a` within 0.5 % of `b`'s: the same mesh and seed, only rounding
/// differs.
void check_same_groups(const rad::Solution& a, const rad::Solution& b) {
  for (const std::string& g : b.groups()) {
    CAPTURE(g);
    const rad::Rgb ba = a.group_radiosity(g), bb = b.group_radiosity(g);
    for (int c = 0; c < 3; ++c) CHECK(ba[c] == doctest::Approx(bb[c]).epsilon(0.005));
  }
}

/// The first vertex's x, y, z of a binary little-endian PLY whose vertices start with three
/// doubles (what write_ply() writes for a scene with an origin), and its header.
glm::dvec3 first_ply_vertex(const fs::path& path, std::string& header) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t end = text.find("end_header\n");
  REQUIRE(end != std::string::npos);
  header = text.substr(0, end);
  glm::dvec3 p(0.0);
  REQUIRE(text.size() >= end + 11 + 24);
  std::memcpy(&p.x, text.data() + end + 11, 8);
  std::memcpy(&p.y, text.data() + end + 19, 8);
  std::memcpy(&p.z, text.data() + end + 27, 8);
  return p;
}

}  // namespace

TEST_SUITE("io") {
  TEST_CASE("an OBJ in UTM coordinates is read relative to a local origin - solves as at home - and its PLY is "
            "where the file had it") {
    const glm::dvec3 offset(500000.0, 30.0, 5700000.0);
    const fs::path dir = fs::path(RADIOSITY_TEST_TMP) / "local_origin_obj";
    const fs::path utm_path = moved_mcguire_box(dir, offset);
    const rad::Scene utm = rad::load_scene(utm_path);
    const rad::Scene home = rad::load_scene(kData / "mcguire" / "CornellBox-Original.obj");

    // The box spans about 2 m: the origin is its centre rounded to whole metres (x -0.01,
    // y 0.995, z -0.025 at home).
    CHECK(utm.origin() == glm::dvec3(500000.0, 31.0, 5700000.0));
    CHECK(home.origin() == glm::dvec3(0.0));
    for (const std::string& w : utm.warnings()) CHECK(!contains(w, "coordinates reach"));
    // The same polygons as at home, 1 m lower: within float rounding of values about 1 (the
    // file's 6 decimals).
    REQUIRE(utm.polygons().size() == home.polygons().size());
    float worst = 0.0f;
    for (std::size_t i = 0; i < home.polygons().size(); ++i) {
      REQUIRE(utm.polygons()[i].vertices.size() == home.polygons()[i].vertices.size());
      for (std::size_t k = 0; k < home.polygons()[i].vertices.size(); ++k) {
        const glm::vec3 d = utm.polygons()[i].vertices[k] + glm::vec3(0.0f, 1.0f, 0.0f) - home.polygons()[i].vertices[k];
        worst = std::max({worst, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
      }
    }
    CHECK(worst < 2e-6f);

    // The default solve: every group's radiosity as at home within 0.5 % (the same mesh and
    // seed; only rounding differs). Without the origin this box could not be meshed at all
    // (test_messy_files.cpp).
    const rad::Solution a = rad::solve(utm);
    const rad::Solution b = rad::solve(home);
    check_same_groups(a, b);
    CHECK(a.origin() == utm.origin());
    rad::SolveOptions grouped;
    grouped.separate_light_groups = true;
    const rad::Solution lit = rad::solve(utm, grouped);
    REQUIRE(!lit.light_groups().empty());
    CHECK(lit.relight(std::vector<rad::Rgb>(lit.light_groups().size(), rad::Rgb(0.5f))).origin() == utm.origin());

    // write_ply(): positions as doubles with the origin added, in the file's coordinates.
    rad::write_ply(a, dir / "utm.ply");
    std::string header;
    const glm::dvec3 p = first_ply_vertex(dir / "utm.ply", header);
    CHECK(contains(header, "comment x/y/z: the scene's positions plus its origin (500000 31 5700000)\nelement vertex"));
    CHECK(contains(header, "property double x\nproperty double y\nproperty double z\nproperty float radiosity_r"));
    const glm::vec3 q = a.hierarchy().vertices()[a.hierarchy().element(a.hierarchy().leaves()[0]).corners[0]];
    CHECK(p.x == doctest::Approx(500000.0 + static_cast<double>(q.x)).epsilon(1e-15));
    CHECK(p.z == doctest::Approx(5700000.0 + static_cast<double>(q.z)).epsilon(1e-15));
    CHECK(std::fabs(p.x - 500000.0) < 1.1);
    CHECK(std::fabs(p.y - 31.0) < 1.1);
    CHECK(std::fabs(p.z - 5700000.0) < 1.1);
    // Near the origin nothing changes: floats, as before.
    rad::write_ply(b, dir / "home.ply");
    std::ifstream home_ply(dir / "home.ply", std::ios::binary);
    std::string home_text((std::istreambuf_iterator<char>(home_ply)), std::istreambuf_iterator<char>());
    CHECK(contains(home_text, "property float x\n"));
    CHECK(!contains(home_text, "origin"));

    // A baked glTF (a new file: the scene is no glTF) moves its nodes back by the origin.
    rad::Scene meshed = utm;
    meshed.add_group_meshes();
    const rad::Solution c = rad::solve(meshed);
    rad::write_baked_gltf({}, meshed, c, dir / "utm.gltf", {});
    std::ifstream gltf(dir / "utm.gltf");
    const nlohmann::json j = nlohmann::json::parse(gltf);
    REQUIRE(!j["nodes"].empty());
    for (const nlohmann::json& node : j["nodes"]) {
      REQUIRE(node.contains("translation"));
      CHECK(node["translation"][0].get<double>() == 500000.0);
      CHECK(node["translation"][1].get<double>() == 31.0);
      CHECK(node["translation"][2].get<double>() == 5700000.0);
    }

    // A JSON scene that includes the file keeps it in the JSON's coordinates (which have no local
    // origin): the box where the OBJ says, not moved by an origin of its own.
    {
      std::ofstream json(dir / "site.json");
      json << R"({"version": 1, "surfaces": [{"type": "obj", "file": "moved.obj"}]})";
    }
    rad::LoadOptions quiet;
    const rad::Scene site = rad::load_scene(dir / "site.json", quiet);
    CHECK(site.origin() == glm::dvec3(0.0));
    // (More polygons than at home: faces bent by single precision are triangulated, as warned.)
    REQUIRE(site.polygons().size() >= home.polygons().size());
    CHECK(std::fabs(site.polygons()[0].vertices[0].z - (home.polygons()[0].vertices[0].z + 5700000.0f)) <= 0.5f);
    bool warned = false;
    for (const std::string& w : site.warnings()) warned = warned || contains(w, "coordinates reach");
    CHECK(warned);

    // A model near the origin, or a small offset for its size, keeps its coordinates.
    const rad::Scene near = rad::load_scene(moved_mcguire_box(dir, glm::dvec3(100.0, 0.0, -50.0)));
    CHECK(near.origin() == glm::dvec3(0.0));
    fs::remove_all(dir);
  }

  TEST_CASE("a glTF placed at UTM coordinates by a root node is read relative to a local origin - meshes and "
            "camera alike - and solves as at home") {
    // The room of tests/data/gltf (embedded buffer) under a new root node that places it at its
    // site, as georeferenced exports do (the vertices stay small, the node carries the offset).
    std::ifstream in(kData / "gltf" / "room.gltf");
    nlohmann::json j = nlohmann::json::parse(in);
    const glm::dvec3 site(512340.3, 30.1, 5701230.7);
    nlohmann::json root = {{"name", "site"}, {"translation", {site.x, site.y, site.z}}, {"children", j["scenes"][0]["nodes"]}};
    j["nodes"].push_back(root);
    j["scenes"][0]["nodes"] = {j["nodes"].size() - 1};
    const fs::path path = fs::path(RADIOSITY_TEST_TMP) / "room_utm.gltf";
    std::ofstream(path) << j.dump();

    const rad::Scene utm = rad::load_scene(path);
    const rad::Scene home = rad::load_scene(kData / "gltf" / "room.gltf");
    const glm::dvec3 origin = utm.origin();
    MESSAGE("origin " << origin.x << " " << origin.y << " " << origin.z);
    CHECK(origin != glm::dvec3(0.0));
    for (int c = 0; c < 3; ++c) CHECK(std::fabs(origin[c] - site[c]) < 10.0);  // near the room
    for (const std::string& w : utm.warnings()) CHECK(!contains(w, "coordinates reach"));
    // Every corner is the room's at home moved by site - origin, to float rounding of values
    // of a few metres (the double world matrix keeps the site's digits).
    const glm::vec3 moved(site - origin);
    REQUIRE(utm.polygons().size() == home.polygons().size());
    float worst = 0.0f;
    for (std::size_t i = 0; i < home.polygons().size(); ++i)
      for (std::size_t k = 0; k < home.polygons()[i].vertices.size(); ++k) {
        const glm::vec3 d = utm.polygons()[i].vertices[k] - moved - home.polygons()[i].vertices[k];
        worst = std::max({worst, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
      }
    CHECK(worst < 4e-6f);
    REQUIRE(utm.has_camera());
    const glm::vec3 eye_shift = utm.camera().eye - moved - home.camera().eye;
    CHECK(glm::length(eye_shift) < 4e-6f);

    const rad::Solution a = rad::solve(utm);
    const rad::Solution b = rad::solve(home);
    check_same_groups(a, b);
    fs::remove(path);
  }

  TEST_CASE("a View3D file in UTM coordinates - local origin - exact view factors as at home - save_view3d writes "
            "the file's coordinates back") {
    const rad::View3DFile utm = rad::load_view3d(kData / "view3d" / "cube_utm.vs3");
    const rad::View3DFile home = rad::load_view3d(kData / "view3d" / "cube.vs3");
    // The corners (x.3, y.7, z.1 decimals) are not floats at 5.7e6; relative to the rounded
    // centre they are within rounding of the cube's at home, moved by (-0.7, -1.3, -0.9).
    CHECK(utm.scene.origin() == glm::dvec3(512341.0, 5701232.0, 31.0));
    REQUIRE(utm.scene.polygons().size() == 6);
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t k = 0; k < 4; ++k) {
        const glm::vec3 d = utm.scene.polygons()[i].vertices[k] - home.scene.polygons()[i].vertices[k];
        CHECK(std::fabs(d.x + 0.7f) < 1e-6f);
        CHECK(std::fabs(d.y + 1.3f) < 1e-6f);
        CHECK(std::fabs(d.z + 0.9f) < 1e-6f);
      }

    // The exact view factors: Howell C-14 (0.199825 opposite, 0.200044 adjacent) as at home.
    const rad::ViewFactorMatrix a = rad::view_factor_matrix(utm.scene);
    const rad::ViewFactorMatrix b = rad::view_factor_matrix(home.scene);
    REQUIRE(a.values.size() == b.values.size());
    for (std::size_t k = 0; k < a.values.size(); ++k) {
      CHECK(a.columns[k] == b.columns[k]);
      CHECK(a.values[k] == doctest::Approx(b.values[k]).epsilon(1e-5));
    }
    CHECK(a.values[0] == doctest::Approx(0.199825).epsilon(1e-4));  // floor -> ceiling

    // Written back in the file's coordinates, and read again to the same floats and origin.
    const fs::path out = fs::path(RADIOSITY_TEST_TMP) / "cube_utm_saved.vs3";
    rad::save_view3d(utm.scene, utm.control, utm.title, out);
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // What the scene holds (the float nearest -0.7, plus the origin), in the fewest digits that
    // read back to it: 512340.3 to 7 decimals.
    const std::size_t v1 = text.find("\nV 1 ");
    REQUIRE(v1 != std::string::npos);
    double x = 0, y = 0, z = 0;
    std::istringstream(text.substr(v1 + 5, 80)) >> x >> y >> z;
    CHECK(std::fabs(x - 512340.3) < 1e-7);
    CHECK(std::fabs(y - 5701230.7) < 1e-7);
    CHECK(std::fabs(z - 30.1) < 1e-7);
    const rad::View3DFile again = rad::load_view3d(out);
    CHECK(again.scene.origin() == utm.scene.origin());
    for (std::size_t i = 0; i < 6; ++i) CHECK(again.scene.polygons()[i].vertices == utm.scene.polygons()[i].vertices);
    fs::remove(out);

    // LoadOptions::local_origin = false keeps the file's coordinates (floats 0.5 apart there).
    rad::LoadOptions kept;
    kept.local_origin = false;
    const rad::Scene as_written = rad::load_scene(kData / "view3d" / "cube_utm.vs3", kept);
    CHECK(as_written.origin() == glm::dvec3(0.0));
    CHECK(as_written.polygons()[0].vertices[0] == glm::vec3(512340.3f, 5701230.7f, 30.1f));
  }
}
