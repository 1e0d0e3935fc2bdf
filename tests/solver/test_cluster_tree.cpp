// The cluster hierarchy of hierarchical radiosity (src/solver/hierarchical/cluster_tree.hpp):
// the tree's structure, bounds, determinism and depth; the directional moments' energy
// conservation and exactness for axis-aligned surfaces; the receiving moments; the moment
// bases (exact for a turned box) and their transposes, which the balancing's adjoint uses.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <utility>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"
#include "city.hpp"
#include "solver/hierarchical/cluster_tree.hpp"

namespace rad = radiosity;
namespace hr = radiosity::detail;

namespace {

constexpr double kPiD = 3.14159265358979323846;

/// One quad of side `size` in the z = 0 plane facing +z, meshed into patches of `patch_area`.
rad::PatchHierarchy grid(float size, float patch_area) {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  scene.add_polygon({{0, 0, 0}, {size, 0, 0}, {size, size, 0}, {0, size, 0}}, m, "grid");
  return rad::PatchHierarchy(scene, rad::MeshOptions{patch_area, patch_area});
}

/// The box [0,1]^3 as six outward-facing quads, turned by `degrees` about the vertical line
/// through its centre, each face cut bilinearly into cuts x cuts facets (as an exporter writes
/// them: their normals differ in the last bits when the box is turned), one patch each.
rad::PatchHierarchy outward_box(float degrees = 0.0f, int cuts = 1) {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  const glm::vec3 centre(0.5f);
  const float t = degrees * static_cast<float>(kPiD) / 180.0f;
  auto add = [&](std::vector<glm::vec3> q) {
    const glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
    if (glm::dot(n, centre - q[0]) > 0.0f) std::reverse(q.begin(), q.end());
    for (glm::vec3& x : q) {
      const glm::vec3 d = x - centre;
      x = centre + glm::vec3(std::cos(t) * d.x + std::sin(t) * d.z, d.y, -std::sin(t) * d.x + std::cos(t) * d.z);
    }
    auto at = [&](int i, int j) {
      const float u = static_cast<float>(i) / static_cast<float>(cuts), v = static_cast<float>(j) / static_cast<float>(cuts);
      return (1.0f - v) * ((1.0f - u) * q[0] + u * q[1]) + v * ((1.0f - u) * q[3] + u * q[2]);
    };
    for (int i = 0; i < cuts; ++i)
      for (int j = 0; j < cuts; ++j) scene.add_polygon({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}, m);
  };
  add({{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}});
  add({{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}});
  add({{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}});
  add({{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}});
  add({{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}});
  add({{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}});
  return rad::PatchHierarchy(scene, rad::MeshOptions{2.0f, 2.0f});
}

/// A city of issue #15's benchmark (`blocks` x `blocks`, facets of 2.25 m): buildings, streets
/// and many coplanar facets, one patch each.
rad::PatchHierarchy city_patches(int blocks) {
  bench::CityOptions o;
  o.blocks = blocks;
  return rad::PatchHierarchy(bench::city(o).scene, rad::MeshOptions{1e4f, 1e4f});
}

/// Per-patch radiosities, each channel in [0.1, 2), from a fixed seed.
std::vector<rad::Rgb> random_radiosities(std::size_t count, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(0.1f, 2.0f);
  std::vector<rad::Rgb> B(count);
  for (auto& b : B) b = rad::Rgb(u(gen), u(gen), u(gen));
  return B;
}

/// Integral of I(w) over the sphere: midpoint rule on an equal-area (cos theta, phi) grid.
glm::dvec3 integrate_intensity(const hr::Moments& P, const hr::MomentBasis& b, int steps) {
  glm::dvec3 sum(0.0);
  for (int i = 0; i < steps; ++i) {
    const double z = -1.0 + 2.0 * (i + 0.5) / steps;
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    for (int j = 0; j < 2 * steps; ++j) {
      const double phi = kPiD * (j + 0.5) / steps;
      const glm::vec3 w(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                        static_cast<float>(z));
      sum += glm::dvec3(hr::intensity(P, b, w));
    }
  }
  return sum * (4.0 * kPiD / (2.0 * steps * steps));
}

std::vector<glm::vec3> random_directions(int count, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> out;
  while (static_cast<int>(out.size()) < count) {
    const glm::vec3 v(g(gen), g(gen), g(gen));
    if (glm::length(v) > 1e-3f) out.push_back(glm::normalize(v));
  }
  return out;
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("node handles put clusters and elements in one id space") {
  const hr::NodeHandle c = hr::cluster_handle(12345);
  const hr::NodeHandle e = hr::element_handle(12345);
  CHECK(hr::is_cluster(c));
  CHECK_FALSE(hr::is_cluster(e));
  CHECK(c != e);
  CHECK(hr::handle_index(c) == 12345u);
  CHECK(hr::handle_index(e) == 12345u);
  CHECK(hr::handle_index(hr::cluster_handle(0x7fffffffu)) == 0x7fffffffu);
}

TEST_CASE("the cluster tree covers every patch once and each node bounds its patches") {
  for (const bool cornell : {true, false}) {
    CAPTURE(cornell);
    const rad::PatchHierarchy h =
        cornell ? rad::PatchHierarchy(rad::cornell_box(), rad::MeshOptions{}) : city_patches(1);
    const hr::ClusterTree tree(h);
    const std::size_t n = h.patches().size();
    REQUIRE(n > 100);
    REQUIRE(tree.nodes().size() == 2 * n - 1);

    // The permutation holds every patch once; each leaf one patch, and leaf_of() finds it.
    std::vector<int> seen(n, 0);
    for (std::uint32_t p : tree.order()) ++seen[p];
    CHECK(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
    const hr::ClusterNode& root = tree.node(hr::ClusterTree::root());
    CHECK(root.first == 0);
    CHECK(root.count == n);

    for (std::uint32_t id = 0; id < tree.nodes().size(); ++id) {
      const hr::ClusterNode& node = tree.node(id);
      CAPTURE(id);
      if (node.is_leaf()) {
        REQUIRE(node.count == 1);
        CHECK(tree.leaf_of(tree.order()[node.first]) == id);
      } else {
        // Children split the parent's range, and come after it.
        const hr::ClusterNode& l = tree.node(node.children[0]);
        const hr::ClusterNode& r = tree.node(node.children[1]);
        CHECK(node.children[0] > id);
        CHECK(node.children[1] > id);
        CHECK(l.first == node.first);
        CHECK(r.first == l.first + l.count);
        CHECK(l.count + r.count == node.count);
      }
      // Bounds and sphere contain every corner of its patches; area is their sum.
      double area = 0.0;
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const rad::Patch& patch = h.patches()[tree.order()[k]];
        area += patch.area;
        const rad::Element& e = h.element(patch.root);
        for (int c = 0; c < e.corner_count(); ++c) {
          const glm::vec3& v = h.vertices()[e.corners[c]];
          CHECK(glm::all(glm::lessThanEqual(node.bounds.lower, v)));
          CHECK(glm::all(glm::lessThanEqual(v, node.bounds.upper)));
          CHECK(glm::length(v - node.centre) <= node.radius * (1.0f + 1e-5f) + 1e-6f);
        }
      }
      CHECK(node.area == doctest::Approx(area).epsilon(1e-5));
    }
  }
}

TEST_CASE("the cluster tree is the same when built twice") {
  const rad::PatchHierarchy h(rad::cornell_box(), rad::MeshOptions{});
  const hr::ClusterTree a(h), b(h);
  REQUIRE(a.nodes().size() == b.nodes().size());
  CHECK(a.order() == b.order());
  for (std::size_t i = 0; i < a.nodes().size(); ++i) {
    const hr::ClusterNode& x = a.nodes()[i];
    const hr::ClusterNode& y = b.nodes()[i];
    CHECK(x.children == y.children);
    CHECK(x.first == y.first);
    CHECK(x.count == y.count);
    CHECK(x.bounds.lower == y.bounds.lower);
    CHECK(x.bounds.upper == y.bounds.upper);
    CHECK(x.radius == y.radius);
    CHECK(x.area == y.area);
  }
}

TEST_CASE("the cluster tree over 10k patches is ceil(log2 n) deep on a grid and a city") {
  const rad::PatchHierarchy h = grid(100.0f, 1.0f);
  const std::size_t n = h.patches().size();
  REQUIRE(n >= 10000);
  const hr::ClusterTree tree(h);
  CHECK(tree.depth() == static_cast<int>(std::ceil(std::log2(static_cast<double>(n)))));

  // The same on a city, whose coplanar facets tie on every axis but one.
  const rad::PatchHierarchy c = city_patches(2);
  REQUIRE(c.patches().size() >= 10000);
  CHECK(hr::ClusterTree(c).depth() == static_cast<int>(std::ceil(std::log2(static_cast<double>(c.patches().size())))));
}

TEST_CASE("a tree over no patches is empty and over one patch is a single leaf") {
  const hr::ClusterTree none{rad::PatchHierarchy()};
  CHECK(none.empty());
  const rad::PatchHierarchy one = grid(1.0f, 2.0f);
  REQUIRE(one.patches().size() == 1);
  const hr::ClusterTree tree(one);
  REQUIRE(tree.nodes().size() == 1);
  CHECK(tree.node(0).is_leaf());
  CHECK(tree.depth() == 0);
}

TEST_CASE("sending moments conserve energy: I integrates to sum B A over the sphere (relative 1e-3)") {
  // The Cornell box's blocks are turned about y, so their normals are off the axes.
  const rad::PatchHierarchy h(rad::cornell_box(), rad::MeshOptions{});
  const hr::ClusterTree tree(h);
  const std::vector<rad::Rgb> B = random_radiosities(h.patches().size(), 7);
  const hr::MomentBases bases(tree, h, std::vector<std::uint8_t>(h.patches().size(), 0));
  std::vector<hr::Moments> P;
  hr::sending_moments(tree, h, bases, B, {}, 2, P);
  glm::dvec3 power(0.0);
  for (std::size_t p = 0; p < B.size(); ++p) power += glm::dvec3(B[p]) * static_cast<double>(h.patches()[p].area);
  const glm::dvec3 integral = integrate_intensity(P[hr::ClusterTree::root()], bases.of(hr::ClusterTree::root()), 600);
  for (int c = 0; c < 3; ++c) CHECK(integral[c] == doctest::Approx(power[c]).epsilon(1e-3));

  // Tilted normals too: one surface along (1, -2, 3).
  hr::Moments tilted{};
  hr::add_surface(tilted, glm::vec3(1.0f, -2.0f, 3.0f), rad::Rgb(2.0f, 1.0f, 0.5f));
  const glm::dvec3 t = integrate_intensity(tilted, hr::MomentBasis{}, 600);
  CHECK(t.x == doctest::Approx(2.0).epsilon(1e-3));
  CHECK(t.y == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(t.z == doctest::Approx(0.5).epsilon(1e-3));
}

TEST_CASE("sending moments are the same at 1 and 2 threads") {
  const rad::PatchHierarchy h = grid(100.0f, 1.0f);
  const hr::ClusterTree tree(h);
  const std::vector<rad::Rgb> B = random_radiosities(h.patches().size(), 3);
  const hr::MomentBases bases(tree, h, std::vector<std::uint8_t>(h.patches().size(), 0));
  std::vector<hr::Moments> one, two;
  hr::sending_moments(tree, h, bases, B, {}, 1, one);
  hr::sending_moments(tree, h, bases, B, {}, 2, two);
  CHECK(one == two);
}

TEST_CASE("an axis-aligned patch sends exactly B A max(0, n.w) / pi in every direction") {
  for (const glm::vec3& n : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, -1, 0),
                             glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)}) {
    CAPTURE(n);
    const float A = 0.75f;
    const rad::Rgb B(1.0f, 2.0f, 3.0f);
    hr::Moments P{};
    hr::add_surface(P, n, B * A);
    for (const glm::vec3& w : random_directions(200, 11)) {
      const rad::Rgb exact = B * A * std::max(0.0f, glm::dot(n, w)) / static_cast<float>(kPiD);
      const rad::Rgb I = hr::intensity(P, w);
      for (int c = 0; c < 3; ++c) CHECK(I[c] == doctest::Approx(exact[c]).epsilon(1e-6));
    }
  }
}

TEST_CASE("a box cluster sends what its six faces send") {
  const rad::PatchHierarchy h = outward_box();
  REQUIRE(h.patches().size() == 6);
  const hr::ClusterTree tree(h);
  const std::vector<rad::Rgb> B = random_radiosities(6, 5);
  std::vector<hr::Moments> P;
  hr::sending_moments(tree, h, hr::MomentBases(tree, h, std::vector<std::uint8_t>(6, 0)), B, {}, 1, P);
  std::vector<glm::vec3> directions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& w : random_directions(50, 13)) directions.push_back(w);
  for (const glm::vec3& w : directions) {
    CAPTURE(w);
    rad::Rgb faces(0.0f);
    for (std::size_t p = 0; p < 6; ++p) {
      const rad::Patch& patch = h.patches()[p];
      faces += B[p] * patch.area * std::max(0.0f, glm::dot(patch.normal, w)) / static_cast<float>(kPiD);
    }
    const rad::Rgb I = hr::intensity(P[hr::ClusterTree::root()], w);
    for (int c = 0; c < 3; ++c) CHECK(I[c] == doctest::Approx(faces[c]).epsilon(1e-5));
  }
}

TEST_CASE("an axis-aligned element receives flux x cos from the side it faces and nothing from behind") {
  const rad::Rgb flux(4.0f, 2.0f, 1.0f);
  const glm::vec3 d = glm::normalize(glm::vec3(0.6f, 0.8f, 0.0f));  // toward the source
  hr::Moments E{};
  hr::add_irradiance(E, d, flux);
  const rad::Rgb facing = hr::element_irradiance(E, glm::vec3(1, 0, 0));
  const rad::Rgb up = hr::element_irradiance(E, glm::vec3(0, 1, 0));
  for (int c = 0; c < 3; ++c) {
    CHECK(facing[c] == doctest::Approx(flux[c] * d.x).epsilon(1e-6));
    CHECK(up[c] == doctest::Approx(flux[c] * d.y).epsilon(1e-6));
  }
  CHECK(hr::element_irradiance(E, glm::vec3(-1, 0, 0)) == rad::Rgb(0.0f));
  CHECK(hr::element_irradiance(E, glm::vec3(0, -1, 0)) == rad::Rgb(0.0f));
  CHECK(hr::element_irradiance(E, glm::vec3(0, 0, 1)) == rad::Rgb(0.0f));

  // Head-on: the element facing the source gets the whole flux; two links add up.
  hr::Moments head_on{};
  hr::add_irradiance(head_on, glm::vec3(0, 0, -1), flux);
  hr::add_irradiance(head_on, glm::vec3(0, 0, -1), flux);
  CHECK(hr::element_irradiance(head_on, glm::vec3(0, 0, -1)) == 2.0f * flux);
  CHECK(hr::element_irradiance(head_on, glm::vec3(0, 0, 1)) == rad::Rgb(0.0f));
}

TEST_CASE("moment bases: one moment per direction for a turned box, the axes for an upright one or more than six") {
  const rad::PatchHierarchy upright = outward_box();
  const hr::ClusterTree upright_tree(upright);
  const hr::MomentBases axes(upright_tree, upright, std::vector<std::uint8_t>(6, 0));
  CHECK(axes.explicit_clusters() == 0);  // every side along an axis: the axis moments are exact
  for (std::uint32_t c = 0; c < upright_tree.nodes().size(); ++c) CHECK(axes.of(c).axes);

  const rad::PatchHierarchy turned = outward_box(30.0f);
  const hr::ClusterTree tree(turned);
  const hr::MomentBases bases(tree, turned, std::vector<std::uint8_t>(6, 0));
  // Turned about y, the top and bottom stay along the axes: their leaves keep the axes.
  CHECK(bases.explicit_clusters() == tree.nodes().size() - 2);
  const hr::MomentBasis& root = bases.of(hr::ClusterTree::root());
  REQUIRE(!root.axes);
  CHECK(root.count == 6);
  for (std::uint32_t p = 0; p < 6; ++p) {
    const glm::vec3& n = turned.patches()[p].normal;
    const int k = root.slot(bases.front(p, n).id);
    REQUIRE(k >= 0);
    CHECK(glm::length(root.directions[static_cast<std::size_t>(k)] - n) < 1e-6f);
  }
  // Two-sided: each face's back faces where the opposite face's front does, still six.
  const hr::MomentBases two_sided(tree, turned, std::vector<std::uint8_t>(6, 1));
  CHECK(!two_sided.of(hr::ClusterTree::root()).axes);
  CHECK(two_sided.of(hr::ClusterTree::root()).count == 6);

  // The same box with each face cut into 6 x 6 facets: their normals differ in the last bits
  // (more than six distinct ones), yet they are six directions, one per face.
  const rad::PatchHierarchy faceted = outward_box(30.0f, 6);
  REQUIRE(faceted.patches().size() == 6 * 36);
  std::vector<std::array<float, 3>> normals;
  for (const rad::Patch& patch : faceted.patches()) normals.push_back({patch.normal.x, patch.normal.y, patch.normal.z});
  std::sort(normals.begin(), normals.end());
  CHECK(std::unique(normals.begin(), normals.end()) - normals.begin() > 6);
  const hr::ClusterTree faceted_tree(faceted);
  const hr::MomentBases faceted_bases(faceted_tree, faceted, std::vector<std::uint8_t>(faceted.patches().size(), 0));
  const hr::MomentBasis& faceted_root = faceted_bases.of(hr::ClusterTree::root());
  CHECK(!faceted_root.axes);
  CHECK(faceted_root.count == 6);
  for (std::uint32_t p = 0; p < faceted.patches().size(); ++p) {
    const glm::vec3& n = faceted.patches()[p].normal;
    const int k = faceted_root.slot(faceted_bases.front(p, n).id);
    REQUIRE(k >= 0);
    CHECK(glm::length(faceted_root.directions[static_cast<std::size_t>(k)] - n) < 1e-5f);
  }

  // The Cornell box faces more than six directions (its blocks are turned): its root keeps the
  // axes, the clusters of one block do not.
  const rad::PatchHierarchy cornell(rad::cornell_box(), rad::MeshOptions{});
  const hr::ClusterTree cornell_tree(cornell);
  const hr::MomentBases cornell_bases(cornell_tree, cornell, std::vector<std::uint8_t>(cornell.patches().size(), 0));
  CHECK(cornell_bases.of(hr::ClusterTree::root()).axes);
  CHECK(cornell_bases.explicit_clusters() > 0);
  CHECK(cornell_bases.explicit_clusters() < cornell_tree.nodes().size());
}

TEST_CASE("a turned box cluster sends and receives exactly per face, where the axis moments err by over 10 %") {
  const rad::PatchHierarchy h = outward_box(30.0f);
  const hr::ClusterTree tree(h);
  const hr::MomentBases bases(tree, h, std::vector<std::uint8_t>(6, 0));
  const std::vector<rad::Rgb> B = random_radiosities(6, 5);
  std::vector<hr::Moments> P;
  hr::sending_moments(tree, h, bases, B, {}, 1, P);
  hr::Moments on_axes{};  // the same faces on the axes: what the solver did before bases
  for (std::size_t p = 0; p < 6; ++p) hr::add_surface(on_axes, h.patches()[p].normal, B[p] * h.patches()[p].area);
  const hr::MomentBasis& root = bases.of(hr::ClusterTree::root());
  double worst_axes = 0.0;
  for (const glm::vec3& w : random_directions(200, 13)) {
    CAPTURE(w);
    rad::Rgb faces(0.0f);
    for (std::size_t p = 0; p < 6; ++p) {
      const rad::Patch& patch = h.patches()[p];
      faces += B[p] * patch.area * std::max(0.0f, glm::dot(patch.normal, w)) / static_cast<float>(kPiD);
    }
    const rad::Rgb I = hr::intensity(P[hr::ClusterTree::root()], root, w);
    for (int c = 0; c < 3; ++c) CHECK(I[c] == doctest::Approx(faces[c]).epsilon(1e-5));
    worst_axes = std::max(worst_axes, std::abs(double{hr::intensity(on_axes, w).x} / faces.x - 1.0));
  }
  CHECK(worst_axes > 0.1);

  // Receiving: a link's flux from d reaches each face as flux max(0, n . d), pushed down the
  // tree to the leaves; on the axes a face gets light from behind.
  const rad::Rgb flux(4.0f, 2.0f, 1.0f);
  const glm::vec3 d = glm::normalize(glm::vec3(0.3f, 0.2f, 0.9f));
  std::vector<hr::Moments> E(tree.nodes().size(), hr::Moments{});
  hr::add_irradiance(E[hr::ClusterTree::root()], root, d, flux);
  for (std::uint32_t c = 0; c < tree.nodes().size(); ++c)
    if (!tree.node(c).is_leaf())
      for (const std::uint32_t child : tree.node(c).children) hr::push_moments(E[c], bases.of(c), E[child], bases.of(child));
  hr::Moments E_axes{};
  hr::add_irradiance(E_axes, d, flux);
  int lit_from_behind = 0;
  for (std::uint32_t p = 0; p < 6; ++p) {
    const glm::vec3& n = h.patches()[p].normal;
    const std::uint32_t leaf = tree.leaf_of(p);
    const rad::Rgb got = hr::element_irradiance(E[leaf], bases.of(leaf), bases.front(p, n));
    const float cosine = std::max(0.0f, glm::dot(n, d));
    CAPTURE(n);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == doctest::Approx(flux[c] * cosine).epsilon(1e-5));
    if (cosine == 0.0f && hr::element_irradiance(E_axes, n).x > 0.1f * flux.x) ++lit_from_behind;
  }
  CHECK(lit_from_behind > 0);
}

TEST_CASE("the moment bases' transposes: <Q, E> and <R, P> hold for add_surface, element_irradiance and the push") {
  // The balancing's adjoint (link_hierarchy.cpp) is built from these transposes; each pair must
  // agree to rounding for a basis on the axes, an explicit one and a tilted side on the axes.
  const rad::PatchHierarchy h = outward_box(30.0f);
  const hr::ClusterTree tree(h);
  const hr::MomentBases bases(tree, h, std::vector<std::uint8_t>(6, 0));
  const hr::MomentBasis& root = bases.of(hr::ClusterTree::root());
  const std::uint32_t child = tree.node(hr::ClusterTree::root()).children[0];
  const hr::MomentBasis axes{};
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> u(0.1, 2.0);
  auto random6 = [&] {
    std::array<double, 6> m{};
    for (double& x : m) x = u(gen);
    return m;
  };
  auto dot = [](const std::array<double, 6>& a, const std::array<double, 6>& b) {
    double s = 0.0;
    for (std::size_t k = 0; k < 6; ++k) s += a[k] * b[k];
    return s;
  };
  const glm::vec3 n0 = h.patches()[0].normal;
  const hr::SideDirection own = bases.front(0, n0), tilted{rad::kNone, glm::normalize(glm::vec3(1.0f, -2.0f, 3.0f))};
  for (const auto& [basis, side] : {std::pair<const hr::MomentBasis*, hr::SideDirection>{&root, own},
                                    {&axes, tilted}, {&axes, hr::SideDirection{2, glm::vec3(0, 1, 0)}}}) {
    const std::array<double, 6> E = random6(), R = random6();
    std::array<double, 6> Q{}, P{};
    hr::add_element_weight(Q, *basis, side, 1.5);
    CHECK(dot(Q, E) == doctest::Approx(1.5 * hr::element_irradiance(E, *basis, side)).epsilon(1e-12));
    hr::add_surface(P, *basis, side, 1.5);
    CHECK(dot(R, P) == doctest::Approx(1.5 * hr::surface_share(R, *basis, side)).epsilon(1e-12));
  }
  // The push from the root to a child and its transpose.
  const std::array<double, 6> Ep = random6(), Qc = random6();
  std::array<double, 6> Ec{}, Qp{};
  hr::push_moments(Ep, root, Ec, bases.of(child));
  hr::push_transpose(Qc, bases.of(child), Qp, root);
  CHECK(dot(Qc, Ec) == doctest::Approx(dot(Qp, Ep)).epsilon(1e-12));
  // And from the axes (more than six directions above) into the explicit child.
  std::array<double, 6> Ec2{}, Qp2{};
  hr::push_moments(Ep, axes, Ec2, bases.of(child));
  hr::push_transpose(Qc, bases.of(child), Qp2, axes);
  CHECK(dot(Qc, Ec2) == doctest::Approx(dot(Qp2, Ep)).epsilon(1e-12));
}

}  // TEST_SUITE
