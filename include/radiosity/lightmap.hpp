// Lightmaps: a solution baked into the texture space (UV1) of a host's meshes, and lightmap UVs
// made for meshes that have none.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "radiosity/common.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace radiosity {
inline namespace v1 {

/// How bake_lightmap() fills a lightmap. Every field has a default.
/// Thread safety: a plain value; bake_lightmap() only reads it.
struct LightmapOptions {
  int width = 1024;   ///< texels, > 0
  int height = 1024;  ///< texels, > 0
  /// What each covered texel stores, W/m^2: irradiance H (incident, before the albedo: what a
  /// renderer multiplies by its own albedo texture; the default), its direct or indirect part,
  /// or the radiosity B.
  Quantity quantity = Quantity::irradiance;
  /// Whose light is baked: -1 (the default) all of it; k, light group k's contribution alone
  /// (an index of Solution::light_groups(): solve with SolveOptions::separate_light_groups).
  /// Interpolated: the group's values (Solution::light_group_values()). Final gather: only the
  /// group's emitting polygons and lights count, for the exact direct light and where a gather
  /// ray meets an emitter, and the gather rays read the group's pass-1 radiosity. The weights of
  /// a relit solution (Solution::relight()) apply: group k at its weight, and with -1 every
  /// emitter and light at its group's weight. >= -1.
  int light_group = -1;
  /// false: the solution's field interpolated at the texel's surface point (as render() shows
  /// it; shadows are as sharp as the elements). true: a gather per texel: the light straight
  /// from the emitters by the exact point-to-polygon factor times a visible fraction from
  /// shadow rays (shadows sharp at texel resolution) and from the point, spot and directional
  /// lights by a shadow ray each, plus the light reflected by the rest of the scene from
  /// hemisphere rays that read pass 1's radiosity where they land (a ray that leaves the
  /// scene brings the sky's light, counted as direct). Only
  /// irradiance and its two parts can be gathered (radiosity is interpolated either way).
  bool final_gather = false;
  int gather_rays = 256;  ///< final gather: cosine-distributed hemisphere rays per texel, >= 1
  int shadow_rays = 16;   ///< final gather: shadow rays per texel and emitter, >= 1
  /// Final gather: the emitting polygons whose direct light is computed exactly per texel, the
  /// strongest for the texel first; the others are found by the hemisphere rays (as the Monte
  /// Carlo estimator's FormFactorOptions::exact_emitters). >= 0.
  int exact_emitters = 16;
  /// Texels of gutter around each chart filled from their covered neighbours, so that bilinear
  /// filtering across a chart border does not bleed black (or another chart's light) in. >= 0.
  int dilation = 4;
  unsigned threads = 0;     ///< 0 = all hardware threads
  std::uint64_t seed = 1;   ///< final gather: the result is bit-identical at any thread count
  ProgressFn on_progress;   ///< Phase::rendering; return false to cancel
};

/// Checks options; throws Error{invalid_argument} naming the first bad field.
RADIOSITY_API void validate(const LightmapOptions& options);

/// What a texel of a Lightmap holds.
enum class TexelState : std::uint8_t {
  empty = 0,    ///< no triangle covers it, and it is beyond the dilation
  covered = 1,  ///< a triangle covers (part of) it: the value at its surface point
  dilated = 2,  ///< in the gutter: the mean of its covered (or earlier dilated) neighbours
};

/// A baked lightmap: `image` (width x height, row 0 at v = 0, texel (x, y) centred at uv
/// ((x + 0.5) / width, (y + 0.5) / height)), what each texel holds, and counts.
struct Lightmap {
  Image image;
  std::vector<TexelState> state;  ///< per texel, row-major like image.pixels
  std::size_t covered = 0;        ///< texels with TexelState::covered
  std::size_t dilated = 0;        ///< texels with TexelState::dilated
  double seconds = 0.0;
  bool cancelled = false;         ///< on_progress returned false: covered texels so far only
};

/// Bakes `quantity` of `solution` (solved from `scene`) into the UV1 space of mesh `mesh`, on
/// the front side of its triangles (the side their normals face; a two-sided surface's back is
/// not baked, and solve() warns about two-sided groups lit mainly on their backs). Each
/// texel that a triangle touches (conservative rasterisation: a thin triangle still gets the
/// texels it crosses) takes the value at the point of the triangle nearest to the texel centre,
/// so a texel on a chart border reads the chart's edge; then `dilation` rings of gutter are
/// filled. Throws Error{invalid_argument} for an unknown mesh, a mesh without UV1 (see
/// generate_lightmap_uvs()), a solution not made from this scene, bad options, a quantity the
/// solution does not hold, a light group it does not have, or (final gather of a light group or
/// of a relit solution) light groups that are not the scene's materials' and lights'. Cost:
/// interpolated, about the covered texels times the depth of the element quadtrees; final
/// gather, gather_rays + shadow_rays x emitters rays per texel.
/// Light groups add up: the sum over k of the lightmaps with light_group = k is the one with -1
/// to within the solver's tolerance (the groups' own solves against the joint one, which is all
/// that the interpolated values and the final gather's indirect part read). The final gather's
/// direct part adds up exactly, up to float rounding, where a texel sees at most exact_emitters
/// emitters (the same seed gives each group the same rays); where it sees more, the strongest
/// are exact and the rest gathered, group by group, so the sum agrees statistically.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API Lightmap bake_lightmap(const Scene& scene, const Solution& solution, MeshId mesh,
                                     const LightmapOptions& options = {});
/// One atlas for several meshes that share a UV1 space (their charts must not overlap).
RADIOSITY_API Lightmap bake_lightmap(const Scene& scene, const Solution& solution, const std::vector<MeshId>& meshes,
                                     const LightmapOptions& options = {});

/// How generate_lightmap_uvs() cuts and packs charts. Every field has a default.
/// Thread safety: a plain value; generate_lightmap_uvs() only reads it.
struct LightmapUvOptions {
  /// Texels per scene unit of length, finite and >= 0. 0 (default): the largest density at
  /// which the charts fit a `resolution` x `resolution` lightmap (found to a relative 1e-5).
  float texels_per_unit = 0.0f;
  int resolution = 1024;  ///< the lightmap's width and height in texels, > 2 * padding
  /// Empty texels kept between charts (and from the border), >= 0; at least the
  /// LightmapOptions::dilation that the lightmap will be baked with is right.
  int padding = 4;
  /// Neighbouring triangles join one planar chart while their normals stay within this angle
  /// (degrees, in (0, 90)) of the chart's first (largest) triangle.
  float chart_angle_deg = 30.0f;
};

/// Checks options; throws Error{invalid_argument} naming the first bad field.
RADIOSITY_API void validate(const LightmapUvOptions& options);

/// Lightmap UVs for an indexed triangle mesh, as a host adopts them: triangles keep their order
/// and corners, but vertices on a chart border are split (one copy per chart), so the mesh gets
/// new vertices, each naming the host vertex it copies. New vertices are ordered by host vertex
/// (then chart), so a mesh that needs no split (and uses every vertex) keeps its numbering;
/// host vertices that no triangle uses get none.
struct LightmapUvs {
  std::vector<glm::vec2> uv1;                ///< per new vertex, in [0, 1]^2
  std::vector<std::uint32_t> vertex_origin;  ///< per new vertex: the host vertex it copies
  std::vector<std::uint32_t> indices;        ///< three per triangle, into the new vertices
  std::vector<std::uint32_t> triangle_chart; ///< per triangle: its chart, < chart_count
  std::size_t chart_count = 0;
  float texels_per_unit = 0.0f;              ///< the density used
  /// Fraction of the lightmap's texels that the charts' triangles cover (their UV area in
  /// texels over resolution^2; padding and the corners of chart rectangles are not counted).
  double utilisation = 0.0;
};

/// Cuts the mesh into planar charts (triangles grown across shared edges, keyed by the host's
/// vertex indices, while their normals stay within chart_angle_deg of the chart's largest
/// triangle; a triangle whose projection would overlap the chart's is left for another chart),
/// projects each onto its plane at one texel density (isometric for a planar chart, shrunk by
/// the cosine of the tilt otherwise), turns it to its minimum-area bounding rectangle with the
/// long side along u, and packs the rectangles, snapped to whole texels, into rows of the
/// lightmap with `padding` empty texels between them and from the border. UVs keep each
/// triangle's winding (counter-clockwise seen from its front is counter-clockwise in UV).
/// A degenerate (zero-area) triangle goes, with zero area, into a chart that holds all three of
/// its corners, or else into one last chart of a single texel.
/// Throws Error{invalid_argument} for bad options, an index_count that is not a multiple of 3, a
/// null array with a count, an index out of range, a NaN or infinite position, and when the
/// charts cannot fit at the requested texels_per_unit (the message names the largest density
/// that fits) or at any density (more charts than the resolution has room for).
/// Cost: O(n log n) in the triangles (a chart's overlap test is a grid over it), 0.1 to 0.3 s
/// for 100k triangles on one core. Deterministic: the same input gives the same result.
/// Thread safety: concurrent calls are safe.
RADIOSITY_API LightmapUvs generate_lightmap_uvs(const glm::vec3* positions, std::size_t vertex_count,
                                                const std::uint32_t* indices, std::size_t index_count,
                                                const LightmapUvOptions& options = {});

/// generate_lightmap_uvs() for a mesh of `scene`, adopted by it (Scene::set_mesh_lightmap_uvs):
/// the mesh's vertices are split as the result says (positions, normals and uv0 copied from
/// their origin), its indices and uv1 replaced. Its polygons do not change; solve after this
/// for mesh values on the new vertices. Throws as generate_lightmap_uvs() and
/// Error{invalid_argument} for an unknown mesh; the scene is then unchanged.
/// Thread safety: mutates `scene`.
RADIOSITY_API LightmapUvs generate_lightmap_uvs(Scene& scene, MeshId mesh, const LightmapUvOptions& options = {});

}  // namespace v1
}  // namespace radiosity
