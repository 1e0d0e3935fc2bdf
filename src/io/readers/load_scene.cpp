// load_scene(): chooses a reader by the file's extension, so callers need not know formats: our
// own for OBJ, JSON, glTF and View3D, Assimp for every other format it reads.
#include <string>

#include "io/readers/reader_files.hpp"
#include "io/readers/readers.hpp"
#include "radiosity/io.hpp"

namespace radiosity {
inline namespace v1 {

Scene load_scene(const std::filesystem::path& path, const LoadOptions& options) {
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

}  // namespace v1
}  // namespace radiosity
