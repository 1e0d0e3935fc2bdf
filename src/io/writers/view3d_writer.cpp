// save_view3d(): a scene as a NIST View3D 3-D vertex/surface file (.vs3).
// Based on: G. N. Walton, "Calculation of obstructed view factors by adaptive integration",
// NISTIR 6925, National Institute of Standards and Technology, Gaithersburg MD, 2002; the
// View3D 3.2 user manual's input format and its reader (getdat.c), which decide what we may
// write: surfaces of 3 or 4 convex planar corners, numbered with the radiating ones first,
// names of one word, and control words View3D reads back unchanged. Every file written here
// is read back by load_view3d() without a warning (docs/SCENE_VS3.md).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "io/view3d_text.hpp"
#include "radiosity/io.hpp"
#include "radiosity/version.hpp"

namespace radiosity {
inline namespace v1 {
namespace {

namespace v3d = detail::view3d;

[[noreturn]] void invalid(const std::string& problem) {
  throw Error(ErrorCode::invalid_argument, "save_view3d: " + problem);
}

/// A group name as one View3D word: blanks, commas and line breaks become '_', and so does a
/// first '!' or '*' (a comment, or View3D's end of data).
std::string surface_name(const std::string& group) {
  std::string name = group.empty() ? std::string("default") : group;
  for (char& c : name)
    if (c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\n' || c == '\0') c = '_';
  if (name[0] == '!' || name[0] == '*') name[0] = '_';
  return name;
}

void check_control(const View3DControl& c, std::size_t radiating_surfaces) {
  if (c.output_format < 0 || c.output_format > 2)
    invalid("View3DControl::output_format " + std::to_string(c.output_format) + " is not 0, 1 or 2");
  if (!(c.epsilon > 0.0f) || !std::isfinite(c.epsilon)) invalid("View3DControl::epsilon must be finite and > 0");
  if (c.max_unobstructed_recursions < 4) invalid("View3DControl::max_unobstructed_recursions must be >= 4");
  if (c.max_obstructed_recursions < 4) invalid("View3DControl::max_obstructed_recursions must be >= 4");
  if (c.min_obstructed_recursions < 0) invalid("View3DControl::min_obstructed_recursions must be >= 0");
  if (c.row < 0 || c.column < 0) invalid("View3DControl::row and column must be >= 0");
  if (c.column > 0 && c.row == 0) invalid("View3DControl::column needs a row");
  if (static_cast<std::size_t>(c.row) > radiating_surfaces || static_cast<std::size_t>(c.column) > radiating_surfaces)
    invalid("View3DControl::row and column must be at most the " + std::to_string(radiating_surfaces) +
            " radiating surfaces written");
  for (const auto& [name, value] : c.other) {
    bool bad = name.empty() || value.empty();
    for (const char ch : name + value) bad = bad || v3d::breaks_word(ch);
    if (bad) invalid("View3DControl::other: '" + name + "=" + value + "' is not two words without blanks, ',', '=' or '!'");
  }
}

/// The pieces of a polygon that View3D can take: itself when it has at most 4 corners, else a
/// fan of quadrilaterals (and a last triangle) from its first corner, each convex because the
/// polygon is.
std::vector<std::vector<std::size_t>> pieces(std::size_t corners) {
  if (corners <= 4) {
    std::vector<std::size_t> all(corners);
    for (std::size_t i = 0; i < corners; ++i) all[i] = i;
    return {all};
  }
  std::vector<std::vector<std::size_t>> out;
  std::size_t i = 1;
  while (i + 1 < corners) {
    if (i + 2 < corners) {
      out.push_back({0, i, i + 1, i + 2});
      i += 2;
    } else {
      out.push_back({0, i, i + 1});
      i += 1;
    }
  }
  return out;
}

}  // namespace

void save_view3d(const Scene& scene, const View3DControl& control, const std::string& title,
                 const std::filesystem::path& path) {
  const std::vector<Polygon>& polygons = scene.polygons();

  // Surfaces in View3D's order: radiating polygons, then obstruction-only ones, each as its pieces.
  struct Piece {
    PolygonId polygon;
    std::vector<std::size_t> corners;
    std::size_t combine;  ///< surface number this piece is combined with, or 0
  };
  std::vector<Piece> surfaces;
  std::size_t radiating = 0;
  for (const bool obstruction : {false, true})
    for (PolygonId id = 0; id < polygons.size(); ++id) {
      if (polygons[id].obstruction_only != obstruction) continue;
      const std::size_t first = surfaces.size() + 1;
      const auto split = pieces(polygons[id].vertices.size());
      for (std::size_t k = 0; k < split.size(); ++k)
        surfaces.push_back(Piece{id, split[k], k > 0 && !obstruction ? first : 0});
      if (!obstruction) radiating = surfaces.size();
    }
  if (radiating == 0) invalid("the scene has no radiating polygons (only obstruction-only ones, or none)");
  check_control(control, radiating);

  // Vertices: one per bit-identical position, numbered in order of first use.
  std::map<std::array<std::uint32_t, 3>, std::size_t> index_of;
  std::vector<glm::vec3> vertices;
  std::vector<std::array<std::size_t, 4>> corner_numbers(surfaces.size(), {0, 0, 0, 0});
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    for (std::size_t k = 0; k < surfaces[s].corners.size(); ++k) {
      const glm::vec3& p = polygons[surfaces[s].polygon].vertices[surfaces[s].corners[k]];
      std::array<std::uint32_t, 3> bits;
      std::memcpy(bits.data(), &p, sizeof bits);
      auto [it, added] = index_of.try_emplace(bits, vertices.size() + 1);
      if (added) vertices.push_back(p);
      corner_numbers[s][k] = it->second;
    }

  std::string text;
  std::string clean_title = title;
  for (char& c : clean_title)
    if (c == '\r' || c == '\n') c = ' ';
  text += "T " + clean_title + "\n";
  text += "C encl=" + std::to_string(control.enclosure ? 1 : 0) + " emit=" + std::to_string(control.script_f ? 1 : 0) +
          " out=" + std::to_string(control.output_format) + " list=" + std::to_string(control.list) +
          " eps=" + v3d::shortest(control.epsilon) + " maxU=" + std::to_string(control.max_unobstructed_recursions) +
          " maxO=" + std::to_string(control.max_obstructed_recursions) +
          " minO=" + std::to_string(control.min_obstructed_recursions) + " row=" + std::to_string(control.row) +
          " col=" + std::to_string(control.column);
  if (control.reverse_projections) text += " prjD=1";
  for (const auto& [name, value] : control.other) text += " " + name + "=" + value;
  text += "\nF 3\n";
  text += "! written by radiosity " RADIOSITY_VERSION_STRING " (save_view3d): " + std::to_string(vertices.size()) +
          " vertices, " + std::to_string(radiating) + " radiating surfaces, " +
          std::to_string(surfaces.size() - radiating) + " obstruction surfaces\n";
  text += "!  #  x y z\n";
  // In the file's coordinates: a scene read with a local origin is written where it was. The
  // sum (a float plus a round origin) is exact in double or within its rounding, far below a
  // float's spacing, so the file reads back to the same floats.
  const glm::dvec3 origin = scene.origin();
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    text += "V " + std::to_string(v + 1);
    for (int k = 0; k < 3; ++k)
      text += " " + (origin[k] == 0.0 ? v3d::shortest(vertices[v][k])
                                      : v3d::shortest(static_cast<double>(vertices[v][k]) + origin[k]));
    text += "\n";
  }
  text += "!  #  v1 v2 v3 v4 base cmb emit name\n";
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const Polygon& p = polygons[surfaces[s].polygon];
    const Rgb& rho = scene.material(p.material).reflectance;
    // Reflectance < 1 keeps this > 0 but for rounding; View3D itself reads 0.001 at least.
    const float emissivity = std::max(1.0f - (rho.x + rho.y + rho.z) / 3.0f, 1e-6f);
    text += (p.obstruction_only ? "O " : "S ") + std::to_string(s + 1);
    for (const std::size_t c : corner_numbers[s]) text += " " + std::to_string(c);
    text += " 0 " + std::to_string(surfaces[s].combine) + " " + v3d::shortest(emissivity) + " " +
            surface_name(scene.groups()[p.group]) + "\n";
  }
  text += "End of data\n";

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::io_error, "save_view3d: cannot open '" + path.string() + "' for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw Error(ErrorCode::io_error, "save_view3d: cannot write '" + path.string() + "'");
}

}  // namespace v1
}  // namespace radiosity
