// Shaft culling between a source and a receiver polygon.
// Based on: E. Haines & J. Wallace, "Shaft culling for efficient ray-traced radiosity",
// Photorealistic Rendering in Computer Graphics (Proc. 2nd Eurographics Workshop on Rendering),
// Springer 1994 (workshop 1991): bound the segments between two objects by a few planes and
// test candidate occluders against them; here the planes are the exact faces of the convex hull
// of the two polygons (edge of one + corner of the other) plus the two front half-spaces, and
// the candidates come from a bounding-volume hierarchy (Kay & Kajiya, "Ray tracing complex
// scenes", SIGGRAPH 1986) with a separating-plane test at the leaves.
#include "form_factors/shaft.hpp"

#include "core/assert.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

namespace radiosity::detail {

void Shaft::add(const glm::vec3& normal, float offset) {
  if (plane_count_ < kMaxPlanes) planes_[static_cast<std::size_t>(plane_count_++)] = HalfSpace{normal, offset};
}

bool Shaft::build(const glm::vec3* a, int na, const glm::vec3& a_normal, const glm::vec3* b, int nb,
                  const glm::vec3& b_normal, float tolerance) {
  RADIOSITY_ASSERT(na >= 1 && na <= 4 && nb >= 3 && nb <= 4);
  plane_count_ = 0;
  corner_count_ = 0;
  tolerance_ = tolerance;
  for (int i = 0; i < na; ++i) corners_[static_cast<std::size_t>(corner_count_++)] = a[i];
  for (int i = 0; i < nb; ++i) corners_[static_cast<std::size_t>(corner_count_++)] = b[i];

  // The two front half-spaces: only segments from the front of `a` to the front of `b` carry
  // energy, so the region is cut by both planes. Either polygon wholly behind the other's
  // plane leaves nothing.
  const float da = glm::dot(a_normal, a[0]), db = glm::dot(b_normal, b[0]);
  bool b_in_front = false, a_in_front = false;
  for (int i = 0; i < nb; ++i) b_in_front |= glm::dot(a_normal, b[i]) - da > tolerance;
  for (int i = 0; i < na; ++i) a_in_front |= glm::dot(b_normal, a[i]) - db > tolerance;
  if (!b_in_front || !a_in_front) return false;
  add(-a_normal, -da);
  add(-b_normal, -db);

  // Faces of the convex hull spanned by an edge of one polygon and a corner of the other. The
  // side of the edge's own polygon is inside (the polygon is convex, so all of it lies there);
  // the plane is a hull face when the other polygon's corners are inside too.
  auto edge_planes = [&](const glm::vec3* p, int np, const glm::vec3* q, int nq) {
    if (np < 3) return;
    glm::vec3 centre(0.0f);
    for (int i = 0; i < np; ++i) centre += p[i];
    centre /= static_cast<float>(np);
    for (int i = 0; i < np; ++i) {
      const glm::vec3& p0 = p[i];
      const glm::vec3 edge = p[(i + 1) % np] - p0;
      for (int k = 0; k < nq; ++k) {
        const glm::vec3 to = q[k] - p0;
        glm::vec3 m = glm::cross(edge, to);
        const float len2 = glm::dot(m, m);
        // Corner on the edge's line: no plane.
        if (!(len2 > 1e-12f * glm::dot(edge, edge) * glm::dot(to, to))) continue;
        m /= std::sqrt(len2);
        const float side = glm::dot(m, centre - p0);
        if (std::fabs(side) <= tolerance) continue;  // corner in p's plane: that plane is already a face
        if (side > 0.0f) m = -m;
        const float d = glm::dot(m, p0);
        bool supporting = true;
        for (int j = 0; j < nq && supporting; ++j) supporting = glm::dot(m, q[j]) - d <= tolerance;
        if (supporting) add(m, d);
      }
    }
  };
  edge_planes(a, na, b, nb);
  edge_planes(b, nb, a, na);
  return true;
}

bool Shaft::excludes_box(const glm::vec3& lower, const glm::vec3& upper) const {
  for (int i = 0; i < plane_count_; ++i) {
    const HalfSpace& h = planes_[static_cast<std::size_t>(i)];
    // The box corner that reaches furthest into the half-space.
    const glm::vec3 p(h.normal.x > 0.0f ? lower.x : upper.x, h.normal.y > 0.0f ? lower.y : upper.y,
                      h.normal.z > 0.0f ? lower.z : upper.z);
    if (glm::dot(h.normal, p) >= h.offset - tolerance_) return true;
  }
  return false;
}

bool Shaft::excludes_polygon(const glm::vec3* corners, int count, const glm::vec3& normal, float plane_offset) const {
  for (int i = 0; i < plane_count_; ++i) {
    const HalfSpace& h = planes_[static_cast<std::size_t>(i)];
    bool outside = true;
    for (int k = 0; k < count && outside; ++k) outside = glm::dot(h.normal, corners[k]) >= h.offset - tolerance_;
    if (outside) return true;
  }
  // The polygon's own plane separates it from the hull when every hull corner is on one side.
  bool above = true, below = true;
  for (int k = 0; k < corner_count_; ++k) {
    const float s = glm::dot(normal, corners_[static_cast<std::size_t>(k)]) - plane_offset;
    above &= s >= -tolerance_;
    below &= s <= tolerance_;
  }
  return above || below;
}

ShaftCuller::ShaftCuller(const std::vector<std::vector<glm::vec3>>& polygons, const std::vector<glm::vec3>& normals) {
  const std::size_t n = polygons.size();
  first_corner_.reserve(n + 1);
  first_corner_.push_back(0);
  normals_ = normals;
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 lo(polygons[i][0]), hi(polygons[i][0]), sum(0.0f);
    for (const glm::vec3& p : polygons[i]) {
      corners_.push_back(p);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      sum += p;
    }
    first_corner_.push_back(static_cast<std::uint32_t>(corners_.size()));
    offsets_.push_back(glm::dot(normals[i], polygons[i][0]));
    lower_.push_back(lo);
    upper_.push_back(hi);
    centre_.push_back(sum / static_cast<float>(polygons[i].size()));
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  if (n == 0) return;
  nodes_.reserve(2 * n);
  nodes_.emplace_back();
  build(0, 0, static_cast<std::uint32_t>(n), 0);
}

// Builds the subtree of node `index` over order_[begin, end): median split of the centroids
// along the longest axis, leaves of up to 4 polygons. An inner node's children are adjacent.
void ShaftCuller::build(std::uint32_t index, std::uint32_t begin, std::uint32_t end, int depth) {
  glm::vec3 lo = lower_[order_[begin]], hi = upper_[order_[begin]];
  glm::vec3 clo = centre_[order_[begin]], chi = clo;
  for (std::uint32_t i = begin; i < end; ++i) {
    lo = glm::min(lo, lower_[order_[i]]);
    hi = glm::max(hi, upper_[order_[i]]);
    clo = glm::min(clo, centre_[order_[i]]);
    chi = glm::max(chi, centre_[order_[i]]);
  }
  nodes_[index].lower = lo;
  nodes_[index].upper = hi;
  if (end - begin <= 4 || depth > 48) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return;
  }
  const glm::vec3 extent = chi - clo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) {
                     const float cx = centre_[x][axis], cy = centre_[y][axis];
                     return cx < cy || (cx == cy && x < y);
                   });
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_[index].first = left;
  nodes_[index].count = 0;
  nodes_.resize(nodes_.size() + 2);
  build(left, begin, mid, depth + 1);
  build(left + 1, mid, end, depth + 1);
}

bool ShaftCuller::test(const Shaft& shaft, std::uint32_t polygon) const {
  const std::uint32_t first = first_corner_[polygon];
  return !shaft.excludes_polygon(&corners_[first], static_cast<int>(first_corner_[polygon + 1] - first),
                                 normals_[polygon], offsets_[polygon]);
}

// Visits the polygons whose node boxes and own test let them into the shaft; stops when
// visit() returns false.
template <typename Visit>
void ShaftCuller::traverse(const Shaft& shaft, const Visit& visit) const {
  if (nodes_.empty()) return;
  std::array<std::uint32_t, 128> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (shaft.excludes_box(node.lower, node.upper)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        if (!visit(order_[i])) return;
    } else {
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }
}

bool ShaftCuller::any(const Shaft& shaft, std::uint32_t skip_a, std::uint32_t skip_b) const {
  bool found = false;
  traverse(shaft, [&](std::uint32_t p) {
    if (p != skip_a && p != skip_b && test(shaft, p)) found = true;
    return !found;
  });
  return found;
}

void ShaftCuller::collect(const Shaft& shaft, std::uint32_t skip, std::vector<std::uint32_t>& out) const {
  const std::size_t before = out.size();
  traverse(shaft, [&](std::uint32_t p) {
    if (p != skip && test(shaft, p)) out.push_back(p);
    return true;
  });
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(before), out.end());
}

}  // namespace radiosity::detail
