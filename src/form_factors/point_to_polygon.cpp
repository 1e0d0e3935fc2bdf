// Exact unoccluded form factor from a differential area to a polygon.
// Based on: J. H. Lambert, Photometria (1760), contour-integral form as given in
// Baum, Rushmeier & Winget, "Improving radiosity solutions through the use of analytically
// determined form-factors", SIGGRAPH 1989, eq. 2; and Cohen & Wallace, "Radiosity and Realistic
// Image Synthesis" (1993), sec. 4.6.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/assert.hpp"
#include "form_factors/estimators.hpp"
#include "radiosity/form_factors.hpp"

namespace radiosity {
inline namespace v1 {

double point_to_polygon_factor(const glm::vec3& point, const glm::vec3& normal, const glm::vec3* polygon,
                               int vertex_count) {
  if (vertex_count < 3 || polygon == nullptr) return 0.0;
  const glm::dvec3 x(point), n(normal);

  // Clip the polygon to the hemisphere above the point (Sutherland-Hodgman against the tangent
  // plane): the part below the horizon contributes nothing, and the contour formula assumes it
  // is gone.
  std::array<glm::dvec3, 16> buffer_a, buffer_b;
  std::vector<glm::dvec3> heap_a, heap_b;
  const bool small = vertex_count <= 8;  // clipping adds at most one vertex per plane
  if (!small) {
    heap_a.resize(static_cast<std::size_t>(vertex_count) * 2);
    heap_b.resize(static_cast<std::size_t>(vertex_count) * 2);
  }
  glm::dvec3* in = small ? buffer_a.data() : heap_a.data();
  glm::dvec3* out = small ? buffer_b.data() : heap_b.data();
  for (int i = 0; i < vertex_count; ++i) in[i] = glm::dvec3(polygon[i]) - x;

  int m = 0;
  for (int i = 0; i < vertex_count; ++i) {
    const glm::dvec3& a = in[i];
    const glm::dvec3& b = in[(i + 1) % vertex_count];
    double da = glm::dot(a, n), db = glm::dot(b, n);
    if (da > 0.0) out[m++] = a;
    if ((da > 0.0) != (db > 0.0)) {
      double t = da / (da - db);
      out[m++] = a + t * (b - a);
    }
  }
  if (m < 3) return 0.0;

  return detail::contour_factor(out, m, n);
}

}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

double contour_factor(const glm::dvec3* r, int m, const glm::dvec3& n) {
  // F = 1/(2 pi) sum_i gamma_i n . (R_i x R_{i+1}) / |R_i x R_{i+1}|, gamma_i the angle between
  // the vectors to consecutive vertices: atan2(|R_i x R_{i+1}|, R_i . R_{i+1}), which, like the
  // edge's direction, does not change when the vectors are scaled, so they are not normalised.
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const glm::dvec3& a = r[i];
    const glm::dvec3& b = r[(i + 1) % m];
    // The point on a vertex: that edge has no extent (its cross product is 0 too).
    if (!(glm::dot(a, a) > 0.0) || !(glm::dot(b, b) > 0.0)) continue;
    const glm::dvec3 c = glm::cross(a, b);
    const double c_length = glm::length(c);
    if (!(c_length > 0.0)) continue;
    sum += std::atan2(c_length, glm::dot(a, b)) * glm::dot(n, c) / c_length;
  }
  double f = std::fabs(sum) / (2.0 * 3.14159265358979323846);
  return f > 1.0 ? 1.0 : f;
}

namespace {

// atan2(y, x) for y >= 0, in [0, pi]: octant reduction to a in [0, 1] and an odd polynomial
// a P(a^2) of degree 17, fitted here to atan on [0, 1] by Lawson's iteratively reweighted least
// squares (minimax); the error in float is below 1e-7, and relative ~1e-7 for small angles.
inline float atan2_nonnegative(float y, float x) {
  const float ax = std::fabs(x);
  const float hi = std::max(y, ax), lo = std::min(y, ax);
  const float a = hi > 0.0f ? lo / hi : 0.0f, z = a * a;
  float p = 0.002456724925f;
  p = p * z - 0.01440136069f;
  p = p * z + 0.03978123079f;
  p = p * z - 0.07234858263f;
  p = p * z + 0.1049894667f;
  p = p * z - 0.1416122941f;
  p = p * z + 0.1998590681f;
  p = p * z - 0.3333259703f;
  p = p * z + 0.9999998864f;
  float r = a * p;
  if (y > ax) r = 1.5707963267948966f - r;
  if (x < 0.0f) r = 3.14159265358979323846f - r;
  return r;
}

}  // namespace

float point_to_polygon_factor_fast(const glm::vec3& x, const glm::vec3& n, const glm::vec3* polygon, int vertex_count) {
  // Same contour integral as point_to_polygon_factor(), in float and for at most 8 corners
  // (patches have 3 or 4): clip to the hemisphere above x, then sum the edge terms.
  RADIOSITY_ASSERT(vertex_count >= 3 && vertex_count <= 8);
  std::array<glm::vec3, 9> r;
  std::array<float, 8> h;
  bool all_above = true;
  const int count = std::min(vertex_count, 8);  // (in Release too: the arrays hold 8)
  for (int i = 0; i < count; ++i) {
    r[static_cast<std::size_t>(i)] = polygon[i] - x;
    h[static_cast<std::size_t>(i)] = glm::dot(r[static_cast<std::size_t>(i)], n);
    all_above &= h[static_cast<std::size_t>(i)] > 0.0f;
  }
  int m = count;
  std::array<glm::vec3, 9> clipped;
  const glm::vec3* p = r.data();
  if (!all_above) {
    m = 0;
    for (int i = 0; i < count; ++i) {
      const auto a = static_cast<std::size_t>(i), b = static_cast<std::size_t>((i + 1) % count);
      if (h[a] > 0.0f) clipped[static_cast<std::size_t>(m++)] = r[a];
      if ((h[a] > 0.0f) != (h[b] > 0.0f)) {
        // Interpolate from the end above the plane, so both polygons sharing the edge agree.
        const std::size_t in = h[a] > 0.0f ? a : b, out = h[a] > 0.0f ? b : a;
        const float t = h[in] / (h[in] - h[out]);
        clipped[static_cast<std::size_t>(m++)] = r[in] + t * (r[out] - r[in]);
      }
    }
    if (m < 3) return 0.0f;
    p = clipped.data();
  }
  // The point on a corner: the edges there have no extent (as contour_factor() skips them).
  for (int i = 0; i < m; ++i)
    if (!(glm::dot(p[i], p[i]) > 0.0f)) return static_cast<float>(point_to_polygon_factor(x, n, polygon, vertex_count));
  // Each edge's term without the unit vectors: gamma = atan2(|a x b|, a . b) and the direction
  // n . (a x b) / |a x b| do not change when a and b are scaled, so the corners' vectors are
  // taken as they are (four square roots and twelve divisions fewer per point).
  float sum = 0.0f;
  for (int i = 0; i < m; ++i) {
    const glm::vec3& a = p[i];
    const glm::vec3& b = p[(i + 1) % m];
    const glm::vec3 c = glm::cross(a, b);
    const float c_length = glm::length(c);
    if (!(c_length > 0.0f)) continue;
    sum += atan2_nonnegative(c_length, glm::dot(a, b)) * glm::dot(n, c) / c_length;
  }
  const float f = std::fabs(sum) * 0.15915494309189535f;  // 1 / (2 pi)
  return f > 1.0f ? 1.0f : f;
}

}  // namespace radiosity::detail
