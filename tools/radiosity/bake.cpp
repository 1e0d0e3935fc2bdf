// `radiosity bake`: what a level baker wants from a scene: per mesh, the irradiance in its
// lightmap (UV1, made when the mesh has none) and on its own vertices, and a manifest that says
// where each went, at what resolution and density, in which units.
#include "bake.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct BakeArgs {
  SolveArgs solve;
  std::string output;
  int lightmap = 512;
  bool vertex_colors = true;
  bool make_uvs = false;
  bool final_gather = false;
  int gather_rays = rad::LightmapOptions{}.gather_rays;
  int dilation = rad::LightmapOptions{}.dilation;
  float texels_per_unit = 0.0f;
  std::string quantity = "irradiance";
  float exposure = 0.0f;  ///< 0: automatic (the 99th percentile of the vertex values shown at 0.8)
};

rad::Quantity quantity_from_name(const std::string& name) {
  return name == "radiosity" ? rad::Quantity::radiosity
         : name == "direct"  ? rad::Quantity::direct_irradiance
         : name == "indirect" ? rad::Quantity::indirect_irradiance
                              : rad::Quantity::irradiance;
}

/// A file name from a group's (or light group's) name: letters, digits, '-' and '_' kept, the
/// rest '_'; unique in `taken` (`id`, the mesh id or light group index, appended when needed).
std::string file_stem(const std::string& name, std::size_t id, std::set<std::string>& taken) {
  std::string stem;
  for (const char c : name) stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  if (stem.empty()) stem = "mesh";
  if (!taken.insert(stem).second) {
    stem += "_" + std::to_string(id);
    taken.insert(stem);
  }
  return stem;
}

/// Texels per scene unit of a mesh's UV1 at size x size: sqrt(texel area / surface area).
double texel_density(const rad::Mesh& m, int size) {
  double uv_area = 0.0, area = 0.0;
  for (std::size_t t = 0; t < m.triangle_polygon.size(); ++t) {
    if (m.triangle_polygon[t] == rad::kNone) continue;
    const std::uint32_t* i = &m.indices[3 * t];
    const glm::vec2 a = m.uv1[i[1]] - m.uv1[i[0]], b = m.uv1[i[2]] - m.uv1[i[0]];
    uv_area += 0.5 * std::abs(double(a.x) * b.y - double(a.y) * b.x);
    area += 0.5 * glm::length(glm::cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
  }
  return area > 0.0 ? static_cast<double>(size) * std::sqrt(uv_area / area) : 0.0;
}

bool is_gltf(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == ".glb" || ext == ".gltf";
}

/// Bakes mesh `id` of `sol` (whose light: lo.light_group) and writes the lightmap to `exr` and
/// its preview to `png`. Throws when the bake is cancelled.
rad::Lightmap bake_to(const rad::Scene& scene, const rad::Solution& sol, rad::MeshId id, const rad::LightmapOptions& lo,
                      const fs::path& exr, const fs::path& png, const rad::PngOptions& po, ProgressBar& bar) {
  rad::Lightmap map = rad::bake_lightmap(scene, sol, id, lo);
  bar.finish();
  if (map.cancelled) throw rad::Error(rad::ErrorCode::invalid_argument, "bake cancelled");
  rad::write_exr(map.image, exr);
  rad::write_png(map.image, png, po);
  return map;
}

/// --light-groups: each light group's contribution alone, in DIR/light_groups/<light group>/:
/// per mesh its lightmap (EXR, PNG at the total's exposure `po`) and its PLY (the solution
/// relit with that group alone, colours `ply_colours`), named by `stems`; `meshes` (the
/// manifest's entries, by mesh id) get each group's files. Returns the manifest's
/// "light_groups" list.
Json write_light_groups(const rad::Scene& scene, const rad::Solution& sol, const BakeArgs& a, rad::LightmapOptions lo,
                        const rad::PngOptions& po, const rad::PngOptions& ply_colours,
                        const std::vector<std::string>& stems, Json& meshes, ProgressBar& bar) {
  Json groups = Json::array();
  std::set<std::string> taken;
  for (std::size_t k = 0; k < sol.light_groups().size(); ++k) {
    const std::string& name = sol.light_groups()[k].name;
    const fs::path folder = fs::path("light_groups") / file_stem(name, k, taken);
    std::error_code made;
    fs::create_directories(fs::path(a.output) / folder, made);
    if (made)
      throw rad::Error(rad::ErrorCode::io_error,
                       "cannot create the folder '" + (fs::path(a.output) / folder).string() + "': " + made.message());
    // The group's share on the vertices: the solution with that group alone.
    const rad::Solution alone = a.vertex_colors ? light_group_alone(sol, k) : rad::Solution();
    lo.light_group = static_cast<int>(k);
    double seconds = 0.0;
    for (rad::MeshId id = 0; id < scene.meshes().size(); ++id) {
      Json files = {{"name", name}};
      const fs::path base = folder / stems[id];
      if (a.lightmap > 0) {
        const fs::path exr = base.string() + ".exr", png = base.string() + ".png";
        seconds += bake_to(scene, sol, id, lo, fs::path(a.output) / exr, fs::path(a.output) / png, po, bar).seconds;
        files["lightmap"] = exr.generic_string();
        files["preview"] = png.generic_string();
      }
      if (a.vertex_colors) {
        const fs::path ply = base.string() + ".ply";
        rad::write_mesh_ply(scene, alone, id, fs::path(a.output) / ply, ply_colours);
        files["ply"] = ply.generic_string();
      }
      meshes[id]["light_groups"].push_back(files);
    }
    groups.push_back({{"name", name}, {"folder", folder.generic_string()}});
    std::printf("light group %s: %s (%.2f s)\n", name.c_str(), folder.generic_string().c_str(), seconds);
  }
  return groups;
}

int run_bake(const BakeArgs& a) {
  return run_guarded([&] {
    ProgressBar bar;
    // Refused before the solve it would waste.
    if (is_gltf(a.output) && a.solve.light_groups)
      throw rad::Error(rad::ErrorCode::invalid_argument,
                       "--light-groups needs an output folder (a .glb/.gltf holds the total only)");
    rad::Scene scene = load(a.solve.scene, a.solve.strict, a.solve.photometric, {a.solve.two_sided, a.solve.reverse_winding});
    print_load_notes(scene);
    // Surfaces that came as polygons (OBJ faces, JSON shapes, the built-in scenes) are baked per
    // group, as meshes welded at shared corners.
    const std::size_t given = scene.meshes().size();
    const std::vector<rad::MeshId> grouped = scene.add_group_meshes();
    if (!grouped.empty())
      std::printf("meshes: %zu given, %zu made from the polygons of as many groups\n", given, grouped.size());

    // Lightmap UVs: the mesh's own UV1 unless --make-uvs, made where a mesh has none.
    std::vector<std::string> uv_source(scene.meshes().size(), "given");
    std::vector<std::size_t> charts(scene.meshes().size(), 0);
    if (a.lightmap > 0) {
      rad::LightmapUvOptions uo;
      uo.resolution = a.lightmap;
      uo.padding = std::max(2, a.dilation);
      uo.texels_per_unit = a.texels_per_unit;
      std::size_t made = 0;
      for (rad::MeshId id = 0; id < scene.meshes().size(); ++id) {
        const bool has_uv1 = scene.meshes()[id].uv1.size() == scene.meshes()[id].positions.size();
        if (has_uv1 && !a.make_uvs) continue;
        const rad::LightmapUvs uvs = rad::generate_lightmap_uvs(scene, id, uo);
        uv_source[id] = "generated";
        charts[id] = uvs.chart_count;
        ++made;
      }
      if (made > 0)
        std::printf("lightmap UVs: made for %zu of %zu meshes (%s; planar charts, %d texels of padding)\n", made,
                    scene.meshes().size(), a.make_uvs ? "--make-uvs" : "the others have no UV1", uo.padding);
    }

    rad::SolveOptions options = to_options(a.solve, bar);
    apply_specular_depth(options, a.solve);
    const rad::Solution sol = rad::solve(scene, options);
    bar.finish();
    print_summary(sol);
    print_estimator(sol, options);
    print_solve_warnings(scene, sol);

    // `-o lit.glb`: one glTF file with the light baked in, instead of a folder.
    const bool gltf_output = is_gltf(a.output);
    rad::GltfBakeOptions gltf;
    gltf.quantity = quantity_from_name(a.quantity);
    if (!gltf_output) {
      std::error_code made;
      fs::create_directories(a.output, made);
      if (made)
        throw rad::Error(rad::ErrorCode::io_error, "cannot create the output folder '" + a.output + "': " + made.message());
    }
    rad::LightmapOptions lo;
    lo.width = lo.height = std::max(a.lightmap, 1);
    lo.quantity = quantity_from_name(a.quantity);
    lo.final_gather = a.final_gather;
    lo.gather_rays = a.gather_rays;
    lo.dilation = a.dilation;
    lo.threads = a.solve.threads;
    lo.seed = a.solve.seed;
    lo.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
    // Previews: one exposure for every mesh, so their brightness compares; automatic unless
    // given, from the baked quantity on the meshes' vertices (cheap, before any texel is baked).
    rad::PngOptions po;
    po.exposure = a.exposure;
    if (!(a.exposure > 0.0f)) {
      std::vector<float> values;
      for (rad::MeshId id = 0; id < scene.meshes().size(); ++id)
        for (const rad::Rgb& v : sol.mesh_vertex_values(id, lo.quantity)) values.push_back(std::max({v.x, v.y, v.z}));
      std::sort(values.begin(), values.end());
      const float p99 = values.empty() ? 0.0f : values[values.size() * 99 / 100];
      po.exposure = p99 > 0.0f ? 0.8f / p99 : 1.0f;
      std::printf("preview exposure: %.4g (automatic: the 99th percentile of the vertex %s shows at 0.8; --exposure "
                  "overrides)\n",
                  po.exposure, a.quantity.c_str());
    }
    if (gltf_output) {
      gltf.exposure = po.exposure;
      if (a.lightmap > 0) gltf.lightmaps.resize(scene.meshes().size());
      double bake_seconds = 0.0;
      for (rad::MeshId id = 0; id < scene.meshes().size() && a.lightmap > 0; ++id) {
        rad::Lightmap map = rad::bake_lightmap(scene, sol, id, lo);
        bar.finish();
        if (map.cancelled) throw rad::Error(rad::ErrorCode::invalid_argument, "bake cancelled");
        bake_seconds += map.seconds;
        gltf.lightmaps[id] = std::move(map.image);
      }
      // A glTF scene is written back as itself; any other becomes a new file.
      const std::string source = is_gltf(a.solve.scene) ? a.solve.scene : std::string();
      rad::write_baked_gltf(source, scene, sol, a.output, gltf);
      if (a.lightmap > 0)
        std::printf("lightmaps: %zu at %dx%d, %s%s, %.2f s, in the glTF as base colour textures on TEXCOORD_1\n",
                    scene.meshes().size(), a.lightmap, a.lightmap, a.quantity.c_str(),
                    a.final_gather ? " (final gather)" : " (interpolated)", bake_seconds);
      std::printf("wrote %s (%zu meshes; %s, unlit materials, exposure %.4g%s)\n", fs::absolute(a.output).c_str(),
                  scene.meshes().size(), a.lightmap > 0 ? "lightmaps" : "COLOR_0 vertex colours", po.exposure,
                  source.empty() ? "; a new file: the scene was not read from glTF" : "");
      return 0;
    }
    // A PLY colour shows B / pi; pi x exposure puts B on the lightmaps' scale.
    rad::PngOptions ply_colours = po;
    ply_colours.exposure = po.exposure * 3.14159265f;

    Json manifest;
    manifest["scene"] = a.solve.scene.empty() ? "cornell" : a.solve.scene;
    manifest["units"] = {{"length", "scene unit"},
                         {"lightmap", a.quantity + ", W/m^2 (watts per scene unit^2), linear float RGB"},
                         {"vertex", "irradiance_r/g/b and radiosity_r/g/b, W/m^2"}};
    // Scene::origin(): the PLYs' positions include it; a host that keeps the model at its
    // site's coordinates places the meshes by it.
    manifest["origin"] = {scene.origin().x, scene.origin().y, scene.origin().z};
    manifest["lightmap"] = {{"quantity", a.quantity},
                            {"final_gather", a.final_gather},
                            {"resolution", a.lightmap},
                            {"dilation", a.dilation},
                            {"texel_centre", "((x + 0.5) / width, (y + 0.5) / height) = UV1; row 0 at v = 0"}};
    Json meshes = Json::array();
    std::set<std::string> taken;
    std::vector<std::string> stems;
    double bake_seconds = 0.0;
    for (rad::MeshId id = 0; id < scene.meshes().size(); ++id) {
      const rad::Mesh& m = scene.meshes()[id];
      const std::string stem = stems.emplace_back(file_stem(scene.groups()[m.group], id, taken));
      std::size_t kept = 0;
      for (rad::PolygonId p : m.triangle_polygon) kept += p != rad::kNone ? 1 : 0;
      Json entry = {{"id", id},          {"group", scene.groups()[m.group]}, {"vertices", m.positions.size()},
                    {"triangles", kept}, {"uv1", a.lightmap > 0 ? uv_source[id] : "none"}};
      if (a.lightmap > 0) {
        const fs::path exr = fs::path(a.output) / (stem + ".exr"), png = fs::path(a.output) / (stem + ".png");
        const rad::Lightmap map = bake_to(scene, sol, id, lo, exr, png, po, bar);
        bake_seconds += map.seconds;
        entry["lightmap"] = {{"file", exr.filename().string()},
                             {"preview", png.filename().string()},
                             {"width", map.image.width},
                             {"height", map.image.height},
                             {"texels_per_unit", texel_density(m, a.lightmap)},
                             {"covered_texels", map.covered},
                             {"dilated_texels", map.dilated}};
        if (uv_source[id] == "generated") entry["lightmap"]["charts"] = charts[id];
      }
      if (a.vertex_colors) {
        const fs::path ply = fs::path(a.output) / (stem + ".ply");
        rad::write_mesh_ply(scene, sol, id, ply, ply_colours);
        entry["ply"] = ply.filename().string();
      }
      meshes.push_back(entry);
    }
    if (a.lightmap > 0)
      std::printf("lightmaps: %zu at %dx%d, %s%s, %.2f s\n", scene.meshes().size(), a.lightmap, a.lightmap,
                  a.quantity.c_str(), a.final_gather ? " (final gather)" : " (interpolated)", bake_seconds);
    if (!sol.light_groups().empty())
      manifest["light_groups"] = write_light_groups(scene, sol, a, lo, po, ply_colours, stems, meshes, bar);
    manifest["meshes"] = meshes;
    const fs::path manifest_path = fs::path(a.output) / "manifest.json";
    std::ofstream out(manifest_path);
    out << manifest.dump(2) << "\n";
    out.close();
    if (!out) throw rad::Error(rad::ErrorCode::io_error, "cannot write '" + manifest_path.string() + "'");
    std::printf("wrote %s (%zu meshes)\n", fs::absolute(manifest_path).c_str(), scene.meshes().size());
    return 0;
  });
}

}  // namespace

Command add_bake_command(CLI::App& app) {
  auto args = std::make_shared<BakeArgs>();
  BakeArgs& a = *args;
  CLI::App* cmd = app.add_subcommand(
      "bake", "Solve and write, per mesh, a lightmap (EXR + PNG preview), a PLY with the solution on its vertices, "
              "and manifest.json");
  cmd->add_option("scene", a.solve.scene, kSceneHelp);
  cmd->add_option("-o,--output", a.output,
                  "Output folder (created); or a .glb/.gltf file: the scene with the light baked in (lightmaps, or "
                  "vertex colours with --lightmap 0)")
      ->required();
  cmd->add_option("--lightmap", a.lightmap, "Lightmap width and height in texels, 0 = no lightmaps")
      ->check(in_range<int>(0, 16384))
      ->capture_default_str();
  cmd->add_flag("--vertex-colors,!--no-vertex-colors", a.vertex_colors,
                "Write each mesh as PLY with the solution on its own vertices (default on)");
  cmd->add_flag("--make-uvs", a.make_uvs, "Make lightmap UVs for every mesh, even one that has UV1");
  cmd->add_option("--texels-per-unit", a.texels_per_unit,
                  "Lightmap density of made UVs, texels per scene unit (0 = the largest that fits)")
      ->check(non_negative<float>());
  cmd->add_option("--quantity", a.quantity, "What the lightmap stores, W/m^2")
      ->check(CLI::IsMember({"irradiance", "direct", "indirect", "radiosity"}))
      ->capture_default_str();
  cmd->add_flag("--final-gather", a.final_gather,
                "Per texel: direct light by shadow rays and a gather of the solution (sharper, slower)");
  cmd->add_option("--gather-rays", a.gather_rays, "Final gather: hemisphere rays per texel")
      ->check(in_range<int>(1, 1 << 16))
      ->capture_default_str();
  cmd->add_option("--dilation", a.dilation, "Texels of gutter filled around each chart")
      ->check(in_range<int>(0, 64))
      ->capture_default_str();
  cmd->add_option("--exposure", a.exposure,
                  "Lightmap preview exposure (linear scale; PLY colours show B/pi at pi times it); default automatic")
      ->check(positive<float>());
  add_solve_options(*cmd, a.solve);
  return Command{cmd, [args] { return run_bake(*args); }};
}

}  // namespace cli
