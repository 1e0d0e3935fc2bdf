// Coincident and interpenetrating polygons, and the lines where polygons meet others' interiors.
// Based on: T. Möller, "A fast triangle-triangle intersection test", Journal of Graphics Tools
// 2(2), 1997 (signed distances to the other plane, the line where the planes meet and the
// overlap of the two intervals on it), here for convex polygons with a tolerance; I. E.
// Sutherland, G. W. Hodgman, "Reentrant polygon clipping", CACM 17(1), 1974 (the overlap of
// coplanar polygons); the broad phase is Embree's BVH collision query (rtcCollide, Embree 3.13;
// Wald et al., "Embree: A Kernel Framework for Efficient CPU Ray Tracing", ACM TOG 33(4), 2014).
//
// Two convex planar polygons a and b conflict in one of two ways:
// - coincident: one lies within the tolerance of the other's plane and their interiors overlap.
//   Both are projected into that plane and shrunk by the tolerance (every edge moved inwards);
//   they overlap when something of the intersection survives. Shared edges, shared corners and
//   gaps thinner than the tolerance do not survive.
// - interpenetrating: each has corners strictly on both sides of the other's plane (so neither
//   merely touches the other with an edge or a corner: a block standing on a floor, a
//   T-junction) and the two chords cut from them by the line where the planes meet overlap by
//   more than the tolerance (so the crossing is inside both).
// The same broad phase finds contact lines (find_contacts()): where b stands on a or passes
// through it along a segment that crosses a from border to border (a partition on a floor).
// Meshes are cut along them so that no element or interpolated vertex straddles a line where
// the light changes abruptly: D. R. Baum, S. Mann, K. P. Smith & J. M. Winget, "Making radiosity
// usable: automatic preprocessing and meshing techniques for the generation of accurate
// radiosity solutions", SIGGRAPH 1991 (surfaces split where others meet them, against light
// and shadow leaks).
#include "scene/overlap.hpp"
#include "core/text.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "geometry/ray_scene.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

namespace {

struct Plane {
  glm::dvec3 normal{0.0};
  double offset = 0.0;    ///< mean of dot(normal, corner)
  double flatness = 0.0;  ///< largest distance of a corner from the plane (the polygon's non-planarity)
};

struct Search {
  const std::vector<Polygon>* polygons = nullptr;
  std::vector<Plane> planes;
  std::vector<glm::vec3> lower, upper;  ///< bounds grown by the tolerance
  double tolerance = 0.0;
  bool contacts = false;  ///< looking for contacts (find_contacts()) rather than overlaps
  std::atomic<bool> stop{false};  ///< the caller's KeepGoing said no: pairs are skipped
  std::mutex mutex;
  std::vector<PolygonOverlap> found;
  std::vector<ContactLine> lines;
  std::vector<ContactSegment> segments;
};

using Points2 = std::vector<glm::dvec2>;

double signed_area(const Points2& p) {
  double a = 0.0;
  for (std::size_t i = 0, n = p.size(); i < n; ++i) {
    const glm::dvec2 &u = p[i], &v = p[(i + 1) % n];
    a += u.x * v.y - v.x * u.y;
  }
  return 0.5 * a;
}

// Keeps the part of `poly` where dot(x - origin, inward) >= margin (Sutherland & Hodgman).
void clip(Points2& poly, Points2& scratch, glm::dvec2 origin, glm::dvec2 inward, double margin) {
  scratch.clear();
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec2 &p = poly[i], &q = poly[(i + 1) % n];
    const double dp = glm::dot(p - origin, inward) - margin, dq = glm::dot(q - origin, inward) - margin;
    if (dp >= 0.0) scratch.push_back(p);
    if ((dp >= 0.0) != (dq >= 0.0)) scratch.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  std::swap(poly, scratch);
}

// The coplanar case: both polygons in the frame of `plane`, each shrunk by the tolerance; true
// (and the middle of what remains) when their shrunk interiors overlap.
bool coplanar_overlap(const Polygon& a, const Polygon& b, const Plane& plane, double tolerance, glm::vec3& where) {
  thread_local Points2 pa, pb, region, scratch;
  const glm::dvec3 n = plane.normal;
  const glm::dvec3 e1 = glm::normalize(std::fabs(n.x) < 0.6 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                                            : glm::cross(n, glm::dvec3(0, 1, 0)));
  const glm::dvec3 e2 = glm::cross(n, e1);
  const glm::dvec3 origin(b.vertices[0]);
  auto project = [&](const Polygon& p, Points2& out) {
    out.clear();
    for (const glm::vec3& v : p.vertices) {
      const glm::dvec3 d = glm::dvec3(v) - origin;
      out.emplace_back(glm::dot(d, e1), glm::dot(d, e2));
    }
    if (signed_area(out) < 0.0) std::reverse(out.begin(), out.end());  // faces the other way
  };
  project(a, pa);
  project(b, pb);
  region = pa;
  for (const Points2* p : {&pa, &pb}) {
    for (std::size_t i = 0, m = p->size(); i < m && region.size() >= 3; ++i) {
      const glm::dvec2 u = (*p)[i], edge = (*p)[(i + 1) % m] - u;
      const double length = glm::length(edge);
      if (!(length > 0.0)) continue;
      clip(region, scratch, u, glm::dvec2(-edge.y, edge.x) / length, tolerance);
    }
  }
  // What survives is at least `tolerance` inside both; a tiny remainder is rounding.
  if (region.size() < 3 || signed_area(region) <= 1e-3 * tolerance * tolerance) return false;
  // The area centroid (clipping leaves repeated corners, which would bias a mean of corners).
  glm::dvec2 c(0.0);
  for (std::size_t i = 0, count = region.size(); i < count; ++i) {
    const glm::dvec2 &u = region[i], &v = region[(i + 1) % count];
    c += (u + v) * (u.x * v.y - v.x * u.y);
  }
  c /= 6.0 * signed_area(region);
  where = glm::vec3(origin + c.x * e1 + c.y * e2);
  return true;
}

// Signed distances of a polygon's corners to a plane, with their extremes.
struct Side {
  double lo = 0.0, hi = 0.0;
};
Side distances(const Polygon& p, const Plane& plane, std::vector<double>& d) {
  d.clear();
  Side s{1e300, -1e300};
  for (const glm::vec3& v : p.vertices) {
    d.push_back(glm::dot(plane.normal, glm::dvec3(v)) - plane.offset);
    s.lo = std::min(s.lo, d.back());
    s.hi = std::max(s.hi, d.back());
  }
  return s;
}

// The chord that the other polygon's plane cuts from `p` (corner distances `d` to that plane),
// as parameters along `axis` and the points where they are reached.
struct Chord {
  double lo = 1e300, hi = -1e300;
  glm::dvec3 at_lo{0.0}, at_hi{0.0};
};
Chord chord(const Polygon& p, const std::vector<double>& d, const glm::dvec3& axis) {
  Chord c;
  for (std::size_t i = 0, n = p.vertices.size(); i < n; ++i) {
    const std::size_t k = (i + 1) % n;
    if ((d[i] > 0.0) == (d[k] > 0.0)) continue;
    const glm::dvec3 u(p.vertices[i]), v(p.vertices[k]);
    const glm::dvec3 x = u + (v - u) * (d[i] / (d[i] - d[k]));
    const double t = glm::dot(x, axis);
    if (t < c.lo) c.lo = t, c.at_lo = x;
    if (t > c.hi) c.hi = t, c.at_hi = x;
  }
  return c;
}

bool test_pair(const Search& s, PolygonId ia, PolygonId ib, PolygonOverlap& out) {
  const Polygon& a = (*s.polygons)[ia];
  const Polygon& b = (*s.polygons)[ib];
  const Plane& pa = s.planes[ia];
  const Plane& pb = s.planes[ib];
  thread_local std::vector<double> da, db;
  const Side sa = distances(a, pb, da);  // a's corners against b's plane
  const Side sb = distances(b, pa, db);
  const double ta = s.tolerance + pb.flatness, tb = s.tolerance + pa.flatness;
  out.first = ia;
  out.second = ib;
  out.same_facing = glm::dot(a.normal, b.normal) > 0.0f;

  const bool a_in_b = sa.lo >= -ta && sa.hi <= ta, b_in_a = sb.lo >= -tb && sb.hi <= tb;
  if (a_in_b || b_in_a) {
    out.kind = OverlapKind::coincident;
    return coplanar_overlap(a, b, a_in_b ? pb : pa, s.tolerance, out.point);
  }
  // Each must reach through the other's plane; one that only touches it cannot cross it.
  if (!(sa.lo < -ta && sa.hi > ta && sb.lo < -tb && sb.hi > tb)) return false;
  glm::dvec3 axis = glm::cross(pa.normal, pb.normal);
  const double length = glm::length(axis);
  if (!(length > 1e-12)) return false;
  axis /= length;
  const Chord ca = chord(a, da, axis), cb = chord(b, db, axis);
  const double lo = std::max(ca.lo, cb.lo), hi = std::min(ca.hi, cb.hi);
  if (!(hi - lo > s.tolerance)) return false;
  out.kind = OverlapKind::interpenetrating;
  out.point = glm::vec3(0.5 * ((ca.lo > cb.lo ? ca.at_lo : cb.at_lo) + (ca.hi < cb.hi ? ca.at_hi : cb.at_hi)));
  return true;
}

// Where `b` divides `a` along a line: b stands on a (an edge of b lies in a's plane, the rest
// of b on one side) or passes through it, along a segment that runs inside a (more than the
// tolerance from its border: not a wall meeting a floor at the floor's edge, a T-junction)
// from border to border. Coplanar pairs have no such line. A contact that ends inside a (a
// block's side on a floor) is a segment instead (`segment` true, `part` set): cutting along
// its whole chord would spread slivers over the floor, so the mesh is graded toward it.
bool contact_of(const Search& s, PolygonId ia, PolygonId ib, ContactLine& out, bool& segment, ContactSegment& part) {
  segment = false;
  const Polygon& a = (*s.polygons)[ia];
  const Polygon& b = (*s.polygons)[ib];
  const Plane& pa = s.planes[ia];
  thread_local std::vector<double> db;
  const Side sb = distances(b, pa, db);
  const double tb = s.tolerance + pa.flatness;
  if (sb.lo >= -tb && sb.hi <= tb) return false;  // coplanar
  if (sb.lo > tb || sb.hi < -tb) return false;    // b does not reach a's plane
  glm::dvec3 axis = glm::cross(pa.normal, glm::normalize(glm::dvec3(b.normal)));
  const double length = glm::length(axis);
  if (!(length > 1e-6)) return false;
  axis /= length;
  // The segment of b in a's plane: its corners within the tolerance and its edges' crossings.
  double lo = 1e300, hi = -1e300;
  glm::dvec3 at{0.0};
  auto take = [&](const glm::dvec3& x) {
    const double t = glm::dot(x, axis);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    at = x;
  };
  for (std::size_t i = 0, n = b.vertices.size(); i < n; ++i) {
    const std::size_t k = (i + 1) % n;
    if (std::fabs(db[i]) <= tb) take(glm::dvec3(b.vertices[i]));
    if ((db[i] > tb && db[k] < -tb) || (db[i] < -tb && db[k] > tb)) {
      const glm::dvec3 u(b.vertices[i]), v(b.vertices[k]);
      take(u + (v - u) * (db[i] / (db[i] - db[k])));
    }
  }
  if (!(hi - lo > s.tolerance)) return false;
  // Project a point of the segment into a's plane; the line is origin + t axis there.
  const glm::dvec3 origin = at - (glm::dot(pa.normal, at) - pa.offset) * pa.normal - glm::dot(at, axis) * axis;
  // a's chord along the line, shrunk by the tolerance (a is convex, counter-clockwise around
  // its normal: each edge's inward direction is normal x edge).
  double chord_lo = -1e300, chord_hi = 1e300;
  for (std::size_t i = 0, n = a.vertices.size(); i < n; ++i) {
    const glm::dvec3 u(a.vertices[i]), v(a.vertices[(i + 1) % n]);
    const glm::dvec3 edge = v - u;
    const double edge_length = glm::length(edge);
    if (!(edge_length > 0.0)) continue;
    const glm::dvec3 inward = glm::cross(pa.normal, edge) / edge_length;
    // dot(origin + t axis - u, inward) >= tolerance
    const double c0 = glm::dot(origin - u, inward) - s.tolerance, c1 = glm::dot(axis, inward);
    if (std::fabs(c1) < 1e-12) {
      if (c0 < 0.0) return false;  // the line runs along a's border or outside it
      continue;
    }
    const double t = -c0 / c1;
    if (c1 > 0.0) chord_lo = std::max(chord_lo, t);
    else chord_hi = std::min(chord_hi, t);
  }
  if (!(chord_hi - chord_lo > s.tolerance)) return false;
  // b must cover the whole chord: it divides a in two. A block standing on a floor covers part
  // of a chord only; rays already find what it hides (docs/ARCHITECTURE.md, "Contact"), and
  // cutting along whole chords there would spread slivers over the floor.
  if (lo > chord_lo + 2.0 * s.tolerance || hi < chord_hi - 2.0 * s.tolerance) {
    lo = std::max(lo, chord_lo);
    hi = std::min(hi, chord_hi);
    if (!(hi - lo > s.tolerance)) return false;  // it meets a's plane outside a
    segment = true;
    part.polygon = ia;
    part.other = ib;
    part.from = origin + lo * axis;
    part.to = origin + hi * axis;
    return false;
  }
  lo = chord_lo;
  hi = chord_hi;
  out.polygon = ia;
  out.point = origin + 0.5 * (lo + hi) * axis;
  out.direction = axis;
  return true;
}

// Polygon `id`'s distance inside its border from `x` (a point in its plane): the least over its
// edges of the distance to the edge's line, negative outside.
double depth_inside(const Search& s, PolygonId id, const glm::dvec3& x) {
  const Polygon& a = (*s.polygons)[id];
  const glm::dvec3& normal = s.planes[id].normal;
  double depth = 1e300;
  for (std::size_t i = 0, n = a.vertices.size(); i < n; ++i) {
    const glm::dvec3 u(a.vertices[i]), v(a.vertices[(i + 1) % n]);
    const double edge_length = glm::length(v - u);
    if (!(edge_length > 0.0)) continue;
    depth = std::min(depth, glm::dot(x - u, glm::cross(normal, v - u) / edge_length));
  }
  return depth;
}

// Contact segments that divide their polygon together: a chain of them, joined end to end,
// whose loose ends all lie on the polygon's border. A wall cut into facets stands on a ground
// triangle with each facet's foot ending inside it, and a building's corner stands in one
// with two feet meeting there; either way the triangle is partly under the building, and an
// element across the feet would be partly buried: its light the mean of its open part and of
// the dark under the building (session 40 found dark wedges along every turned building's feet).
// Cutting along each such segment's whole line leaves every piece wholly on one side of every
// foot, so wholly under the building or wholly open (the footprint is an intersection of the
// half-planes of its edges, or a union of such). A closed chain (a block whose four feet all lie
// inside a floor) or one with an end inside the polygon (a wall that stops in the middle of a
// room) stays segments: cutting it along whole lines would spread slivers over the floor. So
// does a chain shorter than kMinDividingChain of the polygon's diameter (a building standing
// across the border of a large ground polygon, a corner clipping a triangle's corner): what it
// leaves open is most of the polygon, which the exposure handles (only a leaf less than
// kMinExposure open is taken as open, and shows dark), and its lines would run across the
// whole polygon.
// `segments` sorted by polygon; the lines are appended to `lines`, the segments kept (the mesh
// is graded toward them as well).
constexpr double kMinDividingChain = 0.25;

void lines_of_dividing_chains(const Search& s, const std::vector<ContactSegment>& segments,
                              std::vector<ContactLine>& lines) {
  const double join = 4.0 * s.tolerance;    // ends this close are one point (shared facet corners)
  const double border = 3.0 * s.tolerance;  // segments end `tolerance` inside a's border
  std::vector<std::uint32_t> parent, ends;
  std::vector<std::uint8_t> matched, duplicate, loose, inner;
  std::vector<double> length;
  for (std::size_t first = 0; first < segments.size();) {
    const PolygonId id = segments[first].polygon;
    std::size_t last = first;
    while (last < segments.size() && segments[last].polygon == id) ++last;
    const auto n = static_cast<std::uint32_t>(last - first);
    auto end_point = [&](std::uint32_t e) -> const glm::dvec3& {
      const ContactSegment& c = segments[first + e / 2];
      return e % 2 == 0 ? c.from : c.to;
    };
    // Union-find over the segments; ends are matched by a sweep along a direction oblique to
    // every axis (along x, the ends of a row of buildings' walls would all share one x).
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](std::uint32_t k) {
      while (parent[k] != k) k = parent[k] = parent[parent[k]];
      return k;
    };
    ends.resize(2 * std::size_t{n});
    std::iota(ends.begin(), ends.end(), 0u);
    const glm::dvec3 oblique = glm::normalize(glm::dvec3(1.0, 0.6180339887, 0.3819660113));
    auto along = [&](std::uint32_t e) { return glm::dot(end_point(e), oblique); };
    std::sort(ends.begin(), ends.end(),
              [&](std::uint32_t x, std::uint32_t y) { return std::make_pair(along(x), x) < std::make_pair(along(y), y); });
    auto near = [&](std::uint32_t x, std::uint32_t y) { return glm::length(end_point(x) - end_point(y)) <= join; };
    // Each pair of ends within `join`: `meet(x, y)` for ends of different segments.
    auto sweep = [&](const auto& meet) {
      for (std::size_t i = 0; i < ends.size(); ++i)
        for (std::size_t j = i + 1; j < ends.size() && along(ends[j]) - along(ends[i]) <= join; ++j)
          if (ends[i] / 2 != ends[j] / 2 && near(ends[i], ends[j])) meet(ends[i], ends[j]);
    };
    // The same segment twice (a wall of two coincident faces, one per room) is one: its copies'
    // ends would otherwise meet each other and leave the chain no loose end.
    duplicate.assign(n, 0);
    sweep([&](std::uint32_t x, std::uint32_t y) {
      if (near(x ^ 1u, y ^ 1u)) duplicate[std::max(x, y) / 2] = 1;
    });
    matched.assign(2 * std::size_t{n}, 0);
    sweep([&](std::uint32_t x, std::uint32_t y) {
      if (duplicate[x / 2] || duplicate[y / 2]) return;
      matched[x] = matched[y] = 1;
      parent[root(x / 2)] = root(y / 2);
    });
    // A chain divides the polygon when it has loose ends, every one on the border, and is long
    // enough.
    const Polygon& polygon = (*s.polygons)[id];
    double diameter = 0.0;
    for (const glm::vec3& u : polygon.vertices)
      for (const glm::vec3& v : polygon.vertices) diameter = std::max(diameter, glm::length(glm::dvec3(u - v)));
    length.assign(n, 0.0);
    for (std::uint32_t k = 0; k < n; ++k)
      if (!duplicate[k]) length[root(k)] += glm::length(segments[first + k].to - segments[first + k].from);
    loose.assign(n, 0);
    inner.assign(n, 0);
    for (std::uint32_t e = 0; e < 2 * n; ++e) {
      if (matched[e] || duplicate[e / 2]) continue;
      const std::uint32_t r = root(e / 2);
      loose[r] = 1;
      if (depth_inside(s, id, end_point(e)) > border) inner[r] = 1;
    }
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t r = root(k);
      if (!loose[r] || inner[r] || length[r] < kMinDividingChain * diameter) continue;
      const ContactSegment& c = segments[first + k];
      ContactLine l;
      l.polygon = id;
      l.point = 0.5 * (c.from + c.to);
      l.direction = glm::normalize(c.to - c.from);
      l.whole = false;
      lines.push_back(l);
    }
    first = last;
  }
}

/// One piece of the broad phase: a BVH over some of the polygons (`ids`), for rtcCollide().
struct Chunk {
  const Search* search = nullptr;
  std::vector<PolygonId> ids;
  glm::vec3 lower{0.0f}, upper{0.0f};
  RTCScene scene = nullptr;
};

void bounds_of(const RTCBoundsFunctionArguments* args) {
  const auto* chunk = static_cast<const Chunk*>(args->geometryUserPtr);
  const PolygonId id = chunk->ids[args->primID];
  const glm::vec3 &lo = chunk->search->lower[id], &hi = chunk->search->upper[id];
  *args->bounds_o = RTCBounds{lo.x, lo.y, lo.z, 0.0f, hi.x, hi.y, hi.z, 0.0f};
}

/// What a collision query between two chunks hands its callback.
struct ChunkPair {
  Search* search;
  const Chunk* first;
  const Chunk* second;
};

void on_collisions(void* user, RTCCollision* collisions, unsigned count) {
  const auto* pair = static_cast<const ChunkPair*>(user);
  Search* s = pair->search;
  // The pair tests are the search's cost (the BVH traversal is a fraction of it), so a stopped
  // search ends within one traversal.
  if (s->stop.load(std::memory_order_relaxed)) return;
  for (unsigned i = 0; i < count; ++i) {
    PolygonId a = pair->first->ids[collisions[i].primID0], b = pair->second->ids[collisions[i].primID1];
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    if (s->contacts) {
      for (const auto& [on, other] : {std::make_pair(a, b), std::make_pair(b, a)}) {
        ContactLine line;
        ContactSegment part;
        bool segment = false;
        const bool divides = contact_of(*s, on, other, line, segment, part);
        if (!divides && !segment) continue;
        const std::lock_guard<std::mutex> lock(s->mutex);
        if (divides) s->lines.push_back(line);
        else s->segments.push_back(part);
      }
      continue;
    }
    PolygonOverlap o;
    if (!test_pair(*s, a, b, o)) continue;
    const std::lock_guard<std::mutex> lock(s->mutex);
    s->found.push_back(o);
  }
}

/// Polygons per chunk of the broad phase. A BVH build cannot be interrupted, and Embree builds
/// a million boxes in about 0.2 s; chunks of this size take a few milliseconds each, so a
/// stopped search ends within that.
constexpr std::size_t kChunkPolygons = 32768;

/// Splits `ids` at the median of their boxes' centres along the longest axis of their extent
/// until each part holds at most kChunkPolygons (a k-d tree's leaves: compact parts, so only
/// neighbouring parts' boxes meet).
void split_chunks(const Search& s, std::vector<PolygonId> ids, std::vector<Chunk>& out) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (const PolygonId id : ids) {
    lo = glm::min(lo, s.lower[id]);
    hi = glm::max(hi, s.upper[id]);
  }
  if (ids.size() <= kChunkPolygons) {
    Chunk c;
    c.search = &s;
    c.ids = std::move(ids);
    c.lower = lo;
    c.upper = hi;
    out.push_back(std::move(c));
    return;
  }
  const glm::vec3 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  auto centre = [&](PolygonId id) { return s.lower[id][axis] + s.upper[id][axis]; };
  const auto middle = ids.begin() + static_cast<std::ptrdiff_t>(ids.size() / 2);
  // Ties by id: the parts, and so the order of the pairs found, do not depend on the sort.
  std::nth_element(ids.begin(), middle, ids.end(), [&](PolygonId a, PolygonId b) {
    const float ca = centre(a), cb = centre(b);
    return ca < cb || (ca == cb && a < b);
  });
  std::vector<PolygonId> upper_half(middle, ids.end());
  ids.erase(middle, ids.end());
  split_chunks(s, std::move(ids), out);
  split_chunks(s, std::move(upper_half), out);
}

bool boxes_meet(const Chunk& a, const Chunk& b) {
  return a.lower.x <= b.upper.x && b.lower.x <= a.upper.x && a.lower.y <= b.upper.y && b.lower.y <= a.upper.y &&
         a.lower.z <= b.upper.z && b.lower.z <= a.upper.z;
}

// The tolerance, planes and grown bounds of every polygon, then Embree's collision query over
// the bounds, which calls test_pair() or contact_of() for every nearby pair; every step ends
// early once `s.stop` is set.
void search_here(const Scene& scene, Search& s, const char* caller) {
  const std::vector<Polygon>& polygons = scene.polygons();
  s.polygons = &polygons;
  s.tolerance = touching_tolerance(scene);
  const auto grow = static_cast<float>(2.0 * s.tolerance);
  s.planes.resize(polygons.size());
  s.lower.resize(polygons.size());
  s.upper.resize(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    if (i % 4096 == 0 && s.stop.load(std::memory_order_relaxed)) return;
    const Polygon& p = polygons[i];
    Plane& plane = s.planes[i];
    plane.normal = glm::normalize(glm::dvec3(p.normal));
    for (const glm::vec3& v : p.vertices) plane.offset += glm::dot(plane.normal, glm::dvec3(v));
    plane.offset /= static_cast<double>(p.vertices.size());
    glm::vec3 lo = p.vertices[0], hi = p.vertices[0];
    for (const glm::vec3& v : p.vertices) {
      plane.flatness = std::max(plane.flatness, std::fabs(glm::dot(plane.normal, glm::dvec3(v)) - plane.offset));
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    s.lower[i] = lo - grow;
    s.upper[i] = hi + grow;
  }

  std::vector<PolygonId> all(polygons.size());
  std::iota(all.begin(), all.end(), PolygonId{0});
  std::vector<Chunk> chunks;
  split_chunks(s, std::move(all), chunks);

  RTCDevice device = rtcNewDevice(embree_device_config());
  if (!device)
    throw Error(ErrorCode::internal, std::string(caller) + ": Embree cannot create a device (error " +
                                         std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  for (Chunk& c : chunks) {
    if (s.stop.load()) break;
    c.scene = rtcNewScene(device);
    // The Morton builder: the pairs do not depend on the tree, and it builds several times faster.
    rtcSetSceneBuildQuality(c.scene, RTC_BUILD_QUALITY_LOW);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_LOW);
    rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(c.ids.size()));
    rtcSetGeometryUserData(geometry, &c);
    rtcSetGeometryBoundsFunction(geometry, bounds_of, nullptr);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(c.scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(c.scene);
  }
  // Each pair of chunks whose boxes meet, a chunk with itself included.
  for (std::size_t i = 0; i < chunks.size() && !s.stop.load(); ++i)
    for (std::size_t j = i; j < chunks.size() && !s.stop.load(); ++j) {
      if (!boxes_meet(chunks[i], chunks[j])) continue;
      ChunkPair pair{&s, &chunks[i], &chunks[j]};
      rtcCollide(chunks[i].scene, chunks[j].scene, on_collisions, &pair);
    }
  const RTCError error = rtcGetDeviceError(device);
  for (Chunk& c : chunks)
    if (c.scene) rtcReleaseScene(c.scene);
  rtcReleaseDevice(device);
  if (error != RTC_ERROR_NONE)
    throw Error(ErrorCode::internal, std::string(caller) + ": Embree's collision query failed (error " +
                                         std::to_string(static_cast<int>(error)) + ")");
}

// search_here() on this thread, or with `keep_going` on a worker while this thread polls it
// (it must be called on the caller's thread, and Embree's build and query cannot be
// interrupted: a stop is seen between them and by each batch of pairs).
void search_pairs(const Scene& scene, Search& s, const char* caller, const KeepGoing& keep_going) {
  if (!keep_going) return search_here(scene, s, caller);
  std::future<void> done = std::async(std::launch::async, [&] { search_here(scene, s, caller); });
  while (done.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready)
    if (!s.stop.load() && !keep_going()) s.stop.store(true);
  done.get();
}

// find_overlaps(), polled by `keep_going`.
std::vector<PolygonOverlap> overlaps(const Scene& scene, const KeepGoing& keep_going) {
  const std::vector<Polygon>& polygons = scene.polygons();
  if (polygons.size() < 2) return {};
  Search s;
  search_pairs(scene, s, "find_overlaps", keep_going);

  // The query may report a pair twice and in any order; sorting makes the result deterministic.
  std::vector<PolygonOverlap> found = std::move(s.found);
  auto key = [](const PolygonOverlap& o) { return std::make_pair(o.first, o.second); };
  std::sort(found.begin(), found.end(), [&](const PolygonOverlap& x, const PolygonOverlap& y) { return key(x) < key(y); });
  found.erase(std::unique(found.begin(), found.end(),
                          [&](const PolygonOverlap& x, const PolygonOverlap& y) { return key(x) == key(y); }),
              found.end());
  return found;
}

}  // namespace

std::vector<std::string> z_fighting_warnings(const Scene& scene, const KeepGoing& keep_going, const char* consequence) {
  return z_fighting_warnings(scene, overlaps(scene, keep_going), consequence);
}

std::vector<std::string> z_fighting_warnings(const Scene& scene, const std::vector<PolygonOverlap>& found,
                                             const char* consequence) {
  std::vector<std::string> out;
  std::vector<const PolygonOverlap*> same_facing;
  for (const PolygonOverlap& o : found)
    if (o.z_fighting()) same_facing.push_back(&o);
  if (same_facing.empty()) return out;
  const PolygonOverlap& o = *same_facing.front();
  auto name = [&](PolygonId p) {
    return "polygon " + std::to_string(p) + " (group '" + scene.groups()[scene.polygons()[p].group] + "')";
  };
  std::string message = name(o.first) + " and " + name(o.second) +
                        " are coincident and face the same way (z-fighting) around " + point_text(o.point, scene.origin()) + ": " +
                        consequence;
  if (same_facing.size() > 1)
    message += " (" + std::to_string(same_facing.size()) + " such pairs in all; radiosity::find_overlaps() lists them)";
  out.push_back(std::move(message));
  return out;
}

Contacts find_contacts(const Scene& scene, const KeepGoing& keep_going) {
  if (scene.polygons().size() < 2) return {};
  Search s;
  s.contacts = true;
  search_pairs(scene, s, "find_contacts", keep_going);
  // The query may report a pair twice and in any order.
  std::vector<ContactSegment> segments = std::move(s.segments);
  auto segment_key = [](const ContactSegment& c) {
    return std::make_tuple(c.polygon, c.other, c.from.x, c.from.y, c.from.z, c.to.x, c.to.y, c.to.z);
  };
  std::sort(segments.begin(), segments.end(),
            [&](const ContactSegment& x, const ContactSegment& y) { return segment_key(x) < segment_key(y); });
  segments.erase(std::unique(segments.begin(), segments.end(),
                             [&](const ContactSegment& x, const ContactSegment& y) {
                               return segment_key(x) == segment_key(y);
                             }),
                 segments.end());
  std::vector<ContactLine> lines = std::move(s.lines);
  lines_of_dividing_chains(s, segments, lines);
  // Sorted by polygon, then by line, and one line per polygon where several polygons meet it
  // along the same line (a wall modelled as two coincident faces, collinear walls, the facets
  // of one wall): the order of Embree's callbacks must not show.
  auto key = [](const ContactLine& l) {
    return std::make_tuple(l.polygon, l.direction.x, l.direction.y, l.direction.z, l.point.x, l.point.y, l.point.z);
  };
  std::sort(lines.begin(), lines.end(), [&](const ContactLine& x, const ContactLine& y) { return key(x) < key(y); });
  std::vector<ContactLine> out;
  for (const ContactLine& l : lines) {
    bool same = false;
    for (auto it = out.rbegin(); it != out.rend() && it->polygon == l.polygon; ++it) {
      const double parallel = glm::length(glm::cross(it->direction, l.direction));
      const glm::dvec3 d = l.point - it->point;
      const double apart = glm::length(d - glm::dot(d, it->direction) * it->direction);
      if (parallel < 1e-6 && apart <= s.tolerance) {
        same = true;
        it->whole = it->whole || l.whole;  // a wall across the polygon and a chain along it: whole
        break;
      }
    }
    if (!same) out.push_back(l);
  }
  return Contacts{std::move(out), std::move(segments)};
}

double touching_tolerance(const glm::vec3& lower, const glm::vec3& upper) {
  // Float corners carry rounding of up to 6e-8 of their magnitude (half an ulp); far from the
  // origin the tolerance stays above a few times that, so that shared edges of tilted polygons
  // never look like crossings.
  const glm::vec3 extent = glm::max(glm::abs(lower), glm::abs(upper));
  const double magnitude = std::max({extent.x, extent.y, extent.z});
  return std::max(kOverlapRelativeTolerance * static_cast<double>(glm::length(upper - lower)), 2.5e-7 * magnitude);
}

double touching_tolerance(const Scene& scene) {
  const Bounds box = scene.bounds();
  return touching_tolerance(box.lower, box.upper);
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

std::vector<PolygonOverlap> find_overlaps(const Scene& scene) { return detail::overlaps(scene, {}); }

}  // namespace v1
}  // namespace radiosity
