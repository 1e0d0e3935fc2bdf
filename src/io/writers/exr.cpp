// OpenEXR reading and writing of Image: linear float RGB in channels R, G, B and each layer NAME
// in NAME.R, NAME.G, NAME.B (the layer naming of OpenEXR's Technical Introduction, which
// compositors and viewers understand). FLOAT channels keep the solver's values bit-exact;
// OpenEXR's exceptions become radiosity::Error naming the path.
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "io/writers/image_checks.hpp"
#include "radiosity/io.hpp"
#include "radiosity/version.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

constexpr const char* kChannels[3] = {"R", "G", "B"};

/// Inserts the three FLOAT slices of an RGB buffer (glm::vec3 is three packed floats) named
/// prefix + R/G/B.
void insert_rgb(Imf::FrameBuffer& fb, const std::string& prefix, const Rgb* pixels, int width,
                const Imath::Box2i& window) {
  const std::size_t x_stride = sizeof(Rgb);
  const std::size_t y_stride = sizeof(Rgb) * static_cast<std::size_t>(width);
  for (int c = 0; c < 3; ++c)
    fb.insert(prefix + kChannels[c],
              Imf::Slice::Make(Imf::FLOAT, reinterpret_cast<const float*>(pixels) + c, window, x_stride, y_stride));
}

void check_image(const Image& image, const std::filesystem::path& path) {
  const std::string where = "write_exr: '" + path.string() + "': ";
  detail::check_image_size(image, where);
  const std::size_t n = image.pixels.size();
  std::set<std::string> names;
  for (const auto& [name, values] : image.layers) {
    if (name.empty()) throw Error(ErrorCode::invalid_argument, where + "a layer has an empty name");
    if (!names.insert(name).second)
      throw Error(ErrorCode::invalid_argument, where + "layer '" + name + "' appears twice");
    if (values.size() != n)
      throw Error(ErrorCode::invalid_argument, where + "layer '" + name + "' has " + std::to_string(values.size()) +
                                                   " pixels, width x height = " + std::to_string(n));
  }
}

/// The most a compression can shrink pixel data (raw bytes over stored bytes), with room to
/// spare: zlib's deflate at best about 1032 : 1 (ZIP, ZIPS, PXR24 after its rounding), PIZ's
/// Huffman runs (at most 255 repeats of a 16-bit symbol per code) about 450 : 1, RLE 64 : 1
/// (128 bytes in 2), B44 32 : 3 (a flat 4 x 4 block of halves); DWAA/DWAB compress each 8 x 8
/// block's coefficients with run lengths and then zlib, so a flat image can reach some
/// 30 000 : 1, and a compression this reader does not know gets the same. It takes the
/// compression as the file's byte gives it, an int: a value outside Imf::Compression's
/// enumerators is no Imf::Compression (casting it is undefined; found by the fuzz target).
double max_compression_ratio(int compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION: return 1.0;
    case Imf::RLE_COMPRESSION: return 128.0;
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION: return 64.0;
    case Imf::ZIPS_COMPRESSION:
    case Imf::ZIP_COMPRESSION:
    case Imf::PIZ_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 4096.0;
    default: return 1e5;
  }
}

/// How many scan lines OpenEXR 3.1 decodes at a time for a compression (ImfCompression.h's
/// getCompressionNumScanlines): it allocates its line buffers for that many lines of the widest
/// line, whatever the window's height. 1 for a value it does not know (it refuses those).
int lines_per_chunk(int compression) {
  switch (compression) {
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION: return 32;
    case Imf::DWAB_COMPRESSION: return 256;
    default: return 1;
  }
}

/// What check_exr_header() reads of a header for check_exr_pixels(). A header without a
/// dataWindow or compression attribute gets OpenEXR's defaults (Imf::Header(): 64 x 64, ZIP).
struct ExrLayout {
  std::int32_t min_x = 0, min_y = 0, max_x = 63, max_y = 63;  ///< dataWindow
  int compression = Imf::ZIP_COMPRESSION;
  std::uint32_t tile_x = 0, tile_y = 0;                      ///< a tiled file's tile size, else 0
  struct Channel {
    std::int32_t type = 0, x_sampling = 1, y_sampling = 1;
  };
  std::vector<Channel> channels;
};

/// Refuses, before OpenEXR or read_exr() allocates for them, a data window whose pixels the file
/// cannot hold at its compression's best ratio (a 48 KB file that declared 20 000 x 20 000 pixels
/// made read_exr() ask for 4.8 GB), and one whose buffers in OpenEXR (a block of lines of the
/// widest line, or a tile, of every channel) pass 256 MiB and what the file could hold (a
/// few-KB fuzzed file with a window 18 million pixels wide and 1 high made OpenEXR's InputFile
/// allocate three line buffers of 1.1 GB each, 16 lines of ZIP at a time, before reading a
/// pixel; session 30).
void check_exr_pixels(const std::filesystem::path& path, std::uintmax_t size, const ExrLayout& layout) {
  if (layout.channels.empty()) return;  // read_exr() refuses it
  const double w = static_cast<double>(layout.max_x) - layout.min_x + 1.0;
  const double h = static_cast<double>(layout.max_y) - layout.min_y + 1.0;
  if (w <= 0.0 || h <= 0.0) return;  // read_exr() refuses it
  // Per pixel over the window (subsampled channels count their share), per line at its widest,
  // and per full-resolution pixel of every channel.
  double bytes_per_pixel = 0.0, line_bytes = 0.0, pixel_bytes = 0.0;
  for (const ExrLayout::Channel& c : layout.channels) {
    const double bytes = c.type == Imf::HALF ? 2.0 : 4.0;
    const double xs = std::max(c.x_sampling, 1), ys = std::max(c.y_sampling, 1);
    bytes_per_pixel += bytes / (xs * ys);
    line_bytes += std::ceil(w / xs) * bytes;
    pixel_bytes += bytes;
  }
  const int lines = lines_per_chunk(layout.compression);
  // A tiled file's buffers hold a tile of every channel (OpenEXR's TiledInputFile).
  const double tile_bytes = static_cast<double>(layout.tile_x) * layout.tile_y * pixel_bytes;
  const double window_bytes = w * h * bytes_per_pixel, buffer_bytes = std::max(line_bytes * lines, tile_bytes);
  const double ratio = max_compression_ratio(layout.compression);
  const double most = static_cast<double>(size) * ratio;
  const std::string at_best = "a file of " + std::to_string(size) + " bytes, even at its compression's best ratio (" +
                              std::to_string(static_cast<long long>(ratio)) + " : 1)";
  char figures[200];
  if (window_bytes > most) {
    std::snprintf(figures, sizeof figures, "%.0f x %.0f data window (%.4g bytes of pixels)", w, h, window_bytes);
    throw Error(ErrorCode::parse_error, "read_exr: '" + path.string() + "': its " + figures + " cannot be in " +
                                            at_best + ": a corrupted header");
  }
  // The buffers may exceed what the file holds when the window is lower than a block of lines;
  // that is refused only beyond kBufferFloor (a 20 000 x 1 strip of 883 bytes reads).
  constexpr double kBufferFloor = 256.0 * 1024.0 * 1024.0;
  if (buffer_bytes > std::max(most, kBufferFloor)) {
    const std::string how = tile_bytes > line_bytes * lines
                                ? "tiles of " + std::to_string(layout.tile_x) + " x " + std::to_string(layout.tile_y)
                                : std::to_string(lines) + " lines at a time";
    std::snprintf(figures, sizeof figures, "%.0f x %.0f data window has OpenEXR allocate %.4g bytes of buffers", w, h,
                  buffer_bytes);
    throw Error(ErrorCode::parse_error, "read_exr: '" + path.string() + "': its " + figures + " (" + how +
                                            "), more than 256 MiB and more than its pixels could take in " + at_best +
                                            ": a corrupted header");
  }
}

/// How many value bytes OpenEXR 3.1's reader takes for an attribute of a type it knows with a
/// fixed-size value (ImfTypedAttribute's readers read the value and ignore the declared size),
/// or -1 for a type whose value it reads otherwise.
int fixed_value_bytes(const std::string& type) {
  static const std::pair<const char*, int> kFixed[] = {
      {"box2i", 16},  {"box2f", 16},          {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8},  {"envmap", 1},          {"float", 4},           {"int", 4},         {"keycode", 28},
      {"lineOrder", 1}, {"m33d", 72},         {"m33f", 36},           {"m44d", 128},      {"m44f", 64},
      {"rational", 8}, {"tiledesc", 9},       {"timecode", 8},        {"v2d", 16},        {"v2f", 8},
      {"v2i", 8},     {"v3d", 24},            {"v3f", 12},            {"v3i", 12}};
  for (const auto& [name, bytes] : kFixed)
    if (type == name) return bytes;
  return -1;
}

/// OpenEXR 3.1 allocates memory for a header attribute from counts in the file before it reads
/// the bytes they count, so a few corrupt bytes can make it ask for gigabytes (found by the
/// fuzz target: a 115-byte file cost a 1.7 GB request and 2.6 s under AddressSanitizer). This
/// walks the header (or a multi-part file's headers) as OpenEXR's reader does: per attribute a
/// name, a type name, a 32-bit little-endian size and the value, where the value's length is
/// what that reader takes, not always the declared size: a channel list runs to its empty
/// name, a known fixed-size type takes its fixed size, a preview its 8 + 4 x width x height
/// bytes, a string vector's strings their own lengths; anything else the declared size. A
/// length beyond the end of the file is refused here, naming the attribute and both figures.
/// Anything else that is wrong is left for OpenEXR to report.
void check_exr_header(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  unsigned char start[8];
  if (ec || !in.read(reinterpret_cast<char*>(start), 8)) return;
  std::int64_t pos = 8;  // where `in` is
  if (!(start[0] == 0x76 && start[1] == 0x2f && start[2] == 0x31 && start[3] == 0x01)) return;
  const bool multipart = (start[5] & 0x10) != 0;  // version flags, bit 12
  // A name or type name: at most 255 characters and a NUL. False when the file ends first.
  auto read_name = [&](std::string& out) {
    out.clear();
    for (char c; in.get(c);) {
      ++pos;
      if (c == '\0') return true;
      if (out.size() == 255) return false;
      out += c;
    }
    return false;
  };
  // A 32-bit little-endian integer; false when the file ends first.
  auto read_u32 = [&](std::uint32_t& out) {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    pos += 4;
    out = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
          static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
    return true;
  };
  auto left = [&] { return static_cast<std::int64_t>(size) - pos; };
  // Skips n bytes: ignore() reads on through the stream's buffer, where a seek would drop it
  // (and asking for the position would ask the system): a seek per attribute was most of the
  // fuzz target's time.
  auto skip = [&](std::int64_t n) {
    in.ignore(static_cast<std::streamsize>(n));
    pos += n;
  };
  std::string name, type, channel;
  ExrLayout layout;
  auto read_i32 = [&](std::int32_t& out) {
    std::uint32_t u = 0;
    if (!read_u32(u)) return false;
    out = static_cast<std::int32_t>(u);
    return true;
  };
  auto refuse = [&](const char* verb, std::int64_t bytes, std::int64_t remaining) {
    throw Error(ErrorCode::parse_error, "read_exr: '" + path.string() + "': header attribute '" + name + "' (" + type +
                                            ") " + verb + " " + std::to_string(bytes) + " bytes, but " +
                                            std::to_string(remaining) + " remain in the file");
  };
  for (;;) {
    bool any = false;
    while (read_name(name) && !name.empty()) {
      any = true;
      std::uint32_t raw = 0;
      if (!read_name(type) || !read_u32(raw)) return;
      const std::int64_t declared = static_cast<std::int32_t>(raw);
      if (declared < 0 || declared > left()) refuse("declares", declared, left());
      const int fixed = fixed_value_bytes(type);
      if (type == "chlist") {
        // Channels to an empty name, each a name and 16 bytes, whatever the declared size.
        // The "channels" list's types and samplings are kept for check_exr_pixels().
        for (;;) {
          if (!read_name(channel)) return;
          if (channel.empty()) break;
          ExrLayout::Channel c;
          if (!read_i32(c.type)) return;
          skip(4);  // pLinear and 3 reserved bytes
          if (!read_i32(c.x_sampling) || !read_i32(c.y_sampling)) return;
          if (name == "channels") layout.channels.push_back(c);
        }
      } else if (name == "dataWindow" && type == "box2i") {
        if (!read_i32(layout.min_x) || !read_i32(layout.min_y) || !read_i32(layout.max_x) || !read_i32(layout.max_y))
          return;
      } else if (name == "tiles" && type == "tiledesc") {
        if (!read_u32(layout.tile_x) || !read_u32(layout.tile_y)) return;
        skip(1);  // the level and rounding modes
      } else if (name == "compression" && type == "compression") {
        char c = 0;
        if (!in.get(c)) return;
        ++pos;
        layout.compression = static_cast<unsigned char>(c);
      } else if (fixed >= 0) {
        if (fixed > left()) return;  // OpenEXR reports the file's end
        skip(fixed);
      } else if (type == "preview") {
        std::uint32_t width = 0, height = 0;
        if (!read_u32(width) || !read_u32(height)) return;
        const double pixels_bytes = 4.0 * width * height;  // up to 2^66: in a double, not an int64
        if (pixels_bytes > static_cast<double>(left()))
          refuse("needs", 8 + static_cast<std::int64_t>(std::min(pixels_bytes, 1e18)), left() + 8);
        skip(static_cast<std::int64_t>(pixels_bytes));
      } else if (type == "stringvector") {
        // Strings, each a 32-bit length and its bytes, until the declared size is read.
        for (std::int64_t read = 0; read < declared;) {
          std::uint32_t length_raw = 0;
          if (!read_u32(length_raw)) return;
          const std::int64_t length = static_cast<std::int32_t>(length_raw);
          if (length < 0 || length > left()) refuse("has a string of", length, left());
          skip(length);
          read += 4 + length;
        }
      } else if (type == "floatvector") {
        skip(declared / 4 * 4);
      } else {
        skip(declared);
      }
    }
    if (!in) return;
    check_exr_pixels(path, size, layout);  // each part's header: its own window and channels
    if (!multipart || !any) return;
    layout = ExrLayout{};
  }
}

}  // namespace

void write_exr(const Image& image, const std::filesystem::path& path) {
  check_image(image, path);
  try {
    Imf::Header header(image.width, image.height);
    header.insert("software", Imf::StringAttribute(std::string("radiosity ") + version()));
    for (const char* c : kChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    for (const auto& layer : image.layers)
      for (const char* c : kChannels) header.channels().insert(layer.first + "." + c, Imf::Channel(Imf::FLOAT));

    Imf::FrameBuffer fb;
    const Imath::Box2i& window = header.dataWindow();
    insert_rgb(fb, "", image.pixels.data(), image.width, window);
    for (const auto& layer : image.layers) insert_rgb(fb, layer.first + ".", layer.second.data(), image.width, window);

    Imf::OutputFile file(path.string().c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error(ErrorCode::io_error, "write_exr: cannot write '" + path.string() + "': " + e.what());
  }
}

Image read_exr(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error(ErrorCode::file_not_found, "read_exr: cannot open '" + path.string() + "': no such file");
  check_exr_header(path);
  try {
    Imf::InputFile file(path.string().c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const Imf::ChannelList& channels = header.channels();

    if (!channels.findChannel("R") && !channels.findChannel("G") && !channels.findChannel("B")) {
      std::string found;
      for (auto it = channels.begin(); it != channels.end(); ++it) found += std::string(found.empty() ? "" : ", ") + it.name();
      throw Error(ErrorCode::parse_error, "read_exr: '" + path.string() + "' has no R, G or B channel (channels: " +
                                              (found.empty() ? "none" : found) + ")");
    }

    // The same check on the header as OpenEXR read it, before the image is allocated: should
    // the walk above have read another header than OpenEXR (as it once did, session 29), the
    // image at least is not allocated for pixels the file cannot hold.
    ExrLayout read;
    read.min_x = window.min.x, read.min_y = window.min.y, read.max_x = window.max.x, read.max_y = window.max.y;
    read.compression = static_cast<int>(header.compression());
    for (auto it = channels.begin(); it != channels.end(); ++it)
      read.channels.push_back({it.channel().type, it.channel().xSampling, it.channel().ySampling});
    std::error_code size_error;
    const std::uintmax_t size = std::filesystem::file_size(path, size_error);
    if (!size_error) check_exr_pixels(path, size, read);

    const long long w = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long h = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (w <= 0 || h <= 0 || w * h > (1ll << 31))
      throw Error(ErrorCode::parse_error, "read_exr: '" + path.string() + "': unusable data window " +
                                              std::to_string(w) + " x " + std::to_string(h));
    Image image(static_cast<int>(w), static_cast<int>(h));

    // Layers: every prefix P of a channel P.R, P.G or P.B (OpenEXR sorts them by name).
    std::set<std::string> layer_names;
    channels.layers(layer_names);
    for (const std::string& name : layer_names) {
      bool has_rgb = false;
      for (const char* c : kChannels) has_rgb = has_rgb || channels.findChannel(name + "." + c) != nullptr;
      if (has_rgb) image.layers.emplace_back(name, std::vector<Rgb>(image.pixels.size(), Rgb(0.0f)));
    }

    // Channels absent from the file are left out of the frame buffer, so they stay 0.
    Imf::FrameBuffer fb;
    auto insert_present = [&](const std::string& prefix, Rgb* pixels) {
      for (int c = 0; c < 3; ++c) {
        const std::string name = prefix + kChannels[c];
        if (!channels.findChannel(name)) continue;
        fb.insert(name, Imf::Slice::Make(Imf::FLOAT, reinterpret_cast<float*>(pixels) + c, window, sizeof(Rgb),
                                         sizeof(Rgb) * static_cast<std::size_t>(w)));
      }
    };
    insert_present("", image.pixels.data());
    for (auto& layer : image.layers) insert_present(layer.first + ".", layer.second.data());
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(ErrorCode::parse_error, "read_exr: cannot read '" + path.string() + "': " + e.what());
  }
}

}  // namespace v1
}  // namespace radiosity
