// The mean colour of a texture, which the scene readers multiply into a material's factor
// (glTF: baseColorFactor x the base colour texture): a polygon has one reflectance, and the
// mean keeps the power it reflects. Decoding is stb_image's (PNG, JPEG, BMP, TGA, HDR, ...).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// The mean of an encoded image's texels, in linear values: sRGB-encoded channels (`srgb`: a
/// colour texture) are decoded before averaging, others (data: metallic-roughness) taken as
/// they are; alpha is not read; a grey image is grey. An HDR (Radiance) image is linear already.
/// Returns nullopt with `why` set when the image cannot be decoded (broken data, a format
/// stb_image does not read, more than 16384 texels a side).
std::optional<Rgb> mean_of_encoded_image(const unsigned char* bytes, std::size_t size, bool srgb, std::string& why);

/// The mean of `count` 8-bit RGBA texels (an uncompressed embedded texture), as above.
Rgb mean_of_rgba8(const std::uint8_t* rgba, std::size_t count, bool srgb);

}  // namespace radiosity::detail
