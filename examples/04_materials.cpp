// The materials example of issue #5: a row of tessellated spheres, one per reflection model of
// brdf.hpp, on a diffuse floor in front of a backdrop under one area light, described in
// examples/scenes/materials.json and rendered with the reference path tracer to EXR + PNG.
//
// Left to right (the JSON groups sphere_1_lambertian ... sphere_8_measured): Lambertian red
// clay, Phong blue plastic, Blinn-Phong green plastic, anisotropic Ward brushed steel, GGX
// microfacet copper, ideal mirror, dielectric glass, and a measured BRDF in the MERL layout.
// No measured data set is available offline, so the measured one is synthetic: this program
// tabulates a GGX gold (Walter, Marschner, Li & Torrance, "Microfacet models for refraction
// through rough surfaces", EGSR 2007) in the MERL layout of Matusik, Pfister, Brand & McMillan,
// "A data-driven reflectance model", SIGGRAPH 2003, and writes it into the output directory,
// which is then the base for the scene's relative file names.
//
// The models show only once the path tracer evaluates Material::brdf; until then every sphere
// renders as the Lambertian of its diffuse reflectance.
//
// Usage: example_04_materials [OUT_DIR [SCENE_JSON [SPP]]]   (defaults: out, the source tree's
// examples/scenes/materials.json, 64). Writes OUT_DIR/materials.exr and OUT_DIR/materials.png.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#ifndef RADIOSITY_EXAMPLE_SCENES
#define RADIOSITY_EXAMPLE_SCENES "examples/scenes"
#endif

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

/// GGX gold with a weak diffuse base, as f(theta_half, theta_diff, phi_diff) per channel.
/// The directions follow Rusinkiewicz's parameterisation: the half vector tilted by theta_half
/// about y, the difference vector (theta_diff, phi_diff) in the half vector's frame.
double synthetic_gold(int channel, double theta_h, double theta_d, double phi_d) {
  // Only the z components matter here, and a rotation about y leaves the y component out of them.
  const double dx = std::sin(theta_d) * std::cos(phi_d), dz = std::cos(theta_d);
  const double ch = std::cos(theta_h), sh = std::sin(theta_h);
  const double cos_i = -dx * sh + dz * ch;  // z of wi = R_y(theta_h) d
  const double cos_o = dx * sh + dz * ch;   // z of wo = R_y(theta_h) (-dx, -dy, dz)
  if (cos_i <= 1e-4 || cos_o <= 1e-4) return 0.0;
  const double alpha = 0.25, a2 = alpha * alpha;
  const double t = ch * ch * (a2 - 1.0) + 1.0;
  const double D = a2 / (kPi * t * t);
  auto lambda = [&](double c) { return 0.5 * (std::sqrt(1.0 + a2 * (1.0 - c * c) / (c * c)) - 1.0); };
  const double G = 1.0 / (1.0 + lambda(cos_i) + lambda(cos_o));
  const double f0[3] = {1.0, 0.71, 0.29};
  const double F = f0[channel] + (1.0 - f0[channel]) * std::pow(1.0 - dz, 5.0);  // Schlick, cos = wi.h
  const double base[3] = {0.04, 0.03, 0.01};
  return base[channel] / kPi + D * F * G / (4.0 * cos_i * cos_o);
}

/// Writes the MERL binary layout: int32 dimensions 90, 90, 180, then all red, green and blue
/// doubles divided by the per-channel scales that load_measured() multiplies back, little-endian.
void write_synthetic_merl(const fs::path& path) {
  constexpr int kTh = 90, kTd = 90, kPd = 180;
  const double scale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
  std::vector<unsigned char> bytes;
  bytes.reserve(12 + 3 * std::size_t{kTh} * kTd * kPd * 8);
  auto put = [&](std::uint64_t bits, int n) {
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<unsigned char>((bits >> (8 * i)) & 0xff));
  };
  for (int d : {kTh, kTd, kPd}) put(static_cast<std::uint32_t>(d), 4);
  for (int c = 0; c < 3; ++c)
    for (int ih = 0; ih < kTh; ++ih) {
      const double u = static_cast<double>(ih) / kTh;
      const double theta_h = u * u * 0.5 * kPi;  // the MERL index is sqrt(theta_h / (pi/2)) * 90
      for (int id = 0; id < kTd; ++id)
        for (int ip = 0; ip < kPd; ++ip) {
          const double v = synthetic_gold(c, theta_h, id * 0.5 * kPi / kTd, ip * kPi / kPd) / scale[c];
          std::uint64_t bits = 0;
          std::memcpy(&bits, &v, sizeof bits);
          put(bits, 8);
        }
    }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw radiosity::Error(radiosity::ErrorCode::io_error, "cannot write '" + path.string() + "'");
}

}  // namespace

int main(int argc, char** argv) try {
  const fs::path out_dir = argc > 1 ? argv[1] : "out";
  const fs::path scene_path =
      argc > 2 && argv[2][0] != '\0' ? fs::path(argv[2]) : fs::path(RADIOSITY_EXAMPLE_SCENES) / "materials.json";
  const int spp = argc > 3 ? std::max(1, std::atoi(argv[3])) : 64;
  fs::create_directories(out_dir);

  write_synthetic_merl(out_dir / "measured_synthetic.binary");
  std::ifstream in(scene_path, std::ios::binary);
  if (!in) throw radiosity::Error(radiosity::ErrorCode::file_not_found, "cannot open '" + scene_path.string() + "'");
  std::ostringstream text;
  text << in.rdbuf();
  // Relative names in the scene (the measured BRDF) resolve against the output directory.
  const radiosity::Scene scene = radiosity::parse_scene_json(text.str(), out_dir, scene_path.string());
  for (const std::string& w : scene.warnings()) std::printf("warning: %s\n", w.c_str());

  radiosity::PathTraceOptions opt;
  opt.width = 640;
  opt.height = 320;
  opt.spp = spp;
  const radiosity::Image image = radiosity::render_path_traced(scene, opt);
  radiosity::write_exr(image, out_dir / "materials.exr");
  radiosity::write_png(image, out_dir / "materials.png");
  std::printf("%zu polygons, %dx%d at %d spp: wrote %s and %s\n", scene.polygons().size(), opt.width, opt.height, spp,
              (out_dir / "materials.exr").string().c_str(), (out_dir / "materials.png").string().c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "example_04_materials: %s\n", e.what());
  return 1;
}
