// Where the emitters' light goes: rays from the front of every emitting polygon, against every
// polygon of the scene (either side), with Embree through RayScene; and which one-sided polygons
// look wound the wrong way (rays from both sides: nothing in front, surfaces behind).
// Stratified sampling as in the Monte Carlo form factors (docs/FORM_FACTORS.md): points from a
// jittered grid on the polygon, directions from a second, shuffled grid, cosine-distributed by
// Malley's method (a uniform disk point projected up onto the hemisphere).
#include "scene/emitter_check.hpp"
#include "scene/emission.hpp"
#include "scene/winding_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "geometry/polygon_fan.hpp"
#include "geometry/ray_scene.hpp"
#include "core/color.hpp"
#include "form_factors/pass1_material.hpp"

namespace radiosity::detail {

namespace {

/// Fixed: the check must give the same answer every time, whatever the solve's seed.
constexpr std::uint64_t kSeed = 0x656d6974746572ull;  // "emitter"

/// "12", "12, 13" or "12, 13, 14, 15 and 9 more".
std::string id_list(const std::vector<PolygonId>& ids) {
  constexpr std::size_t kShown = 4;
  std::string s;
  for (std::size_t k = 0; k < ids.size() && k < kShown; ++k) s += (k ? ", " : "") + std::to_string(ids[k]);
  if (ids.size() > kShown) s += " and " + std::to_string(ids.size() - kShown) + " more";
  return s;
}

/// The share of `side` x `side` rays from the side of `polygon` facing `n` that meet a polygon
/// of `rays_scene`: points from a jittered grid on the polygon, lifted by `lift`, directions from
/// a second grid shuffled against the first, cosine-distributed. `order`, `origin`, `dir` and
/// `hit` are the caller's scratch (resized here), `rng` the polygon's own stream.
/// With `near` (not null), also the share that meets one within `near_distance`.
double hit_fraction(const RayScene& rays_scene, const Polygon& polygon, const glm::vec3& n, std::size_t side, float lift,
                    Rng& rng, std::vector<std::uint32_t>& order, std::vector<glm::vec3>& origin,
                    std::vector<glm::vec3>& dir, std::vector<std::uint8_t>& hit, float near_distance = 0.0f,
                    double* near = nullptr) {
  const std::size_t rays = side * side;
  order.resize(rays);
  origin.resize(rays);
  dir.resize(rays);
  hit.resize(rays);
  const PolygonFan fan(polygon.vertices);
  const Frame frame(n);
  std::iota(order.begin(), order.end(), 0u);
  shuffle(order.data(), rays, rng);
  const float cell = 1.0f / static_cast<float>(side);
  auto stratum = [&](std::size_t s) {
    const glm::vec2 u = rng.uniform2();
    return glm::min((glm::vec2(static_cast<float>(s % side), static_cast<float>(s / side)) + u) * cell,
                    glm::vec2(0x1.fffffep-1f));
  };
  for (std::size_t i = 0; i < rays; ++i) {
    origin[i] = fan.sample(stratum(i)) + lift * n;
    dir[i] = frame.to_world(cosine_hemisphere(stratum(order[i])));
  }
  if (near) {
    rays_scene.occluded(rays, origin.data(), dir.data(), 0.0f, near_distance, hit.data());
    *near = static_cast<double>(std::count(hit.begin(), hit.end(), std::uint8_t{1})) / static_cast<double>(rays);
  }
  rays_scene.occluded(rays, origin.data(), dir.data(), 0.0f, std::numeric_limits<float>::infinity(), hit.data());
  return static_cast<double>(std::count(hit.begin(), hit.end(), std::uint8_t{1})) / static_cast<double>(rays);
}

}  // namespace

std::vector<EmitterReach> emitter_reach(const Scene& scene, unsigned threads, const std::vector<Rgb>* emission) {
  const std::vector<Polygon>& polygons = scene.polygons();
  std::vector<EmitterReach> out;
  for (PolygonId p = 0; p < polygons.size(); ++p) {
    const Rgb& e = polygon_emission(scene, p, emission);
    // A two-sided emitter also emits from its back (pass 1 and the path tracer): whichever way
    // it is wound, one of its sides faces the scene.
    if (!(max_channel(e) > 0.0f) || scene.material(polygons[p].material).two_sided) continue;
    EmitterReach r;
    r.polygon = p;
    r.power = static_cast<double>(polygons[p].area) *
              (static_cast<double>(e.x) + static_cast<double>(e.y) + static_cast<double>(e.z));
    out.push_back(r);
  }
  if (out.empty()) return out;

  // A square number of rays per emitter (side x side), within the budget.
  const std::size_t wanted = std::clamp(kEmitterRayBudget / out.size(), kMinEmitterRays, kEmitterRays);
  const auto side = static_cast<std::size_t>(std::sqrt(static_cast<double>(wanted)));
  // Ray origins are lifted off the emitter as the estimators lift theirs.
  const float lift = 1e-5f * std::max(scene.bounds().diagonal(), std::numeric_limits<float>::min());
  const RayScene rays_scene = RayScene::from_polygons(scene);

  parallel_for(threads, out.size(), 1, [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec3> origin, dir;
    std::vector<std::uint8_t> hit;
    std::vector<std::uint32_t> order;
    for (std::size_t k = begin; k < end; ++k) {
      const Polygon& polygon = polygons[out[k].polygon];
      Rng rng(kSeed, out[k].polygon);
      const float near_distance = static_cast<float>(kNearEmitterShare * std::sqrt(static_cast<double>(polygon.area)));
      out[k].hit_fraction = hit_fraction(rays_scene, polygon, polygon.normal, side, lift, rng, order, origin, dir, hit,
                                         near_distance, &out[k].near_fraction);
    }
  });
  return out;
}

std::vector<std::string> escaped_light_warnings(const Scene& scene, const Rgb& emitted, const Rgb& escaped,
                                                bool balanced, unsigned threads,
                                                const std::vector<Rgb>* emission) {
  std::vector<std::string> warnings;
  const std::vector<EmitterReach> reach = emitter_reach(scene, threads, emission);
  if (reach.empty()) return warnings;

  // find_overlaps() (0.5 s at 246k polygons) only when something needs it, and once.
  std::optional<std::vector<PolygonOverlap>> overlaps;
  auto overlaps_found = [&]() -> const std::vector<PolygonOverlap>& {
    if (!overlaps) overlaps = find_overlaps(scene);
    return *overlaps;
  };

  // Emitters that see nothing, by group in order of first appearance; apart, those that lie
  // against another polygon facing them (a light fixture's top against the ceiling): turning
  // them would not help, their light has nowhere to go.
  std::vector<PolygonId> seeing_nothing;
  for (const EmitterReach& r : reach)
    if (!(r.hit_fraction > 0.0)) seeing_nothing.push_back(r.polygon);
  std::vector<PolygonId> against;
  if (!seeing_nothing.empty())
    for (const PolygonOverlap& o : overlaps_found()) {
      if (!o.lying_against()) continue;
      for (const PolygonId p : {o.first, o.second})
        if (std::binary_search(seeing_nothing.begin(), seeing_nothing.end(), p)) against.push_back(p);
    }
  std::sort(against.begin(), against.end());
  against.erase(std::unique(against.begin(), against.end()), against.end());

  constexpr std::size_t kGroupsShown = 4;
  // "'lamp' (polygon 3), 'desk' (polygons 5, 6) and 2 more groups" for polygons in order.
  auto by_group = [&](const std::vector<PolygonId>& polygons) {
    std::vector<std::pair<GroupId, std::vector<PolygonId>>> groups;
    for (const PolygonId p : polygons) {
      const GroupId g = scene.polygons()[p].group;
      auto it = std::find_if(groups.begin(), groups.end(), [g](const auto& entry) { return entry.first == g; });
      if (it == groups.end()) it = groups.insert(groups.end(), {g, {}});
      it->second.push_back(p);
    }
    std::string who;
    for (std::size_t k = 0; k < groups.size() && k < kGroupsShown; ++k) {
      if (k > 0) who += k + 1 == groups.size() ? " and " : ", ";
      who += "'" + scene.groups()[groups[k].first] + "' (polygon" + (groups[k].second.size() > 1 ? "s " : " ") +
             id_list(groups[k].second) + ")";
    }
    if (groups.size() > kGroupsShown) who += " and " + std::to_string(groups.size() - kGroupsShown) + " more groups";
    return who;
  };
  std::vector<PolygonId> away;
  std::set_difference(seeing_nothing.begin(), seeing_nothing.end(), against.begin(), against.end(),
                      std::back_inserter(away));
  if (!away.empty()) {
    const bool many = away.size() > 1;
    warnings.push_back(std::string(many ? "emitters " : "emitter ") + by_group(away) +
                       (many ? " face away from every surface: their light leaves the scene; check the polygons' "
                             : " faces away from every surface: its light leaves the scene; check the polygon's ") +
                       "winding (vertex order) or use two-sided materials (--two-sided; Material::two_sided in code)");
  }
  // Emitters whose light is caught right in front of them: a lamp under a ceiling wound to face
  // it (found by trying an exported room: the room came out at a fortieth of its light, with
  // nothing said). Their light does not leave the scene, so the checks below stay silent.
  std::vector<PolygonId> caught;
  double caught_share = 1.0;  // the least near_fraction among them
  for (const EmitterReach& r : reach)
    if (r.near_fraction >= kCaughtEmitterFraction) {
      caught.push_back(r.polygon);
      caught_share = std::min(caught_share, r.near_fraction);
    }
  if (!caught.empty()) {
    const bool many = caught.size() > 1;
    char share_text[32];
    std::snprintf(share_text, sizeof share_text, "%.0f", std::floor(100.0 * caught_share));
    warnings.push_back(std::string(many ? "emitters " : "emitter ") + by_group(caught) +
                       (many ? " face surfaces right in front of them (" : " faces a surface right in front of it (") +
                       share_text + " % or more of " + (many ? "their" : "its") + " rays meet one within " +
                       std::to_string(static_cast<int>(100.0 * kNearEmitterShare)) + " % of " +
                       (many ? "their" : "its") + " size), which " + (many ? "take" : "takes") +
                       " almost all of " + (many ? "their" : "its") + " light first; if " + (many ? "they" : "it") +
                       " should face the other way, reverse the winding (vertex order) or use two-sided materials "
                       "(--two-sided; Material::two_sided in code)");
  }
  if (!against.empty()) {
    const bool many = against.size() > 1;
    warnings.push_back(std::string(many ? "emitters " : "emitter ") + by_group(against) +
                       (many ? " lie against polygons facing them (in contact): their light is lost there; give "
                               "them no emission or remove them"
                             : " lies against a polygon facing it (in contact): its light is lost there; give it no "
                               "emission or remove it"));
  }

  // A closed-looking scene that loses most of its light.
  const double total = static_cast<double>(emitted.x) + static_cast<double>(emitted.y) + static_cast<double>(emitted.z);
  const double lost = static_cast<double>(escaped.x) + static_cast<double>(escaped.y) + static_cast<double>(escaped.z);
  if (balanced && total > 0.0 && lost > 0.5 * total) {
    double power = 0.0, reached = 0.0;
    for (const EmitterReach& r : reach) {
      power += r.power;
      reached += r.power * r.hit_fraction;
    }
    char share[32];
    std::snprintf(share, sizeof share, "%.0f", 100.0 * lost / total);
    if (power > 0.0 && reached > 0.95 * power) {
      warnings.push_back(std::string("the scene looks closed but ") + share +
                         " % of the emitted light left it: polygons probably face outwards (wound the wrong way); "
                         "reverse their winding (--reverse-winding outward; in code, Scene::reverse_winding() of find_polygons_facing_outward()) or use two-sided materials (--two-sided; Material::two_sided in code)");
    } else {
      // The emitters' own rays may leave (a light fixture modelled as a box wound outward, its
      // top against the ceiling) while the room around them is wound outward too: ask the
      // polygons themselves, as `radiosity check` does. Only here, where most light escaped,
      // since it costs rays from every one-sided polygon and find_overlaps().
      const OutwardFacing outward = find_polygons_facing_outward(scene, overlaps_found());
      if (outward.looks_wound_outward()) {
        char area_share[32];
        std::snprintf(area_share, sizeof area_share, "%.0f", 100.0 * outward.area / outward.one_sided_area);
        warnings.push_back(std::string(share) + " % of the emitted light left the scene, and " +
                           std::to_string(outward.polygons.size()) + " of " + std::to_string(scene.polygons().size()) +
                           " polygons (" + area_share +
                           " % of the one-sided area) see nothing in front of them and surfaces behind: a closed "
                           "model wound outward? Reverse their winding (--reverse-winding outward; in code, Scene::reverse_winding() of find_polygons_facing_outward()) or use "
                           "two-sided materials (--two-sided; Material::two_sided in code)");
      }
    }
  }
  return warnings;
}

std::vector<std::string> back_lit_warnings(const Scene& scene, const PatchHierarchy& hierarchy,
                                           const std::vector<Rgb>& front, const std::vector<Rgb>& back) {
  std::vector<std::string> warnings;
  if (back.empty()) return warnings;
  // Power per group from the fronts and the backs of its two-sided opaque elements.
  std::vector<double> front_power(scene.groups().size(), 0.0), back_power(scene.groups().size(), 0.0);
  for (const std::uint32_t e : hierarchy.leaves()) {
    const Polygon& polygon = scene.polygons()[hierarchy.patches()[hierarchy.element(e).patch].polygon];
    const Material& m = scene.material(polygon.material);
    if (!m.two_sided || m.diffuse_transmittance != Rgb(0.0f)) continue;
    const double area = hierarchy.element(e).area;
    front_power[polygon.group] += area * (front[e].x + front[e].y + front[e].z);
    back_power[polygon.group] += area * (back[e].x + back[e].y + back[e].z);
  }
  std::vector<GroupId> lit;
  for (GroupId g = 0; g < scene.groups().size(); ++g)
    if (back_power[g] > 0.0 && back_power[g] > 4.0 * front_power[g]) lit.push_back(g);
  if (lit.empty()) return warnings;
  constexpr std::size_t kGroupsShown = 4;
  std::string who;
  for (std::size_t k = 0; k < lit.size() && k < kGroupsShown; ++k) {
    if (k > 0) who += k + 1 == lit.size() ? " and " : ", ";
    who += "'" + scene.groups()[lit[k]] + "'";
  }
  if (lit.size() > kGroupsShown) who += " and " + std::to_string(lit.size() - kGroupsShown) + " more";
  const bool many = lit.size() > 1;
  warnings.push_back(std::string(many ? "groups " : "group ") + who + (many ? " are" : " is") +
                     " lit mainly on the back of " + (many ? "their" : "its") +
                     " two-sided polygons (their normals face away from the light, as in a room modelled with "
                     "outward normals): solved and rendered right, but lightmaps and per-vertex values hold the "
                     "front side, which is dark; reverse those polygons' winding");
  return warnings;
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

OutwardFacing find_polygons_facing_outward(const Scene& scene) {
  return find_polygons_facing_outward(scene, find_overlaps(scene));
}

OutwardFacing find_polygons_facing_outward(const Scene& scene, const std::vector<PolygonOverlap>& overlaps) {
  constexpr std::size_t kSide = 4, kRays = kSide * kSide;
  const std::vector<Polygon>& polygons = scene.polygons();
  OutwardFacing out;
  if (polygons.empty()) return out;
  // One-sided: no back of its own (detail::pass1_has_back()) and no glass to see through.
  const auto one_sided = detail::has_sides;
  std::vector<std::uint8_t> outward(polygons.size(), 0);
  const float lift = 1e-5f * std::max(scene.bounds().diagonal(), std::numeric_limits<float>::min());
  const detail::RayScene rays_scene = detail::RayScene::from_polygons(scene);
  detail::parallel_for(0, polygons.size(), 256, [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec3> origin, dir;
    std::vector<std::uint8_t> hit;
    std::vector<std::uint32_t> order;
    for (std::size_t p = begin; p < end; ++p) {
      const Polygon& polygon = polygons[p];
      if (!one_sided(scene.material(polygon.material))) continue;
      double seen[2];
      for (int side = 0; side < 2; ++side) {
        detail::Rng rng(detail::kSeed, 2 * std::uint64_t{p} + static_cast<std::uint64_t>(side));
        seen[side] = detail::hit_fraction(rays_scene, polygon, side == 0 ? polygon.normal : -polygon.normal, kSide, lift,
                                          rng, order, origin, dir, hit);
      }
      // At most 1 of the front's rays and at least 15 of the back's meet a polygon.
      outward[p] = seen[0] * kRays <= 1.0 && seen[1] * kRays + 1.0 >= kRays ? 1 : 0;
    }
  });
  // A polygon lying on another (a box's bottom on a floor) sees nothing in front because its
  // rays start past the other one, so rays cannot judge it. Turning the polygons found must
  // leave every coincident pair facing opposite ways (in contact) rather than the same way
  // (z-fighting): of a pair that faces the same way, one is turned; of a pair in contact, both
  // or none. Which one: the one whose surface (the polygons it shares edges with, and theirs)
  // the rays found wound outward, else the larger (the room's floor, not the box standing on
  // it). By size alone, a floor exported as facets smaller than the box's bottom kept the
  // facets under the box's edges facing down, and they came out black around it.
  for (const PolygonOverlap& o : overlaps)
    if (o.first >= polygons.size() || o.second >= polygons.size())
      throw Error(ErrorCode::invalid_argument, "find_polygons_facing_outward: an overlap names polygon " +
                                                   std::to_string(std::max(o.first, o.second)) + " of a scene of " +
                                                   std::to_string(polygons.size()) + " (overlaps of another scene?)");
  auto same_way = [&](const PolygonOverlap& o) {
    return glm::dot(polygons[o.first].normal, polygons[o.second].normal) > 0.0f;
  };
  const bool judge_by_surface = std::any_of(overlaps.begin(), overlaps.end(), [&](const PolygonOverlap& o) {
    return o.kind == OverlapKind::coincident && same_way(o) && outward[o.first] && outward[o.second];
  });
  // Per polygon, the share of the rest of its surface's area found outward (-1: no rest).
  std::vector<double> surface_outward;
  if (judge_by_surface) {
    detail::PolygonAdjacency adjacency;
    detail::polygon_adjacency(scene, {}, adjacency);
    const std::vector<std::uint32_t> surface = detail::connected_surfaces(adjacency);
    std::vector<double> area, found;
    for (PolygonId p = 0; p < polygons.size(); ++p) {
      if (surface[p] == kNone) continue;
      if (surface[p] >= area.size()) {
        area.resize(surface[p] + 1, 0.0);
        found.resize(surface[p] + 1, 0.0);
      }
      area[surface[p]] += polygons[p].area;
      found[surface[p]] += outward[p] ? polygons[p].area : 0.0;
    }
    surface_outward.assign(polygons.size(), -1.0);
    for (PolygonId p = 0; p < polygons.size(); ++p) {
      if (surface[p] == kNone) continue;
      const double rest = area[surface[p]] - polygons[p].area;
      if (rest > 0.0) surface_outward[p] = (found[surface[p]] - (outward[p] ? polygons[p].area : 0.0)) / rest;
    }
  }
  const std::vector<std::uint8_t> found_by_rays = outward;
  for (const PolygonOverlap& o : overlaps) {
    if (o.kind != OverlapKind::coincident) continue;
    const PolygonId a = o.first, b = o.second;
    if (same_way(o)) {
      if (!found_by_rays[a] || !found_by_rays[b]) continue;
      // The one to keep facing as it does: the other's surface is the one wound outward.
      const double sa = surface_outward[a], sb = surface_outward[b];
      PolygonId keep = polygons[a].area >= polygons[b].area ? b : a;
      if (sa >= 0.0 && sb >= 0.0 && sa != sb) keep = sa > sb ? b : a;
      else if (sa >= 0.0 && sb < 0.0) keep = sa >= 0.5 ? b : a;
      else if (sb >= 0.0 && sa < 0.0) keep = sb >= 0.5 ? a : b;
      outward[keep] = 0;
    } else if (outward[a] != outward[b]) {
      outward[a] = outward[b] = 0;
    }
  }
  for (PolygonId p = 0; p < polygons.size(); ++p) {
    const Polygon& polygon = polygons[p];
    if (!one_sided(scene.material(polygon.material))) continue;
    out.one_sided_area += polygon.area;
    if (!outward[p]) continue;
    out.polygons.push_back(p);
    out.area += polygon.area;
  }
  if (out.polygons.empty()) return out;

  // Where the light is. A closed model whose polygons face out is a room wound outward when
  // light is inside it, and an object seen from outside (a glTF asset, a CAD part) when all of
  // its light comes from outside: a sun, a sky, lamps whose rays get away. Found with Khronos'
  // Box.gltf under a sky: `check` called the box "a closed model wound outward". A source is
  // inside when at least 15 of its 16 rays meet a polygon (an emitting polygon: from its
  // front, or either side if two-sided) or all 14 of a point or spot light's (the axes and
  // the diagonals).
  bool any_light = false, enclosed = false;
  for (const Light& light : scene.lights()) {
    any_light = true;
    if (enclosed || (light.type != LightType::point && light.type != LightType::spot)) continue;
    std::array<glm::vec3, 14> dir;
    std::array<glm::vec3, 14> origin;
    std::size_t k = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (const float sign : {-1.0f, 1.0f}) {
        dir[k] = glm::vec3(0.0f);
        dir[k++][axis] = sign;
      }
    for (const float x : {-1.0f, 1.0f})
      for (const float y : {-1.0f, 1.0f})
        for (const float z : {-1.0f, 1.0f}) dir[k++] = glm::vec3(x, y, z) * 0.57735027f;
    origin.fill(light.position);
    std::array<std::uint8_t, 14> hit{};
    rays_scene.occluded(dir.size(), origin.data(), dir.data(), 0.0f, std::numeric_limits<float>::infinity(),
                        hit.data());
    enclosed = std::count(hit.begin(), hit.end(), std::uint8_t{1}) == static_cast<std::ptrdiff_t>(hit.size());
  }
  {
    std::vector<glm::vec3> origin, dir;
    std::vector<std::uint8_t> hit;
    std::vector<std::uint32_t> order;
    for (PolygonId p = 0; p < polygons.size() && !enclosed; ++p) {
      const Material& m = scene.material(polygons[p].material);
      if (!(detail::max_channel(m.emission) > 0.0f)) continue;
      any_light = true;
      for (int side = 0; side < (m.two_sided ? 2 : 1) && !enclosed; ++side) {
        detail::Rng rng(detail::kSeed, 2 * std::uint64_t{p} + static_cast<std::uint64_t>(side));
        const double seen = detail::hit_fraction(rays_scene, polygons[p], side == 0 ? polygons[p].normal
                                                                                    : -polygons[p].normal,
                                                 kSide, lift, rng, order, origin, dir, hit);
        enclosed = seen * kRays + 1.0 >= kRays;
      }
    }
  }
  out.lit_from_outside = any_light && !enclosed;
  return out;
}

std::vector<PolygonId> find_emitters_facing_away(const Scene& scene) {
  std::vector<PolygonId> out;
  for (const detail::EmitterReach& r : detail::emitter_reach(scene))
    if (r.hit_fraction <= 0.0) out.push_back(r.polygon);
  return out;
}

}  // namespace v1
}  // namespace radiosity
