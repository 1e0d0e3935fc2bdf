// The `radiosity` command-line tool: render, solve, factors, check and bake.
// Output formats are a contract that scripts parse: see docs/CLI.md.
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "cli_common.hpp"
#include "bake.hpp"
#include "check.hpp"
#include "cli_mpi.hpp"
#include "factors.hpp"

#if RADIOSITY_HAS_MPI
#include "radiosity/mpi.hpp"
#endif

using namespace cli;

int main(int argc, char** argv) {
  // Under mpirun, factors and solve --method jacobi split their work among the processes
  // (docs/MPI.md); rank 0 prints and writes, the other ranks are silent.
  const MpiSession mpi(argc, argv);
  CLI::App app{"radiosity " + std::string(rad::version()) +
               ": global illumination by the radiosity method.\nWith no SCENE, the built-in Cornell box is used."};
  app.require_subcommand(1);

  // render
  SolveArgs render_args;
  std::string out = "radiosity.exr", png;
  bool no_png = false, no_default_light = false;
  int width = 512, height = 512, spp = 0;
  std::string eye, look_at, up;
  float fov = 0.0f;
  float exposure = 0.0f;  // 0: automatic (preview_exposure())
  CLI::App* render = app.add_subcommand("render", "Solve and render a scene to EXR (linear) and PNG (preview)");
  render->add_option("scene", render_args.scene, kSceneHelp);
  render->add_option("-o,--output", out, "EXR output (a .png name writes the sRGB preview alone)")->capture_default_str();
  render->add_option("--png", png, "PNG preview (default: the EXR path with .png)");
  render->add_flag("--no-png", no_png, "Do not write a PNG preview");
  render->add_flag("--no-default-light", no_default_light,
                   "Render a scene without lights or emitting materials black (by default a uniform sky of 1 W/m^2 "
                   "lights it, so that it shows)");
  render->add_option("--width", width, "Image width")->check(positive<int>())->capture_default_str();
  render->add_option("--height", height, "Image height")->check(positive<int>())->capture_default_str();
  render
      ->add_option("--spp", spp,
                   "Stratified samples per pixel, rounded up to a square (default 4, two-pass: 16, path: 256)")
      ->check(positive<int>());
  render->add_option("--eye", eye, "Camera position x,y,z")->check(vec3_check());
  render->add_option("--look-at", look_at, "Camera target x,y,z")->check(vec3_check());
  render->add_option("--up", up, "Camera up vector x,y,z")->check(vec3_check());
  render->add_option("--fov", fov, "Vertical field of view, degrees")->check(in_range<float>(0.0f, 180.0f));
  render->add_option("--exposure", exposure,
                     "PNG exposure (linear scale; default: 1 unless the image would be mostly clipped or dark, "
                     "then the 95th percentile of its lit pixels shows at 0.8)")
      ->check(any_number<float>());
  std::string mode_name = "auto";
  render
      ->add_option("--mode", mode_name,
                   "Pipeline: auto (two-pass when some material is specular or transmitting, else radiosity), "
                   "radiosity, two-pass or path (the reference path tracer)")
      ->check(CLI::IsMember(render_mode_names()))
      ->capture_default_str();
  bool wireframe = false, ambient = false;
  render->add_flag("--wireframe", wireframe, "Draw the element mesh over the image");
  render->add_flag("--ambient", ambient, "Add progressive refinement's ambient term to the display");
  int max_depth = 0;
  render->add_option("--max-depth", max_depth, "Path tracer: reflections at most (0 = unlimited, Russian roulette)")
      ->check(non_negative<int>());
  bool two_pass = false, pass1_only = false, direct_only = false;
  std::size_t photons = 200000;
  render->add_flag("--two-pass", two_pass,
                   "Same as --mode two-pass: radiosity, then ray-traced mirrors, glass and glossy lobes, and "
                   "photon-mapped caustics; the EXR gets layers direct, indirect, specular, caustic");
  render->add_flag("--pass1-only", pass1_only, "Two-pass: diffuse interreflection only, no specular pass");
  render->add_flag("--direct-only", direct_only, "Two-pass: direct illumination only");
  render->add_option("--photons", photons, "Two-pass: caustic photons (0 = no caustics)")
      ->check(any_number<std::size_t>())
      ->capture_default_str();
  add_solve_options(*render, render_args, true);

  // solve
  SolveArgs solve_args;
  std::string stats, ply;
  CLI::App* solve = app.add_subcommand("solve", "Solve a scene; write statistics (JSON) and a coloured mesh (PLY)");
  solve->add_option("scene", solve_args.scene, kSceneHelp);
  solve->add_option("--stats", stats, "Write statistics JSON here");
  solve->add_option("--ply", ply, "Write the solution as a PLY mesh with per-vertex colours");
  add_solve_options(*solve, solve_args);

  Command factors = add_factors_command(app);
  Command check = add_check_command(app);
  Command bake = add_bake_command(app);

  if (const std::optional<int> code = parse_command_line(app, argc, argv)) return *code;
  // The rest is not split: rank 0 runs it alone (the others would only repeat it).
  const bool split = *factors.app || (*solve && solve_args.method == "jacobi");
  if (process_count() > 1 && !split) {
    if (process_rank() != 0) return 0;
    std::fprintf(stderr, "radiosity: note: only factors and solve --method jacobi are split among MPI processes; "
                         "rank 0 runs this alone\n");
  }
  if (*factors.app) return factors.run();
  if (*check.app) return check.run();
  if (*bake.app) return bake.run();

  // What the user asked of the render pipeline; contradictions are argument errors.
  ModeRequest requested;
  if (*render) {
    const std::string conflict =
        pass1_only && direct_only
            ? "--pass1-only and --direct-only exclude each other"
            : requested.add(render_mode_from_name(mode_name), "--mode " + mode_name)
                  .add(render_args.method == "path" ? rad::RenderMode::path : rad::RenderMode::automatic,
                       "--method path")
                  .add(two_pass ? rad::RenderMode::two_pass : rad::RenderMode::automatic, "--two-pass")
                  .add(pass1_only ? rad::RenderMode::two_pass : rad::RenderMode::automatic, "--pass1-only")
                  .add(direct_only ? rad::RenderMode::two_pass : rad::RenderMode::automatic, "--direct-only")
                  .conflict;
    if (!conflict.empty()) return argument_error("render", conflict);
    // `-o image.png` asks for a PNG: the preview goes there, and no EXR is written (it was
    // written and then overwritten by the preview, and said so twice).
    if (lower_extension(out) == ".png" && no_png)
      return argument_error("render", "-o " + out + " names a PNG and --no-png asks for none: nothing would be written");
    if (lower_extension(out) == ".png" && !png.empty())
      return argument_error("render", "-o " + out + " writes the PNG preview and --png names a second one (give -o "
                                      "FILE.exr --png FILE.png for both)");
    if (render_args.light_groups && requested.mode == rad::RenderMode::path)
      return argument_error("render", "--light-groups needs a solve: --mode radiosity, two-pass or auto (the path "
                                      "tracer solves nothing)");
  }

  return run_guarded([&] {
    ProgressBar bar;
    if (*render) {
      rad::Scene scene = load(render_args.scene, render_args.strict, render_args.photometric, {render_args.two_sided, render_args.reverse_winding});
      print_load_notes(scene);
      // A scene without any light (an STL, a PLY, an OBJ without an emitting material) would
      // render black: as a modeller's viewport does, a preview lights it, by a uniform sky
      // around the scene's up (the camera choice's), and says so. solve, bake and the library
      // keep such a scene dark (it is the physical answer; they warn).
      if (!no_default_light && !has_light(scene)) {
        const glm::vec3 zenith = rad::choose_camera(scene).camera.up;
        rad::Light sky;
        sky.type = rad::LightType::sky;
        sky.intensity = 1.0f;
        sky.direction = zenith;
        scene.add_light(sky);
        std::printf("light: the scene has none: lit by a uniform sky of 1 W/m^2 around %s (the scene's up) so that "
                    "it shows; give it lights or emitting materials, or --no-default-light to render it black\n",
                    axis_name(zenith).c_str());
      }
      // A scene without a camera (an OBJ, STL or PLY has none) gets one chosen for it, said
      // unless --eye and --look-at place it.
      const rad::CameraChoice chosen = rad::choose_camera(scene);
      if (!scene.has_camera() && (eye.empty() || look_at.empty()))
        std::printf("camera: %s; --eye and --look-at override\n", chosen.reason.c_str());
      std::optional<rad::Camera> camera = chosen.camera;
      if (!eye.empty() || !look_at.empty() || !up.empty() || fov > 0.0f) {
        rad::Camera c = chosen.camera;
        if (!eye.empty()) c.eye = parse_point(eye, "--eye", scene);
        if (!look_at.empty()) c.look_at = parse_point(look_at, "--look-at", scene);
        if (!up.empty()) c.up = parse_vec3(up, "--up");
        if (fov > 0.0f) c.fov_deg = fov;
        scene.set_camera(c);  // validates
        camera = c;
      }
      // What the three renderers' options share (rad::ImageOptions); spp defaults per renderer.
      auto image_options = [&](rad::ImageOptions& o, int default_spp) {
        o.width = width;
        o.height = height;
        o.spp = spp > 0 ? spp : default_spp;
        o.camera = camera;
        o.threads = render_args.threads;
        o.seed = render_args.seed;
        o.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
      };
      // The pipeline: as asked, else the one the scene needs.
      const rad::RenderMode needed = rad::choose_render_mode(scene);
      const rad::RenderMode mode = requested.mode == rad::RenderMode::automatic ? needed : requested.mode;
      std::string why = requested.mode == rad::RenderMode::automatic ? "automatic: " : requested.source;
      if (requested.mode == rad::RenderMode::automatic)
        why += mode == rad::RenderMode::radiosity  ? "every material is diffuse"
               : rad::needs_extended_first_pass(scene) ? "the scene has mirror or glass materials"
                                                       : "the scene has glossy materials";
      else if (mode == rad::RenderMode::radiosity && needed == rad::RenderMode::two_pass)
        why += "; specular materials are shown as diffuse";
      rad::SolveOptions solve_options = to_options(render_args, bar);
      if (mode == rad::RenderMode::two_pass) {
        // The extended first pass (mirror and window form factors) where the scene has mirrors
        // or glass, unless the user chose otherwise.
        prepare_pass1(scene, solve_options, render_args);
        why += "; pass 1 with " + form_factor_name(solve_options.form_factors.method) +
               " form factors and specular depth " + std::to_string(solve_options.form_factors.specular_depth);
      }
      std::printf("mode: %s (%s)\n", rad::to_string(mode), why.c_str());
      std::fflush(stdout);
      // --light-groups: one layer per light group, the image of that group's light alone (its
      // emitters and lights, and its share of pass 1).
      auto add_light_group_layers = [](rad::Image& image, const rad::Solution& sol,
                                       const std::function<rad::Image(const rad::Solution&)>& draw) {
        for (std::size_t k = 0; k < sol.light_groups().size(); ++k)
          image.layers.emplace_back("light_group_" + sol.light_groups()[k].name,
                                    draw(light_group_alone(sol, k)).pixels);
      };

      rad::Image image;
      if (mode == rad::RenderMode::path) {
        // The reference: an unbiased path tracer, no radiosity solve.
        rad::PathTraceOptions po;
        image_options(po, 256);
        po.max_depth = max_depth;
        image = rad::render_path_traced(scene, po);
        bar.finish();
        std::printf("path traced: %d samples per pixel\n", po.spp);
      } else if (mode == rad::RenderMode::two_pass) {
        // Pass 1: radiosity; with the Monte Carlo estimator and --specular-depth it carries mirror
        // and window form factors (the extended first pass).
        rad::Solution sol = rad::solve(scene, solve_options);
        bar.finish();
        print_summary(sol);
        print_estimator(sol, solve_options);
        print_solve_warnings(scene, sol);
        rad::TwoPassOptions to;
        image_options(to, 16);
        to.ambient = ambient;
        to.caustics.photons = photons;
        to.content = direct_only  ? rad::TwoPassContent::direct_only
                     : pass1_only ? rad::TwoPassContent::pass1_only
                                  : rad::TwoPassContent::full;
        rad::TwoPassReport report;
        image = rad::render_two_pass(scene, sol, to, report);
        add_light_group_layers(image, sol,
                               [&](const rad::Solution& part) { return rad::render_two_pass(scene, part, to); });
        bar.finish();
        std::printf("two-pass: %d samples per pixel, %zu of %zu caustic photons stored\n", to.spp,
                    report.photons_stored, report.photons_emitted);
      } else {
        rad::Solution sol = rad::solve(scene, solve_options);
        bar.finish();
        print_summary(sol);
        print_estimator(sol, solve_options);
        print_solve_warnings(scene, sol);
        rad::RenderOptions ro;
        image_options(ro, 4);
        ro.wireframe = wireframe;
        ro.ambient = ambient;
        image = rad::render(scene, sol, ro);
        add_light_group_layers(image, sol, [&](const rad::Solution& part) { return rad::render(scene, part, ro); });
        bar.finish();
      }
      if (lower_extension(out) == ".png") {
        png = out;
      } else {
        rad::write_exr(image, out);
        std::string layers;
        for (const auto& layer : image.layers) layers += (layers.empty() ? "; layers " : ", ") + layer.first;
        std::printf("wrote %s (%dx%d, linear float RGB%s)\n", std::filesystem::absolute(out).c_str(), width, height,
                    layers.c_str());
      }
      if (!no_png) {
        if (png.empty()) png = std::filesystem::path(out).replace_extension(".png").string();
        rad::PngOptions po;
        po.exposure = exposure;
        if (!(exposure > 0.0f)) {
          std::vector<float> values;
          values.reserve(image.pixels.size());
          for (const rad::Rgb& p : image.pixels) values.push_back(std::max({p.x, p.y, p.z}));
          std::string exposure_why;
          po.exposure = preview_exposure(std::move(values), exposure_why);
          if (!exposure_why.empty())
            std::printf("preview exposure: %.4g (automatic: %s; --exposure overrides)\n", po.exposure,
                        exposure_why.c_str());
        }
        rad::write_png(image, png, po);
        std::printf("wrote %s (sRGB preview, exposure %g)\n", std::filesystem::absolute(png).c_str(), po.exposure);
      }
    } else if (*solve) {
      rad::Scene scene = load(solve_args.scene, solve_args.strict, solve_args.photometric, {solve_args.two_sided, solve_args.reverse_winding});
      print_load_notes(scene);
      rad::SolveOptions options = to_options(solve_args, bar);
      apply_specular_depth(options, solve_args);
#if RADIOSITY_HAS_MPI
      // Jacobi split among the processes: every rank gets the whole solution; rank 0 reports it.
      rad::Solution sol = process_count() > 1 ? rad::mpi::solve(scene, options, MPI_COMM_WORLD) : rad::solve(scene, options);
#else
      rad::Solution sol = rad::solve(scene, options);
#endif
      bar.finish();
      if (process_rank() != 0) return 0;
      if (process_count() > 1)
        std::printf("mpi: Jacobi split among %d processes (form-factor rows and lights by blocks of unknowns)\n",
                    process_count());
      print_summary(sol);
      print_estimator(sol, options);
      print_solve_warnings(scene, sol);
      for (const std::string& g : sol.groups()) {
        rad::Rgb b = sol.group_radiosity(g);
        std::printf("  %-16s B = (%.5g, %.5g, %.5g)  area %.6g", g.c_str(), b.x, b.y, b.z, sol.group_area(g));
        // Two-sided and translucent groups: their back side too.
        const rad::Rgb back = sol.group_back_radiosity(g);
        if (!sol.back_radiosity().empty() && (back.x > 0.0f || back.y > 0.0f || back.z > 0.0f))
          std::printf("  back B = (%.5g, %.5g, %.5g)", back.x, back.y, back.z);
        std::printf("\n");
      }
      // Each light group's share of each group (--light-groups).
      for (std::size_t k = 0; k < sol.light_groups().size(); ++k) {
        std::printf("light group %s:\n", sol.light_groups()[k].name.c_str());
        for (const std::string& g : sol.groups()) {
          const rad::Rgb b = sol.light_group_radiosity(k, g);
          std::printf("  %-16s B = (%.5g, %.5g, %.5g)\n", g.c_str(), b.x, b.y, b.z);
        }
      }
      if (!stats.empty()) {
        rad::write_stats_json(sol, stats, options, solve_args.scene.empty() ? "cornell-box" : solve_args.scene);
        std::printf("wrote %s\n", stats.c_str());
      }
      if (!ply.empty()) {
        rad::write_ply(sol, ply);
        std::printf("wrote %s\n", ply.c_str());
      }
    }
    return 0;
  });
}
