// load_scene() on OBJ/MTL fixtures in tests/data: groups, material mapping, triangulation
// warnings, the forgiving policy (what a renderer steps over is fixed with one aggregated
// warning, or an Error under LoadOptions::strict), and an Error naming the file and the line
// for every kind of input that cannot mean anything.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <doctest/doctest.h>

#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"

namespace {

namespace fs = std::filesystem;
using radiosity::Error;
using radiosity::ErrorCode;
using radiosity::Rgb;

const fs::path kData = RADIOSITY_TEST_DATA;
const fs::path kTmp = RADIOSITY_TEST_TMP;
constexpr float kPi = 3.14159265358979323846f;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Loads a file that must fail (`strict`: under LoadOptions::strict); returns the error.
Error load_error(const fs::path& path, bool strict = false) {
  try {
    radiosity::LoadOptions options;
    options.strict = strict;
    radiosity::load_scene(path, options);
  } catch (const Error& e) {
    return e;
  }
  FAIL("load_scene(" << path.string() << ") did not throw");
  return Error(ErrorCode::internal, "");
}

/// Checks code, and that the message names `file` and "file:line:".
void check_error(const fs::path& path, ErrorCode code, const std::string& file, int line, const std::string& problem,
                 bool strict = false) {
  Error e = load_error(path, strict);
  INFO("message: " << e.what());
  CHECK(e.code() == code);
  CHECK(contains(e.what(), file + ":" + std::to_string(line) + ":"));
  CHECK(contains(e.what(), problem));
}

fs::path write_tmp(const std::string& name, const std::string& text) {
  fs::create_directories(kTmp);
  const fs::path p = kTmp / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

bool near(const Rgb& a, const Rgb& b, float eps = 1e-5f) {
  return std::fabs(a.x - b.x) <= eps && std::fabs(a.y - b.y) <= eps && std::fabs(a.z - b.z) <= eps;
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("two quads keep o/g names as groups - Kd as reflectance and pi*Ke as emission") {
  radiosity::Scene s = radiosity::load_scene(kData / "two_quads.obj");
  REQUIRE(s.polygons().size() == 2);
  REQUIRE(s.groups().size() == 2);
  CHECK(s.groups()[0] == "floor");
  CHECK(s.groups()[1] == "light");
  CHECK(s.warnings().empty());

  const radiosity::Polygon& floor = s.polygons()[0];
  CHECK(floor.vertices.size() == 4);  // not triangulated
  CHECK(floor.area == doctest::Approx(1.0));
  CHECK(near(floor.normal, Rgb(0, 1, 0)));
  CHECK(s.groups()[floor.group] == "floor");
  const radiosity::Material& white = s.material(floor.material);
  CHECK(white.name == "white");
  CHECK(near(white.reflectance, Rgb(0.8f, 0.7f, 0.6f)));
  CHECK(near(white.emission, Rgb(0.0f)));

  const radiosity::Polygon& light = s.polygons()[1];
  CHECK(near(light.normal, Rgb(0, -1, 0)));
  const radiosity::Material& lamp = s.material(light.material);
  CHECK(lamp.name == "lamp");
  CHECK(near(lamp.reflectance, Rgb(0.78f)));  // "Kd 0.78" means grey
  CHECK(near(lamp.emission, kPi * Rgb(17, 12, 4), 1e-4f));
}

TEST_CASE("MTL Ks - Ns - illum - Tf and Ni map to specular - mirror and glass - and unknown materials get the default grey") {
  radiosity::Scene s = radiosity::load_scene(kData / "materials.obj");
  REQUIRE(s.polygons().size() == 6);
  REQUIRE(s.groups().size() == 1);
  CHECK(s.groups()[0] == "things");
  auto mat = [&](std::size_t polygon) -> const radiosity::Material& {
    return s.material(s.polygons()[polygon].material);
  };

  CHECK(mat(0).name == "default");  // a face before any usemtl
  CHECK(near(mat(0).reflectance, Rgb(0.5f)));

  CHECK(mat(1).name == "mirror");  // illum 3: ideal mirror
  CHECK(near(mat(1).specular, Rgb(0.9f)));
  CHECK(mat(1).specular_exponent == 0.0f);

  CHECK(mat(2).name == "glass");  // illum 7 with Tf and Ni
  CHECK(near(mat(2).transmittance, Rgb(0.9f, 0.95f, 1.0f)));
  CHECK(mat(2).ior == doctest::Approx(1.45));
  // Ks 0.1 tints the Fresnel reflection: no Phong lobe, a dielectric with a reflection tint.
  CHECK(near(mat(2).specular, Rgb(0.0f)));
  REQUIRE(mat(2).brdf != nullptr);
  {
    const float R = radiosity::fresnel_dielectric(1.0f, 1.45f);
    CHECK(near(mat(2).brdf->albedo(glm::vec3(0, 0, 1)), R * Rgb(0.1f) + (1.0f - R) * Rgb(0.9f, 0.95f, 1.0f)));
  }

  CHECK(mat(3).name == "glossy");  // Kd 0.8 + Ks 0.5: Ks scaled to keep Kd + Ks at 0.99
  CHECK(mat(3).specular_exponent == 250.0f);
  CHECK(near(mat(3).reflectance + mat(3).specular, Rgb(0.99f)));

  CHECK(mat(4).name == "extra_red");  // from the second file of the mtllib line
  CHECK(near(mat(4).reflectance, Rgb(0.6f, 0.1f, 0.1f)));
  CHECK(s.polygons()[4].vertices.size() == 4);  // negative (relative) indices

  CHECK(mat(5).name == "default");  // usemtl nosuch
  CHECK(s.polygons()[5].material == s.polygons()[0].material);

  REQUIRE(s.warnings().size() == 2);
  CHECK(contains(s.warnings()[0], "materials.mtl:19:"));
  CHECK(contains(s.warnings()[0], "glossy"));
  CHECK(contains(s.warnings()[1], "materials.obj:19:"));
  CHECK(contains(s.warnings()[1], "nosuch"));
}

TEST_CASE("non-planar and non-convex faces are triangulated with a warning naming file and line") {
  radiosity::Scene s = radiosity::load_scene(kData / "cornell_like.obj");
  REQUIRE(s.materials().size() == 1);
  CHECK(s.materials()[0].name == "default");
  CHECK(near(s.materials()[0].reflectance, Rgb(0.5f)));
  CHECK(s.groups().size() == 6);
  // One warning for the kind, naming the first face and the others' lines.
  REQUIRE(s.warnings().size() == 1);
  INFO(s.warnings()[0]);
  CHECK(contains(s.warnings()[0], "cornell_like.obj:17:"));
  CHECK(contains(s.warnings()[0], "back_wall"));
  CHECK(contains(s.warnings()[0], "2 in all; also at "));
  CHECK(contains(s.warnings()[0], "cornell_like.obj:29"));

  // No geometry lost: the L-shaped shelf keeps its area (0.75) as triangles.
  const radiosity::GroupId shelf = *s.find_group("shelf");
  double shelf_area = 0.0;
  for (const radiosity::Polygon& p : s.polygons())
    if (p.group == shelf) {
      CHECK(p.vertices.size() == 3);
      shelf_area += p.area;
    }
  CHECK(shelf_area == doctest::Approx(0.75));
}

TEST_CASE("a UTF-8 byte order mark does not hide the first vertex") {
  radiosity::Scene s = radiosity::load_scene(write_tmp("bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  REQUIRE(s.polygons().size() == 1);
  CHECK(s.polygons()[0].area == doctest::Approx(0.5));
}

TEST_CASE("a face with more than 255 vertices stays one polygon") {
  // tinyobjloader, which read OBJ files before, counted face vertices in an unsigned char.
  std::string obj = "# a 300-gon, by absolute and by relative indices\n";
  const int n = 300;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * 3.14159265358979323846 * i / n;
    obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  std::string relative = "f";
  obj += "f";
  for (int i = 1; i <= n; ++i) {
    obj += " " + std::to_string(i);
    relative += " " + std::to_string(i - n - 1);
  }
  obj += "\n" + relative + "\n";
  radiosity::Scene s = radiosity::load_scene(write_tmp("polygon300.obj", obj));
  REQUIRE(s.polygons().size() == 2);
  CHECK(s.warnings().empty());
  for (const radiosity::Polygon& p : s.polygons()) {
    CHECK(p.vertices.size() == 300);
    CHECK(p.area == doctest::Approx(3.14159).epsilon(1e-3));
  }
  CHECK(s.polygons()[0].vertices == s.polygons()[1].vertices);
}

TEST_CASE("g and o name groups as before - faces before any name are in group default") {
  // Each statement is followed by one face; the comment says the group that face is in.
  const char* statements[][2] = {
      {"", "default"},                        // faces before any g or o
      {"g a b", "a b"},                       // several names: one group, joined by a space
      {"g  a\t b  ", "a b"},                  // ... by one space whatever the blanks
      {"g ", "default"},                      // g with no name: the unnamed group
      {"g a", "a"},
      {"g", "a"},                             // a bare g, not even a blank after it: no change
      {"o name with  spaces ", "name with  spaces"},  // o takes its whole line, inner blanks kept
      {"o", "name with  spaces"},             // a bare o: no change
      {"o ", "default"},
      {"g a # c", "a # c"},                   // '#' starts a comment only at the start of a line
      {"o\tx", "x"},
  };
  std::string obj;
  int v = 0;
  for (const auto& st : statements) {
    if (*st[0] != '\0') obj += std::string(st[0]) + "\n";
    obj += "v 0 0 " + std::to_string(v) + "\nv 1 0 " + std::to_string(v) + "\nv 0 1 " + std::to_string(v) + "\n";
    obj += "f -3 -2 -1\n";
    ++v;
  }
  radiosity::Scene s = radiosity::load_scene(write_tmp("group_names.obj", obj));
  REQUIRE(s.polygons().size() == std::size(statements));
  for (std::size_t i = 0; i < std::size(statements); ++i) {
    INFO("statement '" << statements[i][0] << "'");
    CHECK(s.groups()[s.polygons()[i].group] == statements[i][1]);
  }
  CHECK(s.groups().size() == 6);  // default, "a b", "a", "name with  spaces", "a # c", "x"
}

TEST_CASE("a usemtl before any mtllib line names no material - as tinyobjloader read it") {
  write_tmp("late_library.mtl", "newmtl red\nKd 0.6 0.1 0.1\n");
  radiosity::Scene s = radiosity::load_scene(write_tmp(
      "late_library.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nmtllib late_library.mtl\nf 1 2 3\nusemtl red\nf 1 2 3\n"));
  REQUIRE(s.polygons().size() == 3);
  CHECK(s.material(s.polygons()[0].material).name == "default");
  CHECK(s.material(s.polygons()[1].material).name == "default");
  CHECK(s.material(s.polygons()[2].material).name == "red");
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], "late_library.obj:4: material 'red' is not defined"));
}

TEST_CASE("CRLF and CR line ends give the same scene - with the same line numbers - as LF") {
  // Groups, materials, a short face, a triangulated and a degenerate face, lines: every kind
  // of statement whose line a message names.
  write_tmp("line_ends.mtl", "newmtl white\nKd 1 1 1\n");
  const std::string lf =
      "mtllib line_ends.mtl\n# a comment\n\nv 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0\nv 2 0 0\n"
      "g floor\nusemtl white\nf 1 2 3 4\nf 1 2\n\no second one\nf 1 2 5\nl 1 2\nusemtl none\nf 1 2 3\n";
  std::string crlf, cr;
  for (char c : lf) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  const radiosity::Scene a = radiosity::load_scene(write_tmp("line_ends.obj", lf));
  REQUIRE(a.polygons().size() == 3);  // the non-planar quad as two triangles, and the triangle
  REQUIRE(a.warnings().size() == 6);
  CHECK(contains(a.warnings()[0], "line_ends.obj:12: face has 2 vertices"));
  CHECK(contains(a.warnings()[1], "line_ends.obj:16: line/point element"));
  CHECK(contains(a.warnings()[2], "line_ends.mtl:2: material 'white': Kd"));
  CHECK(contains(a.warnings()[3], "line_ends.obj:11: face (group 'floor'): non-planar"));
  CHECK(contains(a.warnings()[4], "line_ends.obj:15: face (group 'second one'): degenerate"));
  CHECK(contains(a.warnings()[5], "line_ends.obj:17: material 'none'"));
  for (const std::string& text : {crlf, cr}) {
    const radiosity::Scene b = radiosity::load_scene(write_tmp("line_ends.obj", text));
    CHECK(b.groups() == a.groups());
    CHECK(b.warnings() == a.warnings());
    REQUIRE(b.polygons().size() == a.polygons().size());
    for (std::size_t i = 0; i < a.polygons().size(); ++i) {
      CHECK(b.polygons()[i].vertices == a.polygons()[i].vertices);
      CHECK(b.polygons()[i].group == a.polygons()[i].group);
      CHECK(b.material(b.polygons()[i].material).name == a.material(a.polygons()[i].material).name);
    }
  }
}

TEST_CASE("a backslash at the end of a line does not continue it") {
  // OBJ allows "\" as a line continuation; this reader (as tinyobjloader before it) does not,
  // so the backslash is one more word of its line.
  check_error(write_tmp("continued_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n3\n"), ErrorCode::parse_error,
              "continued_face.obj", 4, "face corner '\\' has no valid vertex index");
  radiosity::Scene s = radiosity::load_scene(
      write_tmp("continued_lines.obj", "v 0 0 0 \\\n9 9\nv 1 0 0\nv 0 1 0\ng a \\\nb\nf 1 2 3\n"));
  REQUIRE(s.polygons().size() == 1);
  CHECK(s.polygons()[0].vertices[0] == glm::vec3(0.0f));
  CHECK(s.groups()[s.polygons()[0].group] == "a \\");
}

TEST_CASE("a missing OBJ file or an unsupported extension is an error naming the path") {
  Error missing = load_error(kData / "no_such_file.obj");
  CHECK(missing.code() == ErrorCode::file_not_found);
  CHECK(contains(missing.what(), "no_such_file.obj"));

  Error ext = load_error(kData / "scene.abc");
  CHECK(ext.code() == ErrorCode::invalid_argument);
  CHECK(contains(ext.what(), "scene.abc"));
  CHECK(contains(ext.what(), "'.abc'"));
}

TEST_CASE("an mtllib line naming one file with spaces (as Blender writes it) reads that file; two files still split") {
  write_tmp("room mm.mtl", "newmtl plaster\nKd 0.7 0.7 0.7\n");
  const radiosity::Scene s = radiosity::load_scene(
      write_tmp("spaced_library.obj", "mtllib room mm.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl plaster\nf 1 2 3\n"));
  CHECK(s.warnings().empty());
  CHECK(near(s.material(s.polygons()[0].material).reflectance, Rgb(0.7f)));
  // Where the whole line is no file, its words are files, as before: "room" and "nosuch.mtl".
  const radiosity::Scene split = radiosity::load_scene(
      write_tmp("split_library.obj", "mtllib room nosuch.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  REQUIRE(!split.warnings().empty());
  CHECK(contains(split.warnings()[0], "material library 'room' not found"));
}

TEST_CASE("a missing MTL file gives the default grey with a warning - an error naming the mtllib line under strict") {
  radiosity::Scene s = radiosity::load_scene(kData / "missing_mtl.obj");
  REQUIRE(!s.polygons().empty());
  for (const radiosity::Polygon& p : s.polygons()) CHECK(near(s.material(p.material).reflectance, Rgb(0.5f)));
  REQUIRE(!s.warnings().empty());
  CHECK(contains(s.warnings()[0], "missing_mtl.obj:3: material library 'does_not_exist.mtl' not found"));
  check_error(kData / "missing_mtl.obj", ErrorCode::file_not_found, "missing_mtl.obj", 3, "does_not_exist.mtl", true);
}

TEST_CASE("an out-of-range vertex index is an error naming file and line") {
  check_error(kData / "bad_index.obj", ErrorCode::parse_error, "bad_index.obj", 8, "out of range");
  check_error(write_tmp("negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n"), ErrorCode::parse_error,
              "negative_index.obj", 4, "out of range");
}

TEST_CASE("a face corner of more than 3 indices is an error naming file and line") {
  check_error(write_tmp("four_indices.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1/1 2 3\n"),
              ErrorCode::parse_error, "four_indices.obj", 6, "face corner '1/1/1/1' has more than 3 indices");
  check_error(write_tmp("trailing_slash.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1 2/1/1/ 3\n"),
              ErrorCode::parse_error, "trailing_slash.obj", 6, "face corner '2/1/1/'");
}

TEST_CASE("a zero vertex index is an error naming file and line") {
  check_error(kData / "zero_index.obj", ErrorCode::parse_error, "zero_index.obj", 5, "index 0");
  check_error(write_tmp("zero_normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//0 3//1\n"),
              ErrorCode::parse_error, "zero_normal.obj", 5, "normal index");
}

TEST_CASE("a NaN or infinite coordinate is an error naming file and line") {
  check_error(kData / "nan_vertex.obj", ErrorCode::parse_error, "nan_vertex.obj", 4, "'nan'");
  check_error(kData / "inf_vertex.obj", ErrorCode::parse_error, "inf_vertex.obj", 3, "'1e39'");
  check_error(write_tmp("short_vertex.obj", "v 0 0 0\nv 1 0\n"), ErrorCode::parse_error, "short_vertex.obj", 2,
              "coordinates");
}

TEST_CASE("zero-area faces are dropped with one warning naming the first line and counting all - an error under strict") {
  radiosity::Scene one = radiosity::load_scene(kData / "zero_area.obj");
  REQUIRE(one.warnings().size() == 1);
  CHECK(contains(one.warnings()[0], "zero_area.obj:9: face (group"));
  CHECK(contains(one.warnings()[0], "degenerate"));
  CHECK(contains(one.warnings()[0], "dropped"));
  check_error(kData / "zero_area.obj", ErrorCode::invalid_scene, "zero_area.obj", 9, "degenerate", true);

  // As an exporter writes them: a good quad and seven degenerate triangles among it.
  std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\n";
  for (int k = 0; k < 7; ++k) obj += "f 1 2 5\n";  // collinear: zero area
  radiosity::Scene many = radiosity::load_scene(write_tmp("many_degenerate.obj", obj));
  REQUIRE(many.polygons().size() == 1);
  CHECK(many.polygons()[0].area == doctest::Approx(1.0));
  REQUIRE(many.warnings().size() == 1);
  INFO(many.warnings()[0]);
  CHECK(contains(many.warnings()[0], "many_degenerate.obj:7:"));
  CHECK(contains(many.warnings()[0], "(7 in all; also at "));
  CHECK(contains(many.warnings()[0], "many_degenerate.obj:8, "));
  CHECK(contains(many.warnings()[0], ", ...)"));

  // Only degenerate faces: nothing to light, an error.
  Error none = load_error(write_tmp("only_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"));
  CHECK(contains(none.what(), "no faces"));
}

TEST_CASE("faces with fewer than 3 vertices are dropped with a warning - an error naming file and line under strict") {
  radiosity::Scene s = radiosity::load_scene(kData / "short_face.obj");
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], "short_face.obj:5: face has 2 vertices"));
  check_error(kData / "short_face.obj", ErrorCode::parse_error, "short_face.obj", 5, "2 vertices", true);
  check_error(write_tmp("empty_face.obj", "v 0 0 0\nf\n"), ErrorCode::parse_error, "empty_face.obj", 2, "0 vertices",
              true);
}

TEST_CASE("a reflectance of 1 or more in an MTL is clamped to 0.99 with a warning - an error naming the MTL line under strict") {
  radiosity::Scene s = radiosity::load_scene(kData / "kd_too_high.obj");
  bool found = false;
  for (const radiosity::Material& m : s.materials())
    if (m.name == "hot") {
      found = true;
      for (int c = 0; c < 3; ++c) CHECK(m.reflectance[c] <= 0.99f);
    }
  CHECK(found);
  REQUIRE(s.warnings().size() == 1);
  CHECK(contains(s.warnings()[0], "kd_too_high.mtl:4: material 'hot': Kd"));
  CHECK(contains(s.warnings()[0], "clamped to"));

  check_error(kData / "kd_too_high.obj", ErrorCode::invalid_scene, "kd_too_high.mtl", 4, "'hot'", true);
  Error e = load_error(kData / "kd_too_high.obj", true);
  CHECK(contains(e.what(), "Kd"));
  const std::string obj = "mtllib MTL\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl bad\nf 1 2 3\n";
  auto with_mtl = [&](const std::string& name, const std::string& mtl) {
    write_tmp(name + ".mtl", mtl);
    return write_tmp(name + ".obj", obj.substr(0, 7) + name + ".mtl" + obj.substr(10));
  };
  // "Kd 1 1 1", the most common white of exported files.
  radiosity::Scene white = radiosity::load_scene(with_mtl("kd_one", "newmtl bad\n\nKd 1 1 1\n"));
  CHECK(near(white.material(white.polygons()[0].material).reflectance, Rgb(0.99f)));
  check_error(with_mtl("kd_one", "newmtl bad\n\nKd 1 1 1\n"), ErrorCode::invalid_scene, "kd_one.mtl", 3, "'bad'", true);
  // NaN cannot mean anything: an error either way.
  check_error(with_mtl("kd_nan", "newmtl bad\nKd 0.5 nan 0.5\n"), ErrorCode::parse_error, "kd_nan.mtl", 2, "'nan'");
  radiosity::Scene negative = radiosity::load_scene(with_mtl("ke_negative", "newmtl bad\nKd 0.5\nKe -1 0 0\n"));
  CHECK(near(negative.material(negative.polygons()[0].material).emission, Rgb(0.0f)));
  check_error(with_mtl("ke_negative", "newmtl bad\nKd 0.5\nKe -1 0 0\n"), ErrorCode::invalid_scene,
              "ke_negative.mtl", 3, "Ke", true);
}

TEST_CASE("an illum that names no model (0 to 10) is ignored with a warning - an error naming the MTL line under strict") {
  // 99999999999999999 came from the OBJ fuzzer: cast to int it was undefined behaviour.
  const std::string obj = "mtllib illum_range.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl shiny\nf 1 2 3\n";
  for (const char* illum : {"99999999999999999", "-3", "11"}) {
    CAPTURE(illum);
    write_tmp("illum_range.mtl", std::string("newmtl shiny\nKd 0.5\nKs 0.25\nNs 20\nillum ") + illum + "\n");
    const fs::path path = write_tmp("illum_range.obj", obj);
    const radiosity::Scene s = radiosity::load_scene(path);
    // As without illum: Ks with Ns is a Phong lobe; no mirror, no glass.
    const radiosity::Material& m = s.material(s.polygons()[0].material);
    CHECK(near(m.reflectance, Rgb(0.5f)));
    CHECK(near(m.specular, Rgb(0.25f)));
    CHECK(m.specular_exponent == doctest::Approx(20.0f));
    CHECK(near(m.transmittance, Rgb(0.0f)));
    REQUIRE(s.warnings().size() == 1);
    CHECK(contains(s.warnings()[0], "illum_range.mtl:5: material 'shiny': illum"));
    CHECK(contains(s.warnings()[0], "no illumination model"));
    check_error(path, ErrorCode::invalid_scene, "illum_range.mtl", 5, "illum", true);
  }
}

TEST_CASE("line numbers count comments - blank lines and CRLF or CR line ends") {
  check_error(kData / "line_numbers.obj", ErrorCode::parse_error, "line_numbers.obj", 23, "'99'");
  std::ifstream in(kData / "line_numbers.obj", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string crlf, cr;
  for (char c : text) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  check_error(write_tmp("line_numbers_crlf.obj", crlf), ErrorCode::parse_error, "line_numbers_crlf.obj", 23, "'99'");
  check_error(write_tmp("line_numbers_cr.obj", cr), ErrorCode::parse_error, "line_numbers_cr.obj", 23, "'99'");
  check_error(write_tmp("line_numbers_bom.obj", "\xEF\xBB\xBF" + crlf), ErrorCode::parse_error, "line_numbers_bom.obj",
              23, "'99'");
}

}  // TEST_SUITE("io")
