#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <radiosity/radiosity.hpp>
#include "support/build.hpp"

namespace rad = radiosity;

namespace {

// Dense LU with partial pivoting, solving A x = b in place (A row-major, k x k).
std::vector<double> lu_solve(std::vector<double> A, std::vector<double> b, std::size_t k) {
  for (std::size_t c = 0; c < k; ++c) {
    std::size_t pivot = c;
    for (std::size_t r = c + 1; r < k; ++r)
      if (std::fabs(A[r * k + c]) > std::fabs(A[pivot * k + c])) pivot = r;
    if (pivot != c) {
      for (std::size_t j = 0; j < k; ++j) std::swap(A[c * k + j], A[pivot * k + j]);
      std::swap(b[c], b[pivot]);
    }
    for (std::size_t r = c + 1; r < k; ++r) {
      const double f = A[r * k + c] / A[c * k + c];
      if (f == 0.0) continue;
      for (std::size_t j = c; j < k; ++j) A[r * k + j] -= f * A[c * k + j];
      b[r] -= f * b[c];
    }
  }
  std::vector<double> x(k);
  for (std::size_t r = k; r-- > 0;) {
    double s = b[r];
    for (std::size_t j = r + 1; j < k; ++j) s -= A[r * k + j] * x[j];
    x[r] = s / A[r * k + r];
  }
  return x;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("every method agrees with a dense LU solve of the same discrete system within 0.1%"
            * test::not_under_thread_sanitizer) {
    const rad::Scene scene = rad::cornell_box();
    rad::SolveOptions o;
    o.mesh.max_patch_area = 20000.0f;
    o.mesh.max_element_area = 10000.0f;
    o.tolerance = 1e-7;
    o.seed = 7;
    // One discrete system for every solver: ray_cast's rows and columns are the same factors
    // (Monte Carlo columns are shot, a different random system).
    o.form_factors.method = rad::FormFactorMethod::ray_cast;

    // The discrete system with the same form factors the solvers will compute (same seed), and
    // the exposure x they measure (the floor's elements around the blocks are partly buried,
    // docs/ARCHITECTURE.md "Contact and light leaks"; the first solve's, the same for every
    // method): B_e = E_e + rho_e / x_e sum_j F_ej sum_{e' in j} (A_e' x_e' / X_j) B_e', with X_j
    // the sum of A_e' x_e' over patch j.
    o.method = rad::SolverMethod::jacobi;
    const rad::Solution first = rad::solve(scene, o);
    const std::vector<float>& x = first.exposure();
    REQUIRE(!x.empty());
    rad::PatchHierarchy h(scene, o.mesh);
    rad::FormFactorOptions fo = o.form_factors;
    fo.seed = o.seed;
    auto estimator = rad::make_form_factor_estimator(scene, h, fo);
    const std::vector<std::uint32_t>& leaves = h.leaves();
    const std::size_t m = leaves.size(), n = h.patches().size();
    std::vector<float> F(m * n);
    estimator->element_rows(leaves, F.data());
    std::vector<double> patch_area(n, 0.0);
    for (std::uint32_t e : leaves) patch_area[h.element(e).patch] += h.element(e).area * x[e];

    std::vector<std::vector<double>> B_exact(3);
    for (int c = 0; c < 3; ++c) {
      std::vector<double> A(m * m, 0.0), b(m);
      for (std::size_t i = 0; i < m; ++i) {
        const rad::Material& mat = scene.material(h.patches()[h.element(leaves[i]).patch].material);
        A[i * m + i] += 1.0;
        b[i] = mat.emission[c];
        const double xi = x[leaves[i]] > 0.0f ? x[leaves[i]] : 1.0;
        for (std::size_t k = 0; k < m; ++k) {
          const rad::Element& ek = h.element(leaves[k]);
          A[i * m + k] -= mat.reflectance[c] / xi * F[i * n + ek.patch] * ek.area * x[leaves[k]] / patch_area[ek.patch];
        }
      }
      B_exact[c] = lu_solve(A, b, m);
    }

    for (rad::SolverMethod method :
         {rad::SolverMethod::jacobi, rad::SolverMethod::gauss_seidel, rad::SolverMethod::progressive}) {
      CAPTURE(static_cast<int>(method));
      o.method = method;
      const rad::Solution sol = rad::solve(scene, o);
      REQUIRE(sol.status() == rad::SolveStatus::converged);
      REQUIRE(sol.hierarchy().leaves() == leaves);
      double worst = 0.0;
      for (std::size_t i = 0; i < m; ++i)
        for (int c = 0; c < 3; ++c) {
          const double exact = B_exact[c][i], got = sol.radiosity()[leaves[i]][c];
          if (exact > 1e-3) worst = std::max(worst, std::fabs(got - exact) / exact);
        }
      MESSAGE("largest relative difference from LU: " << worst);
      CHECK(worst < 1e-3);
    }
  }
}
