// What every scene reader does with its files: read one whole, with the same errors for a file
// that is missing or unreadable, and turn a byte offset into the "line:column" of a message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace radiosity::detail {

/// Little-endian integers from a binary file's bytes (GLB, 3DS, binary FBX), whatever the host's
/// byte order. The caller checks that the bytes are there.
inline std::uint16_t le16(const unsigned char* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
inline std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}
inline std::uint64_t le64(const unsigned char* p) { return std::uint64_t{le32(p)} | std::uint64_t{le32(p + 4)} << 32; }

/// The bytes of the file at `path`. Throws Error{file_not_found} "load_scene: cannot open
/// <what> '<path>': no such file" (or ": not a regular file"), or "cannot read" when reading
/// fails; `what` names the kind of file ("OBJ file", "glTF file").
std::string read_file(const std::filesystem::path& path, const char* what);

/// The extension of `path` in lower case, with its dot (".glb"), or empty: what the readers and
/// writers choose a format by.
std::string lower_extension(const std::filesystem::path& path);

/// `s` in single quotes, as messages name files, materials and nodes.
inline std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

/// "line:column" (both 1-based) of the byte at 0-based offset `pos` of `text`.
std::string line_column(std::string_view text, std::size_t pos);

}  // namespace radiosity::detail
