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
// The same broad phase finds contact lines (contact_lines()): where b stands on a or passes
// through it along a segment that crosses a from border to border (a partition on a floor).
// Meshes are cut along them so that no element or interpolated vertex straddles a line where
// the light changes abruptly: D. R. Baum, S. Mann, K. P. Smith & J. M. Winget, "Making radiosity
// usable: automatic preprocessing and meshing techniques for the generation of accurate
// radiosity solutions", SIGGRAPH 1991 (surfaces split where others meet them, against light
// and shadow leaks).
#include "scene/overlap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
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
  bool contacts = false;  ///< looking for contact lines (contact_lines()) rather than overlaps
  std::mutex mutex;
  std::vector<PolygonOverlap> found;
  std::vector<ContactLine> lines;
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
// from border to border. Coplanar pairs have no such line.
bool contact_of(const Search& s, PolygonId ia, PolygonId ib, ContactLine& out) {
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
  if (lo > chord_lo + 2.0 * s.tolerance || hi < chord_hi - 2.0 * s.tolerance) return false;
  lo = chord_lo;
  hi = chord_hi;
  out.polygon = ia;
  out.point = origin + 0.5 * (lo + hi) * axis;
  out.direction = axis;
  return true;
}

void bounds_of(const RTCBoundsFunctionArguments* args) {
  const auto* s = static_cast<const Search*>(args->geometryUserPtr);
  const glm::vec3 &lo = s->lower[args->primID], &hi = s->upper[args->primID];
  *args->bounds_o = RTCBounds{lo.x, lo.y, lo.z, 0.0f, hi.x, hi.y, hi.z, 0.0f};
}

void on_collisions(void* user, RTCCollision* collisions, unsigned count) {
  auto* s = static_cast<Search*>(user);
  for (unsigned i = 0; i < count; ++i) {
    PolygonId a = collisions[i].primID0, b = collisions[i].primID1;
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    if (s->contacts) {
      for (const auto& [on, other] : {std::make_pair(a, b), std::make_pair(b, a)}) {
        ContactLine line;
        if (!contact_of(*s, on, other, line)) continue;
        const std::lock_guard<std::mutex> lock(s->mutex);
        s->lines.push_back(line);
      }
      continue;
    }
    PolygonOverlap o;
    if (!test_pair(*s, a, b, o)) continue;
    const std::lock_guard<std::mutex> lock(s->mutex);
    s->found.push_back(o);
  }
}

// The tolerance, planes and grown bounds of every polygon, then Embree's collision query over
// the bounds, which calls test_pair() or contact_of() for every nearby pair.
void search_pairs(const Scene& scene, Search& s, const char* caller) {
  const std::vector<Polygon>& polygons = scene.polygons();
  s.polygons = &polygons;
  s.tolerance = touching_tolerance(scene);
  const auto grow = static_cast<float>(2.0 * s.tolerance);
  s.planes.resize(polygons.size());
  s.lower.resize(polygons.size());
  s.upper.resize(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
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

  RTCDevice device = rtcNewDevice(embree_device_config());
  if (!device)
    throw Error(ErrorCode::internal, std::string(caller) + ": Embree cannot create a device (error " +
                                         std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  RTCScene boxes = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(polygons.size()));
  rtcSetGeometryUserData(geometry, &s);
  rtcSetGeometryBoundsFunction(geometry, bounds_of, nullptr);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(boxes, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(boxes);
  rtcCollide(boxes, boxes, on_collisions, &s);
  const RTCError error = rtcGetDeviceError(device);
  rtcReleaseScene(boxes);
  rtcReleaseDevice(device);
  if (error != RTC_ERROR_NONE)
    throw Error(ErrorCode::internal, std::string(caller) + ": Embree's collision query failed (error " +
                                         std::to_string(static_cast<int>(error)) + ")");
}

std::string point_text(const glm::vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", static_cast<double>(p.x), static_cast<double>(p.y),
                static_cast<double>(p.z));
  return text;
}

}  // namespace

std::vector<std::string> z_fighting_warnings(const Scene& scene) {
  std::vector<std::string> out;
  std::vector<const PolygonOverlap*> same_facing;
  const std::vector<PolygonOverlap> found = find_overlaps(scene);
  for (const PolygonOverlap& o : found)
    if (o.kind == OverlapKind::coincident &&
        glm::dot(scene.polygons()[o.first].normal, scene.polygons()[o.second].normal) > 0.0f)
      same_facing.push_back(&o);
  if (same_facing.empty()) return out;
  const PolygonOverlap& o = *same_facing.front();
  auto name = [&](PolygonId p) {
    return "polygon " + std::to_string(p) + " (group '" + scene.groups()[scene.polygons()[p].group] + "')";
  };
  std::string message = name(o.first) + " and " + name(o.second) +
                        " are coincident and face the same way (z-fighting) around " + point_text(o.point) +
                        ": which of them is in front is decided by rounding; remove one or move them apart";
  if (same_facing.size() > 1)
    message += " (" + std::to_string(same_facing.size()) + " such pairs in all; radiosity::find_overlaps() lists them)";
  out.push_back(std::move(message));
  return out;
}

std::vector<ContactLine> contact_lines(const Scene& scene) {
  if (scene.polygons().size() < 2) return {};
  Search s;
  s.contacts = true;
  search_pairs(scene, s, "contact_lines");
  // Sorted by polygon, then by line, and one line per polygon where several polygons meet it
  // along the same line (a wall modelled as two coincident faces, collinear walls): the order
  // of Embree's callbacks must not show.
  std::vector<ContactLine> lines = std::move(s.lines);
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
        break;
      }
    }
    if (!same) out.push_back(l);
  }
  return out;
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

std::vector<PolygonOverlap> find_overlaps(const Scene& scene) {
  const std::vector<Polygon>& polygons = scene.polygons();
  if (polygons.size() < 2) return {};
  detail::Search s;
  detail::search_pairs(scene, s, "find_overlaps");

  // The query may report a pair twice and in any order; sorting makes the result deterministic.
  std::vector<PolygonOverlap> found = std::move(s.found);
  auto key = [](const PolygonOverlap& o) { return std::make_pair(o.first, o.second); };
  std::sort(found.begin(), found.end(), [&](const PolygonOverlap& x, const PolygonOverlap& y) { return key(x) < key(y); });
  found.erase(std::unique(found.begin(), found.end(),
                          [&](const PolygonOverlap& x, const PolygonOverlap& y) { return key(x) == key(y); }),
              found.end());
  return found;
}

}  // namespace v1
}  // namespace radiosity
