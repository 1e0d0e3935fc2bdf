// 8-bit sRGB PNG previews of linear images via stb_image_write: exposure, clamp to [0, 1], then
// the sRGB transfer curve. For a quick look; EXR keeps the real values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "io/writers/image_checks.hpp"
#include "io/writers/png_encode.hpp"
#include "io/writers/srgb.hpp"
#include "radiosity/io.hpp"

#include "core/third_party_warnings.hpp"

// The implementation lives here, with internal linkage so it cannot clash with another copy of
// stb in the program.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
RADIOSITY_THIRD_PARTY_BEGIN
#include <stb_image_write.h>
RADIOSITY_THIRD_PARTY_END

namespace radiosity {
namespace detail {

std::vector<std::uint8_t> encode_png(const Image& image, const PngOptions& options, const std::string& where) {
  check_image_size(image, where);
  const std::size_t n = image.pixels.size();
  if (!(options.exposure >= 0.0f) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::invalid_argument, where + "PngOptions::exposure must be finite and >= 0");

  std::vector<std::uint8_t> rgb(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = srgb8(options.exposure * image.pixels[i][c]);

  std::vector<std::uint8_t> png;
  auto append = [](void* context, void* data, int size) {
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    static_cast<std::vector<std::uint8_t>*>(context)->insert(static_cast<std::vector<std::uint8_t>*>(context)->end(),
                                                             bytes, bytes + size);
  };
  if (stbi_write_png_to_func(append, &png, image.width, image.height, 3, rgb.data(), 3 * image.width) == 0)
    throw Error(ErrorCode::io_error, where + "PNG encoding failed");
  return png;
}

}  // namespace detail

inline namespace v1 {

void write_png(const Image& image, const std::filesystem::path& path, const PngOptions& options) {
  const std::vector<std::uint8_t> png = detail::encode_png(image, options, "write_png: '" + path.string() + "': ");
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.close();
  if (!out) throw Error(ErrorCode::io_error, "write_png: cannot write '" + path.string() + "'");
}

}  // namespace v1
}  // namespace radiosity
