// The glTF file as gltf_model.hpp describes it: the GLB container and the JSON checked before
// tinygltf reads them (glTF 2.0 specification, sections 3 and 4.4), and the accessors' ranges.
#include "io/readers/gltf_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <climits>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <system_error>

#include "io/readers/reader_files.hpp"

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

/// tinygltf's error text as one line.
std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::replace(text.begin(), text.end(), '\n', ';');
  return text;
}

}  // namespace

/// Where `count` elements of `size` bytes, `stride` apart, starting at `offset`, fit in `length`
/// bytes. Written so that nothing overflows, whatever the file claims.
bool fits(std::uint64_t offset, std::uint64_t count, std::uint64_t stride, std::uint64_t size, std::uint64_t length) {
  if (offset > length) return false;
  if (count == 0) return true;
  if (size > length - offset) return false;
  return count - 1 <= (length - offset - size) / stride;
}

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

/// The bytes of bufferView `index`, checked to lie in their buffer.
std::pair<const unsigned char*, std::size_t> GltfAccessors::buffer_view(int index, const std::string& place, const std::string& what) const {
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
CheckedAccessor GltfAccessors::check(int index, const std::string& place, const std::string& role,
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

GltfFile read_gltf_file(const fs::path& path) {
  const std::string bytes = read_file(path, "glTF file");
  GltfFile file{Source(path.string()), {}, {}};
  const Source& src = file.src;
  std::error_code ec;
  fs::path base_dir = fs::absolute(path, ec).parent_path();
  if (ec) base_dir = path.parent_path();

  // Binary by its magic, whatever the extension says; a .glb must be binary.
  const bool binary = bytes.size() >= 4 && le32(reinterpret_cast<const unsigned char*>(bytes.data())) == kGlbMagic;
  const std::string ext = lower_extension(path);
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

  LoadContext& ctx = file.ctx;
  ctx.base_prefix = base_dir.string() + "/";
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_image_bytes, &ctx);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&file_exists, &expand_path, &read_whole_file, &write_whole_file, &ctx});
  tinygltf::Model& model = file.model;
  std::string err, warn;
  const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                    static_cast<unsigned int>(glb->length), base_dir.string())
                      : loader.LoadASCIIFromString(&model, &err, &warn, text.data(), static_cast<unsigned int>(text.size()),
                                                   base_dir.string());
  // tinygltf's warnings are about images only, which are reported where a material uses them.
  if (!ok)
    throw Error(err.find("File not found") != std::string::npos ? ErrorCode::file_not_found : ErrorCode::parse_error,
                src.name() + ": " + (err.empty() ? std::string("tinygltf cannot read it") : one_line(err)));
  return file;
}

}  // namespace radiosity::detail
