// Closed forms and invariants of the analytic BRDF models, parameter validation and the
// shading frame.
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/gtc/constants.hpp>

#include "brdf/brdf_test_util.hpp"
#include "radiosity/brdf.hpp"
#include "radiosity/scene.hpp"

using namespace brdf_test;
using radiosity::ErrorCode;
using radiosity::Rgb;

namespace {

/// Runs `make` and checks that it throws Error{invalid_argument} whose message names `param`.
template <typename Make>
void check_rejects(Make make, const std::string& param) {
  try {
    make();
    FAIL("no exception; expected one naming ", param);
  } catch (const radiosity::Error& e) {
    INFO("message: ", e.what());
    CHECK(e.code() == ErrorCode::invalid_argument);
    CHECK(std::string(e.what()).find(param) != std::string::npos);
  }
}

bool near_rel(float a, float b, float rel, float abs_tol = 1e-7f) {
  return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + abs_tol;
}

}  // namespace

TEST_SUITE("brdf") {
  TEST_CASE("lambertian equals reflectance over pi exactly and its albedo is the reflectance") {
    const Rgb rho(0.8f, 0.5f, 0.25f);
    const auto b = radiosity::make_lambertian(rho);
    Rng rng(7);
    for (int n = 0; n < 100; ++n) {
      const glm::vec3 wo = rng.upper_hemisphere();
      const glm::vec3 wi = rng.upper_hemisphere();
      CHECK(b->eval(wo, wi) == rho / glm::pi<float>());
      CHECK(b->albedo(wo) == rho);
      const auto s = b->sample(wo, rng.next_vec2());
      REQUIRE(s);
      CHECK(s->weight == rho);
    }
    // One-sided: nothing below the horizon.
    CHECK(b->eval(dir_deg(30, 0), dir_deg(120, 1)) == Rgb(0.0f));
    CHECK(b->eval(dir_deg(120, 0), dir_deg(30, 1)) == Rgb(0.0f));
    CHECK_FALSE(b->sample(dir_deg(120, 0), glm::vec2(0.5f)));
    CHECK_FALSE(b->is_delta());
  }

  TEST_CASE("every non-delta model obeys Helmholtz reciprocity") {
    // 2000 random pairs on the upper hemisphere per model; relative tolerance 1e-4 (float).
    for (const auto& m : glossy_models()) {
      Rng rng(11);
      for (int n = 0; n < 2000; ++n) {
        const glm::vec3 a = rng.upper_hemisphere();
        const glm::vec3 b = rng.upper_hemisphere();
        const Rgb f_ab = m.brdf->eval(a, b);
        const Rgb f_ba = m.brdf->eval(b, a);
        INFO(m.name, " a=(", a.x, ",", a.y, ",", a.z, ") b=(", b.x, ",", b.y, ",", b.z, ")");
        for (int k = 0; k < 3; ++k) REQUIRE(near_rel(f_ab[k], f_ba[k], 1e-4f));
      }
    }
  }

  TEST_CASE("albedo matches an independent quadrature of f cos") {
    // Midpoint rule on a 256 x 512 (theta, phi) grid (error < 1e-3 for these lobes) vs albedo().
    // The default albedo() is a 128^2 stratified estimate; tolerance 0.5 % as documented.
    double worst = 0.0;
    for (const auto& m : glossy_models()) {
      for (const double theta : {0.0, 35.0, 65.0, 85.0}) {
        const glm::vec3 wo = dir_deg(theta, 0.7);
        const glm::dvec3 q = quadrature_albedo(*m.brdf, wo);
        const Rgb a = m.brdf->albedo(wo);
        for (int k = 0; k < 3; ++k) {
          const double rel = std::abs(a[k] - q[k]) / q[k];
          worst = std::max(worst, rel);
          INFO(m.name, " theta_o=", theta, " channel ", k, " albedo=", a[k], " quadrature=", q[k]);
          CHECK(rel < 0.005);
        }
      }
    }
    if (verbose()) MESSAGE("worst relative albedo error vs quadrature: ", worst);
  }

  TEST_CASE("albedo is at most one for energy-conserving parameters") {
    // Parameters at the energy limit (diffuse + specular = 1, f0 = 1), 9 x 2 viewing directions
    // from normal to 89.5 degrees. Slack 2e-3 for the albedo estimator's own error.
    std::vector<NamedBrdf> limit;
    limit.push_back({"lambertian 1", radiosity::make_lambertian(Rgb(1.0f))});
    limit.push_back({"phong n=10", radiosity::make_phong(Rgb(0.4f), Rgb(0.6f), 10.0f)});
    limit.push_back({"phong n=1000 specular only", radiosity::make_phong(Rgb(0.0f), Rgb(1.0f), 1000.0f)});
    limit.push_back({"phong n=1 specular only", radiosity::make_phong(Rgb(0.0f), Rgb(1.0f), 1.0f)});
    limit.push_back({"blinn-phong n=0 specular only", radiosity::make_blinn_phong(Rgb(0.0f), Rgb(1.0f), 0.0f)});
    limit.push_back({"blinn-phong n=500", radiosity::make_blinn_phong(Rgb(0.3f), Rgb(0.7f), 500.0f)});
    limit.push_back({"ward 0.05", radiosity::make_ward(Rgb(0.0f), Rgb(1.0f), 0.05f, 0.05f)});
    limit.push_back({"ward 0.5 x 0.1", radiosity::make_ward(Rgb(0.0f), Rgb(1.0f), 0.5f, 0.1f)});
    limit.push_back({"ward 0.8", radiosity::make_ward(Rgb(0.2f), Rgb(0.8f), 0.8f, 0.8f)});
    limit.push_back({"ggx 0.05", radiosity::make_microfacet(Rgb(1.0f), 0.05f, 0.05f)});
    limit.push_back({"ggx 1.0 x 0.3", radiosity::make_microfacet(Rgb(1.0f), 1.0f, 0.3f)});
    limit.push_back({"mix", radiosity::make_mix(radiosity::make_lambertian(Rgb(1.0f)),
                                                radiosity::make_microfacet(Rgb(1.0f), 0.3f, 0.3f), 0.3f)});
    double highest = 0.0;
    for (const auto& m : limit) {
      for (const double theta : {0.0, 20.0, 40.0, 60.0, 70.0, 80.0, 85.0, 88.0, 89.5}) {
        for (int j = 0; j < 2; ++j) {
          const glm::vec3 wo = dir_deg(theta, 0.4 + 2.5 * j);
          const Rgb a = m.brdf->albedo(wo);
          for (int k = 0; k < 3; ++k) {
            highest = std::max(highest, static_cast<double>(a[k]));
            INFO(m.name, " wo.z=", wo.z, " albedo=", a[k]);
            CHECK(a[k] <= 1.002f);
            CHECK(a[k] >= 0.0f);
          }
        }
      }
    }
    if (verbose()) MESSAGE("highest albedo at the energy limit: ", highest);
  }

  TEST_CASE("phong albedo at normal incidence equals diffuse plus specular") {
    // Lafortune & Willems' normalisation makes the lobe's albedo exactly ks at normal incidence.
    const auto b = radiosity::make_phong(Rgb(0.2f, 0.1f, 0.0f), Rgb(0.5f, 0.6f, 0.9f), 40.0f);
    const Rgb a = b->albedo(glm::vec3(0.0f, 0.0f, 1.0f));
    CHECK(a.x == doctest::Approx(0.7).epsilon(1e-3));
    CHECK(a.y == doctest::Approx(0.7).epsilon(1e-3));
    CHECK(a.z == doctest::Approx(0.9).epsilon(1e-3));
  }

  TEST_CASE("isotropic models are invariant under a rotation about the normal") {
    // Both directions rotated by the same random angle; relative tolerance 1e-4.
    std::vector<NamedBrdf> iso;
    for (const auto& m : glossy_models()) {
      if (m.name != "ward 0.1 x 0.3" && m.name != "ggx 0.1 x 0.4") iso.push_back(m);
    }
    for (const auto& m : iso) {
      Rng rng(13);
      for (int n = 0; n < 1000; ++n) {
        const glm::vec3 wo = rng.upper_hemisphere();
        const glm::vec3 wi = rng.upper_hemisphere();
        const float angle = 6.2831853f * rng.next_float();
        const Rgb f = m.brdf->eval(wo, wi);
        const Rgb g = m.brdf->eval(rotate_z(wo, angle), rotate_z(wi, angle));
        INFO(m.name, " angle=", angle);
        for (int k = 0; k < 3; ++k) REQUIRE(near_rel(f[k], g[k], 1e-4f, 1e-6f));
        REQUIRE(m.brdf->pdf(wo, wi) == doctest::Approx(m.brdf->pdf(rotate_z(wo, angle), rotate_z(wi, angle)))
                                           .epsilon(1e-4));
      }
    }
  }

  TEST_CASE("anisotropic ward and ggx change under a rotation about the normal") {
    // The lobe is elongated along y (alpha_y > alpha_x): an off-specular pair displaced along y
    // reflects more than the same pair rotated by 90 degrees (displaced along x).
    const auto ward = radiosity::make_ward(Rgb(0.0f), Rgb(0.8f), 0.1f, 0.4f);
    const auto ggx = radiosity::make_microfacet(Rgb(0.8f), 0.1f, 0.4f);
    const glm::vec3 wo = dir_deg(30.0, 0.0);
    const glm::vec3 wi = glm::normalize(glm::vec3(-wo.x, 0.3f, wo.z));  // mirror direction tilted along y
    for (const radiosity::Brdf* b : {ward.get(), ggx.get()}) {
      const float along_y = b->eval(wo, wi).x;
      const float along_x = b->eval(rotate_z(wo, 1.5707963f), rotate_z(wi, 1.5707963f)).x;
      INFO("along y ", along_y, " along x ", along_x);
      CHECK(along_y > 2.0f * along_x);
    }
    // The albedo differs too when the view direction is rotated.
    CHECK(std::abs(ward->albedo(dir_deg(70, 0.0)).x - ward->albedo(dir_deg(70, 1.5707963)).x) > 0.01f);
  }

  TEST_CASE("mix is the weighted sum of its parts") {
    const std::shared_ptr<const radiosity::Brdf> a = radiosity::make_lambertian(Rgb(0.6f));
    const std::shared_ptr<const radiosity::Brdf> b = radiosity::make_microfacet(Rgb(0.5f), 0.3f, 0.3f);
    const auto mix = radiosity::make_mix(a, b, 0.25f);
    Rng rng(17);
    for (int n = 0; n < 200; ++n) {
      const glm::vec3 wo = rng.upper_hemisphere();
      const glm::vec3 wi = rng.upper_hemisphere();
      const Rgb expect = 0.75f * a->eval(wo, wi) + 0.25f * b->eval(wo, wi);
      for (int k = 0; k < 3; ++k) CHECK(near_rel(mix->eval(wo, wi)[k], expect[k], 1e-6f));
      CHECK(mix->pdf(wo, wi) == doctest::Approx(0.75f * a->pdf(wo, wi) + 0.25f * b->pdf(wo, wi)));
    }
    const glm::vec3 wo = dir_deg(40, 0.2);
    CHECK(mix->albedo(wo).x == doctest::Approx(0.75f * a->albedo(wo).x + 0.25f * b->albedo(wo).x));
    // A mix with a delta part keeps the delta samples, with the discrete probability scaled.
    const auto glossy_mirror = radiosity::make_mix(a, radiosity::make_mirror(Rgb(0.9f)), 0.5f);
    const auto s = glossy_mirror->sample(wo, glm::vec2(0.2f, 0.5f));
    REQUIRE(s);
    CHECK(s->delta);
    CHECK(s->pdf == doctest::Approx(0.5f));
    CHECK(s->weight.x == doctest::Approx(0.9f));
    CHECK_FALSE(glossy_mirror->is_delta());
    CHECK(radiosity::make_mix(radiosity::make_mirror(Rgb(1.0f)), radiosity::make_dielectric(1.5f, Rgb(1.0f)), 0.5f)
              ->is_delta());
  }

  TEST_CASE("albedo is deterministic") {
    for (const auto& m : glossy_models()) {
      const glm::vec3 wo = dir_deg(50, 2.0);
      CHECK(m.brdf->albedo(wo) == m.brdf->albedo(wo));
    }
  }

  TEST_CASE("factories reject invalid parameters and name them") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    check_rejects([&] { return radiosity::make_lambertian(Rgb(nan, 0.5f, 0.5f)); }, "reflectance");
    check_rejects([&] { return radiosity::make_lambertian(Rgb(-0.1f, 0.5f, 0.5f)); }, "reflectance");
    check_rejects([&] { return radiosity::make_lambertian(Rgb(0.5f, 1.1f, 0.5f)); }, "reflectance");

    check_rejects([&] { return radiosity::make_phong(Rgb(0.6f), Rgb(0.5f), 10.0f); }, "diffuse + specular");
    check_rejects([&] { return radiosity::make_phong(Rgb(0.2f), Rgb(0.5f), -1.0f); }, "exponent");
    check_rejects([&] { return radiosity::make_phong(Rgb(0.2f), Rgb(0.5f), nan); }, "exponent");
    check_rejects([&] { return radiosity::make_phong(Rgb(0.2f), Rgb(0.5f, -0.1f, 0.0f), 5.0f); }, "specular");
    check_rejects([&] { return radiosity::make_phong(Rgb(inf), Rgb(0.0f), 5.0f); }, "diffuse");

    check_rejects([&] { return radiosity::make_blinn_phong(Rgb(0.5f), Rgb(0.0f, 0.0f, 0.6f), 10.0f); },
                  "diffuse + specular");
    check_rejects([&] { return radiosity::make_blinn_phong(Rgb(0.2f), Rgb(0.5f), -0.5f); }, "exponent");

    check_rejects([&] { return radiosity::make_ward(Rgb(0.2f), Rgb(0.5f), 0.0f, 0.1f); }, "alpha_x");
    check_rejects([&] { return radiosity::make_ward(Rgb(0.2f), Rgb(0.5f), 0.1f, -0.1f); }, "alpha_y");
    check_rejects([&] { return radiosity::make_ward(Rgb(0.2f), Rgb(0.5f), 0.1f, nan); }, "alpha_y");
    check_rejects([&] { return radiosity::make_ward(Rgb(0.7f), Rgb(0.5f), 0.1f, 0.1f); }, "diffuse + specular");

    check_rejects([&] { return radiosity::make_microfacet(Rgb(0.5f), 0.0f, 0.1f); }, "roughness_x");
    check_rejects([&] { return radiosity::make_microfacet(Rgb(0.5f), 0.1f, -1.0f); }, "roughness_y");
    check_rejects([&] { return radiosity::make_microfacet(Rgb(1.5f), 0.1f, 0.1f); }, "f0");
    check_rejects([&] { return radiosity::make_microfacet(Rgb(0.5f), inf, 0.1f); }, "roughness_x");

    check_rejects([&] { return radiosity::make_mirror(Rgb(0.5f, nan, 0.5f)); }, "reflectance");
    check_rejects([&] { return radiosity::make_mirror(Rgb(2.0f)); }, "reflectance");

    check_rejects([&] { return radiosity::make_dielectric(0.0f, Rgb(1.0f)); }, "eta");
    check_rejects([&] { return radiosity::make_dielectric(-1.5f, Rgb(1.0f)); }, "eta");
    check_rejects([&] { return radiosity::make_dielectric(nan, Rgb(1.0f)); }, "eta");
    check_rejects([&] { return radiosity::make_dielectric(1.5f, Rgb(1.0f, 1.2f, 1.0f)); }, "tint");

    const std::shared_ptr<const radiosity::Brdf> l = radiosity::make_lambertian(Rgb(0.5f));
    check_rejects([&] { return radiosity::make_mix(nullptr, l, 0.5f); }, "first");
    check_rejects([&] { return radiosity::make_mix(l, nullptr, 0.5f); }, "second");
    check_rejects([&] { return radiosity::make_mix(l, l, 1.5f); }, "weight_second");
    check_rejects([&] { return radiosity::make_mix(l, l, nan); }, "weight_second");

    check_rejects([&] { return radiosity::fresnel_dielectric(0.5f, 0.0f); }, "eta");

    // Limits that are allowed.
    CHECK_NOTHROW(radiosity::make_phong(Rgb(0.5f), Rgb(0.5f), 0.0f));
    CHECK_NOTHROW(radiosity::make_lambertian(Rgb(0.0f)));
    CHECK_NOTHROW(radiosity::make_lambertian(Rgb(1.0f)));
  }

  TEST_CASE("shading frame is orthonormal - right-handed and round-trips directions") {
    Rng rng(19);
    for (int n = 0; n < 500; ++n) {
      // Normals all over the sphere, including near -z where the construction switches branch.
      const float z = n < 5 ? -1.0f + 1e-7f * n : 2.0f * rng.next_float() - 1.0f;
      const float phi = 6.2831853f * rng.next_float();
      const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      const glm::vec3 normal(r * std::cos(phi), r * std::sin(phi), z);
      const auto f = radiosity::ShadingFrame::from_normal(3.0f * normal);
      CHECK(glm::length(f.tangent) == doctest::Approx(1.0f).epsilon(1e-5));
      CHECK(glm::length(f.bitangent) == doctest::Approx(1.0f).epsilon(1e-5));
      CHECK(std::abs(glm::dot(f.tangent, f.bitangent)) < 1e-5f);
      CHECK(std::abs(glm::dot(f.tangent, f.normal)) < 1e-5f);
      CHECK(glm::length(glm::cross(f.normal, f.tangent) - f.bitangent) < 1e-5f);
      CHECK(glm::length(f.to_local(f.normal) - glm::vec3(0, 0, 1)) < 1e-5f);
      const glm::vec3 v = rng.upper_hemisphere();
      CHECK(glm::length(f.to_local(f.to_world(v)) - v) < 1e-5f);
    }
    const auto t = radiosity::ShadingFrame::from_normal_tangent(glm::vec3(0, 0, 2), glm::vec3(1, 1, 5));
    CHECK(glm::length(t.tangent - glm::normalize(glm::vec3(1, 1, 0))) < 1e-6f);
    CHECK(glm::length(t.bitangent - glm::normalize(glm::vec3(-1, 1, 0))) < 1e-6f);
    // A tangent parallel to the normal falls back to some valid frame.
    const auto p = radiosity::ShadingFrame::from_normal_tangent(glm::vec3(0, 0, 1), glm::vec3(0, 0, 3));
    CHECK(std::abs(glm::dot(p.tangent, p.normal)) < 1e-6f);
    CHECK_THROWS_AS(radiosity::ShadingFrame::from_normal(glm::vec3(0.0f)), radiosity::Error);
  }
}

TEST_CASE("make_brdf derives the second-pass model from a material's fields") {
  using namespace radiosity;
  const glm::vec3 wo = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
  SUBCASE("diffuse only is Lambertian") {
    Material m;
    m.reflectance = Rgb(0.2f, 0.4f, 0.6f);
    const auto b = make_brdf(m);
    const Rgb f = b->eval(wo, glm::vec3(0, 0, 1));
    CHECK(f.y == doctest::Approx(0.4f / 3.14159265f).epsilon(1e-6));
  }
  SUBCASE("a mirror keeps both albedos") {
    Material m;
    m.reflectance = Rgb(0.1f, 0.2f, 0.3f);
    m.specular = Rgb(0.6f);
    const auto b = make_brdf(m);
    const Rgb a = b->albedo(wo);
    CHECK(a.x == doctest::Approx(0.7f).epsilon(0.01));
    CHECK(a.z == doctest::Approx(0.9f).epsilon(0.01));
  }
  SUBCASE("glass is a dielectric that conserves energy") {
    Material m;
    m.reflectance = Rgb(0.0f);
    m.transmittance = Rgb(1.0f);
    m.ior = 1.5f;
    const auto b = make_brdf(m);
    CHECK(b->is_delta());
    CHECK(b->albedo(wo).y == doctest::Approx(1.0f).epsilon(1e-4));
  }
  SUBCASE("a set brdf wins") {
    Material m;
    m.brdf = make_mirror(Rgb(0.5f));
    CHECK(make_brdf(m) == m.brdf);
  }
}
