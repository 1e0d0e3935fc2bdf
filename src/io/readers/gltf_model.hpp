// A glTF 2.0 file as the reader (gltf_loader.cpp) and the baked-scene writer
// (io/writers/gltf_writer.cpp) see it: the GLB container and every reference of the JSON checked,
// then parsed by Debian's tinygltf (shared libtinygltf, which names no place in its messages and
// leaves most ranges to its caller), and each accessor's bytes reached only through GltfAccessors,
// after its range in its bufferView and buffer is checked (Khronos glTF 2.0 specification,
// https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html, sections 3.6 and 4.4).
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/readers/reader_files.hpp"
#include "radiosity/common.hpp"

namespace radiosity::detail {

inline bool is_data_uri(std::string_view uri) { return uri.compare(0, 5, "data:") == 0; }

/// Where `count` elements of `size` bytes, `stride` apart, starting at `offset`, fit in `length`
/// bytes. Written so that nothing overflows, whatever the file claims.
bool fits(std::uint64_t offset, std::uint64_t count, std::uint64_t stride, std::uint64_t size, std::uint64_t length);

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

/// What tinygltf's callbacks need while it reads, and what they leave for the reader.
struct LoadContext {
  std::string base_prefix;                                    ///< the glTF's folder, with a trailing '/'
  std::map<int, std::vector<unsigned char>> uri_image_bytes;  ///< encoded bytes of images given by URI
};

/// A glTF file read and checked: every message names `src` and the place in the document.
struct GltfFile {
  Source src;
  tinygltf::Model model;
  LoadContext ctx;
};

/// Reads `path` (.gltf with embedded or external buffers, or .glb: binary by its magic whatever
/// the extension): the GLB container, the JSON (syntax with line and column, the version, the
/// required extensions, every index into another array, the buffers' files) checked before
/// tinygltf parses it. Images given by URI are kept encoded in ctx.uri_image_bytes. Throws
/// Error{parse_error} or Error{file_not_found} naming the file and the place
/// (docs/SCENE_GLTF.md lists the cases).
GltfFile read_gltf_file(const std::filesystem::path& path);

/// Components per element of an accessor type (SCALAR 1 ... VEC4 4), 0 for the matrix types.
int components_of(int type);
/// The accessor type's name ("VEC3"), for messages.
const char* type_name(int type);
/// Bytes of one component of `component_type`, 0 for an unknown type.
std::size_t component_size(int component_type);
/// One component's value, little-endian; normalized integers map to [0, 1] or [-1, 1] as
/// section 3.11 (animation's table, which accessors share) gives.
double component_value(const unsigned char* p, int component_type, bool normalized);

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

/// The accessors and bufferViews of a model, reached only after their ranges are checked.
/// Every failure is Error{parse_error} at `place` in `src`.
class GltfAccessors {
 public:
  GltfAccessors(const Source& src, const tinygltf::Model& model) : src_(src), model_(model) {}

  /// The bytes of bufferView `index`, checked to lie in their buffer.
  std::pair<const unsigned char*, std::size_t> buffer_view(int index, const std::string& place, const std::string& what) const;

  /// Accessor `index` for `role`, of one of `types`, checked element by element range: its
  /// component type (indices: unsigned integers; attributes: floats, or 8/16-bit integers under
  /// KHR_mesh_quantization), stride, offset and count against its bufferView, and its
  /// bufferView against its buffer (section 3.6.2.4).
  CheckedAccessor check(int index, const std::string& place, const std::string& role, std::initializer_list<int> types,
                        bool indices) const;

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

 private:
  const Source& src_;
  const tinygltf::Model& model_;
};

}  // namespace radiosity::detail
