// add_placed_mesh() (placed_mesh.hpp): world placement of a reader's mesh. Normals transform by
// the inverse transpose of the matrix's linear part, computed as its cofactor matrix (columns
// b x c, c x a, a x b of its columns a, b, c: the determinant times the inverse transpose),
// which stays defined when a scale flattens the mesh.
#include "io/readers/placed_mesh.hpp"

#include <cmath>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "scene/polygon_math.hpp"

namespace radiosity::detail {

std::size_t add_placed_mesh(Scene& scene, ReaderWarnings& warnings, LocalMesh mesh, const glm::dmat4& world,
                            MaterialId material, std::string_view group, const std::string& where,
                            const LoadOptions& options, std::string_view source) {
  const std::size_t vertices = mesh.positions.size();
  for (std::size_t v = 0; v < vertices; ++v) {
    const glm::dvec4 q = world * glm::dvec4(glm::dvec3(mesh.positions[v]), 1.0);
    mesh.positions[v] = glm::vec3(q);
    if (!std::isfinite(mesh.positions[v].x) || !std::isfinite(mesh.positions[v].y) || !std::isfinite(mesh.positions[v].z))
      throw Error(ErrorCode::invalid_scene,
                  where + ": vertex " + std::to_string(v) + " is not finite once placed (its node's transform is too large)");
  }
  const glm::dmat3 linear(world);
  const double det = glm::determinant(linear);
  if (!mesh.normals.empty()) {
    const glm::dmat3 cofactor =
        glm::dmat3(glm::cross(linear[1], linear[2]), glm::cross(linear[2], linear[0]), glm::cross(linear[0], linear[1])) *
        (det < 0.0 ? -1.0 : 1.0);
    for (glm::vec3& n : mesh.normals) {
      const glm::dvec3 t = cofactor * glm::dvec3(n);
      const double length = glm::length(t);
      n = length > 0.0 && std::isfinite(length) ? glm::vec3(t / length) : glm::vec3(0.0f);
    }
  }
  if (det < 0.0)
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);

  // Degenerate triangles are reported here, at their place in the file, and left out: add_mesh()
  // would skip them too, with a message naming the scene's mesh instead.
  std::vector<std::uint32_t> kept;
  kept.reserve(mesh.indices.size());
  std::vector<std::size_t> degenerate;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (triangle_shape(mesh.positions[a], mesh.positions[b], mesh.positions[c]).degenerate)
      degenerate.push_back(t / 3);
    else
      kept.insert(kept.end(), {a, b, c});
  }
  if (!degenerate.empty()) {
    constexpr std::size_t kListed = 8;
    std::string list;
    for (std::size_t k = 0; k < degenerate.size() && k < kListed; ++k) list += (k ? ", " : "") + std::to_string(degenerate[k]);
    if (degenerate.size() > kListed) list += ", ...";
    warnings.forgive("degenerate triangle", ErrorCode::invalid_scene, where,
                     std::to_string(degenerate.size()) + " degenerate (zero-area) triangle" + (degenerate.size() > 1 ? "s" : "") +
                         " (" + list + ")" + (det == 0.0 ? ", its node's transform flattens it" : ""),
                     "skipped");
  }
  if (kept.empty()) return degenerate.size();

  MeshDesc desc;
  desc.positions = mesh.positions.data();
  desc.vertex_count = vertices;
  desc.indices = kept.data();
  desc.index_count = kept.size();
  desc.material = material;
  desc.group = group;
  desc.normals = mesh.normals.empty() ? nullptr : mesh.normals.data();
  desc.uv0 = mesh.uv0.empty() ? nullptr : mesh.uv0.data();
  desc.uv1 = mesh.uv1.empty() ? nullptr : mesh.uv1.data();
  desc.source = source;
  try {
    scene.add_mesh(desc, options);
  } catch (const Error& e) {
    throw Error(e.code(), where + ": " + e.what());
  }
  return degenerate.size();
}

}  // namespace radiosity::detail
