// Exact unoccluded form factor from a differential area to a polygon.
// Based on: J. H. Lambert, Photometria (1760), contour-integral form as given in
// Baum, Rushmeier & Winget, "Improving radiosity solutions through the use of analytically
// determined form-factors", SIGGRAPH 1989, eq. 2; and Cohen & Wallace, "Radiosity and Realistic
// Image Synthesis" (1993), sec. 4.6.
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

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

  // F = 1/(2 pi) sum_i gamma_i n . (R_i x R_{i+1}) / |R_i x R_{i+1}|, gamma_i the angle between
  // the unit vectors to consecutive vertices.
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    glm::dvec3 a = out[i], b = out[(i + 1) % m];
    double la = glm::length(a), lb = glm::length(b);
    if (la <= 0.0 || lb <= 0.0) continue;  // the point is on a vertex: that edge has no extent
    a /= la;
    b /= lb;
    glm::dvec3 c = glm::cross(a, b);
    double sin_gamma = glm::length(c);
    if (sin_gamma <= 0.0) continue;
    double gamma = std::atan2(sin_gamma, glm::dot(a, b));
    sum += gamma * glm::dot(n, c) / sin_gamma;
  }
  double f = std::fabs(sum) / (2.0 * 3.14159265358979323846);
  return f > 1.0 ? 1.0 : f;
}

}  // namespace v1
}  // namespace radiosity
