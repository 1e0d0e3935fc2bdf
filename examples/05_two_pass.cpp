// The two-pass method's figure-10 triple (Wallace, Cohen & Greenberg 1987) for a Cornell box
// with a mirror tall block and a glass short block: (a) direct illumination only, (b) diffuse
// interreflection added (pass 1), (c) the full solution with specular reflection, refraction
// and photon-mapped caustics. Writes two_pass_{a_direct,b_pass1,c_full}.{exr,png} into the
// current folder (or the folder given as the first argument); the EXRs carry the layers
// direct, indirect, specular and caustic.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace {

/// The built-in Cornell box with the tall block made a mirror and the short block clear glass.
radiosity::Scene cornell_specular() {
  const radiosity::Scene base = radiosity::cornell_box();
  radiosity::Scene scene;
  std::vector<radiosity::MaterialId> ids;
  for (const radiosity::Material& m : base.materials()) ids.push_back(scene.add_material(m));
  radiosity::Material mirror, glass;
  mirror.name = "mirror";
  mirror.reflectance = radiosity::Rgb(0.0f);  // no diffuse part: pass 1 sees it black
  mirror.specular = radiosity::Rgb(0.9f);     // specular_exponent 0 = ideal mirror
  glass.name = "glass";
  glass.reflectance = radiosity::Rgb(0.0f);
  glass.transmittance = radiosity::Rgb(1.0f);
  glass.ior = 1.5f;
  const radiosity::MaterialId mirror_id = scene.add_material(mirror), glass_id = scene.add_material(glass);
  for (const radiosity::Polygon& p : base.polygons()) {
    const std::string& group = base.groups()[p.group];
    scene.add_polygon(p.vertices, group == "tall_block" ? mirror_id : group == "short_block" ? glass_id : ids[p.material],
                      group);
  }
  scene.set_camera(base.camera());
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path folder = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(folder);
  const radiosity::Scene scene = cornell_specular();
  const radiosity::Solution pass1 = radiosity::solve(scene);  // the diffuse first pass

  const struct {
    radiosity::TwoPassContent content;
    const char* name;
  } images[] = {{radiosity::TwoPassContent::direct_only, "two_pass_a_direct"},
                {radiosity::TwoPassContent::pass1_only, "two_pass_b_pass1"},
                {radiosity::TwoPassContent::full, "two_pass_c_full"}};
  for (const auto& im : images) {
    radiosity::TwoPassOptions opt;  // 512 x 512, 16 rays per pixel, 200k photons
    opt.content = im.content;
    radiosity::TwoPassReport report;
    const radiosity::Image image = radiosity::render_two_pass(scene, pass1, opt, report);
    radiosity::write_exr(image, folder / (std::string(im.name) + ".exr"));
    radiosity::write_png(image, folder / (std::string(im.name) + ".png"));
    std::printf("%-18s photons stored %7zu of %zu, render %.2f s\n", im.name, report.photons_stored,
                report.photons_emitted, report.seconds_render);
  }
}
