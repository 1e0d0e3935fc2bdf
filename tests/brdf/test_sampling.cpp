// Statistical tests of the BRDF samplers: chi-squared goodness of fit against pdf(), pdf()
// normalisation, agreement of the reported pdf and weight, and E[weight] = albedo().
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <doctest/doctest.h>

#include "brdf/brdf_test_util.hpp"
#include "radiosity/brdf.hpp"

using namespace brdf_test;
using radiosity::Rgb;

namespace {

/// Viewing directions for the sampler tests: near normal, 45 degrees, grazing.
std::vector<glm::vec3> sampler_views() { return {dir_deg(10.0, 0.3), dir_deg(45.0, 1.9), dir_deg(80.0, 4.0)}; }

constexpr int kSamples = 100000;

/// A deliberately broken model for testing the test: pdf() claims cosine weighting, but
/// sample() draws cos theta = (1 - u)^0.45 instead of (1 - u)^0.5.
class SkewedSampler final : public radiosity::Brdf {
 public:
  Rgb eval(const glm::vec3&, const glm::vec3& wi) const override {
    return wi.z > 0.0f ? Rgb(0.5f / 3.14159265f) : Rgb(0.0f);
  }
  float pdf(const glm::vec3&, const glm::vec3& wi) const override {
    return wi.z > 0.0f ? wi.z / 3.14159265f : 0.0f;
  }
  std::optional<radiosity::BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u) const override {
    const float z = std::pow(1.0f - u.x, 0.45f);
    const glm::vec3 wi = dir_cos_phi(z, 6.2831853 * u.y);
    if (!(wi.z > 0.0f)) return std::nullopt;
    return radiosity::BrdfSample{wi, eval(wo, wi) * (wi.z / pdf(wo, wi)), pdf(wo, wi), false};
  }
};

}  // namespace

TEST_SUITE("brdf") {
  TEST_CASE("every sampler passes a chi-squared test against its pdf") {
    // 32 x 32 equal-solid-angle bins in (cos theta, phi) over the sphere plus one bin for failed
    // samples, 1e5 samples per (model, wo); expected counts by 12 x 12 Simpson per bin, bins
    // expecting < 5 pooled. Null hypothesis: sample() draws from pdf(). Overall significance 1 %
    // with the Sidak correction over all runs (per run: 1 - 0.99^(1/27) = 3.7e-4), so a correct
    // sampler fails this test case with probability 1 % (fixed seeds make the outcome repeatable).
    const auto models = glossy_models();
    const auto views = sampler_views();
    const int runs = static_cast<int>(models.size() * views.size());
    const double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / runs);
    std::uint64_t seed = 1;
    for (const auto& m : models) {
      for (const glm::vec3& wo : views) {
        const Chi2Result r = sampler_chi2(*m.brdf, wo, kSamples, seed++, 32, 32, 12);
        INFO(m.name, " wo.z=", wo.z, " chi2=", r.chi2, " dof=", r.dof, " p=", r.p_value);
        if (verbose()) MESSAGE(m.name, " wo.z=", wo.z, " chi2=", r.chi2, " dof=", r.dof, " p=", r.p_value);
        CHECK(r.p_value > alpha);
      }
    }
  }

  TEST_CASE("chi-squared machinery has the right p-values and rejects a skewed sampler") {
    // Upper 5 % points of the chi-squared distribution (standard tables), to 1e-3.
    CHECK(gamma_q(0.5 * 1, 0.5 * 3.841459) == doctest::Approx(0.05).epsilon(1e-3));
    CHECK(gamma_q(0.5 * 10, 0.5 * 18.307038) == doctest::Approx(0.05).epsilon(1e-3));
    CHECK(gamma_q(0.5 * 100, 0.5 * 124.342113) == doctest::Approx(0.05).epsilon(1e-3));
    CHECK(gamma_q(0.5 * 500, 0.5 * 553.126954) == doctest::Approx(0.05).epsilon(1e-3));
    // A sampler 10 % off in its exponent must be rejected decisively at 1e5 samples.
    const SkewedSampler skewed;
    const Chi2Result r = sampler_chi2(skewed, dir_deg(30.0, 0.0), kSamples, 77);
    INFO("chi2=", r.chi2, " dof=", r.dof, " p=", r.p_value);
    CHECK(r.p_value < 1e-6);
  }

  TEST_CASE("pdf integrates to the probability that sample returns a direction") {
    // Midpoint quadrature of pdf() over the sphere (384 x 384 in theta, phi; error < 1e-3 for
    // these lobes) vs the success fraction of 20000 samples. Tolerance: 4 binomial standard
    // deviations plus 2e-3. The Lambertian sampler never fails, so its pdf must integrate to 1
    // within 1e-3.
    std::uint64_t seed = 1000;
    constexpr int kN = 20000;
    for (const auto& m : glossy_models()) {
      for (const glm::vec3& wo : sampler_views()) {
        const double integral = quadrature_pdf_integral(*m.brdf, wo);
        Rng rng(seed++);
        int ok = 0;
        for (int n = 0; n < kN; ++n) ok += m.brdf->sample(wo, rng.next_vec2()) ? 1 : 0;
        const double p = static_cast<double>(ok) / kN;
        const double sigma = std::sqrt(std::max(p * (1.0 - p), 1e-12) / kN);
        INFO(m.name, " wo.z=", wo.z, " integral=", integral, " success=", p);
        if (verbose()) MESSAGE(m.name, " wo.z=", wo.z, " integral pdf=", integral, " success=", p);
        CHECK(std::abs(integral - p) < 4.0 * sigma + 2e-3);
        CHECK(integral <= 1.0 + 1e-3);
        if (m.name == "lambertian") CHECK(integral == doctest::Approx(1.0).epsilon(1e-3));
      }
    }
  }

  TEST_CASE("sample reports the same pdf as pdf() and weight = f cos / pdf") {
    // Every returned sample (20000 per model and view): unit wi above the horizon, non-delta,
    // and pdf and weight agree with pdf() and eval() to a relative 1e-3 (float arithmetic along
    // different paths).
    std::uint64_t seed = 2000;
    for (const auto& m : glossy_models()) {
      for (const glm::vec3& wo : sampler_views()) {
        Rng rng(seed++);
        double worst_pdf = 0.0;
        double worst_weight = 0.0;
        double worst_length = 0.0;
        int bad = 0;
        for (int n = 0; n < 20000; ++n) {
          const auto s = m.brdf->sample(wo, rng.next_vec2());
          if (!s) continue;
          if (s->delta || !(s->wi.z > 0.0f)) ++bad;
          worst_length = std::max(worst_length, static_cast<double>(std::abs(glm::length(s->wi) - 1.0f)));
          const double p = m.brdf->pdf(wo, s->wi);
          worst_pdf = std::max(worst_pdf, std::abs(s->pdf - p) / p);
          const Rgb expect = m.brdf->eval(wo, s->wi) * (s->wi.z / static_cast<float>(p));
          for (int k = 0; k < 3; ++k) {
            worst_weight = std::max(worst_weight, std::abs(static_cast<double>(s->weight[k] - expect[k])) /
                                                      (std::abs(static_cast<double>(expect[k])) + 1e-6));
          }
        }
        INFO(m.name, " wo.z=", wo.z);
        CHECK(bad == 0);
        CHECK(worst_length < 1e-4);
        CHECK(worst_pdf < 1e-3);
        CHECK(worst_weight < 1e-3);
      }
    }
  }

  TEST_CASE("mean sample weight equals albedo within 2 percent") {
    // 5e4 independent samples (fixed seed) per (model, wo) vs the deterministic albedo(); the
    // relative standard error of the mean is < 0.45 % for these models, so 2 % is > 4 sigma.
    std::uint64_t seed = 3000;
    double worst = 0.0;
    for (const auto& m : glossy_models()) {
      for (const glm::vec3& wo : sampler_views()) {
        Rng rng(seed++);
        glm::dvec3 sum(0.0);
        constexpr int kN = 50000;
        for (int n = 0; n < kN; ++n) {
          const auto s = m.brdf->sample(wo, rng.next_vec2());
          if (s) sum += glm::dvec3(s->weight);
        }
        const glm::dvec3 mean = sum / static_cast<double>(kN);
        const Rgb a = m.brdf->albedo(wo);
        for (int k = 0; k < 3; ++k) {
          const double rel = std::abs(mean[k] - a[k]) / a[k];
          worst = std::max(worst, rel);
          INFO(m.name, " wo.z=", wo.z, " channel ", k, " mean weight=", mean[k], " albedo=", a[k]);
          CHECK(rel < 0.02);
        }
      }
    }
    if (verbose()) MESSAGE("worst relative difference of mean weight and albedo: ", worst);
  }
}
