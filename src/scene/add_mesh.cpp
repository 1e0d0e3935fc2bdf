// Scene::add_mesh(): a host's indexed triangle mesh in, one polygon per triangle, with the
// host's arrays kept so that results can go back onto its own vertices and triangles. The
// rules are the readers' (LoadOptions): what cannot mean anything (an index out of range, a NaN)
// is an error naming mesh and vertex or triangle; a degenerate triangle is skipped and reported
// with the others of its mesh in one warning, or refused under strict.
// Scene::set_mesh_lightmap_uvs(): a mesh's vertices split for lightmap UVs (lightmap/), checked
// to be the same triangles, so its polygons stay as they are.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "radiosity/scene.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using detail::finite;
bool finite(const glm::vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

/// "5, 17 and 230" or "5, 17, 230, ... and 12 more".
std::string index_list(const std::vector<std::uint32_t>& ids) {
  constexpr std::size_t kShown = 8;
  std::string s;
  for (std::size_t k = 0; k < ids.size() && k < kShown; ++k) {
    if (k > 0) s += (k + 1 == ids.size()) ? " and " : ", ";
    s += std::to_string(ids[k]);
  }
  if (ids.size() > kShown) s += " and " + std::to_string(ids.size() - kShown) + " more";
  return s;
}

}  // namespace

MeshId Scene::add_mesh(const MeshDesc& desc, const LoadOptions& options) {
  const auto id = static_cast<MeshId>(meshes_.size());
  const std::string where =
      "mesh " + std::to_string(id) + " (group '" + std::string(desc.group.empty() ? "default" : desc.group) + "')";
  auto fail = [&](ErrorCode code, const std::string& problem) { throw Error(code, "add_mesh: " + where + ": " + problem); };

  // The arrays and counts, before anything is read.
  if (desc.index_count % 3 != 0)
    fail(ErrorCode::invalid_argument, "index_count " + std::to_string(desc.index_count) + " is not a multiple of 3");
  if (desc.vertex_count > 0 && desc.positions == nullptr)
    fail(ErrorCode::invalid_argument, "positions is null but vertex_count is " + std::to_string(desc.vertex_count));
  if (desc.index_count > 0 && desc.indices == nullptr)
    fail(ErrorCode::invalid_argument, "indices is null but index_count is " + std::to_string(desc.index_count));
  if (desc.vertex_count >= kNone)
    fail(ErrorCode::invalid_argument, "vertex_count " + std::to_string(desc.vertex_count) +
                                          " exceeds what 32-bit indices can address");
  if (desc.triangle_materials == nullptr && desc.material >= materials_.size())
    fail(ErrorCode::invalid_argument, "material id " + std::to_string(desc.material) + " does not exist (scene has " +
                                          std::to_string(materials_.size()) + " materials)");
  const std::size_t vertex_count = desc.vertex_count, triangles = desc.index_count / 3;
  if (polygons_.size() + triangles >= kNone)
    fail(ErrorCode::invalid_argument, std::to_string(triangles) + " triangles would exceed 32-bit polygon ids");

  for (std::size_t v = 0; v < vertex_count; ++v) {
    auto check = [&](bool ok, const char* what) {
      if (!ok) fail(ErrorCode::invalid_scene, std::string(what) + " of vertex " + std::to_string(v) + " is NaN or infinite");
    };
    check(finite(desc.positions[v]), "the position");
    if (!detail::usable_position(desc.positions[v]))
      fail(ErrorCode::invalid_scene, "the position of vertex " + std::to_string(v) +
                                         " has a coordinate beyond +-1e9 (its areas and distances would overflow)");
    if (desc.normals) check(finite(desc.normals[v]), "the normal");
    if (desc.uv0) check(finite(desc.uv0[v]), "uv0");
    if (desc.uv1) check(finite(desc.uv1[v]), "uv1");
  }

  Mesh mesh;
  mesh.positions.assign(desc.positions, desc.positions + vertex_count);
  mesh.indices.assign(desc.indices, desc.indices + desc.index_count);
  if (desc.normals) mesh.normals.assign(desc.normals, desc.normals + vertex_count);
  if (desc.uv0) mesh.uv0.assign(desc.uv0, desc.uv0 + vertex_count);
  if (desc.uv1) mesh.uv1.assign(desc.uv1, desc.uv1 + vertex_count);
  mesh.triangle_polygon.assign(triangles, kNone);
  mesh.source = std::string(desc.source);

  // Polygons go straight into the scene; on an error they (and a group made for this mesh) are
  // taken back, so a throwing call leaves the scene as it was.
  const std::size_t first_polygon = polygons_.size(), groups_before = groups_.size();
  std::vector<std::uint32_t> degenerate;
  try {
    mesh.group = intern_group(desc.group);
    // Geometric growth: many small meshes must not reallocate on every call.
    if (polygons_.capacity() < polygons_.size() + triangles)
      polygons_.reserve(std::max(polygons_.size() + triangles, 2 * polygons_.capacity()));
    for (std::size_t t = 0; t < triangles; ++t) {
      const std::uint32_t* corner = mesh.indices.data() + 3 * t;
      for (int k = 0; k < 3; ++k)
        if (corner[k] >= vertex_count)
          fail(ErrorCode::invalid_scene, "triangle " + std::to_string(t) + ": index " + std::to_string(corner[k]) +
                                             " is out of range (" + std::to_string(vertex_count) + " vertices)");
      const MaterialId material = desc.triangle_materials ? desc.triangle_materials[t] : desc.material;
      if (material >= materials_.size())
        fail(ErrorCode::invalid_argument, "triangle " + std::to_string(t) + ": material id " + std::to_string(material) +
                                              " does not exist (scene has " + std::to_string(materials_.size()) +
                                              " materials)");
      const glm::vec3 &p0 = mesh.positions[corner[0]], &p1 = mesh.positions[corner[1]], &p2 = mesh.positions[corner[2]];
      const detail::TriangleShape shape = detail::triangle_shape(p0, p1, p2);
      if (shape.degenerate) {
        degenerate.push_back(static_cast<std::uint32_t>(t));
        continue;
      }
      Polygon polygon;
      polygon.vertices = {p0, p1, p2};
      polygon.normal = shape.normal;
      polygon.area = shape.area;
      polygon.material = material;
      polygon.group = mesh.group;
      polygon.mesh = id;
      polygon.mesh_triangle = static_cast<std::uint32_t>(t);
      mesh.triangle_polygon[t] = static_cast<PolygonId>(polygons_.size());
      polygons_.push_back(std::move(polygon));
    }
    if (!degenerate.empty() && options.strict)
      fail(ErrorCode::invalid_scene, "triangle " + std::to_string(degenerate.front()) + " is degenerate (zero area)" +
                                         (degenerate.size() > 1
                                              ? " (" + std::to_string(degenerate.size() - 1) + " more degenerate triangles)"
                                              : std::string()));
  } catch (...) {
    polygons_.resize(first_polygon);
    groups_.resize(groups_before);
    throw;
  }
  if (!degenerate.empty())
    add_warning(where + ": " + std::to_string(degenerate.size()) + " degenerate (zero-area) triangle" +
                (degenerate.size() > 1 ? "s" : "") + " skipped: " + index_list(degenerate));
  mesh.polygons = PolygonRange{static_cast<PolygonId>(first_polygon),
                               static_cast<std::uint32_t>(polygons_.size() - first_polygon)};
  meshes_.push_back(std::move(mesh));
  return id;
}

std::vector<MeshId> Scene::add_group_meshes() {
  // Exact position bits as the weld key (+0.0f turns -0 into +0, which compare equal).
  struct Key {
    std::uint32_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = k.x;
      h = h * 0x9E3779B97F4A7C15ull ^ k.y;
      h = h * 0x9E3779B97F4A7C15ull ^ k.z;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  auto key = [](const glm::vec3& p) {
    Key k{};
    const glm::vec3 q = p + glm::vec3(0.0f);
    std::memcpy(&k.x, &q.x, 4);
    std::memcpy(&k.y, &q.y, 4);
    std::memcpy(&k.z, &q.z, 4);
    return k;
  };

  std::vector<std::vector<PolygonId>> by_group(groups_.size());
  for (PolygonId p = 0; p < polygons_.size(); ++p)
    if (polygons_[p].mesh == kNone) by_group[polygons_[p].group].push_back(p);
  std::vector<MeshId> made;
  for (GroupId g = 0; g < by_group.size(); ++g) {
    if (by_group[g].empty()) continue;
    const auto id = static_cast<MeshId>(meshes_.size());
    Mesh mesh;
    mesh.group = g;
    std::unordered_map<Key, std::uint32_t, Hash> vertex;
    auto vertex_of = [&](const glm::vec3& p) {
      const auto [it, added] = vertex.try_emplace(key(p), static_cast<std::uint32_t>(mesh.positions.size()));
      if (added) mesh.positions.push_back(p);
      return it->second;
    };
    for (const PolygonId p : by_group[g]) {
      Polygon& polygon = polygons_[p];
      polygon.mesh = id;
      polygon.mesh_triangle = static_cast<std::uint32_t>(mesh.triangle_polygon.size());
      const std::uint32_t first = vertex_of(polygon.vertices[0]);
      for (std::size_t k = 1; k + 1 < polygon.vertices.size(); ++k) {
        mesh.indices.insert(mesh.indices.end(), {first, vertex_of(polygon.vertices[k]), vertex_of(polygon.vertices[k + 1])});
        mesh.triangle_polygon.push_back(p);
      }
    }
    mesh.polygons = PolygonRange{by_group[g].front(), by_group[g].back() - by_group[g].front() + 1};
    meshes_.push_back(std::move(mesh));
    made.push_back(id);
  }
  return made;
}

void Scene::set_mesh_lightmap_uvs(MeshId id, const std::vector<std::uint32_t>& vertex_origin,
                                  std::vector<std::uint32_t> indices, std::vector<glm::vec2> uv1) {
  auto fail = [&](const std::string& problem) {
    throw Error(ErrorCode::invalid_argument, "set_mesh_lightmap_uvs: mesh " + std::to_string(id) + ": " + problem);
  };
  if (id >= meshes_.size())
    fail("does not exist (scene has " + std::to_string(meshes_.size()) + " meshes)");
  const Mesh& old = meshes_[id];
  const std::size_t count = vertex_origin.size();
  if (indices.size() != old.indices.size())
    fail(std::to_string(indices.size()) + " indices given, the mesh has " + std::to_string(old.indices.size()));
  if (uv1.size() != count)
    fail(std::to_string(uv1.size()) + " uv1 entries for " + std::to_string(count) + " new vertices");
  if (count >= kNone) fail(std::to_string(count) + " new vertices exceed what 32-bit indices can address");
  for (std::size_t v = 0; v < count; ++v) {
    if (vertex_origin[v] >= old.positions.size())
      fail("new vertex " + std::to_string(v) + " copies vertex " + std::to_string(vertex_origin[v]) +
           ", out of range (" + std::to_string(old.positions.size()) + " vertices)");
    if (!finite(uv1[v])) fail("uv1 of new vertex " + std::to_string(v) + " is NaN or infinite");
  }
  // The same triangles: each corner's new vertex copies the vertex it had.
  for (std::size_t c = 0; c < indices.size(); ++c) {
    if (indices[c] >= count)
      fail("triangle " + std::to_string(c / 3) + ": index " + std::to_string(indices[c]) + " is out of range (" +
           std::to_string(count) + " new vertices)");
    if (vertex_origin[indices[c]] != old.indices[c])
      fail("triangle " + std::to_string(c / 3) + ", corner " + std::to_string(c % 3) + ": new vertex " +
           std::to_string(indices[c]) + " copies vertex " + std::to_string(vertex_origin[indices[c]]) +
           ", the corner was vertex " + std::to_string(old.indices[c]));
  }

  // Built aside and moved in, so a throw above (or bad_alloc here) leaves the mesh unchanged.
  std::vector<glm::vec3> positions(count), normals(old.normals.empty() ? 0 : count);
  std::vector<glm::vec2> uv0(old.uv0.empty() ? 0 : count);
  // The host's vertex of each new one: through an earlier split when there was one.
  std::vector<std::uint32_t> host(count);
  for (std::size_t v = 0; v < count; ++v) {
    positions[v] = old.positions[vertex_origin[v]];
    if (!normals.empty()) normals[v] = old.normals[vertex_origin[v]];
    if (!uv0.empty()) uv0[v] = old.uv0[vertex_origin[v]];
    host[v] = old.vertex_origin.empty() ? vertex_origin[v] : old.vertex_origin[vertex_origin[v]];
  }
  Mesh& mesh = meshes_[id];
  mesh.vertex_origin = std::move(host);
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
  mesh.uv0 = std::move(uv0);
  mesh.uv1 = std::move(uv1);
  mesh.indices = std::move(indices);
}

}  // namespace v1
}  // namespace radiosity
