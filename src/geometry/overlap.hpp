// Coincident and interpenetrating polygons: the check that form factors and solves run on a
// scene before trusting it. The public face is radiosity::find_overlaps() (scene.hpp).
#pragma once

namespace radiosity {
inline namespace v1 {
class Scene;
}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

/// Distances below this fraction of the scene's bounding-box diagonal count as touching: twice
/// the offset by which the estimators lift ray end points off their surfaces (1e-5 of the
/// diagonal), so a surface closer than that to another cannot be told apart from it by rays.
inline constexpr double kOverlapRelativeTolerance = 2e-5;

/// Throws Error{invalid_scene} when find_overlaps(scene) is not empty; the message names the
/// first pair (lowest polygon ids) by index and group, says where they meet and how many other
/// pairs there are. `who` prefixes the message (e.g. "solve").
void check_no_overlaps(const Scene& scene, const char* who);

}  // namespace radiosity::detail
