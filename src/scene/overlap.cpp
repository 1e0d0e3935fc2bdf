// Coincident and interpenetrating polygons.
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
#include "scene/overlap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
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
  std::mutex mutex;
  std::vector<PolygonOverlap> found;
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
    PolygonOverlap o;
    if (!test_pair(*s, a, b, o)) continue;
    const std::lock_guard<std::mutex> lock(s->mutex);
    s->found.push_back(o);
  }
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

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

std::vector<PolygonOverlap> find_overlaps(const Scene& scene) {
  const std::vector<Polygon>& polygons = scene.polygons();
  if (polygons.size() < 2) return {};
  detail::Search s;
  s.polygons = &polygons;
  // Float corners carry rounding of up to 6e-8 of their magnitude (half an ulp); far from the
  // origin the tolerance stays above a few times that, so that shared edges of tilted polygons
  // never look like crossings.
  const Bounds box = scene.bounds();
  const glm::vec3 extent = glm::max(glm::abs(box.lower), glm::abs(box.upper));
  const double magnitude = std::max({extent.x, extent.y, extent.z});
  s.tolerance = std::max(detail::kOverlapRelativeTolerance * box.diagonal(), 2.5e-7 * magnitude);
  const auto grow = static_cast<float>(2.0 * s.tolerance);
  s.planes.resize(polygons.size());
  s.lower.resize(polygons.size());
  s.upper.resize(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const Polygon& p = polygons[i];
    detail::Plane& plane = s.planes[i];
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

  RTCDevice device = rtcNewDevice(detail::embree_device_config());
  if (!device)
    throw Error(ErrorCode::internal, "find_overlaps: Embree cannot create a device (error " +
                                         std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  RTCScene boxes = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(polygons.size()));
  rtcSetGeometryUserData(geometry, &s);
  rtcSetGeometryBoundsFunction(geometry, detail::bounds_of, nullptr);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(boxes, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(boxes);
  rtcCollide(boxes, boxes, detail::on_collisions, &s);
  const RTCError error = rtcGetDeviceError(device);
  rtcReleaseScene(boxes);
  rtcReleaseDevice(device);
  if (error != RTC_ERROR_NONE)
    throw Error(ErrorCode::internal,
                "find_overlaps: Embree's collision query failed (error " + std::to_string(static_cast<int>(error)) + ")");

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
