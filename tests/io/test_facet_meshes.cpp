// Facet meshes through load_scene() (the Assimp reader): the STL (ASCII and binary) and PLY
// fixtures tests/data/facets.* hold facets in different orientations, and each must become a
// polygon with the facet's area and the normal of its winding, in file order: what thermal
// users who bring STL geometry to view factors (as to View3D) rely on.
#include <cmath>
#include <filesystem>
#include <string>

#include <doctest/doctest.h>

#include "radiosity/io.hpp"
#include "support/loading.hpp"

namespace {

namespace fs = std::filesystem;
using test::near;

const fs::path kData = RADIOSITY_TEST_DATA;

/// The three facets of facets.stl: area and unit normal (right-hand rule of their corners).
struct Facet {
  double area;
  glm::vec3 normal;
};
const float kThird = 0.57735026f;  // 1 / sqrt(3)
const Facet kFacets[3] = {{2.0, {0, 0, 1}}, {0.5, {-1, 0, 0}}, {0.8660254, {kThird, kThird, kThird}}};

}  // namespace

TEST_SUITE("io") {

TEST_CASE("STL ASCII and binary facets load as polygons with their areas and normals in file order") {
  for (const char* name : {"facets.stl", "facets_binary.stl"}) {
    CAPTURE(name);
    const radiosity::Scene s = test::load(kData / name, true);
    CHECK(s.warnings().empty());
    REQUIRE(s.polygons().size() == 3);
    double total = 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      CAPTURE(i);
      const radiosity::Polygon& p = s.polygons()[i];
      CHECK(p.vertices.size() == 3);
      CHECK(p.area == doctest::Approx(kFacets[i].area).epsilon(1e-6));
      CHECK(near(p.normal, kFacets[i].normal, 1e-5f));
      total += p.area;
    }
    CHECK(s.total_area() == doctest::Approx(total));
  }
  // Both files hold the same corners, bit for bit.
  const radiosity::Scene ascii = test::load(kData / "facets.stl");
  const radiosity::Scene binary = test::load(kData / "facets_binary.stl");
  for (std::size_t i = 0; i < 3; ++i) CHECK(ascii.polygons()[i].vertices == binary.polygons()[i].vertices);
}

TEST_CASE("PLY facets load as polygons with their areas and normals - a quad face as two triangles") {
  const radiosity::Scene s = test::load(kData / "facets.ply", true);
  CHECK(s.warnings().empty());
  REQUIRE(s.polygons().size() == 5);
  for (std::size_t i = 0; i < 3; ++i) {
    CAPTURE(i);
    CHECK(s.polygons()[i].area == doctest::Approx(kFacets[i].area).epsilon(1e-6));
    CHECK(near(s.polygons()[i].normal, kFacets[i].normal, 1e-5f));
  }
  // The unit square at z = 3, wound to face -z.
  CHECK(s.polygons()[3].area + s.polygons()[4].area == doctest::Approx(1.0));
  CHECK(near(s.polygons()[3].normal, {0, 0, -1}));
  CHECK(near(s.polygons()[4].normal, {0, 0, -1}));
  for (std::size_t i = 3; i < 5; ++i)
    for (const glm::vec3& v : s.polygons()[i].vertices) CHECK(v.z == 3.0f);
}

}  // TEST_SUITE
