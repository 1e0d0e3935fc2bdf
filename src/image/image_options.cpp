// validate(ImageOptions) and the check behind it (image_options.hpp).
#include "image/image_options.hpp"

#include "core/camera_check.hpp"

namespace radiosity {

namespace detail {

std::string image_options_problem(const ImageOptions& options) {
  if (options.width <= 0) return "width must be > 0, got " + std::to_string(options.width);
  if (options.height <= 0) return "height must be > 0, got " + std::to_string(options.height);
  if (options.spp <= 0) return "spp must be > 0, got " + std::to_string(options.spp);
  if (options.camera) return camera_problem(*options.camera);
  return {};
}

}  // namespace detail

inline namespace v1 {

void validate(const ImageOptions& options) {
  const std::string problem = detail::image_options_problem(options);
  if (!problem.empty()) throw Error(ErrorCode::invalid_argument, "ImageOptions::" + problem);
}

}  // namespace v1
}  // namespace radiosity
