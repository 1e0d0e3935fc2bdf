// A procedural city of facets (issue #15's benchmark scene): a ground of streets and blocks, boxes
// of random height standing on the blocks, every surface cut into quads of about one facet size,
// under a sky. Built through the public API (its random numbers from the library's
// core/rng.hpp), so benchmarks (bench_city) and tests (tests/scene/test_city.cpp) share it.
// Header-only.
//
// Layout, in metres, y up: n x n square blocks of kCityBlock, with streets of kCityStreet between
// them and around the edge, so the city is n (kCityBlock + kCityStreet) + kCityStreet wide in x
// and z. Along each axis the ground is 2n + 1 strips (street, block, street, ..., street); each
// of the (2n + 1)^2 rectangles they make is cut into a lattice of its own, in group "ground" (the
// blocks: pavements and yards) where both strips are blocks, "streets" elsewhere. A block holds 1, 2 or
// 4 buildings (1 or 2 lots along each axis), each a box in its lot, at least kCityMargin from
// the lot's edges, 6-30 m tall (one in ten a tower of 30-60 m). A building is four walls and a
// roof (no floor): it stands on the ground, which runs on under it, as a box put on a floor
// does; its walls' bottom edges lie in the ground plane (touching, no gap, no overlap). The
// ground facets wholly under a building are in group "under_buildings": they stay dark, about
// 10 % of the facets (as in a modelled scene, where nobody cuts the floor out under a box).
//
// Facets: a length L is cut into cells(L, s) = ceil(L / s) equal pieces (at least 1), so every
// facet is a quad with edges of at most the facet size s, and
//   ground and streets  ((n + 1) cells(kCityStreet, s) + n cells(kCityBlock, s))^2,
//                       of which the blocks' ground (under buildings or not) is n^2 cells(kCityBlock, s)^2;
//   a building w x d x h  2 (cells(w, s) + cells(d, s)) cells(h, s) walls + cells(w, s) cells(d, s) roof;
// City::facets() is their sum: about n^2 11 600 m^2 / s^2 (a block with its share of the streets
// has about 5 300 m^2 of ground and 6 300 m^2 of walls and roofs), up to ~10 % more at facets of
// a few metres, where lengths are rounded up to whole facets. With seed 1, 3, 10 and 20 blocks at
// 2.25 m give 23 454, 250 481 and 990 994 facets: bench_city's presets "22k", "246k" and "1M".
//
// The sky: a Light of LightType::sky (uniform, kCitySkyIrradiance on open ground), not an
// emitting polygon. It is the library's sky (docs/LIGHTS.md): radiance from the whole upper
// hemisphere down to the horizon, which a polygon above the city cannot give without boxing
// it in; its direct light is computed exactly where nothing is in the way (roofs) and by shadow
// rays elsewhere; it adds no unknowns, so facets = patches = elements = unknowns (at the default
// mesh of a city of thousands of facets); and light reflected upwards leaves the scene
// (SolveReport::escaped_power) as under a real sky. An emitting polygon would instead be cut
// into patches by the mesh, add every one of them to each element's form-factor row (the rows'
// bound is hemisphere_rays + emitting patches) and absorb what a real sky lets escape.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <radiosity/radiosity.hpp>

#include "core/rng.hpp"  // src/ is on the benchmarks' and the tests' include paths

namespace bench {

inline constexpr double kCityBlock = 60.0;   ///< side of a block, m
inline constexpr double kCityStreet = 12.0;  ///< width of a street, m
inline constexpr double kCityMargin = 2.0;   ///< a building's least distance from its lot's edges, m
inline constexpr float kCitySkyIrradiance = 100.0f;  ///< W/m^2 on open ground (an overcast day)

/// What city() builds. Every field has a default.
struct CityOptions {
  int blocks = 3;            ///< blocks along each side (n x n), >= 1
  double facet_size = 2.25;  ///< longest edge of a facet, m, > 0
  std::uint64_t seed = 1;    ///< the buildings' lots, footprints and heights
};

/// One building: the box [lower, upper] (lower.y = 0, on the ground) and its facets, the
/// polygons first .. first + count - 1 of the scene (walls, then the roof).
struct CityBuilding {
  glm::vec3 lower{0.0f};
  glm::vec3 upper{0.0f};
  radiosity::PolygonId first = 0;
  std::uint32_t count = 0;
};

/// A city and what it is made of. Thread safety: a plain value.
struct City {
  radiosity::Scene scene;
  std::vector<CityBuilding> buildings;
  double size = 0.0;  ///< the city's width in x and z, m (the ground is [0, size]^2 at y = 0)
  /// Facets per group: "ground" (the blocks' ground that is not under a building),
  /// "under_buildings" (the blocks' ground facets that lie wholly under a building: hidden, they
  /// receive no light), "streets", "walls", "roofs". The ground's three groups are the scene's
  /// first ground_facets + hidden_facets + street_facets polygons, the buildings' follow.
  std::size_t ground_facets = 0, hidden_facets = 0, street_facets = 0, wall_facets = 0, roof_facets = 0;
  std::size_t facets() const { return ground_facets + hidden_facets + street_facets + wall_facets + roof_facets; }
};

/// Equal pieces of at most `facet_size` that a length is cut into: ceil(length / facet_size),
/// at least 1 (a length a hair over a whole number of facets is not given a sliver).
inline int city_cells(double length, double facet_size) {
  return std::max(1, static_cast<int>(std::ceil(length / facet_size - 1e-6)));
}

namespace city_detail {

/// A random stream per block, keyed by the seed and the block's place, so a block is the same
/// in every city that has it (a larger city contains the smaller ones). SplitMix64 steps (the
/// library's mix64) give the same numbers on every platform, unlike the standard distributions.
class BlockRandom {
 public:
  BlockRandom(std::uint64_t seed, int i, int j) : state_(mix(mix(seed) ^ mix(key(i, j)))) {}
  /// Uniform in [a, b).
  double uniform(double a, double b) {
    state_ = mix(state_);
    return a + (b - a) * static_cast<double>(state_ >> 11) * 0x1.0p-53;
  }

 private:
  static std::uint64_t mix(std::uint64_t z) { return radiosity::detail::mix64(z); }
  static std::uint64_t key(int i, int j) {
    return 0x100000000ull * static_cast<std::uint64_t>(i) + static_cast<std::uint64_t>(j);
  }
  std::uint64_t state_;
};

/// Point k of n equal steps from a to b; exactly a at k = 0 and b at k = n, so neighbouring
/// lattices that share an edge share its corners bit for bit.
inline float lerp(float a, float b, int k, int n) {
  const float t = static_cast<float>(k) / static_cast<float>(n);
  return (1.0f - t) * a + t * b;
}

/// Adds the nu x nv facets of a lattice, facet (i, j) with corners at(i, j), at(i + 1, j),
/// at(i + 1, j + 1), at(i, j + 1), in group group(i, j): it faces (at(1, 0) - at(0, 0)) x
/// (at(0, 1) - at(0, 0)).
template <class At, class Group>
void add_lattice(radiosity::Scene& scene, int nu, int nv, At at, radiosity::MaterialId material, Group group) {
  std::vector<glm::vec3> quad(4);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      quad[0] = at(i, j);
      quad[1] = at(i + 1, j);
      quad[2] = at(i + 1, j + 1);
      quad[3] = at(i, j + 1);
      scene.add_polygon(quad, material, group(i, j));
    }
}

/// A lattice's group when all its facets are in one.
inline auto whole(std::string_view group) {
  return [group](int, int) { return group; };
}

}  // namespace city_detail

/// Builds the city of `options` (see the top of this file). Deterministic: the same options give
/// the same scene, polygon for polygon, bit for bit. Throws radiosity::Error{invalid_argument}
/// for blocks < 1 or a facet size that is not finite and > 0.
/// Thread safety: may be called concurrently.
inline City city(const CityOptions& options = {}) {
  namespace rad = radiosity;
  using city_detail::lerp;
  const int n = options.blocks;
  const double s = options.facet_size;
  if (n < 1) throw rad::Error(rad::ErrorCode::invalid_argument, "CityOptions::blocks must be >= 1");
  if (!(s > 0.0) || !std::isfinite(s))
    throw rad::Error(rad::ErrorCode::invalid_argument, "CityOptions::facet_size must be finite and > 0");

  City c;
  rad::Scene& scene = c.scene;
  auto material = [&](const char* name, rad::Rgb reflectance) {
    rad::Material m;
    m.name = name;
    m.reflectance = reflectance;
    return scene.add_material(m);
  };
  const rad::MaterialId street = material("asphalt", rad::Rgb(0.12f, 0.12f, 0.13f));
  const rad::MaterialId pavement = material("pavement", rad::Rgb(0.32f, 0.31f, 0.29f));
  const rad::MaterialId wall = material("facade", rad::Rgb(0.45f, 0.40f, 0.35f));
  const rad::MaterialId roof = material("roof", rad::Rgb(0.20f, 0.20f, 0.22f));

  // The strips along each axis: edge[k] to edge[k + 1], streets at even k, blocks at odd k.
  std::vector<float> edge(2 * static_cast<std::size_t>(n) + 2);
  for (std::size_t k = 0; k < edge.size(); ++k)
    edge[k] = static_cast<float>(static_cast<double>((k + 1) / 2) * kCityStreet +
                                 static_cast<double>(k / 2) * kCityBlock);
  c.size = static_cast<double>(edge.back());

  // Buildings, block by block: 1 or 2 lots along each axis, a box in each lot. Block (i, j)'s
  // are c.buildings[block_first[i n + j]] up to the next block's.
  std::vector<std::size_t> block_first;
  for (int bi = 0; bi < n; ++bi)
    for (int bj = 0; bj < n; ++bj) {
      block_first.push_back(c.buildings.size());
      city_detail::BlockRandom random(options.seed, bi, bj);
      const int lots_x = random.uniform(0.0, 1.0) < 0.5 ? 1 : 2, lots_z = random.uniform(0.0, 1.0) < 0.5 ? 1 : 2;
      const double block_x = edge[2 * static_cast<std::size_t>(bi) + 1];
      const double block_z = edge[2 * static_cast<std::size_t>(bj) + 1];
      for (int li = 0; li < lots_x; ++li)
        for (int lj = 0; lj < lots_z; ++lj) {
          // A footprint of 55-90 % of the lot's room inside its margins, placed anywhere in it.
          auto span = [&](double lot_start, int lots, double& lo, double& hi) {
            const double lot = kCityBlock / lots, room = lot - 2.0 * kCityMargin;
            const double width = room * random.uniform(0.55, 0.9);
            lo = lot_start + kCityMargin + (room - width) * random.uniform(0.0, 1.0);
            hi = lo + width;
          };
          double x0 = 0, x1 = 0, z0 = 0, z1 = 0;
          span(block_x + li * kCityBlock / lots_x, lots_x, x0, x1);
          span(block_z + lj * kCityBlock / lots_z, lots_z, z0, z1);
          const double height = random.uniform(0.0, 1.0) < 0.1 ? random.uniform(30.0, 60.0) : random.uniform(6.0, 30.0);
          CityBuilding b;
          b.lower = glm::vec3(static_cast<float>(x0), 0.0f, static_cast<float>(z0));
          b.upper = glm::vec3(static_cast<float>(x1), static_cast<float>(height), static_cast<float>(z1));
          c.buildings.push_back(b);
        }
    }
  block_first.push_back(c.buildings.size());

  // Ground: each rectangle of strips a lattice facing up (+z x +x = +y); a block's facets that
  // lie wholly under a building are its ground too, in a group of their own.
  for (std::size_t a = 0; a + 1 < edge.size(); ++a)
    for (std::size_t b = 0; b + 1 < edge.size(); ++b) {
      const float x0 = edge[a], x1 = edge[a + 1], z0 = edge[b], z1 = edge[b + 1];
      const int nx = city_cells(x1 - x0, s), nz = city_cells(z1 - z0, s);
      auto at = [&](int i, int j) { return glm::vec3(lerp(x0, x1, j, nx), 0.0f, lerp(z0, z1, i, nz)); };
      if (a % 2 == 0 || b % 2 == 0) {
        city_detail::add_lattice(scene, nz, nx, at, street, city_detail::whole("streets"));
        c.street_facets += static_cast<std::size_t>(nx) * static_cast<std::size_t>(nz);
        continue;
      }
      const std::size_t block = a / 2 * static_cast<std::size_t>(n) + b / 2;
      city_detail::add_lattice(scene, nz, nx, at, pavement, [&](int i, int j) {
        const glm::vec3 lo = at(i, j), hi = at(i + 1, j + 1);
        for (std::size_t k = block_first[block]; k < block_first[block + 1]; ++k) {
          const CityBuilding& under = c.buildings[k];
          if (under.lower.x <= lo.x && hi.x <= under.upper.x && under.lower.z <= lo.z && hi.z <= under.upper.z) {
            ++c.hidden_facets;
            return std::string_view("under_buildings");
          }
        }
        ++c.ground_facets;
        return std::string_view("ground");
      });
    }

  // The buildings' walls and roofs.
  for (CityBuilding& b : c.buildings) {
    b.first = static_cast<rad::PolygonId>(scene.polygons().size());
    const glm::vec3 lo = b.lower, hi = b.upper;
    const int nx = city_cells(hi.x - lo.x, s), ny = city_cells(hi.y, s), nz = city_cells(hi.z - lo.z, s);
    auto x = [&](int k) { return lerp(lo.x, hi.x, k, nx); };
    auto y = [&](int k) { return lerp(0.0f, hi.y, k, ny); };
    auto z = [&](int k) { return lerp(lo.z, hi.z, k, nz); };
    // Walls facing -z, +z, -x, +x and the roof facing +y (first direction x second).
    const auto walls = city_detail::whole("walls");
    city_detail::add_lattice(scene, ny, nx, [&](int i, int j) { return glm::vec3(x(j), y(i), lo.z); }, wall, walls);
    city_detail::add_lattice(scene, nx, ny, [&](int i, int j) { return glm::vec3(x(i), y(j), hi.z); }, wall, walls);
    city_detail::add_lattice(scene, nz, ny, [&](int i, int j) { return glm::vec3(lo.x, y(j), z(i)); }, wall, walls);
    city_detail::add_lattice(scene, ny, nz, [&](int i, int j) { return glm::vec3(hi.x, y(i), z(j)); }, wall, walls);
    city_detail::add_lattice(scene, nz, nx, [&](int i, int j) { return glm::vec3(x(j), hi.y, z(i)); }, roof,
                             city_detail::whole("roofs"));
    const std::size_t wall_facets = 2 * static_cast<std::size_t>(nx + nz) * static_cast<std::size_t>(ny);
    const std::size_t roof_facets = static_cast<std::size_t>(nx) * static_cast<std::size_t>(nz);
    c.wall_facets += wall_facets;
    c.roof_facets += roof_facets;
    b.count = static_cast<std::uint32_t>(wall_facets + roof_facets);
  }

  rad::Light sky;
  sky.type = rad::LightType::sky;
  sky.name = "sky";
  sky.sky = rad::SkyModel::uniform;
  sky.intensity = kCitySkyIrradiance;
  scene.add_light(sky);

  // Looking at the centre from above one corner.
  const float size = static_cast<float>(c.size);
  rad::Camera camera;
  camera.eye = glm::vec3(-0.25f * size, 0.6f * size, -0.25f * size);
  camera.look_at = glm::vec3(0.5f * size, 0.0f, 0.5f * size);
  camera.fov_deg = 50.0f;
  scene.set_camera(camera);
  return c;
}

}  // namespace bench
