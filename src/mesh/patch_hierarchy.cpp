// Meshing of scene polygons into patches and element quadtrees, with vertices shared within a
// polygon and across the smooth edges between polygons, and crack-free per-vertex interpolation.
// Based on:
//   M. F. Cohen, D. P. Greenberg, D. S. Immel & P. J. Brock, "An efficient radiosity approach for
//     realistic image synthesis", IEEE Computer Graphics and Applications 6(3), 1986
//     (patches shoot/receive, elements subdivide them: patch/element substructuring).
//   D. R. Baum, S. Mann, K. P. Smith & J. M. Winget, "Making radiosity usable: automatic
//     preprocessing and meshing techniques for the generation of accurate radiosity solutions",
//     SIGGRAPH 1991 (shared vertices, T-vertices and their interpolation).
//   M. F. Cohen & J. R. Wallace, "Radiosity and Realistic Image Synthesis", Academic Press 1993,
//     ch. 8 (quadtree element meshes, vertex radiosities by area-weighted averaging).
//   (and the same paper's splitting of surfaces where other surfaces meet them, so that no
//   element or interpolated vertex carries light across a wall standing on a floor: contact
//   lines from scene/overlap.hpp, MeshOptions::split_at_contacts).
//   M. de Berg, O. Cheong, M. van Kreveld & M. Overmars, "Computational Geometry", 3rd ed.,
//     Springer 2008, ch. 14 ("Quadtrees: non-uniform mesh generation": elements fine where the
//     detail is and growing with the distance from it; here toward contacts that end inside a
//     polygon, MeshOptions::grade_at_contacts, grade_toward_contacts()).
//   R. E. Tarjan, "Efficiency of a good but not linear set union algorithm", J. ACM 22(2), 1975
//     (union-find, here over polygon corners joined by smooth edges).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

#include "radiosity/mesh.hpp"

#include "core/assert.hpp"
#include "core/progress.hpp"
#include "core/sampling.hpp"
#include "core/union_find.hpp"
#include "scene/overlap.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

// Areas are computed in double and stored as float, so a cell that is mathematically exactly at
// the limit may round a few ulps above it; this slack keeps such a cell from being split again
// (which would quadruple its element count for nothing).
constexpr double kAreaSlack = 1e-6;

// A polygon is cut along at most this many contact lines (the first in find_contacts()'s
// order); beyond, the pieces would be slivers of little use, and their count grows as the
// square of the lines.
constexpr std::size_t kMaxContactLines = 64;

// Refuse meshes whose estimated element count could not be indexed by 32-bit ids anyway,
// before any memory is spent on them.
constexpr double kMaxEstimatedElements = 1u << 28;

// Splits of one patch's root before the mesher gives up on an element that does not shrink
// (corners that single precision cannot tell apart); see the split loop.
constexpr int kMaxSplitDepth = 40;

// Grading toward contacts (MeshOptions::grade_at_contacts): elements reach a quarter of the
// object's size near it, at most this many levels below the polygon's own elements, and grow
// to at most half their distance from it (a 2:1 grading, so neighbours differ by a level or so).
constexpr double kGradeTargetShare = 0.25;
constexpr int kMaxGradeLevels = 8;
constexpr double kGradeDistanceShare = 0.5;
// The new elements may be twice as many as the mesh had, and at least this many (a small scene
// with objects on a large ground): the cost of a solve stays within a few times the ungraded one.
constexpr std::size_t kGradeBudgetShare = 2;
constexpr std::size_t kMinGradeBudget = 32768;

double distance_to_segment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 ab = b - a;
  const double length2 = glm::dot(ab, ab);
  const double t = length2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / length2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// PatchHierarchy::vertex_values()'s fill of the vertices whose `weight` (the open area of the
// leaves around them) is 0: under a block, inside a prop sunk into the floor.
void dilate_into_buried(const std::vector<Element>& elements, const std::vector<std::uint32_t>& leaves,
                        const std::vector<double>& weight, std::vector<Rgb>& out) {
  // Ring by ring: each pass gives every corner still without a value the mean, over the
  // leaves it belongs to, of those leaves' corners that had one before the pass (so the result
  // does not depend on the order of the leaves). A buried region is as many passes wide as it
  // is leaves across; what no pass reaches (a polygon wholly buried) keeps 0.
  std::vector<std::uint8_t> known(out.size());
  for (std::size_t v = 0; v < known.size(); ++v) known[v] = weight[v] > 0.0;
  std::vector<std::uint32_t> pending;
  for (const std::uint32_t id : leaves) {
    const Element& e = elements[id];
    for (int k = 0; k < e.corner_count(); ++k)
      if (!known[e.corners[k]]) {
        pending.push_back(id);
        break;
      }
  }
  std::vector<glm::dvec3> sum(out.size(), glm::dvec3(0.0));
  std::vector<std::uint32_t> count(out.size(), 0);
  std::vector<std::uint32_t> reached;
  while (!pending.empty()) {
    for (const std::uint32_t id : pending) {
      const Element& e = elements[id];
      glm::dvec3 mean(0.0);
      int n = 0;
      for (int k = 0; k < e.corner_count(); ++k)
        if (known[e.corners[k]]) {
          mean += glm::dvec3(out[e.corners[k]]);
          ++n;
        }
      if (n == 0) continue;
      mean /= n;
      for (int k = 0; k < e.corner_count(); ++k) {
        const std::uint32_t v = e.corners[k];
        if (known[v]) continue;
        if (count[v]++ == 0) reached.push_back(v);
        sum[v] += mean;
      }
    }
    if (reached.empty()) break;  // the rest lie where nothing open is connected
    for (const std::uint32_t v : reached) {
      out[v] = Rgb(sum[v] / static_cast<double>(count[v]));
      known[v] = 1;
      sum[v] = glm::dvec3(0.0);
      count[v] = 0;
    }
    reached.clear();
    std::size_t kept = 0;
    for (const std::uint32_t id : pending) {
      const Element& e = elements[id];
      bool unknown_corner_left = false;
      for (int k = 0; k < e.corner_count(); ++k) unknown_corner_left = unknown_corner_left || !known[e.corners[k]];
      if (unknown_corner_left) pending[kept++] = id;
    }
    pending.resize(kept);
  }
}

bool fits(double area, float limit) { return area <= static_cast<double>(limit) * (1.0 + kAreaSlack); }

struct AreaCentroid {
  double area = 0.0;
  glm::dvec3 centroid{0.0};
};

double triangle_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

// Exact area and centroid of a planar convex triangle or quad; a quad is the two triangles
// c0c1c2 + c0c2c3, their centroids weighted by area.
AreaCentroid cell_geometry(const std::vector<glm::vec3>& vertices, const std::array<std::uint32_t, 4>& corners) {
  const glm::dvec3 c0(vertices[corners[0]]), c1(vertices[corners[1]]), c2(vertices[corners[2]]);
  AreaCentroid out;
  const double a1 = triangle_area(c0, c1, c2);
  const glm::dvec3 g1 = (c0 + c1 + c2) / 3.0;
  if (corners[3] == kNone) {
    out.area = a1;
    out.centroid = g1;
    return out;
  }
  const glm::dvec3 c3(vertices[corners[3]]);
  const double a2 = triangle_area(c0, c2, c3);
  const glm::dvec3 g2 = (c0 + c2 + c3) / 3.0;
  out.area = a1 + a2;
  out.centroid = out.area > 0.0 ? (a1 * g1 + a2 * g2) / out.area : (g1 + g2) * 0.5;
  return out;
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
  return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

// A convex piece of a polygon cut at contact lines, its corners counter-clockwise.
using Piece = std::vector<glm::dvec3>;

// Drops repeated corners (closer than `tolerance`), then corners on the straight line between
// their neighbours.
void clean_piece(Piece& piece, double tolerance) {
  Piece out;
  for (const glm::dvec3& x : piece)
    if (out.empty() || glm::length(x - out.back()) > tolerance) out.push_back(x);
  while (out.size() > 1 && glm::length(out.front() - out.back()) <= tolerance) out.pop_back();
  for (bool removed = true; removed && out.size() >= 3;) {
    removed = false;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const glm::dvec3 &a = out[(i + out.size() - 1) % out.size()], &b = out[i], &c = out[(i + 1) % out.size()];
      const glm::dvec3 ab = b - a, bc = c - b;
      if (glm::length(glm::cross(ab, bc)) <= tolerance * glm::length(c - a)) {
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
        removed = true;
        break;
      }
    }
  }
  piece = std::move(out);
}

// A convex planar polygon cut along contact lines into convex pieces, in double: each line
// splits every piece that has corners more than `tolerance` on both sides of it; corners within
// `tolerance` of a line go to both sides. Corners of the input stay exact (they are converted
// back to the same floats), so host vertices and polygon corners are still found bit for bit.
// Pieces come out in a fixed order (the lines' order, positive side first), without repeated
// or collinear corners.
std::vector<Piece> cut_polygon(const PolygonVertices& corners, const glm::vec3& normal,
                               const detail::ContactLine* lines, std::size_t line_count, double tolerance) {
  std::vector<Piece> pieces(1);
  for (const glm::vec3& c : corners) pieces[0].emplace_back(c);
  const glm::dvec3 n = glm::normalize(glm::dvec3(normal));
  std::vector<Piece> next;
  std::vector<double> d;
  for (std::size_t l = 0; l < line_count; ++l) {
    const glm::dvec3 across = glm::normalize(glm::cross(n, lines[l].direction));
    next.clear();
    for (Piece& piece : pieces) {
      d.clear();
      double lo = 0.0, hi = 0.0;
      for (const glm::dvec3& x : piece) {
        d.push_back(glm::dot(x - lines[l].point, across));
        lo = std::min(lo, d.back());
        hi = std::max(hi, d.back());
      }
      if (!(lo < -tolerance && hi > tolerance)) {
        next.push_back(std::move(piece));
        continue;
      }
      Piece positive, negative;
      for (std::size_t i = 0, count = piece.size(); i < count; ++i) {
        const std::size_t k = (i + 1) % count;
        if (d[i] >= -tolerance) positive.push_back(piece[i]);
        if (d[i] <= tolerance) negative.push_back(piece[i]);
        if ((d[i] > tolerance && d[k] < -tolerance) || (d[i] < -tolerance && d[k] > tolerance)) {
          // From the edge's lexicographically lower end, so that the two pieces that share this
          // edge (which run along it in opposite directions) get the same point when a later
          // line crosses it: their corners are then one vertex (Weld).
          const bool up = std::tie(piece[i].x, piece[i].y, piece[i].z) < std::tie(piece[k].x, piece[k].y, piece[k].z);
          const std::size_t from = up ? i : k, to = up ? k : i;
          const glm::dvec3 x = piece[from] + (piece[to] - piece[from]) * (d[from] / (d[from] - d[to]));
          positive.push_back(x);
          negative.push_back(x);
        }
      }
      for (Piece* side : {&positive, &negative}) {
        clean_piece(*side, 1e-3 * tolerance);
        if (side->size() >= 3) next.push_back(std::move(*side));
      }
    }
    std::swap(pieces, next);
  }
  return pieces;
}

// Checks one area option: 0 (derive) or a positive number; +inf is allowed and means "never split".
void check_area_option(float value, const char* field) {
  if (!(value >= 0.0f))
    throw Error(ErrorCode::invalid_argument,
                std::string("MeshOptions::") + field + " must be >= 0 (0 derives it), got " + std::to_string(value));
}

void check_crease_option(float value) {
  if (!(value >= 0.0f && value < 180.0f))
    throw Error(ErrorCode::invalid_argument,
                "MeshOptions::crease_angle_deg must be in [0, 180) degrees (0 shares no vertices between "
                "polygons), got " + std::to_string(value));
}

// Welding compares positions bit for bit: a shared vertex then sits exactly where each polygon's
// own corner or lattice point would have, so patches and elements (and every solve) do not
// depend on what is shared.
std::array<std::uint32_t, 3> position_bits(const glm::vec3& p) {
  std::array<std::uint32_t, 3> bits{};
  static_assert(sizeof(bits) == sizeof(glm::vec3), "glm::vec3 is three packed floats");
  std::memcpy(bits.data(), &p, sizeof(bits));
  return bits;
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) { return position_bits(a) == position_bits(b); }

// SplitMix64's finaliser: spreads the few bits in which neighbouring grid positions differ.
std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

std::uint64_t position_hash(const glm::vec3& p) {
  const std::array<std::uint32_t, 3> b = position_bits(p);
  return mix(((static_cast<std::uint64_t>(b[0]) << 32) | b[1]) ^ mix(b[2]));
}

// A contact segment a polygon is graded toward (grade_toward_contacts()).
struct GradeTarget {
  glm::dvec3 from, to;
  double size;    // elements touching it are split while larger
  double extent;  // the object's
  PolygonId other;
};
// A polygon's targets in a uniform grid of cells of twice its largest element (a forest on
// a plot has thousands of them, and a leaf is split only for those within twice its size).
struct GradedPolygon {
  PolygonId polygon = 0;
  double smallest_area = 0.0;  // kMaxGradeLevels below its largest element (less rounding)
  std::vector<GradeTarget> targets;
  double cell = 0.0;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;  // cell -> targets

  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    // 21 bits a coordinate: cells repeat every 2^21 (aliases only cost a few extra tests).
    constexpr std::uint64_t mask = (std::uint64_t{1} << 21) - 1;
    return (static_cast<std::uint64_t>(x) & mask) | ((static_cast<std::uint64_t>(y) & mask) << 21) |
           ((static_cast<std::uint64_t>(z) & mask) << 42);
  }
  std::int64_t at(double v) const { return static_cast<std::int64_t>(std::floor(v / cell)); }
  void index(double element) {
    cell = 2.0 * element;
    for (std::uint32_t t = 0; t < targets.size(); ++t) {
      const glm::dvec3 lo = glm::min(targets[t].from, targets[t].to), hi = glm::max(targets[t].from, targets[t].to);
      for (std::int64_t x = at(lo.x); x <= at(hi.x); ++x)
        for (std::int64_t y = at(lo.y); y <= at(hi.y); ++y)
          for (std::int64_t z = at(lo.z); z <= at(hi.z); ++z) grid[key(x, y, z)].push_back(t);
    }
  }
  /// Calls visit(target, gap) for the targets within `reach` of a leaf (centre, bounding
  /// radius) until it returns true; whether one did. A target may be visited twice.
  template <typename Visit>
  bool any_near(const glm::dvec3& centre, double radius, double reach, const Visit& visit) const {
    const glm::dvec3 lo = centre - (radius + reach), hi = centre + (radius + reach);
    for (std::int64_t x = at(lo.x); x <= at(hi.x); ++x)
      for (std::int64_t y = at(lo.y); y <= at(hi.y); ++y)
        for (std::int64_t z = at(lo.z); z <= at(hi.z); ++z) {
          const auto cell_targets = grid.find(key(x, y, z));
          if (cell_targets == grid.end()) continue;
          for (const std::uint32_t k : cell_targets->second) {
            const GradeTarget& t = targets[k];
            if (visit(t, std::max(0.0, distance_to_segment(centre, t.from, t.to) - radius))) return true;
          }
        }
    return false;
  }
  /// Whether a leaf (centre, bounding radius, edge) is to be split for a target near it
  /// (beyond edge / kGradeDistanceShare none splits it).
  bool wants_split(const glm::dvec3& centre, double radius, double edge) const {
    return any_near(centre, radius, edge / kGradeDistanceShare, [&](const GradeTarget& t, double gap) {
      return edge > t.size && edge > kGradeDistanceShare * gap;
    });
  }
};

// MeshOptions::grade_at_contacts, once every element fits max_element_area: the leaves of each
// polygon that has contact segments are split while they are larger than a quarter of the
// object standing there and than half their distance from it. Through the public interface
// (subdivide() keeps vertices shared and leaves() in a deterministic order). False when
// `keep_going` said no (polled per element visited).
template <typename KeepGoingFn>
bool grade_toward_contacts(PatchHierarchy& h, const Scene& scene, const std::vector<detail::ContactSegment>& segments,
                           const KeepGoingFn& keep_going, ContactGrading& report) {
  const std::vector<Polygon>& polygons = scene.polygons();
  // The size of what stands on a polygon: its group's largest extent, or the polygon's own when
  // both are in one group (a single-group file: its whole extent says nothing).
  std::vector<glm::vec3> lower(scene.groups().size(), glm::vec3(std::numeric_limits<float>::max()));
  std::vector<glm::vec3> upper(scene.groups().size(), glm::vec3(std::numeric_limits<float>::lowest()));
  for (const Polygon& p : polygons)
    for (const glm::vec3& v : p.vertices) {
      lower[p.group] = glm::min(lower[p.group], v);
      upper[p.group] = glm::max(upper[p.group], v);
    }
  auto extent = [](const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 d = hi - lo;
    return static_cast<double>(std::max({d.x, d.y, d.z}));
  };
  // Its extent decides whether to grade; the elements are then sized by its height off the
  // polygon's plane (its bounds' farthest corner), within [extent / 4, extent]: the shadow and
  // the darkening at the foot of a 3 m high, 10 m wide house are about 3 m across, while a flat
  // thing (a coaster, a rug smaller than an element) is not worth elements of its thickness.
  struct Object {
    double extent, size;
  };
  auto object_size = [&](PolygonId under, PolygonId object) {
    const Polygon& o = polygons[object];
    glm::vec3 lo = lower[o.group], hi = upper[o.group];
    if (o.group == polygons[under].group) {
      lo = hi = o.vertices[0];
      for (const glm::vec3& v : o.vertices) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
      }
    }
    const glm::dvec3 normal(polygons[under].normal), origin(polygons[under].vertices[0]);
    double height = 0.0;
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
      height = std::max(height, std::fabs(glm::dot(normal, corner - origin)));
    }
    const double across = extent(lo, hi);
    return Object{across, std::clamp(height, 0.25 * across, across)};
  };
  // Each polygon's largest element and its patches (patches are made in polygon order).
  std::vector<float> largest(polygons.size(), 0.0f);
  for (const std::uint32_t leaf : h.leaves()) {
    float& a = largest[h.patches()[h.element(leaf).patch].polygon];
    a = std::max(a, h.element(leaf).area);
  }
  std::vector<std::uint32_t> first_patch(polygons.size() + 1, 0);
  for (const Patch& p : h.patches()) ++first_patch[p.polygon + 1];
  std::partial_sum(first_patch.begin(), first_patch.end(), first_patch.begin());

  std::vector<GradedPolygon> graded;
  for (std::size_t k = 0; k < segments.size();) {
    const PolygonId id = segments[k].polygon;
    // Only where the polygon's elements are larger than the object: there its shadow and
    // contact cannot show. Smaller elements already resolve it about as well as the rest of
    // the scene (and a model cut into facets of one size, walls standing on ground facets,
    // stays as it is).
    const double element = std::sqrt(static_cast<double>(largest[id]));
    GradedPolygon g;
    g.polygon = id;
    g.smallest_area = static_cast<double>(largest[id]) / std::pow(4.0, kMaxGradeLevels) * (1.0 - 1e-3);
    for (; k < segments.size() && segments[k].polygon == id; ++k) {
      const Object o = object_size(id, segments[k].other);
      if (element > o.extent)
        g.targets.push_back(
            GradeTarget{segments[k].from, segments[k].to, kGradeTargetShare * o.size, o.extent, segments[k].other});
    }
    if (g.targets.empty()) continue;
    g.index(element);
    graded.push_back(std::move(g));
  }
  // Level by level over every graded polygon, so that when the budget runs out every contact
  // has been graded as far as the others (a village on a plot: each house's ground a level or
  // two finer, not the first houses' four levels and the rest none).
  const std::size_t budget = std::max(kGradeBudgetShare * h.leaves().size(), kMinGradeBudget);
  std::size_t added = 0;
  report.polygons = graded.size();
  std::vector<std::uint32_t> stack, split;
  // Calls leaf(g, id, centre, radius, edge) for every leaf of every graded polygon; false when
  // `keep_going` said no.
  auto for_each_leaf = [&](const auto& leaf) {
    for (const GradedPolygon& g : graded)
      for (std::uint32_t patch = first_patch[g.polygon]; patch < first_patch[g.polygon + 1]; ++patch) {
        stack.push_back(h.patches()[patch].root);
        while (!stack.empty()) {
          if (!keep_going()) return false;
          const std::uint32_t e = stack.back();
          stack.pop_back();
          const Element& element = h.element(e);
          if (!element.is_leaf()) {
            for (std::uint32_t c = 4; c-- > 0;) stack.push_back(element.first_child + c);
            continue;
          }
          const glm::dvec3 centre(element.centroid);
          double radius = 0.0;
          for (int c = 0; c < element.corner_count(); ++c)
            radius = std::max(radius, glm::length(glm::dvec3(h.vertices()[element.corners[c]]) - centre));
          leaf(g, e, centre, radius, std::sqrt(static_cast<double>(element.area)));
        }
      }
    return true;
  };
  while (!report.budget_reached) {
    split.clear();
    if (!for_each_leaf([&](const GradedPolygon& g, std::uint32_t e, const glm::dvec3& centre, double radius, double edge) {
          if (edge * edge / 4.0 >= g.smallest_area && g.wants_split(centre, radius, edge)) split.push_back(e);
        }))
      return false;
    if (split.empty()) break;
    for (const std::uint32_t e : split) {
      if (added + 3 > budget) {
        report.budget_reached = true;
        break;
      }
      h.subdivide(e);
      added += 3;
    }
  }
  report.added_leaves = added;
  // What the limits left coarser than the object: the largest leaf touching each contact.
  std::vector<ContactGrading::Coarse> coarse;
  if (!for_each_leaf([&](const GradedPolygon& g, std::uint32_t, const glm::dvec3& centre, double radius, double edge) {
        g.any_near(centre, radius, 0.0, [&](const GradeTarget& t, double gap) {
          if (gap > 0.0 || !(edge > t.extent)) return false;
          coarse.push_back(ContactGrading::Coarse{g.polygon, t.other, static_cast<float>(edge),
                                                  static_cast<float>(t.extent)});
          return false;
        });
      }))
    return false;
  // One per polygon and group standing on it: the largest leaf.
  auto group_of = [&](const ContactGrading::Coarse& c) { return polygons[c.other].group; };
  std::sort(coarse.begin(), coarse.end(), [&](const ContactGrading::Coarse& a, const ContactGrading::Coarse& b) {
    return std::make_tuple(a.polygon, group_of(a), -a.element, a.other) <
           std::make_tuple(b.polygon, group_of(b), -b.element, b.other);
  });
  for (const ContactGrading::Coarse& c : coarse)
    if (report.coarse.empty() || report.coarse.back().polygon != c.polygon || group_of(report.coarse.back()) != group_of(c))
      report.coarse.push_back(c);
  return true;
}

}  // namespace

struct PatchHierarchy::Edges {
  /// Edge (min vertex, max vertex) -> its midpoint vertex, for sharing and T-vertex handling.
  std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
  /// For a midpoint vertex, the edge it splits (kNone for lattice and centre vertices).
  std::vector<std::array<std::uint32_t, 2>> vertex_edge;
  /// Edges between smooth neighbours whose inner points are not shared (the two sides cut the
  /// edge into different numbers of segments, or their lattice points round differently):
  /// vertex_values() makes the field continuous along them. A seam is seam_sides[first ..
  /// first + count); a side is {its first point in seam_points, its segment count n}, and its
  /// n + 1 points run from the same end of the edge for every side of the seam.
  struct Seam {
    std::uint32_t first = 0, count = 0;
  };
  std::vector<Seam> seams;
  std::vector<std::array<std::uint32_t, 2>> seam_sides;
  std::vector<std::uint32_t> seam_points;
};

// Which polygon corners are one vertex and which polygon edges are one edge, found before
// meshing; then, while meshing, the vertices made for them. Triangles and quads that share an
// edge (the same two end positions, bit for bit) are smooth neighbours when they have the same
// material and group and their normals are within the crease angle; union-find over the
// (polygon, corner) pairs joined by smooth edges gives the corner classes, each one vertex.
// An edge's inner lattice points are shared when the next polygon cuts it into the same number
// of segments at the same positions; otherwise it gets a side of its own, and the edge becomes
// a seam (Edges).
struct PatchHierarchy::Weld {
  /// One polygon's cut of a shared edge: `count` segments from vertex `start` to `end`, its
  /// count - 1 inner points at inner[first_inner ..]; `next` is the edge's next side.
  struct Side {
    std::uint32_t start, end, count, first_inner, next;
  };

  /// Per polygon: the index of its corner 0 among all corners, kNone if it shares nothing
  /// (more than four corners, or welding is off). Empty when welding is off.
  std::vector<std::uint32_t> first_corner;
  std::vector<std::uint32_t> root;    ///< per corner: the first corner of its class
  std::vector<std::uint32_t> vertex;  ///< per class root: its vertex, once made
  std::vector<std::uint32_t> edge;    ///< per corner c: the shared edge from c to the next corner, or kNone
  std::uint32_t edge_count = 0;
  std::vector<std::uint32_t> first_side;  ///< per shared edge: its first side, or kNone
  std::vector<Side> sides;
  std::vector<std::uint32_t> inner;

  /// Scratch of the polygon being meshed: its lattice positions, their vertex ids, and the
  /// lattice indices along each edge from corner c to corner c + 1 (along[along_start[c] ..
  /// along_start[c + 1])).
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> ids;
  std::vector<std::uint32_t> along;
  std::array<std::uint32_t, 5> along_start{};
  std::uint32_t along_edges = 0;

  Weld() = default;
  /// Over `polygons` (the scene's: weld ids 0 ..) and `pieces` (triangles and quads of the cut
  /// polygons: weld ids polygons.size() + k), with `piece_contacts[k]` bit c set where piece
  /// k's edge from corner c lies along a contact (shared by nothing). `excluded` (empty, or one
  /// flag per scene polygon): polygons that share nothing (those meshed as pieces). `keep_going`
  /// (may be empty) is asked every so many items; when it says no, the weld stops unfinished.
  Weld(const std::vector<Polygon>& polygons, const std::vector<Polygon>& pieces,
       const std::vector<std::uint8_t>& piece_contacts, float crease_angle_deg, const std::vector<bool>& excluded,
       const detail::KeepGoing& keep_going);

  bool welded(PolygonId polygon) const { return !first_corner.empty() && first_corner[polygon] != kNone; }
  /// Records the edges that ended up with more than one side in `edges`, as seams.
  void make_seams(Edges& edges) const;
};

PatchHierarchy::Weld::Weld(const std::vector<Polygon>& scene_polygons, const std::vector<Polygon>& pieces,
                           const std::vector<std::uint8_t>& piece_contacts, float crease_angle_deg,
                           const std::vector<bool>& excluded, const detail::KeepGoing& keep_going) {
  // Weld ids: the scene's polygons, then the pieces of the cut ones.
  const std::size_t scene_count = scene_polygons.size(), total = scene_count + pieces.size();
  struct Polygons {
    const std::vector<Polygon>& scene;
    const std::vector<Polygon>& pieces;
    const Polygon& operator[](std::size_t p) const { return p < scene.size() ? scene[p] : pieces[p - scene.size()]; }
  } polygons{scene_polygons, pieces};
  // Every pass below is O(corners); a million triangles take about 0.5 s in all.
  auto stop = [&](std::size_t i) { return i % 16384 == 0 && keep_going && !keep_going(); };
  // `v` as n copies of `value`, made in steps with a check between: the first touch of tens of
  // megabytes takes a noticeable time (page faults). False when stopped.
  auto filled = [&](auto& v, std::size_t n, auto value) {
    constexpr std::size_t kStep = std::size_t{1} << 20;
    v.clear();
    v.reserve(n);
    for (std::size_t at = 0; at < n; at += kStep) {
      if (stop(0)) return false;
      v.insert(v.end(), std::min(kStep, n - at), value);
    }
    return true;
  };
  // Number the corners of the triangles and quads; a fan polygon shares nothing (its triangles
  // do not share vertices with each other either), nor does a polygon cut at contact lines
  // (its pieces, after the scene's polygons, are welded in its place).
  first_corner.assign(total, kNone);
  std::size_t corner_count = 0;
  for (std::size_t p = 0; p < total; ++p) {
    const std::size_t n = polygons[p].vertices.size();
    if ((n != 3 && n != 4) || (p < scene_count && !excluded.empty() && excluded[p])) continue;
    first_corner[p] = static_cast<std::uint32_t>(corner_count);
    corner_count += n;
    if (corner_count >= kNone)
      throw Error(ErrorCode::memory_budget, "PatchHierarchy: more polygon corners than 32-bit ids can index");
  }
  const auto count = static_cast<std::uint32_t>(corner_count);
  std::vector<std::uint32_t> polygon_of(count);
  for (std::size_t p = 0; p < total; ++p) {
    if (stop(p)) return;
    if (first_corner[p] != kNone)
      for (std::size_t c = 0; c < polygons[p].vertices.size(); ++c)
        polygon_of[first_corner[p] + c] = static_cast<std::uint32_t>(p);
  }
  auto next_corner = [&](std::uint32_t c) {
    const std::uint32_t p = polygon_of[c];
    return c + 1 < first_corner[p] + polygons[p].vertices.size() ? c + 1 : first_corner[p];
  };
  auto position_of = [&](std::uint32_t c) -> const glm::vec3& {
    return polygons[polygon_of[c]].vertices[c - first_corner[polygon_of[c]]];
  };
  // A piece's edge along a contact (a wall's foot): its two sides are lit differently, so it is
  // shared by nothing, as a crease.
  auto on_contact = [&](std::uint32_t c) {
    const std::uint32_t p = polygon_of[c];
    return p >= scene_count && ((piece_contacts[p - scene_count] >> (c - first_corner[p])) & 1u) != 0;
  };

  // 1. Number the distinct positions, in an open-addressing hash table of corner indices (load
  // at most 1/2), so that the rest compares small integers.
  std::vector<std::uint32_t> position(count);
  std::uint32_t distinct = 0;
  {
    std::size_t size = 16;
    while (size < 2 * corner_count) size *= 2;
    std::vector<std::uint32_t> table;  // a corner with that position
    if (!filled(table, size, kNone)) return;
    for (std::uint32_t c = 0; c < count; ++c) {
      if (stop(c)) return;
      const glm::vec3& q = position_of(c);
      std::size_t slot = static_cast<std::size_t>(position_hash(q)) & (size - 1);
      while (table[slot] != kNone && !same_bits(position_of(table[slot]), q)) slot = (slot + 1) & (size - 1);
      if (table[slot] == kNone) {
        table[slot] = c;
        position[c] = distinct++;
      } else {
        position[c] = position[table[slot]];
      }
    }
  }

  // 2. Group the edges by their two end positions: each edge goes into the bucket of its lower
  // end, keyed by (upper end, corner) so that sorting a bucket brings an edge's polygons
  // together in corner order (deterministic). O(corners) but for the sorts of buckets, which
  // hold a vertex's few edges.
  if (stop(0)) return;
  std::vector<std::uint32_t> bucket_start(static_cast<std::size_t>(distinct) + 1, 0);
  for (std::uint32_t c = 0; c < count; ++c) {
    if (stop(c)) return;
    const std::uint32_t a = position[c], b = position[next_corner(c)];
    if (a != b && !on_contact(c)) ++bucket_start[std::min(a, b) + 1];
  }
  std::partial_sum(bucket_start.begin(), bucket_start.end(), bucket_start.begin());
  std::vector<std::uint64_t> bucket;
  if (!filled(bucket, bucket_start.back(), std::uint64_t{0})) return;
  {
    std::vector<std::uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (std::uint32_t c = 0; c < count; ++c) {
      if (stop(c)) return;
      const std::uint32_t a = position[c], b = position[next_corner(c)];
      if (a != b && !on_contact(c)) bucket[fill[std::min(a, b)]++] = (static_cast<std::uint64_t>(std::max(a, b)) << 32) | c;
    }
  }

  // 3. Join the corners of smooth neighbours, and number each set of polygon edges joined by
  // smoothness (usually a pair) as one shared edge.
  const double cos_crease = std::cos(glm::radians(static_cast<double>(crease_angle_deg)));
  auto smooth = [&](std::uint32_t p, std::uint32_t q) {
    const Polygon &a = polygons[p], &b = polygons[q];
    return p != q && a.material == b.material && a.group == b.group &&
           static_cast<double>(glm::dot(a.normal, b.normal)) >= cos_crease;
  };
  if (!filled(root, count, 0u) || !filled(edge, count, kNone)) return;
  std::iota(root.begin(), root.end(), 0u);
  std::vector<std::uint32_t> local, members, local_edge;
  for (std::uint32_t v = 0; v < distinct; ++v) {
    if (stop(v)) return;
    const auto begin = bucket.begin() + bucket_start[v], end = bucket.begin() + bucket_start[v + 1];
    std::sort(begin, end);
    for (auto run = begin; run != end;) {
      auto run_end = run + 1;
      while (run_end != end && (*run_end >> 32) == (*run >> 32)) ++run_end;
      const auto r = static_cast<std::uint32_t>(run_end - run);
      if (r >= 2) {
        // Union-find among the run's edges too, for the rare edge with more than two polygons.
        local.resize(r);
        std::iota(local.begin(), local.end(), 0u);
        for (std::uint32_t i = 0; i < r; ++i)
          for (std::uint32_t j = i + 1; j < r; ++j) {
            const auto ci = static_cast<std::uint32_t>(run[i]), cj = static_cast<std::uint32_t>(run[j]);
            if (!smooth(polygon_of[ci], polygon_of[cj])) continue;
            const std::uint32_t ni = next_corner(ci), nj = next_corner(cj);
            if (position[ci] == position[cj]) {  // same direction (the polygons' orders disagree)
              detail::unite(root, ci, cj);
              detail::unite(root, ni, nj);
            } else {  // opposite directions: consistently oriented neighbours
              detail::unite(root, ci, nj);
              detail::unite(root, ni, cj);
            }
            detail::unite(local, i, j);
          }
        members.assign(r, 0);
        local_edge.assign(r, kNone);
        for (std::uint32_t i = 0; i < r; ++i) ++members[detail::find_root(local, i)];
        for (std::uint32_t i = 0; i < r; ++i) {
          const std::uint32_t l = detail::find_root(local, i);
          if (members[l] < 2) continue;
          if (local_edge[l] == kNone) local_edge[l] = edge_count++;
          edge[static_cast<std::uint32_t>(run[i])] = local_edge[l];
        }
      }
      run = run_end;
    }
  }
  for (std::uint32_t c = 0; c < count; ++c) {
    if (stop(c)) return;
    root[c] = detail::find_root(root, c);
  }
  vertex = std::move(position);  // reuse the memory
  std::fill(vertex.begin(), vertex.end(), kNone);
  first_side.assign(edge_count, kNone);
}

void PatchHierarchy::Weld::make_seams(Edges& edges) const {
  for (std::uint32_t e = 0; e < edge_count; ++e) {
    const std::uint32_t head = first_side[e];
    if (head == kNone || sides[head].next == kNone) continue;  // unused, or shared point for point
    Edges::Seam seam;
    seam.first = static_cast<std::uint32_t>(edges.seam_sides.size());
    for (std::uint32_t s = head; s != kNone; s = sides[s].next) {
      const Side& side = sides[s];
      const bool forward = side.start == sides[head].start;
      RADIOSITY_ASSERT(forward ? side.end == sides[head].end
                               : side.start == sides[head].end && side.end == sides[head].start);
      edges.seam_sides.push_back({static_cast<std::uint32_t>(edges.seam_points.size()), side.count});
      edges.seam_points.push_back(forward ? side.start : side.end);
      for (std::uint32_t m = 1; m < side.count; ++m)
        edges.seam_points.push_back(inner[side.first_inner + (forward ? m : side.count - m) - 1]);
      edges.seam_points.push_back(forward ? side.end : side.start);
      ++seam.count;
    }
    edges.seams.push_back(seam);
  }
}

PatchHierarchy::PatchHierarchy() : edges_(std::make_unique<Edges>()) {}
PatchHierarchy::~PatchHierarchy() = default;
PatchHierarchy::PatchHierarchy(PatchHierarchy&&) noexcept = default;
PatchHierarchy& PatchHierarchy::operator=(PatchHierarchy&&) noexcept = default;

PatchHierarchy::PatchHierarchy(const PatchHierarchy& other)
    : options_(other.options_),
      grading_(other.grading_),
      patches_(other.patches_),
      elements_(other.elements_),
      leaves_(other.leaves_),
      leaf_slot_(other.leaf_slot_),
      vertices_(other.vertices_),
      edges_(std::make_unique<Edges>(*other.edges_)) {}

PatchHierarchy& PatchHierarchy::operator=(const PatchHierarchy& other) {
  if (this != &other) *this = PatchHierarchy(other);
  return *this;
}

PatchHierarchy::PatchHierarchy(const Scene& scene, const MeshOptions& options) : PatchHierarchy() {
  build(scene, options, nullptr);
}

PatchHierarchy::PatchHierarchy(const Scene& scene, const MeshOptions& options, const ProgressFn& on_progress)
    : PatchHierarchy() {
  if (build(scene, options, on_progress ? &on_progress : nullptr)) return;
  grading_ = {};
  patches_ = {};
  elements_ = {};
  leaves_ = {};
  leaf_slot_ = {};
  vertices_ = {};
  edges_ = std::make_unique<Edges>();
}

bool PatchHierarchy::build(const Scene& scene, const MeshOptions& options, const ProgressFn* on_progress) {
  static const ProgressFn kSilent;
  detail::ProgressGate gate(on_progress ? *on_progress : kSilent);
  // Phase::meshing's fraction: contact lines and welding first, then the polygons (half), then
  // the subdivision of their patches. `due()` is a clock read: asked every kCheckEvery items.
  constexpr std::size_t kCheckEvery = 64;
  bool stopped = false;  // once the callback said no, it is not called again
  auto report = [&](double fraction, bool force = false) {
    if (stopped) return false;
    Progress p;
    p.phase = Phase::meshing;
    p.fraction = fraction;
    stopped = !gate.report(p, force);
    return !stopped;
  };
  if (!report(0.0, true)) return false;
  // Polled by the overlap search and the weld; empty without a callback (nothing to poll).
  detail::KeepGoing keep_going;
  if (on_progress) keep_going = [&] { return report(0.1); };
  check_area_option(options.max_patch_area, "max_patch_area");
  check_area_option(options.max_element_area, "max_element_area");
  check_crease_option(options.crease_angle_deg);
  const double total_area = scene.total_area();

  // Derive what was left at 0. A derived patch limit never undercuts an explicit element limit:
  // asking only for coarser elements should not be an error.
  options_ = options;
  if (options_.max_patch_area == 0.0f) {
    options_.max_patch_area = static_cast<float>(total_area / 512.0);
    options_.max_patch_area = std::max(options_.max_patch_area, options_.max_element_area);
  } else if (options_.max_element_area > options_.max_patch_area) {
    throw Error(ErrorCode::invalid_argument, "MeshOptions::max_element_area (" + std::to_string(options.max_element_area) +
                                                 ") must not exceed MeshOptions::max_patch_area (" +
                                                 std::to_string(options.max_patch_area) + ")");
  }
  if (options_.max_element_area == 0.0f) options_.max_element_area = options_.max_patch_area / 4.0f;

  if (scene.polygons().empty()) return report(1.0, true);
  if (!(options_.max_element_area > 0.0f))
    throw Error(ErrorCode::invalid_argument,
                "MeshOptions::max_element_area is 0 after derivation (the scene's polygons have no area)");
  // Leaves cover the scene at <= max_element_area each, and a full quadtree has ~4/3 nodes per leaf.
  const double estimate = total_area / static_cast<double>(options_.max_element_area) * (4.0 / 3.0);
  if (estimate > kMaxEstimatedElements)
    throw Error(ErrorCode::invalid_argument,
                "MeshOptions::max_element_area (" + std::to_string(options_.max_element_area) +
                    ") is too small for this scene: about " + std::to_string(static_cast<double>(estimate)) +
                    " elements would be created");

  const std::vector<Polygon>& polygons = scene.polygons();
  // Room for what the estimate says, so that the arrays do not grow by copying (a copy of a
  // hundred megabytes is a tenth of a second without a cancel check); untouched until used.
  const auto expected = static_cast<std::size_t>(std::min(estimate + static_cast<double>(polygons.size()), 6.7e7));
  elements_.reserve(expected);
  leaf_slot_.reserve(expected);
  leaves_.reserve(expected);
  vertices_.reserve(expected);
  patches_.reserve(polygons.size());
  // Contact lines, by polygon: [first_line[p], first_line[p + 1]) in `lines`. A polygon that
  // has any is cut along them into convex pieces, each meshed as quads where it allows (a
  // rectangle cut by a line parallel to its sides gives rectangles), else quads and a triangle
  // of a fan (mesh_quad() grids planar convex quads). The pieces are welded as polygons of their
  // own (with each other and with the neighbours whose edges they share whole), except along
  // the contacts, whose two sides are lit differently: without it, the pieces' vertex values
  // broke along every cut line, also where it runs on beyond the wall's foot that made it (faint
  // lines from a box's feet across an exported floor).
  std::vector<detail::ContactLine> lines;
  std::vector<detail::ContactSegment> segments;
  std::vector<std::uint32_t> first_line;
  std::vector<bool> cut;
  std::vector<Polygon> pieces;                // of the cut polygons, in polygon order
  std::vector<std::uint32_t> first_piece;     // per polygon: its pieces are [first_piece[p], first_piece[p + 1])
  std::vector<std::uint8_t> piece_contacts;   // per piece: bit c when its edge from corner c lies on a contact
  if (options_.split_at_contacts || options_.grade_at_contacts) {
    detail::Contacts contacts = detail::find_contacts(scene, keep_going);
    if (stopped) return false;
    if (options_.split_at_contacts) lines = std::move(contacts.lines);
    segments = std::move(contacts.segments);
  }
  if (options_.split_at_contacts) {
    const double tolerance = detail::touching_tolerance(scene);
    first_line.assign(polygons.size() + 1, 0);
    for (const detail::ContactLine& l : lines) ++first_line[l.polygon + 1];
    std::partial_sum(first_line.begin(), first_line.end(), first_line.begin());
    cut.assign(polygons.size(), false);
    for (const detail::ContactLine& l : lines) cut[l.polygon] = true;
    // The segments of each polygon (sorted by polygon), for the contacts of the pieces' edges.
    std::vector<std::uint32_t> first_segment(polygons.size() + 1, 0);
    for (const detail::ContactSegment& c : segments) ++first_segment[c.polygon + 1];
    std::partial_sum(first_segment.begin(), first_segment.end(), first_segment.begin());
    first_piece.assign(polygons.size() + 1, 0);
    for (PolygonId id = 0; id < polygons.size(); ++id) {
      first_piece[id] = static_cast<std::uint32_t>(pieces.size());
      if (!cut[id]) continue;
      if (id % kCheckEvery == 0 && keep_going && !keep_going()) return false;
      const Polygon& polygon = polygons[id];
      const std::size_t count = std::min<std::size_t>(first_line[id + 1] - first_line[id], kMaxContactLines);
      const detail::ContactLine* own = &lines[first_line[id]];
      // Whether the segment from a to b lies on a contact: on a line along which the other
      // polygon stands whole, or along one of this polygon's segments.
      auto on_contact = [&](const glm::dvec3& a, const glm::dvec3& b) {
        const glm::dvec3 m = 0.5 * (a + b);
        for (std::size_t l = 0; l < count; ++l) {
          const glm::dvec3 d = m - own[l].point;
          if (glm::length(d - glm::dot(d, own[l].direction) * own[l].direction) > 4.0 * tolerance) continue;
          if (own[l].whole) return true;
          for (std::uint32_t k = first_segment[id]; k < first_segment[id + 1]; ++k)
            if (distance_to_segment(m, segments[k].from, segments[k].to) <= 4.0 * tolerance) return true;
        }
        return false;
      };
      Polygon entry = polygon;
      for (const Piece& piece : cut_polygon(polygon.vertices, polygon.normal, own, count, tolerance)) {
        std::vector<glm::vec3> corners;
        for (const glm::dvec3& x : piece) corners.emplace_back(x);
        auto add = [&](std::initializer_list<std::size_t> at) {
          std::vector<glm::vec3> v;
          std::uint8_t contacts = 0;
          std::uint8_t bit = 1;
          for (auto c = at.begin(); c != at.end(); ++c, bit = static_cast<std::uint8_t>(bit << 1)) {
            v.push_back(corners[*c]);
            const std::size_t next = c + 1 == at.end() ? *at.begin() : *(c + 1);
            if (on_contact(piece[*c], piece[next])) contacts = static_cast<std::uint8_t>(contacts | bit);
          }
          entry.vertices = PolygonVertices(v.data(), v.size());
          pieces.push_back(entry);
          piece_contacts.push_back(contacts);
        };
        std::size_t i = 1;
        for (; i + 2 < corners.size(); i += 2) add({0, i, i + 1, i + 2});
        if (i + 1 < corners.size()) add({0, i, i + 1});
      }
    }
    first_piece[polygons.size()] = static_cast<std::uint32_t>(pieces.size());
    if (!report(0.1)) return false;
  }
  Weld weld = options_.crease_angle_deg > 0.0f
                  ? Weld(polygons, pieces, piece_contacts, options_.crease_angle_deg, cut, keep_going)
                  : Weld();
  if (stopped || !report(0.2)) return false;
  const auto weld_piece = static_cast<std::uint32_t>(polygons.size());  // the first piece's weld id
  for (PolygonId id = 0; id < polygons.size(); ++id) {
    if (id % kCheckEvery == 0 && gate.due(Phase::meshing) &&
        !report(0.2 + 0.5 * static_cast<double>(id) / static_cast<double>(polygons.size())))
      return false;
    const Polygon& polygon = polygons[id];
    const PolygonVertices& p = polygon.vertices;
    if (!cut.empty() && cut[id]) {
      for (std::uint32_t k = first_piece[id]; k < first_piece[id + 1]; ++k) {
        const PolygonVertices& q = pieces[k].vertices;
        if (q.size() == 4) mesh_quad(id, pieces[k], weld, weld_piece + k);
        else mesh_triangle(id, polygon, q[0], q[1], q[2], weld, weld_piece + k);
      }
    } else if (p.size() == 4) {
      mesh_quad(id, polygon, weld, id);
    } else if (p.size() == 3) {
      mesh_triangle(id, polygon, p[0], p[1], p[2], weld, id);
    } else {
      // A convex polygon with more vertices is a fan of triangles around vertex 0. Each triangle
      // gets its own lattice, so vertices are not shared across the fan diagonals: vertex values
      // may be discontinuous there (the same as at a crease). Such polygons are not welded.
      for (std::size_t i = 1; i + 1 < p.size(); ++i) mesh_triangle(id, polygon, p[0], p[i], p[i + 1], weld, id);
    }
  }
  weld.make_seams(*edges_);

  // Split each patch's root until every leaf fits max_element_area. Roots are visited in order
  // and their subtrees depth-first, so element ids and leaves() do not depend on anything else.
  // Subdivisions are counted for the cancel checks: one large polygon can make millions.
  std::vector<std::uint32_t> stack;
  std::size_t splits = 0;
  for (std::size_t patch = 0; patch < patches_.size(); ++patch) {
    stack.push_back(patches_[patch].root);
    while (!stack.empty()) {
      if (++splits % kCheckEvery == 0 && gate.due(Phase::meshing) &&
          !report(0.7 + 0.3 * static_cast<double>(patch) / static_cast<double>(patches_.size())))
        return false;
      const std::uint32_t e = stack.back();
      stack.pop_back();
      if (fits(elements_[e].area, options_.max_element_area)) continue;
      // An element that does not shrink when split: its corners are too close together for
      // single precision (a model far from the origin: a city at its UTM coordinates, where
      // floats are 0.5 apart), and splitting would go on to the depth limit. Found so: the
      // message was "element 2161 is at the maximum depth". 40 levels divide an area by 4^40
      // (1e24): no mesh within any memory budget is that fine.
      if (elements_[e].depth >= kMaxSplitDepth) {
        const Patch& stuck = patches_[elements_[e].patch];
        throw Error(ErrorCode::invalid_scene,
                    "polygon " + std::to_string(stuck.polygon) + " (group '" + scene.groups()[stuck.group] +
                        "') does not shrink into elements of max_element_area " +
                        std::to_string(options_.max_element_area) + " after " + std::to_string(kMaxSplitDepth) +
                        " splits: its corners are too close together for single precision (is the model far "
                        "from the origin for its size? load_scene() warns then)");
      }
      const std::uint32_t first = subdivide(e);
      for (std::uint32_t k = 4; k-- > 0;) stack.push_back(first + k);
    }
  }
  grading_ = ContactGrading{};
  if (options_.grade_at_contacts && !segments.empty() && !grade_toward_contacts(
                               *this, scene, segments,
                               [&] { return ++splits % kCheckEvery != 0 || !gate.due(Phase::meshing) || report(0.99); },
                               grading_))
    return false;
  return report(1.0, true);
}


std::uint32_t PatchHierarchy::add_vertex(const glm::vec3& position, std::uint32_t edge_a, std::uint32_t edge_b) {
  if (vertices_.size() >= kNone - 1)
    throw Error(ErrorCode::memory_budget, "PatchHierarchy: more vertices than 32-bit ids can index");
  vertices_.push_back(position);
  edges_->vertex_edge.push_back({edge_a, edge_b});
  return static_cast<std::uint32_t>(vertices_.size() - 1);
}

std::uint32_t PatchHierarchy::add_element(const Element& e) {
  if (elements_.size() >= kNone - 1)
    throw Error(ErrorCode::memory_budget, "PatchHierarchy: more elements than 32-bit ids can index");
  elements_.push_back(e);
  leaf_slot_.push_back(kNone);  // the caller registers it in leaves_
  return static_cast<std::uint32_t>(elements_.size() - 1);
}

std::uint32_t PatchHierarchy::midpoint(std::uint32_t a, std::uint32_t b) {
  // One midpoint per undirected edge: the neighbour on the other side of (a, b) finds the same
  // vertex, which keeps the mesh conforming where both sides are split and lets vertex_values()
  // recognise it as a T-vertex where only one side is.
  const std::uint64_t key = edge_key(a, b);
  const auto found = edges_->midpoints.find(key);
  if (found != edges_->midpoints.end()) return found->second;
  const std::uint32_t m = add_vertex(0.5f * (vertices_[a] + vertices_[b]), std::min(a, b), std::max(a, b));
  edges_->midpoints.emplace(key, m);
  return m;
}

void PatchHierarchy::add_patch(PolygonId polygon_id, const Polygon& polygon,
                               const std::array<std::uint32_t, 4>& corners) {
  const AreaCentroid g = cell_geometry(vertices_, corners);
  Element root;
  root.corners = corners;
  root.patch = static_cast<std::uint32_t>(patches_.size());
  root.centroid = glm::vec3(g.centroid);
  root.area = static_cast<float>(g.area);
  const std::uint32_t id = add_element(root);
  leaf_slot_[id] = static_cast<std::uint32_t>(leaves_.size());
  leaves_.push_back(id);

  Patch patch;
  patch.polygon = polygon_id;
  patch.material = polygon.material;
  patch.group = polygon.group;
  patch.normal = polygon.normal;
  patch.centroid = root.centroid;
  patch.area = root.area;
  patch.root = id;
  patches_.push_back(patch);
}

void PatchHierarchy::mesh_quad(PolygonId polygon_id, const Polygon& polygon, Weld& weld, std::uint32_t weld_id) {
  const PolygonVertices& p = polygon.vertices;
  const glm::dvec3 p0(p[0]), p1(p[1]), p2(p[2]), p3(p[3]);
  // Bilinear map P(s,t) = (1-s)(1-t)p0 + s(1-t)p1 + st p2 + (1-s)t p3; for a planar convex quad
  // its iso-lines are straight, so the grid cells are planar convex quads.
  auto at = [&](double s, double t) {
    return (1.0 - s) * (1.0 - t) * p0 + s * (1.0 - t) * p1 + s * t * p2 + (1.0 - s) * t * p3;
  };
  auto cell_area = [&](std::size_t i, std::size_t j, std::size_t nu, std::size_t nv) {
    const double s0 = double(i) / double(nu), s1 = double(i + 1) / double(nu);
    const double t0 = double(j) / double(nv), t1 = double(j + 1) / double(nv);
    const glm::dvec3 a = at(s0, t0), b = at(s1, t0), c = at(s1, t1), d = at(s0, t1);
    return triangle_area(a, b, c) + triangle_area(a, c, d);
  };

  // Near-square cells: divide each direction by the mean length of its two opposite edges.
  const double len_u = 0.5 * (glm::length(p1 - p0) + glm::length(p2 - p3));
  const double len_v = 0.5 * (glm::length(p3 - p0) + glm::length(p2 - p1));
  const double side = std::sqrt(static_cast<double>(options_.max_patch_area));
  std::size_t nu = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len_u / side)));
  std::size_t nv = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len_v / side)));
  // The area density |P_s x P_t| of a planar bilinear map is affine in (s,t) (the st term is
  // d x d = 0), so the largest cell is one of the four corner cells. Refine the direction with
  // the longer cells until that one fits.
  for (;;) {
    const double largest = std::max({cell_area(0, 0, nu, nv), cell_area(nu - 1, 0, nu, nv),
                                     cell_area(nu - 1, nv - 1, nu, nv), cell_area(0, nv - 1, nu, nv)});
    if (fits(largest, options_.max_patch_area)) break;
    if (len_u / double(nu) >= len_v / double(nv)) {
      ++nu;
    } else {
      ++nv;
    }
  }

  // Grid vertices, created once and shared by the patches around them.
  std::vector<glm::vec3>& q = weld.positions;
  q.clear();
  for (std::size_t j = 0; j <= nv; ++j)
    for (std::size_t i = 0; i <= nu; ++i) {
      // Use the input corners exactly so that patch borders on the polygon border are not moved.
      if (i == 0 && j == 0) q.push_back(p[0]);
      else if (i == nu && j == 0) q.push_back(p[1]);
      else if (i == nu && j == nv) q.push_back(p[2]);
      else if (i == 0 && j == nv) q.push_back(p[3]);
      else q.push_back(glm::vec3(at(double(i) / double(nu), double(j) / double(nv))));
    }
  auto index = [&](std::size_t i, std::size_t j) { return static_cast<std::uint32_t>(j * (nu + 1) + i); };
  std::vector<std::uint32_t>& ids = weld.ids;
  if (weld.welded(weld_id)) {
    // The four edges, each from its corner c to corner c + 1.
    weld.along.clear();
    weld.along_start[0] = 0;
    for (std::size_t i = 0; i <= nu; ++i) weld.along.push_back(index(i, 0));
    weld.along_start[1] = static_cast<std::uint32_t>(weld.along.size());
    for (std::size_t j = 0; j <= nv; ++j) weld.along.push_back(index(nu, j));
    weld.along_start[2] = static_cast<std::uint32_t>(weld.along.size());
    for (std::size_t i = nu + 1; i-- > 0;) weld.along.push_back(index(i, nv));
    weld.along_start[3] = static_cast<std::uint32_t>(weld.along.size());
    for (std::size_t j = nv + 1; j-- > 0;) weld.along.push_back(index(0, j));
    weld.along_start[4] = static_cast<std::uint32_t>(weld.along.size());
    weld.along_edges = 4;
    place_lattice(weld_id, q, weld, ids);
  } else {
    ids.clear();
    for (const glm::vec3& position : q) ids.push_back(add_vertex(position, kNone, kNone));
  }
  auto vid = [&](std::size_t i, std::size_t j) { return ids[index(i, j)]; };
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i)
      add_patch(polygon_id, polygon, {vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)});
}

void PatchHierarchy::mesh_triangle(PolygonId polygon_id, const Polygon& polygon, const glm::vec3& p0,
                                   const glm::vec3& p1, const glm::vec3& p2, Weld& weld, std::uint32_t weld_id) {
  const glm::dvec3 a(p0), b(p1), c(p2);
  const double area = triangle_area(a, b, c);
  // k x k similar sub-triangles, each of area area / k^2.
  const double limit = static_cast<double>(options_.max_patch_area);
  std::size_t k = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(std::sqrt(area / limit))));
  while (!fits(area / double(k * k), options_.max_patch_area)) ++k;

  // Lattice vertex (i, j), i + j <= k, at p0 + i/k (p1 - p0) + j/k (p2 - p0); row j holds k+1-j vertices.
  std::vector<glm::vec3>& q = weld.positions;
  q.clear();
  std::vector<std::uint32_t> row_start(k + 2);
  for (std::size_t j = 0; j <= k; ++j) {
    row_start[j] = static_cast<std::uint32_t>(q.size());
    for (std::size_t i = 0; i + j <= k; ++i) {
      if (i == 0 && j == 0) q.push_back(p0);
      else if (i == k) q.push_back(p1);
      else if (j == k) q.push_back(p2);
      else q.push_back(glm::vec3(a + (double(i) / double(k)) * (b - a) + (double(j) / double(k)) * (c - a)));
    }
  }
  auto index = [&](std::size_t i, std::size_t j) { return row_start[j] + static_cast<std::uint32_t>(i); };
  std::vector<std::uint32_t>& ids = weld.ids;
  if (weld.welded(weld_id)) {  // never a fan's triangle: fans are not welded
    weld.along.clear();
    weld.along_start[0] = 0;
    for (std::size_t i = 0; i <= k; ++i) weld.along.push_back(index(i, 0));
    weld.along_start[1] = static_cast<std::uint32_t>(weld.along.size());
    for (std::size_t j = 0; j <= k; ++j) weld.along.push_back(index(k - j, j));
    weld.along_start[2] = static_cast<std::uint32_t>(weld.along.size());
    for (std::size_t j = k + 1; j-- > 0;) weld.along.push_back(index(0, j));
    weld.along_start[3] = static_cast<std::uint32_t>(weld.along.size());
    weld.along_edges = 3;
    place_lattice(weld_id, q, weld, ids);
  } else {
    ids.clear();
    for (const glm::vec3& position : q) ids.push_back(add_vertex(position, kNone, kNone));
  }
  auto vid = [&](std::size_t i, std::size_t j) { return ids[index(i, j)]; };
  // "Up" triangles are translates of (p0, p1, p2), "down" ones are point reflections of it; both
  // keep the polygon's counter-clockwise orientation.
  for (std::size_t j = 0; j < k; ++j)
    for (std::size_t i = 0; i + j < k; ++i) {
      add_patch(polygon_id, polygon, {vid(i, j), vid(i + 1, j), vid(i, j + 1), kNone});
      if (i + j + 1 < k) add_patch(polygon_id, polygon, {vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1), kNone});
    }
}

void PatchHierarchy::place_lattice(std::uint32_t weld_id, const std::vector<glm::vec3>& positions, Weld& weld,
                                   std::vector<std::uint32_t>& ids) {
  ids.assign(positions.size(), kNone);
  const std::uint32_t first = weld.first_corner[weld_id];
  const std::uint32_t edge_count = weld.along_edges;
  // Corners: one vertex per class, made by the first polygon that reaches it.
  for (std::uint32_t c = 0; c < edge_count; ++c) {
    const std::uint32_t at = weld.along[weld.along_start[c]];
    std::uint32_t& v = weld.vertex[weld.root[first + c]];
    if (v == kNone) v = add_vertex(positions[at], kNone, kNone);
    RADIOSITY_ASSERT(same_bits(vertices_[v], positions[at]));
    ids[at] = v;
  }
  // Inner points of each edge: the points of an earlier side with the same cut (reversed if it
  // runs the other way), else new ones, which become a side of the edge.
  for (std::uint32_t c = 0; c < edge_count; ++c) {
    const std::uint32_t* points = weld.along.data() + weld.along_start[c];
    const std::uint32_t n = weld.along_start[c + 1] - weld.along_start[c] - 1;  // segments
    const std::uint32_t start = ids[points[0]], end = ids[points[n]];
    const std::uint32_t shared = weld.edge[first + c];
    bool found = false;
    if (shared != kNone) {
      for (std::uint32_t s = weld.first_side[shared]; s != kNone && !found; s = weld.sides[s].next) {
        const Weld::Side& side = weld.sides[s];
        if (side.count != n) continue;
        RADIOSITY_ASSERT((side.start == start && side.end == end) || (side.start == end && side.end == start));
        const bool forward = side.start == start;
        auto inner = [&](std::uint32_t m) { return weld.inner[side.first_inner + (forward ? m : n - m) - 1]; };
        found = true;
        for (std::uint32_t m = 1; m < n && found; ++m) found = same_bits(vertices_[inner(m)], positions[points[m]]);
        if (found)
          for (std::uint32_t m = 1; m < n; ++m) ids[points[m]] = inner(m);
      }
    }
    if (found) continue;
    const auto first_inner = static_cast<std::uint32_t>(weld.inner.size());
    for (std::uint32_t m = 1; m < n; ++m) {
      ids[points[m]] = add_vertex(positions[points[m]], kNone, kNone);
      if (shared != kNone) weld.inner.push_back(ids[points[m]]);
    }
    if (shared != kNone) {
      weld.sides.push_back({start, end, n, first_inner, weld.first_side[shared]});
      weld.first_side[shared] = static_cast<std::uint32_t>(weld.sides.size() - 1);
    }
  }
  // The polygon's own inner points.
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (ids[i] == kNone) ids[i] = add_vertex(positions[i], kNone, kNone);
}

std::uint32_t PatchHierarchy::subdivide(std::uint32_t element) {
  if (element >= elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::subdivide: element " + std::to_string(element) +
                                                 " is out of range (" + std::to_string(elements_.size()) +
                                                 " elements)");
  if (!elements_[element].is_leaf())
    throw Error(ErrorCode::invalid_argument,
                "PatchHierarchy::subdivide: element " + std::to_string(element) + " is not a leaf");
  if (elements_[element].depth == std::numeric_limits<std::uint8_t>::max())
    throw Error(ErrorCode::invalid_argument,
                "PatchHierarchy::subdivide: element " + std::to_string(element) + " is at the maximum depth");

  // Copy: add_element() below may reallocate elements_.
  const Element parent = elements_[element];
  const std::array<std::uint32_t, 4>& c = parent.corners;
  std::array<std::array<std::uint32_t, 4>, 4> kids;
  if (parent.corner_count() == 4) {
    const std::uint32_t m01 = midpoint(c[0], c[1]), m12 = midpoint(c[1], c[2]);
    const std::uint32_t m23 = midpoint(c[2], c[3]), m30 = midpoint(c[3], c[0]);
    // The mean of the corners is the bilinear centre, so children are the bilinear sub-cells.
    const glm::vec3 centre = 0.25f * (vertices_[c[0]] + vertices_[c[1]] + vertices_[c[2]] + vertices_[c[3]]);
    const std::uint32_t ctr = add_vertex(centre, kNone, kNone);
    kids = {{{c[0], m01, ctr, m30}, {m01, c[1], m12, ctr}, {ctr, m12, c[2], m23}, {m30, ctr, m23, c[3]}}};
  } else {
    const std::uint32_t m01 = midpoint(c[0], c[1]), m12 = midpoint(c[1], c[2]), m20 = midpoint(c[2], c[0]);
    kids = {{{c[0], m01, m20, kNone}, {m01, c[1], m12, kNone}, {m20, m12, c[2], kNone}, {m01, m12, m20, kNone}}};
  }

  const std::uint32_t first = static_cast<std::uint32_t>(elements_.size());
  for (const auto& corners : kids) {
    const AreaCentroid g = cell_geometry(vertices_, corners);
    Element child;
    child.corners = corners;
    child.patch = parent.patch;
    child.parent = element;
    child.depth = static_cast<std::uint8_t>(parent.depth + 1);
    child.centroid = glm::vec3(g.centroid);
    child.area = static_cast<float>(g.area);
    add_element(child);
  }
  elements_[element].first_child = first;

  // The first child takes the parent's slot in leaves_, the others go to the end, so the order
  // depends only on the sequence of subdivide() calls.
  const std::uint32_t slot = leaf_slot_[element];
  leaves_[slot] = first;
  leaf_slot_[first] = slot;
  leaf_slot_[element] = kNone;
  for (std::uint32_t k = 1; k < 4; ++k) {
    leaf_slot_[first + k] = static_cast<std::uint32_t>(leaves_.size());
    leaves_.push_back(first + k);
  }
  return first;
}

glm::vec3 PatchHierarchy::sample_point(std::uint32_t element, glm::vec2 uv) const {
  // The estimators' warp (core/sampling.hpp): area-uniform, and (u,v) strata stay compact cells
  // of equal area on quads too.
  const Element& e = elements_[element];
  std::array<glm::vec3, 4> corners{};
  for (int k = 0; k < e.corner_count(); ++k)
    corners[static_cast<std::size_t>(k)] = vertices_[e.corners[static_cast<std::size_t>(k)]];
  return detail::CellSampler(corners.data(), e.corner_count())(uv);
}

std::vector<Rgb> PatchHierarchy::vertex_values(const std::vector<Rgb>& element_values,
                                               const std::vector<float>& exposure) const {
  if (element_values.size() != elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::vertex_values: element_values has " +
                                                 std::to_string(element_values.size()) + " entries, expected " +
                                                 std::to_string(elements_.size()) + " (one per element)");
  if (!exposure.empty() && exposure.size() != elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::vertex_values: exposure has " +
                                                 std::to_string(exposure.size()) + " entries, expected " +
                                                 std::to_string(elements_.size()) + " (one per element, or none)");
  // Mean of the leaves around each vertex weighted by their open area. Accumulating in double
  // makes a constant field come back exactly after rounding to float.
  std::vector<glm::dvec3> sum(vertices_.size(), glm::dvec3(0.0));
  std::vector<double> weight(vertices_.size(), 0.0);
  for (const std::uint32_t id : leaves_) {
    const Element& e = elements_[id];
    const glm::dvec3 value(element_values[id]);
    const double w = static_cast<double>(e.area) * (exposure.empty() ? 1.0 : static_cast<double>(exposure[id]));
    for (int k = 0; k < e.corner_count(); ++k) {
      sum[e.corners[k]] += w * value;
      weight[e.corners[k]] += w;
    }
  }
  // Seams (smooth neighbours whose edge points are not shared): with side counts n_s and g
  // their gcd, every side has a point at each multiple of 1/g of the edge, the common knots.
  // Those take the mean over all sides, as one shared vertex would.
  const Edges& edges = *edges_;
  auto seam_gcd = [&](const Edges::Seam& seam) {
    std::uint32_t g = 0;
    for (std::uint32_t s = seam.first; s < seam.first + seam.count; ++s) g = std::gcd(g, edges.seam_sides[s][1]);
    return g;
  };
  for (const Edges::Seam& seam : edges.seams) {
    const std::uint32_t g = seam_gcd(seam);
    for (std::uint32_t m = 1; m < g; ++m) {
      glm::dvec3 knot_sum(0.0);
      double knot_weight = 0.0;
      for (std::uint32_t s = seam.first; s < seam.first + seam.count; ++s) {
        const std::uint32_t v = edges.seam_points[edges.seam_sides[s][0] + m * edges.seam_sides[s][1] / g];
        knot_sum += sum[v];
        knot_weight += weight[v];
      }
      for (std::uint32_t s = seam.first; s < seam.first + seam.count; ++s) {
        const std::uint32_t v = edges.seam_points[edges.seam_sides[s][0] + m * edges.seam_sides[s][1] / g];
        sum[v] = knot_sum;
        weight[v] = knot_weight;
      }
    }
  }

  std::vector<Rgb> out(vertices_.size(), Rgb(0.0f));
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (weight[v] > 0.0) out[v] = Rgb(sum[v] / weight[v]);
  if (!exposure.empty()) dilate_into_buried(elements_, leaves_, weight, out);

  // Every other point of a seam side, its lattice points and the midpoints subdivision made
  // along it, gets the linear interpolation between the common knots around it: then each side
  // is the same line between knots, the T-vertex rule below with the knots for the coarse edge's
  // ends. (Seam points are never hanging unless two polygons share a side; then that rule gives
  // them the same line.)
  struct Span {
    std::uint32_t a, b;
    double ta, tb;  ///< along the edge, in segments of the side
  };
  std::vector<Span> spans;
  for (const Edges::Seam& seam : edges.seams) {
    const std::uint32_t g = seam_gcd(seam);
    for (std::uint32_t s = seam.first; s < seam.first + seam.count; ++s) {
      const std::uint32_t* points = edges.seam_points.data() + edges.seam_sides[s][0];
      const std::uint32_t n = edges.seam_sides[s][1];
      for (std::uint32_t i = 0; i < n; ++i) {
        // Segment i lies between the knots at points lo n/g and (lo + 1) n/g.
        const std::uint32_t lo = i * g / n;
        const glm::dvec3 k0(out[points[lo * n / g]]), k1(out[points[(lo + 1) * n / g]]);
        auto line = [&](double t) {
          const double w = t * g / n - lo;
          return Rgb((1.0 - w) * k0 + w * k1);
        };
        if (i * g % n != 0) out[points[i]] = line(i);
        spans.push_back({points[i], points[i + 1], double(i), double(i + 1)});
        while (!spans.empty()) {
          const Span span = spans.back();
          spans.pop_back();
          const auto found = edges.midpoints.find(edge_key(span.a, span.b));
          if (found == edges.midpoints.end()) continue;
          const double t = 0.5 * (span.ta + span.tb);
          out[found->second] = line(t);
          spans.push_back({span.a, found->second, span.ta, t});
          spans.push_back({found->second, span.b, t, span.tb});
        }
      }
    }
  }

  // T-vertices (Baum et al. 1991): a midpoint of a leaf's edge, and recursively any midpoint of
  // the halves of such an edge, lies on a coarse edge that interpolates only its two endpoints.
  // Setting each to the mean of the endpoints of the edge it splits makes both sides agree.
  std::vector<bool> hanging(vertices_.size(), false);
  std::vector<std::array<std::uint32_t, 2>> leaf_edges;
  for (const std::uint32_t id : leaves_) {
    const Element& e = elements_[id];
    const int n = e.corner_count();
    for (int k = 0; k < n; ++k) {
      leaf_edges.push_back({e.corners[k], e.corners[(k + 1) % n]});
      while (!leaf_edges.empty()) {
        const std::array<std::uint32_t, 2> ab = leaf_edges.back();
        leaf_edges.pop_back();
        const auto found = edges.midpoints.find(edge_key(ab[0], ab[1]));
        if (found == edges.midpoints.end() || hanging[found->second]) continue;
        const std::uint32_t m = found->second;
        hanging[m] = true;
        leaf_edges.push_back({ab[0], m});
        leaf_edges.push_back({m, ab[1]});
      }
    }
  }
  // midpoint(a, b) creates m after a and b exist, so m > a, b: in increasing id order the
  // endpoints of every hanging vertex, hanging or not, already hold their final values.
  for (std::size_t m = 0; m < vertices_.size(); ++m) {
    if (!hanging[m]) continue;
    const std::array<std::uint32_t, 2>& ab = edges.vertex_edge[m];
    out[m] = 0.5f * (out[ab[0]] + out[ab[1]]);
  }
  return out;
}

void PatchHierarchy::aggregate(std::vector<Rgb>& element_values) const {
  if (element_values.size() != elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::aggregate: element_values has " +
                                                 std::to_string(element_values.size()) + " entries, expected " +
                                                 std::to_string(elements_.size()) + " (one per element)");
  // Children always have larger ids than their parent, so a reverse sweep sees every child's
  // final value before the parent's.
  for (std::size_t id = elements_.size(); id-- > 0;) {
    const Element& e = elements_[id];
    if (e.is_leaf()) continue;
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::uint32_t k = 0; k < 4; ++k) {
      const Element& child = elements_[e.first_child + k];
      sum += static_cast<double>(child.area) * glm::dvec3(element_values[e.first_child + k]);
      area += static_cast<double>(child.area);
    }
    element_values[id] = area > 0.0 ? Rgb(sum / area) : Rgb(0.0f);
  }
}

}  // namespace v1
}  // namespace radiosity
