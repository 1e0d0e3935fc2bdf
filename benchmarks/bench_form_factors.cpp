// Form-factor throughput: the ray-cast estimator next to bare Embree occlusion rays on the same
// scene, hemicube rows per second, and the time for all factors of a ~10k-element Cornell box.
// A plain std::chrono harness (median of a few runs for the short measurements); prints what it
// measured, and the time of find_overlaps() on a ~100k-polygon scene. Usage: bench_form_factors
// [--quick | --overlaps | --emitters] (--quick skips the ~10k-element runs, --overlaps runs only
// find_overlaps, --emitters only the many-emitters enclosure).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/shaft.hpp"
#include "geometry/ray_scene.hpp"
#include "radiosity/radiosity.hpp"

namespace rad = radiosity;
namespace detail = radiosity::detail;

namespace {

double seconds(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median_seconds(int runs, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) t.push_back(seconds(f));
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// A 10 x 4 x 10 room with a 4 x 4 grid of 1 x 1.5 x 1 boxes on its floor: most pairs are shadowed.
rad::Scene grid_of_boxes() {
  rad::Scene s;
  const rad::MaterialId m = s.add_material({});
  auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 towards, const char* group) {
    std::vector<glm::vec3> q{a, b, c, d};
    if (glm::dot(glm::cross(b - a, c - a), towards - a) < 0.0f) std::reverse(q.begin(), q.end());
    s.add_polygon(q, m, group);
  };
  auto box = [&](glm::vec3 lo, glm::vec3 hi, bool inward, const char* group) {
    const glm::vec3 c = 0.5f * (lo + hi);
    auto face = [&](glm::vec3 a, glm::vec3 b, glm::vec3 cc, glm::vec3 d) {
      const glm::vec3 centre = 0.25f * (a + b + cc + d);
      quad(a, b, cc, d, inward ? c : 2.0f * centre - c, group);
    };
    const float x0 = lo.x, x1 = hi.x, y0 = lo.y, y1 = hi.y, z0 = lo.z, z1 = hi.z;
    face({x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, {x0, y0, z1});
    face({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});
    if (inward) face({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // boxes have no bottom
    face({x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1});
    face({x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0});
    face({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});
  };
  box({0, 0, 0}, {10, 4, 10}, true, "room");
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) {
      const glm::vec3 lo(1.5f + 2.0f * i, 0.0f, 1.5f + 2.0f * k);
      box(lo, lo + glm::vec3(1.0f, 1.5f, 1.0f), false, "boxes");
    }
  return s;
}

// Occlusion rays like the estimator's: between uniform points of (element, patch) pairs that
// face each other and that the shaft test cannot clear, offset off both surfaces.
struct RaySet {
  std::vector<glm::vec3> origin, direction;
};

RaySet shadowed_pair_rays(const rad::Scene& scene, const rad::PatchHierarchy& h, std::size_t count) {
  std::vector<std::vector<glm::vec3>> polygons;
  std::vector<glm::vec3> normals;
  for (const rad::Polygon& p : scene.polygons()) {
    polygons.push_back(p.vertices);
    normals.push_back(p.normal);
  }
  const detail::ShaftCuller culler(polygons, normals);
  const float eps = 1e-5f * scene.bounds().diagonal();
  const auto& leaves = h.leaves();
  const auto& patches = h.patches();
  detail::Rng rng(7);
  RaySet rays;
  while (rays.origin.size() < count) {
    const std::uint32_t e = leaves[rng.next() % leaves.size()];
    const std::uint32_t j = static_cast<std::uint32_t>(rng.next() % patches.size());
    const rad::Element& el = h.element(e);
    const rad::Patch& src = patches[el.patch];
    const rad::Patch& dst = patches[j];
    if (src.polygon == dst.polygon) continue;
    std::vector<glm::vec3> a, b;
    for (int k = 0; k < el.corner_count(); ++k) a.push_back(h.vertices()[el.corners[static_cast<std::size_t>(k)]]);
    const rad::Element& root = h.element(dst.root);
    for (int k = 0; k < root.corner_count(); ++k) b.push_back(h.vertices()[root.corners[static_cast<std::size_t>(k)]]);
    detail::Shaft shaft;
    if (!shaft.build(a.data(), static_cast<int>(a.size()), src.normal, b.data(), static_cast<int>(b.size()), dst.normal,
                     eps))
      continue;
    if (!culler.any(shaft, src.polygon, dst.polygon)) continue;
    for (int r = 0; r < 16; ++r) {
      const glm::vec3 x = h.sample_point(e, rng.uniform2()) + eps * src.normal;
      const glm::vec3 y = h.sample_point(dst.root, rng.uniform2()) + eps * dst.normal;
      rays.origin.push_back(x);
      rays.direction.push_back(y - x);
    }
  }
  return rays;
}

// Bare Embree: occluded() over the ray set on `threads` threads, in rays per second.
double bare_rays_per_second(const detail::RayScene& rs, const RaySet& rays, unsigned threads) {
  std::vector<unsigned char> hit(rays.origin.size());
  const double t = median_seconds(3, [&] {
    detail::parallel_for(threads, rays.origin.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) hit[i] = rs.occluded(rays.origin[i], rays.direction[i], 0.0f, 1.0f - 1e-4f);
    });
  });
  std::size_t blocked = 0;
  for (const unsigned char c : hit) blocked += c;
  std::printf("    bare Embree rtcOccluded1, %u thread(s): %zu rays (%.0f%% blocked) in %.3f s = %.2f Mrays/s\n",
              threads, rays.origin.size(),
              100.0 * static_cast<double>(blocked) / static_cast<double>(rays.origin.size()), t,
              static_cast<double>(rays.origin.size()) / t * 1e-6);
  // The same rays as coherent packets (each pair's 16 rays together), as the estimator traces
  // them: for reference, not the ceiling the estimator is compared with.
  std::vector<std::uint8_t> packed(rays.origin.size());
  const double tp = median_seconds(3, [&] {
    detail::parallel_for(threads, rays.origin.size() / 16, 256, [&](std::size_t b, std::size_t e) {
      rs.occluded(16 * (e - b), &rays.origin[16 * b], &rays.direction[16 * b], 0.0f, 1.0f - 1e-4f, &packed[16 * b]);
    });
  });
  std::printf("    bare Embree packets of 16 (RayScene batch), %u thread(s): %.2f Mrays/s\n", threads,
              static_cast<double>(rays.origin.size()) / tp * 1e-6);
  return static_cast<double>(rays.origin.size()) / t;
}

// All rows of the scene with the ray-cast estimator; returns rays per second.
double ray_cast_rows(const rad::Scene& scene, const rad::PatchHierarchy& h, unsigned threads, double bare) {
  rad::FormFactorOptions o;
  o.method = rad::FormFactorMethod::ray_cast;  // the default (automatic) would pick monte_carlo here
  o.threads = threads;
  const auto est = rad::make_form_factor_estimator(scene, h, o);
  const std::size_t m = h.leaves().size(), n = h.patches().size();
  std::vector<float> F(m * n);
  const double t = seconds([&] { est->element_rows(h.leaves(), F.data()); });
  detail::RayCastCounters c;
  detail::ray_cast_counters(*est, c);
  std::size_t nonzero = 0;
  for (const float f : F) nonzero += f > 0.0f ? 1 : 0;
  const double rays_per_second = static_cast<double>(c.rays) / t;
  std::printf("    ray-cast estimator, %u thread(s): %zu x %zu factors (%zu non-zero) in %.3f s = %.2f Mfactors/s\n",
              threads, m, n, nonzero, t, static_cast<double>(m * n) / t * 1e-6);
  std::printf("      %.1f%% of the pairs needed rays (shaft test); %.2f M rays = %.1f per such pair; %.2f Mrays/s\n",
              100.0 * static_cast<double>(c.shadowed) / static_cast<double>(m * n), static_cast<double>(c.rays) * 1e-6,
              static_cast<double>(c.rays) / std::max<double>(1.0, static_cast<double>(c.shadowed)),
              rays_per_second * 1e-6);
  std::printf("      ratio to bare Embree: %.2f (the share of the estimator's time that its rays would take alone)\n",
              rays_per_second / bare);
  return rays_per_second;
}

void ray_cast_section(const char* title, const rad::Scene& scene, const rad::MeshOptions& mesh) {
  const rad::PatchHierarchy h(scene, mesh);
  std::printf("\n%s: %zu polygons, %zu patches, %zu elements\n", title, scene.polygons().size(), h.patches().size(),
              h.leaves().size());
  const detail::RayScene rs = detail::RayScene::from_polygons(scene);
  const RaySet rays = shadowed_pair_rays(scene, h, 2'000'000);
  for (const unsigned threads : {1u, 2u}) {
    const double bare = bare_rays_per_second(rs, rays, threads);
    ray_cast_rows(scene, h, threads, bare);
  }
}

void hemicube_section(const rad::Scene& scene) {
  const rad::PatchHierarchy h(scene, rad::MeshOptions{});
  std::printf("\nHemicube, resolution 256, 4 hemicubes per element (the defaults), Cornell box %zu patches:\n",
              h.patches().size());
  std::vector<std::uint32_t> rows(h.leaves().begin(), h.leaves().begin() + 256);
  std::vector<float> F(rows.size() * h.patches().size());
  for (const unsigned threads : {1u, 2u}) {
    rad::FormFactorOptions o;
    o.method = rad::FormFactorMethod::hemicube;
    o.threads = threads;
    const auto est = rad::make_form_factor_estimator(scene, h, o);
    const double t = median_seconds(3, [&] { est->element_rows(rows, F.data()); });
    std::printf("    %u thread(s): %zu rows in %.3f s = %.1f rows/s (%.0f hemicubes/s)\n", threads, rows.size(), t,
                static_cast<double>(rows.size()) / t, 4.0 * static_cast<double>(rows.size()) / t);
    o.source_samples = 1;
    const auto one = rad::make_form_factor_estimator(scene, h, o);
    const double t1 = median_seconds(3, [&] { one->element_rows(rows, F.data()); });
    std::printf("    %u thread(s), 1 hemicube per element: %.1f rows/s\n", threads,
                static_cast<double>(rows.size()) / t1);
  }
  rad::FormFactorOptions o;
  o.method = rad::FormFactorMethod::hemicube;
  o.threads = 2;
  const auto est = rad::make_form_factor_estimator(scene, h, o);
  std::vector<float> column(h.leaves().size());
  const double t = median_seconds(3, [&] { est->patch_column(17, h.leaves(), column.data()); });
  std::printf("    patch_column over all %zu elements, 2 threads: %.3f s\n", h.leaves().size(), t);
}

void cornell_10k(const rad::Scene& scene) {
  rad::MeshOptions mesh;
  mesh.max_patch_area = static_cast<float>(scene.total_area() / 512.0);
  mesh.max_element_area = mesh.max_patch_area / 16.0f;
  const rad::PatchHierarchy h(scene, mesh);
  const std::size_t m = h.leaves().size(), n = h.patches().size();
  std::printf("\nCornell box, %zu patches, %zu elements, all %zu factors on 2 threads:\n", n, m, m * n);
  std::vector<float> F(m * n);
  for (const rad::FormFactorMethod method :
       {rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::analytic, rad::FormFactorMethod::hemicube}) {
    rad::FormFactorOptions o;
    o.method = method;
    o.threads = 2;
    const auto est = rad::make_form_factor_estimator(scene, h, o);
    const double t = seconds([&] { est->element_rows(h.leaves(), F.data()); });
    std::printf("    %-9s %.2f s (%.2f Mfactors/s)\n",
                method == rad::FormFactorMethod::ray_cast   ? "ray-cast"
                : method == rad::FormFactorMethod::analytic ? "analytic"
                                                            : "hemicube",
                t, static_cast<double>(m * n) / t * 1e-6);
  }
}

// find_overlaps() on a large scene: an n x n tiled floor with a box (4 sides and a top) standing
// on every tile, so every polygon touches several others (shared edges, T-junctions, edges on a
// plane) and none overlaps; then the same with the boxes sunk into the floor.
rad::Scene tiles_and_boxes(int n, float sink) {
  rad::Scene s;
  const rad::MaterialId m = s.add_material({});
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) {
      const float x0 = static_cast<float>(i), z0 = static_cast<float>(k), x1 = x0 + 1.0f, z1 = z0 + 1.0f;
      s.add_polygon({{x0, 0, z0}, {x0, 0, z1}, {x1, 0, z1}, {x1, 0, z0}}, m, "floor");
      const float a = x0 + 0.25f, b = x0 + 0.75f, c = z0 + 0.25f, d = z0 + 0.75f, y0 = -sink, y1 = 0.5f;
      s.add_polygon({{a, y0, c}, {a, y0, d}, {a, y1, d}, {a, y1, c}}, m, "boxes");
      s.add_polygon({{b, y0, c}, {b, y1, c}, {b, y1, d}, {b, y0, d}}, m, "boxes");
      s.add_polygon({{a, y0, c}, {a, y1, c}, {b, y1, c}, {b, y0, c}}, m, "boxes");
      s.add_polygon({{a, y0, d}, {b, y0, d}, {b, y1, d}, {a, y1, d}}, m, "boxes");
      s.add_polygon({{a, y1, c}, {a, y1, d}, {b, y1, d}, {b, y1, c}}, m, "boxes");
    }
  return s;
}

void overlap_section() {
  for (const float sink : {0.0f, 0.1f}) {
    const rad::Scene s = tiles_and_boxes(130, sink);
    std::size_t found = 0;
    const double t = median_seconds(3, [&] { found = rad::find_overlaps(s).size(); });
    std::printf("\nfind_overlaps, %zu polygons (%s): %zu pairs in %.3f s (all threads)\n", s.polygons().size(),
                sink > 0.0f ? "boxes sunk into the floor" : "boxes standing on a tiled floor", found, t);
  }
}

/// An enclosure of about 4000 facets (floor and ceiling 24 x 24, walls 24 x 30; a 5 x 3 x 5
/// room with a 1 x 1 x 1 block on the floor), one element per facet, lit either by its whole
/// ceiling (576 emitting facets) or by one ceiling facet. Gauss-Seidel with Monte Carlo factors
/// on one thread: the form-factor time of each, and how far limiting the exact emitter factors
/// (FormFactorOptions::exact_emitters) moves the solution from the all-exact one.
void emitters_section() {
  auto room = [](bool whole_ceiling) {
    rad::Scene scene;
    rad::Material wall, lamp;
    wall.name = "wall";
    wall.reflectance = rad::Rgb(0.6f);
    lamp.name = "lamp";
    lamp.emission = rad::Rgb(10.0f);
    lamp.reflectance = rad::Rgb(0.6f);
    const rad::MaterialId w = scene.add_material(wall), l = scene.add_material(lamp);
    const float X = 5.0f, Y = 3.0f, Z = 5.0f;
    auto grid = [&](glm::vec3 o, glm::vec3 u, glm::vec3 v, int nu, int nv, bool ceiling, const char* group) {
      for (int i = 0; i < nu; ++i)
        for (int k = 0; k < nv; ++k) {
          const glm::vec3 a = o + u * (static_cast<float>(i) / nu) + v * (static_cast<float>(k) / nv);
          const bool emits = ceiling && (whole_ceiling || (i == nu / 2 && k == nv / 2));
          rad::add_quad(scene, a, u / static_cast<float>(nu), v / static_cast<float>(nv), emits ? l : w, group);
        }
    };
    // Inward: floor up, ceiling down, four walls.
    grid({0, 0, 0}, {0, 0, Z}, {X, 0, 0}, 24, 24, false, "floor");
    grid({0, Y, 0}, {X, 0, 0}, {0, 0, Z}, 24, 24, true, "ceiling");
    grid({0, 0, 0}, {X, 0, 0}, {0, Y, 0}, 24, 30, false, "wall");
    grid({0, 0, Z}, {0, Y, 0}, {X, 0, 0}, 30, 24, false, "wall");
    grid({0, 0, 0}, {0, Y, 0}, {0, 0, Z}, 30, 24, false, "wall");
    grid({X, 0, 0}, {0, 0, Z}, {0, Y, 0}, 24, 30, false, "wall");
    rad::add_box(scene, {2, 0, 2}, {3, 1, 3}, w, "block");
    return scene;
  };
  auto run = [](const rad::Scene& scene, std::uint32_t exact, rad::Solution* out, std::uint64_t seed = 1) {
    rad::SolveOptions o;
    o.seed = seed;
    o.form_factors.method = rad::FormFactorMethod::monte_carlo;
    o.form_factors.exact_emitters = exact;
    o.threads = 1;
    o.mesh.max_patch_area = 5.0f * 5.0f / (24 * 24) + 1e-4f;
    o.mesh.max_element_area = o.mesh.max_patch_area;
    rad::Solution sol = rad::solve(scene, o);
    const double t = sol.report().seconds_form_factors;
    if (out) *out = std::move(sol);
    return t;
  };
  std::printf("many emitters: %zu-facet enclosure, Monte Carlo factors, 1 thread\n", room(true).polygons().size());
  const rad::Scene one = room(false), whole = room(true);
  const double t_one = run(one, 0, nullptr);
  rad::Solution reference;
  const double t_all = run(whole, 0, &reference);
  std::printf("  one emitting facet:                           form factors %6.2f s\n", t_one);
  std::printf("  whole ceiling (576 facets), every one exact:  form factors %6.2f s (%.1f x one facet)\n", t_all,
              t_all / t_one);
  // k = 0 at another seed: the all-exact solution's own noise, the yardstick for the others.
  for (std::uint32_t k : {0u, 4u, 16u, 64u}) {
    rad::Solution sol;
    const double t = run(whole, k, &sol, k == 0 ? 2 : 1);
    double num = 0.0, den = 0.0, worst_group = 0.0;
    const rad::PatchHierarchy& h = reference.hierarchy();
    for (std::uint32_t e : h.leaves()) {
      const rad::Patch& p = h.patches()[h.element(e).patch];
      if (whole.material(p.material).emission.x > 0.0f) continue;  // reflectors only
      const double a = h.element(e).area, d = sol.radiosity()[e].x - reference.radiosity()[e].x;
      num += a * d * d;
      den += a * static_cast<double>(reference.radiosity()[e].x) * reference.radiosity()[e].x;
    }
    for (const std::string& g : {std::string("floor"), std::string("wall"), std::string("block")})
      worst_group = std::max(worst_group, std::fabs(sol.group_radiosity(g).x / reference.group_radiosity(g).x - 1.0));
    std::printf("  whole ceiling, %s form factors %6.2f s (%.1f x one facet); "
                "reflectors' RMS difference from all-exact %.2f %%, worst group mean %.2f %%\n",
                k == 0 ? "every one exact, seed 2: " : ("exact_emitters " + std::to_string(k) + ":" + std::string(k < 10 ? "          " : "         ")).c_str(),
                t, t / t_one, 100.0 * std::sqrt(num / den), 100.0 * worst_group);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 2 || (argc == 2 && std::strcmp(argv[1], "--quick") != 0 && std::strcmp(argv[1], "--overlaps") != 0 &&
                    std::strcmp(argv[1], "--emitters") != 0)) {
    const bool help = argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0);
    if (!help) std::fprintf(stderr, "bench_form_factors: bad argument '%s'\n", argv[argc - 1]);
    std::fprintf(stderr, "usage: bench_form_factors [--quick | --overlaps | --emitters]\n");
    return help ? 0 : 2;
  }
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("bench_form_factors (radiosity %s), %u hardware threads\n", rad::version(),
              std::thread::hardware_concurrency());
  const rad::Scene cornell = rad::cornell_box();
  if (argc > 1 && std::strcmp(argv[1], "--overlaps") == 0) {
    overlap_section();
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--emitters") == 0) {
    emitters_section();
    return 0;
  }
  ray_cast_section("Cornell box, default mesh", cornell, rad::MeshOptions{});
  rad::MeshOptions grid_mesh;
  grid_mesh.max_patch_area = 0.5f;
  ray_cast_section("Grid of boxes in a room (mostly shadowed pairs)", grid_of_boxes(), grid_mesh);
  hemicube_section(cornell);
  if (!quick) cornell_10k(cornell);
  overlap_section();
  return 0;
}
