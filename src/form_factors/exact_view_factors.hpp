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

#include "core/progress.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// How a pair's transport was integrated, counted for benchmarks.
struct ExactPairCounters {
  std::uint64_t pairs = 0;      ///< unordered pairs integrated (facing each other)
  std::uint64_t far = 0;        ///< of those, by the double area rule (far apart, nothing between)
  std::uint64_t near = 0;       ///< by the adaptive single area rule (near, nothing between)
  std::uint64_t obstructed = 0; ///< with candidate occluders (exact visibility by clipping)
  std::uint64_t points = 0;     ///< source points of the obstructed pairs' integrals
  std::uint64_t occluders = 0;  ///< candidate occluders over the obstructed pairs
};

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

  /// Per-thread scratch space of transport() (and its counters).
  struct Workspace {
    ExactPairCounters counts;
    std::vector<std::uint32_t> candidates;
    std::vector<glm::dvec3> corners, next_corners, occluder, scratch, planes, cone;
    /// Convex pieces of the receiver: (first corner, corner count) in `corners`.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pieces, next_pieces;
  };
  std::unique_ptr<Workspace> workspace() const;

  /// G_ij, bit for bit the same for (i, j) and (j, i). 0 for i == j.
  double transport(std::uint32_t i, std::uint32_t j, Workspace& w) const;

  /// The polygons that can hide anything at all (some polygon has corners on both sides of
  /// their plane): a closed room's walls cannot.
  std::size_t occluder_count() const;
  /// What transport() has done, summed over workspaces (add() them first).
  void add(const Workspace& w, ExactPairCounters& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiosity::detail
