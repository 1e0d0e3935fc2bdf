// Reads each file named on the command line as the fuzz targets do (load_scene(), read_exr() for
// .exr, load_measured() for .binary), catching what they throw, and names each file on stderr
// before reading it. Built with the tests (a Release build, no sanitizer) for
// valgrind_sweep.sh: valgrind's memcheck sees the reads and writes inside the libraries that
// AddressSanitizer does not instrument (Assimp, OpenEXR, tinygltf), which is how session 31
// found the heap overflow behind two fuzz runs' allocator stops (docs/FUZZING.md).
#include <cstdio>
#include <exception>
#include <filesystem>

#include <radiosity/radiosity.hpp>

int main(int argc, char** argv) {
  int refused = 0;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path path = argv[i];
    std::fprintf(stderr, "FILE %s\n", argv[i]);
    try {
      if (path.extension() == ".exr")
        (void)radiosity::read_exr(path);
      else if (path.extension() == ".binary")
        (void)radiosity::load_measured(path);
      else
        (void)radiosity::load_scene(path);
    } catch (const std::exception&) {
      ++refused;
    }
  }
  std::printf("%d files read, %d refused\n", argc - 1, refused);
  return 0;
}
