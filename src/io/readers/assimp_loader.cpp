// Every other scene format through Assimp, the Open Asset Import Library (Debian's libassimp
// 5.2: FBX, COLLADA, 3DS, PLY, STL, OFF, Blender and more; the formats with a reader of their own
// here, OBJ, glTF and JSON, never go to it). Its scene graph is read as glTF's is (nodes place
// meshes by their world matrices, groups are node names) and its materials through the mapping
// glTF's reader uses (material_mapping.hpp), with the keys each format fills (Assimp's
// "Material System" documentation: $clr.base or $clr.diffuse, $clr.emissive with
// $mat.emissiveIntensity, $mat.twosided, $mat.opacity, $mat.transmission.factor, $mat.refracti,
// $mat.metallicFactor and $mat.roughnessFactor). docs/SCENE_GLTF.md has the table. Its point,
// spot and directional lights (aiLight, each placed by the node of its name) become Lights as
// glTF's KHR_lights_punctual ones do (placed_light.hpp; docs/LIGHTS.md).
//
// Assimp is asked to parse and validate only (aiProcess_ValidateDataStructure); the reader then
// checks what the validation leaves through (empty faces, NaN positions) before triangulating,
// because Debian's build asserts, and aborts, in its Triangulate step on the empty faces of a
// truncated PLY. The files known to make Assimp 5.2 loop forever or write out of bounds (a PLY
// whose header never ends, a COLLADA index list with a stray character or an array longer than
// its count) are refused before Assimp opens them. Other
// corruptions of formats read by Assimp are in its hands: its parsers are not hardened the way
// the glTF reader is.
#include <assimp/DefaultIOSystem.h>
#include <assimp/IOStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>

#include "core/color.hpp"
#include "core/constants.hpp"
#include "io/readers/material_mapping.hpp"
#include "io/readers/placed_light.hpp"
#include "io/readers/placed_mesh.hpp"
#include "io/readers/reader_files.hpp"
#include "io/readers/reader_warnings.hpp"
#include "io/readers/readers.hpp"
#include "io/readers/texture_mean.hpp"

namespace radiosity::detail {
namespace {

namespace fs = std::filesystem;

/// The size in bytes of a PLY scalar type (char, uchar, ..., float64), 0 for another name
/// (Assimp 5.2 does not read "FLOAT" either).
std::size_t ply_type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

/// A property of a PLY element: a scalar of `type` (`size` bytes), or a list whose count is a
/// `type` and whose items are of `item_size` bytes.
struct PlyProperty {
  bool list = false;
  std::string type;       ///< a scalar's type, or a list's count type
  std::string item_type;  ///< a list's item type
  std::size_t size = 0;
  std::size_t item_size = 0;
};

struct PlyElement {
  std::string name;
  std::size_t line = 0;  ///< of its header line
  double declared = 0.0;  ///< the count as its line writes it
  /// The count as Assimp 5.2 reads it: the declared one for an element it knows
  /// (ply_element_known()), 0 for another (it reads the count from where the name begins, and
  /// the names it does not know are refused when they begin with a digit).
  double count = 0.0;
  std::vector<PlyProperty> properties;
};

/// The element names Assimp 5.2's PLY reader knows (and parses the values of).
bool ply_element_known(const std::string& name) {
  return name == "vertex" || name == "face" || name == "tristrips" || name == "edge" || name == "material";
}

bool has_list(const PlyElement& e) {
  return std::any_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& p) { return p.list; });
}

/// Whether Assimp 5.2 parses the values of an ASCII element (it skips the lines of an element
/// whose name it does not know, or that has no properties).
bool assimp_parses(const PlyElement& e) { return ply_element_known(e.name) && !e.properties.empty(); }

/// Whether Assimp 5.2's ASCII PLY reader takes `token` whole as a value of `type`. It parses a
/// value where it stands (strtoul10 for the unsigned types: digits only; strtol10 for the
/// signed ones: a sign, then digits; fast_atoreal_move for float and double) and skips only
/// spaces after it, so what a parser leaves of a token is where it parses the next value:
/// "1-7" for an int and a list count after it is 1, then the count -7, 4 billion unsigned.
/// A float's digit run of more than 19 digits overflows fast_atoreal_move's 64-bit integer,
/// which then returns without moving: refused too.
bool ply_value_whole(std::string_view t, const std::string& type) {
  const auto digit = [&](std::size_t i) { return i < t.size() && t[i] >= '0' && t[i] <= '9'; };
  // The digits from i; false when they would overflow 64 bits (leading zeros do not count).
  const auto digits = [&](std::size_t& i) {
    while (digit(i) && t[i] == '0') ++i;
    const std::size_t start = i;
    while (digit(i)) ++i;
    return i - start <= 19;
  };
  std::size_t i = 0;
  const bool is_unsigned = type == "uchar" || type == "uint8" || type == "ushort" || type == "uint16" || type == "uint" ||
                           type == "uint32";
  const bool is_signed = type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" ||
                         type == "int32";
  if (is_unsigned || is_signed) {
    if (is_signed && !t.empty() && (t[0] == '+' || t[0] == '-')) ++i;
    if (!digit(i)) return false;
    while (digit(i)) ++i;
    return i == t.size();
  }
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) ++i;
  std::string rest(t.substr(i));
  for (char& c : rest) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (rest == "nan" || rest == "inf" || rest == "infinity") return true;
  const auto point = [&](std::size_t at) { return at < t.size() && (t[at] == '.' || t[at] == ','); };
  if (!digit(i) && !(point(i) && digit(i + 1))) return false;  // Assimp throws: its error
  if (!digits(i)) return false;
  if (point(i) && digit(i + 1)) {
    ++i;
    while (digit(i)) ++i;  // it reads 15 decimals and skips the rest
  } else if (i < t.size() && t[i] == '.') {
    ++i;
  }
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    if (!digit(i) || !digits(i)) return false;
  }
  return i == t.size();
}

/// A PLY header as Assimp 5.2's reader takes it, or refused where it would take it otherwise
/// than its text says.
struct PlyHeader {
  bool binary = false, big_endian = false;
  std::vector<PlyElement> elements;
  std::size_t body = 0;       ///< the byte where Assimp starts the data
  std::size_t body_line = 0;  ///< its line (ASCII)
};

/// Reads a file forwards from an offset, a buffer at a time (the PLY checks below).
class ForwardReader {
 public:
  ForwardReader(const fs::path& path, std::size_t offset) : in_(path, std::ios::binary), offset_(offset) {
    in_.seekg(static_cast<std::streamoff>(offset));
  }
  /// The next byte without taking it, or -1 at the end of the file.
  int peek() {
    if (at_ == end_ && !fill()) return -1;
    return static_cast<unsigned char>(buffer_[at_]);
  }
  /// The next byte, or -1 at the end of the file.
  int get() {
    const int c = peek();
    if (c >= 0) ++at_, ++offset_;
    return c;
  }
  /// Skips n bytes; false when the file ends first.
  bool skip(double n) {
    while (n > 0.0) {
      if (at_ == end_ && !fill()) return false;
      const auto step = static_cast<std::size_t>(std::min(n, static_cast<double>(end_ - at_)));
      at_ += step;
      offset_ += step;
      n -= static_cast<double>(step);
    }
    return true;
  }
  std::size_t offset() const { return offset_; }

 private:
  bool fill() {
    in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    at_ = 0;
    end_ = static_cast<std::size_t>(std::max<std::streamsize>(in_.gcount(), 0));
    return end_ > 0;
  }
  std::ifstream in_;
  std::vector<char> buffer_ = std::vector<char>(std::size_t{1} << 16);
  std::size_t at_ = 0, end_ = 0, offset_ = 0;
};

/// Lines as Assimp 5.2's IOStreamBuffer::getNextLine() cuts them: at '\r' or '\n'; a line end
/// at the start of a call is skipped through the next '\n' (so "\r\n" is one line end, and of
/// two blank lines one is skipped and one is an empty line). The PLY reader parses an ASCII
/// element instance from one such line, so the checks below walk the same lines.
class PlyLines {
 public:
  /// `all_line_ends`: a NUL and a form feed end a line too, as IsLineEnd() has them (the body,
  /// which Assimp reads so; the header walk keeps them in its lines to refuse them, naming the
  /// byte). A line cut at one goes on as a new line after it, and one that starts at one is
  /// skipped through the next '\n' (an element line beginning with NUL bytes, the rest of it
  /// skipped: Assimp read the next line for it, every line after it one element off, and a
  /// list count from a line the walk took for another; radiosity_fuzz_ply, session 34).
  PlyLines(ForwardReader& in, std::size_t line, bool all_line_ends = false)
      : in_(in), line_(line), all_line_ends_(all_line_ends) {}
  /// The next line's text into `out`, its number into `number`; false at the end of the file.
  bool next(std::string& out, std::size_t& number) {
    int c = in_.peek();
    if (line_end(c)) {
      while ((c = in_.get()) >= 0 && c != '\n') {}
      if (c == '\n') ++line_;
    }
    if (in_.peek() < 0) return false;
    out.clear();
    number = line_;
    while ((c = in_.peek()) >= 0 && !line_end(c)) out.push_back(static_cast<char>(in_.get()));
    if (in_.get() == '\n') ++line_;
    return true;
  }

 private:
  bool line_end(int c) const { return c == '\r' || c == '\n' || (all_line_ends_ && (c == '\0' || c == '\f')); }
  ForwardReader& in_;
  std::size_t line_;
  bool all_line_ends_;
};

/// The byte of a header or ASCII line that no PLY file holds (a control character other than
/// tab; Assimp ends a line at NUL and form feed, so the line it reads would not be this one).
std::size_t control_byte(const std::string& line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    const auto c = static_cast<unsigned char>(line[i]);
    if ((c < 0x20 && c != '\t') || c == 0x7f) return i;
  }
  return std::string::npos;
}

/// Reads the header of a PLY file (refusing the forms Assimp 5.2 would read otherwise than
/// they say: see check_ply()).
PlyHeader read_ply_header(const fs::path& path) {
  {
    // A cut header first: its last line may look like anything.
    // At most its first megabyte, and no more than the file holds: a buffer of the full
    // megabyte per file was most of the PLY fuzz target's time (allocating and zeroing it).
    std::error_code size_error;
    const std::uintmax_t file_bytes = fs::file_size(path, size_error);
    std::ifstream file(path, std::ios::binary);
    std::string head(size_error ? std::size_t{1} << 20 : std::min<std::size_t>(file_bytes, std::size_t{1} << 20), '\0');
    file.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(std::max<std::streamsize>(file.gcount(), 0)));
    bool found = false;
    for (std::size_t at = head.find("end_header"); at != std::string::npos && !found; at = head.find("end_header", at + 1))
      found = at > 0 && (head[at - 1] == '\n' || head[at - 1] == '\r') && at + 10 < head.size() &&
              (head[at + 10] == '\n' || head[at + 10] == '\r' || head[at + 10] == ' ' || head[at + 10] == '\t');
    if (!found)
      throw Error(ErrorCode::parse_error, path.string() + ": the PLY header has no end_header line (a truncated file?)");
  }
  ForwardReader in(path, 0);
  PlyLines lines(in, 1);
  PlyHeader header;
  std::string line;
  std::size_t number = 0;
  auto refuse = [&](const std::string& what) {
    throw Error(ErrorCode::parse_error, path.string() + ":" + std::to_string(number) + ": " + what);
  };
  bool in_element = false;  // the lines since the last element line were its properties (or comments)
  bool ended = false;
  std::size_t format_line = 0;
  while (in.offset() < (std::size_t{1} << 20) && lines.next(line, number)) {
    if (const std::size_t at = control_byte(line); at != std::string::npos) {
      char code[8];
      std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned>(static_cast<unsigned char>(line[at])));
      refuse("the PLY header holds the byte " + std::string(code) + " (column " + std::to_string(at + 1) +
             "), which no PLY header has (a corrupted or cut file)");
    }
    std::istringstream words(line);
    std::string word;
    if (!(words >> word)) continue;  // a blank line
    if (word == "end_header") {
      ended = true;
      break;
    }
    if (number == 1 || word == "comment" || word == "obj_info") continue;  // line 1 is "ply" (Assimp checks it)
    if (word == "format") {
      // Assimp 5.2 takes the format from the line after "ply" and passes over any later one
      // (its header parser ignores the lines it does not know): a second format line made
      // this walk read an ASCII body as binary, and Assimp reserved a list of 444444444 items
      // (3.5 GB) from a 1.4 kB file (radiosity_fuzz_ply, session 34).
      if (format_line != 0)
        refuse("a second PLY format line (the first is on line " + std::to_string(format_line) +
               "); the PLY reader (Assimp 5.2) reads the first");
      format_line = number;
      std::string format;
      words >> format;
      // Assimp tells the formats by "ascii" and the prefix "binary_" (big-endian when a 'b'
      // follows), so it reads other words as one of them: only PLY's own three.
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        refuse("PLY format '" + format.substr(0, 40) + "', which is none of ascii, binary_little_endian and "
               "binary_big_endian");
      header.binary = format != "ascii";
      header.big_endian = format == "binary_big_endian";
      in_element = false;
    } else if (word == "element") {
      PlyElement e;
      std::string count, extra;
      words >> e.name >> count;
      char* end = nullptr;
      e.declared = std::strtod(count.c_str(), &end);
      e.line = number;
      if (count.empty() || *end != '\0' || !(e.declared >= 0.0) || e.declared != std::floor(e.declared) || (words >> extra))
        refuse("PLY element '" + e.name + "' has the count '" + count + "', not a number of elements");
      // For a name it does not know, Assimp 5.2 reads the count where the name begins: 0 for a
      // name of letters, and the digits of one that begins with digits (modulo 2^32: an element
      // "999...9vex" of 117 nines asked for 4 billion instances, 103 GB; radiosity_fuzz_ply,
      // session 31).
      if (!ply_element_known(e.name) && !e.name.empty() && e.name[0] >= '0' && e.name[0] <= '9')
        refuse("PLY element '" + e.name.substr(0, 40) + "' has a name that begins with a digit, which the PLY reader "
               "(Assimp 5.2) takes for its count (it reads the count of an element it does not know from where "
               "its name begins)");
      e.count = ply_element_known(e.name) ? e.declared : 0.0;
      header.elements.push_back(e);
      in_element = true;
    } else if (word == "property") {
      // Assimp attaches only the properties that follow their element's line (comments
      // between them); one after another line it drops, and reads the data without it.
      if (!in_element) refuse("a PLY property line that does not follow an element's line or its properties");
      std::string type, name;
      words >> type;
      PlyProperty property;
      if (type == "list") {
        std::string item;
        words >> type >> item;
        property.list = true;
        property.item_type = item;
        property.item_size = ply_type_size(item);
        if (property.item_size == 0) refuse("PLY list items of the type '" + item + "', which is no PLY type");
      }
      property.type = type;
      property.size = ply_type_size(type);
      if (property.size == 0) refuse("a PLY property of the type '" + type + "', which is no PLY type");
      if (!(words >> name)) refuse("a PLY property without a name");
      header.elements.back().properties.push_back(property);
    } else {
      refuse("'" + word + "' begins no PLY header line (ply, format, comment, obj_info, element, property, end_header)");
    }
  }
  if (!ended)
    throw Error(ErrorCode::parse_error,
                path.string() + ": the PLY header has no end_header line (a truncated file?)");
  header.body = in.offset();
  header.body_line = number + 1;
  // Assimp 5.2 keeps one array of vertices and one of faces (a tristrip's too), sized by the
  // first element that fills it: a second one writes its instances into it, past its end when
  // it has more (a heap overflow, seen by valgrind; under AddressSanitizer, which does not
  // instrument Assimp, it corrupted the allocator's own records and stopped two fuzz runs,
  // session 31).
  {
    std::size_t vertex_line = 0, face_line = 0;
    for (const PlyElement& e : header.elements) {
      const bool faces = e.name == "face" || e.name == "tristrips";
      if (e.name != "vertex" && !faces) continue;
      std::size_t& first = faces ? face_line : vertex_line;
      if (first != 0) {
        number = e.line;
        refuse("a second PLY element of " + std::string(faces ? "faces ('face' or 'tristrips')" : "vertices") +
               " (the first is on line " + std::to_string(first) + "); the PLY reader (Assimp 5.2) would write its "
               "instances into the first one's storage, past its end when it has more");
      }
      first = e.line;
    }
  }
  // Assimp 5.2 reads no data for an element it does not know (ply_element_known()) and goes
  // on with the next element's: one before the faces shifts every vertex or face after it.
  bool faces_after = false;
  for (std::size_t k = header.elements.size(); k-- > 0;) {
    const PlyElement& e = header.elements[k];
    if (!ply_element_known(e.name) && faces_after && e.declared > 0.0) {
      number = e.line;
      refuse("PLY element '" + e.name + "' comes before the vertices or faces, and the PLY reader (Assimp 5.2) "
             "cannot skip an element it does not know: it would read its values as theirs. Put it after them");
    }
    faces_after |= e.name == "vertex" || e.name == "face" || e.name == "tristrips";
  }
  return header;
}

/// Refuses a PLY file that Assimp 5.2's reader would take otherwise than it says, loop on, or
/// allocate for beyond what the file can hold, before Assimp opens it:
/// - a header that does not end (a truncated file) makes it loop forever: "end_header" must
///   come within the first MiB;
/// - a header line that is none of PLY's, a control byte in it, a property after a line that
///   is not its element's, or an element it does not know before the faces: it would read the
///   data shifted (vertices and faces from the wrong values);
/// - it allocates what the element counts ask for before reading them (a count of four
///   billion in a 1 kB file is tens of GB): each element needs at least its fixed-size
///   properties in a binary file, two characters per property in an ASCII one (but the last),
///   and one byte when it has no properties;
/// - it reserves a list's count before reading its items: an ASCII face whose count was
///   4444444444444444444444444444440 (radiosity_fuzz_ply, session 25) took 7.5 GB and 15 s from
///   a 219-byte file. An ASCII element is one line for Assimp, so a list's items must be on its
///   line (a NUL there ends the line for Assimp: refused too); in a binary file they must fit in
///   the bytes left;
/// - an ASCII body that makes it read other bytes than its lines' values (below).
void check_ply(const fs::path& path, const PlyHeader& header) {
  std::error_code size_error;
  const std::uintmax_t size = fs::file_size(path, size_error);
  if (size_error) return;  // Assimp will say what is wrong
  const double available = static_cast<double>(size) - static_cast<double>(std::min<std::uintmax_t>(header.body, size));
  double needed = 0.0;
  for (const PlyElement& e : header.elements) {
    double per = 0.0;
    for (const PlyProperty& p : e.properties) per += header.binary ? static_cast<double>(p.size) : 2.0;
    // An element without properties is still read instance by instance, a line each in an
    // ASCII file: a count of billions is minutes of Assimp skipping lines the file does not
    // have (a face element of 48888888888888888888888888888888, radiosity_fuzz_ply, session 31:
    // a hang, or a segmentation fault when those lines were carriage returns). A byte each.
    if (e.properties.empty()) per = 1.0;
    needed += e.count * per;
  }
  if (!header.binary && needed > 0.0) needed -= 1.0;  // the last value may end the file without a separator
  auto whole = [](double v) { return v < 1e19 ? std::to_string(static_cast<std::uint64_t>(v)) : number_text(v); };
  if (needed > available) {
    // Whole numbers in full (a count of 4000000000, not 4e+09), however large.
    std::string counts;
    for (const PlyElement& e : header.elements)
      if (e.count > 0.0) counts += (counts.empty() ? "" : ", ") + whole(e.count) + " " + e.name;
    throw Error(ErrorCode::parse_error, path.string() + ": the PLY header declares " + counts + ", which need at least " +
                                            whole(needed) + " bytes, but the file holds " + whole(available) +
                                            " after its header (a truncated file or a wrong count)");
  }

  if (std::none_of(header.elements.begin(), header.elements.end(), has_list)) return;
  ForwardReader in(path, header.body);
  if (header.binary) {
    for (const PlyElement& e : header.elements) {
      if (!has_list(e)) {  // every instance of the same size: no walk
        double fixed = 0.0;
        for (const PlyProperty& p : e.properties) fixed += static_cast<double>(p.size);
        if (!in.skip(e.count * fixed)) return;
        continue;
      }
      for (double k = 0.0; k < e.count; k += 1.0)
        for (const PlyProperty& p : e.properties) {
          if (!p.list) {
            if (!in.skip(static_cast<double>(p.size))) return;  // a short body is Assimp's to report
            continue;
          }
          const std::size_t at = in.offset();
          unsigned char bytes[8] = {};
          for (std::size_t b = 0; b < p.size; ++b) {
            const int c = in.get();
            if (c < 0) return;
            bytes[header.big_endian ? p.size - 1 - b : b] = static_cast<unsigned char>(c);
          }
          const std::string& t = p.type;
          double count = 0.0;
          if (t == "float" || t == "float32") {
            float f;
            std::memcpy(&f, bytes, 4);
            count = f;
          } else if (t == "double" || t == "float64") {
            std::memcpy(&count, bytes, 8);
          } else {
            std::uint64_t u = 0;
            for (std::size_t b = 0; b < p.size; ++b) u |= static_cast<std::uint64_t>(bytes[b]) << (8 * b);
            const bool is_signed = t == "char" || t == "int8" || t == "short" || t == "int16" || t == "int" || t == "int32";
            count = is_signed && (bytes[p.size - 1] & 0x80u) ? -1.0 : static_cast<double>(u);
          }
          const std::string where = path.string() + ": PLY element '" + e.name + "' " + whole(k) + ": ";
          if (!(count >= 0.0 && count == std::floor(count)))
            throw Error(ErrorCode::parse_error, where + "a list count of " + number_text(count) + " at byte " +
                                                    std::to_string(at) + ", not a number of items (a corrupted file)");
          const double left = static_cast<double>(size) - static_cast<double>(in.offset());
          if (count * static_cast<double>(p.item_size) > left)
            throw Error(ErrorCode::parse_error, where + "a list of " + whole(count) + " items at byte " +
                                                    std::to_string(at) + ", but the file holds " + whole(left) +
                                                    " bytes after it (a corrupted file or a wrong count)");
          if (!in.skip(count * static_cast<double>(p.item_size))) return;
        }
    }
    return;
  }
  // ASCII: one line per element instance (PlyLines), its values separated by spaces and tabs.
  // Assimp's line reader keeps one buffer for every line, written over from its start, and the
  // PLY reader skips line ends as it skips spaces after a value; so it reads bytes that are not
  // the line's values, left there by earlier (longer) lines, in three cases, each refused:
  // - a body shorter than its counts: at the end of the file the line reader fails and leaves
  //   the buffer as it was, and the last line is read again for every instance still to come
  //   (a 205-byte file whose 4-line body ended in "444444444445 ..." declared 8 faces: that
  //   number, modulo 2^32, became each face's list count, 16 GB; radiosity_fuzz_ply, session
  //   30). A truncated file, or a wrong count: Assimp would make the missing vertices and faces
  //   copies of the last line's;
  // - a line with some values, but fewer than its element's properties ask for: the missing
  //   ones would be read past its line end, in what the longer lines before it left there (a
  //   line with no value at all is read as zeros, without going past it);
  // - in an element with a list, a value its type's parser does not take whole
  //   (ply_value_whole()): the rest would be read as the next value, a list count among them.
  // An element Assimp does not parse (assimp_parses()) has its lines skipped, whatever they hold.
  PlyLines lines(in, header.body_line, true);
  std::string line;
  std::size_t number = header.body_line - 1;
  std::vector<std::string_view> values;
  for (const PlyElement& e : header.elements) {
    if (!assimp_parses(e)) {
      for (double k = 0.0; k < e.count; k += 1.0)
        if (!lines.next(line, number)) return;
      continue;
    }
    const bool lists = has_list(e);
    for (double k = 0.0; k < e.count; k += 1.0) {
      if (!lines.next(line, number))
        throw Error(ErrorCode::parse_error,
                    path.string() + ":" + std::to_string(number) + ": the PLY body ends here, after " + whole(k) + " of the " +
                        whole(e.count) + " '" + e.name + "' lines its header declares (a truncated file or a wrong count; "
                        "the PLY reader, Assimp 5.2, would read the last line again for each one missing)");
      const std::string where = path.string() + ":" + std::to_string(number) + ": PLY element '" + e.name + "' " + whole(k) + ": ";
      if (lists)
        if (const std::size_t at = control_byte(line); at != std::string::npos)
          throw Error(ErrorCode::parse_error, where + "a control byte (column " + std::to_string(at + 1) +
                                                  ") in ASCII data (a corrupted or binary file)");
      values.clear();
      for (std::size_t i = 0; i < line.size();) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) values.emplace_back(line.data() + start, i - start);
      }
      if (values.empty()) continue;  // read as zeros
      const auto short_line = [&] {
        return Error(ErrorCode::parse_error, where + "its line holds " + std::to_string(values.size()) +
                                                 " values, fewer than the element's properties ask for (a corrupted file; "
                                                 "the PLY reader, Assimp 5.2, would read the missing ones from the lines before it)");
      };
      const auto not_whole = [&](std::string_view value, const std::string& type) {
        return Error(ErrorCode::parse_error, where + "the value '" + std::string(value.substr(0, 40)) + "' is not a PLY " + type +
                                                 " (the PLY reader, Assimp 5.2, would read part of it and the rest as the "
                                                 "next value)");
      };
      std::size_t v = 0;
      for (const PlyProperty& p : e.properties) {
        if (v >= values.size()) throw short_line();
        if (!p.list) {
          if (lists && !ply_value_whole(values[v], p.type)) throw not_whole(values[v], p.type);
          ++v;
          continue;
        }
        const std::string count_text(values[v++]);
        char* end = nullptr;
        const double count = std::strtod(count_text.c_str(), &end);
        if (*end != '\0' || !(count >= 0.0) || count != std::floor(count))
          throw Error(ErrorCode::parse_error, where + "the list count '" + count_text.substr(0, 40) +
                                                  "' is not a number of items");
        if (!ply_value_whole(count_text, p.type)) throw not_whole(count_text, p.type);
        const double left = static_cast<double>(values.size() - v);
        if (count > left)
          throw Error(ErrorCode::parse_error, where + "a list of " + whole(count) + " items, but its line holds " +
                                                  whole(left) + " values after the count (a corrupted file or a wrong count)");
        for (std::size_t item = 0; item < static_cast<std::size_t>(count); ++item, ++v)
          if (!ply_value_whole(values[v], p.item_type)) throw not_whole(values[v], p.item_type);
      }
    }
  }
}

/// What Assimp 5.2's 3DS reader trusts and should not: a keyframer track (chunks 0xB020 ..
/// 0xB029: position, rotation, scale and the rest of an object's animation) declares its key
/// count in 32 bits, and the reader reserves that many 24-byte keys before reading one. A 2 KB
/// file found by the fuzzer asked for 18.7 GB (AddressSanitizer's shadow of it alone took
/// 2.3 GB; without it the reservation either stays untouched or fails with std::bad_alloc, by
/// the machine's memory). Each key takes at least 6 bytes (its frame and flags), so a count
/// beyond what its chunk holds is refused here first, naming both figures. Only the containers
/// that hold tracks are walked (the main chunk, the keyframer, its object nodes).
void check_3ds_tracks(const fs::path& path) {
  const std::string bytes = read_file(path, "3DS file");
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  auto u16 = [&](std::size_t at) { return std::uint32_t{le16(data + at)}; };
  auto u32 = [&](std::size_t at) { return le32(data + at); };
  // A track: the chunk header (id, length), 2 bytes of flags, 8 unknown, then the key count.
  constexpr std::size_t kHeader = 6, kTrackHead = 16, kMinKey = 6;
  auto walk = [&](auto&& self, std::size_t begin, std::size_t end, int depth) -> void {
    for (std::size_t at = begin; at + kHeader <= end && depth < 8;) {
      const std::uint32_t id = u16(at);
      const std::size_t length = u32(at + 2);
      if (length < kHeader) return;  // Assimp says what is wrong
      const std::size_t stop = at + std::min<std::size_t>(length, end - at);
      const bool container = id == 0x4D4D || id == 0xB000 || (id >= 0xB001 && id <= 0xB007);
      if (container) self(self, at + kHeader, stop, depth + 1);
      if (id >= 0xB020 && id <= 0xB029 && at + kTrackHead + 4 <= stop) {
        const std::uint64_t keys = u32(at + kTrackHead);
        const std::uint64_t holds = (stop - at - kTrackHead - 4) / kMinKey;
        if (keys > holds) {
          char where[64];
          std::snprintf(where, sizeof where, "chunk 0x%04X at byte %zu", static_cast<unsigned>(id), at);
          throw Error(ErrorCode::parse_error, path.string() + ": 3DS animation track (" + where + ") declares " +
                                                  std::to_string(keys) + " keys, but its " + std::to_string(stop - at) +
                                                  " bytes hold at most " + std::to_string(holds) +
                                                  " (a corrupted file or a wrong count)");
        }
      }
      at += std::max<std::size_t>(length, kHeader);
    }
  };
  walk(walk, 0, bytes.size(), 0);
}

/// The primitives (<triangles>, <polylist>, ...) of a COLLADA text whose index lists Assimp 5.2
/// cannot read without an internal assertion, which Debian's build keeps and which aborts the
/// process (ColladaParser::ReadIndexData, ReadPrimitives): a <triangles> or <polylist> whose
/// count is not that of its one index list (<p>; a missing one, found by libFuzzer in session 20,
/// or several), a <polygons> with other than count <p>s, a <polylist> with no <vcount> before its
/// <p>, a <tristrips> or <linestrips> strip too short to make one primitive. `fail(at, problem)`
/// throws.
/// XML's white space.
bool blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

template <typename Fail>
void check_collada_primitives(const std::string& text, const Fail& fail) {
  // The unsigned value of attribute `name` in the tag [at, end), or `fallback` when absent.
  auto attribute = [&](std::size_t at, std::size_t end, const char* name, std::size_t fallback) {
    const std::string key = std::string(" ") + name + "=\"";
    const std::size_t k = text.find(key, at);
    if (k == std::string::npos || k > end) return fallback;
    std::size_t value = 0;
    for (std::size_t i = k + key.size(); i < end && text[i] >= '0' && text[i] <= '9'; ++i)
      value = std::min(value * 10 + std::size_t(text[i] - '0'), std::size_t{1} << 40);
    return value;
  };
  // Whether the element opening at `at` is named exactly `name` (not a longer name).
  auto named = [&](std::size_t at, const std::string& name) {
    const std::size_t after = at + 1 + name.size();
    return text.compare(at + 1, name.size(), name) == 0 && after < text.size() &&
           (blank(text[after]) || text[after] == '>' || text[after] == '/');
  };
  for (const std::string primitive : {"triangles", "lines", "polylist", "polygons", "tristrips", "linestrips"}) {
    for (std::size_t at = text.find("<" + primitive); at != std::string::npos; at = text.find("<" + primitive, at + 1)) {
      if (!named(at, primitive)) continue;
      const std::size_t open_end = text.find('>', at);
      if (open_end == std::string::npos) return;  // truncated: Assimp's XML parser refuses it
      const std::size_t count = attribute(at, open_end, "count", 0);
      const bool empty = text[open_end - 1] == '/';
      const std::size_t close = empty ? open_end : std::min(text.find("</" + primitive, open_end), text.size());
      std::size_t lists = 0, offsets = 1, indices = 0;
      // The <vcount> values Assimp reads (the first `count`) and their sum, saturating.
      std::size_t vcounts = 0, vcount_sum = 0;
      bool vcount = false;
      for (std::size_t k = text.find('<', open_end); k < close; k = text.find('<', k + 1)) {
        if (named(k, "input")) {
          const std::size_t end = text.find('>', k);
          offsets = std::max(offsets, attribute(k, std::min(end, close), "offset", 0) + 1);
        } else if (named(k, "vcount") || named(k, "p")) {
          const std::size_t content = text.find('>', k);
          if (content == std::string::npos || content >= close || text[content - 1] == '/') continue;
          const std::size_t end = std::min(text.find('<', content), close);
          const bool counts = named(k, "vcount");
          std::size_t numbers = 0;
          for (std::size_t i = content + 1; i < end;) {
            if (blank(text[i])) {
              ++i;
              continue;
            }
            std::size_t value = 0;
            for (; i < end && !blank(text[i]); ++i)
              if (text[i] >= '0' && text[i] <= '9') value = std::min(value * 10 + std::size_t(text[i] - '0'), std::size_t{1} << 40);
            ++numbers;
            if (counts && vcounts < count) ++vcounts, vcount_sum = std::min(vcount_sum + value, std::size_t{1} << 50);
          }
          if (numbers == 0) continue;  // an empty list: Assimp skips it
          if (counts) {
            vcount = true;
            continue;
          }
          indices += numbers;
          if (primitive == "polylist" && count > 0 && !vcount)
            fail(k, "a <polylist>'s index list (<p>) comes before its vertex counts (<vcount>)");
          const std::size_t vertices = numbers / offsets;
          if (primitive == "tristrips" && vertices < 2) fail(k, "a <tristrips> strip has fewer than 2 vertices");
          if (primitive == "linestrips" && vertices < 1) fail(k, "a <linestrips> strip has no vertex");
          ++lists;
        }
      }
      const bool one_list = primitive == "triangles" || primitive == "polylist";
      if (one_list && count > 0 && lists != 1)
        fail(at, "a <" + primitive + "> of count " + std::to_string(count) + " has " + std::to_string(lists) +
                     " index lists (<p>), not one");
      // Assimp reserves the indices its counts promise before reading one (and then refuses a
      // list of another length): a wrong count of a few digits asks for gigabytes.
      // In doubles: the counts are capped at 2^40 and 2^50, so their product may not fit an integer.
      const double promised =
          primitive == "triangles" ? 3.0 * count : primitive == "lines" ? 2.0 * count : primitive == "polylist" ? double(vcount_sum) : 0.0;
      if (primitive == "polylist" && count > 0 && vcounts < count)
        fail(at, "a <polylist> of count " + std::to_string(count) + " has " + std::to_string(vcounts) +
                     " vertex counts (<vcount>)");
      if (count > 0 && lists == 1 && (primitive == "triangles" || primitive == "polylist") && promised * double(offsets) != double(indices))
        fail(at, "a <" + primitive + "> promises " +
                     (promised >= 0x1p40 ? std::string("over 10^12") : std::to_string(static_cast<std::uint64_t>(promised))) +
                     " vertices of " + std::to_string(offsets) + " indices each" +
                     (primitive == "polylist" ? " (the sum of its <vcount>)" : "") + ", but its index list (<p>) holds " +
                     std::to_string(indices) + " indices");
      if (primitive == "lines" && promised * double(offsets) > double(text.size()))
        fail(at, "a <lines> of count " + std::to_string(count) + " promises more indices than the file holds characters");
      if (primitive == "polygons" && lists != count)
        fail(at, "a <polygons> of count " + std::to_string(count) + " has " + std::to_string(lists) + " index lists (<p>)");
    }
  }
}

/// What Assimp 5.2's COLLADA reader trusts and should not: an index list (<p>) that holds
/// anything but numbers makes it loop forever, an array (<float_array count="N">) holding more
/// values than its count makes it write beyond what it allocated, and primitives whose index
/// lists do not match their counts abort it (check_collada_primitives()). Such corruptions are
/// refused here first, with their line.
void check_collada(const fs::path& path) {
  const std::string text = read_file(path, "COLLADA file");
  auto fail = [&](std::size_t at, const std::string& problem) {
    throw Error(ErrorCode::parse_error, path.string() + ":" + line_column(text, at) + ": " + problem);
  };
  for (std::size_t at = text.find("<p>"); at != std::string::npos; at = text.find("<p>", at + 3)) {
    const std::size_t end = std::min(text.find('<', at + 3), text.size());
    for (std::size_t i = at + 3; i < end; ++i)
      if (!((text[i] >= '0' && text[i] <= '9') || blank(text[i]) || text[i] == '-' || text[i] == '+'))
        fail(i, "an index list (<p>) holds a character that is not part of a number");
  }
  for (const char* tag : {"<float_array", "<int_array"}) {
    for (std::size_t at = text.find(tag); at != std::string::npos; at = text.find(tag, at + 1)) {
      const std::size_t open_end = text.find('>', at);
      if (open_end == std::string::npos) break;
      if (text[open_end - 1] == '/') continue;  // empty
      const std::size_t count_at = text.find(" count=\"", at);
      if (count_at == std::string::npos || count_at > open_end) fail(at, std::string(tag + 1) + " has no count");
      std::size_t count = 0, i = count_at + 8;
      for (; i < open_end && text[i] >= '0' && text[i] <= '9'; ++i) count = std::min(count * 10 + std::size_t(text[i] - '0'), std::size_t{1} << 40);
      if (i == count_at + 8 || text[i] != '"') fail(count_at, std::string(tag + 1) + "'s count is not a number");
      const std::size_t end = std::min(text.find('<', open_end), text.size());
      std::size_t values = 0;
      for (std::size_t k = open_end + 1; k < end; ++k)
        if (!blank(text[k]) && blank(text[k - 1] == '>' ? ' ' : text[k - 1])) ++values;
      if (values > count)
        fail(at, std::string(tag + 1) + " holds " + std::to_string(values) + " values, more than its count " + std::to_string(count));
    }
  }
  check_collada_primitives(text, fail);
}

/// One FBX connection, `C: "OO", child, parent` (or "OP" with a property), and where it is:
/// the byte offset of its record (binary) or of its key (text).
struct FbxConnection {
  std::string child, parent;
  std::size_t at = 0;
};

/// A connection on a cycle among `connections` (an object its own parent or ancestor), or null.
/// Depth first from each object along its parents, marking the objects on the current walk (1)
/// and those already cleared (2). Cost: linear in the connections (times a map's log).
const FbxConnection* fbx_connection_cycle(const std::vector<FbxConnection>& connections) {
  std::map<std::string, std::vector<std::size_t>> parents_of;  // child -> its connections
  for (std::size_t k = 0; k < connections.size(); ++k) parents_of[connections[k].child].push_back(k);
  std::map<std::string, int> state;
  for (const auto& start : parents_of) {
    if (state[start.first] != 0) continue;
    // (object, index of the next of its connections to follow)
    std::vector<std::pair<std::string, std::size_t>> walk = {{start.first, 0}};
    state[start.first] = 1;
    while (!walk.empty()) {
      auto& [object, next] = walk.back();
      const auto found = parents_of.find(object);
      if (found == parents_of.end() || next == found->second.size()) {
        state[object] = 2;
        walk.pop_back();
        continue;
      }
      const FbxConnection& c = connections[found->second[next++]];
      int& seen = state[c.parent];
      if (seen == 1) return &c;
      if (seen == 0) {
        seen = 1;
        walk.emplace_back(c.parent, 0);
      }
    }
  }
  return nullptr;
}

std::string fbx_cycle_text(const FbxConnection& c) {
  return "object " + c.parent + " is its own " + (c.parent == c.child ? "parent" : "ancestor") +
         " (a scene graph has none; Assimp 5.2 follows one until its stack overflows)";
}

/// The connections of a binary FBX (the records "C" under the top-level record "Connections";
/// Autodesk's format as Blender's and Assimp's readers document it: after the 27-byte header,
/// records of an end offset, a property count and a property-list length, 64-bit from version
/// 7500 and 32-bit before, a name, the properties, then nested records). Best effort: what it
/// cannot read it leaves to Assimp, returning what it found so far.
std::vector<FbxConnection> binary_fbx_connections(const std::string& bytes) {
  std::vector<FbxConnection> out;
  if (bytes.size() < 27) return out;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  auto u32 = [&](std::size_t at) { return le32(data + at); };
  auto u64 = [&](std::size_t at) { return le64(data + at); };
  const bool wide = u32(23) >= 7500;
  const std::size_t head = wide ? 25 : 13;  // end offset, property count and list length, name length
  // A record at `at`: its end, property count, where its properties start and end, its name.
  struct Record {
    std::uint64_t end = 0, properties = 0;
    std::size_t first = 0, after = 0;
    std::string name;
  };
  auto record = [&](std::size_t at, Record& r) {
    if (at + head > bytes.size()) return false;
    r.end = wide ? u64(at) : u32(at);
    r.properties = wide ? u64(at + 8) : u32(at + 4);
    const std::uint64_t list = wide ? u64(at + 16) : u32(at + 8);
    const std::size_t name_length = static_cast<unsigned char>(bytes[at + head - 1]);
    r.first = at + head + name_length;
    // Ends after it starts (so a walk always moves on), within the file, past its name and list.
    if (r.end <= at || r.end > bytes.size() || r.first > r.end || list > r.end - r.first) return false;
    r.after = r.first + static_cast<std::size_t>(list);
    r.name.assign(bytes, at + head, name_length);
    return true;
  };
  Record top;
  for (std::size_t at = 27; record(at, top); at = static_cast<std::size_t>(top.end)) {
    if (top.name != "Connections") continue;
    Record c;
    for (std::size_t child = top.after; child < top.end && record(child, c); child = static_cast<std::size_t>(c.end)) {
      if (c.name != "C" || c.properties < 3) continue;
      // The type ('S': a 32-bit length and the text), then the two ids ('L': 64-bit integers).
      std::size_t p = c.first;
      if (p + 5 > c.after || bytes[p] != 'S') continue;
      p += 5 + u32(p + 1);
      std::string ids[2];
      for (std::string& id : ids) {
        if (p + 9 > c.after || bytes[p] != 'L') break;
        id = std::to_string(static_cast<std::int64_t>(u64(p + 1)));
        p += 9;
      }
      if (!ids[0].empty() && !ids[1].empty()) out.push_back({ids[0], ids[1], child});
    }
    break;
  }
  return out;
}

/// What Assimp 5.2's FBX reader trusts and should not: in a text FBX, a mesh's `Layer:`
/// element names its index as its first value, and the reader takes that value without
/// checking there is one (it reads the first of an empty token list): a `Layer:` whose next
/// token is a `{` or another key (`Layer:   {`, `Layer:LayerElementMaterial: 0 {`, both found by
/// radiosity_fuzz_fbx in session 23, and `Layer: 0rial: 0 {`, session 24: a key that starts with
/// a digit) crashes the process with a segmentation fault. Refused here first, with its line:
/// the token after every `Layer:` key (outside strings and `;` comments) must be a whole
/// integer.
///
/// The converter then copies every property of a model (`Model:` object) it did not read itself
/// into the node's metadata, and asserts when one's type is none it has metadata for: `KTime`
/// (a 64-bit integer) and `ColorAndAlpha` (a colour with alpha) abort the process (Debian keeps
/// assertions; found by radiosity_fuzz_fbx in session 23: a model without a `Properties70`
/// block takes the property template of `ObjectType: "Model"` as its own table, and the fuzzed
/// template held GlobalSettings' `TimeSpanStart`, a KTime). No exporter writes either type on a
/// node, so a `P:` of one of these types inside a `Model:` object or the Model property template
/// is refused, with its line. The scopes are followed by their braces, as Assimp's parser does.
///
/// The converter walks the scene graph from the root by the connections (`C: "OO", child,
/// parent`), recursively and without remembering where it has been, so a cycle among them (an
/// object connected to itself, found by radiosity_fuzz_fbx in session 30, or to its own
/// descendant) recurses until the stack overflows: a segmentation fault. A cycle is refused,
/// with the line of one of its connections; in a binary FBX (whose other checks above do not
/// apply) with the byte where that connection's record starts.
void check_fbx(const fs::path& path) {
  const std::string text = read_file(path, "FBX file");
  if (text.rfind("Kaydara FBX Binary", 0) == 0) {
    const std::vector<FbxConnection> connections = binary_fbx_connections(text);
    if (const FbxConnection* c = fbx_connection_cycle(connections))
      throw Error(ErrorCode::parse_error, path.string() + ": at byte " + std::to_string(c->at) +
                                              ": the connections form a cycle: " + fbx_cycle_text(*c));
    return;
  }
  auto name_char = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '|';
  };
  auto fail = [&](std::size_t at, const std::string& what) {
    throw Error(ErrorCode::parse_error, path.string() + ":" + line_column(text, at) + ": " + what);
  };
  // The open scopes, each by the key before its `{`, and whether it is a model's (a `Model:`
  // object or `ObjectType: "Model"`'s template); the key last read and its first string value.
  std::vector<bool> scope_in_model;
  std::string last_key;
  std::string last_key_value;
  bool key_has_value = false;
  std::vector<FbxConnection> connections;
  for (std::size_t at = 0; at < text.size(); ++at) {
    const char c = text[at];
    if (c == '"') {  // a string: skipped whole
      const std::size_t close = text.find('"', at + 1);
      if (close == std::string::npos) break;  // Assimp says what is wrong
      if (!key_has_value) last_key_value = text.substr(at + 1, close - at - 1);
      key_has_value = true;
      at = close;
      continue;
    }
    if (c == '{') {
      const bool parent = !scope_in_model.empty() && scope_in_model.back();
      scope_in_model.push_back(parent || last_key == "Model" || (last_key == "ObjectType" && last_key_value == "Model"));
      last_key.clear();
      continue;
    }
    if (c == '}') {
      if (!scope_in_model.empty()) scope_in_model.pop_back();
      last_key.clear();
      continue;
    }
    if (c == ';') {  // a comment, to the end of the line
      const std::size_t eol = text.find('\n', at);
      if (eol == std::string::npos) break;
      at = eol;
      continue;
    }
    if (!name_char(c) || (at > 0 && name_char(text[at - 1]))) continue;
    std::size_t end = at;
    while (end < text.size() && name_char(text[end])) ++end;
    const bool key = end < text.size() && text[end] == ':';
    if (!key) {
      key_has_value = true;
      at = end - 1;
      continue;
    }
    last_key.assign(text, at, end - at);
    last_key_value.clear();
    key_has_value = false;
    if (last_key == "Layer") {
      std::size_t value = end + 1;
      while (value < text.size() && blank(text[value])) ++value;
      if (value < text.size() && (text[value] == '-' || text[value] == '+')) ++value;
      const std::size_t digits = value;
      while (value < text.size() && text[value] >= '0' && text[value] <= '9') ++value;
      // A whole number: `Layer: 0rial: 0 {` starts with a digit, yet `0rial:` is a key.
      if (value == digits || (value < text.size() && (name_char(text[value]) || text[value] == ':' || text[value] == '.')))
        fail(at, "a Layer element has no index (its first value)");
    }
    if (last_key == "P" && !scope_in_model.empty() && scope_in_model.back()) {
      // The type is the second value: `P: "name", "type", ...`.
      const std::size_t name_open = text.find_first_not_of(" \t", end + 1);
      const std::size_t name_close = name_open != std::string::npos && text[name_open] == '"' ? text.find('"', name_open + 1)
                                                                                           : std::string::npos;
      const std::size_t type_open = name_close == std::string::npos ? name_close : text.find_first_not_of(" \t,", name_close + 1);
      if (type_open != std::string::npos && text[type_open] == '"') {
        const std::size_t type_close = text.find('"', type_open + 1);
        const std::string type = text.substr(type_open + 1, type_close == std::string::npos ? 0 : type_close - type_open - 1);
        if (type == "KTime" || type == "ColorAndAlpha")
          fail(at, "a model's property of type " + type + " (Assimp 5.2 cannot keep it as node metadata and aborts)");
      }
    }
    if (last_key == "C") {
      // `C: "OO", child, parent` (or "OP", child, parent, "property"): the two ids after the type.
      std::size_t next = text.find_first_not_of(" \t", end + 1);
      if (next != std::string::npos && text[next] == '"') next = text.find('"', next + 1);
      std::string ids[2];
      for (std::string& id : ids) {
        if (next == std::string::npos) break;
        next = text.find_first_not_of(" \t,", next + 1);
        if (next == std::string::npos) break;
        const std::size_t id_end = text.find_first_of(" \t,\r\n", next);
        id = text.substr(next, id_end == std::string::npos ? std::string::npos : id_end - next);
        next = id_end == std::string::npos ? id_end : id_end - 1;
      }
      if (!ids[0].empty() && !ids[1].empty()) connections.push_back({ids[0], ids[1], at});
    }
    at = end;
  }

  if (const FbxConnection* c = fbx_connection_cycle(connections))
    fail(c->at, "the connections form a cycle: " + fbx_cycle_text(*c));
}

glm::dmat4 to_glm(const aiMatrix4x4& m) {
  // Assimp's matrices are row-major (a1..a4 the first row), GLM's column-major.
  const ai_real* r = &m.a1;
  glm::dmat4 out;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) out[col][row] = static_cast<double>(r[4 * row + col]);
  return out;
}

bool finite(const aiVector3D& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::dvec3 to_glm(const aiVector3D& v) { return glm::dvec3(v.x, v.y, v.z); }

/// A node's world matrix: its own transformation under its ancestors'.
glm::dmat4 world_matrix(const aiNode* node) {
  glm::dmat4 world(1.0);
  for (const aiNode* n = node; n; n = n->mParent) world = to_glm(n->mTransformation) * world;
  return world;
}

class AssimpReader {
 public:
  AssimpReader(const fs::path& path, const aiScene& scene, const LoadOptions& options)
      : path_(path), name_(path.string()), ai_(scene), options_(options), warnings_(options.strict),
        ply_(lower_extension(path) == ".ply") {}

  /// What validation does not check, before anything else runs on the scene.
  void check() const {
    if (!ai_.mRootNode) fail(ErrorCode::parse_error, "", "has no scene graph (no root node)");
    for (unsigned m = 0; m < ai_.mNumMeshes; ++m) {
      const aiMesh* mesh = ai_.mMeshes[m];
      const std::string place = mesh_place(m);
      if (!mesh || !mesh->HasPositions()) continue;
      for (unsigned v = 0; v < mesh->mNumVertices; ++v)
        if (!finite(mesh->mVertices[v]))
          fail(ErrorCode::parse_error, place, "vertex " + std::to_string(v) + " is NaN or infinite");
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices == 0 || !face.mIndices)
          fail(ErrorCode::parse_error, place, "face " + std::to_string(f) + " has no vertices (a truncated file?)");
        for (unsigned k = 0; k < face.mNumIndices; ++k)
          if (face.mIndices[k] >= mesh->mNumVertices)
            fail(ErrorCode::parse_error, place, "face " + std::to_string(f) + ": vertex " + std::to_string(face.mIndices[k]) +
                                                    " is out of range (" + std::to_string(mesh->mNumVertices) + " vertices)");
      }
    }
  }

  Scene read() {
    // Depth first from the root, each node with its parent's world matrix.
    std::vector<std::pair<const aiNode*, glm::dmat4>> stack = {{ai_.mRootNode, glm::dmat4(1.0)}};
    std::size_t visited = 0;
    while (!stack.empty()) {
      const auto [node, parent] = stack.back();
      stack.pop_back();
      // Assimp builds a tree; a count beyond its nodes would be a cycle.
      if (++visited > (std::size_t{1} << 24)) fail(ErrorCode::parse_error, "", "its node hierarchy does not end");
      const glm::dmat4 world = parent * to_glm(node->mTransformation);
      const std::string node_name = node->mName.C_Str();
      for (unsigned k = 0; k < node->mNumMeshes; ++k) {
        const unsigned m = node->mMeshes[k];
        if (m >= ai_.mNumMeshes || !ai_.mMeshes[m]) continue;  // validation refuses these
        add_mesh(m, node_name, world);
      }
      for (unsigned c = node->mNumChildren; c-- > 0;)
        if (node->mChildren[c]) stack.emplace_back(node->mChildren[c], world);
    }
    add_camera();
    add_lights();
    if (scene_.polygons().empty())
      fail(ErrorCode::parse_error, "",
           skipped_ ? "has no triangles that are not degenerate" : "has no triangles (no node places a mesh of faces)");
    warnings_.move_to(scene_);
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(ErrorCode code, const std::string& place, const std::string& problem) const {
    throw Error(code, name_ + ": " + (place.empty() ? "" : place + ": ") + problem);
  }
  std::string where(const std::string& place) const { return name_ + ": " + place; }

  std::string mesh_place(unsigned m) const {
    const aiMesh* mesh = ai_.mMeshes[m];
    const std::string name = mesh ? mesh->mName.C_Str() : "";
    return "meshes[" + std::to_string(m) + "]" + (name.empty() ? "" : " " + in_quotes(name));
  }

  void add_mesh(unsigned m, const std::string& node_name, const glm::dmat4& world) {
    const aiMesh& mesh = *ai_.mMeshes[m];
    const std::string mesh_name = mesh.mName.C_Str();
    // Assimp names the root node after the file format ("<STL_ASCII>") or leaves it empty.
    const bool made_up = node_name.empty() || node_name.front() == '<';
    const std::string group = !made_up ? node_name : !mesh_name.empty() ? mesh_name : "mesh" + std::to_string(m);
    const std::string place = mesh_place(m) + (node_name.empty() ? "" : " (placed by node " + in_quotes(node_name) + ")");

    LocalMesh local;
    local.positions.resize(mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v)
      local.positions[v] = glm::vec3(mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z);
    if (mesh.HasNormals()) {
      local.normals.resize(mesh.mNumVertices);
      for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const aiVector3D& n = mesh.mNormals[v];
        local.normals[v] = finite(n) ? glm::vec3(n.x, n.y, n.z) : glm::vec3(0.0f);
      }
    }
    auto uv = [&](unsigned set, std::vector<glm::vec2>& out) {
      if (!mesh.HasTextureCoords(set)) return;
      out.resize(mesh.mNumVertices);
      for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const aiVector3D& t = mesh.mTextureCoords[set][v];
        out[v] = finite(t) ? glm::vec2(t.x, t.y) : glm::vec2(0.0f);
      }
    };
    uv(0, local.uv0);
    uv(1, local.uv1);
    std::size_t no_area = 0;
    local.indices.reserve(3 * std::size_t{mesh.mNumFaces});
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) {
        ++no_area;  // points and lines (Triangulate left no polygons)
        continue;
      }
      local.indices.insert(local.indices.end(), {face.mIndices[0], face.mIndices[1], face.mIndices[2]});
    }
    if (no_area > 0)
      warnings_.forgive("points or lines", ErrorCode::parse_error, where(place),
                        std::to_string(no_area) + " point or line face" + (no_area > 1 ? "s have" : " has") + " no area",
                        "skipped");
    if (local.indices.empty()) return;
    if (add_placed_mesh(scene_, warnings_, std::move(local), world, material(mesh.mMaterialIndex), group, where(place),
                        options_, "nodes " + in_quotes(node_name) + ": meshes[" + std::to_string(m) + "]") > 0)
      skipped_ = true;
  }

  /// The first camera placed by a node becomes the scene's: Assimp gives its position, viewing
  /// direction and up in its node's coordinates, and the horizontal field of view, which its
  /// importers (COLLADA, FBX, 3DS) fill with the full angle though its documentation says half.
  void add_camera() {
    bool set = false;
    for (unsigned i = 0; i < ai_.mNumCameras; ++i) {
      const aiCamera* camera = ai_.mCameras[i];
      if (!camera) continue;
      const aiNode* node = ai_.mRootNode->FindNode(camera->mName);
      const std::string place = "cameras[" + std::to_string(i) + "] " + in_quotes(camera->mName.C_Str());
      if (!node) continue;  // not in the scene
      if (set) {
        warnings_.forgive("more cameras", ErrorCode::invalid_scene, where(place), "only the scene's first camera is used",
                          "ignored");
        continue;
      }
      const glm::dmat4 world = world_matrix(node);
      const glm::dmat3 linear(world);
      const glm::dvec3 eye(world * glm::dvec4(to_glm(camera->mPosition), 1.0));
      const glm::dvec3 forward = glm::normalize(linear * to_glm(camera->mLookAt));
      const glm::dvec3 up = glm::normalize(linear * to_glm(camera->mUp));
      const double horizontal = camera->mHorizontalFOV, aspect = camera->mAspect;
      const double vertical = aspect > 0.0 ? 2.0 * std::atan(std::tan(horizontal / 2.0) / aspect) : horizontal;
      Camera c;
      c.eye = glm::vec3(eye);
      c.look_at = glm::vec3(eye + forward);
      c.up = glm::vec3(up);
      c.fov_deg = static_cast<float>(glm::degrees(vertical));
      try {
        scene_.set_camera(c);
      } catch (const Error& e) {
        fail(e.code(), place, e.what());
      }
      set = true;
    }
  }

  /// Assimp's lights as docs/SCENE_GLTF.md ("Other formats") maps them: point, spot and
  /// directional lights placed by the node of the light's name (its world matrix moves
  /// mPosition and turns mDirection); ambient, area and undefined ones skipped with a warning.
  /// Assimp folds the intensity into the colour (mColorDiffuse = colour x intensity): the
  /// largest channel becomes Light::intensity, the colour is what is left (largest channel 1).
  void add_lights() {
    for (unsigned i = 0; i < ai_.mNumLights; ++i) {
      const aiLight* in = ai_.mLights[i];
      if (!in) continue;
      const std::string name = in->mName.C_Str();
      const std::string place = "lights[" + std::to_string(i) + "]" + (name.empty() ? "" : " " + in_quotes(name));
      Light light;
      switch (in->mType) {
        case aiLightSource_POINT: light.type = LightType::point; break;
        case aiLightSource_SPOT: light.type = LightType::spot; break;
        case aiLightSource_DIRECTIONAL: light.type = LightType::directional; break;
        default: {
          const char* type = in->mType == aiLightSource_AMBIENT ? "an ambient"
                             : in->mType == aiLightSource_AREA  ? "an area"
                                                                : "an undefined";
          warnings_.forgive("unsupported light type", ErrorCode::invalid_scene, where(place),
                            std::string(type) + " light has no counterpart (point, spot and directional lights are read)",
                            "skipped");
          continue;
        }
      }
      const aiNode* node = ai_.mRootNode->FindNode(in->mName);
      if (!node) {
        warnings_.forgive("light without a node", ErrorCode::invalid_scene, where(place),
                          "no node is named after it, so nothing places it in the scene", "skipped");
        continue;
      }
      const Rgb folded(in->mColorDiffuse.r, in->mColorDiffuse.g, in->mColorDiffuse.b);  // colour x intensity
      if (!finite(in->mPosition) || !finite(in->mDirection) || !std::isfinite(folded.x) || !std::isfinite(folded.y) ||
          !std::isfinite(folded.z) || !std::isfinite(in->mAngleInnerCone) || !std::isfinite(in->mAngleOuterCone))
        fail(ErrorCode::parse_error, place, "a position, direction, colour or cone angle is NaN or infinite");
      light.name = name.empty() ? "light " + std::to_string(i) : name;
      const Rgb c = clamp_colour(folded, FLT_MAX, FLT_MAX, warnings_, "light colour out of range", where(place),
                                 "colour x intensity", "an emitted intensity", ">= 0");
      light.intensity = max_channel(c);
      light.color = light.intensity > 0.0f ? c / light.intensity : Rgb(1.0f);
      if (light.type == LightType::spot) set_cones(light, *in, place);
      // Assimp's attenuation is 1 / (constant + linear d + quadratic d^2); the library's lights
      // fall off as 1 / d^2 (the physical law, and glTF's).
      if (light.type != LightType::directional &&
          (in->mAttenuationConstant != 0.0f || in->mAttenuationLinear != 0.0f || in->mAttenuationQuadratic != 1.0f))
        warnings_.forgive("light attenuation", ErrorCode::invalid_scene, where(place),
                          "attenuation 1/(" + number_text(in->mAttenuationConstant) + " + " + number_text(in->mAttenuationLinear) +
                              " d + " + number_text(in->mAttenuationQuadratic) + " d^2) is not applied",
                          "the light falls off as 1/d^2 (physical)");
      const glm::dvec3 direction = light.type == LightType::point ? glm::dvec3(0.0) : to_glm(in->mDirection);
      add_placed_light(scene_, light, world_matrix(node), to_glm(in->mPosition), direction, options_, where(place));
    }
  }

  /// A spot's cones: Assimp's angles are the full angles of the cones (what its COLLADA, FBX,
  /// 3DS and Blender importers fill them with, though its documentation does not say), the
  /// Light's half angles from the axis. Forgiven: an outer half angle beyond 90 degrees (90
  /// used), an inner one beyond the outer (the outer used), a negative one (0).
  void set_cones(Light& light, const aiLight& in, const std::string& place) {
    const double inner = glm::degrees(0.5 * static_cast<double>(in.mAngleInnerCone));
    const double outer = glm::degrees(0.5 * static_cast<double>(in.mAngleOuterCone));
    const double outer_used = std::clamp(outer, 0.0, 90.0);
    const double inner_used = std::clamp(inner, 0.0, outer_used);
    if (outer_used != outer || inner_used != inner)
      warnings_.forgive("spot cone out of range", ErrorCode::invalid_scene, where(place),
                        "cone half angles " + number_text(inner) + " and " + number_text(outer) +
                            " degrees (inner, outer) must satisfy 0 <= inner <= outer <= 90",
                        "clamped to " + number_text(inner_used) + " and " + number_text(outer_used));
    light.inner_cone_deg = static_cast<float>(inner_used);
    light.outer_cone_deg = static_cast<float>(outer_used);
  }

  /// A texture's mean (decoded from sRGB), or nullopt with a warning when it cannot be read.
  std::optional<Rgb> texture_mean(const aiMaterial& m, const std::string& place) {
    aiString file;
    if (m.GetTexture(aiTextureType_BASE_COLOR, 0, &file) != AI_SUCCESS &&
        m.GetTexture(aiTextureType_DIFFUSE, 0, &file) != AI_SUCCESS)
      return std::nullopt;
    const std::string name = file.C_Str();
    if (auto it = textures_.find(name); it != textures_.end()) {
      if (!it->second.first)
        warnings_.forgive("unreadable texture", ErrorCode::file_not_found, where(place), it->second.second,
                          "its colour alone is used");
      return it->second.first;
    }
    std::optional<Rgb> mean;
    std::string why;
    if (const aiTexture* embedded = ai_.GetEmbeddedTexture(file.C_Str())) {
      if (embedded->mHeight == 0) {
        mean = mean_of_encoded_image(reinterpret_cast<const unsigned char*>(embedded->pcData), embedded->mWidth, true, why);
      } else {
        // Uncompressed texels, stored b g r a.
        const std::size_t count = std::size_t{embedded->mWidth} * embedded->mHeight;
        std::vector<std::uint8_t> rgba(4 * count);
        for (std::size_t i = 0; i < count; ++i) {
          const aiTexel& t = embedded->pcData[i];
          rgba[4 * i] = t.r, rgba[4 * i + 1] = t.g, rgba[4 * i + 2] = t.b, rgba[4 * i + 3] = t.a;
        }
        mean = mean_of_rgba8(rgba.data(), count, true);
      }
    } else {
      std::string relative = name;
      std::replace(relative.begin(), relative.end(), '\\', '/');  // paths written on Windows
      const fs::path image = path_.parent_path() / fs::u8path(relative);
      try {
        const std::string bytes = read_file(image, "texture");
        mean = mean_of_encoded_image(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), true, why);
      } catch (const Error&) {
        why = "its file was not found or could not be read (looked for '" + image.string() + "')";
      }
    }
    if (!mean) why = "texture " + in_quotes(name) + ": " + why;
    textures_[name] = {mean, why};
    if (!mean)
      warnings_.forgive("unreadable texture", ErrorCode::file_not_found, where(place), why, "its colour alone is used");
    return mean;
  }

  /// Scene material of Assimp material `index`, made once.
  MaterialId material(unsigned index) {
    if (auto it = materials_.find(index); it != materials_.end()) return it->second;
    const aiMaterial* a = index < ai_.mNumMaterials ? ai_.mMaterials[index] : nullptr;
    aiString ai_name;
    if (a) a->Get(AI_MATKEY_NAME, ai_name);
    const std::string name = ai_name.C_Str();
    // Assimp's stand-in where the file has no material: "DefaultMaterial" (STL, meshes without
    // one), and the unnamed white one its PLY reader makes. Ours is the readers' grey.
    Material m;
    if (!a || name == AI_DEFAULT_MATERIAL_NAME || (ply_ && name.empty())) {
      m.name = "default";
    } else {
      m = to_material(*a, index, name);
    }
    MaterialId id;
    try {
      id = scene_.add_material(m);
    } catch (const Error& e) {
      fail(e.code(), "materials[" + std::to_string(index) + "]", e.what());
    }
    materials_.emplace(index, id);
    return id;
  }

  Material to_material(const aiMaterial& a, unsigned index, const std::string& name) {
    const std::string place = "materials[" + std::to_string(index) + "]" + (name.empty() ? "" : " " + in_quotes(name));
    auto colour = [&](const char* key, unsigned type, unsigned idx) -> std::optional<Rgb> {
      aiColor4D c;
      if (a.Get(key, type, idx, c) != AI_SUCCESS) return std::nullopt;
      return Rgb(c.r, c.g, c.b);
    };
    auto number = [&](const char* key, unsigned type, unsigned idx) -> std::optional<float> {
      ai_real v;
      if (a.Get(key, type, idx, v) != AI_SUCCESS || !std::isfinite(v)) return std::nullopt;
      return static_cast<float>(v);
    };
    Material m;
    m.name = name.empty() ? "material" + std::to_string(index) : name;

    // Base colour (PBR formats) or diffuse colour, times the mean of its texture.
    std::optional<Rgb> base = colour(AI_MATKEY_BASE_COLOR);
    if (!base) base = colour(AI_MATKEY_COLOR_DIFFUSE);
    Rgb rho = base.value_or(Rgb(0.5f));
    std::string what = "diffuse colour";
    if (const std::optional<Rgb> mean = texture_mean(a, place)) {
      rho *= *mean;
      what = "diffuse colour (times the mean of its texture)";
    }
    if (!std::isfinite(rho.x) || !std::isfinite(rho.y) || !std::isfinite(rho.z))
      fail(ErrorCode::parse_error, place, what + " is NaN or infinite");
    rho = clamp_colour(rho, kMaxForgivenAlbedo, 1.0f, warnings_, "material colour out of range", where(place), what,
                       "a diffuse reflectance (1 or more would create energy)", "in [0, 1)");

    // Emission: a radiance, as glTF's and MTL's (E = pi L).
    // An FBX material may hold only the computed "Emissive" (EmissiveColor x EmissiveFactor),
    // as Assimp's own FBX exporter writes it; Assimp's importer keeps that as a raw property.
    std::optional<Rgb> emitted = colour(AI_MATKEY_COLOR_EMISSIVE);
    if (!emitted) emitted = colour("$raw.Emissive", 0, 0);
    Rgb emissive = emitted.value_or(Rgb(0.0f));
    emissive *= number(AI_MATKEY_EMISSIVE_INTENSITY).value_or(1.0f);
    if (!std::isfinite(emissive.x) || !std::isfinite(emissive.y) || !std::isfinite(emissive.z))
      fail(ErrorCode::parse_error, place, "emissive colour is NaN or infinite");
    emissive = clamp_colour(emissive, FLT_MAX, FLT_MAX, warnings_, "material colour out of range", where(place),
                            "emissive colour", "an emitted radiance", ">= 0");
    m.emission = kPi * emissive;

    int two_sided = 0;
    if (a.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) m.two_sided = two_sided != 0;

    float ior = number(AI_MATKEY_REFRACTI).value_or(1.5f);
    if (!(ior > 0.0f)) ior = 1.5f;
    const float transmission = std::clamp(number(AI_MATKEY_TRANSMISSION_FACTOR).value_or(0.0f), 0.0f, 1.0f);
    const std::optional<float> metallic = number(AI_MATKEY_METALLIC_FACTOR), roughness = number(AI_MATKEY_ROUGHNESS_FACTOR);
    if (transmission > 0.0f) {
      set_transmission(m, rho, transmission, ior);
    } else if (metallic || roughness) {
      set_metallic_roughness(m, rho, std::clamp(metallic.value_or(0.0f), 0.0f, 1.0f),
                             std::clamp(roughness.value_or(0.5f), 0.0f, 1.0f), ior);
    } else {
      m.reflectance = rho;
      const float opacity = number(AI_MATKEY_OPACITY).value_or(1.0f);
      if (opacity < 0.0f || opacity > 1.0f)
        warnings_.forgive("material opacity out of range", ErrorCode::invalid_scene, where(place),
                          "opacity " + std::to_string(opacity) + " must be in [0, 1]", "clamped");
      if (std::clamp(opacity, 0.0f, 1.0f) < 1.0f) set_thin_pane(m, std::clamp(opacity, 0.0f, 1.0f), Rgb(1.0f));
    }
    return m;
  }

  fs::path path_;
  std::string name_;
  const aiScene& ai_;
  const LoadOptions& options_;
  ReaderWarnings warnings_;
  bool ply_;
  Scene scene_;
  std::map<unsigned, MaterialId> materials_;
  std::map<std::string, std::pair<std::optional<Rgb>, std::string>> textures_;
  bool skipped_ = false;
};

}  // namespace

bool assimp_reads(const std::string& extension) {
  const Assimp::Importer importer;
  return !extension.empty() && importer.IsExtensionSupported(extension);
}

std::string assimp_extensions() {
  const Assimp::Importer importer;
  std::string list;
  importer.GetExtensionList(list);  // "*.3ds;*.dae;..."
  std::string out;
  for (std::size_t at = 0; at < list.size();) {
    std::size_t end = list.find(';', at);
    if (end == std::string::npos) end = list.size();
    std::string ext = list.substr(at, end - at);
    if (ext.rfind("*", 0) == 0) ext.erase(0, 1);
    if (ext != ".obj" && ext != ".gltf" && ext != ".glb" && !ext.empty()) out += (out.empty() ? "" : " ") + ext;
    at = end + 1;
  }
  return out;
}

/// A file read with a line end after its last byte, for an ASCII PLY file that has none.
/// Assimp 5.2's line reader (IOStreamBuffer::getNextLine) returns at the end of the file
/// before it ends the line in its buffer, and that buffer still holds what longer lines before
/// left there: the PLY reader reads the last line on into them ("3 0 1 2" after "3 1 2 345" is
/// read as "3 0 1 245", and a count "3" after "34444444444 ..." as 34444444444, modulo 2^32).
class LineEndedStream : public Assimp::IOStream {
 public:
  explicit LineEndedStream(Assimp::IOStream* file) : file_(file), size_(file->FileSize() + 1) {}
  ~LineEndedStream() override { delete file_; }
  LineEndedStream(const LineEndedStream&) = delete;
  LineEndedStream& operator=(const LineEndedStream&) = delete;

  size_t Read(void* buffer, size_t size, size_t count) override {
    if (size == 0 || count == 0) return 0;
    char* out = static_cast<char*>(buffer);
    const size_t wanted = size * count;
    size_t got = 0;
    if (at_ + 1 < size_) {
      if (file_->Seek(at_, aiOrigin_SET) != aiReturn_SUCCESS) return 0;
      got = file_->Read(out, 1, std::min(wanted, size_ - 1 - at_));
      at_ += got;
    }
    if (got < wanted && at_ + 1 == size_) {
      out[got++] = '\n';
      ++at_;
    }
    return got / size;
  }
  size_t Write(const void*, size_t, size_t) override { return 0; }
  aiReturn Seek(size_t offset, aiOrigin origin) override {
    const size_t base = origin == aiOrigin_CUR ? at_ : origin == aiOrigin_END ? size_ : 0;
    if (origin == aiOrigin_END ? offset > size_ : offset > size_ - base) return aiReturn_FAILURE;
    at_ = origin == aiOrigin_END ? size_ - offset : base + offset;
    return aiReturn_SUCCESS;
  }
  size_t Tell() const override { return at_; }
  size_t FileSize() const override { return size_; }
  void Flush() override {}

 private:
  Assimp::IOStream* file_;  // owned
  size_t size_;             // the file's bytes and the line end
  size_t at_ = 0;
};

/// The files Assimp opens, each with a line end after its last byte (LineEndedStream).
class LineEndedFiles : public Assimp::DefaultIOSystem {
 public:
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    Assimp::IOStream* stream = DefaultIOSystem::Open(file, mode);
    return stream ? new LineEndedStream(stream) : nullptr;
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }
};

/// Whether a file's last byte is something else than a line end ('\r' or '\n').
bool ends_unended(const fs::path& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file || file.tellg() <= 0) return false;
  file.seekg(-1, std::ios::end);
  const int last = file.get();
  return last != '\n' && last != '\r';
}

Scene load_assimp(const fs::path& path, const LoadOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw Error(ErrorCode::file_not_found, "load_scene: cannot open model file '" + path.string() +
                                               (fs::exists(path, ec) ? "': not a regular file" : "': no such file"));
  bool add_line_end = false;
  if (lower_extension(path) == ".ply") {
    const PlyHeader header = read_ply_header(path);
    check_ply(path, header);
    add_line_end = !header.binary && ends_unended(path);
  }
  if (lower_extension(path) == ".dae") check_collada(path);
  if (lower_extension(path) == ".3ds") check_3ds_tracks(path);
  if (lower_extension(path) == ".fbx") check_fbx(path);
  Assimp::Importer importer;
  if (add_line_end) importer.SetIOHandler(new LineEndedFiles);  // the importer owns it
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_ValidateDataStructure);
  if (!scene) {
    // Assimp's validation names the mesh but not what the user has: a scan's point cloud
    // (vertices, no faces), an STL exported from an empty selection.
    const std::string what = importer.GetErrorString();
    const char* meaning = what.find("contains no faces") != std::string::npos
                              ? "it holds points but no faces (a point cloud?), and radiosity needs polygons"
                          : what.find("contains no vertices") != std::string::npos ? "it holds no geometry"
                                                                                   : nullptr;
    throw Error(ErrorCode::parse_error,
                path.string() + ": " + (meaning ? std::string(meaning) + " (Assimp: " + what + ")" : what));
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    throw Error(ErrorCode::parse_error, path.string() + ": holds no complete scene (" +
                                            std::string(scene->mNumMeshes == 0 ? "no meshes" : "an animation or skeleton only") + ")");
  AssimpReader(path, *scene, options).check();
  // Polygons to triangles, and the corners that the file repeats merged into shared vertices.
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (!scene) throw Error(ErrorCode::parse_error, path.string() + ": " + importer.GetErrorString());
  return AssimpReader(path, *scene, options).read();
}

}  // namespace radiosity::detail
