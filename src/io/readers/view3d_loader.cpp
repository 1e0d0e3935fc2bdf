// NIST View3D 3-D vertex/surface files (.vs3): load_view3d(), and load_scene() for ".vs3".
// Based on: G. N. Walton, "Calculation of obstructed view factors by adaptive integration",
// NISTIR 6925, National Institute of Standards and Technology, Gaithersburg MD, 2002; and the
// View3D 3.2 user manual and reader (getdat.c: CountVS3D, GetCtrl, GetVS3D, GetSrfD), whose
// rules this reader keeps where they decide what a file means: the first letter of a line's
// first word is its keyword, words are separated by blanks, tabs and commas, '!' starts a
// comment, vertices and surfaces are numbered 1, 2, ... in file order with the radiating
// surfaces before the obstruction-only ones, and the corners of a surface are counter-clockwise
// seen from its radiating side, as our polygons are seen from their front (so nothing is
// flipped). Where View3D would compute something we cannot represent (mask and null surfaces,
// 2-D and BLAST geometry, a surface that is not one convex planar polygon) the file is refused
// with its line, because a polygon split or dropped here would shift every later surface
// number, and the numbers are what ties View3D's output rows to surfaces. docs/SCENE_VS3.md
// has the whole mapping.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/assert.hpp"
#include "io/readers/local_origin.hpp"
#include "io/readers/reader_files.hpp"
#include "io/readers/reader_warnings.hpp"
#include "io/readers/readers.hpp"
#include "io/view3d_text.hpp"
#include "radiosity/io.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity {
inline namespace v1 {
namespace {

namespace fs = std::filesystem;
using detail::in_quotes;
using detail::ReaderWarnings;
namespace v3d = detail::view3d;

/// One line of the file: its number and its words (a word that starts with '!' and the rest of
/// the line are a comment, as in View3D's NxtWord).
struct Line {
  std::size_t number = 0;
  std::vector<std::string_view> words;
  std::string_view after_keyword;  ///< the text after the first word, blanks trimmed (T and C lines)
};

bool is_separator(char c, bool control) {
  return c == ' ' || c == '\t' || c == ',' || c == '\0' || (control && c == '=');
}

/// The words of `text`; with `control`, '=' separates words too (the control line's name=value).
std::vector<std::string_view> split_words(std::string_view text, bool control) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_separator(text[i], control)) ++i;
    if (i >= text.size() || text[i] == '!') break;
    const std::size_t start = i;
    while (i < text.size() && !is_separator(text[i], control)) ++i;
    words.push_back(text.substr(start, i - start));
  }
  return words;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// The lines of `text`; "\n", "\r\n" and a lone "\r" each end one, so files from any platform
/// count lines alike.
std::vector<Line> split_lines(std::string_view text) {
  std::vector<Line> lines;
  std::size_t pos = 0, number = 0;
  while (pos < text.size()) {
    std::size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    Line line;
    line.number = ++number;
    const std::string_view raw = text.substr(pos, end - pos);
    line.words = split_words(raw, false);
    if (!line.words.empty()) {
      const std::size_t first_end = static_cast<std::size_t>(line.words[0].data() - raw.data()) + line.words[0].size();
      line.after_keyword = trim(raw.substr(first_end));
    }
    lines.push_back(std::move(line));
    pos = end + 1;
    if (end < text.size() && text[end] == '\r' && pos < text.size() && text[pos] == '\n') ++pos;
  }
  return lines;
}

std::optional<long long> parse_integer(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

/// A number that is a finite float, read as the nearest float to the decimal (so that the
/// shortest digits save_view3d() writes read back to the same bits).
std::optional<float> parse_float(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  float v = 0.0f;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// A surface line (`S` or `O`) as read, before its geometry is checked.
struct Surface {
  std::size_t line = 0;
  bool obstruction = false;
  long long corner[4] = {0, 0, 0, 0};  ///< 1-based vertex numbers; corner[3] == 0 for a triangle
  long long base = 0;
  long long combine = 0;
  float emissivity = 1.0f;  ///< clamped into (0, 1]
  std::string name;         ///< as written, or "s<N>"
};

class Reader {
 public:
  Reader(const fs::path& file, const LoadOptions& options)
      : file_(file), warnings_(options.strict), local_origin_(options.local_origin) {}

  View3DFile read(std::string_view text) {
    View3DFile out;
    std::vector<const Line*> vertices, surfaces;
    bool ended = false, obstruction_seen = false;
    const std::vector<Line> lines = split_lines(text);
    // One pass reads the title and control lines and sorts the others by keyword up to the
    // end-of-data line, as View3D's CountVS3D does: a surface may name a vertex defined after
    // it, and its checks need the counts of vertices and radiating surfaces.
    for (const Line& line : lines) {
      if (line.words.empty()) continue;
      const std::string_view first = line.words[0];
      switch (std::toupper(static_cast<unsigned char>(first[0]))) {
        case '/':
          break;  // a comment line
        case 'E':
        case '*':
          ended = true;
          break;
        case 'T':
          out.title = std::string(line.after_keyword);  // the last title line wins, as in View3D
          break;
        case 'F':
        case 'G':  // the geometry line; View3D 3.5 spells it G
          check_geometry(line);
          break;
        case 'C':
          read_control(line, out.control);  // a later line's words override an earlier one's
          break;
        case 'V':
          vertices.push_back(&line);
          break;
        case 'S':
          if (obstruction_seen)
            fail(ErrorCode::parse_error, line.number,
                 "radiating surface after an obstruction surface: View3D numbers every S surface before the O surfaces");
          surfaces.push_back(&line);
          ++radiating_;
          break;
        case 'O':
          obstruction_seen = true;
          surfaces.push_back(&line);
          break;
        case 'M':
        case 'N':
          fail(ErrorCode::parse_error, line.number,
               std::string(first[0] == 'M' || first[0] == 'm' ? "mask" : "null") +
                   " surfaces (M and N lines) are not supported: a polygon cannot cover part of its base "
                   "as View3D's do");
        case 'X':
          warnings_.note("transformation", loc(line.number),
                         "X (coordinate transformation) line ignored, as View3D 3.2 ignores it",
                         "transform the vertices in the file instead");
          break;
        default:
          warnings_.forgive("unknown line", ErrorCode::parse_error, loc(line.number),
                            "unknown line " + in_quotes(first) +
                                " (View3D lines start with T, C, F, V, S, O, E, ! or /)",
                            "ignored");
          break;
      }
      if (ended) break;
    }
    if (!ended)
      warnings_.note("no end line", file_.string(), "no end-of-data line (E or *): read to the end of the file",
                     "a truncated file? View3D files end with 'End of data'");

    read_vertices(vertices);
    read_surfaces(surfaces);
    check_row_column(out.control);
    build(out.scene);
    warnings_.move_to(out.scene);
    return out;
  }

 private:
  std::string loc(std::size_t line) const { return file_.string() + ":" + std::to_string(line); }

  [[noreturn]] void fail(ErrorCode code, std::size_t line, const std::string& problem) const {
    throw Error(code, loc(line) + ": " + problem);
  }

  void check_geometry(const Line& line) const {
    const std::string_view value = line.words.size() > 1 ? line.words[1] : std::string_view();
    if (value == "3") return;
    if (value == "2")
      fail(ErrorCode::parse_error, line.number,
           "2-D geometry (F 2) is View2D's format (.vs2); only 3-D vertex/surface files (F 3) are read");
    if (value == "3a" || value == "3A")
      fail(ErrorCode::parse_error, line.number,
           "BLAST surface geometry (F 3a) is not supported; only vertex/surface files (F 3) are read");
    fail(ErrorCode::parse_error, line.number, "invalid geometry " + in_quotes(value) + " (F 3 expected)");
  }

  int control_integer(const Line& line, std::string_view name, std::string_view value) const {
    const std::optional<long long> v = parse_integer(value);
    if (!v || *v < -2147483647LL || *v > 2147483647LL)
      fail(ErrorCode::parse_error, line.number,
           "control " + std::string(name) + ": " + in_quotes(value) + " is not an integer");
    return static_cast<int>(*v);
  }

  /// `value` clamped up to `lowest` with a warning, as View3D resets maxU/maxO below 4 and
  /// minO, row and col below 0.
  int at_least(const Line& line, std::string_view name, int value, int lowest) {
    if (value >= lowest) return value;
    warnings_.forgive("control value", ErrorCode::parse_error, loc(line.number),
                      "control " + std::string(name) + "=" + std::to_string(value) + " is below " +
                          std::to_string(lowest),
                      "set to " + std::to_string(lowest) + " (as View3D does)");
    return lowest;
  }

  /// One control line: `name=value` pairs in any order, names in any case (View3D's GetCtrl).
  void read_control(const Line& line, View3DControl& c) {
    const std::vector<std::string_view> words = split_words(line.after_keyword, true);
    for (std::size_t i = 0; i < words.size(); i += 2) {
      const std::string_view name = words[i];
      if (i + 1 >= words.size())
        fail(ErrorCode::parse_error, line.number, "control word " + in_quotes(name) + " has no value");
      const std::string_view value = words[i + 1];
      const std::string key = v3d::lower(name);
      if (key == "eps") {
        const std::optional<float> v = parse_float(value);
        if (!v || *v <= 0.0f)
          fail(ErrorCode::parse_error, line.number, "control eps: " + in_quotes(value) + " is not a number > 0");
        c.epsilon = *v;
      } else if (key == "out") {
        const int v = control_integer(line, name, value);
        if (v < 0 || v > 2)
          fail(ErrorCode::parse_error, line.number,
               "control out=" + std::to_string(v) + ": the output format is 0 (text), 1 (binary) or 2 (sparse)");
        c.output_format = v;
      } else if (key == "encl") {
        c.enclosure = control_integer(line, name, value) != 0;
      } else if (key == "emit") {
        c.script_f = control_integer(line, name, value) != 0;
      } else if (key == "list") {
        c.list = control_integer(line, name, value);
      } else if (key == "maxu") {
        c.max_unobstructed_recursions = at_least(line, name, control_integer(line, name, value), 4);
      } else if (key == "maxo") {
        c.max_obstructed_recursions = at_least(line, name, control_integer(line, name, value), 4);
      } else if (key == "mino") {
        c.min_obstructed_recursions = at_least(line, name, control_integer(line, name, value), 0);
      } else if (key == "row") {
        c.row = at_least(line, name, control_integer(line, name, value), 0);
        row_line_ = line.number;
      } else if (key == "col") {
        c.column = at_least(line, name, control_integer(line, name, value), 0);
        row_line_ = std::max(row_line_, line.number);
      } else if (key == "prjd") {
        c.reverse_projections = control_integer(line, name, value) != 0;
      } else {
        warnings_.note("control word", loc(line.number),
                       "control word " + in_quotes(name) + " is not one of View3D 3.2's",
                       "kept for save_view3d(); View3D 3.2 ignores it");
        auto same = std::find_if(c.other.begin(), c.other.end(),
                                 [&](const auto& kv) { return v3d::lower(kv.first) == key; });
        if (same != c.other.end())
          same->second = std::string(value);
        else
          c.other.emplace_back(std::string(name), std::string(value));
      }
    }
  }

  void check_row_column(const View3DControl& c) const {
    if (c.column > 0 && c.row == 0)
      fail(ErrorCode::parse_error, row_line_, "control col=" + std::to_string(c.column) + " needs a row");
    for (const auto& [what, value] : {std::pair<const char*, int>{"row", c.row}, {"col", c.column}})
      if (value > static_cast<int>(radiating_))
        fail(ErrorCode::parse_error, row_line_,
             std::string("control ") + what + "=" + std::to_string(value) + " is beyond the " +
                 std::to_string(radiating_) + " radiating surfaces");
  }

  /// `V n x y z`, numbered 1, 2, ... in file order.
  void read_vertices(const std::vector<const Line*>& lines) {
    positions_.reserve(lines.size());
    for (const Line* line : lines) {
      const std::vector<std::string_view>& w = line->words;
      if (w.size() < 5)
        fail(ErrorCode::parse_error, line->number,
             "vertex line has " + std::to_string(w.size() - 1) + " values; a number and x y z needed");
      const std::optional<long long> n = parse_integer(w[1]);
      const std::size_t expected = positions_.size() + 1;
      if (!n) fail(ErrorCode::parse_error, line->number, "vertex number " + in_quotes(w[1]) + " is not an integer");
      if (*n != static_cast<long long>(expected))
        fail(ErrorCode::parse_error, line->number,
             "vertex " + std::string(w[1]) + " is out of sequence (expected " + std::to_string(expected) +
                 ": View3D numbers vertices 1, 2, 3, ... in file order)");
      glm::vec3 p;
      glm::dvec3 exact;
      for (int k = 0; k < 3; ++k) {
        const std::string_view word = w[2 + static_cast<std::size_t>(k)];
        const std::optional<float> c = parse_float(word);
        if (!c)
          fail(ErrorCode::parse_error, line->number,
               "vertex " + std::to_string(expected) + ": coordinate " + in_quotes(word) + " is not a finite number");
        p[k] = *c;
        // Also in double, for a local origin (LoadOptions::local_origin); the float read
        // directly stays what a file near the origin gives (the round trip of save_view3d()).
        exact[k] = *c;
        const std::string_view digits = word.front() == '+' ? word.substr(1) : word;
        const auto parsed = std::from_chars(digits.data(), digits.data() + digits.size(), exact[k]);
        static_cast<void>(parsed);  // the float parse above checked the digits
      }
      positions_.push_back(p);
      exact_.push_back(exact);
    }
  }

  /// `S n v1 v2 v3 v4 base cmbn emit name` and `O n v1 v2 v3 v4 ...`, numbered 1, 2, ... in
  /// file order; the checks of View3D's GetVS3D and GetSrfD.
  void read_surfaces(const std::vector<const Line*>& lines) {
    const long long all = static_cast<long long>(lines.size());
    const long long radiating = static_cast<long long>(radiating_);
    for (const Line* line : lines) {
      const std::vector<std::string_view>& w = line->words;
      Surface s;
      s.line = line->number;
      s.obstruction = std::toupper(static_cast<unsigned char>(w[0][0])) == 'O';
      const long long number = static_cast<long long>(surfaces_.size()) + 1;
      if (w.size() < 6)
        fail(ErrorCode::parse_error, s.line,
             "surface line has " + std::to_string(w.size() - 1) +
                 " values; a number and 4 vertex numbers needed (the 4th 0 for a triangle)");
      const std::optional<long long> n = parse_integer(w[1]);
      if (!n) fail(ErrorCode::parse_error, s.line, "surface number " + in_quotes(w[1]) + " is not an integer");
      if (*n != number)
        fail(ErrorCode::parse_error, s.line,
             "surface " + std::string(w[1]) + " is out of sequence (expected " + std::to_string(number) +
                 ": View3D numbers surfaces 1, 2, 3, ... in file order)");
      const std::string what = "surface " + std::to_string(number);
      const long long vertex_count = static_cast<long long>(positions_.size());
      for (int k = 0; k < 4; ++k) {
        const std::string_view word = w[2 + static_cast<std::size_t>(k)];
        const std::optional<long long> v = parse_integer(word);
        if (!v) fail(ErrorCode::parse_error, s.line, what + ": vertex number " + in_quotes(word) + " is not an integer");
        const bool triangle = k == 3 && *v == 0;
        if (!triangle && (*v < 1 || *v > vertex_count))
          fail(ErrorCode::parse_error, s.line,
               what + ": vertex " + std::string(word) + " is out of range (the file has " + std::to_string(vertex_count) +
                   " vertices" + (k == 3 ? "; 0 makes a triangle)" : ")"));
        s.corner[k] = *v;
      }
      if (!s.obstruction) {
        if (w.size() < 9)
          fail(ErrorCode::parse_error, s.line, what + " needs base, combine and emissivity after its 4 vertices");
        s.base = surface_number(*line, what + ": base surface", w[6]);
        s.combine = surface_number(*line, what + ": combine surface", w[7]);
        // View3D's GetSrfD: a base must exist and, when it radiates, come first (an
        // obstruction base is numbered after every radiating surface); a combination joins an
        // earlier radiating surface that is not itself combined (no chains).
        if (s.base < 0 || s.base > all || s.base == number || (s.base > number && s.base <= radiating))
          fail(ErrorCode::parse_error, s.line,
               what + ": base surface " + std::to_string(s.base) +
                   " is invalid (0, an earlier radiating surface or an obstruction surface)");
        if (s.combine < 0 || s.combine >= number)
          fail(ErrorCode::parse_error, s.line,
               what + ": combine surface " + std::to_string(s.combine) + " is invalid (0 or an earlier surface)");
        if (s.combine > 0 && surfaces_[static_cast<std::size_t>(s.combine - 1)].combine > 0)
          fail(ErrorCode::parse_error, s.line,
               what + ": combine surface " + std::to_string(s.combine) + " is itself combined with surface " +
                   std::to_string(surfaces_[static_cast<std::size_t>(s.combine - 1)].combine) +
                   " (combine every piece with the first one)");
        s.emissivity = emissivity(s.line, what, w[8], true);
      } else if (w.size() >= 10) {
        // View3D reads nothing after an obstruction's vertices; a line in the S layout keeps
        // its emissivity and name here (for the radiosity solve and for a round trip).
        if (parse_float(w[8])) s.emissivity = emissivity(s.line, what, w[8], false);
      }
      if (w.size() >= 10) {
        s.name = std::string(w[9]);
      } else {
        s.name = "s" + std::to_string(number);
        if (!s.obstruction)
          warnings_.forgive("unnamed surface", ErrorCode::parse_error, loc(s.line), what + " has no name",
                            "named " + in_quotes(s.name));
      }
      if (s.base > 0) {
        const Surface* base = s.base < number ? &surfaces_[static_cast<std::size_t>(s.base - 1)] : nullptr;
        warnings_.forgive("subsurface", ErrorCode::invalid_scene, loc(s.line),
                          what + " (" + in_quotes(s.name) + ") is a subsurface of surface " + std::to_string(s.base) +
                              (base ? " (" + in_quotes(base->name) + ")" : std::string()) +
                              ": View3D subtracts it from its base, here both are whole polygons that overlap",
                          "kept as written");
      }
      surfaces_.push_back(std::move(s));
    }
  }

  long long surface_number(const Line& line, const std::string& what, std::string_view word) const {
    const std::optional<long long> v = parse_integer(word);
    if (!v) fail(ErrorCode::parse_error, line.number, what + " " + in_quotes(word) + " is not an integer");
    return *v;
  }

  /// An emissivity, clamped into (0, 1] with a warning: 0 or less to 0.01 (reflectance 0.99,
  /// the most the readers forgive; View3D uses 0.001), more than 1 to 1.
  float emissivity(std::size_t line, const std::string& what, std::string_view word, bool required) {
    const std::optional<float> e = parse_float(word);
    if (!e) {
      if (required)
        fail(ErrorCode::parse_error, line, what + ": emissivity " + in_quotes(word) + " is not a finite number");
      return 1.0f;
    }
    if (*e > 0.0f && *e <= 1.0f) return *e;
    const float clamped = *e > 1.0f ? 1.0f : 0.01f;  // 1 - 0.01f rounds to kMaxForgivenAlbedo
    warnings_.forgive("emissivity out of range", ErrorCode::invalid_scene, loc(line),
                      what + ": emissivity " + std::string(word) + " is outside (0, 1]",
                      "clamped to " + v3d::shortest(clamped));
    return clamped;
  }

  /// The scene: one polygon per surface, in order, each checked to be one convex planar
  /// polygon before it is added, since Scene::add_polygon() would triangulate it otherwise.
  void build(Scene& scene) {
    if (surfaces_.empty())
      throw Error(ErrorCode::parse_error, "load_scene: '" + file_.string() + "' has no surfaces (S lines)");
    if (radiating_ == 0)
      throw Error(ErrorCode::parse_error,
                  "load_scene: '" + file_.string() + "' has no radiating surfaces (S lines), only obstructions");
    // A model far from the origin for its size is stored relative to a point near it.
    glm::dvec3 origin(0.0);
    if (local_origin_) {
      detail::LocalOriginFinder finder;
      std::vector<glm::dvec3> exact;
      for (const Surface& s : surfaces_) {
        exact.clear();
        for (int k = 0; k < 4; ++k)
          if (s.corner[k] > 0) exact.push_back(exact_[static_cast<std::size_t>(s.corner[k] - 1)]);
        finder.add_polygon(exact.data(), exact.size());
      }
      origin = finder.origin();
      scene.set_origin(origin);
    }
    const bool moved = origin != glm::dvec3(0.0);
    std::map<float, MaterialId> materials;
    std::vector<glm::vec3> corners;
    for (std::size_t i = 0; i < surfaces_.size(); ++i) {
      const Surface& s = surfaces_[i];
      const std::string what =
          "surface " + std::to_string(i + 1) + " (" + in_quotes(s.name) + ")";
      corners.clear();
      for (int k = 0; k < 4; ++k) {
        if (s.corner[k] <= 0) continue;
        const auto v = static_cast<std::size_t>(s.corner[k] - 1);
        corners.push_back(moved ? glm::vec3(exact_[v] - origin) : positions_[v]);
      }
      const detail::CleanPolygon clean = detail::clean_polygon(corners);
      if (clean.vertices.size() < 3 || clean.area <= detail::kDegenerateAreaRatio * clean.diameter * clean.diameter)
        fail(ErrorCode::invalid_scene, s.line,
             what + ": degenerate (zero-area) surface: its corners are repeated or in one line");
      if (!clean.planar)
        fail(ErrorCode::invalid_scene, s.line,
             what + ": its 4 corners are not in one plane (View3D needs planar surfaces: split it into 2 triangles)");
      if (!clean.convex)
        fail(ErrorCode::invalid_scene, s.line,
             what + ": non-convex quadrilateral (View3D needs convex ones: split it into 2 triangles)");

      auto [it, added] = materials.try_emplace(s.emissivity, MaterialId{0});
      if (added) {
        Material m;
        m.name = "emissivity " + v3d::shortest(s.emissivity);
        m.reflectance = Rgb(1.0f - s.emissivity);
        it->second = scene.add_material(m);
      }
      // A combined surface is one surface in View3D's results: here, one group.
      const std::string& group =
          s.combine > 0 ? surfaces_[static_cast<std::size_t>(s.combine - 1)].name : s.name;
      PolygonRange range;
      try {
        range = scene.add_polygon(corners, it->second, group);
      } catch (const Error& e) {
        fail(e.code(), s.line, what + ": " + e.what());
      }
      RADIOSITY_ASSERT(range.count == 1 && range.first == i);
      if (s.obstruction) scene.set_obstruction_only(range.first);
    }
  }

  const fs::path& file_;
  ReaderWarnings warnings_;
  bool local_origin_ = true;
  std::vector<glm::vec3> positions_;
  std::vector<glm::dvec3> exact_;  ///< positions_ in double
  std::vector<Surface> surfaces_;
  std::size_t radiating_ = 0;
  std::size_t row_line_ = 0;  ///< the control line that set row or col last
};

}  // namespace

View3DFile load_view3d(const std::filesystem::path& path, const LoadOptions& options) {
  std::string text = detail::read_file(path, "View3D file");
  // A UTF-8 byte order mark would hide the first line's keyword.
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  return Reader(path, options).read(text);
}

}  // namespace v1

namespace detail {

Scene load_view3d(const std::filesystem::path& path, const LoadOptions& options) {
  return std::move(radiosity::load_view3d(path, options).scene);
}

}  // namespace detail
}  // namespace radiosity
