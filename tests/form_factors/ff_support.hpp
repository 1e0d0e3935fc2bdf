// Helpers of the form-factor tests: scenes of a few polygons, random rotations, and an
// independent brute-force Monte Carlo area-to-area factor (its own sampling and ray-polygon
// intersection; nothing from the library's estimators).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>
#include <radiosity/radiosity.hpp>

namespace fftest {

namespace rad = radiosity;

constexpr double kPi = 3.14159265358979323846;

/// SplitMix64: a tiny independent generator for the tests.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }

 private:
  std::uint64_t state_;
};

/// A uniformly distributed random rotation (Shoemake's quaternion method, Graphics Gems III).
inline glm::dmat3 random_rotation(Random& rng) {
  const double u1 = rng.uniform(), u2 = 2 * kPi * rng.uniform(), u3 = 2 * kPi * rng.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double x = a * std::sin(u2), y = a * std::cos(u2), z = b * std::sin(u3), w = b * std::cos(u3);
  // Column-major glm: m[col][row].
  glm::dmat3 m;
  m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
  m[1] = {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)};
  m[2] = {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
  return m;
}

/// A planar convex polygon in double precision, counter-clockwise seen from its front.
struct Poly {
  std::vector<glm::dvec3> v;

  glm::dvec3 normal() const {
    glm::dvec3 n(0.0);
    for (std::size_t i = 0; i < v.size(); ++i) n += glm::cross(v[i], v[(i + 1) % v.size()]);
    return glm::normalize(n);
  }
  double area() const {
    glm::dvec3 n(0.0);
    for (std::size_t i = 0; i < v.size(); ++i) n += glm::cross(v[i], v[(i + 1) % v.size()]);
    return 0.5 * glm::length(n);
  }
  Poly transformed(const glm::dmat3& r, const glm::dvec3& t = glm::dvec3(0.0)) const {
    Poly p;
    for (const glm::dvec3& x : v) p.v.push_back(r * x + t);
    return p;
  }
  std::vector<glm::vec3> to_float() const {
    std::vector<glm::vec3> out;
    for (const glm::dvec3& x : v) out.emplace_back(x);
    return out;
  }
};

/// Axis-aligned rectangle in the plane z = z0 facing +z (up = true) or -z.
inline Poly rect_z(double x0, double y0, double x1, double y1, double z0, bool up) {
  Poly p;
  if (up)
    p.v = {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}};
  else
    p.v = {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}};
  return p;
}

/// The segment from `a` to `b` (excluding tiny end pieces) crosses the polygon's interior.
inline bool segment_hits(const glm::dvec3& a, const glm::dvec3& b, const Poly& p) {
  const glm::dvec3 n = p.normal();
  const double da = glm::dot(n, a - p.v[0]), db = glm::dot(n, b - p.v[0]);
  if ((da > 0) == (db > 0) || da == db) return false;
  const double t = da / (da - db);
  if (t < 1e-9 || t > 1 - 1e-9) return false;
  const glm::dvec3 x = a + t * (b - a);
  for (std::size_t i = 0; i < p.v.size(); ++i) {
    const glm::dvec3& p0 = p.v[i];
    const glm::dvec3& p1 = p.v[(i + 1) % p.v.size()];
    if (glm::dot(glm::cross(p1 - p0, x - p0), n) < 0) return false;
  }
  return true;
}

/// Uniform point on a convex polygon: a fan triangle chosen by area, then a uniform point in it.
inline glm::dvec3 sample_poly(const Poly& p, double u, double v, double pick) {
  std::vector<double> cdf;
  double total = 0;
  for (std::size_t i = 1; i + 1 < p.v.size(); ++i) {
    total += 0.5 * glm::length(glm::cross(p.v[i] - p.v[0], p.v[i + 1] - p.v[0]));
    cdf.push_back(total);
  }
  std::size_t t = 0;
  while (t + 1 < cdf.size() && pick * total > cdf[t]) ++t;
  if (u + v > 1) u = 1 - u, v = 1 - v;
  return p.v[0] + u * (p.v[t + 1] - p.v[0]) + v * (p.v[t + 2] - p.v[0]);
}

struct McResult {
  double value = 0, standard_error = 0;
};

/// Brute-force Monte Carlo estimate of F(src -> dst) with occluders: the mean over random point
/// pairs of A_dst cos_s cos_d / (pi r^2) V (V = 1 when the segment is clear). With
/// `blocked_part` the estimate is of the shadowed share instead (V replaced by 1 - V): it has no
/// 1/r^2 spike near a shared edge, so subtracting it from a closed form gives a reference with
/// a much smaller error. Source and receiver points are each stratified on a k x k grid of their
/// parameter square and paired by a random permutation; `rounds` independent rounds give the
/// standard error.
inline McResult mc_factor(const Poly& src, const Poly& dst, const std::vector<Poly>& occluders, std::size_t k,
                          std::size_t rounds, std::uint64_t seed, bool blocked_part = false) {
  Random rng(seed);
  const glm::dvec3 ns = src.normal(), nd = dst.normal();
  const double area = dst.area();
  const std::size_t strata = k * k;
  std::vector<std::size_t> perm(strata);
  double sum = 0, sum2 = 0;
  for (std::size_t r = 0; r < rounds; ++r) {
    for (std::size_t i = 0; i < strata; ++i) perm[i] = i;
    for (std::size_t i = strata; i > 1; --i) std::swap(perm[i - 1], perm[rng.next() % i]);
    double round_sum = 0;
    for (std::size_t i = 0; i < strata; ++i) {
      const double su = (double(i % k) + rng.uniform()) / double(k), sv = (double(i / k) + rng.uniform()) / double(k);
      const std::size_t j = perm[i];
      const double du = (double(j % k) + rng.uniform()) / double(k), dv = (double(j / k) + rng.uniform()) / double(k);
      const glm::dvec3 x = sample_poly(src, su, sv, rng.uniform());
      const glm::dvec3 y = sample_poly(dst, du, dv, rng.uniform());
      const glm::dvec3 d = y - x;
      const double r2 = glm::dot(d, d);
      const double cs = glm::dot(d, ns), cd = -glm::dot(d, nd);
      if (cs <= 0 || cd <= 0) continue;
      bool visible = true;
      for (const Poly& o : occluders)
        if (segment_hits(x, y, o)) {
          visible = false;
          break;
        }
      if (visible != blocked_part) round_sum += area * cs * cd / (kPi * r2 * r2);
    }
    const double mean = round_sum / double(strata);
    sum += mean;
    sum2 += mean * mean;
  }
  McResult out;
  out.value = sum / double(rounds);
  const double var = rounds > 1 ? (sum2 / double(rounds) - out.value * out.value) / double(rounds - 1) : 0.0;
  out.standard_error = std::sqrt(std::max(var, 0.0));
  return out;
}

/// A scene of the given polygons, polygon i in group "p<i>".
inline rad::Scene scene_of(const std::vector<Poly>& polys) {
  rad::Scene s;
  const rad::MaterialId m = s.add_material({});
  for (std::size_t i = 0; i < polys.size(); ++i) s.add_polygon(polys[i].to_float(), m, "p" + std::to_string(i));
  return s;
}

/// Group-level factor F(p<from> -> p<to>) of a scene built by scene_of().
inline double group_factor(const rad::Scene& scene, const rad::ViewFactorOptions& o, std::size_t from, std::size_t to) {
  rad::ViewFactorOptions vo = o;
  vo.groups = {"p" + std::to_string(from), "p" + std::to_string(to)};
  return rad::view_factors(scene, vo).at(0, 1);
}

/// Mesh options giving each polygon of `scene` a single patch and element.
inline rad::MeshOptions one_element_each(const rad::Scene& scene) {
  rad::MeshOptions m;
  m.max_patch_area = static_cast<float>(2.0 * scene.total_area());
  m.max_element_area = m.max_patch_area;
  return m;
}

}  // namespace fftest
