// Shape helpers: parallelograms, boxes and tessellated spheres built from planar convex polygons
// that face outwards, so that scenes written in code or in the JSON format need no hand-ordered
// vertices.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Appends the polygons of one add_polygon call to a running range (calls are contiguous).
void extend(PolygonRange& total, const PolygonRange& part, bool first) {
  if (first) total.first = part.first;
  total.count += part.count;
}

}  // namespace

PolygonRange add_quad(Scene& scene, glm::vec3 origin, glm::vec3 edge_u, glm::vec3 edge_v, MaterialId material,
                      std::string_view group) {
  if (!finite3(origin) || !finite3(edge_u) || !finite3(edge_v))
    throw Error(ErrorCode::invalid_argument, "add_quad: origin, edge_u and edge_v must be finite");
  const float cross_len = glm::length(glm::cross(edge_u, edge_v));
  if (!(cross_len > 1e-6f * glm::length(edge_u) * glm::length(edge_v)) || cross_len == 0.0f)
    throw Error(ErrorCode::invalid_argument, "add_quad: edge_u and edge_v must be non-zero and not parallel");
  return scene.add_polygon({origin, origin + edge_u, origin + edge_u + edge_v, origin + edge_v}, material, group);
}

PolygonRange add_box(Scene& scene, glm::vec3 lower, glm::vec3 upper, MaterialId material, std::string_view group,
                     const glm::mat4& transform) {
  if (!finite3(lower) || !finite3(upper))
    throw Error(ErrorCode::invalid_argument, "add_box: lower and upper must be finite");
  for (int a = 0; a < 3; ++a)
    if (!(lower[a] < upper[a]))
      throw Error(ErrorCode::invalid_argument, "add_box: lower must be below upper in every coordinate (axis " +
                                                   std::to_string(a) + ")");
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(transform[c][r])) throw Error(ErrorCode::invalid_argument, "add_box: transform must be finite");
  // glm is column-major: transform[column][row]. An affine map has the last row 0 0 0 1.
  if (transform[0][3] != 0.0f || transform[1][3] != 0.0f || transform[2][3] != 0.0f || transform[3][3] != 1.0f)
    throw Error(ErrorCode::invalid_argument, "add_box: transform must be affine (last row 0 0 0 1)");
  const glm::mat3 linear(transform);
  const float det = glm::determinant(linear);
  // Singular relative to the transform's own scale: the box would collapse onto a plane.
  const float scale = glm::length(linear[0]) * glm::length(linear[1]) * glm::length(linear[2]);
  if (!(std::fabs(det) > 1e-6f * scale))
    throw Error(ErrorCode::invalid_argument, "add_box: transform is singular (the box would be flat)");

  const glm::vec3 centre = 0.5f * (lower + upper);
  PolygonRange total;
  bool first = true;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      // The face at lower[axis] or upper[axis], spanned by the other two axes.
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      std::vector<glm::vec3> q(4);
      const float corners[4][2] = {{lower[a], lower[b]}, {upper[a], lower[b]}, {upper[a], upper[b]}, {lower[a], upper[b]}};
      for (int k = 0; k < 4; ++k) {
        q[k][axis] = side == 0 ? lower[axis] : upper[axis];
        q[k][a] = corners[k][0];
        q[k][b] = corners[k][1];
      }
      // Outward in box coordinates; a mirroring transform (det < 0) reverses every orientation.
      const glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
      const bool outward = glm::dot(n, q[0] - centre) > 0.0f;
      if (outward == (det < 0.0f)) std::reverse(q.begin(), q.end());
      for (glm::vec3& p : q) p = glm::vec3(transform * glm::vec4(p, 1.0f));
      extend(total, scene.add_polygon(q, material, group), first);
      first = false;
    }
  }
  return total;
}

PolygonRange add_sphere(Scene& scene, glm::vec3 centre, float radius, MaterialId material, std::string_view group,
                        int segments) {
  if (!finite3(centre)) throw Error(ErrorCode::invalid_argument, "add_sphere: centre must be finite");
  if (!std::isfinite(radius) || !(radius > 0.0f))
    throw Error(ErrorCode::invalid_argument, "add_sphere: radius must be finite and > 0");
  if (segments < 4 || segments > 1024)
    throw Error(ErrorCode::invalid_argument,
                "add_sphere: segments must be in [4, 1024], got " + std::to_string(segments));
  const int rings = (segments + 1) / 2;
  // Polar axis +y (the usual "up" of scenes here); theta from the north pole, phi around y.
  const double pi = glm::pi<double>();
  auto point = [&](int ring, int slice) {
    const double theta = pi * ring / rings, phi = 2.0 * pi * (slice % segments) / segments;
    const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
    return centre + radius * glm::vec3(d);
  };
  const glm::vec3 north = centre + glm::vec3(0.0f, radius, 0.0f), south = centre - glm::vec3(0.0f, radius, 0.0f);

  PolygonRange total;
  bool first = true;
  auto add = [&](std::vector<glm::vec3> poly) {
    // Orient counter-clockwise seen from outside: the normal must point away from the centre.
    glm::vec3 mid(0.0f);
    for (const glm::vec3& p : poly) mid += p;
    mid /= static_cast<float>(poly.size());
    const glm::vec3 n = glm::cross(poly[1] - poly[0], poly[2] - poly[0]);
    if (glm::dot(n, mid - centre) < 0.0f) std::reverse(poly.begin(), poly.end());
    extend(total, scene.add_polygon(poly, material, group), first);
    first = false;
  };
  for (int j = 0; j < segments; ++j) {
    add({north, point(1, j + 1), point(1, j)});
    // Each band quad lies in a plane: its corners are symmetric about the meridian plane
    // through the middle of the slice, and the two rings are parallel circles.
    for (int i = 1; i + 1 < rings; ++i) add({point(i, j), point(i, j + 1), point(i + 1, j + 1), point(i + 1, j)});
    add({south, point(rings - 1, j), point(rings - 1, j + 1)});
  }
  return total;
}

}  // namespace v1
}  // namespace radiosity
