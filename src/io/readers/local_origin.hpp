#pragma once
// A local origin for models far from the origin for their size (LoadOptions::local_origin,
// Scene::origin()). Georeferenced files (a city in UTM, a building at its national-grid
// position) give corners like (500123.4, 31.2, 5700456.7): Polygon stores single precision,
// whose neighbouring values are 0.5 apart at 5.7e6, so a reader that parses in double subtracts
// a round point near the model's centre before it stores anything, as CloudCompare and GIS
// viewers do ("global shift"), and the writers add it back.
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

namespace radiosity::detail {

/// Collects a model's polygons in double precision as a reader reads them (their bounds and
/// sizes) and picks the point to subtract. Not thread-safe; one per file read.
class LocalOriginFinder {
 public:
  /// One polygon's corners, in the file's coordinates (count >= 3).
  void add_polygon(const glm::dvec3* corners, std::size_t count);

  /// (0, 0, 0) when single precision holds the model: the spacing of floats at its largest
  /// coordinate is under 0.1 % of its median polygon's size (the square root of its area).
  /// Otherwise the centre of its bounds rounded to a multiple of the power of ten at or below
  /// its extent (readable, and within 1.5 extents of every corner), so that the positions
  /// left are as small as the model. Deterministic; cost: linear in the polygons.
  glm::dvec3 origin();

 private:
  glm::dvec3 lower_{0.0}, upper_{0.0};
  bool empty_ = true;
  std::vector<double> sizes_;
};

}  // namespace radiosity::detail
