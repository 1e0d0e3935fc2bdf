// Text helpers shared by the View3D reader (readers/view3d_loader.cpp) and writer
// (writers/view3d_writer.cpp), so that what one writes the other reads back unchanged.
#pragma once

#include <cctype>
#include <charconv>
#include <string>
#include <string_view>
#include <system_error>

namespace radiosity::detail::view3d {

/// `s` in lower case (View3D compares control words without case).
inline std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// The fewest decimal digits that read back (as the nearest float) to exactly `x`: vertices
/// and emissivities survive save -> load bit for bit, and 0.5 stays "0.5".
inline std::string shortest(float x) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : std::string("0");
}

/// The same for a double: a vertex of a scene with a local origin (Scene::origin()), written in
/// the file's coordinates.
inline std::string shortest(double x) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : std::string("0");
}

/// Whether `c` would end or split a View3D word: blanks and commas separate words, '!' starts
/// a comment, '=' separates a control word from its value, a line break ends the line.
inline bool breaks_word(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == '!' || c == '=' || c == '\r' || c == '\n' || c == '\0';
}

}  // namespace radiosity::detail::view3d
