#include <doctest/doctest.h>

#include <string>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// A closed unit box of diffuse emitters plus, if `extra` is given, one inner quad of it.
rad::Scene box_with(const rad::Material* extra) {
  rad::Material wall;
  wall.emission = rad::Rgb(1.0f);
  rad::Scene scene = test::closed_box(wall);
  if (extra) {
    const rad::MaterialId id = scene.add_material(*extra);
    rad::add_quad(scene, {0.25f, 0.25f, 0.5f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, id);
  }
  return scene;
}

}  // namespace

TEST_SUITE("render") {
  TEST_CASE("choose_render_mode: the Cornell box is diffuse and its specular variants need the two-pass view") {
    const rad::Scene diffuse = rad::cornell_box();
    CHECK(rad::choose_render_mode(diffuse) == rad::RenderMode::radiosity);
    CHECK_FALSE(rad::needs_extended_first_pass(diffuse));
    for (rad::CornellSpecular blocks :
         {rad::CornellSpecular::mirror_and_glass, rad::CornellSpecular::mirror, rad::CornellSpecular::glass}) {
      const rad::Scene s = rad::cornell_box_specular(blocks);
      CHECK(rad::choose_render_mode(s) == rad::RenderMode::two_pass);
      CHECK(rad::needs_extended_first_pass(s));
    }
  }

  TEST_CASE("choose_render_mode: materials that no polygon uses do not count") {
    rad::Scene scene = box_with(nullptr);
    rad::Material mirror;
    mirror.reflectance = rad::Rgb(0.0f);
    mirror.specular = rad::Rgb(0.9f);
    scene.add_material(mirror);
    CHECK(rad::choose_render_mode(scene) == rad::RenderMode::radiosity);
    CHECK_FALSE(rad::needs_extended_first_pass(scene));
  }

  TEST_CASE("choose_render_mode: what counts as diffuse") {
    rad::Material m;
    m.reflectance = rad::Rgb(0.4f);
    SUBCASE("plain Lambertian fields") {
      CHECK(rad::choose_render_mode(box_with(&m)) == rad::RenderMode::radiosity);
    }
    SUBCASE("translucency is carried by pass 1") {
      m.diffuse_transmittance = rad::Rgb(0.3f);
      CHECK(rad::choose_render_mode(box_with(&m)) == rad::RenderMode::radiosity);
    }
    SUBCASE("a Lambertian brdf of its own") {
      m.brdf = rad::make_lambertian(rad::Rgb(0.4f));
      CHECK(rad::choose_render_mode(box_with(&m)) == rad::RenderMode::radiosity);
    }
    SUBCASE("a mix of two Lambertians") {
      m.brdf = rad::make_mix(rad::make_lambertian(rad::Rgb(0.2f)), rad::make_lambertian(rad::Rgb(0.6f)), 0.5f);
      CHECK(rad::choose_render_mode(box_with(&m)) == rad::RenderMode::radiosity);
    }
  }

  TEST_CASE("choose_render_mode: what needs the two-pass view and which of it the extended first pass carries") {
    rad::Material m;
    m.reflectance = rad::Rgb(0.3f);
    bool extended = false;
    SUBCASE("an ideal mirror") {
      m.specular = rad::Rgb(0.0f, 0.0f, 0.5f);
      extended = true;
    }
    SUBCASE("a window") {
      m.reflectance = rad::Rgb(0.0f);
      m.transmittance = rad::Rgb(0.9f);
      m.ior = 1.0f;
      extended = true;
    }
    SUBCASE("glass") {
      m.reflectance = rad::Rgb(0.0f);
      m.transmittance = rad::Rgb(0.9f);
      extended = true;
    }
    SUBCASE("a glossy Phong lobe") {
      m.specular = rad::Rgb(0.3f);
      m.specular_exponent = 50.0f;
    }
    SUBCASE("a Phong brdf of its own") {
      m.brdf = rad::make_phong(rad::Rgb(0.3f), rad::Rgb(0.3f), 20.0f);
    }
    SUBCASE("a mirror brdf of its own") {
      m.brdf = rad::make_mirror(rad::Rgb(0.9f));
    }
    SUBCASE("a Lambertian mixed with a mirror") {
      m.brdf = rad::make_mix(rad::make_lambertian(rad::Rgb(0.5f)), rad::make_mirror(rad::Rgb(0.9f)), 0.3f);
    }
    const rad::Scene scene = box_with(&m);
    CHECK(rad::choose_render_mode(scene) == rad::RenderMode::two_pass);
    CHECK(rad::needs_extended_first_pass(scene) == extended);
  }

  TEST_CASE("prepare_two_pass: monte-carlo and specular depth >= 1 for mirrors and glass and nothing otherwise") {
    rad::SolveOptions o;
    o.form_factors.method = rad::FormFactorMethod::hemicube;
    rad::prepare_two_pass(rad::cornell_box(), o);
    CHECK(o.form_factors.method == rad::FormFactorMethod::hemicube);
    CHECK(o.form_factors.specular_depth == 0);

    const rad::Scene specular = rad::cornell_box_specular();
    rad::prepare_two_pass(specular, o);
    CHECK(o.form_factors.method == rad::FormFactorMethod::monte_carlo);
    CHECK(o.form_factors.specular_depth == 1);
    o.form_factors.specular_depth = 3;
    rad::prepare_two_pass(specular, o);
    CHECK(o.form_factors.specular_depth == 3);
  }

  TEST_CASE("to_string(RenderMode) gives the CLI's spellings") {
    CHECK(std::string(rad::to_string(rad::RenderMode::automatic)) == "auto");
    CHECK(std::string(rad::to_string(rad::RenderMode::radiosity)) == "radiosity");
    CHECK(std::string(rad::to_string(rad::RenderMode::two_pass)) == "two-pass");
    CHECK(std::string(rad::to_string(rad::RenderMode::path)) == "path");
  }
}
