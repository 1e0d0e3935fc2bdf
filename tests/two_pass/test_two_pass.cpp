#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "core/rng.hpp"
#include "image/camera.hpp"
#include "two_pass/photon_map.hpp"
#include "two_pass/specular_scene.hpp"
#include "two_pass/two_pass_scenes.hpp"
#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

const std::vector<rad::Rgb>& layer(const rad::Image& img, const char* name) {
  for (const auto& l : img.layers)
    if (l.first == name) return l.second;
  FAIL("no layer " << name);
  static std::vector<rad::Rgb> none;
  return none;
}

rad::Solution coarse_solve(const rad::Scene& scene, float patch_area) {
  rad::SolveOptions o;
  o.form_factors.method = rad::FormFactorMethod::ray_cast;  // its accuracy is what the tests assume
  o.mesh.max_patch_area = patch_area;
  o.mesh.max_element_area = patch_area / 4.0f;
  o.tolerance = 1e-5;
  return rad::solve(scene, o);
}

/// Unpolarised Fresnel reflectance from air into a medium of index n at incidence cos_i,
/// written out here independently of the library (Born & Wolf, sec. 1.5).
double fresnel(double cos_i, double n) {
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i)) / n;
  const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin_t * sin_t));
  const double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

/// A unit room lit by a small lamp under the ceiling. The floor (added last, so the other
/// polygons keep their ids and random streams) has no diffuse part and a specular reflectance
/// `r`: a mirror for exponent 0, a Phong lobe otherwise.
rad::Scene mirror_room(bool with_floor, float r, float exponent) {
  rad::Scene s;
  rad::Material white;
  white.reflectance = rad::Rgb(0.6f, 0.5f, 0.4f);
  rad::Material lamp;
  lamp.reflectance = rad::Rgb(0.0f);
  lamp.emission = rad::Rgb(10.0f);
  rad::Material mirror;
  mirror.reflectance = rad::Rgb(0.0f);
  mirror.specular = rad::Rgb(r);
  mirror.specular_exponent = exponent;
  const auto w = s.add_material(white), l = s.add_material(lamp), m = s.add_material(mirror);
  test::add_quad(s, {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {1, 0, 0}, w, "x0");
  test::add_quad(s, {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}, {-1, 0, 0}, w, "x1");
  test::add_quad(s, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 0, 1}, w, "z0");
  test::add_quad(s, {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, {0, 0, -1}, w, "z1");
  test::add_quad(s, {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, {0, -1, 0}, w, "ceiling");
  test::add_quad(s, {{0.4f, 0.95f, 0.4f}, {0.6f, 0.95f, 0.4f}, {0.6f, 0.95f, 0.6f}, {0.4f, 0.95f, 0.6f}}, {0, -1, 0},
                 l, "lamp");
  if (with_floor) test::add_quad(s, {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, {0, 1, 0}, m, "floor");
  return s;
}

}  // namespace

TEST_SUITE("two_pass") {
  TEST_CASE("without specular parts the two-pass image equals render of the same solution") {
    const rad::Scene scene = rad::cornell_box();
    const rad::Solution sol = coarse_solve(scene, 20000.0f);
    rad::RenderOptions ro;
    ro.width = 40;
    ro.height = 32;
    ro.spp = 4;
    ro.seed = 7;
    const rad::Image expected = rad::render(scene, sol, ro);
    rad::TwoPassOptions to;
    to.width = ro.width;
    to.height = ro.height;
    to.spp = ro.spp;
    to.seed = ro.seed;
    const rad::Image got = rad::render_two_pass(scene, sol, to);
    REQUIRE(got.pixels.size() == expected.pixels.size());
    // Same rays, same interpolation: only the split into direct + indirect rounds differently
    // (a few float ulps of the pixel value).
    double worst = 0.0;
    for (std::size_t i = 0; i < got.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(double(got.pixels[i][c]) - expected.pixels[i][c]) /
                                    std::max(1e-3, double(expected.pixels[i][c])));
    CHECK(worst < 1e-5);
    for (const rad::Rgb& p : layer(got, "specular")) CHECK(p == rad::Rgb(0.0f));
    for (const rad::Rgb& p : layer(got, "caustic")) CHECK(p == rad::Rgb(0.0f));
  }

  TEST_CASE("the back of a translucent sheet shows in the two-pass image as in render") {
    // A lamp above a translucent panel that faces it, seen from below at an angle. Pass 1 puts
    // tau H_front on the panel's back; both renderers show it, the two-pass one in its indirect
    // layer.
    rad::Scene scene;
    rad::Material lamp, paper;
    lamp.emission = rad::Rgb(10.0f);
    paper.reflectance = rad::Rgb(0.2f);
    paper.diffuse_transmittance = rad::Rgb(0.5f, 0.4f, 0.3f);
    const rad::MaterialId l = scene.add_material(lamp), p = scene.add_material(paper);
    rad::add_quad(scene, {0, 1, 2}, {1, 0, 0}, {0, -1, 0}, l, "lamp");  // faces down
    rad::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, p, "paper");  // faces up
    rad::SolveOptions so;
    so.form_factors.method = rad::FormFactorMethod::monte_carlo;
    so.mesh.max_element_area = 0.02f;
    const rad::Solution sol = rad::solve(scene, so);
    rad::Camera camera;
    camera.eye = {0.3f, -0.4f, -1.0f};
    camera.look_at = {0.5f, 0.5f, 1.0f};
    camera.fov_deg = 50.0f;
    rad::RenderOptions ro;
    ro.width = ro.height = 24;
    ro.spp = 4;
    ro.camera = camera;
    const rad::Image expected = rad::render(scene, sol, ro);
    rad::TwoPassOptions to;
    to.width = to.height = ro.width;
    to.spp = ro.spp;
    to.camera = camera;
    const rad::Image got = rad::render_two_pass(scene, sol, to);
    double worst = 0.0, sum = 0.0;
    for (std::size_t i = 0; i < got.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(double(got.pixels[i][c]) - expected.pixels[i][c]) /
                                    std::max(1e-3, double(expected.pixels[i][c])));
        sum += expected.pixels[i][c];
      }
    CHECK(sum > 0.0);
    CHECK(worst < 1e-5);
    double indirect = 0.0;
    for (const rad::Rgb& v : layer(got, "indirect")) indirect += v.x;
    CHECK(indirect > 0.0);
  }

  TEST_CASE("the four layers are non-negative and sum to the image of the specular Cornell box") {
    const rad::Scene scene = rad::cornell_box_specular();
    const rad::Solution sol = coarse_solve(scene, 20000.0f);
    rad::TwoPassOptions to;
    to.width = 32;
    to.height = 32;
    to.spp = 4;
    to.caustics.photons = 20000;
    rad::TwoPassReport report;
    const rad::Image img = rad::render_two_pass(scene, sol, to, report);
    REQUIRE(img.layers.size() == 4);
    CHECK(img.layers[0].first == "direct");
    CHECK(img.layers[1].first == "indirect");
    CHECK(img.layers[2].first == "specular");
    CHECK(img.layers[3].first == "caustic");
    rad::Rgb totals[4] = {rad::Rgb(0.0f), rad::Rgb(0.0f), rad::Rgb(0.0f), rad::Rgb(0.0f)};
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      rad::Rgb sum(0.0f);
      for (int l = 0; l < 4; ++l) {
        const rad::Rgb v = img.layers[l].second[i];
        CHECK(std::min({v.x, v.y, v.z}) >= 0.0f);
        sum += v;
        totals[l] += v;
      }
      for (int c = 0; c < 3; ++c) CHECK(std::abs(img.pixels[i][c] - sum[c]) <= 1e-6f * std::max(1e-3f, sum[c]));
    }
    // Each layer holds something in this scene: the mirror and the glass are in view and the
    // glass focuses light from the lamp.
    for (int l = 0; l < 4; ++l) CHECK(totals[l].x > 0.0f);
    CHECK(report.photons_emitted == 20000);
    CHECK(report.photons_stored > 0);
    // Photons land with at most the power that left the lamp (the glass and mirror absorb or
    // let some escape, none is created).
    CHECK(report.caustic_power.x <= report.emitted_power.x);
  }

  TEST_CASE("a mirror floor of reflectance r shows r times what a camera mirrored in it sees") {
    // The floor is a black mirror of reflectance 0.8.
    const float r = 0.8f;
    const rad::Scene with = mirror_room(true, r, 0.0f), without = mirror_room(false, r, 0.0f);
    const rad::Solution sol_with = coarse_solve(with, 0.05f), sol_without = coarse_solve(without, 0.05f);
    // The black mirror neither reflects nor blocks anything in pass 1: the room is the same (to
    // the solver's tolerance and the form factors' visibility sampling, which sees one more
    // polygon).
    const rad::Rgb c1 = sol_with.group_radiosity("ceiling"), c2 = sol_without.group_radiosity("ceiling");
    CHECK(std::abs(c1.x / c2.x - 1.0f) < 1e-3f);

    const int n = 48;
    rad::TwoPassOptions to;
    to.width = n;
    to.height = n;
    to.spp = 64;
    to.camera = rad::Camera{{0.5f, 0.8f, 0.05f}, {0.5f, 0.0f, 0.45f}, {0, 1, 0}, 40.0f};
    // The lamp's light that the mirror throws onto the walls (a caustic, which pass 1 lacks)
    // would brighten the reflection; this test is about the reflection alone.
    to.caustics.photons = 0;
    const rad::Image seen = rad::render_two_pass(with, sol_with, to);
    rad::RenderOptions ro;
    ro.width = n;
    ro.height = n;
    ro.spp = 64;
    ro.seed = 99;  // other jitter than the two-pass image, on purpose
    // The camera reflected in the floor plane y = 0; a reflection flips the image left-right.
    ro.camera = rad::Camera{{0.5f, -0.8f, 0.05f}, {0.5f, 0.0f, 0.45f}, {0, -1, 0}, 40.0f};
    const rad::Image mirrored = rad::render(without, sol_without, ro);

    const auto& direct = layer(seen, "direct");
    double sum_seen = 0.0, sum_expected = 0.0;
    int pixels = 0, close = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * n + x;
        if (direct[i] != rad::Rgb(0.0f)) continue;  // some camera ray missed the mirror
        const double a = seen.pixels[i].x, b = r * mirrored.at(n - 1 - x, y).x;
        sum_seen += a;
        sum_expected += b;
        if (std::abs(a - b) <= 0.01 * b) ++close;
        ++pixels;
      }
    REQUIRE(pixels > n * n / 2);
    // Mean over the mirror: only the jitter of the two images differs (the pass 1 fields are
    // identical), which averages out to well below 0.5 %.
    CHECK(std::abs(sum_seen / sum_expected - 1.0) < 5e-3);
    // Per pixel, 64 jittered rays each: within 1 % wherever the picture is smooth; only pixels
    // on the lamp's edges (300 times brighter than the walls) and the room's corners differ more.
    CHECK(close >= 0.95 * pixels);
    MESSAGE(close << " of " << pixels << " mirror pixels within 1 %, sum ratio " << sum_seen / sum_expected);
  }

  TEST_CASE("a glossy floor with a narrow lobe reflects the room like a mirror scaled by the lobe's albedo") {
    // A Phong lobe of exponent 2000 is about 2 degrees wide: sampling it and reading pass 1 where
    // the rays land must give the mirror's picture (blurred by a pixel or so), scaled per pixel
    // by the lobe's albedo over the mirror's reflectance (energy-conserving Phong reflects
    // r cos(theta), not r). The camera looks so that the floor reflects walls and ceiling but not
    // the lamp, whose blurred edges would only add noise.
    const float r = 0.8f;
    const rad::Scene mirror = mirror_room(true, r, 0.0f), glossy = mirror_room(true, r, 2000.0f);
    const rad::Solution sol_mirror = coarse_solve(mirror, 0.05f), sol_glossy = coarse_solve(glossy, 0.05f);
    rad::TwoPassOptions to;
    to.width = 32;
    to.height = 32;
    to.spp = 16;
    to.caustics.photons = 0;
    to.camera = rad::Camera{{0.5f, 0.5f, 0.05f}, {0.5f, 0.0f, 0.6f}, {0, 1, 0}, 40.0f};
    const rad::Image a = rad::render_two_pass(mirror, sol_mirror, to), b = rad::render_two_pass(glossy, sol_glossy, to);
    const rad::detail::PinholeCamera camera(*to.camera, to.width, to.height);
    const auto& direct = layer(a, "direct");
    double expected = 0.0, got = 0.0;
    int pixels = 0;
    for (int y = 0; y < to.height; ++y)
      for (int x = 0; x < to.width; ++x) {
        if (direct[static_cast<std::size_t>(y) * to.width + x] != rad::Rgb(0.0f)) continue;  // not all on the floor
        const glm::vec3 d = camera.direction((x + 0.5f) / to.width, (y + 0.5f) / to.height);
        // The lobe's albedo: r (n+2)/(2 pi) integral of cos^n(alpha) cos(theta_i) over the lobe.
        // With cos(theta_i) = cos(theta_r) cos(alpha) + (a term odd in the lobe's azimuth), it
        // is r cos(theta_r) (n+2)/(2 pi) 2 pi/(n+2) = r cos(theta_r) while the lobe stays above
        // the horizon (here within 1e-6).
        const float c = -d.y;  // cos(theta_r): cosine to the floor's normal (0, 1, 0)
        expected += c * a.at(x, y).x;
        got += b.at(x, y).x;
        ++pixels;
      }
    REQUIRE(pixels > 300);
    // The albedo varies by about 1 % across a pixel; the lobe's blur moves light between pixels
    // of slightly different albedo; the lobe is sampled 64 times per pixel. 1 % covers these.
    CHECK(std::abs(got / expected - 1.0) < 0.01);
    MESSAGE("glossy image sum / (albedo / r x mirror image) = " << got / expected << " over " << pixels << " pixels");
  }

  TEST_CASE("photons through a glass slab put on the floor the flux that Fresnel transmission predicts") {
    // A 1 x 1 lamp facing down 0.1 above a wide clear slab (index 1.5, 0.1 thick) over a wide
    // diffuse floor. Nearly all the lamp's light meets the slab first; a slab with incoherent
    // internal reflections transmits T = (1-R)/(1+R) of what arrives at incidence theta, so the
    // floor receives P * integral of T(theta) 2 sin cos dtheta (Lambertian lamp).
    rad::Scene scene;
    rad::Material floor_m;
    floor_m.reflectance = rad::Rgb(0.5f);
    rad::Material lamp;
    lamp.reflectance = rad::Rgb(0.0f);
    lamp.emission = rad::Rgb(4.0f, 2.0f, 1.0f);
    rad::Material glass;
    glass.reflectance = rad::Rgb(0.0f);
    glass.transmittance = rad::Rgb(1.0f);
    glass.ior = 1.5f;
    const auto f = scene.add_material(floor_m), l = scene.add_material(lamp), g = scene.add_material(glass);
    test::add_quad(scene, {{-100, 0, -100}, {100, 0, -100}, {100, 0, 100}, {-100, 0, 100}}, {0, 1, 0}, f, "floor");
    test::add_box(scene, {-20, 1.0f, -20}, {20, 1.1f, 20}, g, "slab");
    test::add_quad(scene, {{-0.5f, 1.2f, -0.5f}, {0.5f, 1.2f, -0.5f}, {0.5f, 1.2f, 0.5f}, {-0.5f, 1.2f, 0.5f}},
                   {0, -1, 0}, l, "lamp");
    const rad::PatchHierarchy hierarchy(scene, rad::MeshOptions{1e6f, 1e6f});
    const rad::detail::SpecularScene specular(scene, hierarchy);
    rad::PhotonOptions po;
    po.photons = 100000;
    po.max_bounces = 12;
    const auto shot = rad::detail::shoot_caustic_photons(specular, po, 0, 0, 3);
    const rad::GroupId floor_group = *scene.find_group("floor");
    rad::Rgb on_floor(0.0f), stored(0.0f);
    for (const auto& p : shot.photons) {
      stored += p.power;
      if (scene.polygons()[p.polygon].group == floor_group) on_floor += p.power;
    }
    double expected = 0.0;
    const int steps = 20000;
    for (int i = 0; i < steps; ++i) {
      const double theta = (i + 0.5) / steps * 1.5707963267948966;
      const double R = fresnel(std::cos(theta), 1.5);
      expected += (1.0 - R) / (1.0 + R) * 2.0 * std::sin(theta) * std::cos(theta) * (1.5707963267948966 / steps);
    }
    const rad::Rgb P = shot.emitted_power;
    CHECK(P.x == doctest::Approx(4.0f).epsilon(1e-6));
    // Binomial noise of 1e5 photons on a fraction ~0.9 is 0.1 %; 1 % also covers the light
    // that misses the slab or the floor (< 0.01 %).
    for (int c = 0; c < 3; ++c) CHECK(std::abs(on_floor[c] / P[c] / expected - 1.0) < 0.01);
    // Everything stored is on the floor: the lamp's back and the slab are not diffuse landings.
    CHECK(stored.x == doctest::Approx(on_floor.x).epsilon(1e-6));
    MESSAGE("floor flux / lamp power = " << on_floor.x / P.x << ", expected " << expected);
    // A pass 1 that carried the lamp's light through glass (SolveReport::emitted_through_glass,
    // depth 1) has all of it: a reflection inside the slab beyond the depth goes on straight
    // there. No photon is stored again.
    CHECK(rad::detail::shoot_caustic_photons(specular, po, 1, 0, 3, true).photons.empty());
    // Depth 1 without it: glass is the photon map's alone, as at depth 0.
    CHECK(rad::detail::shoot_caustic_photons(specular, po, 1, 0, 3).photons.size() == shot.photons.size());
  }

  TEST_CASE("photons that the extended pass 1 carries through a window are not stored again, from either side") {
    // A lamp facing up under a window pane (ior 1, transmittance 0.7) and a diffuse ceiling
    // above it. The pane faces up or down: the photons meet its front or its back. Pass 1 at
    // depth 1 carries a window passage either way (before session 32 a passage through the
    // back was taken for a reflection, and stored again as a caustic).
    for (const float facing : {1.0f, -1.0f}) {
      CAPTURE(facing);
      rad::Scene scene;
      rad::Material ceiling, lamp, window;
      ceiling.reflectance = rad::Rgb(0.5f);
      lamp.reflectance = rad::Rgb(0.0f);
      lamp.emission = rad::Rgb(1.0f);
      window.reflectance = rad::Rgb(0.0f);
      window.transmittance = rad::Rgb(0.7f);
      window.ior = 1.0f;
      const auto c = scene.add_material(ceiling), l = scene.add_material(lamp), w = scene.add_material(window);
      test::add_quad(scene, {{-50, 2, -50}, {50, 2, -50}, {50, 2, 50}, {-50, 2, 50}}, {0, -1, 0}, c, "ceiling");
      test::add_quad(scene, {{-20, 1, -20}, {20, 1, -20}, {20, 1, 20}, {-20, 1, 20}}, {0, facing, 0}, w, "pane");
      test::add_quad(scene, {{-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}}, {0, 1, 0}, l,
                     "lamp");
      const rad::PatchHierarchy hierarchy(scene, rad::MeshOptions{1e6f, 1e6f});
      const rad::detail::SpecularScene specular(scene, hierarchy);
      rad::PhotonOptions po;
      po.photons = 20000;
      const auto all = rad::detail::shoot_caustic_photons(specular, po, 0, 0, 3);
      rad::Rgb stored(0.0f);
      for (const auto& p : all.photons) stored += p.power;
      // Classic pass 1: the photon map has the lamp's light through the pane, 0.7 of nearly all.
      CHECK(stored.x > 0.6f * all.emitted_power.x);
      CHECK(rad::detail::shoot_caustic_photons(specular, po, 1, 0, 3).photons.empty());
    }
  }

  TEST_CASE("photons that the extended pass 1 carries through the mirror are not stored again") {
    // The mirror room: the only specular surface is the planar floor, so every caustic photon
    // has exactly one specular event (a photon cannot meet a plane twice).
    const rad::Scene scene = mirror_room(true, 0.8f, 0.0f);
    const rad::PatchHierarchy hierarchy(scene, rad::MeshOptions{1.0f, 1.0f});
    const rad::detail::SpecularScene specular(scene, hierarchy);
    rad::PhotonOptions po;
    po.photons = 20000;
    const auto all = rad::detail::shoot_caustic_photons(specular, po, 0, 0, 3);
    REQUIRE(!all.photons.empty());
    rad::Rgb stored(0.0f);
    for (const auto& p : all.photons) {
      CHECK(p.specular_bounces == 1);
      stored += p.power;
    }
    // The mirror passes on at most r of what reaches it, and not all the lamp's light does.
    CHECK(stored.x < 0.8f * all.emitted_power.x);
    // Pass 1 with specular_depth 1 carries light reflected once by the mirror.
    const auto rest = rad::detail::shoot_caustic_photons(specular, po, 1, 0, 3);
    CHECK(rest.photons.empty());
  }

  TEST_CASE("the photon density estimate of a uniformly lit plane recovers its irradiance") {
    // Photons uniform on the unit square of the plane z = 0, total power E x area.
    const rad::Rgb E(2.0f, 3.0f, 4.0f);
    const std::size_t count = 400000;
    std::vector<rad::detail::Photon> photons(count);
    rad::detail::Rng rng(5);
    for (auto& p : photons) {
      const glm::vec2 u = rng.uniform2();
      p.position = glm::vec3(u.x, u.y, 0.0f);
      p.normal = glm::vec3(0, 0, 1);
      p.power = E / static_cast<float>(count);
      p.specular_bounces = 1;
    }
    const rad::detail::PhotonMap map(std::move(photons));
    for (rad::PhotonFilter filter : {rad::PhotonFilter::cone, rad::PhotonFilter::epanechnikov}) {
      double mean = 0.0, worst = 0.0;
      int n = 0;
      for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
          const glm::vec3 x(0.3f + 0.1f * i, 0.3f + 0.1f * j, 0.0f);
          const rad::Rgb got = map.irradiance(x, glm::vec3(0, 0, 1), 1000, 0.2f, filter);
          CHECK(std::abs(got.z / got.x - 2.0f) < 1e-4f);
          mean += got.x / E.x;
          worst = std::max(worst, std::abs(got.x / E.x - 1.0));
          ++n;
        }
      mean /= n;
      // k = 1000 photons: relative noise about 1/sqrt(k) = 3 % per estimate, about 4 % with a
      // peaked kernel (12 % is 3 sigma); the 25 disjoint discs average it to under 1.5 %.
      CHECK(std::abs(mean - 1.0) < 0.015);
      CHECK(worst < 0.12);
      MESSAGE("filter " << static_cast<int>(filter) << ": mean " << mean << ", worst " << worst);
    }
    // A surface facing another way sees none of these photons; a point far away neither.
    CHECK(map.irradiance({0.5f, 0.5f, 0.0f}, {1, 0, 0}, 100, 0.2f, rad::PhotonFilter::cone) == rad::Rgb(0.0f));
    CHECK(map.irradiance({5.0f, 5.0f, 0.0f}, {0, 0, 1}, 100, 0.2f, rad::PhotonFilter::cone) == rad::Rgb(0.0f));
  }

  TEST_CASE("the two-pass image with caustics is identical at 1 and 2 threads") {
    const rad::Scene scene = rad::cornell_box_specular();
    const rad::Solution sol = coarse_solve(scene, 20000.0f);
    rad::TwoPassOptions to;
    to.width = 24;
    to.height = 24;
    to.spp = 4;
    to.caustics.photons = 20000;
    to.diffuse = rad::DiffuseShading::final_gather;
    to.threads = 1;
    const rad::Image a = rad::render_two_pass(scene, sol, to);
    to.threads = 2;
    const rad::Image b = rad::render_two_pass(scene, sol, to);
    CHECK(a.pixels == b.pixels);
    REQUIRE(a.layers.size() == b.layers.size());
    for (std::size_t l = 0; l < a.layers.size(); ++l) CHECK(a.layers[l].second == b.layers[l].second);
  }

  TEST_CASE("the final gather of direct light agrees with the direct part of pass 1") {
    const rad::Scene scene = rad::cornell_box();
    const rad::Solution sol = coarse_solve(scene, 20000.0f);
    rad::TwoPassOptions to;
    to.width = 32;
    to.height = 32;
    to.spp = 16;
    to.content = rad::TwoPassContent::direct_only;
    const rad::Image by_pass1 = rad::render_two_pass(scene, sol, to);
    to.diffuse = rad::DiffuseShading::final_gather;
    const rad::Image gathered = rad::render_two_pass(scene, sol, to);
    for (const auto& p : layer(by_pass1, "indirect")) CHECK(p == rad::Rgb(0.0f));
    rad::Rgb a(0.0f), b(0.0f);
    for (std::size_t i = 0; i < by_pass1.pixels.size(); ++i) a += by_pass1.pixels[i], b += gathered.pixels[i];
    // Both estimate the same direct light, one per element and interpolated, one per pixel; the
    // image means agree to the interpolation error of a coarse mesh.
    for (int c = 0; c < 3; ++c) CHECK(std::abs(a[c] / b[c] - 1.0f) < 0.03f);
    MESSAGE("direct: pass-1 split / final gather = " << a.x / b.x);
  }

  TEST_CASE("bad two-pass options are rejected with the field named") {
    const rad::Scene scene = test::closed_box(rad::Material{});
    const rad::Solution sol = coarse_solve(scene, 1.0f);
    rad::TwoPassOptions to;
    to.width = 8;
    to.height = 8;
    to.spp = 0;
    CHECK_THROWS_WITH_AS(rad::render_two_pass(scene, sol, to), doctest::Contains("spp"), rad::Error);
    to.spp = 1;
    to.caustics.nearest = 0;
    CHECK_THROWS_WITH_AS(rad::render_two_pass(scene, sol, to), doctest::Contains("caustics.nearest"), rad::Error);
    to.caustics.nearest = 10;
    to.max_specular_depth = -1;
    CHECK_THROWS_AS(rad::render_two_pass(scene, sol, to), rad::Error);
    to.max_specular_depth = 2;
    const rad::Scene other = rad::cornell_box();
    const rad::Solution other_sol = coarse_solve(other, 40000.0f);
    CHECK_THROWS_AS(rad::render_two_pass(scene, other_sol, to), rad::Error);
  }
}

TEST_SUITE("two_pass") {
  TEST_CASE("glass interfaces are split into reflection and refraction so glass renders without grain") {
    // The glass Cornell box at 64 x 64, 4 camera rays per pixel, no photons, rendered at two
    // seeds: with delta events split (the first three of a camera path) the specular layers
    // differ only by the pixel jitter and the deeper random choices. Measured: 9.0 % relative
    // RMS difference over the pixels that see through the glass; 29 % without splitting.
    const rad::Scene scene = rad::cornell_box_specular(rad::CornellSpecular::glass);
    rad::SolveOptions so;
    so.form_factors.method = rad::FormFactorMethod::monte_carlo;
    so.form_factors.specular_depth = 1;
    so.mesh.max_patch_area = 20000.0f;
    const rad::Solution sol = rad::solve(scene, so);
    rad::TwoPassOptions to;
    to.width = to.height = 64;
    to.spp = 4;
    to.caustics.photons = 0;
    to.seed = 1;
    const rad::Image a = rad::render_two_pass(scene, sol, to);
    to.seed = 2;
    const rad::Image b = rad::render_two_pass(scene, sol, to);
    // Over the pixels whose light went through the glass (a specular layer in either image).
    const std::vector<rad::Rgb>&sa = layer(a, "specular"), &sb = layer(b, "specular");
    double squared = 0.0, sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < sa.size(); ++i) {
      if (sa[i] == rad::Rgb(0.0f) && sb[i] == rad::Rgb(0.0f)) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = double(sa[i][c]) - sb[i][c];
        squared += d * d;
        sum += 0.5 * (double(sa[i][c]) + sb[i][c]);
      }
      ++count;
    }
    REQUIRE(count > 50);
    const double difference = std::sqrt(squared / (3.0 * count)) / (sum / (3.0 * count));
    MESSAGE("glass box at 4 spp: relative RMS difference of the specular layer between seeds "
            << difference << " over " << count << " pixels");
    CHECK(difference < 0.15);
  }
}
