// Binary little-endian PLY export of a solution's leaf elements, for viewing the radiosity on the
// mesh in MeshLab or Blender: per-vertex position, float radiosity and 8-bit sRGB display colour;
// faces are triangles (quads split in two), since many importers handle nothing else well.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "io/srgb.hpp"
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

}  // namespace

void write_ply(const Solution& solution, const std::filesystem::path& path, const PngOptions& options) {
  const std::string where = "write_ply: '" + path.string() + "': ";
  if (!(options.exposure >= 0.0f) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::invalid_argument, where + "PngOptions::exposure must be finite and >= 0");

  const PatchHierarchy& h = solution.hierarchy();
  const std::vector<glm::vec3>& positions = h.vertices();
  const std::vector<Rgb> B = solution.vertex_radiosity();
  if (B.size() != positions.size())
    throw Error(ErrorCode::invalid_argument, where + "the solution has " + std::to_string(B.size()) +
                                                 " vertex radiosities for " + std::to_string(positions.size()) +
                                                 " vertices");

  // Vertices used by leaves, numbered in order of first use; each leaf gives corner_count - 2
  // triangles as a fan from its first corner (elements are convex).
  std::vector<std::uint32_t> remap(positions.size(), kNone);
  std::vector<std::uint32_t> used;
  std::size_t triangles = 0;
  for (std::uint32_t leaf : h.leaves()) {
    const Element& e = h.element(leaf);
    for (int c = 0; c < e.corner_count(); ++c) {
      const std::uint32_t v = e.corners[static_cast<std::size_t>(c)];
      if (v >= positions.size())
        throw Error(ErrorCode::invalid_argument, where + "element " + std::to_string(leaf) + " has vertex id " +
                                                     std::to_string(v) + " out of range");
      if (remap[v] == kNone) {
        remap[v] = static_cast<std::uint32_t>(used.size());
        used.push_back(v);
      }
    }
    triangles += static_cast<std::size_t>(e.corner_count() - 2);
  }
  if (used.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw Error(ErrorCode::invalid_argument, where + "too many vertices for PLY int indices");

  std::string header;
  header += "ply\nformat binary_little_endian 1.0\n";
  header += std::string("comment written by radiosity ") + version() + "\n";
  header += "comment radiosity_r/g/b: radiosity B in W/m^2 per scene unit^2; red/green/blue: sRGB of B/pi x exposure\n";
  header += "element vertex " + std::to_string(used.size()) + "\n";
  for (const char* p : {"x", "y", "z", "radiosity_r", "radiosity_g", "radiosity_b"})
    header += std::string("property float ") + p + "\n";
  for (const char* p : {"red", "green", "blue"}) header += std::string("property uchar ") + p + "\n";
  header += "element face " + std::to_string(triangles) + "\n";
  header += "property list uchar int vertex_indices\n";
  header += "end_header\n";

  std::string body;
  body.reserve(used.size() * 27 + triangles * 13);
  for (std::uint32_t v : used) {
    for (int c = 0; c < 3; ++c) put_f32(body, positions[v][c]);
    for (int c = 0; c < 3; ++c) put_f32(body, B[v][c]);
    // Displayed radiance of a diffuse surface is B / pi.
    for (int c = 0; c < 3; ++c) body.push_back(static_cast<char>(detail::srgb8(options.exposure * B[v][c] / kPi)));
  }
  for (std::uint32_t leaf : h.leaves()) {
    const Element& e = h.element(leaf);
    for (int t = 1; t + 1 < e.corner_count(); ++t) {
      body.push_back(3);
      put_u32(body, remap[e.corners[0]]);
      put_u32(body, remap[e.corners[static_cast<std::size_t>(t)]]);
      put_u32(body, remap[e.corners[static_cast<std::size_t>(t + 1)]]);
    }
  }

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::io_error, "write_ply: cannot open '" + path.string() + "' for writing");
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  out.close();
  if (!out) throw Error(ErrorCode::io_error, "write_ply: cannot write '" + path.string() + "'");
}

}  // namespace v1
}  // namespace radiosity
