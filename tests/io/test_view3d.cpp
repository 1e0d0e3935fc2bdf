// NIST View3D files: load_view3d() and load_scene() on the .vs3 fixtures of tests/data/view3d
// (polygons in surface order, areas, normals facing the radiating side, groups, combined
// surfaces, obstruction-only surfaces, materials from emissivities, the control line), the
// forgiving policy (one warning per kind, an Error under LoadOptions::strict), an Error naming
// file and line for every file that cannot mean anything, save_view3d() round trips, and the
// View3D output file written from a hand-made ViewFactorMatrix (tools/radiosity/view3d_format.hpp).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <doctest/doctest.h>

#include "../../tools/radiosity/view3d_format.hpp"
#include "radiosity/io.hpp"
#include "support/loading.hpp"

namespace {

namespace fs = std::filesystem;
using radiosity::Error;
using radiosity::ErrorCode;
using radiosity::Rgb;
using test::near;

const fs::path kData = fs::path(RADIOSITY_TEST_DATA) / "view3d";
const fs::path kTmp = fs::path(RADIOSITY_TEST_TMP) / "view3d";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

fs::path write_tmp(const std::string& name, const std::string& text) {
  fs::create_directories(kTmp);
  const fs::path p = kTmp / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

radiosity::View3DFile load(const fs::path& path, bool strict = false) {
  radiosity::LoadOptions options;
  options.strict = strict;
  return radiosity::load_view3d(path, options);
}

/// The Error load_view3d() throws for `path` (failing the test when it loads).
Error load_error(const fs::path& path, bool strict = false) {
  try {
    load(path, strict);
  } catch (const Error& e) {
    return e;
  }
  FAIL("load_view3d(" << path.string() << ") did not throw");
  return Error(ErrorCode::internal, "");
}

/// A file of `body` lines must fail at `line` with `code` and a message holding `problem`.
void check_error(const std::string& name, const std::string& body, int line, ErrorCode code, const std::string& problem,
                 bool strict = false) {
  const fs::path p = write_tmp(name, body);
  const Error e = load_error(p, strict);
  INFO("message: " << e.what());
  CHECK(e.code() == code);
  CHECK(contains(e.what(), p.string() + ":" + std::to_string(line) + ": "));
  CHECK(contains(e.what(), problem));
}

/// Three vertices and one triangle, after `head` lines (so the triangle is on line head + 4).
std::string triangle_file(const std::string& head, const std::string& surface = "S 1 1 2 3 0 0 0 0.9 tri") {
  return head + "V 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\n" + surface + "\nEnd of data\n";
}

glm::vec3 centroid(const radiosity::Polygon& p) {
  glm::vec3 c(0.0f);
  for (const glm::vec3& v : p.vertices) c += v;
  return c / static_cast<float>(p.vertices.size());
}

const std::string& group_of(const radiosity::Scene& s, std::size_t polygon) { return s.groups()[s.polygons()[polygon].group]; }

}  // namespace

TEST_SUITE("io") {

TEST_CASE("view3d cube: six surfaces in order - areas - normals into the enclosure - names as groups - emissivities as materials") {
  const radiosity::View3DFile f = load(kData / "cube.vs3", true);
  const radiosity::Scene& s = f.scene;
  CHECK(s.warnings().empty());
  REQUIRE(s.polygons().size() == 6);  // the surface after "End of data" is not read
  const char* names[6] = {"floor", "ceiling", "wall-x0", "wall-x2", "wall-y0", "wall-y2"};
  const glm::vec3 normals[6] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (std::size_t i = 0; i < 6; ++i) {
    CAPTURE(i);
    const radiosity::Polygon& p = s.polygons()[i];
    CHECK(p.vertices.size() == 4);
    CHECK(p.area == doctest::Approx(4.0));
    CHECK(near(p.normal, normals[i]));
    // View3D's radiating side is our front: every face looks at the cube's centre.
    CHECK(glm::dot(p.normal, glm::vec3(1.0f) - centroid(p)) > 0.5f);
    CHECK(group_of(s, i) == names[i]);
    CHECK_FALSE(p.obstruction_only);
  }
  // The first surface's corners in the file's order: V1 V2 V3 V4.
  CHECK(s.polygons()[0].vertices[0] == glm::vec3(0, 0, 0));
  CHECK(s.polygons()[0].vertices[2] == glm::vec3(2, 2, 0));

  // One material per distinct emissivity, reflectance 1 - emissivity.
  REQUIRE(s.materials().size() == 2);
  CHECK(s.polygons()[0].material == s.polygons()[1].material);
  CHECK(s.polygons()[2].material == s.polygons()[5].material);
  CHECK(s.material(s.polygons()[0].material).reflectance == Rgb(0.5f));
  CHECK(s.material(s.polygons()[2].material).reflectance.x == doctest::Approx(0.1).epsilon(1e-6));
  CHECK(s.material(s.polygons()[2].material).name == "emissivity 0.9");
  CHECK(s.material(s.polygons()[2].material).emission == Rgb(0.0f));

  CHECK(f.title == "A 2 m cube: six surfaces facing in (a closed enclosure)");
  const radiosity::View3DControl& c = f.control;
  CHECK(c.enclosure);
  CHECK(c.script_f);
  CHECK(c.output_format == 0);
  CHECK(c.list == 2);
  CHECK(c.epsilon == doctest::Approx(1e-5));
  CHECK(c.max_unobstructed_recursions == 10);
  CHECK(c.max_obstructed_recursions == 6);
  CHECK(c.min_obstructed_recursions == 1);
  CHECK(c.row == 0);
  CHECK(c.column == 0);
  CHECK(c.other.empty());

  // load_scene() reads .vs3 the same way.
  const radiosity::Scene same = radiosity::load_scene(kData / "cube.vs3");
  REQUIRE(same.polygons().size() == 6);
  CHECK(same.polygons()[3].vertices == s.polygons()[3].vertices);
}

TEST_CASE("view3d plates: CRLF - commas and tabs - a triangle - an obstruction-only plate numbered last - other control words kept") {
  const radiosity::View3DFile f = load(kData / "plates.vs3");
  const radiosity::Scene& s = f.scene;
  REQUIRE(s.polygons().size() == 4);
  CHECK(near(s.polygons()[0].normal, {0, 0, 1}));
  CHECK(near(s.polygons()[1].normal, {0, 0, -1}));
  CHECK(s.polygons()[2].vertices.size() == 3);
  CHECK(s.polygons()[2].area == doctest::Approx(0.5));
  CHECK(s.polygons()[3].area == doctest::Approx(0.25));
  for (std::size_t i = 0; i < 3; ++i) CHECK_FALSE(s.polygons()[i].obstruction_only);
  CHECK(s.polygons()[3].obstruction_only);
  CHECK(group_of(s, 0) == "bottom");
  CHECK(group_of(s, 2) == "wedge");
  CHECK(group_of(s, 3) == "s4");  // an O line without a name
  // The obstruction is black (emissivity 1), the material it shares with the wedge.
  CHECK(s.polygons()[3].material == s.polygons()[2].material);
  CHECK(s.material(s.polygons()[3].material).reflectance == Rgb(0.0f));
  CHECK(s.material(s.polygons()[0].material).reflectance.x == doctest::Approx(0.2).epsilon(1e-6));

  CHECK(f.title == "Two plates with an obstruction between them");
  CHECK(f.control.output_format == 1);
  CHECK(f.control.row == 2);
  CHECK(f.control.column == 1);
  CHECK_FALSE(f.control.enclosure);
  REQUIRE(f.control.other.size() == 1);
  CHECK(f.control.other[0] == std::pair<std::string, std::string>("maxD", "10"));
  // maxD is not View3D 3.2's: a note, which strict loading keeps as a warning.
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], "plates.vs3:3: control word 'maxD' is not one of View3D 3.2's"));
  CHECK(load(kData / "plates.vs3", true).scene.warnings().size() == 1);
}

TEST_CASE("view3d combine: pieces combined with a surface join its group - subsurfaces warn - strict refuses them") {
  const radiosity::View3DFile f = load(kData / "combine.vs3", true);
  const radiosity::Scene& s = f.scene;
  REQUIRE(s.polygons().size() == 4);
  CHECK(s.groups() == std::vector<std::string>{"floor", "ceiling"});
  for (std::size_t i = 0; i < 3; ++i) CHECK(group_of(s, i) == "floor");
  CHECK(s.polygons()[3].area == doctest::Approx(4.0));
  CHECK(s.warnings().empty());

  // A window in a wall (base 1): kept whole, with one warning for all subsurfaces.
  const std::string wall =
      "T wall with windows\nV 1 0 0 0\nV 2 4 0 0\nV 3 4 0 3\nV 4 0 0 3\nV 5 1 0 1\nV 6 2 0 1\nV 7 2 0 2\nV 8 1 0 2\n"
      "S 1 1 2 3 4 0 0 0.9 wall\nS 2 5 6 7 8 1 0 0.9 window\nS 3 5 6 7 0 1 0 0.9 pane\nE\n";
  const fs::path p = write_tmp("subsurface.vs3", wall);
  const radiosity::Scene w = load(p).scene;
  REQUIRE(w.polygons().size() == 3);
  REQUIRE(w.warnings().size() == 1);
  CHECK(contains(w.warnings()[0], p.string() + ":11: surface 2 ('window') is a subsurface of surface 1 ('wall')"));
  CHECK(contains(w.warnings()[0], "(2 in all; also at " + p.string() + ":12)"));
  const Error e = load_error(p, true);
  CHECK(e.code() == ErrorCode::invalid_scene);
  CHECK(contains(e.what(), p.string() + ":11: surface 2 ('window') is a subsurface"));
}

TEST_CASE("view3d forgiving: emissivities outside 0 to 1 clamped - unnamed surfaces - unknown lines - low recursions - each one warning") {
  const std::string text =
      "T forgiven\nC maxU=2 minO=-1\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nV 4 1 1 0\nQ what is this\n"
      "S 1 1 2 3 0 0 0 0 black-hole\nS 2 2 4 3 0 0 0 1.5 too-much\nS 3 1 2 3 0 0 0 -2\nS 4 2 4 3 0 0 0 0.5\nE\n";
  const fs::path p = write_tmp("forgiven.vs3", text);
  const radiosity::View3DFile f = load(p);
  const radiosity::Scene& s = f.scene;
  REQUIRE(s.polygons().size() == 4);
  CHECK(s.material(s.polygons()[0].material).reflectance.x == doctest::Approx(0.99));
  CHECK(s.material(s.polygons()[1].material).reflectance == Rgb(0.0f));
  CHECK(s.polygons()[2].material == s.polygons()[0].material);
  CHECK(group_of(s, 2) == "s3");
  CHECK(group_of(s, 3) == "s4");
  CHECK(f.control.max_unobstructed_recursions == 4);
  CHECK(f.control.min_obstructed_recursions == 0);
  const std::vector<std::string>& w = s.warnings();
  REQUIRE(w.size() == 4);  // one per kind: control value, unknown line, emissivity, unnamed surface
  CHECK(contains(w[0], p.string() + ":2: control maxU=2 is below 4; set to 4 (as View3D does) (2 in all;"));
  CHECK(contains(w[1], p.string() + ":7: unknown line 'Q'"));
  CHECK(contains(w[2], p.string() + ":8: surface 1: emissivity 0 is outside (0, 1]; clamped to 0.01 (3 in all;"));
  CHECK(contains(w[3], p.string() + ":10: surface 3 has no name; named 's3' (2 in all;"));

  // Under strict, the first of them is the Error.
  const Error e = load_error(p, true);
  CHECK(contains(e.what(), p.string() + ":2: control maxU=2 is below 4"));
  check_error("strict_emissivity.vs3", triangle_file("T\n", "S 1 1 2 3 0 0 0 0 tri"), 5, ErrorCode::invalid_scene,
              "surface 1: emissivity 0 is outside (0, 1]", true);
  check_error("strict_unnamed.vs3", triangle_file("T\n", "S 1 1 2 3 0 0 0 0.5"), 5, ErrorCode::parse_error,
              "surface 1 has no name", true);

  // Notes stay warnings under strict: an X line, no end line.
  const radiosity::Scene notes = load(write_tmp("notes.vs3", "X 1 0 0\n" + triangle_file("")), true).scene;
  REQUIRE(notes.warnings().size() == 1);
  CHECK(contains(notes.warnings()[0], ":1: X (coordinate transformation) line ignored"));
  const radiosity::Scene open = load(kData / "no_end.vs3", true).scene;
  REQUIRE(open.polygons().size() == 1);
  REQUIRE(open.warnings().size() == 1);
  CHECK(contains(open.warnings()[0], "no_end.vs3: no end-of-data line (E or *): read to the end of the file"));
}

TEST_CASE("view3d bad files: each an Error naming file - line and problem") {
  const Error degenerate = load_error(kData / "degenerate.vs3");
  CHECK(degenerate.code() == ErrorCode::invalid_scene);
  CHECK(contains(degenerate.what(), "degenerate.vs3:8: surface 2 ('line'): degenerate (zero-area) surface"));
  const Error dart = load_error(kData / "nonconvex.vs3");
  CHECK(dart.code() == ErrorCode::invalid_scene);
  CHECK(contains(dart.what(), "nonconvex.vs3:6: surface 1 ('dart'): non-convex quadrilateral"));
  check_error("nonplanar.vs3", "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0.5\nV 4 0 1 0\nS 1 1 2 3 4 0 0 0.9 twisted\n", 5,
              ErrorCode::invalid_scene, "surface 1 ('twisted'): its 4 corners are not in one plane");

  const Error missing = load_error(kData / "missing.vs3");
  CHECK(missing.code() == ErrorCode::file_not_found);
  CHECK(contains(missing.what(), "missing.vs3"));

  using E = ErrorCode;
  check_error("vertex_sequence.vs3", "T\nV 1 0 0 0\nV 3 1 0 0\n", 3, E::parse_error, "vertex 3 is out of sequence (expected 2");
  check_error("vertex_nan.vs3", "V 1 0 nan 0\n", 1, E::parse_error, "coordinate 'nan' is not a finite number");
  check_error("vertex_huge.vs3", "V 1 0 1e39 0\n", 1, E::parse_error, "coordinate '1e39' is not a finite number");
  check_error("vertex_short.vs3", "V 1 0 0\n", 1, E::parse_error, "vertex line has 3 values");
  check_error("surface_sequence.vs3", triangle_file("", "S 2 1 2 3 0 0 0 0.9 tri"), 4, E::parse_error,
              "surface 2 is out of sequence (expected 1");
  check_error("vertex_range.vs3", triangle_file("", "S 1 1 2 4 0 0 0 0.9 tri"), 4, E::parse_error,
              "surface 1: vertex 4 is out of range (the file has 3 vertices)");
  check_error("vertex_zero.vs3", triangle_file("", "S 1 1 0 3 0 0 0 0.9 tri"), 4, E::parse_error,
              "surface 1: vertex 0 is out of range");
  check_error("surface_short.vs3", triangle_file("", "S 1 1 2 3 0 0 0"), 4, E::parse_error,
              "surface 1 needs base, combine and emissivity");
  check_error("surface_words.vs3", triangle_file("", "S 1 1 2 3"), 4, E::parse_error, "surface line has 4 values");
  check_error("emissivity_word.vs3", triangle_file("", "S 1 1 2 3 0 0 0 grey tri"), 4, E::parse_error,
              "surface 1: emissivity 'grey' is not a finite number");
  check_error("base_self.vs3", triangle_file("", "S 1 1 2 3 0 1 0 0.9 tri"), 4, E::parse_error,
              "surface 1: base surface 1 is invalid");
  check_error("combine_later.vs3", triangle_file("", "S 1 1 2 3 0 0 2 0.9 tri"), 4, E::parse_error,
              "surface 1: combine surface 2 is invalid");
  check_error("combine_chain.vs3",
              "V 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nS 1 1 2 3 0 0 0 0.9 a\nS 2 1 2 3 0 0 1 0.9 b\nS 3 1 2 3 0 0 2 0.9 c\n", 6,
              E::parse_error, "surface 3: combine surface 2 is itself combined with surface 1");
  check_error("obstruction_first.vs3", "V 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nO 1 1 2 3 0\nS 2 1 2 3 0 0 0 0.9 a\n", 5,
              E::parse_error, "radiating surface after an obstruction surface");
  check_error("mask.vs3", triangle_file("", "M 1 1 2 3 0 0 0 0.9 tri"), 4, E::parse_error,
              "mask surfaces (M and N lines) are not supported");
  check_error("two_d.vs3", "T a 2-D file\nF 2\nV 1 0 0\n", 2, E::parse_error,
              "2-D geometry (F 2) is View2D's format (.vs2)");
  check_error("blast.vs3", "F 3a\n", 1, E::parse_error, "BLAST surface geometry (F 3a) is not supported");
  check_error("control_out.vs3", triangle_file("C out=3\n"), 1, E::parse_error, "control out=3");
  check_error("control_value.vs3", triangle_file("C encl=yes\n"), 1, E::parse_error, "control encl: 'yes' is not an integer");
  check_error("control_missing.vs3", triangle_file("C encl=1 list\n"), 1, E::parse_error, "control word 'list' has no value");
  check_error("control_eps.vs3", triangle_file("C eps=0\n"), 1, E::parse_error, "control eps: '0' is not a number > 0");
  check_error("control_col.vs3", triangle_file("C col=1\n"), 1, E::parse_error, "control col=1 needs a row");
  check_error("control_row.vs3", triangle_file("C encl=1\nC row=2\n"), 2, E::parse_error,
              "control row=2 is beyond the 1 radiating surfaces");

  const Error empty = load_error(write_tmp("empty.vs3", "T nothing\nV 1 0 0 0\nEnd of data\n"));
  CHECK(empty.code() == ErrorCode::parse_error);
  CHECK(contains(empty.what(), "has no surfaces (S lines)"));
  const Error only_obstruction =
      load_error(write_tmp("only_obstruction.vs3", triangle_file("", "O 1 1 2 3 0")));
  CHECK(contains(only_obstruction.what(), "has no radiating surfaces"));
}

TEST_CASE("view3d every truncation of a file is an Error or a scene - never a crash") {
  const std::string text = read_bytes(kData / "plates.vs3");
  std::size_t scenes = 0;
  for (std::size_t n = 0; n <= text.size(); ++n) {
    const fs::path p = write_tmp("cut.vs3", text.substr(0, n));
    try {
      load(p);
      ++scenes;
    } catch (const Error&) {
    }
  }
  CHECK(scenes > 0);
}

TEST_CASE("view3d save then load: same polygons - order - groups - obstruction flags - emissivities - title and control") {
  for (const char* name : {"cube.vs3", "plates.vs3", "combine.vs3"}) {
    CAPTURE(name);
    const radiosity::View3DFile a = load(kData / name);
    const fs::path out = kTmp / (std::string("saved_") + name);
    fs::create_directories(kTmp);
    radiosity::save_view3d(a.scene, a.control, a.title, out);
    const radiosity::View3DFile b = load(out, true);  // written files load without a warning but notes
    REQUIRE(b.scene.polygons().size() == a.scene.polygons().size());
    for (std::size_t i = 0; i < a.scene.polygons().size(); ++i) {
      CAPTURE(i);
      const radiosity::Polygon& p = a.scene.polygons()[i];
      const radiosity::Polygon& q = b.scene.polygons()[i];
      CHECK(q.vertices == p.vertices);  // bit for bit
      CHECK(group_of(b.scene, i) == group_of(a.scene, i));
      CHECK(q.obstruction_only == p.obstruction_only);
      CHECK(b.scene.material(q.material).reflectance.x ==
            doctest::Approx(a.scene.material(p.material).reflectance.x).epsilon(1e-6));
    }
    CHECK(b.scene.groups() == a.scene.groups());
    CHECK(b.scene.materials().size() == a.scene.materials().size());
    CHECK(b.title == a.title);
    const radiosity::View3DControl& c = a.control;
    const radiosity::View3DControl& d = b.control;
    CHECK(d.enclosure == c.enclosure);
    CHECK(d.script_f == c.script_f);
    CHECK(d.output_format == c.output_format);
    CHECK(d.epsilon == c.epsilon);
    CHECK(d.max_unobstructed_recursions == c.max_unobstructed_recursions);
    CHECK(d.max_obstructed_recursions == c.max_obstructed_recursions);
    CHECK(d.min_obstructed_recursions == c.min_obstructed_recursions);
    CHECK(d.row == c.row);
    CHECK(d.column == c.column);
    CHECK(d.list == c.list);
    CHECK(d.reverse_projections == c.reverse_projections);
    CHECK(d.other == c.other);
  }

  // The cube's 8 corners are shared by its 6 faces: 8 V lines.
  radiosity::View3DFile cube = load(kData / "cube.vs3");
  const fs::path saved = kTmp / "saved_cube.vs3";
  const std::string text = read_bytes(saved);
  CHECK(contains(text, "\nV 8 "));
  CHECK_FALSE(contains(text, "\nV 9 "));
  CHECK(contains(text, "\nS 1 1 2 3 4 0 0 0.5 floor\n"));
  CHECK(contains(text, "C encl=1 emit=1 out=0 list=2 eps=1e-05 maxU=10 maxO=6 minO=1 row=0 col=0\n"));
}

TEST_CASE("view3d save: many-cornered polygons fan into combined pieces - obstructions go last - names made one word") {
  radiosity::Scene s;
  radiosity::Material grey;
  grey.reflectance = Rgb(0.25f, 0.5f, 0.75f);  // mean 0.5: emissivity 0.5
  const radiosity::MaterialId m = s.add_material(grey);
  s.add_polygon({{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, m, "lid");  // an obstruction, before the others
  s.set_obstruction_only(0);
  // A regular hexagon facing +z: a fan of two quadrilaterals.
  std::vector<glm::vec3> hexagon;
  for (int k = 0; k < 6; ++k)
    hexagon.emplace_back(std::cos(k * 1.04719755f), std::sin(k * 1.04719755f), 0.0f);
  s.add_polygon(hexagon, m, "hex floor, north!");
  s.add_polygon({{0, 0, 2}, {0, 1, 2}, {1, 0, 2}}, m, "roof");
  const double hexagon_area = s.polygons()[1].area;

  radiosity::View3DControl control;
  control.reverse_projections = true;
  const fs::path out = kTmp / "fan.vs3";
  fs::create_directories(kTmp);
  radiosity::save_view3d(s, control, "line one\nline two", out);
  const std::string text = read_bytes(out);
  CHECK(contains(text, "T line one line two\n"));
  CHECK(contains(text, " prjD=1\n"));
  CHECK(contains(text, "S 1 1 2 3 4 0 0 0.5 hex_floor__north!\n"));
  CHECK(contains(text, "S 2 1 4 5 6 0 1 0.5 hex_floor__north!\n"));  // combined with the first piece
  CHECK(contains(text, "\nO 4 "));

  const radiosity::View3DFile f = load(out, true);
  const radiosity::Scene& b = f.scene;
  REQUIRE(b.polygons().size() == 4);
  CHECK(b.polygons()[0].area + b.polygons()[1].area == doctest::Approx(hexagon_area));
  CHECK(group_of(b, 0) == "hex_floor__north!");
  CHECK(group_of(b, 1) == "hex_floor__north!");
  CHECK(group_of(b, 2) == "roof");
  CHECK(b.polygons()[3].obstruction_only);
  CHECK(group_of(b, 3) == "lid");
  CHECK(b.material(b.polygons()[0].material).reflectance == Rgb(0.5f));
  CHECK(f.control.reverse_projections);
  CHECK(f.title == "line one line two");

  // What load_view3d() would not read back as written is refused.
  radiosity::View3DControl bad;
  bad.column = 1;
  CHECK_THROWS_WITH_AS(radiosity::save_view3d(s, bad, "", out), doctest::Contains("column needs a row"), Error);
  bad = {};
  bad.row = 4;
  CHECK_THROWS_WITH_AS(radiosity::save_view3d(s, bad, "", out), doctest::Contains("at most the 3 radiating surfaces"), Error);
  bad = {};
  bad.other = {{"maxD", "1 0"}};
  CHECK_THROWS_AS(radiosity::save_view3d(s, bad, "", out), Error);
  bad = {};
  bad.max_obstructed_recursions = 2;
  CHECK_THROWS_AS(radiosity::save_view3d(s, bad, "", out), Error);
  radiosity::Scene obstructions_only;
  obstructions_only.add_polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, obstructions_only.add_material(grey));
  obstructions_only.set_obstruction_only(0);
  CHECK_THROWS_WITH_AS(radiosity::save_view3d(obstructions_only, {}, "", out), doctest::Contains("no radiating polygons"), Error);
  const Error io = [&] {
    try {
      radiosity::save_view3d(s, {}, "", kTmp / "no_such_dir" / "x.vs3");
    } catch (const Error& e) {
      return e;
    }
    return Error(ErrorCode::internal, "did not throw");
  }();
  CHECK(io.code() == ErrorCode::io_error);
  CHECK(contains(io.what(), "no_such_dir"));
}

TEST_CASE("view3d output file: a hand-made 3x3 matrix in View3D's text and binary layouts") {
  radiosity::ViewFactorMatrix m;
  m.level = radiosity::ViewFactorLevel::polygon;
  m.ids = {0, 1, 2};
  m.area = {1.0, 2.0, 0.5};
  m.row_offsets = {0, 2, 4, 6};
  m.columns = {1, 2, 0, 2, 0, 1};
  m.values = {0.25f, 0.125f, 0.125f, 1.0f / 3.0f, 0.25f, 0.5f};
  const std::vector<float> emissivity = {0.9f, 0.5f, 1.0f};
  radiosity::View3DControl control;
  control.enclosure = true;

  const std::string text = cli::view3d_output(m, emissivity, control, "View3D", "3.2");
  CHECK(text ==
        "View3D 3.2 0 1 0 3" + std::string(12, ' ') + "\n"  // padded to 30 characters
        "1 2 0.5\n"
        "0.000000 0.250000 0.125000\n"
        "0.125000 0.000000 0.333333\n"
        "0.250000 0.500000 0.000000\n"
        "0.900 0.500 1.000\n");
  // Our own name by default, still two words and a 30-character header.
  const std::string ours = cli::view3d_output(m, emissivity, control);
  CHECK(ours.rfind("radiosity " RADIOSITY_VERSION_STRING " 0 1 0 3", 0) == 0);
  CHECK(ours.find('\n') == 30);

  control.output_format = 1;
  control.script_f = true;
  const std::string binary = cli::view3d_output(m, emissivity, control, "View3D", "3.2");
  REQUIRE(binary.size() == 32 + 4 * (3 + 9 + 3));
  CHECK(binary.substr(0, 32) == "View3D 3.2 1 1 1 3" + std::string(12, ' ') + "\r\n");
  auto float_at = [&](std::size_t index) {
    std::uint32_t u = 0;
    for (int b = 0; b < 4; ++b) u |= static_cast<std::uint32_t>(static_cast<unsigned char>(binary[32 + 4 * index + b])) << (8 * b);
    float f = 0.0f;
    std::memcpy(&f, &u, sizeof f);
    return f;
  };
  CHECK(float_at(1) == 2.0f);                 // area of surface 2
  CHECK(float_at(3 + 1 * 3 + 2) == 1.0f / 3.0f);  // F(2 -> 3)
  CHECK(float_at(3 + 9 + 0) == 0.9f);         // emissivity of surface 1

  control.output_format = 2;
  CHECK_THROWS_WITH_AS(cli::view3d_output(m, emissivity, control), doctest::Contains("out=2 is not written"), Error);
  control.output_format = 0;
  CHECK_THROWS_AS(cli::view3d_output(m, {0.9f}, control), Error);
  m.columns[1] = 7;
  CHECK_THROWS_WITH_AS(cli::view3d_output(m, emissivity, control), doctest::Contains("column 7 of row 0"), Error);
}

TEST_CASE("view3d output emissivities: per polygon and area-weighted per group from the scene's materials") {
  const radiosity::Scene s = load(kData / "plates.vs3").scene;
  radiosity::ViewFactorMatrix polygons;
  polygons.level = radiosity::ViewFactorLevel::polygon;
  polygons.ids = {0, 1, 2};
  const std::vector<float> e = cli::view3d_emissivities(s, polygons);
  REQUIRE(e.size() == 3);
  CHECK(e[0] == doctest::Approx(0.8));
  CHECK(e[2] == doctest::Approx(1.0));

  const radiosity::Scene c = load(kData / "combine.vs3").scene;
  radiosity::ViewFactorMatrix groups;
  groups.level = radiosity::ViewFactorLevel::group;
  groups.ids = {0, 1};
  const std::vector<float> g = cli::view3d_emissivities(c, groups);
  REQUIRE(g.size() == 2);
  CHECK(g[0] == doctest::Approx(0.9));
  CHECK(g[1] == doctest::Approx(0.7));

  radiosity::ViewFactorMatrix elements;
  elements.level = radiosity::ViewFactorLevel::element;
  CHECK_THROWS_AS(cli::view3d_emissivities(c, elements), Error);
}

}  // TEST_SUITE
