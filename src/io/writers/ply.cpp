// Binary little-endian PLY export of a solution's leaf elements, for viewing the radiosity on the
// mesh in MeshLab or Blender: per-vertex position, float radiosity and 8-bit sRGB display colour;
// faces are triangles (quads split in two), since many importers handle nothing else well.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "io/writers/srgb.hpp"
#include "radiosity/io.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

constexpr float kPi = 3.14159265358979323846f;

// PLY's binary_little_endian, written byte by byte so the file is the same on any host.
void put_u32(std::string& out, std::uint32_t u) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((u >> (8 * i)) & 0xffu));
}
void put_f32(std::string& out, float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  put_u32(out, u);
}

void put_f64(std::string& out, double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((u >> (8 * i)) & 0xffu));
}

/// Vertex positions in the scene file's coordinates (Scene::origin()): floats as the scene
/// holds them, or, for a scene read with a local origin, doubles with the origin added (a float
/// could not hold the sum: that is why the origin was taken off).
class PlyPositions {
 public:
  explicit PlyPositions(const glm::dvec3& origin) : origin_(origin), wide_(origin != glm::dvec3(0.0)) {}
  /// A comment line for the header (before the elements, where every reader accepts one).
  std::string comment() const {
    if (!wide_) return {};
    char text[200];
    std::snprintf(text, sizeof text, "comment x/y/z: the scene's positions plus its origin (%.17g %.17g %.17g)\n",
                  origin_.x, origin_.y, origin_.z);
    return text;
  }
  std::string properties() const {
    std::string out;
    for (const char* p : {"x", "y", "z"}) out += std::string(wide_ ? "property double " : "property float ") + p + "\n";
    return out;
  }
  void put(std::string& out, const glm::vec3& p) const {
    for (int c = 0; c < 3; ++c)
      if (wide_)
        put_f64(out, static_cast<double>(p[c]) + origin_[c]);
      else
        put_f32(out, p[c]);
  }

 private:
  glm::dvec3 origin_;
  bool wide_;
};

/// Writes header + body to `path`; `who` names the writer in errors.
void write_file(const std::filesystem::path& path, const std::string& header, const std::string& body, const char* who) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::io_error, std::string(who) + ": cannot open '" + path.string() + "' for writing");
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  out.close();
  if (!out) throw Error(ErrorCode::io_error, std::string(who) + ": cannot write '" + path.string() + "'");
}

void check_exposure(const PngOptions& options, const std::string& where) {
  if (!(options.exposure >= 0.0f) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::invalid_argument, where + "PngOptions::exposure must be finite and >= 0");
}

}  // namespace

void write_ply(const Solution& solution, const std::filesystem::path& path, const PngOptions& options) {
  const std::string where = "write_ply: '" + path.string() + "': ";
  check_exposure(options, where);

  const PatchHierarchy& h = solution.hierarchy();
  const std::vector<glm::vec3>& positions = h.vertices();
  const std::vector<Rgb> B = solution.vertex_radiosity();
  if (B.size() != positions.size())
    throw Error(ErrorCode::invalid_argument, where + "the solution has " + std::to_string(B.size()) +
                                                 " vertex radiosities for " + std::to_string(positions.size()) +
                                                 " vertices");

  // Vertices used by leaves, numbered in order of first use; each leaf gives corner_count - 2
  // triangles as a fan from its first corner (elements are convex). Back faces of translucent
  // leaves follow, over their own copies of the vertices (numbered after the fronts').
  std::vector<std::uint32_t> remap(positions.size(), kNone), back_remap(positions.size(), kNone);
  std::vector<std::uint32_t> used, used_back, backs;
  const std::vector<Rgb>& back = solution.back_radiosity();
  const std::vector<Rgb> back_B = solution.vertex_back_radiosity();
  std::size_t triangles = 0;
  for (std::uint32_t leaf : h.leaves()) {
    const Element& e = h.element(leaf);
    const bool two_faces = !back.empty() && (back[leaf].x > 0.0f || back[leaf].y > 0.0f || back[leaf].z > 0.0f);
    if (two_faces) backs.push_back(leaf);
    for (int c = 0; c < e.corner_count(); ++c) {
      const std::uint32_t v = e.corners[static_cast<std::size_t>(c)];
      if (v >= positions.size())
        throw Error(ErrorCode::invalid_argument, where + "element " + std::to_string(leaf) + " has vertex id " +
                                                     std::to_string(v) + " out of range");
      if (remap[v] == kNone) {
        remap[v] = static_cast<std::uint32_t>(used.size());
        used.push_back(v);
      }
      if (two_faces && back_remap[v] == kNone) {
        back_remap[v] = static_cast<std::uint32_t>(used_back.size());
        used_back.push_back(v);
      }
    }
    triangles += static_cast<std::size_t>(e.corner_count() - 2) * (two_faces ? 2 : 1);
  }
  for (std::uint32_t& v : back_remap)
    if (v != kNone) v += static_cast<std::uint32_t>(used.size());
  const std::size_t vertex_count = used.size() + used_back.size();
  if (vertex_count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw Error(ErrorCode::invalid_argument, where + "too many vertices for PLY int indices");

  std::string header;
  header += "ply\nformat binary_little_endian 1.0\n";
  header += std::string("comment written by radiosity ") + version() + "\n";
  header += "comment radiosity_r/g/b: radiosity B in W/m^2 per scene unit^2; red/green/blue: sRGB of B/pi x exposure\n";
  if (!backs.empty())
    header += "comment translucent elements have a back face over their own vertex copies (back radiosity)\n";
  const PlyPositions xyz(solution.origin());
  header += xyz.comment();
  header += "element vertex " + std::to_string(vertex_count) + "\n";
  header += xyz.properties();
  for (const char* p : {"radiosity_r", "radiosity_g", "radiosity_b"}) header += std::string("property float ") + p + "\n";
  for (const char* p : {"red", "green", "blue"}) header += std::string("property uchar ") + p + "\n";
  header += "element face " + std::to_string(triangles) + "\n";
  header += "property list uchar int vertex_indices\n";
  header += "end_header\n";

  std::string body;
  body.reserve(vertex_count * 27 + triangles * 13);
  auto put_vertex = [&](std::uint32_t v, const Rgb& b) {
    xyz.put(body, positions[v]);
    for (int c = 0; c < 3; ++c) put_f32(body, b[c]);
    // Displayed radiance of a diffuse surface is B / pi.
    for (int c = 0; c < 3; ++c) body.push_back(static_cast<char>(detail::srgb8(options.exposure * b[c] / kPi)));
  };
  for (std::uint32_t v : used) put_vertex(v, B[v]);
  for (std::uint32_t v : used_back) put_vertex(v, back_B[v]);
  auto put_faces = [&](std::uint32_t leaf, const std::vector<std::uint32_t>& index, bool reversed) {
    const Element& e = h.element(leaf);
    for (int t = 1; t + 1 < e.corner_count(); ++t) {
      const std::uint32_t a = index[e.corners[0]], b = index[e.corners[static_cast<std::size_t>(t)]],
                          c = index[e.corners[static_cast<std::size_t>(t + 1)]];
      body.push_back(3);
      put_u32(body, a);
      put_u32(body, reversed ? c : b);
      put_u32(body, reversed ? b : c);
    }
  };
  for (std::uint32_t leaf : h.leaves()) put_faces(leaf, remap, false);
  for (std::uint32_t leaf : backs) put_faces(leaf, back_remap, true);

  write_file(path, header, body, "write_ply");
}

void write_mesh_ply(const Scene& scene, const Solution& solution, MeshId mesh, const std::filesystem::path& path,
                    const PngOptions& options) {
  const std::string where = "write_mesh_ply: '" + path.string() + "': ";
  check_exposure(options, where);
  if (mesh >= scene.meshes().size())
    throw Error(ErrorCode::invalid_argument, where + "mesh " + std::to_string(mesh) + " does not exist (the scene has " +
                                                 std::to_string(scene.meshes().size()) + " meshes)");
  const Mesh& m = scene.meshes()[mesh];
  if (mesh >= solution.meshes().size() || solution.meshes()[mesh].triangle_polygon != m.triangle_polygon ||
      solution.meshes()[mesh].positions.size() != m.positions.size())
    throw Error(ErrorCode::invalid_argument,
                where + "mesh " + std::to_string(mesh) + " of the scene is not the mesh the solution was solved with");
  const std::vector<Rgb> B = solution.mesh_vertex_values(mesh, Quantity::radiosity);
  const std::vector<Rgb> H = solution.mesh_vertex_values(mesh, Quantity::irradiance);
  std::size_t triangles = 0;
  for (PolygonId p : m.triangle_polygon) triangles += p != kNone ? 1 : 0;
  if (m.positions.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw Error(ErrorCode::invalid_argument, where + "too many vertices for PLY int indices");
  const bool uv = m.uv1.size() == m.positions.size();

  std::string header;
  header += "ply\nformat binary_little_endian 1.0\n";
  header += std::string("comment written by radiosity ") + version() + "\n";
  header += "comment the host mesh's own vertices and kept triangles; s/t: its lightmap UV1\n";
  header += "comment irradiance_r/g/b: H, radiosity_r/g/b: B, W/m^2 per scene unit^2; red/green/blue: sRGB of B/pi x exposure\n";
  const PlyPositions xyz(scene.origin());
  header += xyz.comment();
  header += "element vertex " + std::to_string(m.positions.size()) + "\n";
  header += xyz.properties();
  std::vector<const char*> properties;
  if (uv) properties.insert(properties.end(), {"s", "t"});
  properties.insert(properties.end(), {"irradiance_r", "irradiance_g", "irradiance_b", "radiosity_r", "radiosity_g", "radiosity_b"});
  for (const char* p : properties) header += std::string("property float ") + p + "\n";
  for (const char* p : {"red", "green", "blue"}) header += std::string("property uchar ") + p + "\n";
  header += "element face " + std::to_string(triangles) + "\n";
  header += "property list uchar int vertex_indices\n";
  header += "end_header\n";

  std::string body;
  body.reserve(m.positions.size() * 47 + triangles * 13);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    xyz.put(body, m.positions[v]);
    if (uv) {
      put_f32(body, m.uv1[v].x);
      put_f32(body, m.uv1[v].y);
    }
    for (int c = 0; c < 3; ++c) put_f32(body, H[v][c]);
    for (int c = 0; c < 3; ++c) put_f32(body, B[v][c]);
    for (int c = 0; c < 3; ++c) body.push_back(static_cast<char>(detail::srgb8(options.exposure * B[v][c] / kPi)));
  }
  for (std::size_t t = 0; t < m.triangle_polygon.size(); ++t) {
    if (m.triangle_polygon[t] == kNone) continue;
    body.push_back(3);
    for (int k = 0; k < 3; ++k) put_u32(body, m.indices[3 * t + static_cast<std::size_t>(k)]);
  }
  write_file(path, header, body, "write_mesh_ply");
}

}  // namespace v1
}  // namespace radiosity
