// PNG encoding to memory, shared by write_png() and the glTF writer (which embeds lightmaps).
// Internal.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "radiosity/io.hpp"

namespace radiosity::detail {

/// The 8-bit sRGB PNG of write_png(): exposure x radiance, clamped to [0, 1], then the sRGB
/// transfer curve. Throws Error{invalid_argument}, prefixed by `where`, for an empty image, a
/// pixel count that is not width x height or an exposure that is negative or not finite.
std::vector<std::uint8_t> encode_png(const Image& image, const PngOptions& options, const std::string& where);

}  // namespace radiosity::detail
