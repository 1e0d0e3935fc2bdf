#include "io/readers/local_origin.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/assert.hpp"

namespace radiosity::detail {

namespace {

/// Share of a typical polygon's size that single precision may move its corners by before the
/// model is moved: 0.1 %, a tenth of what load_scene() warns about for the formats read in
/// single precision (there, contacts already open and faces bend).
constexpr double kPrecisionShare = 1e-3;

}  // namespace

void LocalOriginFinder::add_polygon(const glm::dvec3* corners, std::size_t count) {
  RADIOSITY_ASSERT(count >= 3);
  // Newell's normal: twice the area vector of a planar polygon, a good estimate of a bent one.
  glm::dvec3 twice_area(0.0);
  for (std::size_t i = 0; i < count; ++i) {
    const glm::dvec3& a = corners[i];
    const glm::dvec3& b = corners[(i + 1) % count];
    if (empty_) {
      lower_ = upper_ = a;
      empty_ = false;
    }
    lower_ = glm::min(lower_, a);
    upper_ = glm::max(upper_, a);
    // Relative to the first corner, so that far coordinates do not swamp the cross products.
    twice_area += glm::cross(a - corners[0], b - corners[0]);
  }
  sizes_.push_back(std::sqrt(0.5 * glm::length(twice_area)));
}

glm::dvec3 LocalOriginFinder::origin() {
  if (empty_) return glm::dvec3(0.0);
  const auto mid = sizes_.begin() + static_cast<std::ptrdiff_t>(sizes_.size() / 2);
  std::nth_element(sizes_.begin(), mid, sizes_.end());
  const double typical = *mid;
  const glm::dvec3 reach3 = glm::max(glm::abs(lower_), glm::abs(upper_));
  const float reach = static_cast<float>(std::max({reach3.x, reach3.y, reach3.z}));
  const double spacing = static_cast<double>(std::nextafter(reach, 2.0f * reach + 1.0f) - reach);
  if (!(typical > 0.0) || spacing < kPrecisionShare * typical) return glm::dvec3(0.0);
  const glm::dvec3 extent3 = upper_ - lower_;
  const double extent = std::max({extent3.x, extent3.y, extent3.z});
  const double step = extent > 0.0 ? std::pow(10.0, std::floor(std::log10(extent))) : 1.0;
  const glm::dvec3 centre = 0.5 * (lower_ + upper_);
  const glm::dvec3 origin = glm::round(centre / step) * step;
  // Positions relative to it must be floats again (coordinates near +-FLT_MAX, which the
  // readers accept, could round it away from the centre by more than float's range allows).
  const glm::dvec3 far = glm::max(glm::abs(upper_ - origin), glm::abs(lower_ - origin));
  if (!(std::max({far.x, far.y, far.z}) <= 0.5 * static_cast<double>(FLT_MAX))) return glm::dvec3(0.0);
  return origin;
}

}  // namespace radiosity::detail
