// The procedural city of issue #15 (benchmarks/city.hpp: streets, blocks and buildings, every
// surface cut into quads, under a sky) solved on 2 threads, the Monte Carlo path and the
// hierarchical one side by side. First the default SolveOptions, which for a city are the issue's
// Monte Carlo configuration (Gauss-Seidel, monte_carlo form factors at 1024 rays per element,
// tolerance 1e-3, one element per facet) while its rows fit the 4 GiB budget, and the
// hierarchical solver beyond (SolverMethod::automatic: the 1M city); when the defaults resolve to
// something else the issue's configuration is run as well. Then SolverMethod::hierarchical at
// one element per facet (HierarchicalOptions::epsilon from --epsilon), unless the defaults ran it.
// Each configuration runs in its own child process, so its peak RSS is its own.
//
// Usage: bench_city [PRESET] [--blocks N] [--facet S] [--seed K] [--threads T] [--memory-budget MIB]
//                   [--epsilon E] [--only monte-carlo|hierarchical] [--city-only] [--sky-rays N]
//                   [--make-reference FILE | --reference FILE [--elements PREFIX]] [--plot FILE.svg]
//   PRESET: 22k (3 blocks, 2.25 m facets: 23.5k facets), 246k (10 blocks: 250k), 1M (20 blocks:
//   991k); the options after a preset change it. Default: 22k. --memory-budget sets
//   SolveOptions::memory_budget_bytes (default: the library's 4 GiB). --city-only builds the city
//   and prints its facets without solving. --sky-rays sets SolveOptions::sky_rays.
//   --make-reference FILE solves the city with 16 times the rays of the issue's configuration
//   (form factors and sky; Gauss-Seidel to a tolerance of 1e-5) and writes its element radiosity (times exposure: power over area);
//   --reference FILE then prints every solve's element RMS relative difference to it, and with
//   --elements PREFIX writes PREFIX.monte-carlo.csv / PREFIX.hierarchical.csv, one line per element.
// Prints the city (facets per group, buildings, time to build it), then per configuration the
// elements, the time of each phase (meshing, the sky's first shot, the estimator's set-up,
// form factors, solving; from SolveReport, the set-up is the rest of the wall time), sweeps,
// residual, peak RSS and form-factor memory, the group means and the power balance. A solve the
// library refuses (the 1M city: the Gauss-Seidel rows exceed the 4 GiB memory budget) prints
// the library's message and how long the refusal took.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"
#include "city.hpp"

namespace rad = radiosity;

namespace {

using bench::peak_rss_mib;
using bench::seconds_since;

struct Args {
  bench::CityOptions city;
  unsigned threads = 2;
  std::size_t memory_budget_bytes = 0;  ///< SolveOptions::memory_budget_bytes (0: the library's 4 GiB)
  bool solve = true;                    ///< false: print the city only
  bool monte_carlo = true;              ///< run the Monte Carlo path (the defaults / the issue's configuration)
  bool hierarchical = true;             ///< run SolverMethod::hierarchical
  float epsilon = rad::HierarchicalOptions{}.epsilon;
  std::string plot;                     ///< --plot FILE: the SVG of time and memory against facets
  std::uint32_t sky_rays = rad::SolveOptions{}.sky_rays;  ///< SolveOptions::sky_rays of every solve
  std::string make_reference;           ///< --make-reference FILE: solve the reference, write its radiosity
  std::string reference;                ///< --reference FILE: compare every solve with that reference
  std::string elements;                 ///< --elements PREFIX: with --reference, every element as CSV
};

/// The reference's rays: 16 times the issue's configuration, for form factors and the sky.
constexpr std::uint32_t kReferenceFactor = 16;

/// Element radiosity (the mean channel per element) as --make-reference writes it: a count,
/// then the values, native float.
bool write_values(const std::string& path, const std::vector<float>& v) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const std::uint64_t n = v.size();
  const bool ok = std::fwrite(&n, sizeof n, 1, f) == 1 && std::fwrite(v.data(), sizeof(float), v.size(), f) == v.size();
  return std::fclose(f) == 0 && ok;
}
std::vector<float> read_values(const std::string& path) {
  std::vector<float> v;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return v;
  std::uint64_t n = 0;
  if (std::fread(&n, sizeof n, 1, f) == 1 && n < (std::uint64_t{1} << 32)) {
    v.resize(n);
    if (std::fread(v.data(), sizeof(float), v.size(), f) != v.size()) v.clear();
  }
  std::fclose(f);
  return v;
}
/// What --make-reference writes and --reference compares per element: the mean channel of its
/// power over its whole area, radiosity() x exposure(). Where a wall cuts a ground facet, a
/// solve's radiosity() is its open part's, over an exposure it estimated itself (the Monte Carlo
/// rows from their rays, the hierarchical solver by points): a sliver 1/8 open can differ by
/// several times between two solves that agree on its power.
std::vector<float> element_values(const rad::Solution& sol) {
  const std::vector<rad::Rgb>& B = sol.radiosity();
  const std::vector<float>& x = sol.exposure();
  std::vector<float> v(B.size());
  for (std::size_t i = 0; i < B.size(); ++i) v[i] = (B[i].x + B[i].y + B[i].z) / 3.0f * (x.empty() ? 1.0f : x[i]);
  return v;
}

/// --elements: one line per element (group, centroid, normal, element_values(), the
/// reference's), for finding where a solve's differences lie (docs/HIERARCHICAL.md).
bool write_elements(const std::string& path, const rad::Solution& sol, const std::vector<std::uint32_t>& group,
                    const std::vector<float>& ref) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  std::fprintf(f, "group,x,y,z,nx,ny,nz,radiosity,reference\n");
  const std::vector<float> B = element_values(sol);
  for (std::size_t e = 0; e < B.size() && e < ref.size(); ++e) {
    const auto id = static_cast<std::uint32_t>(e);
    const glm::vec3 c = sol.hierarchy().element(id).centroid, n = sol.hierarchy().normal(id);
    std::fprintf(f, "%u,%g,%g,%g,%g,%g,%g,%g,%g\n", group[e], c.x, c.y, c.z, n.x, n.y, n.z, B[e], ref[e]);
  }
  return std::fclose(f) == 0;
}

/// Prints how far `got` (mean channel per element) lies from `ref`: the RMS relative difference
/// over the elements whose reference exceeds a tenth of the mean (the dark ground under the
/// buildings would make relative figures meaningless), and the relative difference of the
/// area-uniform mean (every facet of a city has nearly the same area).
void compare(const std::vector<float>& got, const std::vector<float>& ref, const std::vector<std::uint32_t>& group,
             const std::vector<std::string>& group_names) {
  if (got.size() != ref.size()) {
    std::printf("  reference: %zu elements there, %zu here: not compared\n", ref.size(), got.size());
    return;
  }
  double mean_ref = 0.0, mean_got = 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    mean_ref += ref[i];
    mean_got += got[i];
  }
  double sq = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (!(ref[i] > 0.1 * mean_ref / static_cast<double>(ref.size()))) continue;
    const double d = got[i] / ref[i] - 1.0;
    sq += d * d;
    ++n;
  }
  std::printf("  against the reference: element RMS relative difference %.2f %% (%zu elements above a tenth of "
              "the mean), mean %+.2f %%\n",
              n ? 100.0 * std::sqrt(sq / static_cast<double>(n)) : 0.0, n, 100.0 * (mean_got / mean_ref - 1.0));
  // The same per group: where the differences are.
  std::printf("    per group (RMS, mean):");
  for (std::uint32_t g = 0; g < group_names.size(); ++g) {
    double gs = 0.0, gr = 0.0, gsq = 0.0;
    std::size_t gn = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      if (group[i] != g) continue;
      gs += got[i];
      gr += ref[i];
      if (!(ref[i] > 0.1 * mean_ref / static_cast<double>(ref.size()))) continue;
      const double d = got[i] / ref[i] - 1.0;
      gsq += d * d;
      ++gn;
    }
    if (gr > 0.0)
      std::printf("  %s %.2f %% %+.2f %%", group_names[g].c_str(), gn ? 100.0 * std::sqrt(gsq / static_cast<double>(gn)) : 0.0,
                  100.0 * (gs / gr - 1.0));
  }
  std::printf("\n");
}

/// With --plot: each child appends "SERIES FACETS SECONDS PEAK_RSS_MIB REFUSED" here.
std::string g_record_path;
std::string g_series;

/// The issue's configuration: Gauss-Seidel, monte_carlo at 1024 rays, one element per facet.
rad::SolveOptions issue_options(const Args& a) {
  rad::SolveOptions opt;
  opt.threads = a.threads;
  opt.memory_budget_bytes = a.memory_budget_bytes;
  opt.sky_rays = a.sky_rays;
  opt.method = rad::SolverMethod::gauss_seidel;
  opt.form_factors.method = rad::FormFactorMethod::monte_carlo;
  opt.form_factors.hemisphere_rays = 1024;
  // Facets have edges of at most facet_size, so none is split.
  opt.mesh.max_patch_area = static_cast<float>(a.city.facet_size * a.city.facet_size);
  opt.mesh.max_element_area = opt.mesh.max_patch_area;
  return opt;
}

double channel_sum(const rad::Rgb& c) { return static_cast<double>(c.x) + c.y + c.z; }

/// What run() reports to main() (as its child's exit code).
enum RunResult : int { kIssueConfiguration = 0, kFailed = 1, kOtherConfiguration = 3, kHierarchical = 4 };

/// Builds the city, solves it with `opt` and prints what it measured: kIssueConfiguration when
/// the solve was the issue's Monte Carlo configuration (monte_carlo, Gauss-Seidel, one element per
/// facet), kHierarchical when the hierarchical solver ran, else kOtherConfiguration.
int run(const Args& a, const rad::SolveOptions& opt, const char* label, bool print_city) {
  auto t0 = std::chrono::steady_clock::now();
  const bench::City city = bench::city(a.city);
  const double build = seconds_since(t0);
  if (print_city) {
    std::printf("city: %d x %d blocks, facet size %g m, seed %llu: %zu facets (ground %zu, under buildings %zu, "
                "streets %zu, walls %zu, roofs %zu), %zu buildings, %.0f m wide, %.0f m^2 of surface; built in %.2f s, "
                "peak RSS %.1f MiB\n",
                a.city.blocks, a.city.blocks, a.city.facet_size, static_cast<unsigned long long>(a.city.seed),
                city.facets(), city.ground_facets, city.hidden_facets, city.street_facets, city.wall_facets,
                city.roof_facets, city.buildings.size(), city.size, city.scene.total_area(), build, peak_rss_mib());
    std::fflush(stdout);
  }
  if (!a.solve) return kIssueConfiguration;
  std::printf("%s, %u threads:\n", label, a.threads);
  t0 = std::chrono::steady_clock::now();
  try {
    const rad::Solution sol = rad::solve(city.scene, opt);
    const double total = seconds_since(t0);
    const rad::SolveReport& r = sol.report();
    const double setup =
        total - r.seconds_meshing - r.seconds_lights - r.seconds_form_factors - r.seconds_solving;
    const bool hierarchical = r.method == rad::SolverMethod::hierarchical;
    if (!r.method_choice.empty())
      std::printf("  method: %s (automatic: %s)\n", hierarchical ? "hierarchical" : "gauss-seidel", r.method_choice.c_str());
    std::printf("  %zu elements, %zu patches, %s, %d sweeps, residual %.2e, %s\n", r.element_count, r.patch_count,
                hierarchical ? "links" : (std::string(rad::to_string(r.form_factor_method)) + " form factors").c_str(),
                r.iterations, r.residual, sol.status() == rad::SolveStatus::converged ? "converged" : "not converged");
    std::printf("  time %.2f s: meshing %.2f s, sky (first shot) %.2f s, set-up %.2f s, form factors %.2f s, "
                "solving %.2f s\n",
                total, r.seconds_meshing, r.seconds_lights, setup, r.seconds_form_factors, r.seconds_solving);
    std::printf("  peak RSS %.1f MiB, form factors %.1f MiB, %zu links\n", peak_rss_mib(),
                static_cast<double>(r.form_factor_bytes) / (1024.0 * 1024.0), r.link_count);
    std::printf("  rays: sky %.1f M (%.0f per element)", static_cast<double>(r.light_rays) * 1e-6,
                static_cast<double>(r.light_rays) / static_cast<double>(std::max<std::size_t>(1, r.element_count)));
    if (hierarchical)
      std::printf(", links %.1f M over %.2f M pairs examined, final gather %.1f M", static_cast<double>(r.link_rays) * 1e-6,
                  static_cast<double>(r.link_pairs_examined) * 1e-6, static_cast<double>(r.gather_rays) * 1e-6);
    std::printf("\n");
    std::printf("  group means B (W/m^2):");
    for (const char* group : {"ground", "streets", "walls", "roofs", "under_buildings"}) {
      const rad::Rgb b = sol.group_radiosity(group);
      std::printf("  %s (%.3f, %.3f, %.3f)", group, b.x, b.y, b.z);
    }
    const double emitted = channel_sum(r.emitted_power);
    std::printf("\n  power: the sky puts %.4g W onto the surfaces; absorbed %.1f %%, escaped %.1f %%\n", emitted / 3.0,
                100.0 * channel_sum(r.absorbed_power) / emitted, 100.0 * channel_sum(r.escaped_power) / emitted);
    for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
    if (!a.make_reference.empty()) {
      if (!write_values(a.make_reference, element_values(sol))) {
        std::printf("  could not write %s\n", a.make_reference.c_str());
        return kFailed;
      }
      std::printf("  wrote the reference to %s\n", a.make_reference.c_str());
    } else if (!a.reference.empty()) {
      const std::vector<float> ref = read_values(a.reference);
      if (ref.empty()) {
        std::printf("  could not read the reference %s\n", a.reference.c_str());
        return kFailed;
      }
      std::vector<std::uint32_t> group(sol.radiosity().size(), 0);
      for (std::size_t e = 0; e < group.size(); ++e)
        group[e] = sol.hierarchy().patches()[sol.hierarchy().element(static_cast<std::uint32_t>(e)).patch].group;
      compare(element_values(sol), ref, group, city.scene.groups());
      if (!a.elements.empty() && !write_elements(a.elements + (hierarchical ? ".hierarchical.csv" : ".monte-carlo.csv"),
                                                  sol, group, ref))
        std::printf("  could not write the elements to %s.*.csv\n", a.elements.c_str());
    }
    std::fflush(stdout);
    if (!g_record_path.empty())
      if (FILE* f = std::fopen(g_record_path.c_str(), "a")) {
        std::fprintf(f, "%s %zu %.3f %.1f 0\n", g_series.c_str(), city.facets(), total, peak_rss_mib());
        std::fclose(f);
      }
    if (hierarchical) return kHierarchical;
    return r.form_factor_method == rad::FormFactorMethod::monte_carlo && r.element_count == city.facets()
               ? kIssueConfiguration
               : kOtherConfiguration;
  } catch (const rad::Error& e) {
    std::printf("  refused after %.2f s (peak RSS %.1f MiB): %s%s\n", seconds_since(t0), peak_rss_mib(),
                e.code() == rad::ErrorCode::memory_budget ? "memory budget: " : "", e.what());
    std::fflush(stdout);
    if (!g_record_path.empty())
      if (FILE* f = std::fopen(g_record_path.c_str(), "a")) {
        std::fprintf(f, "%s %zu %.3f %.1f 1\n", g_series.c_str(), city.facets(), seconds_since(t0), peak_rss_mib());
        std::fclose(f);
      }
    // Refused by the defaults means refused by the issue's configuration too (the same rows).
    return kIssueConfiguration;
  }
}

/// Runs `run` in a child process (its own peak RSS) and returns its RunResult (kFailed when it
/// failed).
int in_child(const Args& a, const rad::SolveOptions& opt, const char* label, bool print_city) {
  std::fflush(stdout);  // the child must not inherit (and print again) buffered output
  const pid_t pid = fork();
  if (pid == 0) {
    try {
      _exit(run(a, opt, label, print_city));
    } catch (const std::exception& e) {
      std::printf("  error: %s\n", e.what());
      std::fflush(stdout);
      _exit(1);
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_city: bad argument '%s'\n", bad);
  std::fprintf(stderr,
               "usage: bench_city [22k|246k|1M] [--blocks N] [--facet METRES] [--seed K] [--threads T]\n"
               "                  [--memory-budget MIB] [--epsilon E] [--only monte-carlo|hierarchical] [--city-only]\n"
               "                  [--sky-rays N] [--make-reference FILE | --reference FILE [--elements PREFIX]]\n"
               "                  [--plot FILE.svg]\n"
               "  presets: 22k = --blocks 3 --facet 2.25 (23.5k facets), 246k = --blocks 10 --facet 2.25 (250k),\n"
               "           1M = --blocks 20 --facet 2.25 (991k)\n");
  return bad ? 2 : 0;
}

}  // namespace

/// --plot: the 22k, 246k and 1M cities (at the given facet size), the issue's Monte Carlo
/// configuration and the hierarchical solver each, then an SVG of time and peak memory against
/// the facet count (log-log), a refusal drawn as a cross at the time it took.
int plot(Args a) {
  char path[] = "/tmp/bench_city_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return 1;
  close(fd);
  g_record_path = path;
  for (int blocks : {3, 10, 20}) {
    a.city.blocks = blocks;
    g_series = "monte-carlo";
    in_child(a, issue_options(a), "the issue's configuration (gauss-seidel, monte-carlo 1024 rays)", true);
    rad::SolveOptions hr = issue_options(a);
    hr.method = rad::SolverMethod::hierarchical;
    hr.hierarchical.epsilon = a.epsilon;
    g_series = "hierarchical";
    in_child(a, hr, "hierarchical", false);
  }
  struct Point {
    double facets, seconds, mib;
    bool refused;
  };
  std::vector<Point> series[2];
  const char* names[2] = {"monte-carlo", "hierarchical"};
  const char* colours[2] = {"#1f77b4", "#d62728"};
  if (FILE* f = std::fopen(path, "r")) {
    char name[64];
    Point p{};
    int refused = 0;
    while (std::fscanf(f, "%63s %lf %lf %lf %d", name, &p.facets, &p.seconds, &p.mib, &refused) == 5) {
      p.refused = refused != 0;
      series[std::string(name) == names[0] ? 0 : 1].push_back(p);
    }
    std::fclose(f);
  }
  std::remove(path);
  std::FILE* svg = std::fopen(a.plot.c_str(), "w");
  if (!svg) return 1;
  std::fprintf(svg, "<svg xmlns='http://www.w3.org/2000/svg' width='880' height='340' font-family='sans-serif'>\n");
  // Two log-log panels: seconds and MiB against facets (1e4 .. 2e6).
  auto panel = [&](double ox, const char* y_label, double y_lo, double y_hi, auto value) {
    const double w = 420, h = 300, x_lo = 1e4, x_hi = 2e6;
    auto px = [&](double x) { return ox + 60 + (std::log10(x) - std::log10(x_lo)) / (std::log10(x_hi) - std::log10(x_lo)) * (w - 80); };
    auto py = [&](double y) { return 10 + (std::log10(y_hi) - std::log10(y)) / (std::log10(y_hi) - std::log10(y_lo)) * (h - 60); };
    std::fprintf(svg, "<rect x='%g' y='10' width='%g' height='%g' fill='none' stroke='#999'/>\n", ox + 60, w - 80, h - 60);
    for (double y = y_lo; y <= y_hi * 1.001; y *= 10)
      std::fprintf(svg, "<text x='%g' y='%g' font-size='11'>%g</text>\n", ox + 5, py(y) + 4, y);
    for (double x : {1e4, 1e5, 1e6})
      std::fprintf(svg, "<text x='%g' y='%g' font-size='11'>%g</text>\n", px(x) - 10, h - 35, x);
    std::fprintf(svg, "<text x='%g' y='%g' font-size='12'>facets (log)</text>\n", ox + 200, h - 15);
    std::fprintf(svg, "<text x='%g' y='25' font-size='12'>%s</text>\n", ox + 70, y_label);
    for (int k = 0; k < 2; ++k) {
      std::fprintf(svg, "<polyline fill='none' stroke='%s' stroke-width='1.5' points='", colours[k]);
      for (const Point& p : series[k])
        if (!p.refused) std::fprintf(svg, "%g,%g ", px(p.facets), py(std::max(y_lo, value(p))));
      std::fprintf(svg, "'/>\n");
      for (const Point& p : series[k]) {
        const double x = px(p.facets), y = py(std::max(y_lo, value(p)));
        if (p.refused)
          std::fprintf(svg, "<text x='%g' y='%g' font-size='14' fill='%s'>x refused</text>\n", x - 5, y + 5, colours[k]);
        else
          std::fprintf(svg, "<circle cx='%g' cy='%g' r='3' fill='%s'/>\n", x, y, colours[k]);
      }
    }
  };
  panel(0, "seconds, 2 threads (log)", 1, 1000, [](const Point& p) { return p.seconds; });
  panel(440, "peak RSS, MiB (log)", 10, 10000, [](const Point& p) { return p.mib; });
  for (int k = 0; k < 2; ++k)
    std::fprintf(svg, "<text x='%d' y='%d' font-size='12' fill='%s'>%s</text>\n", 80 + 140 * k, 335, colours[k], names[k]);
  std::fprintf(svg, "</svg>\n");
  std::fclose(svg);
  std::printf("wrote %s\n", a.plot.c_str());
  return 0;
}

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    char* end = nullptr;
    if (arg == "--help" || arg == "-h") return usage(nullptr);
    if (arg == "22k" || arg == "246k" || arg == "1M") {
      a.city.blocks = arg == "22k" ? 3 : arg == "246k" ? 10 : 20;
      a.city.facet_size = 2.25;
    } else if (arg == "--blocks" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 1 || v > 1000) return usage(argv[i]);
      a.city.blocks = static_cast<int>(v);
    } else if (arg == "--facet" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v > 0.0) || !std::isfinite(v)) return usage(argv[i]);
      a.city.facet_size = v;
    } else if (arg == "--seed" && has_value) {
      a.city.seed = std::strtoull(argv[++i], &end, 10);
      if (*end != '\0') return usage(argv[i]);
    } else if (arg == "--memory-budget" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 1) return usage(argv[i]);
      a.memory_budget_bytes = static_cast<std::size_t>(v) << 20;
    } else if (arg == "--epsilon" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v > 0.0) || v > 1.0) return usage(argv[i]);
      a.epsilon = static_cast<float>(v);
    } else if (arg == "--only" && has_value) {
      const std::string which = argv[++i];
      if (which != "monte-carlo" && which != "hierarchical") return usage(argv[i]);
      a.monte_carlo = which == "monte-carlo";
      a.hierarchical = which == "hierarchical";
    } else if (arg == "--sky-rays" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 5 || v > (1L << 24)) return usage(argv[i]);
      a.sky_rays = static_cast<std::uint32_t>(v);
    } else if (arg == "--make-reference" && has_value) {
      a.make_reference = argv[++i];
    } else if (arg == "--reference" && has_value) {
      a.reference = argv[++i];
    } else if (arg == "--elements" && has_value) {
      a.elements = argv[++i];
    } else if (arg == "--plot" && has_value) {
      a.plot = argv[++i];
    } else if (arg == "--city-only") {
      a.solve = false;
    } else if (arg == "--threads" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 0) return usage(argv[i]);
      a.threads = static_cast<unsigned>(v);
    } else {
      return usage(argv[i]);
    }
  }
  std::printf("bench_city: radiosity %s, procedural city under a uniform sky of %g W/m^2\n", rad::version(),
              static_cast<double>(bench::kCitySkyIrradiance));
  if (!a.plot.empty()) return plot(a);
  if (!a.make_reference.empty()) {
    // Gauss-Seidel over Monte Carlo rows with kReferenceFactor times the rays, and as many
    // more sky rays: the converged reference the accuracy targets are stated against.
    rad::SolveOptions ref = issue_options(a);
    ref.form_factors.hemisphere_rays *= kReferenceFactor;
    ref.sky_rays *= kReferenceFactor;
    ref.tolerance = 1e-5;
    const std::string label = "reference (gauss-seidel, monte-carlo " + std::to_string(ref.form_factors.hemisphere_rays) +
                              " rays, " + std::to_string(ref.sky_rays) + " sky rays, tolerance 1e-5)";
    return in_child(a, ref, label.c_str(), true) == kFailed ? 1 : 0;
  }
  rad::SolveOptions defaults;
  defaults.threads = a.threads;
  defaults.memory_budget_bytes = a.memory_budget_bytes;
  defaults.sky_rays = a.sky_rays;
  int first = 0;
  if (a.monte_carlo) {
    first = in_child(a, defaults, "default solve (automatic method and form factors, tolerance 1e-3)", true);
    if (first == kOtherConfiguration || first == kHierarchical)
      in_child(a, issue_options(a),
               "the issue's configuration (gauss-seidel, monte-carlo 1024 rays, one element per facet)", false);
  }
  // The hierarchical solver with one element per facet, unless the defaults just ran it.
  if (a.hierarchical && first != kHierarchical) {
    rad::SolveOptions hr = issue_options(a);
    hr.method = rad::SolverMethod::hierarchical;
    hr.hierarchical.epsilon = a.epsilon;
    const std::string label = "hierarchical (epsilon " + std::to_string(a.epsilon) + ", one element per facet)";
    const int second = in_child(a, hr, label.c_str(), !a.monte_carlo);
    if (second == kFailed) first = kFailed;
  }
  return first == kFailed ? 1 : 0;
}
