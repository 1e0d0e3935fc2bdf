// Coincident and interpenetrating polygons: a diagnostic. Contact (a box resting on a floor
// with its bottom face, a prop sunk into the floor) is lit correctly by every estimator, since
// rays and hemicubes that reach a back face are blocked there; only coincident surfaces facing
// the same way (z-fighting) are ambiguous. The public face is radiosity::find_overlaps().
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace radiosity {
inline namespace v1 {
class Scene;
struct PolygonOverlap;
}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

/// Distances below this fraction of the scene's bounding-box diagonal count as touching: twice
/// the offset by which the estimators lift ray end points off their surfaces (1e-5 of the
/// diagonal), so a surface closer than that to another cannot be told apart from it by rays.
inline constexpr double kOverlapRelativeTolerance = 2e-5;

/// Polled by the searches below on the calling thread, about every 10 ms while Embree's
/// collision query runs on a worker: false stops the search, which then returns what it found
/// so far (a caller that cancels discards it). Empty: not polled, the query runs on the caller.
using KeepGoing = std::function<bool()>;

/// One warning (or none) for the coincident pairs of find_overlaps(scene) whose normals point
/// the same way: it names the first pair by index and group, where they meet, and how many
/// pairs there are. Coincident pairs facing each other (contact) and interpenetrating pairs
/// are not warned about: they are lit correctly. `consequence` says what it does to the caller's
/// result (by default: to a solve and a render).
std::vector<std::string> z_fighting_warnings(
    const Scene& scene, const KeepGoing& keep_going = {},
    const char* consequence = "which of them is in front is decided by rounding; remove one or move them apart");
/// The same from `overlaps`, find_overlaps(scene)'s result that the caller already has.
std::vector<std::string> z_fighting_warnings(const Scene& scene, const std::vector<PolygonOverlap>& overlaps,
                                             const char* consequence);

/// The distance below which two surfaces count as touching in `scene`:
/// kOverlapRelativeTolerance of its bounding-box diagonal, and at least a few ulps of its
/// largest coordinate.
double touching_tolerance(const Scene& scene);
/// The same for the box [lower, upper].
double touching_tolerance(const glm::vec3& lower, const glm::vec3& upper);

/// A line in a polygon's plane along which another polygon meets its interior.
struct ContactLine {
  std::uint32_t polygon = 0;   ///< the polygon touched (a PolygonId)
  glm::dvec3 point{0.0};       ///< a point of the line, in the polygon's plane, inside it
  glm::dvec3 direction{0.0};   ///< unit, in the polygon's plane
  /// The other polygon stands along the line's whole chord (it divides the polygon by itself);
  /// false for the line of a segment of a dividing chain, in contact only along the chain's
  /// segments (Contacts::segments), so that the pieces on its two sides may share vertices
  /// beyond them.
  bool whole = true;
};

/// A segment in a polygon's plane, inside it, along which another polygon stands on it or
/// passes through it without dividing it: a wall's foot on a ground, a block's sides on a
/// floor, a leg through a floor.
struct ContactSegment {
  std::uint32_t polygon = 0;  ///< the polygon touched (a PolygonId)
  std::uint32_t other = 0;    ///< the polygon standing on it or passing through it
  glm::dvec3 from{0.0}, to{0.0};
};

/// What one search finds: the lines that divide polygons and the segments that end inside them.
struct Contacts {
  /// Every line along which a polygon is divided by another that stands on it (an edge in its
  /// plane: a partition wall on a floor running from border to border) or passes through it,
  /// the contact running across the polygon from border to border, and the whole line of each
  /// segment of a chain of `segments` whose loose ends all lie on its border and that is at
  /// least a quarter of its diameter long (the facets of one wall, a building's corner standing
  /// inside a ground triangle); not lines along its border (walls meeting at corners,
  /// T-junctions), not contacts that end inside it (a block's sides on a floor, a closed chain:
  /// only `segments`) and nothing for coplanar pairs. Sorted by polygon, one entry per line
  /// (several polygons meeting a polygon along the same line give one).
  /// PatchHierarchy cuts the polygons along them (MeshOptions::split_at_contacts): the light on
  /// the two sides of such a line differs by everything the other polygon blocks, and an
  /// element or an interpolated vertex across it would carry light into the dark side (Baum et
  /// al. 1991).
  std::vector<ContactLine> lines;
  /// The contacts that end inside a polygon, sorted by polygon, then by other polygon (those
  /// of dividing chains included: the mesh is graded toward them as well).
  std::vector<ContactSegment> segments;
};
/// Both kinds at the cost of one search (as find_overlaps()). PatchHierarchy cuts polygons
/// along the lines and grades their elements toward the segments (MeshOptions::grade_at_contacts):
/// the shadow and the darkening at a contact are as small as what stands there. Thread
/// safety: concurrent calls are safe.
Contacts find_contacts(const Scene& scene, const KeepGoing& keep_going = {});

}  // namespace radiosity::detail
