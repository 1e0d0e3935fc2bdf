// What each polygon emits in one solve: its material's emission, or the per-polygon emission a
// relit solve supplies instead (Problem::solve(polygon_emission)).
#pragma once

#include <vector>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// The emission (W/m^2, leaving the front; a two-sided material's back too) of polygon `p`:
/// (*override)[p] when `override` is given (one value per polygon), else its material's.
inline const Rgb& polygon_emission(const Scene& scene, PolygonId p, const std::vector<Rgb>* override) {
  return override ? (*override)[p] : scene.material(scene.polygons()[p].material).emission;
}

}  // namespace radiosity::detail
