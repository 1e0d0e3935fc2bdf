// Form factors against closed forms (Howell's catalogue) and exact polygon values, for the three
// estimators at their default settings, axis-aligned and under random rotations.
// Tolerances: ray_cast and analytic 0.5 %, hemicube 2 % (relative), as the issue requires.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "form_factors/ff_support.hpp"
#include "support/scenes.hpp"
#include "support/build.hpp"

using namespace fftest;

namespace {

constexpr double kExactTolerance = 5e-3;     // ray_cast, analytic
constexpr double kHemicubeTolerance = 2e-2;  // hemicube

std::string name(rad::FormFactorMethod m) {
  return m == rad::FormFactorMethod::ray_cast   ? "ray_cast"
         : m == rad::FormFactorMethod::analytic ? "analytic"
                                                : "hemicube";
}

double tolerance(rad::FormFactorMethod m) {
  return m == rad::FormFactorMethod::hemicube ? kHemicubeTolerance : kExactTolerance;
}

// The hemicube treats each element as a few points: it needs elements that are small next to
// their distance from the receiver (docs/FORM_FACTORS.md, "proximity"). It gets one patch per
// polygon and elements of 1/`divisions` of the scene's area; the others one element per polygon.
rad::MeshOptions mesh_for(rad::FormFactorMethod m, const rad::Scene& s, float divisions = 32.0f) {
  if (m != rad::FormFactorMethod::hemicube) return one_element_each(s);
  rad::MeshOptions o;
  o.max_patch_area = static_cast<float>(s.total_area());
  o.max_element_area = o.max_patch_area / divisions;
  return o;
}

double factor(const std::vector<Poly>& polys, rad::FormFactorMethod m, std::size_t from = 0, std::size_t to = 1) {
  const rad::Scene s = scene_of(polys);
  rad::ViewFactorOptions o;
  o.form_factors.method = m;
  o.mesh = mesh_for(m, s);
  return group_factor(s, o, from, to);
}

// The identity and two random rigid motions.
std::vector<std::pair<glm::dmat3, glm::dvec3>> motions(std::uint64_t seed) {
  Random rng(seed);
  std::vector<std::pair<glm::dmat3, glm::dvec3>> out{{glm::dmat3(1.0), glm::dvec3(0.0)}};
  for (int i = 0; i < 2; ++i)
    out.emplace_back(random_rotation(rng),
                     glm::dvec3(4 * rng.uniform() - 2, 4 * rng.uniform() - 2, 4 * rng.uniform() - 2));
  return out;
}

std::vector<Poly> moved(const std::vector<Poly>& polys, const std::pair<glm::dmat3, glm::dvec3>& m) {
  std::vector<Poly> out;
  for (const Poly& p : polys) out.push_back(p.transformed(m.first, m.second));
  return out;
}

const rad::FormFactorMethod kMethods[] = {rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::analytic,
                                          rad::FormFactorMethod::hemicube};

// A regular n-gon of circumradius r centred on the z axis at height z, facing +z or -z.
Poly ngon(int n, double r, double z, bool up) {
  Poly p;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n * (up ? 1 : -1);
    p.v.emplace_back(r * std::cos(a), r * std::sin(a), z);
  }
  return p;
}

// Gauss-Legendre nodes and weights on [0, 1], a fixed 6-point rule.
const double kGlNode[6] = {0.033765242898424, 0.169395306766868, 0.380690406958402,
                           0.619309593041598, 0.830604693233132, 0.966234757101576};
const double kGlWeight[6] = {0.085662246189585, 0.180380786524069, 0.233956967286346,
                             0.233956967286346, 0.180380786524069, 0.085662246189585};

// The exact unoccluded factor from a point at height h below the plane of a convex polygon
// (parallel, facing it) whose foot point f lies inside the polygon: in polar coordinates about
// f, F = 1/(2 pi) integral of rho(phi)^2 / (h^2 + rho(phi)^2) dphi, rho the distance to the
// boundary. Between consecutive corners rho = d / cos(phi - theta) (one edge line at distance d
// with normal direction theta), a smooth integrand: 6-point Gauss-Legendre per edge.
double polar_point_factor(glm::dvec2 f, double h, const std::vector<glm::dvec2>& poly) {
  double sum = 0;
  const std::size_t n = poly.size();
  for (std::size_t k = 0; k < n; ++k) {
    const glm::dvec2 a = poly[k] - f, b = poly[(k + 1) % n] - f;
    const glm::dvec2 e = b - a;
    glm::dvec2 normal(e.y, -e.x);
    normal /= glm::length(normal);
    double d = glm::dot(normal, a);
    if (d < 0) d = -d, normal = -normal;
    const double theta = std::atan2(normal.y, normal.x);
    double pa = std::atan2(a.y, a.x), pb = std::atan2(b.y, b.x);
    while (pb < pa) pb += 2 * kPi;
    if (pb - pa > kPi) pa += 2 * kPi, std::swap(pa, pb);
    for (int i = 0; i < 6; ++i) {
      const double phi = pa + kGlNode[i] * (pb - pa);
      const double rho = d / std::cos(phi - theta);
      sum += kGlWeight[i] * (pb - pa) * rho * rho / (h * h + rho * rho);
    }
  }
  return sum / (2 * kPi);
}

// Area-to-area factor from a coaxial regular n-gon of radius r1 to one of radius r2 at distance
// h (both centred on the axis, r1 <= r2 cos(pi/n) so every foot point is inside): the mean of
// polar_point_factor over the source, by Gauss-Legendre in each of the source's fan triangles
// (collapsed square map).
double coaxial_ngon_factor(int n, double r1, double r2, double h) {
  std::vector<glm::dvec2> target, source;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n;
    target.emplace_back(r2 * std::cos(a), r2 * std::sin(a));
    source.emplace_back(r1 * std::cos(a), r1 * std::sin(a));
  }
  double integral = 0, area = 0;
  for (int k = 0; k < n; ++k) {
    const glm::dvec2 p1 = source[static_cast<std::size_t>(k)], p2 = source[static_cast<std::size_t>((k + 1) % n)];
    const double tri = 0.5 * std::fabs(p1.x * p2.y - p1.y * p2.x);
    area += tri;
    // x(s, t) = s ((1 - t) p1 + t p2), Jacobian 2 tri s.
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const double s = kGlNode[i], t = kGlNode[j];
        const glm::dvec2 x = s * ((1 - t) * p1 + t * p2);
        integral += kGlWeight[i] * kGlWeight[j] * 2 * tri * s * polar_point_factor(x, h, target);
      }
  }
  return integral / area;
}

// Howell C-41: coaxial parallel disks, radii r1 (source) and r2 at distance h.
double coaxial_disks(double r1, double r2, double h) {
  const double R1 = r1 / h, R2 = r2 / h, X = 1 + (1 + R2 * R2) / (R1 * R1);
  return 0.5 * (X - std::sqrt(X * X - 4 * (R2 / R1) * (R2 / R1)));
}

// A closed box [0,sx]x[0,sy]x[0,sz] of six inward-facing rectangles, in the order x0, x1, y0,
// y1, z0, z1.
std::vector<Poly> box(double sx, double sy, double sz) {
  const glm::dvec3 c(0.5 * sx, 0.5 * sy, 0.5 * sz);
  std::vector<std::vector<glm::dvec3>> faces = {
      {{0, 0, 0}, {0, 0, sz}, {0, sy, sz}, {0, sy, 0}}, {{sx, 0, 0}, {sx, sy, 0}, {sx, sy, sz}, {sx, 0, sz}},
      {{0, 0, 0}, {sx, 0, 0}, {sx, 0, sz}, {0, 0, sz}}, {{0, sy, 0}, {0, sy, sz}, {sx, sy, sz}, {sx, sy, 0}},
      {{0, 0, 0}, {0, sy, 0}, {sx, sy, 0}, {sx, 0, 0}}, {{0, 0, sz}, {sx, 0, sz}, {sx, sy, sz}, {0, sy, sz}}};
  std::vector<Poly> out;
  for (auto& f : faces) {
    Poly p;
    p.v = f;
    if (glm::dot(p.normal(), c - f[0]) < 0) std::reverse(p.v.begin(), p.v.end());
    out.push_back(p);
  }
  return out;
}

}  // namespace

namespace {

/// Face pairs of the closed 1 x 2 x 3 box (box(1, 2, 3)) with closed forms: x0 -> x1 is C-11
/// (2 x 3 at distance 1); x0 -> y0 is C-14 (shared edge 3, source width 2, receiver height 1);
/// z0 -> y1 is C-14 (edge 1, width 2, height 3).
struct ClosedFormPair {
  std::size_t from, to;
  double exact;
};
std::vector<ClosedFormPair> box123_closed_forms() {
  return {{0, 1, test::parallel_rectangles(2, 3, 1)},
          {0, 2, test::perpendicular_rectangles(3, 2, 1)},
          {4, 3, test::perpendicular_rectangles(1, 2, 3)}};
}

}  // namespace

TEST_SUITE("form_factors") {
  TEST_CASE(
      "parallel rectangles (Howell C-11) at several sizes and distances - rotated: ray_cast and analytic within 0.5% - "
      "hemicube within 2%" * test::not_under_thread_sanitizer) {
    const double cases[][3] = {{1, 1, 1}, {1, 1, 0.1}, {2, 0.5, 0.3}, {1, 1, 5}, {10, 1, 0.5}, {0.1, 0.1, 1}};
    std::uint64_t seed = 11;
    for (const auto& c : cases) {
      const double exact = test::parallel_rectangles(c[0], c[1], c[2]);
      const std::vector<Poly> polys = {rect_z(0, 0, c[0], c[1], 0, true), rect_z(0, 0, c[0], c[1], c[2], false)};
      const auto all_motions = motions(++seed);
      for (std::size_t k = 0; k < all_motions.size(); ++k)
        for (const rad::FormFactorMethod m : kMethods) {
          if (m == rad::FormFactorMethod::hemicube && k == 2) continue;  // the slow one: two motions
          const double f = factor(moved(polys, all_motions[k]), m);
          INFO(name(m), " a=", c[0], " b=", c[1], " c=", c[2], " exact ", exact, " got ", f);
          CHECK(std::fabs(f / exact - 1) <= tolerance(m));
        }
    }
  }

  TEST_CASE(
      "perpendicular rectangles sharing an edge (Howell C-14) at several aspect ratios - rotated: ray_cast and analytic "
      "within 0.5% - hemicube within 2%" * test::not_under_thread_sanitizer) {
    // {shared edge l, source width w, receiver height h}
    const double cases[][3] = {{1, 1, 1}, {1, 0.1, 1}, {1, 1, 0.1}, {2, 1, 3}, {0.2, 1, 1}, {5, 1, 1}};
    std::uint64_t seed = 21;
    for (const auto& c : cases) {
      const double l = c[0], w = c[1], h = c[2];
      const double exact = test::perpendicular_rectangles(l, w, h);
      Poly floor = rect_z(0, 0, w, l, 0, true), wall;
      wall.v = {{0, 0, 0}, {0, l, 0}, {0, l, h}, {0, 0, h}};
      const auto all_motions = motions(++seed);
      for (std::size_t k = 0; k < all_motions.size(); ++k)
        for (const rad::FormFactorMethod m : kMethods) {
          if (m == rad::FormFactorMethod::hemicube && k == 2) continue;  // the slow one: two motions
          const double f = factor(moved({floor, wall}, all_motions[k]), m);
          INFO(name(m), " l=", l, " w=", w, " h=", h, " exact ", exact, " got ", f);
          CHECK(std::fabs(f / exact - 1) <= tolerance(m));
        }
    }
  }

  TEST_CASE("hemicube on single elements: within 2% where the element is no larger than its distance to the receiver") {
    // The hemicube's proximity limit, measured: with one element per polygon it stays within
    // 2 % for unit squares (C-11 at distance >= 1, C-14); docs/FORM_FACTORS.md lists the
    // configurations where it does not (e.g. C-11 at distance 0.1: +10 %).
    struct Case {
      std::vector<Poly> polys;
      double exact;
    };
    Poly wall;
    wall.v = {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}};
    const Case cases[] = {
        {{rect_z(0, 0, 1, 1, 0, true), rect_z(0, 0, 1, 1, 1, false)}, test::parallel_rectangles(1, 1, 1)},
        {{rect_z(0, 0, 1, 1, 0, true), rect_z(0, 0, 1, 1, 5, false)}, test::parallel_rectangles(1, 1, 5)},
        {{rect_z(0, 0, 1, 1, 0, true), wall}, test::perpendicular_rectangles(1, 1, 1)},
    };
    for (const Case& c : cases) {
      const rad::Scene s = scene_of(c.polys);
      rad::ViewFactorOptions o;
      o.form_factors.method = rad::FormFactorMethod::hemicube;
      o.mesh = one_element_each(s);
      const double f = group_factor(s, o, 0, 1);
      INFO("exact ", c.exact, " got ", f);
      CHECK(std::fabs(f / c.exact - 1) <= kHemicubeTolerance);
    }
  }

  TEST_CASE(
      "point to disk: the contour integral matches the disk closed form and a polygon's exact polar integral - "
      "rotated") {
    const double h_values[] = {0.1, 1.0, 3.0};
    Random rng(5);
    for (const double h : h_values) {
      const double R = 1.0;
      const Poly disk = ngon(512, R, h, false);
      std::vector<glm::dvec2> flat;
      for (const glm::dvec3& v : disk.v) flat.emplace_back(v.x, v.y);
      const double polygon_exact = polar_point_factor({0, 0}, h, flat);
      const double disk_exact = R * R / (h * h + R * R);
      // A 512-gon differs from its circle by < 1e-4 of the factor.
      CHECK(polygon_exact == doctest::Approx(disk_exact).epsilon(1e-4));
      for (int trial = 0; trial < 3; ++trial) {
        const glm::dmat3 r = trial == 0 ? glm::dmat3(1.0) : random_rotation(rng);
        const glm::dvec3 t(rng.uniform(), rng.uniform(), rng.uniform());
        const Poly moved_disk = disk.transformed(r, t);
        const std::vector<glm::vec3> corners = moved_disk.to_float();
        const double f = rad::point_to_polygon_factor(glm::vec3(t), glm::vec3(r * glm::dvec3(0, 0, 1)), corners.data(),
                                                      static_cast<int>(corners.size()));
        INFO("h=", h, " trial ", trial);
        CHECK(f == doctest::Approx(polygon_exact).epsilon(1e-5));
        // Facing away: nothing.
        CHECK(rad::point_to_polygon_factor(glm::vec3(t), glm::vec3(r * glm::dvec3(0, 0, -1)), corners.data(),
                                           static_cast<int>(corners.size())) == 0.0);
      }
    }
  }

  TEST_CASE(
      "coaxial disks as 32-gons match the polygons' exact factor (and Howell C-41 within the polygon error): ray_cast "
      "and analytic within 0.5% - hemicube within 2% - both directions" * test::not_under_thread_sanitizer) {
    const double cases[][3] = {{0.5, 1.0, 0.5}, {0.5, 1.0, 2.0}, {0.9, 1.0, 0.25}};  // r1, r2, h
    std::uint64_t seed = 31;
    for (const auto& c : cases) {
      const double r1 = c[0], r2 = c[1], h = c[2];
      const int n = 32;
      const double exact = coaxial_ngon_factor(n, r1, r2, h);
      CHECK(exact == doctest::Approx(coaxial_disks(r1, r2, h)).epsilon(1e-2));
      const Poly small = ngon(n, r1, 0, true), big = ngon(n, r2, h, false);
      const double reverse = small.area() * exact / big.area();  // reciprocity
      const auto all_motions = motions(++seed);
      for (std::size_t k = 0; k < all_motions.size(); ++k) {
        const std::vector<Poly> polys = moved({small, big}, all_motions[k]);
        for (const rad::FormFactorMethod m : kMethods) {
          // The hemicube (the slow one) runs on the second motion of the first case only. The
          // scene meshes an n-gon as a fan of long thin triangles, so its elements must be
          // finer (1/128 of the area).
          if (m == rad::FormFactorMethod::hemicube && (k != 1 || h != 0.5)) continue;
          const rad::Scene s = scene_of(polys);
          rad::ViewFactorOptions o;
          o.form_factors.method = m;
          o.mesh = mesh_for(m, s, 128.0f);
          o.groups = {"p0", "p1"};
          const rad::GroupViewFactors v = rad::view_factors(s, o);
          INFO(name(m), " r1=", r1, " r2=", r2, " h=", h, " exact ", exact, " got ", v.at(0, 1), " reverse ", reverse,
               " got ", v.at(1, 0));
          CHECK(std::fabs(v.at(0, 1) / exact - 1) <= tolerance(m));
          CHECK(std::fabs(v.at(1, 0) / reverse - 1) <= tolerance(m));
        }
      }
    }
  }

  TEST_CASE("unit cube: opposite faces 0.1998249 - adjacent 0.2000438 - rows sum to 1 - for every estimator") {
    const std::vector<Poly> faces = box(1, 1, 1);
    const rad::Scene s = scene_of(faces);
    for (const rad::FormFactorMethod m : kMethods) {
      rad::ViewFactorOptions o;
      o.form_factors.method = m;
      o.mesh.max_patch_area = 1.0f;
      o.mesh.max_element_area = 1.0f / 16.0f;
      const rad::GroupViewFactors v = rad::view_factors(s, o);
      REQUIRE(v.groups.size() == 6);
      for (std::size_t i = 0; i < 6; ++i) {
        double sum = 0;
        for (std::size_t k = 0; k < 6; ++k) {
          sum += v.at(i, k);
          const double expected = k == i ? 0.0 : (k == (i ^ 1u) ? 0.1998249 : 0.2000438);
          INFO(name(m), " F(", i, " -> ", k, ") = ", v.at(i, k), ", expected ", expected);
          if (expected == 0.0)
            CHECK(v.at(i, k) == 0.0);
          else
            CHECK(std::fabs(v.at(i, k) / expected - 1) <= tolerance(m));
        }
        INFO(name(m), " row ", i, " sums to ", sum);
        CHECK(std::fabs(sum - 1) <= tolerance(m));
      }
    }
  }

  TEST_CASE(
      "closed 1 x 2 x 3 box - rotated: faces match C-11 and C-14 - reciprocity A_i F_ij = A_j F_ji and row sums of 1"
      * test::not_under_thread_sanitizer) {
    const std::vector<Poly> faces = box(1, 2, 3);
    const std::vector<ClosedFormPair> pairs = box123_closed_forms();
    Random rng(41);
    const glm::dmat3 r = random_rotation(rng);
    const rad::Scene s = scene_of(moved(faces, {r, glm::dvec3(1, -2, 0.5)}));
    for (const rad::FormFactorMethod m : kMethods) {
      rad::ViewFactorOptions o;
      o.form_factors.method = m;
      o.mesh.max_patch_area = 0.5f;
      o.mesh.max_element_area = 0.125f;
      const rad::GroupViewFactors v = rad::view_factors(s, o);
      for (const auto& p : pairs) {
        INFO(name(m), " F(", p.from, " -> ", p.to, ") = ", v.at(p.from, p.to), ", exact ", p.exact);
        CHECK(std::fabs(v.at(p.from, p.to) / p.exact - 1) <= tolerance(m));
      }
      for (std::size_t i = 0; i < 6; ++i) {
        double sum = 0;
        for (std::size_t k = 0; k < 6; ++k) {
          sum += v.at(i, k);
          const double a = v.area[i] * v.at(i, k), b = v.area[k] * v.at(k, i);
          INFO(name(m), " A F(", i, " -> ", k, ") = ", a, ", A F(", k, " -> ", i, ") = ", b);
          CHECK(std::fabs(a - b) <= tolerance(m) * std::max(a, b));
        }
        INFO(name(m), " row ", i, " sums to ", sum);
        CHECK(std::fabs(sum - 1) <= tolerance(m));
      }
    }
  }

  TEST_CASE("hierarchical links: the 1 x 2 x 3 box's C-11 and C-14 factors - exactly reciprocal - rows of 1"
            * test::not_under_thread_sanitizer) {
    // ViewFactorMethod::hierarchical: the links refined for unit radiosity, one gather per face.
    // Measured, worst relative error over the three closed forms / worst row sum: 0.22 % / 0.31 %
    // at epsilon 0.05, 0.16 % / 0.18 % at 0.01 (and 0.17 % / 0.20 % at 0.002: the elements, 1/32
    // of a unit each, are the finest ends; below about 0.01 what remains is their quadrature and
    // their links' visibility rays, not the refinement).
    const std::vector<Poly> faces = box(1, 2, 3);
    const std::vector<ClosedFormPair> pairs = box123_closed_forms();
    const rad::Scene s = scene_of(faces);
    for (const float eps : {0.05f, 0.01f}) {
      CAPTURE(eps);
      rad::ViewFactorOptions o;
      o.method = rad::ViewFactorMethod::hierarchical;
      o.epsilon = eps;
      o.mesh.max_patch_area = 0.5f;
      o.mesh.max_element_area = 1.0f / 32.0f;
      const rad::GroupViewFactors v = rad::view_factors(s, o);
      CHECK(v.link_count > 0);
      double worst = 0.0, worst_row = 0.0;
      for (const auto& p : pairs) worst = std::max(worst, std::fabs(v.at(p.from, p.to) / p.exact - 1));
      for (std::size_t i = 0; i < 6; ++i) {
        double sum = 0;
        for (std::size_t k = 0; k < 6; ++k) {
          sum += v.at(i, k);
          const double a = v.area[i] * v.at(i, k), b = v.area[k] * v.at(k, i);
          CHECK(std::fabs(a - b) <= 1e-12 * std::max(a, b));  // reciprocal by construction
        }
        worst_row = std::max(worst_row, std::fabs(sum - 1));
      }
      MESSAGE("links at epsilon " << eps << ": worst closed-form error " << worst << ", worst row " << worst_row);
      CHECK(worst < 0.005);
      CHECK(worst_row < 0.005);
    }
  }

  TEST_CASE("hierarchical links at polygon level: the 1 x 2 x 3 box's C-11 and C-14 factors - the group level's - "
            "exactly reciprocal - rows of 1" * test::not_under_thread_sanitizer) {
    // ViewFactorMethod::hierarchical below group level: each row the transpose of the gather at
    // unit radiosity (LinkHierarchy::view_factor_rows()), made reciprocal by averaging.
    // Measured: the closed forms within 0.086 %, rows within 0.074 % of 1, the group level's
    // factors (one gather per face) within 0.044 %.
    const std::vector<Poly> faces = box(1, 2, 3);
    const std::vector<ClosedFormPair> pairs = box123_closed_forms();
    const rad::Scene s = scene_of(faces);
    rad::ViewFactorOptions o;
    o.method = rad::ViewFactorMethod::hierarchical;
    o.epsilon = 0.05f;
    o.mesh.max_patch_area = 0.5f;
    o.mesh.max_element_area = 1.0f / 32.0f;
    const rad::ViewFactorMatrix polygons = rad::view_factor_matrix(s, o);
    REQUIRE(polygons.rows() == 6);
    CHECK(polygons.method == "hierarchical");
    const rad::GroupViewFactors groups = rad::view_factors(s, o);
    double worst = 0.0, worst_row = 0.0, worst_group = 0.0;
    for (const auto& p : pairs) worst = std::max(worst, std::fabs(polygons.at(p.from, static_cast<std::uint32_t>(p.to)) / p.exact - 1));
    for (std::size_t i = 0; i < 6; ++i) {
      double sum = 0;
      for (std::uint32_t k = 0; k < 6; ++k) {
        sum += polygons.at(i, k);
        const double a = polygons.area[i] * polygons.at(i, k), b = polygons.area[k] * polygons.at(k, i);
        CHECK(std::fabs(a - b) <= 1e-6 * std::max(a, b));  // reciprocal by construction (float factors)
        if (groups.at(i, k) > 0.01) worst_group = std::max(worst_group, std::fabs(polygons.at(i, k) / groups.at(i, k) - 1));
      }
      worst_row = std::max(worst_row, std::fabs(sum - 1));
    }
    MESSAGE("polygon level: worst closed-form error " << worst << ", worst row " << worst_row
                                                      << ", worst against the group level " << worst_group);
    CHECK(worst < 0.005);
    CHECK(worst_row < 0.005);
    CHECK(worst_group < 1e-3);

  }

  TEST_CASE("hierarchical links: a floor square and a wall panel above its edge (a difference of Howell C-14 factors) "
            "within 0.05 %" * test::not_under_thread_sanitizer) {
    // One element each, so the link is the element pair's closed form, averaged over Gauss-
    // Legendre points of the receiver (3 x 3 here: centroids 1.58 apart, radii adding up to
    // 1.41), both ways and made reciprocal. The floor's points near the wall see the panel at a
    // factor that vanishes toward the wall's plane: the midpoint grid of 4 x 4 cells used before
    // overestimated that direction by 1.24 % and underestimated the other by 0.46 % (+0.39 %
    // after averaging); Gauss-Legendre 3 x 3 is within 0.01 % either way
    // (docs/HIERARCHICAL.md, "Element links").
    const std::vector<Poly> polys = {rect_z(0, 0, 1, 1, 0, true),
                                     Poly{{{0, 0, 1}, {0, 1, 1}, {0, 1, 2}, {0, 0, 2}}}};  // x = 0, facing +x
    const double exact = test::perpendicular_rectangles(1, 1, 2) - test::perpendicular_rectangles(1, 1, 1);
    rad::ViewFactorOptions o;
    o.method = rad::ViewFactorMethod::hierarchical;
    o.mesh.max_patch_area = 1.0f;
    o.mesh.max_element_area = 1.0f;
    const rad::ViewFactorMatrix m = rad::view_factor_matrix(scene_of(polys), o);
    REQUIRE(m.rows() == 2);
    MESSAGE("F(floor -> panel) " << m.at(0, 1) << ", F(panel -> floor) " << m.at(1, 0) << ", exact " << exact);
    CHECK(std::fabs(m.at(0, 1) / exact - 1) < 5e-4);
    CHECK(std::fabs(m.at(1, 0) / exact - 1) < 5e-4);
  }

  TEST_CASE("hierarchical links at element level: against the exact mode's element factors, the error shrinking with "
            "epsilon - summed per face, C-11 and C-14" * test::release_only) {
    // Every leaf element of the 1 x 2 x 3 box a row (992 rows, about 0.8 M factors: a closed
    // box's rows are dense). Measured against the exact mode (ray_cast) per element: the RMS
    // difference of the factors 1.13 % of their RMS at epsilon 0.05, 0.26 % at 0.01; the worst
    // row 0.025 and 0.0085 from 1 (the exact mode's 6e-6); factors above 0.01 within 0.063 %
    // (the touching pairs along the box's edges, averaged adaptively since session 43; 0.51 %
    // with the midpoints of 8 x 8 cells, 0.22 % at 4 x 4 Gauss-Legendre points). Summed per
    // face, the closed forms within 0.27 % at 0.05 and 0.021 % at 0.01.
    const std::vector<Poly> faces = box(1, 2, 3);
    const std::vector<ClosedFormPair> pairs = box123_closed_forms();
    const rad::Scene s = scene_of(faces);
    rad::ViewFactorOptions o;
    o.level = rad::ViewFactorLevel::element;
    o.mesh.max_patch_area = 0.5f;
    o.mesh.max_element_area = 1.0f / 32.0f;
    const rad::ViewFactorMatrix exact = rad::view_factor_matrix(s, o);
    const rad::PatchHierarchy h(s, o.mesh);
    REQUIRE(exact.rows() == h.leaves().size());
    o.method = rad::ViewFactorMethod::hierarchical;
    std::vector<double> errors;
    for (const float eps : {0.05f, 0.01f}) {
      CAPTURE(eps);
      o.epsilon = eps;
      // Progress goes forward through the links' refinement and then their rows.
      double last_fraction = 0.0;
      int backward = 0;
      o.on_progress = [&](const rad::Progress& p) {
        if (p.phase != rad::Phase::form_factors) return true;
        backward += p.fraction < last_fraction ? 1 : 0;
        last_fraction = p.fraction;
        return true;
      };
      const rad::ViewFactorMatrix links = rad::view_factor_matrix(s, o);
      CHECK(backward == 0);
      CHECK(last_fraction == 1.0);
      REQUIRE(links.rows() == exact.rows());
      double difference = 0.0, size = 0.0, worst_row = 0.0, worst_large = 0.0;
      std::array<double, 6> area{};
      std::array<std::array<double, 6>, 6> transport{};
      for (std::size_t i = 0; i < links.rows(); ++i) {
        const std::size_t from = h.patches()[h.element(links.ids[i]).patch].polygon;
        area[from] += links.area[i];
        double sum = 0.0;
        for (std::uint64_t k = links.row_offsets[i]; k < links.row_offsets[i + 1]; ++k) {
          const std::size_t to = h.patches()[h.element(links.ids[links.columns[k]]).patch].polygon;
          transport[from][to] += links.area[i] * static_cast<double>(links.values[k]);
          sum += static_cast<double>(links.values[k]);
        }
        worst_row = std::max(worst_row, std::fabs(sum - 1));
        for (std::uint64_t k = exact.row_offsets[i]; k < exact.row_offsets[i + 1]; ++k) {
          const double x = exact.values[k], d = links.at(i, exact.columns[k]) - x;
          difference += d * d;
          size += x * x;
          if (x > 0.01) worst_large = std::max(worst_large, std::fabs(d) / x);
        }
      }
      errors.push_back(std::sqrt(difference / size));
      double worst_summed = 0.0;
      for (const auto& p : pairs) worst_summed = std::max(worst_summed, std::fabs(transport[p.from][p.to] / area[p.from] / p.exact - 1));
      MESSAGE("element level at epsilon " << eps << ": " << links.non_zeros() << " factors, RMS difference to the exact "
                                          << "mode " << errors.back() << " of theirs, worst row " << worst_row
                                          << ", factors over 0.01 within " << worst_large << ", per face " << worst_summed);
      CHECK(errors.back() < (eps > 0.02f ? 0.02 : 0.005));
      CHECK(worst_row < (eps > 0.02f ? 0.03 : 0.012));
      CHECK(worst_large < 0.002);
      CHECK(worst_summed < 0.005);
    }
    CHECK(errors[1] < 0.5 * errors[0]);
  }
}
