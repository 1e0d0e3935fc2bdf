// Scene construction and validation. Everything that enters a Scene is checked here, so the
// mesher, the estimators and the solvers can trust their input.
#include "radiosity/scene.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "radiosity/version.hpp"
#include "scene/polygon_math.hpp"
#include "core/camera_check.hpp"

namespace radiosity {
inline namespace v1 {

const char* version() noexcept { return RADIOSITY_VERSION_STRING; }

float Bounds::diagonal() const { return glm::length(upper - lower); }

namespace {

std::string describe(const Rgb& c) {
  std::ostringstream s;
  s << '(' << c.x << ", " << c.y << ", " << c.z << ')';
  return s.str();
}

void check_channels(const Material& m, const char* field, const Rgb& value, float upper, bool upper_inclusive) {
  for (int c = 0; c < 3; ++c) {
    float v = value[c];
    bool ok = std::isfinite(v) && v >= 0.0f && (upper_inclusive ? v <= upper : v < upper);
    if (!ok) {
      std::ostringstream s;
      s << "material '" << m.name << "': " << field << " " << describe(value) << " must be finite and in [0, "
        << upper << (upper_inclusive ? "]" : ")") << " per channel";
      throw Error(ErrorCode::invalid_scene, s.str());
    }
  }
}

}  // namespace

Scene::Scene() = default;

MaterialId Scene::add_material(const Material& material) {
  const Material& m = material;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(m.emission[c]) || m.emission[c] < 0.0f)
      throw Error(ErrorCode::invalid_scene, "material '" + m.name + "': emission " + describe(m.emission) +
                                                " must be finite and >= 0 per channel");
  }
  // Reflectance 1 would make a closed scene's system singular (B = E / (1 - rho)).
  check_channels(m, "reflectance", m.reflectance, 1.0f, false);
  check_channels(m, "specular", m.specular, 1.0f, true);
  check_channels(m, "transmittance", m.transmittance, 1.0f, true);
  check_channels(m, "diffuse_transmittance", m.diffuse_transmittance, 1.0f, true);
  // The parts that leave the surface in the radiosity pass must not create energy. Specular
  // transmission is split by Fresnel against specular reflection in the renderer, so it is
  // bounded on its own above.
  check_channels(m, "reflectance + specular + diffuse_transmittance",
                 m.reflectance + m.specular + m.diffuse_transmittance, 1.0f, false);
  if (!std::isfinite(m.specular_exponent) || m.specular_exponent < 0.0f)
    throw Error(ErrorCode::invalid_scene, "material '" + m.name + "': specular_exponent must be finite and >= 0");
  if (!std::isfinite(m.ior) || m.ior <= 0.0f)
    throw Error(ErrorCode::invalid_scene, "material '" + m.name + "': ior must be finite and > 0");
  materials_.push_back(material);
  return static_cast<MaterialId>(materials_.size() - 1);
}

void Scene::set_obstruction_only(PolygonId id, bool obstruction_only) {
  if (id >= polygons_.size())
    throw Error(ErrorCode::invalid_argument, "set_obstruction_only: no polygon " + std::to_string(id) + " (the scene has " +
                                                 std::to_string(polygons_.size()) + ")");
  polygons_[id].obstruction_only = obstruction_only;
}

void Scene::make_two_sided() {
  for (Material& m : materials_) m.two_sided = true;
}

void Scene::reverse_winding(const std::vector<PolygonId>& polygons) {
  std::vector<std::uint8_t> turn(polygons_.size(), 0);
  for (const PolygonId id : polygons) {
    if (id >= polygons_.size())
      throw Error(ErrorCode::invalid_argument, "Scene::reverse_winding: polygon " + std::to_string(id) +
                                                   " does not exist (the scene has " +
                                                   std::to_string(polygons_.size()) + ")");
    turn[id] = 1;
  }
  for (PolygonId id = 0; id < polygons_.size(); ++id) {
    if (!turn[id]) continue;
    Polygon& p = polygons_[id];
    // Corner 0 stays first, so a mesh triangle (a, b, c) becomes (a, c, b) in both places.
    if (p.vertices.size() > 2) std::reverse(p.vertices.begin() + 1, p.vertices.end());
    p.normal = -p.normal;
  }
  for (Mesh& m : meshes_) {
    // Per vertex: bit 0 when a turned triangle uses it, bit 1 when a kept one does.
    std::vector<std::uint8_t> use(m.positions.size(), 0);
    for (std::size_t t = 0; t < m.triangle_polygon.size(); ++t) {
      const PolygonId p = m.triangle_polygon[t];
      if (p == kNone) continue;  // a skipped (degenerate) triangle faces nowhere
      const std::uint8_t bit = turn[p] ? 1 : 2;
      if (turn[p]) std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
      for (std::size_t c = 0; c < 3; ++c) use[m.indices[3 * t + c]] |= bit;
    }
    if (m.normals.empty()) continue;
    for (std::size_t v = 0; v < use.size(); ++v)
      if (use[v] == 1) m.normals[v] = -m.normals[v];
  }
}

void Scene::reverse_winding() {
  std::vector<PolygonId> all(polygons_.size());
  for (PolygonId id = 0; id < all.size(); ++id) all[id] = id;
  reverse_winding(all);
}

GroupId Scene::intern_group(std::string_view name) {
  if (name.empty()) name = "default";
  if (auto id = find_group(name)) return *id;
  groups_.emplace_back(name);
  return static_cast<GroupId>(groups_.size() - 1);
}

std::optional<GroupId> Scene::find_group(std::string_view name) const {
  for (std::size_t i = 0; i < groups_.size(); ++i)
    if (groups_[i] == name) return static_cast<GroupId>(i);
  return std::nullopt;
}

PolygonRange Scene::add_polygon(const std::vector<glm::vec3>& vertices, MaterialId material, std::string_view group) {
  if (material >= materials_.size())
    throw Error(ErrorCode::invalid_argument, "add_polygon: material id " + std::to_string(material) +
                                                 " does not exist (scene has " + std::to_string(materials_.size()) +
                                                 " materials)");
  const std::string where = "polygon " + std::to_string(polygons_.size()) + " (group '" +
                            std::string(group.empty() ? "default" : group) + "')";
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const glm::vec3& v = vertices[i];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw Error(ErrorCode::invalid_scene, where + ": vertex " + std::to_string(i) + " is NaN or infinite");
    if (!detail::usable_position(v))
      throw Error(ErrorCode::invalid_scene, where + ": vertex " + std::to_string(i) +
                                                " has a coordinate beyond +-1e9 (its areas and distances would overflow)");
  }
  detail::CleanPolygon clean = detail::clean_polygon(vertices);
  if (clean.vertices.size() < 3)
    throw Error(ErrorCode::invalid_scene, where + ": degenerate polygon (fewer than 3 distinct, non-collinear vertices)");
  if (clean.area <= detail::kDegenerateAreaRatio * clean.diameter * clean.diameter)
    throw Error(ErrorCode::invalid_scene, where + ": degenerate (zero-area) polygon");

  std::vector<std::vector<glm::vec3>> pieces;
  if (clean.planar && clean.convex) {
    pieces.push_back(std::move(clean.vertices));
  } else {
    pieces = detail::triangulate(clean.vertices, clean.normal);
    add_warning(where + ": " + (clean.planar ? "non-convex" : "non-planar") + " polygon triangulated into " +
                std::to_string(pieces.size()) + " triangles");
  }

  PolygonRange range{static_cast<PolygonId>(polygons_.size()), 0};
  const GroupId gid = intern_group(group);
  for (auto& piece : pieces) {
    Polygon p;
    glm::vec3 n = detail::newell_normal(piece);
    p.area = 0.5f * glm::length(n);
    // Sliver triangles of an ear-clipped polygon can be degenerate; the polygon as a whole is
    // not, so they carry no area and are dropped.
    if (p.area <= detail::kDegenerateAreaRatio * clean.diameter * clean.diameter) continue;
    p.normal = n / (2.0f * p.area);
    p.vertices = std::move(piece);
    p.material = material;
    p.group = gid;
    polygons_.push_back(std::move(p));
    ++range.count;
  }
  return range;
}

void Scene::set_camera(const Camera& camera) {
  const std::string problem = detail::camera_problem(camera);
  if (!problem.empty()) throw Error(ErrorCode::invalid_argument, problem);
  camera_ = camera;
}

void Scene::set_origin(const glm::dvec3& origin) {
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    throw Error(ErrorCode::invalid_argument, "Scene::set_origin: a coordinate is NaN or infinite");
  origin_ = origin;
}

Camera Scene::camera() const {
  if (camera_) return *camera_;
  // Frame the bounding sphere from -z with a 45 degree field of view.
  Bounds b = bounds();
  glm::vec3 centre = 0.5f * (b.lower + b.upper);
  float radius = std::max(0.5f * b.diagonal(), 1e-3f);
  Camera c;
  c.fov_deg = 45.0f;
  float distance = radius / std::sin(glm::radians(0.5f * c.fov_deg));
  c.look_at = centre;
  c.eye = centre - glm::vec3(0.0f, 0.0f, distance);
  c.up = glm::vec3(0.0f, 1.0f, 0.0f);
  return c;
}

Bounds Scene::bounds() const {
  Bounds b;
  bool first = true;
  for (const Polygon& p : polygons_)
    for (const glm::vec3& v : p.vertices) {
      b.lower = first ? v : glm::min(b.lower, v);
      b.upper = first ? v : glm::max(b.upper, v);
      first = false;
    }
  return b;
}

double Scene::total_area() const {
  double a = 0.0;
  for (const Polygon& p : polygons_) a += p.area;
  return a;
}

}  // namespace v1
}  // namespace radiosity
