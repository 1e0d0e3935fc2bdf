// find_inconsistent_winding(): polygons wound against the polygons they share edges with (a
// flipped face of an exported mesh), and what solve() and Scene::reverse_winding() make of them.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// The box [0, 1]^3 as an exporter writes a triangle mesh: each face cut into n x n squares, each
/// square two triangles, wound so that the normals point out of the box (`inward`: into it).
/// Polygon k's triangle is in group "box" unless `odd` names it (then "odd").
rad::Scene triangle_box(int n, bool inward, const rad::Material& material, const std::vector<std::size_t>& odd = {}) {
  rad::Scene s;
  const rad::MaterialId m = s.add_material(material);
  std::size_t k = 0;
  auto triangle = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const bool is_odd = std::find(odd.begin(), odd.end(), k++) != odd.end();
    if (inward) std::swap(b, c);
    s.add_polygon({a, b, c}, m, is_odd ? "odd" : "box");
  };
  // Each face: its corner, two edges whose cross product points out of the box.
  const std::array<std::array<glm::vec3, 3>, 6> faces = {{{glm::vec3(0, 0, 0), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0)},
                                                          {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)},
                                                          {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)},
                                                          {glm::vec3(0, 1, 0), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0)},
                                                          {glm::vec3(0, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)},
                                                          {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)}}};
  const float h = 1.0f / static_cast<float>(n);
  for (const auto& f : faces)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const glm::vec3 p = f[0] + (static_cast<float>(i) * h) * f[1] + (static_cast<float>(j) * h) * f[2];
        const glm::vec3 u = h * f[1], v = h * f[2];
        triangle(p, p + u, p + u + v);
        triangle(p, p + u + v, p + v);
      }
  return s;
}

rad::Material grey() {
  rad::Material m;
  m.reflectance = rad::Rgb(0.5f);
  return m;
}

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("find_inconsistent_winding: a mesh wound one way has none - a flipped triangle or face is found - a box "
            "wound inward or outward throughout has none") {
    const rad::Scene consistent = triangle_box(4, false, grey());
    REQUIRE(consistent.polygons().size() == 192);
    CHECK(rad::find_inconsistent_winding(consistent).polygons.empty());
    CHECK(rad::find_inconsistent_winding(triangle_box(4, true, grey())).polygons.empty());

    rad::Scene one = triangle_box(4, false, grey());
    one.reverse_winding({37});
    const rad::InconsistentWinding found = rad::find_inconsistent_winding(one);
    CHECK(found.polygons == std::vector<rad::PolygonId>{37});
    CHECK(found.area == doctest::Approx(1.0 / 32.0));
    CHECK(found.surfaces == 1);
    // Turned back, the mesh is consistent again.
    one.reverse_winding(found.polygons);
    CHECK(rad::find_inconsistent_winding(one).polygons.empty());

    // A whole face (32 triangles, 1/6 of the area) turned: the face is found, not the rest.
    rad::Scene face = triangle_box(4, false, grey());
    std::vector<rad::PolygonId> second_face;
    for (rad::PolygonId p = 32; p < 64; ++p) second_face.push_back(p);
    face.reverse_winding(second_face);
    CHECK(rad::find_inconsistent_winding(face).polygons == second_face);

    // Two separate boxes, one triangle flipped in each: two surfaces.
    rad::Scene two = triangle_box(2, false, grey());
    const rad::MaterialId m = two.add_material(grey());
    for (rad::PolygonId p = 0; p < 48; ++p) {
      const rad::Polygon copy = two.polygons()[p];
      std::vector<glm::vec3> moved;
      for (const glm::vec3& v : copy.vertices) moved.push_back(v + glm::vec3(3, 0, 0));
      two.add_polygon(moved, m, "other");
    }
    two.reverse_winding({5, 48 + 20});
    const rad::InconsistentWinding both = rad::find_inconsistent_winding(two);
    CHECK(both.polygons == std::vector<rad::PolygonId>{5, 68});
    CHECK(both.surfaces == 2);
  }

  TEST_CASE("find_inconsistent_winding: two-sided and glass polygons have no wrong side - a face modelled twice and a "
            "sheet's two layers are not flipped faces - an edge three polygons share tells nothing - a tie takes the "
            "side without the lowest id") {
    rad::Material two_sided = grey();
    two_sided.two_sided = true;
    rad::Scene s = triangle_box(4, false, two_sided);
    s.reverse_winding({37});
    CHECK(rad::find_inconsistent_winding(s).polygons.empty());
    rad::Material glass = grey();
    glass.transmittance = rad::Rgb(0.9f);
    rad::Scene g = triangle_box(4, false, glass);
    g.reverse_winding({37});
    CHECK(rad::find_inconsistent_winding(g).polygons.empty());

    // A quad modelled twice the same way (z-fighting: find_overlaps()'s) and a sheet as two
    // layers facing apart: each pair shares all its edges, lying on the same side of them.
    rad::Scene twice;
    const rad::MaterialId m = twice.add_material(grey());
    twice.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "a");
    twice.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "b");
    twice.add_polygon({{2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 1, 0}}, m, "front");
    twice.add_polygon({{2, 0, 0}, {2, 1, 0}, {3, 1, 0}, {3, 0, 0}}, m, "back");
    CHECK(rad::find_inconsistent_winding(twice).polygons.empty());

    // A floor cut into two quads along x = 1 and a partition standing on that line, wound either
    // way: the line is an edge of three polygons.
    rad::Scene partition;
    const rad::MaterialId pm = partition.add_material(grey());
    partition.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, pm, "floor");  // facing -y
    partition.add_polygon({{1, 0, 0}, {2, 0, 0}, {2, 0, 1}, {1, 0, 1}}, pm, "floor");  // facing -y
    partition.reverse_winding({0});                                                     // now +y
    partition.add_polygon({{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}, pm, "partition");
    // The two floor quads are wound apart (0 turned, 1 not) but their shared line also holds
    // the partition's foot, so nothing is judged.
    CHECK(rad::find_inconsistent_winding(partition).polygons.empty());

    // A quad as two triangles, one turned: half the area each way; the turned one is the one
    // without the lowest id whichever it is.
    for (const rad::PolygonId turned : {0u, 1u}) {
      rad::Scene quad;
      const rad::MaterialId q = quad.add_material(grey());
      quad.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, q);
      quad.add_polygon({{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}, q);
      quad.reverse_winding({turned});
      CHECK(rad::find_inconsistent_winding(quad).polygons == std::vector<rad::PolygonId>{1});
    }
  }

  TEST_CASE("a flipped triangle in a lit room: black, said by solve() - turned by reverse_winding(), it takes its "
            "neighbours' light") {
    // A closed room (the box wound inward) with a point light inside; triangle 37 of the mesh
    // (group "odd", on the second face) turned: its front faces out of the room.
    rad::Scene room = triangle_box(4, true, grey(), {36, 37, 38});
    room.reverse_winding({37});
    rad::Light light;
    light.type = rad::LightType::point;
    light.position = glm::vec3(0.5f);
    light.intensity = 1.0f;
    room.add_light(light);
    rad::SolveOptions o;
    o.mesh.max_patch_area = o.mesh.max_element_area = 1.0f;  // one element per triangle
    const rad::Solution before = rad::solve(room, o);
    bool said = false;
    for (const std::string& w : before.report().warnings)
      said |= w.find("1 polygon is wound opposite to the polygons it shares edges with") != std::string::npos &&
              w.find("polygon 37 of group 'odd'") != std::string::npos;
    CHECK(said);
    // Of "odd" (three triangles of one area), 36 and 38 are lit and 37 is black: the mean is
    // two thirds of a lit triangle's, and turning 37 makes it about 3/2 of that.
    const double mean_before = before.group_radiosity("odd").x;
    room.reverse_winding(rad::find_inconsistent_winding(room).polygons);
    const rad::Solution after = rad::solve(room, o);
    for (const std::string& w : after.report().warnings) CHECK(w.find("wound opposite") == std::string::npos);
    const double mean_after = after.group_radiosity("odd").x;
    INFO("odd before ", mean_before, ", after ", mean_after, ", the box ", after.group_radiosity("box").x);
    CHECK(mean_after > 1.3 * mean_before);
    CHECK(mean_after == doctest::Approx(1.5 * mean_before).epsilon(0.15));
  }
}

TEST_SUITE("scene") {
  TEST_CASE("a flipped triangle in a closed room: its view-factor row looks out of the room, said by "
            "view_factor_matrix() - turned, its row sums to 1") {
    // The closed room of the case above (4 x 4 x 2 triangles a face, wound inward), triangle 37
    // turned: its row sees what lies behind the wall (nothing: only the sky), so it sums to 0
    // where every other row of the closed room sums to 1 (the exact mode, to 1e-3).
    rad::Scene room = triangle_box(4, true, grey(), {36, 37, 38});
    room.reverse_winding({37});
    rad::ViewFactorOptions o;
    o.level = rad::ViewFactorLevel::polygon;
    o.form_factors.method = rad::FormFactorMethod::ray_cast;
    auto row_sum = [](const rad::ViewFactorMatrix& m, std::size_t r) {
      double sum = 0.0;
      for (std::uint64_t k = m.row_offsets[r]; k < m.row_offsets[r + 1]; ++k) sum += m.values[k];
      return sum;
    };
    const rad::ViewFactorMatrix before = rad::view_factor_matrix(room, o);
    REQUIRE(before.rows() == room.polygons().size());
    CHECK(row_sum(before, 37) == 0.0);
    CHECK(before.sky[37] == 1.0);
    bool said = false;
    for (const std::string& w : before.warnings)
      said |= w.find("1 polygon is wound opposite to the polygons it shares edges with") != std::string::npos &&
              w.find("polygon 37 of group 'odd'") != std::string::npos &&
              w.find("its row sees what lies behind the surface it belongs to") != std::string::npos;
    CHECK(said);

    room.reverse_winding(rad::find_inconsistent_winding(room).polygons);
    const rad::ViewFactorMatrix after = rad::view_factor_matrix(room, o);
    for (const std::string& w : after.warnings) CHECK(w.find("wound opposite") == std::string::npos);
    for (std::size_t r = 0; r < after.rows(); ++r) {
      INFO("row ", r);
      CHECK(row_sum(after, r) == doctest::Approx(1.0).epsilon(1e-3));
    }
    // Before, the other rows missed what they now see of triangle 37 (its back blocked them).
    for (const std::size_t r : {std::size_t{0}, std::size_t{100}}) {
      INFO("row ", r, ": F(r -> 37) ", after.at(r, 37));
      CHECK(after.at(r, 37) > 0.0);
      CHECK(row_sum(before, r) == doctest::Approx(1.0 - after.at(r, 37)).epsilon(1e-3));
    }
  }
}
