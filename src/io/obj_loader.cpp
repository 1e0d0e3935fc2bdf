// Wavefront OBJ/MTL reader. tinyobjloader parses the files (faces kept as polygons, not
// triangulated). Our own light pre-scan of the same text maps every face and material key to its
// line and checks what tinyobjloader would accept silently or only warn about (out-of-range
// indices, NaN coordinates, missing MTL files, faces it would drop), so that every error names
// the file, the line and the problem.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/readers.hpp"

namespace radiosity::detail {
namespace {

namespace fs = std::filesystem;

constexpr float kPi = 3.14159265358979323846f;
/// Largest diffuse + specular albedo an MTL material keeps; Ks is scaled down to fit (see below).
constexpr float kMaxAlbedo = 0.99f;

// ---------------------------------------------------------------------------------------------
// Text helpers

/// "file:line: ", the prefix of every located message.
std::string at(const fs::path& file, std::size_t line) {
  return file.string() + ":" + std::to_string(line) + ": ";
}

[[noreturn]] void fail(ErrorCode code, const fs::path& file, std::size_t line, const std::string& problem) {
  throw Error(code, at(file, line) + problem);
}

std::string read_text(const fs::path& path, const char* what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw Error(ErrorCode::file_not_found,
                std::string("load_scene: cannot open ") + what + " '" + path.string() +
                    (fs::exists(path, ec) ? "': not a regular file" : "': no such file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::file_not_found, std::string("load_scene: cannot open ") + what + " '" + path.string() + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::file_not_found, std::string("load_scene: cannot read ") + what + " '" + path.string() + "'");
  // A UTF-8 byte order mark would hide the first statement from tinyobjloader and from us.
  std::string s = text.str();
  if (s.compare(0, 3, "\xEF\xBB\xBF") == 0) s.erase(0, 3);
  return s;
}

/// Splits text into lines exactly as tinyobjloader's safeGetline does ("\n", "\r\n" and a lone
/// "\r" each end a line), so that our line numbers and its own agree.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n' && text[i] != '\r') continue;
    lines.push_back(text.substr(start, i - start));
    if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    start = i + 1;
  }
  if (start < text.size()) lines.push_back(text.substr(start));
  return lines;
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\r' || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

/// Whitespace-separated tokens (spaces and tabs, as tinyobjloader).
std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    std::size_t j = i;
    while (j < line.size() && !is_blank(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
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

std::string describe(const Rgb& c) {
  std::ostringstream s;
  s << '(' << c.x << ", " << c.y << ", " << c.z << ')';
  return s.str();
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

// ---------------------------------------------------------------------------------------------
// MTL pre-scan: where each material and each of the keys we map is, with the values checked.

struct MtlKey {
  std::size_t line = 0;
  int count = 0;         ///< numbers given (1 or 3 for colours, 1 for scalars)
  float value[3] = {0.0f, 0.0f, 0.0f};
};

struct MtlInfo {
  fs::path file;
  std::size_t line = 0;  ///< of its `newmtl`
  std::string name;
  std::map<std::string, MtlKey, std::less<>> keys;  ///< Kd, Ke, Ks, Tf (also from Kt), Ns, Ni, illum

  const MtlKey* key(std::string_view k) const {
    auto it = keys.find(k);
    return it == keys.end() ? nullptr : &it->second;
  }
  std::size_t line_of(std::string_view k) const {
    const MtlKey* m = key(k);
    return m ? m->line : line;
  }
};

/// Appends one MtlInfo per material that tinyobj::LoadMtl will produce from `text` (it keeps a
/// material only if `newmtl` gave it a name), in the same order.
void scan_mtl(const fs::path& file, std::string_view text, std::vector<MtlInfo>& out) {
  std::vector<std::string_view> lines = split_lines(text);
  MtlInfo* current = nullptr;
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::size_t line_no = n + 1;
    // LoadMtl trims trailing blanks and then requires a blank after "newmtl".
    std::string_view line = trim(lines[n]);
    if (line.empty() || line.front() == '#') continue;
    if (line.size() > 6 && line.substr(0, 6) == "newmtl" && is_blank(line[6])) {
      std::string_view name = line.substr(7);
      if (name.empty()) continue;
      out.push_back(MtlInfo{file, line_no, std::string(name), {}});
      current = &out.back();
      continue;
    }
    std::vector<std::string_view> tok = tokens(line);
    std::string key(tok[0]);
    if (key == "Kt") key = "Tf";
    const bool colour = key == "Kd" || key == "Ke" || key == "Ks" || key == "Tf";
    const bool scalar = key == "Ns" || key == "Ni";
    if (!colour && !scalar && key != "illum") continue;
    if (current == nullptr) continue;  // before the first newmtl: LoadMtl drops it too

    MtlKey k;
    k.line = line_no;
    if (key == "illum") {
      std::optional<long long> v = tok.size() == 2 ? parse_int(tok[1]) : std::nullopt;
      if (!v) fail(ErrorCode::parse_error, file, line_no, "material " + in_quotes(current->name) + ": illum needs one integer");
      k.count = 1;
      k.value[0] = static_cast<float>(*v);
    } else {
      if (colour && tok.size() > 1 && (tok[1] == "spectral" || tok[1] == "xyz"))
        fail(ErrorCode::parse_error, file, line_no,
             "material " + in_quotes(current->name) + ": " + key + " " + std::string(tok[1]) +
                 " is not supported (give r g b)");
      const std::size_t given = tok.size() - 1;
      if (colour ? (given != 1 && given != 3) : given != 1)
        fail(ErrorCode::parse_error, file, line_no,
             "material " + in_quotes(current->name) + ": " + key + (colour ? " needs 1 or 3 numbers" : " needs 1 number") +
                 ", got " + std::to_string(given));
      for (std::size_t i = 0; i < given; ++i) {
        std::optional<float> v = parse_finite_float(tok[i + 1]);
        if (!v)
          fail(ErrorCode::parse_error, file, line_no,
               "material " + in_quotes(current->name) + ": " + key + " value " + in_quotes(tok[i + 1]) +
                   " is not a finite number");
        k.value[i] = *v;
      }
      k.count = static_cast<int>(given);
      // A single value means grey (r = g = b), as the MTL specification says; tinyobjloader
      // would set g = b = 0.
      if (given == 1) k.value[1] = k.value[2] = k.value[0];
    }
    current->keys[key] = k;
  }
}

/// The colour of `key` (from the pre-scan, which handles single values) or tinyobjloader's
/// default when the material does not set it.
Rgb colour(const MtlInfo& info, std::string_view key, const tinyobj::real_t* fallback) {
  if (const MtlKey* k = info.key(key)) return Rgb(k->value[0], k->value[1], k->value[2]);
  return Rgb(static_cast<float>(fallback[0]), static_cast<float>(fallback[1]), static_cast<float>(fallback[2]));
}

void check_range(const MtlInfo& info, std::string_view key, const Rgb& v, bool upper_inclusive, const char* meaning) {
  for (int c = 0; c < 3; ++c) {
    const bool ok = v[c] >= 0.0f && (upper_inclusive ? v[c] <= 1.0f : v[c] < 1.0f);
    if (!ok)
      fail(ErrorCode::invalid_scene, info.file, info.line_of(key),
           "material " + in_quotes(info.name) + ": " + std::string(key) + " " + describe(v) + " is " + meaning +
               " and must be in [0, 1" + (upper_inclusive ? "]" : ")") + " per channel");
  }
}

/// Converts one MTL material. Mapping: Kd -> reflectance; Ke -> emission E = pi * Ke (Ke is a
/// radiance); Ks -> specular with Ns as its Phong exponent (at least 1, since 0 means a mirror
/// here); illum 3 or 5 with Ks -> ideal mirror (exponent 0); illum 4, 6, 7 or 9 with Tf ->
/// transmittance = Tf and ior = Ni. When Kd + Ks would reach 1 (common in exported files),
/// Ks is scaled down with a warning so the surface does not create energy; Kd >= 1 is an error.
Material to_material(const tinyobj::material_t& tm, const MtlInfo& info, std::vector<std::string>& warnings) {
  Material m;
  m.name = tm.name;
  const Rgb kd = colour(info, "Kd", tm.diffuse);
  const Rgb ke = colour(info, "Ke", tm.emission);
  check_range(info, "Kd", kd, false, "a diffuse reflectance (1 or more would create energy)");
  for (int c = 0; c < 3; ++c)
    if (ke[c] < 0.0f)
      fail(ErrorCode::invalid_scene, info.file, info.line_of("Ke"),
           "material " + in_quotes(info.name) + ": Ke " + describe(ke) + " is an emitted radiance and must be >= 0");
  m.reflectance = kd;
  m.emission = kPi * ke;

  const int illum = info.key("illum") ? static_cast<int>(info.key("illum")->value[0]) : tm.illum;
  if (info.key("Ks")) {
    const Rgb ks = colour(info, "Ks", tm.specular);
    check_range(info, "Ks", ks, true, "a specular reflectance");
    m.specular = ks;
    if (illum == 3 || illum == 5) {
      m.specular_exponent = 0.0f;
    } else {
      const float ns = info.key("Ns") ? info.key("Ns")->value[0] : static_cast<float>(tm.shininess);
      if (ns < 0.0f)
        fail(ErrorCode::invalid_scene, info.file, info.line_of("Ns"),
             "material " + in_quotes(info.name) + ": Ns " + std::to_string(ns) + " must be >= 0");
      m.specular_exponent = std::max(ns, 1.0f);
    }
    // Keep Kd + Ks below 1 per channel by scaling Ks (hue kept).
    float scale = 1.0f;
    for (int c = 0; c < 3; ++c)
      if (ks[c] > 0.0f && kd[c] + ks[c] > kMaxAlbedo) scale = std::min(scale, std::max(0.0f, (kMaxAlbedo - kd[c]) / ks[c]));
    if (scale < 1.0f) {
      m.specular = ks * scale;
      std::ostringstream s;
      s << at(info.file, info.line_of("Ks")) << "material " << in_quotes(info.name) << ": Kd + Ks exceeds "
        << kMaxAlbedo << " (1 or more would create energy); Ks scaled by " << scale << " to "
        << describe(m.specular);
      warnings.push_back(s.str());
    }
  }
  if ((illum == 4 || illum == 6 || illum == 7 || illum == 9) && info.key("Tf")) {
    const Rgb tf = colour(info, "Tf", tm.transmittance);
    check_range(info, "Tf", tf, true, "a transmittance");
    m.transmittance = tf;
    if (const MtlKey* ni = info.key("Ni")) {
      if (!(ni->value[0] > 0.0f))
        fail(ErrorCode::invalid_scene, info.file, ni->line,
             "material " + in_quotes(info.name) + ": Ni " + std::to_string(ni->value[0]) + " must be > 0");
      m.ior = ni->value[0];
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// OBJ pre-scan

struct FaceInfo {
  std::size_t line = 0;
  std::size_t vertex_count = 0;
  std::string_view material;      ///< name given by the last usemtl ("" if none)
  std::size_t material_line = 0;  ///< line of that usemtl
};

struct ObjScan {
  std::vector<FaceInfo> faces;     ///< in file order, which is tinyobjloader's face order
  std::vector<fs::path> mtl_files; ///< resolved, each once, in order of mention
  std::size_t vertex_count = 0;
  std::vector<std::string> warnings;
};

/// mtllib names, split like tinyobjloader does: on spaces, with "\ " escaping a space.
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

/// Checks one index field of a face corner ("v", "v/vt", "v//vn" or "v/vt/vn"). tinyobjloader
/// rejects 0 or a missing vt/vn index, and accepts an out-of-range vertex index silently.
void check_corner(const fs::path& file, std::size_t line_no, std::string_view corner, std::size_t vertex_count) {
  const std::size_t slash = corner.find('/');
  const std::string_view v = corner.substr(0, slash);
  const std::optional<long long> idx = parse_int(v);
  if (!idx) fail(ErrorCode::parse_error, file, line_no, "face corner " + in_quotes(corner) + " has no valid vertex index");
  if (*idx == 0)
    fail(ErrorCode::parse_error, file, line_no, "face corner " + in_quotes(corner) + ": vertex index 0 is invalid (OBJ indices start at 1)");
  const long long n = static_cast<long long>(vertex_count);
  const long long resolved = *idx > 0 ? *idx - 1 : n + *idx;
  if (resolved < 0 || resolved >= n)
    fail(ErrorCode::parse_error, file, line_no,
         "face corner " + in_quotes(corner) + ": vertex index " + std::to_string(*idx) + " is out of range (" +
             std::to_string(vertex_count) + " vertices defined before this line)");
  if (slash == std::string_view::npos) return;
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
    std::string_view vn = rest.substr(slash2 + 1);
    vn = vn.substr(0, vn.find('/'));
    check_nonzero(vn, "normal");
  }
}

ObjScan scan_obj(const fs::path& file, std::string_view text) {
  ObjScan scan;
  std::set<fs::path> seen_mtl;
  std::string_view material;
  std::size_t material_line = 0;
  std::size_t ignored = 0, first_ignored = 0;
  const std::vector<std::string_view> lines = split_lines(text);
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::size_t line_no = n + 1;
    const std::vector<std::string_view> tok = tokens(lines[n]);
    if (tok.empty() || tok[0].front() == '#') continue;
    const std::string_view key = tok[0];
    if (key == "v") {
      if (tok.size() < 4)
        fail(ErrorCode::parse_error, file, line_no,
             "vertex has " + std::to_string(tok.size() - 1) + " coordinates; x y z needed");
      for (std::size_t i = 1; i <= 3; ++i)
        if (!parse_finite_float(tok[i]))
          fail(ErrorCode::parse_error, file, line_no, "vertex coordinate " + in_quotes(tok[i]) + " is not a finite number");
      ++scan.vertex_count;
    } else if (key == "f") {
      for (std::size_t i = 1; i < tok.size(); ++i) check_corner(file, line_no, tok[i], scan.vertex_count);
      if (tok.size() < 4)
        fail(ErrorCode::parse_error, file, line_no,
             "face has " + std::to_string(tok.size() - 1) + " vertices; a polygon needs at least 3");
      scan.faces.push_back(FaceInfo{line_no, tok.size() - 1, material, material_line});
    } else if (key == "usemtl") {
      material = tok.size() > 1 ? tok[1] : std::string_view();
      material_line = line_no;
    } else if (key == "mtllib") {
      const std::string_view line = trim(lines[n]);
      const std::vector<std::string> names = mtllib_names(line.substr(std::min<std::size_t>(line.size(), 7)));
      if (names.empty()) scan.warnings.push_back(at(file, line_no) + "mtllib without a file name ignored");
      for (const std::string& name : names) {
        fs::path p(name);
        if (p.is_relative()) p = file.parent_path() / p;
        std::error_code ec;
        if (!fs::is_regular_file(p, ec))
          fail(ErrorCode::file_not_found, file, line_no,
               "material library " + in_quotes(name) + " not found (looked for '" + p.string() + "')");
        if (seen_mtl.insert(p.lexically_normal()).second) scan.mtl_files.push_back(p);
      }
    } else if (key == "l" || key == "p") {
      if (ignored++ == 0) first_ignored = line_no;
    }
  }
  if (ignored > 0)
    scan.warnings.push_back(at(file, first_ignored) + std::to_string(ignored) +
                            " line/point element(s) ignored: they have no area");
  return scan;
}

/// Hands tinyobjloader the materials we loaded from every mtllib beforehand. tinyobjloader
/// stops at the first file of a multi-file `mtllib` line, and we want all of them.
class PreloadedMaterials : public tinyobj::MaterialReader {
 public:
  PreloadedMaterials(const std::vector<tinyobj::material_t>& materials, const std::map<std::string, int>& map)
      : materials_(materials), map_(map) {}
  bool operator()(const std::string&, std::vector<tinyobj::material_t>* materials, std::map<std::string, int>* map,
                  std::string*, std::string*) override {
    if (!given_) {
      *materials = materials_;
      *map = map_;
      given_ = true;
    }
    return true;
  }

 private:
  const std::vector<tinyobj::material_t>& materials_;
  const std::map<std::string, int>& map_;
  bool given_ = false;
};

/// "polygon 7 (group 'x'): problem" -> "problem": Scene numbers polygons of the scratch scene
/// below, which mean nothing to the user; we give file:line instead.
std::string without_polygon_prefix(const std::string& message) {
  if (message.rfind("polygon ", 0) == 0) {
    const std::size_t end = message.find("): ");
    if (end != std::string::npos) return message.substr(end + 3);
  }
  return message;
}

/// Adds faces to the scene so that Scene's own warnings (triangulated faces) carry file:line.
/// Each face first goes into a scratch scene; if that records a warning, the pieces it made are
/// added instead of the face, and the warning is re-worded with the face's location.
class FaceAdder {
 public:
  FaceAdder(Scene& scene, const fs::path& file) : scene_(scene), file_(file) { reset_scratch(); }

  void add(const std::vector<glm::vec3>& vertices, MaterialId material, const std::string& group, std::size_t line) {
    const std::string where = at(file_, line) + "face (group '" + (group.empty() ? "default" : group) + "'): ";
    const std::size_t warnings_before = scratch_.warnings().size();
    PolygonRange pieces;
    try {
      pieces = scratch_.add_polygon(vertices, 0);
    } catch (const Error& e) {
      throw Error(e.code(), where + without_polygon_prefix(e.what()));
    }
    try {
      if (scratch_.warnings().size() == warnings_before) {
        scene_.add_polygon(vertices, material, group);
      } else {
        // A piece is a triangle Scene accepted once; one so thin that Scene's collinearity test
        // rejects it on its own carries no area worth keeping, and the warning says so.
        std::size_t slivers = 0;
        for (std::uint32_t i = 0; i < pieces.count; ++i) {
          try {
            scene_.add_polygon(scratch_.polygons()[pieces.first + i].vertices, material, group);
          } catch (const Error&) {
            ++slivers;
          }
        }
        for (std::size_t w = warnings_before; w < scratch_.warnings().size(); ++w)
          scene_.add_warning(where + without_polygon_prefix(scratch_.warnings()[w]) +
                             (slivers > 0 && w + 1 == scratch_.warnings().size()
                                  ? " (" + std::to_string(slivers) + " sliver triangle(s) dropped)"
                                  : std::string()));
      }
    } catch (const Error& e) {
      throw Error(e.code(), where + without_polygon_prefix(e.what()));
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
  Scene scratch_;
};

}  // namespace

Scene load_obj(const fs::path& path) {
  const std::string text = read_text(path, "OBJ file");
  ObjScan scan = scan_obj(path, text);

  // Every MTL file, in order of mention, into one list and name map (the first definition of a
  // name wins, as in tinyobjloader).
  std::vector<tinyobj::material_t> tmaterials;
  std::map<std::string, int> tmaterial_map;
  std::vector<MtlInfo> infos;
  for (const fs::path& mtl : scan.mtl_files) {
    const std::string mtl_text = read_text(mtl, "MTL file");
    scan_mtl(mtl, mtl_text, infos);
    std::istringstream in(mtl_text);
    std::string warn, err;
    tinyobj::LoadMtl(&tmaterial_map, &tmaterials, &in, &warn, &err);
    if (infos.size() != tmaterials.size())
      throw Error(ErrorCode::internal, "load_scene: '" + mtl.string() + "': found " + std::to_string(infos.size()) +
                                           " materials, tinyobjloader read " + std::to_string(tmaterials.size()));
  }

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> used_materials;
  std::string warn, err;
  {
    std::istringstream in(text);
    PreloadedMaterials reader(tmaterials, tmaterial_map);
    if (!tinyobj::LoadObj(&attrib, &shapes, &used_materials, &warn, &err, &in, &reader, /*triangulate=*/false)) {
      std::string first = err.substr(0, err.find('\n'));
      throw Error(ErrorCode::parse_error, path.string() + ": " + (first.empty() ? "cannot parse" : first));
    }
  }
  if (attrib.vertices.size() != 3 * scan.vertex_count)
    throw Error(ErrorCode::internal, "load_scene: '" + path.string() + "': found " + std::to_string(scan.vertex_count) +
                                         " vertices, tinyobjloader read " + std::to_string(attrib.vertices.size() / 3));

  Scene scene;
  for (std::string& w : scan.warnings) scene.add_warning(std::move(w));

  // Materials: MTL material i becomes scene material ids[i]; "default" grey is added on demand.
  std::vector<MaterialId> ids;
  ids.reserve(tmaterials.size());
  for (std::size_t i = 0; i < tmaterials.size(); ++i) {
    std::vector<std::string> warnings;
    Material m = to_material(tmaterials[i], infos[i], warnings);
    try {
      ids.push_back(scene.add_material(m));
    } catch (const Error& e) {
      throw Error(e.code(), at(infos[i].file, infos[i].line) + e.what());
    }
    for (std::string& w : warnings) scene.add_warning(std::move(w));
  }
  std::optional<MaterialId> default_material;
  std::set<std::string_view> unknown_reported;

  // Faces, in file order: tinyobjloader's shapes are consecutive runs of the file's faces. The
  // per-face vertex counts come from our scan (tinyobjloader stores them in an unsigned char).
  FaceAdder adder(scene, path);
  std::size_t face = 0;
  bool matched = true;
  std::vector<glm::vec3> vertices;
  for (const tinyobj::shape_t& shape : shapes) {
    const std::string group(trim(shape.name));
    std::size_t corner = 0;
    for (std::size_t f = 0; f < shape.mesh.material_ids.size() && matched; ++f, ++face) {
      matched = face < scan.faces.size() && corner + scan.faces[face].vertex_count <= shape.mesh.indices.size();
      if (!matched) break;
      const FaceInfo& info = scan.faces[face];
      vertices.clear();
      for (std::size_t k = 0; k < info.vertex_count; ++k) {
        const int v = shape.mesh.indices[corner + k].vertex_index;
        if (v < 0 || static_cast<std::size_t>(v) >= scan.vertex_count)
          fail(ErrorCode::internal, path, info.line, "tinyobjloader returned vertex index " + std::to_string(v));
        const std::size_t o = 3 * static_cast<std::size_t>(v);
        vertices.emplace_back(attrib.vertices[o], attrib.vertices[o + 1], attrib.vertices[o + 2]);
      }
      corner += info.vertex_count;

      const int mid = shape.mesh.material_ids[f];
      MaterialId material;
      if (mid >= 0 && static_cast<std::size_t>(mid) < ids.size()) {
        material = ids[static_cast<std::size_t>(mid)];
      } else {
        if (!default_material) {
          Material grey;
          grey.name = "default";
          default_material = scene.add_material(grey);
        }
        material = *default_material;
        if (!info.material.empty() && unknown_reported.insert(info.material).second)
          scene.add_warning(at(path, info.material_line) + "material " + in_quotes(info.material) +
                            " is not defined by the mtllib files read so far; its faces use the default grey");
      }
      adder.add(vertices, material, group, info.line);
    }
    matched = matched && corner == shape.mesh.indices.size();
  }
  if (!matched || face != scan.faces.size())
    throw Error(ErrorCode::internal, "load_scene: '" + path.string() + "': could not match tinyobjloader's faces to the file's " +
                                         std::to_string(scan.faces.size()) + " f lines");
  if (scan.faces.empty())
    throw Error(ErrorCode::parse_error, "load_scene: '" + path.string() + "' has no faces (f lines)");
  return scene;
}

}  // namespace radiosity::detail
