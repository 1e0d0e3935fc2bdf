// Readers and writers. This is the only part of the library that knows file formats; none of
// their libraries appear in public headers.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace radiosity {
inline namespace v1 {

/// Loads a scene, choosing the reader by extension: .obj with its .mtl files, .json, .gltf and
/// .glb, .vs3 (NIST View3D), and the formats of Assimp.
/// OBJ: `o`/`g` names become groups, `Kd` the diffuse reflectance, `Ke` emitted radiance (so
/// E = pi * Ke); without materials everything is grey 0.5. MTL `illum` modes map as the format
/// means them (docs/SCENE_OBJ.md has the table): 0/1 diffuse; 2 (or none, with Ks) Phong from
/// Ks and Ns; 3/5/8 an ideal mirror of reflectance Ks; 4/6/7/9 a smooth dielectric of index Ni
/// (1.5 when absent) transmitting Tf (white when absent), with Fresnel's reflection tinted by
/// Ks and no other lobe; `d` < 1 (or `Tr` > 0) a straight window (ior 1) transmitting 1 - d;
/// `Pr`/`Pm` (the PBR extension) a GGX microfacet coat over a diffuse base for the view pass.
/// Malformed input that cannot mean anything is an Error naming file, line and problem: a
/// missing OBJ file, a bad or out-of-range index, a NaN/infinite coordinate, a number that is
/// not one, an OBJ without faces. What a renderer would step over is fixed with a warning (or
/// an Error under `options.strict`): see LoadOptions. Warnings start with "file:line: ".
/// JSON (.json): the scene format of docs/SCENE_JSON.md (materials with any model of brdf.hpp,
/// polygons, quads, boxes, spheres, OBJ includes, a camera); see parse_scene_json().
/// glTF 2.0 (.gltf with embedded or external buffers, .glb; docs/SCENE_GLTF.md): each mesh
/// primitive placed by its node's world matrix becomes one Scene mesh (Scene::add_mesh(),
/// TEXCOORD_0/1 as uv0/uv1), grouped by node name (else mesh name, else "mesh<N>"); the first
/// perspective camera of the default scene becomes the scene's; materials map physically:
/// baseColorFactor (times the mean of its texture) the diffuse reflectance, emissiveFactor x
/// KHR_materials_emissive_strength the emitted radiance (E = pi L), metallic-roughness the
/// GGX model of the view pass, KHR_materials_transmission (with KHR_materials_ior) a
/// dielectric, doubleSided Material::two_sided. Errors name the file and the place in the
/// document ("scene.glb: meshes[2].primitives[0]: accessor 7 (POSITION): ..."): Error{parse_error}
/// for a broken container, JSON, reference, accessor or index, NaN values, an unsupported
/// required extension (Draco, meshopt); Error{file_not_found} for a missing external buffer.
/// Every other extension Assimp reads (FBX, COLLADA, 3DS, PLY, STL, ...): its scene graph and
/// materials read the same way, where the format carries them.
/// NIST View3D (.vs3): load_view3d()'s scene (its control line and title are dropped).
/// Whatever the format, a model too far from the origin for its size to be held in single
/// precision (floats 1 % of its median polygon's size apart or more at its largest coordinate: a
/// city at its UTM position) gets a warning with the figures (Error{parse_error} under strict).
/// Throws Error{invalid_argument} for an unsupported extension, and only radiosity::Error (or
/// std::bad_alloc) whatever the file holds.
/// Thread safety: may be called concurrently.
RADIOSITY_API Scene load_scene(const std::filesystem::path& path, const LoadOptions& options = {});

/// Reads a scene in the JSON format of docs/SCENE_JSON.md from `text`. Relative file names in
/// it (OBJ includes, measured BRDFs) are resolved against `base_dir`; `source_name` starts every
/// message (load_scene() passes the file's path). Every error names the value's place in the
/// document, e.g. "scene.json: materials[2].brdf.alpha_x: must be > 0 (got -0.1)":
/// Error{parse_error} for broken JSON ("scene.json:3:14: JSON syntax error: ..."), an unknown
/// key, a wrong type, a missing field, an unknown material name or format version;
/// Error{invalid_scene} for a value out of range or unusable geometry; the reader's own error
/// (with the place in front) for a missing or broken OBJ or measured-BRDF file.
/// Forgiving as LoadOptions says: a degenerate polygon is dropped, a reflectance of 1 or more
/// clamped to 0.99 (and reflectance + specular + diffuse_transmittance scaled below 1), each
/// with a warning naming its place; under `options.strict` these are errors too. OBJ includes
/// are read with the same options.
/// Thread safety: may be called concurrently.
RADIOSITY_API Scene parse_scene_json(std::string_view text, const std::filesystem::path& base_dir = {},
                                     std::string_view source_name = "<string>", const LoadOptions& options = {});

/// The control line (`C name=value ...`) of a NIST View3D vertex/surface file: View3D's run
/// settings, under View3D's names in the comments. The library computes nothing from them;
/// load_view3d() reads them so that save_view3d() writes them back and the View3D output
/// writer (tools/radiosity/view3d_format.hpp) fills its header. A field the line does not set
/// keeps View3D 3.2's default, given here. docs/SCENE_VS3.md has the format.
/// Thread safety: a plain value.
struct View3DControl {
  /// encl: the surfaces form a closed enclosure (View3D then adjusts each row to sum to 1).
  bool enclosure = false;
  /// emit: View3D's output holds Hottel's script-F (exchange factors of grey surfaces of the
  /// files' emissivities) instead of black-body view factors.
  bool script_f = false;
  /// out: the output file's format: 0 text, 1 binary (32-bit floats), 2 the sparse format of
  /// uDALES' View3D fork. In [0, 2].
  int output_format = 0;
  /// eps: convergence criterion of View3D's adaptive integration (View3D warns outside
  /// [1e-6, 1e-2]). Finite and > 0.
  float epsilon = 1e-4f;
  int max_unobstructed_recursions = 12;  ///< maxU: recursion limit of unobstructed factors, >= 4
  int max_obstructed_recursions = 8;     ///< maxO: recursion limit of obstructed factors, >= 4
  int min_obstructed_recursions = 0;     ///< minO: recursions always made for obstructed factors, >= 0
  /// row: compute only this row (a 1-based surface number; 0 = every row). At most the
  /// radiating surfaces.
  int row = 0;
  /// col: with `row`, compute only this factor (1-based; 0 = the whole row). Needs row > 0.
  int column = 0;
  int list = 0;                      ///< list: detail of View3D's log file, 0 (least) to 3
  bool reverse_projections = false;  ///< prjD: View3D's projection test in reverse (written only when true)
  /// Words View3D 3.2 does not know (later versions' and forks' maxV, maxD, ...), as written,
  /// name and value, in order of first appearance (a repeated name keeps its last value);
  /// written back after the others. Neither may be empty or hold a blank, ',', '=' or '!'.
  std::vector<std::pair<std::string, std::string>> other;
};

/// What load_view3d() reads from a View3D file. Thread safety: a plain value.
struct View3DFile {
  /// One polygon per surface, in the file's surface order, so PolygonId = surface number - 1
  /// (radiating surfaces first, then obstruction-only ones, as View3D numbers them).
  Scene scene;
  View3DControl control;  ///< the control line(s)
  std::string title;      ///< the last `T` line's text, blanks trimmed ("" when there is none)
};

/// Reads a NIST View3D 3-D vertex/surface file (.vs3, "F 3" geometry; G. Walton, NISTIR 6925,
/// 2002; docs/SCENE_VS3.md). Each surface becomes one polygon, in surface order
/// (PolygonId = surface number - 1), counter-clockwise seen from its radiating side as in the
/// file, coordinates in the file's units (areas in those units squared). Its group is its
/// name ("s<N>" for surface N without one, with a warning), or, for a surface combined with
/// another (cmbn > 0), that surface's name, so that group-level view factors are View3D's
/// combined rows. Its material is grey and diffuse, reflectance 1 - emissivity, one material
/// (named "emissivity <e>") per distinct emissivity; obstruction-only surfaces (`O`) get
/// Scene::set_obstruction_only() and emissivity 1 unless their line gives one in the `S` layout.
/// Errors name file and line (Error{parse_error} for syntax, Error{invalid_scene} for geometry):
/// a number that is not one, a vertex or surface numbered out of sequence, a radiating surface
/// after an obstruction surface, a vertex index out of range, a bad base or combine number, a
/// surface that is not one convex planar polygon (degenerate, non-planar or non-convex: split
/// it into triangles), mask (`M`) and null (`N`) surfaces, 2-D ("F 2") and BLAST ("F 3a")
/// geometry, a bad control value (out outside [0, 2], col without row, row beyond the
/// surfaces), no surface at all; Error{file_not_found} for a missing file. Forgiven with one
/// warning per kind (an Error under options.strict): an emissivity outside (0, 1] (clamped to
/// 0.01 or 1), a surface without a name, a subsurface (base > 0: View3D subtracts it from its
/// base, here both are whole polygons), maxU/maxO below 4, minO, row or col below 0 (clamped as
/// View3D does), an unknown line. Notes (warnings even under strict): an unknown control word
/// (kept in View3DControl::other), an `X` transformation line (ignored, as View3D 3.2 does), no
/// end-of-data line (`E` or `*`). Throws only radiosity::Error (or std::bad_alloc).
/// Thread safety: may be called concurrently.
RADIOSITY_API View3DFile load_view3d(const std::filesystem::path& path, const LoadOptions& options = {});

/// Writes `scene` as a View3D 3-D vertex/surface file that View3D and load_view3d() read:
/// `T title` (line breaks in it become blanks), the control line with every field of
/// `control`, "F 3", the corners of all polygons as vertices (bit-identical positions shared,
/// each written with the fewest digits that read back to the same float), then one surface per
/// polygon in polygon order, radiating polygons first and obstruction-only ones (`O`) after, so
/// surface number = PolygonId + 1 whenever the obstruction-only polygons come last (always so
/// for a scene load_view3d() read). A polygon of more than 4 corners is split into a fan of
/// convex quadrilaterals (and a triangle) from its first corner, the later pieces combined
/// with the first (cmbn), which View3D reports as one surface; load_view3d() reads them back
/// as that many polygons of one group. Emissivity = 1 - the mean of the material's diffuse
/// reflectance (emission, colour and specular parts are not written); the name is the group's,
/// with blanks, ',' and '!' made '_' (View3D names are one word). Base and cmbn are otherwise 0.
/// load -> save -> load gives the same polygons, order, groups, obstruction flags, emissivities
/// (to float rounding), title and control.
/// Throws Error{invalid_argument} for a scene without radiating polygons or a control value
/// that load_view3d() would not read back as written (see View3DControl's ranges; row and
/// col at most the radiating surfaces written), Error{io_error} naming the path when the file
/// cannot be written. Thread safety: may be called concurrently for different paths.
RADIOSITY_API void save_view3d(const Scene& scene, const View3DControl& control, const std::string& title,
                               const std::filesystem::path& path);

/// Writes linear float RGB (channels R, G, B) and each layer as LAYER.R/.G/.B. Throws
/// Error{io_error} naming the path when the file cannot be written, Error{invalid_argument}
/// for an empty image or pixel/layer sizes that do not match width x height.
/// Thread safety: may be called concurrently for different paths.
RADIOSITY_API void write_exr(const Image& image, const std::filesystem::path& path);

/// Reads an EXR written by write_exr (or any RGB EXR) with its layers, in name order; channels
/// missing from the file are 0. Throws Error{file_not_found} or Error{parse_error} (unreadable
/// file, no R, G or B channel) naming the path. Thread safety: may be called concurrently.
RADIOSITY_API Image read_exr(const std::filesystem::path& path);

/// Options for the tone-mapped preview.
struct PngOptions {
  float exposure = 1.0f;  ///< linear scale applied before clamping and sRGB encoding
};

/// Writes an 8-bit sRGB preview: clamp(exposure * radiance) then the sRGB transfer curve.
/// Throws Error{io_error} naming the path when the file cannot be written.
RADIOSITY_API void write_png(const Image& image, const std::filesystem::path& path, const PngOptions& options = {});

/// Writes the solution's leaf elements as a binary little-endian PLY with per-vertex position,
/// float radiosity (r, g, b properties named radiosity_r/g/b) and 8-bit display colours
/// (red/green/blue, sRGB of B/pi x exposure), so MeshLab and Blender show the solution.
/// Only vertices used by leaves are written; faces are triangles (quads split in two), facing
/// like the polygons. With diffuse transmission (Solution::back_radiosity()), every leaf whose
/// back sends light also gets a back face: its triangles reversed, over copies of its vertices
/// that carry the back radiosity (coincident with the front, so view it with back-face culling).
/// Throws Error{io_error} naming the path when the file cannot be written.
RADIOSITY_API void write_ply(const Solution& solution, const std::filesystem::path& path,
                             const PngOptions& options = {});

/// Writes mesh `mesh` of `scene` with the solution on the host's own vertices (the vertex
/// colours of `radiosity bake`), as a binary little-endian PLY: per vertex the position, the
/// lightmap UV1 as s/t (when the mesh has one), float irradiance_r/g/b and radiosity_r/g/b
/// (Solution::mesh_vertex_values()) and 8-bit red/green/blue (sRGB of B/pi x exposure); the
/// faces are the mesh's kept triangles, in its order. Throws Error{invalid_argument} for an
/// unknown mesh or a solution not solved with this mesh, Error{io_error} naming the path when
/// the file cannot be written.
RADIOSITY_API void write_mesh_ply(const Scene& scene, const Solution& solution, MeshId mesh,
                                  const std::filesystem::path& path, const PngOptions& options = {});

/// What write_baked_gltf() bakes into the scene. Every field has a default.
/// Thread safety: a plain value; write_baked_gltf() only reads it.
struct GltfBakeOptions {
  /// What the vertex colours and lightmaps hold, as LightmapOptions::quantity; a viewer shows it
  /// times the material's diffuse reflectance (Material::reflectance), or as it is for
  /// Quantity::radiosity, so that irradiance shows the radiosity B = reflectance x H.
  Quantity quantity = Quantity::irradiance;
  /// Per MeshId: the lightmap bake_lightmap() made of `quantity` in that mesh's UV1, or an empty
  /// Image for none. Empty (the default): no lightmaps. A mesh with one gets TEXCOORD_1 and the
  /// lightmap as its base colour texture; one without gets COLOR_0.
  std::vector<Image> lightmaps;
  /// Linear scale from `quantity` to display values: vertex colours and lightmap texels are
  /// clamp(exposure x value, 0, 1), the texels sRGB-encoded in 8-bit PNG. >= 0, finite.
  float exposure = 1.0f;
};

/// Writes `scene` with `solution` baked in as glTF 2.0, so that any glTF viewer (Blender,
/// three.js, ...) shows the lit scene: `output` is binary (.glb) or JSON (.gltf, its buffer in
/// OUTPUT_STEM.bin beside it). Every material becomes KHR_materials_unlit, its base colour the
/// diffuse reflectance (white for Quantity::radiosity; an emitter shows its emission x exposure,
/// flat); each mesh's light goes in as COLOR_0 vertex colours, or, where options.lightmaps has
/// one, as its base colour texture on TEXCOORD_1 (not both: viewers would multiply them). Every
/// primitive also gets `_IRRADIANCE` (float RGB per vertex, W/m^2, unscaled) for pipelines.
/// `source` is the glTF file the scene was loaded from (load_scene()): the output is that file
/// (its node hierarchy, transforms, cameras, lights, animations, extras) with its meshes' light
/// added, found by Mesh::source; a mesh placed by several nodes is copied for each, and
/// vertices split by lightmap UVs (Mesh::vertex_origin) carry every attribute of the vertex
/// they copy (skin weights, morph targets). Textures are dropped (the viewer shows the light,
/// not the texture). An empty `source` (scenes from OBJ, JSON, add_mesh(), the built-ins): a new
/// file, one node per mesh (Scene::add_group_meshes() makes meshes of polygons), positions in
/// world units, one primitive per material.
/// Throws Error{invalid_argument} for bad options, a lightmap count larger than the meshes, a
/// solution not solved with these meshes, or a scene that was not loaded from `source`
/// (a mesh without a glTF Mesh::source, or one whose vertex count differs from the file's);
/// the reader's errors for a broken `source`; Error{io_error} naming the path when the output
/// cannot be written. Thread safety: may be called concurrently for different outputs.
RADIOSITY_API void write_baked_gltf(const std::filesystem::path& source, const Scene& scene, const Solution& solution,
                                    const std::filesystem::path& output, const GltfBakeOptions& options = {});

/// Writes the statistics JSON of `radiosity solve --stats` (format in docs/CLI-stats.md):
/// status, iterations, residual history, per-group mean radiosity and area, power balance,
/// sizes, timings and warnings. Throws Error{io_error} naming the path when it cannot be written.
RADIOSITY_API void write_stats_json(const Solution& solution, const std::filesystem::path& path);

/// As above, and also records what the Solution itself does not know: the scene's name (left out
/// when empty) and the options the solve ran with (method, form-factor method, tolerance, ...).
RADIOSITY_API void write_stats_json(const Solution& solution, const std::filesystem::path& path,
                                    const SolveOptions& options, std::string_view scene = {});

}  // namespace v1
}  // namespace radiosity
