// Inconsistent winding (radiosity::find_inconsistent_winding(), scene.hpp): the warning that
// `radiosity check` and solve() give for what it finds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "radiosity/scene.hpp"
#include "scene/overlap.hpp"

namespace radiosity::detail {

/// Whether a polygon of material `m` has a wrong side: one-sided (no back of its own) and no
/// glass to see through, as find_polygons_facing_outward() and find_inconsistent_winding() judge.
bool has_sides(const Material& m);

/// Which one-sided polygons (has_sides()) share edges, as find_inconsistent_winding() pairs them:
/// an edge whose two ends are exactly those of one edge of exactly one other polygon, not lying
/// on it from the same side. As adjacency lists: polygon p's neighbours are
/// adjacent[first[p] .. first[p + 1]), each with 1 when the two run along their edge the same
/// way (wound opposite to each other).
struct PolygonAdjacency {
  std::vector<std::size_t> first;  ///< polygons + 1 offsets
  std::vector<std::pair<PolygonId, std::uint8_t>> adjacent;
};
/// Builds `adjacency` for `scene`, polling `keep_going` as inconsistent_winding() does; false
/// when it stopped. Cost: a sort of the polygons' edges.
bool polygon_adjacency(const Scene& scene, const KeepGoing& keep_going, PolygonAdjacency& adjacency);
/// Per polygon, the connected surface (polygons joined by shared edges) it belongs to, numbered
/// from 0 in the order of their lowest polygon ids; kNone for a polygon that shares no edge.
std::vector<std::uint32_t> connected_surfaces(const PolygonAdjacency& adjacency);

/// find_inconsistent_winding(), polling `keep_going` (when set) every 32 768 polygons or edges
/// and between the steps of its sort: when it returns false the search stops and returns nothing.
InconsistentWinding inconsistent_winding(const Scene& scene, const KeepGoing& keep_going);

/// One warning (or none, when `found` is empty) naming how many polygons of `scene` are wound
/// against their neighbours, the first of them and where, what that does to the caller's result
/// (`for_view_factors`: to the rows; otherwise to a solve), and the two ways to fix it.
std::vector<std::string> inconsistent_winding_warnings(const Scene& scene, const InconsistentWinding& found,
                                                       bool for_view_factors = false);

}  // namespace radiosity::detail
