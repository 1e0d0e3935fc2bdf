// A libFuzzer target for one of the library's readers (issue #17), compiled once per format
// with RADIOSITY_FUZZ_FORMAT set to its name (tests/fuzz/CMakeLists.txt). Each input is written
// to a file of this process's own temporary folder and read through the public call a user
// makes (load_scene(), read_exr(), load_measured()), so the fuzzer exercises exactly what a
// broken file does to a program.
//
// The contract checked: whatever the bytes, the reader returns or throws radiosity::Error (or
// std::bad_alloc). Any other exception escapes this function, and libFuzzer reports it as a
// crash, as it does every sanitizer finding (memory error, undefined behaviour, leak) and every
// input slower than -timeout. A scene that loads is also checked: its polygons have finite corners and
// a positive area, since a reader that lets NaN through gives a silently wrong answer later.
//
// Formats: obj (an OBJ, then optionally a line "#%%MTL%%" and the text of the MTL library that
// `mtllib fuzz.mtl` names), json, gltf, glb, vs3, ply, stl, dae, fbx and 3ds (Assimp's readers
// behind load_scene()), exr (read_exr()), merl (load_measured()). Seeds and the runs:
// run_fuzzers.sh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <string_view>

#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"
#include "radiosity/scene.hpp"

#ifndef RADIOSITY_FUZZ_FORMAT
#error "RADIOSITY_FUZZ_FORMAT must name the format (obj, json, gltf, glb, vs3, ply, stl, dae, fbx, 3ds, exr, merl)"
#endif

namespace {

namespace fs = std::filesystem;
using namespace std::string_view_literals;

constexpr std::string_view kFormat = RADIOSITY_FUZZ_FORMAT;
/// Separates an OBJ input's own text from its MTL library's.
constexpr std::string_view kMtlSeparator = "#%%MTL%%";

fs::path& work_dir() {
  static fs::path dir;
  return dir;
}

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz_reader: cannot write %s\n", path.c_str());
    std::abort();
  }
}

/// A loaded scene must hold only finite corners and polygons of positive finite area (Scene
/// validates on entry; this checks that no reader gets around it).
void check_scene(const radiosity::Scene& scene) {
  for (const radiosity::Polygon& p : scene.polygons()) {
    for (const glm::vec3& v : p.vertices)
      if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))) {
        std::fprintf(stderr, "fuzz_reader: a loaded scene has a non-finite corner\n");
        std::abort();
      }
    if (!(p.area > 0.0f && std::isfinite(p.area))) {
      std::fprintf(stderr, "fuzz_reader: a loaded scene has a polygon of area %g\n", static_cast<double>(p.area));
      std::abort();
    }
  }
}

// True when a "segments" key is followed by a number above 96, or one with a fraction or an
// exponent.
bool many_segments(std::string_view bytes) {
  for (std::size_t at = bytes.find("segments"); at != std::string_view::npos; at = bytes.find("segments", at + 1)) {
    std::size_t k = at + 8;
    while (k < bytes.size() && (bytes[k] == '"' || bytes[k] == ' ' || bytes[k] == ':' || bytes[k] == '\t')) ++k;
    double value = 0.0;
    bool digits = false;
    for (; k < bytes.size() && bytes[k] >= '0' && bytes[k] <= '9'; ++k) {
      value = 10.0 * value + (bytes[k] - '0');
      digits = true;
    }
    if (digits && value > 96.0) return true;
    // 1e3, 96.5e1: read as numbers by JSON; skipped whatever their value.
    if (digits && k < bytes.size() && (bytes[k] == 'e' || bytes[k] == 'E' || bytes[k] == '.')) return true;
  }
  return false;
}

void read_input(std::string_view bytes) {
  const fs::path& dir = work_dir();
  if (kFormat == "exr"sv) {
    const fs::path path = dir / "fuzz.exr";
    write_file(path, bytes);
    (void)radiosity::read_exr(path);
    return;
  }
  if (kFormat == "merl"sv) {
    const fs::path path = dir / "fuzz.binary";
    write_file(path, bytes);
    (void)radiosity::load_measured(path);
    return;
  }
  if (kFormat == "json"sv) {
    // A sphere of up to 1024 segments is valid and makes half a million polygons, which takes
    // longer than the 10 s limit under ASan: a slow input, not a finding (the first 10M run
    // stopped at "segments": 428 after 5.8M inputs). Such inputs are skipped; large spheres are
    // tested in tests/scene.
    if (many_segments(bytes)) return;
    check_scene(radiosity::parse_scene_json(bytes, dir, "fuzz.json"));
    return;
  }
  std::string_view scene_bytes = bytes;
  if (kFormat == "obj"sv) {
    const std::size_t split = bytes.find(kMtlSeparator);
    if (split != std::string_view::npos) {
      scene_bytes = bytes.substr(0, split);
      write_file(dir / "fuzz.mtl", bytes.substr(split + kMtlSeparator.size()));
    } else {
      fs::remove(dir / "fuzz.mtl");
    }
  }
  const fs::path path = dir / ("fuzz." + std::string(kFormat));
  write_file(path, scene_bytes);
  check_scene(radiosity::load_scene(path));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One folder per process, so parallel fuzzing jobs do not share files.
  std::string pattern = (fs::temp_directory_path() / "radiosity-fuzz-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    std::perror("fuzz_reader: mkdtemp");
    std::abort();
  }
  work_dir() = pattern;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    read_input(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const radiosity::Error&) {
    // The contract: a broken file is an Error naming it.
  } catch (const std::bad_alloc&) {
    // Allowed by the contract (a file may ask for more than the machine has).
  }
  return 0;
}
