// Scenes: planar polygons with materials, grouped by name, and a camera.
#pragma once

#include <array>
#include <cstddef>
#include <initializer_list>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "radiosity/common.hpp"

namespace radiosity {
inline namespace v1 {

class Brdf;  // brdf.hpp; only the two-pass compositor evaluates it

using MaterialId = std::uint32_t;
using GroupId = std::uint32_t;
using PolygonId = std::uint32_t;
using MeshId = std::uint32_t;
using LightId = std::uint32_t;

/// Surface description. The diffuse part (emission, reflectance, diffuse transmittance) drives
/// radiosity; the specular parts are for the extended first pass and the ray-traced second pass.
/// Every field has a default, so `Material{}` is a grey (0.5) non-emitting diffuse surface.
struct Material {
  std::string name;
  Rgb emission{0.0f};               ///< emitted exitance E, W/m^2 (per scene unit^2), >= 0
  Rgb reflectance{0.5f};            ///< diffuse reflectance rho, each channel in [0, 1)
  Rgb specular{0.0f};               ///< specular reflectance, each channel in [0, 1]
  float specular_exponent = 0.0f;   ///< Phong exponent of the specular lobe; 0 = ideal mirror
  Rgb transmittance{0.0f};          ///< specular transmission tint (glass), each channel in [0, 1]
  float ior = 1.5f;                 ///< index of refraction used when transmittance > 0
  Rgb diffuse_transmittance{0.0f};  ///< translucency, each channel in [0, 1]
  /// Reflects and emits on both sides, each side with a radiosity of its own (a single-sheet
  /// partition wall, a table top as one quad, foliage cards); otherwise the back absorbs
  /// everything and sends nothing.
  bool two_sided = false;
  /// Optional full reflection model for the second pass; null means "derive from the fields
  /// above". Shared and immutable, so copying a Material is cheap.
  std::shared_ptr<const Brdf> brdf;
};

/// The polygons that one add_polygon() call produced: more than one when the input had to be
/// triangulated.
struct PolygonRange {
  PolygonId first = 0;
  std::uint32_t count = 0;
};

/// The corners of a polygon. Up to four (triangles and quads, nearly every polygon) are stored
/// inline, so a polygon costs no heap allocation of its own (a million triangles of
/// Scene::add_mesh() make no million small allocations); more go to the heap. It reads like
/// the std::vector<glm::vec3> it replaces, and converts to and from one.
/// Thread safety: a plain value.
class PolygonVertices {
 public:
  static constexpr std::size_t kInline = 4;

  PolygonVertices() = default;
  PolygonVertices(const glm::vec3* vertices, std::size_t count) { assign(vertices, count); }
  PolygonVertices(std::initializer_list<glm::vec3> vertices) { assign(vertices.begin(), vertices.size()); }
  PolygonVertices(const std::vector<glm::vec3>& vertices) { assign(vertices.data(), vertices.size()); }  // NOLINT: implicit
  PolygonVertices(std::vector<glm::vec3>&& vertices) {  // NOLINT: implicit
    if (vertices.size() > kInline) {
      size_ = vertices.size();
      heap_ = std::move(vertices);
    } else {
      assign(vertices.data(), vertices.size());
    }
  }
  /// A copy as a vector, for functions that take one.
  operator std::vector<glm::vec3>() const { return std::vector<glm::vec3>(begin(), end()); }  // NOLINT: implicit

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const glm::vec3* data() const { return size_ > kInline ? heap_.data() : inline_.data(); }
  glm::vec3* data() { return size_ > kInline ? heap_.data() : inline_.data(); }
  const glm::vec3* begin() const { return data(); }
  const glm::vec3* end() const { return data() + size_; }
  glm::vec3* begin() { return data(); }
  glm::vec3* end() { return data() + size_; }
  const glm::vec3& operator[](std::size_t i) const { return data()[i]; }
  glm::vec3& operator[](std::size_t i) { return data()[i]; }
  const glm::vec3& front() const { return data()[0]; }
  const glm::vec3& back() const { return data()[size_ - 1]; }

  friend bool operator==(const PolygonVertices& a, const PolygonVertices& b) {
    if (a.size_ != b.size_) return false;
    for (std::size_t i = 0; i < a.size_; ++i)
      if (a[i] != b[i]) return false;
    return true;
  }
  friend bool operator!=(const PolygonVertices& a, const PolygonVertices& b) { return !(a == b); }

 private:
  void assign(const glm::vec3* vertices, std::size_t count) {
    size_ = count;
    if (count > kInline) {
      heap_.assign(vertices, vertices + count);
    } else {
      heap_.clear();
      for (std::size_t i = 0; i < count; ++i) inline_[i] = vertices[i];
    }
  }

  std::array<glm::vec3, kInline> inline_{};
  std::vector<glm::vec3> heap_;  ///< used only beyond kInline corners
  std::size_t size_ = 0;
};

/// A planar convex polygon as stored in a Scene (after validation and any triangulation).
struct Polygon {
  PolygonVertices vertices;         ///< counter-clockwise seen from the front
  glm::vec3 normal{0.0f};           ///< unit, right-hand rule of the vertex order
  float area = 0.0f;
  MaterialId material = 0;
  GroupId group = 0;
  MeshId mesh = kNone;                ///< the mesh it came from (Scene::add_mesh()), or kNone
  std::uint32_t mesh_triangle = kNone;  ///< its triangle's index in that mesh, or kNone
  /// Blocks light but is no surface of the view-factor matrix (View3D's obstruction-only
  /// surfaces): view_factor_matrix() and view_factors() give it no row or column, while it
  /// still hides what lies behind it. solve() treats it as any polygon of its material.
  bool obstruction_only = false;
};

/// How forgiving the scene readers are (load_scene(), parse_scene_json()) and
/// Scene::add_mesh().
struct LoadOptions {
  /// false (the default): the readers step over what a renderer would and say so, each kind of
  /// problem in one warning in Scene::warnings() (how many, the first "file:line: ", the next
  /// few places): degenerate (zero-area) faces and faces of fewer than 3 vertices are dropped;
  /// a diffuse reflectance of 1 or more is clamped to 0.99 and Kd + Ks above 0.99 scaled down;
  /// negative colours are clamped to 0; a missing MTL file or an undefined material gives the
  /// default grey; non-planar or non-convex faces are triangulated. true: each such problem
  /// is an Error naming the file and line instead, so a loaded scene has no warnings but
  /// notes. A note reports valid input read exactly as written whose result is probably not
  /// what was meant (a glTF material that is all metal, so radiosity passes no light on from
  /// it); it stays a warning under strict, which would otherwise refuse a valid file.
  bool strict = false;
  /// The library is radiometric (Light): false (the default) reads light intensities as they
  /// are written, W/sr for point and spot lights and W/m^2 for directional lights and skies.
  /// true reads them as photometric, candela and lux, and divides by 683 lm/W
  /// (photometric_to_radiometric()). Read by the JSON scene reader, the glTF reader
  /// (KHR_lights_punctual) and the Assimp reader (its point, spot and directional lights); see
  /// docs/LIGHTS.md.
  bool photometric = false;
  /// true (the default): a model so far from the origin for its size that single precision,
  /// in which Polygon stores positions, would move its corners by 0.1 % of a typical polygon
  /// or more (georeferenced coordinates: a city in UTM, a building at its national-grid
  /// position) is read relative to a round point near its centre, and that point kept as
  /// Scene::origin(). Done by the readers that have the coordinates in double precision: OBJ,
  /// View3D `.vs3`, and glTF (its node matrices: a georeferenced root translation). Assimp's
  /// formats (STL, PLY, FBX, ...) are read in single precision and cannot be moved. false keeps
  /// the file's coordinates as they are; load_scene() then warns (for every format) when single
  /// precision cannot hold them.
  bool local_origin = true;
};

/// An indexed triangle mesh as a host renderer holds it, in meshoptimizer's pointer-and-count
/// style: Scene::add_mesh() reads the arrays during the call and keeps no pointer. The optional
/// arrays are null when absent; each has vertex_count entries (triangle_materials has
/// index_count / 3). Positions are in scene units; triangles are counter-clockwise seen from
/// their front.
struct MeshDesc {
  const glm::vec3* positions = nullptr;
  std::size_t vertex_count = 0;
  const std::uint32_t* indices = nullptr;  ///< three per triangle, into positions
  std::size_t index_count = 0;             ///< a multiple of 3
  MaterialId material = 0;                 ///< of every triangle, unless triangle_materials is given
  const MaterialId* triangle_materials = nullptr;  ///< per triangle; overrides `material`
  std::string_view group;                  ///< the group of every triangle; empty means "default"
  const glm::vec3* normals = nullptr;      ///< per vertex (shading normals; kept, not used by radiosity)
  const glm::vec2* uv0 = nullptr;          ///< per vertex: texture coordinates
  const glm::vec2* uv1 = nullptr;          ///< per vertex: lightmap coordinates
  /// Where the host's mesh came from, kept as Mesh::source (a file reader's place; optional).
  std::string_view source;
};

/// What a Scene keeps of a mesh given to add_mesh(): copies of the host's arrays in its own
/// order, and where each triangle went, so results can be handed back on the host's vertices
/// and triangles.
struct Mesh {
  GroupId group = 0;
  std::vector<glm::vec3> positions;    ///< vertex_count entries
  std::vector<std::uint32_t> indices;  ///< three per triangle, as given
  std::vector<glm::vec3> normals;      ///< empty when the host gave none
  std::vector<glm::vec2> uv0, uv1;     ///< empty when absent
  /// Per triangle: the polygon it became, or kNone when it was skipped (degenerate).
  std::vector<PolygonId> triangle_polygon;
  PolygonRange polygons;               ///< the polygons of its triangles, consecutive (add_mesh())
  /// Where it came from (MeshDesc::source): the glTF reader writes
  /// "nodes[N]: meshes[M].primitives[P]" (the node that places it and the primitive, indices
  /// into the file's arrays), the Assimp reader "nodes 'NAME': meshes[M]"; empty otherwise.
  std::string source;
  /// Empty while the mesh has the host's vertices; after set_mesh_lightmap_uvs() split them,
  /// per vertex the host vertex (as given to add_mesh()) it copies, so that a host's other
  /// per-vertex data (tangents, colours, skin weights) can follow the split.
  std::vector<std::uint32_t> vertex_origin;
};

/// What kind of light a Light is (docs/LIGHTS.md).
enum class LightType {
  point,        ///< an isotropic point at Light::position
  spot,         ///< a point whose light is confined to a cone around Light::direction
  directional,  ///< parallel light from infinitely far away along Light::direction (the sun)
  sky,          ///< light from every direction above the horizon (the zenith is Light::direction)
};

/// The radiance distribution of a LightType::sky over its hemisphere.
enum class SkyModel {
  uniform,       ///< the same radiance L = E / pi from every direction above the horizon
  /// The CIE standard overcast sky (Moon & Spencer 1942; CIE S 011/E:2003 type 16): a zenith
  /// three times as bright as the horizon, L(theta) = Lz (1 + 2 cos theta) / 3 for theta from
  /// the zenith, with E = 7 pi Lz / 9.
  cie_overcast,
};

/// A light that is not a polygon: glTF KHR_lights_punctual's point, spot and directional lights
/// and a sky. The library is radiometric: the units below are watts (W/sr, W/m^2 per scene
/// unit^2, like Material::emission); LoadOptions::photometric converts candela and lux when a
/// scene file is read. A light emits `intensity x color` per channel. Radiosity lights every
/// element with it as the first shot (its direct irradiance by shadow rays), the renderers
/// sample it directly; see docs/LIGHTS.md.
/// Thread safety: a plain value.
struct Light {
  LightType type = LightType::point;
  std::string name;         ///< for messages and per-light results; may be empty
  /// The light group this light belongs to (SolveOptions::separate_light_groups,
  /// Solution::relight()); empty means its own, named after the light. A light group named like
  /// a group of emitting polygons shares their weight.
  std::string light_group;
  Rgb color{1.0f};          ///< each channel finite and >= 0; multiplies intensity
  /// point, spot: radiant intensity in W/sr (on the axis and inside the inner cone for a spot).
  /// directional: irradiance in W/m^2 on a surface facing the light. sky: the irradiance in
  /// W/m^2 that an unobstructed horizontal surface (facing the zenith) receives from the whole
  /// sky. Finite and >= 0.
  float intensity = 0.0f;
  glm::vec3 position{0.0f};  ///< point, spot: where the light is (scene units); unused otherwise
  /// spot, directional: the direction the light travels (spot: its axis); sky: the zenith.
  /// Normalised by Scene::add_light(); (0, 0, 0) means the default: straight down (0, -1, 0)
  /// for spot and directional lights, up (0, 1, 0) for a sky's zenith. Unused for a point.
  glm::vec3 direction{0.0f};
  /// spot: full intensity within inner_cone_deg of the axis, none beyond outer_cone_deg, and
  /// between them the smooth falloff of KHR_lights_punctual: t = clamp((cos a - cos outer) /
  /// (cos inner - cos outer), 0, 1), intensity x t^2 at angle a. 0 <= inner <= outer <= 90.
  float inner_cone_deg = 0.0f;
  float outer_cone_deg = 45.0f;
  SkyModel sky = SkyModel::uniform;  ///< sky: its radiance distribution
};

/// Lumens per watt by which LoadOptions::photometric divides: the luminous efficacy of light
/// at 555 nm, the definition of the candela (glTF's lights are in candela and lux).
inline constexpr float kLumensPerWatt = 683.0f;

/// A photometric light quantity (candela, lux) as the radiometric one the library uses (W/sr,
/// W/m^2): value / 683 lm/W. Thread safety: pure.
constexpr float photometric_to_radiometric(float photometric) { return photometric / kLumensPerWatt; }

/// Pinhole camera. `fov_deg` is the vertical field of view in degrees.
struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 0.0f};
  glm::vec3 look_at{0.0f, 0.0f, 1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_deg = 45.0f;
};

/// Axis-aligned box.
struct Bounds {
  glm::vec3 lower{0.0f};
  glm::vec3 upper{0.0f};
  float diagonal() const;
};

/// Polygons, materials, groups, lights and a camera. Everything is validated on entry, so a Scene that
/// exists is usable by every solver.
/// Thread safety: const member functions may be called concurrently; mutation needs exclusive access.
class RADIOSITY_API Scene {
 public:
  Scene();

  /// Adds a material and returns its id. Throws Error{invalid_scene} naming the material and
  /// field when a value is NaN/infinite, emission < 0, reflectance outside [0, 1) or another
  /// coefficient outside [0, 1].
  MaterialId add_material(const Material& material);

  /// Adds a polygon (3 or more vertices, counter-clockwise seen from the side it faces).
  /// Consecutive duplicate and collinear vertices are dropped. A non-planar or non-convex polygon
  /// is triangulated (ear clipping in its best-fit plane) and a warning recorded.
  /// `group` names the surface for per-group results; empty means "default".
  /// Throws Error{invalid_scene} for a NaN or infinite coordinate or one beyond +-1e9 (the areas and
  /// normals, computed in float, would overflow), fewer than 3 distinct vertices,
  /// a zero-area (degenerate) polygon, or Error{invalid_argument} for an unknown material id.
  PolygonRange add_polygon(const std::vector<glm::vec3>& vertices, MaterialId material,
                           std::string_view group = {});

  /// Adds an indexed triangle mesh: one polygon per triangle (Polygon::mesh and mesh_triangle
  /// say where it came from), with copies of the host's arrays in meshes(). Cost: linear, a few
  /// reallocations of the scene's arrays and no allocation per triangle (PolygonVertices keeps
  /// a triangle's corners inline): about 0.1 s for a million triangles (bench_add_mesh).
  /// Throws Error{invalid_argument} naming the mesh for an index_count that is not a multiple
  /// of 3, a null array whose count is not 0, or an unknown material id (naming the triangle);
  /// Error{invalid_scene} naming the mesh and the vertex or triangle for a NaN or infinite
  /// value, a position coordinate beyond +-1e9, or an index out of range. A degenerate (zero-area) triangle is skipped, and all of a
  /// mesh's skipped triangles listed by index in one warning (warnings()); with
  /// options.strict it is an Error{invalid_scene} instead. When it throws the scene is
  /// unchanged. Thread safety: mutates the scene.
  MeshId add_mesh(const MeshDesc& mesh, const LoadOptions& options = {});
  const std::vector<Mesh>& meshes() const { return meshes_; }
  /// Gives mesh `mesh` lightmap coordinates by splitting its vertices (what
  /// generate_lightmap_uvs() returns): new vertex i copies host vertex vertex_origin[i] (its
  /// position, and its normal and uv0 when the mesh has them) and gets uv1[i]; `indices` replace
  /// the mesh's, one new vertex per corner of the same triangles in the same order, so
  /// vertex_origin[indices[c]] must be the corner's old index. Polygons and triangle_polygon do
  /// not change (the geometry is the same); a Solution solved before keeps the old vertices.
  /// Mesh::vertex_origin then names each new vertex's host vertex (through earlier splits).
  /// Throws Error{invalid_argument} naming the mesh for an unknown mesh, sizes that disagree
  /// (indices.size() must stay, uv1 has one entry per new vertex), an index or origin out of
  /// range, a corner whose new vertex does not copy its old one, or a NaN or infinite uv1; the
  /// mesh is then unchanged. Thread safety: mutates the scene.
  void set_mesh_lightmap_uvs(MeshId mesh, const std::vector<std::uint32_t>& vertex_origin,
                             std::vector<std::uint32_t> indices, std::vector<glm::vec2> uv1);

  /// Gives the polygons that belong to no mesh (add_polygon(), add_quad(), cornell_box(), the
  /// readers) an indexed triangle mesh per group, so that mesh results
  /// (Solution::mesh_vertex_values()), lightmaps (bake_lightmap()) and `radiosity bake` reach
  /// them: corners at bit-identical positions become one vertex (an OBJ's faces that share a
  /// `v`), and each polygon a fan of triangles that all name it in Mesh::triangle_polygon (a
  /// quad's two triangles read the whole quad). The polygons themselves do not change, so
  /// neither does any solve; each gets Polygon::mesh and its first triangle's index. A group
  /// mesh's Mesh::polygons spans its first to its last polygon (others may lie between).
  /// Returns the new meshes' ids in group order: none for a group whose polygons all belong to
  /// meshes. Cost: linear in the polygons' corners. Thread safety: mutates the scene.
  std::vector<MeshId> add_group_meshes();

  /// Makes every material two-sided (Material::two_sided), for models whose winding cannot be
  /// trusted (CLI `--two-sided`): a closed room wound outwards then lights its inside. Costs a
  /// second radiosity per element. Thread safety: mutates the scene.
  void make_two_sided();

  /// Turns polygons over, as if the file had been written with their winding reversed: each
  /// keeps its first corner and takes the others in reverse order, its normal negated (its area
  /// unchanged). A mesh's triangles follow their polygons (their second and third indices
  /// swapped), so that mesh and polygons still face the same way and per-vertex results stay
  /// aligned with the host's vertices; a vertex normal is negated when every triangle that uses
  /// it was turned. For one-sided models wound the wrong way (CLI `--reverse-winding`): above
  /// all a closed room or enclosure wound outwards, whose inside is otherwise dark and whose
  /// view factors are 0 (find_polygons_facing_outward() finds such polygons). Unlike
  /// make_two_sided() it keeps one radiosity per element, and it is what view factors need:
  /// they are taken on fronts only. The first form turns `polygons` (an id listed twice is
  /// turned once), the second every polygon. Throws Error{invalid_argument} naming an unknown
  /// id, the scene then unchanged. Cost: linear in the corners. Thread safety: mutates the scene.
  void reverse_winding(const std::vector<PolygonId>& polygons);
  void reverse_winding();

  /// Adds a light (Light) and returns its id, with `direction` normalised and its default
  /// filled in. Throws Error{invalid_scene} naming the light (its name and id) and the field
  /// for a NaN or infinite value, a negative intensity or colour channel, cones outside
  /// 0 <= inner_cone_deg <= outer_cone_deg <= 90, or a direction that cannot be normalised.
  /// Thread safety: mutates the scene.
  LightId add_light(const Light& light);
  /// The lights, by LightId.
  const std::vector<Light>& lights() const { return lights_; }

  const std::vector<Material>& materials() const { return materials_; }
  const Material& material(MaterialId id) const { return materials_.at(id); }
  const std::vector<Polygon>& polygons() const { return polygons_; }
  /// Marks polygon `id` obstruction-only (Polygon::obstruction_only) or not. Throws
  /// Error{invalid_argument} for an unknown id. Thread safety: mutates the scene.
  void set_obstruction_only(PolygonId id, bool obstruction_only = true);
  /// Group names, indexed by GroupId, in order of first use.
  const std::vector<std::string>& groups() const { return groups_; }
  std::optional<GroupId> find_group(std::string_view name) const;

  void set_camera(const Camera& camera);
  bool has_camera() const { return camera_.has_value(); }
  /// The camera set on the scene, or one that frames the scene's bounds from -z.
  Camera camera() const;

  /// The point of the file's coordinate system that the scene's (0, 0, 0) stands for, in
  /// double precision: every position of the scene (polygons, meshes, lights, the camera) is
  /// relative to it. (0, 0, 0) unless a reader moved a model that lay far from the origin
  /// (LoadOptions::local_origin). The writers add it back to the positions they write
  /// (write_ply(), write_mesh_ply(), write_baked_gltf(), save_view3d()), so outputs are in the
  /// file's coordinates; view factors and radiosity do not depend on it.
  glm::dvec3 origin() const { return origin_; }
  /// Sets origin(); it moves nothing (the positions are already relative to it). Throws
  /// Error{invalid_argument} for a NaN or infinite coordinate. Thread safety: mutates the scene.
  void set_origin(const glm::dvec3& origin);

  Bounds bounds() const;
  double total_area() const;
  /// Non-fatal problems found while building (triangulated polygons, ...).
  const std::vector<std::string>& warnings() const { return warnings_; }
  void add_warning(std::string text) { warnings_.push_back(std::move(text)); }

 private:
  GroupId intern_group(std::string_view name);

  std::vector<Material> materials_;
  std::vector<Polygon> polygons_;
  std::vector<Mesh> meshes_;
  std::vector<Light> lights_;
  std::vector<std::string> groups_;
  std::optional<Camera> camera_;
  glm::dvec3 origin_{0.0};
  std::vector<std::string> warnings_;
};

/// How two polygons of a scene conflict (find_overlaps()).
enum class OverlapKind {
  coincident,        ///< (nearly) coplanar and their interiors overlap with positive area
  interpenetrating,  ///< their interiors cross: an edge of one passes through the other's interior
};

/// One conflicting pair of polygons, `first < second` (indices into Scene::polygons()).
struct PolygonOverlap {
  PolygonId first = 0;
  PolygonId second = 0;
  OverlapKind kind = OverlapKind::coincident;
  glm::vec3 point{0.0f};  ///< a point where they meet: the middle of the shared region or crossing
  bool same_facing = false;  ///< their normals point the same way (a positive dot product)

  /// Coincident and facing the same way: which of them is in front is decided by rounding.
  bool z_fighting() const { return kind == OverlapKind::coincident && same_facing; }
  /// Coincident and facing apart: one lies against the other (a box's bottom on a floor, a wall
  /// modelled once per room), in contact, lit correctly.
  bool lying_against() const { return kind == OverlapKind::coincident && !same_facing; }
};

/// Pairs of polygons that are coincident or interpenetrate, sorted by (first, second). Distances
/// below 2e-5 of the scene's bounding-box diagonal (plus a polygon's own deviation from
/// planarity) count as touching, so polygons that share edges or vertices, T-junctions, a block
/// standing on a floor (touching it along its bottom edges) and the pieces of a triangulated
/// polygon are not reported; two polygons stacked closer than that are (z-fighting).
/// A diagnostic: form factors, view_factors() and solve() accept such scenes and light them
/// as the path tracer does (a ray that reaches a back face is blocked, so contact regions are
/// dark); solve() warns about coincident pairs that face the same way (z-fighting), where which
/// surface is in front is rounding. Cost: a bounding-box hierarchy (Embree's
/// collision query) and an exact test per nearby pair, about linear in the number of polygons.
/// Throws Error{internal} if Embree cannot create a device.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API std::vector<PolygonOverlap> find_overlaps(const Scene& scene);

/// Emitting polygons (material emission > 0 in some channel) whose front sees no polygon at
/// all, in polygon order: all of their light leaves the scene, usually because the polygon is
/// wound the wrong way (it faces the sky instead of the room). Each emitter casts a few hundred
/// cosine-distributed rays (256; at least 64 when the scene has thousands of emitters) from
/// stratified points just in front of it and is reported when none hits anything, front or
/// back of any polygon; an emitter that sees only a speck smaller than about 1/256 of its
/// cosine-weighted view may be reported too. Deterministic: a fixed seed, the same answer at
/// any thread count. solve() warns about such emitters (SolveReport::warnings). Cost: a BVH
/// over the scene (Embree) and the rays. Throws Error{internal} if Embree cannot create a device.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API std::vector<PolygonId> find_emitters_facing_away(const Scene& scene);

/// What find_polygons_facing_outward() found.
struct OutwardFacing {
  std::vector<PolygonId> polygons;  ///< in polygon order
  double area = 0.0;                ///< theirs, scene units^2
  double one_sided_area = 0.0;      ///< of every polygon tested (the one-sided ones)
  /// The scene has light and none of it is inside what the polygons found enclose: only
  /// directional or sky lights, point and spot lights and emitting polygons whose rays get
  /// away (a light counts as inside when all of 14 rays from a point or spot light, or 15 of
  /// 16 from an emitting polygon's front, meet a polygon). The polygons then face out of an
  /// object seen from outside (a glTF asset, a CAD part under a sky), as they should. A room
  /// wound outward and lit only through its windows reads so too (its walls' outsides take the
  /// sun on their fronts). False when the scene has no light: nothing tells the two apart.
  bool lit_from_outside = false;
  /// Whether they are more than half of the one-sided area and the scene is not lit from
  /// outside: a closed model wound outward (a roof under an open sky is found too, but it is not
  /// most of a scene). `radiosity check` warns then, and so does solve() when most of the
  /// emitted light escaped.
  bool looks_wound_outward() const {
    return one_sided_area > 0.0 && area > 0.5 * one_sided_area && !lit_from_outside;
  }
};

/// One-sided polygons (material neither two-sided nor translucent, nor glass) that look wound
/// the wrong way: their front sees no polygon while their back sees polygons all around, as
/// every polygon of a closed room or enclosure wound outward does (a CAD solid's facets point
/// out of the solid). Each side casts 16 cosine-distributed rays from stratified points (a
/// 4 x 4 grid, directions shuffled against the points); a polygon is reported when at most 1
/// of its front's rays and at least 15 of its back's meet a polygon. An exterior seen alone (a
/// box with nothing around it) is reported too, and so is a roof under an open sky (its back
/// sees the building's inside), so the caller judges the share of the one-sided area and where
/// the light is (OutwardFacing::looks_wound_outward(), OutwardFacing::lit_from_outside). Rays cannot judge a polygon coincident with another
/// (find_overlaps(): a box's bottom on a floor), so such pairs are reported so that turning the
/// polygons found leaves them facing opposite ways (in contact), not the same way: of a pair
/// facing the same way one (when rays found both: the one whose surface, the polygons joined
/// to it by shared edges, the rays found wound outward, else the larger: the floor, not the
/// box's bottom, also where the floor is exported as facets smaller than the bottom), of a
/// pair in contact both or neither. Scene::reverse_winding() turns the polygons found over. Deterministic
/// (a fixed seed). Cost: a BVH over the scene, 32 rays per one-sided polygon (16 per emitting one), and find_overlaps(). Throws Error{internal} if Embree cannot create a
/// device. Thread safety: concurrent calls are safe.
RADIOSITY_API OutwardFacing find_polygons_facing_outward(const Scene& scene);
/// The same, with find_overlaps(scene)'s result that the caller already has (it is most of the
/// cost for a large scene: 0.5 s at 246k polygons). Throws Error{invalid_argument} when an
/// overlap names a polygon the scene does not have.
RADIOSITY_API OutwardFacing find_polygons_facing_outward(const Scene& scene, const std::vector<PolygonOverlap>& overlaps);

/// What find_inconsistent_winding() found.
struct InconsistentWinding {
  std::vector<PolygonId> polygons;  ///< in polygon order
  double area = 0.0;                ///< theirs, scene units^2
  std::size_t surfaces = 0;         ///< connected surfaces that hold some of them
};

/// One-sided polygons (as find_polygons_facing_outward() takes them) wound opposite to the
/// polygons they share edges with: an exporter's slip, a face flipped by hand. Such a polygon
/// faces away from the light its neighbours take and comes out black. Two polygons that share
/// an edge (both ends at exactly the same positions, as an indexed mesh's faces or a triangulated
/// polygon's pieces do, and no third polygon on it) are wound alike when they run along it in
/// opposite directions. Over each surface connected by such edges the polygons fall into two
/// orientations; those of the one holding less area are reported (on a tie, the one without the
/// surface's lowest polygon id). No rays: a closed model wound outward throughout is consistent
/// (find_polygons_facing_outward() finds that). Scene::reverse_winding() turns the polygons
/// found. Deterministic. Cost: a sort of the polygons' edges and a walk over them, no rays.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API InconsistentWinding find_inconsistent_winding(const Scene& scene);

/// Adds the parallelogram origin, origin + edge_u, origin + edge_u + edge_v, origin + edge_v,
/// facing edge_u x edge_v (counter-clockwise seen from that side). Units are scene units.
/// Throws Error{invalid_argument} for a non-finite value or parallel (or zero) edges, and what
/// Scene::add_polygon throws. Thread safety: mutates `scene`.
RADIOSITY_API PolygonRange add_quad(Scene& scene, glm::vec3 origin, glm::vec3 edge_u, glm::vec3 edge_v,
                                    MaterialId material, std::string_view group = {});

/// Adds the box [lower, upper] (each coordinate of `lower` strictly below that of `upper`),
/// mapped by the affine `transform` (default identity; a mirroring transform is allowed, the
/// faces still face out), as 6 planar quads whose normals point out of the box. The returned
/// range covers all six. Throws Error{invalid_argument} for non-finite or empty bounds, a
/// transform that is not finite, not affine (last row other than 0 0 0 1) or singular.
/// Thread safety: mutates `scene`.
RADIOSITY_API PolygonRange add_box(Scene& scene, glm::vec3 lower, glm::vec3 upper, MaterialId material,
                                   std::string_view group = {}, const glm::mat4& transform = glm::mat4(1.0f));

/// Adds a UV sphere inscribed in the sphere of `radius` (> 0) around `centre`: `segments`
/// slices in longitude, in [4, 1024], and ceil(segments / 2) bands in latitude, the bands
/// next to the poles as triangles and the rest as planar quads (isosceles trapezoids), all
/// convex, counter-clockwise seen from outside (normals point out). The polyhedron's area is
/// below 4 pi r^2 by a relative 5 pi^2 / (6 segments^2): 0.8 % at 32 segments, 0.2 % at 64.
/// Throws Error{invalid_argument} naming the argument for a non-finite centre, a radius that is
/// not finite and > 0, or segments outside [4, 1024]. Thread safety: mutates `scene`.
RADIOSITY_API PolygonRange add_sphere(Scene& scene, glm::vec3 centre, float radius, MaterialId material,
                                      std::string_view group = {}, int segments = 32);

/// The Cornell box as published by the Cornell Program of Computer Graphics: geometry in mm,
/// camera at (278, 273, -800) looking +z with a 39.3077 degree vertical field of view, measured
/// white/red/green reflectances, light radiance (17, 12, 4) (so E = pi * L) and light reflectance
/// 0.78. Groups: floor, ceiling, back_wall, red_wall, green_wall, light, short_block, tall_block.
/// The ceiling has a hole where the light sits, so no two surfaces overlap.
RADIOSITY_API Scene cornell_box();

/// Which blocks of cornell_box_specular() are specular; the other one stays white.
enum class CornellSpecular {
  mirror_and_glass,  ///< tall block a mirror, short block glass
  mirror,            ///< tall block a mirror, short block white ("the mirror Cornell box")
  glass,             ///< short block glass, tall block white ("the glass Cornell box")
};

/// cornell_box() with specular blocks, for the two-pass compositor and its path-traced
/// references: the tall block an ideal mirror (material "mirror": reflectance 0, specular 0.95,
/// specular_exponent 0), the short block clear glass (material "glass": reflectance 0,
/// transmittance 1, ior 1.5). Same geometry, groups, camera and other materials, in the same
/// order; the specular materials are added after "light". The blocks have no bottom face: they
/// stand on the floor, which closes the glass block. Also shipped as
/// examples/scenes/cornell_specular.obj (mirror and glass).
/// Thread safety: may be called concurrently.
RADIOSITY_API Scene cornell_box_specular(CornellSpecular blocks = CornellSpecular::mirror_and_glass);

}  // namespace v1
}  // namespace radiosity
