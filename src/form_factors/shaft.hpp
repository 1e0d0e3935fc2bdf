// Shaft culling: which polygons can block the segments between two convex polygons (or between
// a point and a polygon)? Used by the ray-cast estimator to skip occlusion rays for pairs that
// nothing can shadow, and by the hemicube to rasterise only the patches that can hide a receiver.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace radiosity::detail {

/// A closed half-space {x : dot(normal, x) <= offset}; `normal` is unit length.
struct HalfSpace {
  glm::vec3 normal{0.0f};
  float offset = 0.0f;
};

/// A convex region that contains every segment from a point of a source polygon (in front of
/// it) to a point of a receiver polygon (in front of it): the convex hull of the two polygons,
/// cut by the two front half-spaces. Built from up to 4 + 4 corners.
/// Thread safety: a value; build() and the tests touch only this object.
class Shaft {
 public:
  /// Source polygon `a` (na in 1..4 corners; 1 = a point, then `a_normal` is the horizon's
  /// normal) and receiver polygon `b` (nb in 3..4) with unit normals. `tolerance` (scene units)
  /// decides "touching": a polygon that only touches the shaft's boundary cannot block it.
  /// Returns false when the region is empty (b entirely behind a's plane or a behind b's).
  bool build(const glm::vec3* a, int na, const glm::vec3& a_normal, const glm::vec3* b, int nb,
             const glm::vec3& b_normal, float tolerance);

  /// True when the axis-aligned box [lower, upper] lies outside one of the bounding planes.
  bool excludes_box(const glm::vec3& lower, const glm::vec3& upper) const;
  /// True when a convex planar polygon (unit `normal`, plane offset dot(normal, p0)) cannot
  /// enter the shaft's interior: all its corners lie outside one bounding plane, or all the
  /// shaft's corners lie on one side of the polygon's plane.
  bool excludes_polygon(const glm::vec3* corners, int count, const glm::vec3& normal, float plane_offset) const;

  int plane_count() const { return plane_count_; }

 private:
  void add(const glm::vec3& normal, float offset);

  static constexpr int kMaxPlanes = 2 + 2 * 16;
  std::array<HalfSpace, kMaxPlanes> planes_{};
  int plane_count_ = 0;
  std::array<glm::vec3, 8> corners_{};
  int corner_count_ = 0;
  float tolerance_ = 0.0f;
};

/// A bounding-volume hierarchy over convex planar polygons (any number of corners >= 3), indexed
/// 0..n-1, answering "which polygons may enter this shaft".
/// Thread safety: const member functions may be called concurrently.
class ShaftCuller {
 public:
  ShaftCuller() = default;
  /// `polygons[i]` lists polygon i's corners (>= 3, planar, convex); `normals[i]` is its unit normal.
  ShaftCuller(const std::vector<std::vector<glm::vec3>>& polygons, const std::vector<glm::vec3>& normals);

  /// True when some polygon other than `skip_a` and `skip_b` may enter the shaft.
  bool any(const Shaft& shaft, std::uint32_t skip_a, std::uint32_t skip_b) const;
  /// Whether a polygon other than `skip_a` and `skip_b` may block a segment between source `a`
  /// and receiver `b` (Shaft::build's arguments): false when the shaft is empty or nothing
  /// enters it, so the pair needs no shadow rays.
  bool may_block(const glm::vec3* a, int na, const glm::vec3& a_normal, const glm::vec3* b, int nb,
                 const glm::vec3& b_normal, float tolerance, std::uint32_t skip_a, std::uint32_t skip_b) const {
    Shaft shaft;
    return shaft.build(a, na, a_normal, b, nb, b_normal, tolerance) && any(shaft, skip_a, skip_b);
  }
  /// Appends the polygons other than `skip` that may enter the shaft to `out`, in increasing order.
  void collect(const Shaft& shaft, std::uint32_t skip, std::vector<std::uint32_t>& out) const;

  std::size_t size() const { return first_corner_.empty() ? 0 : first_corner_.size() - 1; }

 private:
  struct Node {
    glm::vec3 lower{0.0f}, upper{0.0f};
    std::uint32_t first = 0;  ///< leaf: first index into order_; inner: index of the left child
    std::uint32_t count = 0;  ///< leaf: number of polygons; inner: 0 (right child = left + 1)
  };

  void build(std::uint32_t index, std::uint32_t begin, std::uint32_t end, int depth);
  bool test(const Shaft& shaft, std::uint32_t polygon) const;
  template <typename Visit>
  void traverse(const Shaft& shaft, const Visit& visit) const;

  std::vector<glm::vec3> corners_;           ///< all polygons' corners, concatenated
  std::vector<std::uint32_t> first_corner_;  ///< polygon i owns corners_[first_corner_[i] .. first_corner_[i+1])
  std::vector<glm::vec3> normals_;
  std::vector<float> offsets_;
  std::vector<glm::vec3> lower_, upper_;  ///< per polygon bounds
  std::vector<glm::vec3> centre_;
  std::vector<std::uint32_t> order_;  ///< polygon ids, grouped by leaf
  std::vector<Node> nodes_;
};

}  // namespace radiosity::detail
