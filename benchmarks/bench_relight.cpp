// Solution::relight() at host scale (light-groups issue target: a 100k-element solution with 8
// light groups relit in under 20 ms): a floor meshed into about 100k elements, a Solution with
// 8 light groups of made-up values (relight's cost does not depend on them), relit 10 times
// with new weights.
//
// Usage: bench_relight [ELEMENTS] [GROUPS]   (defaults 100000 and 8)
// Prints the element and group counts and the time per relight (best and mean of 10).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"

namespace rad = radiosity;

int main(int argc, char** argv) {
  const long elements = argc > 1 ? std::atol(argv[1]) : 100000;
  const long groups = argc > 2 ? std::atol(argv[2]) : 8;
  if (elements < 100 || groups < 1) {
    std::fprintf(stderr, "usage: bench_relight [ELEMENTS >= 100] [GROUPS >= 1]\n");
    return 2;
  }
  rad::Scene scene;
  rad::add_quad(scene, {0, 0, 0}, {10, 0, 0}, {0, 0, 10}, scene.add_material(rad::Material{}), "floor");
  rad::MeshOptions mo;
  mo.max_element_area = 100.0f / static_cast<float>(elements);
  mo.max_patch_area = 16.0f * mo.max_element_area;
  rad::PatchHierarchy h(scene, mo);
  const std::size_t n = h.elements().size();
  std::vector<rad::LightGroupSolution> parts;
  std::vector<rad::Rgb> total(n, rad::Rgb(0.0f));
  for (long k = 0; k < groups; ++k) {
    rad::LightGroupSolution g;
    g.name = "lamp" + std::to_string(k);
    g.radiosity.resize(n);
    for (std::size_t e = 0; e < n; ++e) g.radiosity[e] = rad::Rgb(static_cast<float>((e * 7 + k) % 13));
    g.irradiance = g.radiosity;
    g.direct_irradiance = g.radiosity;
    for (std::size_t e = 0; e < n; ++e) total[e] += g.radiosity[e];
    parts.push_back(std::move(g));
  }
  rad::Solution sol(std::move(h), total, scene.groups(), rad::SolveStatus::converged, rad::SolveReport{}, rad::Rgb(0.0f),
                    {}, {}, total, total);
  sol.set_light_groups(std::move(parts));

  double best = 1e30, sum = 0.0;
  float check = 0.0f;
  for (int rep = 0; rep < 10; ++rep) {
    std::vector<rad::Rgb> weights(static_cast<std::size_t>(groups), rad::Rgb(0.5f + 0.1f * static_cast<float>(rep)));
    const auto t0 = std::chrono::steady_clock::now();
    const rad::Solution relit = sol.relight(weights);
    const double s = bench::seconds_since(t0);
    check += relit.radiosity()[n / 2].x;
    best = std::min(best, s);
    sum += s;
  }
  // What a relight must copy besides the values: the hierarchy the new Solution owns.
  double copy_best = 1e30;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    const rad::PatchHierarchy copy(sol.hierarchy());
    copy_best = std::min(copy_best, bench::seconds_since(t0));
    check += static_cast<float>(copy.elements().size() % 2);
  }
  std::printf("relight: %zu elements (%zu leaves), %ld light groups\n", n, sol.hierarchy().leaves().size(), groups);
  std::printf("  per relight: best %.2f ms, mean %.2f ms (target: under 20 ms for 100k elements and 8 groups)\n",
              1e3 * best, 1e3 * sum / 10.0);
  std::printf("  of which the hierarchy's copy: best %.2f ms\n", 1e3 * copy_best);
  std::printf("  (checksum %.3g)\n", static_cast<double>(check));
  return 0;
}
