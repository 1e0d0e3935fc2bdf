// Ideal specular models: mirror and smooth dielectric.
#include <cmath>

#include <doctest/doctest.h>

#include "brdf/brdf_test_util.hpp"
#include "radiosity/brdf.hpp"

using namespace brdf_test;
using radiosity::Rgb;

TEST_SUITE("brdf") {
  TEST_CASE("mirror returns the reflected direction with weight equal to the reflectance") {
    const Rgb r(0.9f, 0.8f, 0.5f);
    const auto m = radiosity::make_mirror(r);
    Rng rng(23);
    for (int n = 0; n < 200; ++n) {
      const glm::vec3 wo = rng.upper_hemisphere();
      const auto s = m->sample(wo, rng.next_vec2());
      REQUIRE(s);
      CHECK(s->delta);
      CHECK(s->pdf == 1.0f);
      CHECK(s->weight == r);
      CHECK(s->wi == glm::vec3(-wo.x, -wo.y, wo.z));
      // Angle of incidence = angle of reflection, in the plane of incidence.
      CHECK(glm::dot(s->wi, glm::vec3(0, 0, 1)) == doctest::Approx(glm::dot(wo, glm::vec3(0, 0, 1))));
      CHECK(m->eval(wo, s->wi) == Rgb(0.0f));
      CHECK(m->pdf(wo, s->wi) == 0.0f);
      CHECK(m->albedo(wo) == r);
    }
    CHECK(m->is_delta());
    CHECK_FALSE(m->sample(glm::vec3(0.0f, 0.6f, -0.8f), glm::vec2(0.5f)));
  }

  TEST_CASE("dielectric conserves energy: R + T = 1 for a white tint") {
    // From both sides, at angles from normal to grazing: the probabilities of the two events add
    // to 1, each weight is exactly 1, and a 4096-sample mean of the weight is 1.
    const auto glass = radiosity::make_dielectric(1.5f, Rgb(1.0f));
    for (int i = 0; i <= 30; ++i) {
      for (const float side : {1.0f, -1.0f}) {
        const double theta = 89.5 * i / 30.0;
        glm::vec3 wo = dir_deg(theta, 0.4);
        wo.z *= side;
        const auto refl = glass->sample(wo, glm::vec2(0.0f, 0.5f));
        const auto last = glass->sample(wo, glm::vec2(0.9999999f, 0.5f));
        REQUIRE(refl);
        REQUIRE(last);
        const float R = radiosity::fresnel_dielectric(wo.z, 1.5f);
        INFO("theta=", theta, " side=", side, " R=", R);
        CHECK(refl->pdf == doctest::Approx(R));
        CHECK(refl->weight == Rgb(1.0f));
        if (R < 1.0f) {
          CHECK(last->wi.z * wo.z < 0.0f);  // refracted: the other side
          CHECK(refl->pdf + last->pdf == doctest::Approx(1.0f));
          CHECK(last->weight == Rgb(1.0f));
        }
        CHECK(glass->albedo(wo).x == doctest::Approx(1.0f));
        double sum = 0.0;
        Rng rng(29);
        for (int n = 0; n < 4096; ++n) sum += glass->sample(wo, rng.next_vec2())->weight.x;
        CHECK(sum / 4096.0 == doctest::Approx(1.0));
      }
    }
    CHECK(glass->is_delta());
    CHECK(glass->eval(dir_deg(30, 0), dir_deg(150, 3.14)) == Rgb(0.0f));
    CHECK(glass->pdf(dir_deg(30, 0), dir_deg(150, 3.14)) == 0.0f);
  }

  TEST_CASE("dielectric reflects with probability equal to the Fresnel reflectance") {
    // Normal incidence: R = ((eta - 1) / (eta + 1))^2 = 0.04 for eta = 1.5; Brewster's angle
    // atan(eta) has zero p-reflectance, so R = Rs / 2 there. The sampled frequency of reflection
    // over 1e5 samples matches R within 4 binomial sigma.
    CHECK(radiosity::fresnel_dielectric(1.0f, 1.5f) == doctest::Approx(0.04f).epsilon(1e-4));
    CHECK(radiosity::fresnel_dielectric(-1.0f, 1.5f) == doctest::Approx(0.04f).epsilon(1e-4));
    const float brewster = std::atan(1.5f);
    const float ci = std::cos(brewster);
    const float ct = std::sqrt(1.0f - std::sin(brewster) * std::sin(brewster) / 2.25f);
    const float rs = (ci - 1.5f * ct) / (ci + 1.5f * ct);
    CHECK(radiosity::fresnel_dielectric(ci, 1.5f) == doctest::Approx(0.5f * rs * rs).epsilon(1e-4));
    CHECK(radiosity::fresnel_dielectric(0.0f, 1.5f) == doctest::Approx(1.0f));

    const auto glass = radiosity::make_dielectric(1.5f, Rgb(1.0f));
    const glm::vec3 wo = dir_deg(60.0, 1.0);
    const double R = radiosity::fresnel_dielectric(wo.z, 1.5f);
    Rng rng(31);
    int reflected = 0;
    constexpr int kN = 100000;
    for (int n = 0; n < kN; ++n) {
      if (glass->sample(wo, rng.next_vec2())->wi.z > 0.0f) ++reflected;
    }
    const double sigma = std::sqrt(R * (1.0 - R) / kN);
    CHECK(std::abs(reflected / static_cast<double>(kN) - R) < 4.0 * sigma);
  }

  TEST_CASE("dielectric refraction obeys Snell's law from both sides") {
    const float eta = 1.5f;
    const auto glass = radiosity::make_dielectric(eta, Rgb(0.8f, 0.9f, 1.0f));
    for (int i = 0; i < 40; ++i) {
      for (const float side : {1.0f, -1.0f}) {
        const double theta = 85.0 * i / 39.0;
        const double phi = 0.3 + 0.1 * i;
        glm::vec3 wo = dir_deg(theta, phi);
        wo.z *= side;
        const float eta_o = side > 0 ? 1.0f : eta;  // index on wo's side
        const float eta_t = side > 0 ? eta : 1.0f;
        const float sin_o = std::sqrt(wo.x * wo.x + wo.y * wo.y);
        if (eta_o * sin_o >= eta_t) continue;  // total internal reflection, tested below
        const auto s = glass->sample(wo, glm::vec2(0.9999f, 0.5f));
        REQUIRE(s);
        INFO("theta=", theta, " side=", side);
        REQUIRE(s->wi.z * wo.z < 0.0f);
        CHECK(s->delta);
        CHECK(glm::length(s->wi) == doctest::Approx(1.0f).epsilon(1e-5));
        const float sin_t = std::sqrt(s->wi.x * s->wi.x + s->wi.y * s->wi.y);
        // eta_i sin(theta_i) = eta_t sin(theta_t)
        CHECK(eta_o * sin_o == doctest::Approx(eta_t * sin_t).epsilon(1e-4));
        // In the plane of incidence, on the far side of the normal.
        if (sin_o > 1e-3f) {
          CHECK(glm::dot(glm::vec2(s->wi.x, s->wi.y), glm::vec2(wo.x, wo.y)) ==
                doctest::Approx(-sin_t * sin_o).epsilon(1e-4));
        }
        // Tint applies to transmission, in the importance convention (no 1/eta^2).
        CHECK(s->weight == Rgb(0.8f, 0.9f, 1.0f));
      }
    }
  }

  TEST_CASE("dielectric totally reflects beyond the critical angle from inside") {
    const float eta = 1.5f;
    const auto glass = radiosity::make_dielectric(eta, Rgb(1.0f));
    const double critical_deg = std::asin(1.0 / eta) * 180.0 / kPi;  // 41.8 degrees
    Rng rng(37);
    for (int i = 1; i <= 20; ++i) {
      const double theta = critical_deg + (89.0 - critical_deg) * i / 20.0;
      glm::vec3 wo = dir_deg(theta, 2.0);
      wo.z = -wo.z;  // inside the glass
      CHECK(radiosity::fresnel_dielectric(wo.z, eta) == 1.0f);
      for (int n = 0; n < 50; ++n) {
        const auto s = glass->sample(wo, rng.next_vec2());
        REQUIRE(s);
        CHECK(s->wi == glm::vec3(-wo.x, -wo.y, wo.z));
        CHECK(s->weight == Rgb(1.0f));
        CHECK(s->pdf == 1.0f);
      }
    }
    // Just inside the critical angle some light still escapes.
    glm::vec3 wo = dir_deg(critical_deg - 1.0, 2.0);
    wo.z = -wo.z;
    CHECK(radiosity::fresnel_dielectric(wo.z, eta) < 1.0f);
    // From outside there is never total internal reflection.
    CHECK(radiosity::fresnel_dielectric(dir_deg(89.0, 0).z, eta) < 1.0f);
  }
}
