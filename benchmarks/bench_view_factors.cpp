// bench_view_factors: per-facet view factors (view_factor_matrix(), issue #16) for thermal and
// urban-climate users, on two scenes:
//  - the procedural city of city.hpp (open, under the sky) in fast mode (Monte Carlo rows) with
//    the reciprocity correction: time, peak memory, stored factors, the estimates' reciprocity
//    error and row standard errors before the correction, the sky view factors per group;
//  - a closed, obstructed enclosure of facets (a faceted room around a faceted block) in exact
//    mode (ray_cast: contour integrals, occlusion by shaft-culled rays) and fast mode, both
//    enclosure-corrected: their agreement per row sum and per large factor, and the speed ratio.
// Each part runs in one process after the other, so its peak RSS is the largest so far.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"
#include "city.hpp"

namespace rad = radiosity;

namespace {

struct Args {
  bench::CityOptions city;
  std::uint32_t rays = rad::FormFactorOptions{}.hemisphere_rays;
  unsigned threads = 0;
  bool city_part = true, enclosure_part = true;
  float room_facet = 0.25f;  ///< the enclosure's facet size (a 4 m room): 0.25 gives 1 632 facets
};

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_view_factors: bad argument '%s'\n", bad);
  std::fprintf(stderr,
               "usage: bench_view_factors [22k|246k] [--blocks N] [--facet METRES] [--rays N] [--threads T]\n"
               "                          [--room-facet METRES] [--only city|enclosure]\n");
  return bad ? 2 : 0;
}

/// Area-weighted mean and the largest of a per-row quantity.
struct Spread {
  double mean = 0.0, largest = 0.0;
};
template <typename F>
Spread spread(const rad::ViewFactorMatrix& m, F value) {
  Spread s;
  double area = 0.0;
  for (std::size_t i = 0; i < m.rows(); ++i) {
    const double v = value(i);
    s.mean += m.area[i] * v;
    area += m.area[i];
    s.largest = std::max(s.largest, std::fabs(v));
  }
  s.mean /= area;
  return s;
}

void print_matrix(const char* what, const rad::ViewFactorMatrix& m) {
  const double bytes = static_cast<double>(m.values.size() * 8 + m.row_offsets.size() * 8 + m.rows() * 32);
  std::printf("  %s: %zu rows, %zu factors (%.0f per row), %.1f MiB as CSR, %.2f s, peak RSS %.0f MiB\n", what,
              m.rows(), m.non_zeros(), static_cast<double>(m.non_zeros()) / static_cast<double>(m.rows()),
              bytes / (1 << 20), m.seconds, bench::peak_rss_mib());
  const rad::ViewFactorCorrectionReport& c = m.correction;
  std::printf("    before correction: reciprocity error up to %.3g; |1 - row sum| up to %.3g, area-weighted RMS %.3g\n",
              c.reciprocity_before, c.row_sum_error_before, c.row_sum_rms_before);
  std::printf("    correction: factors changed by up to %.3g (RMS %.3g)", c.largest_change, c.rms_change);
  if (c.iterations > 0) std::printf(", %d CG iterations, %zu clamped", c.iterations, c.clamped);
  std::printf("\n");
  if (!m.row_standard_error.empty()) {
    const Spread se = spread(m, [&](std::size_t i) { return m.row_standard_error[i]; });
    std::printf("    row sums' standard error (binomial): mean %.3g, largest %.3g\n", se.mean, se.largest);
  }
}

/// A closed room [0,4]^3 around a block, every face cut into facets of side `facet`.
rad::Scene faceted_room(float facet) {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  // One axis-aligned rectangle at `at` on `axis`, spanning [lo, hi] on the other two, cut into
  // facets, facing `facing` (+1 or -1 along the axis).
  auto rectangle = [&](int axis, float at, glm::vec2 lo, glm::vec2 hi, int facing, const char* group) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::max(1, static_cast<int>(std::lround((hi.x - lo.x) / facet)));
    const int nv = std::max(1, static_cast<int>(std::lround((hi.y - lo.y) / facet)));
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const float u0 = lo.x + (hi.x - lo.x) * static_cast<float>(i) / static_cast<float>(nu);
        const float u1 = lo.x + (hi.x - lo.x) * static_cast<float>(i + 1) / static_cast<float>(nu);
        const float v0 = lo.y + (hi.y - lo.y) * static_cast<float>(j) / static_cast<float>(nv);
        const float v1 = lo.y + (hi.y - lo.y) * static_cast<float>(j + 1) / static_cast<float>(nv);
        std::vector<glm::vec3> q(4, glm::vec3(at));
        const float us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
        for (int k = 0; k < 4; ++k) {
          q[static_cast<std::size_t>(k)][u] = us[k];
          q[static_cast<std::size_t>(k)][v] = vs[k];
        }
        // (u, v, axis) is right-handed, so u x v points along +axis.
        if (facing < 0) std::reverse(q.begin(), q.end());
        scene.add_polygon(q, m, group);
      }
  };
  const float S = 4.0f;
  for (int axis = 0; axis < 3; ++axis) {
    rectangle(axis, 0.0f, glm::vec2(0.0f), glm::vec2(S), +1, "room");
    rectangle(axis, S, glm::vec2(0.0f), glm::vec2(S), -1, "room");
  }
  // The block [1.5, 2.5] x [0, 1.5] x [1.5, 2.5] (y up) stands on the floor: five faces outward.
  const glm::vec3 lo(1.5f, 0.0f, 1.5f), hi(2.5f, 1.5f, 2.5f);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const glm::vec2 a(lo[u], lo[v]), b(hi[u], hi[v]);
    if (axis != 1) rectangle(axis, lo[axis], a, b, -1, "block");
    rectangle(axis, hi[axis], a, b, +1, "block");
  }
  return scene;
}

void city_part(const Args& a) {
  const bench::City city = bench::city(a.city);
  std::printf("city: %d x %d blocks, facet %.2f m: %zu facets (open, under the sky)\n", a.city.blocks, a.city.blocks,
              a.city.facet_size, city.facets());
  rad::ViewFactorOptions o;
  o.level = rad::ViewFactorLevel::polygon;
  o.form_factors.method = rad::FormFactorMethod::monte_carlo;
  o.form_factors.hemisphere_rays = a.rays;
  o.form_factors.threads = a.threads;
  o.correction = rad::ViewFactorCorrection::reciprocity;
  const rad::ViewFactorMatrix m = rad::view_factor_matrix(city.scene, o);
  char what[96];
  std::snprintf(what, sizeof what, "fast (monte-carlo, %u rays per facet), reciprocity", a.rays);
  print_matrix(what, m);
  // The sky view factor per group: what urban-climate codes take for longwave exchange with the sky.
  std::printf("    sky view factor (area-weighted mean per group):");
  for (std::size_t g = 0; g < city.scene.groups().size(); ++g) {
    double sky = 0.0, area = 0.0;
    for (std::size_t i = 0; i < m.rows(); ++i)
      if (city.scene.polygons()[m.ids[i]].group == g) {
        sky += m.area[i] * m.sky[i];
        area += m.area[i];
      }
    if (area > 0.0) std::printf(" %s %.3f", city.scene.groups()[g].c_str(), sky / area);
  }
  std::size_t over = 0;
  for (std::size_t i = 0; i < m.rows(); ++i) {
    double sum = m.sky[i];
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k) sum += static_cast<double>(m.values[k]);
    const double se = std::hypot(m.sky_standard_error[i], m.row_standard_error[i]);
    over += sum > 1.0 + 3.0 * se + 1e-6 ? 1 : 0;
  }
  std::printf("\n    rows whose factors and sky add up to more than 1 (beyond 3 standard errors): %zu\n", over);
}

void enclosure_part(const Args& a) {
  const rad::Scene scene = faceted_room(a.room_facet);
  std::printf("enclosure: a 4 m room around a block on its floor, facet %.3g m: %zu facets (closed)\n", a.room_facet,
              scene.polygons().size());
  rad::ViewFactorOptions o;
  o.level = rad::ViewFactorLevel::polygon;
  o.correction = rad::ViewFactorCorrection::enclosure;
  o.form_factors.threads = a.threads;
  // One element per facet, as View3D integrates each surface whole.
  o.mesh.max_patch_area = o.mesh.max_element_area = 1e30f;
  o.form_factors.method = rad::FormFactorMethod::ray_cast;
  const rad::ViewFactorMatrix exact = rad::view_factor_matrix(scene, o);
  print_matrix("exact (ray-cast), enclosure", exact);
  o.form_factors.method = rad::FormFactorMethod::monte_carlo;
  o.form_factors.hemisphere_rays = a.rays;
  const rad::ViewFactorMatrix fast = rad::view_factor_matrix(scene, o);
  char what[96];
  std::snprintf(what, sizeof what, "fast (monte-carlo, %u rays per facet), enclosure", a.rays);
  print_matrix(what, fast);
  // Agreement: factors of 0.01 and more in the exact matrix.
  double worst = 0.0, squares = 0.0;
  std::size_t large = 0;
  for (std::size_t i = 0; i < exact.rows(); ++i)
    for (std::uint64_t k = exact.row_offsets[i]; k < exact.row_offsets[i + 1]; ++k) {
      if (exact.values[k] < 0.01f) continue;
      const double d = std::fabs(fast.at(i, exact.columns[k]) - static_cast<double>(exact.values[k]));
      worst = std::max(worst, d);
      squares += d * d;
      ++large;
    }
  std::printf("  fast against exact, over the %zu factors >= 0.01: largest |difference| %.3g, RMS %.3g\n", large, worst,
              large ? std::sqrt(squares / static_cast<double>(large)) : 0.0);
  std::printf("  speed: fast is %.1fx the exact mode's\n", exact.seconds / fast.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    char* end = nullptr;
    if (arg == "--help" || arg == "-h") return usage(nullptr);
    if (arg == "22k" || arg == "246k") {
      a.city.blocks = arg == "22k" ? 3 : 10;
      a.city.facet_size = 2.25;
    } else if (arg == "--blocks" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 1 || v > 1000) return usage(argv[i]);
      a.city.blocks = static_cast<int>(v);
    } else if (arg == "--facet" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v > 0.0) || !std::isfinite(v)) return usage(argv[i]);
      a.city.facet_size = v;
    } else if (arg == "--rays" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 16 || v > (1L << 20)) return usage(argv[i]);
      a.rays = static_cast<std::uint32_t>(v);
    } else if (arg == "--threads" && has_value) {
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 0) return usage(argv[i]);
      a.threads = static_cast<unsigned>(v);
    } else if (arg == "--room-facet" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v > 0.01) || v > 4.0) return usage(argv[i]);
      a.room_facet = static_cast<float>(v);
    } else if (arg == "--only" && has_value) {
      const std::string which = argv[++i];
      if (which != "city" && which != "enclosure") return usage(argv[i]);
      a.city_part = which == "city";
      a.enclosure_part = which == "enclosure";
    } else {
      return usage(argv[i]);
    }
  }
  std::printf("bench_view_factors: radiosity %s, %u threads\n", rad::version(),
              a.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : a.threads);
  if (a.enclosure_part) enclosure_part(a);
  if (a.city_part) city_part(a);
  return 0;
}
