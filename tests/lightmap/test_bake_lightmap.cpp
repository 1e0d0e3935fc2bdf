// bake_lightmap(): a floor under an area light against the closed-form irradiance E F(x -> light)
// texel by texel (interpolated and final gather; with a blocker, against the exact factor of the
// light's unblocked part), seams of a furnace cube whose faces are separate charts (dilation),
// conservative coverage of a sliver, determinism and errors; light groups: their lightmaps add up
// to the whole, and one group's final gather sees only its own lights.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <radiosity/lightmap.hpp>
#include <radiosity/radiosity.hpp>

#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

constexpr float kE = 10.0f;  // the light's exitance, W/m^2

/// The unit floor [0,1]^2 at z = 0 facing +z as a two-triangle mesh, its UV1 the floor's (x, y)
/// mapped into [kPad, 1 - kPad].
constexpr float kPad = 0.02f;
struct Floor {
  std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  std::vector<glm::vec2> uv1;
  std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3};
  Floor() {
    for (const glm::vec3& p : positions) uv1.push_back(kPad + (1.0f - 2.0f * kPad) * glm::vec2(p.x, p.y));
  }
  rad::MeshDesc desc(rad::MaterialId m) const { return test::mesh_desc(positions, indices, m, "floor", uv1); }
  /// The floor point under the centre of texel (x, y) of a size x size lightmap.
  static glm::vec3 point(int x, int y, int size) {
    const glm::vec2 uv((static_cast<float>(x) + 0.5f) / static_cast<float>(size),
                       (static_cast<float>(y) + 0.5f) / static_cast<float>(size));
    const glm::vec2 p = (uv - kPad) / (1.0f - 2.0f * kPad);
    return {p.x, p.y, 0.0f};
  }
};

/// The light [0.3, 0.7]^2 at z = 0.5 facing down (reflectance 0, so the floor's light does not
/// come back), optionally a blocker [0.45, 0.55]^2 at z = 0.25 facing up (its black back towards
/// the floor): the floor's irradiance is all direct.
struct LitFloor {
  rad::Scene scene;
  rad::MeshId floor = 0;
  Floor mesh;
  explicit LitFloor(bool blocker) {
    rad::Material white;
    white.reflectance = rad::Rgb(0.5f);
    rad::Material lamp;
    lamp.reflectance = rad::Rgb(0.0f);
    lamp.emission = rad::Rgb(kE);
    floor = scene.add_mesh(mesh.desc(scene.add_material(white)));
    rad::add_quad(scene, {0.3f, 0.3f, 0.5f}, {0.0f, 0.4f, 0.0f}, {0.4f, 0.0f, 0.0f}, scene.add_material(lamp), "light");
    if (blocker)
      rad::add_quad(scene, {0.45f, 0.45f, 0.25f}, {0.1f, 0.0f, 0.0f}, {0.0f, 0.1f, 0.0f}, scene.add_material(white),
                    "blocker");
  }
};

/// Exact direct irradiance at floor point x: E times the factor to the light, less the factor to
/// the part of the light that the blocker hides (the blocker's shadow from x on the light's
/// plane is the blocker scaled by 2 about x's footprint: planes at 0, 0.25 and 0.5).
double exact_irradiance(const glm::vec3& x, bool blocker) {
  const glm::vec3 n(0, 0, 1);
  auto factor = [&](glm::vec2 lo, glm::vec2 hi) {
    if (!(hi.x > lo.x && hi.y > lo.y)) return 0.0;
    const glm::vec3 q[4] = {{lo.x, lo.y, 0.5f}, {lo.x, hi.y, 0.5f}, {hi.x, hi.y, 0.5f}, {hi.x, lo.y, 0.5f}};
    return rad::point_to_polygon_factor(x, n, q, 4);
  };
  double F = factor({0.3f, 0.3f}, {0.7f, 0.7f});
  if (blocker) {
    const glm::vec2 foot(x.x, x.y);
    const glm::vec2 lo = foot + 2.0f * (glm::vec2(0.45f) - foot), hi = foot + 2.0f * (glm::vec2(0.55f) - foot);
    F -= factor(glm::max(lo, glm::vec2(0.3f)), glm::min(hi, glm::vec2(0.7f)));
  }
  return kE * F;
}

/// Fine elements; no visibility estimate, which is exact for the unblocked floor (and keeps the
/// noise of the estimators out of a test of interpolation).
/// The largest relative difference between a size x size lightmap of the Floor and
/// `expected(p, c)` over its first `channels` channels, at the texels 5 % or more inside it.
template <typename Expected>
double worst_relative_error(const rad::Lightmap& map, int size, int channels, const Expected& expected) {
  double worst = 0.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec3 p = Floor::point(x, y, size);
      if (std::min({p.x, p.y, 1.0f - p.x, 1.0f - p.y}) < 0.05f) continue;
      for (int c = 0; c < channels; ++c) {
        const double want = expected(p, c);
        worst = std::max(worst, std::abs(map.image.at(x, y)[c] - want) / want);
      }
    }
  return worst;
}

rad::SolveOptions fine_solve() {
  rad::SolveOptions o;
  o.form_factors.method = rad::FormFactorMethod::analytic;
  o.mesh.max_patch_area = 0.004f;
  o.mesh.max_element_area = 0.0005f;
  o.tolerance = 1e-6;
  return o;
}

/// Bilinear lookup of a lightmap at uv, texel centres at (i + 0.5) / size, clamped at the border.
rad::Rgb bilinear(const rad::Image& image, glm::vec2 uv) {
  const float fx = uv.x * static_cast<float>(image.width) - 0.5f, fy = uv.y * static_cast<float>(image.height) - 0.5f;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
  auto at = [&](int x, int y) {
    return image.at(std::clamp(x, 0, image.width - 1), std::clamp(y, 0, image.height - 1));
  };
  return (1 - tx) * (1 - ty) * at(x0, y0) + tx * (1 - ty) * at(x0 + 1, y0) + (1 - tx) * ty * at(x0, y0 + 1) +
         tx * ty * at(x0 + 1, y0 + 1);
}

/// A floor lit by four light groups, in Solution::light_groups() order: "light" (the area
/// light of LitFloor, reflectance 0.3, joined by a directional light of that light group),
/// "panel" (a small, brighter area light to the side), "bulb" (a point light) and "sky" (a
/// uniform sky); a wall at x = 1 reflects light back onto the floor.
struct GroupedFloor {
  rad::Scene scene;
  rad::MeshId floor = 0;
  Floor mesh;
  GroupedFloor() {
    rad::Material white;
    white.reflectance = rad::Rgb(0.5f);
    rad::Material lamp;
    lamp.reflectance = rad::Rgb(0.3f);
    lamp.emission = rad::Rgb(kE);
    rad::Material panel = lamp;
    panel.emission = rad::Rgb(2.0f * kE, kE, 0.5f * kE);
    const rad::MaterialId w = scene.add_material(white);
    floor = scene.add_mesh(mesh.desc(w));
    rad::add_quad(scene, {0.3f, 0.3f, 0.5f}, {0.0f, 0.4f, 0.0f}, {0.4f, 0.0f, 0.0f}, scene.add_material(lamp), "light");
    rad::add_quad(scene, {0.05f, 0.05f, 0.6f}, {0.0f, 0.2f, 0.0f}, {0.2f, 0.0f, 0.0f}, scene.add_material(panel),
                  "panel");
    rad::add_quad(scene, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}, w, "wall");
    rad::Light sun, sky;
    sun.type = rad::LightType::directional;
    sun.direction = {0.3f, 0.2f, -1.0f};
    sun.intensity = 1.0f;
    sun.light_group = "light";
    sky.type = rad::LightType::sky;
    sky.name = "sky";
    sky.direction = {0.0f, 0.0f, 1.0f};
    sky.intensity = 0.5f;
    scene.add_light(sun);
    scene.add_light(test::point_light("bulb", 0.5f, {0.8f, 0.2f, 0.3f}));
    scene.add_light(sky);
  }
};

/// The largest difference between `sum` and `whole` over the texels `whole` covers, relative to
/// the brightest of them (green channel), the mean of the texels' own relative differences, and
/// the relative difference of their totals.
struct Agreement {
  double worst = 0.0;
  double mean = 0.0;
  double total = 0.0;
};
Agreement agreement(const std::vector<rad::Rgb>& sum, const rad::Lightmap& whole) {
  float brightest = 0.0f;
  for (std::size_t i = 0; i < sum.size(); ++i)
    if (whole.state[i] == rad::TexelState::covered) brightest = std::max(brightest, whole.image.pixels[i].y);
  Agreement a;
  std::size_t count = 0;
  double sum_total = 0.0, whole_total = 0.0;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    if (whole.state[i] != rad::TexelState::covered) continue;
    const double d = std::abs(static_cast<double>(sum[i].y) - whole.image.pixels[i].y);
    a.worst = std::max(a.worst, d / brightest);
    a.mean += d / whole.image.pixels[i].y;
    sum_total += sum[i].y;
    whole_total += whole.image.pixels[i].y;
    ++count;
  }
  a.mean /= static_cast<double>(count);
  a.total = std::abs(sum_total - whole_total) / whole_total;
  return a;
}

/// A size x size lightmap, interpolated or final-gathered with `rays` gather rays.
rad::LightmapOptions lightmap_options(int size, bool gather, int rays = 16) {
  rad::LightmapOptions o;
  o.width = o.height = size;
  o.final_gather = gather;
  o.gather_rays = rays;
  return o;
}

/// The sum over light groups of the lightmaps baked with light_group = k.
std::vector<rad::Rgb> sum_of_groups(const GroupedFloor& lit, const rad::Solution& sol, rad::LightmapOptions o) {
  std::vector<rad::Rgb> sum(static_cast<std::size_t>(o.width) * o.height, rad::Rgb(0.0f));
  for (std::size_t k = 0; k < sol.light_groups().size(); ++k) {
    o.light_group = static_cast<int>(k);
    const rad::Lightmap part = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += part.image.pixels[i];
  }
  return sum;
}

}  // namespace

TEST_SUITE("lightmap") {
  TEST_CASE("bake_lightmap: a floor under an area light equals E F(x to light) texel by texel within 1 percent") {
    const LitFloor lit(false);
    const rad::Solution sol = rad::solve(lit.scene, fine_solve());
    for (bool gather : {false, true}) {
      CAPTURE(gather);
      rad::LightmapOptions o;
      o.width = o.height = 64;
      o.final_gather = gather;
      o.gather_rays = 16;
      const rad::Lightmap map = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
      REQUIRE(map.image.width == 64);
      double worst = 0.0;
      int checked = 0;
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          const glm::vec3 p = Floor::point(x, y, 64);
          // Away from the floor's edges (where a texel reads the nearest edge point).
          if (std::min({p.x, p.y, 1.0f - p.x, 1.0f - p.y}) < 0.05f) continue;
          REQUIRE(map.state[static_cast<std::size_t>(y) * 64 + x] == rad::TexelState::covered);
          const double expected = exact_irradiance(p, false);
          worst = std::max(worst, std::abs(map.image.at(x, y).y - expected) / expected);
          ++checked;
        }
      CHECK(checked > 3000);
      // Gathered: exact factors, but each point stepped 4 ray offsets (6e-5 here) inside its
      // triangle; interpolated: the element mesh's interpolation error.
      CHECK(worst < (gather ? 1e-3 : 0.01));
      MESSAGE("largest relative error, " << (gather ? "final gather: " : "interpolated: ") << worst);
    }
  }

  TEST_CASE("bake_lightmap: final gather draws the shadow of a blocker at texel resolution") {
    const LitFloor lit(true);
    rad::SolveOptions so = fine_solve();
    so.form_factors.method = rad::FormFactorMethod::automatic;
    const rad::Solution sol = rad::solve(lit.scene, so);
    rad::LightmapOptions o;
    o.width = o.height = 48;
    o.final_gather = true;
    o.gather_rays = 16;
    o.shadow_rays = 64;
    const rad::Lightmap map = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    o.final_gather = false;
    const rad::Lightmap smooth = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    double sum_error = 0.0, smooth_error = 0.0, worst = 0.0;
    int penumbra = 0;
    const double open = exact_irradiance({0.5f, 0.5f, 0.0f}, false);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        const glm::vec3 p = Floor::point(x, y, 48);
        if (std::min({p.x, p.y, 1.0f - p.x, 1.0f - p.y}) < 0.05f) continue;
        const double expected = exact_irradiance(p, true);
        const double error = std::abs(map.image.at(x, y).y - expected) / open;
        worst = std::max(worst, error);
        if (expected < 0.98 * exact_irradiance(p, false)) {
          sum_error += error;
          smooth_error += std::abs(smooth.image.at(x, y).y - expected) / open;
          ++penumbra;
        }
      }
    REQUIRE(penumbra > 50);
    MESSAGE("shadowed texels " << penumbra << ": mean error " << sum_error / penumbra << " (interpolated "
                               << smooth_error / penumbra << "), worst " << worst << " of the unshadowed value");
    // Shadow rays estimate the visible fraction: 64 rays, 256 more in a penumbra.
    CHECK(sum_error / penumbra < 0.01);
    CHECK(worst < 0.05);
  }

  TEST_CASE("bake_lightmap: a floor under a point light and a uniform sky bakes I cos / r^2 + E") {
    rad::Scene scene;
    Floor mesh;
    rad::Material white;
    white.reflectance = rad::Rgb(0.5f);
    const rad::MeshId floor = scene.add_mesh(mesh.desc(scene.add_material(white)));
    rad::Light lamp, sky;
    lamp.intensity = 2.0f;
    lamp.position = {0.4f, 0.6f, 0.5f};
    sky.type = rad::LightType::sky;
    sky.direction = {0.0f, 0.0f, 1.0f};  // the floor's up
    sky.intensity = 3.0f;
    scene.add_light(lamp);
    scene.add_light(sky);
    const rad::Solution sol = rad::solve(scene, fine_solve());
    for (bool gather : {false, true}) {
      CAPTURE(gather);
      rad::LightmapOptions o;
      o.width = o.height = 32;
      o.final_gather = gather;
      o.gather_rays = 16;
      const rad::Lightmap map = rad::bake_lightmap(scene, sol, floor, o);
      const double worst = worst_relative_error(map, 32, 1, [&](const glm::vec3& p, int) {
        const glm::vec3 d = lamp.position - p;
        return lamp.intensity * d.z / std::pow(glm::dot(d, d), 1.5) + sky.intensity;
      });
      MESSAGE("largest relative error, " << (gather ? "final gather: " : "interpolated: ") << worst);
      // Gathered: the point light exact at the texel's point, every sky ray escapes (pi L = E).
      CHECK(worst < (gather ? 1e-3 : 0.01));
    }
  }

  TEST_CASE("bake_lightmap: under a window pane the floor bakes tau I cos / r^2 + E (1 - F + tau F), interpolated "
            "and gathered") {
    // The floor of the test above under a window pane (transmittance (0.7, 0.6, 0.5), ior 1,
    // black) of side 3 at z = 0.3, the lamp above it: with the extended first pass the lamp's
    // shadow rays and the final gather's rays pass the pane times tau (F the point factor from
    // the floor to the pane). Before session 31 the pane stopped the gather's rays and the
    // lamp's shadow rays: the sky and the lamp were baked as the 1 - F the pane leaves open.
    rad::Scene scene;
    Floor mesh;
    rad::Material white, window;
    white.reflectance = rad::Rgb(0.5f);
    window.reflectance = rad::Rgb(0.0f);
    window.transmittance = rad::Rgb(0.7f, 0.6f, 0.5f);
    window.ior = 1.0f;
    const rad::MeshId floor = scene.add_mesh(mesh.desc(scene.add_material(white)));
    const glm::vec3 pane[] = {{-1, -1, 0.3f}, {-1, 2, 0.3f}, {2, 2, 0.3f}, {2, -1, 0.3f}};  // facing down
    scene.add_polygon({pane[0], pane[1], pane[2], pane[3]}, scene.add_material(window), "pane");
    rad::Light lamp, sky;
    lamp.intensity = 2.0f;
    lamp.position = {0.4f, 0.6f, 1.0f};
    sky.type = rad::LightType::sky;
    sky.direction = {0.0f, 0.0f, 1.0f};
    sky.intensity = 3.0f;
    scene.add_light(lamp);
    scene.add_light(sky);
    rad::SolveOptions so;
    so.form_factors.method = rad::FormFactorMethod::monte_carlo;
    so.form_factors.hemisphere_rays = 64;
    so.form_factors.specular_depth = 1;
    so.mesh.max_patch_area = 0.01f;
    so.mesh.max_element_area = 0.0025f;
    const rad::Solution sol = rad::solve(scene, so);
    const rad::Rgb tau = window.transmittance;
    for (bool gather : {false, true}) {
      CAPTURE(gather);
      rad::LightmapOptions o;
      o.width = o.height = 32;
      o.final_gather = gather;
      o.gather_rays = 1024;
      const rad::Lightmap map = rad::bake_lightmap(scene, sol, floor, o);
      const double worst = worst_relative_error(map, 32, 3, [&](const glm::vec3& p, int c) {
        const glm::vec3 d = lamp.position - p;
        const double F = rad::point_to_polygon_factor(p, glm::vec3(0, 0, 1), pane, 4);
        return tau[c] * lamp.intensity * d.z / std::pow(glm::dot(d, d), 1.5) + sky.intensity * (1.0 - F + tau[c] * F);
      });
      MESSAGE("under a window pane, largest relative error, " << (gather ? "final gather: " : "interpolated: ") << worst);
      // Gathered: the lamp exact at the texel's point; the sky by 1024 stratified rays, each
      // through the pane (tau pi L) or past its edge (pi L): measured 1.0 % (14 % at 16 rays,
      // falling as their noise does). Interpolated: 0.26 % (pass 1's first shot is exact here).
      CHECK(worst < (gather ? 0.02 : 0.01));
    }
  }

  TEST_CASE("bake_lightmap: a furnace cube whose faces are separate charts has no dark seams after dilation") {
    // An inward cube of 24 vertices (each face its own 4), every face a chart in a 3 x 2 grid of
    // 16 x 16 texel cells with the chart inset by 2 texels.
    rad::Scene scene;
    rad::Material m;
    m.emission = rad::Rgb(1.0f);
    m.reflectance = rad::Rgb(0.5f);
    const rad::MaterialId id = scene.add_material(m);
    const glm::vec3 faces[6][4] = {
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},
        {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}},
        {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}};
    // The charts' borders fall inside texels, as they do in a packed atlas.
    const int W = 48, H = 32, cell = 16;
    const float inset = 2.3f;
    std::vector<glm::vec3> positions;
    std::vector<glm::vec2> uv1;
    std::vector<std::uint32_t> indices;
    std::vector<std::pair<glm::vec2, glm::vec2>> charts;  // uv rectangles
    for (int f = 0; f < 6; ++f) {
      const glm::vec2 lo((static_cast<float>((f % 3) * cell) + inset) / W, (static_cast<float>((f / 3) * cell) + inset) / H);
      const glm::vec2 size((static_cast<float>(cell) - 2 * inset) / W, (static_cast<float>(cell) - 2 * inset) / H);
      charts.emplace_back(lo, lo + size);
      const auto base = static_cast<std::uint32_t>(positions.size());
      const glm::vec2 corner_uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int k = 0; k < 4; ++k) {
        positions.push_back(faces[f][k]);
        uv1.push_back(lo + corner_uv[k] * size);
      }
      indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    const rad::MeshId mesh = scene.add_mesh(test::mesh_desc(positions, indices, id, "cube", uv1));
    rad::SolveOptions so;
    so.mesh.max_patch_area = 0.05f;
    so.form_factors.method = rad::FormFactorMethod::ray_cast;
    so.tolerance = 1e-6;
    const rad::Solution sol = rad::solve(scene, so);
    const float expected = 1.0f / (1.0f - 0.5f);  // H = B = E / (1 - rho) in a furnace

    for (int dilation : {0, 2}) {
      CAPTURE(dilation);
      rad::LightmapOptions o;
      o.width = W;
      o.height = H;
      o.dilation = dilation;
      const rad::Lightmap map = rad::bake_lightmap(scene, sol, mesh, o);
      // Bilinear lookups along every chart's border and just inside it.
      float darkest = expected;
      for (const auto& [lo, hi] : charts)
        for (int i = 0; i <= 40; ++i) {
          const float s = static_cast<float>(i) / 40.0f;
          for (const glm::vec2 uv : {glm::vec2(lo.x + s * (hi.x - lo.x), lo.y), glm::vec2(lo.x + s * (hi.x - lo.x), hi.y),
                                     glm::vec2(lo.x, lo.y + s * (hi.y - lo.y)), glm::vec2(hi.x, lo.y + s * (hi.y - lo.y))})
            darkest = std::min(darkest, bilinear(map.image, uv).x);
        }
      MESSAGE("dilation " << dilation << ": darkest border lookup " << darkest / expected << " of the furnace value");
      if (dilation == 0) {
        CHECK(darkest < 0.9f * expected);  // the gutter's black bleeds in: the check below can fail
      } else {
        CHECK(darkest > 0.99f * expected);
        CHECK(map.dilated > 0);
      }
    }

    // Final gather in the furnace: direct light E from the other faces (exact factors summing
    // to 1) and the reflected rest E rho / (1 - rho) from the hemisphere rays.
    rad::LightmapOptions o;
    o.width = W;
    o.height = H;
    o.final_gather = true;
    o.gather_rays = 16;
    for (rad::Quantity q : {rad::Quantity::irradiance, rad::Quantity::direct_irradiance, rad::Quantity::indirect_irradiance}) {
      CAPTURE(static_cast<int>(q));
      o.quantity = q;
      const rad::Lightmap map = rad::bake_lightmap(scene, sol, mesh, o);
      const float want = q == rad::Quantity::irradiance ? expected : 1.0f;
      float lo = 1e30f, hi = 0.0f;
      for (std::size_t i = 0; i < map.state.size(); ++i)
        if (map.state[i] == rad::TexelState::covered) {
          lo = std::min(lo, map.image.pixels[i].x);
          hi = std::max(hi, map.image.pixels[i].x);
        }
      CHECK(lo > 0.99f * want);
      CHECK(hi < 1.01f * want);
    }
  }

  TEST_CASE("bake_lightmap: conservative rasterisation covers every texel a sliver triangle crosses") {
    rad::Scene scene;
    rad::Material m;
    m.emission = rad::Rgb(1.0f);
    const rad::MaterialId id = scene.add_material(m);
    // A long thin triangle whose UV footprint is a diagonal 0.1 texel wide across 32 texels.
    const std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {1, 0.01f, 0}};
    const std::vector<glm::vec2> uv1{{0.0f, 0.0f}, {1.0f, 1.0f}, {1.0f - 0.1f / 32.0f, 1.0f}};
    const std::vector<std::uint32_t> indices{0, 1, 2};
    const rad::MeshId mesh = scene.add_mesh(test::mesh_desc(positions, indices, id, "sliver", uv1));
    const rad::Solution sol = rad::solve(scene);
    rad::LightmapOptions o;
    o.width = o.height = 32;
    o.dilation = 0;
    o.quantity = rad::Quantity::radiosity;
    const rad::Lightmap map = rad::bake_lightmap(scene, sol, mesh, o);
    for (int k = 0; k < 32; ++k) {
      CAPTURE(k);
      CHECK(map.state[static_cast<std::size_t>(k) * 32 + k] == rad::TexelState::covered);
      CHECK(map.image.at(k, k).x == doctest::Approx(1.0f).epsilon(1e-4));  // B = E on a lone emitter
    }
    CHECK(map.covered >= 32);
    CHECK(map.covered <= 3 * 32);

    // UVs far outside [0, 1] are clipped before any conversion to int, not a crash (float
    // precision at 1e30 leaves the coverage test nothing it can tell; what is covered is inside).
    rad::Scene far;
    const std::vector<glm::vec2> huge{{-1e30f, 0.5f}, {1e30f, 0.5f}, {0.5f, 1e30f}};
    const rad::MeshId far_mesh = far.add_mesh(test::mesh_desc(positions, indices, far.add_material(m), "far", huge));
    const rad::Lightmap clipped = rad::bake_lightmap(far, rad::solve(far), far_mesh, o);
    CHECK(clipped.image.pixels.size() == 32u * 32u);
    CHECK(clipped.covered <= 32u * 32u);
  }

  TEST_CASE("bake_lightmap: final gather is bit-identical at 1 and 2 threads") {
    const LitFloor lit(true);
    const rad::Solution sol = rad::solve(lit.scene);
    rad::LightmapOptions o;
    o.width = o.height = 24;
    o.final_gather = true;
    o.gather_rays = 16;
    o.threads = 1;
    const rad::Lightmap one = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    o.threads = 2;
    const rad::Lightmap two = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    CHECK(one.image.pixels == two.image.pixels);
    CHECK(one.state == two.state);
  }

  TEST_CASE("bake_lightmap: two meshes sharing one atlas bake as the single mesh they split") {
    // The floor's two triangles as two meshes with the same UV1: one atlas, texel for texel the
    // lightmap of the one-mesh floor.
    const LitFloor whole(false);
    rad::Scene split;
    rad::Material white;
    white.reflectance = rad::Rgb(0.5f);
    rad::Material lamp;
    lamp.reflectance = rad::Rgb(0.0f);
    lamp.emission = rad::Rgb(kE);
    const rad::MaterialId w = split.add_material(white);
    const Floor f;
    rad::MeshDesc d = f.desc(w);
    const std::vector<std::uint32_t> first(f.indices.begin(), f.indices.begin() + 3),
        second(f.indices.begin() + 3, f.indices.end());
    d.indices = first.data();
    d.index_count = 3;
    const rad::MeshId a = split.add_mesh(d);
    d.indices = second.data();
    const rad::MeshId b = split.add_mesh(d);
    rad::add_quad(split, {0.3f, 0.3f, 0.5f}, {0.0f, 0.4f, 0.0f}, {0.4f, 0.0f, 0.0f}, split.add_material(lamp), "light");
    rad::SolveOptions o = fine_solve();
    const rad::Solution one = rad::solve(whole.scene, o), two = rad::solve(split, o);
    rad::LightmapOptions lo;
    lo.width = lo.height = 32;
    const rad::Lightmap single = rad::bake_lightmap(whole.scene, one, whole.floor, lo);
    const rad::Lightmap atlas = rad::bake_lightmap(split, two, std::vector<rad::MeshId>{a, b}, lo);
    CHECK(atlas.covered == single.covered);
    CHECK(atlas.state == single.state);
    float worst = 0.0f;
    for (std::size_t i = 0; i < single.image.pixels.size(); ++i)
      worst = std::max(worst, std::abs(atlas.image.pixels[i].y - single.image.pixels[i].y));
    CHECK(worst < 1e-3f * kE);
  }

  TEST_CASE("bake_lightmap: a progress callback that returns false cancels the bake") {
    const LitFloor lit(false);
    const rad::Solution sol = rad::solve(lit.scene);
    rad::LightmapOptions o;
    o.width = o.height = 64;
    o.final_gather = true;
    o.gather_rays = 4;
    int calls = 0;
    o.on_progress = [&](const rad::Progress& p) {
      CHECK(p.phase == rad::Phase::rendering);
      ++calls;
      return false;
    };
    const rad::Lightmap map = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    CHECK(calls == 1);
    CHECK(map.cancelled);
    CHECK(map.covered < 64 * 64 / 2);
    CHECK(map.dilated == 0);
  }

  TEST_CASE("bake_lightmap: errors name the problem") {
    const LitFloor lit(false);
    const rad::Solution sol = rad::solve(lit.scene);
    auto message = [&](auto&& call) -> std::string {
      try {
        call();
      } catch (const rad::Error& e) {
        CHECK(e.code() == rad::ErrorCode::invalid_argument);
        return e.what();
      }
      return "no error";
    };
    CHECK(message([&] { rad::bake_lightmap(lit.scene, sol, 7); }).find("mesh 7 does not exist") != std::string::npos);
    rad::LightmapOptions bad;
    bad.width = 0;
    CHECK(message([&] { rad::bake_lightmap(lit.scene, sol, lit.floor, bad); }).find("width") != std::string::npos);
    bad = {};
    bad.gather_rays = 0;
    CHECK(message([&] { rad::bake_lightmap(lit.scene, sol, lit.floor, bad); }).find("gather_rays") != std::string::npos);
    bad = {};
    bad.width = bad.height = 100000;
    CHECK(message([&] { rad::bake_lightmap(lit.scene, sol, lit.floor, bad); }).find("MiB") != std::string::npos);

    // A mesh without UV1.
    rad::Scene scene;
    Floor f;
    rad::MeshDesc d = f.desc(scene.add_material(rad::Material{}));
    d.uv1 = nullptr;
    const rad::MeshId id = scene.add_mesh(d);
    rad::Material lamp;
    lamp.emission = rad::Rgb(1.0f);
    rad::add_quad(scene, {0.3f, 0.3f, 0.5f}, {0.0f, 0.4f, 0.0f}, {0.4f, 0.0f, 0.0f}, scene.add_material(lamp));
    const rad::Solution no_uv = rad::solve(scene);
    CHECK(message([&] { rad::bake_lightmap(scene, no_uv, id); }).find("no UV1") != std::string::npos);
    // A solution of a scene without that mesh.
    rad::Scene quads;
    rad::add_quad(quads, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, quads.add_material(rad::Material{}));
    rad::add_quad(quads, {0.3f, 0.3f, 0.5f}, {0.0f, 0.4f, 0.0f}, {0.4f, 0.0f, 0.0f}, quads.add_material(lamp));
    const rad::Solution other = rad::solve(quads);
    CHECK(message([&] { rad::bake_lightmap(lit.scene, other, lit.floor); }).find("not the mesh") != std::string::npos);
  }

  TEST_CASE("bake_lightmap: the light groups' lightmaps add up to the whole - interpolated and final gather") {
    const GroupedFloor lit;
    rad::SolveOptions so;
    so.mesh.max_patch_area = 0.01f;
    so.mesh.max_element_area = 0.0025f;
    so.tolerance = 1e-6;
    so.separate_light_groups = true;
    const rad::Solution sol = rad::solve(lit.scene, so);
    REQUIRE(sol.light_groups().size() == 4);
    CHECK(sol.light_groups()[0].name == "light");
    CHECK(sol.light_groups()[1].name == "panel");
    CHECK(sol.light_groups()[2].name == "bulb");
    CHECK(sol.light_groups()[3].name == "sky");
    // A relit solution bakes its weights: each group at its own, the whole at every group's.
    const rad::Solution relit =
        sol.relight({rad::Rgb(0.5f), rad::Rgb(2.0f), rad::Rgb(0.0f), rad::Rgb(1.0f, 0.5f, 0.25f)});
    for (const rad::Solution* s : {&sol, &relit}) {
      for (bool gather : {false, true}) {
        CAPTURE(gather);
        CAPTURE(s == &relit);
        const rad::LightmapOptions o = lightmap_options(32, gather);
        const rad::Lightmap whole = rad::bake_lightmap(lit.scene, *s, lit.floor, o);
        const Agreement a = agreement(sum_of_groups(lit, *s, o), whole);
        const std::string what = std::string(s == &relit ? "relit, " : "solved, ") +
                                 (gather ? "final gather" : "interpolated");
        MESSAGE(what << ": sum of the groups against the whole: largest difference " << a.worst
                     << " of the brightest texel, mean " << a.mean);
        // Every texel's emitters are exact (2 <= exact_emitters) and each group casts the same
        // rays (same seed and texel), so only float rounding and the solver's tolerance (1e-6:
        // the groups' own solves against the joint one) separate them.
        CHECK(a.worst < 1e-5);
      }
    }
    // Final gather with exact_emitters = 1: where the whole takes the light group's lamp exactly
    // and the panel by gather rays, the panel's own bake takes it exactly: the sum agrees only
    // statistically, texel by texel within the noise of the gather rays, and over the map (the
    // estimators are unbiased) within a fraction of it.
    rad::LightmapOptions o = lightmap_options(32, true, 64);
    o.exact_emitters = 1;
    const rad::Lightmap whole = rad::bake_lightmap(lit.scene, sol, lit.floor, o);
    const Agreement a = agreement(sum_of_groups(lit, sol, o), whole);
    MESSAGE("final gather, exact_emitters 1: largest difference " << a.worst << " of the brightest texel, mean "
                                                                  << a.mean << ", totals " << a.total);
    CHECK(a.worst > 1e-3);  // not exact: the exact and gathered emitters differ between the bakes
    CHECK(a.mean < 0.05);
    CHECK(a.total < 0.005);
  }

  TEST_CASE("bake_lightmap: a light group's point light over a floor bakes I cos / r^2 with other groups on") {
    // Light groups "panel" (an area light to the side, above the point light), "lamp" (the point
    // light) and "other" (a second point light).
    rad::Scene scene;
    Floor mesh;
    rad::Material white;
    white.reflectance = rad::Rgb(0.5f);
    rad::Material panel;
    panel.emission = rad::Rgb(kE);
    const rad::MeshId floor = scene.add_mesh(mesh.desc(scene.add_material(white)));
    rad::add_quad(scene, {0.75f, 0.05f, 0.6f}, {0.0f, 0.2f, 0.0f}, {0.2f, 0.0f, 0.0f}, scene.add_material(panel),
                  "panel");
    const rad::Light lamp = test::point_light("lamp", 2.0f, {0.4f, 0.6f, 0.5f});
    scene.add_light(lamp);
    scene.add_light(test::point_light("other", 1.0f, {0.8f, 0.8f, 0.3f}));
    rad::SolveOptions so = fine_solve();
    so.separate_light_groups = true;
    const rad::Solution sol = rad::solve(scene, so);
    REQUIRE(sol.light_groups().size() == 3);
    REQUIRE(sol.light_groups()[1].name == "lamp");
    for (bool gather : {false, true}) {
      CAPTURE(gather);
      rad::LightmapOptions o = lightmap_options(32, gather);
      o.quantity = rad::Quantity::direct_irradiance;
      const rad::Lightmap all = rad::bake_lightmap(scene, sol, floor, o);
      o.light_group = 1;
      const rad::Lightmap map = rad::bake_lightmap(scene, sol, floor, o);
      double worst = 0.0, others = 1e30;
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
          const glm::vec3 p = Floor::point(x, y, 32);
          if (std::min({p.x, p.y, 1.0f - p.x, 1.0f - p.y}) < 0.05f) continue;
          const glm::vec3 d = lamp.position - p;
          const double expected = lamp.intensity * d.z / std::pow(glm::dot(d, d), 1.5);
          worst = std::max(worst, std::abs(map.image.at(x, y).y - expected) / expected);
          others = std::min(others, (all.image.at(x, y).y - expected) / expected);
        }
      MESSAGE("light group lamp, direct, " << (gather ? "final gather" : "interpolated") << ": largest relative error "
                                           << worst << "; the other groups add at least " << others);
      // Gathered: the point light exact at the texel's point (as with no other light); the
      // interpolated group values: the element mesh's interpolation error.
      CHECK(worst < (gather ? 1e-3 : 0.01));
      CHECK(others > 0.05);  // the other groups do shine on every texel
    }
  }

  TEST_CASE("bake_lightmap: light group errors name the problem") {
    const LitFloor lit(false);
    auto message = [&](const rad::Solution& sol, const rad::LightmapOptions& o) -> std::string {
      try {
        rad::bake_lightmap(lit.scene, sol, lit.floor, o);
      } catch (const rad::Error& e) {
        CHECK(e.code() == rad::ErrorCode::invalid_argument);
        return e.what();
      }
      return "no error";
    };
    rad::LightmapOptions o = lightmap_options(8, false, 4);
    o.light_group = 0;
    const rad::Solution plain = rad::solve(lit.scene);
    CHECK(message(plain, o).find("the solution has no light groups") != std::string::npos);
    rad::SolveOptions so;
    so.separate_light_groups = true;
    const rad::Solution grouped = rad::solve(lit.scene, so);
    o.light_group = 1;
    CHECK(message(grouped, o).find("light group 1 does not exist (the solution has 1 light groups") !=
          std::string::npos);
    o.light_group = -2;
    CHECK(message(grouped, o).find("light_group must be >= -1") != std::string::npos);
    // Solved with other emission than the materials': the light is off, a blocker-free floor
    // emits instead, so the solution's light group is "floor", the scene's "light".
    rad::Problem problem(lit.scene, so);
    std::vector<rad::Rgb> emission(lit.scene.polygons().size(), rad::Rgb(0.0f));
    emission.front() = rad::Rgb(1.0f);
    const rad::Solution other = problem.solve(emission);
    REQUIRE(other.light_groups().size() == 1);
    o.light_group = 0;
    CHECK(message(other, o) == "no error");  // interpolated: the solution's own values
    o.final_gather = true;
    CHECK(message(other, o).find("light groups (floor) are not those of the scene's emitters and lights (light)") !=
          std::string::npos);
  }
}
