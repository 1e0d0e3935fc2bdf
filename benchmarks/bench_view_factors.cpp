// bench_view_factors: per-facet view factors (view_factor_matrix(), issue #16) for thermal and
// urban-climate users, on two scenes:
//  - the procedural city of city.hpp (open, under the sky) in fast mode (Monte Carlo rows) with
//    the reciprocity correction: time, peak memory, stored factors, the estimates' reciprocity
//    error and row standard errors before the correction, the sky view factors per group; with
//    --city-links the hierarchical links' factors as well;
//  - a closed, obstructed enclosure of facets (a faceted room around a faceted block, or with
//    --cornell the Cornell box closed by a front wall, its two turned blocks) in exact
//    mode (ray_cast: contour integrals, occlusion by shaft-culled rays) and fast mode, both
//    enclosure-corrected, and the hierarchical links' rows (ViewFactorMethod::hierarchical): their
//    agreement per row sum and per large factor, and the speed ratios;
//    and, side by side with NIST View3D (G. N. Walton, "Calculation of obstructed view factors by
//    adaptive integration", NISTIR 6925, 2002), built apart from this repository: --write-vs3
//    writes the room as View3D's input file, --view3d-output reads View3D's text output for it
//    and compares both modes with it per row sum, per large factor and overall.
// Each part runs in one process after the other, so its peak RSS is the largest so far.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
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
  bool city_links = false;  ///< the city's factors from the hierarchical links as well (--city-links)
  /// The enclosure's facet size (a 4 m room): 0.25 gives 1 648 facets; 1/6 (0.1666667) 3 708, the
  /// most below 4 000 whose floor facets end at the block's footprint (at 0.16 some lie partly
  /// under it, see nothing there, and the enclosure correction refuses the room).
  float room_facet = 0.25f;
  /// --cornell MM: instead of the room, the Cornell box closed by a front wall, its two blocks as
  /// published (one turned each way), every face cut into facets of about MM millimetres, the
  /// floor cut around the blocks (23 gives 4 111 facets).
  float cornell_facet = 0.0f;
  std::string write_vs3;      ///< write the room as a View3D input file here (before computing)
  std::string view3d_output;  ///< View3D's text output file (out=0) for that room, to compare with
  double view3d_seconds = 0.0;  ///< View3D's wall time for it, measured outside (0: not given)
};

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_view_factors: bad argument '%s'\n", bad);
  std::fprintf(stderr,
               "usage: bench_view_factors [22k|246k] [--blocks N] [--facet METRES] [--rays N] [--threads T]\n"
               "                          [--room-facet METRES | --cornell MM] [--only city|enclosure] [--city-links]\n"
               "                          [--write-vs3 FILE] [--view3d-output FILE [--view3d-seconds S]]\n");
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

/// The Cornell box (the published geometry in mm, its room made rectangular) closed by a front
/// wall, the blocks without bottoms standing on the floor, every face cut into facets of about
/// `facet` mm: a closed enclosure obstructed by two blocks turned each way, the "Cornell-style"
/// scene of issue #16's target.
rad::Scene faceted_cornell(float facet) {
  rad::Scene scene;
  const rad::MaterialId m = scene.add_material(rad::Material{});
  using Quad = std::vector<glm::vec3>;
  // A planar quad cut bilinearly, its facets wound as the quad is (its normal towards `inside`
  // when `toward`, else away from it).
  auto facets = [&](Quad q, const glm::vec3& inside, bool toward, const char* group) {
    const glm::vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
    if ((glm::dot(n, inside - q[0]) < 0.0f) == toward) std::reverse(q.begin(), q.end());
    const float du = std::max(glm::length(q[1] - q[0]), glm::length(q[2] - q[3]));
    const float dv = std::max(glm::length(q[3] - q[0]), glm::length(q[2] - q[1]));
    const int nu = std::max(1, static_cast<int>(std::lround(du / facet)));
    const int nv = std::max(1, static_cast<int>(std::lround(dv / facet)));
    // In double, rounded once: a face's facets then share its plane exactly where it lies along
    // an axis (View3D warns of vertices out of plane otherwise).
    auto at = [&](int i, int j) {
      const double s = static_cast<double>(i) / nu, t = static_cast<double>(j) / nv;
      const glm::dvec3 p = (1.0 - t) * ((1.0 - s) * glm::dvec3(q[0]) + s * glm::dvec3(q[1])) +
                           t * ((1.0 - s) * glm::dvec3(q[3]) + s * glm::dvec3(q[2]));
      return glm::vec3(p);
    };
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) scene.add_polygon({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}, m, group);
  };
  const float X = 556.0f, Y = 548.8f, Z = 559.2f;
  const glm::vec3 inside(278.0f, 274.0f, 280.0f);
  // The floor: facets of the grid less the blocks' footprints (each grid cell split by the
  // footprints' edge lines into convex pieces, those inside a footprint dropped, pieces of more
  // than 4 corners fanned into triangles, as View3D takes 3 or 4), so that no facet lies partly
  // under a block, seeing nothing there (its row would not sum to 1 and the two programs would
  // disagree about the hidden part: View3D counts it).
  // The blocks as rad::cornell_box() has them (the published corners); a block's footprint is
  // its top face seen from above (its sides are vertical).
  const rad::Scene published = rad::cornell_box();
  const char* const block_groups[2] = {"short_block", "tall_block"};
  std::vector<std::vector<glm::vec2>> footprints;
  for (const char* name : block_groups) {
    const rad::GroupId g = *published.find_group(name);
    for (const rad::Polygon& p : published.polygons()) {
      if (p.group != g || !(p.normal.y > 0.99f)) continue;
      std::vector<glm::vec2> corners;
      for (const glm::vec3& v : p.vertices) corners.emplace_back(v.x, v.z);
      footprints.push_back(corners);
    }
  }
  using Piece = std::vector<glm::vec2>;
  auto cross2 = [](glm::vec2 u, glm::vec2 v) { return u.x * v.y - u.y * v.x; };
  auto area2 = [&](const Piece& q) {
    float a = 0.0f;
    for (std::size_t k = 0; k < q.size(); ++k) a += cross2(q[k], q[(k + 1) % q.size()]);
    return 0.5f * std::fabs(a);
  };
  // The part of convex q where side * cross(b - a, p - a) >= 0.
  auto half = [&](const Piece& q, glm::vec2 a, glm::vec2 b, float side) {
    Piece out;
    for (std::size_t k = 0; k < q.size(); ++k) {
      const glm::vec2 p = q[k], r = q[(k + 1) % q.size()];
      const float dp = side * cross2(b - a, p - a), dr = side * cross2(b - a, r - a);
      if (dp >= 0.0f) out.push_back(p);
      if ((dp > 0.0f && dr < 0.0f) || (dp < 0.0f && dr > 0.0f)) out.push_back(p + (dp / (dp - dr)) * (r - p));
    }
    return out;
  };
  const int nx = std::max(1, static_cast<int>(std::lround(X / facet)));
  const int nz = std::max(1, static_cast<int>(std::lround(Z / facet)));
  const float cell_area = (X / static_cast<float>(nx)) * (Z / static_cast<float>(nz));
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nz; ++j) {
      const float x0 = X * static_cast<float>(i) / static_cast<float>(nx), x1 = X * static_cast<float>(i + 1) / static_cast<float>(nx);
      const float z0 = Z * static_cast<float>(j) / static_cast<float>(nz), z1 = Z * static_cast<float>(j + 1) / static_cast<float>(nz);
      std::vector<Piece> pieces = {{{x0, z0}, {x1, z0}, {x1, z1}, {x0, z1}}};
      for (const Piece& f : footprints) {
        const float orientation = cross2(f[1] - f[0], f[2] - f[0]) > 0.0f ? 1.0f : -1.0f;  // inside: >= 0
        std::vector<Piece> outside;
        for (Piece rest : pieces) {
          // A piece that does not reach into the footprint stays whole (cut by the edges' lines
          // it would leave slivers far from the block).
          Piece within = rest;
          for (std::size_t e = 0; e < f.size() && within.size() >= 3; ++e)
            within = half(within, f[e], f[(e + 1) % f.size()], orientation);
          if (within.size() < 3 || area2(within) <= 1e-6f * cell_area) {
            outside.push_back(rest);
            continue;
          }
          for (std::size_t e = 0; e < f.size() && !rest.empty(); ++e) {
            const Piece out = half(rest, f[e], f[(e + 1) % f.size()], -orientation);
            if (out.size() >= 3 && area2(out) > 1e-6f * cell_area) outside.push_back(out);
            rest = half(rest, f[e], f[(e + 1) % f.size()], orientation);
            if (rest.size() < 3 || area2(rest) <= 1e-6f * cell_area) rest.clear();
          }
          // What is left of `rest` lies inside the footprint: dropped.
        }
        pieces = std::move(outside);
      }
      for (const Piece& q : pieces) {
        auto lift = [](glm::vec2 p) { return glm::vec3(p.x, 0.0f, p.y); };
        auto add = [&](Quad poly) {
          const glm::vec3 n = glm::cross(poly[1] - poly[0], poly[2] - poly[0]);
          if (n.y < 0.0f) std::reverse(poly.begin(), poly.end());
          scene.add_polygon(poly, m, "floor");
        };
        if (q.size() <= 4) {
          Quad poly;
          for (const glm::vec2& p : q) poly.push_back(lift(p));
          add(poly);
        } else {
          for (std::size_t k = 1; k + 1 < q.size(); ++k) add({lift(q[0]), lift(q[k]), lift(q[k + 1])});
        }
      }
    }
  facets({{0, Y, 0}, {X, Y, 0}, {X, Y, Z}, {0, Y, Z}}, inside, true, "ceiling");
  facets({{0, 0, Z}, {X, 0, Z}, {X, Y, Z}, {0, Y, Z}}, inside, true, "back_wall");
  facets({{0, 0, 0}, {X, 0, 0}, {X, Y, 0}, {0, Y, 0}}, inside, true, "front_wall");
  facets({{0, 0, 0}, {0, 0, Z}, {0, Y, Z}, {0, Y, 0}}, inside, true, "green_wall");
  facets({{X, 0, 0}, {X, 0, Z}, {X, Y, Z}, {X, Y, 0}}, inside, true, "red_wall");
  // The blocks' faces, outward as cornell_box() makes them.
  for (const char* name : block_groups) {
    const rad::GroupId g = *published.find_group(name);
    for (const rad::Polygon& p : published.polygons())
      if (p.group == g) facets(Quad(p.vertices.begin(), p.vertices.end()), p.vertices[0] + p.normal, true, name);
  }
  return scene;
}

/// View3D's text output file (out=0; docs/SCENE_VS3.md, "Output file"; written by View3D's
/// SaveF0): the header "<program> <version> <out> <encl> <emit> <N>", then the N areas, N rows
/// F(i -> 1..N) ("%.6f") and the N emissivities, each a line of numbers.
struct View3DOutput {
  std::string program, version;
  int enclosure = 0, script_f = 0;
  std::size_t n = 0;
  std::vector<double> area;
  std::vector<float> factors;  ///< dense, row-major: F(i -> j) = factors[i * n + j], 0-based
  double at(std::size_t i, std::size_t j) const { return static_cast<double>(factors[i * n + j]); }
};

/// Reads `path` into `out`; false, with a message on stderr, for a file that is not one.
bool read_view3d_output(const std::string& path, View3DOutput& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "bench_view_factors: cannot open View3D output '%s'\n", path.c_str());
    return false;
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const char* p = text.c_str();
  char program[64] = {}, version[64] = {};
  int format = -1, consumed = 0;
  unsigned long n = 0;
  if (std::sscanf(p, "%63s %63s %d %d %d %lu%n", program, version, &format, &out.enclosure, &out.script_f, &n,
                  &consumed) != 6 ||
      n == 0 || n > 20000) {
    std::fprintf(stderr, "bench_view_factors: '%s' does not start with View3D's output header\n", path.c_str());
    return false;
  }
  if (format != 0) {
    std::fprintf(stderr, "bench_view_factors: '%s' is View3D output format %d; only the text format (out=0) is read\n",
                 path.c_str(), format);
    return false;
  }
  out.program = program;
  out.version = version;
  out.n = n;
  p += consumed;
  // The numbers follow in order; strtod skips the blanks and line ends between them.
  auto next = [&p](double& v) {
    char* end = nullptr;
    v = std::strtod(p, &end);
    if (end == p) return false;
    p = end;
    return true;
  };
  out.area.resize(out.n);
  out.factors.resize(out.n * out.n);
  double v = 0.0;
  for (std::size_t i = 0; i < out.n; ++i)
    if (!next(out.area[i])) {
      std::fprintf(stderr, "bench_view_factors: '%s': area %zu is missing\n", path.c_str(), i + 1);
      return false;
    }
  for (std::size_t k = 0; k < out.n * out.n; ++k) {
    if (!next(v)) {
      std::fprintf(stderr, "bench_view_factors: '%s': factor %zu of row %zu is missing\n", path.c_str(),
                   k % out.n + 1, k / out.n + 1);
      return false;
    }
    out.factors[k] = static_cast<float>(v);
  }
  for (std::size_t i = 0; i < out.n; ++i)
    if (!next(v)) {
      std::fprintf(stderr, "bench_view_factors: '%s': emissivity %zu is missing\n", path.c_str(), i + 1);
      return false;
    }
  // View3D's normalisation (encl=1) divides each row by its sum: a row that sees nothing (a
  // floor facet under the block) turns the whole matrix into NaN.
  const std::size_t broken = static_cast<std::size_t>(
      std::count_if(out.factors.begin(), out.factors.end(), [](float f) { return !std::isfinite(f); }));
  if (broken > 0) {
    std::fprintf(stderr,
                 "bench_view_factors: '%s' holds %zu factors that are not numbers (View3D's encl=1 normalisation"
                 " divides by the zero sums of rows that see nothing; write the room with encl=0)\n",
                 path.c_str(), broken);
    return false;
  }
  return true;
}

/// Largest and RMS of |difference| over a set of values, and where the largest is.
struct Deviation {
  double largest = 0.0, squares = 0.0;
  std::size_t count = 0, where = 0;
  void add(double d, std::size_t at = 0) {
    if (std::fabs(d) > largest) {
      largest = std::fabs(d);
      where = at;
    }
    squares += d * d;
    ++count;
  }
  double rms() const { return count ? std::sqrt(squares / static_cast<double>(count)) : 0.0; }
};

/// `m` against View3D's matrix: row sums, factors where View3D's is >= 0.01, and all N^2
/// factors. Row r of `m` is polygon m.ids[r], which save_view3d() wrote as surface ids[r] + 1
/// (the room has no obstruction-only polygons), so View3D's row and column ids[r].
struct Agreement {
  Deviation row_sums, large, all;
};
Agreement against_view3d(const rad::ViewFactorMatrix& m, const View3DOutput& v) {
  Agreement a;
  std::vector<double> row(v.n);
  for (std::size_t r = 0; r < m.rows(); ++r) {
    std::fill(row.begin(), row.end(), 0.0);
    double ours = 0.0, theirs = 0.0;
    for (std::uint64_t k = m.row_offsets[r]; k < m.row_offsets[r + 1]; ++k) {
      row[m.ids[m.columns[k]]] = static_cast<double>(m.values[k]);
      ours += static_cast<double>(m.values[k]);
    }
    const std::size_t i = m.ids[r];
    for (std::size_t j = 0; j < v.n; ++j) {
      const double f = v.at(i, j);
      theirs += f;
      a.all.add(row[j] - f, i);
      if (f >= 0.01) a.large.add(row[j] - f, i);
    }
    a.row_sums.add(ours - theirs, i);
  }
  return a;
}

/// Checks that `m`'s rows are View3D's surfaces (the same count, each once, areas within 1e-4);
/// false, with a message on stderr, when they are not.
bool same_surfaces(const rad::ViewFactorMatrix& m, const View3DOutput& v) {
  if (m.rows() != v.n) {
    std::fprintf(stderr, "bench_view_factors: View3D's output has %zu surfaces, the room %zu rows: not the same room\n",
                 v.n, m.rows());
    return false;
  }
  std::vector<bool> seen(v.n, false);
  double worst = 0.0;
  for (std::size_t r = 0; r < m.rows(); ++r) {
    if (m.ids[r] >= v.n || seen[m.ids[r]]) {
      std::fprintf(stderr, "bench_view_factors: row %zu (polygon %u) has no View3D surface of its own\n", r, m.ids[r]);
      return false;
    }
    seen[m.ids[r]] = true;
    worst = std::max(worst, std::fabs(v.area[m.ids[r]] - m.area[r]) / m.area[r]);
  }
  if (worst > 1e-4) {
    std::fprintf(stderr, "bench_view_factors: areas differ from View3D's by up to %.3g (relative): not the same room\n",
                 worst);
    return false;
  }
  return true;
}

/// One line of the comparison; the polygons (0-based) whose row sum and whose large factor
/// differ most follow in brackets.
void print_agreement(const char* what, const Agreement& a, const rad::Scene& scene) {
  auto group = [&](std::size_t polygon) { return scene.groups()[scene.polygons()[polygon].group].c_str(); };
  std::printf("    %-24s %9.3g %9.3g   %9.3g %9.3g   %9.3g %9.3g   (row sum: polygon %zu, %s; factor: row %zu, %s)\n",
              what, a.row_sums.largest, a.row_sums.rms(), a.large.largest, a.large.rms(), a.all.largest, a.all.rms(),
              a.row_sums.where, group(a.row_sums.where), a.large.where, group(a.large.where));
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
  if (!a.city_links) return;
  // The hierarchical links' rows: a cluster link spreads over every facet of its source that
  // faces it, so the rows hold every facet a facet may see; the budget may refuse them.
  o.method = rad::ViewFactorMethod::hierarchical;
  try {
    const rad::ViewFactorMatrix links = rad::view_factor_matrix(city.scene, o);
    std::snprintf(what, sizeof what, "hierarchical links (epsilon %g), reciprocity", static_cast<double>(o.epsilon));
    print_matrix(what, links);
  } catch (const rad::Error& e) {
    std::printf("  hierarchical links: %s\n", e.what());
  }
}

bool enclosure_part(const Args& a) {
  const bool cornell = a.cornell_facet > 0.0f;
  const rad::Scene scene = cornell ? faceted_cornell(a.cornell_facet) : faceted_room(a.room_facet);
  if (cornell)
    std::printf("enclosure: the Cornell box closed by a front wall, its two blocks standing on the floor, facet %.4g mm:"
                " %zu facets (closed: the floor cut around the blocks' footprints)\n",
                a.cornell_facet, scene.polygons().size());
  else
    std::printf("enclosure: a 4 m room around a block on its floor, facet %.4g m: %zu facets (closed)\n", a.room_facet,
                scene.polygons().size());
  if (!a.write_vs3.empty()) {
    // encl=0: View3D then writes its factors as integrated, without its own row normalisation
    // (NormAF), so its row sums' distance from 1 is its own error and one file serves as the
    // reference for both our uncorrected and our corrected factors. Other controls: View3D 3.2's
    // defaults (eps 1e-4, maxU 12, maxO 8, minO 0), text output.
    rad::View3DControl control;
    control.enclosure = false;
    control.output_format = 0;
    char title[96];
    if (cornell)
      std::snprintf(title, sizeof title, "bench_view_factors closed Cornell box, facet %.4g mm", a.cornell_facet);
    else
      std::snprintf(title, sizeof title, "bench_view_factors room around a block, facet %.4g m", a.room_facet);
    rad::save_view3d(scene, control, title, a.write_vs3);
    std::printf("  wrote %s: View3D input, %zu surfaces (surface i + 1 = polygon i), encl=0, eps=%g, out=0\n",
                a.write_vs3.c_str(), scene.polygons().size(), static_cast<double>(control.epsilon));
  }
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
  // The hierarchical links' rows (ViewFactorMethod::hierarchical, at ViewFactorOptions' epsilon).
  o.method = rad::ViewFactorMethod::hierarchical;
  const rad::ViewFactorMatrix links = rad::view_factor_matrix(scene, o);
  std::snprintf(what, sizeof what, "hierarchical links (epsilon %g), enclosure", static_cast<double>(o.epsilon));
  print_matrix(what, links);
  o.method = rad::ViewFactorMethod::estimator;
  // Agreement: factors of 0.01 and more in the exact matrix.
  auto against_exact = [&](const char* name, const rad::ViewFactorMatrix& m) {
    double worst = 0.0, squares = 0.0;
    std::size_t large = 0;
    for (std::size_t i = 0; i < exact.rows(); ++i)
      for (std::uint64_t k = exact.row_offsets[i]; k < exact.row_offsets[i + 1]; ++k) {
        if (exact.values[k] < 0.01f) continue;
        const double d = std::fabs(m.at(i, exact.columns[k]) - static_cast<double>(exact.values[k]));
        worst = std::max(worst, d);
        squares += d * d;
        ++large;
      }
    std::printf("  %s against exact, over the %zu factors >= 0.01: largest |difference| %.3g, RMS %.3g\n", name, large,
                worst, large ? std::sqrt(squares / static_cast<double>(large)) : 0.0);
  };
  against_exact("fast", fast);
  against_exact("hierarchical", links);
  std::printf("  speed: fast is %.1fx the exact mode's, hierarchical %.1fx\n", exact.seconds / fast.seconds,
              exact.seconds / links.seconds);
  if (a.view3d_output.empty()) return true;

  // Side by side with View3D: our exact mode once more without correction, then both modes
  // against View3D's factors (its rows as it wrote them, normalised only if its encl was 1).
  // Read only now, so that the peak memory printed above is ours alone.
  View3DOutput view3d;
  if (!read_view3d_output(a.view3d_output, view3d) || !same_surfaces(exact, view3d)) return false;
  o.form_factors.method = rad::FormFactorMethod::ray_cast;
  o.correction = rad::ViewFactorCorrection::none;
  const rad::ViewFactorMatrix raw = rad::view_factor_matrix(scene, o);
  std::printf("  View3D: %s (%s %s, encl=%d, emit=%d, %zu surfaces); exact without correction took %.2f s\n",
              a.view3d_output.c_str(), view3d.program.c_str(), view3d.version.c_str(), view3d.enclosure,
              view3d.script_f, view3d.n, raw.seconds);
  Deviation own;
  std::size_t blind = 0;
  for (std::size_t i = 0; i < view3d.n; ++i) {
    double sum = 0.0;
    for (std::size_t j = 0; j < view3d.n; ++j) sum += view3d.at(i, j);
    if (sum < 0.5)
      ++blind;  // a floor facet under the block: it sees nothing, in View3D as here
    else
      own.add(1.0 - sum);
  }
  std::printf("    View3D's own row sums: |1 - sum| up to %.3g, RMS %.3g (over the %zu rows that see something; %zu"
              " see nothing)\n",
              own.largest, own.rms(), own.count, blind);
  std::printf("    |ours - View3D's|:       row sums (max, RMS)  factors >= 0.01 (max, RMS)  all N^2 (max, RMS)\n");
  const Agreement exact_raw = against_view3d(raw, view3d);
  std::printf("    (%zu rows; %zu factors >= 0.01 in View3D's matrix; %zu factors in all)\n", exact_raw.row_sums.count,
              exact_raw.large.count, exact_raw.all.count);
  print_agreement("exact, no correction", exact_raw, scene);
  print_agreement("exact, enclosure", against_view3d(exact, view3d), scene);
  print_agreement("fast, enclosure", against_view3d(fast, view3d), scene);
  print_agreement("hierarchical, enclosure", against_view3d(links, view3d), scene);
  if (a.view3d_seconds > 0.0) {
    const unsigned threads = a.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : a.threads;
    std::printf("  time: View3D %.1f s (one thread; measured outside) against the exact mode's %.2f s on %u threads"
                " (with correction): View3D / exact = %.2f; View3D / fast (%.2f s) = %.1f\n",
                a.view3d_seconds, exact.seconds, threads, a.view3d_seconds / exact.seconds, fast.seconds,
                a.view3d_seconds / fast.seconds);
  }
  return true;
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
    } else if (arg == "--cornell" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v >= 5.0) || v > 600.0) return usage(argv[i]);
      a.cornell_facet = static_cast<float>(v);
    } else if (arg == "--write-vs3" && has_value) {
      a.write_vs3 = argv[++i];
    } else if (arg == "--view3d-output" && has_value) {
      a.view3d_output = argv[++i];
    } else if (arg == "--view3d-seconds" && has_value) {
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v > 0.0) || !std::isfinite(v)) return usage(argv[i]);
      a.view3d_seconds = v;
    } else if (arg == "--city-links") {
      a.city_links = true;
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
  if (a.enclosure_part && !enclosure_part(a)) return 1;
  if (a.city_part) city_part(a);
  return 0;
}
