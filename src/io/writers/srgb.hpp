// The sRGB transfer curve, shared by the PNG preview and the PLY display colours. Internal.
#pragma once

#include <cmath>
#include <cstdint>

namespace radiosity::detail {

/// sRGB encoding of a linear value (IEC 61966-2-1): 12.92 x below 0.0031308, else
/// 1.055 x^(1/2.4) - 0.055. The input is clamped to [0, 1] first; NaN gives 0.
inline float srgb_encode(float linear) {
  if (!(linear > 0.0f)) return 0.0f;  // also NaN
  if (linear >= 1.0f) return 1.0f;
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

/// srgb_encode() quantised to 8 bits, rounding to nearest.
inline std::uint8_t srgb8(float linear) {
  return static_cast<std::uint8_t>(std::lround(255.0f * srgb_encode(linear)));
}

}  // namespace radiosity::detail
