// Tests for PatchHierarchy: area bookkeeping, option handling, shared vertices, crack-free vertex
// values, aggregation, area-uniform sampling and progress and cancel while meshing.
#include <algorithm>
#include <map>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/geometric.hpp>

#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

#include "support/fields.hpp"

using namespace radiosity;

namespace {

Scene one_polygon(const std::vector<glm::vec3>& vertices) {
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  scene.add_polygon(vertices, m, "p");
  return scene;
}

// A triangle, a trapezoid (not a parallelogram, so its grid cells differ in size) and a regular
// pentagon, in different planes and orientations.
Scene mixed_scene() {
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  scene.add_polygon({{0, 0, 0}, {3, 0, 0}, {0, 2, 0}}, m, "triangle");
  scene.add_polygon({{0, 0, 5}, {4, 0, 5}, {3, 2, 5}, {1, 2, 5}}, m, "trapezoid");
  std::vector<glm::vec3> pentagon;
  for (int i = 0; i < 5; ++i) {
    const float a = 2.0f * 3.14159265f * static_cast<float>(i) / 5.0f;
    pentagon.emplace_back(10.0f, 1.5f * std::cos(a), 1.5f * std::sin(a));  // faces +x
  }
  scene.add_polygon(pentagon, m, "pentagon");
  return scene;
}

double signed_area_along(const PatchHierarchy& h, std::uint32_t id) {
  const Element& e = h.element(id);
  const auto& v = h.vertices();
  glm::vec3 twice(0.0f);
  for (int k = 0; k < e.corner_count(); ++k)
    twice += glm::cross(v[e.corners[k]], v[e.corners[(k + 1) % e.corner_count()]]);
  return 0.5 * static_cast<double>(glm::dot(twice, h.normal(id)));
}

// Point-in-convex-element test in the element's plane, with an absolute slack.
bool inside(const PatchHierarchy& h, std::uint32_t id, const glm::vec3& p, float slack) {
  const Element& e = h.element(id);
  const auto& v = h.vertices();
  const glm::vec3 n = h.normal(id);
  for (int k = 0; k < e.corner_count(); ++k) {
    const glm::vec3 a = v[e.corners[k]], b = v[e.corners[(k + 1) % e.corner_count()]];
    const glm::vec3 inward = glm::normalize(glm::cross(n, b - a));
    if (glm::dot(p - a, inward) < -slack) return false;
  }
  return std::fabs(glm::dot(p - v[e.corners[0]], n)) <= slack;
}

// Deterministic uniform floats in [0, 1) (std distributions are not portable across libraries).
struct Uniform {
  std::mt19937 engine{12345u};
  float operator()() { return static_cast<float>(engine() >> 8) * (1.0f / 16777216.0f); }
};

using test::largest_crack;

}  // namespace

TEST_SUITE("mesh") {

TEST_CASE("leaf and patch areas sum to each polygon's area (relative 1e-5)") {
  const Scene scene = mixed_scene();
  const PatchHierarchy h(scene, MeshOptions{0.3f, 0.05f});
  std::vector<double> patch_sum(scene.polygons().size(), 0.0), leaf_sum(scene.polygons().size(), 0.0);
  for (const Patch& p : h.patches()) patch_sum[p.polygon] += p.area;
  for (const std::uint32_t id : h.leaves()) leaf_sum[h.patches()[h.element(id).patch].polygon] += h.element(id).area;
  for (std::size_t i = 0; i < scene.polygons().size(); ++i) {
    const double a = scene.polygons()[i].area;
    CHECK(patch_sum[i] == doctest::Approx(a).epsilon(1e-5));
    CHECK(leaf_sum[i] == doctest::Approx(a).epsilon(1e-5));
  }
}

TEST_CASE("every leaf fits max_element_area and every patch fits max_patch_area (relative 1e-5)") {
  const Scene scene = mixed_scene();
  for (const MeshOptions& options : {MeshOptions{0.3f, 0.05f}, MeshOptions{1.0f, 0.01f}, MeshOptions{}}) {
    const PatchHierarchy h(scene, options);
    const float max_patch = h.options().max_patch_area, max_element = h.options().max_element_area;
    for (const Patch& p : h.patches()) CHECK(p.area <= max_patch * (1.0f + 1e-5f));
    for (const std::uint32_t id : h.leaves()) CHECK(h.element(id).area <= max_element * (1.0f + 1e-5f));
  }
}

TEST_CASE("triangles - quads and a pentagon mesh into counter-clockwise cells of the polygon") {
  SUBCASE("a unit square with max_patch_area 0.25 is a 2x2 grid sharing 9 vertices") {
    const PatchHierarchy h(one_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}), MeshOptions{0.25f, 0.25f});
    CHECK(h.patches().size() == 4);
    CHECK(h.vertices().size() == 9);
    CHECK(h.leaves().size() == 4);
    for (const Patch& p : h.patches()) CHECK(p.area == doctest::Approx(0.25).epsilon(1e-6));
  }
  SUBCASE("a triangle of area 1 with max_patch_area 1/9 is a 3x3 lattice of 9 similar triangles") {
    const PatchHierarchy h(one_polygon({{0, 0, 0}, {2, 0, 0}, {0, 1, 0}}), MeshOptions{1.0f / 9.0f, 1.0f / 9.0f});
    CHECK(h.patches().size() == 9);
    CHECK(h.vertices().size() == 10);
    for (const Patch& p : h.patches()) CHECK(p.area == doctest::Approx(1.0 / 9.0).epsilon(1e-5));
  }
  SUBCASE("a pentagon is a fan of three triangles, each meshed on its own") {
    std::vector<glm::vec3> pentagon;
    for (int i = 0; i < 5; ++i) {
      const float a = 2.0f * 3.14159265f * static_cast<float>(i) / 5.0f;
      pentagon.emplace_back(std::cos(a), std::sin(a), 0.0f);
    }
    const PatchHierarchy h(one_polygon(pentagon), MeshOptions{100.0f, 100.0f});
    CHECK(h.patches().size() == 3);
    CHECK(h.vertices().size() == 9);  // vertices are not shared across the fan diagonals
  }
  SUBCASE("every cell of a mixed scene is counter-clockwise about its polygon's normal") {
    const Scene scene = mixed_scene();
    const PatchHierarchy h(scene, MeshOptions{0.3f, 0.05f});
    for (std::uint32_t id = 0; id < h.elements().size(); ++id) {
      const Element& e = h.element(id);
      CHECK(signed_area_along(h, id) == doctest::Approx(e.area).epsilon(1e-4));
      CHECK(inside(h, id, e.centroid, 1e-4f));
    }
    for (const Patch& p : h.patches()) {
      CHECK(p.normal == scene.polygons()[p.polygon].normal);
      CHECK(p.group == scene.polygons()[p.polygon].group);
      CHECK(p.centroid == h.element(p.root).centroid);
      CHECK(h.element(p.root).parent == kNone);
      CHECK(h.element(p.root).depth == 0);
    }
  }
}

TEST_CASE("effective options are derived from the scene's total area") {
  const Scene scene = one_polygon({{0, 0, 0}, {32, 0, 0}, {32, 32, 0}, {0, 32, 0}});
  const PatchHierarchy derived(scene, MeshOptions{});
  CHECK(derived.options().max_patch_area == doctest::Approx(1024.0 / 512.0));
  CHECK(derived.options().max_element_area == doctest::Approx(1024.0 / 512.0 / 4.0));
  // Cells of side <= sqrt(2): a 23 x 23 grid, each patch split once.
  CHECK(derived.patches().size() == 23 * 23);
  CHECK(derived.leaves().size() == 4 * 23 * 23);

  const PatchHierarchy element_only(scene, MeshOptions{0.0f, 8.0f});
  CHECK(element_only.options().max_patch_area == 8.0f);  // raised to the explicit element limit
  CHECK(element_only.options().max_element_area == 8.0f);

  const PatchHierarchy patch_only(scene, MeshOptions{16.0f, 0.0f});
  CHECK(patch_only.options().max_element_area == 4.0f);
}

TEST_CASE("bad options throw Error{invalid_argument} naming the field") {
  const Scene scene = one_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto message = [&](const MeshOptions& o) -> std::string {
    try {
      PatchHierarchy h(scene, o);
    } catch (const Error& e) {
      CHECK(e.code() == ErrorCode::invalid_argument);
      return e.what();
    }
    return "(no throw)";
  };
  CHECK(message(MeshOptions{-1.0f, 0.0f}).find("max_patch_area") != std::string::npos);
  CHECK(message(MeshOptions{nan, 0.0f}).find("max_patch_area") != std::string::npos);
  CHECK(message(MeshOptions{0.0f, -0.5f}).find("max_element_area") != std::string::npos);
  CHECK(message(MeshOptions{0.0f, nan}).find("max_element_area") != std::string::npos);
  const std::string too_big = message(MeshOptions{0.1f, 0.2f});
  CHECK(too_big.find("max_element_area") != std::string::npos);
  CHECK(too_big.find("max_patch_area") != std::string::npos);
  CHECK(message(MeshOptions{1e-12f, 1e-12f}).find("max_element_area") != std::string::npos);  // absurd size
}

TEST_CASE("neighbours subdividing the same edge share its midpoint") {
  SUBCASE("quads") {
    // Two unit patches side by side share the edge x = 1: 6 grid vertices.
    PatchHierarchy h(one_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}}), MeshOptions{1.0f, 1.0f});
    REQUIRE(h.patches().size() == 2);
    REQUIRE(h.vertices().size() == 6);
    h.subdivide(h.patches()[0].root);
    CHECK(h.vertices().size() == 6 + 4 + 1);  // 4 edge midpoints + centre
    h.subdivide(h.patches()[1].root);
    CHECK(h.vertices().size() == 11 + 3 + 1);  // the shared edge's midpoint is reused
    CHECK(h.leaves().size() == 8);
    std::size_t at_shared_midpoint = 0;
    for (const std::uint32_t id : h.leaves())
      for (const std::uint32_t c : h.element(id).corners)
        if (c != kNone && h.vertices()[c] == glm::vec3(1.0f, 0.5f, 0.0f)) ++at_shared_midpoint;
    CHECK(at_shared_midpoint == 4);  // two children on each side touch the one shared vertex
  }
  SUBCASE("triangles") {
    // k = 2: three "up" and one "down" triangle on 6 lattice vertices.
    PatchHierarchy h(one_polygon({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}), MeshOptions{0.5f, 0.5f});
    REQUIRE(h.patches().size() == 4);
    REQUIRE(h.vertices().size() == 6);
    std::size_t added = 0;
    for (const Patch& p : h.patches()) {
      const std::size_t before = h.vertices().size();
      h.subdivide(p.root);
      added += h.vertices().size() - before;
    }
    CHECK(added == 9);  // the 9 edges of the 4 triangles each get exactly one midpoint
    CHECK(h.vertices().size() == 15);  // = the vertex count of a k = 4 lattice
  }
}

TEST_CASE("subdivide keeps leaves() ordered and rejects inner nodes and bad ids") {
  PatchHierarchy h(one_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}}), MeshOptions{1.0f, 1.0f});
  const std::uint32_t root0 = h.patches()[0].root, root1 = h.patches()[1].root;
  const std::uint32_t first = h.subdivide(root0);
  CHECK(h.leaves() == std::vector<std::uint32_t>{first, root1, first + 1, first + 2, first + 3});
  for (std::uint32_t i = 0; i < h.leaves().size(); ++i) CHECK(h.leaf_index(h.leaves()[i]) == i);
  CHECK(h.leaf_index(root0) == kNone);
  for (std::uint32_t k = 0; k < 4; ++k) {
    CHECK(h.element(first + k).parent == root0);
    CHECK(h.element(first + k).depth == 1);
    CHECK(h.element(first + k).patch == 0);
    CHECK(h.element(first + k).area == doctest::Approx(0.25).epsilon(1e-6));
  }
  CHECK_THROWS_AS(h.subdivide(root0), Error);
  CHECK_THROWS_AS(h.subdivide(static_cast<std::uint32_t>(h.elements().size())), Error);
}

TEST_CASE("a constant field is reproduced exactly at every vertex") {
  PatchHierarchy h(mixed_scene(), MeshOptions{0.3f, 0.05f});
  // Irregular refinement, so that T-vertices exist.
  for (std::uint32_t i = 0; i < 40; ++i) h.subdivide(h.leaves()[(i * 7919u) % h.leaves().size()]);
  const Rgb c(0.1f, 0.7f, 3.3f);
  const std::vector<Rgb> values(h.elements().size(), c);
  for (const Rgb& v : h.vertex_values(values)) CHECK(v == c);
}

TEST_CASE("vertex values weigh leaves by their open area: buried leaves neither darken their open neighbours' corners nor "
          "stay black at their own") {
  // A 4 x 1 floor quad meshed into 4 x 1 unit leaves (welded along x), the two at x < 2 under a
  // block (exposure 0, value 0 as a solver leaves them), the others open with value 1 and 3.
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  add_quad(scene, {0, 0, 0}, {4, 0, 0}, {0, 0, -1}, m, "floor");
  PatchHierarchy h(scene, MeshOptions{1.0f, 1.0f});
  REQUIRE(h.leaves().size() == 4);
  std::vector<Rgb> values(h.elements().size(), Rgb(0.0f));
  std::vector<float> exposure(h.elements().size(), 1.0f);
  for (const std::uint32_t leaf : h.leaves()) {
    const float x = h.element(leaf).centroid.x;
    values[leaf] = Rgb(x < 2.0f ? 0.0f : x < 3.0f ? 1.0f : 3.0f);
    exposure[leaf] = x < 2.0f ? 0.0f : 1.0f;
  }
  const std::vector<Rgb> area_weighted = h.vertex_values(values);
  const std::vector<Rgb> open_weighted = h.vertex_values(values, exposure);
  for (std::size_t v = 0; v < h.vertices().size(); ++v) {
    const float x = h.vertices()[v].x;
    CAPTURE(x);
    // Without exposure, the corners at x = 2 take the mean with the buried leaf: 0.5.
    if (x == 2.0f) CHECK(area_weighted[v].x == doctest::Approx(0.5));
    // With it, the open leaf's value there and beyond; under the block, the corners one ring
    // in take the mean of their leaf's known corners (1), and the next ring takes theirs.
    const float expected = x >= 4.0f ? 3.0f : x >= 3.0f ? 2.0f : 1.0f;
    CHECK(open_weighted[v].x == doctest::Approx(expected));
  }
  // Wholly buried: nothing to take a value from, every vertex 0.
  const std::vector<float> buried(h.elements().size(), 0.0f);
  for (const Rgb& v : h.vertex_values(std::vector<Rgb>(h.elements().size(), Rgb(5.0f)), buried)) CHECK(v.x == 0.0f);
  CHECK_THROWS_AS(h.vertex_values(values, std::vector<float>(3, 1.0f)), Error);
}

TEST_CASE("vertex values are continuous across T-vertices - nested ones included (abs 1e-5)") {
  // Patch 1 of a 2x1 strip is refined twice along the shared edge x = 1, patch 0 not at all.
  PatchHierarchy h(one_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}}), MeshOptions{1.0f, 1.0f});
  const std::uint32_t first = h.subdivide(h.patches()[1].root);
  h.subdivide(first);      // child at (c0, m01, ctr, m30): touches x = 1 on [0, 0.5]
  h.subdivide(first + 3);  // child at (m30, ctr, m23, c3): touches x = 1 on [0.5, 1]
  std::vector<Rgb> values(h.elements().size());
  Uniform u;
  for (Rgb& v : values) v = Rgb(u(), u(), u());
  const std::vector<Rgb> vv = h.vertex_values(values);

  // The coarse side interpolates linearly between (1, 0) and (1, 1); the fine side has vertices
  // at y = 0.25, 0.5, 0.75 on that edge. Each must lie on the coarse side's line.
  const auto& v = h.vertices();
  auto vertex_at = [&](float y) {
    for (std::uint32_t i = 0; i < v.size(); ++i)
      if (v[i] == glm::vec3(1.0f, y, 0.0f)) return i;
    return kNone;
  };
  const std::uint32_t a = vertex_at(0.0f), b = vertex_at(1.0f);
  REQUIRE(a != kNone);
  REQUIRE(b != kNone);
  for (const float y : {0.25f, 0.5f, 0.75f}) {
    const std::uint32_t m = vertex_at(y);
    REQUIRE(m != kNone);
    const Rgb expected = (1.0f - y) * vv[a] + y * vv[b];
    CHECK(glm::length(vv[m] - expected) < 1e-5f);
  }
  CHECK(largest_crack(h, vv) < 1e-5f);
}

TEST_CASE("randomly refined meshes have no cracks in their vertex values (abs 1e-5)") {
  // No fan-meshed polygon here: the vertices of neighbouring fan triangles coincide without being
  // shared, so their values may legitimately differ.
  Scene scene;
  const MaterialId material = scene.add_material(Material{});
  scene.add_polygon({{0, 0, 0}, {3, 0, 0}, {0, 2, 0}}, material, "triangle");
  scene.add_polygon({{0, 0, 5}, {4, 0, 5}, {3, 2, 5}, {1, 2, 5}}, material, "trapezoid");
  PatchHierarchy h(scene, MeshOptions{0.5f, 0.5f});
  Uniform u;
  for (int i = 0; i < 60; ++i) {
    const auto& leaves = h.leaves();
    h.subdivide(leaves[static_cast<std::size_t>(u() * static_cast<float>(leaves.size())) % leaves.size()]);
  }
  std::vector<Rgb> values(h.elements().size());
  for (Rgb& v : values) v = Rgb(u(), u(), u());
  const std::vector<Rgb> vv = h.vertex_values(values);
  for (const Rgb& v : vv) CHECK(std::isfinite(v.x + v.y + v.z));
  CHECK(largest_crack(h, vv) < 1e-5f);
}

TEST_CASE("aggregate gives inner nodes the area-weighted mean of their children (relative 1e-5)") {
  PatchHierarchy h(mixed_scene(), MeshOptions{0.3f, 0.05f});
  std::vector<Rgb> values(h.elements().size(), Rgb(-1.0f));  // inner nodes are overwritten
  Uniform u;
  for (const std::uint32_t id : h.leaves()) values[id] = Rgb(u(), u(), u());
  const std::vector<Rgb> leaves_before = values;
  h.aggregate(values);
  for (const std::uint32_t id : h.leaves()) CHECK(values[id] == leaves_before[id]);
  for (const Patch& p : h.patches()) {
    // The root is the area-weighted mean of all leaves below it.
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (const std::uint32_t id : h.leaves())
      if (h.element(id).patch == h.element(p.root).patch) {
        sum += static_cast<double>(h.element(id).area) * glm::dvec3(values[id]);
        area += h.element(id).area;
      }
    const glm::dvec3 mean = sum / area;
    CHECK(values[p.root].x == doctest::Approx(mean.x).epsilon(1e-5));
    CHECK(values[p.root].y == doctest::Approx(mean.y).epsilon(1e-5));
    CHECK(values[p.root].z == doctest::Approx(mean.z).epsilon(1e-5));
  }
  std::vector<Rgb> wrong_size(3);
  CHECK_THROWS_AS(h.aggregate(wrong_size), Error);
  CHECK_THROWS_AS(h.vertex_values(wrong_size), Error);
}

TEST_CASE("sample_point stays inside the element and is area-uniform (5 sigma)") {
  // One trapezoid patch (cells of unequal triangles) and one triangle patch.
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  scene.add_polygon({{0, 0, 0}, {4, 0, 0}, {3, 1, 0}, {1, 1, 0}}, m, "trapezoid");
  scene.add_polygon({{0, 0, 2}, {0, 3, 2}, {1, 0, 2}}, m, "triangle");
  PatchHierarchy h(scene, MeshOptions{100.0f, 100.0f});
  REQUIRE(h.patches().size() == 2);
  for (const Patch& p : h.patches()) {
    const std::uint32_t root = p.root;
    const std::uint32_t first = h.subdivide(root);  // children to count samples in
    const int n = 40000;
    Uniform u;
    glm::dvec3 mean(0.0);
    int in_child[4] = {0, 0, 0, 0};
    bool all_inside = true;
    for (int i = 0; i < n; ++i) {
      const glm::vec3 x = h.sample_point(root, glm::vec2(u(), u()));
      all_inside = all_inside && inside(h, root, x, 1e-5f);
      mean += glm::dvec3(x);
      for (std::uint32_t k = 0; k < 4; ++k)
        if (inside(h, first + k, x, 1e-6f)) {
          ++in_child[k];
          break;
        }
    }
    CHECK(all_inside);
    CHECK(in_child[0] + in_child[1] + in_child[2] + in_child[3] == n);
    mean /= double(n);
    // Coordinates span <= 4 units, so their standard deviation is < 2 and the mean's < 2/sqrt(n) = 0.01.
    CHECK(glm::length(mean - glm::dvec3(h.element(root).centroid)) < 0.05);
    for (std::uint32_t k = 0; k < 4; ++k) {
      const double q = double(h.element(first + k).area) / double(h.element(root).area);
      const double sigma = std::sqrt(n * q * (1.0 - q));
      CHECK(std::fabs(in_child[k] - n * q) < 5.0 * sigma);
    }
  }
}

TEST_CASE("meshing is deterministic") {
  const Scene scene = mixed_scene();
  const PatchHierarchy a(scene, MeshOptions{0.3f, 0.05f}), b(scene, MeshOptions{0.3f, 0.05f});
  REQUIRE(a.elements().size() == b.elements().size());
  CHECK(a.leaves() == b.leaves());
  CHECK(a.vertices() == b.vertices());
  for (std::size_t i = 0; i < a.elements().size(); ++i) CHECK(a.elements()[i].corners == b.elements()[i].corners);
}

TEST_CASE("the default Cornell box meshes into a few hundred patches and a few thousand elements") {
  const Scene scene = cornell_box();
  const PatchHierarchy h(scene, MeshOptions{});
  const std::size_t patches = h.patches().size(), leaves = h.leaves().size();
  MESSAGE("Cornell box, default options: " << patches << " patches, " << leaves << " leaf elements, "
                                           << h.elements().size() << " elements, " << h.vertices().size()
                                           << " vertices");
  CHECK(patches >= 200);
  CHECK(patches <= 1500);
  CHECK(leaves >= 1000);
  CHECK(leaves <= 10000);
  double area = 0.0;
  for (const std::uint32_t id : h.leaves()) area += h.element(id).area;
  CHECK(area == doctest::Approx(scene.total_area()).epsilon(1e-5));
}

TEST_CASE("a ground's elements are graded toward a house standing on it when they are larger than the house") {
  // A 10 m wide, 3 m high house (a box) on a 1 km plot: the default elements are 21.7 m
  // across, larger than the house, so its shadow and contact could not show. Graded
  // (MeshOptions::grade_at_contacts), the ground's elements across the house's walls are at
  // most a quarter of its size (its height, 3 m, the smaller), grow to at most about half
  // their distance from it, and far away are as before.
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  scene.add_polygon({{-500, 0, 500}, {500, 0, 500}, {500, 0, -500}, {-500, 0, -500}}, m, "ground");
  add_box(scene, {-5, 0, -5}, {5, 3, 5}, m, "house");
  const PatchHierarchy graded(scene, MeshOptions{});
  MeshOptions off;
  off.grade_at_contacts = false;
  const PatchHierarchy plain(scene, off);
  const GroupId ground = *scene.find_group("ground");
  double area = 0.0, largest = 0.0, largest_plain = 0.0, at_house = 0.0, worst_grading = 0.0;
  std::size_t ground_leaves = 0;
  for (const std::uint32_t id : graded.leaves()) {
    const Element& e = graded.element(id);
    area += e.area;
    if (scene.polygons()[graded.patches()[e.patch].polygon].group != ground) continue;
    ++ground_leaves;
    const double edge = std::sqrt(static_cast<double>(e.area));
    largest = std::max(largest, edge);
    // The gap between the element and the house's footprint, |x|, |z| <= 5 (0 where they
    // meet), and whether it lies wholly inside the footprint.
    float gap = 0.0f;
    bool inside = true;
    for (int k = 0; k < 3; k += 2) {
      float lo = 1e9f, hi = -1e9f;
      for (int c = 0; c < e.corner_count(); ++c) {
        lo = std::min(lo, graded.vertices()[e.corners[static_cast<std::size_t>(c)]][k]);
        hi = std::max(hi, graded.vertices()[e.corners[static_cast<std::size_t>(c)]][k]);
      }
      gap = std::max({gap, lo - 5.0f, -5.0f - hi});
      inside = inside && lo > -5.0f && hi < 5.0f;
    }
    if (gap <= 0.0f && !inside) at_house = std::max(at_house, edge);
    // Beyond the contact, no element larger than about half its distance: the rule splits
    // while edge > max(0.75, gap / 2), gap measured from the element's centre less its
    // radius (here from its bounds: measured 0.65).
    if (gap > 0.0f && edge > 0.75) worst_grading = std::max(worst_grading, edge / static_cast<double>(gap));
  }
  for (const std::uint32_t id : plain.leaves()) {
    const Element& e = plain.element(id);
    if (scene.polygons()[plain.patches()[e.patch].polygon].group == ground)
      largest_plain = std::max(largest_plain, std::sqrt(static_cast<double>(e.area)));
  }
  MESSAGE("ground leaves " << ground_leaves << " (without grading " << plain.leaves().size() - 6
                           << "), at the house " << at_house << " m, largest " << largest << " m, worst edge / gap "
                           << worst_grading);
  CHECK(area == doctest::Approx(scene.total_area()).epsilon(1e-5));
  CHECK(at_house <= 0.75);
  CHECK(largest == doctest::Approx(largest_plain));
  CHECK(largest_plain > 20.0);
  CHECK(worst_grading <= 1.0);
  // About a thousand elements more (1 008), not the plot at the house's scale (millions):
  // the grading follows the house.
  CHECK(graded.leaves().size() > plain.leaves().size() + 100);
  CHECK(graded.leaves().size() < plain.leaves().size() + 2000);
  // And it says what it did.
  CHECK(graded.contact_grading().polygons == 1);
  CHECK(graded.contact_grading().added_leaves == graded.leaves().size() - plain.leaves().size());
  CHECK(!graded.contact_grading().budget_reached);
  CHECK(graded.contact_grading().coarse.empty());
  // A 0.7 m crate on a 10 km plot: 8 levels below 217 m elements leave 0.85 m, larger than the
  // crate, and the grading says where (what `radiosity check` warns about).
  Scene plot;
  const MaterialId pm = plot.add_material(Material{});
  plot.add_polygon({{-5000, 0, 5000}, {5000, 0, 5000}, {5000, 0, -5000}, {-5000, 0, -5000}}, pm, "ground");
  add_box(plot, {0, 0, 0}, {0.7f, 0.7f, 0.7f}, pm, "crate");
  const ContactGrading crate = PatchHierarchy(plot, MeshOptions{}).contact_grading();
  REQUIRE(crate.coarse.size() == 1);
  CHECK(crate.coarse[0].polygon == 0);
  CHECK(plot.polygons()[crate.coarse[0].other].group == *plot.find_group("crate"));
  // 23 x 23 patches of 2 x 2 elements (217 m), 8 levels down.
  CHECK(crate.coarse[0].element == doctest::Approx(10000.0 / 23 / 2 / 256).epsilon(1e-3));
  CHECK(crate.coarse[0].object == doctest::Approx(0.7));
  CHECK(plain.contact_grading().polygons == 0);
  CHECK(plain.contact_grading().added_leaves == 0);
  // Where the elements are smaller than what stands on them, nothing changes (the Cornell
  // box's blocks, 165 mm, on its 31 mm floor elements).
  const Scene cornell = cornell_box();
  MeshOptions cornell_off;
  cornell_off.grade_at_contacts = false;
  CHECK(PatchHierarchy(cornell, MeshOptions{}).leaves() == PatchHierarchy(cornell, cornell_off).leaves());
  // Nor for a rug 1 cm thick, larger than the floor's elements: its thickness is no reason to
  // mesh its border at centimetres.
  Scene room;
  const MaterialId w = room.add_material(Material{});
  add_box(room, {0, 0, 0}, {4, 2.5f, 4}, w, "room");
  add_box(room, {1, 0, 1}, {3, 0.01f, 3}, w, "rug");
  CHECK(PatchHierarchy(room, MeshOptions{}).contact_grading().polygons == 0);
}

}  // TEST_SUITE("mesh")

TEST_CASE("a floor is cut along feet that cross it as a chain of facets, not along a block standing inside it nor a "
          "wall ending inside it") {
  // The floor [0, 10] x [0, 10] at y = 0 facing up; walls of height 2 cut into 3 x 3 facets as
  // exporters write a subdivided face (each facet's foot a contact segment ending inside it).
  auto floor_pieces = [](const std::vector<std::array<glm::vec3, 2>>& feet) {
    Scene scene;
    const MaterialId m = scene.add_material(Material{});
    add_quad(scene, {0, 0, 10}, {10, 0, 0}, {0, 0, -10}, m, "floor");
    for (const auto& [a, b] : feet) {
      const glm::vec3 u = (b - a) / 3.0f, v(0.0f, 2.0f / 3.0f, 0.0f);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          add_quad(scene, a + static_cast<float>(i) * u + static_cast<float>(j) * v, u, v, m, "wall");
    }
    const PatchHierarchy h(scene, MeshOptions{1000.0f, 1000.0f});
    std::size_t pieces = 0;
    for (const Patch& p : h.patches()) pieces += p.polygon == 0 ? 1 : 0;
    return pieces;
  };
  CHECK(floor_pieces({}) == 1);
  // A partition across the floor at 17 degrees, in three facets: two pieces, as one quad
  // from border to border gives.
  const glm::vec3 w0(0.0f, 0.0f, 3.0f), w1(10.0f, 0.0f, 6.0573f);
  CHECK(floor_pieces({{w0, w1}}) == 2);
  // An L of two such walls from border to border (a building's corner standing on the floor):
  // the floor is cut along both lines, four pieces.
  const glm::vec3 corner(6.0f, 0.0f, 4.2f);
  CHECK(floor_pieces({{glm::vec3(0.0f, 0.0f, 2.5f), corner}, {corner, glm::vec3(7.3f, 0.0f, 10.0f)}}) == 4);
  // A block's four feet, a closed chain inside the floor, a wall that stops in the middle of
  // it, and a small block standing across its corner (feet 2 m long, under a quarter of the
  // floor's diameter: 1 % of it buried, which the exposure handles): not cut (the mesh is
  // graded toward them instead).
  const glm::vec3 b0(3, 0, 3), b1(6, 0, 3.5f), b2(5.5f, 0, 6.5f), b3(2.5f, 0, 6);
  CHECK(floor_pieces({{b0, b1}, {b1, b2}, {b2, b3}, {b3, b0}}) == 1);
  CHECK(floor_pieces({{w0, 0.5f * (w0 + w1)}}) == 1);
  const glm::vec3 c0(0.0f, 0.0f, 1.0f), c1(1.0f, 0.0f, 1.0f), c2(1.0f, 0.0f, 0.0f);
  CHECK(floor_pieces({{c0, c1}, {c1, c2}}) == 1);
}

TEST_CASE("the pieces of a cut floor share their vertices along the cut lines beyond the walls' feet, not along "
          "the feet") {
  // The floor cut by an L of two faceted walls (a building's corner standing on it): four
  // pieces. Along the feet the two sides are lit differently and keep vertices of their own;
  // along each line's run beyond the corner nothing stands, and the pieces' vertex values there
  // were broken too (faint lines from a box's feet across an exported floor), since the pieces
  // shared no vertices with each other.
  Scene scene;
  const MaterialId m = scene.add_material(Material{});
  add_quad(scene, {0, 0, 10}, {10, 0, 0}, {0, 0, -10}, m, "floor");
  const glm::vec3 a(0.0f, 0.0f, 2.5f), corner(6.0f, 0.0f, 4.2f), b(7.3f, 0.0f, 10.0f);
  for (const auto& [from, to] : {std::pair{a, corner}, std::pair{corner, b}}) {
    const glm::vec3 u = (to - from) / 3.0f, v(0.0f, 2.0f / 3.0f, 0.0f);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) add_quad(scene, from + static_cast<float>(i) * u + static_cast<float>(j) * v, u, v, m, "wall");
  }
  // The side of each foot's line a point lies on: the quadrant (0 .. 3) the two lines make.
  auto quadrant = [&](const glm::vec3& x) {
    auto side = [](const glm::vec3& p, const glm::vec3& q, const glm::vec3& y) {
      return (q.x - p.x) * (y.z - p.z) - (q.z - p.z) * (y.x - p.x) > 0.0f ? 1 : 0;
    };
    return side(a, corner, x) + 2 * side(corner, b, x);
  };
  auto distance_to_segment = [](const glm::vec3& x, const glm::vec3& p, const glm::vec3& q) {
    const glm::vec3 d = q - p;
    const float t = std::clamp(glm::dot(x - p, d) / glm::dot(d, d), 0.0f, 1.0f);
    return glm::length(x - (p + t * d));
  };
  auto distance_to_line = [](const glm::vec3& x, const glm::vec3& p, const glm::vec3& q) {
    const glm::vec3 d = glm::normalize(q - p);
    return glm::length((x - p) - glm::dot(x - p, d) * d);
  };
  for (const float element_area : {1000.0f, 1.0f}) {
    CAPTURE(element_area);
    const PatchHierarchy h(scene, MeshOptions{element_area, element_area});
    // The floor's leaves take 10 x their quadrant: each quadrant uniform, a step between them.
    std::vector<Rgb> values(h.elements().size(), Rgb(0.0f));
    for (std::uint32_t leaf : h.leaves())
      if (h.patches()[h.element(leaf).patch].polygon == 0)
        values[leaf] = Rgb(10.0f * static_cast<float>(quadrant(h.element(leaf).centroid)));
    const std::vector<Rgb> at = h.vertex_values(values);
    // Per position (exact): the quadrant of each floor leaf with a corner there, and the
    // value of that corner's vertex.
    std::map<std::array<float, 3>, std::vector<std::pair<int, float>>> by_position;
    for (std::uint32_t leaf : h.leaves()) {
      const Element& e = h.element(leaf);
      if (h.patches()[e.patch].polygon != 0) continue;
      for (int c = 0; c < e.corner_count(); ++c) {
        const std::uint32_t v = e.corners[static_cast<std::size_t>(c)];
        const glm::vec3& x = h.vertices()[v];
        by_position[{x.x, x.y, x.z}].push_back({quadrant(e.centroid), at[v].x});
      }
    }
    int on_feet = 0, beyond = 0;
    for (const auto& [key, seen] : by_position) {
      const glm::vec3 x(key[0], key[1], key[2]);
      if (glm::length(x - corner) < 1e-4f) continue;
      bool two_sides = false;
      float lo = seen[0].second, hi = seen[0].second;
      for (const auto& [q, value] : seen) {
        two_sides = two_sides || q != seen[0].first;
        lo = std::min(lo, value);
        hi = std::max(hi, value);
      }
      if (!two_sides) continue;  // a lattice point of one side only
      const bool foot = distance_to_segment(x, a, corner) < 1e-4f || distance_to_segment(x, corner, b) < 1e-4f;
      const bool line = distance_to_line(x, a, corner) < 1e-4f || distance_to_line(x, corner, b) < 1e-4f;
      REQUIRE(line);  // quadrants meet only on the lines
      if (foot) {
        ++on_feet;
        CHECK(hi - lo > 5.0f);  // each side its own value
      } else {
        ++beyond;
        CHECK(hi - lo < 1e-4f);  // one value, shared across the line
      }
    }
    CHECK(on_feet >= 2);
    CHECK(beyond >= 2);
  }
}

TEST_CASE("meshing with a progress callback: the same mesh, reported from 0 to 1; a cancel leaves it empty") {
  const Scene scene = mixed_scene();
  MeshOptions o;
  o.max_element_area = 0.01f;
  const PatchHierarchy plain(scene, o);
  std::vector<double> fractions;
  const PatchHierarchy reported(scene, o, [&](const Progress& p) {
    CHECK(p.phase == Phase::meshing);
    fractions.push_back(p.fraction);
    return true;
  });
  CHECK(reported.leaves() == plain.leaves());
  CHECK(reported.vertices().size() == plain.vertices().size());
  REQUIRE(fractions.size() >= 2);
  CHECK(fractions.front() == 0.0);
  CHECK(fractions.back() == 1.0);
  for (std::size_t k = 1; k < fractions.size(); ++k) CHECK(fractions[k] >= fractions[k - 1]);

  int calls = 0;
  const PatchHierarchy cancelled(scene, o, [&](const Progress&) { return ++calls < 1; });
  CHECK(calls == 1);  // not called again after the cancel
  CHECK(cancelled.patches().empty());
  CHECK(cancelled.leaves().empty());
  CHECK(cancelled.elements().empty());

  // Cancelled while meshing, solve() returns cancelled with no elements (and without copying
  // the scene's meshes).
  SolveOptions so;
  so.mesh = o;
  so.on_progress = [](const Progress& p) { return p.phase != Phase::meshing; };
  const Solution s = solve(scene, so);
  CHECK(s.status() == SolveStatus::cancelled);
  CHECK(s.hierarchy().leaves().empty());
}
