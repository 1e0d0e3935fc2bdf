// Continuity checks of the interpolated vertex field (PatchHierarchy::vertex_values), shared by
// the mesh and solver tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include <glm/geometric.hpp>
#include <radiosity/mesh.hpp>
#include <radiosity/scene.hpp>

namespace test {

namespace rad = radiosity;

/// Every vertex lying strictly inside a leaf's edge must carry the linear interpolation of the
/// edge's end values; then the piecewise-linear field on the finer side equals the coarse side's
/// linear one, i.e. there is no crack. Returns the largest deviation found. Looks at every
/// vertex of the hierarchy, whichever polygon it belongs to (O(leaves x vertices): small meshes).
inline float largest_crack(const rad::PatchHierarchy& h, const std::vector<rad::Rgb>& vv) {
  const auto& v = h.vertices();
  float worst = 0.0f;
  for (const std::uint32_t id : h.leaves()) {
    const rad::Element& e = h.element(id);
    for (int k = 0; k < e.corner_count(); ++k) {
      const std::uint32_t a = e.corners[k], b = e.corners[(k + 1) % e.corner_count()];
      const glm::vec3 ab = v[b] - v[a];
      const float len2 = glm::dot(ab, ab);
      for (std::uint32_t m = 0; m < v.size(); ++m) {
        if (m == a || m == b) continue;
        const float t = glm::dot(v[m] - v[a], ab) / len2;
        if (t <= 1e-4f || t >= 1.0f - 1e-4f) continue;
        if (glm::length(v[a] + t * ab - v[m]) > 1e-5f * std::sqrt(len2)) continue;
        const rad::Rgb expected = (1.0f - t) * vv[a] + t * vv[b];
        const rad::Rgb d = glm::abs(expected - vv[m]);
        worst = std::max({worst, d.x, d.y, d.z});
      }
    }
  }
  return worst;
}

/// The interpolated field at point x on polygon `polygon`'s border, seen from that polygon: the
/// linear interpolation along its leaf edge through x. False if no leaf edge of the polygon
/// passes within `slack` of x.
inline bool field_on_border(const rad::PatchHierarchy& h, const std::vector<std::uint32_t>& leaves,
                            const std::vector<rad::Rgb>& vv, const glm::vec3& x, float slack, rad::Rgb& out) {
  for (const std::uint32_t id : leaves) {
    const rad::Element& e = h.element(id);
    for (int k = 0; k < e.corner_count(); ++k) {
      const std::uint32_t a = e.corners[k], b = e.corners[(k + 1) % e.corner_count()];
      const glm::vec3 A = h.vertices()[a], ab = h.vertices()[b] - A;
      const float t = glm::dot(x - A, ab) / glm::dot(ab, ab);
      if (t < -1e-6f || t > 1.0f + 1e-6f || glm::length(A + t * ab - x) > slack) continue;
      out = (1.0f - t) * vv[a] + t * vv[b];
      return true;
    }
  }
  return false;
}

/// What largest_seam_jump() found.
struct SeamJump {
  std::size_t edges = 0;   ///< smooth edges looked at
  double largest = 0.0;    ///< the largest relative jump over their points
  bool complete = true;    ///< false if some point was on no leaf edge of its polygon
};

/// For every edge that two triangles or quads share (the same end points bit for bit, in either
/// direction) with the same material and group and normals within `crease_deg`: the interpolated
/// field `vv` at 49 points along it (every 1/48, so thirds and sixteenths too), seen from
/// either polygon. A jump is |a - b| / max(|a|, |b|, floor), per channel; the largest is kept.
inline SeamJump largest_seam_jump(const rad::Scene& scene, const rad::PatchHierarchy& h,
                                  const std::vector<rad::Rgb>& vv, float crease_deg, float floor) {
  const auto& polygons = scene.polygons();
  std::vector<std::vector<std::uint32_t>> leaves_of(polygons.size());
  for (const std::uint32_t id : h.leaves()) leaves_of[h.patches()[h.element(id).patch].polygon].push_back(id);
  using Key = std::array<float, 6>;
  std::map<Key, std::vector<std::uint32_t>> edges;
  for (std::uint32_t p = 0; p < polygons.size(); ++p) {
    const auto& v = polygons[p].vertices;
    if (v.size() > 4) continue;
    for (std::size_t k = 0; k < v.size(); ++k) {
      glm::vec3 a = v[k], b = v[(k + 1) % v.size()];
      if (std::array<float, 3>{b.x, b.y, b.z} < std::array<float, 3>{a.x, a.y, a.z}) std::swap(a, b);
      edges[Key{a.x, a.y, a.z, b.x, b.y, b.z}].push_back(p);
    }
  }
  const double cos_crease = std::cos(static_cast<double>(crease_deg) * 3.14159265358979323846 / 180.0);
  SeamJump out;
  for (const auto& [key, sharing] : edges) {
    if (sharing.size() != 2) continue;
    const rad::Polygon &p = polygons[sharing[0]], &q = polygons[sharing[1]];
    if (p.material != q.material || p.group != q.group) continue;
    if (static_cast<double>(glm::dot(p.normal, q.normal)) < cos_crease) continue;
    ++out.edges;
    const glm::vec3 a(key[0], key[1], key[2]), b(key[3], key[4], key[5]);
    const float slack = 1e-5f * glm::length(b - a);
    for (int j = 0; j <= 48; ++j) {
      const glm::vec3 x = a + (static_cast<float>(j) / 48.0f) * (b - a);
      rad::Rgb from_p, from_q;
      if (!field_on_border(h, leaves_of[sharing[0]], vv, x, slack, from_p) ||
          !field_on_border(h, leaves_of[sharing[1]], vv, x, slack, from_q)) {
        out.complete = false;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const double scale = std::max({std::fabs(from_p[c]), std::fabs(from_q[c]), floor});
        out.largest = std::max(out.largest, std::fabs(static_cast<double>(from_p[c]) - from_q[c]) / scale);
      }
    }
  }
  return out;
}

}  // namespace test
