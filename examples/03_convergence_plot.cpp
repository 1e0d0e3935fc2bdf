// Convergence of the three solvers on the Cornell box: residual against iterations and against
// time, written as an SVG plot (log residual). Usage: example_03_convergence_plot [out.svg]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace {

struct Series {
  std::string name, colour;
  std::vector<double> x, residual;
};

// One panel: log10(residual) against x, in a w x h box at (ox, oy).
void panel(std::ofstream& svg, const std::vector<Series>& series, const char* x_label, bool log_x, double ox,
           double oy) {
  const double w = 420, h = 300;
  double x_max = 0, r_min = 1, r_max = 1;
  for (const Series& s : series)
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      x_max = std::max(x_max, s.x[i]);
      r_min = std::min(r_min, s.residual[i]);
      r_max = std::max(r_max, s.residual[i]);
    }
  const double lo = std::floor(std::log10(std::max(r_min, 1e-12))), hi = std::ceil(std::log10(r_max));
  auto px = [&](double x) {
    const double f = log_x ? std::log10(std::max(x, 1.0)) / std::max(std::log10(x_max), 1e-12) : x / std::max(x_max, 1e-12);
    return ox + 50 + (w - 60) * f;
  };
  auto py = [&](double r) { return oy + 10 + (h - 50) * (hi - std::log10(std::max(r, 1e-12))) / std::max(hi - lo, 1.0); };
  svg << "<rect x='" << ox + 50 << "' y='" << oy + 10 << "' width='" << w - 60 << "' height='" << h - 50
      << "' fill='none' stroke='#888'/>\n";
  for (double d = lo; d <= hi; d += 1)
    svg << "<text x='" << ox + 5 << "' y='" << py(std::pow(10.0, d)) + 4 << "' font-size='11'>1e" << d << "</text>\n";
  svg << "<text x='" << ox + 50 << "' y='" << oy + h - 22 << "' font-size='12'>" << x_label << ", up to "
      << x_max << (log_x ? " (log scale)" : "") << "</text>\n";
  for (const Series& s : series) {
    svg << "<polyline fill='none' stroke='" << s.colour << "' stroke-width='1.5' points='";
    for (std::size_t i = 0; i < s.x.size(); ++i) svg << px(s.x[i]) << ',' << py(s.residual[i]) << ' ';
    svg << "'/>\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "convergence.svg";
  const radiosity::Scene scene = radiosity::cornell_box();
  const struct {
    radiosity::SolverMethod method;
    const char* name;
    const char* colour;
  } methods[] = {{radiosity::SolverMethod::jacobi, "Jacobi", "#d62728"},
                 {radiosity::SolverMethod::gauss_seidel, "Gauss-Seidel", "#2ca02c"},
                 {radiosity::SolverMethod::progressive, "progressive", "#1f77b4"}};
  std::vector<Series> by_step, by_time;
  for (const auto& m : methods) {
    radiosity::SolveOptions opt;
    opt.method = m.method;
    opt.tolerance = 1e-4;
    const radiosity::Solution sol = radiosity::solve(scene, opt);
    const radiosity::SolveReport& r = sol.report();
    Series s{m.name, m.colour, {}, r.residual_history}, t{m.name, m.colour, {}, r.residual_history};
    for (std::size_t i = 0; i < r.residual_history.size(); ++i) {
      s.x.push_back(static_cast<double>(i + 1));
      // Time includes computing the form factors the solver needed up to then.
      t.x.push_back(r.time_history[i]);
    }
    std::printf("%-13s %5d iterations to residual %.3g in %.2f s (form factors %.2f s)\n", m.name, r.iterations,
                r.residual, r.seconds_form_factors + r.seconds_solving, r.seconds_form_factors);
    by_step.push_back(std::move(s));
    by_time.push_back(std::move(t));
  }
  std::ofstream svg(out);
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='880' height='340' font-family='sans-serif'>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n";
  panel(svg, by_step, "sweeps or shooting steps", true, 0, 0);
  panel(svg, by_time, "seconds, form factors included", false, 440, 0);
  double y = 30;
  for (const Series& s : by_step) {
    svg << "<text x='780' y='" << y << "' font-size='12' fill='" << s.colour << "'>" << s.name << "</text>\n";
    y += 16;
  }
  svg << "</svg>\n";
  std::printf("wrote %s\n", out.c_str());
  return svg ? 0 : 1;
}
