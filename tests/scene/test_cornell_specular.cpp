// The specular Cornell box: the built-in variants share cornell_box()'s geometry, and the shipped
// OBJ/MTL (examples/scenes/cornell_specular.*) is the same scene.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

const char* const kSpecularObj = RADIOSITY_TEST_DATA "/../../examples/scenes/cornell_specular.obj";

const rad::Material& material_of_group(const rad::Scene& scene, const std::string& group) {
  const auto g = scene.find_group(group);
  REQUIRE(g);
  for (const rad::Polygon& p : scene.polygons())
    if (p.group == *g) return scene.material(p.material);
  FAIL("no polygon in group " << group);
  return scene.materials().front();
}

void check_same_material(const rad::Material& a, const rad::Material& b) {
  CAPTURE(a.name);
  CHECK(a.name == b.name);
  for (int c = 0; c < 3; ++c) {
    CHECK(a.reflectance[c] == doctest::Approx(b.reflectance[c]).epsilon(1e-6));
    CHECK(a.emission[c] == doctest::Approx(b.emission[c]).epsilon(1e-6));
    CHECK(a.specular[c] == doctest::Approx(b.specular[c]).epsilon(1e-6));
    CHECK(a.transmittance[c] == doctest::Approx(b.transmittance[c]).epsilon(1e-6));
    CHECK(a.diffuse_transmittance[c] == doctest::Approx(b.diffuse_transmittance[c]).epsilon(1e-6));
  }
  CHECK(a.specular_exponent == b.specular_exponent);
  CHECK(a.ior == doctest::Approx(b.ior).epsilon(1e-6));
  CHECK(a.two_sided == b.two_sided);
  CHECK(a.brdf == b.brdf);
}

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("cornell_box_specular keeps the Cornell box's geometry and changes only the blocks' materials") {
    const rad::Scene plain = rad::cornell_box();
    const struct {
      rad::CornellSpecular blocks;
      const char* tall;
      const char* short_block;
    } variants[] = {{rad::CornellSpecular::mirror_and_glass, "mirror", "glass"},
                    {rad::CornellSpecular::mirror, "mirror", "white"},
                    {rad::CornellSpecular::glass, "white", "glass"}};
    for (const auto& v : variants) {
      CAPTURE(static_cast<int>(v.blocks));
      const rad::Scene s = rad::cornell_box_specular(v.blocks);
      REQUIRE(s.polygons().size() == plain.polygons().size());
      CHECK(s.groups() == plain.groups());
      CHECK(s.camera().eye == plain.camera().eye);
      CHECK(s.camera().fov_deg == plain.camera().fov_deg);
      for (std::size_t i = 0; i < s.polygons().size(); ++i) {
        const rad::Polygon &p = s.polygons()[i], &q = plain.polygons()[i];
        CHECK(p.vertices == q.vertices);
        CHECK(p.group == q.group);
        const std::string& group = s.groups()[p.group];
        const rad::Material& m = s.material(p.material);
        if (group == "tall_block") CHECK(m.name == v.tall);
        else if (group == "short_block") CHECK(m.name == v.short_block);
        else check_same_material(m, plain.material(q.material));
      }
    }
    const rad::Scene both = rad::cornell_box_specular();
    const rad::Material& mirror = material_of_group(both, "tall_block");
    CHECK(mirror.reflectance == rad::Rgb(0.0f));
    CHECK(mirror.specular == rad::Rgb(0.95f));
    CHECK(mirror.specular_exponent == 0.0f);
    const rad::Material& glass = material_of_group(both, "short_block");
    CHECK(glass.reflectance == rad::Rgb(0.0f));
    CHECK(glass.transmittance == rad::Rgb(1.0f));
    CHECK(glass.ior == 1.5f);
    // The glass block is closed by the floor: its 5 faces plus the floor enclose it.
    CHECK(rad::make_brdf(glass)->is_delta());
    CHECK(rad::make_brdf(mirror)->is_delta());
  }

  TEST_CASE("examples/scenes/cornell_specular.obj loads as cornell_box_specular()") {
    const rad::Scene built_in = rad::cornell_box_specular();
    const rad::Scene loaded = rad::load_scene(kSpecularObj);
    CHECK(loaded.warnings().empty());
    REQUIRE(loaded.polygons().size() == built_in.polygons().size());
    CHECK(loaded.groups().size() == built_in.groups().size());
    for (const std::string& group : built_in.groups()) {
      CAPTURE(group);
      const auto gb = built_in.find_group(group), gl = loaded.find_group(group);
      REQUIRE(gl);
      int count_b = 0, count_l = 0;
      double area_b = 0.0, area_l = 0.0;
      for (const rad::Polygon& p : built_in.polygons())
        if (p.group == *gb) ++count_b, area_b += p.area;
      for (const rad::Polygon& p : loaded.polygons())
        if (p.group == *gl) ++count_l, area_l += p.area;
      CHECK(count_l == count_b);
      CHECK(area_l == doctest::Approx(area_b).epsilon(1e-6));
      check_same_material(material_of_group(loaded, group), material_of_group(built_in, group));
    }
    // Polygon by polygon: the same vertices (the file prints each float so that it reads back
    // exactly) and therefore the same facing.
    for (std::size_t i = 0; i < built_in.polygons().size(); ++i) {
      const rad::Polygon &p = built_in.polygons()[i], &q = loaded.polygons()[i];
      CAPTURE(i);
      CHECK(loaded.groups()[q.group] == built_in.groups()[p.group]);
      CHECK(q.vertices == p.vertices);
      CHECK(glm::dot(q.normal, p.normal) > 0.9999f);
    }
  }
}
