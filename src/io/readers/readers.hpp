// Scene readers behind load_scene(), one per file format. Internal: load_scene() picks one by
// the file's extension.
#pragma once

#include <filesystem>
#include <string>

#include "radiosity/io.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// Wavefront OBJ with its MTL libraries (see load_scene() in io.hpp for the mapping).
Scene load_obj(const std::filesystem::path& path, const LoadOptions& options);

/// The JSON scene format of docs/SCENE_JSON.md (reads the file, then parse_scene_json()).
Scene load_scene_json(const std::filesystem::path& path, const LoadOptions& options);

/// glTF 2.0, .gltf (embedded or external buffers) or .glb (docs/SCENE_GLTF.md).
Scene load_gltf(const std::filesystem::path& path, const LoadOptions& options);

/// NIST View3D vertex/surface files (.vs3): load_view3d()'s scene (docs/SCENE_VS3.md).
Scene load_view3d(const std::filesystem::path& path, const LoadOptions& options);

/// Every other format Assimp reads (FBX, COLLADA, 3DS, PLY, STL, ...; docs/SCENE_GLTF.md).
Scene load_assimp(const std::filesystem::path& path, const LoadOptions& options);

/// Whether Assimp reads files of `extension` (".fbx", lower case, with the dot).
bool assimp_reads(const std::string& extension);

/// The extensions load_assimp() reads, space-separated (".3ds .dae .fbx ..."), without those
/// that have a reader of their own.
std::string assimp_extensions();

}  // namespace radiosity::detail
