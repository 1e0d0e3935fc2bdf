// Lights that are not polygons (Light: point, spot, directional, sky) as radiosity's first shot:
// each element's direct irradiance against closed forms and dense quadrature, the interreflection
// they start, every solver, determinism, relit solves and adaptive subdivision.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// A grey plane of side `size` centred on the origin, facing +y.
rad::Scene plane_scene(float size, rad::Rgb reflectance = rad::Rgb(0.5f)) {
  rad::Scene scene;
  rad::Material grey;
  grey.reflectance = reflectance;
  const rad::MaterialId m = scene.add_material(grey);
  rad::add_quad(scene, {-0.5f * size, 0, -0.5f * size}, {0, 0, size}, {size, 0, 0}, m, "floor");
  return scene;
}

/// The element mean of `f(x)` by a kN x kN midpoint rule over equal-area cells of the element.
template <typename F>
double element_mean(const rad::PatchHierarchy& h, std::uint32_t e, const F& f, int n = 64) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) sum += f(h.sample_point(e, glm::vec2((i + 0.5f) / n, (k + 0.5f) / n)));
  return sum / (n * n);
}

double angle_deg(glm::vec3 a, glm::vec3 b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)) * 180.0 / 3.14159265358979;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("lights: a point light over a plane gives each element the mean of I cos(theta) / r^2 within 0.5 %") {
    rad::Scene scene = plane_scene(4.0f);
    rad::Light light;
    light.type = rad::LightType::point;
    light.intensity = 10.0f;
    light.color = rad::Rgb(1.0f, 0.5f, 0.25f);
    light.position = {0.3f, 1.0f, -0.2f};
    scene.add_light(light);
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.25f;
    o.mesh.max_element_area = 1.0f / 16.0f;
    const rad::Solution sol = rad::solve(scene, o);
    const rad::PatchHierarchy& h = sol.hierarchy();
    double worst = 0.0;
    for (std::uint32_t e : h.leaves()) {
      const double exact = element_mean(h, e, [&](const glm::vec3& x) {
        const glm::vec3 d = light.position - x;
        const double r2 = glm::dot(d, d);
        return light.intensity * d.y / (r2 * std::sqrt(r2));
      });
      const rad::Rgb H = sol.direct_irradiance()[e];
      for (int c = 0; c < 3; ++c) {
        const double want = exact * light.color[c];
        worst = std::max(worst, std::fabs(H[c] - want) / want);
        CHECK(std::fabs(H[c] - want) <= 5e-3 * want);
      }
      // A plane does not see itself: all of its irradiance is the light's, and B = rho H.
      for (int c = 0; c < 3; ++c) {
        CHECK(sol.irradiance()[e][c] == doctest::Approx(H[c]).epsilon(1e-6));
        CHECK(sol.radiosity()[e][c] == doctest::Approx(0.5f * H[c]).epsilon(1e-6));
      }
    }
    MESSAGE("point light: worst element error " << worst * 100 << " % over " << h.leaves().size() << " elements");
    CHECK(sol.status() == rad::SolveStatus::converged);
    // Power onto the plane: I times the solid angle the plane subtends, per channel.
    double omega = 0.0;
    for (std::uint32_t e : h.leaves()) omega += h.element(e).area * sol.direct_irradiance()[e].x / light.intensity;
    CHECK(sol.report().light_power.x == doctest::Approx(light.intensity * omega).epsilon(1e-5));
    CHECK(sol.report().emitted_power.x == doctest::Approx(sol.report().light_power.x).epsilon(1e-6));
  }

  TEST_CASE("lights: a spot light gives nothing outside its outer cone and the full point light inside its inner cone") {
    rad::Scene scene = plane_scene(4.0f);
    rad::Light spot;
    spot.type = rad::LightType::spot;
    spot.intensity = 5.0f;
    spot.position = {0.0f, 1.0f, 0.0f};
    spot.direction = {0.0f, -1.0f, 0.2f};
    spot.inner_cone_deg = 20.0f;
    spot.outer_cone_deg = 35.0f;
    scene.add_light(spot);
    const glm::vec3 axis = scene.lights()[0].direction;
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.25f;
    o.mesh.max_element_area = 1.0f / 64.0f;
    const rad::Solution sol = rad::solve(scene, o);
    const rad::PatchHierarchy& h = sol.hierarchy();
    int inside = 0, outside = 0, between = 0;
    double worst_between = 0.0;
    for (std::uint32_t e : h.leaves()) {
      const rad::Element& el = h.element(e);
      double lo = 180.0, hi = 0.0;
      for (int k = 0; k < el.corner_count(); ++k) {
        const double a = angle_deg(h.vertices()[el.corners[k]] - spot.position, axis);
        lo = std::min(lo, a);
        hi = std::max(hi, a);
      }
      const float H = sol.direct_irradiance()[e].x;
      if (lo >= spot.outer_cone_deg) {
        CHECK(H == 0.0f);
        ++outside;
      } else if (hi <= spot.inner_cone_deg) {
        const double exact = element_mean(h, e, [&](const glm::vec3& x) {
          const glm::vec3 d = spot.position - x;
          const double r2 = glm::dot(d, d);
          return spot.intensity * d.y / (r2 * std::sqrt(r2));
        });
        CHECK(std::fabs(H - exact) <= 5e-3 * exact);
        ++inside;
      } else {
        // Between the cones: the KHR_lights_punctual falloff, by dense quadrature.
        const float ci = std::cos(spot.inner_cone_deg * 3.14159265f / 180.0f),
                    co = std::cos(spot.outer_cone_deg * 3.14159265f / 180.0f);
        const double exact = element_mean(h, e, [&](const glm::vec3& x) {
          const glm::vec3 d = spot.position - x;
          const double r2 = glm::dot(d, d);
          const float c = glm::dot(-glm::normalize(d), axis);
          const double t = std::clamp((c - co) / (ci - co), 0.0f, 1.0f);
          return spot.intensity * t * t * d.y / (r2 * std::sqrt(r2));
        });
        // The falloff's integral is split into cells until smooth: within 0.1 % of the inner
        // cone's irradiance.
        CHECK(std::fabs(H - exact) <= 1e-3 * spot.intensity);
        worst_between = std::max(worst_between, std::fabs(H - exact) / spot.intensity);
        ++between;
      }
    }
    MESSAGE("spot: worst error between the cones " << worst_between * 100 << " % of I");
    CHECK(inside > 10);
    CHECK(outside > 100);
    CHECK(between > 20);
  }

  TEST_CASE("lights: an open plane under a uniform or an overcast sky receives the sky's irradiance E") {
    for (rad::SkyModel model : {rad::SkyModel::uniform, rad::SkyModel::cie_overcast}) {
      CAPTURE(static_cast<int>(model));
      rad::Scene scene = plane_scene(2.0f);
      rad::Light sky;
      sky.type = rad::LightType::sky;
      sky.sky = model;
      sky.intensity = 100.0f;
      sky.color = rad::Rgb(0.8f, 0.9f, 1.0f);
      scene.add_light(sky);
      rad::SolveOptions o;
      o.mesh.max_patch_area = 0.25f;
      const rad::Solution sol = rad::solve(scene, o);
      for (std::uint32_t e : sol.hierarchy().leaves())
        for (int c = 0; c < 3; ++c) CHECK(sol.direct_irradiance()[e][c] == doctest::Approx(100.0f * sky.color[c]).epsilon(1e-5));
    }
  }

  TEST_CASE("lights: a vertical wall gets E / 2 of a uniform sky and 0.396 E of an overcast one") {
    for (rad::SkyModel model : {rad::SkyModel::uniform, rad::SkyModel::cie_overcast}) {
      CAPTURE(static_cast<int>(model));
      rad::Scene scene;
      const rad::MaterialId m = scene.add_material(rad::Material{});
      rad::add_quad(scene, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}, m, "wall");  // facing -z
      rad::Light sky;
      sky.type = rad::LightType::sky;
      sky.sky = model;
      sky.intensity = 1.0f;
      scene.add_light(sky);
      const rad::Solution sol = rad::solve(scene);
      // The overcast sky's vertical over horizontal illuminance: 3/14 + 4 / (7 pi) = 0.3962.
      const double want = model == rad::SkyModel::uniform ? 0.5 : 3.0 / 14.0 + 4.0 / (7.0 * 3.14159265358979);
      for (std::uint32_t e : sol.hierarchy().leaves()) CHECK(sol.direct_irradiance()[e].x == doctest::Approx(want).epsilon(1e-5));
    }
  }

  TEST_CASE("lights: under a parallel square roof the floor receives E (1 - F(x to roof)) of a uniform sky") {
    // A floor of side 4 under a roof of side 1 at height 0.5, both centred: the floor's
    // elements see the sky except the roof's solid angle, weighted by the cosine: the point
    // factor F of Lambert's contour integral.
    rad::Scene scene;
    rad::Material grey;
    const rad::MaterialId m = scene.add_material(grey);
    rad::add_quad(scene, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, m, "floor");
    const glm::vec3 roof[] = {{-0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {-0.5f, 0.5f, 0.5f}};
    rad::add_quad(scene, roof[0], {1, 0, 0}, {0, 0, 1}, m, "roof");  // facing down
    rad::Light sky;
    sky.type = rad::LightType::sky;
    sky.intensity = 1.0f;
    scene.add_light(sky);
    rad::SolveOptions o;
    o.mesh.max_patch_area = 0.25f;
    o.mesh.max_element_area = 1.0f / 16.0f;
    const rad::Solution sol = rad::solve(scene, o);
    const rad::PatchHierarchy& h = sol.hierarchy();
    double worst = 0.0, sum_error = 0.0;
    int count = 0;
    for (std::uint32_t e : h.leaves()) {
      if (h.patches()[h.element(e).patch].group != 0) continue;
      const double exact = element_mean(h, e, [&](const glm::vec3& x) {
        return 1.0 - rad::point_to_polygon_factor(x, glm::vec3(0, 1, 0), roof, 4);
      }, 16);
      const double H = sol.direct_irradiance()[e].x;
      worst = std::max(worst, std::fabs(H - exact));
      sum_error += H - exact;
      ++count;
      // 1280 rays (256, and 1024 more where they disagree) per element: the visible fraction of
      // a half-covered sky has a standard error of about 1 %.
      CHECK(std::fabs(H - exact) < 0.03);
    }
    MESSAGE("sky under a roof: worst element error " << worst << " E, mean " << sum_error / count << " E over " << count
                                                     << " elements");
    CHECK(std::fabs(sum_error / count) < 2e-3);
  }
}
