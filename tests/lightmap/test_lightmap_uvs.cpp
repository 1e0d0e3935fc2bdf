// generate_lightmap_uvs(): planar charts, split vertices and a shelf-packed atlas. Checked on a
// cube (six isometric charts, 24 vertices), a tessellated sphere (many charts, rasterised:
// no texel is claimed by two charts, padding texels are empty), a spiral ramp (the flood fill
// alone would fold it over itself), degenerate triangles, bad options, and a scene's mesh
// adopting the result and solving on its new vertices.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/lightmap.hpp>
#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct TestMesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::size_t triangles() const { return indices.size() / 3; }
};

rad::LightmapUvs generate(const TestMesh& m, const rad::LightmapUvOptions& o) {
  return rad::generate_lightmap_uvs(m.positions.data(), m.positions.size(), m.indices.data(), m.indices.size(), o);
}

TestMesh cube() {
  const test::InwardCube c;
  return TestMesh{c.corners, c.indices};
}

/// A UV sphere of radius 1: `segments` around, `rings` bands, shared vertices (one per pole),
/// counter-clockwise seen from outside.
TestMesh sphere(int segments, int rings) {
  TestMesh m;
  m.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double theta = kPi * r / rings, phi = 2 * kPi * s / segments;
      m.positions.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    }
  m.positions.push_back({0, 0, -1});
  const auto south = static_cast<std::uint32_t>(m.positions.size() - 1);
  auto at = [&](int r, int s) { return static_cast<std::uint32_t>(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) {
    m.indices.insert(m.indices.end(), {0u, at(1, s), at(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r)
      m.indices.insert(m.indices.end(), {at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    m.indices.insert(m.indices.end(), {at(rings - 1, s), south, at(rings - 1, s + 1)});
  }
  return m;
}

/// A spiral ramp (between radii 1 and 2, rising `pitch` per turn) of `turns` turns: every
/// normal within a few degrees of +z, so the normal bound alone would make one chart of it,
/// whose turns cover each other in projection.
TestMesh spiral_ramp(double turns, double pitch) {
  TestMesh m;
  const int steps = static_cast<int>(48 * turns);
  for (int i = 0; i <= steps; ++i) {
    const double phi = 2 * kPi * turns * i / steps;
    for (double r : {1.0, 1.5, 2.0})
      m.positions.emplace_back(r * std::cos(phi), r * std::sin(phi), pitch * phi / (2 * kPi));
  }
  for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(steps); ++i)
    for (std::uint32_t j = 0; j < 2; ++j) {
      const std::uint32_t a = 3 * i + j, b = a + 1, c = a + 4, d = a + 3;
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  return m;
}

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

/// A triangle's corners in texels.
std::array<glm::dvec2, 3> texel_triangle(const rad::LightmapUvs& uvs, std::size_t t, int resolution) {
  std::array<glm::dvec2, 3> p;
  for (std::size_t k = 0; k < 3; ++k) p[k] = glm::dvec2(uvs.uv1[uvs.indices[3 * t + k]]) * double(resolution);
  return p;
}

double signed_area(const std::array<glm::dvec2, 3>& p) { return 0.5 * cross2(p[1] - p[0], p[2] - p[0]); }

double area3(const TestMesh& m, std::size_t t) {
  const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
      c(m.positions[m.indices[3 * t + 2]]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

/// Interiors overlap by more than `tol` (separating axes on the six edge normals; either winding).
bool overlap(std::array<glm::dvec2, 3> a, std::array<glm::dvec2, 3> b, double tol) {
  if (signed_area(a) < 0) std::swap(a[1], a[2]);
  if (signed_area(b) < 0) std::swap(b[1], b[2]);
  auto separates = [tol](const std::array<glm::dvec2, 3>& p, const std::array<glm::dvec2, 3>& q) {
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::dvec2 e = p[(k + 1) % 3] - p[k];
      const double len = glm::length(e);
      if (len == 0) continue;
      double deepest = -1e300;
      for (const auto& v : q) deepest = std::max(deepest, cross2(e, v - p[k]) / len);
      if (deepest <= tol) return true;
    }
    return false;
  };
  return !separates(a, b) && !separates(b, a);
}

/// Whether a triangle touches the closed texel square [x, x+1] x [y, y+1] (conservative coverage).
bool touches(const std::array<glm::dvec2, 3>& t, int x, int y) {
  const glm::dvec2 lo = glm::min(t[0], glm::min(t[1], t[2])), hi = glm::max(t[0], glm::max(t[1], t[2]));
  if (hi.x < x || lo.x > x + 1 || hi.y < y || lo.y > y + 1) return false;
  const double s = signed_area(t) < 0 ? -1.0 : 1.0;
  const std::array<glm::dvec2, 4> square{glm::dvec2(x, y), glm::dvec2(x + 1, y), glm::dvec2(x, y + 1), glm::dvec2(x + 1, y + 1)};
  for (std::size_t k = 0; k < 3; ++k) {
    const glm::dvec2 e = t[(k + 1) % 3] - t[k];
    if (glm::dot(e, e) == 0) continue;
    bool all_outside = true;
    for (const auto& c : square) all_outside = all_outside && s * cross2(e, c - t[k]) < 0;
    if (all_outside) return false;
  }
  return true;
}

/// Checks that every mesh must pass: counts and ranges, origins, winding, no overlap inside a
/// chart, and chart rectangles (in whole texels, grown by the padding) apart and inside the
/// border.
void check_layout(const TestMesh& m, const rad::LightmapUvs& uvs, const rad::LightmapUvOptions& o) {
  const int res = o.resolution;
  REQUIRE(uvs.indices.size() == m.indices.size());
  REQUIRE(uvs.triangle_chart.size() == m.triangles());
  REQUIRE(uvs.uv1.size() == uvs.vertex_origin.size());
  for (const glm::vec2& uv : uvs.uv1) {
    CHECK(uv.x >= 0.0f);
    CHECK(uv.x <= 1.0f);
    CHECK(uv.y >= 0.0f);
    CHECK(uv.y <= 1.0f);
  }
  for (std::size_t c = 0; c < m.indices.size(); ++c) {
    REQUIRE(uvs.indices[c] < uvs.uv1.size());
    CHECK(uvs.vertex_origin[uvs.indices[c]] == m.indices[c]);  // the corner's own host vertex
  }
  // One copy per host vertex and chart: no two new vertices with the same origin in one chart.
  std::vector<std::uint32_t> chart_of_vertex(uvs.uv1.size(), rad::kNone);
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    REQUIRE(uvs.triangle_chart[t] < uvs.chart_count);
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t& c = chart_of_vertex[uvs.indices[3 * t + k]];
      CHECK((c == rad::kNone || c == uvs.triangle_chart[t]));
      c = uvs.triangle_chart[t];
    }
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keys;
  for (std::size_t v = 0; v < uvs.uv1.size(); ++v) keys.emplace_back(uvs.vertex_origin[v], chart_of_vertex[v]);
  std::sort(keys.begin(), keys.end());
  CHECK(std::adjacent_find(keys.begin(), keys.end()) == keys.end());

  // Per chart: its triangles keep their winding, overlap nowhere, and their texel rectangle.
  std::vector<std::vector<std::size_t>> members(uvs.chart_count);
  for (std::size_t t = 0; t < m.triangles(); ++t) members[uvs.triangle_chart[t]].push_back(t);
  struct Rect {
    int x0, y0, x1, y1;
  };
  std::vector<Rect> rects;
  for (std::size_t c = 0; c < uvs.chart_count; ++c) {
    REQUIRE(!members[c].empty());
    glm::dvec2 lo(1e300), hi(-1e300);
    for (std::size_t i = 0; i < members[c].size(); ++i) {
      const auto a = texel_triangle(uvs, members[c][i], res);
      for (const auto& p : a) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
      if (area3(m, members[c][i]) > 1e-6) CHECK(signed_area(a) > 0.0);
      // (A zero-area triangle has no inside to overlap.)
      if (std::abs(signed_area(a)) < 1e-9) continue;
      for (std::size_t j = i + 1; j < members[c].size(); ++j) {
        const auto b = texel_triangle(uvs, members[c][j], res);
        if (std::abs(signed_area(b)) >= 1e-9) CHECK_FALSE(overlap(a, b, 1e-3));
      }
    }
    rects.push_back(Rect{int(std::floor(lo.x)), int(std::floor(lo.y)), int(std::ceil(hi.x)), int(std::ceil(hi.y))});
  }
  const int p = o.padding;
  for (std::size_t a = 0; a < rects.size(); ++a) {
    CHECK(rects[a].x0 >= p);
    CHECK(rects[a].y0 >= p);
    CHECK(rects[a].x1 <= res - p);
    CHECK(rects[a].y1 <= res - p);
    for (std::size_t b = 0; b < rects.size(); ++b) {
      if (a == b) continue;
      const bool apart = rects[a].x1 + p <= rects[b].x0 || rects[b].x1 + p <= rects[a].x0 ||
                         rects[a].y1 + p <= rects[b].y0 || rects[b].y1 + p <= rects[a].y0;
      CHECK(apart);
    }
  }
}

/// Conservative rasterisation of every triangle: no texel touched by two charts, and none within
/// `padding` texels (in x and y) of another chart's. Returns the touched texels.
std::size_t check_raster(const TestMesh& m, const rad::LightmapUvs& uvs, const rad::LightmapUvOptions& o) {
  const int res = o.resolution;
  std::vector<std::uint32_t> owner(std::size_t(res) * res, rad::kNone);
  std::size_t conflicts = 0, touched = 0;
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    const auto tri = texel_triangle(uvs, t, res);
    const glm::dvec2 lo = glm::min(tri[0], glm::min(tri[1], tri[2])), hi = glm::max(tri[0], glm::max(tri[1], tri[2]));
    for (int y = std::max(0, int(std::floor(lo.y)) - 1); y <= std::min(res - 1, int(std::floor(hi.y))); ++y)
      for (int x = std::max(0, int(std::floor(lo.x)) - 1); x <= std::min(res - 1, int(std::floor(hi.x))); ++x) {
        if (!touches(tri, x, y)) continue;
        std::uint32_t& cell = owner[std::size_t(y) * res + x];
        if (cell == rad::kNone) {
          cell = uvs.triangle_chart[t];
          ++touched;
        } else if (cell != uvs.triangle_chart[t]) {
          ++conflicts;
        }
      }
  }
  CHECK(conflicts == 0);
  std::size_t too_close = 0;
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) {
      const std::uint32_t c = owner[std::size_t(y) * res + x];
      if (c == rad::kNone) continue;
      for (int dy = -o.padding; dy <= o.padding; ++dy)
        for (int dx = -o.padding; dx <= o.padding; ++dx) {
          const int u = x + dx, v = y + dy;
          if (u < 0 || v < 0 || u >= res || v >= res) continue;
          const std::uint32_t d = owner[std::size_t(v) * res + u];
          if (d != rad::kNone && d != c) ++too_close;
        }
    }
  CHECK(too_close == 0);
  return touched;
}

/// UV area over 3D area of each chart, divided by texels_per_unit^2 / resolution^2.
std::vector<double> chart_scales(const TestMesh& m, const rad::LightmapUvs& uvs, int res) {
  std::vector<double> uv(uvs.chart_count, 0.0), world(uvs.chart_count, 0.0);
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    uv[uvs.triangle_chart[t]] += signed_area(texel_triangle(uvs, t, res));
    world[uvs.triangle_chart[t]] += area3(m, t);
  }
  std::vector<double> out;
  const double tpu = uvs.texels_per_unit;
  for (std::size_t c = 0; c < uv.size(); ++c) out.push_back(uv[c] / world[c] / (tpu * tpu));
  return out;
}

}  // namespace

TEST_SUITE("lightmap") {
  TEST_CASE("lightmap uvs: a cube gets six isometric charts of 24 split vertices that do not overlap") {
    const TestMesh m = cube();
    rad::LightmapUvOptions o;
    o.resolution = 64;
    o.padding = 2;
    const rad::LightmapUvs uvs = generate(m, o);
    CHECK(uvs.chart_count == 6);
    CHECK(uvs.uv1.size() == 24);  // each corner on three faces
    check_layout(m, uvs, o);
    for (double s : chart_scales(m, uvs, o.resolution)) CHECK(s == doctest::Approx(1.0).epsilon(1e-4));
    // The two triangles of a face are one chart.
    for (std::size_t f = 0; f < 6; ++f) CHECK(uvs.triangle_chart[2 * f] == uvs.triangle_chart[2 * f + 1]);
    // Six unit squares at 17.9 texels each, 3 x 2 in a 64 square with 2 of padding: 2 + 3 x
    // (ceil(tpu + 0.1) + 2) <= 62 gives tpu <= 17.9.
    CHECK(uvs.texels_per_unit == doctest::Approx(17.9).epsilon(1e-3));
    CHECK(uvs.utilisation == doctest::Approx(6 * 17.9 * 17.9 / (64 * 64)).epsilon(2e-3));
    check_raster(m, uvs, o);
  }

  TEST_CASE("lightmap uvs: the automatic density is the largest that fits and an explicit one is used as given") {
    const TestMesh m = cube();
    rad::LightmapUvOptions o;
    o.resolution = 64;
    o.padding = 2;
    const float best = generate(m, o).texels_per_unit;
    o.texels_per_unit = best * 1.01f;
    CHECK_THROWS_AS(generate(m, o), rad::Error);
    o.texels_per_unit = 10.0f;
    const rad::LightmapUvs uvs = generate(m, o);
    CHECK(uvs.texels_per_unit == 10.0f);
    check_layout(m, uvs, o);
    for (double s : chart_scales(m, uvs, o.resolution)) CHECK(s == doctest::Approx(1.0).epsilon(1e-4));
    CHECK(uvs.utilisation == doctest::Approx(600.0 / (64 * 64)).epsilon(1e-4));
  }

  TEST_CASE("lightmap uvs: a tessellated sphere packs many charts with no texel claimed twice and padding empty") {
    const TestMesh m = sphere(32, 16);
    rad::LightmapUvOptions o;
    o.resolution = 256;
    o.padding = 2;
    const rad::LightmapUvs uvs = generate(m, o);
    MESSAGE("sphere: " << uvs.chart_count << " charts, " << uvs.uv1.size() << " vertices (" << m.positions.size()
                       << " given), texels_per_unit " << uvs.texels_per_unit << ", utilisation " << uvs.utilisation);
    CHECK(uvs.chart_count >= 14);  // 30 degree caps cover at most 4 pi / (2 pi (1 - cos 30)) = 15 of them
    check_layout(m, uvs, o);
    const std::size_t touched = check_raster(m, uvs, o);
    CHECK(uvs.utilisation > 0.45);
    CHECK(double(touched) / (256.0 * 256.0) >= uvs.utilisation);  // conservative coverage covers the area
    // Projection shrinks a curved chart by at most the cosine of the angle.
    for (double s : chart_scales(m, uvs, o.resolution)) {
      CHECK(s <= 1.0 + 1e-4);
      CHECK(s >= std::cos(30.0 * kPi / 180.0) - 1e-4);
    }
  }

  TEST_CASE("lightmap uvs: no padding still leaves charts on separate texels") {
    const TestMesh m = sphere(24, 12);
    rad::LightmapUvOptions o;
    o.resolution = 128;
    o.padding = 0;
    const rad::LightmapUvs uvs = generate(m, o);
    check_layout(m, uvs, o);
    check_raster(m, uvs, o);
  }

  TEST_CASE("lightmap uvs: a spiral ramp whose turns cover each other is cut so no chart overlaps itself") {
    const TestMesh m = spiral_ramp(2.5, 0.5);
    rad::LightmapUvOptions o;
    o.resolution = 256;
    o.padding = 2;
    o.chart_angle_deg = 45.0f;
    const rad::LightmapUvs uvs = generate(m, o);
    CHECK(uvs.chart_count >= 3);  // 2.5 turns: at least three pieces of less than a turn
    check_layout(m, uvs, o);
    check_raster(m, uvs, o);
  }

  TEST_CASE("lightmap uvs: one triangle and degenerate triangles work and the result is deterministic") {
    SUBCASE("one triangle") {
      const TestMesh m{{{0, 0, 0}, {2, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
      rad::LightmapUvOptions o;
      o.resolution = 32;
      o.padding = 1;
      const rad::LightmapUvs uvs = generate(m, o);
      CHECK(uvs.chart_count == 1);
      CHECK(uvs.vertex_origin == std::vector<std::uint32_t>{0, 1, 2});
      CHECK(uvs.indices == m.indices);
      check_layout(m, uvs, o);
      CHECK(chart_scales(m, uvs, o.resolution)[0] == doctest::Approx(1.0).epsilon(1e-4));
    }
    SUBCASE("degenerate triangles") {
      TestMesh m = cube();
      m.positions.push_back({0.5f, 0, 0});     // 8: on the edge 0-1
      m.positions.push_back({0.3f, 0.3f, 0});  // 9: used only by a point triangle
      m.indices.insert(m.indices.end(), {0, 0, 1,    // repeated index: corners in a face's chart
                                         0, 8, 1,    // collinear, vertex 8 in no chart
                                         9, 9, 9});  // a point
      rad::LightmapUvOptions o;
      o.resolution = 64;
      o.padding = 2;
      const rad::LightmapUvs uvs = generate(m, o);
      CHECK(uvs.chart_count == 7);  // the six faces and one texel for the strays
      check_layout(m, uvs, o);
      CHECK(uvs.triangle_chart[12] < 6);
      CHECK(uvs.triangle_chart[13] == 6);
      CHECK(uvs.triangle_chart[14] == 6);
      for (std::size_t t = 12; t < 15; ++t) CHECK(std::abs(signed_area(texel_triangle(uvs, t, 64))) < 1e-6);
      check_raster(m, uvs, o);
      // Determinism: the same call gives the same result.
      const rad::LightmapUvs again = generate(m, o);
      CHECK(again.uv1 == uvs.uv1);
      CHECK(again.indices == uvs.indices);
      CHECK(again.vertex_origin == uvs.vertex_origin);
      CHECK(again.texels_per_unit == uvs.texels_per_unit);
    }
    SUBCASE("only degenerate triangles") {
      const TestMesh m{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {0, 1, 2}};
      const rad::LightmapUvs uvs = generate(m, {});
      CHECK(uvs.chart_count == 1);
      CHECK(uvs.uv1.size() == 3);
    }
    SUBCASE("no triangles") {
      const TestMesh m{{{0, 0, 0}}, {}};
      const rad::LightmapUvs uvs = generate(m, {});
      CHECK(uvs.chart_count == 0);
      CHECK(uvs.uv1.empty());
    }
  }

  TEST_CASE("lightmap uvs: a density that cannot fit throws naming one that does") {
    const TestMesh m = cube();
    rad::LightmapUvOptions o;
    o.resolution = 64;
    o.padding = 2;
    o.texels_per_unit = 30.0f;
    std::string message;
    try {
      generate(m, o);
    } catch (const rad::Error& e) {
      CHECK(e.code() == rad::ErrorCode::invalid_argument);
      message = e.what();
    }
    MESSAGE(message);
    const std::string key = "; texels_per_unit ";
    const std::size_t at = message.find(key);
    REQUIRE(at != std::string::npos);
    CHECK(message.find("texels_per_unit 30") != std::string::npos);
    o.texels_per_unit = std::stof(message.substr(at + key.size()));
    CHECK(o.texels_per_unit > 17.0f);
    CHECK_NOTHROW(generate(m, o));
  }

  TEST_CASE("lightmap uvs: more charts than the resolution holds throw at any density") {
    TestMesh m;  // 100 separate triangles: 100 charts, each at least 2 x 2 texels with padding 1
    for (std::uint32_t i = 0; i < 100; ++i) {
      m.positions.insert(m.positions.end(), {{float(i), 0, 0}, {float(i) + 1, 0, 0}, {float(i), 1, 0}});
      m.indices.insert(m.indices.end(), {3 * i, 3 * i + 1, 3 * i + 2});
    }
    rad::LightmapUvOptions o;
    o.resolution = 16;
    o.padding = 1;
    CHECK_THROWS_WITH_AS(generate(m, o), doctest::Contains("at any density"), rad::Error);
    o.resolution = 32;  // 15 x 15 places
    check_layout(m, generate(m, o), o);
  }

  TEST_CASE("lightmap uvs: bad options and bad meshes throw naming the field") {
    const TestMesh m = cube();
    auto throws_naming = [&](const rad::LightmapUvOptions& o, const char* field) {
      CAPTURE(field);
      CHECK_THROWS_WITH_AS(generate(m, o), doctest::Contains(field), rad::Error);
      CHECK_THROWS_WITH_AS(rad::validate(o), doctest::Contains(field), rad::Error);
    };
    rad::LightmapUvOptions o;
    o.resolution = 0;
    throws_naming(o, "resolution");
    o = {};
    o.padding = -1;
    throws_naming(o, "padding");
    o = {};
    o.resolution = 8;
    o.padding = 4;
    throws_naming(o, "padding");
    for (float angle : {0.0f, 90.0f, -5.0f, std::nanf("")}) {
      o = {};
      o.chart_angle_deg = angle;
      throws_naming(o, "chart_angle_deg");
    }
    for (float density : {-1.0f, std::nanf(""), INFINITY}) {
      o = {};
      o.texels_per_unit = density;
      throws_naming(o, "texels_per_unit");
    }
    CHECK_NOTHROW(rad::validate(rad::LightmapUvOptions{}));

    const std::vector<std::uint32_t> out_of_range{0, 1, 8};
    CHECK_THROWS_WITH_AS(rad::generate_lightmap_uvs(m.positions.data(), 8, out_of_range.data(), 3),
                         doctest::Contains("index 8 is out of range"), rad::Error);
    CHECK_THROWS_WITH_AS(rad::generate_lightmap_uvs(m.positions.data(), 8, m.indices.data(), 4),
                         doctest::Contains("index_count"), rad::Error);
    std::vector<glm::vec3> nan = m.positions;
    nan[3].y = std::nanf("");
    CHECK_THROWS_WITH_AS(rad::generate_lightmap_uvs(nan.data(), 8, m.indices.data(), m.indices.size()),
                         doctest::Contains("vertex 3"), rad::Error);
  }

  TEST_CASE("lightmap uvs: a scene mesh adopts split vertices and solves on them") {
    rad::Scene scene;
    rad::Material material;
    material.emission = rad::Rgb(1.0f, 2.0f, 0.5f);
    material.reflectance = rad::Rgb(0.5f, 0.8f, 0.2f);
    const test::InwardCube cube_mesh;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uv0;
    for (const glm::vec3& p : cube_mesh.corners) {
      normals.push_back(glm::normalize(glm::vec3(0.5f) - p));
      uv0.emplace_back(p.x + 2 * p.y, p.z);
    }
    rad::MeshDesc desc = cube_mesh.desc(scene.add_material(material));
    desc.normals = normals.data();
    desc.uv0 = uv0.data();
    const rad::MeshId id = scene.add_mesh(desc);
    const std::vector<rad::Polygon> polygons_before = scene.polygons();
    const rad::Mesh before = scene.meshes()[id];

    rad::LightmapUvOptions o;
    o.resolution = 128;
    const rad::LightmapUvs uvs = rad::generate_lightmap_uvs(scene, id, o);
    const rad::Mesh& after = scene.meshes()[id];
    REQUIRE(after.positions.size() == 24);
    CHECK(after.uv1 == uvs.uv1);
    CHECK(after.indices == uvs.indices);
    CHECK(after.triangle_polygon == before.triangle_polygon);
    CHECK(after.polygons.first == before.polygons.first);
    CHECK(after.polygons.count == before.polygons.count);
    REQUIRE(after.normals.size() == 24);
    REQUIRE(after.uv0.size() == 24);
    for (std::size_t v = 0; v < 24; ++v) {
      CHECK(after.positions[v] == before.positions[uvs.vertex_origin[v]]);
      CHECK(after.normals[v] == before.normals[uvs.vertex_origin[v]]);
      CHECK(after.uv0[v] == before.uv0[uvs.vertex_origin[v]]);
    }
    REQUIRE(scene.polygons().size() == polygons_before.size());
    for (std::size_t p = 0; p < polygons_before.size(); ++p) {
      CHECK(scene.polygons()[p].vertices == polygons_before[p].vertices);
      CHECK(scene.polygons()[p].mesh_triangle == polygons_before[p].mesh_triangle);
    }

    // A furnace: B = E / (1 - rho) on every one of the 24 new vertices.
    rad::SolveOptions so;
    so.method = rad::SolverMethod::gauss_seidel;
    so.form_factors.method = rad::FormFactorMethod::ray_cast;
    so.mesh.max_patch_area = 0.05f;
    so.tolerance = 1e-6;
    const rad::Solution solution = rad::solve(scene, so);
    const std::vector<rad::Rgb> values = solution.mesh_vertex_values(id, rad::Quantity::radiosity);
    REQUIRE(values.size() == 24);
    const rad::Rgb B = material.emission / (rad::Rgb(1.0f) - material.reflectance);
    for (const rad::Rgb& value : values)
      for (int c = 0; c < 3; ++c) CHECK(value[c] == doctest::Approx(B[c]).epsilon(2e-3));

    CHECK_THROWS_WITH_AS(rad::generate_lightmap_uvs(scene, 7, o), doctest::Contains("mesh 7"), rad::Error);
  }
}
