// Polygon clean-up, planarity/convexity tests and triangulation used when a polygon enters a Scene.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

namespace radiosity::detail {

/// A polygon whose area is at most this times its diameter squared is degenerate (zero-area).
inline constexpr float kDegenerateAreaRatio = 1e-7f;
/// Vertices may leave the best-fit plane by this fraction of the diameter and still be planar.
inline constexpr float kPlanarityTolerance = 1e-4f;

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
