// Gauss-Legendre quadrature on [0,1] and over triangles and planar quads.
// Based on: the Gauss-Legendre rule (nodes at the roots of the Legendre polynomial P_n, found by
// Newton's method; e.g. Press et al., "Numerical Recipes", 3rd ed., section 4.6), exact for
// polynomials of degree 2n - 1; over a triangle by the collapsed (Duffy) square, M. G. Duffy,
// "Quadrature over a pyramid or cube of integrands with a singularity at a vertex", SIAM J.
// Numer. Anal. 19(6), 1982, whose Jacobian is linear, so the rule stays polynomial.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/assert.hpp"
#include "core/sampling.hpp"

namespace radiosity::detail {

/// The n-point Gauss-Legendre nodes and weights on [0,1] (weights sum to 1), by Newton's method
/// on the Legendre polynomial.
inline void gauss_legendre(int n, std::vector<float>& node, std::vector<double>& weight) {
  node.resize(static_cast<std::size_t>(n));
  weight.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double z = std::cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int k = 1; k <= n; ++k) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k;
      }
      dp = n * (z * p0 - p1) / (z * z - 1.0);
      const double step = p0 / dp;
      z -= step;
      if (std::fabs(step) < 1e-15) break;
    }
    node[static_cast<std::size_t>(i)] = static_cast<float>(0.5 * (1.0 - z));
    weight[static_cast<std::size_t>(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
  }
}

/// A Gauss-Legendre rule of up to kMaxGaussOrder points on [0,1], computed once per order.
inline constexpr int kMaxGaussOrder = 8;
struct GaussRule {
  int n = 0;
  std::array<float, kMaxGaussOrder> node{}, weight{};
};
/// The n-point rule, 1 <= n <= kMaxGaussOrder. Thread safety: may be called concurrently (the
/// tables are made by a function-local static's initialisation).
inline const GaussRule& gauss_rule(int n) {
  RADIOSITY_ASSERT(n >= 1 && n <= kMaxGaussOrder);
  static const std::array<GaussRule, kMaxGaussOrder> rules = [] {
    std::array<GaussRule, kMaxGaussOrder> out{};
    std::vector<float> node;
    std::vector<double> weight;
    for (int k = 1; k <= kMaxGaussOrder; ++k) {
      gauss_legendre(k, node, weight);
      GaussRule& r = out[static_cast<std::size_t>(k - 1)];
      r.n = k;
      for (std::size_t i = 0; i < node.size(); ++i) {
        r.node[i] = node[i];
        r.weight[i] = static_cast<float>(weight[i]);
      }
    }
    return out;
  }();
  return rules[static_cast<std::size_t>(n - 1)];
}

/// The mean of f over a triangle or a planar quad (`count` 3 or 4 corners, in order) by the
/// n x n Gauss-Legendre rule through the cell's polynomial map from the unit square (CellMap,
/// core/sampling.hpp: the bilinear map of a quad, the collapsed square of a triangle), each
/// point weighted by the map's area density. Exact for polynomials of degree 2n - 1 in the map's
/// coordinates, where a midpoint grid of n x n cells is exact only for degree 1: a receiver
/// beside a source's plane sees it with a factor that vanishes along that plane, and the
/// midpoint rule overestimates such a concave profile (docs/HIERARCHICAL.md, session 42). 0 for
/// a degenerate polygon.
template <typename F>
float polygon_gauss_mean(const glm::vec3* c, int count, int n, const F& f) {
  RADIOSITY_ASSERT(count == 3 || count == 4);
  const CellMap map(c, count);
  if (!(map.area() > 0.0f)) return 0.0f;
  const GaussRule& rule = gauss_rule(n);
  double sum = 0.0, weights = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec2 st(rule.node[static_cast<std::size_t>(i)], rule.node[static_cast<std::size_t>(j)]);
      const double w = static_cast<double>(rule.weight[static_cast<std::size_t>(i)]) *
                       rule.weight[static_cast<std::size_t>(j)] * map.density(st);
      sum += w * static_cast<double>(f(map.point(st)));
      weights += w;
    }
  return weights > 0.0 ? static_cast<float>(sum / weights) : 0.0f;
}

}  // namespace radiosity::detail
