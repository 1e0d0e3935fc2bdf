// view_factors() and the estimators as an API: determinism, rows vs columns, options, errors,
// cancel, no NaN on awkward geometry, and the CSV/JSON formats of `radiosity factors`.
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../tools/radiosity/factors_format.hpp"
#include "form_factors/ff_support.hpp"
#include "support/build.hpp"
#include "support/scenes.hpp"

using namespace fftest;

namespace {

const rad::FormFactorMethod kMethods[] = {rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::analytic,
                                          rad::FormFactorMethod::hemicube};

// A small occluded room: the unit box around a floating block, 2 patches per wall.
rad::Scene room_with_block() {
  rad::Scene s = test::closed_box(rad::Material{});
  const rad::MaterialId m = 0;
  const float a = 0.35f, b = 0.65f, lo = 0.2f, hi = 0.5f;
  s.add_polygon({{a, lo, a}, {b, lo, a}, {b, lo, b}, {a, lo, b}}, m, "block");  // faces -y
  s.add_polygon({{a, hi, a}, {a, hi, b}, {b, hi, b}, {b, hi, a}}, m, "block");  // faces +y
  s.add_polygon({{a, lo, a}, {a, hi, a}, {b, hi, a}, {b, lo, a}}, m, "block");  // faces -z
  s.add_polygon({{a, lo, b}, {b, lo, b}, {b, hi, b}, {a, hi, b}}, m, "block");  // faces +z
  s.add_polygon({{a, lo, a}, {a, lo, b}, {a, hi, b}, {a, hi, a}}, m, "block");  // faces -x
  s.add_polygon({{b, lo, a}, {b, hi, a}, {b, hi, b}, {b, lo, b}}, m, "block");  // faces +x
  return s;
}

rad::MeshOptions coarse() {
  rad::MeshOptions m;
  m.max_patch_area = 0.5f;
  m.max_element_area = 0.125f;
  return m;
}

}  // namespace

TEST_SUITE("form_factors") {
  TEST_CASE(
      "view_factors names the groups - sums element areas - and is bit-identical at 1 and 2 threads for every "
      "estimator") {
    const rad::Scene s = room_with_block();
    for (const rad::FormFactorMethod m : kMethods) {
      rad::ViewFactorOptions o;
      o.mesh = coarse();
      o.form_factors.method = m;
      o.form_factors.threads = 1;
      const rad::GroupViewFactors one = rad::view_factors(s, o);
      o.form_factors.threads = 2;
      const rad::GroupViewFactors two = rad::view_factors(s, o);
      REQUIRE(one.groups == std::vector<std::string>{"x0", "x1", "y0", "y1", "z0", "z1", "block"});
      CHECK(one.area[0] == doctest::Approx(1.0).epsilon(1e-6));
      CHECK(one.area[6] == doctest::Approx(6 * 0.09).epsilon(1e-5));
      CHECK(one.factors == two.factors);  // exact equality
      CHECK_FALSE(one.cancelled);
      CHECK(one.patch_count > 0);
      // A different seed changes the sampled estimator (and not the analytic one).
      if (m == rad::FormFactorMethod::hemicube) continue;
      o.form_factors.seed = 2;
      const rad::GroupViewFactors other = rad::view_factors(s, o);
      if (m == rad::FormFactorMethod::ray_cast) CHECK(other.factors != one.factors);
      if (m == rad::FormFactorMethod::analytic) CHECK(other.factors == one.factors);
    }
  }

  TEST_CASE("view_factors from hierarchical links: the occluded room against ray_cast - bit-identical at 1 and 2 "
            "threads - a bad epsilon is an error") {
    const rad::Scene s = room_with_block();
    rad::ViewFactorOptions o;
    o.mesh.max_patch_area = 0.25f;
    o.mesh.max_element_area = 1.0f / 64.0f;
    o.form_factors.method = rad::FormFactorMethod::ray_cast;
    const rad::GroupViewFactors reference = rad::view_factors(s, o);
    o.method = rad::ViewFactorMethod::hierarchical;
    o.form_factors.threads = 1;
    const rad::GroupViewFactors one = rad::view_factors(s, o);
    o.form_factors.threads = 2;
    const rad::GroupViewFactors two = rad::view_factors(s, o);
    CHECK(one.factors == two.factors);  // exact equality
    CHECK(one.link_count > 0);
    CHECK(reference.link_count == 0);
    REQUIRE(one.groups == reference.groups);
    double worst = 0.0;
    for (std::size_t i = 0; i < one.groups.size(); ++i)
      for (std::size_t k = 0; k < one.groups.size(); ++k) {
        const double a = one.at(i, k), b = reference.at(i, k);
        INFO("F(", one.groups[i], " -> ", one.groups[k], ") = ", a, " links, ", b, " ray_cast");
        CHECK(std::fabs(a - b) < 0.01);  // absolute, in units of view factor
        worst = std::max(worst, std::fabs(a - b));
      }
    // Measured: worst |difference| 0.0044 (epsilon 0.02, the default).
    MESSAGE("links against ray_cast in the room with a block: worst |difference| " << worst);
    o.epsilon = 0.0f;
    CHECK_THROWS_AS(rad::view_factors(s, o), rad::Error);
    o.epsilon = 1.5f;
    CHECK_THROWS_AS(rad::view_factors(s, o), rad::Error);
  }

  TEST_CASE("patch_column agrees with element_rows for every estimator - in an occluded scene") {
    const rad::Scene s = room_with_block();
    const rad::PatchHierarchy h(s, coarse());
    const std::size_t n = h.patches().size();
    const std::vector<std::uint32_t>& leaves = h.leaves();
    for (const rad::FormFactorMethod m : kMethods) {
      rad::FormFactorOptions o;
      o.method = m;
      const auto est = rad::make_form_factor_estimator(s, h, o);
      std::vector<float> rows(leaves.size() * n);
      est->element_rows(leaves, rows.data());
      std::vector<float> column(leaves.size());
      double worst = 0;
      for (std::uint32_t j = 0; j < n; j += 3) {
        est->patch_column(j, leaves, column.data());
        for (std::size_t k = 0; k < leaves.size(); ++k)
          worst = std::max(worst, std::fabs(static_cast<double>(column[k]) - rows[k * n + j]));
      }
      INFO("largest |column - row| ", worst);
      // Ray cast and analytic evaluate the same code per pair. The hemicube rasterises only the
      // column's receiver and the patches in its shaft: the same pixels, except where a patch
      // behind the receiver, sharing its edge, wins a depth tie by rounding in the full row
      // (measured 1.3e-6 here, a fraction of one pixel's delta form factor).
      CHECK(worst <= (m == rad::FormFactorMethod::hemicube ? 1e-5 : 0.0));
    }
  }

  TEST_CASE("view_factors: a group filter selects and orders rows and columns - unknown or repeated names are errors") {
    const rad::Scene s = room_with_block();
    rad::ViewFactorOptions o;
    o.mesh = coarse();
    const rad::GroupViewFactors all = rad::view_factors(s, o);
    o.groups = {"block", "x0"};
    const rad::GroupViewFactors two = rad::view_factors(s, o);
    REQUIRE(two.groups == o.groups);
    CHECK(two.at(0, 1) == all.at(6, 0));
    CHECK(two.at(1, 0) == all.at(0, 6));
    CHECK(two.at(1, 1) == 0.0);
    o.groups = {"x0", "floor"};
    try {
      rad::view_factors(s, o);
      FAIL("expected an Error");
    } catch (const rad::Error& e) {
      CHECK(e.code() == rad::ErrorCode::invalid_argument);
      CHECK(std::string(e.what()).find("'floor'") != std::string::npos);
    }
    o.groups = {"x0", "x0"};
    CHECK_THROWS_AS(rad::view_factors(s, o), rad::Error);
  }

  TEST_CASE("absurd estimator options including zero counts are errors that name the field") {
    const rad::Scene s = test::closed_box(rad::Material{});
    const rad::PatchHierarchy h(s, coarse());
    auto fails_naming = [&](rad::FormFactorOptions o, const char* field) {
      try {
        rad::make_form_factor_estimator(s, h, o);
        FAIL("expected an Error for ", field);
      } catch (const rad::Error& e) {
        CHECK(e.code() == rad::ErrorCode::invalid_argument);
        CHECK(std::string(e.what()).find(field) != std::string::npos);
      }
      rad::ViewFactorOptions v;
      v.form_factors = o;
      CHECK_THROWS_AS(rad::view_factors(s, v), rad::Error);
    };
    rad::FormFactorOptions o;
    o.method = rad::FormFactorMethod::hemicube;
    o.hemicube_resolution = 9000;
    fails_naming(o, "hemicube_resolution");
    o.hemicube_resolution = 1;
    fails_naming(o, "hemicube_resolution");
    o = {};
    o.source_samples = 65;
    fails_naming(o, "source_samples");
    o = {};
    o.visibility_rays = 1000;
    fails_naming(o, "visibility_rays");
    o = {};
    o.method = static_cast<rad::FormFactorMethod>(42);
    fails_naming(o, "method");
    // Zero samples, rays or resolution: an error for every estimator, never a NaN.
    for (const rad::FormFactorMethod m : kMethods) {
      CAPTURE(static_cast<int>(m));
      o = {};
      o.method = m;
      o.source_samples = 0;
      fails_naming(o, "source_samples");
      o = {};
      o.method = m;
      o.visibility_rays = 0;
      fails_naming(o, "visibility_rays");
      o = {};
      o.method = m;
      o.hemicube_resolution = 0;
      fails_naming(o, "hemicube_resolution");
      o = {};
      o.method = m;
      o.hemisphere_rays = 0;
      fails_naming(o, "hemisphere_rays");
      // The defaults make a usable estimator.
      rad::FormFactorOptions d;
      d.method = m;
      CHECK_NOTHROW(rad::make_form_factor_estimator(s, h, d));
    }
    rad::ViewFactorOptions bad_mesh;
    bad_mesh.mesh.max_patch_area = -1.0f;
    CHECK_THROWS_AS(rad::view_factors(s, bad_mesh), rad::Error);
    CHECK_THROWS_AS(rad::view_factors(rad::Scene{}, rad::ViewFactorOptions{}), rad::Error);
  }

  TEST_CASE("view_factors reports progress on the calling thread and stops when the callback says so") {
    const rad::Scene s = room_with_block();
    rad::ViewFactorOptions o;
    o.mesh.max_patch_area = 0.05f;
    const std::thread::id caller = std::this_thread::get_id();
    int calls = 0;
    bool same_thread = true;
    o.on_progress = [&](const rad::Progress& p) {
      ++calls;
      same_thread &= std::this_thread::get_id() == caller;
      CHECK(p.phase == rad::Phase::form_factors);
      return false;  // cancel at the first report
    };
    const rad::GroupViewFactors v = rad::view_factors(s, o);
    CHECK(v.cancelled);
    CHECK(calls == 1);
    CHECK(same_thread);
  }

  TEST_CASE("touching - grazing - coincident and crossing polygons give finite factors in 0..1") {
    // A square, a fin standing on it (touching along its bottom edge), and one sharing an edge
    // at a grazing angle: legal, and every factor must be finite.
    auto base = [] {
      rad::Scene s;
      const rad::MaterialId m = s.add_material({});
      s.add_polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, m, "up");
      s.add_polygon({{0.5f, 0.2f, 0}, {0.5f, 0.8f, 0}, {0.5f, 0.8f, 0.5f}, {0.5f, 0.2f, 0.5f}}, m, "fin");
      s.add_polygon({{1, 0, 0}, {2, 0, 1e-4f}, {2, 1, 1e-4f}, {1, 1, 0}}, m, "graze");
      return s;
    };
    const rad::Scene s = base();
    for (const rad::FormFactorMethod method : kMethods) {
      rad::ViewFactorOptions o;
      o.form_factors.method = method;
      o.mesh.max_patch_area = 0.25f;
      const rad::GroupViewFactors v = rad::view_factors(s, o);
      for (std::size_t i = 0; i < v.groups.size(); ++i) {
        double sum = 0;
        for (std::size_t k = 0; k < v.groups.size(); ++k) {
          const double f = v.at(i, k);
          INFO(v.groups[i], " -> ", v.groups[k], " = ", f);
          CHECK(std::isfinite(f));
          CHECK(f >= 0.0);
          CHECK(f <= 1.0);
          sum += f;
        }
        CHECK(sum <= 1.0 + 1e-3);
      }
    }
    // A coincident back-to-back copy of the square, or a quad crossing it: accepted by every
    // estimator (contact and interpenetration are lit correctly), factors finite and rows <= 1.
    rad::Scene coincident = base();
    coincident.add_polygon({{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}, 0, "down");
    rad::Scene crossing = base();
    crossing.add_polygon({{0.25f, -0.5f, -0.5f}, {0.25f, 1.5f, -0.5f}, {0.25f, 1.5f, 0.5f}, {0.25f, -0.5f, 0.5f}}, 0,
                         "cross");
    for (const rad::FormFactorMethod method : kMethods) {
      rad::ViewFactorOptions o;
      o.form_factors.method = method;
      // The derived mesh (hundreds of elements) takes 40 s under the sanitizers; they check
      // the same contacts on the coarse mesh of the first half, the Release build on both.
      if (test::kSanitizerBuild) o.mesh.max_patch_area = 0.25f;
      for (const rad::Scene* scene : {&coincident, &crossing}) {
        const rad::GroupViewFactors v = rad::view_factors(*scene, o);
        for (std::size_t i = 0; i < v.groups.size(); ++i) {
          double sum = 0.0;
          for (std::size_t k = 0; k < v.groups.size(); ++k) {
            CHECK(std::isfinite(v.at(i, k)));
            CHECK(v.at(i, k) >= 0.0);
            sum += v.at(i, k);
          }
          CHECK(sum <= 1.0 + 1e-3);
        }
      }
    }
  }

  TEST_CASE("radiosity factors formats: CSV header and rows - sparse triplets - JSON with areas parses back") {
    rad::GroupViewFactors v;
    v.groups = {"floor", "wall, north", "sky"};
    v.area = {2.0, 1.5, 0.0};
    v.factors = {0.0, 0.25, 0.5, 1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    v.patch_count = 7;
    v.element_count = 11;
    CHECK(cli::factors_csv(v, false) ==
          ",floor,\"wall, north\",sky\n"
          "floor,0,0.25,0.5\n"
          "\"wall, north\",0.333333333,0,0\n"
          "sky,0,0,0\n");
    CHECK(cli::factors_csv(v, true) ==
          "from,to,factor\n"
          "floor,\"wall, north\",0.25\n"
          "floor,sky,0.5\n"
          "\"wall, north\",floor,0.333333333\n");
    const nlohmann::json dense = nlohmann::json::parse(cli::factors_json(v, false, "hemicube"));
    CHECK(dense["method"] == "hemicube");
    CHECK(dense["patches"] == 7);
    CHECK(dense["elements"] == 11);
    REQUIRE(dense["groups"].size() == 3);
    CHECK(dense["groups"][1]["name"] == "wall, north");
    CHECK(dense["groups"][1]["area"] == 1.5);
    REQUIRE(dense["factors"].size() == 3);
    CHECK(dense["factors"][1][0].get<double>() == 1.0 / 3.0);  // full precision
    const nlohmann::json sparse = nlohmann::json::parse(cli::factors_json(v, true, "ray-cast"));
    REQUIRE(sparse["factors"].size() == 3);
    CHECK(sparse["factors"][2]["from"] == "wall, north");
    CHECK(sparse["factors"][2]["to"] == "floor");
    CHECK(sparse["factors"][2]["factor"].get<double>() == 1.0 / 3.0);
  }
}
