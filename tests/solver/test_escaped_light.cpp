#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

rad::SolveOptions coarse() {
  rad::SolveOptions o;
  o.mesh.max_patch_area = 1.0f;
  o.mesh.max_element_area = 0.25f;
  o.tolerance = 1e-5;
  return o;
}

double share(const rad::Rgb& part, const rad::Rgb& whole) {
  return (double(part.x) + double(part.y) + double(part.z)) / (double(whole.x) + double(whole.y) + double(whole.z));
}

bool has_warning(const rad::SolveReport& r, const std::string& text) {
  for (const std::string& w : r.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

rad::Material lamp() {
  rad::Material m;
  m.name = "lamp";
  m.emission = rad::Rgb(10.0f);
  m.reflectance = rad::Rgb(0.0f);
  return m;
}

/// A unit floor facing up at y = 0 and a 0.5 x 0.5 light at y = 1, facing down or up.
rad::Scene floor_and_light(bool light_faces_down) {
  rad::Scene scene;
  const rad::MaterialId white = scene.add_material(rad::Material{});
  const rad::MaterialId light = scene.add_material(lamp());
  rad::add_quad(scene, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, white, "floor");
  if (light_faces_down)
    rad::add_quad(scene, {0.25f, 1, 0.25f}, {0.5f, 0, 0}, {0, 0, 0.5f}, light, "light");
  else
    rad::add_quad(scene, {0.25f, 1, 0.25f}, {0, 0, 0.5f}, {0.5f, 0, 0}, light, "light");
  return scene;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("escaped power: a closed room with an inward light loses nothing and gets no warning") {
    rad::Material white;
    white.reflectance = rad::Rgb(0.6f);
    rad::Scene scene = test::closed_box(white, glm::vec3(2.0f));
    const rad::MaterialId light = scene.add_material(lamp());
    // Small, so that little of the ceiling's light falls on its (black, one-sided) back.
    rad::add_quad(scene, {0.9f, 1.99f, 0.9f}, {0.2f, 0, 0}, {0, 0, 0.2f}, light, "light");  // faces down
    REQUIRE(scene.polygons().back().normal.y < 0.0f);
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    CHECK(std::abs(share(r.escaped_power, r.emitted_power)) < 0.005);
    CHECK(r.warnings.empty());
    CHECK(rad::find_emitters_facing_away(scene).empty());
  }

  TEST_CASE("escaped power: the Cornell box loses light through its open front only and gets no warning") {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 20000.0f;
    o.tolerance = 1e-5;
    const rad::Solution sol = rad::solve(scene, o);
    const rad::SolveReport& r = sol.report();
    for (int c = 0; c < 3; ++c)
      CHECK(r.escaped_power[c] == doctest::Approx(r.emitted_power[c] - r.absorbed_power[c]).epsilon(1e-5));
    const double escaped = share(r.escaped_power, r.emitted_power);
    CHECK(escaped > 0.05);  // the front is open
    CHECK(escaped < 0.5);
    CHECK(!has_warning(r, "faces away"));  // (the red wall's triangulation is warned about)
    CHECK(!has_warning(r, "looks closed"));
    CHECK(rad::find_emitters_facing_away(scene).empty());
  }

  TEST_CASE("escaped power: a room of outward-facing polygons loses its light and is said to look closed") {
    rad::Scene scene;
    const rad::MaterialId white = scene.add_material(rad::Material{});
    const rad::MaterialId light = scene.add_material(lamp());
    rad::add_box(scene, {0, 0, 0}, {2, 2, 2}, white, "room");  // faces out: the room is inside out
    rad::add_quad(scene, {0.75f, 1.9f, 0.75f}, {0.5f, 0, 0}, {0, 0, 0.5f}, light, "light");  // faces down
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    CHECK(share(r.escaped_power, r.emitted_power) > 0.5);
    CHECK(has_warning(r, "the scene looks closed but 100 % of the emitted light left it: polygons probably face "
                         "outwards (wound the wrong way); reverse their winding (--reverse-winding outward; in code, "
                         "Scene::reverse_winding() of find_polygons_facing_outward()) or use two-sided materials "
                         "(--two-sided; Material::two_sided in code)"));
    CHECK(!has_warning(r, "faces away"));
    CHECK(rad::find_emitters_facing_away(scene).empty());
  }

  TEST_CASE("escaped power: a room and its light fixture both wound outward are said to be, though the fixture's light leaves") {
    // As a CAD exporter writes a room with a box-shaped ceiling light: every solid's facets point
    // out of it, and the fixture's top lies against the ceiling. Half of the fixture's light
    // (its top) leaves the scene at once, so "looks closed" (the emitters' rays meet surfaces)
    // cannot judge it; the polygons' own rays can.
    rad::Scene scene;
    const rad::MaterialId white = scene.add_material(rad::Material{});
    const rad::MaterialId light = scene.add_material(lamp());
    rad::add_box(scene, {0, 0, 0}, {4, 2.7f, 3}, white, "room");
    rad::add_box(scene, {1.8f, 2.69f, 1.2f}, {2.4f, 2.7f, 1.6f}, light, "fixture");
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    CHECK(share(r.escaped_power, r.emitted_power) > 0.9);
    CHECK(!has_warning(r, "looks closed"));
    CHECK(has_warning(r, "% of the emitted light left the scene, and 6 of 12 polygons"));
    CHECK(has_warning(r, "a closed model wound outward? Reverse their winding (--reverse-winding outward; in code, "
                         "Scene::reverse_winding() of find_polygons_facing_outward())"));

    // What the warning asks for: the room turned, the light stays in but for the fixture's top
    // (48 % of its area), which lies against the ceiling and sends into its back.
    const rad::OutwardFacing outward = rad::find_polygons_facing_outward(scene);
    CHECK(outward.looks_wound_outward());
    scene.reverse_winding(outward.polygons);
    const rad::Solution fixed = rad::solve(scene, coarse());
    CHECK(share(fixed.report().escaped_power, fixed.report().emitted_power) == doctest::Approx(0.48).epsilon(0.02));
    CHECK(!has_warning(fixed.report(), "wound outward"));
    // The fixture's top: no use turning it, and no "faces away" that would ask for that.
    CHECK(has_warning(fixed.report(), "emitter 'fixture' (polygon 9) lies against a polygon facing it (in contact): "
                                      "its light is lost there; give it no emission or remove it"));
    CHECK(!has_warning(fixed.report(), "faces away"));
  }

  TEST_CASE("escaped power: the same room made two-sided keeps its light, and is said to be lit on its back") {
    // What a user does on the warning above (--two-sided): the light stays, but the room's lit
    // side is the back of its polygons, which lightmaps and per-vertex values do not hold.
    rad::Scene scene;
    rad::Material wall;
    wall.two_sided = true;
    const rad::MaterialId white = scene.add_material(wall);
    const rad::MaterialId light = scene.add_material(lamp());
    rad::add_box(scene, {0, 0, 0}, {2, 2, 2}, white, "room");
    rad::add_quad(scene, {0.75f, 1.9f, 0.75f}, {0.5f, 0, 0}, {0, 0, 0.5f}, light, "light");  // faces down
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    CHECK(std::abs(share(r.escaped_power, r.emitted_power)) < 0.05);  // the light's own back only
    CHECK(sol.group_back_radiosity("room").x > 10.0f * sol.group_radiosity("room").x);
    CHECK(has_warning(r, "group 'room' is lit mainly on the back of its two-sided polygons"));
    CHECK(!has_warning(r, "looks closed"));

    // Wound inwards, two-sided: lit on the front, no warning.
    rad::Scene inward = test::closed_box(wall, glm::vec3(2.0f));
    const rad::MaterialId inward_light = inward.add_material(lamp());
    rad::add_quad(inward, {0.75f, 1.9f, 0.75f}, {0.5f, 0, 0}, {0, 0, 0.5f}, inward_light, "light");
    const rad::Solution ok = rad::solve(inward, coarse());
    CHECK(!has_warning(ok.report(), "lit mainly on the back"));
  }

  TEST_CASE("escaped power: a lamp 1 cm under a ceiling wound to face it is said to face a surface right in front of "
            "it - facing down, nothing is said") {
    // Found by trying an exported room: its lamp wound to face up lit the ceiling 1 cm above it,
    // whose light came back onto the lamp (black) or out through the gap; the room came out at
    // a fortieth of its light with no warning, since nothing escaped the scene.
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.8f);
    float floor_lit_down = 0.0f;  // the floor's light with the lamp facing down (the first pass)
    for (const bool faces_down : {true, false}) {
      CAPTURE(faces_down);
      rad::Scene room = test::closed_box(grey, glm::vec3(4.0f, 3.0f, 4.0f));
      const rad::MaterialId l = room.add_material(lamp());
      if (faces_down) rad::add_quad(room, {1.6f, 2.99f, 1.6f}, {0.8f, 0, 0}, {0, 0, 0.8f}, l, "lamp");
      else rad::add_quad(room, {1.6f, 2.99f, 1.6f}, {0, 0, 0.8f}, {0.8f, 0, 0}, l, "lamp");
      REQUIRE(room.polygons().back().normal.y == doctest::Approx(faces_down ? -1.0f : 1.0f));
      const rad::Solution sol = rad::solve(room, rad::SolveOptions{});
      CHECK(has_warning(sol.report(), "faces a surface right in front of it") != faces_down);
      CHECK(!has_warning(sol.report(), "faces away from every surface"));
      // What it does: the floor's light, lamp facing up against facing down (0.31 at the default
      // mesh; less where the elements beside the lamp are finer than the gap).
      if (faces_down) {
        floor_lit_down = sol.group_radiosity("y0").y;
        REQUIRE(floor_lit_down > 0.0f);
      } else {
        CHECK(sol.group_radiosity("y0").y < 0.5f * floor_lit_down);
      }
    }
  }

  TEST_CASE("escaped power: an emitter facing away from an open floor is found and named") {
    const rad::Scene scene = floor_and_light(false);
    const std::vector<rad::PolygonId> away = rad::find_emitters_facing_away(scene);
    REQUIRE(away.size() == 1);
    CHECK(away[0] == 1);
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    CHECK(share(r.escaped_power, r.emitted_power) == doctest::Approx(1.0));
    CHECK(has_warning(r, "emitter 'light' (polygon 1) faces away from every surface: its light leaves the scene; "
                         "check the polygon's winding (vertex order) or use two-sided materials"));
    CHECK(!has_warning(r, "looks closed"));
    CHECK(!has_warning(r, "wound outward"));
  }

  TEST_CASE("escaped power: a light facing down onto an open floor is not flagged though most light escapes") {
    const rad::Scene scene = floor_and_light(true);
    CHECK(rad::find_emitters_facing_away(scene).empty());
    const rad::Solution sol = rad::solve(scene, coarse());
    const rad::SolveReport& r = sol.report();
    CHECK(share(r.escaped_power, r.emitted_power) > 0.5);  // open: the light spreads past the floor
    CHECK(r.warnings.empty());
  }

  TEST_CASE("find_emitters_facing_away: several emitters are listed in order and the answer is repeatable") {
    rad::Scene scene = floor_and_light(false);
    const rad::MaterialId light = scene.polygons()[1].material;
    rad::add_quad(scene, {0.25f, 2, 0.25f}, {0, 0, 0.5f}, {0.5f, 0, 0}, light, "light");  // up, sees nothing
    rad::add_quad(scene, {0.25f, 0.5f, 0.25f}, {0.5f, 0, 0}, {0, 0, 0.5f}, light, "low");  // down, sees the floor
    rad::add_quad(scene, {0.25f, 3, 0.25f}, {0, 0, 0.5f}, {0.5f, 0, 0}, light, "top");  // up, sees nothing
    const std::vector<rad::PolygonId> away = rad::find_emitters_facing_away(scene);
    CHECK(away == std::vector<rad::PolygonId>{4});  // 1 and 2 face up into the lights above them
    CHECK(rad::find_emitters_facing_away(scene) == away);
    const rad::Solution sol = rad::solve(scene, coarse());
    CHECK(has_warning(sol.report(), "emitter 'top' (polygon 4) faces away"));
  }

  TEST_CASE("polygons facing outward: a closed box wound outward is found whole, one wound inward or two-sided not at all") {
    rad::Material grey;
    grey.name = "grey";
    grey.reflectance = rad::Rgb(0.5f);
    const rad::Scene inward = test::closed_box(grey, glm::vec3(2.0f, 1.0f, 3.0f));
    CHECK(rad::find_polygons_facing_outward(inward).polygons.empty());
    // The same box with every polygon turned over: its fronts face out, its backs see the box.
    rad::Scene outward = inward;
    outward.reverse_winding();
    const std::vector<rad::PolygonId> found_whole = rad::find_polygons_facing_outward(outward).polygons;
    CHECK(found_whole.size() == 6);
    rad::Scene turned_back = outward;  // what --reverse-winding outward does
    turned_back.reverse_winding(found_whole);
    CHECK(rad::find_polygons_facing_outward(turned_back).polygons.empty());
    for (std::size_t p = 0; p < 6; ++p) CHECK(turned_back.polygons()[p].normal == inward.polygons()[p].normal);
    rad::Scene two_sided = outward;
    two_sided.make_two_sided();
    CHECK(rad::find_polygons_facing_outward(two_sided).polygons.empty());
    // Where the light is tells a room wound outward from an object seen from outside (Khronos'
    // Box.gltf): without light, nothing does; a lamp inside makes it a room; a sky, a sun or a
    // lamp outside an object, whose faces face out as they should.
    CHECK(rad::find_polygons_facing_outward(outward).looks_wound_outward());
    CHECK(!rad::find_polygons_facing_outward(outward).lit_from_outside);
    auto with_light = [&](rad::LightType type, glm::vec3 position) {
      rad::Scene lit = outward;
      rad::Light light;
      light.type = type;
      light.position = position;
      light.direction = glm::vec3(0.3f, -1.0f, 0.2f);
      lit.add_light(light);
      return rad::find_polygons_facing_outward(lit);
    };
    CHECK(with_light(rad::LightType::point, {1.0f, 0.5f, 1.5f}).looks_wound_outward());  // inside the box
    CHECK(!with_light(rad::LightType::point, {1.0f, 0.5f, 1.5f}).lit_from_outside);
    for (const rad::LightType type : {rad::LightType::point, rad::LightType::sky, rad::LightType::directional}) {
      const rad::OutwardFacing object = with_light(type, {5.0f, 3.0f, -4.0f});
      CHECK(object.polygons.size() == 6);  // found, as before
      CHECK(object.lit_from_outside);
      CHECK(!object.looks_wound_outward());
    }
    // An emitting polygon: inside (a lamp under the ceiling, facing down) or outside the box.
    rad::Material lamp_material;
    lamp_material.emission = rad::Rgb(10.0f);
    rad::Scene lamp_inside = outward, lamp_outside = outward;
    rad::add_quad(lamp_inside, {0.8f, 0.9f, 1.3f}, {0.4f, 0, 0}, {0, 0, 0.4f}, lamp_inside.add_material(lamp_material),
                  "lamp");
    rad::add_quad(lamp_outside, {0.8f, 3.0f, 1.3f}, {0.4f, 0, 0}, {0, 0, 0.4f},
                  lamp_outside.add_material(lamp_material), "lamp");
    REQUIRE(lamp_inside.polygons().back().normal.y < -0.99f);
    CHECK(rad::find_polygons_facing_outward(lamp_inside).looks_wound_outward());
    CHECK(rad::find_polygons_facing_outward(lamp_outside).lit_from_outside);
    CHECK(!rad::find_polygons_facing_outward(lamp_outside).looks_wound_outward());
    // And a solve of the box lit from outside by that lamp: most of the light leaves (it is an
    // open scene), but nothing is said about winding.
    const rad::Solution object_solve = rad::solve(lamp_outside, coarse());
    CHECK(share(object_solve.report().escaped_power, object_solve.report().emitted_power) > 0.5);
    CHECK(!has_warning(object_solve.report(), "wound outward"));
    CHECK(!has_warning(object_solve.report(), "looks closed"));
    // A box standing on a large ground, wound outward as an exterior should be: only its roof
    // (open sky in front, the box's inside behind) is reported, a small share of the area, which
    // is why `radiosity check` warns only above half of it.
    rad::Scene street;
    const rad::MaterialId s = street.add_material(grey);
    street.add_polygon({{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}}, s, "ground");
    for (const rad::Polygon& p : outward.polygons()) {
      if (p.normal.y < -0.5f) continue;  // the box's floor lies on the ground
      street.add_polygon(std::vector<glm::vec3>(p.vertices.begin(), p.vertices.end()), s, "building");
    }
    const rad::OutwardFacing found = rad::find_polygons_facing_outward(street);
    REQUIRE(found.polygons.size() == 1);
    CHECK(street.polygons()[found.polygons[0]].normal.y > 0.99f);
    CHECK(found.area < 0.5 * found.one_sided_area);
  }
  TEST_CASE("polygons facing outward: a room wound outward with its floor exported as facets smaller than a box's "
            "bottom resting on it - the floor is turned whole, the box's bottom kept") {
    // An exporter's room: every face wound out of the room, the floor as 1 m triangles, a lamp
    // under the ceiling facing down, and a box wound out of itself (as it should be) turned 23
    // degrees, resting on the floor with its bottom (1.2 x 1.2 m, larger than a floor facet).
    // The floor facets under the box's bottom are coincident with it and face the same way;
    // rays cannot judge them (their backs see into the box). Chosen by size, the box's bottom
    // was turned and the facets under its edges kept facing down: black around the box in a
    // render, and `--reverse-winding outward` left 7 facets wound against their neighbours.
    rad::Material grey;
    grey.reflectance = rad::Rgb(0.5f);
    rad::Scene room = test::closed_box(grey, glm::vec3(4.0f, 3.0f, 4.0f));
    rad::Scene scene;
    const rad::MaterialId g = scene.add_material(grey);
    for (const rad::Polygon& p : room.polygons())
      if (p.normal.y < 0.5f) scene.add_polygon(std::vector<glm::vec3>(p.vertices.begin(), p.vertices.end()), g, "room");
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const glm::vec3 a(i, 0, j), b(i + 1, 0, j), c(i + 1, 0, j + 1), d(i, 0, j + 1);  // facing up
        scene.add_polygon({a, c, b}, g, "floor");
        scene.add_polygon({a, d, c}, g, "floor");
      }
    rad::Material lamp_material;
    lamp_material.emission = rad::Rgb(10.0f);
    const auto lamp_id = static_cast<rad::PolygonId>(scene.polygons().size());
    rad::add_quad(scene, {1.6f, 2.99f, 1.6f}, {0.8f, 0, 0}, {0, 0, 0.8f}, scene.add_material(lamp_material), "lamp");
    REQUIRE(scene.polygons().back().normal.y < -0.99f);
    scene.reverse_winding();  // the room wound outward (and the lamp facing up)
    rad::Scene box_only = test::turned_about_y(test::closed_box(grey, glm::vec3(1.2f, 0.8f, 1.2f)), 23.0f,
                                               glm::vec3(0.6f, 0.0f, 0.6f));
    box_only.reverse_winding();  // wound out of the box
    const glm::vec3 at(1.45f, 0.0f, 2.15f);
    for (const rad::Polygon& p : box_only.polygons()) {
      std::vector<glm::vec3> v;
      for (const glm::vec3& x : p.vertices) v.push_back(x + at - glm::vec3(0.6f, 0.0f, 0.6f));
      scene.add_polygon(v, g, "box");
    }
    scene.reverse_winding({lamp_id});  // the lamp faces down again
    const rad::OutwardFacing found = rad::find_polygons_facing_outward(scene);
    CHECK(found.looks_wound_outward());
    rad::Scene turned = scene;
    turned.reverse_winding(found.polygons);
    const rad::GroupId floor = *turned.find_group("floor"), box = *turned.find_group("box");
    int floor_up = 0, floor_down = 0;
    for (const rad::Polygon& p : turned.polygons()) {
      if (p.group == floor) (p.normal.y > 0.99f ? floor_up : floor_down) += 1;
      if (p.group == box && std::abs(p.normal.y) > 0.99f) CHECK(p.normal.y * (p.vertices[0].y > 0.4f ? 1.0f : -1.0f) > 0.0f);
    }
    CHECK(floor_up == 32);
    CHECK(floor_down == 0);
    CHECK(rad::find_inconsistent_winding(turned).polygons.empty());
    // Nothing left facing the same way as what it lies on.
    for (const rad::PolygonOverlap& o : rad::find_overlaps(turned))
      if (o.kind == rad::OverlapKind::coincident)
        CHECK(glm::dot(turned.polygons()[o.first].normal, turned.polygons()[o.second].normal) < 0.0f);
  }
}
