// Inconsistent winding (radiosity::find_inconsistent_winding(), scene.hpp): the warning that
// `radiosity check` and solve() give for what it finds.
#pragma once

#include <string>
#include <vector>

#include "radiosity/scene.hpp"
#include "scene/overlap.hpp"

namespace radiosity::detail {

/// Whether a polygon of material `m` has a wrong side: one-sided (no back of its own) and no
/// glass to see through, as find_polygons_facing_outward() and find_inconsistent_winding() judge.
bool has_sides(const Material& m);

/// find_inconsistent_winding(), polling `keep_going` (when set) every 32 768 polygons or edges
/// and between the steps of its sort: when it returns false the search stops and returns nothing.
InconsistentWinding inconsistent_winding(const Scene& scene, const KeepGoing& keep_going);

/// One warning (or none, when `found` is empty) naming how many polygons of `scene` are wound
/// against their neighbours, the first of them and where, what that does to the caller's result
/// (`for_view_factors`: to the rows; otherwise to a solve), and the two ways to fix it.
std::vector<std::string> inconsistent_winding_warnings(const Scene& scene, const InconsistentWinding& found,
                                                       bool for_view_factors = false);

}  // namespace radiosity::detail
