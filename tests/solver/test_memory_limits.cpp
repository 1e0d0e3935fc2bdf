// Issue #17: every method that can grow past the machine checks the memory budget before the
// allocation, and refuses with the figure (Error{memory_budget}), not a std::bad_alloc partway:
// hierarchical links (solve and view factors), the view-factor matrix (exact and Monte Carlo
// rows) and the caustic photon map. The matrix methods' rows and progressive's cache are
// test_solve.cpp's.
#include <doctest/doctest.h>

#include <string>

#include <radiosity/radiosity.hpp>

namespace rad = radiosity;

namespace {

/// Calls `call`; true when it throws Error{memory_budget} whose message gives a figure in MiB
/// and names `field`.
template <typename Call>
bool refused_with_figure(const Call& call, const std::string& field) {
  try {
    call();
  } catch (const rad::Error& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(e.code() == rad::ErrorCode::memory_budget);
    CHECK(what.find(" MiB, over the memory budget of ") != std::string::npos);
    CHECK(what.find(field) != std::string::npos);
    return e.code() == rad::ErrorCode::memory_budget;
  }
  return false;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("memory budget: hierarchical links, the view-factor matrix and the photon map are refused with the figure") {
    const rad::Scene cornell = rad::cornell_box();

    // Hierarchical radiosity: its links against a 64 KiB budget, then the default.
    rad::SolveOptions o;
    o.method = rad::SolverMethod::hierarchical;
    o.memory_budget_bytes = 64 << 10;
    CHECK(refused_with_figure([&] { (void)rad::solve(cornell, o); }, "SolveOptions::memory_budget_bytes"));
    o.memory_budget_bytes = 0;
    const rad::Solution solved = rad::solve(cornell, o);
    CHECK(solved.status() == rad::SolveStatus::converged);
    MESSAGE("hierarchical Cornell box: " << solved.report().link_count << " links, "
                                         << solved.report().form_factor_bytes << " bytes");

    // The view-factor matrix: exact rows, Monte Carlo rows and hierarchical group factors.
    rad::ViewFactorOptions v;
    v.level = rad::ViewFactorLevel::element;
    v.mesh.max_element_area = 2500.0f;
    v.memory_budget_bytes = 16 << 10;
    for (const rad::FormFactorMethod method : {rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::monte_carlo}) {
      CAPTURE(static_cast<int>(method));
      v.form_factors.method = method;
      CHECK(refused_with_figure([&] { (void)rad::view_factor_matrix(cornell, v); },
                                "ViewFactorOptions::memory_budget_bytes"));
    }
    v.memory_budget_bytes = 0;
    v.form_factors.method = rad::FormFactorMethod::monte_carlo;
    CHECK(rad::view_factor_matrix(cornell, v).rows() > 0);
    rad::ViewFactorOptions links;
    links.method = rad::ViewFactorMethod::hierarchical;
    links.memory_budget_bytes = 16 << 10;
    CHECK(refused_with_figure([&] { (void)rad::view_factors(cornell, links); }, "ViewFactorOptions::memory_budget_bytes"));

    // The photon map: glass and mirror blocks, 200k photons against 64 KiB.
    const rad::Scene specular = rad::cornell_box_specular();
    rad::SolveOptions coarse;
    coarse.mesh.max_element_area = 10000.0f;
    coarse.specular_paths = rad::SpecularPaths::as_given;  // a classic pass 1: every caustic is the photon map's
    const rad::Solution pass1 = rad::solve(specular, coarse);
    rad::TwoPassOptions t;
    t.width = t.height = 8;
    t.spp = 1;
    t.caustics.memory_budget_bytes = 64 << 10;
    CHECK(refused_with_figure([&] { (void)rad::render_two_pass(specular, pass1, t); },
                              "PhotonOptions::memory_budget_bytes"));
    t.caustics.memory_budget_bytes = 0;
    CHECK(rad::render_two_pass(specular, pass1, t).pixels.size() == 64u);
  }
}
