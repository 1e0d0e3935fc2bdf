// Small functions of RGB triples shared by the modules.
#pragma once

#include <algorithm>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// The largest of the three channels.
inline float max_channel(const Rgb& c) { return std::max(c.x, std::max(c.y, c.z)); }

/// The mean of the three channels.
inline float channel_mean(const Rgb& c) { return (c.x + c.y + c.z) / 3.0f; }

}  // namespace radiosity::detail
