// find_overlaps(), the diagnostic: coincident and interpenetrating polygons are found and named,
// touching ones (shared edges and corners, T-junctions, blocks standing on floors) are not.
// Solves accept contact and interpenetration (tests/solver/test_contacts.cpp checks the light);
// only coincident polygons facing the same way (z-fighting) give a warning.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

using Quad = std::vector<glm::vec3>;

// A rigid motion applied to every corner, so that the same configurations are also checked
// tilted and far from the origin (where float rounding is largest).
struct Motion {
  glm::vec3 offset{0.0f};
  float angle = 0.0f;  ///< about the axis (1, 2, 3) / |.|
  glm::vec3 operator()(glm::vec3 p) const {
    const glm::vec3 k = glm::normalize(glm::vec3(1.0f, 2.0f, 3.0f));
    const float c = std::cos(angle), s = std::sin(angle);
    return p * c + glm::cross(k, p) * s + k * glm::dot(k, p) * (1.0f - c) + offset;  // Rodrigues
  }
};

const Motion kMotions[] = {{}, {glm::vec3(100.0f, -200.0f, 50.0f), 0.7f}};

struct Builder {
  rad::Scene scene;
  rad::MaterialId material;
  Motion motion;
  explicit Builder(const Motion& m, const rad::Material& mat = {}) : material(scene.add_material(mat)), motion(m) {}
  void add(Quad q, const char* group) {
    for (glm::vec3& p : q) p = motion(p);
    scene.add_polygon(q, material, group);
  }
  // A box [lo, hi] of outward-facing quads; `bottom` = false leaves the bottom (y = lo.y) open.
  void box(glm::vec3 lo, glm::vec3 hi, bool bottom, const char* group) {
    const float x0 = lo.x, x1 = hi.x, y0 = lo.y, y1 = hi.y, z0 = lo.z, z1 = hi.z;
    add({{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}, group);  // -x
    add({{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}}, group);  // +x
    add({{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}}, group);  // +y
    add({{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}, group);  // -z
    add({{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}, group);  // +z
    if (bottom) add({{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}, group);  // -y
  }
  void floor(float size = 4.0f) { add({{0, 0, 0}, {0, 0, size}, {size, 0, size}, {size, 0, 0}}, "floor"); }
};

Quad square(float x0, float y0, float size, float z = 0.0f) {
  return {{x0, y0, z}, {x0 + size, y0, z}, {x0 + size, y0 + size, z}, {x0, y0 + size, z}};
}

/// The first pair find_overlaps() reports, in words ("polygon 1 (group 'a') and polygon 2
/// (group 'b') are coincident (and 3 more pairs)"), or "" when there is none.
std::string error_of(const rad::Scene& s) {
  const std::vector<rad::PolygonOverlap> found = rad::find_overlaps(s);
  if (found.empty()) return {};
  auto name = [&](rad::PolygonId p) {
    return "polygon " + std::to_string(p) + " (group '" + s.groups()[s.polygons()[p].group] + "')";
  };
  const rad::PolygonOverlap& o = found.front();
  std::string text = name(o.first) + " and " + name(o.second) +
                     (o.kind == rad::OverlapKind::coincident ? " are coincident" : " interpenetrate");
  if (found.size() > 1) text += " (and " + std::to_string(found.size() - 1) + " more pairs)";
  return text;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_SUITE("scene") {
  TEST_CASE("an exact duplicate polygon is coincident and named") {
    for (const Motion& m : kMotions) {
      Builder b(m);
      b.floor();
      b.add(square(0, 0, 1, 1), "a");
      b.add(square(0, 0, 1, 1), "b");
      const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
      REQUIRE(o.size() == 1);
      CHECK(o[0].first == 1);
      CHECK(o[0].second == 2);
      CHECK(o[0].kind == rad::OverlapKind::coincident);
      // The middle of the shared square, to rounding.
      CHECK(glm::length(o[0].point - m({0.5f, 0.5f, 1.0f})) < 1e-3f);
      const std::string e = error_of(b.scene);
      CHECK(contains(e, "polygon 1 (group 'a') and polygon 2 (group 'b') are coincident"));
    }
  }

  TEST_CASE("coplanar quads overlapping by half - facing either way - are coincident") {
    for (const Motion& m : kMotions) {
      for (const bool flip : {false, true}) {
        Builder b(m);
        b.add(square(0, 0, 1), "a");
        Quad q = square(0.5f, 0, 1);
        if (flip) std::reverse(q.begin(), q.end());
        b.add(q, "b");
        const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
        REQUIRE(o.size() == 1);
        CHECK(o[0].kind == rad::OverlapKind::coincident);
        // Facing the same way they z-fight; facing apart one lies against the other.
        CHECK(o[0].same_facing == !flip);
        CHECK(o[0].z_fighting() == !flip);
        CHECK(o[0].lying_against() == flip);
        // The overlap is [0.5, 1] x [0, 1]; its middle.
        CHECK(glm::length(o[0].point - m({0.75f, 0.5f, 0.0f})) < 1e-3f);
        CHECK(contains(error_of(b.scene), "polygon 0 (group 'a') and polygon 1 (group 'b') are coincident"));
      }
    }
  }

  TEST_CASE("near-coplanar quads within the tolerance are coincident - a gap beyond it is allowed") {
    // Scene diagonal ~6.1 (floor 4 x 4 in y = 0, squares up to y = 2.2): the tolerance is 2e-5 of
    // it, ~1.2e-4; the lifted copy reaches at most 8e-5, gaps of 3e-4 and more are real.
    for (const Motion& m : kMotions) {
      for (const float gap : {0.0f, 2e-5f, 6e-5f}) {
        Builder b(m);
        b.floor();
        b.add(square(1, 1, 1, 1), "a");
        // Lifted by `gap` and tilted: one corner a further 2e-5 up (z-fighting).
        b.add({{1.2f, 1.2f, 1 + gap}, {2.2f, 1.2f, 1 + gap}, {2.2f, 2.2f, 1 + gap + 2e-5f}, {1.2f, 2.2f, 1 + gap}}, "b");
        const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
        INFO("gap ", gap);
        REQUIRE(o.size() == 1);
        CHECK(o[0].kind == rad::OverlapKind::coincident);
        CHECK(contains(error_of(b.scene), "polygon 1 (group 'a') and polygon 2 (group 'b') are coincident"));
      }
      for (const float gap : {3e-4f, 1e-3f, 1e-2f}) {
        Builder b(m);
        b.floor();
        b.add(square(1, 1, 1, 1), "a");
        b.add(square(1.2f, 1.2f, 1, 1 + gap), "b");
        INFO("gap ", gap);
        CHECK(rad::find_overlaps(b.scene).empty());
        CHECK(error_of(b.scene).empty());
      }
    }
  }

  TEST_CASE("a quad piercing another through its middle interpenetrates it") {
    for (const Motion& m : kMotions) {
      Builder b(m);
      b.add(square(0, 0, 1), "sheet");
      b.add({{0.5f, -0.5f, -0.5f}, {0.5f, 1.5f, -0.5f}, {0.5f, 1.5f, 0.5f}, {0.5f, -0.5f, 0.5f}}, "blade");
      const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
      REQUIRE(o.size() == 1);
      CHECK(o[0].kind == rad::OverlapKind::interpenetrating);
      CHECK(!o[0].z_fighting());
      CHECK(!o[0].lying_against());
      // They cross along x = 0.5, z = 0, y in [0, 1]: the middle of that segment.
      CHECK(glm::length(o[0].point - m({0.5f, 0.5f, 0.0f})) < 1e-3f);
      CHECK(contains(error_of(b.scene), "polygon 0 (group 'sheet') and polygon 1 (group 'blade') interpenetrate"));
    }
  }

  TEST_CASE("a corner poking through a quad interpenetrates it - one stopping short does not") {
    for (const Motion& m : kMotions) {
      for (const float tip : {0.05f, -0.01f}) {
        Builder b(m);
        b.add(square(0, 0, 1), "sheet");
        b.add({{0.3f, 0.5f, 1.0f}, {0.5f, 0.5f, -tip}, {0.7f, 0.5f, 1.0f}}, "spike");  // faces -y
        const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
        INFO("tip ", tip);
        if (tip > 0.0f) {
          REQUIRE(o.size() == 1);
          CHECK(o[0].kind == rad::OverlapKind::interpenetrating);
        } else {
          CHECK(o.empty());
        }
      }
    }
  }

  TEST_CASE("a box sunk into the floor interpenetrates it with each side - one standing on it passes") {
    for (const Motion& m : kMotions) {
      Builder sunk(m);
      sunk.floor();
      sunk.box({1, -0.2f, 1}, {2, 1, 2}, false, "box");
      const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(sunk.scene);
      REQUIRE(o.size() == 4);  // the four sides; the top stays above the floor
      for (const rad::PolygonOverlap& p : o) {
        CHECK(p.first == 0);
        CHECK(p.kind == rad::OverlapKind::interpenetrating);
      }
      const std::string e = error_of(sunk.scene);
      CHECK(contains(e, "polygon 0 (group 'floor') and polygon 1 (group 'box') interpenetrate"));
      CHECK(contains(e, "and 3 more pairs"));

      Builder standing(m);
      standing.floor();
      standing.box({1, 0, 1}, {2, 1, 2}, false, "box");
      standing.box({2.5f, 0, 2.5f}, {3, 0.5f, 3}, true, "closed_box");  // its bottom lies on the floor: coincident
      const std::vector<rad::PolygonOverlap> closed = rad::find_overlaps(standing.scene);
      REQUIRE(closed.size() == 1);
      CHECK(standing.scene.groups()[standing.scene.polygons()[closed[0].second].group] == "closed_box");
      CHECK(closed[0].kind == rad::OverlapKind::coincident);

      Builder open(m);
      open.floor();
      open.box({1, 0, 1}, {2, 1, 2}, false, "box");
      open.box({2, 0, 1}, {3, 0.5f, 2}, false, "lean_to");  // shares the box's +x side partly: coincident
      REQUIRE(rad::find_overlaps(open.scene).size() == 1);

      Builder good(m);
      good.floor();
      good.box({1, 0, 1}, {2, 1, 2}, false, "box");
      good.box({1, 1, 1}, {1.5f, 1.5f, 1.5f}, false, "stacked");  // stands on the box's top
      CHECK(rad::find_overlaps(good.scene).empty());
      CHECK(error_of(good.scene).empty());
    }
  }

  TEST_CASE("shared edges - shared corners - T-junctions and a corner of three walls pass") {
    for (const Motion& m : kMotions) {
      Builder b(m);
      b.add(square(0, 0, 1), "a");                                  // neighbours sharing edges
      b.add(square(1, 0, 1), "a");
      b.add(square(2, 1, 1), "b");                                  // shares only a corner with the last
      b.add({{0, 1, 0}, {2, 1, 0}, {2, 2, 0}, {0, 2, 0}}, "c");     // T-vertex at (1, 1)
      b.add({{0, 0, 0}, {0, 2, 0}, {0, 2, 1}, {0, 0, 1}}, "wall");  // perpendicular, sharing edges
      b.add({{0.5f, 0.5f, 0}, {0.5f, 0.5f, 1}, {0.5f, 1.5f, 1}, {0.5f, 1.5f, 0}}, "fin");  // stands across a seam
      b.add({{0, 2, 0}, {2, 2, 0}, {2, 2, 1}, {0, 2, 1}}, "back");  // corner of three polygons at (0, 2, 0)
      // Grazing: shares the edge x = 3 and rises at a slope of 1e-4.
      b.add({{3, 1, 0}, {4, 1, 1e-4f}, {4, 2, 1e-4f}, {3, 2, 0}}, "graze");
      CHECK(rad::find_overlaps(b.scene).empty());
      CHECK(error_of(b.scene).empty());
    }
  }

  TEST_CASE("a triangulated non-convex polygon - closed boxes and the Cornell box pass") {
    rad::Scene s;
    const rad::MaterialId id = s.add_material({});
    const rad::PolygonRange r = s.add_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}}, id, "L");
    REQUIRE(r.count >= 2);
    CHECK(rad::find_overlaps(s).empty());
    CHECK(rad::find_overlaps(test::closed_box(rad::Material{}, glm::vec3(1, 2, 3))).empty());
    const rad::Scene cornell = rad::cornell_box();
    CHECK(rad::find_overlaps(cornell).empty());
    CHECK(error_of(cornell).empty());
    CHECK(rad::find_overlaps(rad::Scene{}).empty());
  }

  TEST_CASE("view_factors and solve accept interpenetrating and touching scenes - z-fighting gets a warning") {
    rad::Material light;
    light.emission = rad::Rgb(1.0f);
    light.reflectance = rad::Rgb(0.5f);
    Builder b(Motion{}, light);
    b.floor();
    b.box({1, -0.2f, 1}, {2, 1, 2}, false, "box");               // sunk into the floor
    b.box({2.5f, 0, 2.5f}, {3, 0.5f, 3}, true, "resting_box");    // its bottom on the floor
    rad::ViewFactorOptions vo;
    vo.mesh.max_patch_area = 1.0f;
    const rad::GroupViewFactors v = rad::view_factors(b.scene, vo);
    for (std::size_t i = 0; i < v.groups.size(); ++i)
      for (std::size_t k = 0; k < v.groups.size(); ++k) CHECK(std::isfinite(v.at(i, k)));
    rad::SolveOptions so;
    so.mesh.max_patch_area = 1.0f;
    const rad::Solution sol = rad::solve(b.scene, so);
    for (const std::string& w : sol.report().warnings) CHECK(!contains(w, "z-fighting"));
    for (const rad::Rgb& B : sol.radiosity()) CHECK(std::isfinite(B.x));

    // Two copies of a quad facing the same way: which one is seen is rounding.
    Builder twin(Motion{}, light);
    twin.floor();
    twin.add(square(0, 0, 1, 1), "a");
    twin.add(square(0, 0, 1, 1), "b");
    const rad::Solution z = rad::solve(twin.scene, so);
    bool warned = false;
    for (const std::string& w : z.report().warnings)
      if (contains(w, "polygon 1 (group 'a') and polygon 2 (group 'b') are coincident and face the same way (z-fighting)"))
        warned = true;
    CHECK(warned);
  }
  TEST_CASE("a large scene searched in parts finds the pairs across the parts' border") {
    // 40 000 unit squares (the broad phase splits more than 32 768 polygons into parts by
    // position; here at x = 100) and a blade through four of them, two on each side.
    Builder b(kMotions[0]);
    for (int i = 0; i < 200; ++i)
      for (int j = 0; j < 200; ++j) b.add(square(static_cast<float>(i), static_cast<float>(j), 1.0f), "ground");
    b.add({{98.2f, 50.5f, -0.5f}, {101.8f, 50.5f, -0.5f}, {101.8f, 50.5f, 0.5f}, {98.2f, 50.5f, 0.5f}}, "blade");
    const std::vector<rad::PolygonOverlap> o = rad::find_overlaps(b.scene);
    REQUIRE(o.size() == 4);
    for (std::size_t k = 0; k < 4; ++k) {
      CAPTURE(k);
      CHECK(o[k].kind == rad::OverlapKind::interpenetrating);
      CHECK(o[k].first == static_cast<rad::PolygonId>((98 + k) * 200 + 50));
      CHECK(o[k].second == 40000u);
    }
  }
}
