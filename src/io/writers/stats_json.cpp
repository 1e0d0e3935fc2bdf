// The statistics file of `radiosity solve --stats`: a JSON summary of a Solution for scripts and
// regression checks (format documented in docs/CLI-stats.md). Fields keep a fixed order so that
// files diff well.
#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "radiosity/io.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

using Json = nlohmann::ordered_json;

/// A float as the shortest decimal that reads back to it (0.3f is written 0.3, not
/// 0.30000001192092896); non-finite values become null.
Json number(float v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  if (ec != std::errc() || !std::isfinite(v)) return nullptr;
  return std::stod(std::string(buf, end));
}

Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json rgb(const Rgb& c) { return Json::array({number(c.x), number(c.y), number(c.z)}); }

const char* status_name(SolveStatus s) {
  switch (s) {
    case SolveStatus::converged: return "converged";
    case SolveStatus::iteration_cap: return "iteration_cap";
    case SolveStatus::cancelled: return "cancelled";
  }
  return "unknown";
}

const char* method_name(SolverMethod m) {
  switch (m) {
    case SolverMethod::jacobi: return "jacobi";
    case SolverMethod::gauss_seidel: return "gauss_seidel";
    case SolverMethod::progressive: return "progressive";
    case SolverMethod::hierarchical: return "hierarchical";
    case SolverMethod::automatic: return "automatic";
  }
  return "unknown";
}

const char* form_factor_name(FormFactorMethod m) {
  switch (m) {
    case FormFactorMethod::ray_cast: return "ray_cast";
    case FormFactorMethod::hemicube: return "hemicube";
    case FormFactorMethod::analytic: return "analytic";
    case FormFactorMethod::monte_carlo: return "monte_carlo";
    case FormFactorMethod::automatic: return "automatic";
  }
  return "unknown";
}

Json stats(const Solution& solution, const SolveOptions* options, std::string_view scene) {
  const SolveReport& r = solution.report();
  Json j;
  j["version"] = version();
  if (!scene.empty()) j["scene"] = std::string(scene);
  if (options) {
    j["method"] = method_name(options->method);
    j["form_factor_method"] = form_factor_name(options->form_factors.method);
    j["tolerance"] = number(options->tolerance);
    j["max_iterations"] = options->max_iterations;
    j["seed"] = options->seed;
  }
  if (r.estimator_ran())
    j["form_factor_method_used"] = form_factor_name(r.form_factor_method);
  else
    j["form_factor_method_used"] = nullptr;
  j["status"] = status_name(solution.status());
  j["iterations"] = r.iterations;
  j["residual"] = number(r.residual);
  j["patches"] = r.patch_count;
  j["elements"] = r.element_count;
  j["form_factor_bytes"] = r.form_factor_bytes;
  j["link_count"] = r.link_count;
  j["link_pairs_examined"] = r.link_pairs_examined;
  j["link_rays"] = r.link_rays;
  j["gather_rays"] = r.gather_rays;
  j["light_rays"] = r.light_rays;
  j["method_used"] = method_name(r.method);
  j["method_choice"] = r.method_choice;
  j["specular_depth_used"] = r.specular_depth;
  j["specular_depth_choice"] = r.specular_depth_choice;
  j["emitted_through_glass"] = r.emitted_through_glass;
  j["mesh"] = Json{{"max_patch_area", number(solution.hierarchy().options().max_patch_area)},
                   {"max_element_area", number(solution.hierarchy().options().max_element_area)}};
  j["emitted_power"] = rgb(r.emitted_power);
  j["absorbed_power"] = rgb(r.absorbed_power);
  j["escaped_power"] = rgb(r.escaped_power);
  j["light_power"] = rgb(r.light_power);

  Json groups = Json::object();
  for (const std::string& name : solution.groups())
    groups[name] = Json{{"radiosity", rgb(solution.group_radiosity(name))}, {"area", number(solution.group_area(name))}};
  j["groups"] = std::move(groups);
  // Each light group's share of every group (SolveOptions::separate_light_groups).
  if (!solution.light_groups().empty()) {
    Json light_groups = Json::object();
    for (std::size_t k = 0; k < solution.light_groups().size(); ++k) {
      Json shares = Json::object();
      for (const std::string& name : solution.groups())
        shares[name] = Json{{"radiosity", rgb(solution.light_group_radiosity(k, name))},
                            {"area", number(solution.group_area(name))}};
      light_groups[solution.light_groups()[k].name] = Json{{"groups", std::move(shares)}};
    }
    j["light_groups"] = std::move(light_groups);
  }

  j["timings"] = Json{{"meshing", number(r.seconds_meshing)},
                      {"form_factors", number(r.seconds_form_factors)},
                      {"solving", number(r.seconds_solving)},
                      {"lights", number(r.seconds_lights)}};
  Json history = Json::array();
  for (double v : r.residual_history) history.push_back(number(v));
  j["residual_history"] = std::move(history);
  Json times = Json::array();
  for (double v : r.time_history) times.push_back(number(v));
  j["time_history"] = std::move(times);
  j["warnings"] = r.warnings;
  return j;
}

void write(const Json& j, const std::filesystem::path& path) {
  // Group names come from scene files and may not be UTF-8: replace bad bytes rather than fail.
  const std::string text = j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::io_error, "write_stats_json: cannot open '" + path.string() + "' for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw Error(ErrorCode::io_error, "write_stats_json: cannot write '" + path.string() + "'");
}

}  // namespace

void write_stats_json(const Solution& solution, const std::filesystem::path& path) {
  write(stats(solution, nullptr, {}), path);
}

void write_stats_json(const Solution& solution, const std::filesystem::path& path, const SolveOptions& options,
                      std::string_view scene) {
  write(stats(solution, &options, scene), path);
}

}  // namespace v1
}  // namespace radiosity
