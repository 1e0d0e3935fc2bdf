// Area-uniform points on a planar convex polygon, through the fan of triangles from its first
// vertex: the emitter sampling of the path tracer, the two-pass renderer and the Monte Carlo
// form factors' shadow rays.
// Based on: G. Turk, "Generating random points in triangles", Graphics Gems (1990).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/distribution.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// The fan triangles (a, b[k], c[k]) of a polygon and the cumulative area fraction over them.
/// Thread safety: immutable after construction.
struct PolygonFan {
  PolygonFan() = default;
  explicit PolygonFan(const PolygonVertices& vertices) {
    float area = 0.0f;
    for (std::size_t k = 1; k + 1 < vertices.size(); ++k) {
      a.push_back(vertices[0]);
      b.push_back(vertices[k]);
      c.push_back(vertices[k + 1]);
      const glm::vec3 edge_b = vertices[k] - vertices[0], edge_c = vertices[k + 1] - vertices[0];
      area += 0.5f * glm::length(glm::cross(edge_b, edge_c));
      cdf.push_back(area);
    }
    for (float& v : cdf) v /= area;
    cdf.back() = 1.0f;
  }

  /// The triangle that u in [0, 1) falls in, by area.
  std::size_t triangle(float u) const { return sample_cdf(cdf, u); }

  /// Uniform point in triangle `tri` for u in [0,1)^2: barycentrics (1 - sqrt(u1), u2 sqrt(u1)).
  glm::vec3 point(std::size_t tri, glm::vec2 u) const {
    const float su = std::sqrt(std::max(u.x, 0.0f));
    return (1.0f - su) * a[tri] + (u.y * su) * b[tri] + (su * (1.0f - u.y)) * c[tri];
  }

  /// Area-uniform point from one u in [0,1)^2: u.x picks the triangle and is then rescaled
  /// within its slice of the cdf to drive the point, so strata of u stay compact.
  glm::vec3 sample(glm::vec2 u) const {
    const std::size_t tri = triangle(u.x);
    const float lo = tri == 0 ? 0.0f : cdf[tri - 1], hi = cdf[tri];
    const float ux = hi > lo ? std::min((u.x - lo) / (hi - lo), 0x1.fffffep-1f) : 0.5f;
    return point(tri, glm::vec2(ux, u.y));
  }

  std::vector<glm::vec3> a, b, c;
  std::vector<float> cdf;
};

}  // namespace radiosity::detail
