// Files as users bring them (tests/data/messy/, written the way exporters write them: outward
// winding, Kd 1, a missing MTL, degenerate and two-corner faces, lines and points, CRLF and a
// byte order mark, the PBR extension): every one loads with warnings that say what was done and
// solves with default options; under LoadOptions::strict each untidy one is refused instead.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <fstream>
#include <filesystem>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/loading.hpp"

namespace rad = radiosity;
namespace fs = std::filesystem;

namespace {

const fs::path kMessy = fs::path(RADIOSITY_TEST_DATA) / "messy";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

rad::SolveOptions coarse() {
  rad::SolveOptions o;
  o.mesh.max_patch_area = 0.5f;
  o.mesh.max_element_area = 0.25f;
  return o;
}

}  // namespace

TEST_SUITE("io") {
  TEST_CASE("every messy exported file loads with its warnings and solves - strict refuses the untidy ones") {
    const struct {
      const char* file;
      std::size_t warnings;  ///< Scene::warnings() of the load: one per kind of problem
      const char* first;     ///< a piece of the first warning
    } files[] = {
        {"exported_room.obj", 3, "exported_room.mtl:5: material 'Wall': Kd (1, 1, 1)"},
        {"missing_library.obj", 2, "missing_library.obj:3: material library 'lost_materials.mtl' not found"},
        {"degenerate_heavy.obj", 1, "(80 in all; also at "},
        {"lines_and_short_faces.obj", 3, "line/point element has no area; ignored (3 in all"},
        {"pbr_dissolve.obj", 2, "pbr_dissolve.mtl:8: material 'plastic': Kd (1.2, 1, 1)"},
        {"crlf_bom.obj", 0, ""},
    };
    std::size_t loaded = 0, solved = 0, refused = 0;
    for (const auto& f : files) {
      CAPTURE(std::string(f.file));
      const rad::Scene scene = rad::load_scene(kMessy / f.file);
      ++loaded;
      CHECK(scene.warnings().size() == f.warnings);
      if (f.warnings > 0) {
        REQUIRE(!scene.warnings().empty());
        CHECK(contains(scene.warnings()[0], f.first));
      }
      const rad::Solution sol = rad::solve(scene, coarse());
      bool finite = true;
      for (const rad::Rgb& b : sol.radiosity()) finite = finite && std::isfinite(b.x + b.y + b.z);
      CHECK(finite);
      solved += finite ? 1 : 0;

      rad::LoadOptions strict;
      strict.strict = true;
      if (f.warnings == 0) {
        CHECK_NOTHROW(rad::load_scene(kMessy / f.file, strict));
      } else {
        bool threw = false;
        try {
          rad::load_scene(kMessy / f.file, strict);
        } catch (const rad::Error& e) {
          threw = true;
          // The error is the first warning's problem, at the same place.
          const std::string first = scene.warnings()[0];
          CHECK(contains(e.what(), first.substr(0, first.find(": ") + 2)));
        }
        CHECK(threw);
        refused += threw ? 1 : 0;
      }
    }
    MESSAGE(loaded << " of " << std::size(files) << " messy files load and " << solved << " solve; strict refuses "
                   << refused << " of the " << std::size(files) - 1 << " untidy ones");
    CHECK(loaded == std::size(files));
  }

  TEST_CASE("a room exported wound outwards is diagnosed - and lit inside once two-sided") {
    rad::Scene scene = rad::load_scene(kMessy / "exported_room.obj");
    const rad::Solution outward = rad::solve(scene, coarse());
    const rad::SolveReport& r = outward.report();
    CHECK(r.escaped_power.x > 0.9f * r.emitted_power.x);
    bool diagnosed = false;
    for (const std::string& w : r.warnings) diagnosed = diagnosed || (contains(w, "looks closed") && contains(w, "--two-sided"));
    CHECK(diagnosed);

    scene.make_two_sided();
    const rad::Solution two_sided = rad::solve(scene, coarse());
    const rad::SolveReport& t = two_sided.report();
    MESSAGE("outward room: " << 100.0 * r.escaped_power.x / r.emitted_power.x << " % escaped; two-sided "
                             << 100.0 * t.escaped_power.x / t.emitted_power.x << " %");
    CHECK(t.escaped_power.x < 0.05f * t.emitted_power.x);
    // The room's inside is its walls' backs: lit now.
    CHECK(two_sided.group_back_radiosity("Room").x > 1.0f);
    for (const std::string& w : t.warnings) CHECK(!contains(w, "looks closed"));
  }

  TEST_CASE("a room exported wound outwards is lit inside once the polygons found facing outward are turned over - its floor, not the box standing on it") {
    rad::Scene scene = rad::load_scene(kMessy / "exported_room.obj");
    // Polygons 0-5 are the room (floor first), 6 the lamp, 7-12 the box (9 its bottom, on the
    // floor), 13 the glass pane. The box's bottom sees nothing in front either (its rays start
    // under the floor), but the pair must end in contact, not z-fighting.
    const rad::OutwardFacing found = rad::find_polygons_facing_outward(scene);
    CHECK(found.polygons == std::vector<rad::PolygonId>{0, 1, 2, 3, 4, 5});
    // The same from the overlaps the caller has (radiosity check), and without them the box's
    // bottom is turned with the floor (z-fighting): so they are used. Overlaps naming a
    // polygon beyond the scene are refused.
    const std::vector<rad::PolygonOverlap> overlaps = rad::find_overlaps(scene);
    CHECK(rad::find_polygons_facing_outward(scene, overlaps).polygons == found.polygons);
    CHECK(rad::find_polygons_facing_outward(scene, {}).polygons == std::vector<rad::PolygonId>{0, 1, 2, 3, 4, 5, 9});
    std::vector<rad::PolygonOverlap> foreign = overlaps;
    REQUIRE(!foreign.empty());
    foreign[0].second = 1000;
    CHECK_THROWS_AS(rad::find_polygons_facing_outward(scene, foreign), rad::Error);
    scene.reverse_winding(found.polygons);
    CHECK(rad::find_polygons_facing_outward(scene).polygons.empty());
    for (const rad::PolygonOverlap& o : rad::find_overlaps(scene))
      CHECK(glm::dot(scene.polygons()[o.first].normal, scene.polygons()[o.second].normal) < 0.0f);
    const rad::Solution turned = rad::solve(scene, coarse());
    const rad::SolveReport& r = turned.report();
    // The room's fronts are lit now, and the box standing in it.
    CHECK(turned.group_radiosity("Room").x > 1.0f);
    CHECK(turned.group_radiosity("Box").x > 0.5f);
    for (const std::string& w : r.warnings) {
      CHECK(!contains(w, "looks closed"));
      CHECK(!contains(w, "z-fighting"));
    }
    // What leaves: light on the lamp's black back (5 cm under the ceiling) and on the glass
    // pane, which this pass does not carry (specular depth 0) and whose back is one-sided.
    MESSAGE("turned room: " << 100.0 * r.escaped_power.x / r.emitted_power.x << " % escaped");
    CHECK(r.escaped_power.x < 0.4f * r.emitted_power.x);
  }

  TEST_CASE("a model at georeferenced coordinates (McGuire's box moved to UTM) kept there is said to lose its "
            "shape in single precision - strict refuses it - the box where it was is not") {
    // As a GIS or BIM export writes it: the model at its site's coordinates (500 000 E, 5 700 000 N),
    // read as written (LoadOptions::local_origin off; by default the reader moves it:
    // test_local_origin.cpp), as the formats read in single precision (Assimp's) are.
    // Floats are 0.5 apart at 5.7e6, so the 2 m box's corners move by up to 0.25 and its light
    // (0.38 deep) collapses and is dropped.
    const fs::path original = fs::path(RADIOSITY_TEST_DATA) / "mcguire" / "CornellBox-Original.obj";
    const fs::path dir = fs::temp_directory_path() / "radiosity_test_utm";
    test::moved_obj(original, dir, "utm.obj", glm::dvec3(500000.0, 30.0, 5700000.0));
    rad::LoadOptions as_written;
    as_written.local_origin = false;
    const rad::Scene utm = rad::load_scene(dir / "utm.obj", as_written);
    bool said = false;
    for (const std::string& w : utm.warnings()) {
      MESSAGE(w);
      said = said || contains(w, "utm.obj: coordinates reach 5700001 while a typical polygon is ");
      if (contains(w, "coordinates reach")) CHECK(contains(w, "single precision, in which polygons are stored, is 0.5 apart there"));
    }
    CHECK(said);
    // Its solve cannot mesh the floor (midpoints round onto its corners) and says why, rather
    // than "element 2161 is at the maximum depth".
    std::string why;
    try {
      (void)rad::solve(utm);  // the default mesh, as the command line has it
    } catch (const rad::Error& e) {
      why = e.what();
    }
    MESSAGE(why);
    CHECK(contains(why, "does not shrink into elements of max_element_area"));
    CHECK(contains(why, "too close together for single precision (is the model far from the origin for its size?"));
    rad::LoadOptions strict = as_written;
    strict.strict = true;
    CHECK_THROWS_AS(rad::load_scene(dir / "utm.obj", strict), rad::Error);
    // Where it was modelled (and at 1 km from the origin) nothing is said.
    const rad::Scene at_home = rad::load_scene(original);
    for (const std::string& w : at_home.warnings()) CHECK(!contains(w, "coordinates reach"));
    fs::remove_all(dir);
  }
}
