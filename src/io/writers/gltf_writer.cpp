// write_baked_gltf(): a scene with its solution baked in, as glTF 2.0 (Khronos specification,
// https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html) that any viewer shows lit.
//
// glTF has no lightmap slot, and a viewer lights a PBR material itself. The baked light is
// therefore shown through KHR_materials_unlit, whose colour is baseColorFactor x
// baseColorTexture x COLOR_0 and nothing else: the factor is the surface's diffuse reflectance,
// and the light comes either per vertex (COLOR_0) or per texel (the base colour texture, read
// through TEXCOORD_1). Never both, since the viewer would multiply them.
//
// From a glTF source the output is that file, re-serialised by tinygltf with every buffer merged
// into one and the new data appended: each primitive a Scene mesh came from (Mesh::source) gets
// its new attributes; vertices split for lightmap UVs (Mesh::vertex_origin) are gathered from
// every attribute the primitive has, whatever its type, so skins and morph targets follow.
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "io/readers/gltf_model.hpp"
#include "io/writers/png_encode.hpp"
#include "radiosity/io.hpp"

namespace radiosity {
namespace detail {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUnlit = "KHR_materials_unlit";

/// The output's one buffer: the source's buffers, then whatever is appended, each piece aligned
/// to 4 bytes (section 3.6.2.4: an accessor's offset is a multiple of its component size).
class BufferBuilder {
 public:
  explicit BufferBuilder(tinygltf::Model& model) : model_(model) {}

  /// Moves every buffer of the model into one (buffer 0), bufferViews following.
  void merge_buffers() {
    std::vector<std::size_t> offset(model_.buffers.size());
    for (std::size_t b = 0; b < model_.buffers.size(); ++b) {
      align();
      offset[b] = data_.size();
      data_.insert(data_.end(), model_.buffers[b].data.begin(), model_.buffers[b].data.end());
    }
    for (tinygltf::BufferView& view : model_.bufferViews) {
      view.byteOffset += offset[static_cast<std::size_t>(view.buffer)];
      view.buffer = 0;
    }
    model_.buffers.clear();
  }

  /// A new bufferView holding `bytes`; `target` is ARRAY_BUFFER or ELEMENT_ARRAY_BUFFER (0: none).
  int add_view(const void* bytes, std::size_t size, int target) {
    align();
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data_.size();
    view.byteLength = size;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(bytes);
    data_.insert(data_.end(), p, p + size);
    model_.bufferViews.push_back(std::move(view));
    return static_cast<int>(model_.bufferViews.size() - 1);
  }

  /// A tightly packed accessor over a new bufferView.
  int add_accessor(const void* bytes, std::size_t count, int component_type, int type, bool normalized, int target,
                   std::vector<double> min = {}, std::vector<double> max = {}) {
    const std::size_t size = count * component_size(component_type) * static_cast<std::size_t>(components_of(type));
    tinygltf::Accessor a;
    a.bufferView = add_view(bytes, size, target);
    a.componentType = component_type;
    a.type = type;
    a.count = count;
    a.normalized = normalized;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    model_.accessors.push_back(std::move(a));
    return static_cast<int>(model_.accessors.size() - 1);
  }

  /// Float vectors (VEC2 or VEC3) of `n` components each, with their bounds when `bounds`.
  int add_floats(const float* values, std::size_t count, int type, bool bounds) {
    const auto n = static_cast<std::size_t>(components_of(type));
    std::vector<double> lo, hi;
    if (bounds && count > 0) {
      lo.assign(n, HUGE_VAL);
      hi.assign(n, -HUGE_VAL);
      for (std::size_t i = 0; i < count * n; ++i) {
        lo[i % n] = std::min(lo[i % n], static_cast<double>(values[i]));
        hi[i % n] = std::max(hi[i % n], static_cast<double>(values[i]));
      }
    }
    return add_accessor(values, count, TINYGLTF_COMPONENT_TYPE_FLOAT, type, false, TINYGLTF_TARGET_ARRAY_BUFFER,
                        std::move(lo), std::move(hi));
  }

  int add_indices(const std::vector<std::uint32_t>& indices) {
    return add_accessor(indices.data(), indices.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, false,
                        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }

  /// Hands the data to the model as its only buffer, named `uri` (empty: the GLB's BIN chunk).
  void finish(const std::string& uri) {
    tinygltf::Buffer buffer;
    buffer.data = std::move(data_);
    buffer.uri = uri;
    model_.buffers.push_back(std::move(buffer));
  }

 private:
  void align() { data_.resize((data_.size() + 3) / 4 * 4, 0); }

  tinygltf::Model& model_;
  std::vector<unsigned char> data_;
};

/// What one Scene mesh shows: its light per vertex (already scaled for display) or its lightmap.
struct MeshLight {
  std::vector<glm::vec3> colours;     ///< clamp(exposure x value), per mesh vertex
  std::vector<glm::vec3> irradiance;  ///< W/m^2 per mesh vertex (_IRRADIANCE)
  int texture = -1;                   ///< the lightmap's glTF texture, or -1: vertex colours
};

class Writer {
 public:
  Writer(const Scene& scene, const Solution& solution, const GltfBakeOptions& options, tinygltf::Model& model)
      : scene_(scene), solution_(solution), options_(options), model_(model), buffer_(model) {}

  BufferBuilder& buffer() { return buffer_; }

  /// Display values and lightmap textures of every mesh.
  void prepare_light() {
    light_.resize(scene_.meshes().size());
    for (MeshId id = 0; id < scene_.meshes().size(); ++id) {
      const Mesh& mesh = scene_.meshes()[id];
      MeshLight& out = light_[id];
      const std::vector<Rgb> values = solution_.mesh_vertex_values(id, options_.quantity);
      const std::vector<Rgb> irradiance = solution_.mesh_vertex_values(id, Quantity::irradiance);
      if (values.size() != mesh.positions.size())
        throw Error(ErrorCode::invalid_argument,
                    "write_baked_gltf: mesh " + std::to_string(id) + " has " + std::to_string(mesh.positions.size()) +
                        " vertices, the solution " + std::to_string(values.size()) +
                        " (solve after changing its vertices, e.g. after generate_lightmap_uvs())");
      out.irradiance.assign(irradiance.begin(), irradiance.end());
      const bool lightmap = id < options_.lightmaps.size() && !options_.lightmaps[id].pixels.empty();
      if (lightmap) {
        if (mesh.uv1.size() != mesh.positions.size())
          throw Error(ErrorCode::invalid_argument,
                      "write_baked_gltf: mesh " + std::to_string(id) + " has a lightmap but no UV1");
        out.texture = add_lightmap_texture(options_.lightmaps[id], id);
      } else {
        out.colours.resize(values.size());
        for (std::size_t v = 0; v < values.size(); ++v)
          out.colours[v] = glm::clamp(options_.exposure * glm::vec3(values[v]), 0.0f, 1.0f);
      }
    }
  }

  /// An unlit material showing mesh `id`'s light on `material`: a new one per use, since each
  /// mesh's lightmap is its own texture.
  int add_material(MaterialId material, MeshId id, const std::string& name, bool double_sided) {
    const Material& m = scene_.material(material);
    tinygltf::Material out;
    out.name = name;
    out.doubleSided = double_sided;
    Rgb factor = options_.quantity == Quantity::radiosity ? Rgb(1.0f) : m.reflectance;
    if (emits(m)) factor = glm::clamp(options_.exposure * m.emission, 0.0f, 1.0f);
    out.pbrMetallicRoughness.baseColorFactor = {factor.x, factor.y, factor.z, 1.0};
    out.pbrMetallicRoughness.metallicFactor = 0.0;
    out.pbrMetallicRoughness.roughnessFactor = 1.0;
    if (light_[id].texture >= 0 && !emits(m)) {
      out.pbrMetallicRoughness.baseColorTexture.index = light_[id].texture;
      out.pbrMetallicRoughness.baseColorTexture.texCoord = 1;
    }
    out.extensions[kUnlit] = tinygltf::Value(tinygltf::Value::Object());
    model_.materials.push_back(std::move(out));
    return static_cast<int>(model_.materials.size() - 1);
  }

  /// Adds mesh `id`'s light to `primitive`, whose vertices are the mesh's: COLOR_0 (or, with a
  /// lightmap, TEXCOORD_1 from the mesh's UV1), and _IRRADIANCE. An emitter's primitive shows
  /// its material's colour only.
  void add_light(tinygltf::Primitive& primitive, MeshId id, bool emitter, const std::vector<std::uint32_t>* subset) {
    const Mesh& mesh = scene_.meshes()[id];
    const MeshLight& light = light_[id];
    primitive.attributes.erase("COLOR_0");
    auto gathered = [&](const auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      if (!subset) return values;
      std::vector<T> out;
      out.reserve(subset->size());
      for (std::uint32_t v : *subset) out.push_back(values[v]);
      return out;
    };
    if (light.texture >= 0) {
      const std::vector<glm::vec2> uv1 = gathered(mesh.uv1);
      primitive.attributes["TEXCOORD_1"] = buffer_.add_floats(&uv1[0].x, uv1.size(), TINYGLTF_TYPE_VEC2, false);
    } else if (!emitter) {
      const std::vector<glm::vec3> colours = gathered(light.colours);
      primitive.attributes["COLOR_0"] = buffer_.add_floats(&colours[0].x, colours.size(), TINYGLTF_TYPE_VEC3, false);
    }
    const std::vector<glm::vec3> irradiance = gathered(light.irradiance);
    primitive.attributes["_IRRADIANCE"] = buffer_.add_floats(&irradiance[0].x, irradiance.size(), TINYGLTF_TYPE_VEC3, false);
  }

  static bool emits(const Material& m) { return m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f; }

  /// The extension is listed once in extensionsUsed (not required: without it a viewer shows a
  /// lit material of the same colours).
  void use_unlit() {
    if (std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), kUnlit) == model_.extensionsUsed.end())
      model_.extensionsUsed.push_back(kUnlit);
  }

 private:
  int add_lightmap_texture(const Image& lightmap, MeshId id) {
    PngOptions po;
    po.exposure = options_.exposure;
    const std::vector<std::uint8_t> png =
        encode_png(lightmap, po, "write_baked_gltf: lightmap of mesh " + std::to_string(id) + ": ");
    if (sampler_ < 0) {
      // Bilinear, clamped: the lightmap's gutter (LightmapOptions::dilation) keeps the filter
      // from reading black across a chart's border.
      tinygltf::Sampler s;
      s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
      s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
      s.wrapS = s.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      model_.samplers.push_back(s);
      sampler_ = static_cast<int>(model_.samplers.size() - 1);
    }
    tinygltf::Image image;
    image.name = "lightmap " + std::to_string(id);
    image.mimeType = "image/png";
    image.bufferView = buffer_.add_view(png.data(), png.size(), 0);
    model_.images.push_back(std::move(image));
    tinygltf::Texture texture;
    texture.source = static_cast<int>(model_.images.size() - 1);
    texture.sampler = sampler_;
    model_.textures.push_back(std::move(texture));
    return static_cast<int>(model_.textures.size() - 1);
  }

  const Scene& scene_;
  const Solution& solution_;
  const GltfBakeOptions& options_;
  tinygltf::Model& model_;
  BufferBuilder buffer_;
  std::vector<MeshLight> light_;
  int sampler_ = -1;
};

// ---------------------------------------------------------------------------------------------
// A glTF source: its file, with the light added to the primitives the meshes came from.

/// Where a Scene mesh came from, as the glTF reader wrote Mesh::source.
struct PrimitivePlace {
  int node = -1, mesh = -1, primitive = -1;
};

bool parse_place(const std::string& source, PrimitivePlace& out) {
  char tail = 0;
  return std::sscanf(source.c_str(), "nodes[%d]: meshes[%d].primitives[%d]%c", &out.node, &out.mesh, &out.primitive,
                     &tail) == 3 &&
         out.node >= 0 && out.mesh >= 0 && out.primitive >= 0;
}

/// Each node's parent, or -1 for a root.
std::vector<int> node_parents(const tinygltf::Model& model) {
  std::vector<int> parent(model.nodes.size(), -1);
  for (std::size_t p = 0; p < model.nodes.size(); ++p)
    for (int c : model.nodes[p].children)
      if (c >= 0 && static_cast<std::size_t>(c) < parent.size()) parent[static_cast<std::size_t>(c)] = static_cast<int>(p);
  return parent;
}

/// Whether node `n`'s world matrix mirrors (a negative determinant: the reader swapped its
/// triangles' corners to keep them facing out, which the written indices must undo). The
/// determinant's sign is the product of the local matrices' signs; a TRS node's is its scale's.
bool mirrors(const tinygltf::Model& model, const std::vector<int>& parent, int n) {
  bool negative = false;
  std::size_t steps = 0;
  for (int k = n; k >= 0 && steps <= model.nodes.size(); k = parent[static_cast<std::size_t>(k)], ++steps) {
    const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(k)];
    double det = 1.0;
    if (node.matrix.size() == 16) {
      const std::vector<double>& m = node.matrix;  // column-major
      det = glm::determinant(glm::dmat3(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]));
    } else if (node.scale.size() == 3) {
      det = node.scale[0] * node.scale[1] * node.scale[2];
    }
    if (det < 0.0) negative = !negative;
  }
  return negative;
}

/// Accessor `index` with its elements re-ordered as `origin` says (element i of the result is
/// element origin[i]), densely packed, sparse storage applied; bounds kept for POSITION.
int gather_accessor(const GltfAccessors& accessors, const tinygltf::Model& model, BufferBuilder& buffer, int index,
                    const std::vector<std::uint32_t>& origin, const std::string& place, const std::string& role) {
  const tinygltf::Accessor& a = model.accessors.at(static_cast<std::size_t>(index));
  // UNSIGNED_INT is for indices only (section 3.6.2.2), but a file's own attributes are copied
  // whatever they hold.
  const bool as_indices = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && a.type == TINYGLTF_TYPE_SCALAR;
  const CheckedAccessor c = accessors.check(
      index, place, role, {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, as_indices);
  const std::size_t element = c.component_bytes * static_cast<std::size_t>(c.components);
  std::vector<unsigned char> dense(c.count * element, 0);
  if (c.base)
    for (std::size_t i = 0; i < c.count; ++i) std::memcpy(&dense[i * element], c.base + i * c.stride, element);
  accessors.for_each_sparse(c, place, [&](std::size_t i, const unsigned char* p) { std::memcpy(&dense[i * element], p, element); });
  std::vector<unsigned char> out(origin.size() * element);
  for (std::size_t v = 0; v < origin.size(); ++v) {
    if (origin[v] >= c.count)
      throw Error(ErrorCode::invalid_argument, "write_baked_gltf: " + place + ": " + c.what + " has " +
                                                   std::to_string(c.count) + " elements, the scene's mesh copies element " +
                                                   std::to_string(origin[v]) + " (not the file it was loaded from?)");
    std::memcpy(&out[v * element], &dense[origin[v] * element], element);
  }
  std::vector<double> lo, hi;
  // POSITION accessors, a morph target's too, must give their bounds (section 3.7.2.1).
  if (role.size() >= 8 && role.compare(role.size() - 8, 8, "POSITION") == 0 && !origin.empty()) {
    const auto n = static_cast<std::size_t>(c.components);
    lo.assign(n, HUGE_VAL);
    hi.assign(n, -HUGE_VAL);
    for (std::size_t v = 0; v < origin.size(); ++v)
      for (std::size_t k = 0; k < n; ++k) {
        const double x = component_value(&out[v * element + k * c.component_bytes], c.component_type, false);
        lo[k] = std::min(lo[k], x);
        hi[k] = std::max(hi[k], x);
      }
  }
  return buffer.add_accessor(out.data(), origin.size(), c.component_type, a.type, a.normalized,
                             TINYGLTF_TARGET_ARRAY_BUFFER, std::move(lo), std::move(hi));
}

void write_from_gltf(const fs::path& source, const Scene& scene, Writer& writer, tinygltf::Model& model,
                     const GltfFile& file) {
  const GltfAccessors accessors(file.src, file.model);
  const tinygltf::Model& in = file.model;
  // Each scene mesh's primitive, grouped by the node that places it.
  std::map<int, std::map<int, MeshId>> by_node;  // node -> primitive -> mesh
  for (MeshId id = 0; id < scene.meshes().size(); ++id) {
    PrimitivePlace at;
    const Mesh& mesh = scene.meshes()[id];
    if (!parse_place(mesh.source, at) || static_cast<std::size_t>(at.node) >= in.nodes.size() ||
        in.nodes[static_cast<std::size_t>(at.node)].mesh != at.mesh ||
        static_cast<std::size_t>(at.mesh) >= in.meshes.size() ||
        static_cast<std::size_t>(at.primitive) >= in.meshes[static_cast<std::size_t>(at.mesh)].primitives.size())
      throw Error(ErrorCode::invalid_argument,
                  "write_baked_gltf: mesh " + std::to_string(id) + " (source '" + mesh.source + "') is not a primitive of '" +
                      source.string() + "' (was the scene loaded from it?)");
    by_node[at.node][at.primitive] = id;
  }

  // Materials and textures are replaced: the output shows the baked light, not the surface.
  model.materials.clear();
  model.textures.clear();
  model.images.clear();
  model.samplers.clear();
  // Extensions of what was dropped are no longer used (KHR_materials_variants' mappings name
  // the old materials); Draco data would stand for the old attributes, so primitives lose it
  // (the reader needs the uncompressed fallback anyway).
  auto dropped = [](const std::string& e) {
    return e.rfind("KHR_materials_", 0) == 0 || e.rfind("KHR_texture_", 0) == 0 || e.rfind("EXT_texture_", 0) == 0 ||
           e == "KHR_draco_mesh_compression";
  };
  auto drop_from = [&](tinygltf::ExtensionMap& extensions) {
    for (auto it = extensions.begin(); it != extensions.end();) it = dropped(it->first) ? extensions.erase(it) : std::next(it);
  };
  for (tinygltf::Mesh& m : model.meshes)
    for (tinygltf::Primitive& p : m.primitives) {
      p.material = -1;
      drop_from(p.extensions);
    }
  drop_from(model.extensions);
  for (auto* list : {&model.extensionsUsed, &model.extensionsRequired})
    list->erase(std::remove_if(list->begin(), list->end(), dropped), list->end());
  writer.prepare_light();
  writer.use_unlit();

  const std::vector<int> parent = node_parents(in);
  std::vector<bool> mesh_taken(in.meshes.size(), false);
  for (const auto& [n, primitives] : by_node) {
    const int m = in.nodes[static_cast<std::size_t>(n)].mesh;
    const tinygltf::Mesh& original = in.meshes[static_cast<std::size_t>(m)];
    // The first node keeps the mesh's slot; every further node that places it gets a copy.
    int slot = m;
    if (mesh_taken[static_cast<std::size_t>(m)]) {
      model.meshes.push_back(original);
      slot = static_cast<int>(model.meshes.size() - 1);
      model.nodes[static_cast<std::size_t>(n)].mesh = slot;
    }
    mesh_taken[static_cast<std::size_t>(m)] = true;
    const bool mirrored = mirrors(in, parent, n);
    for (const auto& [p, id] : primitives) {
      const std::string place =
          "nodes[" + std::to_string(n) + "]: meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
      const Mesh& mesh = scene.meshes()[id];
      tinygltf::Primitive& out = model.meshes[static_cast<std::size_t>(slot)].primitives[static_cast<std::size_t>(p)];
      out = original.primitives[static_cast<std::size_t>(p)];
      drop_from(out.extensions);
      const int position = out.attributes.count("POSITION") ? out.attributes.at("POSITION") : -1;
      const std::size_t count = accessors.check(position, place, "POSITION", {TINYGLTF_TYPE_VEC3}, false).count;
      std::vector<std::uint32_t> origin = mesh.vertex_origin;
      bool split = !origin.empty();
      if (split && origin.size() == count) {
        split = false;
        for (std::size_t v = 0; v < count && !split; ++v) split = origin[v] != v;
      }
      if (!split && mesh.positions.size() != count)
        throw Error(ErrorCode::invalid_argument, "write_baked_gltf: mesh " + std::to_string(id) + " has " +
                                                     std::to_string(mesh.positions.size()) + " vertices, " + place +
                                                     " has " + std::to_string(count) +
                                                     " (was the scene loaded from this file?)");
      if (split) {
        // Every attribute, and every morph target's, follows the split; the triangles are the
        // mesh's (degenerate ones left out, strips and fans as lists), wound as in the file.
        for (auto& [name, accessor] : out.attributes)
          if (name != "COLOR_0" && name != "TEXCOORD_1" && name != "_IRRADIANCE")
            accessor = gather_accessor(accessors, in, writer.buffer(), accessor, origin, place, name);
        for (auto& target : out.targets)
          for (auto& [name, accessor] : target)
            accessor = gather_accessor(accessors, in, writer.buffer(), accessor, origin, place, "target " + name);
        std::vector<std::uint32_t> indices = mesh.indices;
        if (mirrored)
          for (std::size_t t = 0; t + 2 < indices.size(); t += 3) std::swap(indices[t + 1], indices[t + 2]);
        out.indices = writer.buffer().add_indices(indices);
        out.mode = TINYGLTF_MODE_TRIANGLES;
      }
      const MaterialId material = scene.polygons()[mesh.polygons.first].material;
      const bool emitter = Writer::emits(scene.material(material));
      writer.add_light(out, id, emitter, nullptr);
      out.material = writer.add_material(material, id, scene.material(material).name, scene.material(material).two_sided);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Any other scene: a new file, a node per mesh and a primitive per material.

void write_new(const Scene& scene, Writer& writer, tinygltf::Model& model) {
  model.asset.version = "2.0";
  writer.prepare_light();
  writer.use_unlit();
  tinygltf::Scene root;
  for (MeshId id = 0; id < scene.meshes().size(); ++id) {
    const Mesh& mesh = scene.meshes()[id];
    // Triangles by material, in order of first use; skipped ones (degenerate) left out.
    std::vector<MaterialId> order;
    std::map<MaterialId, std::vector<std::uint32_t>> triangles;
    for (std::size_t t = 0; t < mesh.triangle_polygon.size(); ++t) {
      if (mesh.triangle_polygon[t] == kNone) continue;
      const MaterialId material = scene.polygons()[mesh.triangle_polygon[t]].material;
      auto [it, added] = triangles.try_emplace(material);
      if (added) order.push_back(material);
      it->second.insert(it->second.end(), mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * t),
                        mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
    }
    tinygltf::Mesh out;
    out.name = scene.groups()[mesh.group];
    for (MaterialId material : order) {
      // Each primitive has the vertices its triangles use, renumbered in order of first use.
      std::vector<std::uint32_t> renumber(mesh.positions.size(), kNone), used, indices;
      for (std::uint32_t v : triangles[material]) {
        if (renumber[v] == kNone) {
          renumber[v] = static_cast<std::uint32_t>(used.size());
          used.push_back(v);
        }
        indices.push_back(renumber[v]);
      }
      tinygltf::Primitive p;
      p.mode = TINYGLTF_MODE_TRIANGLES;
      std::vector<glm::vec3> positions, normals;
      for (std::uint32_t v : used) positions.push_back(mesh.positions[v]);
      p.attributes["POSITION"] = writer.buffer().add_floats(&positions[0].x, positions.size(), TINYGLTF_TYPE_VEC3, true);
      if (!mesh.normals.empty()) {
        for (std::uint32_t v : used) normals.push_back(mesh.normals[v]);
        p.attributes["NORMAL"] = writer.buffer().add_floats(&normals[0].x, normals.size(), TINYGLTF_TYPE_VEC3, false);
      }
      p.indices = writer.buffer().add_indices(indices);
      const Material& m = scene.material(material);
      writer.add_light(p, id, Writer::emits(m), &used);
      p.material = writer.add_material(material, id, m.name, m.two_sided);
      out.primitives.push_back(std::move(p));
    }
    if (out.primitives.empty()) continue;
    model.meshes.push_back(std::move(out));
    tinygltf::Node node;
    node.name = scene.groups()[mesh.group];
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    // A scene read with a local origin (Scene::origin()) goes back where the file had it: the
    // vertices stay small floats and the node moves them (glTF's translation is a double).
    const glm::dvec3 origin = scene.origin();
    if (origin != glm::dvec3(0.0)) node.translation = {origin.x, origin.y, origin.z};
    model.nodes.push_back(std::move(node));
    root.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
  }
  model.scenes.push_back(std::move(root));
  model.defaultScene = 0;
}

}  // namespace
}  // namespace detail

inline namespace v1 {

void write_baked_gltf(const std::filesystem::path& source, const Scene& scene, const Solution& solution,
                      const std::filesystem::path& output, const GltfBakeOptions& options) {
  namespace fs = std::filesystem;
  const std::string where = "write_baked_gltf: '" + output.string() + "': ";
  if (!(options.exposure >= 0.0f) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::invalid_argument, where + "GltfBakeOptions::exposure must be finite and >= 0");
  if (options.lightmaps.size() > scene.meshes().size())
    throw Error(ErrorCode::invalid_argument, where + std::to_string(options.lightmaps.size()) + " lightmaps for " +
                                                 std::to_string(scene.meshes().size()) + " meshes");
  if (solution.meshes().size() != scene.meshes().size())
    throw Error(ErrorCode::invalid_argument, where + "the solution has " + std::to_string(solution.meshes().size()) +
                                                 " meshes, the scene " + std::to_string(scene.meshes().size()) +
                                                 " (solve the scene after adding its meshes)");
  const std::string ext = detail::lower_extension(output);
  if (ext != ".glb" && ext != ".gltf")
    throw Error(ErrorCode::invalid_argument, where + "the output must be a .glb or .gltf file");
  const bool binary = ext == ".glb";

  tinygltf::Model model;
  std::optional<detail::GltfFile> file;
  if (!source.empty()) {
    file = detail::read_gltf_file(source);
    model = file->model;
  }
  detail::Writer writer(scene, solution, options, model);
  writer.buffer().merge_buffers();
  if (file)
    detail::write_from_gltf(source, scene, writer, model, *file);
  else
    detail::write_new(scene, writer, model);
  model.asset.generator = "radiosity write_baked_gltf";
  writer.buffer().finish(binary ? "" : output.stem().string() + ".bin");

  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToFile(&model, output.string(), /*embedImages=*/false, /*embedBuffers=*/false,
                                 /*prettyPrint=*/true, binary))
    throw Error(ErrorCode::io_error, "write_baked_gltf: cannot write '" + output.string() + "'");
}

}  // namespace v1
}  // namespace radiosity
