// generate_lightmap_uvs(): planar charts cut from a host's mesh by normal, each projected onto
// its plane at one texel density, turned to its minimum-area bounding rectangle and shelf-packed
// into a square lightmap with whole empty texels between the charts.
// Based on: B. Levy, S. Petitjean, N. Ray, J. Maillot, "Least squares conformal maps for
// automatic texture atlas generation", SIGGRAPH 2002 (the cut-into-charts, flatten, pack
// structure; our charts are planar projections, not conformal maps); A. M. Andrew, "Another
// efficient algorithm for convex hulls in two dimensions", Information Processing Letters 9(5),
// 1979 (monotone chain); H. Freeman, R. Shapira, "Determining the minimum-area encasing
// rectangle for an arbitrary closed curve", CACM 18(7), 1975 (the rectangle has a side on the
// hull); J. Jylanki, "A thousand ways to pack the bin", 2010 (shelf packing, tallest first);
// D. Eberly, "Intersection of convex objects: the method of separating axes", Geometric Tools,
// 2008 (two triangles' interiors are disjoint iff one of their six edge normals separates them).
//
// Why the overlap check: every triangle of a chart faces within chart_angle_deg (< 90) of the
// chart's normal, so none flips in projection; but a chart can still wrap over itself (a spiral
// ramp, a surface curling round), so each chart's projected triangles are tested pairwise (a
// grid over the chart) and the later of an overlapping pair is left for another chart.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/assert.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "radiosity/lightmap.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

/// Gap (texels) kept between a chart and the sides of its texel rectangle, so that its
/// triangles stay strictly inside it after float rounding of the UVs and a conservative
/// rasteriser touches no texel outside it.
constexpr double kMargin = 0.05;
/// Hull edges tried for the minimum-area rectangle; a finely tessellated round chart has
/// thousands, and any rotation is correct (only the waste changes), so larger hulls are sampled.
constexpr std::size_t kMaxRectangleTrials = 1024;

struct TriangleInfo {
  glm::dvec3 normal{0.0};  ///< unit (zero when degenerate)
  double area = 0.0;
  bool degenerate = false;
};

/// One chart: its triangles, the host vertices they use (local index = position in `vertices`),
/// the corners of its triangles as local indices, and its points in the plane.
struct Chart {
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint32_t> vertices;
  std::vector<std::array<std::uint32_t, 3>> corners;  ///< per entry of `triangles`
  std::vector<glm::dvec2> points;                     ///< per local vertex, scene units
  double width = 0.0, height = 0.0;                   ///< extent of `points` after turning
  double area = 0.0;                                  ///< projected area, scene units^2
};

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

/// Whether triangles a and b (counter-clockwise) have overlapping interiors, more than `tol`
/// deep: no edge normal of either separates them (separating axes).
bool triangles_overlap(const std::array<glm::dvec2, 3>& a, const std::array<glm::dvec2, 3>& b, double tol) {
  auto separated_by_edges_of = [tol](const std::array<glm::dvec2, 3>& p, const std::array<glm::dvec2, 3>& q) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 e = p[static_cast<std::size_t>((k + 1) % 3)] - p[static_cast<std::size_t>(k)];
      const double length = std::sqrt(glm::dot(e, e));
      if (length == 0.0) continue;
      // p lies to the left of its own edges; q is separated when it lies (up to tol) to the right.
      double deepest = -1e300;
      for (const glm::dvec2& v : q) deepest = std::max(deepest, cross2(e, v - p[static_cast<std::size_t>(k)]) / length);
      if (deepest <= tol) return true;
    }
    return false;
  };
  return !separated_by_edges_of(a, b) && !separated_by_edges_of(b, a);
}

/// Pairs (i, j), i < j, of a chart's triangles whose projections overlap more than `tol` deep:
/// a uniform grid over the chart's bounds with about one triangle per cell, each pair tested
/// once (in the cell that holds the lower corner of the intersection of their bounding boxes).
/// Cost: about linear for a chart of similar triangles; a fan of long slivers around one vertex
/// puts many triangles in one cell (quadratic in the fan's size).
std::vector<std::pair<std::uint32_t, std::uint32_t>> overlapping_pairs(const Chart& chart, double tol) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  const std::size_t n = chart.corners.size();
  if (n < 2) return pairs;
  auto corner = [&](std::size_t i, int k) { return chart.points[chart.corners[i][static_cast<std::size_t>(k)]]; };
  std::vector<glm::dvec2> lo(n), hi(n);
  glm::dvec2 lower(1e300), upper(-1e300);
  for (std::size_t i = 0; i < n; ++i) {
    lo[i] = glm::min(corner(i, 0), glm::min(corner(i, 1), corner(i, 2)));
    hi[i] = glm::max(corner(i, 0), glm::max(corner(i, 1), corner(i, 2)));
    lower = glm::min(lower, lo[i]);
    upper = glm::max(upper, hi[i]);
  }
  const glm::dvec2 size = glm::max(upper - lower, glm::dvec2(1e-300));
  const double cell = std::sqrt(size.x * size.y / static_cast<double>(n));
  auto cells_along = [&](double extent) {
    return static_cast<std::size_t>(std::clamp(std::ceil(extent / cell), 1.0, 2.0 * static_cast<double>(n)));
  };
  const std::size_t gx = cells_along(size.x), gy = cells_along(size.y);
  auto cell_x = [&](double x) {
    return std::min(gx - 1, static_cast<std::size_t>(std::max(0.0, (x - lower.x) / size.x * static_cast<double>(gx))));
  };
  auto cell_y = [&](double y) {
    return std::min(gy - 1, static_cast<std::size_t>(std::max(0.0, (y - lower.y) / size.y * static_cast<double>(gy))));
  };

  // Compressed rows: the triangles of each cell, in increasing order.
  std::vector<std::size_t> start(gx * gy + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t y = cell_y(lo[i].y); y <= cell_y(hi[i].y); ++y)
      for (std::size_t x = cell_x(lo[i].x); x <= cell_x(hi[i].x); ++x) ++start[y * gx + x + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> items(start.back());
  std::vector<std::size_t> cursor(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t y = cell_y(lo[i].y); y <= cell_y(hi[i].y); ++y)
      for (std::size_t x = cell_x(lo[i].x); x <= cell_x(hi[i].x); ++x)
        items[cursor[y * gx + x]++] = static_cast<std::uint32_t>(i);

  for (std::size_t c = 0; c + 1 < start.size(); ++c)
    for (std::size_t a = start[c]; a < start[c + 1]; ++a)
      for (std::size_t b = a + 1; b < start[c + 1]; ++b) {
        const std::uint32_t i = items[a], j = items[b];
        const glm::dvec2 from = glm::max(lo[i], lo[j]), to = glm::min(hi[i], hi[j]);
        if (from.x > to.x || from.y > to.y) continue;
        if (cell_y(from.y) * gx + cell_x(from.x) != c) continue;  // tested in another cell
        const std::array<glm::dvec2, 3> ti{corner(i, 0), corner(i, 1), corner(i, 2)};
        const std::array<glm::dvec2, 3> tj{corner(j, 0), corner(j, 1), corner(j, 2)};
        if (triangles_overlap(ti, tj, tol)) pairs.emplace_back(i, j);
      }
  return pairs;
}

/// Turns the chart's points to their minimum-area bounding rectangle (a side of it lies on a
/// side of the convex hull: Freeman & Shapira), the long side along u, the lower corner at the
/// origin. Only rotations: a triangle's winding is kept.
void turn_to_bounding_rectangle(Chart& chart) {
  // Convex hull by the monotone chain (Andrew), counter-clockwise.
  std::vector<glm::dvec2> sorted = chart.points;
  std::sort(sorted.begin(), sorted.end(),
            [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<glm::dvec2> hull;
  if (sorted.size() < 3) {
    hull = sorted;
  } else {
    hull.resize(2 * sorted.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], sorted[i] - hull[k - 2]) <= 0.0) --k;
      hull[k++] = sorted[i];
    }
    for (std::size_t i = sorted.size() - 1, t = k + 1; i-- > 0;) {
      while (k >= t && cross2(hull[k - 1] - hull[k - 2], sorted[i] - hull[k - 2]) <= 0.0) --k;
      hull[k++] = sorted[i];
    }
    hull.resize(k - 1);
  }

  // The best of the hull's edge directions (sampled evenly on a large hull).
  glm::dvec2 best_u(1.0, 0.0);
  if (hull.size() >= 2) {
    double best_area = 1e300;
    const std::size_t h = hull.size(), step = std::max<std::size_t>(1, h / kMaxRectangleTrials);
    for (std::size_t e = 0; e < h; e += step) {
      const glm::dvec2 d = hull[(e + 1) % h] - hull[e];
      const double length = std::sqrt(glm::dot(d, d));
      if (length == 0.0) continue;
      const glm::dvec2 u = d / length, v(-u.y, u.x);
      double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
      for (const glm::dvec2& p : hull) {
        u0 = std::min(u0, glm::dot(p, u));
        u1 = std::max(u1, glm::dot(p, u));
        v0 = std::min(v0, glm::dot(p, v));
        v1 = std::max(v1, glm::dot(p, v));
      }
      if ((u1 - u0) * (v1 - v0) < best_area) {
        best_area = (u1 - u0) * (v1 - v0);
        best_u = u;
      }
    }
  }
  glm::dvec2 u = best_u, v(-u.y, u.x);
  auto extent = [&](const glm::dvec2& axis, double& low) {
    double a = 1e300, b = -1e300;
    for (const glm::dvec2& p : chart.points) {
      a = std::min(a, glm::dot(p, axis));
      b = std::max(b, glm::dot(p, axis));
    }
    low = a;
    return b - a;
  };
  double u_low = 0.0, v_low = 0.0;
  double width = extent(u, u_low), height = extent(v, v_low);
  if (height > width) {  // a quarter turn: (u, v) -> (v, -u) keeps the orientation
    const glm::dvec2 old_u = u;
    u = v;
    v = -old_u;
    width = extent(u, u_low);
    height = extent(v, v_low);
  }
  for (glm::dvec2& p : chart.points) p = glm::dvec2(glm::dot(p, u) - u_low, glm::dot(p, v) - v_low);
  chart.width = width;
  chart.height = height;
}

/// Where a chart goes: its texel rectangle [x, x + w) x [y, y + h).
struct Placement {
  std::int64_t x = 0, y = 0, w = 0, h = 0;
};

/// Shelf packing at `texels_per_unit` of charts taken in `order` (tallest first): left to right
/// in rows, `padding` texels between rectangles and from the border. Returns false when they
/// do not fit.
bool pack(const std::vector<Chart>& charts, const std::vector<std::uint32_t>& order, double texels_per_unit,
          const LightmapUvOptions& options, std::vector<Placement>* placements) {
  const std::int64_t res = options.resolution, pad = options.padding;
  std::int64_t x = pad, y = pad, row = 0;
  for (std::uint32_t c : order) {
    const double w = charts[c].width * texels_per_unit + 2.0 * kMargin;
    const double h = charts[c].height * texels_per_unit + 2.0 * kMargin;
    if (!(w <= static_cast<double>(res) && h <= static_cast<double>(res))) return false;
    Placement p;
    p.w = static_cast<std::int64_t>(std::ceil(w));
    p.h = static_cast<std::int64_t>(std::ceil(h));
    if (x > pad && x + p.w > res - pad) {  // the next shelf
      y += row + pad;
      x = pad;
      row = 0;
    }
    if (x + p.w > res - pad || y + p.h > res - pad) return false;
    p.x = x;
    p.y = y;
    if (placements) (*placements)[c] = p;
    x += p.w + pad;
    row = std::max(row, p.h);
  }
  return true;
}

/// The largest density at which the charts fit (to a relative 1e-5, as a float that fits).
/// Requires that they fit at density 0 (every chart one texel).
float largest_density(const std::vector<Chart>& charts, const std::vector<std::uint32_t>& order,
                      const LightmapUvOptions& options) {
  // Upper bounds: the charts' area cannot exceed the usable square, nor a chart its side.
  const double usable = static_cast<double>(options.resolution - 2 * options.padding);
  double area = 0.0, longest = 0.0;
  for (const Chart& c : charts) {
    area += c.area;
    longest = std::max(longest, c.width);  // width >= height
  }
  if (!(area > 0.0) || !(longest > 0.0)) return 0.0f;  // nothing with an extent: any density
  double bad = std::min(usable / std::sqrt(area), usable / longest) * (1.0 + 1e-6);
  double good = bad;
  // Shrink by 10 % until the packing fits (the shelves waste a few tens of percent), then bisect.
  while (!pack(charts, order, good, options, nullptr)) {
    bad = good;
    good *= 0.9;
    if (good < 1e-30) return 0.0f;
  }
  if (good == bad) bad = good * 1.01;
  while (bad - good > 1e-5 * good) {
    const double mid = 0.5 * (good + bad);
    (pack(charts, order, mid, options, nullptr) ? good : bad) = mid;
  }
  float f = static_cast<float>(good);
  while (f > 0.0f && !pack(charts, order, f, options, nullptr)) f = std::nextafter(f, 0.0f);
  return f;
}

std::string show(double value, int digits = 6) {
  std::ostringstream s;
  s.precision(digits);
  s << value;
  return s.str();
}

/// `density` rounded down to 4 significant digits when that still fits (a number a person can
/// type back), else in full.
std::string show_density(const std::vector<Chart>& charts, const std::vector<std::uint32_t>& order,
                         const LightmapUvOptions& options, float density) {
  if (density > 0.0f) {
    const double scale = std::pow(10.0, 3 - std::floor(std::log10(static_cast<double>(density))));
    const float rounded = static_cast<float>(std::floor(static_cast<double>(density) * scale) / scale);
    if (rounded > 0.0f && pack(charts, order, rounded, options, nullptr)) return show(rounded);
  }
  return show(density, 9);
}

}  // namespace

void validate(const LightmapUvOptions& options) {
  auto fail = [](const std::string& problem) {
    throw Error(ErrorCode::invalid_argument, "LightmapUvOptions::" + problem);
  };
  if (!(std::isfinite(options.texels_per_unit) && options.texels_per_unit >= 0.0f))
    fail("texels_per_unit must be finite and >= 0 (0: the largest that fits), got " + show(options.texels_per_unit));
  if (options.resolution <= 0) fail("resolution must be > 0, got " + std::to_string(options.resolution));
  if (options.padding < 0) fail("padding must be >= 0, got " + std::to_string(options.padding));
  if (2 * static_cast<std::int64_t>(options.padding) >= options.resolution)
    fail("padding " + std::to_string(options.padding) + " leaves no texel inside a resolution of " +
         std::to_string(options.resolution) + " (resolution must be > 2 * padding)");
  if (!(options.chart_angle_deg > 0.0f && options.chart_angle_deg < 90.0f))
    fail("chart_angle_deg must be in (0, 90) degrees, got " + show(options.chart_angle_deg));
}

LightmapUvs generate_lightmap_uvs(const glm::vec3* positions, std::size_t vertex_count, const std::uint32_t* indices,
                                  std::size_t index_count, const LightmapUvOptions& options) {
  validate(options);
  auto fail = [](const std::string& problem) {
    throw Error(ErrorCode::invalid_argument, "generate_lightmap_uvs: " + problem);
  };
  if (index_count % 3 != 0) fail("index_count " + std::to_string(index_count) + " is not a multiple of 3");
  if (vertex_count > 0 && positions == nullptr)
    fail("positions is null but vertex_count is " + std::to_string(vertex_count));
  if (index_count > 0 && indices == nullptr) fail("indices is null but index_count is " + std::to_string(index_count));
  if (vertex_count >= kNone || index_count / 3 >= kNone)
    fail("the mesh exceeds what 32-bit indices can address");
  for (std::size_t v = 0; v < vertex_count; ++v) {
    const glm::vec3& p = positions[v];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
      fail("the position of vertex " + std::to_string(v) + " is NaN or infinite");
  }
  for (std::size_t c = 0; c < index_count; ++c)
    if (indices[c] >= vertex_count)
      fail("triangle " + std::to_string(c / 3) + ": index " + std::to_string(indices[c]) + " is out of range (" +
           std::to_string(vertex_count) + " vertices)");

  const std::size_t triangle_count = index_count / 3;
  auto position = [&](std::uint32_t v) { return glm::dvec3(positions[v]); };
  auto corner = [&](std::size_t t, int k) { return indices[3 * t + static_cast<std::size_t>(k)]; };

  // Normals and areas; add_mesh()'s test for degenerate triangles (area against diameter^2).
  std::vector<TriangleInfo> info(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const glm::dvec3 p0 = position(corner(t, 0)), p1 = position(corner(t, 1)), p2 = position(corner(t, 2));
    const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const double length = glm::length(n);
    const double diameter = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
    info[t].area = 0.5 * length;
    info[t].degenerate = !(info[t].area > static_cast<double>(detail::kDegenerateAreaRatio) * diameter * diameter);
    if (!info[t].degenerate) info[t].normal = n / length;
  }

  // Neighbours across shared edges (keyed by the host's vertex indices; an edge of more than two
  // triangles joins them all), as compressed rows.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
  edges.reserve(3 * triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    if (info[t].degenerate) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = corner(t, k), b = corner(t, (k + 1) % 3);
      edges.emplace_back(std::min(a, b) << 32 | std::max(a, b), static_cast<std::uint32_t>(t));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> links;
  for (std::size_t r = 0; r < edges.size();) {
    std::size_t end = r + 1;
    while (end < edges.size() && edges[end].first == edges[r].first) ++end;
    for (std::size_t i = r; i < end; ++i)
      for (std::size_t j = r; j < end; ++j)
        if (edges[i].second != edges[j].second) links.emplace_back(edges[i].second, edges[j].second);
    r = end;
  }
  std::sort(links.begin(), links.end());
  links.erase(std::unique(links.begin(), links.end()), links.end());
  std::vector<std::size_t> link_start(triangle_count + 1, 0);
  for (const auto& l : links) ++link_start[l.first + 1];
  std::partial_sum(link_start.begin(), link_start.end(), link_start.begin());

  // Seeds: the largest triangle not yet in a chart (ties by index), so a chart starts on its
  // most significant face.
  std::vector<std::uint32_t> seeds;
  for (std::size_t t = 0; t < triangle_count; ++t)
    if (!info[t].degenerate) seeds.push_back(static_cast<std::uint32_t>(t));
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return info[a].area > info[b].area; });

  const double cos_limit = std::cos(static_cast<double>(options.chart_angle_deg * detail::kPi / 180.0f));
  std::vector<std::uint32_t> chart_of(triangle_count, kNone);
  std::vector<std::uint32_t> local_of(vertex_count, kNone);  // scratch, kNone between charts
  std::vector<std::uint32_t> slot(triangle_count, kNone);    // scratch: place in `members`
  std::vector<Chart> charts;

  for (std::uint32_t seed : seeds) {
    if (chart_of[seed] != kNone) continue;
    const auto id = static_cast<std::uint32_t>(charts.size());
    const glm::dvec3 seed_normal = info[seed].normal;

    // Flood fill across shared edges while the normal stays within the angle of the seed's.
    std::vector<std::uint32_t> members{seed};
    chart_of[seed] = id;
    for (std::size_t q = 0; q < members.size(); ++q)
      for (std::size_t l = link_start[members[q]]; l < link_start[members[q] + 1]; ++l) {
        const std::uint32_t nb = links[l].second;
        if (chart_of[nb] == kNone && glm::dot(info[nb].normal, seed_normal) >= cos_limit) {
          chart_of[nb] = id;
          members.push_back(nb);
        }
      }

    // The projection's normal: the area-weighted mean when it tilts no triangle more than the
    // seed's normal does (less distortion), else the seed's (every triangle within the angle).
    glm::dvec3 mean(0.0);
    for (std::uint32_t t : members) mean += info[t].area * info[t].normal;
    mean = glm::normalize(mean);
    double worst_seed = 1.0, worst_mean = 1.0;
    for (std::uint32_t t : members) {
      worst_seed = std::min(worst_seed, glm::dot(info[t].normal, seed_normal));
      worst_mean = std::min(worst_mean, glm::dot(info[t].normal, mean));
    }
    Chart chart;
    const glm::dvec3 origin = position(corner(seed, 0));
    glm::dvec3 tangent, bitangent;
    auto project = [&](const std::vector<std::uint32_t>& tris) {
      for (std::uint32_t v : chart.vertices) local_of[v] = kNone;
      chart = Chart{};
      chart.triangles = tris;
      for (std::uint32_t t : tris) {
        std::array<std::uint32_t, 3> local{};
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t v = corner(t, k);
          if (local_of[v] == kNone) {
            local_of[v] = static_cast<std::uint32_t>(chart.vertices.size());
            chart.vertices.push_back(v);
            const glm::dvec3 d = position(v) - origin;
            chart.points.emplace_back(glm::dot(d, tangent), glm::dot(d, bitangent));
          }
          local[static_cast<std::size_t>(k)] = local_of[v];
        }
        chart.corners.push_back(local);
      }
    };
    auto signed_area = [&](std::size_t i) {
      const std::array<std::uint32_t, 3>& c = chart.corners[i];
      return 0.5 * cross2(chart.points[c[1]] - chart.points[c[0]], chart.points[c[2]] - chart.points[c[0]]);
    };
    auto use_normal = [&](const glm::dvec3& n) {
      glm::vec3 t, b;
      detail::tangent_frame(glm::vec3(n), t, b);
      tangent = glm::dvec3(t);
      bitangent = glm::dvec3(b);
      project(members);
    };
    use_normal(worst_mean > worst_seed ? mean : seed_normal);
    if (!(signed_area(0) > 0.0)) use_normal(seed_normal);  // rounding, near 90 degrees only
    RADIOSITY_ASSERT(signed_area(0) > 0.0);

    // Leave out triangles turned over by rounding (near 90 degrees) and, of each overlapping
    // pair, the later one; then keep what still hangs together with the seed.
    std::vector<bool> removed(members.size(), false);
    bool any_removed = false;
    for (std::size_t i = 1; i < members.size(); ++i)
      if (!(signed_area(i) > 0.0)) removed[i] = any_removed = true;
    double scale = 0.0;
    for (const glm::dvec2& p : chart.points) scale = std::max({scale, std::abs(p.x), std::abs(p.y)});
    double magnitude = 0.0;
    for (std::uint32_t v : chart.vertices)
      magnitude = std::max({magnitude, std::abs(static_cast<double>(positions[v].x)),
                            std::abs(static_cast<double>(positions[v].y)), std::abs(static_cast<double>(positions[v].z))});
    // Deeper than rounding: 1e-6 of the chart's size and of its coordinates (~16 float ulps), so
    // a T-junction's vertex on its neighbour's edge is no overlap.
    const double tol = 1e-6 * (scale + magnitude);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs = overlapping_pairs(chart, tol);
    std::sort(pairs.begin(), pairs.end(),
              [](const auto& a, const auto& b) { return a.second < b.second || (a.second == b.second && a.first < b.first); });
    for (const auto& [i, j] : pairs)
      if (!removed[i] && !removed[j]) removed[j] = any_removed = true;
    if (any_removed) {
      for (std::size_t i = 0; i < members.size(); ++i) slot[members[i]] = removed[i] ? kNone : static_cast<std::uint32_t>(i);
      std::vector<std::uint32_t> kept{seed};
      slot[seed] = kNone;
      for (std::size_t q = 0; q < kept.size(); ++q)
        for (std::size_t l = link_start[kept[q]]; l < link_start[kept[q] + 1]; ++l) {
          const std::uint32_t nb = links[l].second;
          if (chart_of[nb] == id && slot[nb] != kNone) {
            slot[nb] = kNone;
            kept.push_back(nb);
          }
        }
      for (std::size_t i = 0; i < members.size(); ++i) {
        slot[members[i]] = kNone;
        chart_of[members[i]] = kNone;
      }
      for (std::uint32_t t : kept) chart_of[t] = id;
      project(kept);
    }
    for (std::uint32_t v : chart.vertices) local_of[v] = kNone;
    charts.push_back(std::move(chart));
  }

  // Which charts hold each host vertex, and where: (vertex, chart, local index), sorted.
  struct Copy {
    std::uint32_t vertex, chart, local;
  };
  std::vector<Copy> copies;
  auto list_copies = [&](std::uint32_t c) {
    for (std::size_t l = 0; l < charts[c].vertices.size(); ++l)
      copies.push_back(Copy{charts[c].vertices[l], c, static_cast<std::uint32_t>(l)});
  };
  auto by_vertex_then_chart = [](const Copy& a, const Copy& b) {
    return a.vertex < b.vertex || (a.vertex == b.vertex && a.chart < b.chart);
  };
  for (std::uint32_t c = 0; c < charts.size(); ++c) list_copies(c);
  std::sort(copies.begin(), copies.end(), by_vertex_then_chart);
  auto copies_of = [&](std::uint32_t v) {
    return std::equal_range(copies.begin(), copies.end(), Copy{v, 0, 0},
                            [](const Copy& a, const Copy& b) { return a.vertex < b.vertex; });
  };

  // Degenerate triangles: into the first chart that holds all three corners (they add no
  // vertex, and their zero-area projection lies among the chart's points), or else into one
  // last chart whose vertices all sit on one point.
  std::vector<std::uint32_t> stray;
  for (std::size_t t = 0; t < triangle_count; ++t) {
    if (!info[t].degenerate) continue;
    const auto r0 = copies_of(corner(t, 0)), r1 = copies_of(corner(t, 1)), r2 = copies_of(corner(t, 2));
    std::uint32_t home = kNone;
    std::array<std::uint32_t, 3> local{};
    for (auto a = r0.first; a != r0.second && home == kNone; ++a) {
      auto find = [&](const auto& range) {
        const auto it = std::lower_bound(range.first, range.second, *a,
                                         [](const Copy& x, const Copy& y) { return x.chart < y.chart; });
        return (it != range.second && it->chart == a->chart) ? it->local : kNone;
      };
      const std::uint32_t l1 = find(r1), l2 = find(r2);
      if (l1 != kNone && l2 != kNone) {
        home = a->chart;
        local = {a->local, l1, l2};
      }
    }
    if (home == kNone) {
      stray.push_back(static_cast<std::uint32_t>(t));
      continue;
    }
    chart_of[t] = home;
    charts[home].triangles.push_back(static_cast<std::uint32_t>(t));
    charts[home].corners.push_back(local);
  }
  if (!stray.empty()) {
    const auto id = static_cast<std::uint32_t>(charts.size());
    Chart chart;
    for (std::uint32_t t : stray) {
      std::array<std::uint32_t, 3> local{};
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = corner(t, k);
        if (local_of[v] == kNone) {
          local_of[v] = static_cast<std::uint32_t>(chart.vertices.size());
          chart.vertices.push_back(v);
          chart.points.emplace_back(0.0, 0.0);
        }
        local[static_cast<std::size_t>(k)] = local_of[v];
      }
      chart.triangles.push_back(t);
      chart.corners.push_back(local);
      chart_of[t] = id;
    }
    for (std::uint32_t v : chart.vertices) local_of[v] = kNone;
    charts.push_back(std::move(chart));
    list_copies(id);
    std::sort(copies.begin(), copies.end(), by_vertex_then_chart);
  }

  // Each chart turned to its smallest rectangle; its projected area.
  for (Chart& chart : charts) {
    turn_to_bounding_rectangle(chart);
    for (const auto& c : chart.corners)
      chart.area += 0.5 * cross2(chart.points[c[1]] - chart.points[c[0]], chart.points[c[2]] - chart.points[c[0]]);
  }

  // The density, then the packing (tallest first; ties by width, then chart).
  LightmapUvs out;
  std::vector<std::uint32_t> order(charts.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return charts[a].height > charts[b].height || (charts[a].height == charts[b].height && charts[a].width > charts[b].width);
  });
  const std::string lightmap = std::to_string(options.resolution) + " x " + std::to_string(options.resolution) +
                               " lightmap with padding " + std::to_string(options.padding);
  if (!pack(charts, order, 0.0, options, nullptr))
    fail("the " + std::to_string(charts.size()) + " charts do not fit a " + lightmap +
         " at any density (each takes at least 1 + padding texels square): raise resolution or lower padding");
  float density = options.texels_per_unit;
  if (density == 0.0f) {
    density = largest_density(charts, order, options);
  } else if (!pack(charts, order, density, options, nullptr)) {
    const float fits = largest_density(charts, order, options);
    fail("the " + std::to_string(charts.size()) + " charts do not fit a " + lightmap + " at texels_per_unit " +
         show(density) + "; texels_per_unit " + show_density(charts, order, options, fits) + " fits");
  }
  std::vector<Placement> placements(charts.size());
  const bool packed = pack(charts, order, density, options, &placements);
  RADIOSITY_ASSERT(packed);
  (void)packed;

  // New vertices ordered by host vertex, then chart; each corner to its chart's copy.
  const double res = options.resolution, tpu = density;
  std::vector<std::vector<std::uint32_t>> new_vertex(charts.size());
  for (std::size_t c = 0; c < charts.size(); ++c) new_vertex[c].resize(charts[c].vertices.size(), kNone);
  out.uv1.resize(copies.size());
  out.vertex_origin.resize(copies.size());
  for (std::size_t i = 0; i < copies.size(); ++i) {
    const Copy& copy = copies[i];
    const Chart& chart = charts[copy.chart];
    const Placement& p = placements[copy.chart];
    // Centred in its rectangle, so at least kMargin texels from each side.
    const glm::dvec2 offset(static_cast<double>(p.x) + 0.5 * (static_cast<double>(p.w) - chart.width * tpu),
                            static_cast<double>(p.y) + 0.5 * (static_cast<double>(p.h) - chart.height * tpu));
    const glm::dvec2 texel = offset + chart.points[copy.local] * tpu;
    out.uv1[i] = glm::vec2(texel / res);
    out.vertex_origin[i] = copy.vertex;
    new_vertex[copy.chart][copy.local] = static_cast<std::uint32_t>(i);
  }
  out.indices.resize(index_count);
  out.triangle_chart.assign(chart_of.begin(), chart_of.end());
  double area = 0.0;
  for (std::size_t c = 0; c < charts.size(); ++c) {
    area += charts[c].area;
    for (std::size_t i = 0; i < charts[c].triangles.size(); ++i)
      for (std::size_t k = 0; k < 3; ++k) out.indices[3 * charts[c].triangles[i] + k] = new_vertex[c][charts[c].corners[i][k]];
  }
  for (std::size_t t = 0; t < triangle_count; ++t) RADIOSITY_ASSERT(chart_of[t] != kNone);
  out.chart_count = charts.size();
  out.texels_per_unit = density;
  out.utilisation = area * tpu * tpu / (res * res);
  return out;
}

LightmapUvs generate_lightmap_uvs(Scene& scene, MeshId mesh, const LightmapUvOptions& options) {
  if (mesh >= scene.meshes().size())
    throw Error(ErrorCode::invalid_argument, "generate_lightmap_uvs: mesh " + std::to_string(mesh) +
                                                 " does not exist (scene has " + std::to_string(scene.meshes().size()) +
                                                 " meshes)");
  const Mesh& m = scene.meshes()[mesh];
  LightmapUvs uvs = generate_lightmap_uvs(m.positions.data(), m.positions.size(), m.indices.data(), m.indices.size(),
                                          options);
  scene.set_mesh_lightmap_uvs(mesh, uvs.vertex_origin, uvs.indices, uvs.uv1);
  return uvs;
}

}  // namespace v1
}  // namespace radiosity
