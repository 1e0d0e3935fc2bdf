// choose_camera(): the camera the renderers take for a scene without one.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

bool inside(const rad::Bounds& b, const glm::vec3& p) {
  return p.x > b.lower.x && p.x < b.upper.x && p.y > b.lower.y && p.y < b.upper.y && p.z > b.lower.z &&
         p.z < b.upper.z;
}

}  // namespace

TEST_SUITE("render") {
  TEST_CASE("choose_camera: the scene's own, the view from outside for an object, a view from inside for a closed "
            "room - whose render is then its radiosity and not black") {
    // A closed box whose walls face its centre, emitting E and reflecting rho: a furnace, whose
    // every wall has B = E / (1 - rho), so every pixel seen from inside shows B / pi. From
    // outside (Scene::camera()'s default view) a camera sees only the walls' backs: black.
    const float E = 1.0f, rho = 0.5f;
    rad::Material wall;
    wall.emission = rad::Rgb(E);
    wall.reflectance = rad::Rgb(rho);
    const rad::Scene room = test::closed_box(wall, glm::vec3(4.0f, 3.0f, 5.0f));
    const rad::CameraChoice chosen = rad::choose_camera(room);
    MESSAGE(chosen.reason);
    CHECK(inside(room.bounds(), chosen.camera.eye));
    CHECK(chosen.reason.find("the scene has none, and from outside") == 0);
    CHECK(chosen.reason.find("inside, at") != std::string::npos);
    CHECK(chosen.reason.find("(100 % of the view lit surfaces; y up: as OBJ and glTF have it)") != std::string::npos);
    CHECK(chosen.camera.up == glm::vec3(0, 1, 0));

    rad::SolveOptions so;
    so.mesh.max_patch_area = 1.0f;
    so.tolerance = 1e-6;
    const rad::Solution sol = rad::solve(room, so);
    rad::RenderOptions ro;
    ro.width = ro.height = 16;
    const rad::Image image = rad::render(room, sol, ro);
    const double expected = E / (1.0 - rho) / 3.14159265358979;
    double worst = 0.0;
    for (const rad::Rgb& p : image.pixels) worst = std::max(worst, std::fabs(p.y - expected) / expected);
    MESSAGE("render from the chosen camera: worst pixel " << worst << " off B / pi");
    // A furnace is uniform: what is left is the form factors' row sums (measured 0.33 %).
    CHECK(worst < 0.01);
    // The two-pass view (nothing specular: the display's image) and the path tracer look from
    // the same chosen camera.
    rad::TwoPassOptions to;
    to.width = to.height = 16;
    to.spp = 4;
    const rad::Image two_pass = rad::render_two_pass(room, sol, to);
    double display_sum = 0.0, two_pass_sum = 0.0;
    for (std::size_t k = 0; k < image.pixels.size(); ++k) {
      display_sum += image.pixels[k].y;
      two_pass_sum += two_pass.pixels[k].y;
    }
    CHECK(two_pass_sum == doctest::Approx(display_sum).epsilon(1e-4));
    rad::PathTraceOptions po;
    po.width = po.height = 16;
    po.spp = 64;
    double traced = 0.0;
    for (const rad::Rgb& p : rad::render_path_traced(room, po).pixels) traced += p.y;
    traced /= 256.0;
    MESSAGE("path traced from the chosen camera: mean pixel " << traced << ", B / pi = " << expected);
    // 16 384 paths of a furnace with rho 0.5: the mean's noise is well under 2 %.
    CHECK(traced == doctest::Approx(expected).epsilon(0.02));

    // The view from outside, which renders used before: black.
    ro.camera = room.camera();
    double outside = 0.0;
    for (const rad::Rgb& p : rad::render(room, sol, ro).pixels) outside += p.y;
    CHECK(outside == 0.0);

    // An object seen from outside (a box whose faces face out): the default view is kept.
    rad::Scene object;
    rad::add_box(object, {0, 0, 0}, {1, 1, 1}, object.add_material(rad::Material{}), "box");
    const rad::CameraChoice framed = rad::choose_camera(object);
    CHECK(framed.reason == "the scene has none: framing its bounds from -z (y up: as OBJ and glTF have it)");
    CHECK(framed.camera.eye == object.camera().eye);

    // Blocks on a ground under a sky (no emitter): their walls see the sky too, so the view
    // from outside is kept.
    rad::Scene blocks;
    const rad::MaterialId grey = blocks.add_material(rad::Material{});
    blocks.add_polygon({{-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}}, grey, "ground");
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j)
        rad::add_box(blocks, {i * 12.0f - 4, 0, j * 12.0f - 4}, {i * 12.0f + 4, 10.0f + 3.0f * ((i + j) & 3), j * 12.0f + 4},
                     grey, "building");
    rad::Light sky;
    sky.type = rad::LightType::sky;
    blocks.add_light(sky);
    // A ground open to the sky: seen from 30 degrees above, framing the blocks.
    CHECK(rad::choose_camera(blocks).reason ==
          "the scene has none: framing what stands on its ground from -z, 30 degrees above (y up: the sky's zenith)");

    // A box open toward +z (the Cornell box as McGuire's OBJ has it, and as glTF's assets face),
    // lit by a lamp under its ceiling: from -z the view shows the back wall's back, so the bounds
    // are framed from +z, through the opening; not from inside, whose camera would stand in the
    // opening, too close to show the room.
    rad::Scene open_box;
    {
      rad::Material white;
      white.reflectance = rad::Rgb(0.7f);
      const rad::Scene closed = test::closed_box(white, glm::vec3(2.0f));
      const rad::MaterialId w = open_box.add_material(white);
      for (const rad::Polygon& p : closed.polygons())
        if (p.normal.z > -0.5f) open_box.add_polygon(p.vertices, w, "wall");  // all but the +z side
      rad::Material lamp;
      lamp.emission = rad::Rgb(10.0f);
      rad::add_quad(open_box, {0.8f, 1.99f, 0.8f}, {0.4f, 0, 0}, {0, 0, 0.4f}, open_box.add_material(lamp), "lamp");
      REQUIRE(open_box.polygons().back().normal.y < -0.99f);
    }
    const rad::CameraChoice through = rad::choose_camera(open_box);
    MESSAGE(through.reason);
    CHECK(through.reason.find("the scene has none, and from -z ") == 0);
    CHECK(through.reason.find("of the view is surfaces no light reaches: framing its bounds from +z (") !=
          std::string::npos);
    CHECK(through.reason.find("; y up: the emitters face down -y)") != std::string::npos);
    CHECK(through.camera.eye.z > open_box.bounds().upper.z);
    CHECK(through.camera.look_at.z == doctest::Approx(1.0f));
    CHECK(through.camera.eye.x == doctest::Approx(1.0f));
    // What it sees is lit: the render through the opening is not black.
    {
      rad::SolveOptions box_solve;
      box_solve.mesh.max_patch_area = 0.25f;
      const rad::Solution box_solution = rad::solve(open_box, box_solve);
      rad::RenderOptions view;
      view.width = view.height = 16;
      view.camera = through.camera;
      int lit = 0;
      for (const rad::Rgb& p : rad::render(open_box, box_solution, view).pixels) lit += p.y > 0.0f;
      CHECK(lit > 256 / 4);
    }

    // A scene with its own camera keeps it.
    rad::Scene with_camera = room;
    rad::Camera own;
    own.eye = {1, 1, 1};
    own.look_at = {2, 1, 3};
    with_camera.set_camera(own);
    const rad::CameraChoice kept = rad::choose_camera(with_camera);
    CHECK(kept.reason == "the scene's camera");
    CHECK(kept.camera.eye == own.eye);
    CHECK(kept.camera.look_at == own.look_at);
  }

  TEST_CASE("choose_camera: a scene with z up (CAD, thermal models) is seen upright, from the side") {
    // A building on a ground at z = 0 under a sky whose zenith is +z.
    rad::Scene city;
    const rad::MaterialId grey = city.add_material(rad::Material{});
    rad::add_quad(city, {-10, -10, 0}, {20, 0, 0}, {0, 20, 0}, grey, "ground");
    rad::add_box(city, {-2, -3, 0}, {2, 3, 6}, grey, "building");
    rad::Light sky;
    sky.type = rad::LightType::sky;
    sky.intensity = 100.0f;
    sky.direction = {0, 0, 1};
    city.add_light(sky);
    rad::CameraChoice c = rad::choose_camera(city);
    CHECK(c.reason ==
          "the scene has none: framing what stands on its ground from -y, 30 degrees above (z up: the sky's zenith)");
    CHECK(c.camera.up == glm::vec3(0, 0, 1));
    // At the middle of the building (what stands on the ground) with as much ground again
    // around it, from -y and 30 degrees above.
    CHECK(c.camera.look_at.x == doctest::Approx(0.0f));
    CHECK(c.camera.look_at.y == doctest::Approx(0.0f));
    CHECK(c.camera.look_at.z == doctest::Approx(3.0f));
    const glm::vec3 back = glm::normalize(c.camera.eye - c.camera.look_at);
    CHECK(back.z == doctest::Approx(0.5f));  // sin 30 degrees
    CHECK(back.y == doctest::Approx(-0.8660254f));
    CHECK(back.x == doctest::Approx(0.0f));
    // Framed: the building (4 x 6 x 6) grown by half its width and depth on each side (8 x 12 x
    // 6, within the 20 x 20 ground); its bounding sphere fills the 45 degrees.
    CHECK(glm::length(c.camera.eye - c.camera.look_at) ==
          doctest::Approx(std::sqrt(244.0f) / 2.0f / std::sin(glm::radians(22.5f))).epsilon(1e-4));
    // What the sky would have said, the ground says without it (lit by a lamp over the roof,
    // facing up: the emitters' normals decide nothing).
    rad::Scene lamp_lit;
    rad::add_quad(lamp_lit, {-10, -10, 0}, {20, 0, 0}, {0, 20, 0}, lamp_lit.add_material(rad::Material{}), "ground");
    rad::add_box(lamp_lit, {-2, -3, 0}, {2, 3, 6}, 0, "building");
    rad::Material lamp;
    lamp.emission = rad::Rgb(10.0f);
    rad::add_quad(lamp_lit, {-0.5f, -0.5f, 7}, {1, 0, 0}, {0, 1, 0}, lamp_lit.add_material(lamp), "lamp");  // faces +z
    c = rad::choose_camera(lamp_lit);
    CHECK(c.reason == "the scene has none: framing what stands on its ground from -y, 30 degrees above (z up: the "
                      "ground lies at the lowest z)");
    CHECK(c.camera.up == glm::vec3(0, 0, 1));

    // A closed room with z up, lit by a ceiling lamp facing down (-z): floor and walls look
    // alike, the lamp decides; the view from inside is upright and looks across (x or y).
    rad::Material white;
    white.reflectance = rad::Rgb(0.6f);
    rad::Scene room = test::closed_box(white, glm::vec3(4.0f, 5.0f, 3.0f));  // 3 high along z
    rad::add_quad(room, {1.5f, 2.0f, 2.99f}, {0, 1, 0}, {1, 0, 0}, room.add_material(lamp), "lamp");
    REQUIRE(room.polygons().back().normal.z < -0.99f);
    c = rad::choose_camera(room);
    MESSAGE(c.reason);
    CHECK(c.camera.up == glm::vec3(0, 0, 1));
    CHECK(c.reason.find("; z up: the emitters face down -z)") != std::string::npos);
    CHECK(inside(room.bounds(), c.camera.eye));
    CHECK(c.camera.eye.z == doctest::Approx(1.5f));  // mid height
    CHECK(std::fabs(c.camera.look_at.z - c.camera.eye.z) < 1e-6f);  // looking across
    // The same room with y up (its lamp facing -y) keeps y.
    rad::Scene y_room = test::closed_box(white, glm::vec3(4.0f, 3.0f, 5.0f));
    rad::add_quad(y_room, {1.5f, 2.99f, 2.0f}, {1, 0, 0}, {0, 0, 1}, y_room.add_material(lamp), "lamp");
    REQUIRE(y_room.polygons().back().normal.y < -0.99f);
    c = rad::choose_camera(y_room);
    CHECK(c.camera.up == glm::vec3(0, 1, 0));
    CHECK(c.reason.find("; y up: the emitters face down -y)") != std::string::npos);
    // A room as exported (y up), lit by a box-shaped fixture whose faces all emit (their normals
    // cancel), with a table leg poking 5 cm through the floor: the floor stays the ground's
    // candidate (within 2 % of the height), ties with the back wall, and y stays up.
    rad::Scene exported = test::closed_box(white, glm::vec3(4.0f, 2.7f, 3.0f));
    rad::add_box(exported, {1.8f, 2.5f, 1.2f}, {2.4f, 2.6f, 1.6f}, exported.add_material(lamp), "fixture");
    rad::add_box(exported, {1.0f, -0.05f, 1.0f}, {1.05f, 0.75f, 1.05f}, 0, "leg");
    c = rad::choose_camera(exported);
    CHECK(c.camera.up == glm::vec3(0, 1, 0));
    CHECK(c.reason.find("; y up: as OBJ and glTF have it)") != std::string::npos);
  }
}
