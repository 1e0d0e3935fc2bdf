// Isotropic measured BRDFs in the MERL binary layout.
//
// Based on:
//   Matusik, W., Pfister, H., Brand, M. & McMillan, L. (2003). A data-driven reflectance model.
//     ACM Transactions on Graphics (Proc. SIGGRAPH 2003) 22(3), 759-769. (the MERL database, its
//     file layout, per-channel scale factors and the non-linear theta_half indexing)
//   Rusinkiewicz, S. (1998). A new change of variables for efficient BRDF representation.
//     Proc. Eurographics Rendering Workshop 1998, 11-22. (half/difference angles)

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "brdf/brdf_util.hpp"
#include "radiosity/brdf.hpp"

namespace radiosity {
inline namespace v1 {

namespace db = detail::brdf;

namespace {

constexpr int kThetaHalfRes = 90;
constexpr int kThetaDiffRes = 90;
constexpr int kPhiDiffRes = 180;
constexpr std::size_t kEntries = static_cast<std::size_t>(kThetaHalfRes) * kThetaDiffRes * kPhiDiffRes;
/// MERL's per-channel scale from stored values to BRDF values in 1/sr.
constexpr double kScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

/// Half/difference angles of Rusinkiewicz (1998) for the pair (wi, wo), isotropic (phi_half
/// dropped). phi_diff is folded into [0, pi): reciprocity maps phi_diff to phi_diff + pi.
struct HalfDiff {
  float theta_half;
  float theta_diff;
  float phi_diff;
};

HalfDiff to_half_diff(const glm::vec3& wo, const glm::vec3& wi) {
  const glm::vec3 h = glm::normalize(wo + wi);
  const float theta_h = std::acos(std::min(std::max(h.z, -1.0f), 1.0f));
  const float phi_h = std::atan2(h.y, h.x);
  // Difference vector: wi seen from a frame whose z axis is h, i.e. wi rotated by -phi_h about z,
  // then by -theta_h about y (Rusinkiewicz 1998, sec. 3).
  const float cp = std::cos(phi_h);
  const float sp = std::sin(phi_h);
  const glm::vec3 a(wi.x * cp + wi.y * sp, -wi.x * sp + wi.y * cp, wi.z);
  const float ct = std::cos(theta_h);
  const float st = std::sin(theta_h);
  const glm::vec3 d(a.x * ct - a.z * st, a.y, a.x * st + a.z * ct);
  HalfDiff hd{};
  hd.theta_half = theta_h;
  hd.theta_diff = std::acos(std::min(std::max(d.z, -1.0f), 1.0f));
  float phi_d = std::atan2(d.y, d.x);
  if (phi_d < 0.0f) phi_d += db::kPi;
  hd.phi_diff = phi_d;
  return hd;
}

class MeasuredBrdf final : public Brdf {
 public:
  explicit MeasuredBrdf(std::vector<float> rgb) : rgb_(std::move(rgb)) {}

  Rgb eval(const glm::vec3& wo, const glm::vec3& wi) const override {
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return Rgb(0.0f);
    const HalfDiff hd = to_half_diff(wo, wi);
    // Continuous grid coordinates: grid point i holds the sample at theta_half = (i / 90)^2 pi/2,
    // theta_diff = i / 90 pi/2 and phi_diff = i / 180 pi (Matusik et al. 2003).
    const float x_h = std::sqrt(std::max(0.0f, hd.theta_half) / (0.5f * db::kPi)) * kThetaHalfRes;
    const float x_d = hd.theta_diff / (0.5f * db::kPi) * kThetaDiffRes;
    const float x_p = hd.phi_diff / db::kPi * kPhiDiffRes;
    return trilinear(x_h, x_d, x_p);
  }

  float pdf(const glm::vec3& wo, const glm::vec3& wi) const override { return db::cosine_lobe_pdf(wo, wi); }

  std::optional<BrdfSample> sample(const glm::vec3& wo, const glm::vec2& u) const override {
    const std::optional<glm::vec3> wi = db::sample_cosine_lobe(wo, u);
    if (!wi) return std::nullopt;
    // f cos / (cos / pi) = pi f.
    return BrdfSample{*wi, eval(wo, *wi) * db::kPi, db::cosine_hemisphere_pdf(*wi), false};
  }

  Rgb albedo(const glm::vec3& wo) const override {
    if (!(wo.z > 0.0f)) return Rgb(0.0f);
    // Measured data can be much more specular than the cosine sampler, so integrate over the
    // half vector instead, on a midpoint grid in (s, phi_h) with theta_h = s^2 pi/2 (the data's
    // own non-linear spacing, two cells per data row near the specular peak).
    //   albedo = int f(wo, wi) cos_i d omega_i,  d omega_i = 4 (wo.h) d omega_h,
    //   d omega_h = sin theta_h d theta_h d phi_h,  d theta_h = pi s ds.
    constexpr int kS = 2 * kThetaHalfRes;
    constexpr int kPhi = 360;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < kS; ++i) {
      const double s = (i + 0.5) / kS;
      const double theta_h = s * s * 0.5 * 3.14159265358979323846;
      const double dtheta = 3.14159265358979323846 * s / kS;
      for (int j = 0; j < kPhi; ++j) {
        const double phi_h = (j + 0.5) / kPhi * 2.0 * 3.14159265358979323846;
        const glm::vec3 h(static_cast<float>(std::sin(theta_h) * std::cos(phi_h)),
                          static_cast<float>(std::sin(theta_h) * std::sin(phi_h)),
                          static_cast<float>(std::cos(theta_h)));
        const float wo_h = glm::dot(wo, h);
        if (!(wo_h > 0.0f)) continue;
        const glm::vec3 wi = db::reflect_about(wo, h);
        if (!(wi.z > 0.0f)) continue;
        const Rgb f = eval(wo, wi);
        const double w = static_cast<double>(wi.z) * 4.0 * wo_h * std::sin(theta_h) * dtheta *
                         (2.0 * 3.14159265358979323846 / kPhi);
        for (int k = 0; k < 3; ++k) sum[k] += w * static_cast<double>(f[k]);
      }
    }
    return Rgb(static_cast<float>(sum[0]), static_cast<float>(sum[1]), static_cast<float>(sum[2]));
  }

 private:
  Rgb at(int ih, int id, int ip) const {
    const std::size_t idx =
        3 * ((static_cast<std::size_t>(ih) * kThetaDiffRes + static_cast<std::size_t>(id)) * kPhiDiffRes +
             static_cast<std::size_t>(ip));
    return Rgb(rgb_[idx], rgb_[idx + 1], rgb_[idx + 2]);
  }

  /// Trilinear interpolation on the index grid: clamped in both thetas, periodic in phi_diff.
  Rgb trilinear(float x_h, float x_d, float x_p) const {
    auto split_clamped = [](float x, int res, int& i0, int& i1, float& t) {
      x = std::min(std::max(x, 0.0f), static_cast<float>(res - 1));
      i0 = std::min(static_cast<int>(x), res - 2);
      i1 = i0 + 1;
      t = x - static_cast<float>(i0);
    };
    int h0 = 0, h1 = 0, d0 = 0, d1 = 0;
    float th = 0.0f, td = 0.0f;
    split_clamped(x_h, kThetaHalfRes, h0, h1, th);
    split_clamped(x_d, kThetaDiffRes, d0, d1, td);
    float xp = std::fmod(x_p, static_cast<float>(kPhiDiffRes));
    if (xp < 0.0f) xp += kPhiDiffRes;
    int p0 = std::min(static_cast<int>(xp), kPhiDiffRes - 1);
    const float tp = std::min(std::max(xp - static_cast<float>(p0), 0.0f), 1.0f);
    const int p1 = (p0 + 1) % kPhiDiffRes;

    auto lerp = [](const Rgb& a, const Rgb& b, float t) { return a + (b - a) * t; };
    const Rgb c00 = lerp(at(h0, d0, p0), at(h0, d0, p1), tp);
    const Rgb c01 = lerp(at(h0, d1, p0), at(h0, d1, p1), tp);
    const Rgb c10 = lerp(at(h1, d0, p0), at(h1, d0, p1), tp);
    const Rgb c11 = lerp(at(h1, d1, p0), at(h1, d1, p1), tp);
    return lerp(lerp(c00, c01, td), lerp(c10, c11, td), th);
  }

  std::vector<float> rgb_;  ///< interleaved R, G, B per entry, already scaled to 1/sr
};

bool host_is_little_endian() {
  const std::uint32_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <typename T>
T from_little_endian(const unsigned char* bytes) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, bytes, sizeof(T));
  if (!host_is_little_endian()) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

}  // namespace

std::unique_ptr<Brdf> load_measured(const std::filesystem::path& merl_binary) {
  const std::string name = "load_measured: '" + merl_binary.string() + "'";
  std::error_code ec;
  if (std::filesystem::is_directory(merl_binary, ec)) {
    throw Error(ErrorCode::file_not_found, name + ": is a directory, not a MERL file");
  }
  std::ifstream in(merl_binary, std::ios::binary);
  if (!in) throw Error(ErrorCode::file_not_found, name + ": cannot open file");

  unsigned char header[12];
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  if (in.gcount() != static_cast<std::streamsize>(sizeof(header))) {
    throw Error(ErrorCode::parse_error, name + ": file too short for the MERL header (3 int32 dimensions)");
  }
  const std::int32_t dims[3] = {from_little_endian<std::int32_t>(header), from_little_endian<std::int32_t>(header + 4),
                                from_little_endian<std::int32_t>(header + 8)};
  if (dims[0] != kThetaHalfRes || dims[1] != kThetaDiffRes || dims[2] != kPhiDiffRes) {
    throw Error(ErrorCode::parse_error, name + ": dimensions " + std::to_string(dims[0]) + " x " +
                                            std::to_string(dims[1]) + " x " + std::to_string(dims[2]) +
                                            ", expected 90 x 90 x 180 (theta_half, theta_diff, phi_diff)");
  }

  // A file too short for the table is refused before the table's 30 MB are allocated.
  const std::size_t expected = 3 * kEntries * sizeof(double);
  std::error_code size_error;
  const std::uintmax_t file_size = std::filesystem::file_size(merl_binary, size_error);
  if (!size_error && file_size < sizeof(header) + expected)
    throw Error(ErrorCode::parse_error, name + ": truncated, expected " + std::to_string(expected) +
                                            " bytes of BRDF data after the header, found " +
                                            std::to_string(file_size - sizeof(header)));

  // Read one channel at a time (all R, then all G, then all B) and interleave.
  std::vector<float> rgb(3 * kEntries);
  std::vector<unsigned char> buffer(kEntries * sizeof(double));
  for (int c = 0; c < 3; ++c) {
    in.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got != buffer.size()) {
      const std::size_t found = c * buffer.size() + got;
      throw Error(ErrorCode::parse_error, name + ": truncated, expected " + std::to_string(expected) +
                                              " bytes of BRDF data after the header, found " +
                                              std::to_string(found));
    }
    for (std::size_t i = 0; i < kEntries; ++i) {
      const double v = from_little_endian<double>(buffer.data() + i * sizeof(double));
      // Negative (and non-finite) entries mark directions without data: read as 0.
      const float f = (std::isfinite(v) && v > 0.0) ? static_cast<float>(v * kScale[c]) : 0.0f;
      rgb[3 * i + static_cast<std::size_t>(c)] = f;
    }
  }
  return std::make_unique<MeasuredBrdf>(std::move(rgb));
}

}  // namespace v1
}  // namespace radiosity
