// Coincident and interpenetrating polygons: a diagnostic. Contact (a box resting on a floor
// with its bottom face, a prop sunk into the floor) is lit correctly by every estimator, since
// rays and hemicubes that reach a back face are blocked there; only coincident surfaces facing
// the same way (z-fighting) are ambiguous. The public face is radiosity::find_overlaps().
#pragma once

#include <string>
#include <vector>

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

/// One warning (or none) for the coincident pairs of find_overlaps(scene) whose normals point
/// the same way: it names the first pair by index and group, where they meet, and how many
/// pairs there are. Coincident pairs facing each other (contact) and interpenetrating pairs
/// are not warned about: they are lit correctly.
std::vector<std::string> z_fighting_warnings(const Scene& scene);

}  // namespace radiosity::detail
