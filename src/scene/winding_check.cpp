// Inconsistent winding: polygons of one surface that face the other way from their neighbours
// (radiosity::find_inconsistent_winding(), scene.hpp). An exporter's slip, a face flipped by
// hand, a mirrored part welded to an unmirrored one: one-sided, such a polygon receives and sends
// nothing on the side its neighbours light, and comes out black with no other sign.
// Based on:
//   the half-edge rule of orientable meshes: two faces that share an edge are oriented alike
//   exactly when they traverse it in opposite directions (M. Mantyla, "An Introduction to Solid
//   Modeling", 1988, ch. 10); a breadth-first walk over shared edges then sorts each connected
//   surface into two orientations, as mesh repair tools do to "recalculate normals" (the
//   majority, by area, taken as meant).
#include "scene/winding_check.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include "core/color.hpp"
#include "core/text.hpp"
#include "form_factors/pass1_material.hpp"
#include "scene/polygon_math.hpp"

namespace radiosity::detail {

namespace {

/// Lexicographic order of positions, exact (the ends of a shared edge are the same floats: an
/// indexed mesh's vertices, or the same text parsed twice).
bool before(const glm::vec3& a, const glm::vec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); }

/// The bits of a coordinate, -0 taken as +0 (they compare equal).
std::uint32_t bits(float x) {
  x += 0.0f;
  std::uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

/// A 64-bit mix of an edge's ends (in lexicographic order): equal edges have equal keys.
std::uint64_t edge_key(const glm::vec3& lo, const glm::vec3& hi) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const float c : {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z}) {
    h ^= bits(c);
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
  }
  return h;
}

/// One edge of a polygon (its vertices edge and edge + 1), by the key of its ends. 16 bytes: a
/// million quads give 4 million, 64 MB while the check runs (the benchmark city of 991k
/// polygons: 1.5 s on one thread, most of it fetching the polygons of the shared edges).
struct EdgeRecord {
  std::uint64_t key = 0;
  PolygonId polygon = 0;
  std::uint32_t edge = 0;
};

// Polled every kPollEvery items of each pass (and between the sort's runs): solve() runs the
// winding check while meshing, where a cancel is to be seen within 100 ms (a terrain of 600k
// triangles takes about a second in all).
constexpr std::size_t kPollEvery = 1u << 15;
bool stopped_at(const KeepGoing& keep_going, std::size_t item) {
  return keep_going && item % kPollEvery == 0 && !keep_going();
}

}  // namespace

bool has_sides(const Material& m) { return !pass1_has_back(m) && !(max_channel(m.transmittance) > 0.0f); }

std::vector<std::string> inconsistent_winding_warnings(const Scene& scene, const InconsistentWinding& found,
                                                       bool for_view_factors) {
  std::vector<std::string> warnings;
  if (found.polygons.empty()) return warnings;
  const PolygonId first = found.polygons.front();
  const Polygon& p = scene.polygons()[first];
  const glm::vec3 centre = vertex_mean(p.vertices);
  char area[32];
  std::snprintf(area, sizeof area, "%.3g", found.area);
  const bool one = found.polygons.size() == 1;
  // What it does: a solve's light arrives on the surface's side the polygon turns away from; a
  // view factor's row looks to the other side. (Two-sided materials mend the first only: the
  // view factors take fronts alone.)
  const std::string consequence =
      for_view_factors ? std::string(one ? "its row sees what lies behind the surface it belongs to"
                                         : "their rows see what lies behind the surfaces they belong to") +
                             ", and the rows of what lies in front do not see " + (one ? "it" : "them")
                       : std::string(one ? "it faces away from the light its neighbours take and comes"
                                         : "they face away from the light their neighbours take and come") +
                             " out black";
  const std::string fix =
      std::string("; reverse the winding (--reverse-winding inconsistent; in code, Scene::reverse_winding() of "
                  "find_inconsistent_winding())") +
      (for_view_factors ? "" : " or use two-sided materials (--two-sided)");
  warnings.push_back(std::to_string(found.polygons.size()) + " polygon" + (one ? " is" : "s are") +
                     " wound opposite to the polygons " + (one ? "it shares" : "they share") + " edges with (" + area +
                     " units^2 in " + std::to_string(found.surfaces) + " surface" + (found.surfaces == 1 ? "" : "s") +
                     "; the first: polygon " + std::to_string(first) + " of group '" + scene.groups()[p.group] +
                     "' at " + point_text(centre, scene.origin()) + "): one-sided, " + consequence + fix);
  return warnings;
}

bool polygon_adjacency(const Scene& scene, const KeepGoing& keep_going, PolygonAdjacency& adjacency) {
  const std::vector<Polygon>& polygons = scene.polygons();
  auto stopped = [&](std::size_t item) { return stopped_at(keep_going, item); };
  // Every edge of every one-sided polygon.
  std::vector<detail::EdgeRecord> edges;
  std::size_t count = 0;
  for (const Polygon& p : polygons) count += p.vertices.size();
  edges.reserve(count);
  // The ends of record e in lexicographic order, and whether its polygon runs from lo to hi.
  auto ends = [&](const detail::EdgeRecord& e, glm::vec3& lo, glm::vec3& hi) {
    const Polygon& p = polygons[e.polygon];
    const glm::vec3 a = p.vertices[e.edge], b = p.vertices[(e.edge + 1) % p.vertices.size()];
    const bool forward = detail::before(a, b);
    lo = forward ? a : b;
    hi = forward ? b : a;
    return forward;
  };
  for (PolygonId id = 0; id < polygons.size(); ++id) {
    if (stopped(id)) return false;
    const Polygon& p = polygons[id];
    if (p.obstruction_only || !detail::has_sides(scene.material(p.material))) continue;
    const auto n = static_cast<std::uint32_t>(p.vertices.size());
    for (std::uint32_t i = 0; i < n; ++i) {
      if (p.vertices[i] == p.vertices[(i + 1) % n]) continue;
      detail::EdgeRecord e{0, id, i};
      glm::vec3 lo, hi;
      ends(e, lo, hi);
      e.key = detail::edge_key(lo, hi);
      edges.push_back(e);
    }
  }
  // Sorted by key (ties in polygon and edge order: deterministic) as a merge sort of runs, with
  // a poll after each run and each merge: one std::sort of a million quads' edges took 0.3 s.
  auto by_key = [](const detail::EdgeRecord& x, const detail::EdgeRecord& y) {
    return x.key < y.key || (x.key == y.key && (x.polygon < y.polygon || (x.polygon == y.polygon && x.edge < y.edge)));
  };
  for (std::size_t begin = 0; begin < edges.size(); begin += kPollEvery) {
    std::sort(edges.begin() + static_cast<std::ptrdiff_t>(begin),
              edges.begin() + static_cast<std::ptrdiff_t>(std::min(edges.size(), begin + kPollEvery)), by_key);
    if (keep_going && !keep_going()) return false;
  }
  for (std::size_t width = kPollEvery; width < edges.size(); width *= 2)
    for (std::size_t begin = 0; begin + width < edges.size(); begin += 2 * width) {
      const auto first = edges.begin() + static_cast<std::ptrdiff_t>(begin);
      std::inplace_merge(first, first + static_cast<std::ptrdiff_t>(width),
                         edges.begin() + static_cast<std::ptrdiff_t>(std::min(edges.size(), begin + 2 * width)), by_key);
      if (keep_going && !keep_going()) return false;
    }
  // Edges that exactly two polygons share (a third on it, as where a partition meets a floor
  // cut along it, says nothing about orientation): 1 when they run along it the same way.
  // Not two polygons on the same side of their edge, lying on each other: a face modelled twice
  // (McGuire's Cornell box has two; z-fighting, which find_overlaps() reports) or a sheet's two
  // layers, which are no surface continuing across the edge.
  struct Link {
    PolygonId a, b;
    std::uint8_t flipped;
  };
  std::vector<Link> links;
  // The unit direction from edge (lo, hi) into polygon p, in its plane.
  auto inward = [&](PolygonId id, const glm::vec3& lo, const glm::vec3& hi) {
    const Polygon& p = polygons[id];
    const glm::vec3 centre = vertex_mean(p.vertices);
    const glm::vec3 along = glm::normalize(hi - lo), to = centre - lo;
    const glm::vec3 across = to - glm::dot(to, along) * along;
    const float length = glm::length(across);
    return length > 0.0f ? across / length : glm::vec3(0.0f);
  };
  constexpr float kSameSide = 0.9998f;  // within about 1.1 degrees
  for (std::size_t i = 0, polled = 0; i < edges.size();) {
    if (i >= polled) {
      if (keep_going && !keep_going()) return false;
      polled = i + kPollEvery;
    }
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    // A run of one key: the records equal to its first (any other is a collision of the hash,
    // which leaves both edges unjudged: they say nothing then, as an edge of three polygons).
    if (j - i == 2 && edges[i].polygon != edges[i + 1].polygon) {
      glm::vec3 lo_a, hi_a, lo_b, hi_b;
      const bool forward_a = ends(edges[i], lo_a, hi_a), forward_b = ends(edges[i + 1], lo_b, hi_b);
      if (lo_a == lo_b && hi_a == hi_b &&
          !(glm::dot(inward(edges[i].polygon, lo_a, hi_a), inward(edges[i + 1].polygon, lo_b, hi_b)) > kSameSide))
        links.push_back({edges[i].polygon, edges[i + 1].polygon, static_cast<std::uint8_t>(forward_a == forward_b ? 1 : 0)});
    }
    i = j;
  }
  edges = {};
  // Both directions of every link, as adjacency lists (CSR).
  std::vector<std::size_t>& first = adjacency.first;
  std::vector<std::pair<PolygonId, std::uint8_t>>& adjacent = adjacency.adjacent;
  first.assign(polygons.size() + 1, 0);
  for (const Link& l : links) {
    ++first[l.a + 1];
    ++first[l.b + 1];
  }
  for (std::size_t p = 0; p < polygons.size(); ++p) first[p + 1] += first[p];
  adjacent.assign(first.back(), {});
  {
    std::vector<std::size_t> at(first.begin(), first.end() - 1);
    for (const Link& l : links) {
      adjacent[at[l.a]++] = {l.b, l.flipped};
      adjacent[at[l.b]++] = {l.a, l.flipped};
    }
  }
  return true;
}

std::vector<std::uint32_t> connected_surfaces(const PolygonAdjacency& adjacency) {
  const std::size_t count = adjacency.first.empty() ? 0 : adjacency.first.size() - 1;
  std::vector<std::uint32_t> surface(count, kNone);
  std::vector<PolygonId> queue;
  std::uint32_t next = 0;
  for (PolygonId start = 0; start < count; ++start) {
    if (surface[start] != kNone || adjacency.first[start + 1] == adjacency.first[start]) continue;
    queue.assign(1, start);
    surface[start] = next;
    for (std::size_t k = 0; k < queue.size(); ++k)
      for (std::size_t e = adjacency.first[queue[k]]; e < adjacency.first[queue[k] + 1]; ++e) {
        const PolygonId q = adjacency.adjacent[e].first;
        if (surface[q] != kNone) continue;
        surface[q] = next;
        queue.push_back(q);
      }
    ++next;
  }
  return surface;
}

InconsistentWinding inconsistent_winding(const Scene& scene, const KeepGoing& keep_going) {
  const std::vector<Polygon>& polygons = scene.polygons();
  InconsistentWinding out;
  auto stopped = [&](std::size_t item) { return stopped_at(keep_going, item); };
  PolygonAdjacency adjacency;
  if (!polygon_adjacency(scene, keep_going, adjacency)) return {};
  const std::vector<std::size_t>& first = adjacency.first;
  const std::vector<std::pair<PolygonId, std::uint8_t>>& adjacent = adjacency.adjacent;
  if (adjacent.empty()) return out;
  // A breadth-first walk per connected surface, from its lowest polygon id (orientation 0):
  // each neighbour takes the orientation its shared edge says. The orientation with less area
  // is the one reported (ties: the one without the lowest id). Where a surface cannot be
  // oriented (a cycle of edges that disagrees: a Moebius strip, or a fold modelled twice) the
  // walk's first answer stands.
  constexpr std::uint8_t kUnseen = 2;
  std::vector<std::uint8_t> side(polygons.size(), kUnseen);
  std::vector<PolygonId> queue, members;
  for (PolygonId start = 0; start < polygons.size(); ++start) {
    if (stopped(start)) return {};
    if (side[start] != kUnseen || first[start + 1] == first[start]) continue;
    queue.assign(1, start);
    side[start] = 0;
    members.clear();
    double area[2] = {0.0, 0.0};
    std::size_t sides[2] = {0, 0};
    for (std::size_t k = 0; k < queue.size(); ++k) {
      const PolygonId p = queue[k];
      members.push_back(p);
      area[side[p]] += polygons[p].area;
      ++sides[side[p]];
      for (std::size_t e = first[p]; e < first[p + 1]; ++e) {
        const PolygonId q = adjacent[e].first;
        if (side[q] != kUnseen) continue;
        side[q] = static_cast<std::uint8_t>(side[p] ^ adjacent[e].second);
        queue.push_back(q);
      }
    }
    if (sides[1] == 0) continue;  // all one way
    const std::uint8_t minority = area[0] < area[1] ? 0 : 1;
    for (const PolygonId p : members)
      if (side[p] == minority) {
        out.polygons.push_back(p);
        out.area += polygons[p].area;
      }
    ++out.surfaces;
  }
  std::sort(out.polygons.begin(), out.polygons.end());
  return out;
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

InconsistentWinding find_inconsistent_winding(const Scene& scene) { return detail::inconsistent_winding(scene, {}); }

}  // namespace v1
}  // namespace radiosity
