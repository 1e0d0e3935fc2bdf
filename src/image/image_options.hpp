// The one check of the options the three renderers share (ImageOptions), so that
// validate(ImageOptions) and the renderers' own validate() refuse the same values with the same
// words, each behind its own prefix ("PathTraceOptions::", "render: ", ...).
#pragma once

#include <string>

#include "radiosity/render.hpp"

namespace radiosity::detail {

/// What makes `options` unusable, or "" when nothing does: the first bad field of width,
/// height, spp and camera, e.g. "width must be > 0, got 0" or camera_problem()'s words
/// ("camera.fov_deg must be in (0, 180), got 190"). Thread safety: pure function.
std::string image_options_problem(const ImageOptions& options);

}  // namespace radiosity::detail
