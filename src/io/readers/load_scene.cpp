// load_scene(): chooses a reader by the file's extension, so callers need not know formats: our
// own for OBJ, JSON, glTF and View3D, Assimp for every other format it reads. Then, whatever
// the format, it checks that single precision could hold the model where it lies.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "io/readers/reader_files.hpp"
#include "io/readers/readers.hpp"
#include "radiosity/io.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

Scene read_by_extension(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string ext = detail::lower_extension(path);
  if (ext == ".obj") return detail::load_obj(path, options);
  if (ext == ".json") return detail::load_scene_json(path, options);
  if (ext == ".gltf" || ext == ".glb") return detail::load_gltf(path, options);
  if (ext == ".vs3") return detail::load_view3d(path, options);
  if (detail::assimp_reads(ext)) return detail::load_assimp(path, options);
  const std::string supported = " (supported: .obj, .json, .gltf, .glb, .vs3, and through Assimp " + detail::assimp_extensions() + ")";
  if (ext.empty())
    throw Error(ErrorCode::invalid_argument, "load_scene: '" + path.string() + "' has no file extension" + supported);
  throw Error(ErrorCode::invalid_argument,
              "load_scene: '" + path.string() + "': unsupported extension '" + path.extension().string() + "'" + supported);
}

/// A model far from the origin for its size (georeferenced: a city in UTM coordinates, a
/// building at its site's national-grid position) cannot be held in single precision, which
/// Polygon stores: at 5.7e6 neighbouring floats are 0.5 apart, so a 2 m facet's corners move by
/// a quarter of it, faces bend, small ones collapse and are dropped as degenerate, and a solve
/// can fail deep in the mesher. Found with McGuire's Cornell box moved to UTM coordinates: its
/// light was dropped and the solve failed with "element 2161 is at the maximum depth". Warned
/// (an Error under strict) when the spacing of floats at the largest coordinate is 1 % or more
/// of the median polygon's size (the square root of its area). The readers that parse in double
/// (OBJ, glTF's node matrices, View3D) move such a model to a local origin first
/// (LoadOptions::local_origin, local_origin.hpp), so this is for Assimp's formats, or the
/// option off.
void check_precision(Scene& scene, const std::filesystem::path& path, bool strict) {
  const std::vector<Polygon>& polygons = scene.polygons();
  if (polygons.empty()) return;
  float reach = 0.0f;
  std::vector<float> size;
  size.reserve(polygons.size());
  for (const Polygon& p : polygons) {
    for (const glm::vec3& v : p.vertices) reach = std::max({reach, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
    size.push_back(std::sqrt(p.area));
  }
  const auto mid = size.begin() + static_cast<std::ptrdiff_t>(size.size() / 2);
  std::nth_element(size.begin(), mid, size.end());
  const float typical = *mid;
  const float spacing = std::nextafter(reach, 2.0f * reach + 1.0f) - reach;
  if (!(typical > 0.0f) || !(spacing >= 0.01f * typical)) return;
  char text[520];
  std::snprintf(text, sizeof text,
                "%s: coordinates reach %.7g while a typical polygon is %.3g across: single precision, in which "
                "polygons are stored, is %.3g apart there (%.0f %% of such a polygon), so corners moved, faces bent "
                "and small ones may have been dropped; move the model near the origin before exporting it (a local "
                "origin, or the modeller's 'apply transform' / 'set origin'), and keep the offset yourself (the OBJ, glTF "
                "and View3D readers do this themselves unless LoadOptions::local_origin is off)",
                path.filename().string().c_str(), static_cast<double>(reach), static_cast<double>(typical),
                static_cast<double>(spacing), 100.0 * static_cast<double>(spacing / typical));
  if (strict) throw Error(ErrorCode::parse_error, text);
  scene.add_warning(text);
}

}  // namespace

Scene load_scene(const std::filesystem::path& path, const LoadOptions& options) {
  Scene scene = read_by_extension(path, options);
  check_precision(scene, path, options.strict);
  return scene;
}

}  // namespace v1
}  // namespace radiosity
