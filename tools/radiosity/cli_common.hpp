// Pieces shared by the subcommands of the `radiosity` CLI.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/common.hpp>

#include "radiosity/radiosity.hpp"

namespace cli {

namespace rad = radiosity;

// Number checks with readable messages, for options of type T. CLI11's PositiveNumber,
// NonNegativeNumber and Range print the bounds of `double` in full (hundreds of digits) and call
// "abc" out of range; these say "'abc' is not a number" or "must be > 0 (got -1)", and CLI11
// prefixes the option's name. The type's own range counts too (an unsigned option refuses -1).

/// A path's extension in lower case, with its dot (".png"; "" when it has none).
inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// `s` as a number when all of it is one (an integer for integral T) and finite, else nullopt.
template <typename T>
std::optional<long double> parse_number(const std::string& s) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return std::nullopt;
  if constexpr (std::is_integral_v<T>) {
    const std::size_t first = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (first == s.size() ||
        !std::all_of(s.begin() + static_cast<std::ptrdiff_t>(first), s.end(),
                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
      return std::nullopt;
  }
  char* end = nullptr;
  const long double v = std::strtold(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

template <typename T>
std::string show_number(T v) {
  std::ostringstream out;
  out << +v;  // + prints a char-sized integer as a number
  return out.str();
}

/// A number of type T in [lo, hi] (lo excluded when `lo_open`); a missing bound is the type's.
template <typename T>
CLI::Validator number_check(std::optional<T> lo, bool lo_open, std::optional<T> hi, const std::string& desc) {
  auto check = [lo, lo_open, hi](std::string& s) -> std::string {
    const std::optional<long double> v = parse_number<T>(s);
    if (!v) return "'" + s + "' is not " + (std::is_integral_v<T> ? "an integer" : "a number");
    const std::string got = " (got " + s + ")";
    const bool below = lo && (lo_open ? !(*v > *lo) : *v < *lo), above = hi && *v > *hi;
    if (lo && hi && (below || above))
      return "must be in [" + show_number(*lo) + ", " + show_number(*hi) + "]" + got;
    if (below) return std::string("must be ") + (lo_open ? "> " : ">= ") + show_number(*lo) + got;
    if (above) return "must be <= " + show_number(*hi) + got;
    constexpr T lowest = std::numeric_limits<T>::lowest(), highest = std::numeric_limits<T>::max();
    if (*v < static_cast<long double>(lowest)) return "must be >= " + show_number(lowest) + got;
    if (*v > static_cast<long double>(highest)) return "must be <= " + show_number(highest) + got;
    return {};
  };
  return CLI::Validator(check, desc);
}

/// Any number of type T (an unsigned one is >= 0).
template <typename T>
CLI::Validator any_number() {
  return number_check<T>(std::nullopt, false, std::nullopt, "");
}
/// > 0.
template <typename T>
CLI::Validator positive() {
  return number_check<T>(T(0), true, std::nullopt, "POSITIVE");
}
/// >= 0.
template <typename T>
CLI::Validator non_negative() {
  return number_check<T>(T(0), false, std::nullopt, "NONNEGATIVE");
}
/// In [lo, hi].
template <typename T>
CLI::Validator in_range(T lo, T hi) {
  return number_check<T>(lo, false, hi, "in [" + show_number(lo) + ", " + show_number(hi) + "]");
}

/// `s` as x,y,z within float's range, or nullopt. Read in double: a place in georeferenced
/// coordinates (Scene::origin()) needs the digits.
inline std::optional<glm::dvec3> try_parse_vec3(const std::string& s) {
  glm::dvec3 v;
  char c1 = 0, c2 = 0;
  std::istringstream in(s);
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !in.eof()) return std::nullopt;
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(v[k]) <= static_cast<double>(FLT_MAX))) return std::nullopt;
  return v;
}

/// A vector x,y,z (three numbers, commas, no spaces).
inline CLI::Validator vec3_check() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        return try_parse_vec3(s) ? std::string() : "expected x,y,z (three numbers), got '" + s + "'";
      },
      "x,y,z");
}

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
      case rad::Phase::lights: return "lights";
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
  std::string method = "auto";
  std::string form_factors = "auto";
  unsigned hemisphere_rays = rad::FormFactorOptions{}.hemisphere_rays;
  unsigned specular_depth = 0;
  float max_patch_area = 0.0f;
  float max_element_area = 0.0f;
  double tolerance = 1e-3;
  unsigned threads = 0;
  unsigned memory_budget_mib = 0;  ///< `--memory-budget`, MiB; 0 = the library's default
  std::uint64_t seed = 1;
  int max_iterations = 0;
  bool adaptive = false;
  float adaptive_threshold = 0.3f;
  int adaptive_passes = 3;
  float epsilon = rad::HierarchicalOptions{}.epsilon;
  bool strict = false;
  bool photometric = false;
  bool two_sided = false;
  std::string reverse_winding;  ///< `--reverse-winding`: "", "all" or "outward"
  bool light_groups = false;
  // Whether the user gave these (apply_specular_depth(), prepare_pass1()); set by add_solve_options().
  const CLI::Option* method_option = nullptr;
  const CLI::Option* form_factors_option = nullptr;
  const CLI::Option* specular_depth_option = nullptr;
};

/// The estimator a `--form-factors` / `--method` name (as the CLI spells it) selects.
inline rad::FormFactorMethod form_factor_method(const std::string& name) {
  return name == "analytic"      ? rad::FormFactorMethod::analytic
         : name == "hemicube"    ? rad::FormFactorMethod::hemicube
         : name == "monte-carlo" ? rad::FormFactorMethod::monte_carlo
         : name == "auto"        ? rad::FormFactorMethod::automatic
                                 : rad::FormFactorMethod::ray_cast;
}

/// The names form_factor_method() accepts.
inline const std::vector<std::string>& form_factor_names() {
  static const std::vector<std::string> names = {"auto", "ray-cast", "hemicube", "analytic", "monte-carlo"};
  return names;
}

/// The name form_factor_method() maps to `method` ("default" for one it has no name for).
inline std::string form_factor_name(rad::FormFactorMethod method) {
  for (const std::string& name : form_factor_names())
    if (form_factor_method(name) == method) return name;
  return "default";
}

/// The names of `render --mode`, as rad::to_string(RenderMode) spells them.
inline const std::vector<std::string>& render_mode_names() {
  static const std::vector<std::string> names = {"auto", "radiosity", "two-pass", "path"};
  return names;
}

/// The mode a `--mode` name selects (automatic for "auto" and anything unknown).
inline rad::RenderMode render_mode_from_name(const std::string& name) {
  for (rad::RenderMode m : {rad::RenderMode::radiosity, rad::RenderMode::two_pass, rad::RenderMode::path})
    if (name == rad::to_string(m)) return m;
  return rad::RenderMode::automatic;
}

/// The render mode that the flags ask for (--mode and its aliases), and the first
/// contradiction between them.
struct ModeRequest {
  rad::RenderMode mode = rad::RenderMode::automatic;
  std::string source;    ///< the flag that asked for `mode`, e.g. "--two-pass"
  std::string conflict;  ///< e.g. "--mode radiosity contradicts --two-pass"; empty if none

  /// Records that flag `flag` asks for `m` (automatic: the flag asks for nothing).
  ModeRequest& add(rad::RenderMode m, const std::string& flag) {
    if (m == rad::RenderMode::automatic || !conflict.empty()) return *this;
    if (mode == rad::RenderMode::automatic) {
      mode = m;
      source = flag;
    } else if (m != mode) {
      conflict = source + " contradicts " + flag;
    }
    return *this;
  }
};

/// Adds `--strict` (every command that loads a scene has it).
inline void add_strict_flag(CLI::App& cmd, bool& strict) {
  cmd.add_flag("--strict", strict,
               "Refuse a scene file with problems the readers would otherwise fix with a warning (degenerate or "
               "short faces, reflectance >= 1, a missing material): exit 1 naming file and line");
}

/// Adds `--photometric` (every command that loads a scene has it).
inline void add_photometric_flag(CLI::App& cmd, bool& photometric) {
  cmd.add_flag("--photometric", photometric,
               "Read light intensities in the scene file as candela (point, spot) and lux (directional, sky) and "
               "divide by 683 lm/W; without it they are W/sr and W/m^2 as written (the library is radiometric)");
}

/// Adds `--reverse-winding all|outward|inconsistent` (every command that loads a scene has it).
inline void add_reverse_winding_option(CLI::App& cmd, std::string& reverse_winding) {
  cmd.add_option("--reverse-winding", reverse_winding,
                 "Turn polygons over (reverse their vertex order) after loading, for one-sided models wound the wrong "
                 "way: 'outward' the polygons whose front sees nothing and whose back sees the scene (the walls of a "
                 "room or enclosure modelled as an outward box, as check lists them; furniture inside keeps its "
                 "winding), 'inconsistent' the polygons wound opposite to the polygons they share edges with (a "
                 "flipped face of a mesh), 'all' every polygon. View factors are taken on fronts only, so for them "
                 "this, not --two-sided, is the fix")
      ->check(CLI::IsMember({"all", "outward", "inconsistent"}));
}

/// `with_path`: also offer `--method path` (render only: the reference path tracer, no solve).
inline void add_solve_options(CLI::App& cmd, SolveArgs& a, bool with_path = false) {
  std::vector<std::string> methods = {"auto", "jacobi", "gauss-seidel", "progressive", "hierarchical"};
  if (with_path) methods.push_back("path");
  a.method_option = cmd.add_option("--method", a.method,
                 std::string("Solver (auto: gauss-seidel while its form-factor rows fit the 4 GiB memory budget, else "
                             "hierarchical)") +
                     (with_path ? ", or path for the reference path tracer" : ""))
      ->check(CLI::IsMember(methods))
      ->capture_default_str();
  a.form_factors_option = cmd.add_option("--form-factors", a.form_factors,
                 with_path ? "Form-factor estimator (two-pass mode on a scene with mirrors or glass: monte-carlo)"
                           : "Form-factor estimator")
      ->check(CLI::IsMember(form_factor_names()))
      ->capture_default_str();
  cmd.add_option("--hemisphere-rays", a.hemisphere_rays, "Monte Carlo estimator: rays per element, 16..1048576")
      ->check(in_range<unsigned>(16u, 1u << 20))
      ->capture_default_str();
  a.specular_depth_option =
      cmd.add_option("--specular-depth", a.specular_depth,
                     std::string("Monte Carlo estimator: mirror reflections and window passages carried between "
                                 "diffuse surfaces (extended form factors), 0..16; by default 1 with monte-carlo ") +
                         (with_path ? "in two-pass mode " : "") +
                         "on a scene with mirror or glass materials (unless --form-factors or --method hierarchical "
                         "is given, or the rows would exceed the memory budget), else 0")
          ->check(in_range<unsigned>(0u, 16u));
  cmd.add_option("--max-patch-area", a.max_patch_area, "Largest patch, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  cmd.add_option("--max-element-area", a.max_element_area, "Largest element, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  cmd.add_option("--tolerance", a.tolerance, "Stop when unshot/emitted power falls below this")
      ->check(positive<double>())
      ->capture_default_str();
  cmd.add_option("--max-iterations", a.max_iterations, "Sweeps or shooting steps at most (0 = default)")
      ->check(non_negative<int>());
  cmd.add_flag("--adaptive", a.adaptive, "Subdivide elements where radiosity varies fast (shadow edges)");
  cmd.add_option("--adaptive-threshold", a.adaptive_threshold, "Relative contrast that splits an element")
      ->check(in_range<float>(0.001f, 1.0f))
      ->capture_default_str();
  cmd.add_option("--adaptive-passes", a.adaptive_passes, "Refinement passes at most")
      ->check(in_range<int>(1, 16))
      ->capture_default_str();
  cmd.add_option("--epsilon", a.epsilon,
                 "Hierarchical: refine a link while the radiosity it brings exceeds this fraction of the scene's "
                 "mean radiosity, (0, 1]; smaller is more accurate and costs more links")
      ->check(in_range<float>(1e-6f, 1.0f))
      ->capture_default_str();
  cmd.add_option("--threads", a.threads, "Worker threads (0 = all cores)")->check(any_number<unsigned>());
  cmd.add_option("--memory-budget", a.memory_budget_mib,
                 "The most memory the form factors may take, MiB (0 = 4096): beyond it a matrix method is refused "
                 "with the figure before it starts, and --method auto takes hierarchical")
      ->check(in_range<unsigned>(0u, 1u << 24));
  cmd.add_option("--seed", a.seed, "Random seed (results are identical for a seed at any thread count)")
      ->check(any_number<std::uint64_t>())
      ->capture_default_str();
  add_strict_flag(cmd, a.strict);
  cmd.add_flag("--light-groups", a.light_groups,
               "Also solve each emitting group's light on its own (one more solve each, same form factors): solve "
               "prints and --stats writes each light group's share, render writes an EXR layer per light group, bake "
               "each light group's lightmaps and PLYs");
  add_photometric_flag(cmd, a.photometric);
  cmd.add_flag("--two-sided", a.two_sided,
               "Make every material two-sided (reflect and emit on both sides, each with its own radiosity): for "
               "models whose polygons face inconsistently or outwards");
  add_reverse_winding_option(cmd, a.reverse_winding);
}

/// --specular-depth: given, the depth is taken as it is (rad::SpecularPaths::as_given), and a
/// depth above 0 without --form-factors selects the Monte Carlo estimator (the only one that
/// carries it). Not given, solve() chooses (rad::SpecularPaths::automatic: the extended first
/// pass on a scene with mirror or glass materials unless --form-factors or --method rules it
/// out, and without it when its rows exceed the memory budget under --method auto), and
/// SolveReport::specular_depth_choice says what it chose. For solve and bake, which no photon
/// pass follows, the emitters' light through glass counts (FormFactorOptions::emitted_through_glass)
/// unless `photons_follow`.
inline void apply_specular_depth(rad::SolveOptions& options, const SolveArgs& a, bool photons_follow = false) {
  auto given = [](const CLI::Option* o) { return o != nullptr && o->count() > 0; };
  if (!given(a.specular_depth_option)) return;
  options.specular_paths = rad::SpecularPaths::as_given;
  options.form_factors.emitted_through_glass = !photons_follow;
  if (a.specular_depth > 0 && !given(a.form_factors_option))
    options.form_factors.method = rad::FormFactorMethod::monte_carlo;
}

/// render's two-pass mode: pass 1 as rad::prepare_two_pass() sets it up (the emitters' light
/// through glass left to the photon map's sharp caustics), unless --specular-depth, a
/// --form-factors other than monte-carlo or --method hierarchical says otherwise (then as
/// apply_specular_depth()).
inline void prepare_pass1(const rad::Scene& scene, rad::SolveOptions& options, const SolveArgs& a) {
  auto given = [](const CLI::Option* o) { return o != nullptr && o->count() > 0; };
  apply_specular_depth(options, a, true);
  if (given(a.specular_depth_option)) return;
  if (given(a.form_factors_option) && options.form_factors.method != rad::FormFactorMethod::monte_carlo) return;
  if (given(a.method_option) && options.method == rad::SolverMethod::hierarchical) return;
  rad::prepare_two_pass(scene, options);
}

inline rad::SolveOptions to_options(const SolveArgs& a, ProgressBar& bar) {
  rad::SolveOptions o;
  o.method = a.method == "jacobi"        ? rad::SolverMethod::jacobi
             : a.method == "progressive" ? rad::SolverMethod::progressive
             : a.method == "hierarchical" ? rad::SolverMethod::hierarchical
             : a.method == "gauss-seidel" ? rad::SolverMethod::gauss_seidel
                                          : rad::SolverMethod::automatic;
  o.form_factors.method = form_factor_method(a.form_factors);
  o.form_factors.hemisphere_rays = a.hemisphere_rays;
  o.form_factors.specular_depth = a.specular_depth;
  o.mesh.max_patch_area = a.max_patch_area;
  o.mesh.max_element_area = a.max_element_area;
  o.tolerance = a.tolerance;
  o.max_iterations = a.max_iterations;
  o.threads = a.threads;
  o.memory_budget_bytes = std::size_t{a.memory_budget_mib} << 20;
  o.seed = a.seed;
  o.adaptive.enabled = a.adaptive;
  o.adaptive.threshold = a.adaptive_threshold;
  o.adaptive.max_passes = a.adaptive_passes;
  o.hierarchical.epsilon = a.epsilon;
  o.separate_light_groups = a.light_groups;
  o.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
  return o;
}

/// The solution with light group `k` alone, at weight 1 (--light-groups: one group's share).
inline rad::Solution light_group_alone(const rad::Solution& sol, std::size_t k) {
  std::vector<rad::Rgb> weights(sol.light_groups().size(), rad::Rgb(0.0f));
  weights.at(k) = rad::Rgb(1.0f);
  return sol.relight(weights);
}

/// Help text for the SCENE argument of every command.
constexpr const char* kSceneHelp =
    "Scene file (OBJ, JSON, glTF .gltf/.glb, or a format Assimp reads: FBX, COLLADA, 3DS, PLY, STL, ...), or a built-in "
    "scene: cornell (the default; also cornell-box), cornell-specular (mirror tall "
    "block, glass short block), cornell-mirror, cornell-glass";

/// A built-in scene by name, else the scene file at `path` (load_scene()), read strictly when `strict`
/// (LoadOptions::strict: what the readers would fix with a warning is an error; built-in scenes
/// have nothing to fix), its light intensities photometric when `photometric`
/// (LoadOptions::photometric).
inline rad::Scene load(const std::string& path, bool strict = false, bool photometric = false) {
  if (path.empty() || path == "cornell" || path == "cornell-box") return rad::cornell_box();
  if (path == "cornell-specular") return rad::cornell_box_specular();
  if (path == "cornell-mirror") return rad::cornell_box_specular(rad::CornellSpecular::mirror);
  if (path == "cornell-glass") return rad::cornell_box_specular(rad::CornellSpecular::glass);
  rad::LoadOptions options;
  options.strict = strict;
  options.photometric = photometric;
  return rad::load_scene(path, options);
}

/// What the command line changes in a scene once it is loaded.
struct SceneEdits {
  bool two_sided = false;       ///< `--two-sided`: Scene::make_two_sided()
  std::string reverse_winding;  ///< `--reverse-winding`: "" (none), "all", "outward" or "inconsistent"
};

/// Applies `--reverse-winding` (Scene::reverse_winding()) and says what it turned.
inline void reverse_winding(rad::Scene& scene, const std::string& which) {
  if (which.empty()) return;
  if (which == "all") {
    scene.reverse_winding();
    std::fprintf(stderr, "reversed the winding of all %zu polygons (--reverse-winding all)\n", scene.polygons().size());
    return;
  }
  if (which == "inconsistent") {
    const rad::InconsistentWinding found = rad::find_inconsistent_winding(scene);
    scene.reverse_winding(found.polygons);
    std::fprintf(stderr,
                 "reversed the winding of %zu of %zu polygons, those wound opposite to the polygons they share edges "
                 "with (--reverse-winding inconsistent)\n",
                 found.polygons.size(), scene.polygons().size());
    return;
  }
  const rad::OutwardFacing outward = rad::find_polygons_facing_outward(scene);
  scene.reverse_winding(outward.polygons);
  std::fprintf(stderr,
               "reversed the winding of %zu of %zu polygons, those whose front sees nothing and whose back sees the "
               "scene (--reverse-winding outward)\n",
               outward.polygons.size(), scene.polygons().size());
}

/// load(), then the edits (models with unreliable winding).
inline rad::Scene load(const std::string& path, bool strict, bool photometric, const SceneEdits& edits) {
  rad::Scene scene = load(path, strict, photometric);
  reverse_winding(scene, edits.reverse_winding);
  if (edits.two_sided) scene.make_two_sided();
  return scene;
}

/// Whether anything in `scene` gives light: a light, or a polygon of an emitting material.
inline bool has_light(const rad::Scene& scene) {
  if (!scene.lights().empty()) return true;
  for (const rad::Polygon& p : scene.polygons()) {
    const rad::Rgb e = scene.material(p.material).emission;
    if (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) return true;
  }
  return false;
}

/// "+y", "-z", ...: the axis a unit axis vector points along.
inline std::string axis_name(const glm::vec3& v) {
  const glm::vec3 a = glm::abs(v);
  const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  return std::string(v[axis] < 0.0f ? "-" : "+") + "xyz"[axis];
}

inline void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
}

/// "(x, y, z): why" for a scene read with a local origin (Scene::origin()), else empty.
inline std::string origin_note(const rad::Scene& scene) {
  const glm::dvec3 o = scene.origin();
  if (o == glm::dvec3(0.0)) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "(%.10g, %.10g, %.10g): the model lies far from (0, 0, 0) for its size, so its positions are held "
                "relative to this point (single precision would move its corners); outputs and --eye / --look-at "
                "are in the file's coordinates",
                o.x, o.y, o.z);
  return text;
}

/// What loading a scene file did that a user should know: the local origin the reader chose,
/// then the readers' warnings.
inline void print_load_notes(const rad::Scene& scene) {
  const std::string origin = origin_note(scene);
  if (!origin.empty()) std::fprintf(stderr, "origin: %s\n", origin.c_str());
  print_warnings(scene.warnings());
}

/// The solve's own warnings (report.warnings repeats the scene's, printed before the solve).
inline void print_solve_warnings(const rad::Scene& scene, const rad::Solution& sol) {
  const std::vector<std::string>& known = scene.warnings();
  for (const std::string& w : sol.report().warnings)
    if (std::find(known.begin(), known.end(), w) == known.end()) std::cerr << "warning: " << w << "\n";
}

inline void print_summary(const rad::Solution& sol) {
  const rad::SolveReport& r = sol.report();
  const char* status = sol.status() == rad::SolveStatus::converged       ? "converged"
                       : sol.status() == rad::SolveStatus::iteration_cap ? "iteration cap"
                                                                         : "cancelled";
  std::printf("solved: %zu patches, %zu elements, %d iterations, residual %.3g (%s)\n", r.patch_count,
              r.element_count, r.iterations, r.residual, status);
  // The mesh's grading toward what stands on coarse polygons (rad::MeshOptions::grade_at_contacts).
  const rad::ContactGrading& graded = sol.hierarchy().contact_grading();
  if (graded.polygons > 0)
    std::printf("mesh: graded toward what stands on %zu polygon%s with elements larger than it: %zu more elements%s\n",
                graded.polygons, graded.polygons == 1 ? "" : "s", graded.added_leaves,
                graded.budget_reached ? " (its budget reached: some contacts stay coarser; radiosity check names them)"
                                      : "");
  if (r.link_count > 0)
    std::printf("hierarchical: %zu links (%.1f MiB with the cluster tree), %d refinement passes, %zu elements split\n",
                r.link_count, static_cast<double>(r.form_factor_bytes) / (1024.0 * 1024.0), r.refinement_passes,
                r.refined_elements);
  else if (r.refinement_passes > 0)
    std::printf("adaptive: %zu elements split in %d passes\n", r.refined_elements, r.refinement_passes);
  std::printf("time: meshing %.3f s, form factors %.3f s, solving %.3f s\n", r.seconds_meshing,
              r.seconds_form_factors, r.seconds_solving);
  // Power over the three channels; what escaped as a share of what was emitted.
  const double emitted = double(r.emitted_power.x) + double(r.emitted_power.y) + double(r.emitted_power.z);
  const double escaped = double(r.escaped_power.x) + double(r.escaped_power.y) + double(r.escaped_power.z);
  const double lit = double(r.light_power.x) + double(r.light_power.y) + double(r.light_power.z);
  // Escaped: emitted minus absorbed, so also what the backs of one-sided polygons took (a
  // pane crossed from behind: what it absorbs; an outward-wound wall: all it gets).
  if (emitted > 0.0 && lit > 0.0)
    std::printf("power: emitted %.6g W (%.6g W of it from the lights), escaped %.1f %% (left the scene or met the "
                "back of a one-sided polygon)\n",
                emitted, lit, 100.0 * escaped / emitted);
  else if (emitted > 0.0)
    std::printf("power: emitted %.6g W, escaped %.1f %% (left the scene or met the back of a one-sided polygon)\n",
                emitted, 100.0 * escaped / emitted);
}

/// The PNG preview's exposure from `values` (per pixel, its largest channel): 1, which shows a
/// calibrated scene (the Cornell box) as it is meant, unless the image would be mostly clipped
/// or dark: when the 95th percentile of the lit pixels (values > 0) is above 1 or below 0.1,
/// the exposure that shows it at 0.8, and `why` says so (else `why` is empty). An exported room
/// in watts comes out white at 1, a scene in photometric units black.
inline float preview_exposure(std::vector<float> values, std::string& why) {
  why.clear();
  values.erase(std::remove_if(values.begin(), values.end(), [](float v) { return !(v > 0.0f) || !std::isfinite(v); }),
               values.end());
  if (values.empty()) return 1.0f;
  const std::size_t k = values.size() * 95 / 100;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  const float p95 = values[k];
  if (p95 >= 0.1f && p95 <= 1.0f) return 1.0f;
  char s[160];
  std::snprintf(s, sizeof s, "at 1 the 95th percentile of the lit pixels, %.3g, would be %s; it shows at 0.8",
                static_cast<double>(p95), p95 > 1.0f ? "clipped" : "below 0.1");
  why = s;
  return 0.8f / p95;
}

/// Says which estimator ran, and why when the choice was automatic.
inline void print_estimator(const rad::Solution& sol, const rad::SolveOptions& options) {
  const rad::SolveReport& r = sol.report();
  // Why the specular depth is 0 on a scene with mirrors or glass (dropped over the memory
  // budget, a warning on stderr says it too).
  const bool say_depth = !r.specular_depth_choice.empty() && r.specular_depth == 0;
  if (!r.method_choice.empty())
    std::printf("method: %s (automatic: %s; --method overrides)\n",
                r.method == rad::SolverMethod::hierarchical ? "hierarchical" : "gauss-seidel", r.method_choice.c_str());
  if (!r.estimator_ran()) {
    std::printf("form factors: links of the hierarchy (point-to-polygon and cluster transport, shadow rays)\n");
    if (say_depth) std::printf("specular depth: %s\n", r.specular_depth_choice.c_str());
    return;
  }
  // solve() chose the extended first pass (a depth given under SpecularPaths::automatic has no choice).
  if (r.specular_depth > 0 && !r.specular_depth_choice.empty()) {
    std::printf("form factors: %s, specular depth %s, the mirror and glass paths carried between diffuse surfaces; "
                "--specular-depth 0 turns it off\n",
                rad::to_string(r.form_factor_method), r.specular_depth_choice.c_str());
    return;
  }
  if (say_depth) std::printf("specular depth: %s\n", r.specular_depth_choice.c_str());
  if (options.form_factors.method != rad::FormFactorMethod::automatic) {
    std::printf("form factors: %s\n", rad::to_string(r.form_factor_method));
    return;
  }
  std::string why;
  if (r.specular_depth > 0)
    why = "mirror and window form factors need it";
  else
    why = std::to_string(r.patch_count) + " patches: " +
          (r.form_factor_method == rad::FormFactorMethod::ray_cast ? "a small mesh, exact unoccluded factors"
                                                                   : "faster and as accurate on a mesh this size");
  std::printf("form factors: %s (automatic: %s; --form-factors overrides)\n", rad::to_string(r.form_factor_method),
              why.c_str());
}

/// try_parse_vec3(), or a CLI::ValidationError naming option `name`.
inline glm::dvec3 parse_dvec3(const std::string& s, const char* name) {
  const std::optional<glm::dvec3> v = try_parse_vec3(s);
  if (!v) throw CLI::ValidationError(name, "expected x,y,z (three numbers), got '" + s + "'");
  return *v;
}

inline glm::vec3 parse_vec3(const std::string& s, const char* name) { return glm::vec3(parse_dvec3(s, name)); }

/// A place given in the scene file's coordinates (--eye, --look-at), as the scene holds it:
/// relative to its origin (Scene::origin(), (0, 0, 0) unless the reader moved a far model).
inline glm::vec3 parse_point(const std::string& s, const char* name, const rad::Scene& scene) {
  const glm::dvec3 relative = parse_dvec3(s, name) - scene.origin();
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(relative[k]) <= static_cast<double>(FLT_MAX)))
      throw CLI::ValidationError(name, "'" + s + "' is beyond single precision's range from the scene");
  return glm::vec3(relative);
}

/// Runs a command body and turns exceptions into the CLI's exit codes: 1 for a
/// radiosity::Error (bad input; the message names the file, line or field), 2 for a bad
/// argument, 3 for anything unexpected.
inline int run_guarded(const std::function<int()>& body) {
  try {
    return body();
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
}

/// Reports a bad argument the CLI's way and returns its exit code, 2: one line
/// `radiosity: error: MESSAGE` on stderr and a hint where to look (`command`: the subcommand's
/// name, or empty before one was given).
inline int argument_error(const std::string& command, const std::string& message) {
  std::fprintf(stderr, "radiosity: error: %s\n", message.c_str());
  if (command.empty())
    std::fprintf(stderr, "Run 'radiosity --help' for the commands.\n");
  else
    std::fprintf(stderr, "Run 'radiosity %s --help' for the options.\n", command.c_str());
  return 2;
}

/// Parses the command line. Returns nullopt to go on, else the exit code: 0 after --help or
/// --help-all (CLI11 prints the help), 2 after any other CLI::ParseError (argument_error()).
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::Success& e) {  // --help, --help-all, a version request
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::vector<CLI::App*> chosen = app.get_subcommands();
    const std::string command = chosen.empty() ? std::string() : chosen.front()->get_name();
    std::string message = e.what();
    if (chosen.empty() && dynamic_cast<const CLI::RequiredError*>(&e)) {
      std::string names;
      for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
      message = "expected a command (" + names + ")";
      if (argc > 1) message += ", got '" + std::string(argv[1]) + "'";
    } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && message.size() > 8 &&
               message.compare(message.size() - 8, 8, " missing") == 0) {
      // "--width: 1 required INT:POSITIVE missing" -> "--width: needs a value"
      message = message.substr(0, message.find(": ")) + ": needs a value";
    }
    // CLI11's messages can span lines; the contract is one line.
    std::replace(message.begin(), message.end(), '\n', ' ');
    return argument_error(command, message);
  }
}

/// A subcommand added by another file: `run` is called when the user chose it and returns the
/// process exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

}  // namespace cli
