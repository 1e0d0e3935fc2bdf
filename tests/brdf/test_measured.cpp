// Measured (MERL layout) BRDFs, on small synthetic files written to RADIOSITY_TEST_TMP.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "brdf/brdf_test_util.hpp"
#include "radiosity/brdf.hpp"

using namespace brdf_test;
using radiosity::ErrorCode;
using radiosity::Rgb;

namespace {

constexpr int kTh = 90;
constexpr int kTd = 90;
constexpr int kPd = 180;
constexpr double kScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

/// Grid angles of MERL index (ih, id, ip), radians.
double theta_half_at(int ih) { return (ih / 90.0) * (ih / 90.0) * 0.5 * kPi; }

/// Appends `count` values of type T as little-endian bytes.
template <typename T>
void put_le(std::vector<unsigned char>& out, const T* values, std::size_t count) {
  const std::size_t start = out.size();
  out.resize(start + count * sizeof(T));
  std::memcpy(out.data() + start, values, count * sizeof(T));
  const std::uint16_t probe = 1;
  unsigned char low = 0;
  std::memcpy(&low, &probe, 1);
  if (low != 1) {  // big-endian host: swap each value
    for (std::size_t v = 0; v < count; ++v) {
      unsigned char* b = out.data() + start + v * sizeof(T);
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
  }
}

/// Writes a MERL-layout file. `value(c, ih, id, ip)` is the stored (unscaled) entry;
/// `data_fraction` < 1 truncates the data.
std::filesystem::path write_merl(const std::string& name, const std::function<double(int, int, int, int)>& value,
                                 const std::int32_t dims[3] = nullptr, double data_fraction = 1.0) {
  const std::filesystem::path path = std::filesystem::path(RADIOSITY_TEST_TMP) / name;
  std::filesystem::create_directories(path.parent_path());
  const std::int32_t standard[3] = {kTh, kTd, kPd};
  if (!dims) dims = standard;
  const std::size_t n = static_cast<std::size_t>(kTh) * kTd * kPd;
  std::vector<double> data(3 * n);
  std::size_t i = 0;
  for (int c = 0; c < 3; ++c) {
    for (int ih = 0; ih < kTh; ++ih) {
      for (int id = 0; id < kTd; ++id) {
        for (int ip = 0; ip < kPd; ++ip) data[i++] = value(c, ih, id, ip);
      }
    }
  }
  std::vector<unsigned char> bytes;
  bytes.reserve(12 + data.size() * 8);
  put_le(bytes, dims, 3);
  put_le(bytes, data.data(), data.size());
  const auto keep = static_cast<std::size_t>(12 + (bytes.size() - 12) * data_fraction);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(keep));
  REQUIRE(out.good());
  return path;
}

/// (wo, wi) with the given Rusinkiewicz angles: the difference vector is wi in the half frame.
void from_half_diff(double theta_h, double phi_h, double theta_d, double phi_d, glm::vec3& wo, glm::vec3& wi) {
  auto to_world = [&](double x, double y, double z) {
    // Rotate by theta_h about y, then by phi_h about z.
    const double x1 = x * std::cos(theta_h) + z * std::sin(theta_h);
    const double z1 = -x * std::sin(theta_h) + z * std::cos(theta_h);
    return glm::vec3(static_cast<float>(x1 * std::cos(phi_h) - y * std::sin(phi_h)),
                     static_cast<float>(x1 * std::sin(phi_h) + y * std::cos(phi_h)), static_cast<float>(z1));
  };
  const double dx = std::sin(theta_d) * std::cos(phi_d);
  const double dy = std::sin(theta_d) * std::sin(phi_d);
  const double dz = std::cos(theta_d);
  wi = to_world(dx, dy, dz);
  wo = to_world(-dx, -dy, dz);
}

/// Removes the file when the test case ends, pass or fail.
struct TempFile {
  std::filesystem::path path;
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

template <typename Load>
void check_load_error(Load load, ErrorCode code, const std::string& file, const std::string& words) {
  try {
    load();
    FAIL("no exception");
  } catch (const radiosity::Error& e) {
    INFO("message: ", e.what());
    CHECK(e.code() == code);
    CHECK(std::string(e.what()).find(file) != std::string::npos);
    CHECK(std::string(e.what()).find(words) != std::string::npos);
  }
}

}  // namespace

TEST_SUITE("brdf") {
  TEST_CASE("measured file encoding a lambertian evaluates to reflectance over pi") {
    // Stored value rho/pi / scale in every cell, except green with theta_diff index >= 80, which
    // holds -1 ("no data") and must read as 0.
    const Rgb rho(0.7f, 0.5f, 0.3f);
    TempFile file{write_merl("brdf_merl_lambertian.binary", [&](int c, int, int id, int) {
      if (c == 1 && id >= 80) return -1.0;
      return static_cast<double>(rho[c]) / kPi / kScale[c];
    })};
    const auto b = radiosity::load_measured(file.path);
    Rng rng(41);
    int checked = 0;
    for (int n = 0; n < 2000; ++n) {
      const glm::vec3 wo = rng.upper_hemisphere();
      const glm::vec3 wi = rng.upper_hemisphere();
      const float theta_d = std::acos(glm::dot(wi, glm::normalize(wo + wi)));
      if (theta_d > 78.0f / 90.0f * 0.5f * 3.14159265f) continue;  // away from the no-data band
      const Rgb f = b->eval(wo, wi);
      for (int k = 0; k < 3; ++k) REQUIRE(f[k] == doctest::Approx(rho[k] / 3.14159265f).epsilon(1e-5));
      ++checked;
    }
    CHECK(checked > 1000);
    // Deep in the no-data band (theta_diff near 85 degrees): green reads 0.
    glm::vec3 wo;
    glm::vec3 wi;
    from_half_diff(0.05, 0.0, 85.0 / 180.0 * kPi, 1.0, wo, wi);
    REQUIRE(wo.z > 0.0f);
    REQUIRE(wi.z > 0.0f);
    CHECK(b->eval(wo, wi).y == 0.0f);
    CHECK(b->eval(wo, wi).x == doctest::Approx(rho.x / 3.14159265f).epsilon(1e-5));
    // Below the horizon nothing is reflected.
    CHECK(b->eval(dir_deg(30, 0), dir_deg(100, 0)) == Rgb(0.0f));
    // Albedo: the no-data band costs green a little; red and blue match rho within 0.5 %.
    const Rgb a = b->albedo(dir_deg(20, 0.5));
    CHECK(a.x == doctest::Approx(rho.x).epsilon(0.005));
    CHECK(a.z == doctest::Approx(rho.z).epsilon(0.005));
    CHECK(a.y < rho.y);
  }

  TEST_CASE("measured lookup follows the MERL index mapping with trilinear interpolation") {
    // Stored entries equal their own indices (theta_half, theta_diff, phi_diff) / scale, so eval
    // returns the continuous MERL index of the query wherever trilinear interpolation of a linear
    // function is exact: theta_half index = sqrt(theta_h / (pi/2)) * 90, theta_diff index =
    // theta_d / (pi/2) * 90, phi_diff index = phi_d / pi * 180. Tolerance 5e-3 index units.
    TempFile file{write_merl("brdf_merl_index.binary", [](int c, int ih, int id, int ip) {
      const int idx = c == 0 ? ih : (c == 1 ? id : ip);
      return idx / kScale[c];
    })};
    const auto b = radiosity::load_measured(file.path);
    Rng rng(43);
    int checked = 0;
    for (int n = 0; n < 3000; ++n) {
      const double th = 0.05 + 1.35 * rng.next_float();
      const double td = 0.05 + 1.35 * rng.next_float();
      const double pd = 0.05 + 3.0 * rng.next_float();  // [0.05, 3.05]: clear of the wrap at pi
      const double ph = 6.2831853 * rng.next_float();
      glm::vec3 wo;
      glm::vec3 wi;
      from_half_diff(th, ph, td, pd, wo, wi);
      if (wo.z < 0.05f || wi.z < 0.05f) continue;
      const Rgb f = b->eval(wo, wi);
      INFO("theta_h=", th, " theta_d=", td, " phi_d=", pd);
      REQUIRE(f.x == doctest::Approx(std::sqrt(th / (0.5 * kPi)) * 90.0).epsilon(5e-3 / 45.0));
      REQUIRE(std::abs(f.y - td / (0.5 * kPi) * 90.0) < 5e-3);
      REQUIRE(std::abs(f.z - pd / kPi * 180.0) < 5e-3);
      // Reciprocity: swapping the directions turns phi_d into phi_d + pi, folded back.
      const Rgb g = b->eval(wi, wo);
      REQUIRE(std::abs(g.z - f.z) < 5e-3);
      ++checked;
    }
    CHECK(checked > 500);
    // Beyond the last theta_half row the lookup clamps to it.
    glm::vec3 wo;
    glm::vec3 wi;
    from_half_diff(89.5 / 180.0 * kPi, 0.0, 0.0, 0.0, wo, wi);
    CHECK(b->eval(wo, wi).x == doctest::Approx(89.0f).epsilon(1e-4));
  }

  TEST_CASE("measured glossy data is reciprocal - isotropic - and its albedo and sampler agree") {
    // f = kd / pi + ks exp(-(theta_h / 0.3)^2) sampled on the MERL grid.
    const Rgb kd(0.3f, 0.2f, 0.1f);
    const float ks = 0.4f;
    TempFile file{write_merl("brdf_merl_glossy.binary", [&](int c, int ih, int, int) {
      const double t = theta_half_at(ih) / 0.3;
      return (kd[c] / kPi + ks * std::exp(-t * t)) / kScale[c];
    })};
    const auto b = radiosity::load_measured(file.path);
    Rng rng(47);
    for (int n = 0; n < 1000; ++n) {
      const glm::vec3 wo = rng.upper_hemisphere();
      const glm::vec3 wi = rng.upper_hemisphere();
      const float angle = 6.2831853f * rng.next_float();
      const Rgb f = b->eval(wo, wi);
      const Rgb g = b->eval(wi, wo);
      const Rgb r = b->eval(rotate_z(wo, angle), rotate_z(wi, angle));
      for (int k = 0; k < 3; ++k) {
        REQUIRE(f[k] == doctest::Approx(g[k]).epsilon(1e-4));
        REQUIRE(f[k] == doctest::Approx(r[k]).epsilon(1e-4));
      }
    }
    // albedo() (half-vector quadrature) vs an independent (theta, phi) quadrature (192 x 384,
    // error < 1e-3 for this lobe): 0.5 %.
    for (const double theta : {0.0, 40.0, 75.0}) {
      const glm::vec3 wo = dir_deg(theta, 0.3);
      const glm::dvec3 q = quadrature_albedo(*b, wo, 192, 384);
      const Rgb a = b->albedo(wo);
      INFO("theta_o=", theta);
      for (int k = 0; k < 3; ++k) CHECK(a[k] == doctest::Approx(q[k]).epsilon(0.005));
      CHECK(a.x <= 1.0f);
      // Cosine sampler: chi-squared at 1 % significance (Sidak-corrected over the 3 views), and
      // E[weight] = albedo within 2 % (5e4 samples; relative standard error of the mean < 0.5 %).
      const Chi2Result r = sampler_chi2(*b, wo, 50000, 53 + static_cast<std::uint64_t>(theta), 32, 32, 8);
      if (verbose()) MESSAGE("measured wo theta=", theta, " chi2 p=", r.p_value, " albedo=", a.x, " quad=", q.x);
      CHECK(r.p_value > 1.0 - std::pow(0.99, 1.0 / 3.0));
      CHECK(r.pdf_integral == doctest::Approx(1.0).epsilon(1e-4));
      CHECK(r.max_pdf_rel_error < 1e-3);
      for (int k = 0; k < 3; ++k) CHECK(r.mean_weight[k] == doctest::Approx(a[k]).epsilon(0.02));
    }
  }

  TEST_CASE("load_measured rejects missing - short - wrong-dimension and truncated files naming the file") {
    const std::filesystem::path dir(RADIOSITY_TEST_TMP);
    std::filesystem::create_directories(dir);

    const std::filesystem::path missing = dir / "brdf_merl_does_not_exist.binary";
    check_load_error([&] { return radiosity::load_measured(missing); }, ErrorCode::file_not_found,
                     missing.filename().string(), "cannot open");
    check_load_error([&] { return radiosity::load_measured(dir); }, ErrorCode::file_not_found, dir.string(),
                     "directory");

    TempFile short_file{dir / "brdf_merl_short.binary"};
    {
      std::ofstream out(short_file.path, std::ios::binary);
      const std::int32_t two[2] = {90, 90};
      out.write(reinterpret_cast<const char*>(two), sizeof(two));
    }
    check_load_error([&] { return radiosity::load_measured(short_file.path); }, ErrorCode::parse_error,
                     "brdf_merl_short.binary", "header");

    const std::int32_t wrong[3] = {90, 90, 90};
    TempFile bad_dims{write_merl("brdf_merl_bad_dims.binary", [](int, int, int, int) { return 1.0; }, wrong)};
    check_load_error([&] { return radiosity::load_measured(bad_dims.path); }, ErrorCode::parse_error,
                     "brdf_merl_bad_dims.binary", "90 x 90 x 90");

    TempFile truncated{write_merl(
        "brdf_merl_truncated.binary", [](int, int, int, int) { return 1.0; }, nullptr, 0.6)};
    check_load_error([&] { return radiosity::load_measured(truncated.path); }, ErrorCode::parse_error,
                     "brdf_merl_truncated.binary", "truncated");
  }
}
