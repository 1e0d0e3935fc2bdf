// Wavefront OBJ/MTL reader. Both parsers are our own: every message names the file and the
// line, and the forgiving policy of reader_warnings.hpp (what a renderer would step over, such as
// degenerate faces, Kd 1 or a missing MTL, is fixed with one warning per kind) needs the parser
// to know the line of each element. tinyobjloader, which parsed the OBJ before (the MTL reader
// was always ours), reports no lines, so the file had to be tokenised a second time to find them.
// The OBJ is read in one pass: vertices as they come, each face corner resolved at once to its
// vertex's position, with the group (`g`, `o`) and material (`usemtl`) current at the face; faces
// stay polygons, of any size. The MTL mapping follows the format's own description of the
// illumination models (Wavefront's MTL specification) and the PBR extension as tinyobjloader
// and Blender read it.
#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/readers/local_origin.hpp"
#include "io/readers/material_mapping.hpp"
#include "io/readers/reader_files.hpp"
#include "io/readers/reader_warnings.hpp"
#include "io/readers/readers.hpp"
#include "radiosity/brdf.hpp"
#include "core/assert.hpp"
#include "core/color.hpp"
#include "core/constants.hpp"

namespace radiosity::detail {
namespace {

namespace fs = std::filesystem;

/// Largest diffuse + specular albedo an MTL material keeps; Ks is scaled down to fit (see below).
constexpr float kMaxAlbedo = kMaxForgivenAlbedo;

// ---------------------------------------------------------------------------------------------
// Text helpers

/// "file:line: ", the prefix of every located message.
/// "file:line", the location that ReaderWarnings takes.
std::string loc(const fs::path& file, std::size_t line) { return file.string() + ":" + std::to_string(line); }

std::string at(const fs::path& file, std::size_t line) { return loc(file, line) + ": "; }

[[noreturn]] void fail(ErrorCode code, const fs::path& file, std::size_t line, const std::string& problem) {
  throw Error(code, at(file, line) + problem);
}

std::string read_text(const fs::path& path, const char* what) {
  std::string s = read_file(path, what);
  // A UTF-8 byte order mark would hide the first statement.
  if (s.compare(0, 3, "\xEF\xBB\xBF") == 0) s.erase(0, 3);
  return s;
}

/// The lines of a text, one at a time: "\n", "\r\n" and a lone "\r" each end a line, so that
/// files from any platform count lines alike. A backslash at the end of a line is an ordinary
/// character (OBJ's line continuation is not read).
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}

  /// The next line without its end, or false after the last one.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
    line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    if (end < text_.size() && text_[end] == '\r' && pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
    ++number_;
    return true;
  }
  /// 1-based number of the line next() returned last.
  std::size_t number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\r' || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

/// The words of a line (separated by spaces and tabs), one at a time, so that reading a line
/// allocates nothing.
class Words {
 public:
  explicit Words(std::string_view line) : line_(line) {}

  /// The next word, or "" at the end of the line.
  std::string_view next() {
    while (pos_ < line_.size() && is_blank(line_[pos_])) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < line_.size() && !is_blank(line_[pos_])) ++pos_;
    return line_.substr(start, pos_ - start);
  }
  /// What follows the last word read, blanks included.
  std::string_view rest() const { return line_.substr(pos_); }

 private:
  std::string_view line_;
  std::size_t pos_ = 0;
};

std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  Words words(line);
  for (std::string_view w = words.next(); !w.empty(); w = words.next()) out.push_back(w);
  return out;
}

std::optional<double> parse_real(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::optional<long long> parse_int(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

/// A number that fits a float and is neither NaN nor infinite.
std::optional<float> parse_finite_float(std::string_view s) {
  std::optional<double> v = parse_real(s);
  if (!v || !std::isfinite(*v) || std::fabs(*v) > static_cast<double>(FLT_MAX)) return std::nullopt;
  return static_cast<float>(*v);
}

// ---------------------------------------------------------------------------------------------
// MTL reader: a list of "key values" lines, each key's line kept for messages.

struct MtlKey {
  std::size_t line = 0;
  float value[3] = {0.0f, 0.0f, 0.0f};
};

struct MtlInfo {
  fs::path file;
  std::size_t line = 0;  ///< of its `newmtl`
  std::string name;
  std::map<std::string, MtlKey, std::less<>> keys;  ///< Kd Ke Ks Tf (also from Kt) Ns Ni d Tr Pr Pm illum map_Kd

  const MtlKey* key(std::string_view k) const {
    auto it = keys.find(k);
    return it == keys.end() ? nullptr : &it->second;
  }
  std::size_t line_of(std::string_view k) const {
    const MtlKey* m = key(k);
    return m ? m->line : line;
  }
  std::string where(std::string_view k) const { return loc(file, line_of(k)); }
  std::string what() const { return "material " + in_quotes(name) + ": "; }
};

/// Appends one MtlInfo per named `newmtl` of `text`, in order. Values are checked to be numbers
/// here (a value that is not one cannot mean anything); their ranges in to_material().
void scan_mtl(const fs::path& file, std::string_view text, std::vector<MtlInfo>& out) {
  Lines lines(text);
  MtlInfo* current = nullptr;
  for (std::string_view raw; lines.next(raw);) {
    const std::size_t line_no = lines.number();
    std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    std::vector<std::string_view> tok = tokens(line);
    if (tok[0] == "newmtl") {
      std::string_view name = trim(line.substr(6));
      current = nullptr;
      if (name.empty()) continue;  // a material without a name cannot be used
      out.push_back(MtlInfo{file, line_no, std::string(name), {}});
      current = &out.back();
      continue;
    }
    std::string key(tok[0]);
    if (key == "Kt") key = "Tf";
    if (key == "map_Kd") {
      if (current != nullptr) current->keys[key] = MtlKey{line_no, {}};
      continue;
    }
    const bool colour = key == "Kd" || key == "Ke" || key == "Ks" || key == "Tf";
    const bool scalar = key == "Ns" || key == "Ni" || key == "d" || key == "Tr" || key == "Pr" || key == "Pm";
    if (!colour && !scalar && key != "illum") continue;
    if (current == nullptr) continue;  // before the first newmtl: belongs to no material

    MtlKey k;
    k.line = line_no;
    if (key == "illum") {
      std::optional<long long> v = tok.size() == 2 ? parse_int(tok[1]) : std::nullopt;
      if (!v) fail(ErrorCode::parse_error, file, line_no, current->what() + "illum needs one integer");
      k.value[0] = static_cast<float>(*v);
    } else {
      if (colour && tok.size() > 1 && (tok[1] == "spectral" || tok[1] == "xyz"))
        fail(ErrorCode::parse_error, file, line_no,
             current->what() + key + " " + std::string(tok[1]) + " is not supported (give r g b)");
      const std::size_t given = tok.size() - 1;
      if (colour ? (given != 1 && given != 3) : given != 1)
        fail(ErrorCode::parse_error, file, line_no,
             current->what() + key + (colour ? " needs 1 or 3 numbers" : " needs 1 number") + ", got " +
                 std::to_string(given));
      for (std::size_t i = 0; i < given; ++i) {
        std::optional<float> v = parse_finite_float(tok[i + 1]);
        if (!v)
          fail(ErrorCode::parse_error, file, line_no,
               current->what() + key + " value " + in_quotes(tok[i + 1]) + " is not a finite number");
        k.value[i] = *v;
      }
      // A single value means grey (r = g = b), as the MTL specification says.
      if (given == 1) k.value[1] = k.value[2] = k.value[0];
    }
    current->keys[key] = k;
  }
}

/// The colour of `key`, or `fallback` when the material does not set it.
Rgb colour(const MtlInfo& info, std::string_view key, Rgb fallback) {
  if (const MtlKey* k = info.key(key)) return Rgb(k->value[0], k->value[1], k->value[2]);
  return fallback;
}

float scalar(const MtlInfo& info, std::string_view key, float fallback) {
  const MtlKey* k = info.key(key);
  return k ? k->value[0] : fallback;
}

/// `c` with every channel clamped into [0, upper]: below 0 always, above `upper` when it is
/// at least `at_or_above` (Kd 1 is clamped to 0.99, Kd 0.995 kept). Each clamp is forgiven
/// with a warning (an Error under strict, worded as the range check it replaces).
Rgb clamped(const MtlInfo& info, std::string_view key, Rgb c, float upper, float at_or_above, const char* meaning,
            const char* range, ReaderWarnings& warnings) {
  return clamp_colour(c, upper, at_or_above, warnings, "MTL " + std::string(key) + " out of range", info.where(key),
                      info.what() + std::string(key), meaning, range);
}

/// Converts one MTL material as the format means it (docs/SCENE_OBJ.md has the table).
Material to_material(const MtlInfo& info, ReaderWarnings& warnings) {
  Material m;
  m.name = info.name;
  // Without Kd the diffuse colour is 0, or 0.6 under a diffuse texture (tinyobjloader's rule:
  // the texture's mean is unknown here).
  const Rgb kd_default(info.key("map_Kd") ? 0.6f : 0.0f);
  const Rgb kd = clamped(info, "Kd", colour(info, "Kd", kd_default), kMaxAlbedo, 1.0f,
                         "a diffuse reflectance (1 or more would create energy)", "in [0, 1)", warnings);
  const Rgb ke = clamped(info, "Ke", colour(info, "Ke", Rgb(0.0f)), FLT_MAX, FLT_MAX, "an emitted radiance", ">= 0", warnings);
  m.reflectance = kd;
  m.emission = kPi * ke;

  // The illumination model, 0 to 10 in the MTL specification; -1 when not given. Another number
  // names no model and is ignored (casting 1e17 to int was undefined: a fuzzer's finding).
  int illum = -1;
  if (const MtlKey* k = info.key("illum")) {
    if (k->value[0] >= 0.0f && k->value[0] <= 10.0f)
      illum = static_cast<int>(k->value[0]);
    else
      warnings.forgive("MTL illum out of range", ErrorCode::invalid_scene, loc(info.file, k->line),
                       info.what() + "illum " + number_text(k->value[0]) + " is no illumination model (0 to 10)",
                       "ignored");
  }
  const bool refracts = illum == 4 || illum == 6 || illum == 7 || illum == 9;
  const bool mirror = illum == 3 || illum == 5 || illum == 8;
  const bool pbr = !refracts && (info.key("Pr") || info.key("Pm"));
  const bool has_ks = info.key("Ks") != nullptr && illum != 0 && illum != 1;  // 0/1: no highlights
  const Rgb ks = has_ks ? clamped(info, "Ks", colour(info, "Ks", Rgb(0.0f)), 1.0f, 1.0f + 1e-6f,
                                  "a specular reflectance", "in [0, 1]", warnings)
                        : Rgb(0.0f);

  auto positive_ni = [&]() -> std::optional<float> {
    const MtlKey* ni = info.key("Ni");
    if (!ni) return std::nullopt;
    if (ni->value[0] > 0.0f) return ni->value[0];
    warnings.forgive("MTL Ni out of range", ErrorCode::invalid_scene, loc(info.file, ni->line),
                     info.what() + "Ni " + std::to_string(ni->value[0]) + " must be > 0", "1.5 used");
    return std::nullopt;
  };

  if (refracts) {
    // A smooth dielectric: Fresnel's reflection (tinted by Ks when given) and refraction
    // (tinted by Tf, white when absent); no Phong lobe on top, which would double the
    // reflection and darken the glass.
    const Rgb tf = clamped(info, "Tf", colour(info, "Tf", Rgb(1.0f)), 1.0f, 1.0f + 1e-6f, "a transmittance", "in [0, 1]", warnings);
    set_dielectric(m, tf, positive_ni().value_or(1.5f), info.key("Ks") ? ks : Rgb(1.0f));
    return m;
  }

  if (pbr) {
    // The PBR extension: base colour Kd, metallic Pm, roughness Pr, dielectric F0 from Ni
    // (1.5 when absent); glTF's metallic-roughness model (material_mapping.hpp).
    set_metallic_roughness(m, kd, std::clamp(scalar(info, "Pm", 0.0f), 0.0f, 1.0f),
                           std::clamp(scalar(info, "Pr", 0.5f), 0.0f, 1.0f), positive_ni().value_or(1.5f));
    return m;
  }

  if (has_ks && max_channel(ks) > 0.0f) {
    m.specular = ks;
    if (mirror) {
      m.specular_exponent = 0.0f;
    } else {
      float ns = scalar(info, "Ns", 1.0f);
      if (ns < 0.0f) {
        warnings.forgive("MTL Ns out of range", ErrorCode::invalid_scene, info.where("Ns"),
                         info.what() + "Ns " + std::to_string(ns) + " must be >= 0", "1 used");
        ns = 1.0f;
      }
      m.specular_exponent = std::max(ns, 1.0f);  // 0 would mean a mirror here
    }
    // Keep Kd + Ks below 1 per channel by scaling Ks (hue kept): exported files often have
    // Kd 0.8 and Ks 0.5.
    float scale = 1.0f;
    for (int c = 0; c < 3; ++c)
      if (ks[c] > 0.0f && kd[c] + ks[c] > kMaxAlbedo) scale = std::min(scale, std::max(0.0f, (kMaxAlbedo - kd[c]) / ks[c]));
    if (scale < 1.0f) {
      m.specular = ks * scale;
      std::ostringstream problem, action;
      problem << info.what() << "Kd + Ks exceeds " << kMaxAlbedo << " (1 or more would create energy)";
      action << "Ks scaled by " << scale << " to " << describe(m.specular);
      warnings.forgive("MTL Kd + Ks", ErrorCode::invalid_scene, info.where("Ks"), problem.str(), action.str());
    }
  }

  // Dissolve (d, or Tr = 1 - d): a fraction 1 - d of the light passes straight through, as
  // through a thin pane (ior 1); the surface's own parts keep the fraction d.
  float opacity = info.key("d") ? scalar(info, "d", 1.0f) : 1.0f - scalar(info, "Tr", 0.0f);
  if (opacity < 0.0f || opacity > 1.0f) {
    const char* key = info.key("d") ? "d" : "Tr";
    const float clamped_opacity = std::clamp(opacity, 0.0f, 1.0f);
    warnings.forgive("MTL d out of range", ErrorCode::invalid_scene, info.where(key),
                     info.what() + key + " " + std::to_string(scalar(info, key, 0.0f)) + " must be in [0, 1]",
                     "clamped");
    opacity = clamped_opacity;
  }
  if (opacity < 1.0f)
    set_thin_pane(m, opacity, clamped(info, "Tf", colour(info, "Tf", Rgb(1.0f)), 1.0f, 1.0f + 1e-6f,
                                      "a transmittance", "in [0, 1]", warnings));
  return m;
}

// ---------------------------------------------------------------------------------------------
// OBJ reader

/// A `usemtl` statement; each face uses the last one before it.
struct UseMaterial {
  std::string_view name;  ///< "" before any usemtl, or for a usemtl without a name
  std::size_t line = 0;
  /// Whether an mtllib line came before. A material named before any mtllib line is taken as
  /// undefined: tinyobjloader (which read these files before) knew no material there, and the
  /// files keep the materials they had.
  bool after_mtllib = false;
};

struct ObjFace {
  std::size_t line = 0;
  std::size_t first = 0;     ///< its first corner in ObjFile::corners
  std::size_t count = 0;     ///< corners, 3 or more
  std::size_t group = 0;     ///< into ObjFile::groups
  std::size_t material = 0;  ///< into ObjFile::materials
};

/// What an OBJ file says, read in one pass.
struct ObjFile {
  std::vector<glm::dvec3> positions;   ///< the `v` lines, in double precision (LoadOptions::local_origin)
  std::vector<std::size_t> corners;    ///< every face's corners (into positions), face after face
  std::vector<ObjFace> faces;          ///< in file order; those of fewer than 3 corners left out
  std::vector<std::string> groups;     ///< [0] "" (before any g or o), then one per g or o
  std::vector<UseMaterial> materials;  ///< [0] before any usemtl, then one per usemtl
  std::vector<fs::path> mtl_files;     ///< resolved, each once, in order of mention
};

/// mtllib names: split on spaces, with "\ " escaping a space (as tinyobjloader read them, so that
/// such files still find their libraries).
std::vector<std::string> mtllib_names(std::string_view rest) {
  std::vector<std::string> names;
  std::string name;
  bool escaping = false;
  for (char ch : rest) {
    if (escaping) {
      escaping = false;
    } else if (ch == '\\') {
      escaping = true;
      continue;
    } else if (ch == ' ' || ch == '\t') {
      if (!name.empty()) names.push_back(name);
      name.clear();
      continue;
    }
    name += ch;
  }
  if (!name.empty()) names.push_back(name);
  return names;
}

/// The vertex of one face corner ("v", "v/vt", "v//vn" or "v/vt/vn"), as an index into the
/// `vertex_count` vertices defined before the face. The vt and vn indices are not used, but must
/// be non-zero integers.
std::size_t corner_vertex(const fs::path& file, std::size_t line_no, std::string_view corner, std::size_t vertex_count) {
  const std::size_t slash = corner.find('/');
  const std::string_view v = corner.substr(0, slash);
  const std::optional<long long> idx = parse_int(v);
  if (!idx) fail(ErrorCode::parse_error, file, line_no, "face corner " + in_quotes(corner) + " has no valid vertex index");
  if (*idx == 0)
    fail(ErrorCode::parse_error, file, line_no, "face corner " + in_quotes(corner) + ": vertex index 0 is invalid (OBJ indices start at 1)");
  // OBJ counts from 1; a negative index counts back from the last vertex defined so far.
  const long long n = static_cast<long long>(vertex_count);
  const long long resolved = *idx > 0 ? *idx - 1 : n + *idx;
  if (resolved < 0 || resolved >= n)
    fail(ErrorCode::parse_error, file, line_no,
         "face corner " + in_quotes(corner) + ": vertex index " + std::to_string(*idx) + " is out of range (" +
             std::to_string(vertex_count) + " vertices defined before this line)");
  if (slash == std::string_view::npos) return static_cast<std::size_t>(resolved);
  const std::string_view rest = corner.substr(slash + 1);
  const std::size_t slash2 = rest.find('/');
  const std::string_view vt = rest.substr(0, slash2);
  auto check_nonzero = [&](std::string_view field, const char* what) {
    std::optional<long long> i = parse_int(field);
    if (!i || *i == 0)
      fail(ErrorCode::parse_error, file, line_no,
           "face corner " + in_quotes(corner) + ": " + what + " index " + in_quotes(field) + " is not a non-zero integer");
  };
  if (!vt.empty() || slash2 == std::string_view::npos) check_nonzero(vt, "texture coordinate");
  if (slash2 != std::string_view::npos) {
    const std::string_view vn = rest.substr(slash2 + 1);
    const std::size_t slash3 = vn.find('/');
    check_nonzero(vn.substr(0, slash3), "normal");
    if (slash3 != std::string_view::npos)
      fail(ErrorCode::parse_error, file, line_no,
           "face corner " + in_quotes(corner) + " has more than 3 indices (v, v/vt, v//vn or v/vt/vn expected)");
  }
  return static_cast<std::size_t>(resolved);
}

/// A group's name from what follows `g` or `o`. `g a b` names the group "a b" (its words joined
/// by one space); `o` takes the rest of its line as one name, inner blanks kept. Both as
/// tinyobjloader named them, so that groups keep their names.
std::string group_name(std::string_view key, Words& words) {
  if (key == "o") return std::string(trim(words.rest()));
  std::string name;
  for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
    if (!name.empty()) name += ' ';
    name += w;
  }
  return name;
}

/// Reads the OBJ statements that make a scene (v, f, g, o, usemtl, mtllib) and warns about l and
/// p; every other statement (vt, vn, s, ...) is ignored. Fails at the first line that cannot
/// mean anything.
ObjFile read_obj(const fs::path& file, std::string_view text, ReaderWarnings& warnings) {
  ObjFile obj;
  obj.groups.emplace_back();
  obj.materials.emplace_back();
  std::vector<glm::dvec3>& positions = obj.positions;
  std::set<fs::path> seen_mtl;
  bool after_mtllib = false;
  Lines lines(text);
  for (std::string_view line; lines.next(line);) {
    const std::size_t line_no = lines.number();
    Words words(line);
    const std::string_view key = words.next();
    if (key.empty() || key.front() == '#') continue;
    if (key == "v") {
      const std::string_view xyz[3] = {words.next(), words.next(), words.next()};
      if (xyz[2].empty())
        fail(ErrorCode::parse_error, file, line_no,
             "vertex has " + std::to_string(xyz[0].empty() ? 0 : xyz[1].empty() ? 1 : 2) + " coordinates; x y z needed");
      glm::dvec3 p;
      for (int i = 0; i < 3; ++i) {
        // Within float's range (what a Polygon can hold once a local origin is subtracted).
        const std::optional<double> c = parse_real(xyz[i]);
        if (!c || !std::isfinite(*c) || std::fabs(*c) > static_cast<double>(FLT_MAX))
          fail(ErrorCode::parse_error, file, line_no, "vertex coordinate " + in_quotes(xyz[i]) + " is not a finite number");
        p[i] = *c;
      }
      positions.push_back(p);
    } else if (key == "f") {
      const std::size_t first = obj.corners.size();
      for (std::string_view corner = words.next(); !corner.empty(); corner = words.next())
        obj.corners.push_back(corner_vertex(file, line_no, corner, positions.size()));
      const std::size_t count = obj.corners.size() - first;
      if (count < 3) {
        obj.corners.resize(first);
        warnings.forgive("short face", ErrorCode::parse_error, loc(file, line_no),
                         "face has " + std::to_string(count) + " vertices; a polygon needs at least 3", "dropped");
      } else {
        obj.faces.push_back(ObjFace{line_no, first, count, obj.groups.size() - 1, obj.materials.size() - 1});
      }
    } else if (key == "g" || key == "o") {
      // A bare `g` or `o` (not even a blank after it) leaves the group as it is, and `g ` starts
      // the unnamed (default) group: tinyobjloader's reading, which files were made against.
      if (words.rest().empty()) continue;
      obj.groups.push_back(group_name(key, words));
    } else if (key == "usemtl") {
      obj.materials.push_back(UseMaterial{words.next(), line_no, after_mtllib});
    } else if (key == "mtllib") {
      after_mtllib = true;
      const std::string_view rest = trim(words.rest());
      std::vector<std::string> names = mtllib_names(rest);
      if (names.size() > 1) {
        // Blender and several CAD exporters write a file name with spaces as it is ("mtllib
        // room mm.mtl"), as Assimp reads it: the whole line names one file when that file exists.
        fs::path whole{std::string(rest)};
        if (whole.is_relative()) whole = file.parent_path() / whole;
        std::error_code ec;
        if (fs::is_regular_file(whole, ec)) names.assign(1, std::string(rest));
      }
      if (names.empty())
        warnings.forgive("empty mtllib", ErrorCode::parse_error, loc(file, line_no), "mtllib without a file name",
                         "ignored");
      for (const std::string& name : names) {
        fs::path p(name);
        if (p.is_relative()) p = file.parent_path() / p;
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) {
          warnings.forgive("missing mtllib", ErrorCode::file_not_found, loc(file, line_no),
                           "material library " + in_quotes(name) + " not found (looked for '" + p.string() + "')",
                           "its materials are the default grey");
          continue;
        }
        if (seen_mtl.insert(p.lexically_normal()).second) obj.mtl_files.push_back(p);
      }
    } else if (key == "l" || key == "p") {
      warnings.forgive("line or point element", ErrorCode::parse_error, loc(file, line_no),
                       "line/point element has no area", "ignored");
    }
  }
  return obj;
}

/// "polygon 7 (group 'x'): problem" -> "problem": Scene numbers polygons of the scratch scene
/// below, which mean nothing to the user; we give file:line instead.
std::string without_polygon_prefix(const std::string& message) {
  if (message.rfind("polygon ", 0) == 0) {
    const std::size_t end = message.find("): ");
    if (end != std::string::npos) return message.substr(end + 3);
  }
  return message;
}

/// Adds faces to the scene so that what Scene would say about them (triangulated, degenerate)
/// carries file:line and follows the forgiving policy. Each face first goes into a scratch
/// scene; if that records a warning, the pieces it made are added instead of the face.
class FaceAdder {
 public:
  FaceAdder(Scene& scene, const fs::path& file, ReaderWarnings& warnings)
      : scene_(scene), file_(file), warnings_(warnings) {
    reset_scratch();
  }

  void add(const std::vector<glm::vec3>& vertices, MaterialId material, const std::string& group, std::size_t line) {
    // Made only for a message: most faces need none.
    auto face = [&]() { return "face (group '" + (group.empty() ? std::string("default") : group) + "'): "; };
    const std::size_t warnings_before = scratch_.warnings().size();
    PolygonRange pieces;
    try {
      pieces = scratch_.add_polygon(vertices, 0);
    } catch (const Error& e) {
      // The vertices are finite (read_obj() checked), so Scene refuses only degenerate faces.
      warnings_.forgive("degenerate face", e.code(), loc(file_, line), face() + without_polygon_prefix(e.what()),
                        "dropped");
      return;
    }
    if (scratch_.warnings().size() == warnings_before) {
      scene_.add_polygon(vertices, material, group);
    } else {
      // A piece is a triangle Scene accepted once; one so thin that Scene's collinearity test
      // rejects it on its own carries no area worth keeping.
      std::size_t slivers = 0;
      for (std::uint32_t i = 0; i < pieces.count; ++i) {
        try {
          scene_.add_polygon(scratch_.polygons()[pieces.first + i].vertices, material, group);
        } catch (const Error&) {
          ++slivers;
        }
      }
      for (std::size_t w = warnings_before; w < scratch_.warnings().size(); ++w)
        warnings_.forgive("triangulated face", ErrorCode::invalid_scene, loc(file_, line),
                          face() + without_polygon_prefix(scratch_.warnings()[w]),
                          slivers > 0 && w + 1 == scratch_.warnings().size()
                              ? std::to_string(slivers) + " sliver triangle(s) dropped"
                              : std::string());
    }
    if (scratch_.polygons().size() > 4096) reset_scratch();
  }

 private:
  void reset_scratch() {
    scratch_ = Scene();
    scratch_.add_material(Material{});
  }

  Scene& scene_;
  const fs::path& file_;
  ReaderWarnings& warnings_;
  Scene scratch_;
};

}  // namespace

Scene load_obj(const fs::path& path, const LoadOptions& options) {
  const std::string text = read_text(path, "OBJ file");
  ReaderWarnings warnings(options.strict);
  const ObjFile obj = read_obj(path, text, warnings);

  // Every MTL file, in order of mention, into one list; the first definition of a name wins.
  std::vector<MtlInfo> infos;
  for (const fs::path& mtl : obj.mtl_files) scan_mtl(mtl, read_text(mtl, "MTL file"), infos);

  Scene scene;

  // Materials: every MTL material, in order; "default" grey is added on demand.
  std::map<std::string_view, MaterialId, std::less<>> by_name;
  for (const MtlInfo& info : infos) {
    Material material = to_material(info, warnings);  // its errors (strict) name their own line
    try {
      by_name.emplace(info.name, scene.add_material(std::move(material)));
    } catch (const Error& e) {
      throw Error(e.code(), at(info.file, info.line) + e.what());
    }
  }
  std::vector<std::optional<MaterialId>> used(obj.materials.size());
  for (std::size_t u = 0; u < used.size(); ++u) {
    auto it = by_name.find(obj.materials[u].name);
    if (obj.materials[u].after_mtllib && it != by_name.end()) used[u] = it->second;
  }
  std::optional<MaterialId> default_material;
  std::set<std::string_view> undefined_reported;
  auto material_of = [&](std::size_t u) -> MaterialId {
    if (used[u]) return *used[u];
    // An undefined material is reported once per name, not once per face.
    const UseMaterial& use = obj.materials[u];
    if (!use.name.empty() && undefined_reported.insert(use.name).second)
      warnings.forgive("undefined material", ErrorCode::invalid_scene, loc(path, use.line),
                       "material " + in_quotes(use.name) + " is not defined by the mtllib files read",
                       "its faces use the default grey");
    if (!default_material) {
      Material grey;
      grey.name = "default";
      default_material = scene.add_material(grey);
    }
    return *default_material;
  };

  // A model far from the origin for its size is stored relative to a point near it.
  glm::dvec3 origin(0.0);
  if (options.local_origin) {
    LocalOriginFinder finder;
    std::vector<glm::dvec3> corners;
    for (const ObjFace& face : obj.faces) {
      corners.clear();
      for (std::size_t c = 0; c < face.count; ++c) corners.push_back(obj.positions[obj.corners[face.first + c]]);
      finder.add_polygon(corners.data(), corners.size());
    }
    origin = finder.origin();
    scene.set_origin(origin);
  }

  // Faces, in file order.
  FaceAdder adder(scene, path, warnings);
  std::vector<glm::vec3> vertices;
  for (const ObjFace& face : obj.faces) {
    RADIOSITY_ASSERT(face.count >= 3 && face.first + face.count <= obj.corners.size());
    vertices.clear();
    for (std::size_t c = 0; c < face.count; ++c)
      vertices.push_back(glm::vec3(obj.positions[obj.corners[face.first + c]] - origin));
    adder.add(vertices, material_of(face.material), obj.groups[face.group], face.line);
  }
  if (scene.polygons().empty())
    throw Error(ErrorCode::parse_error, "load_scene: '" + path.string() + "' has no faces (f lines)" +
                                            (obj.faces.empty() ? "" : " that are not degenerate"));
  warnings.move_to(scene);
  return scene;
}

}  // namespace radiosity::detail
