// Tests for vertex sharing between polygons (MeshOptions::crease_angle_deg): smooth neighbours
// share corners, edge points and subdivision midpoints; creases, material and group changes
// do not; edges cut differently on the two sides (or rounded differently) stay continuous; and
// patches and elements are bit for bit those of the unshared mesh.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/geometric.hpp>

#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

#include "support/fields.hpp"

using namespace radiosity;

namespace {

MeshOptions options(float max_patch_area, float max_element_area, float crease_angle_deg) {
  MeshOptions o;
  o.max_patch_area = max_patch_area;
  o.max_element_area = max_element_area;
  o.crease_angle_deg = crease_angle_deg;
  return o;
}

// Deterministic uniform floats in [0, 1).
struct Uniform {
  std::mt19937 engine{2024u};
  float operator()() { return static_cast<float>(engine() >> 8) * (1.0f / 16777216.0f); }
};

std::vector<Rgb> random_values(const PatchHierarchy& h, Uniform& u) {
  std::vector<Rgb> values(h.elements().size());
  for (Rgb& v : values) v = Rgb(u(), u(), u());
  return values;
}

void refine_randomly(PatchHierarchy& h, Uniform& u, int splits) {
  for (int i = 0; i < splits; ++i) {
    const auto& leaves = h.leaves();
    h.subdivide(leaves[static_cast<std::size_t>(u() * static_cast<float>(leaves.size())) % leaves.size()]);
  }
}

// After `splits` random subdivisions, random element values interpolate without a crack inside
// a polygon and continuously across the scene's one smooth seam.
void check_one_continuous_seam(const Scene& scene, PatchHierarchy& h, int splits) {
  Uniform u;
  refine_randomly(h, u, splits);
  const std::vector<Rgb> vv = h.vertex_values(random_values(h, u));
  CHECK(test::largest_crack(h, vv) < 1e-5f);
  const test::SeamJump jump = test::largest_seam_jump(scene, h, vv, 30.0f, 1e-3f);
  CHECK(jump.edges == 1);
  CHECK(jump.complete);
  CHECK(jump.largest < 1e-5);
}

// Hierarchy vertices at exactly this position.
std::vector<std::uint32_t> vertices_at(const PatchHierarchy& h, const glm::vec3& p) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t v = 0; v < h.vertices().size(); ++v)
    if (h.vertices()[v] == p) out.push_back(v);
  return out;
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof(glm::vec3)) == 0; }

// The square [0,2]^2 as two triangles sharing the diagonal (0,0)-(2,2).
Scene split_square(bool same_material = true) {
  Scene scene;
  const MaterialId m = scene.add_material(Material{}), other = scene.add_material(Material{});
  scene.add_polygon({{0, 0, 0}, {2, 0, 0}, {2, 2, 0}}, m, "square");
  scene.add_polygon({{0, 0, 0}, {2, 2, 0}, {0, 2, 0}}, same_material ? m : other, "square");
  return scene;
}

}  // namespace

TEST_SUITE("mesh") {

TEST_CASE("smooth neighbours share corners and edge points - crease_angle_deg 0 shares nothing") {
  // k = 2 lattices of 6 vertices each; the diagonal's 3 points are shared.
  const Scene scene = split_square();
  const PatchHierarchy shared(scene, options(0.5f, 0.5f, 30.0f));
  const PatchHierarchy unshared(scene, options(0.5f, 0.5f, 0.0f));
  REQUIRE(shared.patches().size() == 8);
  CHECK(shared.vertices().size() == 9);
  CHECK(unshared.vertices().size() == 12);
  for (const glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1, 1, 0), glm::vec3(2, 2, 0)}) {
    CHECK(vertices_at(shared, p).size() == 1);
    CHECK(vertices_at(unshared, p).size() == 2);
  }
  // The default shares.
  CHECK(PatchHierarchy(scene, MeshOptions{0.5f, 0.5f}).vertices().size() == 9);
}

TEST_CASE("a shared vertex takes the area-weighted mean of the leaves of every polygon around it") {
  // One element per triangle (equal areas), values 1 and 3.
  const Scene scene = split_square();
  for (const float crease : {30.0f, 0.0f}) {
    CAPTURE(crease);
    const PatchHierarchy h(scene, options(10.0f, 10.0f, crease));
    REQUIRE(h.leaves().size() == 2);
    std::vector<Rgb> values(h.elements().size());
    values[h.leaves()[0]] = Rgb(1.0f);
    values[h.leaves()[1]] = Rgb(3.0f);
    const std::vector<Rgb> vv = h.vertex_values(values);
    auto value_at = [&](const glm::vec3& p, std::size_t which) { return vv[vertices_at(h, p)[which]].x; };
    CHECK(value_at({2, 0, 0}, 0) == 1.0f);
    CHECK(value_at({0, 2, 0}, 0) == 3.0f);
    if (crease > 0.0f) {
      CHECK(value_at({0, 0, 0}, 0) == 2.0f);
      CHECK(value_at({2, 2, 0}, 0) == 2.0f);
    } else {
      CHECK(value_at({0, 0, 0}, 0) == 1.0f);  // each triangle keeps its own corner
      CHECK(value_at({0, 0, 0}, 1) == 3.0f);
    }
  }
}

TEST_CASE("creases and changes of material or group are not shared") {
  SUBCASE("a box shares nothing across its 90 degree edges below a crease angle of 90") {
    Scene scene;
    add_box(scene, {0, 0, 0}, {1, 1, 1}, scene.add_material(Material{}), "box");
    const PatchHierarchy at30(scene, options(10.0f, 10.0f, 30.0f));
    CHECK(at30.vertices().size() == 24);
    CHECK(vertices_at(at30, {1, 1, 1}).size() == 3);
    // Each face's corner keeps its own face's value.
    std::vector<Rgb> values(at30.elements().size());
    for (const std::uint32_t id : at30.leaves()) values[id] = Rgb(static_cast<float>(at30.element(id).patch + 1));
    const std::vector<Rgb> vv = at30.vertex_values(values);
    std::vector<float> at_corner;
    for (const std::uint32_t v : vertices_at(at30, {1, 1, 1})) at_corner.push_back(vv[v].x);
    std::sort(at_corner.begin(), at_corner.end());
    CHECK(std::adjacent_find(at_corner.begin(), at_corner.end()) == at_corner.end());  // three different values
    // Above 90 degrees the box is one smooth surface: 8 corners.
    CHECK(PatchHierarchy(scene, options(10.0f, 10.0f, 91.0f)).vertices().size() == 8);
    CHECK(PatchHierarchy(scene, options(10.0f, 10.0f, 89.0f)).vertices().size() == 24);
  }
  SUBCASE("two coplanar quads of different materials or groups") {
    for (int variant = 0; variant < 3; ++variant) {
      CAPTURE(variant);
      Scene scene;
      const MaterialId a = scene.add_material(Material{}), b = scene.add_material(Material{});
      add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, a, "left");
      add_quad(scene, {1, 0, 0}, {1, 0, 0}, {0, 1, 0}, variant == 1 ? b : a, variant == 2 ? "right" : "left");
      const PatchHierarchy h(scene, options(10.0f, 10.0f, 30.0f));
      CHECK(h.vertices().size() == (variant == 0 ? 6u : 8u));
    }
  }
  SUBCASE("a fold of 45 degrees is shared from a crease angle of 45 up") {
    Scene scene;
    const MaterialId m = scene.add_material(Material{});
    add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, -1}, m, "fold");  // faces +y
    add_quad(scene, {1, 0, 0}, {1, 1, 0}, {0, 0, -1}, m, "fold");  // tilted up by 45 degrees
    CHECK(PatchHierarchy(scene, options(10.0f, 10.0f, 40.0f)).vertices().size() == 8);
    CHECK(PatchHierarchy(scene, options(10.0f, 10.0f, 46.0f)).vertices().size() == 6);
  }
}

TEST_CASE("subdivision midpoints are shared across polygons and T-vertices stay continuous") {
  const Scene scene = split_square();
  PatchHierarchy h(scene, options(10.0f, 10.0f, 30.0f));
  REQUIRE(h.vertices().size() == 4);
  h.subdivide(h.patches()[0].root);
  CHECK(h.vertices().size() == 4 + 3);
  Uniform u;
  std::vector<Rgb> vv = h.vertex_values(random_values(h, u));
  // The first triangle's midpoint of the diagonal hangs on the unsplit second triangle's edge.
  const std::vector<std::uint32_t> mid = vertices_at(h, {1, 1, 0});
  REQUIRE(mid.size() == 1);
  const Rgb ends = 0.5f * (vv[vertices_at(h, {0, 0, 0})[0]] + vv[vertices_at(h, {2, 2, 0})[0]]);
  CHECK(glm::length(vv[mid[0]] - ends) < 1e-6f);
  CHECK(test::largest_crack(h, vv) < 1e-5f);
  h.subdivide(h.patches()[1].root);
  CHECK(h.vertices().size() == 7 + 2);  // the diagonal's midpoint is reused
  refine_randomly(h, u, 30);
  vv = h.vertex_values(random_values(h, u));
  CHECK(test::largest_crack(h, vv) < 1e-5f);
}

TEST_CASE("smooth neighbours that cut their edge into different numbers of patches stay continuous") {
  // Triangles with the edge x = 0, y in [0, 1] in common, of widths chosen for k x k lattices
  // (area 0.095 k^2 against max_patch_area 0.1), so the edge is cut into k_left and k_right
  // segments: common knots at multiples of 1 / gcd.
  const int cuts[][2] = {{1, 5}, {2, 4}, {2, 3}, {4, 6}, {3, 3}};
  for (const auto& cut : cuts) {
    const int k_left = cut[0], k_right = cut[1];
    CAPTURE(k_left);
    CAPTURE(k_right);
    Scene scene;
    const MaterialId m = scene.add_material(Material{});
    const float w_left = 0.19f * static_cast<float>(k_left * k_left);
    const float w_right = 0.19f * static_cast<float>(k_right * k_right);
    scene.add_polygon({{0, 0, 0}, {0, 1, 0}, {-w_left, 0.5f, 0}}, m, "pair");
    scene.add_polygon({{0, 0, 0}, {w_right, 0.5f, 0}, {0, 1, 0}}, m, "pair");
    PatchHierarchy h(scene, options(0.1f, 0.1f, 30.0f));
    const std::size_t lattices = static_cast<std::size_t>((k_left + 1) * (k_left + 2) / 2 + (k_right + 1) * (k_right + 2) / 2);
    // Corners always shared; inner points of the edge only when the cuts are the same.
    CHECK(h.vertices().size() == lattices - 2 - (k_left == k_right ? static_cast<std::size_t>(k_left - 1) : 0u));
    check_one_continuous_seam(scene, h, 40);
  }
  SUBCASE("quads: a unit square and a trapezoid cut the common edge into 2 and 8") {
    Scene scene;
    const MaterialId m = scene.add_material(Material{});
    scene.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "pair");
    scene.add_polygon({{1, 0, 0}, {3, -3, 0}, {3, 4, 0}, {1, 1, 0}}, m, "pair");
    PatchHierarchy h(scene, options(0.25f, 0.25f, 30.0f));
    CHECK(vertices_at(h, {1, 0.5f, 0}).size() == 2);  // a common knot, one vertex per side
    check_one_continuous_seam(scene, h, 60);
  }
}

TEST_CASE("edge points that two neighbours round differently are not shared but stay continuous") {
  // Both triangles are cut k = 3 along P-Q, but the first computes the point at 1/3 as
  // P + 1/3 (Q - P) and the second as Y + 1/3 (Q - Y) + 2/3 (P - Y): the y coordinates round to
  // -0.600000024 and -0.599999964. Sharing one of them would move the other triangle's patches.
  const glm::vec3 P(-2.0f, -0.7f, 0.0f), Q(0.2f, -0.4f, 0.0f), Y(3.0f, 2.2f, 0.0f), X(-4.8f, -3.3f, 0.0f);
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  scene.add_polygon({P, Q, X}, m, "pair");
  scene.add_polygon({Y, Q, P}, m, "pair");
  PatchHierarchy h(scene, options(0.28f, 0.28f, 30.0f));
  REQUIRE(h.patches().size() == 18);  // k = 3 on both
  CHECK(h.vertices().size() == 10 + 10 - 2);
  check_one_continuous_seam(scene, h, 40);
}

TEST_CASE("welding changes no patch or element - only which vertices are shared") {
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  add_sphere(scene, {0, 0, 0}, 1.0f, m, "ball", 12);
  add_box(scene, {2, 0, 0}, {3, 1, 1}, m, "box");
  scene.add_polygon({{-2, 0, 0}, {-2, 1, 0}, {-4, 0.5f, 0}}, m, "pair");
  scene.add_polygon({{-2, 0, 0}, {-1, 0.5f, 0}, {-2, 1, 0}}, m, "pair");
  PatchHierarchy a(scene, options(0.05f, 0.02f, 0.0f)), b(scene, options(0.05f, 0.02f, 30.0f));
  CHECK(b.vertices().size() < a.vertices().size());
  // The same subdivisions on both.
  Uniform u;
  for (int i = 0; i < 50; ++i) {
    const std::size_t pick = static_cast<std::size_t>(u() * static_cast<float>(a.leaves().size())) % a.leaves().size();
    a.subdivide(a.leaves()[pick]);
    b.subdivide(b.leaves()[pick]);
  }
  REQUIRE(a.elements().size() == b.elements().size());
  REQUIRE(a.patches().size() == b.patches().size());
  CHECK(a.leaves() == b.leaves());
  for (std::uint32_t id = 0; id < a.elements().size(); ++id) {
    const Element &ea = a.element(id), &eb = b.element(id);
    REQUIRE(ea.corner_count() == eb.corner_count());
    bool same = ea.area == eb.area && same_bits(ea.centroid, eb.centroid) && ea.patch == eb.patch &&
                ea.parent == eb.parent && ea.first_child == eb.first_child;
    for (int k = 0; k < ea.corner_count(); ++k)
      same = same && same_bits(a.vertices()[ea.corners[k]], b.vertices()[eb.corners[k]]);
    if (!same) FAIL_CHECK("element " << id << " differs");
  }
  for (std::size_t p = 0; p < a.patches().size(); ++p) {
    CHECK(a.patches()[p].area == b.patches()[p].area);
    CHECK(same_bits(a.patches()[p].centroid, b.patches()[p].centroid));
  }
}

TEST_CASE("crease_angle_deg outside 0 to 180 throws Error{invalid_argument} naming the field") {
  const Scene scene = split_square();
  for (const float bad : {-1.0f, 180.0f, 360.0f, std::numeric_limits<float>::quiet_NaN()}) {
    CAPTURE(bad);
    try {
      PatchHierarchy h(scene, options(0.0f, 0.0f, bad));
      FAIL("no throw");
    } catch (const Error& e) {
      CHECK(e.code() == ErrorCode::invalid_argument);
      CHECK(std::string(e.what()).find("crease_angle_deg") != std::string::npos);
    }
  }
  CHECK_NOTHROW(PatchHierarchy(scene, options(0.0f, 0.0f, 179.0f)));
}

}  // TEST_SUITE
