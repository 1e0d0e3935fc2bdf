// glTF 2.0 reader (.gltf with embedded or external buffers, .glb). Implements the Khronos glTF 2.0
// specification (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html): the GLB container
// (section 4.4), accessors with their byte strides and sparse storage (3.6, 5.1), the node
// hierarchy and its transforms (3.5), primitive modes and winding (3.7.2.1), cameras (3.10) and
// the metallic-roughness material (3.9), with the Khronos extensions
// KHR_materials_emissive_strength, KHR_materials_transmission, KHR_materials_ior and
// KHR_mesh_quantization, and KHR_lights_punctual (docs/LIGHTS.md). docs/SCENE_GLTF.md has the
// mapping.
//
// tinygltf (Debian's shared libtinygltf) parses the JSON and decodes the buffers. It leaves most
// ranges to its caller (a bufferView that reaches beyond its buffer, an accessor beyond its
// bufferView, an index beyond the vertices), and it names no place in its own messages, so the
// reader checks the GLB container and every reference of the JSON before tinygltf sees them, and
// every accessor before reading a byte of it: a broken file is an Error naming the file and the
// place ("scene.glb: meshes[2].primitives[0]: accessor 7 (POSITION): ..."), never a crash.
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "core/constants.hpp"
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
using json = nlohmann::json;

// GLB (section 4.4): a 12-byte header, then chunks of (length, type, data).
constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;
constexpr std::uint32_t kChunkBin = 0x004E4942;

/// An accessor without a bufferView reads as zeros (section 3.6.2.1); it needs no bytes, so its
/// count is all that limits the memory it takes. Larger ones are refused.
constexpr std::size_t kMaxZeroAccessor = std::size_t{1} << 24;

/// Extensions a file may require (section 3.12): the ones read here, and KHR_texture_transform,
/// which moves texels around but leaves the mean of a texture (all that is read of it) alone.
constexpr std::string_view kReadableRequired[] = {"KHR_materials_emissive_strength", "KHR_materials_transmission",
                                                  "KHR_materials_ior", "KHR_mesh_quantization",
                                                  "KHR_texture_transform", "KHR_lights_punctual"};

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

/// Where `count` elements of `size` bytes, `stride` apart, starting at `offset`, fit in `length`
/// bytes. Written so that nothing overflows, whatever the file claims.
bool fits(std::uint64_t offset, std::uint64_t count, std::uint64_t stride, std::uint64_t size, std::uint64_t length) {
  if (offset > length) return false;
  if (count == 0) return true;
  if (size > length - offset) return false;
  return count - 1 <= (length - offset - size) / stride;
}

/// A URI's path with its %XX escapes decoded (RFC 3986), for the file it names.
std::string decode_uri(std::string_view uri) {
  std::string out;
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

bool is_data_uri(std::string_view uri) { return uri.compare(0, 5, "data:") == 0; }

/// Every message starts with the file's name, then the place in the document.
class Source {
 public:
  explicit Source(std::string name) : name_(std::move(name)) {}
  const std::string& name() const { return name_; }
  std::string where(const std::string& place) const { return place.empty() ? name_ : name_ + ": " + place; }
  [[noreturn]] void fail(ErrorCode code, const std::string& place, const std::string& problem) const {
    throw Error(code, where(place) + ": " + problem);
  }

 private:
  std::string name_;
};

// ---------------------------------------------------------------------------------------------
// The GLB container, checked before tinygltf reads it.

struct Glb {
  std::string_view json;            ///< the JSON chunk
  std::size_t length = 0;           ///< bytes of the GLB (the header's length; trailing bytes are not part of it)
  std::optional<std::size_t> bin;   ///< bytes of the BIN chunk that follows the JSON chunk, when there is one
};

Glb split_glb(const Source& src, const std::string& bytes) {
  auto fail = [&](const std::string& problem) { src.fail(ErrorCode::parse_error, "", problem); };
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::size_t size = bytes.size();
  if (size < 12) fail("truncated GLB: " + std::to_string(size) + " bytes, fewer than its 12-byte header");
  if (le32(p) != kGlbMagic) fail("not a binary glTF (GLB) file: its first 4 bytes are not the magic 'glTF'");
  const std::uint32_t version = le32(p + 4), length = le32(p + 8);
  if (version != 2) fail("GLB version " + std::to_string(version) + " (only version 2, glTF 2.0, is read)");
  if (length > size)
    fail("truncated GLB: its header gives " + std::to_string(length) + " bytes, the file has " + std::to_string(size));
  if (length < 20) fail("GLB of " + std::to_string(length) + " bytes has no room for its JSON chunk");
  const std::uint32_t json_length = le32(p + 12);
  if (le32(p + 16) != kChunkJson) fail("the first GLB chunk is not the JSON chunk");
  if (json_length > length - 20)
    fail("truncated GLB: its JSON chunk of " + std::to_string(json_length) + " bytes ends beyond the file's " +
         std::to_string(length) + " bytes");
  Glb glb;
  glb.json = std::string_view(bytes.data() + 20, json_length);
  glb.length = length;
  // Chunks of other types may follow; a reader skips them (section 4.4.3.1).
  for (std::size_t pos = 20 + std::size_t{json_length}; pos < length;) {
    if (length - pos < 8)
      fail("truncated GLB: " + std::to_string(length - pos) + " bytes at byte " + std::to_string(pos) +
           ", fewer than a chunk header");
    const std::uint32_t chunk_length = le32(p + pos);
    if (chunk_length > length - pos - 8)
      fail("truncated GLB: the chunk at byte " + std::to_string(pos) + " of " + std::to_string(chunk_length) +
           " bytes ends beyond the file's " + std::to_string(length) + " bytes");
    if (le32(p + pos + 4) == kChunkBin && pos == 20 + std::size_t{json_length}) glb.bin = chunk_length;
    pos += 8 + std::size_t{chunk_length};
  }
  return glb;
}

// ---------------------------------------------------------------------------------------------
// The JSON, checked before tinygltf reads it: the version, the required extensions, every index
// that refers to another object, and the buffers' files.

class JsonCheck {
 public:
  JsonCheck(const Source& src, const json& root) : src_(src), root_(root) {}

  void run(const std::optional<Glb>& glb, const fs::path& base_dir) {
    if (!root_.is_object()) src_.fail(ErrorCode::parse_error, "", "the glTF JSON is not an object");
    const json* version = find(root_, "asset");
    version = version && version->is_object() ? find(*version, "version") : nullptr;
    if (!version || !version->is_string())
      src_.fail(ErrorCode::parse_error, "asset.version", "missing (a glTF file gives its version, \"2.0\")");
    if (version->get<std::string>().compare(0, 2, "2.") != 0)
      src_.fail(ErrorCode::parse_error, "asset.version",
                in_quotes(version->get<std::string>()) + ": only glTF 2.0 is read");
    if (const json* required = find(root_, "extensionsRequired"); required && required->is_array())
      for (std::size_t i = 0; i < required->size(); ++i) {
        const json& name = (*required)[i];
        if (!name.is_string()) continue;
        const std::string n = name.get<std::string>();
        if (std::find(std::begin(kReadableRequired), std::end(kReadableRequired), n) == std::end(kReadableRequired))
          src_.fail(ErrorCode::parse_error, "extensionsRequired[" + std::to_string(i) + "]",
                    in_quotes(n) + " is not supported" +
                        (n == "KHR_draco_mesh_compression" || n == "EXT_meshopt_compression"
                             ? " (decompress the file first, e.g. gltf-transform copy or gltfpack -noq)"
                             : std::string()) +
                        "; the extensions a file may require here are KHR_materials_emissive_strength, "
                        "KHR_materials_transmission, KHR_materials_ior, KHR_mesh_quantization, "
                        "KHR_texture_transform and KHR_lights_punctual");
      }

    if (const json* scene = find(root_, "scene")) index(*scene, "scene", "scenes");
    each("scenes", [&](const json& s, const std::string& at) { refs(s, "nodes", at, "nodes"); });
    each("nodes", [&](const json& n, const std::string& at) {
      refs(n, "children", at, "nodes");
      ref(n, "mesh", at, "meshes");
      ref(n, "camera", at, "cameras");
      ref(n, "skin", at, "skins");
    });
    each("meshes", [&](const json& m, const std::string& at) {
      require(m, "primitives", at, Kind::array);
      const json& primitives = m.at("primitives");
      for (std::size_t j = 0; j < primitives.size(); ++j) {
        const json& p = primitives[j];
        const std::string pat = at + ".primitives[" + std::to_string(j) + "]";
        if (!p.is_object()) src_.fail(ErrorCode::parse_error, pat, "must be an object");
        require(p, "attributes", pat, Kind::object);
        ref(p, "indices", pat, "accessors");
        // tinygltf reads indices only from a bufferView (not zeros, nor sparse storage alone).
        if (const json* i = find(p, "indices"); i && !find(root_.at("accessors").at(i->get<std::size_t>()), "bufferView"))
          src_.fail(ErrorCode::parse_error, pat + ".indices",
                    "accessor " + i->dump() + " has no bufferView (indices are read from one)");
        ref(p, "material", pat, "materials");
        if (const json* attributes = find(p, "attributes"); attributes && attributes->is_object())
          for (const auto& [name, value] : attributes->items())
            index(value, pat + ".attributes." + name, "accessors");
        if (const json* targets = find(p, "targets"); targets && targets->is_array())
          for (std::size_t t = 0; t < targets->size(); ++t)
            if ((*targets)[t].is_object())
              for (const auto& [name, value] : (*targets)[t].items())
                index(value, pat + ".targets[" + std::to_string(t) + "]." + name, "accessors");
      }
    });
    each("accessors", [&](const json& a, const std::string& at) {
      require(a, "componentType", at, Kind::index);
      const std::uint64_t component = a.at("componentType").get<std::uint64_t>();
      if (component < 5120 || component > 5126 || component == 5124)
        src_.fail(ErrorCode::parse_error, at + ".componentType",
                  std::to_string(component) + " is not a component type (5120, 5121, 5122, 5123, 5125 or 5126)");
      require(a, "count", at, Kind::index);
      require(a, "type", at, Kind::string);
      const std::string type = a.at("type").get<std::string>();
      if (type != "SCALAR" && type != "VEC2" && type != "VEC3" && type != "VEC4" && type != "MAT2" && type != "MAT3" &&
          type != "MAT4")
        src_.fail(ErrorCode::parse_error, at + ".type", in_quotes(type) + " is not an accessor type (SCALAR, VEC2 to VEC4, MAT2 to MAT4)");
      ref(a, "bufferView", at, "bufferViews");
      if (const json* sparse = find(a, "sparse"); sparse && sparse->is_object()) {
        if (const json* i = find(*sparse, "indices"); i && i->is_object()) ref(*i, "bufferView", at + ".sparse.indices", "bufferViews");
        if (const json* v = find(*sparse, "values"); v && v->is_object()) ref(*v, "bufferView", at + ".sparse.values", "bufferViews");
      }
    });
    each("bufferViews", [&](const json& v, const std::string& at) {
      require(v, "buffer", at, Kind::index);
      require(v, "byteLength", at, Kind::index);
      ref(v, "buffer", at, "buffers");
    });
    each("buffers", [&](const json& b, const std::string& at) { require(b, "byteLength", at, Kind::index); });
    each("cameras", [&](const json& c, const std::string& at) {
      require(c, "type", at, Kind::string);
      const std::string type = c.at("type").get<std::string>();
      if (type != "perspective" && type != "orthographic")
        src_.fail(ErrorCode::parse_error, at + ".type", in_quotes(type) + " is neither 'perspective' nor 'orthographic'");
      require(c, type.c_str(), at, Kind::object);
      if (type == "perspective") {
        require(c.at("perspective"), "yfov", at + ".perspective", Kind::number);
        require(c.at("perspective"), "znear", at + ".perspective", Kind::number);
      }
    });
    each("images", [&](const json& i, const std::string& at) { ref(i, "bufferView", at, "bufferViews"); });
    each("textures", [&](const json& t, const std::string& at) {
      ref(t, "source", at, "images");
      ref(t, "sampler", at, "samplers");
    });
    each("materials", [&](const json& m, const std::string& at) {
      auto texture = [&](const json& owner, const char* key, const std::string& owner_at) {
        if (const json* info = find(owner, key); info && info->is_object()) ref(*info, "index", owner_at + "." + key, "textures");
      };
      if (const json* pbr = find(m, "pbrMetallicRoughness"); pbr && pbr->is_object()) {
        texture(*pbr, "baseColorTexture", at + ".pbrMetallicRoughness");
        texture(*pbr, "metallicRoughnessTexture", at + ".pbrMetallicRoughness");
      }
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture(m, key, at);
      if (const json* ext = find(m, "extensions"); ext && ext->is_object())
        if (const json* t = find(*ext, "KHR_materials_transmission"); t && t->is_object())
          texture(*t, "transmissionTexture", at + ".extensions.KHR_materials_transmission");
    });
    each("skins", [&](const json& s, const std::string& at) {
      refs(s, "joints", at, "nodes");
      ref(s, "skeleton", at, "nodes");
      ref(s, "inverseBindMatrices", at, "accessors");
    });
    each("animations", [&](const json& a, const std::string& at) {
      if (const json* samplers = find(a, "samplers"); samplers && samplers->is_array())
        for (std::size_t k = 0; k < samplers->size(); ++k)
          if ((*samplers)[k].is_object()) {
            ref((*samplers)[k], "input", at + ".samplers[" + std::to_string(k) + "]", "accessors");
            ref((*samplers)[k], "output", at + ".samplers[" + std::to_string(k) + "]", "accessors");
          }
      if (const json* channels = find(a, "channels"); channels && channels->is_array())
        for (std::size_t k = 0; k < channels->size(); ++k) {
          const json& c = (*channels)[k];
          if (!c.is_object()) continue;
          const std::string cat = at + ".channels[" + std::to_string(k) + "]";
          const json* samplers = find(a, "samplers");
          if (const json* s = find(c, "sampler"); s && (!s->is_number_unsigned() || !samplers || !samplers->is_array() ||
                                                        s->get<std::uint64_t>() >= samplers->size()))
            src_.fail(ErrorCode::parse_error, cat + ".sampler", "not an index of the animation's samplers");
          if (const json* target = find(c, "target"); target && target->is_object()) ref(*target, "node", cat + ".target", "nodes");
        }
    });
    check_buffers(glb, base_dir);
  }

 private:
  static const json* find(const json& object, const char* key) {
    if (!object.is_object()) return nullptr;
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  std::size_t count(const char* array) const {
    const json* a = find(root_, array);
    return a && a->is_array() ? a->size() : 0;
  }

  /// Calls f(element, "array[i]") for each object of a top-level array.
  template <class F>
  void each(const char* array, F&& f) const {
    const json* a = find(root_, array);
    if (!a || !a->is_array()) return;
    for (std::size_t i = 0; i < a->size(); ++i)
      if ((*a)[i].is_object()) f((*a)[i], std::string(array) + "[" + std::to_string(i) + "]");
  }

  enum class Kind { index, number, string, object, array };

  /// `object[key]` must be there, of kind `kind` (properties the specification requires, which
  /// tinygltf would miss without saying where).
  void require(const json& object, const char* key, const std::string& place, Kind kind) const {
    const json* v = find(object, key);
    static const char* const kNames[] = {"a non-negative integer", "a number", "a string", "an object", "an array"};
    const bool ok = v && (kind == Kind::index    ? v->is_number_unsigned() || (v->is_number_integer() && v->get<std::int64_t>() >= 0)
                          : kind == Kind::number ? v->is_number()
                          : kind == Kind::string ? v->is_string()
                          : kind == Kind::object ? v->is_object()
                                                 : v->is_array());
    if (!ok)
      src_.fail(ErrorCode::parse_error, place + "." + key,
                (v ? "must be " : "is missing; it is required and must be ") + std::string(kNames[static_cast<int>(kind)]) +
                    (v ? " (got " + v->dump() + ")" : std::string()));
  }

  /// "mesh" of "meshes", "accessor" of "accessors".
  static std::string singular(std::string_view array) {
    return std::string(array == "meshes" ? "mesh" : array.substr(0, array.size() - 1));
  }

  /// `value` (at `place`) must index the top-level array `target`.
  void index(const json& value, const std::string& place, const char* target) const {
    if (!value.is_number_unsigned() && !value.is_number_integer())
      src_.fail(ErrorCode::parse_error, place, "must be an index into " + std::string(target) + " (got " + value.dump() + ")");
    if (value.is_number_integer() && !value.is_number_unsigned() && value.get<std::int64_t>() < 0)
      src_.fail(ErrorCode::parse_error, place, "index " + value.dump() + " is negative");
    const std::uint64_t i = value.get<std::uint64_t>();
    const std::size_t n = count(target);
    if (i >= n)
      src_.fail(ErrorCode::parse_error, place,
                singular(target) + " " + std::to_string(i) +
                    " does not exist (the file has " + std::to_string(n) + " " + target + ")");
  }
  void ref(const json& object, const char* key, const std::string& place, const char* target) const {
    if (const json* v = find(object, key)) index(*v, place + "." + key, target);
  }
  void refs(const json& object, const char* key, const std::string& place, const char* target) const {
    const json* list = find(object, key);
    if (!list || !list->is_array()) return;
    for (std::size_t k = 0; k < list->size(); ++k)
      index((*list)[k], place + "." + key + "[" + std::to_string(k) + "]", target);
  }

  /// A buffer's data: the GLB's BIN chunk (the first buffer of a GLB, without a uri), a data
  /// URI (decoded by tinygltf), or an external file, which must exist.
  void check_buffers(const std::optional<Glb>& glb, const fs::path& base_dir) const {
    each("buffers", [&](const json& b, const std::string& at) {
      const json* uri = find(b, "uri");
      if (!uri || !uri->is_string()) {
        if (!glb || at != "buffers[0]")
          src_.fail(ErrorCode::parse_error, at, "has no uri (only the first buffer of a .glb may leave it out)");
        if (!glb->bin) src_.fail(ErrorCode::parse_error, at, "has no uri, and the GLB has no BIN chunk to hold its data");
        if (const json* length = find(b, "byteLength"); length && length->is_number_unsigned() && length->get<std::uint64_t>() > *glb->bin)
          src_.fail(ErrorCode::parse_error, at + ".byteLength",
                    std::to_string(length->get<std::uint64_t>()) + " bytes exceed the GLB's BIN chunk of " +
                        std::to_string(*glb->bin) + " bytes (truncated file?)");
        return;
      }
      const std::string u = uri->get<std::string>();
      if (is_data_uri(u)) return;
      // tinygltf looks for files below the .gltf's folder only (the file system callbacks).
      if (u.find("://") != std::string::npos || fs::u8path(decode_uri(u)).is_absolute())
        src_.fail(ErrorCode::parse_error, at + ".uri",
                  in_quotes(u) + " is not a relative file name (data: URIs and files beside the glTF are read)");
      const fs::path file = base_dir / fs::u8path(decode_uri(u));
      std::error_code ec;
      if (!fs::is_regular_file(file, ec))
        src_.fail(ErrorCode::file_not_found, at + ".uri",
                  "external buffer file " + in_quotes(u) + " not found (looked for '" + file.string() + "')");
    });
  }

  const Source& src_;
  const json& root_;
};

// ---------------------------------------------------------------------------------------------
// tinygltf's callbacks: files only from the glTF's own folder (tinygltf would also look in the
// working directory), images kept encoded for the textures that are used.

struct LoadContext {
  std::string base_prefix;                                    ///< the glTF's folder, with a trailing '/'
  std::map<int, std::vector<unsigned char>> uri_image_bytes;  ///< encoded bytes of images given by URI
};

bool file_exists(const std::string& path, void* user) {
  const auto* ctx = static_cast<const LoadContext*>(user);
  if (path.compare(0, ctx->base_prefix.size(), ctx->base_prefix) != 0) return false;
  std::error_code ec;
  return fs::is_regular_file(fs::u8path(path), ec);
}

std::string expand_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  std::ifstream in(fs::u8path(path), std::ios::binary);
  if (in) out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) {
    if (err) *err += "cannot read '" + path + "'";
    return false;
  }
  return true;
}

bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the reader writes no files";
  return false;
}

/// Keeps the encoded bytes of an image given by URI (a data URI or a file, read by tinygltf);
/// decoding waits until a material uses the image, and then only its mean is kept. An image in
/// a bufferView is skipped: tinygltf hands its bytes over without checking that the bufferView
/// lies in its buffer, so they are read later, from the checked bufferView.
bool keep_image_bytes(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* user) {
  if (image->bufferView >= 0 || bytes == nullptr || size <= 0) return true;
  static_cast<LoadContext*>(user)->uri_image_bytes[index].assign(bytes, bytes + size);
  return true;
}

// ---------------------------------------------------------------------------------------------
// The model, read into a Scene.

int components_of(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
  }
}

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

std::size_t component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

/// One component's value, little-endian; normalized integers map to [0, 1] or [-1, 1] as
/// section 3.11 (animation's table, which accessors share) gives.
double component_value(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] | p[1] << 8));
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = static_cast<std::uint16_t>(p[0] | p[1] << 8);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return le32(p);
    default: {
      const std::uint32_t bits = le32(p);
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
  }
}

/// An accessor whose every byte was checked to lie in its buffer.
struct CheckedAccessor {
  const tinygltf::Accessor* accessor = nullptr;
  std::string what;                    ///< "accessor 7 (POSITION)"
  std::size_t count = 0;
  int components = 0;
  int component_type = 0;
  std::size_t component_bytes = 0;
  const unsigned char* base = nullptr;  ///< the first element; null: every element is zero
  std::size_t stride = 0;
};

class GltfReader {
 public:
  GltfReader(const Source& src, const tinygltf::Model& model, const LoadContext& ctx, const LoadOptions& options)
      : src_(src), model_(model), ctx_(ctx), options_(options), warnings_(options.strict) {}

  Scene read() {
    const std::vector<int> roots = scene_roots();
    // Depth first, children in order, each with its parent's world matrix (section 3.5.3).
    std::vector<bool> visited(model_.nodes.size(), false);
    std::vector<std::pair<int, glm::dmat4>> stack;
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
      if (node.mesh >= 0) add_node_mesh(n, node, world);
      if (node.camera >= 0) add_camera(n, node, world);
      add_node_light(n, node, world);
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.emplace_back(*it, world);
    }
    if (scene_.polygons().empty())
      src_.fail(ErrorCode::parse_error, "",
                skipped_triangles_ ? "has no triangles that are not degenerate"
                                   : "has no triangles in its scene (no node of it places a mesh of triangles)");
    warnings_.move_to(scene_);
    return std::move(scene_);
  }

 private:
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

  /// The bytes of bufferView `index`, checked to lie in their buffer.
  std::pair<const unsigned char*, std::size_t> buffer_view(int index, const std::string& place, const std::string& what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.bufferViews.size())
      src_.fail(ErrorCode::parse_error, place, what + ": bufferView " + std::to_string(index) + " does not exist");
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<std::size_t>(index)];
    const std::string view_name = "bufferViews[" + std::to_string(index) + "]";
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size())
      src_.fail(ErrorCode::parse_error, view_name, "buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& data = model_.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (!fits(view.byteOffset, 1, 1, view.byteLength, data.size()))
      src_.fail(ErrorCode::parse_error, view_name,
                "bytes " + std::to_string(view.byteOffset) + " + " + std::to_string(view.byteLength) + " lie beyond buffer " +
                    std::to_string(view.buffer) + " (" + std::to_string(data.size()) + " bytes)");
    return {data.data() + view.byteOffset, view.byteLength};
  }

  /// Accessor `index` for `role`, of one of `types`, checked element by element range: its
  /// component type, stride, offset and count against its bufferView, and its bufferView
  /// against its buffer (section 3.6.2.4).
  CheckedAccessor check_accessor(int index, const std::string& place, const std::string& role,
                                 std::initializer_list<int> types, bool indices) const {
    CheckedAccessor c;
    c.what = "accessor " + std::to_string(index) + " (" + role + ")";
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
      src_.fail(ErrorCode::parse_error, place, c.what + " does not exist (the file has " +
                                                   std::to_string(model_.accessors.size()) + " accessors)");
    const tinygltf::Accessor& a = model_.accessors[static_cast<std::size_t>(index)];
    c.accessor = &a;
    auto fail = [&](const std::string& problem) { src_.fail(ErrorCode::parse_error, place, c.what + ": " + problem); };
    if (std::find(types.begin(), types.end(), a.type) == types.end()) {
      std::string expected;
      for (int t : types) expected += std::string(expected.empty() ? "" : " or ") + type_name(t);
      fail("type " + std::string(type_name(a.type)) + ", " + expected + " expected");
    }
    c.components = components_of(a.type);
    c.component_type = a.componentType;
    c.component_bytes = component_size(a.componentType);
    const bool integer_index = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                               a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                               a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    // Vertex attributes are floats, or 8/16-bit integers under KHR_mesh_quantization.
    if (indices ? (!integer_index || a.normalized)
                : (c.component_bytes == 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      fail("component type " + std::to_string(a.componentType) + (a.normalized ? " (normalized)" : "") + " is not allowed for " +
           (indices ? "indices (unsigned byte, short or int)" : "a vertex attribute (float, or 8/16-bit integers)"));
    if (a.count == 0) fail("count 0 (an accessor has at least one element)");
    if (a.count >= kNone) fail("count " + std::to_string(a.count) + " exceeds what 32-bit indices address");
    c.count = a.count;
    const std::size_t element = c.component_bytes * static_cast<std::size_t>(c.components);
    if (a.bufferView < 0) {
      // Zeros (and the sparse values on top).
      if (a.count > kMaxZeroAccessor)
        fail("has no bufferView, and " + std::to_string(a.count) + " elements of zeros are not read");
      c.stride = element;
      return c;
    }
    const auto [bytes, length] = buffer_view(a.bufferView, place, c.what);
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<std::size_t>(a.bufferView)];
    c.stride = view.byteStride != 0 ? view.byteStride : element;
    if (c.stride < element)
      fail("bufferView " + std::to_string(a.bufferView) + "'s byteStride " + std::to_string(view.byteStride) +
           " is smaller than an element (" + std::to_string(element) + " bytes)");
    if (!fits(a.byteOffset, a.count, c.stride, element, length))
      fail(std::to_string(a.count) + " elements of " + std::to_string(element) + " bytes, " + std::to_string(c.stride) +
           " apart from byte " + std::to_string(a.byteOffset) + ", reach beyond bufferView " + std::to_string(a.bufferView) +
           " (" + std::to_string(length) + " bytes)");
    c.base = bytes + a.byteOffset;
    return c;
  }

  /// Calls write(element, bytes) for each element the accessor's sparse storage replaces
  /// (section 3.6.2.3), after checking its indices and values like any accessor's.
  template <class Write>
  void for_each_sparse(const CheckedAccessor& c, const std::string& place, Write&& write) const {
    const auto& s = c.accessor->sparse;
    if (!s.isSparse) return;
    auto fail = [&](const std::string& problem) { src_.fail(ErrorCode::parse_error, place, c.what + ": sparse " + problem); };
    if (s.count < 1 || static_cast<std::size_t>(s.count) > c.count)
      fail("count " + std::to_string(s.count) + " is not in [1, " + std::to_string(c.count) + "]");
    const std::size_t count = static_cast<std::size_t>(s.count);
    const std::size_t index_bytes = component_size(s.indices.componentType);
    if (index_bytes == 0 || s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail("indices have component type " + std::to_string(s.indices.componentType) + " (unsigned byte, short or int expected)");
    const auto [indices, indices_length] = buffer_view(s.indices.bufferView, place, c.what + " sparse indices");
    if (s.indices.byteOffset < 0 || !fits(static_cast<std::size_t>(s.indices.byteOffset), count, index_bytes, index_bytes, indices_length))
      fail("indices reach beyond bufferView " + std::to_string(s.indices.bufferView));
    const std::size_t element = c.component_bytes * static_cast<std::size_t>(c.components);
    const auto [values, values_length] = buffer_view(s.values.bufferView, place, c.what + " sparse values");
    if (s.values.byteOffset < 0 || !fits(static_cast<std::size_t>(s.values.byteOffset), count, element, element, values_length))
      fail("values reach beyond bufferView " + std::to_string(s.values.bufferView));
    for (std::size_t k = 0; k < count; ++k) {
      const auto i = static_cast<std::size_t>(component_value(
          indices + static_cast<std::size_t>(s.indices.byteOffset) + k * index_bytes, s.indices.componentType, false));
      if (i >= c.count)
        fail("index " + std::to_string(i) + " (entry " + std::to_string(k) + ") is out of range (" + std::to_string(c.count) +
             " elements)");
      write(i, values + static_cast<std::size_t>(s.values.byteOffset) + k * element);
    }
  }

  /// A vertex attribute's elements as floats, n per element; every value finite.
  std::vector<float> read_floats(int index, const std::string& place, const std::string& role, int type) const {
    const CheckedAccessor c = check_accessor(index, place, role, {type}, false);
    const auto n = static_cast<std::size_t>(c.components);
    const bool normalized = c.accessor->normalized;
    std::vector<float> out(c.count * n, 0.0f);
    auto element = [&](std::size_t i, const unsigned char* p) {
      for (std::size_t k = 0; k < n; ++k)
        out[i * n + k] = static_cast<float>(component_value(p + k * c.component_bytes, c.component_type, normalized));
    };
    if (c.base)
      for (std::size_t i = 0; i < c.count; ++i) element(i, c.base + i * c.stride);
    for_each_sparse(c, place, element);
    for (std::size_t v = 0; v < out.size(); ++v)
      if (!std::isfinite(out[v]))
        src_.fail(ErrorCode::parse_error, place, c.what + ": element " + std::to_string(v / n) + " is NaN or infinite");
    return out;
  }

  /// A primitive's indices, each checked against the vertex count.
  std::vector<std::uint32_t> read_indices(int index, const std::string& place, std::size_t vertices) const {
    const CheckedAccessor c = check_accessor(index, place, "indices", {TINYGLTF_TYPE_SCALAR}, true);
    std::vector<std::uint32_t> out(c.count, 0);
    auto element = [&](std::size_t i, const unsigned char* p) {
      out[i] = static_cast<std::uint32_t>(component_value(p, c.component_type, false));
    };
    if (c.base)
      for (std::size_t i = 0; i < c.count; ++i) element(i, c.base + i * c.stride);
    for_each_sparse(c, place, element);
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
  std::vector<std::uint32_t> triangles(int mode, const std::vector<std::uint32_t>& v, const std::string& place) {
    std::vector<std::uint32_t> t;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      t.assign(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 3 * 3));
      if (v.size() % 3 != 0)
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
    if (add_placed_mesh(scene_, warnings_, std::move(local), world, id, group,
                        src_.where(place + " (placed by " + node_place + ")"), options_) > 0)
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
      const auto [bytes, length] = buffer_view(image.bufferView, "images[" + std::to_string(source) + "]", image_name);
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

/// tinygltf's error text as one line.
std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::replace(text.begin(), text.end(), '\n', ';');
  return text;
}

}  // namespace

Scene load_gltf(const fs::path& path, const LoadOptions& options) {
  const std::string bytes = read_file(path, "glTF file");
  const Source src(path.string());
  std::error_code ec;
  fs::path base_dir = fs::absolute(path, ec).parent_path();
  if (ec) base_dir = path.parent_path();

  // Binary by its magic, whatever the extension says; a .glb must be binary.
  const bool binary = bytes.size() >= 4 && le32(reinterpret_cast<const unsigned char*>(bytes.data())) == kGlbMagic;
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::optional<Glb> glb;
  if (binary || ext == ".glb") glb = split_glb(src, bytes);
  const std::string_view text = glb ? glb->json : std::string_view(bytes);
  if (text.size() > UINT_MAX) src.fail(ErrorCode::parse_error, "", "larger than the 4 GiB that tinygltf reads");

  // The JSON is checked first, with every problem at its place.
  json root;
  try {
    root = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    const std::size_t colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw Error(ErrorCode::parse_error,
                src.name() + ":" + line_column(text, e.byte > 0 ? e.byte - 1 : 0) + ": JSON syntax error: " + what);
  } catch (const json::exception& e) {
    throw Error(ErrorCode::parse_error, src.name() + ": JSON value error: " + e.what());
  }
  try {
    JsonCheck(src, root).run(glb, base_dir);
  } catch (const json::exception& e) {
    throw Error(ErrorCode::parse_error, src.name() + ": " + e.what());
  }
  root = json();  // tinygltf parses again

  LoadContext ctx;
  ctx.base_prefix = base_dir.string() + "/";
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_image_bytes, &ctx);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&file_exists, &expand_path, &read_whole_file, &write_whole_file, &ctx});
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                    static_cast<unsigned int>(glb->length), base_dir.string())
                      : loader.LoadASCIIFromString(&model, &err, &warn, text.data(), static_cast<unsigned int>(text.size()),
                                                   base_dir.string());
  // tinygltf's warnings are about images only, which are reported where a material uses them.
  if (!ok)
    throw Error(err.find("File not found") != std::string::npos ? ErrorCode::file_not_found : ErrorCode::parse_error,
                src.name() + ": " + (err.empty() ? std::string("tinygltf cannot read it") : one_line(err)));
  return GltfReader(src, model, ctx, options).read();
}

}  // namespace radiosity::detail
