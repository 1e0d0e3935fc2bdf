// Polygon clean-up, planarity/convexity tests and triangulation used when a polygon enters a Scene.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace radiosity::detail {

/// A polygon whose area is at most this times its diameter squared is degenerate (zero-area).
inline constexpr float kDegenerateAreaRatio = 1e-7f;
/// The largest coordinate a scene accepts, in scene units. The geometry is computed in float,
/// and the largest product it takes is the squared length of a cross product of two edges
/// (areas, normals): up to 144 x this^4, which must stay below float's 3.4e38. Beyond it (a
/// file's 1e30, or 1e18) an area overflows to infinity, a silently wrong answer; the scene
/// refuses such a vertex as it refuses NaN (found by fuzzing the STL reader). A billion units
/// is 1000 km in millimetres, where float's spacing is already 64 units.
inline constexpr float kMaxCoordinate = 1e9f;

/// Whether every coordinate of `v` is finite.
inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Whether `v` is a position a scene can hold: finite, every coordinate within kMaxCoordinate.
inline bool usable_position(const glm::vec3& v) {
  return std::fabs(v.x) <= kMaxCoordinate && std::fabs(v.y) <= kMaxCoordinate && std::fabs(v.z) <= kMaxCoordinate;
}
/// The mean of `vertices` (not empty): a point inside a convex polygon, where its warnings place
/// it and its plane's offset is measured from.
inline glm::vec3 vertex_mean(const std::vector<glm::vec3>& vertices) {
  glm::vec3 sum(0.0f);
  for (const glm::vec3& v : vertices) sum += v;
  return sum / static_cast<float>(vertices.size());
}

/// A unit normal's components quantised to 2^-12 (about 2.4e-4 rad): equal for the facets of
/// one face, whose normals (each computed from its own float corners) differ in their last
/// bits when the face is turned off the axes, and different for faces at any visible angle.
/// A face whose facets straddle a step gets two keys; callers treat that as two faces.
inline std::array<std::int64_t, 3> direction_key(const glm::vec3& n) {
  constexpr double kSteps = 4096.0;
  return {std::llround(double{n.x} * kSteps), std::llround(double{n.y} * kSteps), std::llround(double{n.z} * kSteps)};
}
/// direction_key() of the axis direction +-1 on one axis: the component that is not 0.
inline constexpr std::int64_t kDirectionKeyUnit = 4096;

/// Vertices may leave the best-fit plane by this fraction of the diameter and still be planar.
inline constexpr float kPlanarityTolerance = 1e-4f;

/// A triangle's area and unit normal, and whether it is degenerate by add_polygon()'s test
/// (area against the diameter squared). Scene::add_mesh() skips the degenerate ones; the file
/// readers ask first, so that they can report them at their place in the file.
struct TriangleShape {
  glm::vec3 normal{0.0f};  ///< unit, right-hand rule of p0 p1 p2 (meaningless when degenerate)
  float area = 0.0f;
  bool degenerate = true;
};

inline TriangleShape triangle_shape(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  TriangleShape t;
  t.area = 0.5f * glm::length(n);
  const float diameter = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
  t.degenerate = !(t.area > kDegenerateAreaRatio * diameter * diameter);
  if (!t.degenerate) t.normal = n / (2.0f * t.area);
  return t;
}

struct CleanPolygon {
  std::vector<glm::vec3> vertices;  ///< duplicates and collinear vertices removed
  glm::vec3 normal{0.0f};           ///< unit Newell normal (0 if degenerate)
  float area = 0.0f;                ///< area projected on the best-fit plane
  float diameter = 0.0f;            ///< largest distance between two input vertices
  bool planar = true;
  bool convex = true;
};

/// Newell's normal: twice the (projected) area times the unit normal, robust for any simple polygon.
glm::vec3 newell_normal(const std::vector<glm::vec3>& v);

CleanPolygon clean_polygon(const std::vector<glm::vec3>& vertices);

/// Ear-clipping triangulation in the plane perpendicular to `normal`; keeps the winding.
std::vector<std::vector<glm::vec3>> triangulate(const std::vector<glm::vec3>& vertices, const glm::vec3& normal);

}  // namespace radiosity::detail
