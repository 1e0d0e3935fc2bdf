// Solver benchmark: the obstructed Cornell box meshed into about N patches of one element each,
// form factors plus solve to tolerance 1e-3 with each method on 2 threads. Each configuration
// runs in its own child process, so its peak memory (getrusage max RSS) is its own.
//
// Usage: bench_solvers [--ray-cast] [--rays N] [--only METHOD] [patches...]
//          (default: 4000 with the monte_carlo estimator at 1024 rays; the second size is 16000)
//        bench_solvers --compare PATCHES   (accuracy of monte_carlo against ray_cast on one mesh)
//        bench_solvers --defaults [PATCHES] (default SolveOptions, only the mesh set; default 4000:
//          the estimator automatic chose and its time, against ray_cast's in the same run)
//        bench_solvers --relight [PATCHES] (a kept Problem: first solve against a relit one)
// Prints one line per configuration: patches, elements, method, seconds (form factors, solve),
// iterations, residual reached, peak RSS.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace {

radiosity::FormFactorMethod g_estimator = radiosity::FormFactorMethod::monte_carlo;
std::uint32_t g_rays = 0;
std::string g_only;  // run only this method

int run(std::size_t target_patches, radiosity::SolverMethod method, const char* name) {
  const radiosity::Scene scene = radiosity::cornell_box();
  radiosity::SolveOptions opt;
  opt.method = method;
  opt.tolerance = 1e-3;
  opt.threads = 2;
  opt.form_factors.method = g_estimator;
  if (g_rays > 0) opt.form_factors.hemisphere_rays = g_rays;
  // Patches are at most this large, so there are somewhat more than target_patches of them.
  opt.mesh.max_patch_area = static_cast<float>(scene.total_area() / static_cast<double>(target_patches));
  opt.mesh.max_element_area = opt.mesh.max_patch_area;
  const auto t0 = std::chrono::steady_clock::now();
  const radiosity::Solution sol = radiosity::solve(scene, opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const radiosity::SolveReport& r = sol.report();
  std::printf("%7zu patches %7zu elements  %-13s total %7.2f s (form factors %7.2f s, solve %6.2f s)  "
              "%6d iterations  residual %.2e  peak RSS %7.1f MiB  form factors %7.1f MiB\n",
              r.patch_count, r.element_count, name, seconds, r.seconds_form_factors, r.seconds_solving, r.iterations,
              r.residual, usage.ru_maxrss / 1024.0, r.form_factor_bytes / (1024.0 * 1024.0));
  std::fflush(stdout);
  return 0;
}

double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

/// Accuracy of the Monte Carlo estimator: Gauss-Seidel solutions on one mesh with the accurate
/// ray-cast factors (seed 1) and then with ray_cast at seed 2 (the reference's own noise) and
/// monte_carlo at several ray counts; prints the area-weighted RMS difference of reflector
/// element radiosity (summed over channels) over their RMS, and the largest difference of a
/// group's mean. Emitters are left out (their emission dominates).
void compare(std::size_t target_patches) {
  const radiosity::Scene scene = radiosity::cornell_box();
  radiosity::SolveOptions opt;
  opt.tolerance = 1e-4;
  opt.threads = 2;
  opt.mesh.max_patch_area = static_cast<float>(scene.total_area() / static_cast<double>(target_patches));
  opt.mesh.max_element_area = opt.mesh.max_patch_area;
  opt.form_factors.method = radiosity::FormFactorMethod::ray_cast;
  // The reference: ray_cast with 16 source samples and 16 visibility rays (4x4 its defaults),
  // so its own noise is well below the candidates'.
  opt.form_factors.source_samples = 16;
  opt.form_factors.visibility_rays = 16;
  double c0 = cpu_seconds();
  const radiosity::Solution ref = radiosity::solve(scene, opt);
  std::printf("compare: %zu elements; ray_cast reference (16 x 16 samples) %.1f s CPU\n",
              ref.report().element_count, cpu_seconds() - c0);
  const radiosity::FormFactorOptions defaults;
  auto sum3 = [](const radiosity::Rgb& c) { return static_cast<double>(c.x) + c.y + c.z; };
  // 0: ray_cast at its defaults; 1: ray_cast with one source sample and one visibility ray
  // (its cheapest); others: monte_carlo with that many rays.
  for (std::uint32_t rays : {0u, 1u, 256u, 1024u, 4096u, 16384u}) {
    opt.form_factors.method = rays <= 1 ? radiosity::FormFactorMethod::ray_cast : radiosity::FormFactorMethod::monte_carlo;
    opt.seed = 2;
    opt.form_factors.source_samples = rays == 1 ? 1 : defaults.source_samples;
    opt.form_factors.visibility_rays = rays == 1 ? 1 : defaults.visibility_rays;
    if (rays > 1) opt.form_factors.hemisphere_rays = rays;
    c0 = cpu_seconds();
    const radiosity::Solution mc = radiosity::solve(scene, opt);
    const double cpu = cpu_seconds() - c0;
    double num = 0.0, den = 0.0;
    for (std::uint32_t e : ref.hierarchy().leaves()) {
      const radiosity::Patch& patch = ref.hierarchy().patches()[ref.hierarchy().element(e).patch];
      if (sum3(scene.material(scene.polygons()[patch.polygon].material).emission) > 0.0)
        continue;
      const double a = ref.hierarchy().element(e).area;
      const double d = sum3(mc.radiosity()[e]) - sum3(ref.radiosity()[e]);
      num += a * d * d;
      den += a * sum3(ref.radiosity()[e]) * sum3(ref.radiosity()[e]);
    }
    if (std::getenv("BENCH_DEBUG")) {
      std::vector<std::pair<double, std::uint32_t>> v;
      for (std::uint32_t e : ref.hierarchy().leaves()) {
        const double d = sum3(mc.radiosity()[e]) - sum3(ref.radiosity()[e]);
        v.emplace_back(ref.hierarchy().element(e).area * d * d, e);
      }
      std::sort(v.rbegin(), v.rend());
      for (int k = 0; k < 6; ++k) {
        const auto e = v[static_cast<std::size_t>(k)].second;
        const auto& el = ref.hierarchy().element(e);
        std::printf("    %s (%.0f %.0f %.0f) ref %.3f mc %.3f\n", scene.groups()[ref.hierarchy().patches()[el.patch].group].c_str(),
                    el.centroid.x, el.centroid.y, el.centroid.z, sum3(ref.radiosity()[e]), sum3(mc.radiosity()[e]));
      }
    }
    double worst = 0.0;
    for (const std::string& g : scene.groups())
      worst = std::max(worst, std::fabs(sum3(mc.group_radiosity(g)) / sum3(ref.group_radiosity(g)) - 1.0));
    char label[64];
    if (rays == 0)
      std::snprintf(label, sizeof label, "ray_cast, seed 2");
    else if (rays == 1)
      std::snprintf(label, sizeof label, "ray_cast 1 x 1");
    else
      std::snprintf(label, sizeof label, "monte_carlo %u rays", rays);
    std::printf("  %-22s reflectors' RMS difference / RMS radiosity %5.2f %%, worst group mean %5.2f %%, "
                "%.2f s CPU (form factors %.2f s wall)\n",
                label, 100.0 * std::sqrt(num / den), 100.0 * worst, cpu, mc.report().seconds_form_factors);
    std::fflush(stdout);
  }
}

/// `radiosity solve` with default options on the Cornell box meshed to about `target_patches`
/// patches: the automatic estimator's total time (wall, 2 cores), against ray_cast's.
void defaults(std::size_t target_patches) {
  const radiosity::Scene scene = radiosity::cornell_box();
  auto timed = [&](radiosity::FormFactorMethod method) {
    radiosity::SolveOptions opt;  // defaults, as `radiosity solve` uses them
    opt.mesh.max_patch_area = static_cast<float>(scene.total_area() / static_cast<double>(target_patches));
    opt.mesh.max_element_area = opt.mesh.max_patch_area;
    opt.form_factors.method = method;
    const auto t0 = std::chrono::steady_clock::now();
    const radiosity::Solution sol = radiosity::solve(scene, opt);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("  %-10s -> %-12s %6zu patches  total %6.2f s (form factors %6.2f s, solve %5.2f s)\n",
                radiosity::to_string(method), radiosity::to_string(sol.report().form_factor_method),
                sol.report().patch_count, seconds, sol.report().seconds_form_factors, sol.report().seconds_solving);
    std::fflush(stdout);
    return seconds;
  };
  std::printf("bench_solvers --defaults: default SolveOptions, Cornell box at about %zu patches\n", target_patches);
  const double automatic = timed(radiosity::FormFactorMethod::automatic);
  const double ray_cast = timed(radiosity::FormFactorMethod::ray_cast);
  std::printf("  automatic / ray_cast time: %.3f (target: automatic under 1 s at 4000 patches on 2 cores)\n",
              automatic / ray_cast);
}

/// A kept Problem solved again for other emission (relighting): each method's first solve
/// (form factors and sweeps) against a relit solve of the same Problem, which reuses the factors
/// (matrix rows, progressive's columns), in one run. The relit emission halves the light and
/// makes the tall block's faces glow, so the solve is a new one, not a repeat.
void relight(std::size_t target_patches) {
  const radiosity::Scene scene = radiosity::cornell_box();
  std::vector<radiosity::Rgb> emission(scene.polygons().size(), radiosity::Rgb(0.0f));
  std::size_t glowing = 0;
  for (std::size_t p = 0; p < scene.polygons().size(); ++p) {
    const radiosity::Polygon& polygon = scene.polygons()[p];
    emission[p] = 0.5f * scene.material(polygon.material).emission;
    if (scene.groups()[polygon.group] == "tall_block") {
      emission[p] = radiosity::Rgb(2.0f, 4.0f, 8.0f);
      ++glowing;
    }
  }
  std::printf("bench_solvers --relight: Cornell box at about %zu patches, monte_carlo, 2 threads; relit: the "
              "light at half and %zu faces of the tall block emitting\n",
              target_patches, glowing);
  for (radiosity::SolverMethod method : {radiosity::SolverMethod::gauss_seidel, radiosity::SolverMethod::progressive}) {
    radiosity::SolveOptions opt;
    opt.method = method;
    opt.threads = 2;
    opt.form_factors.method = radiosity::FormFactorMethod::monte_carlo;
    opt.mesh.max_patch_area = static_cast<float>(scene.total_area() / static_cast<double>(target_patches));
    opt.mesh.max_element_area = opt.mesh.max_patch_area;
    radiosity::Problem problem(scene, opt);
    auto timed = [&](const std::vector<radiosity::Rgb>* e) {
      const auto t0 = std::chrono::steady_clock::now();
      const radiosity::Solution sol = e ? problem.solve(*e) : problem.solve();
      return std::pair<double, int>(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                                    sol.report().iterations);
    };
    const auto first = timed(nullptr);
    const auto relit = timed(&emission);
    std::printf("  %-13s %6zu patches  first solve %6.2f s (%d iterations), relit %6.3f s (%d iterations): "
                "relit / first %.3f, factors kept %.1f MiB\n",
                method == radiosity::SolverMethod::progressive ? "progressive" : "gauss-seidel",
                problem.hierarchy().patches().size(), first.first, first.second, relit.first, relit.second,
                relit.first / first.first, problem.form_factor_bytes() / (1024.0 * 1024.0));
    std::fflush(stdout);
  }
}

}  // namespace

/// A positive integer argument, or 0 when `text` is not one.
std::size_t count_arg(const char* text) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  return (end != text && *end == '\0' && text[0] != '-') ? static_cast<std::size_t>(v) : 0;
}

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_solvers: bad argument '%s'\n", bad);
  std::fprintf(stderr,
               "usage: bench_solvers [--ray-cast] [--rays N] [--only jacobi|gauss-seidel|progressive] [PATCHES...]\n"
               "       bench_solvers --compare PATCHES\n"
               "       bench_solvers --defaults [PATCHES]\n"
               "       bench_solvers --relight [PATCHES]\n");
  return bad ? 2 : 0;
}

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--help" || arg == "-h") return usage(nullptr);
    if (arg == "--compare" && has_value) {
      const std::size_t n = count_arg(argv[++i]);
      if (n == 0) return usage(argv[i]);
      compare(n);
      return 0;
    }
    if (arg == "--defaults") {
      std::size_t n = 4000;
      if (has_value && (n = count_arg(argv[i + 1])) != 0)
        ++i;
      else
        n = 4000;
      defaults(n);
      return 0;
    }
    if (arg == "--relight") {
      std::size_t n = 4000;
      if (has_value && (n = count_arg(argv[i + 1])) != 0)
        ++i;
      else
        n = 4000;
      relight(n);
      return 0;
    }
    if (arg == "--only" && has_value) {
      g_only = argv[++i];
      if (g_only != "jacobi" && g_only != "gauss-seidel" && g_only != "progressive") return usage(argv[i]);
    } else if (arg == "--ray-cast") {
      g_estimator = radiosity::FormFactorMethod::ray_cast;
    } else if (arg == "--rays" && has_value) {
      g_rays = static_cast<std::uint32_t>(count_arg(argv[++i]));
      if (g_rays == 0) return usage(argv[i]);
    } else {
      const std::size_t n = count_arg(argv[i]);
      if (n == 0) return usage(argv[i]);
      sizes.push_back(n);
    }
  }
  if (sizes.empty()) sizes = {4000};
  const struct {
    radiosity::SolverMethod method;
    const char* name;
  } methods[] = {{radiosity::SolverMethod::jacobi, "jacobi"},
                 {radiosity::SolverMethod::gauss_seidel, "gauss-seidel"},
                 {radiosity::SolverMethod::progressive, "progressive"}};
  std::printf("bench_solvers: radiosity %s, obstructed Cornell box, tolerance 1e-3, 2 threads\n",
              radiosity::version());
  for (std::size_t n : sizes)
    for (const auto& m : methods) {
      if (!g_only.empty() && g_only != m.name) continue;
      std::fflush(stdout);  // the child must not inherit (and print again) buffered output
      const pid_t pid = fork();
      if (pid == 0) {
        try {
          _exit(run(n, m.method, m.name));
        } catch (const std::exception& e) {
          std::printf("%7zu patches  %-13s error: %s\n", n, m.name, e.what());
          std::fflush(stdout);
          _exit(1);
        }
      }
      int status = 0;
      waitpid(pid, &status, 0);
    }
  return 0;
}
