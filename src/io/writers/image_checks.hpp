// Checks shared by the image writers: an Image whose size and pixel count disagree must not
// reach a file format library.
#pragma once

#include <cstddef>
#include <string>

#include "radiosity/render.hpp"

namespace radiosity::detail {

/// Throws Error{invalid_argument}, prefixed by `where`, when the image is empty or its pixel
/// count is not width x height.
inline void check_image_size(const Image& image, const std::string& where) {
  if (image.width <= 0 || image.height <= 0)
    throw Error(ErrorCode::invalid_argument, where + "image size " + std::to_string(image.width) + " x " +
                                                 std::to_string(image.height) + " is empty");
  const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.pixels.size() != n)
    throw Error(ErrorCode::invalid_argument, where + "image has " + std::to_string(image.pixels.size()) +
                                                 " pixels, width x height = " + std::to_string(n));
}

}  // namespace radiosity::detail
