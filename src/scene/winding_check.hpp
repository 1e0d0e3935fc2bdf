// Inconsistent winding (radiosity::find_inconsistent_winding(), scene.hpp): the warning that
// `radiosity check` and solve() give for what it finds.
#pragma once

#include <string>
#include <vector>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// Whether a polygon of material `m` has a wrong side: one-sided (no back of its own) and no
/// glass to see through, as find_polygons_facing_outward() and find_inconsistent_winding() judge.
bool has_sides(const Material& m);

/// One warning (or none, when `found` is empty) naming how many polygons of `scene` are wound
/// against their neighbours, the first of them and where, and the two ways to fix it.
std::vector<std::string> inconsistent_winding_warnings(const Scene& scene, const InconsistentWinding& found);

}  // namespace radiosity::detail
