// glTF 2.0 reader (.gltf with embedded or external buffers, .glb). Implements the Khronos glTF 2.0
// specification (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html): the GLB container
// (section 4.4), accessors with their byte strides and sparse storage (3.6, 5.1), the node
// hierarchy and its transforms (3.5), primitive modes and winding (3.7.2.1), cameras (3.10) and
// the metallic-roughness material (3.9), with the Khronos extensions
// KHR_materials_emissive_strength, KHR_materials_transmission, KHR_materials_ior and
// KHR_mesh_quantization, and KHR_lights_punctual (docs/LIGHTS.md). docs/SCENE_GLTF.md has the
// mapping.
//
// The file is read by read_gltf_file() (gltf_model.hpp), which checks the GLB container and
// every reference of the JSON before tinygltf parses them; every accessor is checked
// (GltfAccessors) before a byte of it is read, and every vertex index here: a broken file is an
// Error naming the file and the place ("scene.glb: meshes[2].primitives[0]: accessor 7
// (POSITION): ..."), never a crash.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "core/constants.hpp"
#include "io/readers/gltf_model.hpp"
#include "io/readers/local_origin.hpp"
#include "io/readers/material_mapping.hpp"
#include "io/readers/placed_light.hpp"
#include "io/readers/placed_mesh.hpp"
#include "io/readers/reader_files.hpp"
#include "io/readers/reader_warnings.hpp"
#include "io/readers/readers.hpp"
#include "io/readers/texture_mean.hpp"

namespace radiosity::detail {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// The model, read into a Scene.

class GltfReader {
 public:
  GltfReader(const Source& src, const tinygltf::Model& model, const LoadContext& ctx, const LoadOptions& options)
      : src_(src), model_(model), accessors_(src, model), ctx_(ctx), options_(options), warnings_(options.strict) {}

  Scene read() {
    const std::vector<std::pair<int, glm::dmat4>> placed = place_nodes();
    // A model far from the origin for its size (a georeferenced root translation) is placed
    // relative to a point near it: the world matrices are double, the positions float.
    glm::dmat4 shift(1.0);
    if (options_.local_origin) {
      const glm::dvec3 origin = local_origin(placed);
      scene_.set_origin(origin);
      shift[3] = glm::dvec4(-origin, 1.0);
    }
    for (const auto& [n, placement] : placed) {
      const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(n)];
      const glm::dmat4 world = shift * placement;
      if (node.mesh >= 0) add_node_mesh(n, node, world);
      if (node.camera >= 0) add_camera(n, node, world);
      add_node_light(n, node, world);
    }
    if (scene_.polygons().empty())
      src_.fail(ErrorCode::parse_error, "",
                skipped_triangles_ ? "has no triangles that are not degenerate"
                                   : "has no triangles in its scene (no node of it places a mesh of triangles)");
    warnings_.move_to(scene_);
    return std::move(scene_);
  }

 private:
  /// The nodes of the default scene with their world matrices (section 3.5.3), depth first,
  /// children in order; checked to form a tree with finite transforms.
  std::vector<std::pair<int, glm::dmat4>> place_nodes() const {
    const std::vector<int> roots = scene_roots();
    std::vector<bool> visited(model_.nodes.size(), false);
    std::vector<std::pair<int, glm::dmat4>> stack, placed;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
      const auto [n, parent] = stack.back();
      stack.pop_back();
      const std::string place = "nodes[" + std::to_string(n) + "]";
      if (visited[static_cast<std::size_t>(n)])
        src_.fail(ErrorCode::parse_error, place,
                  "reached twice from the scene's roots (a node has at most one parent, and the hierarchy no cycles)");
      visited[static_cast<std::size_t>(n)] = true;
      const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(n)];
      const glm::dmat4 world = parent * local_matrix(node, place);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          if (!std::isfinite(world[c][r]))
            src_.fail(ErrorCode::invalid_scene, place, "its world transform (the product of its ancestors') is not finite");
      placed.emplace_back(n, world);
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.emplace_back(*it, world);
    }
    return placed;
  }

  /// Scene::origin() for the placed meshes' triangles in world space (LocalOriginFinder). It
  /// reads the accessors the main pass reads, with the same checks, so a broken one fails here
  /// with the message that pass would give; modes without triangles are left to that pass.
  glm::dvec3 local_origin(const std::vector<std::pair<int, glm::dmat4>>& placed) {
    LocalOriginFinder finder;
    for (const auto& [n, world] : placed) {
      const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(n)];
      if (node.mesh < 0) continue;
      const auto m = static_cast<std::size_t>(node.mesh);
      for (std::size_t p = 0; p < model_.meshes[m].primitives.size(); ++p) {
        const tinygltf::Primitive& primitive = model_.meshes[m].primitives[p];
        const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
        const auto position = primitive.attributes.find("POSITION");
        if (mode < TINYGLTF_MODE_TRIANGLES || mode > TINYGLTF_MODE_TRIANGLE_FAN || position == primitive.attributes.end())
          continue;
        const std::string place = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
        const std::vector<float> f = read_floats(position->second, place, "POSITION", TINYGLTF_TYPE_VEC3);
        std::vector<std::uint32_t> corners;
        if (primitive.indices >= 0) {
          corners = read_indices(primitive.indices, place, f.size() / 3);
        } else {
          corners.resize(f.size() / 3);
          std::iota(corners.begin(), corners.end(), 0u);
        }
        const std::vector<std::uint32_t> t = triangles(mode, corners, place, false);
        for (std::size_t k = 0; k + 2 < t.size(); k += 3) {
          glm::dvec3 triangle[3];
          for (int c = 0; c < 3; ++c) {
            const std::size_t v = 3 * static_cast<std::size_t>(t[k + static_cast<std::size_t>(c)]);
            triangle[c] = glm::dvec3(world * glm::dvec4(f[v], f[v + 1], f[v + 2], 1.0));
          }
          finder.add_polygon(triangle, 3);
        }
      }
    }
    return finder.origin();
  }

  /// The default scene's root nodes (section 3.5.1): `scene`, else the first scene; without
  /// scenes, every node that is no other node's child.
  std::vector<int> scene_roots() const {
    if (!model_.scenes.empty()) {
      const int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      return model_.scenes[static_cast<std::size_t>(s)].nodes;
    }
    std::vector<bool> child(model_.nodes.size(), false);
    for (const tinygltf::Node& node : model_.nodes)
      for (int c : node.children) child[static_cast<std::size_t>(c)] = true;
    std::vector<int> roots;
    for (std::size_t n = 0; n < model_.nodes.size(); ++n)
      if (!child[n]) roots.push_back(static_cast<int>(n));
    return roots;
  }

  /// `values` (at `place`) as n finite numbers, or `fallback` when the file leaves them out.
  std::vector<double> numbers(const std::vector<double>& values, std::size_t n, const std::string& place,
                              std::vector<double> fallback) const {
    if (values.empty()) return fallback;
    if (values.size() != n)
      src_.fail(ErrorCode::parse_error, place, std::to_string(n) + " numbers expected (got " + std::to_string(values.size()) + ")");
    // Every value read through here becomes a float.
    for (double v : values)
      if (!(std::fabs(v) <= static_cast<double>(FLT_MAX)))
        src_.fail(ErrorCode::parse_error, place, "a number is NaN, infinite or beyond float range");
    return values;
  }

  /// The node's matrix, or its translation x rotation x scale (section 3.5.2).
  glm::dmat4 local_matrix(const tinygltf::Node& node, const std::string& place) const {
    if (!node.matrix.empty()) {
      const std::vector<double> m = numbers(node.matrix, 16, place + ".matrix", {});
      glm::dmat4 out;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[c][r] = m[static_cast<std::size_t>(4 * c + r)];  // column-major
      if (out[0][3] != 0.0 || out[1][3] != 0.0 || out[2][3] != 0.0 || out[3][3] != 1.0)
        src_.fail(ErrorCode::parse_error, place + ".matrix", "not an affine transform (its last row is not 0 0 0 1)");
      return out;
    }
    const std::vector<double> t = numbers(node.translation, 3, place + ".translation", {0.0, 0.0, 0.0});
    const std::vector<double> q = numbers(node.rotation, 4, place + ".rotation", {0.0, 0.0, 0.0, 1.0});
    const std::vector<double> s = numbers(node.scale, 3, place + ".scale", {1.0, 1.0, 1.0});
    glm::dquat rotation(q[3], q[0], q[1], q[2]);  // glTF stores x y z w
    const double length = glm::length(rotation);
    if (!(length > 0.0)) src_.fail(ErrorCode::parse_error, place + ".rotation", "the zero quaternion is no rotation");
    rotation /= length;  // the file's quaternion is unit up to rounding
    glm::dmat4 out = glm::mat4_cast(rotation);
    for (int r = 0; r < 3; ++r) {
      out[0][r] *= s[0];
      out[1][r] *= s[1];
      out[2][r] *= s[2];
    }
    out[3] = glm::dvec4(t[0], t[1], t[2], 1.0);
    return out;
  }

  // --- accessors ------------------------------------------------------------------------------

  /// A vertex attribute's elements as floats, n per element; every value finite.
  std::vector<float> read_floats(int index, const std::string& place, const std::string& role, int type) const {
    const CheckedAccessor c = accessors_.check(index, place, role, {type}, false);
    const auto n = static_cast<std::size_t>(c.components);
    const bool normalized = c.accessor->normalized;
    std::vector<float> out(c.count * n, 0.0f);
    auto element = [&](std::size_t i, const unsigned char* p) {
      for (std::size_t k = 0; k < n; ++k)
        out[i * n + k] = static_cast<float>(component_value(p + k * c.component_bytes, c.component_type, normalized));
    };
    if (c.base)
      for (std::size_t i = 0; i < c.count; ++i) element(i, c.base + i * c.stride);
    accessors_.for_each_sparse(c, place, element);
    for (std::size_t v = 0; v < out.size(); ++v)
      if (!std::isfinite(out[v]))
        src_.fail(ErrorCode::parse_error, place, c.what + ": element " + std::to_string(v / n) + " is NaN or infinite");
    return out;
  }

  /// A primitive's indices, each checked against the vertex count.
  std::vector<std::uint32_t> read_indices(int index, const std::string& place, std::size_t vertices) const {
    const CheckedAccessor c = accessors_.check(index, place, "indices", {TINYGLTF_TYPE_SCALAR}, true);
    std::vector<std::uint32_t> out(c.count, 0);
    auto element = [&](std::size_t i, const unsigned char* p) {
      out[i] = static_cast<std::uint32_t>(component_value(p, c.component_type, false));
    };
    if (c.base)
      for (std::size_t i = 0; i < c.count; ++i) element(i, c.base + i * c.stride);
    accessors_.for_each_sparse(c, place, element);
    for (std::size_t i = 0; i < out.size(); ++i)
      if (out[i] >= vertices)
        src_.fail(ErrorCode::parse_error, place, c.what + ": element " + std::to_string(i) + " is vertex " +
                                                     std::to_string(out[i]) + ", out of range (" + std::to_string(vertices) +
                                                     " vertices)");
    return out;
  }

  // --- meshes ---------------------------------------------------------------------------------

  void add_node_mesh(int n, const tinygltf::Node& node, const glm::dmat4& world) {
    const auto m = static_cast<std::size_t>(node.mesh);
    const tinygltf::Mesh& mesh = model_.meshes[m];
    const std::string group = !node.name.empty() ? node.name : !mesh.name.empty() ? mesh.name : "mesh" + std::to_string(m);
    const std::string node_place = "nodes[" + std::to_string(n) + "]";
    if (node.skin >= 0)
      warnings_.forgive("skin", ErrorCode::invalid_scene, src_.where(node_place),
                        "skin " + std::to_string(node.skin) + " is not applied",
                        "the mesh is read as stored (its bind pose), placed by the node");
    const std::vector<double>& weights = !node.weights.empty() ? node.weights : mesh.weights;
    const bool morphed = std::any_of(weights.begin(), weights.end(), [](double w) { return w != 0.0; });
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      const std::string place = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
      if (morphed && !mesh.primitives[p].targets.empty())
        warnings_.forgive("morph targets", ErrorCode::invalid_scene, src_.where(place),
                          "morph target weights are not applied", "the base shape is read");
      add_primitive(mesh.primitives[p], place, node_place, group, world);
    }
  }

  /// The triangles of a primitive's corners (section 3.7.2.1): a list, a strip or a fan.
  /// `say`: warn about an incomplete triangle (once per primitive: not in the first look).
  std::vector<std::uint32_t> triangles(int mode, const std::vector<std::uint32_t>& v, const std::string& place,
                                       bool say = true) {
    std::vector<std::uint32_t> t;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      t.assign(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 3 * 3));
      if (v.size() % 3 != 0 && say)
        warnings_.forgive("incomplete triangle", ErrorCode::parse_error, src_.where(place),
                          std::to_string(v.size()) + " indices are not a whole number of triangles",
                          "the last " + std::to_string(v.size() % 3) + " ignored");
    } else if (v.size() >= 3) {
      t.reserve(3 * (v.size() - 2));
      for (std::size_t i = 0; i + 2 < v.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
          t.insert(t.end(), {v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]});
        else
          t.insert(t.end(), {v[i + 1], v[i + 2], v[0]});
      }
    }
    return t;
  }

  void add_primitive(const tinygltf::Primitive& primitive, const std::string& place, const std::string& node_place,
                     const std::string& group, const glm::dmat4& world) {
    const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
      static const char* const kNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      warnings_.forgive("points or lines", ErrorCode::parse_error, src_.where(place),
                        std::string("mode ") + kNames[mode] + " has no area", "skipped");
      return;
    }
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN)
      src_.fail(ErrorCode::parse_error, place + ".mode", std::to_string(mode) + " is not a primitive mode (0 to 6)");
    auto attribute = [&](const char* name) {
      auto it = primitive.attributes.find(name);
      return it == primitive.attributes.end() ? -1 : it->second;
    };
    const int position_accessor = attribute("POSITION");
    if (position_accessor < 0) src_.fail(ErrorCode::parse_error, place, "has no POSITION attribute");
    const std::vector<float> p = read_floats(position_accessor, place, "POSITION", TINYGLTF_TYPE_VEC3);
    const std::size_t vertices = p.size() / 3;
    auto optional = [&](const char* name, int type) {
      const int a = attribute(name);
      if (a < 0) return std::vector<float>();
      std::vector<float> values = read_floats(a, place, name, type);
      if (values.size() / static_cast<std::size_t>(components_of(type)) != vertices)
        src_.fail(ErrorCode::parse_error, place,
                  "accessor " + std::to_string(a) + " (" + name + ") has " +
                      std::to_string(values.size() / static_cast<std::size_t>(components_of(type))) +
                      " elements, POSITION has " + std::to_string(vertices));
      return values;
    };
    const std::vector<float> normals = optional("NORMAL", TINYGLTF_TYPE_VEC3);
    const std::vector<float> uv0 = optional("TEXCOORD_0", TINYGLTF_TYPE_VEC2);
    const std::vector<float> uv1 = optional("TEXCOORD_1", TINYGLTF_TYPE_VEC2);

    std::vector<std::uint32_t> corners;
    if (primitive.indices >= 0) {
      corners = read_indices(primitive.indices, place, vertices);
    } else {
      corners.resize(vertices);
      std::iota(corners.begin(), corners.end(), 0u);
    }
    LocalMesh local;
    local.indices = triangles(mode, corners, place);
    local.positions.resize(vertices);
    for (std::size_t v = 0; v < vertices; ++v) local.positions[v] = glm::vec3(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    if (!normals.empty()) {
      local.normals.resize(vertices);
      for (std::size_t v = 0; v < vertices; ++v)
        local.normals[v] = glm::vec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
    }
    auto to_vec2 = [](const std::vector<float>& f, std::vector<glm::vec2>& out) {
      out.resize(f.size() / 2);
      for (std::size_t v = 0; v < out.size(); ++v) out[v] = glm::vec2(f[2 * v], f[2 * v + 1]);
    };
    to_vec2(uv0, local.uv0);
    to_vec2(uv1, local.uv1);
    if (local.indices.empty()) return;
    const MaterialId id = material(primitive.material);
    // Mesh::source: what write_baked_gltf() finds the primitive by.
    if (add_placed_mesh(scene_, warnings_, std::move(local), world, id, group,
                        src_.where(place + " (placed by " + node_place + ")"), options_, node_place + ": " + place) > 0)
      skipped_triangles_ = true;
  }

  // --- lights (KHR_lights_punctual) -----------------------------------------------------------

  /// The light a node carries (its extension's "light" index into the root's lights): point,
  /// spot and directional map onto Light (docs/LIGHTS.md) at the node's world position, shining
  /// down its world -Z; intensities as written (W/sr, W/m^2) or, under LoadOptions::photometric,
  /// candela and lux / 683. `range` (a cut-off the library does not have) is ignored with a
  /// warning, an unknown type is skipped with one.
  void add_node_light(int n, const tinygltf::Node& node, const glm::dmat4& world) {
    const auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end()) return;
    const std::string place = "nodes[" + std::to_string(n) + "].extensions.KHR_lights_punctual";
    if (!ext->second.IsObject() || !ext->second.Has("light") || !ext->second.Get("light").IsNumber())
      src_.fail(ErrorCode::parse_error, place, "has no light index (\"light\": an integer)");
    const double index = ext->second.Get("light").GetNumberAsDouble();
    if (!(index >= 0.0 && index < static_cast<double>(model_.lights.size()) && index == std::floor(index)))
      src_.fail(ErrorCode::parse_error, place + ".light",
                std::to_string(index) + " is not an index into the " + std::to_string(model_.lights.size()) +
                    " lights of extensions.KHR_lights_punctual.lights");
    const auto k = static_cast<std::size_t>(index);
    const tinygltf::Light& in = model_.lights[k];
    const std::string where = "extensions.KHR_lights_punctual.lights[" + std::to_string(k) + "]";
    Light light;
    if (in.type == "point") {
      light.type = LightType::point;
    } else if (in.type == "spot") {
      light.type = LightType::spot;
      light.inner_cone_deg = static_cast<float>(glm::degrees(in.spot.innerConeAngle));
      light.outer_cone_deg = static_cast<float>(glm::degrees(in.spot.outerConeAngle));
    } else if (in.type == "directional") {
      light.type = LightType::directional;
    } else {
      warnings_.forgive("unknown light type", ErrorCode::parse_error, src_.where(where),
                        "type " + in_quotes(in.type) + " is not point, spot or directional", "skipped");
      return;
    }
    if (in.range > 0.0)
      warnings_.forgive("light range", ErrorCode::invalid_scene, src_.where(where),
                        "range " + std::to_string(in.range) + " is not supported (lights reach everything)", "ignored");
    light.name = in.name.empty() ? "light " + std::to_string(k) : in.name;
    if (in.color.size() == 3)
      light.color = Rgb(static_cast<float>(in.color[0]), static_cast<float>(in.color[1]), static_cast<float>(in.color[2]));
    light.intensity = static_cast<float>(in.intensity);
    add_placed_light(scene_, light, world, glm::dvec3(0.0), glm::dvec3(0.0, 0.0, -1.0), options_,
                     src_.where(where) + ": (on " + place + ")");
  }

  // --- cameras --------------------------------------------------------------------------------

  /// The first perspective camera becomes the scene's: it looks down its node's -Z with +Y up
  /// (section 3.10.1), its yfov is the vertical field of view; aspect ratio and clipping planes
  /// are the renderer's business.
  void add_camera(int n, const tinygltf::Node& node, const glm::dmat4& world) {
    const std::string place = "nodes[" + std::to_string(n) + "]";
    const tinygltf::Camera& camera = model_.cameras[static_cast<std::size_t>(node.camera)];
    const std::string name = "camera " + std::to_string(node.camera) + (camera.name.empty() ? "" : " " + in_quotes(camera.name));
    if (camera.type != "perspective") {
      warnings_.forgive("orthographic camera", ErrorCode::invalid_scene, src_.where(place),
                        name + " is " + (camera.type.empty() ? "of no type" : camera.type) + "; the renderers have pinhole cameras only",
                        "ignored");
      return;
    }
    if (camera_set_) {
      warnings_.forgive("more cameras", ErrorCode::invalid_scene, src_.where(place),
                        name + ": only the scene's first perspective camera is used", "ignored");
      return;
    }
    const glm::dvec3 eye(world[3]);
    const glm::dvec3 forward = glm::normalize(glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0));
    const glm::dvec3 up = glm::normalize(glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0));
    Camera c;
    c.eye = glm::vec3(eye);
    c.look_at = glm::vec3(eye + forward);
    c.up = glm::vec3(up);
    c.fov_deg = static_cast<float>(glm::degrees(camera.perspective.yfov));
    try {
      scene_.set_camera(c);
    } catch (const Error& e) {
      src_.fail(e.code(), place, name + ": " + e.what());
    }
    camera_set_ = true;
  }

  // --- materials ------------------------------------------------------------------------------

  /// A number of an extension object, or `fallback` when absent.
  double extension_number(const tinygltf::ExtensionMap& extensions, const char* extension, const char* key,
                          double fallback, const std::string& place) const {
    auto it = extensions.find(extension);
    if (it == extensions.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
    const tinygltf::Value& v = it->second.Get(key);
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
      src_.fail(ErrorCode::parse_error, place + ".extensions." + extension + "." + key, "must be a finite number");
    return v.GetNumberAsDouble();
  }

  /// A texture's mean (linear; decoded from sRGB when `srgb`), or nullopt, with a warning,
  /// when its image cannot be read (a missing file, a format stb_image does not decode).
  std::optional<Rgb> texture_mean(int texture, bool srgb, const std::string& place) {
    if (texture < 0) return std::nullopt;
    if (static_cast<std::size_t>(texture) >= model_.textures.size())
      src_.fail(ErrorCode::parse_error, place, "texture " + std::to_string(texture) + " does not exist");
    const int source = model_.textures[static_cast<std::size_t>(texture)].source;
    auto unreadable = [&](const std::string& why) -> std::optional<Rgb> {
      warnings_.forgive("unreadable texture", ErrorCode::file_not_found, src_.where(place),
                        "texture " + std::to_string(texture) + ": " + why, "its factor alone is used");
      return std::nullopt;
    };
    if (source < 0 || static_cast<std::size_t>(source) >= model_.images.size())
      return unreadable("has no image in a format that is read (PNG, JPEG; not KTX2 or WebP)");
    const auto key = std::make_pair(source, srgb);
    if (auto it = texture_means_.find(key); it != texture_means_.end()) {
      if (!it->second.first) return unreadable(it->second.second);
      return it->second.first;
    }
    const tinygltf::Image& image = model_.images[static_cast<std::size_t>(source)];
    const std::string image_name = "image " + std::to_string(source) + (image.uri.empty() || is_data_uri(image.uri) ? "" : " " + in_quotes(image.uri));
    std::optional<Rgb> mean;
    std::string why;
    if (image.bufferView >= 0) {
      const auto [bytes, length] = accessors_.buffer_view(image.bufferView, "images[" + std::to_string(source) + "]", image_name);
      mean = mean_of_encoded_image(bytes, length, srgb, why);
    } else if (auto it = ctx_.uri_image_bytes.find(source); it != ctx_.uri_image_bytes.end()) {
      mean = mean_of_encoded_image(it->second.data(), it->second.size(), srgb, why);
    } else {
      why = "its file was not found or could not be read";
    }
    if (!mean) why = image_name + ": " + why;
    texture_means_[key] = {mean, why};
    if (!mean) return unreadable(why);
    return mean;
  }

  float clamped_unit(double v, const std::string& place, const std::string& what) {
    if (v >= 0.0 && v <= 1.0) return static_cast<float>(v);
    const float out = static_cast<float>(std::clamp(v, 0.0, 1.0));
    warnings_.forgive("glTF factor out of range", ErrorCode::invalid_scene, src_.where(place),
                      what + " " + std::to_string(v) + " must be in [0, 1]", "clamped to " + std::to_string(out));
    return out;
  }

  /// The scene material of glTF material `index` (-1: none, the default grey), made once.
  MaterialId material(int index) {
    if (index < 0) {
      if (!default_material_) {
        Material grey;
        grey.name = "default";
        default_material_ = scene_.add_material(grey);
      }
      return *default_material_;
    }
    if (auto it = materials_.find(index); it != materials_.end()) return it->second;
    const std::string place = "materials[" + std::to_string(index) + "]";
    Material m = to_material(model_.materials[static_cast<std::size_t>(index)], index, place);
    MaterialId id;
    try {
      id = scene_.add_material(m);
    } catch (const Error& e) {
      src_.fail(e.code(), place, e.what());
    }
    materials_.emplace(index, id);
    return id;
  }

  /// glTF's metallic-roughness material as docs/SCENE_GLTF.md maps it.
  Material to_material(const tinygltf::Material& g, int index, const std::string& place) {
    Material m;
    m.name = g.name.empty() ? "material" + std::to_string(index) : g.name;
    const std::string pbr_place = place + ".pbrMetallicRoughness";
    const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;

    // Base colour: the factor, times the mean of its texture (section 3.9.2).
    const std::vector<double> f = numbers(pbr.baseColorFactor, 4, pbr_place + ".baseColorFactor", {1.0, 1.0, 1.0, 1.0});
    Rgb base(static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2]));
    std::string base_what = "base colour";
    if (const std::optional<Rgb> mean = texture_mean(pbr.baseColorTexture.index, true, pbr_place + ".baseColorTexture")) {
      base *= *mean;
      base_what = "base colour (baseColorFactor x the mean of its texture)";
    }
    base = clamp_colour(base, kMaxForgivenAlbedo, 1.0f, warnings_, "glTF base colour out of range", src_.where(place),
                        base_what, "a diffuse reflectance (1 or more would create energy)", "in [0, 1)");

    float metallic = clamped_unit(pbr.metallicFactor, pbr_place + ".metallicFactor", "metallicFactor");
    float roughness = clamped_unit(pbr.roughnessFactor, pbr_place + ".roughnessFactor", "roughnessFactor");
    if (const std::optional<Rgb> mean = texture_mean(pbr.metallicRoughnessTexture.index, false, pbr_place + ".metallicRoughnessTexture")) {
      metallic *= std::clamp(mean->z, 0.0f, 1.0f);  // metalness in blue, roughness in green
      roughness *= std::clamp(mean->y, 0.0f, 1.0f);
    }

    // Emission: a radiance (glTF's emissive is the colour the surface shows, scaled by
    // KHR_materials_emissive_strength), so the exitance is pi times it.
    const std::vector<double> e = numbers(g.emissiveFactor, 3, place + ".emissiveFactor", {0.0, 0.0, 0.0});
    Rgb emissive(static_cast<float>(e[0]), static_cast<float>(e[1]), static_cast<float>(e[2]));
    if (const std::optional<Rgb> mean = texture_mean(g.emissiveTexture.index, true, place + ".emissiveTexture")) emissive *= *mean;
    double strength = extension_number(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0, place);
    if (strength < 0.0) {
      warnings_.forgive("glTF factor out of range", ErrorCode::invalid_scene, src_.where(place),
                        "KHR_materials_emissive_strength.emissiveStrength " + std::to_string(strength) + " must be >= 0",
                        "0 used");
      strength = 0.0;
    }
    emissive = clamp_colour(emissive, FLT_MAX, FLT_MAX, warnings_, "glTF emissiveFactor out of range", src_.where(place),
                            "emissiveFactor", "an emitted radiance", ">= 0");
    m.emission = kPi * static_cast<float>(strength) * emissive;

    double ior = extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5, place);
    if (!(ior > 0.0)) {
      warnings_.forgive("glTF ior out of range", ErrorCode::invalid_scene, src_.where(place),
                        "KHR_materials_ior.ior " + std::to_string(ior) + " must be > 0", "1.5 used");
      ior = 1.5;
    }
    float transmission = clamped_unit(
        extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0, place),
        place + ".extensions.KHR_materials_transmission.transmissionFactor", "transmissionFactor");
    if (transmission > 0.0f) {
      auto ext = g.extensions.find("KHR_materials_transmission");
      const tinygltf::Value& texture = ext->second.Get("transmissionTexture");
      if (texture.IsObject() && texture.Has("index") && texture.Get("index").IsInt())
        if (const std::optional<Rgb> mean = texture_mean(texture.Get("index").GetNumberAsInt(), false,
                                                         place + ".extensions.KHR_materials_transmission.transmissionTexture"))
          transmission *= std::clamp(mean->x, 0.0f, 1.0f);  // in red
    }

    m.two_sided = g.doubleSided;
    if (transmission > 0.0f) {
      // Metallic and roughness are not read: the transmitting material is a smooth dielectric.
      set_transmission(m, base, transmission, static_cast<float>(ior));
    } else {
      set_metallic_roughness(m, base, metallic, roughness, static_cast<float>(ior));
      // Valid and read as written, but a hand-written material that gives only its base colour
      // is this metal, and radiosity would pass no light on from it without a word.
      if (metallic >= 1.0f)
        warnings_.note("all metal", src_.where(place + (g.name.empty() ? "" : " " + in_quotes(g.name))),
                       "metallic 1 (glTF's default when metallicFactor is absent): a metal has no diffuse reflectance, "
                       "so radiosity passes no light on from it",
                       "set metallicFactor 0 for a diffuse surface");
    }
    return m;
  }

  const Source& src_;
  const tinygltf::Model& model_;
  const GltfAccessors accessors_;
  const LoadContext& ctx_;
  const LoadOptions& options_;
  ReaderWarnings warnings_;
  Scene scene_;
  std::map<int, MaterialId> materials_;
  std::optional<MaterialId> default_material_;
  std::map<std::pair<int, bool>, std::pair<std::optional<Rgb>, std::string>> texture_means_;
  bool camera_set_ = false;
  bool skipped_triangles_ = false;
};

}  // namespace

Scene load_gltf(const fs::path& path, const LoadOptions& options) {
  const GltfFile file = read_gltf_file(path);
  return GltfReader(file.src, file.model, file.ctx, options).read();
}

}  // namespace radiosity::detail
