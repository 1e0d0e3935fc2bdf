// Small functions of RGB triples shared by the modules.
#pragma once

#include <algorithm>
#include <cmath>

#include "radiosity/common.hpp"

namespace radiosity::detail {

/// The largest of the three channels.
inline float max_channel(const Rgb& c) { return std::max(c.x, std::max(c.y, c.z)); }

/// The sum of the channels' magnitudes (a change's size in the sweeps' convergence measures).
inline double channel_l1(const Rgb& c) { return std::fabs(c.x) + std::fabs(c.y) + std::fabs(c.z); }

/// The mean of the three channels.
inline float channel_mean(const Rgb& c) { return (c.x + c.y + c.z) / 3.0f; }

}  // namespace radiosity::detail
