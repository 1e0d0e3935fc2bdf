// Shared helpers for the brdf tests: a deterministic RNG, direction helpers, numerical
// quadrature over the sphere and a chi-squared goodness-of-fit test for samplers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "radiosity/brdf.hpp"

namespace brdf_test {

constexpr double kPi = 3.14159265358979323846;

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fixed across platforms, good enough for tests.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next_u64() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 24 bits.
  float next_float() { return static_cast<float>(next_u64() >> 40) * 0x1.0p-24f; }
  glm::vec2 next_vec2() {
    const float a = next_float();
    return {a, next_float()};
  }
  /// Uniform direction on the upper hemisphere (z > 0).
  glm::vec3 upper_hemisphere() {
    const float z = std::max(1e-3f, 1.0f - next_float());
    const float phi = static_cast<float>(2.0 * kPi) * next_float();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }

 private:
  std::uint64_t state_;
};

/// Unit direction from a polar angle (degrees, from +z) and an azimuth (radians).
inline glm::vec3 dir_deg(double theta_deg, double phi) {
  const double t = theta_deg * kPi / 180.0;
  return glm::vec3(static_cast<float>(std::sin(t) * std::cos(phi)), static_cast<float>(std::sin(t) * std::sin(phi)),
                   static_cast<float>(std::cos(t)));
}

inline glm::vec3 dir_cos_phi(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return glm::vec3(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                   static_cast<float>(cos_theta));
}

inline glm::vec3 rotate_z(const glm::vec3& v, float angle) {
  const float c = std::cos(angle);
  const float s = std::sin(angle);
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

inline bool verbose() { return std::getenv("RADIOSITY_BRDF_VERBOSE") != nullptr; }

/// A named model for table-driven tests.
struct NamedBrdf {
  std::string name;
  std::shared_ptr<const radiosity::Brdf> brdf;
};

/// The non-delta analytic models, with moderate lobes, used by several tests.
inline std::vector<NamedBrdf> glossy_models() {
  using radiosity::Rgb;
  std::vector<NamedBrdf> m;
  m.push_back({"lambertian", radiosity::make_lambertian(Rgb(0.8f, 0.5f, 0.2f))});
  m.push_back({"phong n=20", radiosity::make_phong(Rgb(0.3f, 0.2f, 0.1f), Rgb(0.6f, 0.7f, 0.5f), 20.0f)});
  m.push_back({"phong n=0 specular only", radiosity::make_phong(Rgb(0.0f), Rgb(0.9f), 0.0f)});
  m.push_back({"blinn-phong n=60", radiosity::make_blinn_phong(Rgb(0.2f, 0.1f, 0.3f), Rgb(0.7f, 0.8f, 0.6f), 60.0f)});
  m.push_back({"ward 0.1 x 0.3", radiosity::make_ward(Rgb(0.2f), Rgb(0.6f, 0.5f, 0.7f), 0.1f, 0.3f)});
  m.push_back({"ward 0.2 isotropic", radiosity::make_ward(Rgb(0.1f), Rgb(0.8f), 0.2f, 0.2f)});
  m.push_back({"ggx 0.3", radiosity::make_microfacet(Rgb(0.9f, 0.6f, 0.3f), 0.3f, 0.3f)});
  m.push_back({"ggx 0.1 x 0.4", radiosity::make_microfacet(Rgb(0.95f), 0.1f, 0.4f)});
  m.push_back({"mix lambertian + ggx 0.2",
               radiosity::make_mix(radiosity::make_lambertian(Rgb(0.6f)),
                                   radiosity::make_microfacet(Rgb(0.04f, 0.05f, 0.06f), 0.2f, 0.2f), 0.5f)});
  return m;
}

/// Integral of f(wo, wi) cos(theta_i) over the upper hemisphere by the midpoint rule on a
/// uniform (theta, phi) grid; independent of the model's sampler.
inline glm::dvec3 quadrature_albedo(const radiosity::Brdf& brdf, const glm::vec3& wo, int n_theta = 256,
                                    int n_phi = 512) {
  glm::dvec3 sum(0.0);
  const double dt = 0.5 * kPi / n_theta;
  const double dp = 2.0 * kPi / n_phi;
  for (int i = 0; i < n_theta; ++i) {
    const double t = (i + 0.5) * dt;
    const double st = std::sin(t);
    const double ct = std::cos(t);
    for (int j = 0; j < n_phi; ++j) {
      const double p = (j + 0.5) * dp;
      const glm::vec3 wi(static_cast<float>(st * std::cos(p)), static_cast<float>(st * std::sin(p)),
                         static_cast<float>(ct));
      const glm::vec3 f = brdf.eval(wo, wi);
      sum += glm::dvec3(f) * (ct * st * dt * dp);
    }
  }
  return sum;
}

/// Integral of pdf(wo, .) over the whole sphere by the midpoint rule on a uniform (theta, phi)
/// grid; independent of the binning used by sampler_chi2().
inline double quadrature_pdf_integral(const radiosity::Brdf& brdf, const glm::vec3& wo, int n_theta = 384,
                                      int n_phi = 384) {
  double sum = 0.0;
  const double dt = kPi / n_theta;
  const double dp = 2.0 * kPi / n_phi;
  for (int i = 0; i < n_theta; ++i) {
    const double t = (i + 0.5) * dt;
    const double st = std::sin(t);
    const double ct = std::cos(t);
    for (int j = 0; j < n_phi; ++j) {
      const double p = (j + 0.5) * dp;
      const glm::vec3 wi(static_cast<float>(st * std::cos(p)), static_cast<float>(st * std::sin(p)),
                         static_cast<float>(ct));
      sum += static_cast<double>(brdf.pdf(wo, wi)) * st * dt * dp;
    }
  }
  return sum;
}

/// Regularised upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a), by its power
/// series for x < a + 1 and by Legendre's continued fraction (modified Lentz) otherwise.
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefactor = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(log_prefactor));
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefactor) * h;
}

/// Result of sampler_chi2().
struct Chi2Result {
  double chi2 = 0.0;
  int dof = 0;
  double p_value = 0.0;
  double pdf_integral = 0.0;       ///< quadrature of pdf() over the sphere
  double success_fraction = 0.0;   ///< fraction of sample() calls that returned a direction
  double max_pdf_rel_error = 0.0;  ///< max |sample.pdf - pdf(wi)| / pdf(wi) over the samples
  glm::dvec3 mean_weight{0.0};     ///< E[weight], nullopt counted as 0
};

/// Chi-squared goodness-of-fit test of brdf.sample(wo, .) against brdf.pdf(wo, .).
/// The sphere is binned uniformly in (cos theta, phi), so that bins have equal solid angle; the
/// expected count of each bin is n_samples times the integral of pdf() over it (composite Simpson
/// rule, `sub` x `sub` intervals per bin); failed samples form one more bin with expected count
/// n_samples (1 - integral). Bins with expected count < 5 are pooled (Cochran's rule), and the
/// p-value is Q(dof / 2, chi2 / 2).
inline Chi2Result sampler_chi2(const radiosity::Brdf& brdf, const glm::vec3& wo, int n_samples, std::uint64_t seed,
                               int z_bins = 32, int phi_bins = 32, int sub = 16) {
  Chi2Result r;
  const int n_bins = z_bins * phi_bins;
  std::vector<double> observed(static_cast<std::size_t>(n_bins) + 1, 0.0);
  std::vector<double> expected(static_cast<std::size_t>(n_bins) + 1, 0.0);
  const double dz = 2.0 / z_bins;
  const double dphi = 2.0 * kPi / phi_bins;

  // Expected frequencies: Simpson's rule over each bin, in (z, phi) where d omega = dz dphi.
  for (int iz = 0; iz < z_bins; ++iz) {
    for (int ip = 0; ip < phi_bins; ++ip) {
      double integral = 0.0;
      const double hz = dz / sub;
      const double hp = dphi / sub;
      for (int a = 0; a <= sub; ++a) {
        const double wz = (a == 0 || a == sub) ? 1.0 : (a % 2 == 1 ? 4.0 : 2.0);
        // Bin edges are evaluated just inside the bin: pdf() jumps at the horizon (z = 0, a bin
        // edge), and the one-sided limit is what the bin integrates.
        const double z = -1.0 + iz * dz + (a == 0 ? 1e-6 * hz : (a == sub ? (sub - 1e-6) * hz : a * hz));
        for (int b = 0; b <= sub; ++b) {
          const double wp = (b == 0 || b == sub) ? 1.0 : (b % 2 == 1 ? 4.0 : 2.0);
          const double phi = ip * dphi + b * hp;
          integral += wz * wp * static_cast<double>(brdf.pdf(wo, dir_cos_phi(z, phi)));
        }
      }
      integral *= hz * hp / 9.0;
      expected[static_cast<std::size_t>(iz * phi_bins + ip)] = integral;
      r.pdf_integral += integral;
    }
  }

  // Observed frequencies, and per-sample consistency of pdf and weight.
  Rng rng(seed);
  int successes = 0;
  for (int n = 0; n < n_samples; ++n) {
    const std::optional<radiosity::BrdfSample> s = brdf.sample(wo, rng.next_vec2());
    if (!s) {
      observed[static_cast<std::size_t>(n_bins)] += 1.0;
      continue;
    }
    ++successes;
    r.mean_weight += glm::dvec3(s->weight);
    const double z = std::min(std::max(static_cast<double>(s->wi.z), -1.0), 1.0);
    double phi = std::atan2(static_cast<double>(s->wi.y), static_cast<double>(s->wi.x));
    if (phi < 0.0) phi += 2.0 * kPi;
    const int iz = std::min(z_bins - 1, static_cast<int>((z + 1.0) / dz));
    const int ip = std::min(phi_bins - 1, static_cast<int>(phi / dphi));
    observed[static_cast<std::size_t>(iz * phi_bins + ip)] += 1.0;

    const double p = brdf.pdf(wo, s->wi);
    r.max_pdf_rel_error = std::max(r.max_pdf_rel_error, std::abs(s->pdf - p) / std::max(p, 1e-12));
  }
  r.mean_weight /= static_cast<double>(n_samples);
  r.success_fraction = static_cast<double>(successes) / n_samples;
  for (int i = 0; i < n_bins; ++i) expected[static_cast<std::size_t>(i)] *= n_samples;
  expected[static_cast<std::size_t>(n_bins)] = std::max(0.0, 1.0 - r.pdf_integral) * n_samples;

  // Pool the bins with the smallest expectations (ascending) until the pool expects >= 5
  // (Cochran's rule); every remaining bin then expects >= 5 too.
  std::vector<std::pair<double, double>> cells;  // (expected, observed)
  for (std::size_t i = 0; i < expected.size(); ++i) cells.emplace_back(expected[i], observed[i]);
  std::sort(cells.begin(), cells.end());
  double pool_e = 0.0;
  double pool_o = 0.0;
  int used = 0;
  for (const auto& c : cells) {
    if (pool_e < 5.0) {
      pool_e += c.first;
      pool_o += c.second;
      continue;
    }
    const double d = c.second - c.first;
    r.chi2 += d * d / c.first;
    ++used;
  }
  // A pool that expects (almost) nothing but saw samples makes chi2 huge: samples where pdf = 0.
  const double d = pool_o - pool_e;
  r.chi2 += d * d / std::max(pool_e, 1e-12);
  ++used;
  r.dof = used - 1;
  r.p_value = r.dof > 0 ? gamma_q(0.5 * r.dof, 0.5 * r.chi2) : 1.0;
  return r;
}

}  // namespace brdf_test
