#include "scene/polygon_math.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace radiosity::detail {

glm::vec3 newell_normal(const std::vector<glm::vec3>& v) {
  glm::vec3 n(0.0f);
  const std::size_t count = v.size();
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3& a = v[i];
    const glm::vec3& b = v[(i + 1) % count];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

CleanPolygon clean_polygon(const std::vector<glm::vec3>& input) {
  CleanPolygon out;
  for (std::size_t i = 0; i < input.size(); ++i)
    for (std::size_t j = i + 1; j < input.size(); ++j)
      out.diameter = std::max(out.diameter, glm::length(input[i] - input[j]));
  const float eps = 1e-6f * out.diameter;

  // Drop consecutive duplicates (including last == first).
  std::vector<glm::vec3> v;
  for (const glm::vec3& p : input)
    if (v.empty() || glm::length(p - v.back()) > eps) v.push_back(p);
  while (v.size() > 1 && glm::length(v.front() - v.back()) <= eps) v.pop_back();

  // Drop collinear vertices until none are left: they add nothing and break convexity tests.
  bool changed = true;
  while (changed && v.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const glm::vec3& prev = v[(i + v.size() - 1) % v.size()];
      const glm::vec3& next = v[(i + 1) % v.size()];
      glm::vec3 a = v[i] - prev, b = next - v[i];
      if (glm::length(glm::cross(a, b)) <= 1e-6f * glm::length(a) * glm::length(b)) {
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
  out.vertices = std::move(v);
  if (out.vertices.size() < 3) return out;

  glm::vec3 n = newell_normal(out.vertices);
  float len = glm::length(n);
  out.area = 0.5f * len;
  if (len <= 0.0f) return out;
  out.normal = n / len;

  // A triangle is planar and convex by definition; the tests below could say otherwise only
  // through rounding (a thin triangle far from the origin), and then a valid triangle would be
  // "triangulated into 1 triangle" with a warning.
  if (out.vertices.size() == 3) return out;

  const glm::vec3 centre = vertex_mean(out.vertices);
  for (const glm::vec3& p : out.vertices)
    if (std::fabs(glm::dot(p - centre, out.normal)) > kPlanarityTolerance * out.diameter) out.planar = false;

  const std::size_t count = out.vertices.size();
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 a = out.vertices[(i + 1) % count] - out.vertices[i];
    glm::vec3 b = out.vertices[(i + 2) % count] - out.vertices[(i + 1) % count];
    if (glm::dot(glm::cross(a, b), out.normal) <= 0.0f) out.convex = false;
  }
  return out;
}

namespace {

float cross2(const glm::vec2& a, const glm::vec2& b) { return a.x * b.y - a.y * b.x; }

bool inside_triangle(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b, const glm::vec2& c) {
  return cross2(b - a, p - a) >= 0.0f && cross2(c - b, p - b) >= 0.0f && cross2(a - c, p - c) >= 0.0f;
}

}  // namespace

std::vector<std::vector<glm::vec3>> triangulate(const std::vector<glm::vec3>& vertices, const glm::vec3& normal) {
  // Project on the plane perpendicular to the normal, with (u, v, normal) right-handed so CCW
  // stays CCW in 2D.
  glm::vec3 u = std::fabs(normal.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  u = glm::normalize(u - normal * glm::dot(u, normal));
  glm::vec3 w = glm::cross(normal, u);
  std::vector<glm::vec2> p;
  for (const glm::vec3& q : vertices) p.emplace_back(glm::dot(q, u), glm::dot(q, w));

  std::vector<std::size_t> idx(vertices.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::vector<std::vector<glm::vec3>> out;
  while (idx.size() > 3) {
    bool clipped = false;
    for (std::size_t k = 0; k < idx.size() && !clipped; ++k) {
      std::size_t ia = idx[(k + idx.size() - 1) % idx.size()], ib = idx[k], ic = idx[(k + 1) % idx.size()];
      if (cross2(p[ib] - p[ia], p[ic] - p[ib]) <= 0.0f) continue;  // reflex corner: not an ear
      bool empty = true;
      for (std::size_t j : idx)
        if (j != ia && j != ib && j != ic && inside_triangle(p[j], p[ia], p[ib], p[ic])) {
          empty = false;
          break;
        }
      if (!empty) continue;
      out.push_back({vertices[ia], vertices[ib], vertices[ic]});
      idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
    }
    // A self-intersecting outline has no ear; fall back to a fan so no geometry is dropped.
    if (!clipped) {
      for (std::size_t k = 1; k + 1 < idx.size(); ++k)
        out.push_back({vertices[idx[0]], vertices[idx[k]], vertices[idx[k + 1]]});
      return out;
    }
  }
  out.push_back({vertices[idx[0]], vertices[idx[1]], vertices[idx[2]]});
  return out;
}

}  // namespace radiosity::detail
