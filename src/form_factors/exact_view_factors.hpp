// The exact mode of view_factor_matrix() at the polygon and element levels
// (form_factors.method = ray_cast; docs/VIEW_FACTORS.md): each unordered pair of polygons
// integrated once, without rays, and both directions filled by reciprocity.
// Private to the library.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// The transport G_ij = A_i F(i -> j) = A_j F(j -> i) between two polygons of a scene, exact to
/// about 1e-5 of a view factor: polygons send and receive on their fronts, and every polygon
/// (obstruction-only ones too) hides what lies behind it, from either side.
/// Thread safety: const member functions may be called concurrently.
class ExactPolygonTransport {
 public:
  explicit ExactPolygonTransport(const Scene& scene);
  ~ExactPolygonTransport();
  ExactPolygonTransport(const ExactPolygonTransport&) = delete;
  ExactPolygonTransport& operator=(const ExactPolygonTransport&) = delete;

  /// Per-thread scratch space of transport().
  struct Workspace {
    std::vector<std::uint32_t> candidates;
    std::vector<glm::dvec3> corners, next_corners, occluder, scratch, planes, cone;
    /// Convex pieces of the receiver: (first corner, corner count) in `corners`.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pieces, next_pieces;
    /// Work done, counted for the automatic choice's estimate (view_factor_matrix.cpp): per
    /// pair 1, plus per point of the adaptive rules 1, plus per occluder clipped at a point 1.
    /// Deterministic (the same pairs do the same work).
    std::uint64_t work = 0;
  };
  std::unique_ptr<Workspace> workspace() const;

  /// G_ij, bit for bit the same for (i, j) and (j, i). 0 for i == j.
  double transport(std::uint32_t i, std::uint32_t j, Workspace& w) const;

  /// The occluders, coplanar facets whose union is convex counted once (a block's face cut
  /// into facets is one).
  std::size_t occluder_count() const;
  /// The convex solids that occluders bound (a block, closed or standing open on a floor),
  /// each of which hides a pair as a whole (without integrating it) when it stands across
  /// every segment between them.
  std::size_t solid_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiosity::detail
