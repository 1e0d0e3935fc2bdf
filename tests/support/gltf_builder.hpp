// Small glTF 2.0 files made in the tests, so that each test says what its file holds: a JSON
// document and one binary buffer, written as a .gltf (buffer as a base64 data URI, or an
// external .bin) or as a .glb (the buffer as its BIN chunk).
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace test {

inline std::string base64(const std::string& bytes) {
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16 | std::uint32_t(std::uint8_t(bytes[i + 1])) << 8 |
                            std::uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

class GltfBuilder {
 public:
  nlohmann::json doc = {{"asset", {{"version", "2.0"}, {"generator", "radiosity tests"}}}};
  std::string bin;  ///< buffer 0

  /// Appends raw bytes (4-byte aligned) as a bufferView; returns its index.
  int view(const void* data, std::size_t bytes, std::size_t stride = 0) {
    while (bin.size() % 4 != 0) bin += '\0';
    const std::size_t offset = bin.size();
    bin.append(static_cast<const char*>(data), bytes);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (stride) v["byteStride"] = stride;
    return push("bufferViews", v);
  }
  int accessor(int view_index, int component_type, std::size_t count, const char* type, nlohmann::json extra = {}) {
    nlohmann::json a = {{"bufferView", view_index}, {"componentType", component_type}, {"count", count}, {"type", type}};
    for (auto& [k, v] : extra.items()) a[k] = v;
    return push("accessors", a);
  }
  int positions(const std::vector<glm::vec3>& p) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& q : p) lo = glm::min(lo, q), hi = glm::max(hi, q);
    return accessor(view(p.data(), p.size() * sizeof(glm::vec3)), 5126, p.size(), "VEC3",
                    {{"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
  }
  int vec3s(const std::vector<glm::vec3>& v) { return accessor(view(v.data(), v.size() * sizeof(glm::vec3)), 5126, v.size(), "VEC3"); }
  int vec2s(const std::vector<glm::vec2>& v) { return accessor(view(v.data(), v.size() * sizeof(glm::vec2)), 5126, v.size(), "VEC2"); }
  int indices(const std::vector<std::uint32_t>& i) {
    return accessor(view(i.data(), i.size() * sizeof(std::uint32_t)), 5125, i.size(), "SCALAR");
  }

  int material(nlohmann::json m) { return push("materials", std::move(m)); }
  /// A primitive of triangles with positions (and normals when given), indexed.
  nlohmann::json triangles(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx, int material_index = -1,
                           const std::vector<glm::vec3>& normals = {}) {
    nlohmann::json prim = {{"attributes", {{"POSITION", positions(p)}}}, {"indices", indices(idx)}};
    if (!normals.empty()) prim["attributes"]["NORMAL"] = vec3s(normals);
    if (material_index >= 0) prim["material"] = material_index;
    return prim;
  }
  /// The quad a, b, c, d (counter-clockwise seen from its front) as two triangles.
  nlohmann::json quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, int material_index = -1) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, d - a));
    return triangles({a, b, c, d}, {0, 1, 2, 0, 2, 3}, material_index, {n, n, n, n});
  }
  /// The box [lo, hi] as one primitive of 12 triangles, facing out (or in, `inward`).
  nlohmann::json box(glm::vec3 lo, glm::vec3 hi, int material_index = -1, bool inward = false) {
    std::vector<glm::vec3> p;
    for (int k = 0; k < 8; ++k) p.emplace_back(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    std::vector<std::uint32_t> idx = {0, 2, 3, 0, 3, 1,  4, 5, 7, 4, 7, 6,  0, 1, 5, 0, 5, 4,
                                      2, 6, 7, 2, 7, 3,  0, 4, 6, 0, 6, 2,  1, 3, 7, 1, 7, 5};
    if (inward)
      for (std::size_t t = 0; t < idx.size(); t += 3) std::swap(idx[t + 1], idx[t + 2]);
    return triangles(p, idx, material_index);
  }
  int mesh(nlohmann::json primitives, const std::string& name = "") {
    nlohmann::json m = {{"primitives", primitives.is_array() ? primitives : nlohmann::json::array({primitives})}};
    if (!name.empty()) m["name"] = name;
    return push("meshes", m);
  }
  int node(nlohmann::json n) { return push("nodes", std::move(n)); }
  /// Scene 0, the default, with these root nodes.
  void scene(const std::vector<int>& roots) {
    doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
    doc["scene"] = 0;
  }

  /// The document with buffer 0 as a base64 data URI (or `bin_uri` when not empty: an
  /// external file, which write_gltf() writes beside the .gltf).
  std::string gltf(const std::string& bin_uri = "") const {
    nlohmann::json d = doc;
    if (!bin.empty() || d.contains("bufferViews"))
      d["buffers"] = nlohmann::json::array(
          {{{"byteLength", bin.size()},
            {"uri", bin_uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : bin_uri}}});
    return d.dump(1);
  }
  /// The GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
  std::string glb() const {
    nlohmann::json d = doc;
    if (!bin.empty()) d["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
    std::string json = d.dump();
    while (json.size() % 4 != 0) json += ' ';
    std::string data = bin;
    while (data.size() % 4 != 0) data += '\0';
    std::string out;
    auto u32 = [&out](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) out += static_cast<char>((v >> (8 * k)) & 0xFF);
    };
    const std::size_t length = 12 + 8 + json.size() + (data.empty() ? 0 : 8 + data.size());
    out += "glTF";
    u32(2);
    u32(static_cast<std::uint32_t>(length));
    u32(static_cast<std::uint32_t>(json.size()));
    u32(0x4E4F534A);
    out += json;
    if (!data.empty()) {
      u32(static_cast<std::uint32_t>(data.size()));
      u32(0x004E4942);
      out += data;
    }
    return out;
  }

 private:
  int push(const char* array, nlohmann::json value) {
    if (!doc.contains(array)) doc[array] = nlohmann::json::array();
    doc[array].push_back(std::move(value));
    return static_cast<int>(doc[array].size()) - 1;
  }
};

inline std::filesystem::path write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

}  // namespace test
