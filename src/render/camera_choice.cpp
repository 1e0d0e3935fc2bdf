// A camera for a scene that has none (choose_camera()): the view that frames its bounds from
// outside, unless that view would show mostly surfaces no light reaches, as a closed room seen
// from outside does (a black image). Then a view from inside, the one whose image shows the
// most lit surfaces. Found by rendering an exported room (an OBJ has no camera): the
// default view from outside was black but for a few specks, with nothing said (session 32).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "render/camera_choice.hpp"
#include "core/frame.hpp"
#include "core/text.hpp"
#include "scene/polygon_math.hpp"
#include "image/camera.hpp"

namespace radiosity::detail {

namespace {

/// The scene's light as seen by a probe: the emitting polygons' centroids (the 16 strongest)
/// and the lights, each a point to see or a direction to see free (a sky: five directions).
class LightProbe {
 public:
  LightProbe(const Scene& scene, const RayScene& rays) : rays_(rays) {
    epsilon_ = 1e-4f * std::max(scene.bounds().diagonal(), 1e-6f);
    std::vector<std::pair<float, std::size_t>> power;
    const std::vector<Polygon>& polygons = scene.polygons();
    for (std::size_t p = 0; p < polygons.size(); ++p) {
      const Material& m = scene.material(polygons[p].material);
      const float e = std::max({m.emission.x, m.emission.y, m.emission.z});
      if (e > 0.0f) power.emplace_back(e * polygons[p].area, p);
    }
    const std::size_t kept = std::min<std::size_t>(power.size(), 16);
    std::partial_sort(power.begin(), power.begin() + static_cast<std::ptrdiff_t>(kept), power.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t k = 0; k < kept; ++k) {
      const Polygon& polygon = polygons[power[k].second];
      const glm::vec3 centroid = vertex_mean(polygon.vertices);
      const bool two_sided = scene.material(polygon.material).two_sided;
      emitters_.push_back(Emitter{centroid, polygon.normal, two_sided});
    }
    for (const Light& light : scene.lights()) {
      const glm::vec3 zenith = glm::length(light.direction) > 0.0f ? glm::normalize(light.direction) : glm::vec3(0, 1, 0);
      if (light.type == LightType::point || light.type == LightType::spot)
        points_.push_back(light.position);
      else if (light.type == LightType::directional)
        directions_.push_back(-zenith);
      else {
        // The sky: its zenith and four directions 60 degrees down from it, so that walls see it.
        const Frame frame(zenith);
        directions_.push_back(zenith);
        for (const glm::vec2 a : {glm::vec2(1, 0), glm::vec2(-1, 0), glm::vec2(0, 1), glm::vec2(0, -1)})
          directions_.push_back(frame.to_world(glm::vec3(0.8660254f * a.x, 0.8660254f * a.y, 0.5f)));
      }
    }
  }
  bool empty() const { return emitters_.empty() && points_.empty() && directions_.empty(); }
  /// Whether light reaches `x` on the side its unit normal `n` faces.
  bool reaches(const glm::vec3& x, const glm::vec3& n) const {
    const glm::vec3 o = x + epsilon_ * n;
    for (const Emitter& e : emitters_) {
      const glm::vec3 d = e.centroid - o;
      if (!(glm::dot(d, n) > 0.0f) || !(e.two_sided || glm::dot(d, e.normal) < 0.0f)) continue;
      if (!rays_.occluded(o, d, 0.0f, 1.0f - 1e-3f)) return true;
    }
    for (const glm::vec3& p : points_) {
      const glm::vec3 d = p - o;
      if (glm::dot(d, n) > 0.0f && !rays_.occluded(o, d, 0.0f, 1.0f - 1e-4f)) return true;
    }
    for (const glm::vec3& d : directions_)
      if (glm::dot(d, n) > 0.0f && !rays_.occluded(o, d, 0.0f, std::numeric_limits<float>::infinity())) return true;
    return false;
  }

 private:
  struct Emitter {
    glm::vec3 centroid, normal;
    bool two_sided;
  };
  const RayScene& rays_;
  float epsilon_ = 0.0f;
  std::vector<Emitter> emitters_;
  std::vector<glm::vec3> points_, directions_;
};

/// What a camera's image shows, sampled by a kGrid x kGrid grid of rays through the pixel
/// centres of a square image: the share of rays that meet a surface that shows light (a side a
/// renderer shows, that some emitter or light reaches), and the share that meet a surface that
/// shows none (the back of a one-sided polygon, black in every renderer, or a side no light
/// reaches, as the outside of a closed room). Misses (the background) are neither.
struct ViewContent {
  double lit = 0.0;
  double unlit = 0.0;
};

constexpr int kGrid = 24;

ViewContent view_content(const Scene& scene, const RayScene& rays,
                         const std::function<PolygonId(std::uint32_t)>& polygon_of, const LightProbe& light,
                         const Camera& camera) {
  const PinholeCamera pinhole(camera, kGrid, kGrid);
  std::vector<glm::vec3> origin(kGrid * kGrid, camera.eye), direction(kGrid * kGrid);
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x)
      direction[static_cast<std::size_t>(y) * kGrid + x] =
          pinhole.direction((static_cast<float>(x) + 0.5f) / kGrid, (static_cast<float>(y) + 0.5f) / kGrid);
  std::vector<RayScene::Hit> hits(origin.size());
  std::vector<std::uint8_t> found(origin.size());
  rays.intersect(origin.size(), origin.data(), direction.data(), 0.0f, std::numeric_limits<float>::infinity(),
                 hits.data(), found.data());
  const auto positive = [](const Rgb& c) { return c.x > 0.0f || c.y > 0.0f || c.z > 0.0f; };
  ViewContent out;
  for (std::size_t r = 0; r < origin.size(); ++r) {
    if (!found[r]) continue;  // the background
    const Polygon& polygon = scene.polygons()[polygon_of(hits[r].id)];
    const Material& m = scene.material(polygon.material);
    const bool front = glm::dot(direction[r], hits[r].geometric_normal) < 0.0f;
    const bool shown = front || m.two_sided || positive(m.diffuse_transmittance) || positive(m.transmittance);
    const glm::vec3 x = camera.eye + hits[r].t * direction[r];
    const glm::vec3 n = front ? polygon.normal : -polygon.normal;
    // An emitter shows its own light; another side a renderer shows needs light to reach it.
    const bool emits = (front || m.two_sided) && positive(m.emission);
    if (shown && (emits || light.reaches(x, n)))
      out.lit += 1.0;
    else
      out.unlit += 1.0;
  }
  out.lit /= static_cast<double>(origin.size());
  out.unlit /= static_cast<double>(origin.size());
  return out;
}

/// A scene's up: a signed coordinate axis, and why it was taken. The scene formats read here
/// have y up (OBJ by custom, glTF by its specification), but CAD and thermal models (STL, PLY,
/// View3D) often have z up, and a camera with the wrong up shows them on their side.
struct Up {
  int axis = 1;       ///< 0, 1 or 2
  float sign = 1.0f;  ///< +1 or -1
  const char* why = "";
  glm::vec3 vector() const {
    glm::vec3 v(0.0f);
    v[axis] = sign;
    return v;
  }
};

/// The signed axis nearest to `v` (non-zero).
Up nearest_axis(const glm::vec3& v, const char* why) {
  const glm::vec3 a = glm::abs(v);
  Up up;
  up.axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  up.sign = v[up.axis] < 0.0f ? -1.0f : 1.0f;
  up.why = why;
  return up;
}

/// The level polygons along a signed axis: those facing along it (either way) at the bounds'
/// lowest end along it, within 2 % of the height (a table's legs poking 5 mm through a floor
/// 2.7 m below the ceiling leave the floor the ground), and the rest.
struct Levels {
  double ground = 0.0;   ///< area of the level polygons at the lowest end
  double cover = 0.0;    ///< ground over the bounds' section across the axis
  double covered = 0.0;  ///< area of the level polygons above them (roofs, a ceiling)
  Bounds rest;           ///< of every polygon that is not ground
  bool any_rest = false;
};

Levels levels(const Scene& scene, int axis, float sign) {
  const Bounds b = scene.bounds();
  const glm::vec3 extent = b.upper - b.lower;
  const float tolerance = std::max(0.02f * extent[axis], 1e-4f * std::max(b.diagonal(), 1e-6f));
  auto height = [&](const glm::vec3& v) { return sign > 0.0f ? v[axis] - b.lower[axis] : b.upper[axis] - v[axis]; };
  Levels out;
  for (const Polygon& polygon : scene.polygons()) {
    const bool level = std::fabs(polygon.normal[axis]) >= 0.999f;
    bool lowest = level;
    for (const glm::vec3& v : polygon.vertices) lowest = lowest && height(v) <= tolerance;
    if (lowest) {
      out.ground += polygon.area;
      continue;
    }
    if (level) out.covered += polygon.area;
    for (const glm::vec3& v : polygon.vertices) {
      out.rest.lower = out.any_rest ? glm::min(out.rest.lower, v) : v;
      out.rest.upper = out.any_rest ? glm::max(out.rest.upper, v) : v;
      out.any_rest = true;
    }
  }
  const double section = double(extent[(axis + 1) % 3]) * double(extent[(axis + 2) % 3]);
  out.cover = section > 0.0 ? out.ground / section : 0.0;
  return out;
}

/// The scene's up, from the first of these that decides:
/// - a sky's zenith; else the directional lights (the sun shines down), weighted by intensity;
/// - the ground: where the polygons facing along y (or z) at the bounds' lowest y (or z) (levels())
///   cover more than half of the bounds' section across that axis and at least twice the share that
///   those at the lowest z (or y) cover (a city's ground, a floor under an open front); a closed
///   room's floor and its wall are alike, and leave it to
/// - the emitting polygons' normals (weighted by power): ceiling lamps face down, -y or -z,
///   when one of the two is at least twice the other and half of the power (a lamp on a wall
///   decides nothing);
/// - y, the formats' custom.
Up scene_up(const Scene& scene) {
  glm::vec3 sun(0.0f);
  for (const Light& light : scene.lights()) {
    if (light.type == LightType::sky)  // a zenith of 0 is up (0, 1, 0), as Light has it
      return nearest_axis(glm::length(light.direction) > 0.0f ? light.direction : glm::vec3(0, 1, 0),
                          "the sky's zenith");
    if (light.type == LightType::directional && glm::length(light.direction) > 0.0f)
      sun -= light.intensity * glm::normalize(light.direction);
  }
  if (glm::length(sun) > 0.0f) return nearest_axis(sun, "the sun shines down");

  glm::dvec3 lamps(0.0);
  double power = 0.0;
  for (const Polygon& polygon : scene.polygons()) {
    const Material& m = scene.material(polygon.material);
    const double e = std::max({m.emission.x, m.emission.y, m.emission.z});
    if (e > 0.0 && !m.two_sided) {
      lamps += e * polygon.area * glm::dvec3(polygon.normal);
      power += e * polygon.area;
    }
  }
  const double cover_y = levels(scene, 1, 1.0f).cover, cover_z = levels(scene, 2, 1.0f).cover;
  Up up;
  if (cover_z > 0.5 && cover_z >= 2.0 * cover_y) {
    up.axis = 2;
    up.why = "the ground lies at the lowest z";
    return up;
  }
  if (cover_y > 0.5 && cover_y >= 2.0 * cover_z) {
    up.why = "the ground lies at the lowest y";
    return up;
  }
  const double down_y = -lamps.y, down_z = -lamps.z;
  if (down_z > 0.5 * power && down_z >= 2.0 * std::fabs(lamps.y)) {
    up.axis = 2;
    up.why = "the emitters face down -z";
    return up;
  }
  if (down_y > 0.5 * power && down_y >= 2.0 * std::fabs(lamps.z)) {
    up.why = "the emitters face down -y";
    return up;
  }
  up.why = "as OBJ and glTF have it";
  return up;
}

/// A share in [0, 1] as the reasons print it: "44 %".
std::string percent(double share) { return std::to_string(static_cast<int>(100.0 * share + 0.5)) + " %"; }

/// Axis names for the reasons: "+x", "-z", ...
std::string axis_name(int axis, float sign) { return std::string(sign < 0.0f ? "-" : "+") + "xyz"[axis]; }

/// "z up: the ground lies at the lowest z", "-y up: the sky's zenith".
std::string up_text(const Up& up) {
  return (up.sign < 0.0f ? "-" : "") + std::string(1, "xyz"[up.axis]) + " up: " + up.why;
}

/// A ground open to the sky (levels() along the scene's up): it covers more than half of the
/// bounds' section, and the level polygons above it (roofs, a ceiling) cover less than half of
/// it (a closed room's ceiling covers its floor); and something stands on it.
bool open_ground(const Levels& l) { return l.any_rest && l.cover > 0.5 && l.covered < 0.5 * l.ground; }

/// How far above the horizontal the view of a ground open to the sky looks down.
constexpr float kAerialElevationDeg = 30.0f;

/// Scene::camera()'s framing of the bounds (their sphere in a 45 degree view), looking along
/// `toward` (a unit axis across the up) from outside.
Camera framed_from(const Scene& scene, const glm::vec3& toward, const Up& up) {
  Camera c = scene.camera();
  const float distance = glm::length(c.eye - c.look_at);
  c.eye = c.look_at - distance * toward;
  c.up = up.vector();
  return c;
}

/// The choice that needs no look: the scene's camera; else, on a ground open to the sky (a
/// site, a city), the view 30 degrees from above that frames what stands on it and as much
/// ground again around it (the ground's
/// edge seen from the side shows nothing: a house on a 1 km plot was a speck on a horizon);
/// else the view that frames the bounds from the side, its up the scene's (Scene::camera()'s
/// view from -z when y is up; from -y when z is). `up`: scene_up(scene), unused (and not worth
/// computing) when the scene has a camera.
CameraChoice unjudged_choice(const Scene& scene, const Up& up, bool* aerial = nullptr) {
  if (aerial) *aerial = false;
  CameraChoice out;
  out.camera = scene.camera();
  if (scene.has_camera()) {
    out.reason = "the scene's camera";
    return out;
  }
  // Look along z unless z is up (then along y), from the negative side, as Scene::camera().
  const int front = up.axis == 2 ? 1 : 2;
  glm::vec3 toward(0.0f);
  toward[front] = 1.0f;
  const Levels ground = levels(scene, up.axis, up.sign);
  if (open_ground(ground)) {
    if (aerial) *aerial = true;
    // What stands on the ground, with as much ground again around it across the up (within the
    // scene's bounds): a house shows its plot; a lamp over a small floor shows the floor.
    const Bounds scene_box = scene.bounds();
    Bounds shown = ground.rest;
    for (int k = 0; k < 3; ++k) {
      if (k == up.axis) continue;
      const float margin = 0.5f * (shown.upper[k] - shown.lower[k]);
      shown.lower[k] = std::max(shown.lower[k] - margin, scene_box.lower[k]);
      shown.upper[k] = std::min(shown.upper[k] + margin, scene_box.upper[k]);
    }
    const glm::vec3 centre = 0.5f * (shown.lower + shown.upper);
    const float radius = std::max(0.5f * shown.diagonal(), 1e-3f);
    out.camera.fov_deg = 45.0f;
    const float distance = radius / std::sin(glm::radians(0.5f * out.camera.fov_deg));
    const float elevation = glm::radians(kAerialElevationDeg);
    out.camera.look_at = centre;
    out.camera.eye = centre + distance * (std::sin(elevation) * up.vector() - std::cos(elevation) * toward);
    out.camera.up = up.vector();
    char degrees[16];
    std::snprintf(degrees, sizeof degrees, "%.0f", kAerialElevationDeg);
    out.reason = "the scene has none: framing what stands on its ground from " + axis_name(front, -1.0f) + ", " +
                 degrees + " degrees above (" + up_text(up) + ")";
    return out;
  }
  if (front != 2 || up.axis != 1 || up.sign < 0.0f) out.camera = framed_from(scene, toward, up);
  out.reason = "the scene has none: framing its bounds from " + axis_name(front, -1.0f) + " (" + up_text(up) + ")";
  return out;
}

/// Whether there is a view to judge: no camera of the scene's own, and something to see.
bool judged(const Scene& scene) { return !scene.has_camera() && !scene.polygons().empty(); }

/// unjudged_choice() with the scene's up found only when it is used.
CameraChoice unjudged_choice(const Scene& scene) {
  return unjudged_choice(scene, scene.has_camera() ? Up{} : scene_up(scene));
}

}  // namespace

CameraChoice choose_camera(const Scene& scene, const RayScene& rays,
                           const std::function<PolygonId(std::uint32_t)>& polygon_of) {
  if (!judged(scene)) return unjudged_choice(scene);
  const Up up = scene_up(scene);  // once: the view from outside and those from inside
  bool aerial = false;
  CameraChoice out = unjudged_choice(scene, up, &aerial);
  const LightProbe light(scene, rays);
  if (light.empty()) return out;  // nothing lights any view
  const ViewContent outside = view_content(scene, rays, polygon_of, light, out.camera);
  // A view from outside that shows mostly lit surfaces, or mostly background, is kept: an
  // object, a city, a box open toward the camera. Only one whose surfaces are mostly unlit (a
  // closed model seen from outside: backs, or outer sides no light reaches) is replaced.
  // (A closed room framed by its bounding sphere fills about 40 % of the view.)
  auto mostly_unlit = [](const ViewContent& v) { return v.unlit > 0.5 * (v.lit + v.unlit) && v.unlit > 0.25; };
  if (!mostly_unlit(outside)) return out;

  // The bounds framed from the other sides across the up: a box open on one side (the Cornell
  // box as McGuire's OBJ has it, open toward +z, where glTF's assets face) is seen through its
  // opening, as people photograph it. Found with that file: the view from -z showed the back
  // wall's back, and the view from inside stood in the opening, too close to show the room.
  const int front = up.axis == 2 ? 1 : 2, side = 3 - up.axis - front;
  const int first_side = aerial ? 3 : 0;  // a ground open to the sky keeps its own view
  double best_outside = 0.0;
  for (int k = first_side; k < 3; ++k) {
    const int axis = k == 0 ? front : side;
    const float sign = k == 0 ? -1.0f : (k == 1 ? 1.0f : -1.0f);  // +front, -side, +side
    glm::vec3 toward(0.0f);
    toward[axis] = sign;
    const Camera camera = framed_from(scene, toward, up);
    const ViewContent view = view_content(scene, rays, polygon_of, light, camera);
    if (mostly_unlit(view) || !(view.lit > best_outside)) continue;
    best_outside = view.lit;
    out.camera = camera;
    out.reason = "the scene has none, and from " + axis_name(front, -1.0f) + " " + percent(outside.unlit) +
                 " of the view is surfaces no light reaches: framing its bounds from " + axis_name(axis, -sign) +
                 " (" + percent(view.lit) + " of the view lit surfaces; " + up_text(up) + ")";
  }
  if (best_outside > 0.0) return out;

  // From inside: at mid height, 5 % of the way in from each side of the bounds, looking across
  // to the opposite side (along the two axes across the scene's up), with a wide lens.
  const Bounds b = scene.bounds();
  const glm::vec3 centre = 0.5f * (b.lower + b.upper), extent = b.upper - b.lower;
  struct Candidate {
    glm::vec3 toward;
    std::string name;
  };
  std::vector<Candidate> candidates;
  for (const int axis : {2, 0, 1}) {  // z, x, then y: y-up scenes as before
    if (axis == up.axis) continue;
    for (const float sign : {1.0f, -1.0f}) {
      glm::vec3 toward(0.0f);
      toward[axis] = sign;
      candidates.push_back(Candidate{toward, axis_name(axis, sign)});
    }
  }
  double best_lit = outside.lit;
  for (const Candidate& c : candidates) {
    Camera camera;
    camera.eye = centre - 0.45f * glm::dot(extent, glm::abs(c.toward)) * c.toward;
    camera.look_at = camera.eye + c.toward;
    camera.up = up.vector();
    camera.fov_deg = 60.0f;
    const ViewContent inside = view_content(scene, rays, polygon_of, light, camera);
    if (inside.lit > best_lit) {
      best_lit = inside.lit;
      out.camera = camera;
      out.reason = "the scene has none, and from outside " + percent(outside.unlit) +
                   " of the view is surfaces no light reaches (a closed model): inside, at " + point_text(camera.eye, scene.origin()) +
                   " looking " + c.name + ", 60 degrees (" + percent(inside.lit) + " of the view lit surfaces; " +
                   up_text(up) + ")";
    }
  }
  return out;
}

}  // namespace radiosity::detail

namespace radiosity {
inline namespace v1 {

CameraChoice choose_camera(const Scene& scene) {
  if (!detail::judged(scene)) return detail::unjudged_choice(scene);  // no ray scene needed
  const detail::RayScene rays = detail::RayScene::from_polygons(scene);
  return detail::choose_camera(scene, rays, [](std::uint32_t id) { return PolygonId{id}; });
}

}  // namespace v1
}  // namespace radiosity
