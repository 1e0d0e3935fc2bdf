// View3D's view-factor output file, from a ViewFactorMatrix, so that scripts written for View3D's
// output (View3D's own ReadVF, ViewHT, uDALES' view3d.m, ...) read ours. Header-only and free of
// CLI11, so the test suite checks it byte for byte.
// Based on: G. N. Walton, "Calculation of obstructed view factors by adaptive integration",
// NISTIR 6925, NIST, 2002; View3D 3.2's savevf.c (SaveVF, SaveF0, SaveF1) and readvf.c
// (ReadVF), whose layout this is (docs/SCENE_VS3.md, "Output file"):
//   text (out=0):   "<program> <version> <out> <encl> <emit> <N>" blank-padded to 30 characters
//                   the N areas ("%g"), then N rows F(i -> 1..N) ("%.6f"), then the N
//                   emissivities ("%.3f"), each a line of values separated by one blank;
//   binary (out=1): the same header as 32 bytes ending "\r\n", then the areas, the rows and
//                   the emissivities as 32-bit little-endian floats.
// View3D's own files say "View3D 3.2" (or its version) where ours say "radiosity <version>":
// its readers take the two words as names and only read the numbers after them.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "radiosity/form_factors.hpp"
#include "radiosity/io.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/version.hpp"

namespace cli {

/// Per row of `matrix`, the View3D emissivity of its surface: 1 - the mean diffuse reflectance
/// of the polygon's material (polygon level), or that of the group's polygons weighted by their
/// area (group level; obstruction-only polygons left out, as they are from the rows). Throws
/// radiosity::Error{invalid_argument} for an element-level matrix (its ids are elements of a
/// mesh the scene does not hold) or an id the scene does not have.
inline std::vector<float> view3d_emissivities(const radiosity::Scene& scene, const radiosity::ViewFactorMatrix& matrix) {
  using radiosity::Error;
  using radiosity::ErrorCode;
  auto emissivity = [&](const radiosity::Polygon& p) {
    const radiosity::Rgb& rho = scene.material(p.material).reflectance;
    return 1.0 - (static_cast<double>(rho.x) + rho.y + rho.z) / 3.0;
  };
  std::vector<float> out;
  out.reserve(matrix.ids.size());
  if (matrix.level == radiosity::ViewFactorLevel::polygon) {
    for (const std::uint32_t id : matrix.ids) {
      if (id >= scene.polygons().size())
        throw Error(ErrorCode::invalid_argument, "view3d_emissivities: no polygon " + std::to_string(id));
      out.push_back(static_cast<float>(emissivity(scene.polygons()[id])));
    }
    return out;
  }
  if (matrix.level != radiosity::ViewFactorLevel::group)
    throw Error(ErrorCode::invalid_argument,
                "view3d_emissivities: an element-level matrix needs its emissivities from the caller");
  for (const std::uint32_t id : matrix.ids) {
    if (id >= scene.groups().size())
      throw Error(ErrorCode::invalid_argument, "view3d_emissivities: no group " + std::to_string(id));
    double weighted = 0.0, area = 0.0;
    for (const radiosity::Polygon& p : scene.polygons())
      if (p.group == id && !p.obstruction_only) {
        weighted += emissivity(p) * p.area;
        area += p.area;
      }
    out.push_back(static_cast<float>(area > 0.0 ? weighted / area : 1.0));
  }
  return out;
}

/// View3D's output file for `matrix` (square: rows and columns are the same surfaces) with the
/// per-row `emissivity` (view3d_emissivities()), in the format control.output_format names:
/// 0 text, 1 binary (the layout above). The header's encl and emit flags are
/// control.enclosure and control.script_f: they say what the numbers are (rows closed to 1,
/// Hottel's script-F), so pass the control of a matrix computed to match. Every factor is
/// written, zeros included: N^2 values. `program` and `version` are one word each.
/// Throws radiosity::Error{invalid_argument} for out=2 (uDALES' sparse format is not written),
/// a matrix whose arrays disagree (row_offsets, columns, values, area) or a column out of range,
/// an emissivity count other than the rows, or a header longer than View3D's 30 characters.
/// Thread safety: pure.
inline std::string view3d_output(const radiosity::ViewFactorMatrix& matrix, const std::vector<float>& emissivity,
                                 const radiosity::View3DControl& control, const std::string& program = "radiosity",
                                 const std::string& version = RADIOSITY_VERSION_STRING) {
  using radiosity::Error;
  using radiosity::ErrorCode;
  const std::size_t n = matrix.area.size();
  if (control.output_format != 0 && control.output_format != 1)
    throw Error(ErrorCode::invalid_argument, "view3d_output: out=" + std::to_string(control.output_format) +
                                                 " is not written (0 text and 1 binary are)");
  if (matrix.row_offsets.size() != n + 1 || matrix.row_offsets[0] != 0 || matrix.columns.size() != matrix.values.size() ||
      matrix.row_offsets[n] != matrix.values.size())
    throw Error(ErrorCode::invalid_argument, "view3d_output: the matrix's row_offsets, columns, values and area disagree");
  if (emissivity.size() != n)
    throw Error(ErrorCode::invalid_argument, "view3d_output: " + std::to_string(emissivity.size()) +
                                                 " emissivities for " + std::to_string(n) + " rows");

  // The dense rows, as View3D holds them (single precision).
  std::vector<float> dense(n * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    if (matrix.row_offsets[i] > matrix.row_offsets[i + 1])
      throw Error(ErrorCode::invalid_argument, "view3d_output: row_offsets decrease at row " + std::to_string(i));
    for (std::uint64_t k = matrix.row_offsets[i]; k < matrix.row_offsets[i + 1]; ++k) {
      if (matrix.columns[k] >= n)
        throw Error(ErrorCode::invalid_argument, "view3d_output: column " + std::to_string(matrix.columns[k]) +
                                                     " of row " + std::to_string(i) + " is out of range");
      dense[i * n + matrix.columns[k]] = matrix.values[k];
    }
  }

  // SaveVF's header: sprintf("%s %s %d %d %d %d"), blanks up to 30 characters, then the line end.
  std::string header = program + " " + version + " " + std::to_string(control.output_format) + " " +
                       std::to_string(control.enclosure ? 1 : 0) + " " + std::to_string(control.script_f ? 1 : 0) + " " +
                       std::to_string(n);
  if (header.size() > 30)
    throw Error(ErrorCode::invalid_argument, "view3d_output: the header '" + header +
                                                 "' is longer than the 30 characters View3D's readers read");
  header.resize(30, ' ');

  std::string out;
  if (control.output_format == 1) {
    // SaveF1: the header as 32 bytes, then float32 arrays (little-endian, as on the PCs View3D
    // was written for; byte by byte so the file is the same on any host).
    out = header + "\r\n";
    auto put = [&out](float v) {
      std::uint32_t u = 0;
      std::memcpy(&u, &v, sizeof u);
      for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((u >> (8 * b)) & 0xffu));
    };
    for (const double a : matrix.area) put(static_cast<float>(a));
    for (const float f : dense) put(f);
    for (const float e : emissivity) put(e);
    return out;
  }

  // SaveF0: printf formats of View3D, applied to the single-precision values it holds.
  out = header + "\n";
  char buffer[64];
  auto line = [&](const char* format, auto value_at) {
    for (std::size_t i = 0; i < n; ++i) {
      std::snprintf(buffer, sizeof buffer, format, static_cast<double>(value_at(i)));
      if (i > 0) out += ' ';
      out += buffer;
    }
    out += '\n';
  };
  line("%g", [&](std::size_t i) { return static_cast<float>(matrix.area[i]); });
  for (std::size_t r = 0; r < n; ++r) line("%.6f", [&](std::size_t i) { return dense[r * n + i]; });
  line("%.3f", [&](std::size_t i) { return emissivity[i]; });
  return out;
}

}  // namespace cli
