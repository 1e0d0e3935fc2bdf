// The `radiosity` command-line tool: render, solve and (with the form-factor issue) factors.
// Output formats are a contract that scripts parse: see docs/CLI.md.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "radiosity/radiosity.hpp"

namespace {

namespace rad = radiosity;

/// A one-line progress bar with rate and ETA on a terminal; silent when stderr is not a tty.
class ProgressBar {
 public:
  ProgressBar() : enabled_(isatty(STDERR_FILENO) != 0) {}
  ~ProgressBar() { finish(); }

  bool update(const rad::Progress& p) {
    if (!enabled_) return true;
    auto now = std::chrono::steady_clock::now();
    if (p.phase != phase_ || !started_) {
      finish();
      phase_ = p.phase;
      started_ = true;
      start_ = now;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double f = std::clamp(p.fraction, 0.0, 1.0);
    const int width = 30, filled = static_cast<int>(f * width);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(width, '.');
    char line[200];
    if (p.phase == rad::Phase::solving) {
      std::snprintf(line, sizeof line, "\r%-13s [%s] %3.0f%%  it %d  residual %.2e  %.1f it/s ", name(p.phase),
                    bar.c_str(), 100 * f, p.iteration, p.residual, elapsed > 0 ? p.iteration / elapsed : 0.0);
    } else {
      const double eta = f > 0 ? elapsed * (1 - f) / f : 0.0;
      std::snprintf(line, sizeof line, "\r%-13s [%s] %3.0f%%  %.1f%%/s  ETA %.0fs ", name(p.phase), bar.c_str(),
                    100 * f, elapsed > 0 ? 100 * f / elapsed : 0.0, eta);
    }
    std::fputs(line, stderr);
    dirty_ = true;
    return true;
  }

  void finish() {
    if (dirty_) std::fputs("\n", stderr);
    dirty_ = false;
  }

 private:
  static const char* name(rad::Phase p) {
    switch (p) {
      case rad::Phase::meshing: return "meshing";
      case rad::Phase::form_factors: return "form factors";
      case rad::Phase::solving: return "solving";
      case rad::Phase::refining: return "refining";
      case rad::Phase::rendering: return "rendering";
    }
    return "";
  }

  bool enabled_;
  bool started_ = false;
  bool dirty_ = false;
  rad::Phase phase_ = rad::Phase::meshing;
  std::chrono::steady_clock::time_point start_;
};

struct SolveArgs {
  std::string scene;
  std::string method = "gauss-seidel";
  std::string form_factors = "ray-cast";
  float max_patch_area = 0.0f;
  float max_element_area = 0.0f;
  double tolerance = 1e-3;
  unsigned threads = 0;
  std::uint64_t seed = 1;
  int max_iterations = 0;
};

void add_solve_options(CLI::App& cmd, SolveArgs& a) {
  cmd.add_option("--method", a.method, "Solver")
      ->check(CLI::IsMember({"jacobi", "gauss-seidel", "progressive"}))
      ->capture_default_str();
  cmd.add_option("--form-factors", a.form_factors, "Form-factor estimator")
      ->check(CLI::IsMember({"ray-cast", "analytic"}))
      ->capture_default_str();
  cmd.add_option("--max-patch-area", a.max_patch_area, "Largest patch, scene units^2 (0 = derive)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--max-element-area", a.max_element_area, "Largest element, scene units^2 (0 = derive)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--tolerance", a.tolerance, "Stop when unshot/emitted power falls below this")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd.add_option("--max-iterations", a.max_iterations, "Sweeps or shooting steps at most (0 = default)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--threads", a.threads, "Worker threads (0 = all cores)");
  cmd.add_option("--seed", a.seed, "Random seed (results are identical for a seed at any thread count)")
      ->capture_default_str();
}

rad::SolveOptions to_options(const SolveArgs& a, ProgressBar& bar) {
  rad::SolveOptions o;
  o.method = a.method == "jacobi"        ? rad::SolverMethod::jacobi
             : a.method == "progressive" ? rad::SolverMethod::progressive
                                         : rad::SolverMethod::gauss_seidel;
  o.form_factors.method =
      a.form_factors == "analytic" ? rad::FormFactorMethod::analytic : rad::FormFactorMethod::ray_cast;
  o.mesh.max_patch_area = a.max_patch_area;
  o.mesh.max_element_area = a.max_element_area;
  o.tolerance = a.tolerance;
  o.max_iterations = a.max_iterations;
  o.threads = a.threads;
  o.seed = a.seed;
  o.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
  return o;
}

rad::Scene load(const std::string& path) {
  if (path.empty() || path == "cornell-box") return rad::cornell_box();
  return rad::load_scene(path);
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
}

void print_summary(const rad::Solution& sol) {
  const rad::SolveReport& r = sol.report();
  const char* status = sol.status() == rad::SolveStatus::converged       ? "converged"
                       : sol.status() == rad::SolveStatus::iteration_cap ? "iteration cap"
                                                                         : "cancelled";
  std::printf("solved: %zu patches, %zu elements, %d iterations, residual %.3g (%s)\n", r.patch_count,
              r.element_count, r.iterations, r.residual, status);
  std::printf("time: meshing %.3f s, form factors %.3f s, solving %.3f s\n", r.seconds_meshing,
              r.seconds_form_factors, r.seconds_solving);
}

glm::vec3 parse_vec3(const std::string& s, const char* name) {
  glm::vec3 v;
  char c1 = 0, c2 = 0;
  std::istringstream in(s);
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !in.eof())
    throw CLI::ValidationError(name, "expected x,y,z, got '" + s + "'");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"radiosity " + std::string(rad::version()) +
               ": global illumination by the radiosity method.\nWith no SCENE, the built-in Cornell box is used."};
  app.require_subcommand(1);

  // render
  SolveArgs render_args;
  std::string out = "radiosity.exr", png;
  bool no_png = false;
  int width = 512, height = 512, spp = 4;
  std::string eye, look_at, up;
  float fov = 0.0f;
  float exposure = 1.0f;
  CLI::App* render = app.add_subcommand("render", "Solve and render a scene to EXR (linear) and PNG (preview)");
  render->add_option("scene", render_args.scene, "OBJ file (default: the built-in Cornell box)");
  render->add_option("-o,--output", out, "EXR output")->capture_default_str();
  render->add_option("--png", png, "PNG preview (default: the EXR path with .png)");
  render->add_flag("--no-png", no_png, "Do not write a PNG preview");
  render->add_option("--width", width, "Image width")->check(CLI::PositiveNumber)->capture_default_str();
  render->add_option("--height", height, "Image height")->check(CLI::PositiveNumber)->capture_default_str();
  render->add_option("--spp", spp, "Stratified samples per pixel (rounded up to a square)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  render->add_option("--eye", eye, "Camera position x,y,z");
  render->add_option("--look-at", look_at, "Camera target x,y,z");
  render->add_option("--up", up, "Camera up vector x,y,z");
  render->add_option("--fov", fov, "Vertical field of view, degrees")->check(CLI::Range(0.0f, 180.0f));
  render->add_option("--exposure", exposure, "PNG exposure (linear scale)")->capture_default_str();
  add_solve_options(*render, render_args);

  // solve
  SolveArgs solve_args;
  std::string stats, ply;
  CLI::App* solve = app.add_subcommand("solve", "Solve a scene; write statistics (JSON) and a coloured mesh (PLY)");
  solve->add_option("scene", solve_args.scene, "OBJ file (default: the built-in Cornell box)");
  solve->add_option("--stats", stats, "Write statistics JSON here");
  solve->add_option("--ply", ply, "Write the solution as a PLY mesh with per-vertex colours");
  add_solve_options(*solve, solve_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    ProgressBar bar;
    if (*render) {
      rad::Scene scene = load(render_args.scene);
      print_warnings(scene.warnings());
      rad::Solution sol = rad::solve(scene, to_options(render_args, bar));
      bar.finish();
      print_summary(sol);
      rad::RenderOptions ro;
      ro.width = width;
      ro.height = height;
      ro.spp = spp;
      ro.threads = render_args.threads;
      ro.seed = render_args.seed;
      if (!eye.empty() || !look_at.empty() || !up.empty() || fov > 0.0f) {
        rad::Camera c = scene.camera();
        if (!eye.empty()) c.eye = parse_vec3(eye, "--eye");
        if (!look_at.empty()) c.look_at = parse_vec3(look_at, "--look-at");
        if (!up.empty()) c.up = parse_vec3(up, "--up");
        if (fov > 0.0f) c.fov_deg = fov;
        scene.set_camera(c);  // validates
        ro.camera = c;
      }
      ro.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
      rad::Image image = rad::render(scene, sol, ro);
      bar.finish();
      rad::write_exr(image, out);
      std::printf("wrote %s (%dx%d, linear float RGB)\n", std::filesystem::absolute(out).c_str(), width, height);
      if (!no_png) {
        if (png.empty()) png = std::filesystem::path(out).replace_extension(".png").string();
        rad::PngOptions po;
        po.exposure = exposure;
        rad::write_png(image, png, po);
        std::printf("wrote %s (sRGB preview, exposure %g)\n", std::filesystem::absolute(png).c_str(), exposure);
      }
    } else if (*solve) {
      rad::Scene scene = load(solve_args.scene);
      print_warnings(scene.warnings());
      rad::Solution sol = rad::solve(scene, to_options(solve_args, bar));
      bar.finish();
      print_summary(sol);
      for (const std::string& g : sol.groups()) {
        rad::Rgb b = sol.group_radiosity(g);
        std::printf("  %-16s B = (%.5g, %.5g, %.5g)  area %.6g\n", g.c_str(), b.x, b.y, b.z, sol.group_area(g));
      }
      if (!stats.empty()) {
        rad::write_stats_json(sol, stats);
        std::printf("wrote %s\n", stats.c_str());
      }
      if (!ply.empty()) {
        rad::write_ply(sol, ply);
        std::printf("wrote %s\n", ply.c_str());
      }
    }
  } catch (const rad::Error& e) {
    std::fprintf(stderr, "radiosity: error: %s\n", e.what());
    return 1;
  } catch (const CLI::ValidationError& e) {
    std::fprintf(stderr, "radiosity: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "radiosity: unexpected error: %s\n", e.what());
    return 3;
  }
  return 0;
}
