// Mean texel values for the readers (texture_mean.hpp). The sRGB decoding is IEC 61966-2-1's
// transfer function (as the glTF 2.0 specification, section 3.9.2, requires for base colour and
// emissive textures); images are decoded by stb_image (Sean Barrett, public domain).
#include "io/readers/texture_mean.hpp"

#include <array>
#include <climits>
#include <cmath>
#include <memory>

#include "core/third_party_warnings.hpp"

// The implementation lives here, with internal linkage so it cannot clash with another copy of
// stb in the program (tinygltf's shared library carries its own).
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO  // images come from memory only
RADIOSITY_THIRD_PARTY_BEGIN
#include <stb_image.h>
RADIOSITY_THIRD_PARTY_END

namespace radiosity::detail {
namespace {

/// Larger images are refused rather than decoded: 16384^2 RGBA texels are 1 GiB already.
constexpr int kMaxSide = 16384;

double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

/// The linear value of each 8-bit code.
const std::array<double, 256>& decode_table(bool srgb) {
  static const std::array<std::array<double, 256>, 2> tables = [] {
    std::array<std::array<double, 256>, 2> t{};
    for (int i = 0; i < 256; ++i) {
      t[0][static_cast<std::size_t>(i)] = i / 255.0;
      t[1][static_cast<std::size_t>(i)] = srgb_to_linear(i / 255.0);
    }
    return t;
  }();
  return tables[srgb ? 1 : 0];
}

struct StbiFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

}  // namespace

Rgb mean_of_rgba8(const std::uint8_t* rgba, std::size_t count, bool srgb) {
  if (count == 0) return Rgb(0.0f);
  const std::array<double, 256>& decode = decode_table(srgb);
  double sum[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c) sum[c] += decode[rgba[4 * i + static_cast<std::size_t>(c)]];
  const double n = static_cast<double>(count);
  return Rgb(static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n));
}

std::optional<Rgb> mean_of_encoded_image(const unsigned char* bytes, std::size_t size, bool srgb, std::string& why) {
  if (bytes == nullptr || size == 0 || size > static_cast<std::size_t>(INT_MAX)) {
    why = size == 0 ? "the image is empty" : "the image is larger than 2 GiB";
    return std::nullopt;
  }
  const int length = static_cast<int>(size);
  int w = 0, h = 0, channels = 0;
  if (!stbi_info_from_memory(bytes, length, &w, &h, &channels)) {
    why = std::string("cannot decode the image (") + stbi_failure_reason() + ")";
    return std::nullopt;
  }
  if (w <= 0 || h <= 0 || w > kMaxSide || h > kMaxSide) {
    why = "the image is " + std::to_string(w) + "x" + std::to_string(h) + " texels (at most " +
          std::to_string(kMaxSide) + " a side are read)";
    return std::nullopt;
  }
  const int info_w = w, info_h = h;
  // The loaders set w and h again; they are the ones info() gave (checked), so `count` holds.
  const std::size_t count = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  auto loaded = [&](const void* px) {
    if (px != nullptr && w == info_w && h == info_h) return true;
    why = std::string("cannot decode the image (") + (px ? "its size changed" : stbi_failure_reason()) + ")";
    return false;
  };
  double sum[3] = {0.0, 0.0, 0.0};
  if (stbi_is_hdr_from_memory(bytes, length)) {
    std::unique_ptr<float, StbiFree> px(stbi_loadf_from_memory(bytes, length, &w, &h, &channels, 3));
    if (!loaded(px.get())) return std::nullopt;
    for (std::size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) sum[c] += static_cast<double>(px.get()[3 * i + static_cast<std::size_t>(c)]);
  } else if (stbi_is_16_bit_from_memory(bytes, length)) {
    std::unique_ptr<stbi_us, StbiFree> px(stbi_load_16_from_memory(bytes, length, &w, &h, &channels, 3));
    if (!loaded(px.get())) return std::nullopt;
    for (std::size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) {
        const double v = px.get()[3 * i + static_cast<std::size_t>(c)] / 65535.0;
        sum[c] += srgb ? srgb_to_linear(v) : v;
      }
  } else {
    std::unique_ptr<stbi_uc, StbiFree> px(stbi_load_from_memory(bytes, length, &w, &h, &channels, 3));
    if (!loaded(px.get())) return std::nullopt;
    const std::array<double, 256>& decode = decode_table(srgb);
    for (std::size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) sum[c] += decode[px.get()[3 * i + static_cast<std::size_t>(c)]];
  }
  const double n = static_cast<double>(count);
  return Rgb(static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n));
}

}  // namespace radiosity::detail
