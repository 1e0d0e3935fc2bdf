// A mesh of a scene-graph format (glTF, Assimp's formats) placed in the world by its node's
// matrix and added to the Scene, with what a reader owes its user at that step: degenerate
// triangles reported at their place in the file, add_mesh()'s errors too.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "io/readers/reader_warnings.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// A mesh as the file gives it, in its node's coordinates: finite positions, optional
/// per-vertex normals and UVs (empty, or one per position), triangles as index triples
/// (counter-clockwise seen from the front, each index below positions.size()).
struct LocalMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uv0, uv1;
  std::vector<std::uint32_t> indices;
};

/// Adds `mesh` placed by the affine `world` matrix, as one Scene mesh of `material` in `group`:
/// positions by the matrix, normals by its inverse transpose (renormalised); a mirroring matrix
/// (negative determinant) turns the winding, so each triangle's corners are swapped to keep it
/// facing out (glTF 2.0, section 3.7.2.1). Degenerate (zero-area) triangles are left out and
/// forgiven in one warning at `where` ("file: meshes[2].primitives[0]"; an Error under strict);
/// returns how many there were. A mesh left without triangles adds nothing. Throws
/// Error{invalid_scene} at `where` for a position the matrix takes beyond float range, and
/// add_mesh()'s errors with `where` in front. `source` becomes Mesh::source.
std::size_t add_placed_mesh(Scene& scene, ReaderWarnings& warnings, LocalMesh mesh, const glm::dmat4& world,
                            MaterialId material, std::string_view group, const std::string& where,
                            const LoadOptions& options, std::string_view source = {});

}  // namespace radiosity::detail
