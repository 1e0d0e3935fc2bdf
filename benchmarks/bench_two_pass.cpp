// Two-pass benchmark: the Cornell box with a mirror tall block and a glass short block, 512 x 512
// at 16 rays per pixel, pass 1 included, 2 threads (the goal of issue #6 is under 5 s in all).
// Prints seconds per phase: pass 1 (mesh, form factors, solve), the direct split of pass 1 and
// the BVH, photons (shooting and the kd-tree) and pass 2 (camera rays).
//
// Usage: bench_two_pass [width [spp [photons [max_patch_area [gather]]]]]
//   (defaults 512, 16, 200000, 0 = solve()'s default mesh; the word `gather` selects
//   DiffuseShading::final_gather, which lets a coarse pass 1 mesh still give sharp shadows)
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace {

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_two_pass: bad argument '%s'\n", bad);
  std::fprintf(stderr, "usage: bench_two_pass [width [spp [photons [max_patch_area [gather]]]]]\n");
  return bad ? 2 : 0;
}

/// A non-negative number, or -1 when `text` is not one.
double number_arg(const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  return (end != text && *end == '\0' && v >= 0.0) ? v : -1.0;
}

int run(int width, int spp, std::size_t photons, float patch_area, bool gather);

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) return usage(nullptr);
  if (argc > 6) return usage(argv[6]);
  double v[4] = {512, 16, 200000, 0};
  for (int i = 1; i < argc && i <= 4; ++i) {
    v[i - 1] = number_arg(argv[i]);
    if (v[i - 1] < 0.0 || (i <= 2 && v[i - 1] < 1.0)) return usage(argv[i]);
  }
  if (argc > 5 && std::string(argv[5]) != "gather") return usage(argv[5]);
  try {
    return run(static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<std::size_t>(v[2]),
               static_cast<float>(v[3]), argc > 5);
  } catch (const radiosity::Error& e) {
    std::fprintf(stderr, "bench_two_pass: error: %s\n", e.what());
    return 1;
  }
}

namespace {

int run(int width, int spp, std::size_t photons, float patch_area, bool gather) {
  const radiosity::Scene scene = radiosity::cornell_box_specular();

  // Wall time per phase, and the process's CPU time (all threads), which a busy shared machine
  // inflates less.
  const std::clock_t c0 = std::clock();
  const auto t0 = std::chrono::steady_clock::now();
  radiosity::SolveOptions so;
  so.threads = 2;
  so.mesh.max_patch_area = patch_area;
  so.form_factors.method = radiosity::FormFactorMethod::monte_carlo;  // with mirror form factors
  so.form_factors.specular_depth = 1;
  const radiosity::Solution pass1 = radiosity::solve(scene, so);
  const double seconds_pass1 = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::clock_t c1 = std::clock();

  radiosity::TwoPassOptions to;
  to.width = to.height = width;
  to.spp = spp;
  to.threads = 2;
  to.caustics.photons = photons;
  if (gather) to.diffuse = radiosity::DiffuseShading::final_gather;
  radiosity::TwoPassReport r;
  const auto t1 = std::chrono::steady_clock::now();
  const radiosity::Image image = radiosity::render_two_pass(scene, pass1, to, r);
  const double seconds_pass2 = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const std::clock_t c2 = std::clock();
  const double cpu_pass1 = static_cast<double>(c1 - c0) / CLOCKS_PER_SEC;
  const double cpu_pass2 = static_cast<double>(c2 - c1) / CLOCKS_PER_SEC;
  const double total = seconds_pass1 + seconds_pass2;

  std::printf("bench_two_pass: radiosity %s, specular Cornell box, %dx%d, %d spp, 2 threads, %s\n",
              radiosity::version(), width, width, spp, gather ? "final gather" : "pass 1 diffuse");
  std::printf("pass 1   %7.2f s  (%zu patches, %zu elements; form factors %.2f s, solve %.2f s)\n", seconds_pass1,
              pass1.report().patch_count, pass1.report().element_count, pass1.report().seconds_form_factors,
              pass1.report().seconds_solving);
  std::printf("setup    %7.2f s  (BVH, materials, direct part of pass 1)\n", r.seconds_setup);
  std::printf("photons  %7.2f s  (%zu emitted, %zu stored)\n", r.seconds_photons, r.photons_emitted, r.photons_stored);
  std::printf("pass 2   %7.2f s  (%.2f M camera rays/s)\n", r.seconds_render,
              static_cast<double>(width) * width * spp / r.seconds_render * 1e-6);
  std::printf("total    %7.2f s  (goal < 5 s)%s\n", total, total < 5.0 ? "" : "  -- over the goal");
  std::printf("cpu      %7.2f s  (pass 1 %.2f s, setup + photons + pass 2 %.2f s, all threads)\n", cpu_pass1 + cpu_pass2,
              cpu_pass1, cpu_pass2);
  return image.pixels.empty() ? 1 : 0;
}

}  // namespace
