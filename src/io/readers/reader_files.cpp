// File helpers of the scene readers (reader_files.hpp).
#include "io/readers/reader_files.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <system_error>

#include "radiosity/common.hpp"

namespace radiosity::detail {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path, const char* what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw Error(ErrorCode::file_not_found,
                std::string("load_scene: cannot open ") + what + " '" + path.string() +
                    (fs::exists(path, ec) ? "': not a regular file" : "': no such file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::file_not_found, std::string("load_scene: cannot open ") + what + " '" + path.string() + "'");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::file_not_found, std::string("load_scene: cannot read ") + what + " '" + path.string() + "'");
  return bytes.str();
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string line_column(std::string_view text, std::size_t pos) {
  pos = std::min(pos, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return std::to_string(line) + ":" + std::to_string(pos - line_start + 1);
}

}  // namespace radiosity::detail
