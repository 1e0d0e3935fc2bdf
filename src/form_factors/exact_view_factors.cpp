// Exact polygon-to-polygon view factors, obstructed or not, without rays: the exact mode of
// view_factor_matrix() (docs/VIEW_FACTORS.md).
// Based on:
//   G. N. Walton, "Calculation of obstructed view factors by adaptive integration", NISTIR 6925,
//     National Institute of Standards and Technology, 2002 (View3D): each pair once, with a
//     cost chosen by the pair's relative separation (double area integration when far, single
//     area integration with the exact point-to-polygon factor when near), and obstructed views
//     integrated over the source with each point's view of the receiver clipped by the
//     shadows of the obstructions projected from that point.
//   J. H. Lambert, Photometria (1760); D. R. Baum, H. E. Rushmeier & J. M. Winget, "Improving
//     radiosity solutions through the use of analytically determined form-factors", SIGGRAPH
//     1989, eq. 2 (the point-to-polygon contour integral, point_to_polygon.cpp).
//   I. E. Sutherland & G. W. Hodgman, "Reentrant polygon clipping", CACM 17(1), 1974 (clipping
//     a convex polygon by planes).
//   E. Haines & J. Wallace, "Shaft culling for efficient ray-traced radiosity", Eurographics
//     Workshop on Rendering 1991 (which polygons may come between a pair; shaft.hpp).
//   J. R. Howell, M. P. Menguc & R. Siegel, "Thermal Radiation Heat Transfer", 6th ed., 2016,
//     ch. 4 (reciprocity A_i F_ij = A_j F_ji, so one integral gives both directions).
//
// G_ij = A_i F_ij = integral over the source s of F(dx -> visible part of r) dx, where s is the
// smaller of the two (ties: the lower index), so (i, j) and (j, i) give the same number:
//   - nothing can come between them (the shaft of the pair meets no polygon that can hide
//     anything): far apart (relative separation d / (r_i + r_j) above kFarSeparation, each
//     wholly in front of the other), the point-to-point kernel cos cos / (pi d^2) by 2x2 Gauss
//     points on both; nearer, the exact point-to-polygon factor at Gauss points of the source,
//     refined adaptively where two levels disagree (shared edges);
//   - otherwise, 0 when one candidate occluder crosses every segment between their corners;
//     else at each source point the receiver (clipped to the point's hemisphere) loses the
//     shadow of each candidate occluder: the occluder is clipped to the slab between the point
//     and the receiver's plane, and the receiver is split by the planes through the point and
//     the occluder's edges (the shadow's cone); the contour integral of the pieces left is the
//     visible point factor, integrated adaptively over the source (and at least to 1/4 of its
//     width along an edge that lies on an occluder, where a thin shadow wedge starts).
// A polygon can hide something only if some corner of the scene lies strictly on each side of
// its plane: the walls of a closed room cannot, and are no candidates at all. Coplanar
// occluders whose union is convex are merged into one (fewer, larger shadows to clip).
#include "form_factors/exact_view_factors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <tuple>

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include "core/union_find.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/sampling.hpp"
#include "form_factors/shaft.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity::detail {

namespace {

constexpr double kInversePi = 0.31830988618379067;
/// Absolute accuracy goal of a factor from the source (mean over the source of the point
/// factor): two levels of the adaptive rule closer than this (weighted by their share of the
/// source) end the refinement.
constexpr double kTolerance = 1e-6;
constexpr int kMaxDepthClear = 5, kMaxDepthObstructed = 6;
/// Depth to which an obstructed source is refined along an edge that lies in an occluder's
/// plane (squares of 1/4 of its width along the edge, each with 2x2 Gauss points in each
/// quarter; 1/8 gave the same rows in the benchmark room at twice the extra cost).
constexpr int kSideDepth = 2;
/// Above this relative separation d / (r_i + r_j) (centroid distance over the sum of the
/// polygons' radii) an unobstructed pair, each wholly in front of the other, takes the 2x2 x 2x2
/// Gauss rule of the point-to-point kernel (its relative error falls as the separation^-4).
constexpr float kFarSeparation = 4.0f;
constexpr std::uint32_t kNoOccluder = 0xffffffffu;
/// A visible point factor below this is rounding (slivers left along a shadow's edges).
constexpr double kSliver = 1e-12;
/// Occluders per cluster of the candidates' sphere test.
constexpr std::size_t kClusterSize = 8;

/// A polygon's triangle or quad as a map of the unit square, with its area.
struct Cell {
  CellMap map;
  double area = 0.0;
};

struct Face {
  std::vector<glm::vec3> corners;
  glm::vec3 normal{0.0f};
  glm::dvec3 dnormal{0.0};
  double offset = 0.0;  ///< dot(normal, corner 0), in double
  glm::vec3 centroid{0.0f};
  float radius = 0.0f;  ///< largest distance from the centroid to a corner
  double area = 0.0;
  std::vector<Cell> cells;
  /// 2x2 Gauss points of every cell, with their area weights (they sum to the area).
  std::vector<glm::vec3> gauss;
  std::vector<double> weight;
};

struct Sphere {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

/// A convex polygon that can hide something: one facet, or coplanar facets whose union is
/// convex (a block's face cut into facets), merged.
struct Occluder {
  std::vector<glm::vec3> corners;
  glm::vec3 normal{0.0f};
  float offset = 0.0f;  ///< dot(normal, corner 0)
  Sphere sphere;
  glm::vec3 lower{0.0f}, upper{0.0f};  ///< bounding box
  std::uint32_t first_facet = 0;  ///< Impl::facets[first_facet, first_facet + facet_count) are its polygons
  std::uint32_t facet_count = 0;
};

/// A group of nearby occluders: occluders[first, first + count) and their bounding sphere.
struct Cluster {
  Sphere sphere;
  std::uint32_t first = 0, count = 0;
};

/// A convex solid bounded by occluders (a block: its faces, closed, or open where it stands on
/// a floor or where nothing lies beyond; find_solids()): the points behind all its planes.
struct Solid {
  std::vector<glm::dvec3> normals;  ///< outward unit normals
  std::vector<double> offsets;      ///< inside where dot(normal, x) < offset
};
constexpr std::uint32_t kNoSolid = 0xffffffffu;
/// The most occluders a solid may have: its convexity test takes every corner against every
/// plane, and a finely tessellated dome of 100 000 triangles would take minutes. A block or a
/// building has 5 or 6 (its faces' facets merge into one occluder per face).
constexpr std::size_t kMaxSolidFaces = 256;

/// The cell of `v` on a grid of side `grid`: corners that coincide but for rounding fall in one
/// cell unless they straddle a grid line (what would join them then stays apart).
std::array<std::int64_t, 3> grid_key(const glm::vec3& v, double grid) {
  return {static_cast<std::int64_t>(std::floor(v.x / grid)), static_cast<std::int64_t>(std::floor(v.y / grid)),
          static_cast<std::int64_t>(std::floor(v.z / grid))};
}

/// A convex polygon in the receiver's plane (corners relative to the source point): its first
/// corner and corner count in a workspace's corners.
using Piece = std::pair<std::uint32_t, std::uint32_t>;

/// Distance from `p` to the segment [a, a + ab] (len2 = |ab|^2 > 0).
float distance_to_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& ab, float len2) {
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

/// Sutherland-Hodgman: the part of convex polygon in[0, n) where dot(m, p) + c >= 0 (sign +1)
/// or <= 0 (sign -1), appended to `out`; returns its corner count. The crossing point is
/// interpolated from the kept end, so both sides of a split share it bit for bit.
int clip(const glm::dvec3* in, int n, const glm::dvec3& m, double c, double sign, std::vector<glm::dvec3>& out) {
  const std::size_t start = out.size();
  for (int i = 0; i < n; ++i) {
    const glm::dvec3& a = in[i];
    const glm::dvec3& b = in[(i + 1) % n];
    const double da = glm::dot(m, a) + c, db = glm::dot(m, b) + c;
    const bool ka = sign * da >= 0.0, kb = sign * db >= 0.0;
    if (ka) out.push_back(a);
    if (ka != kb) {
      // From the end with da > 0 (the same end for either sign), so the point is shared.
      const glm::dvec3& p = da > 0.0 ? a : b;
      const glm::dvec3& q = da > 0.0 ? b : a;
      const double dp = da > 0.0 ? da : db, dq = da > 0.0 ? db : da;
      out.push_back(p + (dp / (dp - dq)) * (q - p));
    }
  }
  const int count = static_cast<int>(out.size() - start);
  if (count < 3) out.resize(start);
  return count < 3 ? 0 : count;
}

/// The planes through the origin and each edge of convex polygon p[0, n) (which does not
/// contain the origin), normals pointing into the cone it spans, into `out`. False when the
/// polygon is edge-on from the origin (no cone).
bool inward_planes(const glm::dvec3* p, int n, std::vector<glm::dvec3>& out) {
  glm::dvec3 centre(0.0);
  for (int i = 0; i < n; ++i) centre += p[i];
  const std::size_t start = out.size();
  double orientation = 0.0;
  for (int i = 0; i < n; ++i) {
    out.push_back(glm::cross(p[i], p[(i + 1) % n]));
    orientation += glm::dot(out.back(), centre);
  }
  if (!(std::fabs(orientation) > 0.0)) {
    out.resize(start);
    return false;
  }
  if (orientation < 0.0)
    for (std::size_t i = start; i < out.size(); ++i) out[i] = -out[i];
  return true;
}

}  // namespace

struct ExactPolygonTransport::Impl {
  std::vector<Face> faces;
  float epsilon = 0.0f;
  std::vector<Occluder> occluders;  ///< by cluster
  std::vector<std::uint32_t> facets;  ///< the occluders' polygons
  std::vector<std::uint32_t> owner;   ///< per polygon: the occluder it is part of, or kNoOccluder
  std::vector<Cluster> clusters;
  std::vector<Solid> solids;
  std::vector<std::uint32_t> solid_of;  ///< per occluder: the solid it bounds, or kNoSolid

  void merge_occluders(std::vector<std::uint32_t> hiding);
  void find_solids(const Bounds& box);

  void add_cluster(std::uint32_t begin, std::uint32_t end);
  void candidates(std::uint32_t s, std::uint32_t r, std::vector<std::uint32_t>& out) const;
  double unobstructed(const Face& S, const Face& R, Workspace& w) const;
  bool hidden_by_one(const Face& S, const Face& R, const std::vector<std::uint32_t>& candidates) const;
  bool hidden_by_solid(const Face& S, const Face& R, const std::vector<std::uint32_t>& candidates) const;
  double visible_factor(const glm::vec3& point, const Face& S, const Face& R, Workspace& w) const;
  template <typename PointFactor, typename Forced>
  double integrate(const Face& S, const PointFactor& g, int max_depth, const Forced& forced) const;
};

// The integral over the source S of g(x) (a point factor): per cell, its area times the mean of
// g over the cell by the adaptive Gauss rule, starting from the face's own 2x2 points. A cell's
// side for which forced(a, b) holds (a and b its ends) is refined down to kSideDepth.
template <typename PointFactor, typename Forced>
double ExactPolygonTransport::Impl::integrate(const Face& S, const PointFactor& g, int max_depth,
                                              const Forced& forced) const {
  double total = 0.0;
  for (std::size_t c = 0; c < S.cells.size(); ++c) {
    const Cell& cell = S.cells[c];
    double coarse = 0.0;
    for (std::size_t k = 0; k < 4; ++k) coarse += S.weight[4 * c + k] * g(S.gauss[4 * c + k]);
    coarse /= cell.area;
    const glm::vec3 corner[4] = {cell.map.point(glm::vec2(0.0f, 0.0f)), cell.map.point(glm::vec2(1.0f, 0.0f)),
                                 cell.map.point(glm::vec2(1.0f, 1.0f)), cell.map.point(glm::vec2(0.0f, 1.0f))};
    unsigned sides = 0;
    for (unsigned k = 0; k < 4; ++k)
      if (forced(corner[k], corner[(k + 1) % 4])) sides |= 1u << k;
    auto at = [&](glm::vec2 st) { return static_cast<double>(cell.map.density(st)) * g(cell.map.point(st)); };
    total += cell.area * adaptive_gauss_mean(at, glm::vec2(0.0f), 1.0f, coarse, 0, max_depth, kTolerance, sides,
                                                 sides ? kSideDepth : 0);
  }
  return total;
}

void ExactPolygonTransport::Impl::add_cluster(std::uint32_t begin, std::uint32_t end) {
  glm::vec3 lo = occluders[begin].sphere.centre, hi = lo;
  for (std::uint32_t k = begin; k < end; ++k) {
    const Sphere& s = occluders[k].sphere;
    lo = glm::min(lo, s.centre - glm::vec3(s.radius));
    hi = glm::max(hi, s.centre + glm::vec3(s.radius));
  }
  if (end - begin <= kClusterSize) {
    Cluster c;
    c.sphere.centre = 0.5f * (lo + hi);
    for (std::uint32_t k = begin; k < end; ++k)
      c.sphere.radius = std::max(c.sphere.radius, glm::length(occluders[k].sphere.centre - c.sphere.centre) +
                                                      occluders[k].sphere.radius);
    c.first = begin;
    c.count = end - begin;
    clusters.push_back(c);
    return;
  }
  // Median split along the longest axis of the box (ties by first polygon: deterministic).
  const glm::vec3 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(occluders.begin() + begin, occluders.begin() + mid, occluders.begin() + end,
                   [&](const Occluder& x, const Occluder& y) {
                     const float cx = x.sphere.centre[axis], cy = y.sphere.centre[axis];
                     return cx < cy || (cx == cy && facets[x.first_facet] < facets[y.first_facet]);
                   });
  add_cluster(begin, mid);
  add_cluster(mid, end);
}

// The polygons `hiding` (those that can hide something) as occluders: grouped by plane (either
// facing), a group whose corners' convex hull has the group's total area is one convex polygon
// (the union of facets that do not overlap fills its hull only when it is that hull); other
// groups stay facet by facet. Fewer, larger occluders make fewer shadows to clip.
void ExactPolygonTransport::Impl::merge_occluders(std::vector<std::uint32_t> hiding) {
  // The plane's normal made canonical (its first component beyond rounding noise positive), its
  // offset, and direction_key() of the normal (quantised to 2^-12): the facets of one turned
  // face (a Cornell block's side cut into facets) have normals that differ in their last bits,
  // so planes are told apart by that key and then by offsets within epsilon. (Grouped by the
  // exact normal, the closed Cornell box's 686 block facets made 627 occluders instead of 10,
  // and its exact rows took longer than View3D's.) A face whose facets straddle a quantisation
  // step merely stays in two parts, each merged or facet by facet.
  struct Plane {
    glm::vec3 normal;
    float offset;
    std::array<std::int64_t, 3> key;
  };
  auto plane_of = [&](std::uint32_t p) {
    glm::vec3 n = faces[p].normal;
    const float lead = std::fabs(n.x) > 1e-3f ? n.x : (std::fabs(n.y) > 1e-3f ? n.y : n.z);
    if (lead < 0.0f) n = -n;
    return Plane{n, glm::dot(n, faces[p].corners[0]), direction_key(n)};
  };
  // Each polygon's plane once, then sorted with it (by key, offset and id).
  std::vector<std::pair<Plane, std::uint32_t>> planes;
  planes.reserve(hiding.size());
  for (const std::uint32_t p : hiding) planes.emplace_back(plane_of(p), p);
  std::sort(planes.begin(), planes.end(), [](const auto& x, const auto& y) {
    if (x.first.key != y.first.key) return x.first.key < y.first.key;
    if (x.first.offset != y.first.offset) return x.first.offset < y.first.offset;
    return x.second < y.second;
  });
  for (std::size_t k = 0; k < planes.size(); ++k) hiding[k] = planes[k].second;
  auto add = [&](const std::vector<glm::vec3>& corners, glm::vec3 normal, const std::uint32_t* members,
                 std::size_t count) {
    Occluder o;
    o.corners = corners;
    o.normal = normal;
    o.offset = glm::dot(normal, corners[0]);
    glm::vec3 centre(0.0f);
    for (const glm::vec3& v : corners) centre += v;
    o.sphere.centre = centre / static_cast<float>(corners.size());
    o.lower = o.upper = corners[0];
    for (const glm::vec3& v : corners) {
      o.sphere.radius = std::max(o.sphere.radius, glm::length(v - o.sphere.centre));
      o.lower = glm::min(o.lower, v);
      o.upper = glm::max(o.upper, v);
    }
    o.first_facet = static_cast<std::uint32_t>(facets.size());
    o.facet_count = static_cast<std::uint32_t>(count);
    facets.insert(facets.end(), members, members + count);
    occluders.push_back(std::move(o));
  };
  // Reorders hiding[begin, end) into the parts that shared corners connect, in the order of
  // each part's first facet (the facets within a part keep their order), and writes each
  // part's end into `ends`; returns the number of parts.
  std::vector<std::size_t> part_ends;
  std::vector<std::uint32_t> part_parent, part_order;
  std::vector<std::pair<std::array<std::int64_t, 3>, std::uint32_t>> part_corners;
  auto connected_parts = [&](std::size_t begin, std::size_t end, std::vector<std::size_t>& ends) {
    const std::size_t n = end - begin;
    ends.clear();
    if (n == 1) {
      ends.push_back(end);
      return std::size_t{1};
    }
    const double grid = 64.0 * static_cast<double>(epsilon);
    part_corners.clear();
    for (std::size_t k = 0; k < n; ++k)
      for (const glm::vec3& v : faces[hiding[begin + k]].corners)
        part_corners.emplace_back(grid_key(v, grid), static_cast<std::uint32_t>(k));
    std::sort(part_corners.begin(), part_corners.end());
    make_sets(part_parent, n);
    for (std::size_t i = 1; i < part_corners.size(); ++i)
      if (part_corners[i].first == part_corners[i - 1].first)
        unite(part_parent, part_corners[i].second, part_corners[i - 1].second);  // root: the first facet
    auto find = [&](std::uint32_t x) { return find_root(part_parent, x); };
    part_order.resize(n);
    std::iota(part_order.begin(), part_order.end(), 0u);
    std::stable_sort(part_order.begin(), part_order.end(),
                     [&](std::uint32_t x, std::uint32_t y) { return find(x) < find(y); });
    std::vector<std::uint32_t> reordered(n);
    for (std::size_t k = 0; k < n; ++k) {
      reordered[k] = hiding[begin + part_order[k]];
      if (k + 1 == n || find(part_order[k + 1]) != find(part_order[k])) ends.push_back(begin + k + 1);
    }
    std::copy(reordered.begin(), reordered.end(), hiding.begin() + static_cast<std::ptrdiff_t>(begin));
    return ends.size();
  };
  std::vector<std::pair<glm::vec2, std::uint32_t>> points;
  std::vector<std::size_t> hull;
  std::size_t begin = 0;
  while (begin < hiding.size()) {
    const Plane& plane = planes[begin].first;
    std::size_t end = begin + 1;
    while (end < hiding.size()) {
      const Plane& next = planes[end].first;
      if (next.key != plane.key || std::fabs(next.offset - plane.offset) > epsilon) break;
      ++end;
    }
    // The group's facets in connected parts (facets that share a corner, compared on a grid
    // of 64 epsilon), each merged on its own: the walls of a row of buildings lie in one plane,
    // and the union of all of them, not convex, kept every facet of every wall an occluder of
    // its own (the exported city block, benchmarks/exported_block.py: 2 400 occluders for its
    // 16 buildings, 75 since session 43).
    const std::size_t parts = connected_parts(begin, end, part_ends);
    std::size_t cb = begin;
    for (std::size_t part = 0; part < parts; ++part) {
      const std::size_t ce = part_ends[part];
      bool merged = false;
      if (ce - cb > 1) {
        // Andrew's monotone chain over the group's corners in the plane's 2-D frame.
        const glm::vec3 n = plane.normal;
        const glm::vec3 t = glm::normalize(std::fabs(n.x) < 0.9f ? glm::cross(n, glm::vec3(1, 0, 0))
                                                                : glm::cross(n, glm::vec3(0, 1, 0)));
        const glm::vec3 b = glm::cross(n, t);
        points.clear();
        double total = 0.0;
        std::vector<glm::vec3> all;
        for (std::size_t k = cb; k < ce; ++k) {
          total += faces[hiding[k]].area;
          for (const glm::vec3& v : faces[hiding[k]].corners) {
            points.emplace_back(glm::vec2(glm::dot(v, t), glm::dot(v, b)), static_cast<std::uint32_t>(all.size()));
            all.push_back(v);
          }
        }
        std::sort(points.begin(), points.end(), [](const auto& x, const auto& y) {
          return x.first.x < y.first.x || (x.first.x == y.first.x && (x.first.y < y.first.y ||
                                                                      (x.first.y == y.first.y && x.second < y.second)));
        });
        auto turn = [&](std::size_t o, std::size_t a, std::size_t c) {
          const glm::vec2 u = points[a].first - points[o].first, v = points[c].first - points[o].first;
          return static_cast<double>(u.x) * v.y - static_cast<double>(u.y) * v.x;
        };
        hull.clear();
        for (int pass = 0; pass < 2; ++pass) {
          const std::size_t floor = hull.size();
          for (std::size_t k = 0; k < points.size(); ++k) {
            const std::size_t i = pass == 0 ? k : points.size() - 1 - k;
            while (hull.size() >= floor + 2 && turn(hull[hull.size() - 2], hull.back(), i) <= 0.0) hull.pop_back();
            hull.push_back(i);
          }
          hull.pop_back();
        }
        double area = 0.0;
        for (std::size_t k = 0; k < hull.size(); ++k) {
          const glm::vec2 p = points[hull[k]].first, q = points[hull[(k + 1) % hull.size()]].first;
          area += 0.5 * (static_cast<double>(p.x) * q.y - static_cast<double>(q.x) * p.y);
        }
        if (hull.size() >= 3 && std::fabs(area - total) <= 1e-5 * total) {
          std::vector<glm::vec3> corners;
          for (const std::size_t k : hull) corners.push_back(all[points[k].second]);
          add(corners, glm::cross(t, b), hiding.data() + cb, ce - cb);
          merged = true;
        }
      }
      if (!merged)
        for (std::size_t k = cb; k < ce; ++k) {
          const Face& f = faces[hiding[k]];
          add(f.corners, f.normal, hiding.data() + k, 1);
        }
      cb = ce;
    }
    begin = end;
  }
  add_cluster(0, static_cast<std::uint32_t>(occluders.size()));
  owner.assign(faces.size(), kNoOccluder);
  for (std::size_t k = 0; k < occluders.size(); ++k)
    for (std::uint32_t i = 0; i < occluders[k].facet_count; ++i)
      owner[facets[occluders[k].first_facet + i]] = static_cast<std::uint32_t>(k);
}

// The occluders that may come between source s and receiver r, in cluster order: the segment
// between the centroids, thickened by the larger radius, holds every segment between the two;
// a cluster or occluder whose sphere stays clear of it is out, and the rest meet the exact
// shaft test (or, for polygons of more than 4 corners, the two front half-spaces).
void ExactPolygonTransport::Impl::candidates(std::uint32_t s, std::uint32_t r, std::vector<std::uint32_t>& out) const {
  out.clear();
  const Face& S = faces[s];
  const Face& R = faces[r];
  const glm::vec3 a = S.centroid, ab = R.centroid - S.centroid;
  const float len2 = glm::dot(ab, ab), reach = std::max(S.radius, R.radius) + epsilon;
  // The pair's bounding box holds its shaft.
  glm::vec3 lower = S.corners[0], upper = lower;
  for (const glm::vec3& v : S.corners) lower = glm::min(lower, v), upper = glm::max(upper, v);
  for (const glm::vec3& v : R.corners) lower = glm::min(lower, v), upper = glm::max(upper, v);
  lower -= glm::vec3(epsilon);
  upper += glm::vec3(epsilon);
  for (const Cluster& c : clusters) {
    if (distance_to_segment(c.sphere.centre, a, ab, len2) > c.sphere.radius + reach) continue;
    for (std::uint32_t k = c.first; k < c.first + c.count; ++k) {
      if (k == owner[s] || k == owner[r]) continue;
      const Occluder& o = occluders[k];
      if (glm::any(glm::lessThan(o.upper, lower)) || glm::any(glm::greaterThan(o.lower, upper))) continue;
      if (distance_to_segment(o.sphere.centre, a, ab, len2) > o.sphere.radius + reach) continue;
      out.push_back(k);
    }
  }
  if (out.empty()) return;
  std::size_t kept = 0;
  if (S.corners.size() <= 4 && R.corners.size() <= 4) {
    Shaft shaft;
    if (!shaft.build(S.corners.data(), static_cast<int>(S.corners.size()), S.normal, R.corners.data(),
                     static_cast<int>(R.corners.size()), R.normal, epsilon)) {
      out.clear();
      return;
    }
    for (const std::uint32_t k : out) {
      const Occluder& O = occluders[k];
      if (!shaft.excludes_polygon(O.corners.data(), static_cast<int>(O.corners.size()), O.normal, O.offset))
        out[kept++] = k;
    }
  } else {
    for (const std::uint32_t k : out) {
      bool before_s = false, before_r = false;
      for (const glm::vec3& v : occluders[k].corners) {
        before_s |= glm::dot(v - S.corners[0], S.normal) > epsilon;
        before_r |= glm::dot(v - R.corners[0], R.normal) > epsilon;
      }
      if (before_s && before_r) out[kept++] = k;
    }
  }
  out.resize(kept);
}

// Whether one candidate occluder hides all of R from all of S: every segment between a corner
// of S and a corner of R crosses its interior. That is enough: for a point y, the points x whose
// segment to y meets a convex occluder form a convex set, so it holds all of S when it holds
// S's corners; and for each x, the points of R hidden from it form a convex set too.
bool ExactPolygonTransport::Impl::hidden_by_one(const Face& S, const Face& R,
                                                const std::vector<std::uint32_t>& candidates) const {
  for (const std::uint32_t k : candidates) {
    const Occluder& O = occluders[k];
    const std::size_t n = O.corners.size();
    bool hidden = true;
    for (std::size_t a = 0; a < S.corners.size() && hidden; ++a)
      for (std::size_t b = 0; b < R.corners.size() && hidden; ++b) {
        const glm::vec3 p = S.corners[a], q = R.corners[b];
        const float dp = glm::dot(O.normal, p) - O.offset, dq = glm::dot(O.normal, q) - O.offset;
        // Strictly through the plane, and strictly inside every edge where it crosses.
        if (!((dp > epsilon && dq < -epsilon) || (dp < -epsilon && dq > epsilon))) {
          hidden = false;
          break;
        }
        const glm::vec3 z = p + (dp / (dp - dq)) * (q - p);
        for (std::size_t e = 0; e < n && hidden; ++e) {
          const glm::vec3& u = O.corners[e];
          const glm::vec3 edge = O.corners[(e + 1) % n] - u;
          hidden = glm::dot(glm::cross(edge, z - u), O.normal) > epsilon * glm::length(edge);
        }
      }
    if (hidden) return true;
  }
  return false;
}

// The occluders that bound convex solids (solids, solid_of). Occluders that share edges (both
// ends within a few epsilon: corners are compared on a grid of 64 epsilon, so a pair that
// straddles a grid line merely leaves its solid unfound) are joined; a joined set is a solid
// when every edge is shared by two of its occluders, or the edges shared by none make loops
// each in one plane (a block standing on a floor has no bottom), of which all planes but one
// are sealed (nothing of the scene beyond them), and every corner of the set lies behind-or-on
// each occluder's plane and those planes (all of them supporting planes of the corners' convex
// hull, the set's centroid strictly behind each). Then the occluders with the openings cover
// the hull's boundary, and a segment between two points outside the hull that passes through
// its interior crosses the boundary twice, in two planes, neither of them a sealed one (an end
// would lie beyond it), so at most once in an opening: it meets an occluder.
void ExactPolygonTransport::Impl::find_solids(const Bounds& box) {
  solid_of.assign(occluders.size(), kNoSolid);
  const double grid = 64.0 * static_cast<double>(epsilon);
  using Key = std::array<std::int64_t, 3>;
  auto key = [&](const glm::vec3& v) { return grid_key(v, grid); };
  // Every occluder edge by its two ends' keys (the smaller first), sorted to find equal edges.
  struct Edge {
    Key a, b;
    std::uint32_t occluder;
    glm::vec3 p, q;  ///< its ends
  };
  std::vector<Edge> edges;
  std::vector<glm::vec3> c;
  for (std::size_t k = 0; k < occluders.size(); ++k) {
    // The corners without those within epsilon of the line through their neighbours: a merged
    // face's hull keeps the facets' corners along its sides where rounding turns them outward
    // (a turned block's top, 10 corners), while the side beside it has one edge there.
    c = occluders[k].corners;
    for (bool dropped = true; dropped && c.size() > 3;) {
      dropped = false;
      for (std::size_t i = 0; i < c.size() && c.size() > 3; ++i) {
        const glm::vec3& a = c[(i + c.size() - 1) % c.size()];
        const glm::vec3 ab = c[(i + 1) % c.size()] - a;
        if (distance_to_segment(c[i], a, ab, glm::dot(ab, ab)) <= epsilon) {
          c.erase(c.begin() + static_cast<std::ptrdiff_t>(i));
          dropped = true;
        }
      }
    }
    for (std::size_t e = 0; e < c.size(); ++e) {
      Key a = key(c[e]), b = key(c[(e + 1) % c.size()]);
      if (a == b) continue;
      if (b < a) std::swap(a, b);
      edges.push_back({a, b, static_cast<std::uint32_t>(k), c[e], c[(e + 1) % c.size()]});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return std::tie(x.a, x.b, x.occluder) < std::tie(y.a, y.b, y.occluder);
  });
  std::vector<std::uint32_t> parent;
  make_sets(parent, occluders.size());
  auto find = [&](std::uint32_t x) { return find_root(parent, x); };
  // Per edge: how many occluders share it (2 joins them; 3 or more spoils the set).
  std::vector<std::uint8_t> spoilt(occluders.size(), 0);
  std::vector<const Edge*> open;  // the edges no other occluder shares
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 1) open.push_back(&edges[i]);
    else if (j - i == 2) unite(parent, edges[i].occluder, edges[i + 1].occluder);
    else
      for (std::size_t k = i; k < j; ++k) spoilt[edges[k].occluder] = 1;
    i = j;
  }
  std::vector<std::vector<std::uint32_t>> members(occluders.size());
  for (std::uint32_t k = 0; k < occluders.size(); ++k) members[find(k)].push_back(k);
  std::vector<std::vector<const Edge*>> open_of(occluders.size());
  for (const Edge* e : open) open_of[find(e->occluder)].push_back(e);
  const double eps = epsilon;
  for (std::uint32_t root = 0; root < occluders.size(); ++root) {
    const std::vector<std::uint32_t>& set = members[root];
    if (set.size() < 3 || set.size() > kMaxSolidFaces) continue;
    bool ok = true;
    glm::dvec3 centre(0.0);
    std::size_t count = 0;
    for (const std::uint32_t k : set) {
      ok = ok && !spoilt[k];
      for (const glm::vec3& v : occluders[k].corners) centre += glm::dvec3(v), ++count;
    }
    if (!ok) continue;
    centre /= static_cast<double>(count);
    Solid solid;
    auto add_plane = [&](glm::dvec3 n, double offset) {
      const double side = glm::dot(n, centre) - offset;
      if (!(std::fabs(side) > eps)) return false;  // the centre on the plane: flat, no inside
      if (side > 0.0) n = -n, offset = -offset;
      for (const std::uint32_t k : set)
        for (const glm::vec3& v : occluders[k].corners)
          if (glm::dot(n, glm::dvec3(v)) - offset > eps) return false;  // a corner in front: not convex
      solid.normals.push_back(n);
      solid.offsets.push_back(offset);
      return true;
    };
    for (const std::uint32_t k : set) {
      const glm::dvec3 n = glm::normalize(glm::dvec3(occluders[k].normal));
      ok = ok && add_plane(n, glm::dot(n, glm::dvec3(occluders[k].corners[0])));
    }
    // The open edges in loops (joined by their ends), each loop in one plane. Of those planes
    // all but one must be sealed, with no corner of the scene (by its box) strictly beyond:
    // no segment between two of the scene's points can cross such an opening (the ground
    // under a building; the roof plane of the tallest one, whose roof hides nothing above and
    // is no occluder).
    const std::vector<const Edge*>& boundary = open_of[root];
    std::vector<std::uint32_t> loop;
    make_sets(loop, boundary.size());
    auto loop_of = [&](std::uint32_t x) { return find_root(loop, x); };
    for (std::size_t i = 0; i < boundary.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (boundary[i]->a == boundary[j]->a || boundary[i]->a == boundary[j]->b || boundary[i]->b == boundary[j]->a ||
            boundary[i]->b == boundary[j]->b)
          unite(loop, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
    int unsealed = 0;
    std::vector<std::pair<glm::dvec3, double>> openings;  // outward normal, offset
    for (std::uint32_t first = 0; ok && first < boundary.size(); ++first) {
      if (loop_of(first) != first) continue;
      // The loop's plane: through its first end, spanned by the farthest end and the end
      // farthest from that line; every end on it.
      std::vector<glm::dvec3> ends;
      for (std::uint32_t i = 0; i < boundary.size(); ++i)
        if (loop_of(i) == first) {
          ends.emplace_back(boundary[i]->p);
          ends.emplace_back(boundary[i]->q);
        }
      const glm::dvec3 p0 = ends[0];
      glm::dvec3 p1 = p0;
      for (const glm::dvec3& p : ends)
        if (glm::length(p - p0) > glm::length(p1 - p0)) p1 = p;
      glm::dvec3 n(0.0);
      for (const glm::dvec3& p : ends) {
        const glm::dvec3 span = glm::cross(p1 - p0, p - p0);
        if (glm::length(span) > glm::length(n)) n = span;
      }
      ok = glm::length(n) > eps * glm::length(p1 - p0);
      if (!ok) break;
      n = glm::normalize(n);
      double offset = glm::dot(n, p0);
      for (const glm::dvec3& p : ends) ok = ok && std::fabs(glm::dot(n, p) - offset) <= eps;
      if (glm::dot(n, centre) > offset) n = -n, offset = -offset;
      bool seen = false;
      for (const auto& o : openings)
        seen = seen || (glm::dot(o.first, n) > 1.0 - 1e-9 && std::fabs(o.second - offset) <= eps);
      if (!ok || seen) continue;
      openings.emplace_back(n, offset);
      ok = add_plane(n, offset);
      const glm::dvec3 far(n.x > 0.0 ? box.upper.x : box.lower.x, n.y > 0.0 ? box.upper.y : box.lower.y,
                           n.z > 0.0 ? box.upper.z : box.lower.z);
      unsealed += glm::dot(n, far) - offset > eps ? 1 : 0;
    }
    ok = ok && unsealed <= 1;
    if (!ok) continue;
    for (const std::uint32_t k : set) solid_of[k] = static_cast<std::uint32_t>(solids.size());
    solids.push_back(std::move(solid));
  }
}

// Whether a convex solid that one of the candidates bounds hides all of R from all of S: S and
// R each lie outside it (all corners on the outer side of one of its planes, not all in it), and every
// segment between a corner of S and a corner of R passes through its interior (shrunk by
// epsilon). As in hidden_by_one(), the corners are enough: for a point y, the points x whose
// segment to y meets a convex set form a convex set. Such a segment meets one of the solid's
// occluders (find_solids()). What a block hides as a whole but none of its faces alone: 13 %
// (the closed Cornell box) to 33 % (the room around a block) of the pairs with candidates
// integrated to exactly 0 point by point before (session 43).
bool ExactPolygonTransport::Impl::hidden_by_solid(const Face& S, const Face& R,
                                                  const std::vector<std::uint32_t>& candidates) const {
  std::array<std::uint32_t, 8> tried{};
  std::size_t tried_count = 0;
  for (const std::uint32_t k : candidates) {
    const std::uint32_t id = solid_of[k];
    if (id == kNoSolid || std::find(tried.begin(), tried.begin() + tried_count, id) != tried.begin() + tried_count)
      continue;
    if (tried_count < tried.size()) tried[tried_count++] = id;
    const Solid& solid = solids[id];
    const std::size_t planes = solid.normals.size();
    // Beyond one of its planes, and not in it: then all of the polygon but a sliver epsilon
    // thin lies strictly outside. A polygon in one of the solid's planes may be inside it (the
    // walls of a room within a building, wound inward, see each other across it).
    auto outside = [&](const Face& F) {
      for (std::size_t p = 0; p < planes; ++p) {
        bool all = true, beyond = false;
        for (const glm::vec3& v : F.corners) {
          const double d = glm::dot(solid.normals[p], glm::dvec3(v)) - solid.offsets[p];
          all = all && d >= -epsilon;
          beyond = beyond || d > epsilon;
        }
        if (all && beyond) return true;
      }
      return false;
    };
    if (!outside(S) || !outside(R)) continue;
    bool hidden = true;
    for (std::size_t a = 0; a < S.corners.size() && hidden; ++a)
      for (std::size_t b = 0; b < R.corners.size() && hidden; ++b) {
        // Cyrus-Beck: the part of the segment inside every plane moved in by epsilon.
        const glm::dvec3 p(S.corners[a]), q(R.corners[b]);
        double t0 = 0.0, t1 = 1.0;
        for (std::size_t i = 0; i < planes && t0 < t1; ++i) {
          const double dp = glm::dot(solid.normals[i], p) - solid.offsets[i] + epsilon,
                       dq = glm::dot(solid.normals[i], q) - solid.offsets[i] + epsilon;
          if (dp >= 0.0 && dq >= 0.0) t1 = -1.0;
          else if (dp >= 0.0) t0 = std::max(t0, dp / (dp - dq));
          else if (dq >= 0.0) t1 = std::min(t1, dp / (dp - dq));
        }
        hidden = t0 < t1;
      }
    if (hidden) return true;
  }
  return false;
}

double ExactPolygonTransport::Impl::unobstructed(const Face& S, const Face& R, Workspace& w) const {
  const float separation = glm::length(R.centroid - S.centroid) / (S.radius + R.radius);
  bool all_in_front = separation > kFarSeparation;
  for (const glm::vec3& v : R.corners) all_in_front = all_in_front && glm::dot(v - S.centroid, S.normal) > epsilon;
  for (const glm::vec3& v : S.corners) all_in_front = all_in_front && glm::dot(v - R.centroid, R.normal) > epsilon;
  if (all_in_front) {
    // G = sum_a sum_b w_a w_b cos_a cos_b / (pi d^2), both cosines positive everywhere here.
    double sum = 0.0;
    for (std::size_t a = 0; a < S.gauss.size(); ++a)
      for (std::size_t b = 0; b < R.gauss.size(); ++b) {
        const glm::vec3 d = R.gauss[b] - S.gauss[a];
        const float d2 = glm::dot(d, d);
        const float k = glm::dot(S.normal, d) * -glm::dot(R.normal, d) / (d2 * d2);
        sum += S.weight[a] * R.weight[b] * static_cast<double>(k);
      }
    return sum * kInversePi;
  }
  const int n = static_cast<int>(R.corners.size());
  auto g = [&](const glm::vec3& x) -> double {
    ++w.work;
    if (glm::dot(x - R.centroid, R.normal) <= 0.0f) return 0.0;  // behind the receiver
    return n <= 8 ? static_cast<double>(point_to_polygon_factor_fast(x, S.normal, R.corners.data(), n))
                  : point_to_polygon_factor(x, S.normal, R.corners.data(), n);
  };
  return integrate(S, g, kMaxDepthClear, [](const glm::vec3&, const glm::vec3&) { return false; });
}

// F(dx -> the part of R visible from x) for x on S: R clipped to x's hemisphere, less the
// shadow of each candidate occluder (w.candidates).
double ExactPolygonTransport::Impl::visible_factor(const glm::vec3& point, const Face& S, const Face& R,
                                                   Workspace& w) const {
  ++w.work;
  const glm::dvec3 x(point);
  const glm::dvec3 nr = R.dnormal;
  const double h = glm::dot(nr, x) - R.offset;  // height of x above the receiver's plane
  if (!(h > 0.0)) return 0.0;
  w.scratch.clear();
  for (const glm::vec3& v : R.corners) w.scratch.push_back(glm::dvec3(v) - x);
  w.corners.clear();
  w.pieces.clear();
  const int m = clip(w.scratch.data(), static_cast<int>(w.scratch.size()), S.dnormal, 0.0, 1.0, w.corners);
  if (m == 0) return 0.0;
  w.pieces.push_back(Piece{0, static_cast<std::uint32_t>(m)});
  // The receiver's cone from x (planes through x and its edges, normals inward): an occluder
  // wholly outside one of them casts no shadow on it.
  w.cone.clear();
  inward_planes(w.corners.data(), m, w.cone);

  for (const std::uint32_t p : w.candidates) {
    const Occluder& O = occluders[p];
    w.scratch.clear();
    for (const glm::vec3& v : O.corners) w.scratch.push_back(glm::dvec3(v) - x);
    const int n = static_cast<int>(w.scratch.size());
    // Outside the receiver's cone, behind its plane or not below x's height: no shadow.
    bool clear = false;
    double lo = 0.0, hi = 0.0;  // of dot(nr, o) + h over the corners
    for (int i = 0; i < n; ++i) {
      const double d = glm::dot(nr, w.scratch[static_cast<std::size_t>(i)]) + h;
      lo = i == 0 ? d : std::min(lo, d);
      hi = i == 0 ? d : std::max(hi, d);
    }
    if (hi <= 0.0 || lo >= h) continue;
    for (const glm::dvec3& c : w.cone) {
      clear = true;
      for (int i = 0; i < n && clear; ++i) clear = glm::dot(c, w.scratch[static_cast<std::size_t>(i)]) <= 0.0;
      if (clear) break;
    }
    if (clear) continue;
    ++w.work;
    // The occluder between x and the receiver's plane: -h <= dot(nr, o) <= -1e-9 h.
    int k = n;
    if (lo < 0.0) {
      w.occluder.clear();
      k = clip(w.scratch.data(), k, nr, h, 1.0, w.occluder);
      if (k == 0) continue;
      w.scratch.swap(w.occluder);
    }
    if (hi > (1.0 - 1e-9) * h) {
      w.occluder.clear();
      k = clip(w.scratch.data(), k, nr, 1e-9 * h, -1.0, w.occluder);
      if (k == 0) continue;
      w.scratch.swap(w.occluder);
    }
    // Its shadow's cone: the planes through x and each edge, normals pointing inward.
    w.planes.clear();
    if (!inward_planes(w.scratch.data(), k, w.planes)) continue;  // edge-on from x: no shadow
    // Each piece: the parts outside one plane are visible; what is inside all is shadow.
    w.next_corners.clear();
    w.next_pieces.clear();
    for (const Piece& piece : w.pieces) {
      w.scratch.assign(w.corners.begin() + piece.first, w.corners.begin() + piece.first + piece.second);
      int left = static_cast<int>(piece.second);
      for (std::size_t i = 0; i < w.planes.size() && left > 0; ++i) {
        const glm::dvec3& mp = w.planes[i];
        double most = 0.0, least = 0.0;
        for (int j = 0; j < left; ++j) {
          const double d = glm::dot(mp, w.scratch[static_cast<std::size_t>(j)]);
          most = j == 0 ? d : std::max(most, d);
          least = j == 0 ? d : std::min(least, d);
        }
        if (least >= 0.0) continue;  // wholly inside this plane
        const auto first = static_cast<std::uint32_t>(w.next_corners.size());
        if (most <= 0.0) {  // wholly outside: all of it is visible
          w.next_corners.insert(w.next_corners.end(), w.scratch.begin(), w.scratch.begin() + left);
          w.next_pieces.push_back(Piece{first, static_cast<std::uint32_t>(left)});
          left = 0;
          break;
        }
        const int out = clip(w.scratch.data(), left, mp, 0.0, -1.0, w.next_corners);
        if (out > 0) w.next_pieces.push_back(Piece{first, static_cast<std::uint32_t>(out)});
        w.occluder.clear();
        left = clip(w.scratch.data(), left, mp, 0.0, 1.0, w.occluder);
        w.scratch.swap(w.occluder);
      }
    }
    std::swap(w.corners, w.next_corners);
    std::swap(w.pieces, w.next_pieces);
    if (w.pieces.empty()) return 0.0;
  }
  double f = 0.0;
  for (const Piece& piece : w.pieces)
    f += contour_factor(w.corners.data() + piece.first, static_cast<int>(piece.second), S.dnormal);
  // Slivers that rounding leaves along shadow edges are no view.
  return f > kSliver ? f : 0.0;
}

ExactPolygonTransport::ExactPolygonTransport(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.epsilon = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
  const std::vector<Polygon>& polygons = scene.polygons();
  m.faces.resize(polygons.size());
  const glm::vec2 nodes[4] = {{kGaussLo, kGaussLo}, {kGaussHi, kGaussLo}, {kGaussLo, kGaussHi}, {kGaussHi, kGaussHi}};
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const Polygon& p = polygons[i];
    Face& f = m.faces[i];
    f.corners.assign(p.vertices.begin(), p.vertices.end());
    f.normal = p.normal;
    f.dnormal = glm::normalize(glm::dvec3(p.normal));
    f.offset = glm::dot(f.dnormal, glm::dvec3(f.corners[0]));
    const std::size_t n = f.corners.size();
    // Cells: the polygon itself when it has 3 or 4 corners, else a fan of triangles.
    if (n <= 4) {
      f.cells.push_back(Cell{CellMap(f.corners.data(), static_cast<int>(n)), 0.0});
    } else {
      for (std::size_t k = 1; k + 1 < n; ++k) {
        const glm::vec3 t[3] = {f.corners[0], f.corners[k], f.corners[k + 1]};
        f.cells.push_back(Cell{CellMap(t, 3), 0.0});
      }
    }
    glm::dvec3 centroid(0.0);
    for (Cell& c : f.cells) {
      double cell_area = 0.0;
      for (const glm::vec2& st : nodes) {
        const glm::vec3 x = c.map.point(st);
        f.gauss.push_back(x);
        f.weight.push_back(static_cast<double>(c.map.density(st)));
      }
      // CellMap's density is relative to the cell's area: weights 0.25 density area.
      const glm::vec3 e1 = c.map.point(glm::vec2(1.0f, 0.0f)) - c.map.point(glm::vec2(0.0f)),
                      e2 = c.map.point(glm::vec2(1.0f, 1.0f)) - c.map.point(glm::vec2(0.0f)),
                      e3 = c.map.point(glm::vec2(0.0f, 1.0f)) - c.map.point(glm::vec2(0.0f));
      cell_area = 0.5 * glm::length(glm::dvec3(glm::cross(e1, e2)) + glm::dvec3(glm::cross(e2, e3)));
      c.area = cell_area;
      for (std::size_t k = f.weight.size() - 4; k < f.weight.size(); ++k) {
        f.weight[k] *= 0.25 * cell_area;
        centroid += f.weight[k] * glm::dvec3(f.gauss[k]);
      }
      f.area += cell_area;
    }
    f.centroid = f.area > 0.0 ? glm::vec3(centroid / f.area) : f.corners[0];
    for (const glm::vec3& v : f.corners) f.radius = std::max(f.radius, glm::length(v - f.centroid));
  }

  // The polygons that can hide anything: some corner of the scene strictly on each side.
  const Bounds box = scene.bounds();
  std::vector<std::uint32_t> hiding;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const Face& f = m.faces[i];
    const float d = glm::dot(f.normal, f.corners[0]);
    // The box's corners farthest along and against the normal.
    const glm::vec3 hi(f.normal.x > 0.0f ? box.upper.x : box.lower.x, f.normal.y > 0.0f ? box.upper.y : box.lower.y,
                       f.normal.z > 0.0f ? box.upper.z : box.lower.z);
    const glm::vec3 lo(f.normal.x > 0.0f ? box.lower.x : box.upper.x, f.normal.y > 0.0f ? box.lower.y : box.upper.y,
                       f.normal.z > 0.0f ? box.lower.z : box.upper.z);
    if (glm::dot(f.normal, hi) - d <= m.epsilon || glm::dot(f.normal, lo) - d >= -m.epsilon) continue;
    bool front = false, back = false;
    for (std::size_t j = 0; j < polygons.size() && !(front && back); ++j)
      for (const glm::vec3& v : m.faces[j].corners) {
        const float s = glm::dot(f.normal, v) - d;
        front |= s > m.epsilon;
        back |= s < -m.epsilon;
      }
    if (front && back) hiding.push_back(static_cast<std::uint32_t>(i));
  }
  if (!hiding.empty()) m.merge_occluders(std::move(hiding));
  m.find_solids(box);
}

ExactPolygonTransport::~ExactPolygonTransport() = default;

std::unique_ptr<ExactPolygonTransport::Workspace> ExactPolygonTransport::workspace() const {
  return std::make_unique<Workspace>();
}

std::size_t ExactPolygonTransport::occluder_count() const { return impl_->occluders.size(); }

std::size_t ExactPolygonTransport::solid_count() const { return impl_->solids.size(); }

double ExactPolygonTransport::transport(std::uint32_t i, std::uint32_t j, Workspace& w) const {
  const Impl& m = *impl_;
  if (i == j) return 0.0;
  ++w.work;
  // The source is the smaller polygon (ties: the lower index), so both orders give one number.
  const bool i_source = m.faces[i].area < m.faces[j].area || (m.faces[i].area == m.faces[j].area && i < j);
  const std::uint32_t s = i_source ? i : j, r = i_source ? j : i;
  const Face& S = m.faces[s];
  const Face& R = m.faces[r];
  // Facing: some corner of each strictly in front of the other (coplanar polygons see nothing).
  bool r_in_front = false, s_in_front = false;
  for (const glm::vec3& v : R.corners) r_in_front |= glm::dot(v - S.centroid, S.normal) > m.epsilon;
  if (!r_in_front) return 0.0;
  for (const glm::vec3& v : S.corners) s_in_front |= glm::dot(v - R.centroid, R.normal) > m.epsilon;
  if (!s_in_front) return 0.0;
  if (!m.clusters.empty()) m.candidates(s, r, w.candidates);
  if (m.clusters.empty() || w.candidates.empty()) return m.unobstructed(S, R, w);
  if (m.hidden_by_one(S, R, w.candidates) || m.hidden_by_solid(S, R, w.candidates)) return 0.0;
  auto g = [&](const glm::vec3& x) { return m.visible_factor(x, S, R, w); };
  // A source edge in the plane of an occluder (a floor facet along a block's face): the shadow
  // may be a wedge along that edge thinner than the first levels' Gauss points can see.
  auto in_occluder_plane = [&](const glm::vec3& a, const glm::vec3& b) {
    for (const std::uint32_t k : w.candidates) {
      const Occluder& O = m.occluders[k];
      if (std::fabs(glm::dot(O.normal, a) - O.offset) > m.epsilon ||
          std::fabs(glm::dot(O.normal, b) - O.offset) > m.epsilon)
        continue;
      // In the plane: does the edge reach the occluder (the segment clipped by its sides)?
      float t0 = 0.0f, t1 = 1.0f;
      const std::size_t n = O.corners.size();
      for (std::size_t e = 0; e < n && t0 <= t1; ++e) {
        const glm::vec3 inward = glm::cross(O.normal, O.corners[(e + 1) % n] - O.corners[e]);
        const float scale = glm::length(inward);
        const float da = glm::dot(inward, a - O.corners[e]) + m.epsilon * scale,
                    db = glm::dot(inward, b - O.corners[e]) + m.epsilon * scale;
        if (da < 0.0f && db < 0.0f) t1 = -1.0f;
        else if (da < 0.0f) t0 = std::max(t0, da / (da - db));
        else if (db < 0.0f) t1 = std::min(t1, da / (da - db));
      }
      if (t0 <= t1) return true;
    }
    return false;
  };
  return m.integrate(S, g, kMaxDepthObstructed, in_occluder_plane);
}

}  // namespace radiosity::detail
